//! antimatter15 `.splat` writer: 32 bytes per splat, the inverse of [`crate::load::splat`]
//! (bytes rounded to nearest; SH beyond the DC term cannot be stored and is dropped).

use crate::cloud::SplatCloud;

fn byte(v: f32) -> u8 {
    if v.is_nan() {
        return 0;
    }
    v.round().clamp(0.0, 255.0) as u8
}

/// Encodes `cloud` as `.splat`. Colours outside the [0, 1] display range are clamped, the
/// quaternion is normalised with w ≥ 0 (a zero one is written as identity).
pub fn to_splat(cloud: &SplatCloud) -> Vec<u8> {
    let mut out = Vec::with_capacity(cloud.len() * crate::load::splat::RECORD);
    for i in 0..cloud.len() {
        for v in cloud.positions[i].iter().chain(&cloud.scales[i]) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for c in cloud.sh_of(i)[0] {
            out.push(byte((crate::sh::color_from_dc(c) * 255.0) as f32));
        }
        out.push(byte(cloud.opacities[i] * 255.0));
        let [x, y, z, w] = match crate::load::normalize_quat(cloud.rotations[i]) {
            Some((q, _)) if q[3] < 0.0 => q.map(|v| -v),
            Some((q, _)) => q,
            None => [0.0, 0.0, 0.0, 1.0],
        };
        for v in [w, x, y, z] {
            out.push(byte(v * 128.0 + 128.0));
        }
    }
    out
}
