//! [`Choices`]: the choices the RC leaves to a renderer, each over the range the kit admits on
//! every asset that does not test it (`docs/conformance.md`, "The RC-silent choices"), and the
//! model rendering a renderer that makes them ([`render_choices`]): the planted-variant proof
//! renders the suite with each row and with combinations of them.

use super::{Blending, Layer, Variant, project, shade_image};
use splatgl::camera::Camera;
use splatgl::cloud::{ColorSpace, SplatCloud};
use splatgl::image::Image;
use splatgl::profile::{ALPHA_MAX, CUTOFF_M2, DILATION_PX2};

/// How far a splat reaches on screen (the RC: "assumes a 3σ cut-off"; how a renderer draws
/// it is its own).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extent {
    /// The 3σ ellipse (Mahalanobis² ≤ 9): splatgl's profile.
    Ellipse,
    /// An axis-aligned box of 3.33σ per screen axis (σ of Σ'ₓₓ and Σ'ᵧᵧ), α ≥ 1/255 inside.
    AxisBox,
    /// A 2√2σ ≈ 2.83σ square along the footprint's axes, corners at 4σ.
    Square,
    /// Tile-granular, as the original 3DGS rasterizer: every 16 × 16 tile that the square of
    /// radius ⌈3·√λmax⌉ around the centre touches, any α ≥ 1/255 inside.
    Tiles,
}

/// σ per axis of [`Extent::AxisBox`].
const AXIS_BOX_SIGMA: f64 = 3.33;
/// The 3DGS rasterizer's tile size (pixels).
const TILE: f64 = 16.0;

impl Extent {
    /// Whether pixel centre `(xc, yc)` lies within layer `l`'s extent (the ellipse's is the
    /// caller's; the square's is the layer's box).
    pub(super) fn contains(self, l: &Layer, (xc, yc): (f64, f64)) -> bool {
        let (dx, dy) = (xc - l.centre[0], yc - l.centre[1]);
        match self {
            Extent::Ellipse | Extent::Square => {
                let [p, q, r] = l.conic;
                p * dx * dx + 2.0 * q * dx * dy + r * dy * dy <= CUTOFF_M2 as f64
            }
            Extent::AxisBox => {
                dx.abs() <= AXIS_BOX_SIGMA * l.cov[0].sqrt()
                    && dy.abs() <= AXIS_BOX_SIGMA * l.cov[2].sqrt()
            }
            Extent::Tiles => {
                let [a, b, c] = l.cov;
                let mid = 0.5 * (a + c);
                let lambda = mid + (mid * mid - (a * c - b * b)).max(0.1).sqrt();
                let r = (3.0 * lambda.sqrt()).ceil();
                // 3DGS's pixel coordinates put pixel centres on integers (ours at +0.5).
                let tile = |v: f64| ((v - 0.5) / TILE).floor();
                let span = |p: f64| {
                    (
                        tile(p - r).max(0.0),
                        ((p - 0.5 + r + TILE - 1.0) / TILE).floor(),
                    )
                };
                let ((x0, x1), (y0, y1)) = (span(l.centre[0]), span(l.centre[1]));
                let (tx, ty) = ((xc / TILE).floor(), (yc / TILE).floor());
                (x0..x1).contains(&tx) && (y0..y1).contains(&ty)
            }
        }
    }
}

/// The choices the RC leaves open, as one renderer makes them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choices {
    /// α cap: 0.99 (3DGS), 0.999, or 1 (none).
    pub alpha_cap: f64,
    /// Contributions with α < 1/255 skipped (3DGS) or drawn.
    pub skip_below_1_255: bool,
    /// Blending of a pixel stops before T falls below 10⁻⁴ (3DGS) or never.
    pub early_stop: bool,
    /// How far a splat reaches.
    pub extent: Extent,
    /// Order by view depth (per tile or global: the same per pixel) instead of distance.
    pub view_depth_order: bool,
    /// Dilation of Σ', 0.1–0.3 px².
    pub dilation: f64,
    /// DC colour and opacity stored in 8 bits (rounded down).
    pub colour_8bit: bool,
    /// The 3D covariance stored as half floats.
    pub covariance_f16: bool,
    /// Blended in an 8-bit target (colour sums above 1 clamped between blends) instead of
    /// floating point.
    pub blending_8bit: bool,
    /// Each splat's colour clamped to 1 before blending.
    pub colour_clamp: bool,
}

