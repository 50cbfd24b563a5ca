//! Binary glTF: bytes as a `.glb` (framing, JSON chunk, BIN chunk).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.glb"));
