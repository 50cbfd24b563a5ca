//! The draw calls of [`SplatRenderer`]: from a [`Camera`] or from a host's view and
//! projection matrices, both through one [`ViewParams`] and one per-draw setup
//! ([`SplatRenderer::draw_view`]: state, uniforms, the instanced draw).

use glam::Mat4;
use glow::HasContext;

use super::GlError;
use super::renderer::{DrawSettings, SplatRenderer};
use super::state::{self, DrawState};
use super::view::ViewParams;
use crate::camera::Camera;
use crate::cloud::ColorSpace;

impl SplatRenderer {
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
    /// viewport's, the camera is fitted to it: the same aspect ratio (e.g. a camera in logical
    /// pixels on a HiDPI surface) scales its intrinsics ([`Camera::resized`]); another aspect
    /// keeps its vertical field of view and square pixels (the horizontal field of view
    /// follows the viewport, centred), so nothing is squashed.
    pub fn draw_current(&self, gl: &glow::Context, camera: &Camera) -> Result<(), GlError> {
        self.draw_current_with(gl, camera, self.settings())
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
        let mut viewport = [0i32; 4];
        // SAFETY: a plain integer query into a 4-element array.
        unsafe { gl.get_parameter_i32_slice(glow::VIEWPORT, &mut viewport) };
        self.draw_view(gl, &ViewParams::from_camera(camera, viewport), settings)
    }

    /// Uploads `order` and draws with a host's own camera: `view` (world → GL eye space,
    /// looking down −z) and `projection` (eye → clip) as the host uses them for its own
    /// geometry, and `viewport` = the viewport the host has bound (`x, y, width, height`).
    ///
    /// Any perspective projection works — off-centre, reversed-Z, infinite far plane, `[0, 1]`
    /// depth range: focal lengths and tan(half fov) are derived from `projection` and
    /// `viewport`, and the depth test uses [`DrawSettings::depth_func`], so with the host's
    /// depth convention splats are occluded exactly by its depth buffer. An orthographic or
    /// skewed projection, or a non-invertible view, is refused with [`GlError::Matrix`].
    /// `draw(camera)` and `draw_with_matrices(camera.gl_view(), camera.gl_projection(), …)`
    /// give identical pixels.
    pub fn draw_with_matrices(
        &mut self,
        gl: &glow::Context,
        view: Mat4,
        projection: Mat4,
        viewport: [i32; 4],
        order: &[u32],
    ) -> Result<(), GlError> {
        self.set_order(gl, order)?;
        let settings = *self.settings();
        self.draw_current_with_matrices(gl, view, projection, viewport, &settings)
    }

    /// [`SplatRenderer::draw_with_matrices`] of the last uploaded order, with `settings` for
    /// this draw only.
    pub fn draw_current_with_matrices(
        &self,
        gl: &glow::Context,
        view: Mat4,
        projection: Mat4,
        viewport: [i32; 4],
        settings: &DrawSettings,
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let params = ViewParams::from_matrices(view, projection, viewport)?;
        self.draw_view(gl, &params, settings)
    }

    /// The one draw path: sets the state the draw needs ([`super::state`], restoring it in
    /// restore mode), the uniforms ([`SplatRenderer::set_uniforms`]) and draws.
    pub(super) fn draw_view(
        &self,
        gl: &glow::Context,
        view: &ViewParams,
        settings: &DrawSettings,
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let Some(tex) = &self.textures else {
            return Err(GlError::NotUploaded);
        };
        let space = settings.color_space.unwrap_or(self.color_space);
        let want = DrawState {
            program: self.program,
            vao: self.vao,
            textures: [tex.geometry, tex.sh],
            blend_src: if self.errata.g_src_alpha_blend {
                glow::SRC_ALPHA
            } else {
                glow::ONE
            },
            depth_test: settings.depth_test,
            depth_func: settings.depth_func.gl_enum(),
            srgb: space == ColorSpace::LinRec709Display,
        };
        let (saved, entered) = state::draw::enter(gl, self.ctx, &want, settings.restore_state);
        self.set_uniforms(gl, view, settings);
        if self.instances > 0 {
            // SAFETY: draws `instances` instances of the bound VAO, which `set_order` bounded
            // by the order buffer's size; the shader culls any index past the uploaded splats.
            unsafe { gl.draw_arrays_instanced(glow::TRIANGLE_STRIP, 0, 4, self.instances as i32) };
        }
        let left = state::draw::leave(gl, self.ctx, saved);
        self.state_calls.set(state::StateCalls {
            queries: entered.queries + left.queries,
            sets: entered.sets + left.sets,
        });
        Ok(())
    }

    /// Every uniform of one draw, in one place (the program is bound).
    fn set_uniforms(&self, gl: &glow::Context, view: &ViewParams, settings: &DrawSettings) {
        let u = &self.uniforms;
        let tex = self.textures.as_ref().expect("checked by draw_view");
        let degree = settings
            .sh_degree
            .unwrap_or(self.cloud_degree)
            .min(self.cloud_degree);
        let [vx, vy, vw, vh] = view.viewport.map(|v| v as f32);
        let m = &self.models;
        // SAFETY: sets uniforms of the bound splat program with values of the declared types;
        // the model arrays hold MAX_CLOUDS entries, as declared.
        unsafe {
            let mat = |l, m: &Mat4| gl.uniform_matrix_4_f32_slice(l, false, &m.to_cols_array());
            mat(u.u_view_matrix.as_ref(), &view.view);
            mat(u.u_projection_matrix.as_ref(), &view.projection);
            let (f, t, e) = (view.focal, view.tan_half_fov, view.eye);
            gl.uniform_2_f32(u.u_focal_length.as_ref(), f.x, f.y);
            gl.uniform_2_f32(u.u_tan_half_fov.as_ref(), t.x, t.y);
            gl.uniform_3_f32(u.u_camera_position.as_ref(), e.x, e.y, e.z);
            gl.uniform_4_f32(u.u_viewport.as_ref(), vx, vy, vw, vh);
            gl.uniform_1_f32(u.u_cull_depth.as_ref(), view.cull_depth);
            gl.uniform_1_i32(u.u_sh_degree.as_ref(), i32::from(degree));
            gl.uniform_1_i32(u.u_sh_texels.as_ref(), tex.sh_texels as i32);
            let fetch = crate::profile::sh_texels(degree);
            gl.uniform_1_i32(u.u_sh_fetch_texels.as_ref(), fetch as i32);
            gl.uniform_1_i32(u.u_splat_count.as_ref(), tex.len as i32);
            gl.uniform_1_i32(u.u_geometry.as_ref(), 0);
            gl.uniform_1_i32(u.u_sh.as_ref(), 1);
            gl.uniform_1_i32(u.u_model_count.as_ref(), m.count as i32);
            if m.count > 0 {
                let rows = bytemuck::cast_slice(&m.rows[..m.count]);
                gl.uniform_4_f32_slice(u.u_model_rows.as_ref(), rows);
                let sh = bytemuck::cast_slice(&m.sh_rotation[..m.count]);
                gl.uniform_matrix_3_f32_slice(u.u_sh_rotation.as_ref(), false, sh);
            }
        }
    }
}
