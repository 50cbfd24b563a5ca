//! antimatter15 `.splat` (32-byte records): bytes as a `.splat`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.splat"));
