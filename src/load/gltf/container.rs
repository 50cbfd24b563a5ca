//! Container level: GLB / JSON, the `KHR_gaussian_splatting:*` semantic work-around for the
//! `gltf` crate, schema validation; buffers are resolved by `buffers.rs` beside this file.

use super::GltfError;
use crate::load::finding::Finding;
use crate::load::{Format, LoadOptions, check_json};
use gltf::json::validation::Validate;
use serde_json::Value;
use std::path::Path;

/// Prefix of the extension's attribute semantics.
pub const PREFIX: &str = "KHR_gaussian_splatting:";
/// The extension's name.
pub const EXT: &str = "KHR_gaussian_splatting";

/// Extensions whose presence in `extensionsRequired` splatgl can honour.
pub const SUPPORTED_REQUIRED: &[&str] = &[
    EXT,
    "KHR_mesh_quantization",
    super::spz::SPZ_2,
    super::spz::LEGACY,
];

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
    /// Bytes read from external buffer files (also part of the allocation budget).
    pub external_bytes: u64,
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
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> Result<Parsed, GltfError> {
    let (json_bytes, bin): (&[u8], Option<Vec<u8>>) = match format {
        Format::Glb => {
            let (json, bin) = split_glb(bytes)?;
            (json, bin.map(<[u8]>::to_vec))
        }
        _ => (bytes, None),
    };
    check_json(json_bytes, &opts.limits).map_err(container)?;
    let json: Value =
        serde_json::from_slice(json_bytes).map_err(|e| container(format!("JSON: {e}")))?;
    if !json.is_object() {
        return Err(container("JSON: the top level is not an object"));
    }
    let mut parsed = Parsed {
        json,
        doc: None,
        buffers: Vec::new(),
        input_len: bytes.len(),
        external_bytes: 0,
    };
    check_required_extensions(&parsed.json, findings);
    let Some(root) = schema_root(&parsed.json, findings) else {
        return Ok(parsed);
    };
    let doc = gltf::Document::from_json_without_validation(root);
    (parsed.buffers, parsed.external_bytes) =
        super::buffers::resolve(&doc, bin, path, opts, findings);
    parsed.doc = Some(doc);
    Ok(parsed)
}

