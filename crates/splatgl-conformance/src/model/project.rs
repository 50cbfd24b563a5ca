//! The model's projection stage: each splat's colour (SH, erratum e and the colour variants),
//! rotation and scale as the deviations read them, its screen covariance (dilation, the
//! eigenvalue floor, half-float storage), opacity, and the centre and pixel rectangle it is
//! blended over: one [`Layer`] per drawn splat, in blending order.

use super::{Erratum, Layer, Variant};
use glam::{DMat3, DQuat, DVec3};
use splatgl::camera::Camera;
use splatgl::cloud::SplatCloud;
use splatgl::covariance::c_matrix;
use splatgl::profile::{ALPHA_MAX, ALPHA_MIN, JACOBIAN_CLAMP, NEAR_CULL};
use splatgl::reference::SortMode;

use super::footprint::{BOX_SIGMA, SQUARE_SIGMA, babylon_axes, box_half_axes, eigenvalue_floor};

/// The appendix's SH basis (erratum e): no Condon–Shortley signs, 2.89 for coefficient 14.
fn appendix_basis(d: [f64; 3]) -> [f64; 16] {
    let mut y = splatgl::sh::basis(d);
    for k in [1, 3, 5, 7, 9, 11, 13, 15] {
        y[k] = -y[k];
    }
    y[14] *= splatgl::sh::SH_C3[1] / splatgl::sh::SH_C3[5];
    y
}

fn colour(cloud: &SplatCloud, i: usize, dir: [f64; 3], e: bool, v: &[Variant]) -> ([f64; 3], f64) {
    let cap = Variant::sh_cap(v);
    let all = cloud.sh_of(i);
    let coeffs = &all[..all.len().min((cap + 1) * (cap + 1))];
    let y = if e {
        appendix_basis(dir)
    } else {
        splatgl::sh::basis(dir)
    };
    let mut sum = [0.0f64; 3];
    let mut f16 = 0.0f64;
    let eight = v.contains(&Variant::Colour8Bit) && !e;
    for (k, c) in coeffs.iter().enumerate() {
        if k == 0 && eight {
            // floor(255·clamp(SH_C0·DC + 0.5)) / 255, less the bias added back below.
            for ch in 0..3 {
                let dc = (y[0] * c[ch] as f64 + splatgl::profile::SH_DC_BIAS).clamp(0.0, 1.0);
                sum[ch] += (dc * 255.0).floor() / 255.0 - splatgl::profile::SH_DC_BIAS;
            }
            continue;
        }
        for ch in 0..3 {
            sum[ch] += y[k] * c[ch] as f64;
        }
        f16 += c
            .iter()
            .map(|v| (*v as f64 * y[k]).abs())
            .fold(0.0, f64::max);
    }
    // f16 keeps 11 significant bits: rounded, a coefficient is off by 2⁻¹¹ of itself at most;
    // truncated (CesiumJS's `>>> 13` of the f32 mantissa), 2⁻¹⁰. Both are storage choices.
    let f16_err = f16 * 2f64.powi(-10);
    let c = if e || v.contains(&Variant::SigmoidColour) {
        sum.map(|v| 1.0 / (1.0 + (-v).exp()))
    } else {
        sum.map(|v| (v + splatgl::profile::SH_DC_BIAS).max(0.0))
    };
    let c = if v.contains(&Variant::ColourClamped) {
        c.map(|v| v.min(1.0))
    } else {
        c
    };
    (c, f16_err)
}

/// What [`project`] needs of the camera and the deviations, once per render.
struct View<'a> {
    cam: &'a Camera,
    errata: &'a [Erratum],
    vars: &'a [Variant],
    w2c: glam::DMat4,
    /// The world → camera rotation as the (possibly erratum-b) shader uses it.
    w: DMat3,
    eye: DVec3,
    /// The J clamp limits on x/z, y/z.
    lim: [f64; 2],
    /// Where in the f32 rounding's range of angles `EigenvalueFloor` takes its major axis.
    axis: Option<f64>,
    /// The dilation added to Σ' (px²; 0 with erratum i).
    dilation: f64,
}

impl View<'_> {
    fn on(&self, e: Erratum) -> bool {
        self.errata.contains(&e)
    }
    fn var(&self, v: Variant) -> bool {
        self.vars.contains(&v)
    }
}

