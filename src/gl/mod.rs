//! OpenGL ES 3 backend (feature `gl`, on by default).
//!
//! Shaped for embedding, like `egui_glow`'s painter: [`SplatRenderer`] borrows the host's
//! [`glow::Context`] and never owns it, so it draws into whatever framebuffer the host has bound.
//!
//! ```no_run
#![doc = include_str!("../../docs/snippets/embed.rs")]
//! ```
//!
//! [`SplatRenderer::draw_frame`] derives the eye from the host's view matrix, culls, sorts
//! ([`crate::sort::Sorter`], or a background [`AsyncSorter`](crate::sort::AsyncSorter) with
//! [`FrameSort::Async`]) and draws. Hosts that sort themselves (the advanced path) upload
//! their own order with [`SplatRenderer::set_order`] and draw it with `draw_current*` or
//! `draw_with_matrices`; headless images come from a [`ReadbackTarget`].
//!
//! * [`SplatRenderer`] and its [`DrawSettings`]: upload once, draw per frame — with a
//!   [`Camera`](crate::camera::Camera) (`draw`) or the host's own view and projection
//!   matrices (`draw_with_matrices`: reversed-Z, infinite far, any [`DepthFunc`]).
//!   `DrawSettings::restore_state` puts back every piece of GL state a call changes.
//! * [`SplatScene`]: several clouds, each with its own model matrix, in one back-to-front
//!   order.
//! * [`ReadbackTarget`]: a framebuffer (RGBA8 / SRGB8_ALPHA8 / RGBA16F colour, optional depth)
//!   read back into an [`Image`](crate::image::Image), for headless use, tests and hosts.
//! * [`OffscreenTarget`]: the RGBA16F accumulation target with a resolve pass.
//! * The draw order of the advanced path: [`crate::sort::Sorter`] (the crate's one sorter;
//!   [`sort_back_to_front`] and [`DistanceSorter`] are deprecated wrappers of it).
//!   `examples/embed.rs` shows a host-owned context.
//! * [`state`]: every piece of GL state the backend touches, in both modes
//!   (`docs/embedding.md` is the guide for hosts).
//!
//! Every type that owns GL objects has `destroy(&mut self, gl)`; call it with the context
//! current before dropping the value (a live value dropped leaks its objects and warns once;
//! a destroyed one returns [`GlError::Destroyed`]). Shaders get every number of the rendering
//! profile as a generated `#define` ([`crate::profile`]).
//!
//! Contexts: OpenGL ES 3.x, desktop GL ≥ 3.3 core or compatibility profile (checked by
//! `SplatRenderer::new`: [`GlError::ContextVersion`]). GL faults are errors, never a panic
//! or a black image: compile/link logs, missing extensions, clouds beyond the texture
//! limits ([`GlError::Capacity`]; below them clouds larger than one texture are spread over
//! array-texture layers), `GL_OUT_OF_MEMORY` ([`GlError::Gl`]).

mod bound;
mod caps;
mod context;
pub(crate) mod data;
mod draw;
mod error;
pub mod frame;
mod stages;
// Fault injection for the GL tests: only with the `testing` feature (hidden); without it every
// lookup (`caps`) is the driver's answer and nothing thread-local is read on a production path.
#[cfg(feature = "testing")]
#[doc(hidden)]
pub mod fault;
mod glsl;
mod host_sort;
mod objects;
mod prepass;
mod program;
mod readback;
mod renderer;
mod scene;
mod settings;
mod sort;
pub mod state;
mod target;
mod uniforms;
mod view;

pub use caps::{can_blend_rgba32f, can_render_rgba16f};
pub use error::GlError;
pub(crate) use error::check_error;
// The review draft's errata as shader switches: for the erratum proof (feature `testing`).
#[cfg(feature = "testing")]
#[doc(hidden)]
pub use glsl::Errata;
#[cfg(all(not(feature = "testing"), not(target_arch = "wasm32")))]
pub(crate) use glsl::Errata;
pub use prepass::PREPASS_MIN_SPLATS;
// Test and benchmark hooks (feature `testing`): host programs for the state tests, the draw
// path, the state-call counts.
pub use data::PAGE_SPLATS;
#[cfg(feature = "testing")]
#[doc(hidden)]
pub use program::build_program;
pub use readback::{ColorFormat, DepthFormat, ReadbackTarget};
pub use renderer::SplatRenderer;
pub use scene::SplatScene;
pub use settings::{DepthFunc, DrawSettings, FrameSort};
#[cfg(feature = "testing")]
#[doc(hidden)]
pub use settings::{DrawPath, Pipeline};
#[allow(deprecated)]
pub use sort::{DistanceSorter, sort_back_to_front};
pub use stages::StageTimes;
#[cfg(feature = "testing")]
#[doc(hidden)]
pub use state::StateCalls;
pub use target::OffscreenTarget;
pub use view::{frustum_for_camera, frustum_for_matrices};
