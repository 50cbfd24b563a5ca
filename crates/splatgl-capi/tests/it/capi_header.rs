//! `include/splatgl.h` is what cbindgen makes of this crate's `src/` with `cbindgen.toml`: the header
//! C hosts compile against cannot drift from the library they link. `SPLATGL_BLESS=1`
//! rewrites it.

use std::path::Path;

#[test]
fn committed_header_is_what_cbindgen_generates() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    // The C API's module only (with its submodules; the crate's other public constants are
    // not C API).
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/lib.rs"))
        .generate()
        .expect("cbindgen parses the C API crate")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = root.join("include/splatgl.h");
    if std::env::var_os("SPLATGL_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    // Every entry point the C examples use is declared.
    for f in [
        "splatgl_renderer_new",
        "splatgl_renderer_draw",
        "splatgl_cloud_from_arrays",
        "splatgl_last_error",
        "SPLATGL_ERROR_WRONG_THREAD",
    ] {
        assert!(
            generated.contains(f),
            "{f} missing from the generated header"
        );
    }
    assert!(
        committed == generated,
        "crates/splatgl-capi/include/splatgl.h differs from what cbindgen generates from its src/ \
         (regenerate: SPLATGL_BLESS=1 cargo test -p splatgl-capi capi_header)"
    );
}
