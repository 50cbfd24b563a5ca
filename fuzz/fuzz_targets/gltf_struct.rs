//! glTF, structure aware: the input is a list of edits to a valid generated document (node
//! transforms, SH up to degree 3, cameras) — JSON values replaced or inserted, buffer floats
//! overwritten — so transforms, SH rotation and every attribute path are reached, not only
//! the JSON parser.
#![no_main]
libfuzzer_sys::fuzz_target!(|input: splatgl_fuzz::gltf_edit::Input| {
    splatgl_fuzz::gltf_edit::run(&input)
});
