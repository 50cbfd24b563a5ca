//! The draw calls of [`SplatRenderer`]: from a [`Camera`] or from a host's view and
//! projection matrices, both through one [`ViewParams`] and one per-draw setup
//! ([`SplatRenderer::draw_view`]: state, uniforms, the instanced draw).

use glam::Mat4;
use glow::HasContext;

use super::GlError;
use super::prepass::PREPASS_MIN_SPLATS;
use super::renderer::SplatRenderer;
use super::settings::{DrawSettings, Pipeline};
use super::stages::Stage;
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
        let prepass = self.prepass.as_ref().filter(|p| {
            let n = self.instances;
            n <= p.capacity()
                && match self.path.pipeline {
                    Pipeline::Direct => false,
                    Pipeline::PrePass => true,
                    Pipeline::Auto => n >= PREPASS_MIN_SPLATS,
                }
        });
        let (program, vao) = match prepass {
            Some(p) => (p.quad, p.quad_vao),
            None => (self.program, self.vao),
        };
        let want = DrawState {
            program,
            vao,
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
        if let Some(q) = &self.stages {
            q.reset();
        }
        match prepass {
            Some(p) if self.instances > 0 => {
                // Per-splat maths once per splat into the records, then the quads read them,
                // in batches of QUADS_PER_INSTANCE.
                let n = self.instances;
                p.bind(gl);
                self.set_uniforms(gl, &p.prep_uniforms, view, settings);
                self.timed(gl, Stage::PrePass, || p.capture(gl, n));
                self.timed(gl, Stage::Copy, || p.copy_records(gl, n));
                p.bind_quads(gl, n, view.viewport);
                self.timed(gl, Stage::Quads, || p.draw_quads(gl, n));
            }
            Some(_) => {}
            None => {
                self.set_uniforms(gl, &self.uniforms, view, settings);
                if self.instances > 0 {
                    let n = self.instances as i32;
                    // SAFETY: draws `instances` instances of the direct VAO, which reads the
                    // order buffer that `set_order` bounded by its size (the shader culls any
                    // index past the uploaded splats).
                    self.timed(gl, Stage::Quads, || unsafe {
                        gl.draw_arrays_instanced(glow::TRIANGLE_STRIP, 0, 4, n)
                    });
                }
            }
        }
        self.used_prepass
            .set(prepass.is_some() && self.instances > 0);
        let left = state::draw::leave(gl, self.ctx, saved);
        self.state_calls.set(state::StateCalls {
            queries: entered.queries + left.queries,
            sets: entered.sets + left.sets,
        });
        Ok(())
    }

    /// Runs `f` inside the timer query of `stage` when stage timing is on.
    fn timed<T>(&self, gl: &glow::Context, stage: Stage, f: impl FnOnce() -> T) -> T {
        match &self.stages {
            Some(q) => q.time(gl, stage, f),
            None => f(),
        }
    }
}
