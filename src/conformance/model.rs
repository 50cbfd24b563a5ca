//! A small f64 model of the rendering profile with each observable Appendix A erratum as a
//! switch, and the per-pixel error bound the tolerances are derived from.
//!
//! It is written from `docs/rendering-profile.md` and `docs/appendix-errata.md`, sharing only
//! the SH basis, the covariance factor and the sort with the reference ([`crate::reference`]);
//! with no erratum switched on it reproduces the reference to f32 rounding (tested). With a
//! switch on it renders what a renderer with that erratum draws, which is how the suite
//! *derives* which assets catch which erratum (`catches` in the manifest): an asset catches
//! erratum x when the model's image with x fails the asset's tolerance. The erratum proof
//! test then renders the suite with the GL backend's own `#define ERRATUM_x` switches and
//! checks that the runner fails exactly those assets.

use super::Erratum;
use crate::camera::Camera;
use crate::cloud::{ColorSpace, SplatCloud};
use crate::covariance::c_matrix;
use crate::image::Image;
use crate::profile::srgb_encode;
use crate::profile::{ALPHA_MAX, ALPHA_MIN, CUTOFF_M2, DILATION_PX2, JACOBIAN_CLAMP, NEAR_CULL};
use crate::reference::{SortMode, back_to_front};
use glam::{DMat3, DQuat, DVec3};

/// One projected splat.
#[derive(Debug, Clone, Copy)]
struct Layer {
    /// Where the Gaussian is evaluated (pixels, y down).
    centre: [f64; 2],
    /// Σ'⁻¹ `[xx, xy, yy]`.
    conic: [f64; 3],
    opacity: f64,
    color: [f64; 3],
    /// Colour error of f16 SH storage: Σₖ maxₓ|coefₖ·Yₖ|·2⁻¹¹ (bound term).
    f16_err: f64,
    /// Pixels `[x0, x1] × [y0, y1]` (centres, inclusive float bounds) the splat may touch.
    rect: [f64; 4],
}

/// Per-pixel error terms, each a worst case over the pixel (see `docs/conformance.md`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Terms {
    /// 8-bit output quantization, 0.5/255.
    pub output: f64,
    /// 8-bit framebuffer rounding, 2 × 0.5/255 per contributing splat (source and result).
    pub blend: f64,
    /// Pixel centres within rounding of a splat's 3σ cut (in for one renderer, out for another).
    pub cutoff: f64,
    /// Layers with α near or below 1/255 (skipped by 3DGS, drawn by others).
    pub threshold: f64,
    /// Layers whose α exceeds the 0.99 cap (capped by 3DGS, not by others).
    pub cap: f64,
    /// f16 storage of SH coefficients.
    pub sh_f16: f64,
    /// Colours above 1 clamped by a UNORM framebuffer between blends.
    pub overbright: f64,
    /// f32 arithmetic.
    pub float: f64,
    /// RC-silent choices a required asset admits (set by the generator, not by [`render`]):
    /// the difference the model shows without the 0.3 px² dilation.
    pub dilation: f64,
}

impl Terms {
    /// The bound: the sum of the terms.
    pub fn total(&self) -> f64 {
        self.output
            + self.blend
            + self.cutoff
            + self.threshold
            + self.cap
            + self.sh_f16
            + self.overbright
            + self.float
            + self.dilation
    }
    pub(crate) fn max(self, o: Terms) -> Terms {
        Terms {
            output: self.output.max(o.output),
            blend: self.blend.max(o.blend),
            cutoff: self.cutoff.max(o.cutoff),
            threshold: self.threshold.max(o.threshold),
            cap: self.cap.max(o.cap),
            sh_f16: self.sh_f16.max(o.sh_f16),
            overbright: self.overbright.max(o.overbright),
            float: self.float.max(o.float),
            dilation: self.dilation.max(o.dilation),
        }
    }
}

/// A model render: the display image and, per pixel, the error bound.
#[derive(Debug, Clone)]
pub struct ModelImage {
    /// Display-referred RGB (clamped to [0, 1]), A = 1 − T.
    pub image: Image,
    /// Per-pixel bound (total of [`Terms`]), row-major.
    pub bound: Vec<f64>,
    /// The largest value of each term over the image.
    pub worst: Terms,
}

/// Relative width of the band around the 3σ cut and the α threshold where f32 and f64
/// (or two implementations' operation orders) can disagree.
const EDGE_BAND: f64 = 1e-4;

/// The appendix's SH basis (erratum e): no Condon–Shortley signs, 2.89 for coefficient 14.
fn appendix_basis(d: [f64; 3]) -> [f64; 16] {
    let mut y = crate::sh::basis(d);
    for k in [1, 3, 5, 7, 9, 11, 13, 15] {
        y[k] = -y[k];
    }
    y[14] *= crate::sh::SH_C3[1] / crate::sh::SH_C3[5];
    y
}

