//! Back-to-front splat ordering on the CPU: camera keys + a parallel radix argsort (one MSD
//! pass, then cache-resident LSD passes per bucket).
//!
//! No GL here: a [`Sorter`] takes plain positions (`&[[f32; 3]]`) and a camera position and
//! returns the splat indices **back to front** (farthest first) as `&[u32]`, ready to upload.
//! The renderer uses the same type; [`AsyncSorter`] runs one on a background thread.
//!
//! ```
//! use splatgl::sort::Sorter;
//! let positions = [[0.0, 0.0, 1.0], [0.0, 0.0, 5.0], [0.0, 0.0, 3.0]];
//! let mut sorter = Sorter::new();
//! assert_eq!(sorter.sort_by_distance(&positions, [0.0; 3]), &[1, 2, 0]);
//! ```
//!
//! # The order, exactly
//! - Key: `cameraDistance` (default) uses the **squared** distance [`squared_distance`] (same
//!   order as the distance, one `sqrt` cheaper); [`Sorter::sort_by_view_depth`] uses the signed
//!   depth along the view direction, [`view_depth`].
//! - Output: keys **descending** (largest first = back to front). **Ties** (bit-equal keys, and
//!   `−0 = +0`) keep **ascending splat index**. The result is therefore exactly a *stable* sort
//!   of the indices by key descending, deterministic and independent of the thread count.
//! - Non-finite keys never panic: **NaN** (e.g. a NaN position) is drawn **first** (treated as
//!   farther than everything, so it is painted over), then `+inf`, the finite keys, and
//!   `−inf` last. See [`far_first_key`].
//! - [`Precision::Quantized`] sorts by a `bits`-bit bucket of the key instead; order errors
//!   are bounded by one bucket width, see [`Precision`]. On the CPU it is *not* faster than
//!   full precision (measured in `docs/sorting.md`): it exists for callers that must match a
//!   quantized (e.g. GPU or web) sorter.
//!
//! Design, measurements and the proof behind [`Reuse::MotionBound`] are in `docs/sorting.md`.

mod async_sorter;
mod keys;
mod quantize;
mod radix;
mod reuse;
mod stale;
mod visible;

pub use async_sorter::{AsyncSorter, SortRequest, SortedFrame};
pub use keys::{far_first_key, squared_distance, view_depth};
pub use quantize::quantized_bucket_width;
use reuse::LastView;
pub use reuse::Outcome;
#[cfg(feature = "gl")]
pub use stale::StaleOrders;
pub use stale::{Freshness, StaleBound};

use quantize::{given_keys_range, quantized_key, visible_range};
use radix::{RadixBuffers, chunk_count, fill_keys};

/// Which key a camera sort uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SortMode {
    /// `cameraDistance`: (squared) Euclidean distance from the camera centre. The glTF default.
    #[default]
    Distance,
    /// Depth along the camera's viewing axis (camera-space `z` in OpenCV axes).
    ViewDepth,
}

/// How precisely keys are compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Precision {
    /// All 32 bits of the `f32` key: the order is exactly the float order (no popping
    /// between close splats). The default.
    #[default]
    Full,
    /// Keys quantized to `bits` bits (16, 20 or 24; other values are clamped to 8..=24) over
    /// the range `[lo, hi]` of the *visible* keys: the finite keys, and for view depth only
    /// those in front of the camera (`> 0`) when there are any. The key quantized is the
    /// distance (not squared) for [`SortMode::Distance`], the depth for
    /// [`SortMode::ViewDepth`], the given float for [`Sorter::sort_keys`].
    ///
    /// **Error bound**: buckets are `w = (hi − lo) / (2^bits − 2)` wide and bucket order is key
    /// order, so two splats are drawn in the wrong order only if they share a bucket, i.e.
    /// only if their keys differ by less than `w` (checked by the tests with a `10⁻⁶·w` slack
    /// for rounding). Within a bucket the order is ascending splat index. Keys outside the
    /// range clamp to the end buckets (NaN and `+inf` farthest, `−inf` nearest).
    Quantized {
        /// Bits per key.
        bits: u32,
    },
}

/// When a sort may return the previous order instead of sorting again.
///
/// Both reuse modes assume that the positions behind the same slice (same address and length)
/// did not change between calls; call [`Sorter::invalidate`] after editing them in place.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reuse {
    /// Always sort. The default: correct whatever the caller does with the positions.
    #[default]
    Never,
    /// Reuse the last order when the positions slice, mode, precision and the camera (eye,
    /// and view direction for depth) are **bit-identical** to the last sort: the sort is
    /// deterministic, so the order is provably the same. The positions slice is recognised
    /// by address and length, not content: a caller that changes positions in place, or frees
    /// and reallocates them, must call [`Sorter::invalidate`].
    SameView,
    /// As `SameView`, plus, for full-precision distance sorts, reuse when the eye moved by
    /// less than a radius proven (in `docs/sorting.md`) not to change any adjacent pair of the
    /// last order, rounding included. Finding the radius costs one extra gather pass after
    /// each sort; on large real clouds it is usually 0 (some pair of different splats has
    /// bit-equal keys), so this mostly pays off for small clouds.
    MotionBound,
}