/// GLB framing (glTF 2.0 §4.4): 12-byte header, a JSON chunk, an optional BIN chunk; unknown
/// chunks are skipped. Every length is checked against the bytes present.
pub fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), GltfError> {
    let u32_at = |b: &[u8], o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    if bytes.len() < 12 || &bytes[..4] != b"glTF" {
        return Err(container("GLB: no 12-byte 'glTF' header"));
    }
    let version = u32_at(bytes, 4);
    if version != 2 {
        return Err(container(format!("GLB: version {version}, expected 2")));
    }
    let length = u32_at(bytes, 8) as usize;
    if length > bytes.len() || length < 20 {
        return Err(container(format!(
            "GLB: header length {length} does not fit the {} bytes present (minimum 20)",
            bytes.len()
        )));
    }
    let data = &bytes[..length];
    let (mut pos, mut json, mut bin) = (12usize, None, None);
    let mut index = 0;
    while pos < length {
        if length - pos < 8 {
            return Err(container(format!("GLB: chunk {index} header is truncated")));
        }
        let (clen, ctype) = (u32_at(data, pos) as usize, u32_at(data, pos + 4));
        let start = pos + 8;
        if clen > length - start {
            return Err(container(format!(
                "GLB: chunk {index} claims {clen} bytes but only {} remain",
                length - start
            )));
        }
        let chunk = &data[start..start + clen];
        match (index, ctype) {
            (0, 0x4E4F_534A) => json = Some(chunk),
            (0, _) => return Err(container("GLB: the first chunk is not JSON")),
            (1, 0x004E_4942) => bin = Some(chunk),
            _ => {} // unknown chunk types are ignored (glTF 2.0)
        }
        pos = start + clen;
        index += 1;
    }
    let json = json.ok_or_else(|| container("GLB: no JSON chunk"))?;
    Ok((json, bin))
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
            Some(n) => findings.push(Finding::unsupported(
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
    rename_semantics(&mut v, findings)?;
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
    let mut blocking = validate_schema(json, &root, findings);
    if let Some(f) = node_graph_problem(&root) {
        findings.push(f);
        blocking = true;
    }
    (!blocking).then_some(root)
}

/// In every primitive of `v`, renames the `KHR_gaussian_splatting:*` attributes to `_`-prefixed
/// custom ones. `None` (after a blocking finding) for a POSITION accessor index out of range,
/// which the `gltf` crate's primitive hook would index unchecked.
fn rename_semantics(v: &mut Value, findings: &mut Vec<Finding>) -> Option<()> {
    let n_accessors = v
        .get("accessors")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let Some(meshes) = v.get_mut("meshes").and_then(Value::as_array_mut) else {
        return Some(());
    };
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
    Some(())
}

/// Runs the `gltf` crate's schema validation of `root` (read from `json`), reporting each
/// problem: as an error where the splat data does not depend on it, else as fatal. Returns
/// whether a fatal one was found.
fn validate_schema(json: &Value, root: &gltf::json::Root, findings: &mut Vec<Finding>) -> bool {
    let mut blocking = false;
    root.validate(root, gltf::json::Path::new, &mut |path, err| {
        let p = path().as_str().to_owned();
        // Missing/invalid POSITION min/max is a glTF MUST the splat data does not depend on.
        // gltf-json also reports an accessor without bufferView, which glTF 2.0 allows
        // (zero-filled or sparse-only); the decoder handles it.
        let soft = p.ends_with(".min")
            || p.ends_with(".max")
            || (p.ends_with(".attributes[\"POSITION\"]")
                && matches!(err, gltf::json::validation::Error::Missing)
                && !is_splat_primitive(json, &p))
            || (p.ends_with(".bufferView")
                && p.starts_with("accessors[")
                && matches!(err, gltf::json::validation::Error::Missing));
        if soft && (p.ends_with(".bufferView") || p.ends_with(".attributes[\"POSITION\"]")) {
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
    blocking
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
    // With at most one parent each, a cycle means a chain that never reaches a root. Each node
    // is walked once: 0 = unknown, 1 = on the current chain, 2 = reaches a root.
    let mut state = vec![0u8; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut cur = start;
        loop {
            match state[cur] {
                2 => break,
                1 => {
                    return Some(Finding::fatal(
                        format!("nodes[{start}]"),
                        "node hierarchy contains a cycle",
                    ));
                }
                _ => {}
            }
            state[cur] = 1;
            chain.push(cur);
            match parent[cur] {
                Some(p) => cur = p,
                None => break,
            }
        }
        for c in chain {
            state[c] = 2;
        }
    }
    // glTF 2.0: a scene's nodes are distinct root nodes (else instances would repeat).
    for (si, scene) in root.scenes.iter().enumerate() {
        let mut seen = std::collections::HashSet::new();
        for (k, nd) in scene.nodes.iter().enumerate() {
            let v = nd.value();
            if v < n && (parent[v].is_some() || !seen.insert(v)) {
                return Some(Finding::fatal(
                    format!("scenes[{si}].nodes[{k}]"),
                    format!(
                        "node {v} is listed twice or is not a root node (glTF 2.0: scene nodes are distinct roots)"
                    ),
                ));
            }
        }
    }
    None
}

/// Whether the primitive a path like `meshes[0].primitives[1]...` points into carries the
/// extension (gltf-json reports a missing POSITION for every primitive; glTF 2.0 requires it
/// only where the primitive is used as splats here).
fn is_splat_primitive(json: &Value, path: &str) -> bool {
    let num = |key: &str| -> Option<usize> {
        let rest = &path[path.find(key)? + key.len()..];
        rest[..rest.find(']')?].parse().ok()
    };
    let (Some(m), Some(p)) = (num("meshes["), num("primitives[")) else {
        return false;
    };
    json["meshes"][m]["primitives"][p]
        .get("extensions")
        .and_then(|e| e.get(EXT))
        .is_some()
}
