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

/// Implementation variants beside the errata: choices and mistakes seen in real renderers,
/// which the runner's diagnosis tests an image against ([`render_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    /// Splats cut by their oriented 3.33σ bounding box instead of the 3σ ellipse.
    BoxCut,
    /// Blending order by view depth (camera-space z; per tile or global, the same per pixel)
    /// instead of camera distance.
    ViewDepthOrder,
    /// Opacity scaled by √(det Σ' / det(Σ' + 0.3 I)) (Mip-Splatting / gsplat antialiasing).
    AaCompensation,
    /// SH evaluated up to degree 0 only (the RC: "MAY ignore higher-degree coefficients").
    ShDegree0,
    /// SH evaluated up to degree 1 only (allowed likewise).
    ShDegree1,
    /// SH evaluated up to degree 2 only (allowed likewise).
    ShDegree2,
    /// ROTATION read as `(w, x, y, z)` instead of glTF's `(x, y, z, w)`.
    QuatWxyz,
    /// SCALE read as log-space (`exp(s)`, the review draft) instead of linear.
    LogScale,
    /// Colour as `sigmoid(Σ SH·Y)` instead of `Σ SH·Y + 0.5`.
    SigmoidColour,
    /// The DC colour (`SH_C0·DC + 0.5`) and the opacity stored in 8 bits, rounded down
    /// (GaussianSplats3D's splat buffers).
    Colour8Bit,
    /// Σ' rebuilt from eigenvalues `mid ± √max(0.1, mid² − det)`, and dropped when the smaller
    /// is ≤ 0 (GaussianSplats3D's vertex shader): near-round footprints come out slightly
    /// anisotropic, sub-pixel splats vanish.
    EigenvalueFloor,
}