fn colour(cloud: &SplatCloud, i: usize, dir: [f64; 3], e: bool) -> ([f64; 3], f64) {
    let coeffs = cloud.sh_of(i);
    let y = if e {
        appendix_basis(dir)
    } else {
        crate::sh::basis(dir)
    };
    let mut sum = [0.0f64; 3];
    let mut f16 = 0.0f64;
    for (k, c) in coeffs.iter().enumerate() {
        for ch in 0..3 {
            sum[ch] += y[k] * c[ch] as f64;
        }
        f16 += c
            .iter()
            .map(|v| (*v as f64 * y[k]).abs())
            .fold(0.0, f64::max);
    }
    let f16_err = f16 * 2f64.powi(-11);
    let c = if e {
        sum.map(|v| 1.0 / (1.0 + (-v).exp()))
    } else {
        sum.map(|v| (v + crate::profile::SH_DC_BIAS).max(0.0))
    };
    (c, f16_err)
}

fn project(cloud: &SplatCloud, cam: &Camera, x: &[Erratum]) -> Vec<Layer> {
    let on = |e| x.contains(&e);
    let w2c = cam.world_to_camera.as_dmat4();
    let w_cv = DMat3::from_mat4(w2c);
    let flip = DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0));
    // (b) the shader's W = transpose(mat3(view)) is, in OpenCV axes, D·Wᵀ·D.
    let w = if on(Erratum::B) {
        flip * w_cv.transpose() * flip
    } else {
        w_cv
    };
    let eye = w2c.inverse().w_axis.truncate();
    let (fx, fy, cx, cy) = (cam.fx as f64, cam.fy as f64, cam.cx as f64, cam.cy as f64);
    let tan = cam.tan_half_fov().as_dvec2();
    let lim = if on(Erratum::K) {
        [f64::INFINITY; 2]
    } else {
        [JACOBIAN_CLAMP * tan.x, JACOBIAN_CLAMP * tan.y]
    };
    let cull = (NEAR_CULL).max(cam.near as f64);
    let mut order = back_to_front(&cloud.positions, cam, SortMode::Distance);
    if on(Erratum::G) {
        order.reverse(); // the appendix's front-to-back
    }
    let mut out = Vec::new();
    for i in order.into_iter().map(|i| i as usize) {
        if !cloud.is_drawable(i) || (cloud.opacities[i].min(ALPHA_MAX)) < ALPHA_MIN {
            continue;
        }
        let mean = DVec3::from_array(cloud.positions[i].map(f64::from));
        let t = w2c.transform_point3(mean);
        if t.z <= cull {
            continue;
        }
        let mut q = cloud.rotations[i];
        if on(Erratum::A) {
            let c = DQuat::from_array(q.map(f64::from)).conjugate(); // Rᵀ = R(q*)
            q = [c.x as f32, c.y as f32, c.z as f32, c.w as f32];
        }
        let c = c_matrix(cloud.scales[i], q);
        let txtz = (t.x / t.z).clamp(-lim[0], lim[0]);
        let tytz = (t.y / t.z).clamp(-lim[1], lim[1]);
        let j0 = DVec3::new(fx / t.z, 0.0, -fx * txtz / t.z);
        let j1 = DVec3::new(0.0, fy / t.z, -fy * tytz / t.z);
        let m = c.transpose() * w.transpose();
        let (p0, p1) = (m * j0, m * j1);
        let d = if on(Erratum::I) { 0.0 } else { DILATION_PX2 };
        let (a, b, cc) = (p0.dot(p0) + d, p0.dot(p1), p1.dot(p1) + d);
        let det = p0.cross(p1).length_squared() + d * (p0.dot(p0) + p1.dot(p1)) + d * d;
        if !(det > 0.0 && det.is_finite()) {
            continue;
        }
        let (u, v) = (fx * t.x / t.z + cx, fy * t.y / t.z + cy);
        let dir = (mean - eye).normalize().to_array();
        let (color, f16_err) = colour(cloud, i, dir, on(Erratum::E));
        let (rx, ry) = (3.0 * a.sqrt(), 3.0 * cc.sqrt());
        let (centre, rect) = if on(Erratum::D) {
            // Quad ± radius/focal in NDC around the mean; centre (ndc/2 + 1/2)·w/P·2.
            let mid = 0.5 * (a + cc);
            let r = (9.0 * (mid + (mid * mid - det).max(0.1).sqrt()))
                .sqrt()
                .ceil();
            let (hx, hy) = (
                r * cam.width as f64 / (2.0 * fx),
                r * cam.height as f64 / (2.0 * fy),
            );
            let h = cam.height as f64;
            let centre = [u * t.z / fx, h - (h - v) * t.z / fy];
            (centre, [u - hx, u + hx, v - hy, v + hy])
        } else {
            ([u, v], [u - rx, u + rx, v - ry, v + ry])
        };
        out.push(Layer {
            centre,
            conic: [cc / det, -b / det, a / det],
            opacity: cloud.opacities[i] as f64,
            color,
            f16_err,
            rect,
        });
    }
    out
}

