//! Which format a file is: magic bytes first, then the extension, then a look at the content.
//!
//! To add a format: a [`Format`] variant with its [`Format::name`], [`Format::magic`] and
//! [`Format::extensions`], and its reader in [`super::read`]. Formats splatgl recognises but
//! does not read yet are listed in [`NOT_YET`], so they fail by name.

use std::path::Path;

/// The file formats splatgl reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// glTF JSON (`.gltf`).
    Gltf,
    /// Binary glTF (`.glb`).
    Glb,
    /// INRIA 3DGS PLY (binary little/big endian or ASCII), and PlayCanvas compressed PLY.
    Ply,
}

impl Format {
    /// Every format, in the order detection tries them.
    const ALL: [Format; 3] = [Format::Gltf, Format::Glb, Format::Ply];

    /// Short lowercase name used in `info` output.
    pub fn name(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Ply => "ply",
        }
    }

    /// Leading bytes that identify the format whatever the file is called.
    fn magic(self) -> &'static [&'static [u8]] {
        match self {
            Format::Gltf => &[],
            Format::Glb => &[b"glTF"],
            Format::Ply => &[b"ply\n", b"ply\r\n"],
        }
    }

    /// File extensions (lowercase, without the dot).
    fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Gltf => &["gltf"],
            Format::Glb => &["glb"],
            Format::Ply => &["ply"],
        }
    }
}

/// Splat formats splatgl recognises but does not read yet: (name, magic, extensions).
pub(super) const NOT_YET: &[(&str, &[u8], &[&str])] = &[
    ("Niantic SPZ", b"NGSP", &["spz"]),
    ("antimatter15 .splat", b"", &["splat"]),
    ("mkkellogg .ksplat", b"", &["ksplat"]),
    ("PlayCanvas SOG", b"", &["sog"]),
];

fn extension(path: Option<&Path>) -> Option<String> {
    path.and_then(|p| p.extension())
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
}

/// Detects the format from magic bytes, then the extension; a file that is neither but starts
/// with `{` is taken for glTF JSON.
pub fn detect_format(bytes: &[u8], path: Option<&Path>) -> Option<Format> {
    let by_magic = Format::ALL
        .into_iter()
        .find(|f| f.magic().iter().any(|m| bytes.starts_with(m)));
    if by_magic.is_some() {
        return by_magic;
    }
    let ext = extension(path);
    let by_ext = Format::ALL
        .into_iter()
        .find(|f| ext.as_deref().is_some_and(|e| f.extensions().contains(&e)));
    if by_ext.is_some() {
        return by_ext;
    }
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    (first == Some(&b'{')).then_some(Format::Gltf)
}

/// The name of a format splatgl recognises but does not read yet.
pub(super) fn not_yet(bytes: &[u8], path: Option<&Path>) -> Option<&'static str> {
    let ext = extension(path);
    NOT_YET.iter().find_map(|&(name, magic, exts)| {
        let by_magic = !magic.is_empty() && bytes.starts_with(magic);
        let by_ext = ext.as_deref().is_some_and(|e| exts.contains(&e));
        (by_magic || by_ext).then_some(name)
    })
}
