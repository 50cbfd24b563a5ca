//! Loaders: glTF 2.0 (`.gltf`, `.glb`) with `KHR_gaussian_splatting`, INRIA 3DGS PLY, and the
//! packed formats of other tools: Niantic SPZ, antimatter15 `.splat`, mkkellogg `.ksplat` and
//! PlayCanvas SOG (`docs/formats.md`).
//!
//! [`load_path`] picks the format by content (then by extension) and returns the
//! [`SplatCloud`] together with a [`LoadReport`] (format, scale space seen, warnings).
//! Every failure is a [`LoadError`] naming the file, the element, the index and what was
//! expected. No input panics, and sizes claimed by headers are checked against the bytes that
//! are really there before anything is allocated.

pub mod finding;
pub mod gltf;
pub mod ply;

pub mod codec;
pub mod details;
mod detect;
pub mod ksplat;
mod packed;
pub mod sog;
pub mod splat;
pub mod spz;
pub use details::Details;

use crate::cloud::SplatCloud;
use std::fmt;
use std::path::{Path, PathBuf};

/// How `KHR_gaussian_splatting:SCALE` values are to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ScaleSpace {
    /// Guess: signed-integer component types or any negative float mean log space (the review
    /// draft); otherwise linear (the RC).
    #[default]
    Auto,
    /// Linear (RC).
    Linear,
    /// Log space, `exp(v)` (review draft).
    Log,
}

impl std::str::FromStr for ScaleSpace {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(ScaleSpace::Auto),
            "linear" => Ok(ScaleSpace::Linear),
            "log" => Ok(ScaleSpace::Log),
            _ => Err(format!("expected auto, linear or log, found {s:?}")),
        }
    }
}

/// Options for all loaders.
#[derive(Debug, Clone, Copy, Default)]
pub struct LoadOptions {
    /// How glTF SCALE values are read (PLY scales are always log, as INRIA writes them).
    pub scale_space: ScaleSpace,
}

/// The file formats splatgl reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// glTF JSON (`.gltf`).
    Gltf,
    /// Binary glTF (`.glb`).
    Glb,
    /// INRIA 3DGS PLY (binary little/big endian or ASCII).
    Ply,
    /// Niantic SPZ, versions 1-4.
    Spz,
    /// antimatter15 `.splat`.
    Splat,
    /// mkkellogg `.ksplat`.
    Ksplat,
    /// PlayCanvas SOG (bundled `.sog` or `meta.json` + WebP).
    Sog,
}

impl Format {
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
}

/// What the loader noticed while reading; nothing here stops the load.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// Where (a JSON path, PLY element/property), may be empty.
    pub location: String,
    /// What.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.location.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.location, self.message)
        }
    }
}

/// Scale space as read from the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScaleSeen {
    /// Linear scales.
    Linear,
    /// Log-space scales (exp applied).
    Log,
    /// Primitives of both kinds.
    Mixed,
}

impl ScaleSeen {
    /// `"linear"`, `"log"` or `"mixed"`.
    pub fn name(self) -> &'static str {
        match self {
            ScaleSeen::Linear => "linear",
            ScaleSeen::Log => "log",
            ScaleSeen::Mixed => "mixed",
        }
    }
    pub(crate) fn merge(a: Option<Self>, b: Self) -> Self {
        match a {
            None => b,
            Some(a) if a == b => a,
            Some(_) => ScaleSeen::Mixed,
        }
    }
}

/// What the loader learnt besides the splats.
#[derive(Debug, Clone)]
pub struct LoadReport {
    /// Detected format.
    pub format: Format,
    /// Scale space seen (`None` when there were no splats to look at).
    pub scale_space: Option<ScaleSeen>,
    /// Quaternions that were not unit length (within 1e-3) and were normalised.
    pub non_unit_quaternions: usize,
    /// Non-fatal findings.
    pub warnings: Vec<Warning>,
    /// Container version, quantization and lossy steps (packed formats only).
    pub details: Option<Details>,
}

