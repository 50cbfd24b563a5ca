//! Container level: GLB / JSON, the `KHR_gaussian_splatting:*` semantic work-around for the
//! `gltf` crate, schema validation, and buffer resolution (GLB BIN, data URIs, files).

use super::GltfError;
use crate::load::Format;
use crate::load::finding::Finding;
use base64::Engine;
use gltf::json::validation::Validate;
use serde_json::Value;
use std::path::Path;

/// Prefix of the extension's attribute semantics.
pub const PREFIX: &str = "KHR_gaussian_splatting:";
/// The extension's name.
pub const EXT: &str = "KHR_gaussian_splatting";

/// Extensions whose presence in `extensionsRequired` splatgl can honour.
pub const SUPPORTED_REQUIRED: &[&str] = &[EXT, "KHR_mesh_quantization"];

/// A parsed glTF asset.
pub struct Parsed {
    /// The JSON as written (original attribute names).
    pub json: Value,
    /// The `gltf` crate's view; `None` when blocking findings made it unsafe to build.
    pub doc: Option<gltf::Document>,
    /// Buffer data by index (empty where a buffer could not be resolved; a finding says why).
    pub buffers: Vec<Vec<u8>>,
    /// Size of the input, for allocation limits.
    pub input_len: usize,
}

fn container(msg: impl Into<String>) -> GltfError {
    GltfError::Container(msg.into())
}

/// Parses the container and validates the structure. Problems found go to `findings`;
/// only unreadable input is an `Err`.
pub fn parse(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
    findings: &mut Vec<Finding>,
) -> Result<Parsed, GltfError> {
    let (json_bytes, bin): (std::borrow::Cow<[u8]>, Option<Vec<u8>>) = match format {
        Format::Glb => {
            let glb =
                gltf::binary::Glb::from_slice(bytes).map_err(|e| container(format!("GLB: {e}")))?;
            (glb.json, glb.bin.map(|b| b.into_owned()))
        }
        _ => (std::borrow::Cow::Borrowed(bytes), None),
    };
    let json: Value =
        serde_json::from_slice(&json_bytes).map_err(|e| container(format!("JSON: {e}")))?;
    if !json.is_object() {
        return Err(container("JSON: the top level is not an object"));
    }
    let mut parsed = Parsed {
        json,
        doc: None,
        buffers: Vec::new(),
        input_len: bytes.len(),
    };
    check_required_extensions(&parsed.json, findings);
    let Some(root) = schema_root(&parsed.json, findings) else {
        return Ok(parsed);
    };
    let doc = gltf::Document::from_json_without_validation(root);
    parsed.buffers = resolve_buffers(&doc, bin, path, findings);
    parsed.doc = Some(doc);
    Ok(parsed)
}

fn check_required_extensions(json: &Value, findings: &mut Vec<Finding>) {
    let Some(req) = json.get("extensionsRequired").and_then(Value::as_array) else {
        return;
    };
    let used: Vec<&str> = json
        .get("extensionsUsed")
        .and_then(Value::as_array)
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    for (i, name) in req.iter().enumerate() {
        let path = format!("extensionsRequired[{i}]");
        match name.as_str() {
            Some(n) if SUPPORTED_REQUIRED.contains(&n) => {
                if !used.contains(&n) {
                    findings.push(Finding::error(
                        path,
                        format!("{n:?} is required but not listed in extensionsUsed"),
                    ));
                }
            }
            Some(n) if n.starts_with("KHR_materials_") || n.starts_with("KHR_texture_") => findings
                .push(Finding::warning(
                    path,
                    format!(
                        "required extension {n:?} concerns materials, which splat rendering ignores"
                    ),
                )),
            Some(n) => findings.push(Finding::fatal(
                path,
                format!("required extension {n:?} is not supported by splatgl"),
            )),
            None => findings.push(Finding::fatal(path, "extension name is not a string")),
        }
    }
}

