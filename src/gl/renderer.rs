//! [`SplatRenderer`]: draws an uploaded cloud into the host's framebuffer.

use glam::Mat4;
use glow::HasContext;

use super::GlError;
use super::data::SplatTextures;
use super::glsl::{self, Errata, GlslVersion};
use super::objects::{Creating, Owned};
use super::program;
use crate::camera::Camera;
use crate::cloud::{ColorSpace, SplatCloud};

/// Per-draw settings: the renderer's own ([`SplatRenderer::settings_mut`], used by
/// [`SplatRenderer::draw`]) or given for one draw ([`SplatRenderer::draw_current_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrawSettings {
    /// SH degree to evaluate (clamped to the cloud's degree); `None` = the cloud's degree.
    pub sh_degree: Option<u8>,
    /// Test against the bound depth buffer (`LESS`, never writing depth), so splats hide behind
    /// the host's opaque geometry. On by default (embedding); without a depth attachment the
    /// test always passes. The headless renderer turns it off.
    pub depth_test: bool,
}

impl Default for DrawSettings {
    fn default() -> Self {
        DrawSettings {
            sh_degree: None,
            depth_test: true,
        }
    }
}

/// Declares `Uniforms`, one location per uniform the renderer sets, each field named exactly
/// like its GLSL uniform (so the two cannot get out of step).
macro_rules! uniforms {
    ($($name:ident),* $(,)?) => {
        /// The locations of the uniforms the renderer sets.
        #[derive(Debug)]
        struct Uniforms {
            $($name: Option<glow::UniformLocation>,)*
        }

        impl Uniforms {
            /// Looks them up; for the correct program (`check`), a debug build asserts that
            /// they all exist.
            fn new(gl: &glow::Context, program: glow::Program, check: bool) -> Self {
                let names = [$(stringify!($name)),*];
                let [$($name),*] = program::uniform_locations(gl, program, "splat", names, check);
                Uniforms { $($name),* }
            }
        }
    };
}

uniforms! {
    u_geometry, u_sh, u_sh_texels, u_sh_fetch_texels, u_sh_degree, u_view_matrix,
    u_projection_matrix, u_focal_length, u_tan_half_fov, u_camera_position, u_viewport,
    u_cull_depth, u_splat_count,
}

/// The splat renderer. It borrows the host's GL context in every call and never owns it; see
/// [`super::state`] for the GL state each call changes. All methods must be called with the
/// same context current.
///
/// Per frame only the order is uploaded (`glBufferSubData`, 4 bytes per splat) and nothing is
/// allocated on the host.
///
/// # Colour spaces
///
/// The shader writes the reconstructed colours as they are (premultiplied). For
/// `srgb_rec709_display` clouds that is final. For `lin_rec709_display` clouds
/// ([`SplatRenderer::color_space`]) blending must happen on linear values and the result be
/// sRGB-encoded once at the end: draw into an `SRGB8_ALPHA8` framebuffer (ES always converts;
/// desktop GL needs `GL_FRAMEBUFFER_SRGB`), or into an [`super::OffscreenTarget`] resolved with
/// `encode_srgb = true`.
///
/// # Lifetime
///
/// It owns GL objects but not the context: call [`SplatRenderer::destroy`] with the context
/// current before dropping it (dropping a live renderer leaks its objects and warns once).
/// After `destroy` every method returns [`GlError::Destroyed`].
#[derive(Debug)]
pub struct SplatRenderer {
    program: glow::Program,
    uniforms: Uniforms,
    vao: glow::VertexArray,
    order_buffer: glow::Buffer,
    order_capacity: usize,
    instances: usize,
    textures: Option<SplatTextures>,
    cloud_degree: u8,
    color_space: ColorSpace,
    settings: DrawSettings,
    errata: Errata,
    tex_width_log2: u32,
    owned: Owned,
}

impl SplatRenderer {
    /// Compiles the splat program for the context's GLSL flavour and creates the (empty) order
    /// buffer and vertex array.
    pub fn new(gl: &glow::Context) -> Result<Self, GlError> {
        Self::with_errata(gl, Errata::default())
    }

