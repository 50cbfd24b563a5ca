//! Little-endian integer and float reads at checked offsets.

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
