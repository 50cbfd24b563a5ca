//! What a draw is asked to do: [`DrawSettings`] (SH degree, depth test and function, restore
//! mode, colour space) and the hidden draw-path switch ([`DrawPath`], [`Pipeline`]) the tests
//! and benches use to compare paths.

use crate::cloud::ColorSpace;
use crate::sort::StaleBound;

/// The depth comparison of [`DrawSettings::depth_func`] (the host's convention: `Less` /
/// `LessEqual` for a standard depth buffer cleared to 1, `Greater` / `GreaterEqual` for a
/// reversed-Z one cleared to 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DepthFunc {
    /// `GL_LESS` (the default).
    #[default]
    Less,
    /// `GL_LEQUAL`.
    LessEqual,
    /// `GL_GREATER`.
    Greater,
    /// `GL_GEQUAL`.
    GreaterEqual,
}

impl DepthFunc {
    /// The GL enum.
    pub fn gl_enum(self) -> u32 {
        match self {
            DepthFunc::Less => glow::LESS,
            DepthFunc::LessEqual => glow::LEQUAL,
            DepthFunc::Greater => glow::GREATER,
            DepthFunc::GreaterEqual => glow::GEQUAL,
        }
    }
}

/// Per-draw settings: the renderer's own ([`SplatRenderer::settings_mut`](super::SplatRenderer::settings_mut), used by
/// [`SplatRenderer::draw`](super::SplatRenderer::draw) and [`SplatRenderer::set_order`](super::SplatRenderer::set_order)) or given for one draw
/// ([`SplatRenderer::draw_current_with`](super::SplatRenderer::draw_current_with)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrawSettings {
    /// SH degree to evaluate (clamped to the cloud's degree); `None` = the cloud's degree.
    pub sh_degree: Option<u8>,
    /// Test against the bound depth buffer with [`DrawSettings::depth_func`], never writing
    /// depth, so splats hide behind the host's opaque geometry. On by default (embedding);
    /// without a depth attachment the test always passes. The headless renderer turns it off.
    pub depth_test: bool,
    /// The depth comparison (the host's convention; `Less` by default).
    pub depth_func: DepthFunc,
    /// Put back every piece of GL state the call changes (`true`, recommended for legacy
    /// hosts), or leave the documented values (`false`, the default: no state queries). See
    /// [`super::state`].
    pub restore_state: bool,
    /// The colour space to draw as (`None` = the uploaded cloud's): decides
    /// `GL_FRAMEBUFFER_SRGB` where it can be switched (see [`SplatRenderer`](super::SplatRenderer)).
    pub color_space: Option<ColorSpace>,
    /// The antialiased kernel (scenes trained with Mip-Splatting's 2D filter or gsplat's
    /// `antialiased` mode; SPZ header flag 0x1): each splat's opacity is scaled by
    /// `sqrt(det Σ' / det(Σ' + 0.3 I))`, so the dilation keeps its integral instead of growing
    /// it. Off by default (the plain 3DGS kernel); `docs/rendering-profile.md` § Antialiased
    /// kernel.
    pub antialiased: bool,
    /// How [`SplatRenderer::draw_frame`](super::SplatRenderer::draw_frame) sorts: on the
    /// calling thread (the default) or on a background thread with bounded staleness.
    pub sort: FrameSort,
}

/// Where [`SplatRenderer::draw_frame`](super::SplatRenderer::draw_frame) sorts the splats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrameSort {
    /// Every frame culls to its view and sorts on the calling thread before it draws (rayon's
    /// pool does the sort): the exact back-to-front order of this frame's eye.
    #[default]
    Sync,
    /// A background thread (an [`AsyncSorter`](crate::sort::AsyncSorter) the renderer owns)
    /// sorts every splat for the newest eye; a frame draws the newest finished order while the
    /// eye moved no more than the bound allows since it was sorted, else it waits for the sort
    /// of its own eye (the viewer's rule, `docs/viewer.md`). No culling in this mode: an order
    /// sorted for an older view must still cover the new one.
    Async(StaleBound),
}

impl Default for DrawSettings {
    fn default() -> Self {
        DrawSettings {
            sh_degree: None,
            depth_test: true,
            depth_func: DepthFunc::Less,
            restore_state: false,
            color_space: None,
            antialiased: false,
            sort: FrameSort::Sync,
        }
    }
}

/// Which way the renderer computes the per-splat maths. **For the benchmarks and the tests
/// that compare the paths** (feature `testing`): every path draws the same image.
#[cfg_attr(not(feature = "testing"), allow(dead_code))] // only tests choose a path
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Pipeline {
    /// The pre-pass from [`PREPASS_MIN_SPLATS`](super::PREPASS_MIN_SPLATS) splats drawn on, else direct (the default).
    #[default]
    Auto,
    /// Every quad corner runs the per-splat maths (the path before the pre-pass).
    Direct,
    /// Always the transform-feedback pre-pass (where the context has transform-feedback
    /// objects and no erratum is switched in; else direct).
    PrePass,
}

/// The renderer's draw path (feature `testing`, see [`Pipeline`]). The former quads the
/// benchmarks compare against are a program of their own (`Errata::FORMER_QUADS`), so the
/// production shaders carry no trace of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DrawPath {
    /// Direct, pre-pass, or chosen by the splat count.
    pub pipeline: Pipeline,
}
