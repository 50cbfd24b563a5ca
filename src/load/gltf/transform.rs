//! Applying a node's global transform to a local-space cloud (RC §Splat Reconstruction).

use crate::cloud::SplatCloud;
use crate::covariance::{
    as_similarity, polar_rotation, scale_rotation_from_covariance, transformed_covariance,
};
use crate::load::finding::Finding;
use crate::sh::ShRotation;
use glam::{DMat3, DMat4, DQuat, DVec3};

/// Checks the RC's decomposability conditions for a node matrix (SHOULDs: warnings).
fn check_decomposable(m: DMat3, node: usize, findings: &mut Vec<Finding>) {
    let path = format!("nodes[{node}]");
    let lens = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
    if lens.iter().any(|l| !(l.is_finite() && *l > 0.0)) {
        findings.push(Finding::warning(
            path,
            "global transform has a zero or non-finite column: not decomposable, splat rendering is undefined (RC)",
        ));
        return;
    }
    let n = DMat3::from_cols(m.x_axis / lens[0], m.y_axis / lens[1], m.z_axis / lens[2]);
    if (n.determinant() - 1.0).abs() > 1e-3 {
        findings.push(Finding::warning(
            path,
            format!(
                "global transform is not rotation × positive scale (det of the normalised 3×3 = {:.4}): splat rendering is undefined (RC)",
                n.determinant()
            ),
        ));
    }
}

/// Returns the cloud in global space under `m` (the node's global matrix). Values the
/// transform makes non-finite (huge matrices, SH near f32::MAX rotated, covariances that
/// overflow) are left for the caller's hygiene pass to drop.
pub fn apply(local: &SplatCloud, m: DMat4, node: usize, findings: &mut Vec<Finding>) -> SplatCloud {
    let mut out = local.clone();
    if m == DMat4::IDENTITY {
        return out;
    }
    let m3 = DMat3::from_mat4(m);
    // Rotation, similarity test and decomposability do not depend on M's overall scale: judge
    // them on M / max|Mᵢⱼ|, so huge but finite node chains do not overflow MᵀM or the column
    // lengths (which made the SH rotation NaN).
    let big = m3
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let (unit, big) = if big.is_finite() && big > 0.0 {
        (m3 * (1.0 / big), big)
    } else {
        (m3, 1.0)
    };
    check_decomposable(unit, node, findings);
    for p in &mut out.positions {
        let g = m.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
        *p = [g.x as f32, g.y as f32, g.z as f32];
    }
    if m3 != DMat3::IDENTITY {
        match as_similarity(unit, 1e-6) {
            Some((r, k)) => {
                let k = k * big;
                let qm = DQuat::from_mat3(&r).normalize();
                for (s, q) in out.scales.iter_mut().zip(out.rotations.iter_mut()) {
                    *s = s.map(|v| (v as f64 * k) as f32);
                    let ql = DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
                    // |qm · ql| = |ql|: the product is rounded to f32 and normalised only
                    // where f32 rounding is not all that separates it from unit length, so a
                    // 180° turn about an axis (qm a unit axis quaternion) moves quaternions
                    // without rounding.
                    let g = qm * ql;
                    let g = [g.x as f32, g.y as f32, g.z as f32, g.w as f32];
                    *q = crate::load::normalize_quat(g).map_or(g, |(n, _)| n);
                }
            }
            None => {
                for (s, q) in out.scales.iter_mut().zip(out.rotations.iter_mut()) {
                    let sigma = transformed_covariance(m3, *s, *q);
                    (*s, *q) = scale_rotation_from_covariance(sigma);
                }
            }
        }
        if out.sh_degree > 0 {
            match polar_rotation(unit) {
                Some(r) => {
                    let rot = ShRotation::new(r);
                    let k = out.coeffs_per_splat();
                    for c in out.sh.chunks_exact_mut(k) {
                        rot.apply(c);
                    }
                }
                None => findings.push(Finding::warning(
                    format!("nodes[{node}]"),
                    "singular transform: SH coefficients left unrotated",
                )),
            }
        }
    }
    out
}

/// The node transform of `apply` (above), then the loader contract on the result: `None` (with
/// a blocking finding at `nodes[node]` naming the first broken splat) when the transform made a
/// value non-finite.
pub fn apply_checked(
    local: &SplatCloud,
    m: DMat4,
    node: usize,
    findings: &mut Vec<Finding>,
) -> Option<SplatCloud> {
    let out = apply(local, m, node, findings);
    match out.validate() {
        Ok(()) => Some(out),
        Err(v) => {
            let mut f = Finding::fatal(format!("nodes[{node}]"), v.message);
            if let Some(i) = v.index {
                f = f.at(i as u64);
            }
            findings.push(f);
            None
        }
    }
}
