//! glTF 2.0 loader for `KHR_gaussian_splatting` (`.gltf` with external or data-URI buffers,
//! and `.glb`).
//!
//! Every primitive carrying the extension, in every node of the default scene (or scene 0),
//! is read with its **global node transform applied** and merged into one cloud (the sort is
//! global):
//! - positions by the full matrix;
//! - covariance per the RC, Σ = M C Cᵀ Mᵀ, stored back as scale + rotation. For a similarity M
//!   this is closed form (rotation composed, scale multiplied); otherwise Σ is eigen-decomposed
//!   in f64, which represents every Σ exactly up to rounding (see [`crate::covariance`]);
//! - SH rotated by the orthogonal factor of M's polar decomposition (real Wigner-D, see
//!   [`crate::sh::ShRotation`]).
//!
//! All RC rules are checked on the way and reported as [`Finding`]s; `splatgl validate` shows
//! them all, the loader stops at the first one that makes the data unusable.

pub mod accessor;
pub mod container;
pub mod primitive;
mod transform;

use super::finding::{Finding, Severity};
use super::{Format, LoadOptions, LoadReport, Loaded, ScaleSeen};
use crate::cloud::SplatCloud;
use container::EXT;
use glam::DMat4;
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;

/// Why a glTF file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The container is unreadable (bad GLB framing, bad JSON).
    #[error("{0}")]
    Container(String),
    /// The document breaks a rule the loader cannot work around.
    #[error("{0}")]
    Invalid(Finding),
    /// No primitive with `KHR_gaussian_splatting` is instantiated by the scene.
    #[error("no primitive with KHR_gaussian_splatting in the scene")]
    NoSplats,
}

/// Everything learnt from one pass over a document.
#[derive(Debug)]
pub struct Walk {
    /// The merged cloud (`None` if a blocking finding stopped the pass, or no splats).
    pub cloud: Option<SplatCloud>,
    /// Every finding, in document order.
    pub findings: Vec<Finding>,
    /// Scale space seen.
    pub scale_seen: Option<ScaleSeen>,
    /// Non-unit quaternions normalised.
    pub non_unit: usize,
    /// Number of splat primitives in the document (instantiated or not).
    pub splat_primitives: usize,
}

