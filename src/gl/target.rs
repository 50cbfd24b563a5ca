//! [`OffscreenTarget`]: an `RGBA16F` accumulation target and its resolve pass.
//!
//! Blending into a float target avoids the per-blend 8-bit rounding of an `RGBA8` framebuffer
//! (RC: "float colour buffers recommended"), and lets `lin_rec709_display` clouds blend linear
//! values; the resolve pass then writes the result into the host's framebuffer, converting to
//! sRGB there if asked.
//!
//! The resolve **replaces** the pixels of the viewport it restores (blending off): clear the
//! target with the scene's background (`begin`), so the resolved image is final.

use crate::gl::bound::Bound;
use glow::HasContext;

use super::GlError;
use super::context::ContextInfo;
use super::data::TextureLayout;
use super::glsl::{self, Errata, GlslVersion};
use super::objects::{Creating, Owned};
use super::program;
use super::readback::{ColorFormat, ReadbackTarget};

/// An `RGBA16F` colour target with a resolve pass into the previously bound framebuffer.
///
/// Owns GL objects but not the context: call [`OffscreenTarget::destroy`] before dropping it.
#[derive(Debug)]
pub struct OffscreenTarget {
    target: ReadbackTarget,
    pass: ResolvePass,
    saved_fbo: Option<glow::Framebuffer>,
    saved_viewport: [i32; 4],
}

/// The resolve program, its (attribute-less) vertex array and its uniforms.
#[derive(Debug)]
struct ResolvePass {
    program: glow::Program,
    vao: glow::VertexArray,
    u_accum: Option<glow::UniformLocation>,
    u_origin: Option<glow::UniformLocation>,
    u_encode: Option<glow::UniformLocation>,
    owned: Owned,
}

impl ResolvePass {
    fn new(gl: &glow::Context) -> Result<Self, GlError> {
        let version = GlslVersion::for_context(ContextInfo::check(gl)?);
        let layout = TextureLayout::for_context(gl);
        let vs = glsl::assemble(version, &Errata::default(), &layout, glsl::RESOLVE_VERT);
        let fs = glsl::assemble(version, &Errata::default(), &layout, glsl::RESOLVE_FRAG);
        let mut objects = Creating::new(gl);
        let program = program::build_program_in(&mut objects, "resolve", &vs, &fs)?;
        let vao = objects.vertex_array()?;
        let names = ["u_accum", "u_origin", "u_encode_srgb"];
        let [u_accum, u_origin, u_encode] =
            program::uniform_locations(gl, program, "resolve", names, true);
        Ok(ResolvePass {
            program,
            vao,
            u_accum,
            u_origin,
            u_encode,
            owned: objects.keep("OffscreenTarget"),
        })
    }
}

impl OffscreenTarget {
    /// Creates a `width × height` `RGBA16F` target. On OpenGL ES it needs
    /// `EXT_color_buffer_float` or `EXT_color_buffer_half_float` (rendering to `RGBA16F`).
    pub fn new(gl: &glow::Context, width: u32, height: u32) -> Result<Self, GlError> {
        Self::with_format(gl, width, height, ColorFormat::Rgba16f)
    }

    /// [`OffscreenTarget::new`] blending in `format`: `Rgba32f` needs, on OpenGL ES,
    /// `EXT_color_buffer_float` and `EXT_float_blend` ([`super::can_blend_rgba32f`]). Single
    /// floats are the cheaper float where blending is done in software: SwiftShader (the
    /// browser's WebGL2 without a GPU) blends half floats 1.7× slower than bytes and single
    /// floats as fast as bytes (`docs/performance.md`); they also round less (llvmpipe, biker
    /// at 1280×720 against the CPU reference: 76.0 dB, max 1/255, where `RGBA16F` gives
    /// 64.1 dB, max 3/255).
    pub fn with_format(
        gl: &glow::Context,
        width: u32,
        height: u32,
        format: ColorFormat,
    ) -> Result<Self, GlError> {
        let mut target = ReadbackTarget::new(gl, width, height, format, None)?;
        match ResolvePass::new(gl) {
            Ok(pass) => Ok(OffscreenTarget {
                target,
                pass,
                saved_fbo: None,
                saved_viewport: [0; 4],
            }),
            Err(e) => {
                target.destroy(gl);
                Err(e)
            }
        }
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        self.target.size()
    }

