//! Covariance algebra in f64: Σ from scale + rotation, node transforms (Σ = M C Cᵀ Mᵀ), and the
//! way back from Σ to scale + rotation (symmetric eigen-decomposition).
//!
//! The loader applies node transforms with these functions and stores the result back as
//! scale and rotation: every symmetric positive semi-definite Σ is `R diag(s)² Rᵀ` for some rotation R
//! (eigenvectors, with one flipped if needed to make det R = +1), so no information is lost even
//! for non-similarity (shearing, non-uniform) node matrices. For a similarity matrix the result
//! is computed in closed form (R' = R_M·R, s' = k·s) and is exact to f32 rounding.

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix formulas

use glam::{DMat3, DQuat, DVec3};

/// Rotation matrix of a quaternion `[x, y, z, w]` (normalised here), as in the spec's C matrix.
pub fn rotation_matrix(q: [f32; 4]) -> DMat3 {
    let q = DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
    let n = q.length();
    let q = if n > 0.0 { q / n } else { DQuat::IDENTITY };
    DMat3::from_quat(q)
}

/// C = R · diag(s) — the spec's per-splat matrix.
pub fn c_matrix(scale: [f32; 3], rotation: [f32; 4]) -> DMat3 {
    let r = rotation_matrix(rotation);
    DMat3::from_cols(
        r.x_axis * scale[0] as f64,
        r.y_axis * scale[1] as f64,
        r.z_axis * scale[2] as f64,
    )
}

/// Packs a symmetric matrix as `[xx, xy, xz, yy, yz, zz]`.
pub fn pack_sym(m: DMat3) -> [f64; 6] {
    [
        m.x_axis.x, m.y_axis.x, m.z_axis.x, m.y_axis.y, m.z_axis.y, m.z_axis.z,
    ]
}

/// Unpacks `[xx, xy, xz, yy, yz, zz]` into a symmetric matrix.
pub fn unpack_sym(s: [f64; 6]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(s[0], s[1], s[2]),
        DVec3::new(s[1], s[3], s[4]),
        DVec3::new(s[2], s[4], s[5]),
    )
}

/// Σ = C Cᵀ = R diag(s)² Rᵀ, packed.
pub fn covariance_from_scale_rotation(scale: [f32; 3], rotation: [f32; 4]) -> [f64; 6] {
    let c = c_matrix(scale, rotation);
    pack_sym(c * c.transpose())
}

/// Σ = M C Cᵀ Mᵀ for a node's upper-left 3×3 `m`.
pub fn transformed_covariance(m: DMat3, scale: [f32; 3], rotation: [f32; 4]) -> DMat3 {
    let mc = m * c_matrix(scale, rotation);
    mc * mc.transpose()
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations.
/// Returns (eigenvalues, eigenvectors as the columns of a rotation matrix, det = +1).
pub fn sym_eigen(a: DMat3) -> (DVec3, DMat3) {
    let mut m = a.to_cols_array_2d(); // m[col][row]; symmetric so the layout does not matter
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0f64]];
    for _sweep in 0..32 {
        let off = m[0][1].powi(2) + m[0][2].powi(2) + m[1][2].powi(2);
        let diag = m[0][0].powi(2) + m[1][1].powi(2) + m[2][2].powi(2);
        if off <= 1e-30 * diag.max(f64::MIN_POSITIVE) || off == 0.0 {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if m[p][q] == 0.0 {
                continue;
            }
            let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // m ← Jᵀ m J, with J the rotation in the (p, q) plane.
            for k in 0..3 {
                let mkp = m[k][p];
                let mkq = m[k][q];
                m[k][p] = c * mkp - s * mkq;
                m[k][q] = s * mkp + c * mkq;
            }
            for k in 0..3 {
                let mpk = m[p][k];
                let mqk = m[q][k];
                m[p][k] = c * mpk - s * mqk;
                m[q][k] = s * mpk + c * mqk;
            }
            for row in &mut v {
                let vp = row[p];
                let vq = row[q];
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // v[row][col]: column j is eigenvector j.
    let col = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]);
    let vals = DVec3::new(m[0][0], m[1][1], m[2][2]);
    let mut vecs = DMat3::from_cols(col(0), col(1), col(2));
    if vecs.determinant() < 0.0 {
        vecs.z_axis = -vecs.z_axis;
    }
    (vals, vecs)
}

