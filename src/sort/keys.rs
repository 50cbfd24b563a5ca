//! Sort keys: camera → one `f32` per splat → one order-preserving `u32` per splat.
//!
//! The radix core sorts `u32` keys *ascending*; we want the *largest* float first (farthest,
//! back to front), so [`far_first_key`] maps floats to `u32` in *descending* float order.

/// `cameraDistance` key: the squared Euclidean distance from `eye` to `p`, computed exactly as
/// `dx·dx + dy·dy + dz·dz` (no FMA, left to right) in `f32`, so every caller gets the same bits.
#[inline(always)]
pub fn squared_distance(p: [f32; 3], eye: [f32; 3]) -> f32 {
    let dx = p[0] - eye[0];
    let dy = p[1] - eye[1];
    let dz = p[2] - eye[2];
    dx * dx + dy * dy + dz * dz
}

/// View-depth key: the signed distance of `p` along the unit view direction `forward` from
/// `eye`, `(p − eye)·forward`, computed left to right in `f32`. Positive in front of the camera.
/// With a [`crate::camera::Camera`] this is the OpenCV camera-space `z`.
#[inline(always)]
pub fn view_depth(p: [f32; 3], eye: [f32; 3], forward: [f32; 3]) -> f32 {
    (p[0] - eye[0]) * forward[0] + (p[1] - eye[1]) * forward[1] + (p[2] - eye[2]) * forward[2]
}

/// Maps a float key to a `u32` whose **ascending** order is the **descending** float order
/// (farthest first), with every float placed deterministically:
///
/// `NaN (any payload) < +inf < finite positives (descending) < ±0 < finite negatives
/// (descending) < −inf` in `u32` order, i.e. in the draw order NaN comes **first** (treated as
/// farther than everything), −inf last, and `−0` equals `+0`.
///
/// This is the "float flip" trick, complemented: non-negative floats have their magnitude bits
/// inverted, negative floats keep their bits (the sign bit puts them after all non-negatives).
#[inline(always)]
pub fn far_first_key(f: f32) -> u32 {
    // −0 + 0 = +0: equal floats get equal keys.
    let b = (f + 0.0).to_bits();
    let sign = ((b as i32) >> 31) as u32;
    let k = b ^ (!sign & 0x7FFF_FFFF);
    if f.is_nan() { 0 } else { k }
}

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
