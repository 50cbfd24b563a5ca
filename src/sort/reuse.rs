//! Reusing the last order: the view it was sorted for ([`LastView`], equal inputs give the
//! same order) and the safe radius of [`Reuse::MotionBound`](super::Reuse::MotionBound): how
//! far the eye may move before a full-precision `cameraDistance` order could change.
//!
//! Claim: let the last order be sorted for eye `e` with computed keys `k_c = fl(|p − e|²)`.
//! If the eye moves by `δ` with `|δ| < R` (below), a fresh sort for `e + δ` returns the same
//! order. Proof sketch (details in `docs/sorting.md`):
//! - `|p_i − e − δ|² − |p_j − e − δ|² = (|p_i − e|² − |p_j − e|²) − 2 (p_i − p_j)·δ`, so the
//!   exact key difference of two splats changes by at most `2 |p_i − p_j| |δ|`.
//! - The `f32` key `dx·dx + dy·dy + dz·dz` of exact value `s` has error `≤ 5u·s`
//!   (`u = 2⁻²⁴`, five roundings of non-negative terms). With `|δ| ≤ 0.4 √K` (`K` the largest
//!   key) every old and new exact key is `≤ 1.96 K (1 + 6u)`, so the four keys of a pair
//!   carry at most `≈ 29.7 u K < 2⁻¹⁸ K = M` of rounding in total.
//! - For every *adjacent* pair `(i, j)` of the last order with `p_i ≠ p_j`: if
//!   `gap = k_c(i) − k_c(j) > M + 2 |p_i − p_j| |δ|`, the new computed keys stay strictly
//!   ordered. Pairs with `p_i = p_j` always get equal keys and keep index order.
//! - So the old sequence is sorted under the new (total) order `(key desc, index asc)`,
//!   which has exactly one sorted sequence: the new order equals the old one.
//!
//! `R = min(0.4 √K, min over adjacent pairs with p_i ≠ p_j of (gap − M) / (2 |p_i − p_j|))`,
//! and 0 if any gap is `≤ M` or any key is not finite.

use super::{Precision, SortMode};

/// The view a sort was made for (for reuse).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LastView {
    pub(super) ptr: usize,
    pub(super) len: usize,
    pub(super) mode: SortMode,
    pub(super) precision: Precision,
    pub(super) eye: [u32; 3],
    pub(super) forward: [u32; 3],
    /// Safe radius ([`Reuse::MotionBound`](super::Reuse::MotionBound)), 0 when not computed.
    pub(super) radius: f64,
    pub(super) eye_f: [f32; 3],
    /// For a culled sort ([`Sorter::sort_visible`](super::Sorter::sort_visible)): the bounds'
    /// address and the frustum.
    pub(super) cull: Option<(usize, crate::cull::Frustum)>,
}

impl LastView {
    pub(super) fn new(
        positions: &[[f32; 3]],
        mode: SortMode,
        precision: Precision,
        eye: [f32; 3],
        forward: [f32; 3],
        cull: Option<(usize, crate::cull::Frustum)>,
    ) -> LastView {
        LastView {
            ptr: positions.as_ptr() as usize,
            len: positions.len(),
            mode,
            precision,
            eye: bits_of(eye),
            // The forward vector only matters to view-depth keys.
            forward: if mode == SortMode::ViewDepth {
                bits_of(forward)
            } else {
                [0; 3]
            },
            radius: 0.0,
            eye_f: eye,
            cull,
        }
    }
}

fn bits_of(v: [f32; 3]) -> [u32; 3] {
    v.map(f32::to_bits)
}

/// What the last call did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// Nothing sorted yet.
    None,
    /// The order was computed for this call.
    Sorted,
    /// The previous order was returned because the view was bit-identical.
    ReusedSameView,
    /// The previous order was returned because the eye moved by `moved`, less than the proven
    /// safe radius `radius`.
    ReusedWithinBound {
        /// Distance the eye moved since the sorted view.
        moved: f64,
        /// Safe radius of that sorted order.
        radius: f64,
    },
}

use super::keys::squared_distance;

/// Distance between two eyes, in `f64`.
pub(crate) fn moved(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let d = f64::from(b[k]) - f64::from(a[k]);
            d * d
        })
        .sum::<f64>()
        .sqrt()
}

/// The safe radius of `order` (back to front for `eye`, full precision) — see the module docs.
pub(crate) fn safe_radius(positions: &[[f32; 3]], order: &[u32], eye: [f32; 3]) -> f64 {
    let key = |i: u32| f64::from(squared_distance(positions[i as usize], eye));
    let Some(&first) = order.first() else {
        return f64::INFINITY;
    };
    if order.len() < 2 {
        return f64::INFINITY;
    }
    let k_max = key(first);
    // The bound needs every moved key (≤ 1.96·K) to stay finite in f32.
    if !k_max.is_finite() || 1.96 * k_max >= f64::from(f32::MAX) {
        return 0.0;
    }
    let margin = k_max * (-18f64).exp2();
    let mut radius = 0.4 * k_max.sqrt();
    for w in order.windows(2) {
        let (pi, pj) = (positions[w[0] as usize], positions[w[1] as usize]);
        if pi == pj {
            continue;
        }
        let gap = key(w[0]) - key(w[1]);
        // NaN gaps (a NaN or inf key further down) fail this test too.
        if gap.is_nan() || gap <= margin {
            return 0.0;
        }
        let dist = moved(pi, pj);
        radius = radius.min((gap - margin) / (2.0 * dist));
    }
    // Slack for the f64 arithmetic above.
    radius * (1.0 - 1e-9)
}
