//! A small f64 model of the rendering profile with each observable Appendix A erratum as a
//! switch, and the per-pixel error bound the tolerances are derived from.
//!
//! It is written from `docs/rendering-profile.md` and `docs/appendix-errata.md`, sharing only
//! the SH basis, the covariance factor and the sort with the reference ([`splatgl::reference`]);
//! with no erratum switched on it reproduces the reference to f32 rounding (tested). With a
//! switch on it renders what a renderer with that erratum draws, which is how the suite
//! *derives* which assets catch which erratum (`catches` in the manifest): an asset catches
//! erratum x when the model's image with x fails the asset's tolerance. The erratum proof
//! test then renders the suite with the GL backend's own `#define ERRATUM_x` switches and
//! checks that the runner fails exactly those assets.

use super::Erratum;
use splatgl::camera::Camera;
use splatgl::cloud::{ColorSpace, SplatCloud};
use splatgl::image::Image;
use splatgl::profile::srgb_encode;
use splatgl::profile::{ALPHA_MAX, ALPHA_MIN, CUTOFF_M2, DILATION_PX2};

mod choices;
mod footprint;
mod project;
mod quantized;
mod terms;
mod variant;
pub use choices::{Choices, Extent, render_choices};
pub(crate) use footprint::AXIS_SAMPLES as axis_samples;
pub(crate) use project::project;
pub(crate) use quantized::spz as spz_copy;
pub use terms::Terms;
pub use variant::Variant;

/// One projected splat.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layer {
    /// The splat's index in the cloud.
    pub(crate) index: usize,
    /// Where the Gaussian is evaluated (pixels, y down).
    pub(crate) centre: [f64; 2],
    /// Σ' `[xx, xy, yy]` (dilated; pixels²).
    pub(crate) cov: [f64; 3],
    /// Σ'⁻¹ `[xx, xy, yy]`.
    pub(crate) conic: [f64; 3],
    pub(crate) opacity: f64,
    pub(crate) color: [f64; 3],
    /// Colour error of f16 SH storage: Σₖ maxₓ|coefₖ·Yₖ|·2⁻¹¹ (bound term).
    f16_err: f64,
    /// Pixels `[x0, x1] × [y0, y1]` (centres, inclusive float bounds) the splat may touch.
    rect: [f64; 4],
    /// [`Variant::BoxCut`] or [`Variant::SquareCut`]: the half axes (pixels) of the box, `None` for the ellipse cut.
    box_axes: Option<[[f64; 2]; 2]>,
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
    /// Per pixel, the admitted-deviation terms (`dilation`, `colour_8bit`, …)
    /// the generator added to `bound`.
    pub extra: Vec<Terms>,
    /// Per pixel, the `overbright` term of `bound` (what an 8-bit target's clamping of
    /// colours above 1 may change): an asset that tests float blending takes it out.
    pub overbright: Vec<f64>,
}

/// 3DGS stops blending a pixel before its transmittance falls below this.
const EARLY_STOP_T: f64 = 1e-4;

/// Relative width of the band around the 3σ cut and the α threshold where f32 and f64
/// (or two implementations' operation orders) can disagree.
const EDGE_BAND: f64 = 1e-4;

/// Renders `cloud` (global space, as loaded) from `cam` over a black background with the
/// errata `x` switched on; with `x` empty also computes the per-pixel bound.
pub fn render(cloud: &SplatCloud, cam: &Camera, x: &[Erratum]) -> ModelImage {
    render_with(cloud, cam, x, &[])
}

/// [`render`] with implementation [`Variant`]s `v` switched on too.
pub fn render_with(cloud: &SplatCloud, cam: &Camera, x: &[Erratum], v: &[Variant]) -> ModelImage {
    render_with_axis(cloud, cam, x, v, None)
}

/// [`render_with`], with [`Variant::EigenvalueFloor`]'s major axis taken at `axis` ∈ [0, 1]
/// of the angles f32 rounding allows it ([`axis_samples`]; `None`: the representative axis).
pub(crate) fn render_with_axis(
    cloud: &SplatCloud,
    cam: &Camera,
    x: &[Erratum],
    v: &[Variant],
    axis: Option<f64>,
) -> ModelImage {
    render_with_dilation(cloud, cam, (x, v), axis, DILATION_PX2)
}

