//! [`SplatRenderer::draw_frame`]: the renderer culls and sorts for its host. It keeps what the
//! order needs from the uploaded cloud (positions, cull radii, the staleness tolerance) and
//! one sorter, so a frame allocates nothing once the sorter's scratch is warm.

use std::sync::Arc;

use glam::Mat4;

use super::GlError;
use super::renderer::SplatRenderer;
use super::settings::FrameSort;
use super::view::ViewParams;
use crate::cloud::SplatCloud;
use crate::cull::CullBounds;
use crate::sort::{Freshness, SortRequest, Sorter, StaleBound, StaleOrders};

/// The cloud's positions and cull radii, and the sorters of both [`FrameSort`] modes.
#[derive(Debug)]
pub(super) struct HostSort {
    positions: Arc<[[f32; 3]]>,
    bounds: CullBounds,
    sorter: Sorter,
    /// [`StaleBound::Auto`]'s tolerance for this cloud.
    auto_tolerance: f32,
    /// The background sorter and the bound it was made for (made on the first async frame).
    background: Option<(StaleBound, StaleOrders)>,
    /// What the last frame drew.
    last: Option<Freshness>,
    /// The background order in the order buffer (its generation), and the last frame's eye.
    uploaded: Option<u64>,
    prev_eye: Option<glam::Vec3>,
}

impl HostSort {
    /// What `draw_frame` needs of `cloud` (12 + 4 bytes per splat).
    pub(super) fn new(cloud: &SplatCloud) -> Self {
        HostSort {
            positions: cloud.positions.as_slice().into(),
            bounds: CullBounds::new(cloud),
            sorter: Sorter::new(),
            auto_tolerance: StaleBound::Auto.tolerance(cloud),
            background: None,
            last: None,
            uploaded: None,
            prev_eye: None,
        }
    }

    fn tolerance(&self, bound: StaleBound) -> f32 {
        match bound {
            StaleBound::Auto => self.auto_tolerance,
            StaleBound::Strict => 0.0,
            StaleBound::Distance(d) => d.max(0.0),
        }
    }
}

impl SplatRenderer {
    /// Draws the uploaded cloud for the host's camera, sorting for it: derives the eye from
    /// `view`, culls to the frustum of `view`, `projection` and `viewport`, sorts back to
    /// front by camera distance (`sortingMethod: cameraDistance`), uploads the order and draws
    /// it into the bound framebuffer, as [`SplatRenderer::draw_with_matrices`] does with an
    /// order of its own. `view` is world → GL eye space (looking down −z), `projection` any
    /// perspective projection (off-centre, reversed-Z, infinite far, `[0, 1]` depth),
    /// `viewport` the host's bound viewport (`x, y, width, height`).
    ///
    /// [`DrawSettings::sort`](super::DrawSettings::sort) chooses where the sort runs
    /// ([`FrameSort`]). Nothing is allocated per frame once the first frame has warmed the
    /// sorter (the background mode starts its thread on its first frame).
    ///
    /// The five-line host is in the [module docs](super).
    ///
    /// Errors: [`GlError::NotUploaded`] before [`SplatRenderer::upload`] (and after an upload
    /// through [`SplatScene`](super::SplatScene), which sorts its own clouds),
    /// [`GlError::Viewport`] for a viewport without pixels, [`GlError::Matrix`] for
    /// non-finite or non-perspective matrices, and whatever the draw reports.
    pub fn draw_frame(
        &mut self,
        gl: &glow::Context,
        view: Mat4,
        projection: Mat4,
        viewport: [i32; 4],
    ) -> Result<(), GlError> {
        self.owned.check()?;
        if viewport[2] <= 0 || viewport[3] <= 0 {
            return Err(GlError::Viewport(viewport));
        }
        let params = ViewParams::from_matrices(view, projection, viewport)?;
        let Some(mut host) = self.host_sort.take() else {
            return Err(GlError::NotUploaded);
        };
        let result = self.sort_and_upload(gl, &mut host, &params);
        self.host_sort = Some(host);
        result?;
        let settings = *self.settings();
        self.draw_view(gl, &params, &settings)
    }

    /// How the last [`SplatRenderer::draw_frame`] got its order: `Exact` for a synchronous
    /// sort; in the background mode also `Stale` or `Waited` ([`Freshness`]).
    pub fn last_frame_order(&self) -> Option<Freshness> {
        self.host_sort.as_ref().and_then(|h| h.last)
    }

    /// Sorts the uploaded cloud back to front for `camera` drawn into a viewport of its own
    /// size — only the splats its frustum may see when `cull` (the same image) — and uploads
    /// the order: what the headless renderer draws (and the web build's exact renders). Uses
    /// the positions and cull radii kept by [`SplatRenderer::upload`].
    ///
    /// Errors: [`GlError::NotUploaded`] before an upload, and whatever uploading the order
    /// reports.
    pub fn sort_for_camera(
        &mut self,
        gl: &glow::Context,
        camera: &crate::camera::Camera,
        cull: bool,
    ) -> Result<(), GlError> {
        let Some(mut host) = self.host_sort.take() else {
            return Err(GlError::NotUploaded);
        };
        let eye = camera.eye().to_array();
        let order = if cull && camera.width > 0 && camera.height > 0 {
            let viewport = [0, 0, camera.width as i32, camera.height as i32];
            let frustum = super::frustum_for_camera(camera, viewport);
            let request = SortRequest::distance(eye);
            host.sorter
                .sort_visible(&host.positions, &host.bounds, &frustum, &request)
        } else {
            host.sorter.sort_by_distance(&host.positions, eye)
        };
        let result = self.set_order(gl, order);
        self.host_sort = Some(host);
        result
    }

    fn sort_and_upload(
        &mut self,
        gl: &glow::Context,
        host: &mut HostSort,
        params: &ViewParams,
    ) -> Result<(), GlError> {
        let eye = params.eye;
        match self.settings().sort {
            FrameSort::Sync => {
                let request = SortRequest::distance(eye.to_array());
                let frustum = params.frustum();
                let order =
                    host.sorter
                        .sort_visible(&host.positions, &host.bounds, &frustum, &request);
                host.last = Some(Freshness::Exact);
                self.set_order(gl, order)
            }
            FrameSort::Async(bound) => {
                if host.background.as_ref().map(|(b, _)| *b) != Some(bound) {
                    let tau = host.tolerance(bound);
                    let orders = StaleOrders::new(host.positions.clone(), tau, false)
                        .map_err(|e| GlError::Unsupported(format!("sorter thread: {e}")))?;
                    host.background = Some((bound, orders));
                    host.uploaded = None;
                }
                let (_, orders) = host.background.as_mut().expect("made above");
                let Some((frame, fresh)) = orders.for_frame(eye) else {
                    return Err(GlError::Unsupported("the sorter thread stopped".into()));
                };
                host.last = Some(fresh);
                if host.uploaded != Some(frame.generation()) {
                    self.set_order(gl, frame.order())?;
                    host.uploaded = Some(frame.generation());
                }
                // Sort ahead for where the eye will be next frame (linear prediction), so the
                // sort overlaps the draw and the next frame finds a close order.
                let next = host.prev_eye.map_or(eye, |p| eye + (eye - p));
                orders.request(next);
                host.prev_eye = Some(eye);
                Ok(())
            }
        }
    }
}
