//! PlayCanvas SOG ("spatially ordered Gaussians"): a `meta.json` and lossless WebP textures,
//! either bundled in a zip (`.sog`) or side by side (`meta.json` + `*.webp`). Texel `i`
//! (row-major) holds splat `i`. Version 2 (current) and the legacy version 1 meta are read.
//! `docs/formats.md` § SOG has the encoding of every texture and the error bounds.

mod decode;
pub mod zip;

use super::codec::{self, BUDGET_RULE, budget_for};
use super::{
    Details, Finding, Format, LimitExceeded, Limits, LoadOptions, LoadReport, ScaleSeen, Scene,
};
use crate::cloud::SplatCloud;
use serde_json::Value;
use std::path::Path;

/// What is wrong with a SOG file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SogError {
    /// The zip structure is unusable.
    #[error("zip: {0}")]
    Zip(String),
    /// A member or file named by the meta is absent.
    #[error("'{member}' is missing")]
    Missing {
        /// Its name.
        member: String,
    },
    /// A member or file cannot be read or used.
    #[error("'{member}': {message}")]
    Member {
        /// Its name.
        member: String,
        /// What is wrong.
        message: String,
    },
    /// `meta.json` is not the expected JSON.
    #[error("meta.json: {path}: {message}")]
    Meta {
        /// JSON path of the offending value.
        path: String,
        /// Expected vs found.
        message: String,
    },
    /// A texture does not match what the meta needs.
    #[error("texture '{file}' ({role}): {message}")]
    Texture {
        /// File name.
        file: String,
        /// What it holds (`"means_l"`, `"quats"`, …).
        role: &'static str,
        /// Expected vs found.
        message: String,
    },
    /// Decoding the textures would pass the budget.
    #[error(
        "decoded textures and cloud take {needed} bytes, over the budget of {limit} bytes ({BUDGET_RULE})"
    )]
    OverBudget {
        /// Bytes needed.
        needed: u64,
        /// Budget.
        limit: u64,
    },
    /// An unbundled meta.json without the folder that holds its textures.
    #[error(
        "an unbundled meta.json needs its path (or LoadOptions::resolver) to find the WebP textures"
    )]
    NoDirectory,
    /// In strict mode: a splat with a non-finite or overflowing value (which, and where).
    #[error("{0}")]
    Unusable(String),
    /// A [`Limits`] bound was exceeded (splat count, bytes read, JSON nesting).
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
}

/// The parts of meta.json the decoder uses.
#[derive(Debug, Clone)]
pub(crate) struct Meta {
    pub version: u32,
    pub count: usize,
    pub means: (Vec<f64>, Vec<f64>, [String; 2]),
    /// V2: 256-entry codebook; V1: per-axis mins/maxs (log scale).
    pub scales: Quant,
    pub scales_file: String,
    pub quats: String,
    /// V2: colour codebook; V1: mins/maxs of r, g, b and the opacity logit.
    pub sh0: (Quant, String),
    /// Palette size, bands, quantisation, [centroids, labels].
    pub sh_n: Option<(usize, u8, Quant, [String; 2])>,
}

/// How bytes map to values: a 256-entry codebook (V2) or a linear range (V1).
#[derive(Debug, Clone)]
pub(crate) enum Quant {
    Codebook(Vec<f32>),
    Range(Vec<f64>, Vec<f64>),
}

fn meta_err(path: &str, message: impl Into<String>) -> SogError {
    SogError::Meta {
        path: path.into(),
        message: message.into(),
    }
}

fn field<'v>(v: &'v Value, path: &str, key: &str) -> Result<&'v Value, SogError> {
    v.get(key)
        .ok_or_else(|| meta_err(&format!("{path}.{key}"), "missing"))
}

fn numbers(v: &Value, path: &str, len: Option<usize>) -> Result<Vec<f64>, SogError> {
    let a = v
        .as_array()
        .ok_or_else(|| meta_err(path, "expected an array of numbers"))?;
    if let Some(n) = len.filter(|&n| a.len() != n) {
        return Err(meta_err(path, format!("{} entries, expected {n}", a.len())));
    }
    a.iter()
        .map(|x| x.as_f64().ok_or_else(|| meta_err(path, "expected numbers")))
        .collect()
}

fn files<const N: usize>(v: &Value, path: &str) -> Result<[String; N], SogError> {
    let p = format!("{path}.files");
    let a = field(v, path, "files")?
        .as_array()
        .ok_or_else(|| meta_err(&p, "expected an array of file names"))?;
    if a.len() < N {
        return Err(meta_err(&p, format!("{} names, expected {N}", a.len())));
    }
    let mut out: [String; N] = std::array::from_fn(|_| String::new());
    for (o, x) in out.iter_mut().zip(a) {
        *o = x
            .as_str()
            .ok_or_else(|| meta_err(&p, "expected strings"))?
            .to_owned();
    }
    Ok(out)
}

