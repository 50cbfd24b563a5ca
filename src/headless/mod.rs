//! Headless rendering through EGL on Mesa's surfaceless platform (feature `gl`).
//!
//! * [`render`] — one call: cloud + camera + options → [`Image`]. This is what a CLI
//!   `--backend gl` calls.
//! * [`HeadlessRenderer`] — the same, keeping the context, the uploaded cloud and the
//!   framebuffers between renders (tests, benchmarks, many views of one cloud).
//! * [`HeadlessContext`] — just the EGL context and its [`glow::Context`], for driving
//!   [`crate::gl`] yourself (e.g. with a [`ReadbackTarget`](crate::gl::ReadbackTarget)).
//!
//! The EGL library is loaded at run time (`libEGL.so.1`); when it is missing or no display can
//! be initialised the error is [`HeadlessError::EglUnavailable`], which callers (and the test
//! suite) may treat as "no GL here". Every other failure is a real error.
//!
//! Contexts are current on the thread that created them and are not `Send`.

mod egl;
mod renderer;

pub use egl::{GlApi, HeadlessContext};
pub use renderer::{HeadlessOptions, HeadlessRenderer, TargetKind};

use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::gl::GlError;
use crate::image::Image;

/// Errors of headless rendering.
#[derive(Debug, thiserror::Error)]
pub enum HeadlessError {
    /// EGL could not be opened here (no `libEGL.so.1`, or no surfaceless display).
    #[error("EGL unavailable: {0}")]
    EglUnavailable(String),
    /// An EGL call failed after EGL was opened.
    #[error("EGL call {call} failed: {error}")]
    Egl {
        /// The failing call.
        call: &'static str,
        /// EGL's error.
        error: khronos_egl::Error,
    },
    /// The GL layer failed.
    #[error(transparent)]
    Gl(#[from] GlError),
}

/// Renders `cloud` seen by `camera` headlessly: creates an EGL context, uploads, sorts back to
/// front, draws and reads back. The image has the camera's size; RGB is display-referred
/// (sRGB-encoded for `lin_rec709_display`) and composited over `opts.background`, A = 1 − T:
/// the image [`crate::reference::render_display`] computes on the CPU.
///
/// For many renders of one cloud keep a [`HeadlessRenderer`] instead.
pub fn render(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &HeadlessOptions,
) -> Result<Image, HeadlessError> {
    let mut r = HeadlessRenderer::new()?;
    r.upload(cloud)?;
    r.render(camera, opts)
}