impl Variant {
    /// All of them.
    pub const ALL: [Variant; 11] = [
        Variant::BoxCut,
        Variant::ViewDepthOrder,
        Variant::AaCompensation,
        Variant::ShDegree0,
        Variant::ShDegree1,
        Variant::ShDegree2,
        Variant::QuatWxyz,
        Variant::LogScale,
        Variant::SigmoidColour,
        Variant::Colour8Bit,
        Variant::EigenvalueFloor,
    ];
    /// A short identifier (the diagnosis's `rule`).
    pub fn name(self) -> &'static str {
        match self {
            Variant::BoxCut => "bounding_box_cutoff",
            Variant::ViewDepthOrder => "view_depth_order",
            Variant::AaCompensation => "antialiasing_compensation",
            Variant::ShDegree0 => "sh_ignored_above_degree_0",
            Variant::ShDegree1 => "sh_ignored_above_degree_1",
            Variant::ShDegree2 => "sh_ignored_above_degree_2",
            Variant::QuatWxyz => "quaternion_read_as_wxyz",
            Variant::LogScale => "scale_read_as_log",
            Variant::SigmoidColour => "sigmoid_colour",
            Variant::Colour8Bit => "colour_and_opacity_8bit",
            Variant::EigenvalueFloor => "eigenvalue_floor",
        }
    }
    /// What a renderer with this variant does, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Variant::BoxCut => "splats cut by a 3.33σ bounding box instead of the 3σ ellipse",
            Variant::ViewDepthOrder => {
                "splats ordered by view depth (camera-space z) instead of distance to the camera"
            }
            Variant::AaCompensation => {
                "opacity scaled by √(det Σ' / det(Σ' + 0.3 I)) (antialiased kernel)"
            }
            Variant::ShDegree0 => "SH coefficients above degree 0 ignored",
            Variant::ShDegree1 => "SH coefficients above degree 1 ignored",
            Variant::ShDegree2 => "SH coefficients above degree 2 ignored",
            Variant::QuatWxyz => "ROTATION read as (w, x, y, z) instead of (x, y, z, w)",
            Variant::LogScale => "SCALE read as ln(scale) (the review draft) instead of linear",
            Variant::SigmoidColour => "colour = sigmoid(Σ SH·Y) instead of Σ SH·Y + 0.5",
            Variant::Colour8Bit => {
                "DC colour and opacity stored in 8 bits, rounded down (lossy storage)"
            }
            Variant::EigenvalueFloor => {
                "Σ' rebuilt from eigenvalues mid ± √max(0.1, mid² − det) (near-round footprints anisotropic, sub-pixel splats dropped)"
            }
        }
    }
    /// The RC section whose rule the variant departs from.
    pub fn rc_section(self) -> &'static str {
        match self {
            Variant::BoxCut => "RC Ellipse Kernel Rendering (3σ cut-off)",
            Variant::ViewDepthOrder => "RC Sorting Method (cameraDistance)",
            Variant::AaCompensation => "RC Ellipse Kernel Rendering (α = opacity · G(x))",
            Variant::ShDegree0 | Variant::ShDegree1 | Variant::ShDegree2 => {
                "RC Splat Projection: \"Implementations MAY ignore higher-degree coefficients\""
            }
            Variant::QuatWxyz => "RC Attributes (ROTATION: xyzw, the usual glTF order)",
            Variant::LogScale => "RC Attributes (SCALE: linear)",
            Variant::SigmoidColour => "RC Lighting (colour = Σ SH·Y + 0.5)",
            Variant::Colour8Bit => {
                "RC Attributes (float SH, OPACITY); the RC does not specify a renderer's precision"
            }
            Variant::EigenvalueFloor => "RC Splat Projection (Σ' = J W Σ Wᵀ Jᵀ)",
        }
    }
    /// Whether the RC allows it: an image that matches it passes.
    pub fn rc_allowed(self) -> bool {
        matches!(
            self,
            Variant::ShDegree0 | Variant::ShDegree1 | Variant::ShDegree2
        )
    }
    /// Whether it is only a precision the RC does not specify (8-bit storage): every asset's
    /// bound admits it, so an image with it passes.
    pub fn precision_only(self) -> bool {
        self == Variant::Colour8Bit
    }
    /// The highest SH degree evaluated (3: all).
    fn sh_cap(v: &[Variant]) -> usize {
        [
            (Variant::ShDegree0, 0),
            (Variant::ShDegree1, 1),
            (Variant::ShDegree2, 2),
        ]
        .into_iter()
        .filter(|(x, _)| v.contains(x))
        .map(|(_, d)| d)
        .min()
        .unwrap_or(3)
    }
}

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
    /// [`Variant::BoxCut`]: the box's half axes (pixels), `None` for the ellipse cut.
    box_axes: Option<[[f64; 2]; 2]>,
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
    /// Deviations an asset admits because it does not test them (set by the generator, not by
    /// [`render`]; isolation): the difference the model shows without the 0.3 px² dilation,
    pub dilation: f64,
    /// …with another cut-off shape (2.83σ, a 3.33σ bounding box),
    pub cutoff_shape: f64,
    /// …with splats ordered by view depth,
    pub sort_order: f64,
    /// …and with the DC colour and the opacity stored in 8 bits (rounded down).
    pub colour_8bit: f64,
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
            + self.cutoff_shape
            + self.sort_order
            + self.colour_8bit
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
            cutoff_shape: self.cutoff_shape.max(o.cutoff_shape),
            sort_order: self.sort_order.max(o.sort_order),
            colour_8bit: self.colour_8bit.max(o.colour_8bit),
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
    /// Per pixel, the admitted-deviation terms (`dilation`, `cutoff_shape`, `sort_order`)
    /// the generator added to `bound`.
    pub extra: Vec<Terms>,
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

