//! What the SPZ, `.splat`, `.ksplat` and SOG readers share: the decompression budget,
//! bounded gzip / raw-deflate / zstd decoding, half floats, the SH sign table for axis flips,
//! the parallel cloud builder and the pass that drops splats a renderer cannot use.
//!
//! **Budget rule** (one for every compressed format): for an input of `L` bytes, the data it
//! decompresses or decodes to plus the cloud built from it take at most the smaller of
//! [`BUDGET_BASE`] + [`BUDGET_PER_INPUT_BYTE`] × `L` bytes (16 MiB + 64 × L) and
//! [`Limits::max_decompressed_bytes`](crate::files::Limits::max_decompressed_bytes) (4 GiB by default, the embedder's cap) — [`budget_for`].
//! Sizes claimed by headers are checked against it (and splat counts against
//! [`Limits::max_splats`](crate::files::Limits::max_splats)) before anything is allocated, and decompression stops as soon as it
//! would pass it, so a gzip bomb or a header that lies about its count costs at most that much
//! memory. The input is the file (SPZ, SOG bundle), the meta.json and textures of an unbundled
//! SOG together, or one glTF SPZ payload.

//!
//! One job per file: [`budget`](budget_for) (the rule above), bounded decompression
//! (`inflate.rs`), half floats (`half.rs`), axis flips (`axes.rs`), the cloud builder and the
//! finishing pass (`build.rs`), little-endian reads (`bytes.rs`).

mod axes;
mod budget;
mod build;
mod bytes;
mod half;
mod inflate;

pub use axes::{flip_axes, flip_signs, sh_flip_signs};
pub use budget::{BUDGET_BASE, BUDGET_PER_INPUT_BYTE, BUDGET_RULE, budget_for, cloud_bytes};
pub use build::{SplatMut, build_cloud};
pub(crate) use build::{drop_site, finish_cloud};
pub use bytes::{f32_at, u16_at, u32_at, u64_at};
pub use half::{f16_to_f32, f32_to_f16};
pub use inflate::{InflateError, inflate_exact, unzstd_exact};

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
