//! glTF 2.0 loader for `KHR_gaussian_splatting` (`.gltf` with external or data-URI buffers,
//! and `.glb`).
//!
//! Every primitive carrying the extension, in every node of the default scene (or scene 0),
//! is read with its **global node transform applied** and merged into one cloud (the sort is
//! global):
//! - positions by the full matrix;
//! - covariance per the RC, Σ = M C Cᵀ Mᵀ, stored back as scale + rotation. For a similarity M
//!   this is closed form (rotation composed, scale multiplied); otherwise Σ is eigen-decomposed
//!   in f64, which represents every Σ exactly up to rounding (`src/covariance.rs`);
//! - SH rotated by the orthogonal factor of M's polar decomposition (real Wigner-D, see
//!   [`crate::sh::ShRotation`]).
//!
//! All RC rules are checked on the way and reported as [`Finding`]s; `splatgl validate` shows
//! them all, the loader stops at the first one that makes the data unusable.

mod accessor;
mod buffers;
mod container;
mod meta;
mod primitive;
mod rules;
mod spz;
mod transform;

/// Applies a node's global matrix to a local-space cloud exactly as the loader does
/// (positions, Σ = M C Cᵀ Mᵀ, SH rotated by the polar factor); findings name `nodes[node]`;
/// `None` when a value becomes non-finite or overflows (a blocking finding names the first
/// splat: what the loader would drop, or refuse in strict mode).
pub use container::SUPPORTED_REQUIRED;
pub use transform::apply_checked as apply_node_transform;

use super::{Finding, Format, LoadOptions, LoadReport, ScaleSeen, Severity, hygiene};
use crate::camera::GltfPerspective;
use crate::cloud::SplatCloud;
use container::{EXT, Parsed};
use glam::DMat4;
use serde_json::Value;
use std::cell::Cell;
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

/// Everything learnt from one pass over a document besides its findings.
#[derive(Debug)]
pub(crate) struct Walk {
    /// The merged cloud (`None` if a blocking finding stopped the pass, or no splats).
    pub cloud: Option<SplatCloud>,
    /// The scene's perspective cameras (empty if a blocking finding stopped the pass).
    pub cameras: Vec<GltfPerspective>,
    /// Number of splat primitives in the document (instantiated or not).
    pub splat_primitives: usize,
}

