//! The verdict rules of `docs/conformance.md` ("The verdict rules", rules version
//! [`crate::manifest::RULES_VERSION`]), each mapped to the item that applies it:
//!
//! 1. **A camera fails** when a judged pixel's largest RGB error (both images [`clamped`])
//!    exceeds its bound, or the largest judged error exceeds `tolerance.max_abs`, or the PSNR
//!    (unjudged pixels counted as equal) falls below `tolerance.min_psnr`: [`camera_fails`],
//!    from [`measure`] (and [`over_bound`], the pixels counted in the report).
//! 2. **The judged region** leaves out the rims and order overlaps an asset does not test:
//!    [`judged_region`] (`judge.rs`), applied to the bound by [`judge_bound`].
//! 3. **The bound** is the sum of the modelled terms (`model/`, worst case over the admitted
//!    choices); the camera's tolerance follows from it: [`tolerance`].
//! 4. **An asset passes** when all its cameras pass ([`crate::runner::AssetResult::pass`]); only
//!    required RC assets fail a run: [`run_fails`] (the counts: [`crate::report::summary`]).
//! 5. **An image may pass as** the model with SH capped (the RC's "MAY ignore") or with one or
//!    two of the asset's admitted choices: the runner's allowance (`runner/judge.rs`,
//!    `allowed_choice`), said in the camera's `cause`.
//! 6. **Every failing camera is explained** by the smallest set of modelled deviations that
//!    reproduces it, or `unexplained` with the nearest model: [`crate::diagnosis`], applied
//!    over a run by [`crate::runner::diagnosis`].

use super::manifest::Tolerance;
use super::model;
use super::runner::AssetResult;
use splatgl::compare::{Comparison, compare};
use splatgl::image::Image;

pub use super::judge::{apply as judge_bound, judged_region};

/// The measures a camera is judged by: the comparison, and the largest ratio of a pixel's
/// error to its bound.
pub fn measure(img: &Image, want: &Image, bound: &[f64]) -> (Comparison, f64) {
    let (mut a, b) = (clamped(img), clamped(want));
    // Pixels outside the judged region (an infinite bound) count as equal.
    for ((p, q), bd) in a.pixels.iter_mut().zip(&b.pixels).zip(bound) {
        if bd.is_infinite() {
            *p = *q;
        }
    }
    let c = compare(&a, &b, 0.0).expect("same size");
    let ratio = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .zip(bound)
        .map(|((p, q), &bd)| {
            let e = (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0f32, f32::max) as f64;
            if e.is_finite() { e / bd } else { f64::INFINITY }
        })
        .fold(0.0, f64::max);
    (c, ratio)
}

/// How many pixels of `a` differ from `b` by more than their bound (in any channel).
pub fn over_bound(a: &Image, b: &Image, bound: &[f64]) -> usize {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .zip(bound)
        .filter(|((p, q), bd)| {
            bd.is_finite()
                && (0..3).any(|k| {
                    let e = (p[k] - q[k]).abs() as f64;
                    e.is_nan() || e > **bd
                })
        })
        .count()
}

/// Whether `img` fails the camera: a pixel over its bound, the max error over `max_abs` or
/// the PSNR under `min_psnr`.
pub fn fails(img: &Image, want: &Image, bound: &[f64], t: &Tolerance) -> bool {
    let (c, ratio) = measure(img, want, bound);
    ratio > 1.0 || c.max_abs as f64 > t.max_abs || c.psnr < t.min_psnr
}

/// RGB clamped to [0, 1] (what a display and an 8-bit file hold).
pub fn clamped(img: &Image) -> Image {
    let mut out = img.clone();
    for p in &mut out.pixels {
        for c in &mut p[..3] {
            *c = c.clamp(0.0, 1.0);
        }
    }
    out
}

/// The tolerance from the model's per-pixel bound: `max_abs` is the largest bound, and if
/// every pixel's error is within its bound the MSE is at most the mean squared bound.
pub fn tolerance(m: &model::ModelImage) -> Tolerance {
    // Over the judged region (finite bounds); the other pixels count as equal ([`measure`]).
    let judged = || m.bound.iter().copied().filter(|b| b.is_finite());
    let max_abs = judged().fold(0.0, f64::max);
    let mse = judged().map(|b| b * b).sum::<f64>() / m.bound.len().max(1) as f64;
    Tolerance {
        max_abs,
        min_psnr: 10.0 * (1.0 / mse).log10(),
        terms: m.worst,
    }
}

/// Rule 1: whether `img` fails the camera (see [`fails`]).
pub fn camera_fails(img: &Image, want: &Image, bound: &[f64], t: &Tolerance) -> bool {
    fails(img, want, bound, t)
}

/// Rule 4: whether the results fail the run — a required RC asset (not optional, not a
/// profile asset) rendered and failing.
pub fn run_fails(results: &[AssetResult]) -> bool {
    crate::report::summary(results).failed > 0
}