/// Renames the extension's semantics so the `gltf` crate reads them as custom (`_`-prefixed)
/// attributes, drops supported names from `extensionsRequired`, runs the crate's schema
/// validation, and returns the typed root when nothing blocking was found.
fn schema_root(json: &Value, findings: &mut Vec<Finding>) -> Option<gltf::json::Root> {
    let mut v = json.clone();
    let n_accessors = v
        .get("accessors")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    if let Some(meshes) = v.get_mut("meshes").and_then(Value::as_array_mut) {
        for (mi, mesh) in meshes.iter_mut().enumerate() {
            let Some(prims) = mesh.get_mut("primitives").and_then(Value::as_array_mut) else {
                continue;
            };
            for (pi, prim) in prims.iter_mut().enumerate() {
                let Some(attrs) = prim.get_mut("attributes").and_then(Value::as_object_mut) else {
                    continue;
                };
                // The gltf crate's primitive hook indexes accessors by POSITION unchecked.
                if let Some(p) = attrs.get("POSITION") {
                    let ok = p.as_u64().is_some_and(|i| (i as usize) < n_accessors);
                    if !ok {
                        findings.push(Finding::fatal(
                            format!("meshes[{mi}].primitives[{pi}].attributes[\"POSITION\"]"),
                            format!("accessor index {p} out of range (there are {n_accessors})"),
                        ));
                        return None;
                    }
                }
                let keys: Vec<String> = attrs
                    .keys()
                    .filter(|k| k.starts_with(PREFIX))
                    .cloned()
                    .collect();
                for k in keys {
                    if let Some(val) = attrs.remove(&k) {
                        attrs.insert(format!("_{k}"), val);
                    }
                }
            }
        }
    }
    // Required extensions were judged above; the gltf crate knows none of ours.
    if let Some(obj) = v.as_object_mut() {
        obj.remove("extensionsRequired");
    }
    let root: gltf::json::Root = match serde_json::from_value(v) {
        Ok(r) => r,
        Err(e) => {
            findings.push(Finding::fatal("", format!("not a glTF 2.0 document: {e}")));
            return None;
        }
    };
    let mut blocking = false;
    root.validate(&root, gltf::json::Path::new, &mut |path, err| {
        let p = path().as_str().to_owned();
        // Missing/invalid POSITION min/max is a glTF MUST the splat data does not depend on.
        // gltf-json also reports an accessor without bufferView, which glTF 2.0 allows
        // (zero-filled or sparse-only); the decoder handles it.
        let soft = p.ends_with(".min")
            || p.ends_with(".max")
            || (p.ends_with(".bufferView")
                && p.starts_with("accessors[")
                && matches!(err, gltf::json::validation::Error::Missing));
        if soft && p.ends_with(".bufferView") {
            return;
        }
        let msg = match err {
            gltf::json::validation::Error::IndexOutOfBounds => "index out of bounds",
            gltf::json::validation::Error::Invalid => "invalid value",
            gltf::json::validation::Error::Missing => "required property missing",
            gltf::json::validation::Error::Oversize => "size exceeds system limits",
            gltf::json::validation::Error::Unsupported => "not supported",
        };
        let msg = format!("glTF 2.0 schema: {msg}");
        blocking |= !soft;
        findings.push(if soft {
            Finding::error(p, msg)
        } else {
            Finding::fatal(p, msg)
        });
    });
    if let Some(f) = node_graph_problem(&root) {
        findings.push(f);
        blocking = true;
    }
    (!blocking).then_some(root)
}

/// Node hierarchy must be a forest (no node with two parents, no cycles).
fn node_graph_problem(root: &gltf::json::Root) -> Option<Finding> {
    let n = root.nodes.len();
    let mut parent = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        for c in node.children.iter().flatten() {
            let c = c.value();
            if c >= n {
                continue; // reported by schema validation
            }
            if c == i || parent[c].is_some() {
                return Some(Finding::fatal(
                    format!("nodes[{i}].children"),
                    format!("node {c} has more than one parent or is its own child"),
                ));
            }
            parent[c] = Some(i);
        }
    }
    // With at most one parent each, a cycle means a chain that never reaches a root.
    for start in 0..n {
        let (mut cur, mut steps) = (start, 0);
        while let Some(p) = parent[cur] {
            cur = p;
            steps += 1;
            if steps > n {
                return Some(Finding::fatal(
                    format!("nodes[{start}]"),
                    "node hierarchy contains a cycle",
                ));
            }
        }
    }
    None
}

fn resolve_buffers(
    doc: &gltf::Document,
    mut bin: Option<Vec<u8>>,
    path: Option<&Path>,
    findings: &mut Vec<Finding>,
) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for buf in doc.buffers() {
        let jp = format!("buffers[{}]", buf.index());
        let data = match buf.source() {
            gltf::buffer::Source::Bin => match bin.take() {
                Some(b) => Ok(b),
                None => Err("refers to the GLB BIN chunk, which is missing (or used twice)".into()),
            },
            gltf::buffer::Source::Uri(uri) => read_uri(uri, path),
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
                findings.push(Finding::fatal(jp, msg));
                out.push(Vec::new());
            }
        }
    }
    out
}

fn read_uri(uri: &str, path: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) = rest
            .split_once(";base64,")
            .ok_or("data URI is not base64 (expected 'data:...;base64,')")?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("data URI: invalid base64 ({e})"));
    }
    if uri.contains("://") {
        return Err(format!(
            "URI {uri:?}: only relative file paths and data URIs are read"
        ));
    }
    let base = path
        .and_then(Path::parent)
        .ok_or_else(|| format!("external buffer {uri:?} needs the glTF file's path"))?;
    let file = base.join(percent_decode(uri));
    std::fs::read(&file).map_err(|e| format!("external buffer {}: {e}", file.display()))
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push(h * 16 + l);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}
