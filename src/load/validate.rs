//! `splatgl validate`: every MUST of `KHR_gaussian_splatting` (RC) for glTF input, glTF 2.0
//! structural errors, and loadability for other input, as a list of [`Finding`]s.
//!
//! The checks are the loader's own: the same readers, the same findings in the same
//! [`super::LoadReport`], so what `validate` accepts is exactly what `load` reads. For glTF the
//! findings go on past the first blocking one (the walk reports every problem it can reach).

use super::{Finding, Format, LoadOptions, Severity, detect_format, gltf};
use std::path::Path;

/// Overall verdict; the process exit status of `splatgl validate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// No errors (warnings allowed; also when splatgl cannot decode the file:
    /// [`Report::unsupported`] > 0): exit 0.
    Valid = 0,
    /// At least one error: exit 1.
    Invalid = 1,
    /// The file cannot be read or parsed at all: exit 2.
    Unreadable = 2,
}

/// The result of validating one file.
#[derive(Debug, Clone)]
pub struct Report {
    /// Detected format, if any.
    pub format: Option<Format>,
    /// Findings in document order.
    pub findings: Vec<Finding>,
    /// Whether the container could be parsed.
    pub readable: bool,
    /// Number of splats that would be loaded (when loading succeeds).
    pub splat_count: Option<usize>,
}

impl Report {
    /// Valid / invalid / unreadable.
    pub fn status(&self) -> Status {
        if !self.readable {
            Status::Unreadable
        } else if self.errors() > 0 {
            Status::Invalid
        } else {
            Status::Valid
        }
    }
    /// Number of errors.
    pub fn errors(&self) -> usize {
        self.findings
            .iter()
            .filter(|f| f.severity == Severity::Error)
            .count()
    }
    /// Number of warnings.
    pub fn warnings(&self) -> usize {
        self.count(Severity::Warning)
    }
    /// Number of [`Severity::Unsupported`] findings: valid, but splatgl cannot decode it.
    pub fn unsupported(&self) -> usize {
        self.count(Severity::Unsupported)
    }
    /// Number of [`Severity::Info`] notes.
    pub fn notes(&self) -> usize {
        self.count(Severity::Info)
    }
    fn count(&self, s: Severity) -> usize {
        self.findings.iter().filter(|f| f.severity == s).count()
    }
    /// The findings for people: repeats of one message collapsed into its first finding
    /// (`(and N more like it)`), in first-seen order.
    pub fn summarized(&self) -> Vec<String> {
        super::finding::collapse(&self.findings)
            .into_iter()
            .map(|(f, n)| match n {
                1 => f.to_string(),
                n => format!("{f} (and {} more like it)", n - 1),
            })
            .collect()
    }
    /// Machine-readable form (the `--json` output).
    pub fn to_json(&self, file: &Path) -> serde_json::Value {
        serde_json::json!({
            "file": file.display().to_string(),
            "format": self.format.map(Format::name),
            "status": match self.status() {
                Status::Valid => "valid",
                Status::Invalid => "invalid",
                Status::Unreadable => "unreadable",
            },
            "valid": self.status() == Status::Valid,
            "errors": self.errors(),
            "warnings": self.warnings(),
            "unsupported": self.unsupported(),
            "notes": self.notes(),
            "splat_count": self.splat_count,
            "findings": self.findings.iter().map(|f| serde_json::json!({
                "severity": f.severity.name(),
                "path": f.path,
                "message": f.message,
                "index": f.index,
            })).collect::<Vec<_>>(),
        })
    }
}

/// Validates a file on disk (a regular file within `limits.max_bytes`, memory-mapped with
/// [`LoadOptions::memory_map`], like `load_path`).
pub fn validate_path(path: &Path, opts: &LoadOptions) -> Report {
    match crate::files::read_file_bytes(path, opts.limits.max_bytes, "the file", opts.memory_map) {
        Ok(bytes) => validate_bytes(&bytes, Some(path), opts),
        Err(e) => Report {
            format: None,
            findings: vec![Finding::fatal(
                "",
                format!("cannot read {}: {e}", path.display()),
            )],
            readable: false,
            splat_count: None,
        },
    }
}

/// Validates bytes (`path` resolves external glTF buffers and picks the format by extension).
pub fn validate_bytes(bytes: &[u8], path: Option<&Path>, opts: &LoadOptions) -> Report {
    let Some(format) = detect_format(bytes, path) else {
        return Report {
            format: None,
            findings: vec![Finding::fatal(
                "",
                "unknown file format (expected glTF, GLB, PLY, SPZ, .splat, .ksplat or SOG)",
            )],
            readable: false,
            splat_count: None,
        };
    };
    let mut load = super::report_for(format, path);
    let mut readable = true;
    let mut splat_count = None;
    match format {
        Format::Gltf | Format::Glb => match gltf::walk(bytes, format, path, opts, &mut load) {
            Err(e) => {
                readable = false;
                load.findings.push(Finding::fatal("", e.to_string()));
            }
            Ok(w) => {
                let unsupported = load
                    .findings
                    .iter()
                    .any(|f| f.severity == Severity::Unsupported);
                if w.splat_primitives == 0 && !unsupported {
                    load.findings.push(Finding::fatal(
                        "meshes",
                        "no primitive uses KHR_gaussian_splatting",
                    ));
                }
                splat_count = w.cloud.as_ref().map(|c| c.len());
            }
        },
        _ => match super::read(format, bytes, path, opts, &mut load) {
            Ok((cloud, _)) => splat_count = Some(cloud.len()),
            Err(e) => {
                readable = !e.unreadable();
                load.findings.push(Finding::fatal("", e.to_string()));
            }
        },
    }
    Report {
        format: Some(format),
        findings: load.findings,
        readable,
        splat_count,
    }
}