/// Every buffer a sort needs, kept across frames: after the first sort of N splats, sorting
/// at most N splats again allocates nothing.
#[derive(Debug, Default)]
pub struct SortScratch {
    radix: RadixBuffers,
    /// Float keys of a quantized sort.
    fkeys: Vec<f32>,
    /// A culled sort's visible indices and their positions.
    visible: Vec<u32>,
    visible_positions: Vec<[f32; 3]>,
    /// Per-chunk (min, max) of the positive and of all finite keys.
    ranges: Vec<[f32; 4]>,
}

/// A reusable back-to-front sorter. See the [module docs](self) for the exact order.
#[derive(Debug)]
pub struct Sorter {
    scratch: SortScratch,
    precision: Precision,
    reuse: Reuse,
    max_digit_bits: u32,
    n: usize,
    last: Option<LastView>,
    outcome: Outcome,
}

impl Default for Sorter {
    fn default() -> Self {
        Self::new()
    }
}

impl Sorter {
    /// A full-precision sorter that never reuses orders.
    pub fn new() -> Self {
        Sorter {
            scratch: SortScratch::default(),
            precision: Precision::Full,
            reuse: Reuse::Never,
            max_digit_bits: radix::MAX_DIGIT_BITS,
            n: 0,
            last: None,
            outcome: Outcome::None,
        }
    }

    /// Sets the key precision (builder style).
    pub fn with_precision(mut self, precision: Precision) -> Self {
        self.precision = precision;
        self
    }

    /// Sets the reuse policy (builder style).
    pub fn with_reuse(mut self, reuse: Reuse) -> Self {
        self.reuse = reuse;
        self
    }

    /// The key precision.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Sets the key precision; the next sort sorts.
    pub fn set_precision(&mut self, precision: Precision) {
        self.precision = precision;
    }

    /// Sets the reuse policy.
    pub fn set_reuse(&mut self, reuse: Reuse) {
        self.reuse = reuse;
    }

    /// Tuning knob for benchmarks: most bits per radix pass, 8..=11 (default 11: a 32-bit key
    /// takes 3 passes; 8 gives 4 passes of 256 buckets). Does not change the result.
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn set_max_digit_bits(&mut self, bits: u32) {
        self.max_digit_bits = bits.clamp(8, radix::MAX_DIGIT_BITS);
    }

    /// Forgets the last view: the next call sorts (use after editing positions in place).
    pub fn invalidate(&mut self) {
        self.last = None;
    }

    /// What the last call did (sorted, or reused the previous order and why).
    pub fn last_outcome(&self) -> Outcome {
        self.outcome
    }

    /// The safe radius of the last order under [`Reuse::MotionBound`] (0 when not computed
    /// or when no motion is provably safe; infinite for fewer than 2 splats).
    pub fn reuse_radius(&self) -> f64 {
        self.last.map_or(0.0, |l| l.radius)
    }

    /// The last order (back to front), as returned by the last call.
    pub fn order(&self) -> &[u32] {
        &self.scratch.radix.out[..self.n]
    }

    /// Splat indices back to front (farthest from `eye` first) by `cameraDistance`.
    pub fn sort_by_distance(&mut self, positions: &[[f32; 3]], eye: [f32; 3]) -> &[u32] {
        self.sort_view(positions, SortMode::Distance, eye, [0.0; 3])
    }

    /// Splat indices back to front by view depth `(p − eye)·forward` (largest depth first;
    /// splats behind the camera come last). `forward` should be a unit vector.
    pub fn sort_by_view_depth(
        &mut self,
        positions: &[[f32; 3]],
        eye: [f32; 3],
        forward: [f32; 3],
    ) -> &[u32] {
        self.sort_view(positions, SortMode::ViewDepth, eye, forward)
    }

    /// Sorts for a [`Camera`](crate::camera::Camera): its centre, and for view depth its
    /// optical axis (+z of OpenCV camera space).
    pub fn sort_for_camera(
        &mut self,
        positions: &[[f32; 3]],
        camera: &crate::camera::Camera,
        mode: SortMode,
    ) -> &[u32] {
        let eye = camera.eye().to_array();
        let forward = camera.world_to_camera.row(2).truncate().to_array();
        self.sort_view(positions, mode, eye, forward)
    }

    /// Indices of `keys` largest first (ties: ascending index), with this sorter's precision
    /// and the NaN/inf placement of [`far_first_key`]. Never reuses.
    pub fn sort_keys(&mut self, keys: &[f32]) -> &[u32] {
        self.last = None;
        let n = keys.len();
        let t = chunk_count(n);
        match self.precision {
            Precision::Full => self.sort_u32(n, t, |start, block| {
                for (k, &f) in block.iter_mut().zip(&keys[start..]) {
                    *k = far_first_key(f);
                }
            }),
            Precision::Quantized { bits } => {
                let bits = bits.clamp(8, 24);
                let q = given_keys_range(&mut self.scratch.ranges, keys, t, bits);
                self.sort_u32(n, t, |start, block| {
                    for (k, &f) in block.iter_mut().zip(&keys[start..]) {
                        *k = quantized_key(f, q.lo, q.scale, q.top);
                    }
                });
            }
        }
        self.outcome = Outcome::Sorted;
        self.order()
    }

