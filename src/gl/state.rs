//! GL state the backend touches, in two modes (also in `docs/embedding.md`). The renderer never
//! owns the context: it draws into the host's bound draw framebuffer and viewport.
//!
//! # The two modes ([`DrawSettings::restore_state`](super::DrawSettings::restore_state))
//!
//! * **`restore_state: true`** (recommended for legacy hosts): `set_order` and every draw query
//!   each piece of state they change (tables below) first, change only what differs from what
//!   they need, and put back exactly what they changed. The host's state after the call is the
//!   state before it, bit for bit.
//! * **`restore_state: false`** (the default, for hosts that set their own state before each of
//!   their passes): no queries; the pieces are set unconditionally and left as listed in
//!   [Left afterwards](#left-afterwards-with-restore_state-false) ([`LEFT_WITHOUT_RESTORE`]).
//!
//! In both modes `SplatRenderer::new`, `upload`, `allocate_pages`, `write_page`, `destroy`
//! (and `SplatScene`'s) leave every
//! piece of state as they found it: they run once, so their queries cost nothing per frame.
//!
//! # Set for every draw (never inherited)
//!
//! | state | set to |
//! |---|---|
//! | `GL_CURRENT_PROGRAM`, `GL_VERTEX_ARRAY_BINDING` | the splat program and the renderer's VAO |
//! | `GL_ACTIVE_TEXTURE`; `GL_TEXTURE_BINDING_2D_ARRAY` and the sampler binding of units 0 and 1 | the geometry and SH textures, no sampler object |
//! | `GL_BLEND`, blend func (separate), blend equation (separate) | enabled; `ONE, ONE_MINUS_SRC_ALPHA` for RGB and alpha; `FUNC_ADD` for both |
//! | `GL_DEPTH_TEST`, `GL_DEPTH_FUNC` | as [`DrawSettings::depth_test`](super::DrawSettings::depth_test) and `depth_func` |
//! | `GL_DEPTH_WRITEMASK` | `false` (splats never write depth) |
//! | `GL_CULL_FACE`, `GL_RASTERIZER_DISCARD`, `GL_POLYGON_OFFSET_FILL`, `GL_SAMPLE_ALPHA_TO_COVERAGE`, `GL_SAMPLE_COVERAGE` | disabled |
//! | `GL_COLOR_WRITEMASK` | all four channels on |
//! | `GL_POLYGON_MODE` (desktop) | `FILL` |
//! | `GL_COLOR_LOGIC_OP` (desktop) | disabled |
//! | `GL_FRAMEBUFFER_SRGB` (desktop; ES with `GL_EXT_sRGB_write_control`) | enabled iff the colour space drawn is `lin_rec709_display` (blending on linear values, encoded by an sRGB framebuffer) |
//! | `GL_ALPHA_TEST` (compatibility profile) | disabled |
//! | `GL_TRANSFORM_FEEDBACK_BINDING` (where transform-feedback objects exist: ES 3.x, desktop ≥ 4.0 or `GL_ARB_transform_feedback2`) | 0 |
//! | `GL_PIXEL_UNPACK_BUFFER_BINDING` | 0 |
//! | `GL_UNPACK_ROW_LENGTH`, `GL_UNPACK_SKIP_ROWS`, `GL_UNPACK_SKIP_PIXELS`, `GL_UNPACK_SKIP_IMAGES`; `GL_UNPACK_SWAP_BYTES` (desktop) | 0 (false) |
//!
//! `set_order` binds the order buffer as `GL_ARRAY_BUFFER` to write it.
//!
//! **The pre-pass** (large clouds, `docs/gl-backend.md`): between setting that state and the
//! quad draw, the draw binds its own pre-pass program and vertex array, its own
//! transform-feedback object (whose buffer binding was made at creation: the generic
//! `GL_TRANSFORM_FEEDBACK_BUFFER` binding is never touched by a draw), enables
//! `GL_RASTERIZER_DISCARD` for one `GL_POINTS` draw inside `glBegin/EndTransformFeedback`,
//! and sets all three back to the values above before the quad draw. It then copies the
//! records into its records texture (binding the records buffer as `GL_PIXEL_UNPACK_BUFFER`
//! for the copy and 0 again after it, with the unpack parameters above) and binds that texture
//! on unit 0, in place of the geometry texture, for the quad draw. So the state left (or
//! restored) is the same whichever path drew. The host must not have transform feedback
//! active during a draw (it would capture the splats' quads on any path).
//!
//! # Inherited on purpose
//!
//! The bound draw framebuffer and its draw buffers; the viewport (read: splats are drawn into
//! it) and depth range (so splat depths compare with the host's); the scissor test and box and
//! the whole stencil state (so a host can clip splats to a rectangle or mask them); dithering.
//! The clip-control origin must be the default lower-left one. Per-draw-buffer (indexed)
//! blend state is set and restored through the non-indexed calls, i.e. from draw buffer 0.
//!
//! # Left afterwards with `restore_state: false`
//!
//! Every piece above not listed here is left as set for the draw. "all" means every context;
//! per-unit rows are units 0 and 1.
//!
//! | state | contexts | left afterwards |
//! |---|---|---|
//! | `GL_CURRENT_PROGRAM` | all | 0 |
//! | `GL_VERTEX_ARRAY_BINDING` | all | 0 |
//! | `GL_ARRAY_BUFFER_BINDING` | all | 0 |
//! | `GL_ACTIVE_TEXTURE` | all | `GL_TEXTURE0` |
//! | `GL_TEXTURE_BINDING_2D_ARRAY`, unit 0 | all | 0 |
//! | `GL_TEXTURE_BINDING_2D_ARRAY`, unit 1 | all | 0 |
//! | `GL_SAMPLER_BINDING`, unit 0 | all | 0 |
//! | `GL_SAMPLER_BINDING`, unit 1 | all | 0 |
//! | `GL_BLEND` | all | enabled |
//! | `GL_BLEND_SRC_RGB` | all | `GL_ONE` |
//! | `GL_BLEND_SRC_ALPHA` | all | `GL_ONE` |
//! | `GL_BLEND_DST_RGB` | all | `GL_ONE_MINUS_SRC_ALPHA` |
//! | `GL_BLEND_DST_ALPHA` | all | `GL_ONE_MINUS_SRC_ALPHA` |
//! | `GL_BLEND_EQUATION_RGB` | all | `GL_FUNC_ADD` |
//! | `GL_BLEND_EQUATION_ALPHA` | all | `GL_FUNC_ADD` |
//! | `GL_DEPTH_TEST` | all | enabled iff `depth_test` |
//! | `GL_DEPTH_FUNC` | all | `depth_func` if `depth_test`, else unchanged |
//! | `GL_DEPTH_WRITEMASK` | all | false |
//! | `GL_CULL_FACE` | all | disabled |
//! | `GL_RASTERIZER_DISCARD` | all | disabled |
//! | `GL_POLYGON_OFFSET_FILL` | all | disabled |
//! | `GL_SAMPLE_ALPHA_TO_COVERAGE` | all | disabled |
//! | `GL_SAMPLE_COVERAGE` | all | disabled |
//! | `GL_COLOR_WRITEMASK` | all | true, true, true, true |
//! | `GL_POLYGON_MODE` | desktop | `GL_FILL` |
//! | `GL_COLOR_LOGIC_OP` | desktop | disabled |
//! | `GL_FRAMEBUFFER_SRGB` | sRGB switch | enabled iff `lin_rec709_display` |
//! | `GL_ALPHA_TEST` | compatibility | disabled |
//! | `GL_TRANSFORM_FEEDBACK_BINDING` | TF objects | 0 |
//! | `GL_PIXEL_UNPACK_BUFFER_BINDING` | all | 0 |
//! | `GL_UNPACK_ROW_LENGTH` | all | 0 |
//! | `GL_UNPACK_SKIP_ROWS` | all | 0 |
//! | `GL_UNPACK_SKIP_PIXELS` | all | 0 |
//! | `GL_UNPACK_SKIP_IMAGES` | all | 0 |
//! | `GL_UNPACK_SWAP_BYTES` | desktop | false |
//!
//! ("sRGB switch": desktop GL, or ES with `GL_EXT_sRGB_write_control`; "TF objects": ES 3.x,
//! desktop GL ≥ 4.0 or `GL_ARB_transform_feedback2`.) `tests/it/gl_embedding.rs`
//! sets over 60 pieces of host state in ES, core and compatibility contexts and checks, in
//! both modes, that every one reads back as this module says; a unit test checks that this
//! table and [`LEFT_WITHOUT_RESTORE`] agree.
//!
//! # Errors
//!
//! No call swallows a GL error the host left pending. Draws and `set_order` never call
//! `glGetError`. `upload` (and [`ReadbackTarget`](super::ReadbackTarget)'s `new` and
//! `read_image`) drain the host's pending codes before checking their own calls and raise
//! them again afterwards, so the host's next `glGetError` returns its own error. The codes
//! raised again are `GL_INVALID_ENUM`, `GL_INVALID_VALUE` and `GL_INVALID_OPERATION` (each
//! with an invalid query that changes nothing; a host with `KHR_debug` output sees it as a
//! message); any other pending code (`GL_OUT_OF_MEMORY`, …) is returned as
//! [`GlError::HostError`](super::GlError::HostError) and the upload is not attempted.
//!
//! # [`SplatRenderer::upload`](super::SplatRenderer::upload)
//!
//! Changes, and puts back: the `GL_TEXTURE_BINDING_2D_ARRAY` of the active unit, the
//! `GL_ARRAY_BUFFER` and `GL_PIXEL_UNPACK_BUFFER` bindings, `GL_UNPACK_ALIGNMENT`,
//! `GL_UNPACK_ROW_LENGTH`, `GL_UNPACK_IMAGE_HEIGHT`, `GL_UNPACK_SKIP_ROWS`,
//! `GL_UNPACK_SKIP_PIXELS`, `GL_UNPACK_SKIP_IMAGES` and on desktop GL `GL_UNPACK_SWAP_BYTES`
//! and `GL_UNPACK_LSB_FIRST` (set to tight client-memory rows for the upload, whatever the
//! host left). `allocate_pages` and `write_page` (paged storage) change and put back the
//! same. `new` changes and puts back the `GL_VERTEX_ARRAY_BINDING` and
//! `GL_ARRAY_BUFFER` bindings. `destroy` deletes only the renderer's own objects, none of which
//! is bound afterwards in either mode.
//!
//! # [`OffscreenTarget`](super::OffscreenTarget)
//!
//! `begin` binds the target's framebuffer (the previous draw framebuffer binding is remembered),
//! sets the viewport to the target's size, sets the clear colour (left set) and clears it;
//! `resolve` binds the remembered
//! framebuffer again and restores the viewport it found at `begin`, then draws one triangle with
//! blending **disabled** and depth testing **disabled** (both left so) and leaves program 0,
//! VAO 0, texture unit 0 bound to 0.
//!
//! # [`ReadbackTarget`](super::ReadbackTarget)
//!
//! Creation (`new`) leaves the `TEXTURE_2D` binding of the active unit and the
//! `RENDERBUFFER` binding at 0 and restores the draw framebuffer binding. `bind` binds the
//! target as `GL_FRAMEBUFFER` (draw and read) and sets the viewport to its size (both left so).
//! `read_image` binds `GL_READ_FRAMEBUFFER` and restores the binding it found, and leaves
//! `GL_PIXEL_PACK_BUFFER` 0, `GL_PACK_ALIGNMENT` 4, `GL_PACK_ROW_LENGTH`, `GL_PACK_SKIP_ROWS`
//! and `GL_PACK_SKIP_PIXELS` 0 (the defaults).