/// [`render_with_axis`] with Σ' dilated by `dilation` px² instead of the profile's 0.3
/// (erratum i still sets it to 0).
pub(crate) fn render_with_dilation(
    cloud: &SplatCloud,
    cam: &Camera,
    (x, v): (&[Erratum], &[Variant]),
    axis: Option<f64>,
    dilation: f64,
) -> ModelImage {
    let quantized = if v.contains(&Variant::SpzPrecision) {
        quantized::spz(cloud)
    } else if v.contains(&Variant::PackedSplat) {
        Some(quantized::packed(cloud, cam.eye().to_array()))
    } else if v.contains(&Variant::Attributes8Bit) {
        Some(quantized::babylon(cloud))
    } else if v.contains(&Variant::ScaleLog8) {
        Some(quantized::playcanvas(cloud))
    } else {
        None
    };
    let cloud = quantized.as_ref().unwrap_or(cloud);
    let layers = project(cloud, cam, (x, v), axis, dilation);
    let linear = cloud.meta.color_space.effective() == ColorSpace::LinRec709Display
        && !v.contains(&Variant::ColorSpaceIgnored);
    let blend = Blending {
        cut: if x.contains(&Erratum::F) || v.contains(&Variant::NormalizedKernel) {
            8.0
        } else {
            CUTOFF_M2 as f64
        },
        cap: if x.contains(&Erratum::K) {
            f64::INFINITY
        } else {
            ALPHA_MAX as f64
        },
        alpha_squared: x.contains(&Erratum::G),
        // CesiumJS's square quads draw every fragment they cover: no 1/255 skip.
        every_fragment: v.contains(&Variant::SquareCut),
        normalized_kernel: v.contains(&Variant::NormalizedKernel),
        unorm: v.contains(&Variant::Unorm8Blending),
        early_stop: false,
        extent: Extent::Ellipse,
    };
    shade_image(&layers, cam, &blend, linear)
}

/// The image of `layers` blended by `blend` (display-referred, sRGB-encoded when `linear`),
/// with the per-pixel bound of the exact profile.
fn shade_image(layers: &[Layer], cam: &Camera, blend: &Blending, linear: bool) -> ModelImage {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut image = Image::filled(cam.width, cam.height, [0.0, 0.0, 0.0, 1.0]);
    let mut bound = vec![0.0; w * h];
    let mut overbright = vec![0.0; w * h];
    let mut worst = Terms::default();
    for py in 0..h {
        for px in 0..w {
            let (c, a, mut t) = shade(layers, (px as f64 + 0.5, py as f64 + 0.5), blend);
            let disp = c.map(|v| if linear { srgb_encode(v) } else { v }.clamp(0.0, 1.0));
            if linear {
                through_srgb_curve(&mut t, c);
            }
            let i = py * w + px;
            image.pixels[i] = [disp[0] as f32, disp[1] as f32, disp[2] as f32, a as f32];
            bound[i] = t.total();
            overbright[i] = t.overbright;
            worst = worst.max(t);
        }
    }
    ModelImage {
        extra: vec![Terms::default(); bound.len()],
        image,
        bound,
        worst,
        overbright,
    }
}

/// How the layers are blended: the cut-off (Mahalanobis²) of the ellipse extent, the α cap
/// (erratum k: none), erratum g (α² weighting), whether fragments under the 1/255 threshold
/// are drawn too, whether blending stops where T would fall below 10⁻⁴ (3DGS), and the
/// extent of a splat ([`Extent`]).
struct Blending {
    cut: f64,
    cap: f64,
    alpha_squared: bool,
    every_fragment: bool,
    /// [`Variant::NormalizedKernel`]: α = opacity·(G − e⁻⁴)/(1 − e⁻⁴).
    normalized_kernel: bool,
    /// [`Variant::Unorm8Blending`]: colour sums clamped to 1 between blends.
    unorm: bool,
    early_stop: bool,
    extent: Extent,
}

/// Layer `l` at pixel centre `p`: `None` outside its rectangle; else its Mahalanobis² and
/// uncapped α, and whether it is drawn there (inside its extent, and not skipped as α < 1/255).
fn fragment(l: &Layer, (xc, yc): (f64, f64), b: &Blending) -> Option<(f64, f64, bool, bool)> {
    let [x0, x1, y0, y1] = l.rect;
    if xc < x0 || xc > x1 || yc < y0 || yc > y1 {
        return None;
    }
    let (dx, dy) = (xc - l.centre[0], yc - l.centre[1]);
    let m2 = l.conic[0] * dx * dx + 2.0 * l.conic[1] * dx * dy + l.conic[2] * dy * dy;
    let g = (-0.5 * m2).exp();
    let raw = if b.normalized_kernel {
        let e4 = (-4.0f64).exp();
        l.opacity * ((g - e4) / (1.0 - e4)).max(0.0)
    } else {
        l.opacity * g
    };
    let inside = match (l.box_axes, b.extent) {
        // Inside the box: |d·eₖ| ≤ |half axis k| for both axes.
        (Some(ax), _) => ax.iter().all(|h| {
            let n2 = h[0] * h[0] + h[1] * h[1];
            (dx * h[0] + dy * h[1]).abs() <= n2 + 1e-12
        }),
        (None, Extent::Ellipse) => (0.0..=b.cut).contains(&m2),
        (None, e) => e.contains(l, (xc, yc)),
    };
    let drawn = inside && (raw.min(b.cap) >= ALPHA_MIN as f64 || b.every_fragment);
    Some((m2, raw, inside, drawn))
}

