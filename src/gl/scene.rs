//! [`SplatScene`]: several clouds, each with its own model matrix, drawn in one globally
//! back-to-front order by one renderer (one program, one sorter).

use std::ops::Range;

use glam::{Mat4, Vec3, Vec4};

use super::renderer::SplatRenderer;
use super::settings::DrawSettings;
use super::{GlError, view::ViewParams};
use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::cull::{CullBounds, radius_scale};
use crate::sort::{SortRequest, Sorter};
use glow::HasContext;

/// Several clouds, each placed by a model matrix (its local → world transform, e.g. an
/// embedded object's pose that changes every frame), drawn in **one** back-to-front order, so
/// overlapping clouds blend correctly.
///
/// The clouds are uploaded once into one set of data textures, in their own (model) space.
/// The model matrices are applied in the vertex shader as the glTF loader applies node
/// transforms: world position `M p`, covariance `Σ = A R S Sᵀ Rᵀ Aᵀ` (A = M's 3×3, the
/// loader's `M C Cᵀ Mᵀ`), and SH evaluated at the model-space view direction `Rₚᵀ d`, where
/// Rₚ is the rotation of A's polar decomposition — exactly the loader's Wigner-D rotation of
/// the coefficients by Rₚ. For non-uniform scale or shear the covariance is still exact; the
/// SH see only Rₚ, as in the loader (and the RC leaves that case undefined). A singular A
/// leaves the SH unrotated, as the loader does. Changing a model costs nothing on the GPU
/// (uniforms).
///
/// The order: each draw sorts all splats the view may see ([`crate::cull`], tested on their
/// world positions and radii) together by the distance of their **world** positions to the
/// eye (one [`Sorter`](crate::sort::Sorter)). World positions are recomputed on the CPU
/// only for clouds whose model changed since the last draw: per-frame work proportional to
/// the splats of the moving clouds, on top of the sort itself.
///
/// All clouds must share one effective `colorSpace`; SH degrees may differ (lower ones are
/// zero-padded). At most [`SplatScene::MAX_CLOUDS`] clouds. The GL state each call touches is
/// the renderer's ([`super::state`]); `settings_mut().restore_state` applies to the scene's
/// draws too.
#[derive(Debug)]
pub struct SplatScene {
    renderer: SplatRenderer,
    ranges: Vec<Range<usize>>,
    models: Vec<Mat4>,
    /// Clouds whose world positions are stale.
    stale: Vec<bool>,
    local: Vec<[f32; 3]>,
    world: Vec<[f32; 3]>,
    /// Cull radii in model space, and in world space (scaled by each model's largest stretch).
    local_bounds: CullBounds,
    world_bounds: CullBounds,
    sorter: Sorter,
}

/// Tolerance of the affine check on model matrices (bottom row `0, 0, 0, 1`).
const AFFINE_TOL: f32 = 1e-6;

fn check_model(k: usize, m: &Mat4) -> Result<(), GlError> {
    let bottom = m.row(3) - Vec4::W;
    if !m.is_finite() || bottom.abs().max_element() > AFFINE_TOL {
        return Err(GlError::Matrix(format!(
            "model matrix of cloud {k} is not a finite affine transform: {m:?}"
        )));
    }
    Ok(())
}

impl SplatScene {
    /// The most clouds a scene holds (the shader's model uniform arrays).
    pub const MAX_CLOUDS: usize = 32;

    /// A scene with its renderer ([`SplatRenderer::new`]; no clouds yet).
    pub fn new(gl: &glow::Context) -> Result<Self, GlError> {
        Ok(SplatScene {
            renderer: SplatRenderer::new(gl)?,
            ranges: Vec::new(),
            models: Vec::new(),
            stale: Vec::new(),
            local: Vec::new(),
            world: Vec::new(),
            local_bounds: CullBounds::default(),
            world_bounds: CullBounds::default(),
            sorter: Sorter::new(),
        })
    }

    /// Uploads the clouds with their model matrices (replacing the previous ones; on failure
    /// they stay). Cloud `k` is entry `k` of [`SplatScene::set_model`].
    pub fn upload(
        &mut self,
        gl: &glow::Context,
        entries: &[(&SplatCloud, Mat4)],
    ) -> Result<(), GlError> {
        if entries.len() > Self::MAX_CLOUDS {
            return Err(GlError::Upload(format!(
                "{} clouds; a scene holds at most {}",
                entries.len(),
                Self::MAX_CLOUDS
            )));
        }
        if let Some((first, _)) = entries.first() {
            let space = first.meta.color_space.effective();
            if let Some(k) = entries
                .iter()
                .position(|(c, _)| c.meta.color_space.effective() != space)
            {
                return Err(GlError::Upload(format!(
                    "cloud {k} has colorSpace {} but cloud 0 has {}: one scene blends in one \
                     colour space",
                    entries[k].0.meta.color_space.effective().as_str(),
                    space.as_str()
                )));
            }
        }
        for (k, (_, m)) in entries.iter().enumerate() {
            check_model(k, m)?;
        }
        let clouds: Vec<&SplatCloud> = entries.iter().map(|(c, _)| *c).collect();
        self.renderer.upload_clouds(gl, &clouds)?;
        self.models = entries.iter().map(|(_, m)| *m).collect();
        self.renderer.set_models(&self.models);
        self.ranges.clear();
        self.local.clear();
        let mut radii = Vec::new();
        for c in &clouds {
            let start = self.local.len();
            self.local.extend_from_slice(&c.positions);
            self.ranges.push(start..self.local.len());
            radii.extend_from_slice(CullBounds::new(c).radii());
        }
        self.world.clone_from(&self.local);
        self.local_bounds = CullBounds::from_radii(radii);
        self.world_bounds = self.local_bounds.clone();
        self.world_bounds.set_extent(&self.world);
        self.stale = self.models.iter().map(|m| *m != Mat4::IDENTITY).collect();
        self.sorter = Sorter::new();
        Ok(())
    }

