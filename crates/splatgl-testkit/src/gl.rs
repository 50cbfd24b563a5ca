//! Shared helpers of the GL test crates (`tests/it/gl_vs_reference.rs`, `tests/it/gl_embedding.rs`,
//! `tests/it/gl_errata.rs`): GL backend (OpenGL ES 3 on Mesa EGL / llvmpipe) against the CPU
//! reference rasterizer. `use common::gl::*` brings these and the general helpers.
//!
//! Every test renders small images (≤ 96 px) so the suite stays fast on llvmpipe. Tests skip
//! (with a message) only when EGL cannot be opened at all; any other GL failure fails them.
//!
//! # Error bound on the RGBA8 path
//!
//! The GL result differs from the f32/f64 reference through
//! 1. 8-bit storage between blends: every blend rounds to the nearest 1/255, and the final value
//!    is rounded once more. An earlier rounding error is only attenuated by later splats, so
//!    with `L` splats covering a pixel the error is at most `(L + 1) · 0.5/255`; in practice the
//!    roundings partly cancel.
//! 2. f32 vs f64 in the projection: a pixel centre that lies on the 3σ ellipse (m² = 9) or on
//!    the α = 1/255 threshold can be in for one backend and out for the other. The jump is at
//!    most α at the cut, `0.99 · e^(−4.5) ≈ 0.011` (2.8/255), times |colour − behind|.
//! 3. f16 SH coefficients: < 1.1e-3 per splat for the coefficient ranges used here.
//!
//! 4. Over-bright splats (SH colour > 1, common in trained data): a UNORM framebuffer clamps the
//!    running sum to 1 after every blend, the reference only at the end (RC: "final C
//!    clamped"). The excess lost is at most `max colour − 1`, later attenuated, so the RGBA8
//!    bound gets `+ max(0, c_max − 1)` ([`overbright`]). The RGBA16F target does not clamp.
//!
//! [`MAX_ERR_SPARSE`] (≤ 2 splats per pixel) and [`MAX_ERR_DENSE`] follow from these terms;
//! PSNR must be ≥ 45 dB everywhere.
#![allow(dead_code, unused_imports)]

pub use super::{look_at_fov_deg, real_files, sh_for};
pub use glam::{Quat, Vec3};
pub use splatgl::SplatCloud;
pub use splatgl::camera::Camera;
pub use splatgl::cloud::ColorSpace;
pub use splatgl::compare::compare;
pub use splatgl::headless::{
    GlApi, HeadlessContext, HeadlessError, HeadlessOptions, HeadlessRenderer, TargetKind,
};
pub use splatgl::image::Image;
pub use splatgl::reference;
pub use splatgl::synthetic::{self, Rng};

/// Sparse scenes: (1 + 2) · 0.5/255 rounding + the 0.011 cut jump.
pub const MAX_ERR_SPARSE: f32 = 1.5 / 255.0 + 0.0111;
/// Dense scenes (tens of layers): rounding can accumulate; 8/255 + the cut jump.
pub const MAX_ERR_DENSE: f32 = 8.0 / 255.0 + 0.0111;
pub const MIN_PSNR: f64 = 45.0;

/// The value, or `None` (test skipped, with a message) when EGL cannot be opened at all; any
/// other error panics with `what`.
pub fn or_skip<T>(r: Result<T, HeadlessError>, what: &str) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(HeadlessError::EglUnavailable(msg)) => {
            super::skip(&format!("EGL cannot be opened here ({msg})"));
            None
        }
        Err(e) => panic!("{what}: {e}"),
    }
}

/// A headless renderer, or `None` (test skipped, with a message) when EGL cannot be opened.
pub fn headless() -> Option<HeadlessRenderer> {
    or_skip(HeadlessRenderer::new(), "headless GL failed")
}

pub fn ref_opts(degree: u8, background: [f32; 3]) -> reference::RenderOptions {
    reference::RenderOptions {
        sh_degree: degree,
        background,
        ..Default::default()
    }
}

/// Measured agreement of two images: (PSNR dB, max RGB error, max alpha error).
#[derive(Debug, Clone, Copy)]
pub struct Score {
    pub psnr: f64,
    pub max_rgb: f32,
    pub max_alpha: f32,
}

