//! Culling before the sort: the splats that can touch the image from a view, found on the CPU
//! once per frame, so that only they are keyed, sorted, uploaded and drawn.
//!
//! The test is **conservative**: it removes only splats that provably produce no pixel in
//! either backend (the GL shader and the reference still apply their own exact culls to the
//! rest), so an image drawn from the visible set is bit-identical to one drawn from all
//! splats. `docs/rendering-profile.md` §3 "cull before sort" derives it:
//!
//! * **Per upload** ([`CullBounds`]): each splat's radius `R = 3·max|s|`, the world-space
//!   sphere around its 3σ ellipsoid, or "never" for splats both backends skip (non-finite
//!   data, α < 1/255 everywhere). (The opacity-aware extent is not used here: the
//!   reference's pixel box falls back to the 3σ box where it cannot prove better, so the 3σ
//!   footprint is the bound that holds for both backends without knowing Σ'.)
//! * **Per frame** ([`Frustum`]): five planes in world space. Near: the centre's depth
//!   `z < max(0.2, near)` minus a rounding margin (3DGS culls by the centre's depth alone).
//!   Sides: the projected footprint's half-extent along x is at most
//!   `|fx|/z · R · √(1 + lim²) + 3·√0.3` pixels (`lim` = the J clamp 1.3·tan, the 0.3 px²
//!   dilation) and the GL quad adds at most √2·2 % and √2·⅛ px; a splat is culled only if even
//!   [`CULL_RADIUS_FACTOR`]·that, plus [`CULL_MARGIN_PX`], misses the image.
//!
//! Every comparison is written so that NaN keeps the splat (the backends decide).

mod crop;
pub use crop::{CropBox, CropError};

use glam::{Mat4, Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::profile::{ALPHA_MAX, ALPHA_MIN, CUTOFF_M2, JACOBIAN_CLAMP};

/// Factor on the footprint bound `|f|/z·R·√(1 + lim²)`: covers the GL quad's rectangle along
/// Σ''s axes (its corners reach √2 beyond the ellipse's box, with the
/// [`QUAD_AXIS_FACTOR`](crate::profile::QUAD_AXIS_FACTOR): √2·1.02 = 1.443) and f32 rounding.
pub const CULL_RADIUS_FACTOR: f32 = 1.5;
/// Pixels added to the footprint bound: the dilation's `1.443·3·√0.3 = 2.37` px, the quad's
/// `QUAD_MARGIN_PX·√2` and rounding (a unit test checks 4 against them).
pub const CULL_MARGIN_PX: f32 = 4.0;
/// Relative rounding margin of the plane tests (≈ 64 f32 ulps of the coordinates involved):
/// the GPU computes the same camera-space values in its own f32 order of operations.
pub const CULL_RELATIVE_MARGIN: f32 = 1.0 / (1 << 18) as f32;

/// Radius given to splats that are never drawn (any comparison with it culls).
const NEVER: f32 = -1.0;

/// Per-splat cull radii of one cloud (computed once per upload): the world-space sphere
/// around each mean that holds the splat's 3σ ellipsoid; with [`CullBounds::new`] also the
/// box of the means, so a view that holds the whole cloud skips the per-splat test.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CullBounds {
    radius: Vec<f32>,
    /// The box of the finite means, when every radius is ≥ 0 (or NaN): with it inside a
    /// frustum every splat is visible.
    whole: Option<[[f32; 3]; 2]>,
}

impl CullBounds {
    /// The bounds of every splat of `cloud` (in parallel).
    pub fn new(cloud: &SplatCloud) -> Self {
        let radius = (0..cloud.len())
            .into_par_iter()
            .map(|i| splat_radius(cloud, i))
            .collect();
        let mut b = CullBounds {
            radius,
            whole: None,
        };
        b.set_extent(&cloud.positions);
        b
    }

    /// Bounds from radii (`< 0`: never visible; NaN: always kept), without the box of the
    /// means (see [`CullBounds::set_extent`]).
    pub fn from_radii(radius: Vec<f32>) -> Self {
        CullBounds {
            radius,
            whole: None,
        }
    }