    fn sort_view(
        &mut self,
        positions: &[[f32; 3]],
        mode: SortMode,
        eye: [f32; 3],
        forward: [f32; 3],
    ) -> &[u32] {
        let view = LastView::new(positions, mode, self.precision, eye, forward, None);
        if self.reuse_last(&view) {
            return self.order();
        }
        self.sort_positions(positions, mode, eye, forward);
        let radius = if self.reuse == Reuse::MotionBound
            && self.precision == Precision::Full
            && mode == SortMode::Distance
        {
            reuse::safe_radius(positions, self.order(), eye)
        } else {
            0.0
        };
        self.last = Some(LastView { radius, ..view });
        self.order()
    }

    /// Whether the last order may be reused for `view` (sets the outcome when it is).
    fn reuse_last(&mut self, view: &LastView) -> bool {
        if self.reuse != Reuse::Never
            && let Some(last) = &self.last
        {
            let same_input = LastView {
                eye: last.eye,
                radius: last.radius,
                eye_f: last.eye_f,
                ..*view
            } == *last;
            if same_input && last.eye == view.eye {
                self.outcome = Outcome::ReusedSameView;
                return true;
            }
            if same_input && last.radius > 0.0 {
                let moved = reuse::moved(last.eye_f, view.eye_f);
                if moved < last.radius {
                    self.outcome = Outcome::ReusedWithinBound {
                        moved,
                        radius: last.radius,
                    };
                    return true;
                }
            }
        }
        false
    }

    /// Keys of `positions` for the view, sorted into the output (`order()`): the sorting core
    /// shared by the full and the culled sort.
    fn sort_positions(
        &mut self,
        positions: &[[f32; 3]],
        mode: SortMode,
        eye: [f32; 3],
        forward: [f32; 3],
    ) {
        let n = positions.len();
        let t = chunk_count(n);
        match (self.precision, mode) {
            (Precision::Full, SortMode::Distance) => self.sort_u32(n, t, |start, block| {
                for (k, &p) in block.iter_mut().zip(&positions[start..]) {
                    *k = far_first_key(squared_distance(p, eye));
                }
            }),
            (Precision::Full, SortMode::ViewDepth) => self.sort_u32(n, t, |start, block| {
                for (k, &p) in block.iter_mut().zip(&positions[start..]) {
                    *k = far_first_key(view_depth(p, eye, forward));
                }
            }),
            (Precision::Quantized { bits }, _) => {
                let bits = bits.clamp(8, 24);
                let mut fkeys = std::mem::take(&mut self.scratch.fkeys);
                radix::grow(&mut fkeys, n);
                let fill = |start: usize, block: &mut [f32]| {
                    let ps = &positions[start..start + block.len()];
                    match mode {
                        SortMode::Distance => {
                            for (k, &p) in block.iter_mut().zip(ps) {
                                *k = squared_distance(p, eye).sqrt();
                            }
                        }
                        SortMode::ViewDepth => {
                            for (k, &p) in block.iter_mut().zip(ps) {
                                *k = view_depth(p, eye, forward);
                            }
                        }
                    }
                };
                let q = visible_range(
                    &mut self.scratch.ranges,
                    &mut fkeys[..n],
                    t,
                    bits,
                    mode == SortMode::ViewDepth,
                    Some(&fill),
                );
                let fk = &fkeys[..n];
                self.sort_u32(n, t, |start, block| {
                    for (k, &f) in block.iter_mut().zip(&fk[start..]) {
                        *k = quantized_key(f, q.lo, q.scale, q.top);
                    }
                });
                self.scratch.fkeys = fkeys;
            }
        }
        self.outcome = Outcome::Sorted;
    }

    /// Keys (`fill(first, block)` writes those of `first..first + block.len()`) → `out[..n]`
    /// in ascending key order (ties by index).
    fn sort_u32(&mut self, n: usize, t: usize, fill: impl Fn(usize, &mut [u32]) + Sync) {
        self.sort_u32_ids(n, t, fill, None);
    }

    /// [`Sorter::sort_u32`] writing `ids[position]` instead of the position (see
    /// [`RadixBuffers::sort`]).
    fn sort_u32_ids(
        &mut self,
        n: usize,
        t: usize,
        fill: impl Fn(usize, &mut [u32]) + Sync,
        ids: Option<&[u32]>,
    ) {
        // Counts and indices are u32: more would wrap and make the parallel scatter race.
        assert!(
            n <= u32::MAX as usize,
            "the sorter handles at most 2^32 − 1 splats"
        );
        let rb = &mut self.scratch.radix;
        rb.prepare(n, t);
        let (keys, minmax) = rb.keys_and_minmax(n, t);
        fill_keys(keys, minmax, t, fill);
        rb.sort(n, t, self.max_digit_bits, ids);
        self.n = n;
    }
}
