//! What the SPZ, `.splat`, `.ksplat` and SOG readers share: the decompression budget,
//! bounded gzip / raw-deflate / zstd decoding, half floats, the SH sign table for axis flips,
//! the parallel cloud builder and the pass that drops splats a renderer cannot use.
//!
//! **Budget rule** (one for every compressed format): for an input of `L` bytes, the data it
//! decompresses or decodes to plus the cloud built from it take at most the smaller of
//! [`BUDGET_BASE`] + [`BUDGET_PER_INPUT_BYTE`] × `L` bytes (16 MiB + 64 × L) and
//! [`Limits::max_decompressed_bytes`] (4 GiB by default, the embedder's cap) — [`budget_for`].
//! Sizes claimed by headers are checked against it (and splat counts against
//! [`Limits::max_splats`]) before anything is allocated, and decompression stops as soon as it
//! would pass it, so a gzip bomb or a header that lies about its count costs at most that much
//! memory. The input is the file (SPZ, SOG bundle), the meta.json and textures of an unbundled
//! SOG together, or one glTF SPZ payload.

use super::{Finding, Limits, Severity};
use crate::cloud::{SplatCloud, sh_coeff_count};
use rayon::prelude::*;
use std::io::Read;

/// Fixed part of the decompression budget (bytes).
pub const BUDGET_BASE: u64 = 16 << 20;
/// Budget granted per input byte.
pub const BUDGET_PER_INPUT_BYTE: u64 = 64;
/// How [`budget_for`] is computed, for error messages.
pub const BUDGET_RULE: &str =
    "the smaller of 16 MiB + 64 × input size and limits.max_decompressed_bytes";

/// The decompression budget for an input of `input_len` bytes under `limits` (module docs):
/// `min(16 MiB + 64 × input_len, limits.max_decompressed_bytes)`.
pub fn budget_for(input_len: usize, limits: &Limits) -> u64 {
    BUDGET_BASE
        .saturating_add(BUDGET_PER_INPUT_BYTE.saturating_mul(input_len as u64))
        .min(limits.max_decompressed_bytes)
}

/// Bytes a cloud of `n` splats of SH degree `degree` takes while being built: its arrays, and
/// at most 24 more per splat for the numeric hygiene pass that drops bad splats (the list of
/// bad ones, 16 bytes each, then their indices, 8 each, or the kept splats' original indices,
/// 4 each); loaders charge it to the budget with the decompressed data before allocating.
pub fn cloud_bytes(n: u64, degree: u8) -> u64 {
    n.saturating_mul(12 + 12 + 16 + 4 + 24 + 12 * sh_coeff_count(degree) as u64)
}

/// Why a bounded decompression failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InflateError {
    /// The stream is corrupt or ends early.
    #[error("{0}")]
    Corrupt(String),
    /// It would decompress to more than the budget allows.
    #[error("decompresses to more than the budget of {limit} bytes ({BUDGET_RULE})")]
    OverBudget {
        /// The limit that was hit.
        limit: u64,
    },
}

/// Reads all of `r` into a vector, failing once more than `limit` bytes come out. Reads in
/// 64 KiB steps, so memory follows the real output, not a claimed size.
fn read_bounded(mut r: impl Read, limit: u64, hint: usize) -> Result<Vec<u8>, InflateError> {
    let mut out = Vec::with_capacity(hint.min(limit as usize));
    let mut buf = vec![0u8; 64 << 10];
    loop {
        let n = match r.read(&mut buf) {
            Ok(0) => return Ok(out),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(InflateError::Corrupt(e.to_string())),
        };
        if out.len() as u64 + n as u64 > limit {
            return Err(InflateError::OverBudget { limit });
        }
        out.extend_from_slice(&buf[..n]);
    }
}

/// Decompresses a raw deflate stream (zip method 8) that must give exactly `expected` bytes.
pub fn inflate_exact(bytes: &[u8], expected: u64) -> Result<Vec<u8>, InflateError> {
    let d = flate2::read::DeflateDecoder::new(bytes);
    let out = read_bounded(d, expected, expected as usize)?;
    if out.len() as u64 != expected {
        return Err(InflateError::Corrupt(format!(
            "inflates to {} bytes, expected {expected}",
            out.len()
        )));
    }
    Ok(out)
}

