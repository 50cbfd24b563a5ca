//! [`OffscreenTarget`]: an `RGBA16F` accumulation target and its resolve pass.
//!
//! Blending into a float target avoids the per-blend 8-bit rounding of an `RGBA8` framebuffer
//! (RC: "float colour buffers recommended"), and lets `lin_rec709_display` clouds blend linear
//! values; the resolve pass then writes the result into the host's framebuffer, converting to
//! sRGB there if asked.
//!
//! The resolve **replaces** the pixels of the viewport it restores (blending off): clear the
//! target with the scene's background (`begin`), so the resolved image is final.

use glow::HasContext;

use super::GlError;
use super::program::{self, Errata, GlslVersion};

/// An `RGBA16F` colour target with a resolve pass into the previously bound framebuffer.
#[derive(Debug)]
pub struct OffscreenTarget {
    fbo: glow::Framebuffer,
    texture: glow::Texture,
    program: glow::Program,
    vao: glow::VertexArray,
    u_accum: Option<glow::UniformLocation>,
    u_origin: Option<glow::UniformLocation>,
    u_encode: Option<glow::UniformLocation>,
    width: u32,
    height: u32,
    saved_fbo: Option<glow::Framebuffer>,
    saved_viewport: [i32; 4],
}

impl OffscreenTarget {
    /// Creates a `width × height` target. On OpenGL ES it needs `EXT_color_buffer_float` or
    /// `EXT_color_buffer_half_float` (rendering to `RGBA16F`).
    pub fn new(gl: &glow::Context, width: u32, height: u32) -> Result<Self, GlError> {
        let version = GlslVersion::for_context(gl);
        if version == GlslVersion::Es300 {
            let ext = gl.supported_extensions();
            if !ext.contains("GL_EXT_color_buffer_float")
                && !ext.contains("GL_EXT_color_buffer_half_float")
            {
                return Err(GlError::Unsupported(
                    "rendering to RGBA16F needs EXT_color_buffer_(half_)float".into(),
                ));
            }
        }
        let vs = program::assemble(version, &Errata::default(), 11, program::RESOLVE_VERT);
        let fs = program::assemble(version, &Errata::default(), 11, program::RESOLVE_FRAG);
        let program = program::build_program(gl, "resolve", &vs, &fs)?;
        // SAFETY: creates and configures objects owned by the target; the framebuffer binding
        // is restored before returning.
        unsafe {
            super::clear_pending_errors(gl);
            // On a failed creation, delete what exists so far.
            let texture = match crate::gl::created(gl.create_texture(), "texture") {
                Ok(t) => t,
                Err(e) => {
                    gl.delete_program(program);
                    return Err(e);
                }
            };
            let fbo = match crate::gl::created(gl.create_framebuffer(), "framebuffer") {
                Ok(f) => f,
                Err(e) => {
                    gl.delete_texture(texture);
                    gl.delete_program(program);
                    return Err(e);
                }
            };
            let vao = match crate::gl::created(gl.create_vertex_array(), "vertex array") {
                Ok(v) => v,
                Err(e) => {
                    gl.delete_framebuffer(fbo);
                    gl.delete_texture(texture);
                    gl.delete_program(program);
                    return Err(e);
                }
            };
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            gl.tex_storage_2d(
                glow::TEXTURE_2D,
                1,
                glow::RGBA16F,
                width as i32,
                height as i32,
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MIN_FILTER,
                glow::NEAREST as i32,
            );
            gl.tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MAG_FILTER,
                glow::NEAREST as i32,
            );
            gl.bind_texture(glow::TEXTURE_2D, None);
            let prev = gl.get_parameter_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(fbo));
            gl.framebuffer_texture_2d(
                glow::DRAW_FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(texture),
                0,
            );
            let status = gl.check_framebuffer_status(glow::DRAW_FRAMEBUFFER);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, prev);
            let target = OffscreenTarget {
                fbo,
                texture,
                vao,
                u_accum: gl.get_uniform_location(program, "u_accum"),
                u_origin: gl.get_uniform_location(program, "u_origin"),
                u_encode: gl.get_uniform_location(program, "u_encode_srgb"),
                program,
                width,
                height,
                saved_fbo: None,
                saved_viewport: [0; 4],
            };
            if status != glow::FRAMEBUFFER_COMPLETE {
                target.destroy(gl);
                return Err(GlError::Framebuffer(status));
            }
            if let Err(e) = super::check_error(gl, "creating the RGBA16F target") {
                target.destroy(gl);
                return Err(e);
            }
            Ok(target)
        }
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Remembers the bound draw framebuffer and viewport, binds the target, sets the viewport to
    /// the whole target and clears it to `clear` (premultiplied; use `(background, 0)`). Leaves
    /// the clear colour set to `clear`.
    pub fn begin(&mut self, gl: &glow::Context, clear: [f32; 4]) {
        // SAFETY: state queries and binding the target's own framebuffer.
        unsafe {
            self.saved_fbo = gl.get_parameter_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING);
            gl.get_parameter_i32_slice(glow::VIEWPORT, &mut self.saved_viewport);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(self.fbo));
            gl.viewport(0, 0, self.width as i32, self.height as i32);
            gl.clear_color(clear[0], clear[1], clear[2], clear[3]);
            gl.clear(glow::COLOR_BUFFER_BIT);
        }
    }

    /// Rebinds the framebuffer and viewport saved by [`OffscreenTarget::begin`] and copies the
    /// target into it (replacing, blending and depth test disabled), encoding RGB with the sRGB
    /// transfer function when `encode_srgb` (for `lin_rec709_display`).
    pub fn resolve(&mut self, gl: &glow::Context, encode_srgb: bool) {
        let v = self.saved_viewport;
        // SAFETY: binds the saved framebuffer (or the default one) and the target's own
        // program/texture/VAO, draws one triangle, and unbinds them.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, self.saved_fbo.take());
            gl.viewport(v[0], v[1], v[2], v[3]);
            gl.disable(glow::BLEND);
            gl.disable(glow::DEPTH_TEST);
            gl.use_program(Some(self.program));
            gl.uniform_1_i32(self.u_accum.as_ref(), 0);
            gl.uniform_2_f32(self.u_origin.as_ref(), v[0] as f32, v[1] as f32);
            gl.uniform_1_i32(self.u_encode.as_ref(), i32::from(encode_srgb));
            gl.active_texture(glow::TEXTURE0);
            gl.bind_sampler(0, None);
            gl.bind_texture(glow::TEXTURE_2D, Some(self.texture));
            gl.bind_vertex_array(Some(self.vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.bind_vertex_array(None);
            gl.bind_texture(glow::TEXTURE_2D, None);
            gl.use_program(None);
        }
    }

    /// Deletes the target's objects.
    pub fn destroy(&self, gl: &glow::Context) {
        // SAFETY: deleting objects this target created.
        unsafe {
            gl.delete_framebuffer(self.fbo);
            gl.delete_texture(self.texture);
            gl.delete_vertex_array(self.vao);
            gl.delete_program(self.program);
        }
    }
}
