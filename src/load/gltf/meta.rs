//! The `KHR_gaussian_splatting` object of a primitive → [`SplatMeta`], with missing, mistyped
//! and unknown values reported.

use super::container::EXT;
use crate::cloud::{ColorSpace, Kernel, Known, Projection, SortingMethod, SplatMeta};
use crate::load::Finding;
use serde_json::{Map, Value};

/// Reads the extension object into [`SplatMeta`], reporting missing/unknown values.
/// `used` is the document's `extensionsUsed` (extensions nested in the object must be listed
/// there, RC §Extending the Base Extension).
pub fn read(
    ext: &Map<String, Value>,
    path: &str,
    used: &[&str],
    f: &mut Vec<Finding>,
) -> SplatMeta {
    let p = format!("{path}.extensions.{EXT}");
    let mut get = |key: &str, required: bool| string(ext, &p, key, required, f);
    let (k, c) = (get("kernel", true), get("colorSpace", true));
    let (pr, s) = (get("projection", false), get("sortingMethod", false));
    let mut meta = SplatMeta::default();
    if let Some(k) = k {
        meta.kernel = Kernel::parse(&k);
    }
    if let Some(c) = c {
        meta.color_space = ColorSpace::parse(&c);
    }
    if let Some(v) = pr {
        meta.projection = Projection::parse(&v);
    }
    if let Some(v) = s {
        meta.sorting_method = SortingMethod::parse(&v);
    }
    report_unknown(&meta, &p, f);
    if let Some(exts) = ext.get("extensions").and_then(Value::as_object) {
        check_nested(exts, &p, used, f);
    }
    meta
}

/// The string property `key` of the extension object `ext` (at JSON path `p`); one of another
/// type, or a missing `required` one, is reported.
fn string(
    ext: &Map<String, Value>,
    p: &str,
    key: &str,
    required: bool,
    f: &mut Vec<Finding>,
) -> Option<String> {
    match ext.get(key) {
        Some(Value::String(s)) => Some(s.clone()),
        Some(_) => {
            f.push(Finding::error(format!("{p}.{key}"), "must be a string"));
            None
        }
        None if required => {
            f.push(Finding::error(
                format!("{p}.{key}"),
                format!("required property '{key}' is missing"),
            ));
            None
        }
        None => None,
    }
}

/// A warning for each property of `meta` with a value splatgl does not know, naming the value
/// it renders with instead.
fn report_unknown(meta: &SplatMeta, p: &str, f: &mut Vec<Finding>) {
    let unknown = [
        ("kernel", unknown_of(&meta.kernel), "ellipse"),
        (
            "colorSpace",
            unknown_of(&meta.color_space),
            "srgb_rec709_display",
        ),
        ("projection", unknown_of(&meta.projection), "perspective"),
        (
            "sortingMethod",
            unknown_of(&meta.sorting_method),
            "cameraDistance",
        ),
    ];
    for (key, val, fallback) in unknown {
        if let Some(v) = val {
            f.push(Finding::warning(
                format!("{p}.{key}"),
                format!("unknown value {v:?}; rendering as {fallback:?}"),
            ));
        }
    }
}

/// The extensions nested in the extension object (`p` is its JSON path): each must be in
/// `used`; SPZ_2 is read by the primitive reader, other compression is unsupported, the rest
/// ignored with a warning.
fn check_nested(exts: &Map<String, Value>, p: &str, used: &[&str], f: &mut Vec<Finding>) {
    for name in exts.keys() {
        let ep = format!("{p}.extensions.{name}");
        if !used.contains(&name.as_str()) {
            f.push(Finding::error(
                &ep,
                format!("{name:?} MUST also be listed in extensionsUsed"),
            ));
        }
        if name == super::spz::SPZ_2 {
            // Read by the primitive reader (`spz.rs`).
        } else if name.to_ascii_lowercase().contains("compression") {
            f.push(Finding::unsupported(
                ep,
                format!("compression extension {name:?} is not supported (yet)"),
            ));
        } else {
            f.push(Finding::warning(
                ep,
                format!("extension {name:?} is not known to splatgl; ignored"),
            ));
        }
    }
}

/// The text of a value splatgl does not know, `None` for a known one.
fn unknown_of<T>(k: &Known<T>) -> Option<&str> {
    match k {
        Known::Unknown(s) => Some(s),
        Known::Known(_) => None,
    }
}