    /// Records the box of `positions` (the means these radii belong to), which lets a view
    /// that holds all of them skip the per-splat test. Call it again after moving them.
    pub fn set_extent(&mut self, positions: &[[f32; 3]]) {
        let drawn = !self.radius.par_iter().any(|r| *r < 0.0);
        let (lo, hi) = positions
            .par_iter()
            .fold(
                || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
                |(mut lo, mut hi), p| {
                    for k in 0..3 {
                        if p[k].is_finite() {
                            lo[k] = lo[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                    (lo, hi)
                },
            )
            .reduce(
                || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
                |a, b| {
                    let m = |f: fn(f32, f32) -> f32, x: [f32; 3], y: [f32; 3]| {
                        [f(x[0], y[0]), f(x[1], y[1]), f(x[2], y[2])]
                    };
                    (m(f32::min, a.0, b.0), m(f32::max, a.1, b.1))
                },
            );
        self.whole = (drawn && positions.len() == self.radius.len()).then_some([lo, hi]);
    }

    /// Whether `frustum` sees every splat (the box of the means inside all its planes, no
    /// splat that is never drawn): then the cull keeps them all without testing each.
    pub fn all_visible(&self, frustum: &Frustum) -> bool {
        self.whole.is_some_and(|[lo, hi]| frustum.holds_box(lo, hi))
    }

    /// The radii, one per splat.
    pub fn radii(&self) -> &[f32] {
        &self.radius
    }

    /// Mutable radii (a scene rescales those of a moved cloud); forgets the box of the means
    /// until the next [`CullBounds::set_extent`].
    pub fn radii_mut(&mut self) -> &mut [f32] {
        self.whole = None;
        &mut self.radius
    }

    /// Number of splats.
    pub fn len(&self) -> usize {
        self.radius.len()
    }

    /// Whether there are no splats.
    pub fn is_empty(&self) -> bool {
        self.radius.is_empty()
    }
}

/// The cull radius of splat `i`: `3·max|s|` (the 3σ sphere; the reference's pixel box and
/// the GL quad never reach beyond its footprint bound), or [`NEVER`] when both backends skip
/// it (not drawable; α < 1/255 everywhere).
fn splat_radius(cloud: &SplatCloud, i: usize) -> f32 {
    let o = cloud.opacities[i];
    // (`is_drawable` excludes a NaN opacity.)
    if !cloud.is_drawable(i) || o.min(ALPHA_MAX) < ALPHA_MIN {
        return NEVER;
    }
    let s = cloud.scales[i].iter().fold(0.0f32, |m, v| m.max(v.abs()));
    // Rounded up so the f32 radius is never below the exact 3σ.
    (f64::from(CUTOFF_M2).sqrt() * f64::from(s) * (1.0 + 1e-6)) as f32
}

/// The matrix bound `σ_max(A) ≤ √‖AᵀA‖∞` of a linear map (exact for a uniform scale): how
/// much a cull radius grows under a model matrix.
pub fn radius_scale(model: Mat4) -> f32 {
    let a = glam::Mat3::from_mat4(model);
    let ata = a.transpose() * a;
    let rows = [ata.row(0), ata.row(1), ata.row(2)];
    let norm = rows
        .iter()
        .map(|r| r.abs().element_sum())
        .fold(0.0, f32::max);
    norm.sqrt() * (1.0 + 1e-5)
}

/// One plane test: visible needs `n·p + w + grow·R + rel·(‖p‖₁ + t) ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Plane {
    n: Vec3,
    w: f32,
    /// Multiplier of the cull radius (0 for the near plane: culled by the centre alone).
    grow: f32,
    /// Rounding margin per unit of `‖p‖₁ + t`.
    rel: f32,
}

/// The five cull planes of one view in world space (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    planes: [Plane; 5],
    /// The view translation's size (rounding margin term).
    t: f32,
}

impl Frustum {
    /// The frustum of `camera` (its image is `width × height` pixels, principal point
    /// `(cx, cy)`), culling centres at depths below `cull_depth` (= `max(NEAR_CULL, near)`).
    pub fn from_camera(camera: &Camera, cull_depth: f32) -> Self {
        Frustum::new(
            camera.world_to_camera,
            Vec2::new(camera.fx, camera.fy),
            Vec2::new(camera.cx, camera.cy),
            Vec2::new(camera.width as f32, camera.height as f32),
            camera.tan_half_fov(),
            cull_depth,
        )
    }

    /// The general form: `world_to_camera` maps world points to camera space with +z the
    /// viewing direction (OpenCV axes; a GL view matrix with its y and z rows negated),
    /// pixel `x = focal.x·X/Z + principal.x` in `0..size.x` (likewise y, either direction),
    /// `tan_half_fov` the tangents the J clamp uses, and `cull_depth` the near cull.
    pub fn new(
        world_to_camera: Mat4,
        focal: Vec2,
        principal: Vec2,
        size: Vec2,
        tan_half_fov: Vec2,
        cull_depth: f32,
    ) -> Self {
        let m = CULL_MARGIN_PX;
        let k = |f: f32, tan: f32| {
            let lim = JACOBIAN_CLAMP as f32 * tan.abs();
            CULL_RADIUS_FACTOR * f.abs() * (1.0 + lim * lim).sqrt()
        };
        // The planes live in camera space, where a world radius R spans up to σ_max(W)·R: a
        // host view matrix may scale (`draw_with_matrices` takes any invertible affine one)
        // and the projected footprint does not shrink with it (J's 1/z and W cancel).
        let stretch = radius_scale(world_to_camera);
        let (kx, ky) = (
            k(focal.x, tan_half_fov.x) * stretch,
            k(focal.y, tan_half_fov.y) * stretch,
        );
        // Camera-space planes (a, b, c, d)·(X, Y, Z, 1) with their radius factor.
        let cam = [
            (Vec4::new(focal.x, 0.0, principal.x + m, 0.0), kx),
            (Vec4::new(-focal.x, 0.0, size.x + m - principal.x, 0.0), kx),
            (Vec4::new(0.0, focal.y, principal.y + m, 0.0), ky),
            (Vec4::new(0.0, -focal.y, size.y + m - principal.y, 0.0), ky),
            (Vec4::new(0.0, 0.0, 1.0, -cull_depth), 0.0),
        ];
        let r = world_to_camera.transpose(); // columns = rows of world_to_camera
        let rows = [r.x_axis, r.y_axis, r.z_axis];
        let w_max = rows
            .iter()
            .map(|v| v.truncate().abs().max_element())
            .fold(0.0, f32::max);
        let t = rows.iter().map(|v| v.w.abs()).fold(0.0, f32::max) + cull_depth.abs();
        let planes = cam.map(|(p, grow)| {
            let n = rows[0].truncate() * p.x + rows[1].truncate() * p.y + rows[2].truncate() * p.z;
            let w = rows[0].w * p.x + rows[1].w * p.y + rows[2].w * p.z + p.w;
            let size = p.truncate().abs().element_sum().max(p.w.abs());
            Plane {
                n,
                w,
                grow,
                rel: CULL_RELATIVE_MARGIN * size * w_max.max(1.0),
            }
        });
        Frustum { planes, t }
    }

