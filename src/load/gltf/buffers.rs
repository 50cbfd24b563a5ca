//! Buffer resolution: the GLB BIN chunk, base64 data URIs, the embedder's
//! [`LoadOptions::resolver`], or files — inside the asset's folder only.
//!
//! **Containment rule.** A file URI is percent-decoded and joined to the folder of the glTF
//! file; both are canonicalised (`..` resolved, symlinks followed) and the file must lie inside
//! the folder. Absolute paths, `..` escapes and symlinks pointing outside are refused with a
//! finding at `buffers[i].uri`, unless [`LoadOptions::allow_outside_paths`] is set. Files are
//! read only when regular ([`crate::files`]), up to `byteLength`, within `limits.max_bytes`.

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
    let file = contained(&base, uri, opts.allow_outside_paths)?;
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

/// The file `uri` names relative to `base`, canonicalised, refused when it leaves `base`
/// (unless `allow_outside`).
fn contained(base: &Path, uri: &str, allow_outside: bool) -> Result<PathBuf, String> {
    let decoded = percent_decode(uri);
    let rel = Path::new(&decoded);
    let how = "external files must lie inside the glTF file's folder (allow with --allow-outside-paths / LoadOptions::allow_outside_paths)";
    if rel.is_absolute() && !allow_outside {
        return Err(format!("URI {uri:?} is an absolute path; {how}"));
    }
    let joined = base.join(rel);
    let file = joined
        .canonicalize()
        .map_err(|e| format!("external buffer {}: {e}", joined.display()))?;
    if allow_outside {
        return Ok(file);
    }
    let root = base
        .canonicalize()
        .map_err(|e| format!("asset folder {}: {e}", base.display()))?;
    if !file.starts_with(&root) {
        return Err(format!(
            "URI {uri:?} resolves to {}, outside the asset's folder {}; {how}",
            file.display(),
            root.display()
        ));
    }
    Ok(file)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push(h * 16 + l);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding_keeps_invalid_escapes() {
        assert_eq!(percent_decode("a%20b%2e.bin"), "a b..bin");
        assert_eq!(percent_decode("%zz%4"), "%zz%4");
    }
}
