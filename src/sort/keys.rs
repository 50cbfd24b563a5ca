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