fn codebook(v: &Value, path: &str) -> Result<Quant, SogError> {
    let c = numbers(
        field(v, path, "codebook")?,
        &format!("{path}.codebook"),
        Some(256),
    )?;
    Ok(Quant::Codebook(c.into_iter().map(|x| x as f32).collect()))
}

fn range(v: &Value, path: &str, n: usize) -> Result<Quant, SogError> {
    let (lo, hi) = (field(v, path, "mins")?, field(v, path, "maxs")?);
    let get = |x: &Value, k: &str| match x.as_f64() {
        Some(s) => Ok(vec![s]),
        None => numbers(x, &format!("{path}.{k}"), Some(n)),
    };
    Ok(Quant::Range(get(lo, "mins")?, get(hi, "maxs")?))
}

/// Parses meta.json (version 2, or version 1 when `version` is absent) after checking its
/// nesting against `limits.max_json_depth`; its count is checked against `limits.max_splats`.
pub(crate) fn parse_meta(json: &[u8], limits: &Limits) -> Result<Meta, SogError> {
    super::check_json(json, limits).map_err(|e| meta_err("$", e))?;
    let v: Value = serde_json::from_slice(json).map_err(|e| meta_err("$", e.to_string()))?;
    let version = match v.get("version") {
        None => 1,
        Some(x) => match x.as_u64() {
            Some(2) => 2,
            _ => {
                return Err(meta_err(
                    "version",
                    format!("{x}, expected 2 (or absent: 1)"),
                ));
            }
        },
    };
    let means = field(&v, "", "means")?;
    let count = if version == 2 {
        field(&v, "", "count")?.as_u64()
    } else {
        field(means, "means", "shape")?
            .get(0)
            .and_then(Value::as_u64)
    }
    .ok_or_else(|| meta_err("count", "expected a non-negative integer"))?;
    limits.check_splats(count, "meta.json count")?;
    let mm = (
        numbers(field(means, "means", "mins")?, "means.mins", Some(3))?,
        numbers(field(means, "means", "maxs")?, "means.maxs", Some(3))?,
        files::<2>(means, "means")?,
    );
    let (scales, sh0) = (field(&v, "", "scales")?, field(&v, "", "sh0")?);
    let (sq, cq) = if version == 2 {
        (codebook(scales, "scales")?, codebook(sh0, "sh0")?)
    } else {
        (range(scales, "scales", 3)?, range(sh0, "sh0", 4)?)
    };
    let sh_n = match v.get("shN") {
        None => None,
        Some(s) => {
            let [c, l] = files::<2>(s, "shN")?;
            let (count, bands, q) = if version == 2 {
                let count = field(s, "shN", "count")?.as_u64().unwrap_or(0) as usize;
                let bands = field(s, "shN", "bands")?.as_u64().unwrap_or(0);
                if !(1..=3).contains(&bands) {
                    return Err(meta_err("shN.bands", format!("{bands}, expected 1-3")));
                }
                (count, bands as u8, codebook(s, "shN")?)
            } else {
                (0, 0, range(s, "shN", 1)?)
            };
            Some((count, bands, q, [c, l]))
        }
    };
    Ok(Meta {
        version,
        count: count as usize,
        means: mm,
        scales: sq,
        scales_file: files::<1>(scales, "scales")?[0].clone(),
        quats: files::<1>(field(&v, "", "quats")?, "quats")?[0].clone(),
        sh0: (cq, files::<1>(sh0, "sh0")?[0].clone()),
        sh_n,
    })
}

/// Whether JSON bytes are a SOG meta (top-level `means` and `quats`), not glTF. Text over the
/// default JSON limits is told by its keys (the reader then names the limit).
pub(crate) fn is_meta_json(bytes: &[u8]) -> bool {
    let has = |k: &[u8]| bytes.windows(k.len()).any(|w| w == k);
    let object = bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
    if !object {
        return false;
    }
    if crate::files::check_json(bytes, &Limits::default()).is_err() {
        return has(b"\"quats\"") && has(b"\"means\"");
    }
    has(b"\"quats\"")
        && serde_json::from_slice::<serde_json::Map<String, Value>>(bytes)
            .is_ok_and(|m| m.contains_key("means") && m.contains_key("quats"))
}

/// Whether a zip holds a `meta.json` (a bundled SOG).
pub(crate) fn is_bundle(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PK\x03\x04") && zip::Archive::new(bytes).is_ok_and(|a| a.has("meta.json"))
}

