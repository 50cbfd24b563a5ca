//! glTF JSON, byte level: bytes as a `.gltf` (external buffers answered by a denying resolver).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| splatgl_fuzz::check_file(data, "fuzz.gltf"));