    /// Remembers the bound draw framebuffer and viewport, binds the target, sets the viewport to
    /// the whole target and clears it to `clear` (premultiplied; use `(background, 0)`). Leaves
    /// the clear colour set to `clear`.
    pub fn begin(&mut self, gl: &glow::Context, clear: [f32; 4]) -> Result<(), GlError> {
        // SAFETY: a state query.
        let bound = unsafe { gl.bound_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING) };
        self.begin_into(gl, clear, bound)
    }

    /// [`OffscreenTarget::begin`] with the framebuffer to resolve into given (`None`: the
    /// default one) instead of queried: on the web, where bindings cannot be queried
    /// ([`Bound`]), the frame knows it.
    pub(crate) fn begin_into(
        &mut self,
        gl: &glow::Context,
        clear: [f32; 4],
        into: Option<glow::Framebuffer>,
    ) -> Result<(), GlError> {
        self.pass.owned.check()?;
        let (w, h) = self.target.size();
        // SAFETY: a state query and binding the target's own framebuffer.
        unsafe {
            self.saved_fbo = into;
            gl.get_parameter_i32_slice(glow::VIEWPORT, &mut self.saved_viewport);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(self.target.framebuffer()));
            gl.viewport(0, 0, w as i32, h as i32);
            gl.clear_color(clear[0], clear[1], clear[2], clear[3]);
            gl.clear(glow::COLOR_BUFFER_BIT);
        }
        Ok(())
    }

    /// Rebinds the framebuffer and viewport saved by [`OffscreenTarget::begin`] and copies the
    /// target into it (replacing, blending and depth test disabled), encoding RGB with the sRGB
    /// transfer function when `encode_srgb` (for `lin_rec709_display`).
    pub fn resolve(&mut self, gl: &glow::Context, encode_srgb: bool) -> Result<(), GlError> {
        self.pass.owned.check()?;
        let v = self.saved_viewport;
        // SAFETY: binds the saved framebuffer (or the default one) and the target's own
        // program/texture/VAO, draws one triangle, and unbinds them.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, self.saved_fbo.take());
            gl.viewport(v[0], v[1], v[2], v[3]);
            gl.disable(glow::BLEND);
            gl.disable(glow::DEPTH_TEST);
            gl.use_program(Some(self.pass.program));
            gl.uniform_1_i32(self.pass.u_accum.as_ref(), 0);
            gl.uniform_2_f32(self.pass.u_origin.as_ref(), v[0] as f32, v[1] as f32);
            gl.uniform_1_i32(self.pass.u_encode.as_ref(), i32::from(encode_srgb));
            gl.active_texture(glow::TEXTURE0);
            gl.bind_sampler(0, None);
            gl.bind_texture(glow::TEXTURE_2D, Some(self.target.color_texture()));
            gl.bind_vertex_array(Some(self.pass.vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.bind_vertex_array(None);
            gl.bind_texture(glow::TEXTURE_2D, None);
            gl.use_program(None);
        }
        Ok(())
    }

    /// Deletes the target's objects (once; afterwards every method returns
    /// [`GlError::Destroyed`]).
    pub fn destroy(&mut self, gl: &glow::Context) {
        self.pass.owned.destroy(gl);
        self.target.destroy(gl);
    }

    /// Forgets the objects without GL calls (their context is already gone).
    pub(crate) fn abandon(&mut self) {
        self.pass.owned.abandon();
        self.target.abandon();
    }
}
