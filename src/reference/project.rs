//! Per-splat preprocessing: cull, project the mean, Σ' = J W Σ Wᵀ Jᵀ (+ dilation), conic,
//! 3σ bounding box, colour. Mirrors 3DGS `preprocessCUDA` / `computeCov2D`, in f64.

use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::covariance::c_matrix;
use crate::profile::{
    ALPHA_MAX, ALPHA_MIN, CUTOFF_M2, DILATION_PX2, JACOBIAN_CLAMP, OPACITY_M2_MARGIN,
    opacity_cutoff_m2,
};
use glam::{DMat3, DMat4, DVec3};

/// One splat ready for rasterization (f32, pixel units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Projected {
    /// Index in the cloud.
    pub(crate) index: u32,
    /// Projected mean in pixels (top-left corner of the image = (0, 0)).
    pub(crate) mean: [f32; 2],
    /// Σ' after dilation, `[xx, xy, yy]` px².
    pub(crate) cov: [f32; 3],
    /// Σ'⁻¹, `[xx, xy, yy]`.
    pub(crate) conic: [f32; 3],
    /// Opacity attribute.
    pub(crate) opacity: f32,
    /// A pure optimisation: beyond this m² no pixel can reach α ≥ 1/255, so the exponential
    /// is skipped: `min(9, 2·ln(opacity/ALPHA_MIN) + OPACITY_M2_MARGIN)` (the margin covers f32
    /// rounding of the exponential).
    pub(crate) m2_max: f32,
    /// SH colour (negatives clamped to 0).
    pub(crate) color: [f32; 3],
    /// `[x0, x1, y0, y1]`: the pixels `x0..x1` × `y0..y1` (exclusive ends) whose centres lie in
    /// the bounding box of the ellipse m² ≤ `m2_max` (with [`PixelBox::Full`]: of the 3σ
    /// ellipse), clipped to the image; never empty.
    pub(crate) bbox: [u32; 4],
}

/// Which box of pixels a splat is rasterized over. Both give bit-identical images (every
/// pixel left out by `OpacityAware` fails the per-pixel test; `docs/rendering-profile.md` §3);
/// the switch exists for the tests and benchmarks that show it.
#[cfg_attr(not(feature = "testing"), allow(dead_code))] // `Full`: the tests' former rule
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PixelBox {
    /// The box of the ellipse m² ≤ min(9, 2·ln(opacity/ALPHA_MIN) + margin), widened by a
    /// proven bound on the f32 rounding of the per-pixel m² (the default).
    #[default]
    OpacityAware,
    /// The box of the 3σ ellipse whatever the opacity (the former rule).
    Full,
}

/// How the reference gets to its image. Every combination gives the bit-identical image
/// (tested); the switches exist for the tests and benchmarks that show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Path {
    /// Pixel box per splat.
    pub extent: PixelBox,
    /// Project and sort only the splats the camera's frustum may see ([`crate::cull`]).
    pub cull: bool,
}

impl Default for Path {
    fn default() -> Self {
        Path {
            extent: PixelBox::OpacityAware,
            cull: true,
        }
    }
}

#[cfg_attr(not(feature = "testing"), allow(dead_code))] // for the tests (feature `testing`)
impl Path {
    /// The rules before the opacity-aware extent and the cull: 3σ boxes, every splat.
    pub const FULL: Path = Path {
        extent: PixelBox::Full,
        cull: false,
    };
}

/// Per-view constants shared by all splats.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ViewContext {
    w2c: DMat4,
    w: DMat3,
    eye: DVec3,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    lim: [f64; 2],
    cull_z: f64,
    size: [u32; 2],
    sh_degree: u8,
    extent: PixelBox,
    /// The antialiased kernel: opacity × √(det Σ' / det(Σ' + 0.3 I)).
    antialiased: bool,
}

impl ViewContext {
    /// With the antialiased kernel on or off ([`RenderOptions::antialiased`](super::RenderOptions::antialiased)).
    pub(crate) fn with_antialiased(mut self, on: bool) -> Self {
        self.antialiased = on;
        self
    }

