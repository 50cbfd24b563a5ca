//! INRIA 3DGS PLY writer.

use crate::cloud::SplatCloud;

/// Writes a cloud as INRIA binary little-endian PLY (log scale, logit opacity, w-first
/// quaternion, channel-major `f_rest`) — the inverse of the
/// [PLY loader](crate::load::ply), used by tests and benches.
pub fn to_inria_ply(cloud: &SplatCloud) -> Vec<u8> {
    let k = cloud.coeffs_per_splat();
    let mut out = Vec::new();
    let mut h = String::from("ply\nformat binary_little_endian 1.0\n");
    h += &format!("element vertex {}\n", cloud.len());
    for p in ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2"] {
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
    out.reserve(cloud.len() * (14 + 3 * k) * 4);
    for i in 0..cloud.len() {
        let sh = cloud.sh_of(i);
        let mut row: Vec<f32> = Vec::with_capacity(14 + 3 * k);
        row.extend_from_slice(&cloud.positions[i]);
        row.extend_from_slice(&sh[0]);
        for ch in 0..3 {
            for c in &sh[1..] {
                row.push(c[ch]);
            }
        }
        let o = cloud.opacities[i] as f64;
        row.push((o / (1.0 - o)).ln() as f32);
        row.extend(cloud.scales[i].map(f32::ln));
        let q = cloud.rotations[i];
        row.extend_from_slice(&[q[3], q[0], q[1], q[2]]);
        out.extend_from_slice(bytemuck::cast_slice(&row));
    }
    out
}