/// Reads a SOG from memory into `report`: a bundle (zip), or a meta.json whose textures are
/// read beside `path` (or from `opts.resolver`).
pub(crate) fn read(
    bytes: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<SplatCloud, SogError> {
    let (cloud, details) = if is_meta_json(bytes) {
        read_dir(bytes, path, opts, &mut report.findings)
    } else {
        read_bundle(bytes, opts, &mut report.findings)
    }?;
    report.details = Some(details);
    report.scale_space = Some(ScaleSeen::Log);
    Ok(cloud)
}

/// Reads a bundled `.sog` (zip) from memory.
fn read_bundle(
    bytes: &[u8],
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> Result<(SplatCloud, Details), SogError> {
    let archive = zip::Archive::new(bytes)?;
    let mut budget = budget_for(bytes.len(), &opts.limits);
    let meta = parse_meta(&archive.read("meta.json", &mut budget)?, &opts.limits)?;
    let textures = decode::names(&meta)
        .iter()
        .map(|(_, name)| archive.read(name, &mut budget))
        .collect::<Result<Vec<_>, _>>()?;
    let drop_at = codec::drop_site("splats", opts);
    let (cloud, mut d) = decode::decode(&meta, &textures, (budget, drop_at), findings)?;
    d.compression = "WebP lossless, in a zip".into();
    Ok((cloud, d))
}

/// Reads an unbundled SOG from wherever its textures are (memory, an archive, the network):
/// `meta` is the meta.json text, and `load` returns the bytes of a texture it names. The
/// budget counts meta.json and every texture as input. `opts` apply as to any load (limits,
/// strict mode); the cloud passes the same exit checks as [`super::load_bytes`]'s.
pub fn read_unbundled(
    meta: &[u8],
    opts: &LoadOptions,
    load: &mut dyn FnMut(&str) -> Result<Vec<u8>, SogError>,
) -> Result<Scene, SogError> {
    let mut report = LoadReport::new(Format::Sog);
    let (mut cloud, details) = unbundled(meta, opts, load, &mut report.findings)?;
    report.details = Some(details);
    report.scale_space = Some(ScaleSeen::Log);
    super::finish(&mut cloud, opts, &mut report).map_err(|e| match e {
        super::ReadError::Limit(l) => SogError::Limit(l),
        e => SogError::Unusable(e.to_string()),
    })?;
    Ok(Scene {
        cloud,
        cameras: Vec::new(),
        report,
    })
}

fn unbundled(
    meta: &[u8],
    opts: &LoadOptions,
    load: &mut dyn FnMut(&str) -> Result<Vec<u8>, SogError>,
    findings: &mut Vec<Finding>,
) -> Result<(SplatCloud, Details), SogError> {
    let m = parse_meta(meta, &opts.limits)?;
    let textures = decode::names(&m)
        .iter()
        .map(|(_, name)| load(name))
        .collect::<Result<Vec<_>, _>>()?;
    let input = meta.len() + textures.iter().map(Vec::len).sum::<usize>();
    let budget = budget_for(input, &opts.limits);
    let drop_at = codec::drop_site("splats", opts);
    let (cloud, mut d) = decode::decode(&m, &textures, (budget, drop_at), findings)?;
    d.compression = "WebP lossless, meta.json + files".into();
    Ok((cloud, d))
}

/// Reads the textures of an unbundled SOG: from `opts.resolver` when there is one, else beside
/// `path` under the containment rule ([`crate::files::contained`]: inside meta.json's folder
/// after `..` and symlinks are resolved, unless `opts.allow_outside_paths`), regular files
/// only, all of them together within `limits.max_bytes`.
fn read_dir(
    meta: &[u8],
    path: Option<&Path>,
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> Result<(SplatCloud, Details), SogError> {
    let mut so_far = 0u64;
    let count = |name: &str, data: Vec<u8>, so_far: &mut u64| {
        *so_far += data.len() as u64;
        opts.limits
            .check_bytes(*so_far, &format!("'{name}' (with the textures before it)"))?;
        Ok::<_, SogError>(data)
    };
    if let Some(resolver) = &opts.resolver {
        let mut load = |name: &str| -> Result<Vec<u8>, SogError> {
            let data = resolver(name).map_err(|message| SogError::Member {
                member: name.into(),
                message: format!("resolver: {message}"),
            })?;
            count(name, data, &mut so_far)
        };
        return unbundled(meta, opts, &mut load, findings);
    }
    let dir = match path.ok_or(SogError::NoDirectory)?.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => std::path::PathBuf::from("."),
    };
    let mut load = |name: &str| -> Result<Vec<u8>, SogError> {
        let fail = |message: String| SogError::Member {
            member: name.into(),
            message,
        };
        // Containment first: a name outside the folder is refused alike, there or not.
        use crate::files::{Refused, contained_file};
        let file = match contained_file(&dir, Path::new(name), name, opts.allow_outside_paths) {
            Ok(file) => file,
            Err(Refused::Outside(m)) => return Err(fail(m)),
            Err(Refused::Missing(_)) => {
                return Err(SogError::Missing {
                    member: name.into(),
                });
            }
        };
        let left = opts.limits.max_bytes.saturating_sub(so_far);
        let data = crate::files::read_bounded(&file, left, "the texture")
            .map_err(|e| fail(e.to_string()))?;
        count(name, data, &mut so_far)
    };
    unbundled(meta, opts, &mut load, findings)
}
