//! Footprint geometry of two variants: GaussianSplats3D's eigenvalue floor and the 3.33σ
//! bounding box (Σ' = [[a, b], [b, c]] in pixels²).

/// [`Variant::EigenvalueFloor`]: Σ' = [[a, b], [b, c]] rebuilt from the floored eigenvalues
/// and the eigenvector `normalize(b, λ₁ − a)` (axis-aligned when that is degenerate), taken
/// at `axis` ∈ [0, 1] of the angles f32 rounding allows it (`None`: the representative one,
/// [`f32_major_axis`]); `None` when the smaller eigenvalue is ≤ 0. Returns `[a, b, c, det]`.
pub(super) fn eigenvalue_floor(
    a: f64,
    b: f64,
    c: f64,
    det: f64,
    axis: Option<f64>,
) -> Option<[f64; 4]> {
    let mid = 0.5 * (a + c);
    let r = (mid * mid - det).max(0.1).sqrt();
    let (l1, l2) = (mid + r, mid - r);
    if l2 <= 0.0 {
        return None;
    }
    let e1 = match axis {
        None => f32_major_axis(a, b, c, l1, mid),
        Some(at) => f32_axis_within_rounding(a, b, c, l1, mid, at),
    };
    let e2 = [-e1[1], e1[0]];
    Some([
        l1 * e1[0] * e1[0] + l2 * e2[0] * e2[0],
        l1 * e1[0] * e1[1] + l2 * e2[0] * e2[1],
        l1 * e1[1] * e1[1] + l2 * e2[1] * e2[1],
        l1 * l2,
    ])
}

/// [`Variant::AxesSwapped`](super::Variant::AxesSwapped): Σ' = [[a, b], [b, c]] rebuilt as
/// Babylon.js 9 does (Shaders/ShadersInclude/gaussianSplatting.js, `gaussianSplatting()`):
/// eigenvalues `mid ± r + 10⁻⁴`, major axis `normalize(b, λ₁ − a)`, which is vertical
/// whatever the footprint's shape when `|b|` ≪ 10⁻⁴; `None` when `λ₂` < 0 (dropped there
/// too). Returns `[a, b, c, det]`.
pub(super) fn babylon_axes(a: f64, b: f64, c: f64) -> Option<[f64; 4]> {
    const EPS: f64 = 1e-4;
    let mid = 0.5 * (a + c);
    let r = (0.5 * (a - c)).hypot(b);
    let (l1, l2) = (mid + r + EPS, mid - r + EPS);
    if l2 < 0.0 {
        return None;
    }
    let (x, y) = (b, l1 - a);
    let n = x.hypot(y);
    let e1 = [x / n, y / n];
    let e2 = [e1[1], -e1[0]];
    Some([
        l1 * e1[0] * e1[0] + l2 * e2[0] * e2[0],
        l1 * e1[0] * e1[1] + l2 * e2[0] * e2[1],
        l1 * e1[1] * e1[1] + l2 * e2[1] * e2[1],
        l1 * l2,
    ])
}

/// Where in [`f32_axis_within_rounding`]'s range the `eigenvalue_floor` term samples the
/// major axis: its ends, its middle and between (the image changes with the angle as a
/// sinusoid of twice it, so a range of up to ~120° needs more than its ends).
pub(crate) const AXIS_SAMPLES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// The major axis GaussianSplats3D's vertex shader takes, `normalize(vec2(b, λ₁ − a))` in
/// f32 (build/gaussian-splats-3d.module.js 0.4.7, lines 8210–8222). Its `λ₁ − a` carries the
/// rounding of `mid² − det` ([`axis_noise`]), so where `|b|` is below that noise the vector is
/// vertical: a near-round footprint a little wider than tall is drawn with its axes swapped,
/// and one the floor lifts (`λ₁ − a` > 0) is vertical as well. An exactly axis-aligned
/// footprint (`b` = 0) is GS3D's degenerate case, which scripts/conformance/gs3d.mjs avoids
/// by rolling each camera [`ADAPTER_ROLL`] rad: the model takes `b` to be at least what that
/// roll gives, `ADAPTER_ROLL·|a − c|`, so only footprints within a few per cent of round
/// (|a − c| ≲ 0.07·mid) swap, as GS3D's do.
fn f32_major_axis(a: f64, b: f64, c: f64, l1: f64, mid: f64) -> [f64; 2] {
    let noise = axis_noise(l1, mid);
    let b_seen = b.abs().max(ADAPTER_ROLL * (a - c).abs());
    if b_seen <= noise {
        [0.0, 1.0]
    } else if b.abs() > 1e-12 * (a.abs() + c.abs()) {
        let (x, y) = (b, l1 - a);
        let n = (x * x + y * y).sqrt();
        [x / n, y / n]
    } else if l1 - a > 1e-12 * l1 {
        [0.0, 1.0]
    } else {
        [1.0, 0.0]
    }
}

