//! antimatter15 `.splat`: a headerless array of 32-byte records — position f32×3, linear scale
//! f32×3, colour u8×4 (r, g, b = (0.5 + Y₀₀·f_dc)·255, a = opacity·255) and rotation u8×4
//! in the order w, x, y, z, each `(b − 128)/128`. Little endian, PLY axes, no SH.

use super::codec::{self, build_cloud, finish_cloud};
use super::{Details, LimitExceeded, LoadOptions, LoadReport, ScaleSeen};
use crate::cloud::SplatCloud;
use crate::sh::dc_from_color;

/// Bytes per record.
pub const RECORD: usize = 32;

/// What is wrong with a `.splat` file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplatError {
    /// The length is not a whole number of records.
    #[error(
        "length {len} is not a multiple of {RECORD} bytes: record {records} is truncated ({rest} of {RECORD} bytes)"
    )]
    Truncated {
        /// File length.
        len: usize,
        /// Complete records.
        records: usize,
        /// Bytes of the partial record.
        rest: usize,
    },
    /// The record count exceeds [`crate::load::Limits::max_splats`].
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
}

/// Whether `bytes` is plausibly a `.splat` file (for content detection when nothing else
/// matched): whole records, and 64 sampled records with finite positions and non-negative
/// finite scales below 10⁴ and a non-zero quaternion.
pub(crate) fn looks_like(bytes: &[u8]) -> bool {
    let n = bytes.len() / RECORD;
    if n == 0 || !bytes.len().is_multiple_of(RECORD) {
        return false;
    }
    (0..64.min(n)).all(|k| {
        let r = &bytes[(k * n / 64.min(n)) * RECORD..][..RECORD];
        let f = |a: usize| codec::f32_at(r, 4 * a);
        (0..3).all(|a| f(a).is_finite() && f(a).abs() < 1e7)
            && (3..6).all(|a| (0.0..1e4).contains(&f(a)))
            && r[28..32].iter().any(|&b| b != 128)
    })
}

/// Reads a `.splat` file from memory into `report` (findings, details, linear scales).
pub(crate) fn read(
    bytes: &[u8],
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<SplatCloud, SplatError> {
    if !bytes.len().is_multiple_of(RECORD) {
        return Err(SplatError::Truncated {
            len: bytes.len(),
            records: bytes.len() / RECORD,
            rest: bytes.len() % RECORD,
        });
    }
    let n = bytes.len() / RECORD;
    opts.limits.check_splats(n as u64, "records")?;
    let cloud = build_cloud::<std::convert::Infallible>(n, 0, |i, s| {
        let r = &bytes[i * RECORD..(i + 1) * RECORD];
        *s.position = std::array::from_fn(|a| codec::f32_at(r, 4 * a));
        *s.scale = std::array::from_fn(|a| codec::f32_at(r, 12 + 4 * a));
        s.sh[0] = std::array::from_fn(|c| dc_from_color(r[24 + c] as f64 / 255.0));
        *s.opacity = r[27] as f32 / 255.0;
        let q: [f32; 4] = std::array::from_fn(|a| (r[28 + a] as f32 - 128.0) / 128.0);
        *s.rotation = [q[1], q[2], q[3], q[0]];
        Ok(())
    });
    let Ok(mut cloud) = cloud;
    finish_cloud(
        &mut cloud,
        codec::drop_site("records", opts),
        &mut report.findings,
    );
    let mut d = Details::new("splat", "none");
    d.bits("position", 32, "f32");
    d.bits("scale", 32, "f32, linear");
    d.bits("rotation", 8, "w, x, y, z as (b − 128)/128, normalised");
    d.bits("color", 8, "b/255 = 0.5 + Y00·DC");
    d.bits("opacity", 8, "b/255 (linear)");
    d.lossy("no SH beyond the DC colour");
    d.lossy("DC colour clamped to the [0, 1] display range in steps of 1/255");
    d.lossy("rotations in steps of 1/128 per component; opacity in steps of 1/255");
    report.details = Some(d);
    report.scale_space = Some(ScaleSeen::Linear);
    Ok(cloud)
}
