//! Format detection by content: magic bytes (glTF, PLY, SPZ's `NGSP`, gzip wrapping an SPZ
//! header, zip), a zip directory holding `meta.json` (SOG), the keys of a JSON document (SOG
//! meta vs glTF), a self-consistent `.ksplat` layout; the extension only when the content says
//! nothing, and `.splat` (which has no header) last, by plausibility.

use super::{Format, ksplat, sog, splat, spz};
use std::io::Read;
use std::path::Path;

/// The format the content itself shows, if any.
pub(crate) fn sniff(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Some(Format::Ply);
    }
    if bytes.starts_with(spz::MAGIC) {
        return Some(Format::Spz);
    }
    if bytes.starts_with(&[0x1f, 0x8b]) {
        // A gzip member: SPZ v1–v3 if it begins with an SPZ header.
        let mut head = [0u8; 4];
        let ok = flate2::read::GzDecoder::new(bytes)
            .read_exact(&mut head)
            .is_ok();
        return (ok && &head == spz::MAGIC).then_some(Format::Spz);
    }
    if sog::is_bundle(bytes) {
        return Some(Format::Sog);
    }
    if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
        return Some(if sog::is_meta_json(bytes) {
            Format::Sog
        } else {
            Format::Gltf
        });
    }
    ksplat::looks_like(bytes).then_some(Format::Ksplat)
}

/// The format an extension names (`meta.json` and other `.json` files: SOG).
pub(crate) fn by_extension(path: Option<&Path>) -> Option<Format> {
    let ext = path?.extension()?.to_str()?.to_ascii_lowercase();
    Some(match ext.as_str() {
        "gltf" => Format::Gltf,
        "glb" => Format::Glb,
        "ply" => Format::Ply,
        "spz" => Format::Spz,
        "splat" => Format::Splat,
        "ksplat" => Format::Ksplat,
        "sog" | "json" => Format::Sog,
        _ => return None,
    })
}

/// Content first, then the extension, then `.splat` plausibility.
pub(crate) fn detect(bytes: &[u8], path: Option<&Path>) -> Option<Format> {
    sniff(bytes)
        .or_else(|| by_extension(path))
        .or_else(|| splat::looks_like(bytes).then_some(Format::Splat))
}

/// The warning for a file whose extension names another format than its content, naming
/// both; `None` when they agree or there is no extension. `.gltf` and `.glb` count as one.
pub(crate) fn extension_mismatch(found: Format, path: Option<&Path>) -> Option<String> {
    let ext = path?.extension()?.to_str()?;
    let same = |f: Format| {
        f == found
            || matches!(
                (f, found),
                (Format::Gltf | Format::Glb, Format::Gltf | Format::Glb)
            )
    };
    match by_extension(path) {
        Some(f) if same(f) => None,
        Some(f) => Some(format!(
            "the extension '.{ext}' says {}, the content is {}: loaded as {}",
            f.name(),
            found.name(),
            found.name()
        )),
        None => Some(format!(
            "the extension '.{ext}' names no splat format; the content is {}",
            found.name()
        )),
    }
}
