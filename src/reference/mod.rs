//! The CPU reference rasterizer: the normative math of `KHR_gaussian_splatting` (RC) written
//! directly from the spec text and the original 3DGS forward pass, independent of the shaders.
//!
//! Pipeline (see `docs/rendering-profile.md` for every choice the spec leaves open):
//! 1. `ViewContext::project` per splat, in parallel: cull at view z ≤
//!    [`RenderOptions::cull_depth`], Σ = R S² Rᵀ (global), Σ' = J W Σ Wᵀ Jᵀ with the
//!    ±1.3·tan(half fov) clamp inside J, + 0.3 px² on the diagonal, colour from SH of degree
//!    min(cloud, requested) along normalize(mean − eye), the 3σ bounding box.
//! 2. the order, [`crate::sort::Sorter::sort_for_camera`]: camera distance (default) or view depth, stable, ties by index.
//! 3. binning into 16×16 tiles, then rasterizing per tile row in parallel:
//!    at each pixel centre (x + 0.5, y + 0.5), m² = dᵀ Σ'⁻¹ d, skip m² > 9,
//!    α = min(0.99, opacity · exp(−½ m²)), skip α < 1/255, and in f32
//!    `C ← c·α + C·(1 − α)`, `A ← α + A·(1 − α)`, starting from (background, 0).
//!
//! [`render`] returns the blended values as they are (scene-referred for
//! `lin_rec709_display`); [`render_display`] returns what a display shows, the image the GL
//! backend and `splatgl render` produce. The constants are [`crate::profile`]'s.

mod project;
mod raster;
mod sort;

// The switches of how the reference gets to its image (the same image by every one): for
// the tests and benchmarks that show it (feature `testing`).
#[cfg(not(feature = "testing"))]
use project::Path;
#[cfg(feature = "testing")]
#[doc(hidden)]
pub use project::{Path, PixelBox};
use project::{Projected, ViewContext};
pub use sort::SortMode;
#[allow(deprecated)]
pub use sort::{back_to_front, sort_key};

/// Most (splat, tile) bin entries held at once (4 bytes each): 64 MiB.
pub const MAX_BIN_ENTRIES: u64 = 16 << 20;

use crate::camera::Camera;
use crate::cloud::{ColorSpace, SplatCloud};
use crate::cull::{CullBounds, Frustum};
use crate::image::Image;
use crate::profile::{srgb_decode, srgb_encode};
use crate::sort::{SortRequest, Sorter};
use rayon::prelude::*;

/// Options of a reference render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Highest SH degree to evaluate; the cloud's degree caps it.
    pub sh_degree: u8,
    /// Background RGB (alpha of the background is 0).
    pub background: [f32; 3],
    /// Blending order.
    pub sort: SortMode,
    /// Splats with view z ≤ max(`near_cull`, camera.near, 0) are culled (3DGS: 0.2).
    pub near_cull: f32,
    /// The antialiased kernel: each splat's opacity × √(det Σ' / det(Σ' + 0.3 I)) (scenes
    /// trained with Mip-Splatting's 2D filter or gsplat's `antialiased` mode; the GL
    /// backend's [`DrawSettings::antialiased`](crate::gl::DrawSettings::antialiased)). Off by
    /// default.
    pub antialiased: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            sh_degree: 3,
            background: [0.0; 3],
            sort: SortMode::Distance,
            near_cull: crate::profile::NEAR_CULL as f32,
            antialiased: false,
        }
    }
}

impl RenderOptions {
    /// The depth at or below which splats are culled for `camera`:
    /// `max(near_cull, camera.near, 0)` — never behind the eye, where a pinhole projection
    /// flips (and `NaN` settings fall back to 0).
    pub fn cull_depth(&self, camera: &Camera) -> f32 {
        self.near_cull.max(camera.near).max(0.0)
    }
}

/// What a render did (for the CLI's progress line and for tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RenderStats {
    /// Splats in the cloud.
    pub splats: usize,
    /// Splats that survived culling and touch the image.
    pub visible: usize,
    /// Splat–tile pairs rasterized.
    pub tile_entries: usize,
}

/// Renders `cloud` as seen by `camera`.
pub fn render(cloud: &SplatCloud, camera: &Camera, opts: &RenderOptions) -> Image {
    render_with_stats(cloud, camera, opts).0
}

/// [`render`], also returning [`RenderStats`].
pub fn render_with_stats(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &RenderOptions,
) -> (Image, RenderStats) {
    render_by(cloud, camera, opts, Path::default())
}

/// [`render_with_stats`] by a given `Path` (the image does not depend on it; feature
/// `testing`).
#[cfg(feature = "testing")]
#[doc(hidden)]
pub fn render_with_path(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &RenderOptions,
    path: Path,
) -> (Image, RenderStats) {
    render_by(cloud, camera, opts, path)
}

