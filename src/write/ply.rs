//! INRIA 3DGS PLY writer.

use crate::cloud::SplatCloud;
// The loader's own function: "decodes back exactly" is checked against what it computes.
use crate::load::ply::sigmoid;

/// Writes a cloud as INRIA binary little-endian PLY (log scale, logit opacity, w-first
/// quaternion, channel-major `f_rest`) — the inverse of the
/// [PLY loader](crate::load::ply).
///
/// Exact: each logit and log value is the f32 nearest the exact inverse for which the
/// loader's decoding (`sigmoid` / `exp` in f64, rounded to f32) gives back the cloud's value
/// bit for bit, whenever such an f32 lies within 64 ulps (it always does for values that were
/// themselves decoded from a PLY). Opacity 1 and 0 and scale 0 are written as finite values
/// that decode to exactly 1, 0 and 0 (±110: `sigmoid(±110)` and `exp(−110)` round to them),
/// so no ±inf reaches other tools.
pub fn to_inria_ply(cloud: &SplatCloud) -> Vec<u8> {
    write(cloud, false)
}

/// [`to_inria_ply`] with zero `nx ny nz` after `x y z`, as the INRIA trainer writes them (62
/// floats a splat at SH 3: the 248 MB file of 1M splats the load benchmarks read).
pub fn to_inria_ply_with_normals(cloud: &SplatCloud) -> Vec<u8> {
    write(cloud, true)
}

fn write(cloud: &SplatCloud, normals: bool) -> Vec<u8> {
    let k = cloud.coeffs_per_splat();
    let extra = if normals { 3 } else { 0 };
    let mut out = Vec::new();
    let mut h = String::from("ply\nformat binary_little_endian 1.0\n");
    h += &format!("element vertex {}\n", cloud.len());
    let normal_names: &[&str] = if normals { &["nx", "ny", "nz"] } else { &[] };
    for p in ["x", "y", "z"]
        .iter()
        .chain(normal_names)
        .chain(&["f_dc_0", "f_dc_1", "f_dc_2"])
    {
        h += &format!("property float {p}\n");
    }
    for i in 0..3 * (k - 1) {
        h += &format!("property float f_rest_{i}\n");
    }
    for p in [
        "opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3",
    ] {
        h += &format!("property float {p}\n");
    }
    h += "end_header\n";
    out.extend_from_slice(h.as_bytes());
    out.reserve(cloud.len() * (14 + extra + 3 * k) * 4);
    let mut row: Vec<f32> = Vec::with_capacity(14 + extra + 3 * k);
    for i in 0..cloud.len() {
        let sh = cloud.sh_of(i);
        row.clear();
        row.extend_from_slice(&cloud.positions[i]);
        row.extend(std::iter::repeat_n(0.0, extra));
        row.extend_from_slice(&sh[0]);
        for ch in 0..3 {
            for c in &sh[1..] {
                row.push(c[ch]);
            }
        }
        row.push(encode_exact(cloud.opacities[i], logit, sigmoid));
        row.extend(cloud.scales[i].map(|s| encode_exact(s, f64::ln, f64::exp)));
        let q = cloud.rotations[i];
        row.extend_from_slice(&[q[3], q[0], q[1], q[2]]);
        out.extend_from_slice(bytemuck::cast_slice(&row));
    }
    out
}

/// Beyond this a logit or log decodes to exactly 0 or 1 (see [`to_inria_ply`]).
const SATURATED: f32 = 110.0;

fn logit(o: f64) -> f64 {
    (o / (1.0 - o)).ln()
}

/// The f32 `x` near `inverse(v)` with `decode(x) as f32 == v`, searching ±64 ulps (nearest
/// first); the rounded inverse itself when none decodes exactly. Infinite inverses are
/// clamped to ±[`SATURATED`].
fn encode_exact(v: f32, inverse: fn(f64) -> f64, decode: fn(f64) -> f64) -> f32 {
    let x0 = (inverse(v as f64) as f32).clamp(-SATURATED, SATURATED);
    if x0.is_nan() {
        return x0;
    }
    let exact = |x: f32| (decode(x as f64) as f32).to_bits() == v.to_bits();
    let (mut up, mut down) = (x0, x0);
    for _ in 0..=64 {
        if exact(up) {
            return up;
        }
        if exact(down) {
            return down;
        }
        (up, down) = (up.next_up(), down.next_down());
    }
    x0
}
