//! Loaders: glTF 2.0 (`.gltf`, `.glb`) with `KHR_gaussian_splatting`, INRIA 3DGS PLY, and the
//! packed formats of other tools: Niantic SPZ, antimatter15 `.splat`, mkkellogg `.ksplat` and
//! PlayCanvas SOG (`docs/formats.md`).
//!
//! [`load_path`] picks the format by content (then by extension, see [`detect_format`])
//! and parses the file once into a [`Scene`]: the [`SplatCloud`], the glTF cameras, and a
//! [`LoadReport`] (format, scale space seen, [`Finding`]s). [`validate`] checks a file with the
//! same readers and reports the same findings.
//!
//! Every failure is a [`LoadError`] naming the file, the element, the index and what was
//! expected. No input panics, and sizes claimed by headers are checked against the bytes that
//! are really there, and against [`Limits`], before anything is allocated.
//!
//! Files are read only when they are regular files within [`Limits::max_bytes`]
//! ([`crate::files`]); external glTF buffers only inside the asset's folder (unless
//! [`LoadOptions::allow_outside_paths`]) or through [`LoadOptions::resolver`]. No splat with a
//! non-finite or overflowing value leaves a loader (`hygiene.rs`): such splats are dropped with
//! a finding, or fail the load in [`LoadOptions::strict`] mode.

pub mod codec;
mod details;
mod finding;
mod format;
pub mod gltf;
pub(crate) mod hygiene;
pub mod ksplat;
pub mod ply;
mod report;
pub mod sog;
pub mod splat;
pub mod spz;
pub mod validate;

pub use crate::files::Format;
pub use crate::files::{JsonShapeError, LimitExceeded, Limits, check_json, check_json_depth};
pub use details::{AttributeBits, Details};
pub use finding::{Finding, Severity, printable};
pub use format::detect_format;
pub use report::{AntialiasMode, LoadReport, ScaleSeen};

use crate::camera::GltfPerspective;
use crate::cloud::SplatCloud;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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

/// Serves the bytes of an external glTF buffer named by its URI (as written in the file, not
/// percent-decoded), like the `gltf` crate's data-source closure. An `Err` message becomes the
/// finding of that buffer.
pub type Resolver = Arc<dyn Fn(&str) -> Result<Vec<u8>, String> + Send + Sync>;

/// Options for all loaders.
#[derive(Clone, Default)]
pub struct LoadOptions {
    /// How glTF SCALE values are read (PLY scales are always log, as INRIA writes them).
    pub scale_space: ScaleSpace,
    /// Which axes SPZ payloads are taken to be in (files and glTF SPZ compression).
    pub spz_axes: spz::SpzAxes,
    /// A splat with a non-finite or overflowing value fails the load (a [`LoadError`] naming
    /// the field, the element and the index) instead of being dropped with a warning.
    pub strict: bool,
    /// Let external buffer URIs leave the asset's folder (absolute paths, `..`, symlinks
    /// pointing outside). Off by default: a file from the internet must not make splatgl read
    /// the rest of the disk.
    pub allow_outside_paths: bool,
    /// Serves external (non-`data:`) glTF buffers instead of the file system; with it, no file
    /// is opened for buffers and `load_bytes` needs no path. The embedder's resolver is its own
    /// policy: the containment rule does not apply to it, the byte limits do.
    pub resolver: Option<Resolver>,
    /// Resource limits.
    pub limits: Limits,
    /// [`load_path`] and [`validate::validate_path`] memory-map the file instead of reading
    /// it ([`crate::files::map_bounded`]: no copy of the file, peak memory the cloud plus a
    /// few blocks for binary PLY). Off by default in the library: a file that another process
    /// truncates while it is mapped kills the reading process with `SIGBUS`, which an
    /// embedding application may not accept. The `splatgl` command turns it on
    /// (`SPLATGL_NO_MMAP=1` turns it off again).
    pub memory_map: bool,
}

