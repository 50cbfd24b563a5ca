//! Headless rendering (feature `gl`): through EGL on Mesa's surfaceless platform on Linux and
//! the other Unixes, through WGL with a hidden window on Windows, through CGL on macOS.
//!
//! * [`render`] — one call: cloud + camera + options → [`Image`]. This is what a CLI
//!   `--backend gl` calls.
//! * [`HeadlessRenderer`] — the same, keeping the context, the uploaded cloud and the
//!   framebuffers between renders (tests, benchmarks, many views of one cloud).
//! * [`HeadlessContext`] — just the context (EGL, WGL or CGL) and its [`glow::Context`], for driving
//!   [`crate::gl`] yourself (e.g. with a [`ReadbackTarget`](crate::gl::ReadbackTarget)).
//!
//! The EGL library is loaded at run time (`libEGL.so.1`); when it is missing or no display can
//! be initialised the error is [`HeadlessError::EglUnavailable`], which callers (and the test
//! suite) may treat as "no GL here". Every other failure is a real error.
//!
//! On macOS it is made by CGL with no drawable (desktop core profiles only: a GLES 3 request
//! gets 4.1 core); a failure is [`HeadlessError::CglUnavailable`].
//! On Windows the context is made by WGL on a hidden window of its own (render into framebuffer
//! objects as on EGL); a failure to make one is [`HeadlessError::WglUnavailable`].
//!
//! Contexts are current on the thread that created them and are not `Send`.

#[cfg(target_os = "macos")]
mod cgl;
#[cfg(not(any(windows, target_os = "macos")))]
mod egl;
mod renderer;
#[cfg(windows)]
mod wgl;

#[cfg(target_os = "macos")]
pub use cgl::HeadlessContext;
#[cfg(not(any(windows, target_os = "macos")))]
pub use egl::HeadlessContext;
pub use renderer::{HeadlessOptions, HeadlessRenderer, TargetKind};
#[cfg(windows)]
pub use wgl::HeadlessContext;

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
    /// WGL could not give a context here (Windows: no window class, window, pixel format or
    /// `wglCreateContextAttribsARB`). The Windows counterpart of
    /// [`HeadlessError::EglUnavailable`].
    #[error("WGL unavailable: {0}")]
    WglUnavailable(String),
    /// A WGL or Win32 call failed after a context could be made (`code`: `GetLastError()`).
    #[error("WGL call {call} failed (error {code})")]
    Wgl {
        /// The failing call.
        call: &'static str,
        /// `GetLastError()` right after it.
        code: u32,
    },
    /// CGL could not give a context here (macOS: OpenGL.framework missing, or a profile macOS
    /// does not offer). The macOS counterpart of [`HeadlessError::EglUnavailable`].
    #[error("CGL unavailable: {0}")]
    CglUnavailable(String),
    /// A CGL call failed (`code`: its `CGLError`).
    #[error("CGL call {call} failed (error {code})")]
    Cgl {
        /// The failing call.
        call: &'static str,
        /// The `CGLError` it returned.
        code: i32,
    },
    /// The GL layer failed.
    #[error(transparent)]
    Gl(#[from] GlError),
}

/// Which client API a [`HeadlessContext`] speaks. More kinds of context may be added: match
/// with a wildcard arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum GlApi {
    /// OpenGL ES 3.0 or newer (shaders get `#version 300 es`). The default. On Windows, where
    /// WGL offers ES contexts only through `WGL_EXT_create_context_es2_profile`, a desktop
    /// 3.3 core context stands in when the driver has no ES (see [`HeadlessContext::describe`]).
    #[default]
    Gles3,
    /// Desktop OpenGL 3.3 (or newer) core profile (shaders get `#version 330 core`).
    DesktopCore33,
    /// Desktop OpenGL compatibility profile, 3.3 or newer (Mesa gives 4.5 on llvmpipe): the
    /// fixed-function pipeline, immediate mode and client arrays of legacy hosts are all
    /// there beside the shaders (which get `#version 330 core`).
    DesktopCompat,
}

impl GlApi {
    /// The `(major, minor)` version asked for by default.
    fn default_version(self) -> (i32, i32) {
        match self {
            GlApi::Gles3 => (3, 0),
            GlApi::DesktopCore33 | GlApi::DesktopCompat => (3, 3),
        }
    }
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