/// Renders `cloud` (global space, as loaded) from `cam` over a black background with the
/// errata `x` switched on; with `x` empty also computes the per-pixel bound.
pub fn render(cloud: &SplatCloud, cam: &Camera, x: &[Erratum]) -> ModelImage {
    let layers = project(cloud, cam, x);
    let linear = cloud.meta.color_space.effective() == ColorSpace::LinRec709Display;
    let (f, k, g) = (
        x.contains(&Erratum::F),
        x.contains(&Erratum::K),
        x.contains(&Erratum::G),
    );
    let cut = if f { 8.0 } else { CUTOFF_M2 as f64 };
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut image = Image::filled(cam.width, cam.height, [0.0, 0.0, 0.0, 1.0]);
    let mut bound = vec![0.0; w * h];
    let mut worst = Terms::default();
    let q = 0.5 / 255.0;
    for py in 0..h {
        for px in 0..w {
            let (xc, yc) = (px as f64 + 0.5, py as f64 + 0.5);
            let (mut c, mut a) = ([0.0f64; 3], 0.0f64);
            let mut t = Terms {
                output: q,
                ..Default::default()
            };
            let mut layers_here = 0usize;
            for l in &layers {
                let [x0, x1, y0, y1] = l.rect;
                if xc < x0 || xc > x1 || yc < y0 || yc > y1 {
                    continue;
                }
                let (dx, dy) = (xc - l.centre[0], yc - l.centre[1]);
                let m2 = l.conic[0] * dx * dx + 2.0 * l.conic[1] * dx * dy + l.conic[2] * dy * dy;
                let raw = l.opacity * (-0.5 * m2).exp();
                if (m2 - cut).abs() <= EDGE_BAND * cut {
                    t.cutoff += raw.min(ALPHA_MAX as f64);
                }
                if !(0.0..=cut).contains(&m2) {
                    continue;
                }
                let alpha = if k { raw } else { raw.min(ALPHA_MAX as f64) };
                if raw < ALPHA_MIN as f64 * (1.0 + 10.0 * EDGE_BAND) {
                    t.threshold += raw;
                }
                if raw > ALPHA_MAX as f64 * (1.0 - EDGE_BAND) {
                    t.cap += (raw.min(1.0) - ALPHA_MAX as f64).max(0.0);
                }
                if alpha < ALPHA_MIN as f64 {
                    continue;
                }
                layers_here += 1;
                t.sh_f16 += alpha * l.f16_err;
                t.overbright += l
                    .color
                    .iter()
                    .map(|v| (v - 1.0).max(0.0))
                    .fold(0.0, f64::max);
                let wgt = if g { alpha * alpha } else { alpha };
                for (v, lc) in c.iter_mut().zip(l.color) {
                    *v = lc * wgt + *v * (1.0 - alpha);
                }
                a = wgt + a * (1.0 - alpha);
            }
            // UNORM8 blending rounds the fragment output (c·α, α) to 8 bits and the result
            // again: two half-steps per blended splat.
            t.blend = 2.0 * q * layers_here as f64;
            t.float = 1e-5 * (layers_here + 1) as f64;
            let disp = c.map(|v| if linear { srgb_encode(v) } else { v }.clamp(0.0, 1.0));
            if linear {
                // α-convention terms act on linear values: map the interval through the curve.
                let lin = t.cutoff + t.threshold + t.cap + t.sh_f16 + t.overbright;
                let span = c
                    .iter()
                    .map(|&v| {
                        let hi = srgb_encode(v + lin) - srgb_encode(v);
                        let lo = srgb_encode(v) - srgb_encode((v - lin).max(0.0));
                        hi.max(lo)
                    })
                    .fold(0.0, f64::max);
                let scale = if lin > 0.0 { span / lin } else { 0.0 };
                for term in [
                    &mut t.cutoff,
                    &mut t.threshold,
                    &mut t.cap,
                    &mut t.sh_f16,
                    &mut t.overbright,
                ] {
                    *term *= scale;
                }
            }
            let i = py * w + px;
            image.pixels[i] = [disp[0] as f32, disp[1] as f32, disp[2] as f32, a as f32];
            bound[i] = t.total();
            worst = worst.max(t);
        }
    }
    ModelImage {
        image,
        bound,
        worst,
    }
}