/// Loads a glTF or GLB document from memory (`path` resolves external buffers): the walk,
/// stopped by its first blocking finding.
pub(crate) fn read(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<(SplatCloud, Vec<GltfPerspective>), GltfError> {
    let w = walk(bytes, format, path, opts, report)?;
    if let Some(f) = report.findings.iter().find(|f| f.blocks_loading) {
        return Err(GltfError::Invalid(f.clone()));
    }
    let cloud = w.cloud.ok_or(GltfError::NoSplats)?;
    Ok((cloud, w.cameras))
}

/// Reads and checks a whole document; every finding goes to `report`, with the scale space
/// and non-unit quaternions seen. Only an unreadable container is an `Err`.
pub(crate) fn walk(
    bytes: &[u8],
    format: Format,
    path: Option<&Path>,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<Walk, GltfError> {
    let parsed = container::parse(bytes, format, path, opts, &mut report.findings)?;
    let mut w = Walk {
        cloud: None,
        cameras: Vec::new(),
        splat_primitives: count_splat_primitives(&parsed.json, true),
    };
    let Some(doc) = &parsed.doc else {
        return Ok(w);
    };
    uses_extension_check(&parsed.json, &mut report.findings);
    // Everything decoded or instantiated is charged to one budget of f32 values, bounded by the
    // input: `limits.decode_budget_values` plus `decode_values_per_byte` per input byte (file
    // and external buffers).
    let input: u64 = parsed.input_len as u64 + parsed.external_bytes;
    let budget = Cell::new(opts.limits.decode_budget(input));
    let Some(decoded) = decode_primitives(&parsed, doc, opts, &budget, &mut report.findings) else {
        return Ok(w);
    };
    let nodes = scene_nodes(doc, &parsed.json, &mut report.findings);
    w.cameras = cameras(&nodes, &parsed.json, &mut report.findings);
    w.cloud = instantiate(&nodes, &parsed.json, &decoded, &budget, input, opts, report);
    Ok(w)
}

/// Splat primitives decoded in their mesh's local space, by (mesh, primitive) index.
type Decoded = HashMap<(usize, usize), primitive::LocalSplats>;

fn array<'v>(v: &'v Value, key: &str) -> &'v [Value] {
    v.get(key)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

/// Pass 1: every splat primitive of every mesh, decoded and checked once. `None` after a
/// blocking finding.
fn decode_primitives(
    parsed: &Parsed,
    doc: &gltf::Document,
    opts: &LoadOptions,
    budget: &Cell<u64>,
    findings: &mut Vec<Finding>,
) -> Option<Decoded> {
    let json = &parsed.json;
    let used: Vec<&str> = array(json, "extensionsUsed")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    let mut decoded = Decoded::new();
    let mut blocked = false;
    for (mi, mesh) in array(json, "meshes").iter().enumerate() {
        for (pi, prim) in array(mesh, "primitives").iter().enumerate() {
            let ppath = format!("meshes[{mi}].primitives[{pi}]");
            let exts = prim.get("extensions").and_then(Value::as_object);
            let legacy_spz = exts.is_some_and(|e| e.contains_key(spz::LEGACY));
            if let Some(legacy) = exts.and_then(|e| {
                e.keys().find(|k| {
                    k.as_str() != EXT && k.as_str() != spz::LEGACY && k.contains("gaussian_splats")
                })
            }) {
                findings.push(Finding::unsupported(
                    format!("{ppath}.extensions.{legacy}"),
                    format!("legacy draft extension {legacy:?} is not supported (re-export with KHR_gaussian_splatting)"),
                ));
                blocked = true;
                continue;
            }
            let before = findings.len();
            let meta = match exts.and_then(|e| e.get(EXT)) {
                Some(Value::Object(ext)) => meta::read(ext, &ppath, &used, findings),
                Some(_) => {
                    findings.push(Finding::fatal(
                        format!("{ppath}.extensions.{EXT}"),
                        "must be an object",
                    ));
                    blocked = true;
                    continue;
                }
                // The legacy draft had no extension object: the RC's defaults.
                None if legacy_spz => crate::cloud::SplatMeta::default(),
                None => continue,
            };
            if findings[before..].iter().any(|f| f.blocks_loading) {
                blocked = true;
                continue;
            }
            let ctx = primitive::Ctx {
                doc,
                buffers: &parsed.buffers,
                path: ppath,
                scale_space: opts.scale_space,
                opts,
                spz_axes: opts.spz_axes,
                budget,
                quantization: used.contains(&"KHR_mesh_quantization"),
            };
            match primitive::read(&ctx, prim, &meta, findings) {
                Some(ls) => {
                    decoded.insert((mi, pi), ls);
                }
                None => blocked = true,
            }
        }
    }
    (!blocked).then_some(decoded)
}

/// Pass 2: the decoded primitives instantiated through the scene's node hierarchy and merged
/// into one global cloud, each instance cleaned after its transform (numeric hygiene). `None`
/// without instances, or after a blocking finding.
fn instantiate(
    nodes: &[(gltf::Node, DMat4)],
    json: &Value,
    decoded: &Decoded,
    budget: &Cell<u64>,
    input: u64,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Option<SplatCloud> {
    let mut total = 0u64;
    let meshes = array(json, "meshes");
    let mut cloud: Option<SplatCloud> = None;
    for (node, m) in nodes {
        let Some(mesh) = node.mesh().map(|m| m.index()) else {
            continue;
        };
        let node = node.index();
        let Some(mesh_json) = meshes.get(mesh) else {
            continue;
        };
        for pi in 0..array(mesh_json, "primitives").len() {
            let Some(ls) = decoded.get(&(mesh, pi)) else {
                continue;
            };
            let charge = (budget, &mut total, input);
            charge_instance(ls, charge, (node, mesh), opts, &mut report.findings)?;
            let ppath = format!("meshes[{mesh}].primitives[{pi}]");
            let global = place(ls, *m, node, &ppath, opts, report)?;
            let Some(c) = &mut cloud else {
                cloud = Some(global);
                continue;
            };
            merge(c, global, ppath, &mut report.findings);
        }
    }
    cloud
}

/// Charges an instance of `ls` (of `meshes[mesh]` under `nodes[node]`) to the document's value
/// budget (for an `input`-byte input) and its splats to the scene's `total`, checked against
/// the limits. `None` after a blocking finding.
fn charge_instance(
    ls: &primitive::LocalSplats,
    (budget, total, input): (&Cell<u64>, &mut u64, u64),
    (node, mesh): (usize, usize),
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> Option<()> {
    let per_splat = 11 + 3 * ls.cloud.coeffs_per_splat() as u64;
    let values = ls.cloud.len() as u64 * per_splat;
    if values > budget.get() {
        let l = &opts.limits;
        findings.push(Finding::fatal(
            format!("nodes[{node}]"),
            format!(
                "instancing meshes[{mesh}] here would exceed the output this {input}-byte input can justify (limits: {} + {} values per input byte)",
                l.decode_budget_values, l.decode_values_per_byte
            ),
        ));
        return None;
    }
    budget.set(budget.get() - values);
    *total += ls.cloud.len() as u64;
    if let Err(e) = opts.limits.check_splats(*total, "the scene's instances") {
        findings.push(Finding::fatal(format!("nodes[{node}]"), e.to_string()));
        return None;
    }
    Some(())
}

/// The primitive at `ppath` (decoded as `ls`) under `nodes[node]`'s global matrix `m`:
/// transformed, cleaned (numeric hygiene), and its scale space, non-unit quaternions and
/// details added to `report`. `None` after a blocking finding.
fn place(
    ls: &primitive::LocalSplats,
    m: DMat4,
    node: usize,
    ppath: &str,
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Option<SplatCloud> {
    let mut global = transform::apply(&ls.cloud, m, node, &mut report.findings);
    let site = hygiene::Site {
        path: &format!("nodes[{node}]"),
        what: &format!("{ppath} under this node's transform"),
        severity: Severity::Error,
        strict: opts.strict,
        origin: ls.origin.as_deref(),
    };
    if let Err(f) = hygiene::clean(&mut global, &site, &mut report.findings) {
        report.findings.push(f);
        return None;
    }
    report.scale_space = Some(ScaleSeen::merge(report.scale_space, ls.scale_seen));
    report.non_unit_quaternions += ls.non_unit;
    if report.details.is_none() {
        report.details.clone_from(&ls.details);
    }
    Some(global)
}

/// Appends the instance `global` (of the primitive at `ppath`) to the cloud `c`, warning when
/// its extension properties or SH degree differ.
fn merge(c: &mut SplatCloud, global: SplatCloud, ppath: String, findings: &mut Vec<Finding>) {
    if c.meta != global.meta {
        findings.push(Finding::warning(
            &ppath,
            "extension properties differ from the first splat primitive's; the first primitive's are used",
        ));
    }
    if c.append(global) {
        findings.push(Finding::warning(
            ppath,
            "primitives have different SH degrees; lower degrees are zero-padded (colours unchanged)",
        ));
    }
}

/// Primitives with `KHR_gaussian_splatting` (and, with `legacy`, those with the legacy SPZ
/// extension instead).
fn count_splat_primitives(json: &Value, legacy: bool) -> usize {
    let prims = json
        .get("meshes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(|m| m.get("primitives").and_then(Value::as_array))
        .flatten();
    prims
        .filter_map(|p| p.get("extensions"))
        .filter(|e| e.get(EXT).is_some() || (legacy && e.get(spz::LEGACY).is_some()))
        .count()
}

fn uses_extension_check(json: &Value, findings: &mut Vec<Finding>) {
    let used = json
        .get("extensionsUsed")
        .and_then(Value::as_array)
        .is_some_and(|a| a.iter().any(|v| v.as_str() == Some(EXT)));
    if count_splat_primitives(json, false) > 0 && !used {
        findings.push(Finding::error(
            "extensionsUsed",
            format!("{EXT} is used by primitives but not listed in extensionsUsed"),
        ));
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

/// The perspective camera nodes among `nodes`, with their global transforms. Orthographic
/// cameras are skipped (splat rendering with them is undefined per the RC); a camera without
/// the object its `type` names is reported and skipped.
fn cameras(
    nodes: &[(gltf::Node, DMat4)],
    json: &Value,
    findings: &mut Vec<Finding>,
) -> Vec<GltfPerspective> {
    let mut out = Vec::new();
    for (node, m) in nodes {
        let Some(cam) = node.camera() else { continue };
        // The gltf crate unwraps the object named by `type`; make sure it is there.
        let cj = &json["cameras"][cam.index()];
        let ty = cj.get("type").and_then(Value::as_str).unwrap_or("");
        if cj.get(ty).is_none_or(|o| !o.is_object()) {
            findings.push(Finding::error(
                format!("cameras[{}]", cam.index()),
                format!("type {ty:?} but no {ty:?} object; camera skipped"),
            ));
            continue;
        }
        if let gltf::camera::Projection::Perspective(p) = cam.projection() {
            let values = [p.yfov(), p.znear(), p.aspect_ratio().unwrap_or(1.0)];
            let far_ok = p.zfar().is_none_or(f32::is_finite);
            if !(values.iter().all(|v| v.is_finite()) && far_ok && m.as_mat4().is_finite()) {
                findings.push(Finding::warning(
                    format!("nodes[{}]", node.index()),
                    format!(
                        "cameras[{}] has a non-finite value or global transform; camera skipped",
                        cam.index()
                    ),
                ));
                continue;
            }
            out.push(GltfPerspective {
                yfov: p.yfov(),
                aspect_ratio: p.aspect_ratio(),
                znear: p.znear(),
                zfar: p.zfar(),
                node_to_world: m.as_mat4(),
            });
        }
    }
    out
}
