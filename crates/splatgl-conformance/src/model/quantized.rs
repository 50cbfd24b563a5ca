//! The model's input-precision variants: a cloud as a lossy encoding carries it, decoded back
//! to floats before the model renders it.
//!
//! - [`spz`]: `KHR_gaussian_splatting_compression_spz_2` (SPZ v2 with Niantic's defaults: 12
//!   fractional bits, 8-bit log scales and quaternions, 8-bit colour and opacity, SH 5/4 bits),
//!   by splatgl's own encoder and loader — what `splatgl convert --spz-compress` gives a
//!   renderer that reads only SPZ.
//! - [`packed`]: Spark 2.2's default packed splats, from its source (`spark.module.js`:
//!   `setPackedSplat` 3134–3187, `encodeQuatOctXy88R8` 3491–3515, `encodeSh1Rgb`/`2`/`3`
//!   3633–3698, and the accumulator's repacking relative to the view centre with halved
//!   opacity, 13071–13084): centres as half floats (absolute, then relative to the eye),
//!   colour and opacity in 8 bits (opacity halved once more: steps of 2/255), scales as 8-bit
//!   ln s over [−12, 9], quaternions as an 8+8-bit octahedral axis and an 8-bit angle, SH 7/8/6
//!   bits in ±1.
//! - [`babylon`]: Babylon.js 9's splat buffer, as its glTF loader fills it
//!   (loaders/glTF/2.0/Extensions/KHR_gaussian_splatting.pure.js: `Clamp255` of the DC colour,
//!   opacity, `q·127.5 + 127.5` and `coef·128 + 128`): colour, opacity and quaternion in 8
//!   bits, rounded; SH above degree 0 in 8 bits over ±1, clamped.
//! - [`playcanvas`]: PlayCanvas 2.23's compact work buffer
//!   (scene/shader-lib/glsl/chunks/gsplat/frag/formats/containerCompactWrite.js and
//!   containerCompactRead.js): scales as 8-bit ln σ over [−12, 9] (255 steps, σ off by up to
//!   ±4.2 %), opacity in 8 bits, the quaternion as 11-11-10 bits of `xyz/√(1 + w)`.

use splatgl::cloud::SplatCloud;
use splatgl::sh::SH_C0;

/// `cloud` after a round trip through `KHR_gaussian_splatting_compression_spz_2` (the
/// converter's encoding; metadata kept). `None` when the encoder refuses it or the decoded
/// cloud is not splat for splat the same (the variant then does not apply).
pub(crate) fn spz(cloud: &SplatCloud) -> Option<SplatCloud> {
    let bytes = splatgl::write::to_glb_spz(cloud).ok()?;
    let decoded = splatgl::load::load_bytes(&bytes, None, &Default::default())
        .ok()?
        .cloud;
    if decoded.len() != cloud.len() || decoded.sh_degree != cloud.sh_degree {
        return None;
    }
    let mut out = cloud.clone();
    out.positions = decoded.positions;
    out.scales = decoded.scales;
    out.rotations = decoded.rotations;
    out.opacities = decoded.opacities;
    out.sh = decoded.sh;
    Some(out)
}

/// `cloud` as Spark's packed splats carry it, for a camera at `eye` (see the module docs).
pub(crate) fn packed(cloud: &SplatCloud, eye: [f32; 3]) -> SplatCloud {
    let mut out = cloud.clone();
    for p in &mut out.positions {
        for (v, e) in p.iter_mut().zip(eye) {
            let absolute = half(*v);
            *v = half(absolute - e) + e;
        }
    }
    for s in &mut out.scales {
        *s = s.map(packed_scale);
    }
    for q in &mut out.rotations {
        *q = octahedral(octahedral(*q));
    }
    for a in &mut out.opacities {
        // 8 bits, then halved into 8 bits by the accumulator and doubled when drawn; capped
        // at 1 (above it Spark takes its LoD opacity branch, not modelled).
        let u = (a.clamp(0.0, 1.0) as f64 * 255.0).round();
        let halved = (u / 255.0 * 0.5 * 255.0).round();
        *a = (2.0 * halved / 255.0).min(1.0) as f32;
    }
    let k = out.coeffs_per_splat();
    for (j, c) in out.sh.iter_mut().enumerate() {
        let coefficient = j % k;
        *c = match coefficient {
            0 => c.map(|dc| {
                let rgb = (0.5 + SH_C0 * dc as f64).clamp(0.0, 1.0);
                (((rgb * 255.0).round() / 255.0 - 0.5) / SH_C0) as f32
            }),
            1..=3 => c.map(|v| signed(v, 63.0)),
            4..=8 => c.map(|v| signed(v, 127.0)),
            _ => c.map(|v| signed(v, 31.0)),
        };
    }
    out
}