/// The splats of `cloud` seen by `cam` with the errata `x` and the variants `vars`, as
/// [`Layer`]s in blending order; Σ' dilated by `dilation` px² (erratum i: none).
pub(crate) fn project(
    cloud: &SplatCloud,
    cam: &Camera,
    (x, vars): (&[Erratum], &[Variant]),
    axis: Option<f64>,
    dilation: f64,
) -> Vec<Layer> {
    let w2c = cam.world_to_camera.as_dmat4();
    let w_cv = DMat3::from_mat4(w2c);
    let flip = DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0));
    let tan = cam.tan_half_fov().as_dvec2();
    let view = View {
        cam,
        errata: x,
        vars,
        w2c,
        // (b) the shader's W = transpose(mat3(view)) is, in OpenCV axes, D·Wᵀ·D.
        w: if x.contains(&Erratum::B) {
            flip * w_cv.transpose() * flip
        } else {
            w_cv
        },
        eye: w2c.inverse().w_axis.truncate(),
        lim: if x.contains(&Erratum::K) {
            [f64::INFINITY; 2]
        } else {
            [JACOBIAN_CLAMP * tan.x, JACOBIAN_CLAMP * tan.y]
        },
        axis,
        dilation: if x.contains(&Erratum::I) {
            0.0
        } else {
            dilation
        },
    };
    let mode = if view.var(Variant::ViewDepthOrder) {
        SortMode::ViewDepth
    } else {
        SortMode::Distance
    };
    let mut order = splatgl::sort::Sorter::new()
        .sort_for_camera(&cloud.positions, cam, mode)
        .to_vec();
    if view.on(Erratum::G) {
        order.reverse(); // the appendix's front-to-back
    }
    order
        .into_iter()
        .filter_map(|i| project_one(cloud, i as usize, &view))
        .collect()
}

/// Splat `i` projected for `view` (`None`: not drawn — culled, or Σ' degenerate).
fn project_one(cloud: &SplatCloud, i: usize, view: &View) -> Option<Layer> {
    let cam = view.cam;
    if !cloud.is_drawable(i) || (cloud.opacities[i].min(ALPHA_MAX)) < ALPHA_MIN {
        return None;
    }
    let mean = DVec3::from_array(cloud.positions[i].map(f64::from));
    let t = view.w2c.transform_point3(mean);
    if t.z <= (NEAR_CULL).max(cam.near as f64) {
        return None;
    }
    let (q, scale) = rotation_and_scale(cloud, i, view);
    let ([a, b, cc, det], det0) = screen_covariance(view, t, scale, q)?;
    let (fx, fy, cx, cy) = (cam.fx as f64, cam.fy as f64, cam.cx as f64, cam.cy as f64);
    let (u, v) = (fx * t.x / t.z + cx, fy * t.y / t.z + cy);
    let dir = (mean - view.eye).normalize().to_array();
    let (color, f16_err) = colour(cloud, i, dir, view.on(Erratum::E), view.vars);
    let opacity = model_opacity(cloud, i, view, det0, det);
    let box_axes = [
        (Variant::BoxCut, BOX_SIGMA),
        (Variant::SquareCut, SQUARE_SIGMA),
    ]
    .into_iter()
    .find(|(v, _)| view.var(*v))
    .map(|(_, k)| box_half_axes(a, b, cc, k));
    let (centre, rect) = centre_and_rect(view, [a, cc, det], [u, v], t.z, box_axes);
    Some(Layer {
        index: i,
        cov: [a, b, cc],
        centre,
        conic: [cc / det, -b / det, a / det],
        opacity,
        color,
        f16_err,
        rect,
        box_axes,
    })
}

/// Splat `i`'s rotation and scale as the deviations read them (`QuatWxyz`, erratum a,
/// `LogScale`).
fn rotation_and_scale(cloud: &SplatCloud, i: usize, view: &View) -> ([f32; 4], [f32; 3]) {
    let mut q = cloud.rotations[i];
    if view.var(Variant::QuatWxyz) {
        q = [q[1], q[2], q[3], q[0]]; // the stored x taken as w
    }
    if view.on(Erratum::A) {
        let c = DQuat::from_array(q.map(f64::from)).conjugate(); // Rᵀ = R(q*)
        q = [c.x as f32, c.y as f32, c.z as f32, c.w as f32];
    }
    let scale = if view.var(Variant::LogScale) {
        cloud.scales[i].map(f32::exp)
    } else {
        cloud.scales[i]
    };
    (q, scale)
}