pub(crate) mod draw;
mod upload;

pub(crate) use draw::DrawState;
pub use draw::StateCalls;
pub(crate) use upload::Bindings;

/// The contexts a piece of state exists in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Contexts {
    /// Every context (ES 3.x, desktop core, desktop compatibility).
    All,
    /// Desktop GL, core and compatibility.
    Desktop,
    /// Desktop GL compatibility profile.
    Compatibility,
    /// Where `GL_FRAMEBUFFER_SRGB` can be switched: desktop GL, or ES with
    /// `GL_EXT_sRGB_write_control`.
    SrgbSwitch,
    /// Where transform-feedback objects exist: ES 3.x, desktop GL ≥ 4.0 or
    /// `GL_ARB_transform_feedback2`.
    TransformFeedbackObjects,
}

/// The value a piece of state is left at by a draw or `set_order` with `restore_state: false`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LeftValue {
    /// 0: no object bound, or the integer 0.
    Zero,
    /// An enum value (e.g. `GL_TEXTURE0`, `GL_ONE`), with its name.
    Enum(u32, &'static str),
    /// Capability enabled (`true`) or disabled.
    Enabled(bool),
    /// A boolean (`GL_DEPTH_WRITEMASK`).
    Bool(bool),
    /// All four channels of `GL_COLOR_WRITEMASK` on.
    AllChannels,
    /// Enabled iff [`DrawSettings::depth_test`](super::DrawSettings::depth_test).
    DepthTestSetting,
    /// [`DrawSettings::depth_func`](super::DrawSettings::depth_func) when depth testing,
    /// else unchanged.
    DepthFuncSetting,
    /// Enabled iff the colour space drawn is `lin_rec709_display`.
    LinearColorSpace,
}