/// Decompresses one zstd frame that must give exactly `expected` bytes.
pub fn unzstd_exact(bytes: &[u8], expected: u64) -> Result<Vec<u8>, InflateError> {
    let mut src = bytes;
    // A frame may ask for a window of up to 3.75 TiB; allow what the output can need (a
    // power of two at least as large, 1 MiB at least), at most 128 MiB.
    let window = expected.saturating_mul(2).clamp(1 << 20, 1 << 27);
    let d = ruzstd::decoding::StreamingDecoder::new_with_max_window_size(&mut src, window)
        .map_err(|e| InflateError::Corrupt(format!("zstd frame header: {e}")))?;
    let out = read_bounded(d, expected, expected as usize)?;
    if out.len() as u64 != expected {
        return Err(InflateError::Corrupt(format!(
            "zstd frame gives {} bytes, expected {expected}",
            out.len()
        )));
    }
    Ok(out)
}

/// IEEE 754 binary16 → f32 (subnormals, infinities and NaN included).
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let man = (h & 0x3ff) as u32;
    let bits = match (exp, man) {
        (0, 0) => sign,
        (0, m) => {
            // Subnormal: value = m · 2^−24.
            let v = m as f32 * (1.0 / 16_777_216.0);
            return if sign != 0 { -v } else { v };
        }
        (0x1f, m) => sign | 0x7f80_0000 | (m << 13),
        (e, m) => sign | ((e + 112) << 23) | (m << 13),
    };
    f32::from_bits(bits)
}

/// f32 → binary16, rounding to nearest even (used by tests and writers).
pub fn f32_to_f16(v: f32) -> u16 {
    let b = v.to_bits();
    let sign = ((b >> 16) & 0x8000) as u16;
    let exp = ((b >> 23) & 0xff) as i32;
    let man = b & 0x7f_ffff;
    if exp == 0xff {
        return sign | 0x7c00 | if man != 0 { 0x200 } else { 0 };
    }
    let e = exp - 127 + 15;
    if e >= 0x1f {
        return sign | 0x7c00;
    }
    if e <= 0 {
        if e < -10 {
            return sign;
        }
        let m = man | 0x80_0000;
        let shift = (14 - e) as u32;
        let half = 1u32 << (shift - 1);
        let rounded = (m + half - 1 + ((m >> shift) & 1)) >> shift;
        return sign | rounded as u16;
    }
    let rounded = man + 0xfff + ((man >> 13) & 1);
    if rounded & 0x80_0000 != 0 {
        return sign | (((e + 1) as u16) << 10);
    }
    sign | ((e as u16) << 10) | (rounded >> 13) as u16
}

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

/// One splat's slots in a cloud being filled.
pub struct SplatMut<'a> {
    /// Mean.
    pub position: &'a mut [f32; 3],
    /// Linear scale.
    pub scale: &'a mut [f32; 3],
    /// Quaternion `[x, y, z, w]` (normalised when the reader finishes the cloud).
    pub rotation: &'a mut [f32; 4],
    /// Linear opacity.
    pub opacity: &'a mut f32,
    /// `sh_coeff_count(degree)` RGB triples, degree-major.
    pub sh: &'a mut [[f32; 3]],
}