/// Reads and checks a whole document. Only an unreadable container is an `Err`.
pub fn walk(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Walk, GltfError> {
    let mut findings = Vec::new();
    let parsed = container::parse(bytes, format, path, &mut findings)?;
    let mut w = Walk {
        cloud: None,
        findings,
        scale_seen: None,
        non_unit: 0,
        splat_primitives: 0,
    };
    w.splat_primitives = count_splat_primitives(&parsed.json);
    let Some(doc) = &parsed.doc else {
        return Ok(w);
    };
    let json = &parsed.json;
    uses_extension_check(json, &mut w.findings);

    // Everything decoded or instantiated is charged to one budget of f32 values, bounded by the
    // input: 16M values (64 MiB) plus 4 values per input byte (file and external buffers).
    let input: u64 = parsed.input_len as u64 + parsed.external_bytes;
    let budget = std::cell::Cell::new((16u64 << 20) + 4 * input);

    // Pass 1: every splat primitive of every mesh, decoded and checked once.
    let mut decoded: HashMap<(usize, usize), primitive::LocalSplats> = HashMap::new();
    let no_values: &[Value] = &[];
    let meshes = json
        .get("meshes")
        .and_then(Value::as_array)
        .map_or(no_values, Vec::as_slice);
    let mut blocked = false;
    for (mi, mesh) in meshes.iter().enumerate() {
        let prims = mesh
            .get("primitives")
            .and_then(Value::as_array)
            .map_or(no_values, Vec::as_slice);
        for (pi, prim) in prims.iter().enumerate() {
            let ppath = format!("meshes[{mi}].primitives[{pi}]");
            let exts = prim.get("extensions").and_then(Value::as_object);
            if let Some(legacy) = exts.and_then(|e| {
                e.keys()
                    .find(|k| k.as_str() != EXT && k.contains("gaussian_splats"))
            }) {
                w.findings.push(Finding::fatal(
                    format!("{ppath}.extensions.{legacy}"),
                    format!("legacy draft extension {legacy:?} is not supported (re-export with KHR_gaussian_splatting)"),
                ));
                blocked = true;
                continue;
            }
            let Some(ext) = exts.and_then(|e| e.get(EXT)) else {
                continue;
            };
            let Some(ext) = ext.as_object() else {
                w.findings.push(Finding::fatal(
                    format!("{ppath}.extensions.{EXT}"),
                    "must be an object",
                ));
                blocked = true;
                continue;
            };
            let before = w.findings.len();
            let used: Vec<&str> = json
                .get("extensionsUsed")
                .and_then(Value::as_array)
                .map(|a| a.iter().filter_map(Value::as_str).collect())
                .unwrap_or_default();
            let meta = primitive::read_meta(ext, &ppath, &used, &mut w.findings);
            if w.findings[before..].iter().any(|f| f.blocks_loading) {
                blocked = true;
                continue;
            }
            let ctx = primitive::Ctx {
                doc,
                buffers: &parsed.buffers,
                path: ppath,
                scale_space: opts.scale_space,
                budget: &budget,
                quantization: json
                    .get("extensionsUsed")
                    .and_then(Value::as_array)
                    .is_some_and(|a| a.iter().any(|v| v == "KHR_mesh_quantization")),
            };
            match primitive::read(&ctx, prim, &meta, &mut w.findings) {
                Some(ls) => {
                    decoded.insert((mi, pi), ls);
                }
                None => blocked = true,
            }
        }
    }
    if blocked {
        return Ok(w);
    }

    // Pass 2: instantiate through the scene's node hierarchy.
    let mut cloud: Option<SplatCloud> = None;
    let mut instances = Vec::new();
    scene_meshes(doc, json, &mut w.findings, &mut instances);
    for (node, mesh, m) in instances {
        let Some(mesh_json) = meshes.get(mesh) else {
            continue;
        };
        let n_prims = mesh_json
            .get("primitives")
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        for pi in 0..n_prims {
            let Some(ls) = decoded.get(&(mesh, pi)) else {
                continue;
            };
            let per_splat = 11 + 3 * ls.cloud.coeffs_per_splat() as u64;
            let values = ls.cloud.len() as u64 * per_splat;
            if values > budget.get() {
                w.findings.push(Finding::fatal(
                    format!("nodes[{node}]"),
                    format!(
                        "instancing meshes[{mesh}] here would exceed the output this {input}-byte input can justify (16M + 4 values per input byte)"
                    ),
                ));
                return Ok(w);
            }
            budget.set(budget.get() - values);
            let Some(global) = transform::apply(&ls.cloud, m, node, &mut w.findings) else {
                return Ok(w);
            };
            w.scale_seen = Some(ScaleSeen::merge(w.scale_seen, ls.scale_seen));
            w.non_unit += ls.non_unit;
            match &mut cloud {
                None => cloud = Some(global),
                Some(c) => {
                    if c.meta != global.meta {
                        w.findings.push(Finding::warning(
                            format!("meshes[{mesh}].primitives[{pi}]"),
                            "extension properties differ from the first splat primitive's; the first primitive's are used",
                        ));
                    }
                    if c.append(global) {
                        w.findings.push(Finding::warning(
                            format!("meshes[{mesh}].primitives[{pi}]"),
                            "primitives have different SH degrees; lower degrees are zero-padded (colours unchanged)",
                        ));
                    }
                }
            }
        }
    }
    w.cloud = cloud;
    Ok(w)
}

fn count_splat_primitives(json: &Value) -> usize {
    let prims = json
        .get("meshes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(|m| m.get("primitives").and_then(Value::as_array))
        .flatten();
    prims
        .filter(|p| p.get("extensions").and_then(|e| e.get(EXT)).is_some())
        .count()
}

fn uses_extension_check(json: &Value, findings: &mut Vec<Finding>) {
    let used = json
        .get("extensionsUsed")
        .and_then(Value::as_array)
        .is_some_and(|a| a.iter().any(|v| v.as_str() == Some(EXT)));
    if count_splat_primitives(json) > 0 && !used {
        findings.push(Finding::error(
            "extensionsUsed",
            format!("{EXT} is used by primitives but not listed in extensionsUsed"),
        ));
    }
}

/// (node index, mesh index, global matrix) for every mesh instance in the scene.
fn scene_meshes(
    doc: &gltf::Document,
    json: &Value,
    findings: &mut Vec<Finding>,
    out: &mut Vec<(usize, usize, DMat4)>,
) {
    for (node, m) in scene_nodes(doc, json, findings) {
        if let Some(mesh) = node.mesh() {
            out.push((node.index(), mesh.index(), m));
        }
    }
}

/// Every node of the default scene (or scene 0; without scenes, every root's tree) with its
/// global matrix, depth first in document order.
fn scene_nodes<'d>(
    doc: &'d gltf::Document,
    json: &Value,
    findings: &mut Vec<Finding>,
) -> Vec<(gltf::Node<'d>, DMat4)> {
    // Depth first with an explicit stack: a deep node chain cannot overflow the call stack.
    // (The hierarchy was checked to be a forest, so this terminates.)
    fn visit<'d>(root: gltf::Node<'d>, out: &mut Vec<(gltf::Node<'d>, DMat4)>) {
        let mut stack = vec![(root, DMat4::IDENTITY)];
        while let Some((node, parent)) = stack.pop() {
            let local =
                DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let m = parent * local;
            let children: Vec<_> = node.children().collect();
            out.push((node, m));
            for c in children.into_iter().rev() {
                stack.push((c, m));
            }
        }
    }
    let mut out = Vec::new();
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    match scene {
        Some(s) => {
            for n in s.nodes() {
                visit(n, &mut out);
            }
        }
        None => {
            // No scene: use every root node, and say so.
            let n = doc.nodes().count();
            let mut is_child = vec![false; n];
            for node in doc.nodes() {
                for c in node.children() {
                    is_child[c.index()] = true;
                }
            }
            if n > 0 && json.get("scenes").is_none() {
                findings.push(Finding::warning(
                    "scenes",
                    "no scene; rendering every root node",
                ));
            }
            for node in doc.nodes() {
                if !is_child[node.index()] {
                    visit(node, &mut out);
                }
            }
        }
    }
    out
}

/// The perspective camera nodes of the scene, in scene traversal order (depth first), with
/// their global transforms. Orthographic cameras are skipped (splat rendering with them is
/// undefined per the RC).
pub fn cameras(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
) -> Result<Vec<crate::camera::GltfPerspective>, GltfError> {
    let mut findings = Vec::new();
    let parsed = container::parse(bytes, format, path, &mut findings)?;
    let Some(doc) = &parsed.doc else {
        let f = findings.into_iter().find(|f| f.blocks_loading);
        return Err(f.map_or(GltfError::NoSplats, GltfError::Invalid));
    };
    if let Some(f) = findings.iter().find(|f| f.blocks_loading) {
        return Err(GltfError::Invalid(f.clone()));
    }
    let mut out = Vec::new();
    for (node, m) in scene_nodes(doc, &parsed.json, &mut findings) {
        let Some(cam) = node.camera() else { continue };
        // The gltf crate unwraps the object named by `type`; make sure it is there.
        let cj = &parsed.json["cameras"][cam.index()];
        let ty = cj.get("type").and_then(Value::as_str).unwrap_or("");
        if cj.get(ty).is_none_or(|o| !o.is_object()) {
            return Err(GltfError::Invalid(Finding::fatal(
                format!("cameras[{}]", cam.index()),
                format!("type {ty:?} but no {ty:?} object"),
            )));
        }
        if let gltf::camera::Projection::Perspective(p) = cam.projection() {
            out.push(crate::camera::GltfPerspective {
                yfov: p.yfov(),
                aspect_ratio: p.aspect_ratio(),
                znear: p.znear(),
                zfar: p.zfar(),
                node_to_world: m.as_mat4(),
            });
        }
    }
    Ok(out)
}

/// Loads a glTF or GLB file from memory (`path` resolves external buffers).
pub fn load(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Loaded, GltfError> {
    let w = walk(bytes, format, path, opts)?;
    if let Some(f) = w.findings.iter().find(|f| f.blocks_loading) {
        return Err(GltfError::Invalid(f.clone()));
    }
    let cloud = w.cloud.ok_or(GltfError::NoSplats)?;
    let mut report = LoadReport::new(format);
    report.scale_space = w.scale_seen;
    report.non_unit_quaternions = w.non_unit;
    for f in w.findings {
        let msg = match f.severity {
            Severity::Error => format!(
                "invalid per KHR_gaussian_splatting RC / glTF 2.0: {}",
                f.message
            ),
            Severity::Warning => f.message,
        };
        let loc = match f.index {
            Some(i) => format!("{} [index {i}]", f.path),
            None => f.path,
        };
        report.warn(loc, msg);
    }
    Ok(Loaded { cloud, report })
}
