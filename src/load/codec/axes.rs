//! Axis flips of whole clouds: the signs positions, quaternions and SH coefficients take.

use crate::cloud::SplatCloud;
use rayon::prelude::*;

/// Which axes each real SH basis function of degree 1..=3 is odd in (bit 0 = x, 1 = y,
/// 2 = z), in our order (degree-major, m = −l..l, DC excluded): y, z, x; xy, yz, 3z²−1, xz,
/// x²−y²; y(3x²−y²), xyz, y(5z²−1), z(5z²−3), x(5z²−1), z(x²−y²), x(x²−3y²).
const SH_ODD_AXES: [u8; 15] = [2, 4, 1, 3, 6, 0, 5, 0, 2, 7, 2, 4, 1, 4, 1];

/// The sign each of the 15 non-DC SH coefficients takes when the axes in `flip` (x, y, z) are
/// negated: a basis function odd in an odd number of the flipped axes changes sign.
pub fn sh_flip_signs(flip: [bool; 3]) -> [f32; 15] {
    let mask = flip[0] as u8 | (flip[1] as u8) << 1 | (flip[2] as u8) << 2;
    SH_ODD_AXES.map(|odd| {
        if (odd & mask).count_ones() % 2 == 1 {
            -1.0
        } else {
            1.0
        }
    })
}

/// Signs of an axis flip F = diag(s): for positions (x, y, z) and for a quaternion's x, y, z
/// (F R F is a rotation for any signs: its quaternion is (x·sy·sz, y·sx·sz, z·sx·sy, w)).
pub fn flip_signs(flip: [bool; 3]) -> ([f32; 3], [f32; 3]) {
    let s = flip.map(|f| if f { -1.0f32 } else { 1.0 });
    (s, [s[1] * s[2], s[0] * s[2], s[0] * s[1]])
}

/// Negates the axes in `flip` (x, y, z) of a whole cloud — positions, quaternions and SH by
/// parity ([`flip_signs`], [`sh_flip_signs`]), as the SPZ reader does while decoding.
pub fn flip_axes(c: &mut SplatCloud, flip: [bool; 3]) {
    let (ps, qs) = flip_signs(flip);
    let shs = sh_flip_signs(flip);
    let k = c.coeffs_per_splat();
    c.positions
        .par_iter_mut()
        .for_each(|p| *p = std::array::from_fn(|a| p[a] * ps[a]));
    c.rotations
        .par_iter_mut()
        .for_each(|q| *q = [q[0] * qs[0], q[1] * qs[1], q[2] * qs[2], q[3]]);
    c.sh.par_chunks_mut(k.max(1)).for_each(|sh| {
        for (j, t) in sh.iter_mut().enumerate().skip(1) {
            *t = t.map(|v| v * shs[j - 1]);
        }
    });
}
