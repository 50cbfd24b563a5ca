//! Which format a file is, by content first: magic bytes (glTF, PLY, SPZ's `NGSP`, gzip, zip),
//! confirmed where the magic is shared (a gzip member must begin with an SPZ header, a zip
//! must hold `meta.json`), then the keys of a JSON document (SOG meta vs glTF) and a
//! self-consistent `.ksplat` layout; the extension only when the content says nothing, and
//! `.splat` (which has no header) last, by plausibility. A file whose extension names another
//! format than its content loads as its content, with a warning naming both.
//!
//! To add a format: a [`Format`] variant (in `files/format.rs`) with its [`Format::name`] and
//! `Format::extensions`, its `Format::magic` here (and a [`confirmed`] rule if that magic is
//! shared), and its reader in [`super::read`].

use super::{ksplat, sog, splat, spz};
use crate::files::Format;
use std::io::Read;
use std::path::Path;

impl Format {
    /// Leading bytes that identify the format whatever the file is called (gzip and zip only
    /// once [`confirmed`]).
    fn magic(self) -> &'static [&'static [u8]] {
        match self {
            Format::Gltf | Format::Splat | Format::Ksplat => &[],
            Format::Glb => &[b"glTF"],
            Format::Ply => &[b"ply\n", b"ply\r\n"],
            Format::Spz => &[spz::MAGIC, GZIP],
            Format::Sog => &[b"PK\x03\x04"],
        }
    }
}

const GZIP: &[u8] = &[0x1f, 0x8b];

/// Whether the content past a shared magic agrees with `f`: a gzip member must begin with an
/// SPZ header (SPZ v1–v3), a zip must hold `meta.json` (bundled SOG).
fn confirmed(f: Format, bytes: &[u8]) -> bool {
    match f {
        Format::Spz if bytes.starts_with(GZIP) => {
            let mut head = [0u8; 4];
            let ok = flate2::read::GzDecoder::new(bytes)
                .read_exact(&mut head)
                .is_ok();
            ok && &head == spz::MAGIC
        }
        Format::Sog => sog::is_bundle(bytes),
        _ => true,
    }
}

/// The format the content itself shows, if any.
fn sniff(bytes: &[u8]) -> Option<Format> {
    let by_magic = Format::ALL
        .into_iter()
        .find(|&f| f.magic().iter().any(|m| bytes.starts_with(m)) && confirmed(f, bytes));
    if by_magic.is_some() {
        return by_magic;
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

fn by_extension(path: Option<&Path>) -> Option<Format> {
    let ext = path?.extension()?.to_str()?.to_ascii_lowercase();
    Format::ALL
        .into_iter()
        .find(|f| f.extensions().contains(&ext.as_str()))
}

/// Detects the format: content first (magic bytes, header, zip directory, JSON keys), then the
/// extension, then `.splat` plausibility.
pub fn detect_format(bytes: &[u8], path: Option<&Path>) -> Option<Format> {
    sniff(bytes)
        .or_else(|| by_extension(path))
        .or_else(|| splat::looks_like(bytes).then_some(Format::Splat))
}

/// The warning for a file whose extension names another format than its content, naming
/// both; `None` when they agree or there is no extension. `.gltf` and `.glb` count as one.
pub(super) fn extension_mismatch(found: Format, path: Option<&Path>) -> Option<String> {
    let ext = path?.extension()?.to_str()?;
    let gltf = |f: Format| matches!(f, Format::Gltf | Format::Glb);
    match by_extension(path) {
        Some(f) if f == found || (gltf(f) && gltf(found)) => None,
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
