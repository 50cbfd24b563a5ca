//! [`Format`]: which file format a cloud was read from. The name of a format and the file
//! extensions that stand for it live here, below every stage that needs to know the format
//! (the up-axis rule of `camera`, the loaders); recognising a file's format by its content is
//! the loader's (`load::detect_format`).

/// The file formats splatgl reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// glTF JSON (`.gltf`).
    Gltf,
    /// Binary glTF (`.glb`).
    Glb,
    /// INRIA 3DGS PLY (binary little/big endian or ASCII), and PlayCanvas compressed PLY.
    Ply,
    /// Niantic SPZ, versions 1–4.
    Spz,
    /// antimatter15 `.splat`.
    Splat,
    /// mkkellogg `.ksplat`.
    Ksplat,
    /// PlayCanvas SOG (bundled `.sog` or `meta.json` + WebP).
    Sog,
}

impl Format {
    /// Every format, in the order detection tries their magic bytes.
    pub(crate) const ALL: [Format; 7] = [
        Format::Gltf,
        Format::Glb,
        Format::Ply,
        Format::Spz,
        Format::Splat,
        Format::Ksplat,
        Format::Sog,
    ];

    /// Short lowercase name used in `info` output.
    pub fn name(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Ply => "ply",
            Format::Spz => "spz",
            Format::Splat => "splat",
            Format::Ksplat => "ksplat",
            Format::Sog => "sog",
        }
    }

    /// File extensions (lowercase, without the dot); `meta.json` and other `.json`: SOG.
    pub(crate) fn extensions(self) -> &'static [&'static str] {
        match self {
            Format::Gltf => &["gltf"],
            Format::Glb => &["glb"],
            Format::Ply => &["ply"],
            Format::Spz => &["spz"],
            Format::Splat => &["splat"],
            Format::Ksplat => &["ksplat"],
            Format::Sog => &["sog", "json"],
        }
    }
}