    /// Whether every point of the box `lo..=hi` passes every plane (so every splat with its
    /// mean there does: the radius and rounding terms only add).
    fn holds_box(&self, lo: [f32; 3], hi: [f32; 3]) -> bool {
        if lo.iter().zip(&hi).any(|(l, h)| l > h) {
            return true; // no finite mean
        }
        self.planes.iter().all(|pl| {
            let corner = |k: usize, n: f32| if n >= 0.0 { lo[k] } else { hi[k] };
            let (x, y, z) = (corner(0, pl.n.x), corner(1, pl.n.y), corner(2, pl.n.z));
            pl.n.x * x + pl.n.y * y + pl.n.z * z + pl.w >= 0.0
        })
    }

    /// Whether a splat at `p` with cull radius `radius` ([`CullBounds`]) may touch the image.
    #[inline(always)]
    pub fn may_see(&self, p: [f32; 3], radius: f32) -> bool {
        let [x, y, z] = p;
        let size = x.abs() + y.abs() + z.abs() + self.t;
        // Branch-free (`&`, `|`, no early exit) so that the cull pass vectorises. NaN (in the
        // data or a radius) keeps the splat: the backends skip it.
        let mut keep = radius >= 0.0 || radius.is_nan();
        for pl in &self.planes {
            let v = pl.n.x * x + pl.n.y * y + pl.n.z * z + pl.w + pl.grow * radius + pl.rel * size;
            keep &= v >= 0.0 || v.is_nan();
        }
        keep
    }
}

/// Writes into `out` the indices (ascending) of the splats of `positions` / `bounds` that
/// [`Frustum::may_see`], in parallel; returns their count. `out` is grown to
/// `positions.len()` and never shrunk, and nothing else is allocated, so a warm buffer makes
/// this allocation-free; its first `count` entries are the result.
///
/// # Panics
/// If `bounds` has another length than `positions`, or there are 2³² − 1 splats or more.
pub fn visible_into(
    frustum: &Frustum,
    positions: &[[f32; 3]],
    bounds: &CullBounds,
    out: &mut Vec<u32>,
) -> usize {
    let n = positions.len();
    assert_eq!(bounds.len(), n, "one cull radius per splat");
    assert!(
        n < END as usize,
        "indices must fit u32 below the end marker"
    );
    if out.len() < n {
        out.resize(n, 0);
    }
    if bounds.all_visible(frustum) {
        out[..n]
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, o)| *o = i as u32);
        return n;
    }
    const CHUNK: usize = 1 << 14;
    let radii = bounds.radii();
    // Each chunk writes its visible indices at the start of its own range, then END: blocks
    // of the (vectorised) test into a mask, then a branch-free compaction.
    const BLOCK: usize = 256;
    out[..n]
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, dst)| {
            let start = c * CHUNK;
            let mut k = 0;
            let mut mask = [false; BLOCK];
            for b in (0..dst.len()).step_by(BLOCK) {
                let len = BLOCK.min(dst.len() - b);
                let (ps, rs) = (&positions[start + b..][..len], &radii[start + b..][..len]);
                for ((m, p), r) in mask.iter_mut().zip(ps).zip(rs) {
                    *m = frustum.may_see(*p, *r);
                }
                for (j, &m) in mask[..len].iter().enumerate() {
                    // k ≤ b + j < dst.len(): the write is in bounds and never past what is read.
                    dst[k] = (start + b + j) as u32;
                    k += usize::from(m);
                }
            }
            if k < dst.len() {
                dst[k] = END;
            }
        });
    // Compact the chunks' runs (each starts at its chunk's start, at or after `total`).
    let mut total = 0;
    for start in (0..n).step_by(CHUNK) {
        let run = &out[start..(start + CHUNK).min(n)];
        let k = run.iter().position(|&i| i == END).unwrap_or(run.len());
        out.copy_within(start..start + k, total);
        total += k;
    }
    total
}

/// Marks the end of a chunk's run in [`visible_into`] (never a splat index).
const END: u32 = u32::MAX;

#[cfg(test)]
mod tests;