    /// Constants for `camera`; splats with view z ≤ `cull_z` are culled; SH up to `sh_degree`;
    /// pixel boxes by `extent`.
    pub(crate) fn new(camera: &Camera, cull_z: f64, sh_degree: u8, extent: PixelBox) -> Self {
        let w2c = camera.world_to_camera.as_dmat4();
        let tan = camera.tan_half_fov().as_dvec2();
        ViewContext {
            w2c,
            w: DMat3::from_mat4(w2c),
            eye: w2c.inverse().w_axis.truncate(),
            fx: camera.fx as f64,
            fy: camera.fy as f64,
            cx: camera.cx as f64,
            cy: camera.cy as f64,
            lim: [JACOBIAN_CLAMP * tan.x, JACOBIAN_CLAMP * tan.y],
            cull_z,
            size: [camera.width, camera.height],
            sh_degree,
            extent,
            antialiased: false,
        }
    }

    /// Σ' = J W Σ Wᵀ Jᵀ + 0.3·I from the factor C of Σ = C Cᵀ (C = R·diag(s)): with
    /// P = J W C (rows p₀, p₁), Σ' = P Pᵀ + 0.3·I, returned as `([xx, xy, yy], det)` where the determinant comes from
    /// Cauchy–Binet, `|p₀ × p₁|² + 0.3·(|p₀|² + |p₁|²) + 0.09`. Positive definite by
    /// construction: no cancellation even for needles seen end-on. Also returns the
    /// determinant before the dilation, `|p₀ × p₁|²` (the antialiased kernel's numerator).
    pub(crate) fn cov2d_factored(&self, t: DVec3, c: DMat3) -> ([f64; 3], f64, f64) {
        let txtz = (t.x / t.z).max(-self.lim[0]).min(self.lim[0]);
        let tytz = (t.y / t.z).max(-self.lim[1]).min(self.lim[1]);
        let j0 = DVec3::new(self.fx / t.z, 0.0, -self.fx * txtz / t.z);
        let j1 = DVec3::new(0.0, self.fy / t.z, -self.fy * tytz / t.z);
        // Rows of J·W·C are Cᵀ Wᵀ jᵢ.
        let ct_wt = c.transpose() * self.w.transpose();
        let (p0, p1) = (ct_wt * j0, ct_wt * j1);
        let (aa, cc) = (p0.dot(p0), p1.dot(p1));
        let d = DILATION_PX2;
        let det0 = p0.cross(p1).length_squared();
        let det = det0 + d * (aa + cc) + d * d;
        ([aa + d, p0.dot(p1), cc + d], det, det0)
    }

    /// Preprocesses splat `i`; `None` when it is culled or cannot contribute to any pixel.
    pub(crate) fn project(&self, cloud: &SplatCloud, i: usize) -> Option<Projected> {
        if !cloud.is_drawable(i) {
            return None;
        }
        let opacity = cloud.opacities[i];
        let best_alpha = opacity.min(ALPHA_MAX);
        if best_alpha.is_nan() || best_alpha < ALPHA_MIN {
            return None; // no pixel can reach α ≥ 1/255
        }
        let mean = DVec3::from_array(cloud.positions[i].map(f64::from));
        let t = self.w2c.transform_point3(mean);
        if !t.is_finite() || t.z <= self.cull_z {
            return None;
        }
        let factor = c_matrix(cloud.scales[i], cloud.rotations[i]);
        let ([a, b, c], det, det0) = self.cov2d_factored(t, factor);
        // Positive definite by construction; only overflow to infinity is left to reject.
        if !(a > 0.0 && det > 0.0 && det.is_finite() && c.is_finite()) {
            return None;
        }
        let opacity = if self.antialiased {
            let o = (f64::from(opacity) * (det0 / det).max(0.0).sqrt()) as f32;
            if o.min(ALPHA_MAX) < ALPHA_MIN {
                return None;
            }
            o
        } else {
            opacity
        };
        let u = self.fx * t.x / t.z + self.cx;
        let v = self.fy * t.y / t.z + self.cy;
        let m2_max = (opacity_cutoff_m2(opacity) + OPACITY_M2_MARGIN).min(f64::from(CUTOFF_M2));
        let m2_max = m2_max as f32;
        let conic = [(c / det) as f32, (-b / det) as f32, (a / det) as f32];
        let (ex, ey) = match self.extent {
            PixelBox::Full => (3.0 * a.sqrt(), 3.0 * c.sqrt()),
            PixelBox::OpacityAware => box_extents([a, b, c], det, conic, [u, v], m2_max),
        };
        let bbox = pixel_range(u, ex, self.size[0]).zip(pixel_range(v, ey, self.size[1]))?;
        let dir = (mean - self.eye).normalize().as_vec3().to_array();
        let color = crate::sh::eval_color(cloud.sh_of(i), self.sh_degree, dir);
        if !color.iter().all(|c| c.is_finite()) {
            return None;
        }
        Some(Projected {
            index: i as u32,
            mean: [u as f32, v as f32],
            cov: [a as f32, b as f32, c as f32],
            conic,
            opacity,
            m2_max,
            color,
            bbox: [bbox.0.0, bbox.0.1, bbox.1.0, bbox.1.1],
        })
    }
}

