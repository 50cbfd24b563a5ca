//! Bounded gzip / raw-deflate / zstd decoding: output checked against the budget as it grows.

use super::budget::BUDGET_RULE;
use std::io::Read;

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
