//! Quantized keys ([`Precision::Quantized`](super::Precision)): the range of the visible keys
//! (one parallel scan), `bits`-bit buckets over it, and the bucket width that bounds the order
//! error.

use super::radix;
use rayon::prelude::*;

/// Maps a float key to a `bits`-bit bucket, again ascending = farthest first, for the quantized
/// modes. `lo`/`scale` come from [`QuantRange`]. Keys below `lo` (and −inf) land in the nearest
/// bucket, keys above the range (and +inf, NaN) in the farthest.
#[inline(always)]
pub(crate) fn quantized_key(f: f32, lo: f64, scale: f64, top: u32) -> u32 {
    // f64: the bucket of every f32 key is exact to ~2^-28 of a bucket even at 24 bits.
    // max/min drop a NaN operand, so `x` is in [0, top] (NaN keys → 0, fixed below).
    // Finite keys use buckets 1..=top−1; 0 is reserved for +inf/NaN and top for −inf, so the
    // infinities stay at the ends even when every finite key shares one bucket.
    let x = ((f64::from(f) - lo) * scale)
        .max(0.0)
        .min(f64::from(top - 2));
    // SAFETY: `x` is finite and in [0, top − 2], top < 2^24 ≤ i32::MAX (i32: one SSE2
    // instruction).
    let q = unsafe { x.to_int_unchecked::<i32>() } as u32 + 1;
    // Infinities go to the end buckets explicitly (with a zero-width range, inf·0 is NaN).
    if f.is_nan() || f == f32::INFINITY {
        0
    } else if f == f32::NEG_INFINITY {
        top
    } else {
        top - q
    }
}

/// The key range of a quantized sort.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct QuantRange {
    pub lo: f64,
    pub scale: f64,
    pub top: u32,
}

impl QuantRange {
    /// Buckets of width `(hi − lo) / (2^bits − 2)` over `[lo, hi]` (two of the `2^bits`
    /// keys are reserved for the infinities).
    pub(crate) fn new(lo: f32, hi: f32, bits: u32) -> Self {
        let top = ((1u64 << bits) - 1) as u32;
        let (lo, hi) = (f64::from(lo), f64::from(hi));
        let scale = if hi > lo && (hi - lo).is_finite() {
            ((1u64 << bits) - 2) as f64 / (hi - lo)
        } else {
            0.0
        };
        QuantRange { lo, scale, top }
    }

    /// Width of one bucket in key units (0 when all keys share one bucket by construction).
    pub(crate) fn bucket_width(&self) -> f64 {
        if self.scale > 0.0 {
            1.0 / self.scale
        } else {
            0.0
        }
    }
}

/// Fills a block of float keys: `fill(first_index, block)`.
type BlockFill<'a> = dyn Fn(usize, &mut [f32]) + Sync + 'a;

/// Running (min, max) of the finite keys `> 0` and of all finite keys, of one block.
fn scan_block(keys: &[f32], acc: &mut [f32; 4]) {
    // Eight independent lanes (so the compiler vectorises and no comparison waits on the
    // previous one); a non-candidate becomes NaN, which every comparison rejects.
    const L: usize = 8;
    let mut lanes = [[acc[0]; L], [acc[1]; L], [acc[2]; L], [acc[3]; L]];
    let mut it = keys.chunks_exact(L);
    let step = |ks: &[f32], lanes: &mut [[f32; L]; 4]| {
        for (j, &k) in ks.iter().enumerate() {
            let all = if k.is_finite() { k } else { f32::NAN };
            let pos = if all > 0.0 { all } else { f32::NAN };
            lanes[0][j] = if pos < lanes[0][j] { pos } else { lanes[0][j] };
            lanes[1][j] = if pos > lanes[1][j] { pos } else { lanes[1][j] };
            lanes[2][j] = if all < lanes[2][j] { all } else { lanes[2][j] };
            lanes[3][j] = if all > lanes[3][j] { all } else { lanes[3][j] };
        }
    };
    for ks in &mut it {
        step(ks, &mut lanes);
    }
    step(it.remainder(), &mut lanes);
    let [lo_pos, hi_pos, lo, hi] = &lanes;
    acc[0] = lo_pos.iter().fold(acc[0], |a, &v| a.min(v));
    acc[1] = hi_pos.iter().fold(acc[1], |a, &v| a.max(v));
    acc[2] = lo.iter().fold(acc[2], |a, &v| a.min(v));
    acc[3] = hi.iter().fold(acc[3], |a, &v| a.max(v));
}

/// Optionally fills `keys` (`fill(first, block)`, in L1-sized blocks) and returns the
/// quantization range of the visible keys: the finite keys, or with `positive_only` those
/// `> 0` when there are any. One parallel pass; `ranges` holds the per-chunk results.
pub(super) fn visible_range(
    ranges: &mut Vec<[f32; 4]>,
    keys: &mut [f32],
    t: usize,
    bits: u32,
    positive_only: bool,
    fill: Option<&BlockFill<'_>>,
) -> QuantRange {
    let n = keys.len();
    let len = n.div_ceil(t).max(1);
    ranges.clear();
    ranges.resize(n.div_ceil(len).max(1), EMPTY_RANGE);
    ranges
        .par_iter_mut()
        .zip(keys.par_chunks_mut(len))
        .enumerate()
        .for_each(|(c, (r, ks))| {
            for (b, block) in ks.chunks_mut(radix::BLOCK).enumerate() {
                if let Some(fill) = fill {
                    fill(c * len + b * radix::BLOCK, block);
                }
                scan_block(block, r);
            }
        });
    combine(ranges, bits, positive_only)
}

/// [`visible_range`] of caller-given keys (all finite keys count).
pub(super) fn given_keys_range(
    ranges: &mut Vec<[f32; 4]>,
    keys: &[f32],
    t: usize,
    bits: u32,
) -> QuantRange {
    let len = keys.len().div_ceil(t).max(1);
    ranges.clear();
    ranges.resize(keys.len().div_ceil(len).max(1), EMPTY_RANGE);
    ranges
        .par_iter_mut()
        .zip(keys.par_chunks(len))
        .for_each(|(r, ks)| scan_block(ks, r));
    combine(ranges, bits, false)
}

/// No keys seen yet.
const EMPTY_RANGE: [f32; 4] = [
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::INFINITY,
    f32::NEG_INFINITY,
];

/// The quantization range from per-chunk [`scan_block`] results.
fn combine(ranges: &[[f32; 4]], bits: u32, positive_only: bool) -> QuantRange {
    let empty = EMPTY_RANGE;
    let [lo_pos, hi_pos, lo, hi] = ranges.iter().fold(empty, |a, r| {
        [
            a[0].min(r[0]),
            a[1].max(r[1]),
            a[2].min(r[2]),
            a[3].max(r[3]),
        ]
    });
    let range = if positive_only && lo_pos <= hi_pos {
        (lo_pos, hi_pos)
    } else if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 0.0)
    };
    QuantRange::new(range.0, range.1, bits)
}

/// Width of one quantization bucket for keys spanning `[lo, hi]` at `bits` bits: two keys
/// further apart than this are never misordered by
/// [`Precision::Quantized`](super::Precision::Quantized).
pub fn quantized_bucket_width(lo: f32, hi: f32, bits: u32) -> f64 {
    QuantRange::new(lo, hi, bits.clamp(8, 24)).bucket_width()
}
