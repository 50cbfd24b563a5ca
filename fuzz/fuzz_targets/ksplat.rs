//! mkkellogg `.ksplat` (levels 0–2, sections, buckets): bytes as a `.ksplat`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.ksplat"));
