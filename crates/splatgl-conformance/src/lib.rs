//! The `KHR_gaussian_splatting` conformance suite: small assets, each checking one rule, with
//! their cameras, reference images and derived tolerances (`splatgl conformance generate`),
//! and the runner that compares another renderer's images with them
//! (`splatgl conformance run`). How to use it and how every number is derived:
//! `docs/conformance.md`.
//!
//! Data flow: [`assets`] (what each asset holds, as a [`splatgl::write::scene::SceneDoc`]) →
//! [`generate`] (writes the files, loads them back, renders the references, derives the
//! tolerances with [`model`] and which errata each asset catches) → [`manifest::Manifest`]
//! → [`runner`] (compares images, explains failures) → [`report`] (HTML + JSON).

#![warn(missing_docs)]

pub mod assets;
mod assets_light;
mod assets_pixel;
mod assets_scene;
pub mod deviation;
pub mod diagnosis;
mod generate;
mod isolation;
pub mod judge;
pub mod manifest;
pub mod model;
pub mod render;
pub mod report;
pub mod runner;
pub mod verdict;

pub use generate::{GenerateError, generate};

/// Why the kit could not read, render or grade a suite.
#[derive(Debug, thiserror::Error)]
pub enum KitError {
    /// `manifest.json` could not be read or breaks its schema (the message names the key).
    #[error("{0}")]
    Manifest(String),
    /// A file the manifest names lies outside the suite's folder or is missing.
    #[error("{rel}: {source}")]
    File {
        /// The name as the manifest writes it.
        rel: String,
        /// Why it was refused.
        source: splatgl::files::Refused,
    },
    /// An asset did not load or one of its cameras could not be made.
    #[error("{0}")]
    Asset(String),
    /// The renderer could not be made, take an asset or draw.
    #[error(transparent)]
    Engine(#[from] splatgl::engine::EngineError),
    /// The GL renderer with errata (the erratum proof) failed.
    #[error("{0}")]
    Gl(String),
    /// A reference image or bound could not be read: a broken suite.
    #[error("{0}")]
    Reference(String),
}

impl From<KitError> for String {
    fn from(e: KitError) -> String {
        e.to_string()
    }
}

/// Image size of every camera of the suite.
pub const WIDTH: u32 = 128;
/// Image height of every camera of the suite.
pub const HEIGHT: u32 = 96;

/// The Appendix A errata of the review draft that show in an image (spec-notes §2; c, h and
/// j do not: c culls everything, h is text, j fails to link).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Erratum {
    /// Rotation matrix transposed (Σ = Rᵀ S² R).
    A,
    /// View matrix transposed in Σ' (T = Vᵀ Σ V).
    B,
    /// Quad offset `radius / focal · w` and a centre that is not in pixels.
    D,
    /// SH without Condon–Shortley signs, 2.89 for coefficient 14, sigmoid colour.
    E,
    /// Cut at power > 4 (2.83σ) instead of 3σ.
    F,
    /// `SRC_ALPHA` blending of premultiplied colour, front to back.
    G,
    /// No 0.3 px² dilation.
    I,
    /// No ±1.3·tan(half fov) clamp in J, no 0.99 α cap.
    K,
}

impl Erratum {
    /// All of them.
    pub const ALL: [Erratum; 8] = [
        Erratum::A,
        Erratum::B,
        Erratum::D,
        Erratum::E,
        Erratum::F,
        Erratum::G,
        Erratum::I,
        Erratum::K,
    ];
    /// The letter used in spec-notes §2 and `docs/appendix-errata.md`.
    pub fn letter(self) -> &'static str {
        match self {
            Erratum::A => "a",
            Erratum::B => "b",
            Erratum::D => "d",
            Erratum::E => "e",
            Erratum::F => "f",
            Erratum::G => "g",
            Erratum::I => "i",
            Erratum::K => "k",
        }
    }
    /// From its letter.
    pub fn from_letter(s: &str) -> Option<Self> {
        Erratum::ALL.into_iter().find(|e| e.letter() == s)
    }
    /// What a renderer with this erratum does wrong, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Erratum::A => "rotation matrix transposed: mat3(...) filled with rows (Σ = Rᵀ S² R)",
            Erratum::B => "view rotation transposed in Σ' = J W Σ Wᵀ Jᵀ",
            Erratum::D => {
                "quad size radius/focal and a splat centre that is not in pixels (right only at 90° fov)"
            }
            Erratum::E => {
                "SH without the Condon–Shortley signs (and 2.89 for Y₃,₂), sigmoid instead of + 0.5"
            }
            Erratum::F => "3σ cut-off taken as power > 4 (2.83σ) instead of 4.5",
            Erratum::G => "SRC_ALPHA blending of premultiplied colour (α²) and front-to-back order",
            Erratum::I => "no 0.3 px² dilation of Σ' (sub-pixel splats vanish or alias)",
            Erratum::K => {
                "no ±1.3·tan(half fov) clamp inside J (edge splats explode) and no 0.99 α cap"
            }
        }
    }
    /// The GL backend's switch for this erratum (feature `testing`: the erratum proof).
    #[cfg(all(feature = "gl", feature = "testing"))]
    pub fn gl_errata(self) -> splatgl::gl::Errata {
        let mut e = splatgl::gl::Errata::default();
        match self {
            Erratum::A => e.a_transposed_rotation = true,
            Erratum::B => e.b_transposed_view = true,
            Erratum::D => e.d_focal_offset = true,
            Erratum::E => e.e_appendix_sh = true,
            Erratum::F => e.f_power_4 = true,
            Erratum::G => e.g_src_alpha_blend = true,
            Erratum::I => e.i_no_dilation = true,
            Erratum::K => e.k_no_clamp_no_cap = true,
        }
        e
    }
}
