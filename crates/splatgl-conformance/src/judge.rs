//! The judged region of a camera (`judge_mask`): isolation by construction. A renderer that
//! follows the RC may still draw a splat's rim differently (the RC "assumes a 3σ cut-off"; a
//! 2.83σ square, a 3.33σ box or 3DGS's tiles reach other pixels) and may blend two
//! overlapping splats in view-depth order per tile; neither is what most assets test. So
//! each camera's pixels where such a choice can move the image beyond a generic amount are
//! left out of its verdict — reported, never failing it — unless the asset tests that very
//! choice (`cutoff_three_sigma`, `sort_distance_not_depth`). What is left is decided by the
//! asset's rule and the small choices the bound's terms admit (α cap, the 1/255 skip, early
//! termination, dilation, storage precision), whatever combination a renderer makes.

use super::model::{self, Layer};
use splatgl::camera::Camera;
use splatgl::cloud::SplatCloud;
use splatgl::profile::DILATION_PX2;

/// How much smaller than the profile's (beyond the dilation) a renderer's footprint may be
/// where it stores scales in 8 bits (SPZ, Spark's packed splats: σ off by up to ~4 %) or
/// floors Σ''s eigenvalues (GaussianSplats3D): a rim starts this much further in.
pub const FOOTPRINT_MARGIN: f64 = 0.06;
/// Mahalanobis² of the smallest cut-off a renderer may make (2√2σ: the review draft's
/// `power > 4` and CesiumJS's square) on a footprint [`FOOTPRINT_MARGIN`] smaller: from here
/// outwards is a splat's rim.
const RIM_M2: f64 = 8.0 * (1.0 - FOOTPRINT_MARGIN) * (1.0 - FOOTPRINT_MARGIN);
/// The α below which one layer cannot move a pixel beyond the generic bound (a quarter of an
/// 8-bit step): a rim or an overlap fainter than this is judged.
pub const QUIET_ALPHA: f64 = 0.25 / 255.0;
/// Distances or view depths closer than this (relative) are a tie: their order is f32
/// rounding's.
const TIE: f64 = 1e-4;

/// What an asset tests of the choices the judged region leaves out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tested {
    /// The extent of a splat (the cut-off): its rims are judged.
    pub extent: bool,
    /// The blending order: its overlaps are judged.
    pub order: bool,
    /// The dilation of Σ': a rim is where the profile's footprint has it (elsewhere also
    /// where an undilated footprint has it).
    pub dilation: bool,
}

/// Per pixel (row-major) whether it is judged: `cloud` seen by `cam`, for an asset that
/// tests `tested`.
pub fn judged_region(cloud: &SplatCloud, cam: &Camera, tested: Tested) -> Vec<bool> {
    let layers = model::project(cloud, cam, (&[], &[]), None, DILATION_PX2);
    // The smallest footprints an admitted dilation gives (none at all): where a pixel lies
    // beyond 2.83σ of one of them, it is in that splat's rim for some renderer.
    let mut smallest = vec![None; cloud.len()];
    for l in model::project(cloud, cam, (&[], &[]), None, 0.0) {
        smallest[l.index] = Some(l);
    }
    let keys = order_keys(cloud, cam);
    let quiet = quiet_alpha(cloud);
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut out = vec![true; w * h];
    let mut here: Vec<&Layer> = Vec::new();
    for py in 0..h {
        for px in 0..w {
            let p = (px as f64 + 0.5, py as f64 + 0.5);
            here.clear();
            let mut rim = 0.0;
            for l in &layers {
                let m2 = mahalanobis2(l, p);
                let raw = l.opacity * (-0.5 * m2).exp();
                // Every rim counts, however faint: a renderer that draws them without the
                // 1/255 skip adds them up. The rim of the largest footprint (`l`) or of the
                // smallest (no dilation; a splat too thin for one has no other).
                let m2_small = match (tested.dilation, smallest[l.index]) {
                    (true, _) => m2,
                    (false, Some(s)) => mahalanobis2(&s, p),
                    (false, None) => f64::INFINITY,
                };
                if m2.max(m2_small) >= RIM_M2 {
                    rim += raw;
                }
                if raw >= quiet {
                    here.push(l);
                }
            }
            let rim_moves = !tested.extent && rim >= quiet;
            let order_moves = !tested.order && ambiguous_pair(&here, &keys, p, quiet).is_some();
            out[py * w + px] = !(rim_moves || order_moves);
        }
    }
    out
}

