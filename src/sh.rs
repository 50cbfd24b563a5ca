//! Real spherical harmonics of degree 0..=3 in the RC's basis (Condon–Shortley phase, the
//! constants of 3DGS `computeColorFromSH`), colour evaluation, and rotation of coefficients.
//!
//! Rotation: the degree-l harmonics span a space that rotations map onto itself, so for an
//! orthogonal matrix Q there is a (2l+1)² matrix D_l (the real Wigner-D matrix) with
//! `Σ c'_m Y_m(d) = Σ c_m Y_m(Qᵀ d)` for every direction d. We obtain D_l exactly (to f64
//! rounding) by evaluating both sides at 2l+1 fixed, well-spread directions and solving the
//! linear system — no Euler-angle recursion to get wrong. The tests check the result at other
//! directions.

use crate::profile::SH_DC_BIAS;
use glam::{DMat3, DVec3};

/// Y₀₀.
pub const SH_C0: f64 = 0.282_094_791_773_878_1;
/// Degree 1 magnitude.
pub const SH_C1: f64 = 0.488_602_511_902_919_9;
/// Degree 2 constants (with the Condon–Shortley signs).
pub const SH_C2: [f64; 5] = [
    1.092_548_430_592_079,
    -1.092_548_430_592_079,
    0.315_391_565_252_52,
    -1.092_548_430_592_079,
    0.546_274_215_296_039_5,
];
/// Degree 3 constants (with the Condon–Shortley signs; Y₃,₂ uses 1.445…, see spec-notes §1).
pub const SH_C3: [f64; 7] = [
    -0.590_043_589_926_643_5,
    2.890_611_442_640_554,
    -0.457_045_799_464_465_7,
    0.373_176_332_590_115_4,
    -0.457_045_799_464_465_7,
    1.445_305_721_320_277,
    -0.590_043_589_926_643_5,
];

/// The DC coefficient whose colour (the DC term alone: `SH_C0·dc + 0.5`, RC §Lighting) is `c`:
/// `(c − 0.5) / SH_C0`, in f64, rounded once to f32. The inverse of [`color_from_dc`].
pub fn dc_from_color(c: f64) -> f32 {
    ((c - SH_DC_BIAS) / SH_C0) as f32
}

/// The colour of a DC coefficient alone: `SH_C0·dc + 0.5` (before any clamping).
pub fn color_from_dc(dc: f32) -> f64 {
    dc as f64 * SH_C0 + SH_DC_BIAS
}

/// Evaluates the 16 basis functions at a unit direction (coefficient order of the cloud).
pub fn basis(d: [f64; 3]) -> [f64; 16] {
    let [x, y, z] = d;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    [
        SH_C0,
        -SH_C1 * y,
        SH_C1 * z,
        -SH_C1 * x,
        SH_C2[0] * x * y,
        SH_C2[1] * y * z,
        SH_C2[2] * (2.0 * zz - xx - yy),
        SH_C2[3] * x * z,
        SH_C2[4] * (xx - yy),
        SH_C3[0] * y * (3.0 * xx - yy),
        SH_C3[1] * x * y * z,
        SH_C3[2] * y * (4.0 * zz - xx - yy),
        SH_C3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy),
        SH_C3[4] * x * (4.0 * zz - xx - yy),
        SH_C3[5] * z * (xx - yy),
        SH_C3[6] * x * (xx - 3.0 * yy),
    ]
}

/// Colour of one splat seen along unit direction `dir` (camera → mean), using degrees
/// `0..=degree` of `coeffs`: `Σ c·Y + 0.5`, negative channels clamped to 0 (RC §Lighting).
pub fn eval_color(coeffs: &[[f32; 3]], degree: u8, dir: [f32; 3]) -> [f32; 3] {
    let n = crate::cloud::sh_coeff_count(degree).min(coeffs.len());
    let y = basis(dir.map(f64::from));
    let mut c = [SH_DC_BIAS; 3];
    for (k, coef) in coeffs[..n].iter().enumerate() {
        for ch in 0..3 {
            c[ch] += y[k] * coef[ch] as f64;
        }
    }
    // `v < 0 → 0` rather than `max`, so a NaN channel stays NaN and the splat is skipped.
    c.map(|v| if v < 0.0 { 0.0 } else { v as f32 })
}

/// Real Wigner-D matrices for degrees 1..=3 of an orthogonal matrix.
#[derive(Debug, Clone)]
pub struct ShRotation {
    /// `d[l-1]` is the (2l+1)² matrix, row-major: `c'[i] = Σ_j d[i][j] c[j]`.
    d: [Vec<f64>; 3],
}

/// 7 fixed directions in general position (no two related by a symmetry of the basis).
const SAMPLE_DIRS: [[f64; 3]; 7] = [
    [0.267, 0.534, 0.802],
    [-0.613, 0.251, 0.749],
    [0.912, -0.329, 0.244],
    [-0.151, -0.874, 0.462],
    [0.432, 0.765, -0.478],
    [-0.812, -0.433, -0.391],
    [0.058, 0.113, -0.992],
];