/// How far f32 rounding may move GaussianSplats3D's `λ₁ − a`: `mid² − det` carries about
/// 2⁻²¹·mid² (the rounding of `mid²`, `a·d` and their difference, with margin), which the
/// square root turns into that over 2(λ₁ − mid); and λ₁ and `a` an ulp or two each.
fn axis_noise(l1: f64, mid: f64) -> f64 {
    2f64.powi(-21) * mid * mid / (2.0 * (l1 - mid)) + 2f64.powi(-22) * l1
}

/// The major axis at `at` ∈ [0, 1] of the angles `normalize(vec2(b, λ₁ − a ± noise))`
/// takes as the rounding of [`axis_noise`] runs over its range, `b` at least what the
/// adapter's roll gives (see [`f32_major_axis`]). Where `|b|` is well above the noise the
/// range is a sliver around the exact axis; where it is comparable, a tilted near-round
/// footprint's axis may come out at any angle in it (GaussianSplats3D's `color0_fallback`
/// fringe: b ≈ 4·10⁻⁴, noise ≈ 7·10⁻⁴, axis anywhere within ±60° of the exact one).
fn f32_axis_within_rounding(a: f64, b: f64, c: f64, l1: f64, mid: f64, at: f64) -> [f64; 2] {
    let noise = axis_noise(l1, mid);
    // (b, y) and (−b, −y) are the same axis: take x ≥ 0 so the range never wraps at ±π.
    let x = b.abs().max(ADAPTER_ROLL * (a - c).abs());
    let y = if b < 0.0 { a - l1 } else { l1 - a };
    if x == 0.0 {
        return f32_major_axis(a, b, c, l1, mid); // exactly round and unrolled: no angle
    }
    let (lo, hi) = ((y - noise).atan2(x), (y + noise).atan2(x));
    let t = lo + at.clamp(0.0, 1.0) * (hi - lo);
    [t.cos(), t.sin()]
}

/// The roll (radians) scripts/conformance/gs3d.mjs gives each camera by default (`GS3D_ROLL`).
const ADAPTER_ROLL: f64 = 1e-4;

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

/// How many σ the half axes of [`Variant::BoxCut`](super::Variant::BoxCut)'s box reach.
pub(super) const BOX_SIGMA: f64 = 3.33;
/// …and those of [`Variant::SquareCut`](super::Variant::SquareCut)'s square (2√2).
pub(super) const SQUARE_SIGMA: f64 = 2.0 * std::f64::consts::SQRT_2;

/// The half axes (pixels) of the `k`σ box of Σ' = [[a, b], [b, c]]: its eigenvectors
/// scaled by k·√λ.
pub(super) fn box_half_axes(a: f64, b: f64, c: f64, k: f64) -> [[f64; 2]; 2] {
    let (mid, half) = (0.5 * (a + c), (0.25 * (a - c) * (a - c) + b * b).sqrt());
    let (l1, l2) = (mid + half, (mid - half).max(0.0));
    let e1 = major_axis(a, b, c, l1);
    let e2 = [-e1[1], e1[0]];
    [
        [k * l1.sqrt() * e1[0], k * l1.sqrt() * e1[1]],
        [k * l2.sqrt() * e2[0], k * l2.sqrt() * e2[1]],
    ]
}