/// Builds a cloud of `n` splats by calling `fill(i, slots)` for every index in parallel (no
/// allocation per splat). `n` must already be justified by the input (checked by the caller).
pub fn build_cloud<E: Send>(
    n: usize,
    degree: u8,
    fill: impl Fn(usize, SplatMut<'_>) -> Result<(), E> + Sync,
) -> Result<SplatCloud, E> {
    let k = sh_coeff_count(degree);
    let mut c = SplatCloud::new(degree);
    c.positions = vec![[0.0; 3]; n];
    c.scales = vec![[0.0; 3]; n];
    c.rotations = vec![[0.0, 0.0, 0.0, 1.0]; n];
    c.opacities = vec![0.0; n];
    c.sh = vec![[0.0; 3]; n * k];
    c.positions
        .par_iter_mut()
        .zip(c.scales.par_iter_mut())
        .zip(c.rotations.par_iter_mut())
        .zip(c.opacities.par_iter_mut())
        .zip(c.sh.par_chunks_mut(k.max(1)))
        .enumerate()
        .with_min_len(1024)
        .try_for_each(|(i, ((((position, scale), rotation), opacity), sh))| {
            fill(
                i,
                SplatMut {
                    position,
                    scale,
                    rotation,
                    opacity,
                    sh,
                },
            )
        })?;
    Ok(c)
}

/// Normalises every quaternion (zero and non-finite ones are left as they are) and, when
/// `drop_at` names a finding path, drops the splats that break the loader contract through the
/// numeric hygiene pass (`hygiene.rs`: any non-finite value, a negative scale or one whose
/// square overflows, an opacity outside [0, 1], a zero quaternion), with a warning per field
/// naming the count and the first index. With `None` the bad splats stay for the caller's pass:
/// in strict mode (the load fails naming the splat) and inside glTF (the primitive's pass names
/// the JSON path).
pub(crate) fn finish_cloud(c: &mut SplatCloud, drop_at: Option<&str>, findings: &mut Vec<Finding>) {
    c.rotations.par_iter_mut().for_each(|q| {
        if let Some((n, _)) = super::normalize_quat(*q) {
            *q = n;
        }
    });
    let Some(path) = drop_at else {
        return;
    };
    let site = super::hygiene::Site {
        path,
        what: "",
        severity: Severity::Warning,
        strict: false,
        origin: None,
    };
    // Not strict: the pass drops and reports, it never fails.
    super::hygiene::clean(c, &site, findings).ok();
}

/// Where a packed reader's [`finish_cloud`] drops bad splats: at `path`, unless the load is
/// strict (then the exit pass of `load::read` fails on the first one).
pub(crate) fn drop_site<'a>(path: &'a str, opts: &super::LoadOptions) -> Option<&'a str> {
    (!opts.strict).then_some(path)
}

/// Little-endian readers over a byte slice whose bounds the caller has checked.
pub fn u16_at(b: &[u8], o: usize) -> u16 {
    u16::from_le_bytes([b[o], b[o + 1]])
}
/// See [`u16_at`].
pub fn u32_at(b: &[u8], o: usize) -> u32 {
    u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]])
}
/// See [`u16_at`].
pub fn u64_at(b: &[u8], o: usize) -> u64 {
    u64::from_le_bytes(std::array::from_fn(|i| b[o + i]))
}
/// See [`u16_at`].
pub fn f32_at(b: &[u8], o: usize) -> f32 {
    f32::from_bits(u32_at(b, o))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_round_trip_and_decode_specials() {
        for v in [
            0.0f32,
            1.0,
            -2.5,
            65504.0,
            6.1035156e-5,
            5.9604645e-8,
            0.333,
        ] {
            let back = f16_to_f32(f32_to_f16(v));
            assert!((back - v).abs() <= v.abs() * 1e-3 + 6e-8, "{v} → {back}");
        }
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert!(f16_to_f32(0x7c00).is_infinite() && f16_to_f32(0x7e00).is_nan());
        assert_eq!(f16_to_f32(0x0001), 5.9604645e-8);
    }

    #[test]
    fn sh_flip_signs_match_the_basis_under_reflection() {
        // Y_k(F d) = sign_k · Y_k(d) for every flip F and direction d.
        let dirs = [[0.3, -0.5, 0.81], [-0.7, 0.2, 0.1], [0.1, 0.9, -0.4]];
        for mask in 0..8u8 {
            let flip = [mask & 1 != 0, mask & 2 != 0, mask & 4 != 0];
            let s = sh_flip_signs(flip);
            for d in dirs {
                let fd: [f64; 3] = std::array::from_fn(|a| if flip[a] { -d[a] } else { d[a] });
                let (y, yf) = (crate::sh::basis(d), crate::sh::basis(fd));
                for k in 0..15 {
                    assert!(
                        (yf[k + 1] - s[k] as f64 * y[k + 1]).abs() < 1e-12,
                        "{mask} {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn bounded_inflate_stops_at_the_expected_size() {
        use std::io::Write;
        let mut e = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::best());
        e.write_all(&vec![0u8; 1 << 20]).unwrap();
        let z = e.finish().unwrap();
        assert_eq!(inflate_exact(&z, 1 << 20).unwrap().len(), 1 << 20);
        assert_eq!(
            inflate_exact(&z, 1000),
            Err(InflateError::OverBudget { limit: 1000 })
        );
        assert!(matches!(
            inflate_exact(&z, 2 << 20),
            Err(InflateError::Corrupt(_))
        ));
        assert!(matches!(
            inflate_exact(&z[..z.len() / 2], 1 << 20),
            Err(InflateError::Corrupt(_))
        ));
    }
}