impl ShRotation {
    /// The matrices for orthogonal `q` (a rotation, or a rotation with a mirror).
    pub fn new(q: DMat3) -> Self {
        let qt = q.transpose();
        let d = [1usize, 2, 3].map(|l| {
            let n = 2 * l + 1;
            let off = l * l;
            // A[k][m] = Y_m(d_k), B[k][m] = Y_m(Qᵀ d_k); D = A⁻¹ B (so that A c' = B c).
            let mut a = vec![0.0; n * n];
            let mut b = vec![0.0; n * n];
            for k in 0..n {
                let dir = DVec3::from_array(SAMPLE_DIRS[k]).normalize();
                let ya = basis(dir.to_array());
                let yb = basis((qt * dir).to_array());
                for m in 0..n {
                    a[k * n + m] = ya[off + m];
                    b[k * n + m] = yb[off + m];
                }
            }
            solve(&mut a, &mut b, n);
            // Entries within solver noise of 0 or ±1 are those values: a 180° turn about an
            // axis (whose matrices are diagonal ±1) then moves coefficients without rounding.
            for v in &mut b {
                let r = v.round();
                if r.abs() <= 1.0 && (*v - r).abs() <= 1e-12 {
                    *v = r;
                }
            }
            b
        });
        ShRotation { d }
    }

    /// Rotates one splat's coefficients in place (degrees present in `coeffs`; DC unchanged).
    pub fn apply(&self, coeffs: &mut [[f32; 3]]) {
        for l in 1..=3usize {
            let (off, n) = (l * l, 2 * l + 1);
            if coeffs.len() < off + n {
                break;
            }
            let mut out = [[0.0f64; 3]; 7];
            let d = &self.d[l - 1];
            for (i, o) in out.iter_mut().enumerate().take(n) {
                for j in 0..n {
                    for ch in 0..3 {
                        o[ch] += d[i * n + j] * coeffs[off + j][ch] as f64;
                    }
                }
            }
            for i in 0..n {
                coeffs[off + i] = out[i].map(|v| v as f32);
            }
        }
    }
}

/// Solves A X = B in place (Gauss–Jordan with partial pivoting); X is left in `b`.
fn solve(a: &mut [f64], b: &mut [f64], n: usize) {
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
            .unwrap_or(col);
        for k in 0..n {
            a.swap(col * n + k, piv * n + k);
            b.swap(col * n + k, piv * n + k);
        }
        let p = a[col * n + col];
        for k in 0..n {
            a[col * n + k] /= p;
            b[col * n + k] /= p;
        }
        for r in 0..n {
            if r != col {
                let f = a[r * n + col];
                if f != 0.0 {
                    for k in 0..n {
                        a[r * n + k] -= f * a[col * n + k];
                        b[r * n + k] -= f * b[col * n + k];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(coeffs: &[[f32; 3]], d: DVec3) -> [f64; 3] {
        let y = basis(d.to_array());
        let mut c = [0.0; 3];
        for (k, cf) in coeffs.iter().enumerate() {
            for ch in 0..3 {
                c[ch] += y[k] * cf[ch] as f64;
            }
        }
        c
    }

    #[test]
    fn rotated_sh_equals_sh_at_inverse_rotated_direction() {
        let q = DMat3::from_euler(glam::EulerRot::ZYX, 0.7, -0.4, 2.1);
        let coeffs: Vec<[f32; 3]> = (0..16)
            .map(|k| {
                [
                    k as f32 * 0.1 - 0.7,
                    (k * k) as f32 * 0.01,
                    -(k as f32) * 0.05,
                ]
            })
            .collect();
        let mut rotated = coeffs.clone();
        ShRotation::new(q).apply(&mut rotated);
        for d in [
            DVec3::new(0.3, -0.2, 0.9),
            DVec3::new(-1.0, 0.4, 0.1),
            DVec3::Z,
        ] {
            let d = d.normalize();
            let want = eval(&coeffs, q.transpose() * d);
            let got = eval(&rotated, d);
            for ch in 0..3 {
                assert!((want[ch] - got[ch]).abs() < 1e-5, "{want:?} {got:?}");
            }
        }
    }

    #[test]
    fn degree1_matches_closed_form() {
        // Y_{1,-1} = -C1 y: a coefficient only there gives colour 0.5 - C1*y*c.
        let mut c = [[0.0f32; 3]; 4];
        c[1] = [1.0, 0.0, 0.0];
        let col = eval_color(&c, 1, [0.0, 1.0, 0.0]);
        assert!((col[0] - (0.5 - SH_C1 as f32)).abs() < 1e-6);
        assert_eq!(col[1], 0.5);
    }

    #[test]
    fn dc_conversions_invert_each_other_and_match_eval_color() {
        for c in [0.0, 0.1, 0.5, 0.73, 1.0, 1.4] {
            let dc = dc_from_color(c);
            assert!((color_from_dc(dc) - c).abs() < 1e-6, "{c}");
            let col = eval_color(&[[dc; 3]], 0, [0.0, 0.0, 1.0]);
            assert!((col[0] as f64 - c).abs() < 1e-6, "{c}: {col:?}");
        }
        assert_eq!(dc_from_color(0.5), 0.0);
    }
}