/// Decomposes a covariance into (scale, rotation `[x, y, z, w]`), Σ = R diag(s)² Rᵀ.
/// Tiny negative eigenvalues (rounding) are clamped to 0.
pub fn scale_rotation_from_covariance(sigma: DMat3) -> ([f32; 3], [f32; 4]) {
    let (vals, vecs) = sym_eigen(sigma);
    let scale = [vals.x, vals.y, vals.z].map(|l| l.max(0.0).sqrt() as f32);
    let q = DQuat::from_mat3(&vecs).normalize();
    (scale, [q.x as f32, q.y as f32, q.z as f32, q.w as f32])
}

/// The rotation of a node's 3×3 (polar decomposition M = R·P with P symmetric positive
/// semi-definite). Returns the orthogonal factor; its determinant is −1 for a mirroring matrix.
/// `None` when M is singular.
pub fn polar_rotation(m: DMat3) -> Option<DMat3> {
    let (vals, v) = sym_eigen(m.transpose() * m);
    if vals.min_element() <= 1e-24 * vals.max_element().max(f64::MIN_POSITIVE) {
        return None;
    }
    let inv_sqrt = DMat3::from_diagonal(DVec3::new(
        1.0 / vals.x.sqrt(),
        1.0 / vals.y.sqrt(),
        1.0 / vals.z.sqrt(),
    ));
    // P⁻¹ = V S⁻¹ Vᵀ; R = M P⁻¹.
    Some(m * v * inv_sqrt * v.transpose())
}

/// If `m` is a similarity (rotation × uniform positive scale, within `tol` relative),
/// returns (rotation, scale factor).
pub fn as_similarity(m: DMat3, tol: f64) -> Option<(DMat3, f64)> {
    let lens = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
    let k = (lens[0] + lens[1] + lens[2]) / 3.0;
    if !(k.is_finite() && k > 0.0) || lens.iter().any(|l| (l - k).abs() > tol * k) {
        return None;
    }
    let r = m * (1.0 / k);
    let err = (r.transpose() * r - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    (err <= tol && r.determinant() > 0.0).then_some((r, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DMat3, b: DMat3, tol: f64) -> bool {
        a.to_cols_array()
            .iter()
            .zip(b.to_cols_array())
            .all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn eigen_roundtrip() {
        let s = [0.3f32, 2.0, 0.01];
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.2, 2.0);
        let sigma = unpack_sym(covariance_from_scale_rotation(s, q.to_array()));
        let (s2, q2) = scale_rotation_from_covariance(sigma);
        let sigma2 = unpack_sym(covariance_from_scale_rotation(s2, q2));
        assert!(close(sigma, sigma2, 1e-6), "{sigma:?} vs {sigma2:?}");
    }

    #[test]
    fn shear_decomposes_exactly() {
        let m = DMat3::from_cols_array(&[1.0, 0.5, 0.0, 0.0, 2.0, 0.3, 0.2, 0.0, 0.7]);
        let sigma = transformed_covariance(m, [0.5, 1.0, 0.25], [0.1, 0.2, 0.3, 0.9]);
        let (s, q) = scale_rotation_from_covariance(sigma);
        let back = unpack_sym(covariance_from_scale_rotation(s, q));
        assert!(close(sigma, back, 1e-6));
    }

    #[test]
    fn polar_of_scaled_rotation() {
        let r = DMat3::from_quat(DQuat::from_rotation_y(0.7));
        let m = r * DMat3::from_diagonal(DVec3::new(2.0, 3.0, 0.5));
        let got = polar_rotation(m).unwrap();
        assert!(close(got, r, 1e-9));
        assert!(as_similarity(m, 1e-6).is_none());
        let (r2, k) = as_similarity(r * 3.0, 1e-6).unwrap();
        assert!(close(r2, r, 1e-12) && (k - 3.0).abs() < 1e-12);
    }
}
