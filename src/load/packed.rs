//! [`super::load_bytes`] for the packed formats (SPZ, `.splat`, `.ksplat`, SOG): runs the
//! reader, wraps its error into [`LoadError`] with the file name, and turns its findings into
//! the report's warnings.

use super::finding::Finding;
use super::{Format, LoadError, LoadReport, Loaded, ksplat, sog, splat, spz};
use std::path::{Path, PathBuf};

/// Loads `bytes` as `format` (one of the four packed formats).
pub(crate) fn load(
    format: Format,
    bytes: &[u8],
    path: Option<&Path>,
    shown: PathBuf,
) -> Result<Loaded, LoadError> {
    let mut findings = Vec::new();
    let f = &mut findings;
    let (cloud, details) = match format {
        Format::Spz => spz::read(bytes, f).map_err(|source| LoadError::Spz {
            path: shown,
            source,
        }),
        Format::Splat => splat::read(bytes, f).map_err(|source| LoadError::Splat {
            path: shown,
            source,
        }),
        Format::Ksplat => ksplat::read(bytes, f).map_err(|source| LoadError::Ksplat {
            path: shown,
            source,
        }),
        _ => if sog::is_meta_json(bytes) {
            sog::read_dir(bytes, path, f)
        } else {
            sog::read_bundle(bytes, f)
        }
        .map_err(|source| LoadError::Sog {
            path: shown,
            source,
        }),
    }?;
    let mut report = LoadReport::new(format);
    report.scale_space = Some(match format {
        Format::Spz | Format::Sog => super::ScaleSeen::Log,
        _ => super::ScaleSeen::Linear,
    });
    report.details = Some(details);
    for w in findings {
        report.warn(location(&w), w.message);
    }
    Ok(Loaded { cloud, report })
}

fn location(f: &Finding) -> String {
    match f.index {
        Some(i) => format!("{} [index {i}]", f.path),
        None => f.path.clone(),
    }
}