/// Pixels `i` with centre `i + 0.5` in `[centre − extent, centre + extent]`, clipped to
/// `0..size`; `None` when empty.
fn pixel_range(centre: f64, extent: f64, size: u32) -> Option<(u32, u32)> {
    if !(centre.is_finite() && extent.is_finite()) {
        return None;
    }
    let lo = (centre - extent - 0.5).ceil().max(0.0);
    let hi = (centre + extent - 0.5).floor().min(size as f64 - 1.0);
    (lo <= hi).then(|| (lo as u32, hi as u32 + 1))
}

/// Unit roundoff of f32.
const U32: f64 = 1.0 / (1u64 << 24) as f64;

/// Half-extents (x, y) in pixels of the box that holds every pixel whose per-pixel test
/// (`raster::blend`: m² in f32 from the f32 `conic` and f32 offsets, skipped when
/// m² > `m2_max`) can pass; never larger than the 3σ box `(3√a, 3√c)`, and exactly it when
/// the proof below cannot do better. `cov = [a, b, c]` is Σ' (f64), `det` its determinant,
/// `mean` the projected mean (f64).
///
/// Proof (`docs/rendering-profile.md` §3 "extent"): a pixel of the 3σ box has
/// `|dx| ≤ X = 3√a`, `|dy| ≤ Y = 3√c`. Its f32 m² differs from the exact quadratic form of
/// Σ'⁻¹ at the exact offset by at most `E` (coefficient and product rounding, 8u relative to
/// the absolute form, plus the offsets' own rounding δ), and the f64 conic is a scalar
/// multiple `1 ± η` of the exact Σ'⁻¹. The exact form is ≥ dx²/a (its minimum over dy), so a
/// pixel with `|dx| > e`, `e² = a·(m2_max + E)/(1 − η)`, has f32 m² > m2_max and is skipped
/// anyway; the same for y.
fn box_extents(
    cov: [f64; 3],
    det: f64,
    conic: [f32; 3],
    mean: [f64; 2],
    m2_max: f32,
) -> (f64, f64) {
    let [a, _, c] = cov;
    let full = (3.0 * a.sqrt(), 3.0 * c.sqrt());
    let [ca, cb, cc] = conic.map(|v| f64::from(v).abs());
    let (x, y) = full;
    let dx = 2.0 * U32 * (mean[0].abs() + x + 1.0);
    let dy = 2.0 * U32 * (mean[1].abs() + y + 1.0);
    let q = |x: f64, y: f64| ca * x * x + 2.0 * cb * x * y + cc * y * y;
    let (outer, inner) = (q(x + dx, y + dy), q(x, y));
    let e = 8.0 * U32 * outer + (outer - inner);
    // f64 rounding of Σ' and of its Cauchy–Binet determinant: ≤ 2⁻⁴⁶·(a·c/det + 1).
    let eta = (a * c / det + 1.0) * (2.0f64).powi(-46);
    let k2 = (f64::from(m2_max) + e) / (1.0 - eta);
    if !(k2 < f64::from(CUTOFF_M2) && eta < 1e-3) {
        return full;
    }
    let k = k2.sqrt();
    // The pixel box's own f64 rounding (`pixel_range`): a relative 1e-9 covers it.
    let widen = |e: f64, centre: f64| e + 1e-9 * (centre.abs() + e + 1.0);
    (
        widen(k * a.sqrt(), mean[0]).min(full.0),
        widen(k * c.sqrt(), mean[1]).min(full.1),
    )
}