impl LoadReport {
    pub(crate) fn new(format: Format) -> Self {
        LoadReport {
            format,
            scale_space: None,
            non_unit_quaternions: 0,
            warnings: Vec::new(),
            details: None,
        }
    }
    /// The warnings for people: identical messages merged into one line naming the first
    /// location and how many more there are, in first-seen order.
    pub fn summarized_warnings(&self) -> Vec<String> {
        let mut groups: Vec<(&Warning, usize)> = Vec::new();
        let mut index: std::collections::HashMap<&str, usize> = Default::default();
        for w in &self.warnings {
            match index.get(w.message.as_str()) {
                Some(&g) => groups[g].1 += 1,
                None => {
                    index.insert(&w.message, groups.len());
                    groups.push((w, 1));
                }
            }
        }
        groups
            .into_iter()
            .map(|(w, n)| match n {
                1 => w.to_string(),
                n => format!("{w} (and {} more like it)", n - 1),
            })
            .collect()
    }

    pub(crate) fn warn(&mut self, location: impl Into<String>, message: impl Into<String>) {
        self.warnings.push(Warning {
            location: location.into(),
            message: message.into(),
        });
    }
}

/// A loaded scene.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The splats, global space.
    pub cloud: SplatCloud,
    /// Format, scale space, warnings.
    pub report: LoadReport,
}

/// Why a file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Neither content nor extension say what the file is.
    #[error("{path}: unknown file format (expected glTF/GLB, PLY, SPZ, .splat, .ksplat or SOG)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// A PLY problem.
    #[error("{path}: {source}")]
    Ply {
        /// The file.
        path: PathBuf,
        /// What.
        source: ply::PlyError,
    },
    /// A glTF problem.
    #[error("{path}: {source}")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// What.
        source: gltf::GltfError,
    },
    /// An SPZ problem.
    #[error("{path}: SPZ: {source}")]
    Spz {
        /// The file.
        path: PathBuf,
        /// What.
        source: spz::SpzError,
    },
    /// A `.splat` problem.
    #[error("{path}: .splat: {source}")]
    Splat {
        /// The file.
        path: PathBuf,
        /// What.
        source: splat::SplatError,
    },
    /// A `.ksplat` problem.
    #[error("{path}: .ksplat: {source}")]
    Ksplat {
        /// The file.
        path: PathBuf,
        /// What.
        source: ksplat::KsplatError,
    },
    /// A SOG problem.
    #[error("{path}: SOG: {source}")]
    Sog {
        /// The file.
        path: PathBuf,
        /// What.
        source: sog::SogError,
    },
}

/// Loads a file of any supported format.
pub fn load_path(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<Loaded, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })?;
    load_bytes(&bytes, Some(path), opts)
}

/// Detects the format from the content (magic bytes, header, zip directory, JSON keys), then
/// the extension, then `.splat` plausibility.
pub fn detect_format(bytes: &[u8], path: Option<&Path>) -> Option<Format> {
    detect::detect(bytes, path)
}

/// Loads from memory. `path` names the file in errors and resolves external glTF buffers
/// (without it, only GLB and data-URI buffers can be read).
pub fn load_bytes(
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Loaded, LoadError> {
    let shown = path.map_or_else(|| PathBuf::from("<memory>"), Path::to_owned);
    let format = detect_format(bytes, path);
    let mut loaded = match format {
        Some(Format::Ply) => ply::load(bytes).map_err(|source| LoadError::Ply {
            path: shown,
            source,
        }),
        Some(f @ (Format::Gltf | Format::Glb)) => {
            gltf::load(bytes, f, path, opts).map_err(|source| LoadError::Gltf {
                path: shown,
                source,
            })
        }
        Some(f @ (Format::Spz | Format::Splat | Format::Ksplat | Format::Sog)) => {
            packed::load(f, bytes, path, shown)
        }
        None => Err(LoadError::UnknownFormat { path: shown }),
    }?;
    if let Some(w) = format.and_then(|f| detect::extension_mismatch(f, path)) {
        loaded.report.warn("", w);
    }
    Ok(loaded)
}

/// Normalises a quaternion `[x, y, z, w]`; returns it and whether it was off unit length by
/// more than 1e-3. A zero or non-finite quaternion is an error (`None`).
pub(crate) fn normalize_quat(q: [f32; 4]) -> Option<([f32; 4], bool)> {
    let n2: f64 = q.iter().map(|&v| (v as f64) * (v as f64)).sum();
    if !n2.is_finite() || n2 <= 1e-24 {
        return None;
    }
    let n = n2.sqrt();
    let off = (n - 1.0).abs() > 1e-3;
    Some((q.map(|v| (v as f64 / n) as f32), off))
}