/// Compares a GL read-back with a reference image as displayed (clamped to [0, 1]).
pub fn score(gl: &Image, want: &Image) -> Score {
    let mut want = want.clone();
    for p in &mut want.pixels {
        *p = p.map(|v| v.clamp(0.0, 1.0));
    }
    let c = compare(gl, &want, 1.0 / 255.0).unwrap();
    let max_alpha = gl
        .pixels
        .iter()
        .zip(&want.pixels)
        .map(|(a, b)| (a[3] - b[3].clamp(0.0, 1.0)).abs())
        .fold(0.0f32, f32::max);
    Score {
        psnr: c.psnr,
        max_rgb: c.max_abs,
        max_alpha,
    }
}

/// Reference image of `cloud` (SH degree `degree`, background `bg`), in display values
/// (`linear`: as a `lin_rec709_display` cloud is shown).
pub fn reference_image(
    cloud: &SplatCloud,
    cam: &Camera,
    degree: u8,
    bg: [f32; 3],
    linear: bool,
) -> Image {
    let space = if linear {
        ColorSpace::LinRec709Display
    } else {
        ColorSpace::SrgbRec709Display
    };
    reference::render_display(cloud, cam, &ref_opts(degree, bg), space).0
}

/// How far the brightest splat colour seen by `cam` exceeds 1 (0 if none does).
pub fn overbright(cloud: &SplatCloud, cam: &Camera, degree: u8) -> f32 {
    let eye = cam.eye();
    (0..cloud.len())
        .map(|i| {
            let dir = (Vec3::from_array(cloud.positions[i]) - eye).normalize();
            let c = splatgl::sh::eval_color(cloud.sh_of(i), degree, dir.to_array());
            c[0].max(c[1]).max(c[2]) - 1.0
        })
        .filter(|e| e.is_finite()) // non-finite colours are culled by both backends
        .fold(0.0f32, f32::max)
}

/// Renders with GL and the reference, prints the numbers, checks PSNR and the error bound
/// (`max_err`, plus [`overbright`] on the RGBA8 path).
pub fn check(
    name: &str,
    r: &mut HeadlessRenderer,
    cloud: &SplatCloud,
    cam: &Camera,
    opts: &HeadlessOptions,
    max_err: f32,
) -> Score {
    r.upload(cloud).unwrap();
    let gl = r.render(cam, opts).unwrap();
    let degree = opts.sh_degree.unwrap_or(cloud.sh_degree);
    let linear = opts
        .color_space
        .unwrap_or(cloud.meta.color_space.effective())
        == ColorSpace::LinRec709Display;
    let want = reference_image(cloud, cam, degree, opts.background, linear);
    let s = score(&gl, &want);
    let extra = if opts.target == TargetKind::Rgba8 {
        overbright(cloud, cam, degree.min(cloud.sh_degree))
    } else {
        0.0
    };
    let max_err = max_err + extra;
    eprintln!(
        "[{name}] {:?} {}x{}: PSNR {:.2} dB, max RGB err {:.5} ({:.2}/255), max A err {:.5}, \
         bound {:.2}/255",
        opts.target,
        cam.width,
        cam.height,
        s.psnr,
        s.max_rgb,
        s.max_rgb * 255.0,
        s.max_alpha,
        max_err * 255.0
    );
    // The scene must actually show something, or the comparison proves nothing.
    let covered = want.pixels.iter().filter(|p| p[3] > 0.05).count();
    assert!(covered > 0, "[{name}] reference image is empty");
    assert!(
        s.psnr >= MIN_PSNR,
        "[{name}] PSNR {:.2} < {MIN_PSNR}",
        s.psnr
    );
    assert!(
        s.max_rgb <= max_err,
        "[{name}] max error {} > {max_err}",
        s.max_rgb
    );
    assert!(
        s.max_alpha <= max_err,
        "[{name}] max alpha error {} > {max_err}",
        s.max_alpha
    );
    s
}

pub fn both_targets() -> [HeadlessOptions; 2] {
    [
        HeadlessOptions::default(),
        HeadlessOptions {
            target: TargetKind::Rgba16fResolve,
            ..Default::default()
        },
    ]
}

/// A headless context made current (`None`: skipped, see [`or_skip`]).
pub fn current_context() -> Option<HeadlessContext> {
    let ctx = or_skip(HeadlessContext::new(), "headless context")?;
    ctx.make_current().unwrap();
    Some(ctx)
}