fn render_by(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &RenderOptions,
    path: Path,
) -> (Image, RenderStats) {
    let [r, g, b] = opts.background;
    let mut image = Image::filled(camera.width, camera.height, [r, g, b, 0.0]);
    if camera.width == 0 || camera.height == 0 {
        let stats = RenderStats {
            splats: cloud.len(),
            ..Default::default()
        };
        return (image, stats);
    }
    let degree = opts.sh_degree.min(cloud.sh_degree);
    let cull_depth = opts.cull_depth(camera);
    let ctx = ViewContext::new(camera, cull_depth as f64, degree, path.extent)
        .with_antialiased(opts.antialiased);
    let splats: Vec<Projected> = if path.cull {
        // The same visible set and order the GL backend draws (`docs/rendering-profile.md`).
        let frustum = Frustum::from_camera(camera, cull_depth);
        let bounds = CullBounds::new(cloud);
        let request = SortRequest::for_camera(camera, opts.sort);
        let mut sorter = Sorter::new();
        let order = sorter.sort_visible(&cloud.positions, &bounds, &frustum, &request);
        order
            .par_iter()
            .filter_map(|&i| ctx.project(cloud, i as usize))
            .collect()
    } else {
        let projected: Vec<Option<Projected>> = (0..cloud.len())
            .into_par_iter()
            .map(|i| ctx.project(cloud, i))
            .collect();
        Sorter::new()
            .sort_for_camera(&cloud.positions, camera, opts.sort)
            .iter()
            .filter_map(|&i| projected[i as usize])
            .collect()
    };
    // Bin and rasterize in bands of tile rows holding at most MAX_BIN_ENTRIES (splat, tile)
    // pairs, so memory stays bounded however large the splats or the image (a single tile row
    // over the limit is still done alone).
    let per_row = raster::row_entries(&splats, camera.height);
    let mut tile_entries = 0u64;
    let mut start = 0usize;
    while start < per_row.len() {
        let (mut end, mut sum) = (start, 0u64);
        while end < per_row.len() && (end == start || sum + per_row[end] <= MAX_BIN_ENTRIES) {
            sum += per_row[end];
            end += 1;
        }
        let rows = start as u32..end as u32;
        let tiles = raster::bin(&splats, camera.width, rows.clone());
        raster::rasterize(&mut image, &splats, &tiles, rows);
        tile_entries += sum;
        start = end;
    }
    let stats = RenderStats {
        splats: cloud.len(),
        visible: splats.len(),
        tile_entries: tile_entries as usize,
    };
    (image, stats)
}

/// One projected splat as the rasterizer sees it: centre in pixels (top-left origin), Σ'
/// after dilation `[xx, xy, yy]` px², opacity. **For the benchmark's fragment-count
/// prediction** (feature `testing`).
#[cfg(feature = "testing")]
#[doc(hidden)]
pub fn footprints(cloud: &SplatCloud, camera: &Camera, opts: &RenderOptions) -> Vec<[f32; 6]> {
    let degree = opts.sh_degree.min(cloud.sh_degree);
    let ctx = ViewContext::new(
        camera,
        opts.cull_depth(camera) as f64,
        degree,
        PixelBox::Full,
    )
    .with_antialiased(opts.antialiased);
    (0..cloud.len())
        .into_par_iter()
        .filter_map(|i| ctx.project(cloud, i))
        .map(|p| {
            [
                p.mean[0], p.mean[1], p.cov[0], p.cov[1], p.cov[2], p.opacity,
            ]
        })
        .collect()
}

/// The reference render as a display shows it, in `color_space` (pass
/// `cloud.meta.color_space.effective()`, or an override): for `lin_rec709_display` the
/// background is taken as a display value (sRGB-decoded), the splats blend in linear, and the
/// result is sRGB-encoded once at the end ([`crate::profile::srgb_encode`], unclamped above 1);
/// `srgb_rec709_display` clouds are shown as blended. This is exactly what the GL backend
/// ([`crate::headless`]) and `splatgl render` produce, and what they are compared against.
pub fn render_display(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &RenderOptions,
    color_space: ColorSpace,
) -> (Image, RenderStats) {
    if color_space != ColorSpace::LinRec709Display {
        return render_with_stats(cloud, camera, opts);
    }
    let linear = RenderOptions {
        background: opts.background.map(|v| srgb_decode(v as f64) as f32),
        ..*opts
    };
    let (mut image, stats) = render_with_stats(cloud, camera, &linear);
    for p in &mut image.pixels {
        for c in &mut p[..3] {
            *c = srgb_encode(*c as f64) as f32;
        }
    }
    (image, stats)
}