/// One row of [the table](#left-afterwards-with-restore_state-false).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Left {
    /// The state's GL name, as in `glGet*` (e.g. `"GL_CURRENT_PROGRAM"`).
    pub name: &'static str,
    /// The enum to query it with (`glGet*`, or `glIsEnabled` for capabilities).
    pub pname: u32,
    /// The texture unit, for per-unit state.
    pub unit: Option<u32>,
    /// Where the piece exists.
    pub contexts: Contexts,
    /// The value left.
    pub value: LeftValue,
}

const fn left(name: &'static str, pname: u32, contexts: Contexts, value: LeftValue) -> Left {
    Left {
        name,
        pname,
        unit: None,
        contexts,
        value,
    }
}

const fn on_unit(mut l: Left, unit: u32) -> Left {
    l.unit = Some(unit);
    l
}

use Contexts::{All, Compatibility, Desktop, SrgbSwitch, TransformFeedbackObjects};
use LeftValue::{AllChannels, Bool, DepthFuncSetting, DepthTestSetting, Enabled, Enum, Zero};

const ONE: LeftValue = Enum(glow::ONE, "GL_ONE");
const ONE_MINUS_SRC_ALPHA: LeftValue = Enum(glow::ONE_MINUS_SRC_ALPHA, "GL_ONE_MINUS_SRC_ALPHA");
const FUNC_ADD: LeftValue = Enum(glow::FUNC_ADD, "GL_FUNC_ADD");
const TEX_2D_ARRAY: Left = left(
    "GL_TEXTURE_BINDING_2D_ARRAY",
    glow::TEXTURE_BINDING_2D_ARRAY,
    All,
    Zero,
);
const SAMPLER: Left = left("GL_SAMPLER_BINDING", glow::SAMPLER_BINDING, All, Zero);