fn colour(cloud: &SplatCloud, i: usize, dir: [f64; 3], e: bool, v: &[Variant]) -> ([f64; 3], f64) {
    let cap = Variant::sh_cap(v);
    let all = cloud.sh_of(i);
    let coeffs = &all[..all.len().min((cap + 1) * (cap + 1))];
    let y = if e {
        appendix_basis(dir)
    } else {
        crate::sh::basis(dir)
    };
    let mut sum = [0.0f64; 3];
    let mut f16 = 0.0f64;
    let eight = v.contains(&Variant::Colour8Bit) && !e;
    for (k, c) in coeffs.iter().enumerate() {
        if k == 0 && eight {
            // floor(255·clamp(SH_C0·DC + 0.5)) / 255, less the bias added back below.
            for ch in 0..3 {
                let dc = (y[0] * c[ch] as f64 + crate::profile::SH_DC_BIAS).clamp(0.0, 1.0);
                sum[ch] += (dc * 255.0).floor() / 255.0 - crate::profile::SH_DC_BIAS;
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
    let f16_err = f16 * 2f64.powi(-11);
    let c = if e || v.contains(&Variant::SigmoidColour) {
        sum.map(|v| 1.0 / (1.0 + (-v).exp()))
    } else {
        sum.map(|v| (v + crate::profile::SH_DC_BIAS).max(0.0))
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
}

impl View<'_> {
    fn on(&self, e: Erratum) -> bool {
        self.errata.contains(&e)
    }
    fn var(&self, v: Variant) -> bool {
        self.vars.contains(&v)
    }
}

fn project(cloud: &SplatCloud, cam: &Camera, x: &[Erratum], vars: &[Variant]) -> Vec<Layer> {
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
    };
    let mode = if view.var(Variant::ViewDepthOrder) {
        SortMode::ViewDepth
    } else {
        SortMode::Distance
    };
    let mut order = back_to_front(&cloud.positions, cam, mode);
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
    let (fx, fy, cx, cy) = (cam.fx as f64, cam.fy as f64, cam.cx as f64, cam.cy as f64);
    let txtz = (t.x / t.z).clamp(-view.lim[0], view.lim[0]);
    let tytz = (t.y / t.z).clamp(-view.lim[1], view.lim[1]);
    let j0 = DVec3::new(fx / t.z, 0.0, -fx * txtz / t.z);
    let j1 = DVec3::new(0.0, fy / t.z, -fy * tytz / t.z);
    let m = c_matrix(scale, q).transpose() * view.w.transpose();
    let (p0, p1) = (m * j0, m * j1);
    let d = if view.on(Erratum::I) {
        0.0
    } else {
        DILATION_PX2
    };
    let (mut a, mut b, mut cc) = (p0.dot(p0) + d, p0.dot(p1), p1.dot(p1) + d);
    let mut det = p0.cross(p1).length_squared() + d * (p0.dot(p0) + p1.dot(p1)) + d * d;
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    if view.var(Variant::EigenvalueFloor) {
        [a, b, cc, det] = eigenvalue_floor(a, b, cc, det)?;
    }
    let (u, v) = (fx * t.x / t.z + cx, fy * t.y / t.z + cy);
    let dir = (mean - view.eye).normalize().to_array();
    let (color, f16_err) = colour(cloud, i, dir, view.on(Erratum::E), view.vars);
    let mut opacity = cloud.opacities[i] as f64;
    if view.var(Variant::Colour8Bit) {
        opacity = (opacity * 255.0).floor() / 255.0;
    }
    if view.var(Variant::AaCompensation) {
        let det0 = p0.cross(p1).length_squared();
        opacity *= (det0 / det).max(0.0).sqrt();
    }
    let box_axes = view.var(Variant::BoxCut).then(|| box_half_axes(a, b, cc));
    let (rx, ry) = (3.0 * a.sqrt(), 3.0 * cc.sqrt());
    let (centre, rect) = if view.on(Erratum::D) {
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
    } else if let Some([e1, e2]) = box_axes {
        let (hx, hy) = (e1[0].abs() + e2[0].abs(), e1[1].abs() + e2[1].abs());
        ([u, v], [u - hx, u + hx, v - hy, v + hy])
    } else {
        ([u, v], [u - rx, u + rx, v - ry, v + ry])
    };
    Some(Layer {
        centre,
        conic: [cc / det, -b / det, a / det],
        opacity,
        color,
        f16_err,
        rect,
        box_axes,
    })
}

/// [`Variant::EigenvalueFloor`]: Σ' = [[a, b], [b, c]] rebuilt from the floored eigenvalues
/// and the eigenvector `normalize(b, λ₁ − a)` (axis-aligned when that is degenerate); `None`
/// when the smaller eigenvalue is ≤ 0. Returns `[a, b, c, det]`.
fn eigenvalue_floor(a: f64, b: f64, c: f64, det: f64) -> Option<[f64; 4]> {
    let mid = 0.5 * (a + c);
    let r = (mid * mid - det).max(0.1).sqrt();
    let (l1, l2) = (mid + r, mid - r);
    if l2 <= 0.0 {
        return None;
    }
    let e1 = major_axis(a, b, c, l1);
    let e2 = [-e1[1], e1[0]];
    Some([
        l1 * e1[0] * e1[0] + l2 * e2[0] * e2[0],
        l1 * e1[0] * e1[1] + l2 * e2[0] * e2[1],
        l1 * e1[1] * e1[1] + l2 * e2[1] * e2[1],
        l1 * l2,
    ])
}

/// The unit eigenvector of [[a, b], [b, c]] for its larger eigenvalue `l1`: `(b, l1 − a)`
/// normalised, or the axis of the larger diagonal entry when `b` is 0 (to rounding).
fn major_axis(a: f64, b: f64, c: f64, l1: f64) -> [f64; 2] {
    if b.abs() > 1e-12 * (a.abs() + c.abs()) {
        let (x, y) = (b, l1 - a);
        let n = (x * x + y * y).sqrt();
        [x / n, y / n]
    } else if a >= c {
        [1.0, 0.0]
    } else {
        [0.0, 1.0]
    }
}

/// The half axes (pixels) of the 3.33σ box of Σ' = [[a, b], [b, c]]: its eigenvectors
/// scaled by 3.33·√λ.
fn box_half_axes(a: f64, b: f64, c: f64) -> [[f64; 2]; 2] {
    let (mid, half) = (0.5 * (a + c), (0.25 * (a - c) * (a - c) + b * b).sqrt());
    let (l1, l2) = (mid + half, (mid - half).max(0.0));
    let e1 = major_axis(a, b, c, l1);
    let e2 = [-e1[1], e1[0]];
    let k = 3.33;
    [
        [k * l1.sqrt() * e1[0], k * l1.sqrt() * e1[1]],
        [k * l2.sqrt() * e2[0], k * l2.sqrt() * e2[1]],
    ]
}

/// Renders `cloud` (global space, as loaded) from `cam` over a black background with the
/// errata `x` switched on; with `x` empty also computes the per-pixel bound.
pub fn render(cloud: &SplatCloud, cam: &Camera, x: &[Erratum]) -> ModelImage {
    render_with(cloud, cam, x, &[])
}

/// [`render`] with implementation [`Variant`]s `v` switched on too.
pub fn render_with(cloud: &SplatCloud, cam: &Camera, x: &[Erratum], v: &[Variant]) -> ModelImage {
    let layers = project(cloud, cam, x, v);
    let linear = cloud.meta.color_space.effective() == ColorSpace::LinRec709Display;
    let blend = Blending {
        cut: if x.contains(&Erratum::F) {
            8.0
        } else {
            CUTOFF_M2 as f64
        },
        no_cap: x.contains(&Erratum::K),
        alpha_squared: x.contains(&Erratum::G),
    };
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut image = Image::filled(cam.width, cam.height, [0.0, 0.0, 0.0, 1.0]);
    let mut bound = vec![0.0; w * h];
    let mut worst = Terms::default();
    for py in 0..h {
        for px in 0..w {
            let (c, a, mut t) = shade(&layers, (px as f64 + 0.5, py as f64 + 0.5), &blend);
            let disp = c.map(|v| if linear { srgb_encode(v) } else { v }.clamp(0.0, 1.0));
            if linear {
                through_srgb_curve(&mut t, c);
            }
            let i = py * w + px;
            image.pixels[i] = [disp[0] as f32, disp[1] as f32, disp[2] as f32, a as f32];
            bound[i] = t.total();
            worst = worst.max(t);
        }
    }
    ModelImage {
        extra: vec![Terms::default(); bound.len()],
        image,
        bound,
        worst,
    }
}

/// How the layers are blended: the cut-off (Mahalanobis²), and the errata k (no α cap) and g
/// (α² weighting).
struct Blending {
    cut: f64,
    no_cap: bool,
    alpha_squared: bool,
}

/// One pixel centre: the blended linear colour, the alpha and the error terms, walking the
/// layers in blending order.
fn shade(layers: &[Layer], (xc, yc): (f64, f64), b: &Blending) -> ([f64; 3], f64, Terms) {
    let q = 0.5 / 255.0;
    let cut = b.cut;
    let (mut c, mut a) = ([0.0f64; 3], 0.0f64);
    let mut t = Terms {
        output: q,
        ..Default::default()
    };
    let mut layers_here = 0usize;
    for l in layers {
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
        let inside = match l.box_axes {
            // Inside the box: |d·eₖ| ≤ |half axis k| for both axes.
            Some(ax) => ax.iter().all(|h| {
                let n2 = h[0] * h[0] + h[1] * h[1];
                (dx * h[0] + dy * h[1]).abs() <= n2 + 1e-12
            }),
            None => (0.0..=cut).contains(&m2),
        };
        if !inside {
            continue;
        }
        let alpha = if b.no_cap {
            raw
        } else {
            raw.min(ALPHA_MAX as f64)
        };
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
        let wgt = if b.alpha_squared {
            alpha * alpha
        } else {
            alpha
        };
        for (v, lc) in c.iter_mut().zip(l.color) {
            *v = lc * wgt + *v * (1.0 - alpha);
        }
        a = wgt + a * (1.0 - alpha);
    }
    // UNORM8 blending rounds the fragment output (c·α, α) to 8 bits and the result again:
    // two half-steps per blended splat.
    t.blend = 2.0 * q * layers_here as f64;
    t.float = 1e-5 * (layers_here + 1) as f64;
    (c, a, t)
}

/// For `lin_rec709_display`: the α-convention terms act on linear values, so their interval
/// around the pixel's linear colour `c` is mapped through the sRGB curve (the rounding terms
/// are already in encoded units).
fn through_srgb_curve(t: &mut Terms, c: [f64; 3]) {
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