    /// Number of clouds.
    pub fn cloud_count(&self) -> usize {
        self.ranges.len()
    }

    /// Splats in all clouds.
    pub fn len(&self) -> usize {
        self.local.len()
    }

    /// Whether the scene has no splats.
    pub fn is_empty(&self) -> bool {
        self.local.is_empty()
    }

    /// The indices of cloud `k`'s splats in the scene's order (`None` past the last cloud).
    pub fn range(&self, k: usize) -> Option<Range<usize>> {
        self.ranges.get(k).cloned()
    }

    /// Cloud `k`'s model matrix.
    pub fn model(&self, k: usize) -> Option<Mat4> {
        self.models.get(k).copied()
    }

    /// Moves cloud `k` (takes effect at the next draw). Fails for a cloud that does not exist
    /// or a matrix that is not a finite affine transform.
    pub fn set_model(&mut self, k: usize, model: Mat4) -> Result<(), GlError> {
        check_model(k, &model)?;
        let Some(m) = self.models.get_mut(k) else {
            return Err(GlError::Upload(format!(
                "no cloud {k} (the scene has {})",
                self.ranges.len()
            )));
        };
        if *m != model {
            *m = model;
            self.stale[k] = true;
            self.renderer.set_models(&self.models);
        }
        Ok(())
    }

    /// The renderer's settings (used by every draw of the scene).
    pub fn settings_mut(&mut self) -> &mut DrawSettings {
        self.renderer.settings_mut()
    }

    /// The renderer's draw path (feature `testing`, see [`super::Pipeline`]).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn set_draw_path(
        &mut self,
        gl: &glow::Context,
        path: super::DrawPath,
    ) -> Result<(), GlError> {
        self.renderer.set_draw_path(gl, path)
    }

    /// The renderer (read-only: uploads go through [`SplatScene::upload`], so the order always
    /// indexes the clouds drawn).
    pub fn renderer(&self) -> &SplatRenderer {
        &self.renderer
    }

    /// The last draw's order (indices into the scene, back to front).
    pub fn order(&self) -> &[u32] {
        self.sorter.order()
    }

    /// Sorts the splats the view may see ([`crate::cull`], on their world positions and
    /// radii) by the distance of their world positions to the eye and uploads the order.
    fn sort(&mut self, gl: &glow::Context, view: &ViewParams) -> Result<(), GlError> {
        let mut moved = false;
        for (k, stale) in self.stale.iter_mut().enumerate() {
            if std::mem::take(stale) {
                let (r, m) = (self.ranges[k].clone(), self.models[k]);
                for (w, p) in self.world[r.clone()].iter_mut().zip(&self.local[r.clone()]) {
                    *w = m.transform_point3(Vec3::from_array(*p)).to_array();
                }
                let grow = radius_scale(m);
                let local = &self.local_bounds.radii()[r.clone()];
                for (w, l) in self.world_bounds.radii_mut()[r].iter_mut().zip(local) {
                    *w = l * grow;
                }
                moved = true;
            }
        }
        if moved {
            self.world_bounds.set_extent(&self.world);
        }
        let frustum = view.frustum();
        let request = SortRequest::distance(view.eye.to_array());
        let (world, bounds) = (&self.world, &self.world_bounds);
        let order = self.sorter.sort_visible(world, bounds, &frustum, &request);
        self.renderer.set_order(gl, order)
    }

    /// Sorts for `camera` and draws every cloud into the bound framebuffer and viewport (as
    /// [`SplatRenderer::draw`]).
    pub fn draw(&mut self, gl: &glow::Context, camera: &Camera) -> Result<(), GlError> {
        let mut viewport = [0i32; 4];
        // SAFETY: a plain integer query into a 4-element array.
        unsafe { gl.get_parameter_i32_slice(glow::VIEWPORT, &mut viewport) };
        let params = ViewParams::from_camera(camera, viewport);
        self.sort(gl, &params)?;
        let settings = *self.renderer.settings();
        self.renderer.draw_view(gl, &params, &settings)
    }

    /// Sorts for the host's camera and draws (as [`SplatRenderer::draw_with_matrices`]).
    pub fn draw_with_matrices(
        &mut self,
        gl: &glow::Context,
        view: Mat4,
        projection: Mat4,
        viewport: [i32; 4],
    ) -> Result<(), GlError> {
        let params = ViewParams::from_matrices(view, projection, viewport)?;
        self.sort(gl, &params)?;
        let settings = *self.renderer.settings();
        self.renderer.draw_view(gl, &params, &settings)
    }

    /// Deletes the renderer's GL objects ([`SplatRenderer::destroy`]).
    pub fn destroy(&mut self, gl: &glow::Context) {
        self.renderer.destroy(gl);
    }
}
