//! The decompression budget of the packed readers (the rule is in the [module docs](super)).

use super::super::Limits;
use crate::cloud::sh_coeff_count;

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