impl Choices {
    /// splatgl's profile (3DGS's choices with the ellipse and distance order the RC names).
    pub const PROFILE: Choices = Choices {
        alpha_cap: ALPHA_MAX as f64,
        skip_below_1_255: true,
        early_stop: false,
        extent: Extent::Ellipse,
        view_depth_order: false,
        dilation: DILATION_PX2,
        colour_8bit: false,
        covariance_f16: false,
        blending_8bit: false,
        colour_clamp: false,
    };

    /// The original 3DGS rasterizer: tile-granular extent, view-depth order (per tile), α cap
    /// 0.99, the 1/255 skip, the stop at T < 10⁻⁴, dilation 0.3 px².
    pub const ORIGINAL_3DGS: Choices = Choices {
        early_stop: true,
        extent: Extent::Tiles,
        view_depth_order: true,
        ..Choices::PROFILE
    };

    /// Each choice's admitted alternatives, one at a time (the rows of the docs' table), by
    /// name.
    pub fn rows() -> Vec<(&'static str, Choices)> {
        let row = |name, set: fn(&mut Choices)| {
            let mut c = Choices::PROFILE;
            set(&mut c);
            (name, c)
        };
        vec![
            row("alpha_cap_0.999", |c| c.alpha_cap = 0.999),
            row("alpha_cap_1", |c| c.alpha_cap = 1.0),
            row("no_1_255_skip", |c| c.skip_below_1_255 = false),
            row("early_stop", |c| c.early_stop = true),
            row("extent_axis_box", |c| c.extent = Extent::AxisBox),
            row("extent_square", |c| c.extent = Extent::Square),
            row("extent_tiles", |c| c.extent = Extent::Tiles),
            row("view_depth_order", |c| c.view_depth_order = true),
            row("dilation_0.1", |c| c.dilation = 0.1),
            row("colour_opacity_8bit", |c| c.colour_8bit = true),
            row("covariance_f16", |c| c.covariance_f16 = true),
            row("blending_8bit", |c| c.blending_8bit = true),
            row("colour_clamped_per_splat", |c| c.colour_clamp = true),
        ]
    }

    /// Whether these choices touch the extent or the order, which one asset each tests
    /// (`cutoff_three_sigma`, `sort_distance_not_depth`).
    pub fn tested(&self) -> (bool, bool) {
        (self.extent != Extent::Ellipse, self.view_depth_order)
    }
}

/// What a renderer making `c` draws of `cloud` from `cam` (display-referred RGB, A = 1 − T).
pub fn render_choices(cloud: &SplatCloud, cam: &Camera, c: &Choices) -> Image {
    let mut vars = Vec::new();
    for (on, v) in [
        (c.view_depth_order, Variant::ViewDepthOrder),
        (c.colour_8bit, Variant::Colour8Bit),
        (c.covariance_f16, Variant::HalfCovariance),
        (c.extent == Extent::Square, Variant::SquareCut),
        (c.colour_clamp, Variant::ColourClamped),
    ] {
        if on {
            vars.push(v);
        }
    }
    let mut layers = project(cloud, cam, (&[], &vars), None, c.dilation);
    if matches!(c.extent, Extent::AxisBox | Extent::Tiles) {
        // Their reach is wider than the ellipse's rectangle: every pixel is tested.
        for l in &mut layers {
            l.rect = [
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
            ];
        }
    }
    let blend = Blending {
        cut: CUTOFF_M2 as f64,
        cap: c.alpha_cap,
        alpha_squared: false,
        every_fragment: !c.skip_below_1_255,
        normalized_kernel: false,
        unorm: c.blending_8bit,
        early_stop: c.early_stop,
        extent: c.extent,
    };
    let linear = cloud.meta.color_space.effective() == ColorSpace::LinRec709Display;
    shade_image(&layers, cam, &blend, linear).image
}
