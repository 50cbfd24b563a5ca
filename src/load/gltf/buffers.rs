//! Buffer resolution: the GLB BIN chunk, base64 data URIs, the embedder's
//! [`LoadOptions::resolver`], or files — inside the asset's folder only.
//!
//! File URIs follow the containment rule ([`crate::files::contained`]: inside the glTF file's
//! folder after `..` and symlinks are resolved) unless [`LoadOptions::allow_outside_paths`];
//! a refusal is a finding at `buffers[i].uri`. Files are read only when regular
//! ([`crate::files`]), up to `byteLength`, within `limits.max_bytes`.

use crate::load::finding::Finding;
use crate::load::{LoadOptions, Resolver};
use base64::Engine;
use std::path::{Path, PathBuf};

/// Every buffer's bytes by index (empty where it could not be resolved; a finding says why),
/// and the bytes read from outside the document (files or the resolver).
pub(super) fn resolve(
    doc: &gltf::Document,
    mut bin: Option<Vec<u8>>,
    path: Option<&Path>,
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> (Vec<Vec<u8>>, u64) {
    let mut out = Vec::new();
    let mut external = 0u64;
    for buf in doc.buffers() {
        let jp = format!("buffers[{}]", buf.index());
        let mut at = jp.clone();
        let data = match buf.source() {
            gltf::buffer::Source::Bin => match bin.take() {
                Some(b) => Ok(b),
                None => Err("refers to the GLB BIN chunk, which is missing (or used twice)".into()),
            },
            gltf::buffer::Source::Uri(uri) => {
                at = format!("{jp}.uri");
                let r = read_uri(uri, path, buf.length(), external, opts);
                if let (Ok(d), false) = (&r, uri.starts_with("data:")) {
                    external += d.len() as u64;
                }
                r
            }
        };
        match data {
            Ok(d) if d.len() < buf.length() => {
                findings.push(Finding::fatal(
                    jp,
                    format!(
                        "byteLength is {} but only {} bytes are present",
                        buf.length(),
                        d.len()
                    ),
                ));
                out.push(Vec::new());
            }
            Ok(mut d) => {
                d.truncate(buf.length());
                out.push(d);
            }
            Err(msg) => {
                findings.push(Finding::fatal(at, msg));
                out.push(Vec::new());
            }
        }
    }
    (out, external)
}

/// Reads a buffer URI: a base64 data URI, the resolver's answer, or a file inside the asset's
/// folder, `len` bytes at most; `so_far` external bytes were read before it (all of them
/// together are bounded by `limits.max_bytes`).
fn read_uri(
    uri: &str,
    path: Option<&Path>,
    len: usize,
    so_far: u64,
    opts: &LoadOptions,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or("data URI is not base64 (expected 'data:...;base64,')")?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("data URI: invalid base64 ({e})"));
    }
    let what = format!("external buffer {uri:?} (with the external buffers before it)");
    opts.limits
        .check_bytes(so_far.saturating_add(len as u64), &what)
        .map_err(|e| e.to_string())?;
    if let Some(resolver) = &opts.resolver {
        return from_resolver(resolver, uri, len);
    }
    if uri.contains("://") {
        return Err(format!(
            "URI {uri:?}: only relative file paths and data URIs are read"
        ));
    }
    let base = path
        .map(|p| match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
            _ => PathBuf::from("."),
        })
        .ok_or_else(|| {
            format!("external buffer {uri:?} needs the glTF file's path (or LoadOptions::resolver)")
        })?;
    let file = crate::files::contained(&base, uri, opts.allow_outside_paths)?;
    let err = |e: std::io::Error| format!("external buffer {}: {e}", file.display());
    let (f, _) = crate::files::open_regular(&file, "the external buffer").map_err(err)?;
    let mut data = Vec::new();
    std::io::Read::read_to_end(&mut std::io::Read::take(f, len as u64), &mut data).map_err(err)?;
    Ok(data)
}

fn from_resolver(resolver: &Resolver, uri: &str, len: usize) -> Result<Vec<u8>, String> {
    let mut d = resolver(uri).map_err(|e| format!("resolver for URI {uri:?}: {e}"))?;
    d.truncate(len);
    Ok(d)
}