/// `cloud` as Babylon.js 9's glTF loader stores it (see the module docs).
pub(crate) fn babylon(cloud: &SplatCloud) -> SplatCloud {
    let byte = |v: f64| v.clamp(0.0, 255.0).round();
    let mut out = cloud.clone();
    for q in &mut out.rotations {
        *q = q.map(|c| ((byte(c as f64 * 127.5 + 127.5) - 127.5) / 127.5) as f32);
        let n = q.iter().map(|c| c * c).sum::<f32>().sqrt();
        if n > 0.0 {
            *q = q.map(|c| c / n);
        }
    }
    for a in &mut out.opacities {
        *a = (byte(*a as f64 * 255.0) / 255.0) as f32;
    }
    let k = out.coeffs_per_splat();
    for (j, c) in out.sh.iter_mut().enumerate() {
        *c = if j % k == 0 {
            c.map(|dc| {
                let rgb = byte((0.5 + SH_C0 * dc as f64) * 255.0) / 255.0;
                ((rgb - 0.5) / SH_C0) as f32
            })
        } else {
            c.map(|v| (byte(v as f64 * 128.0 + 128.0) * 2.0 / 255.0 - 1.0) as f32)
        };
    }
    out
}

/// `cloud` as PlayCanvas's compact work buffer carries it (see the module docs).
pub(crate) fn playcanvas(cloud: &SplatCloud) -> SplatCloud {
    const LOG_MIN: f64 = -12.0;
    let step = 21.0 / 255.0;
    let mut out = cloud.clone();
    for s in &mut out.scales {
        *s = s.map(|v| {
            if (v as f64) < 1e-10 {
                return 0.0;
            }
            let code = (((v as f64).ln() - LOG_MIN) / step + 0.5)
                .clamp(1.0, 255.0)
                .floor();
            (code * step + LOG_MIN).exp() as f32
        });
    }
    for a in &mut out.opacities {
        *a = ((a.clamp(0.0, 1.0) as f64 * 255.0 + 0.5).floor() / 255.0) as f32;
    }
    for q in &mut out.rotations {
        *q = compact_quat(*q);
    }
    out
}

/// A unit quaternion `[x, y, z, w]` through PlayCanvas's 11-11-10-bit `xyz/√(1 + w)` code.
fn compact_quat(q: [f32; 4]) -> [f32; 4] {
    let n = q.iter().map(|c| (*c as f64).powi(2)).sum::<f64>().sqrt();
    if n == 0.0 {
        return q;
    }
    let mut v = q.map(|c| c as f64 / n);
    if v[3] < 0.0 {
        v = v.map(|c| -c);
    }
    let k = (1.0 + v[3]).sqrt();
    let code = |c: f64, max: f64| {
        ((c / k * 0.5 + 0.5) * max + 0.5).clamp(0.0, max).floor() / max * 2.0 - 1.0
    };
    let p = [code(v[0], 2047.0), code(v[1], 2047.0), code(v[2], 1023.0)];
    let d = p.iter().map(|c| c * c).sum::<f64>();
    let r = (2.0 - d).max(0.0).sqrt();
    [
        (p[0] * r) as f32,
        (p[1] * r) as f32,
        (p[2] * r) as f32,
        (1.0 - d) as f32,
    ]
}

/// `v` in ±1 with `steps` steps each side (Spark's SH codes, rounded, clamped).
fn signed(v: f32, steps: f64) -> f32 {
    ((v as f64 * steps).clamp(-steps, steps).round() / steps) as f32
}

/// `v` rounded to a half float and back (round to nearest even, as `toHalf` and
/// `packHalf2x16` do for normal values).
fn half(v: f32) -> f32 {
    splatgl::load::codec::f16_to_f32(splatgl::load::codec::f32_to_f16(v))
}

/// Spark's 8-bit ln-scale code over [−12, 9] (`0`: zero scale), decoded.
fn packed_scale(s: f32) -> f32 {
    const LN_MIN: f64 = -12.0;
    const LN_MAX: f64 = 9.0;
    let step = 254.0 / (LN_MAX - LN_MIN);
    if (s as f64) < (-30f64).exp() {
        return 0.0;
    }
    let u = ((((s as f64).ln() - LN_MIN) * step).round() + 1.0).clamp(1.0, 255.0);
    (LN_MIN + (u - 1.0) / step).exp() as f32
}

