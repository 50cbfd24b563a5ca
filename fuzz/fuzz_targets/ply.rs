//! PLY (INRIA binary little/big endian, ASCII, PlayCanvas compressed): bytes as a `.ply`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.ply"));