    /// Like [`SplatRenderer::new`], with some of the review draft's Appendix A errata switched
    /// back in. **Erratum tests only** (hidden from the documented API).
    #[doc(hidden)]
    pub fn with_errata(gl: &glow::Context, errata: Errata) -> Result<Self, GlError> {
        let version = GlslVersion::for_context(gl);
        // SAFETY: a plain integer query.
        let max_texture_size = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE) };
        let tex_width_log2 = super::data::tex_width_log2(max_texture_size);
        let vs = glsl::assemble(version, &errata, tex_width_log2, glsl::SPLAT_VERT);
        let fs = glsl::assemble(version, &errata, tex_width_log2, glsl::SPLAT_FRAG);
        let mut objects = Creating::new(gl);
        let program = program::build_program_in(&mut objects, "splat", &vs, &fs)?;
        // Erratum variants may compile some uniforms away: only the correct program is checked.
        let uniforms = Uniforms::new(gl, program, errata == Errata::default());
        let vao = objects.vertex_array()?;
        let order_buffer = objects.buffer()?;
        // SAFETY: configures the VAO and buffer created just above; both bindings are left 0.
        unsafe {
            // The only vertex attribute: the sorted splat index, one u32 per instance.
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(order_buffer));
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_i32(0, 1, glow::UNSIGNED_INT, 4, 0);
            gl.vertex_attrib_divisor(0, 1);
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        Ok(SplatRenderer {
            program,
            uniforms,
            vao,
            order_buffer,
            order_capacity: 0,
            instances: 0,
            textures: None,
            cloud_degree: 0,
            color_space: ColorSpace::default(),
            settings: DrawSettings::default(),
            errata,
            tex_width_log2,
            owned: objects.keep("SplatRenderer"),
        })
    }

    /// Uploads a cloud's data into textures (once per cloud; replaces any previous cloud) and
    /// sizes the order buffer for `cloud.len()` indices.
    pub fn upload(&mut self, gl: &glow::Context, cloud: &SplatCloud) -> Result<(), GlError> {
        self.owned.check()?;
        let mut textures = SplatTextures::upload(gl, cloud, self.tex_width_log2)?;
        // The order buffer first: on failure the previous cloud stays complete and usable.
        // SAFETY: (re)allocates the renderer's own order buffer.
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.order_buffer));
            gl.buffer_data_size(
                glow::ARRAY_BUFFER,
                (cloud.len().max(1) * 4) as i32,
                glow::DYNAMIC_DRAW,
            );
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        if let Err(e) = super::check_error(gl, "allocating the order buffer") {
            textures.destroy(gl);
            self.instances = 0; // the buffer's old contents are gone
            return Err(e);
        }
        if let Some(mut old) = self.textures.replace(textures) {
            old.destroy(gl);
        }
        self.cloud_degree = cloud.sh_degree;
        self.color_space = cloud.meta.color_space.effective();
        self.instances = 0;
        self.order_capacity = cloud.len();
        Ok(())
    }

    /// The linked splat program (for inspection, e.g. its active attributes; erratum tests).
    #[doc(hidden)]
    pub fn program(&self) -> glow::Program {
        self.program
    }

    /// Number of splats uploaded.
    pub fn len(&self) -> usize {
        self.textures.as_ref().map_or(0, |t| t.len)
    }

    /// Whether no splats are uploaded.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The uploaded cloud's `colorSpace` (unknown values fall back to the default,
    /// `srgb_rec709_display`).
    pub fn color_space(&self) -> ColorSpace {
        self.color_space
    }

    /// SH degree of the uploaded cloud.
    pub fn cloud_sh_degree(&self) -> u8 {
        self.cloud_degree
    }

    /// The current draw settings.
    pub fn settings(&self) -> &DrawSettings {
        &self.settings
    }

    /// Mutable draw settings (take effect at the next draw).
    pub fn settings_mut(&mut self) -> &mut DrawSettings {
        &mut self.settings
    }

    /// Uploads a draw order (`glBufferSubData`, 4 bytes per index): splat indices back to front,
    /// each `< len()`. May be shorter than the cloud (culled or partial draws).
    pub fn set_order(&mut self, gl: &glow::Context, order: &[u32]) -> Result<(), GlError> {
        self.owned.check()?;
        if self.textures.is_none() {
            return Err(GlError::NotUploaded);
        }
        if order.len() > self.order_capacity {
            return Err(GlError::OrderTooLong {
                got: order.len(),
                capacity: self.order_capacity,
            });
        }
        // SAFETY: writes `order.len() * 4` bytes into the order buffer, which holds
        // `order_capacity * 4 >= order.len() * 4` bytes.
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.order_buffer));
            gl.buffer_sub_data_u8_slice(glow::ARRAY_BUFFER, 0, bytemuck::cast_slice(order));
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
        }
        self.instances = order.len();
        Ok(())
    }

    /// Uploads `order` ([`SplatRenderer::set_order`]) and draws ([`SplatRenderer::draw_current`]).
    pub fn draw(
        &mut self,
        gl: &glow::Context,
        camera: &Camera,
        order: &[u32],
    ) -> Result<(), GlError> {
        self.set_order(gl, order)?;
        self.draw_current(gl, camera)
    }

    /// Draws the splats of the last uploaded order into the bound framebuffer and viewport with
    /// the renderer's [`DrawSettings`], blending premultiplied colour with
    /// `ONE, ONE_MINUS_SRC_ALPHA`. When the camera's `width`/`height` differ from the
    /// viewport's (e.g. a camera in logical pixels on a HiDPI surface), its intrinsics are
    /// scaled to the viewport ([`Camera::resized`]).
    pub fn draw_current(&self, gl: &glow::Context, camera: &Camera) -> Result<(), GlError> {
        self.draw_current_with(gl, camera, &self.settings)
    }

    /// [`SplatRenderer::draw_current`] with `settings` for this draw only (the renderer's own
    /// settings are neither used nor changed).
    pub fn draw_current_with(
        &self,
        gl: &glow::Context,
        camera: &Camera,
        settings: &DrawSettings,
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let Some(tex) = &self.textures else {
            return Err(GlError::NotUploaded);
        };
        let u = &self.uniforms;
        let degree = settings
            .sh_degree
            .unwrap_or(self.cloud_degree)
            .min(self.cloud_degree);
        let mut viewport = [0i32; 4];
        // SAFETY: a plain integer query into a 4-element array.
        unsafe { gl.get_parameter_i32_slice(glow::VIEWPORT, &mut viewport) };
        let (vw, vh) = (viewport[2].max(0) as u32, viewport[3].max(0) as u32);
        let scaled;
        let camera = if (camera.width, camera.height) != (vw, vh) && vw > 0 && vh > 0 {
            scaled = camera.resized(vw, vh);
            &scaled
        } else {
            camera
        };
        let view: Mat4 = camera.gl_view();
        let proj: Mat4 = camera.gl_projection();
        let eye = camera.eye();
        let tan = camera.tan_half_fov();
        // SAFETY: binds objects this renderer owns, sets uniforms of its own program with values
        // of the declared types, and draws `instances` instances, which `set_order` bounded by
        // the order buffer's size; the shader culls any index past the uploaded splats.
        unsafe {
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(u.u_view_matrix.as_ref(), false, &view.to_cols_array());
            gl.uniform_matrix_4_f32_slice(
                u.u_projection_matrix.as_ref(),
                false,
                &proj.to_cols_array(),
            );
            gl.uniform_2_f32(u.u_focal_length.as_ref(), camera.fx, camera.fy);
            gl.uniform_2_f32(u.u_tan_half_fov.as_ref(), tan.x, tan.y);
            gl.uniform_3_f32(u.u_camera_position.as_ref(), eye.x, eye.y, eye.z);
            gl.uniform_4_f32(
                u.u_viewport.as_ref(),
                viewport[0] as f32,
                viewport[1] as f32,
                viewport[2] as f32,
                viewport[3] as f32,
            );
            let cull = (crate::profile::NEAR_CULL as f32).max(camera.near);
            gl.uniform_1_f32(u.u_cull_depth.as_ref(), cull);
            gl.uniform_1_i32(u.u_sh_degree.as_ref(), i32::from(degree));
            gl.uniform_1_i32(u.u_sh_texels.as_ref(), tex.sh_texels as i32);
            let fetch = crate::profile::sh_texels(degree);
            gl.uniform_1_i32(u.u_sh_fetch_texels.as_ref(), fetch as i32);
            gl.uniform_1_i32(u.u_splat_count.as_ref(), tex.len as i32);
            gl.uniform_1_i32(u.u_geometry.as_ref(), 0);
            gl.uniform_1_i32(u.u_sh.as_ref(), 1);
            // A host sampler object on these units would override the textures' NEAREST
            // filtering (RGBA32F is not filterable on ES 3.0): unbind samplers.
            gl.bind_sampler(0, None);
            gl.bind_sampler(1, None);
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, Some(tex.geometry));
            gl.active_texture(glow::TEXTURE1);
            gl.bind_texture(glow::TEXTURE_2D, Some(tex.sh));

            gl.enable(glow::BLEND);
            gl.blend_equation(glow::FUNC_ADD);
            if self.errata.g_src_alpha_blend {
                gl.blend_func(glow::SRC_ALPHA, glow::ONE_MINUS_SRC_ALPHA);
            } else {
                gl.blend_func(glow::ONE, glow::ONE_MINUS_SRC_ALPHA);
            }
            gl.disable(glow::CULL_FACE);
            gl.depth_mask(false);
            if settings.depth_test {
                gl.enable(glow::DEPTH_TEST);
                gl.depth_func(glow::LESS);
            } else {
                gl.disable(glow::DEPTH_TEST);
            }

            gl.bind_vertex_array(Some(self.vao));
            if self.instances > 0 {
                gl.draw_arrays_instanced(glow::TRIANGLE_STRIP, 0, 4, self.instances as i32);
            }

            gl.bind_vertex_array(None);
            gl.bind_texture(glow::TEXTURE_2D, None);
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, None);
            gl.use_program(None);
        }
        Ok(())
    }

    /// Deletes every GL object the renderer created (once; afterwards every method returns
    /// [`GlError::Destroyed`]). Call it with the renderer's context current.
    pub fn destroy(&mut self, gl: &glow::Context) {
        if let Some(mut t) = self.textures.take() {
            t.destroy(gl);
        }
        self.owned.destroy(gl);
        self.order_capacity = 0;
        self.instances = 0;
    }

    /// Forgets the objects without GL calls (their context is already gone).
    pub(crate) fn abandon(&mut self) {
        if let Some(mut t) = self.textures.take() {
            t.abandon();
        }
        self.owned.abandon();
    }
}