/// With [`Blending::early_stop`]: the index of the layer (blending order, back to front) at
/// which 3DGS stops at pixel `p` — walking front to back, the first drawn layer that would
/// take T below 10⁻⁴; it and every layer behind it are not blended.
fn early_stop_at(layers: &[Layer], p: (f64, f64), b: &Blending) -> Option<usize> {
    let mut t = 1.0f64;
    for (i, l) in layers.iter().enumerate().rev() {
        let Some((_, raw, _, true)) = fragment(l, p, b) else {
            continue;
        };
        let alpha = raw.min(b.cap);
        if t * (1.0 - alpha) < EARLY_STOP_T {
            return Some(i);
        }
        t *= 1.0 - alpha;
    }
    None
}

/// One pixel centre: the blended linear colour, the alpha and the error terms, walking the
/// layers in blending order.
fn shade(layers: &[Layer], p: (f64, f64), b: &Blending) -> ([f64; 3], f64, Terms) {
    let q = 0.5 / 255.0;
    let cut = b.cut;
    let (mut c, mut a) = ([0.0f64; 3], 0.0f64);
    let mut t = Terms {
        output: q,
        ..Default::default()
    };
    let stop = if b.early_stop {
        early_stop_at(layers, p, b)
    } else {
        None
    };
    let mut layers_here = 0usize;
    // What each drawn layer contributes, uncapped, for the early-stop term.
    let mut drawn_here: Vec<(f64, [f64; 3])> = Vec::new();
    for (i, l) in layers.iter().enumerate() {
        let Some((m2, raw, inside, drawn)) = fragment(l, p, b) else {
            continue;
        };
        if (m2 - cut).abs() <= EDGE_BAND * cut {
            t.cutoff += raw.min(ALPHA_MAX as f64);
        }
        if !inside {
            continue;
        }
        let alpha = raw.min(b.cap);
        if raw < ALPHA_MIN as f64 * (1.0 + 10.0 * EDGE_BAND) {
            t.threshold += raw;
        }
        if raw > ALPHA_MAX as f64 * (1.0 - EDGE_BAND) {
            t.cap += (raw.min(1.0) - ALPHA_MAX as f64).max(0.0);
        }
        if !drawn || stop.is_some_and(|s| i <= s) {
            continue;
        }
        layers_here += 1;
        drawn_here.push((raw.min(1.0), l.color));
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
            *v = if b.unorm {
                ((lc * wgt).min(1.0) + *v * (1.0 - alpha)).min(1.0)
            } else {
                lc * wgt + *v * (1.0 - alpha)
            };
        }
        a = wgt + a * (1.0 - alpha);
    }
    // UNORM8 blending rounds the fragment output (c·α, α) to 8 bits and the result again:
    // two half-steps per blended splat.
    t.blend = 2.0 * q * layers_here as f64;
    t.float = 1e-5 * (layers_here + 1) as f64;
    t.early_stop = early_stop_change(&drawn_here);
    (c, a, t)
}

/// The most a stop at T < 10⁻⁴ (3DGS) changes a pixel whose drawn layers are `drawn` (back to
/// front; α uncapped, colour), under each admitted α cap (0.99, 0.999, 1): with α up to 1 a nearly
/// opaque layer can end the blending while much transmittance is left.
fn early_stop_change(drawn: &[(f64, [f64; 3])]) -> f64 {
    // `drawn` is back to front; 3DGS walks front to back.
    let walk = |cap: f64, stop: bool| {
        let (mut c, mut t) = ([0.0f64; 3], 1.0f64);
        for &(raw, col) in drawn.iter().rev() {
            let a = raw.min(cap);
            if stop && t * (1.0 - a) < EARLY_STOP_T {
                break;
            }
            for (v, lc) in c.iter_mut().zip(col) {
                *v += lc * a * t;
            }
            t *= 1.0 - a;
        }
        c
    };
    [ALPHA_MAX as f64, 0.999, 1.0]
        .into_iter()
        .map(|cap| {
            let (a, b) = (walk(cap, false), walk(cap, true));
            (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// For `lin_rec709_display`: the α-convention terms act on linear values, so their interval
/// around the pixel's linear colour `c` is mapped through the sRGB curve (the rounding terms
/// are already in encoded units).
fn through_srgb_curve(t: &mut Terms, c: [f64; 3]) {
    let lin = t.cutoff + t.threshold + t.cap + t.sh_f16 + t.overbright + t.early_stop;
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
        &mut t.early_stop,
    ] {
        *term *= scale;
    }
}
