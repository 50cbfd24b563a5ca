//! 3DGS `cameras.json`: bytes as text; every parsed entry must make a valid camera or a
//! precise error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_cameras_json(data));
