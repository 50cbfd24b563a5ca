//! Draw orders sorted on a background thread: the newest finished order of an [`AsyncSorter`],
//! drawn while it is stale by no more than a bound ([`StaleBound`], see `docs/viewer.md`). The
//! viewer's frames and [`SplatRenderer::draw_frame`](crate::gl::SplatRenderer::draw_frame)
//! with [`FrameSort::Async`](crate::gl::FrameSort::Async) use it.
//!
//! An order sorted (by `cameraDistance`) for eye `e₀` and drawn from eye `e₁`, `δ = |e₁ − e₀|`:
//! - **exact** when `δ` is within the frame's [`SortedFrame::exact_radius`] (the sorter's
//!   [`Reuse::MotionBound`] proof): a fresh sort would give the same order;
//! - otherwise every pair it draws in the wrong order has distances from `e₁` that differ by
//!   at most `2δ` (each distance changes by at most `δ`, triangle inequality), so the order is
//!   a correct back-to-front order up to a depth tolerance of `2δ`. It is drawn when
//!   `2δ ≤ τ` (the bound's tolerance); beyond that the frame **waits** for the sort of `e₁`.
//!
//! Rotating the camera in place never changes a distance order: only the eye matters.

use std::sync::Arc;

use glam::Vec3;

use super::{AsyncSorter, Reuse, SortRequest, SortedFrame, Sorter};
use crate::cloud::SplatCloud;

/// How stale an order may be before a frame waits for the next sort.
#[derive(Debug, Clone, Copy)]
pub enum StaleBound {
    /// Only provably exact orders ([`SortedFrame::exact_radius`]); any other motion waits.
    Strict,
    /// τ = the median over the drawable splats of their largest standard deviation: orders
    /// are allowed to swap only splats whose centres are closer in distance than a typical
    /// splat's own size, where the centre order of 3DGS is arbitrary anyway (such splats
    /// overlap in depth, and a fresh sort flips them under small motions too).
    Auto,
    /// A fixed τ in world units.
    Distance(f32),
}

/// Equal when the same variant with bit-identical distances (so `Eq` holds for every value,
/// NaN included).
impl PartialEq for StaleBound {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (StaleBound::Strict, StaleBound::Strict) | (StaleBound::Auto, StaleBound::Auto) => true,
            (StaleBound::Distance(a), StaleBound::Distance(b)) => a.to_bits() == b.to_bits(),
            _ => false,
        }
    }
}

impl Eq for StaleBound {}

impl StaleBound {
    /// τ for `cloud`.
    pub fn tolerance(self, cloud: &SplatCloud) -> f32 {
        match self {
            StaleBound::Strict => 0.0,
            StaleBound::Distance(d) => d.max(0.0),
            StaleBound::Auto => median_largest_sigma(cloud),
        }
    }
}

/// The median of `max(scale)` over splats with finite scales and opacity ≥ `ALPHA_MIN`.
fn median_largest_sigma(cloud: &SplatCloud) -> f32 {
    let mut s: Vec<f32> = cloud
        .scales
        .iter()
        .zip(&cloud.opacities)
        .filter(|(s, o)| **o >= crate::profile::ALPHA_MIN && s.iter().all(|v| v.is_finite()))
        .map(|(s, _)| s[0].max(s[1]).max(s[2]))
        .collect();
    if s.is_empty() {
        return 0.0;
    }
    let mid = s.len() / 2;
    *s.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// What a frame did with the newest order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Freshness {
    /// Provably the order a fresh sort gives.
    Exact,
    /// Older than the eye by `moved` (world units), within the bound: inversions only between
    /// splats whose distances differ by ≤ `2·moved`.
    Stale {
        /// Distance from the order's eye.
        moved: f32,
    },
    /// Waited for the sort of this frame's eye (beyond the bound, `--sort-sync`, or the first
    /// order of a scene).
    Waited,
}

/// The decision for one frame: the order's eye moved `moved` from the request it was sorted
/// for, which has exact radius `exact`; tolerance `tau`.
#[cfg_attr(not(feature = "gl"), allow(dead_code))] // the users are GL's
pub fn decide(moved: f64, exact: f64, tau: f64) -> Option<Freshness> {
    if moved <= exact {
        Some(Freshness::Exact)
    } else if 2.0 * moved <= tau {
        Some(Freshness::Stale {
            moved: moved as f32,
        })
    } else {
        None
    }
}

/// Orders from a background sorter: an [`AsyncSorter`] over the cloud's positions with
/// [`Reuse::MotionBound`], and the staleness rule.
#[derive(Debug)]
#[cfg_attr(not(feature = "gl"), allow(dead_code))] // the users are GL's
pub struct StaleOrders {
    sorter: AsyncSorter,
    tau: f32,
    sync: bool,
    requested: Option<[f32; 3]>,
    generation: u64,
    /// Orders older than this generation were posted before the last crop change.
    first_valid: u64,
}