/// What a draw or `set_order` with `restore_state: false` leaves (the table above, in code).
pub const LEFT_WITHOUT_RESTORE: &[Left] = &[
    left("GL_CURRENT_PROGRAM", glow::CURRENT_PROGRAM, All, Zero),
    left(
        "GL_VERTEX_ARRAY_BINDING",
        glow::VERTEX_ARRAY_BINDING,
        All,
        Zero,
    ),
    left(
        "GL_ARRAY_BUFFER_BINDING",
        glow::ARRAY_BUFFER_BINDING,
        All,
        Zero,
    ),
    left(
        "GL_ACTIVE_TEXTURE",
        glow::ACTIVE_TEXTURE,
        All,
        Enum(glow::TEXTURE0, "GL_TEXTURE0"),
    ),
    on_unit(TEX_2D_ARRAY, 0),
    on_unit(TEX_2D_ARRAY, 1),
    on_unit(SAMPLER, 0),
    on_unit(SAMPLER, 1),
    left("GL_BLEND", glow::BLEND, All, Enabled(true)),
    left("GL_BLEND_SRC_RGB", glow::BLEND_SRC_RGB, All, ONE),
    left("GL_BLEND_SRC_ALPHA", glow::BLEND_SRC_ALPHA, All, ONE),
    left(
        "GL_BLEND_DST_RGB",
        glow::BLEND_DST_RGB,
        All,
        ONE_MINUS_SRC_ALPHA,
    ),
    left(
        "GL_BLEND_DST_ALPHA",
        glow::BLEND_DST_ALPHA,
        All,
        ONE_MINUS_SRC_ALPHA,
    ),
    left(
        "GL_BLEND_EQUATION_RGB",
        glow::BLEND_EQUATION_RGB,
        All,
        FUNC_ADD,
    ),
    left(
        "GL_BLEND_EQUATION_ALPHA",
        glow::BLEND_EQUATION_ALPHA,
        All,
        FUNC_ADD,
    ),
    left("GL_DEPTH_TEST", glow::DEPTH_TEST, All, DepthTestSetting),
    left("GL_DEPTH_FUNC", glow::DEPTH_FUNC, All, DepthFuncSetting),
    left(
        "GL_DEPTH_WRITEMASK",
        glow::DEPTH_WRITEMASK,
        All,
        Bool(false),
    ),
    left("GL_CULL_FACE", glow::CULL_FACE, All, Enabled(false)),
    left(
        "GL_RASTERIZER_DISCARD",
        glow::RASTERIZER_DISCARD,
        All,
        Enabled(false),
    ),
    left(
        "GL_POLYGON_OFFSET_FILL",
        glow::POLYGON_OFFSET_FILL,
        All,
        Enabled(false),
    ),
    left(
        "GL_SAMPLE_ALPHA_TO_COVERAGE",
        glow::SAMPLE_ALPHA_TO_COVERAGE,
        All,
        Enabled(false),
    ),
    left(
        "GL_SAMPLE_COVERAGE",
        glow::SAMPLE_COVERAGE,
        All,
        Enabled(false),
    ),
    left(
        "GL_COLOR_WRITEMASK",
        glow::COLOR_WRITEMASK,
        All,
        AllChannels,
    ),
    left(
        "GL_POLYGON_MODE",
        glow::POLYGON_MODE,
        Desktop,
        Enum(glow::FILL, "GL_FILL"),
    ),
    left(
        "GL_COLOR_LOGIC_OP",
        glow::COLOR_LOGIC_OP,
        Desktop,
        Enabled(false),
    ),
    left(
        "GL_FRAMEBUFFER_SRGB",
        glow::FRAMEBUFFER_SRGB,
        SrgbSwitch,
        LeftValue::LinearColorSpace,
    ),
    left("GL_ALPHA_TEST", ALPHA_TEST, Compatibility, Enabled(false)),
    left(
        "GL_TRANSFORM_FEEDBACK_BINDING",
        glow::TRANSFORM_FEEDBACK_BINDING,
        TransformFeedbackObjects,
        Zero,
    ),
    left(
        "GL_PIXEL_UNPACK_BUFFER_BINDING",
        glow::PIXEL_UNPACK_BUFFER_BINDING,
        All,
        Zero,
    ),
    left("GL_UNPACK_ROW_LENGTH", glow::UNPACK_ROW_LENGTH, All, Zero),
    left("GL_UNPACK_SKIP_ROWS", glow::UNPACK_SKIP_ROWS, All, Zero),
    left("GL_UNPACK_SKIP_PIXELS", glow::UNPACK_SKIP_PIXELS, All, Zero),
    left("GL_UNPACK_SKIP_IMAGES", glow::UNPACK_SKIP_IMAGES, All, Zero),
    left(
        "GL_UNPACK_SWAP_BYTES",
        glow::UNPACK_SWAP_BYTES,
        Desktop,
        Bool(false),
    ),
];