/// The first pair of overlapping splats (at some pixel, both with α ≥ [`QUIET_ALPHA`]) whose
/// distances to the camera — the RC's sort key — are a tie of f32 rounding, as `(i, j,
/// relative difference)`: an asset must not hold one. (Ties of view depth, splats side by side
/// facing the camera, are common; where such splats overlap, the judged region leaves the
/// pixels out.)
pub fn sort_tie(cloud: &SplatCloud, cam: &Camera) -> Option<(usize, usize, f64)> {
    let layers = model::project(cloud, cam, (&[], &[]), None, DILATION_PX2);
    let keys = order_keys(cloud, cam);
    let quiet = quiet_alpha(cloud);
    let mut here: Vec<&Layer> = Vec::new();
    for py in 0..cam.height {
        for px in 0..cam.width {
            let p = (px as f64 + 0.5, py as f64 + 0.5);
            here.clear();
            here.extend(
                layers
                    .iter()
                    .filter(|l| l.opacity * (-0.5 * mahalanobis2(l, p)).exp() >= quiet),
            );
            for (x, a) in here.iter().enumerate() {
                for b in &here[x + 1..] {
                    let (ka, kb) = (keys[a.index], keys[b.index]);
                    let d = relative(ka.0, kb.0);
                    if d <= TIE && swap_moves(a, b, p, quiet) {
                        return Some((a.index, b.index, d));
                    }
                }
            }
        }
    }
    None
}

/// Two layers at a pixel whose distance order and view-depth order disagree, or whose keys
/// tie: where a renderer sorting either way (or per tile) blends them differently.
fn ambiguous_pair(
    here: &[&Layer],
    keys: &[(f64, f64)],
    p: (f64, f64),
    quiet: f64,
) -> Option<(usize, usize)> {
    for (x, a) in here.iter().enumerate() {
        for b in &here[x + 1..] {
            let (ka, kb) = (keys[a.index], keys[b.index]);
            let by_distance = ka.0 > kb.0;
            let by_depth = ka.1 > kb.1;
            let ambiguous = by_distance != by_depth
                || relative(ka.0, kb.0) <= TIE
                || relative(ka.1, kb.1) <= TIE;
            if ambiguous && swap_moves(a, b, p, quiet) {
                return Some((a.index, b.index));
            }
        }
    }
    None
}

/// Per splat: its distance to the eye and its view depth.
fn order_keys(cloud: &SplatCloud, cam: &Camera) -> Vec<(f64, f64)> {
    let w2c = cam.world_to_camera.as_dmat4();
    let eye = w2c.inverse().w_axis.truncate();
    cloud
        .positions
        .iter()
        .map(|p| {
            let m = glam::DVec3::from_array(p.map(f64::from));
            (m.distance(eye), w2c.transform_point3(m).z)
        })
        .collect()
}

/// Whether blending `a` and `b` at pixel `p` in the other order can move it by `quiet` or
/// more: the swap changes it by T·αₐ·α_b·|cₐ − c_b| at most.
fn swap_moves(a: &Layer, b: &Layer, p: (f64, f64), quiet: f64) -> bool {
    let alpha = |l: &Layer| l.opacity * (-0.5 * mahalanobis2(l, p)).exp();
    let dc = (0..3)
        .map(|k| (a.color[k] - b.color[k]).abs())
        .fold(0.0, f64::max);
    alpha(a) * alpha(b) * dc >= quiet
}

/// [`QUIET_ALPHA`] in the units splats blend in: for `lin_rec709_display` linear values,
/// which the display's sRGB encoding magnifies up to 12.92× near black.
fn quiet_alpha(cloud: &SplatCloud) -> f64 {
    match cloud.meta.color_space.effective() {
        splatgl::cloud::ColorSpace::LinRec709Display => QUIET_ALPHA / 12.92,
        _ => QUIET_ALPHA,
    }
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-12)
}

fn mahalanobis2(l: &Layer, (xc, yc): (f64, f64)) -> f64 {
    let (dx, dy) = (xc - l.centre[0], yc - l.centre[1]);
    l.conic[0] * dx * dx + 2.0 * l.conic[1] * dx * dy + l.conic[2] * dy * dy
}

/// Leaves the pixels outside `judged` out of a bound: an infinite bound, which
/// the runner's measure skips (no error, no ratio, no PSNR contribution).
pub fn apply(bound: &mut [f64], judged: &[bool]) {
    for (b, &j) in bound.iter_mut().zip(judged) {
        if !j {
            *b = f64::INFINITY;
        }
    }
}
