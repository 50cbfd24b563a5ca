//! 3D Tiles / streamed-SOG `tileset.json`: JSON and content URIs; nothing loads from outside
//! the tileset's folder, and an http URI resolves under its folder or is refused.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_tileset(data));
