//! GL state the backend touches. The renderer never owns the context: the host keeps its
//! framebuffer, viewport and scissor, and the renderer leaves state as listed here.
//!
//! # [`SplatRenderer::draw`](super::SplatRenderer::draw) (and `draw_current`, `draw_current_with`)
//!
//! Reads: the bound draw framebuffer and `GL_VIEWPORT` (splats are drawn into the host's
//! viewport; a camera of another size is scaled to it with `Camera::resized`).
//!
//! | state | set to during the draw | left afterwards |
//! |---|---|---|
//! | `GL_CURRENT_PROGRAM` | the splat program | **0** |
//! | `GL_VERTEX_ARRAY_BINDING` | the renderer's VAO | **0** |
//! | `GL_ARRAY_BUFFER_BINDING` | the order buffer | **0** |
//! | `GL_ACTIVE_TEXTURE` | `TEXTURE0` / `TEXTURE1` | **`TEXTURE0`** |
//! | `TEXTURE_2D` binding, units 0 and 1 | geometry / SH textures | **0** on both units |
//! | sampler object binding, units 0 and 1 | none | **none** |
//! | `GL_BLEND` | enabled | **enabled** (left) |
//! | blend func | `ONE, ONE_MINUS_SRC_ALPHA` (both RGB and alpha) | **left** |
//! | blend equation | `FUNC_ADD` | **left** |
//! | `GL_DEPTH_TEST` | enabled iff [`DrawSettings::depth_test`](super::DrawSettings) | **left** |
//! | `glDepthMask` | `false` (splats never write depth) | **`false`** (left) |
//! | `glDepthFunc` | `LESS` when depth testing | **left** |
//! | `GL_CULL_FACE` | disabled | **disabled** (left) |
//! | `GL_SCISSOR_TEST`, stencil, colour mask | not touched | unchanged |
//!
//! `tests/gl_embedding.rs::host_depth_buffer_viewport_and_gl_state_are_respected` checks the
//! "left afterwards" column.
//!
//! A host that needs other values back (e.g. `glDepthMask(true)` for its next pass) sets them
//! after the call; querying and restoring everything would cost a round-trip per state per frame.
//!
//! # [`SplatRenderer::upload`](super::SplatRenderer::upload)
//!
//! Changes the `TEXTURE_2D` binding of the active texture unit (left 0),
//! `GL_PIXEL_UNPACK_BUFFER` binding (left 0), `GL_UNPACK_ALIGNMENT` (left 4, the default),
//! `GL_UNPACK_ROW_LENGTH`, `GL_UNPACK_SKIP_ROWS`, `GL_UNPACK_SKIP_PIXELS` (left 0, the
//! defaults), and the `GL_ARRAY_BUFFER` binding (left 0).
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
