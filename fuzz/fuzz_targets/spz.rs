//! Niantic SPZ v1–v4 (gzip, uncompressed legacy, zstd streams): bytes as a `.spz`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.spz"));