impl std::fmt::Debug for LoadOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadOptions")
            .field("scale_space", &self.scale_space)
            .field("spz_axes", &self.spz_axes)
            .field("strict", &self.strict)
            .field("allow_outside_paths", &self.allow_outside_paths)
            .field("resolver", &self.resolver.as_ref().map(|_| "Fn(&str)"))
            .field("limits", &self.limits)
            .field("memory_map", &self.memory_map)
            .finish()
    }
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
    /// A [`Limits`] bound was exceeded.
    #[error("{path}: {source}")]
    Limit {
        /// The file.
        path: PathBuf,
        /// Which limit, by how much.
        source: LimitExceeded,
    },
    /// In strict mode: a splat with a non-finite or overflowing value.
    #[error("{path}: {finding}")]
    Unusable {
        /// The file.
        path: PathBuf,
        /// Where, which field, which index.
        finding: Finding,
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
pub fn load_path(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<Scene, LoadError> {
    let path = path.as_ref();
    let bytes = read_scene_file(path, opts)?;
    load_bytes(&bytes, Some(path), opts)
}

/// Reads a scene file: a regular file within `limits.max_bytes`, memory-mapped with
/// [`LoadOptions::memory_map`]; `-` reads standard input.
pub(crate) fn read_scene_file(
    path: &Path,
    opts: &LoadOptions,
) -> Result<crate::files::FileBytes, LoadError> {
    crate::files::read_file_bytes(
        path,
        opts.limits.max_bytes,
        "the scene file",
        opts.memory_map,
    )
    .map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Loads from memory. `path` names the file in errors, helps detect the format, and resolves
/// external glTF buffers (without it, only GLB and data-URI buffers can be read, or those
/// [`LoadOptions::resolver`] serves). External buffers read from files count against
/// `limits.max_bytes`; `bytes` themselves do not.
pub fn load_bytes(
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Scene, LoadError> {
    let shown = path.map_or_else(|| PathBuf::from("<memory>"), Path::to_owned);
    let Some(format) = detect_format(bytes, path) else {
        return Err(LoadError::UnknownFormat { path: shown });
    };
    let mut report = report_for(format, path);
    let (cloud, cameras) = read(format, bytes, path, opts, &mut report).map_err(|e| e.at(shown))?;
    Ok(Scene {
        cloud,
        cameras,
        report,
    })
}

/// A fresh report for a file detected as `format`, with the warning for an extension that
/// names another format ([`load_bytes`] and [`validate`] start from it).
pub(crate) fn report_for(format: Format, path: Option<&Path>) -> LoadReport {
    let mut report = LoadReport::new(format);
    if let Some(w) = format::extension_mismatch(format, path) {
        report.findings.push(Finding::warning("", w));
    }
    report
}

/// Why a reader stopped, before the file name is attached (see [`LoadError`]).
#[derive(Debug, thiserror::Error)]
pub(crate) enum ReadError {
    #[error(transparent)]
    Ply(#[from] ply::PlyError),
    #[error(transparent)]
    Gltf(#[from] gltf::GltfError),
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
    #[error("{0}")]
    Unusable(Finding),
    #[error(transparent)]
    Spz(#[from] spz::SpzError),
    #[error(transparent)]
    Splat(#[from] splat::SplatError),
    #[error(transparent)]
    Ksplat(#[from] ksplat::KsplatError),
    #[error(transparent)]
    Sog(#[from] sog::SogError),
}

impl ReadError {
    fn at(self, path: PathBuf) -> LoadError {
        match self {
            ReadError::Ply(ply::PlyError::Limit(source))
            | ReadError::Spz(spz::SpzError::Limit(source))
            | ReadError::Splat(splat::SplatError::Limit(source))
            | ReadError::Ksplat(ksplat::KsplatError::Limit(source))
            | ReadError::Sog(sog::SogError::Limit(source))
            | ReadError::Limit(source) => LoadError::Limit { path, source },
            ReadError::Ply(source) => LoadError::Ply { path, source },
            ReadError::Gltf(source) => LoadError::Gltf { path, source },
            ReadError::Unusable(finding) => LoadError::Unusable { path, finding },
            ReadError::Spz(source) => LoadError::Spz { path, source },
            ReadError::Splat(source) => LoadError::Splat { path, source },
            ReadError::Ksplat(source) => LoadError::Ksplat { path, source },
            ReadError::Sog(source) => LoadError::Sog { path, source },
        }
    }
    /// Whether the file's framing could not be read at all (`validate`'s "unreadable").
    fn unreadable(&self) -> bool {
        match self {
            ReadError::Ply(e) => matches!(e, ply::PlyError::Header { .. }),
            ReadError::Gltf(e) => matches!(e, gltf::GltfError::Container(_)),
            // A limit or a strict-mode splat: the file was read, its data is refused.
            ReadError::Limit(_) | ReadError::Unusable(_) => false,
            // The packed formats have no structure to report findings on once they fail.
            _ => true,
        }
    }
}

/// The readers, one arm per format. Each fills `report` (findings, scale space, non-unit
/// quaternions) and returns the cloud and the cameras the file defines.
///
/// A new format is a [`Format`] variant (with its magic bytes and extensions), a reader here,
/// and a [`ReadError`] / [`LoadError`] variant for the reader's error type. Readers check
/// `opts.limits` before allocating (`check_splats`, `check_decompressed`); the splat limit and
/// the numeric hygiene pass below apply to every format whatever its reader does.
pub(crate) fn read(
    format: Format,
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<(SplatCloud, Vec<GltfPerspective>), ReadError> {
    let (mut cloud, cameras) = match format {
        Format::Ply => (ply::read(bytes, opts, report)?, Vec::new()),
        Format::Gltf | Format::Glb => gltf::read(bytes, format, path, opts, report)?,
        Format::Spz => (spz::read(bytes, opts, report)?, Vec::new()),
        Format::Splat => (splat::read(bytes, opts, report)?, Vec::new()),
        Format::Ksplat => (ksplat::read(bytes, opts, report)?, Vec::new()),
        Format::Sog => (sog::read(bytes, path, opts, report)?, Vec::new()),
    };
    finish(&mut cloud, opts, report)?;
    Ok((cloud, cameras))
}

/// The checks at the exit of every reader: the splat limit, and the numeric hygiene pass (bad
/// splats dropped with a warning, or in strict mode the first one is the error).
pub(crate) fn finish(
    cloud: &mut SplatCloud,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<(), ReadError> {
    opts.limits
        .check_splats(cloud.len() as u64, "the loaded cloud")?;
    let site = hygiene::Site {
        path: "",
        what: "",
        severity: Severity::Warning,
        strict: opts.strict,
        origin: None,
    };
    hygiene::clean(cloud, &site, &mut report.findings).map_err(ReadError::Unusable)?;
    debug_assert!(cloud.validate().is_ok(), "{:?}", cloud.validate());
    Ok(())
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
