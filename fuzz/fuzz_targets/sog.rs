//! PlayCanvas SOG: a zip bundle or a meta.json (its textures refused): bytes as a `.sog`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.sog"));