/// The dilated screen covariance `[a, b, c, det]` of a splat at camera point `t` (after the
/// `EigenvalueFloor` variant), and the undilated determinant; `None` when degenerate.
fn screen_covariance(
    view: &View,
    t: DVec3,
    scale: [f32; 3],
    q: [f32; 4],
) -> Option<([f64; 4], f64)> {
    let cam = view.cam;
    let (fx, fy) = (cam.fx as f64, cam.fy as f64);
    let txtz = (t.x / t.z).clamp(-view.lim[0], view.lim[0]);
    let tytz = (t.y / t.z).clamp(-view.lim[1], view.lim[1]);
    let j0 = DVec3::new(fx / t.z, 0.0, -fx * txtz / t.z);
    let j1 = DVec3::new(0.0, fy / t.z, -fy * tytz / t.z);
    let m = c_matrix(scale, q).transpose() * view.w.transpose();
    if view.var(Variant::HalfCovariance) || view.var(Variant::Attributes8Bit) {
        return half_covariance(view, m, [j0, j1]);
    }
    let (p0, p1) = (m * j0, m * j1);
    let d = view.dilation;
    let (mut a, mut b, mut cc) = (p0.dot(p0) + d, p0.dot(p1), p1.dot(p1) + d);
    let mut det = p0.cross(p1).length_squared() + d * (p0.dot(p0) + p1.dot(p1)) + d * d;
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    if view.var(Variant::EigenvalueFloor) {
        [a, b, cc, det] = eigenvalue_floor(a, b, cc, det, view.axis)?;
    }
    if view.var(Variant::AxesSwapped) {
        [a, b, cc, det] = babylon_axes(a, b, cc)?;
    }
    Some(([a, b, cc, det], p0.cross(p1).length_squared()))
}

/// [`screen_covariance`] with the world covariance Σ = Cᵀ… rounded to half floats first
/// ([`Variant::HalfCovariance`]): `m` is `Cᵀ Wᵀ`, `j` the rows of J.
fn half_covariance(view: &View, m: DMat3, [j0, j1]: [DVec3; 2]) -> Option<([f64; 4], f64)> {
    use splatgl::load::codec::{f16_to_f32, f32_to_f16};
    let h = |v: f64| f64::from(f16_to_f32(f32_to_f16(v as f32)));
    let c = m * view.w; // Cᵀ
    let sigma = c.transpose() * c; // Σ = C Cᵀ, world
    let q = splatgl::covariance::pack_sym(sigma).map(h);
    let sq = DMat3::from_cols(
        DVec3::new(q[0], q[1], q[2]),
        DVec3::new(q[1], q[3], q[4]),
        DVec3::new(q[2], q[4], q[5]),
    );
    let wt = view.w.transpose();
    let (u0, u1) = (wt * j0, wt * j1);
    let (a0, b, c0) = (u0.dot(sq * u0), u0.dot(sq * u1), u1.dot(sq * u1));
    let d = view.dilation;
    let (mut a, mut b, mut cc) = (a0 + d, b, c0 + d);
    let mut det = a * cc - b * b;
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    if view.var(Variant::EigenvalueFloor) {
        [a, b, cc, det] = eigenvalue_floor(a, b, cc, det, view.axis)?;
    }
    if view.var(Variant::AxesSwapped) {
        [a, b, cc, det] = babylon_axes(a, b, cc)?;
    }
    Some(([a, b, cc, det], (a0 * c0 - b * b).max(0.0)))
}

/// Splat `i`'s opacity as the variants store it (`Colour8Bit`) and compensate it
/// (`AaCompensation`, by the undilated over the dilated determinant).
fn model_opacity(cloud: &SplatCloud, i: usize, view: &View, det0: f64, det: f64) -> f64 {
    let mut opacity = cloud.opacities[i] as f64;
    if view.var(Variant::Colour8Bit) {
        opacity = (opacity * 255.0).floor() / 255.0;
    }
    if view.var(Variant::AaCompensation) {
        opacity *= (det0 / det).max(0.0).sqrt();
    }
    opacity
}

/// Where the Gaussian is evaluated and the pixels it may touch, for the projected centre
/// `[u, v]` at depth `tz`: erratum d's quad, the box cut's, or the 3σ ellipse's bounds.
fn centre_and_rect(
    view: &View,
    [a, cc, det]: [f64; 3],
    [u, v]: [f64; 2],
    tz: f64,
    box_axes: Option<[[f64; 2]; 2]>,
) -> ([f64; 2], [f64; 4]) {
    let cam = view.cam;
    let (fx, fy) = (cam.fx as f64, cam.fy as f64);
    let (rx, ry) = (3.0 * a.sqrt(), 3.0 * cc.sqrt());
    if view.on(Erratum::D) {
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
        let centre = [u * tz / fx, h - (h - v) * tz / fy];
        (centre, [u - hx, u + hx, v - hy, v + hy])
    } else if let Some([e1, e2]) = box_axes {
        let (hx, hy) = (e1[0].abs() + e2[0].abs(), e1[1].abs() + e2[1].abs());
        ([u, v], [u - hx, u + hx, v - hy, v + hy])
    } else {
        ([u, v], [u - rx, u + rx, v - ry, v + ry])
    }
}
