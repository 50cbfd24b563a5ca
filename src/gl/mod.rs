//! OpenGL ES 3 backend (feature `gl`, on by default).
//!
//! Shaped for embedding, like `egui_glow`'s painter: [`SplatRenderer`] borrows the host's
//! [`glow::Context`] and never owns it, so it draws into whatever framebuffer the host has bound.
//!
//! ```no_run
//! # fn demo(gl: &glow::Context, cloud: &splatgl::SplatCloud, camera: &splatgl::camera::Camera)
//! # -> Result<(), splatgl::gl::GlError> {
//! use splatgl::gl::{ColorFormat, ReadbackTarget, SplatRenderer, sort_back_to_front};
//! let mut renderer = SplatRenderer::new(gl)?;
//! renderer.upload(gl, cloud)?;                  // once: splat data → textures
//! let mut target = ReadbackTarget::new(gl, camera.width, camera.height, ColorFormat::Rgba8, None)?;
//! target.bind(gl)?;                              // or draw into the host's own framebuffer
//! let mut order = Vec::new();
//! sort_back_to_front(&cloud.positions, camera.eye(), &mut order); // per frame
//! renderer.draw(gl, camera, &order)?;            // per frame: 4 bytes/splat uploaded
//! let image = target.read_image(gl)?;            // top row first
//! target.destroy(gl);
//! renderer.destroy(gl);
//! # Ok(()) }
//! ```
//!
//! * [`SplatRenderer`] and its [`DrawSettings`]: upload once, draw per frame.
//! * [`ReadbackTarget`]: a framebuffer (RGBA8 / SRGB8_ALPHA8 / RGBA16F colour, optional depth)
//!   read back into an [`Image`](crate::image::Image), for headless use, tests and hosts.
//! * [`OffscreenTarget`]: the RGBA16F accumulation target with a resolve pass.
//! * [`sort_back_to_front`] / [`DistanceSorter`]: the draw order, over the crate's radix sorter
//!   ([`crate::sort::Sorter`]). `examples/embed.rs` shows a host-owned context.
//! * [`state`]: every piece of GL state the backend touches.
//!
//! Every type that owns GL objects has `destroy(&mut self, gl)`; call it with the context
//! current before dropping the value (a live value dropped leaks its objects and warns once;
//! a destroyed one returns [`GlError::Destroyed`]). Shaders get every number of the rendering
//! profile as a generated `#define` ([`crate::profile`]).

mod data;
mod glsl;
mod objects;
mod program;
mod readback;
mod renderer;
mod sort;
pub mod state;
mod target;

#[doc(hidden)]
pub use glsl::Errata;
#[doc(hidden)]
pub use program::build_program;
pub use readback::{ColorFormat, DepthFormat, ReadbackTarget};
pub use renderer::{DrawSettings, SplatRenderer};
pub use sort::{DistanceSorter, sort_back_to_front};
pub use target::OffscreenTarget;

/// Errors of the GL layer.
#[derive(Debug, thiserror::Error)]
pub enum GlError {
    /// A shader stage failed to compile. `source` is the assembled source with line numbers.
    #[error("{stage} shader failed to compile:\n{log}\n--- source ---\n{numbered_source}")]
    Compile {
        /// `"vertex"` or `"fragment"`, with the program's name.
        stage: String,
        /// The driver's info log.
        log: String,
        /// The assembled source, one numbered line per source line.
        numbered_source: String,
    },
    /// The program failed to link.
    #[error(
        "program `{program}` failed to link:\n{log}\n--- vertex ---\n{vertex}\n--- fragment ---\n{fragment}"
    )]
    Link {
        /// Which program.
        program: String,
        /// The driver's info log.
        log: String,
        /// Numbered vertex source.
        vertex: String,
        /// Numbered fragment source.
        fragment: String,
    },
    /// A GL object could not be created (the driver's message).
    #[error("could not create GL {what}: {message}")]
    Create {
        /// What kind of object.
        what: &'static str,
        /// The driver's message.
        message: String,
    },
    /// The context lacks something the backend needs.
    #[error("unsupported GL context: {0}")]
    Unsupported(String),
    /// The cloud does not fit the texture layout or is inconsistent.
    #[error("cannot upload cloud: {0}")]
    Upload(String),
    /// `draw` was given more indices than the uploaded cloud has splats.
    #[error("order has {got} indices but the uploaded cloud has {capacity} splats")]
    OrderTooLong {
        /// Length of the order passed.
        got: usize,
        /// Splats uploaded.
        capacity: usize,
    },
    /// `draw` was called before `upload`.
    #[error("draw called before upload")]
    NotUploaded,
    /// A framebuffer was incomplete.
    #[error("framebuffer incomplete: status 0x{0:04X}")]
    Framebuffer(u32),
    /// A method was called after `destroy` (the name of the type).
    #[error("{0} used after destroy()")]
    Destroyed(&'static str),
    /// `glGetError` reported an error after an operation.
    #[error("GL error 0x{code:04X} after {during}")]
    Gl {
        /// The error code.
        code: u32,
        /// What the backend was doing.
        during: &'static str,
    },
}

/// Clears errors the host left pending (at most a few: each `glGetError` clears one flag), so
/// that a later [`check_error`] reports only what this crate caused.
pub(crate) fn clear_pending_errors(gl: &glow::Context) {
    use glow::HasContext;
    for _ in 0..8 {
        // SAFETY: as in `check_error`.
        if unsafe { gl.get_error() } == glow::NO_ERROR {
            break;
        }
    }
}

/// Checks `glGetError` (used after uploads and target creation, never on the draw hot path).
pub(crate) fn check_error(gl: &glow::Context, during: &'static str) -> Result<(), GlError> {
    use glow::HasContext;
    // SAFETY: glGetError has no preconditions beyond a current context, which every caller of
    // this crate's GL functions must provide.
    let code = unsafe { gl.get_error() };
    if code == glow::NO_ERROR {
        Ok(())
    } else {
        Err(GlError::Gl { code, during })
    }
}