#[cfg_attr(not(feature = "gl"), allow(dead_code))]
impl StaleOrders {
    /// A sorter thread for `positions`; `tau` from [`StaleBound::tolerance`]; `sync` makes
    /// every frame wait (`--sort-sync`).
    pub fn new(positions: Arc<[[f32; 3]]>, tau: f32, sync: bool) -> std::io::Result<Self> {
        let sorter = Sorter::new().with_reuse(Reuse::MotionBound);
        Ok(StaleOrders {
            sorter: AsyncSorter::new(positions, sorter)?,
            tau,
            sync,
            requested: None,
            generation: 0,
            first_valid: 0,
        })
    }

    /// Cuts every order from now on to `crop` ([`AsyncSorter::set_crop`]); the next frame
    /// waits for an order with the new crop.
    pub fn set_crop(&mut self, crop: Option<crate::cull::CropBox>) {
        self.sorter.set_crop(crop);
        self.requested = None;
        self.first_valid = self.generation + 1;
    }

    /// Posts a sort for `eye` unless it is the last one posted (never waits).
    pub fn request(&mut self, eye: Vec3) {
        let e = eye.to_array();
        if self.requested.map(|r| r.map(f32::to_bits)) != Some(e.map(f32::to_bits)) {
            self.generation = self.sorter.request(SortRequest::distance(e));
            self.requested = Some(e);
        }
    }

    /// The order to draw from `eye`: the newest finished one if the bound allows it, else
    /// (waiting) the order sorted for `eye`. `None` only if the sorter thread died.
    pub fn for_frame(&mut self, eye: Vec3) -> Option<(&SortedFrame, Freshness)> {
        let first_valid = self.first_valid;
        let decision = match self.sorter.latest() {
            Some(f) if !self.sync && f.generation() >= first_valid => f.request().and_then(|req| {
                let moved = (eye - Vec3::from_array(req.eye)).length() as f64;
                decide(moved, f.exact_radius(), self.tau as f64)
            }),
            _ => None,
        };
        if let Some(fresh) = decision {
            // The order just checked (not a newer one that may have finished since).
            return self.sorter.current().map(|f| (f, fresh));
        }
        self.request(eye);
        let generation = self.generation;
        self.sorter
            .wait_for(generation)
            .map(|f| (f, Freshness::Waited))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::Rng;

    /// The documented bound: an order sorted for `e₀`, drawn from `e₁` with `2|e₁ − e₀| ≤ τ`
    /// ([`decide`] says `Stale`), has every inverted pair within `τ` of each other in distance
    /// from `e₁`.
    #[test]
    fn stale_orders_only_swap_splats_within_the_tolerance() {
        let mut rng = Rng::new(3);
        let (mut stale, mut tightest) = (0, 0.0f32);
        for trial in 0..30 {
            let n = 2000 + 100 * trial;
            let pos: Vec<[f32; 3]> = (0..n)
                .map(|_| [(); 3].map(|_| rng.range(-2.0, 2.0)))
                .collect();
            let e0 = Vec3::new(rng.range(-6.0, 6.0), rng.range(-6.0, 6.0), 6.0);
            let tau = rng.range(0.001, 0.2);
            let dir = Vec3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
            let e1 = e0 + dir * 0.499 * tau;
            let moved = (e1 - e0).length() as f64;
            let Some(Freshness::Stale { .. }) = decide(moved, 0.0, tau as f64) else {
                panic!("within the bound");
            };
            stale += 1;
            let order = Sorter::new().sort_by_distance(&pos, e0.to_array()).to_vec();
            // Worst inversion from e₁: a later-drawn splat farther than an earlier one.
            let d = |i: u32| (Vec3::from_array(pos[i as usize]) - e1).length();
            let mut nearest = f32::INFINITY;
            let mut worst = 0.0f32;
            for &i in &order {
                worst = worst.max(d(i) - nearest);
                nearest = nearest.min(d(i));
            }
            let bound = 2.0 * moved as f32;
            assert!(
                worst <= bound * (1.0 + 1e-4) + 1e-6 && bound <= tau,
                "{worst} > {bound}"
            );
            tightest = tightest.max(worst / bound);
        }
        assert_eq!(stale, 30);
        // Stale orders do contain inversions close to the bound (the check is not vacuous).
        assert!(
            tightest > 0.25,
            "worst inversion only {tightest} of the bound"
        );
        assert_eq!(decide(0.2, 0.0, 0.3), None);
        assert_eq!(decide(0.2, 0.25, 0.0), Some(Freshness::Exact));
    }

    #[test]
    fn auto_tolerance_is_the_median_largest_sigma() {
        let mut c = SplatCloud::new(0);
        let cases = [
            (0.1, 1.0),
            (0.3, 1.0),
            (0.2, 1.0),
            (9.0, 0.0),
            (f32::NAN, 1.0),
        ];
        for (s, o) in cases {
            c.push(
                [0.0; 3],
                [s, 0.01, 0.02],
                [0.0, 0.0, 0.0, 1.0],
                o,
                &[[0.0; 3]],
            );
        }
        // 0.1, 0.2, 0.3 drawable and finite (the 9.0 splat is invisible, the NaN one unusable).
        assert_eq!(StaleBound::Auto.tolerance(&c), 0.2);
        assert_eq!(StaleBound::Strict.tolerance(&c), 0.0);
    }
}