/// A unit quaternion `[x, y, z, w]` through Spark's `encodeQuatOctXy88R8` and
/// `decodeQuatOctXy88R8`.
fn octahedral(q: [f32; 4]) -> [f32; 4] {
    let mut q = q.map(f64::from);
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n > 0.0 {
        q = q.map(|v| v / n);
    }
    if q[3] < 0.0 {
        q = q.map(|v| -v);
    }
    let theta = 2.0 * q[3].clamp(-1.0, 1.0).acos();
    let xyz = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
    let axis = if xyz < 1e-6 {
        [1.0, 0.0, 0.0]
    } else {
        [q[0] / xyz, q[1] / xyz, q[2] / xyz]
    };
    let sum = axis[0].abs() + axis[1].abs() + axis[2].abs();
    let (mut px, mut py) = (axis[0] / sum, axis[1] / sum);
    if axis[2] < 0.0 {
        let sign = |v: f64| if v >= 0.0 { 1.0 } else { -1.0 };
        (px, py) = ((1.0 - py.abs()) * sign(px), (1.0 - px.abs()) * sign(py));
    }
    let qu = ((px * 0.5 + 0.5) * 255.0).round();
    let qv = ((py * 0.5 + 0.5) * 255.0).round();
    let angle = (theta * (255.0 / std::f64::consts::PI)).round();
    // Decode.
    let (mut fx, mut fy) = ((qu / 255.0 - 0.5) * 2.0, (qv / 255.0 - 0.5) * 2.0);
    let fz = 1.0 - (fx.abs() + fy.abs());
    let t = (-fz).max(0.0);
    fx += if fx >= 0.0 { -t } else { t };
    fy += if fy >= 0.0 { -t } else { t };
    let len = (fx * fx + fy * fy + fz * fz).sqrt();
    let half_theta = angle / 255.0 * std::f64::consts::PI * 0.5;
    let s = half_theta.sin() / len;
    [fx * s, fy * s, fz * s, half_theta.cos()].map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_scales_are_8_bit_log_codes() {
        // 0.2: ln 0.2 = −1.609 → code round(10.391 · 254/21) + 1 = 127 → e^(−12 + 126·21/254).
        let s = packed_scale(0.2);
        assert!((s - 0.2054).abs() < 1e-4, "{s}");
        assert_eq!(packed_scale(packed_scale(0.7)), packed_scale(0.7));
        assert_eq!(packed_scale(0.0), 0.0);
    }

    #[test]
    fn octahedral_quaternions_stay_unit_and_near() {
        for q in [
            [0.0, 0.0, 0.0, 1.0],
            [0.3, -0.4, 0.5, 0.7],
            [-0.6, 0.2, -0.1, 0.77],
        ] {
            let n = (q.iter().map(|v: &f32| v * v).sum::<f32>()).sqrt();
            let q = q.map(|v| v / n);
            let r = octahedral(q);
            let len = r.iter().map(|v| v * v).sum::<f32>().sqrt();
            assert!((len - 1.0).abs() < 1e-5, "{r:?}");
            let dot: f32 = q.iter().zip(&r).map(|(a, b)| a * b).sum();
            // Within a few degrees (8-bit angle: π/255 ≈ 0.7°, 8-bit axis).
            assert!(dot.abs() > 0.998, "{q:?} -> {r:?}");
        }
    }

    #[test]
    fn packed_opacity_moves_in_steps_of_two_255ths() {
        let mut c = SplatCloud::new(0);
        for a in [0.5f32, 0.3, 1.0] {
            c.push(
                [0.0; 3],
                [0.1; 3],
                [0.0, 0.0, 0.0, 1.0],
                a,
                &[[0.2, 0.1, 0.0]],
            );
        }
        let p = packed(&c, [0.0, 0.0, 4.0]);
        for a in &p.opacities[..2] {
            let k = a * 255.0 / 2.0;
            assert!((k - k.round()).abs() < 1e-3, "{a}");
        }
        assert_eq!(p.opacities[2], 1.0);
    }

    #[test]
    fn spz_round_trip_keeps_every_splat() {
        let c = splatgl::synthetic::random_cloud(50, 2, 1.0, 7);
        let q = spz(&c).expect("encodes");
        assert_eq!(q.len(), c.len());
        let moved = c
            .positions
            .iter()
            .zip(&q.positions)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max))
            .fold(0.0, f32::max);
        // 12 fractional bits: within half a step of 1/4096.
        assert!(moved > 0.0 && moved <= 0.5 / 4096.0 + 1e-6, "{moved}");
    }
}
