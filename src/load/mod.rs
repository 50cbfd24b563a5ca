//! Loaders: glTF 2.0 (`.gltf`, `.glb`) with `KHR_gaussian_splatting`, and INRIA 3DGS PLY.
//!
//! [`load_path`] picks the format by magic bytes (then by extension, see [`detect_format`])
//! and parses the file once into a [`Scene`]: the [`SplatCloud`], the glTF cameras, and a
//! [`LoadReport`] (format, scale space seen, [`Finding`]s). [`validate`] checks a file with the
//! same readers and reports the same findings.
//!
//! Every failure is a [`LoadError`] naming the file, the element, the index and what was
//! expected. No input panics, and sizes claimed by headers are checked against the bytes that
//! are really there before anything is allocated.

mod finding;
mod format;
pub mod gltf;
pub mod ply;
mod report;
pub mod validate;

pub use finding::{Finding, Severity};
pub use format::{Format, detect_format};
pub use report::{LoadReport, ScaleSeen};

use crate::camera::GltfPerspective;
use crate::cloud::SplatCloud;
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

/// A loaded file: the splats, the cameras it defines, and what the loader noticed.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The splats, global space.
    pub cloud: SplatCloud,
    /// The perspective camera nodes of the glTF scene, in traversal order (depth first), with
    /// their global transforms (orthographic cameras are skipped: splat rendering with them is
    /// undefined per the RC). Empty for formats without cameras (PLY).
    pub cameras: Vec<GltfPerspective>,
    /// Format, scale space, findings.
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
    /// A splat format splatgl recognises but does not read yet.
    #[error(
        "{path}: {kind} files are not supported yet (splatgl reads glTF/GLB with KHR_gaussian_splatting and PLY)"
    )]
    NotYet {
        /// The file.
        path: PathBuf,
        /// The format.
        kind: &'static str,
    },
    /// Neither magic bytes nor extension say what the file is.
    #[error("{path}: unknown file format (expected .gltf, .glb or .ply)")]
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
}

/// Loads a file of any supported format.
pub fn load_path(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<Scene, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })?;
    load_bytes(&bytes, Some(path), opts)
}

/// Loads from memory. `path` names the file in errors, helps detect the format, and resolves
/// external glTF buffers (without it, only GLB and data-URI buffers can be read).
pub fn load_bytes(
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Scene, LoadError> {
    let shown = path.map_or_else(|| PathBuf::from("<memory>"), Path::to_owned);
    let Some(format) = detect_format(bytes, path) else {
        return Err(match format::not_yet(bytes, path) {
            Some(kind) => LoadError::NotYet { path: shown, kind },
            None => LoadError::UnknownFormat { path: shown },
        });
    };
    let mut report = LoadReport::new(format);
    let (cloud, cameras) = read(format, bytes, path, opts, &mut report).map_err(|e| e.at(shown))?;
    Ok(Scene {
        cloud,
        cameras,
        report,
    })
}

/// Why a reader stopped, before the file name is attached (see [`LoadError`]).
#[derive(Debug, thiserror::Error)]
pub(crate) enum ReadError {
    #[error(transparent)]
    Ply(#[from] ply::PlyError),
    #[error(transparent)]
    Gltf(#[from] gltf::GltfError),
}

impl ReadError {
    fn at(self, path: PathBuf) -> LoadError {
        match self {
            ReadError::Ply(source) => LoadError::Ply { path, source },
            ReadError::Gltf(source) => LoadError::Gltf { path, source },
        }
    }
    /// Whether the file's framing could not be read at all (`validate`'s "unreadable").
    fn unreadable(&self) -> bool {
        matches!(
            self,
            ReadError::Ply(ply::PlyError::Header { .. })
                | ReadError::Gltf(gltf::GltfError::Container(_))
        )
    }
}

/// The readers, one arm per format. Each fills `report` (findings, scale space, non-unit
/// quaternions) and returns the cloud and the cameras the file defines.
///
/// A new format is a [`Format`] variant (with its magic bytes and extensions), a reader here,
/// and a [`ReadError`] / [`LoadError`] variant for the reader's error type.
pub(crate) fn read(
    format: Format,
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<(SplatCloud, Vec<GltfPerspective>), ReadError> {
    Ok(match format {
        Format::Ply => (ply::read(bytes, report)?, Vec::new()),
        Format::Gltf | Format::Glb => gltf::read(bytes, format, path, opts, report)?,
    })
}

/// A quaternion whose norm is 1 within this (4 f32 ulps at 1) is kept as stored: renormalising
/// an already normalised f32 quaternion can flip last bits, so a file written from a loaded
/// cloud would not load back bit for bit. Renderers normalise again anyway.
pub(crate) const UNIT_NORM_ROUNDING: f64 = 4.0 * f32::EPSILON as f64;

/// Normalises a quaternion `[x, y, z, w]` (kept as is when unit to f32 rounding); returns it and whether it was off unit length by
/// more than 1e-3. A zero or non-finite quaternion is an error (`None`).
pub(crate) fn normalize_quat(q: [f32; 4]) -> Option<([f32; 4], bool)> {
    let n2: f64 = q.iter().map(|&v| (v as f64) * (v as f64)).sum();
    if !n2.is_finite() || n2 <= 1e-24 {
        return None;
    }
    let n = n2.sqrt();
    let off = (n - 1.0).abs() > 1e-3;
    if (n - 1.0).abs() <= UNIT_NORM_ROUNDING {
        return Some((q, off)); // unit to f32 rounding: dividing would only flip last bits
    }
    Some((q.map(|v| (v as f64 / n) as f32), off))
}