/// `GL_ALPHA_TEST` (compatibility profile only; not in `glow`'s core enums).
pub(crate) const ALPHA_TEST: u32 = 0x0BC0;

impl Left {
    #[cfg(test)]
    /// The row of the documented table.
    fn row(&self) -> String {
        let unit = self.unit.map_or(String::new(), |u| format!(", unit {u}"));
        let contexts = match self.contexts {
            All => "all",
            Desktop => "desktop",
            Compatibility => "compatibility",
            SrgbSwitch => "sRGB switch",
            TransformFeedbackObjects => "TF objects",
        };
        let value = match self.value {
            Zero => "0".to_owned(),
            Enum(_, name) => format!("`{name}`"),
            Enabled(true) => "enabled".to_owned(),
            Enabled(false) => "disabled".to_owned(),
            Bool(b) => b.to_string(),
            AllChannels => "true, true, true, true".to_owned(),
            DepthTestSetting => "enabled iff `depth_test`".to_owned(),
            DepthFuncSetting => "`depth_func` if `depth_test`, else unchanged".to_owned(),
            LeftValue::LinearColorSpace => "enabled iff `lin_rec709_display`".to_owned(),
        };
        format!("| `{}`{unit} | {contexts} | {value} |", self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn documented_table_is_the_list_in_code() {
        let src = include_str!("state.rs");
        let table: Vec<&str> = src
            .lines()
            .skip_while(|l| !l.starts_with("//! # Left afterwards"))
            .map(|l| l.trim_start_matches("//! "))
            .skip_while(|l| !l.starts_with("|---"))
            .skip(1)
            .take_while(|l| l.starts_with('|'))
            .collect();
        let rows: Vec<String> = LEFT_WITHOUT_RESTORE.iter().map(Left::row).collect();
        assert_eq!(table, rows);
    }
}
