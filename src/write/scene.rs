//! glTF documents with several nodes (TRS or matrix, children), meshes of several splat
//! primitives, and perspective cameras: what the conformance suite's assets need. Each
//! primitive is written like [`super::to_glb`] writes its one primitive (same options, same
//! accessors), so everything the single-cloud writer guarantees holds per primitive.

use super::{Builder, Comp, GltfWriteOptions, extension_object, glb_bytes, gltf_bytes};
use crate::cloud::SplatCloud;
use serde_json::{Value, json};

/// A node's local transform.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum NodeTransform {
    /// No transform property.
    #[default]
    Identity,
    /// `matrix`, column-major.
    Matrix([f64; 16]),
    /// `translation`, `rotation` (unit quaternion xyzw), `scale`.
    Trs {
        /// Translation.
        translation: [f64; 3],
        /// Rotation quaternion `[x, y, z, w]`.
        rotation: [f64; 4],
        /// Scale.
        scale: [f64; 3],
    },
}

/// One node.
#[derive(Debug, Clone, Default)]
pub struct SceneNode {
    /// `name`.
    pub name: Option<String>,
    /// Index into [`SceneDoc::meshes`].
    pub mesh: Option<usize>,
    /// Index into [`SceneDoc::cameras`].
    pub camera: Option<usize>,
    /// Child node indices.
    pub children: Vec<usize>,
    /// Local transform.
    pub transform: NodeTransform,
}

/// A splat primitive: a cloud in the mesh's local space and how to store it
/// ([`GltfWriteOptions::node_matrix`] is ignored here: nodes carry transforms).
#[derive(Debug, Clone)]
pub struct SplatPrimitive {
    /// The splats (local space) and their `KHR_gaussian_splatting` metadata.
    pub cloud: SplatCloud,
    /// Component types, COLOR_0, padding, sparse opacity.
    pub options: GltfWriteOptions,
}

/// A glTF perspective camera (radians; `aspectRatio` = width / height).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerspectiveCamera {
    /// `yfov`.
    pub yfov: f64,
    /// `aspectRatio`.
    pub aspect_ratio: Option<f64>,
    /// `znear`.
    pub znear: f64,
    /// `zfar` (`None`: infinite projection).
    pub zfar: Option<f64>,
}

/// A document under construction: nodes, meshes, cameras and the scene's root nodes.
#[derive(Debug, Clone, Default)]
pub struct SceneDoc {
    /// All nodes.
    pub nodes: Vec<SceneNode>,
    /// Meshes, each a list of splat primitives.
    pub meshes: Vec<Vec<SplatPrimitive>>,
    /// Cameras.
    pub cameras: Vec<PerspectiveCamera>,
    /// Root nodes of scene 0.
    pub roots: Vec<usize>,
}

impl SceneDoc {
    /// Adds a node; returns its index.
    pub fn add_node(&mut self, node: SceneNode) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// Adds a mesh; returns its index.
    pub fn add_mesh(&mut self, primitives: Vec<SplatPrimitive>) -> usize {
        self.meshes.push(primitives);
        self.meshes.len() - 1
    }

    /// Adds a camera; returns its index.
    pub fn add_camera(&mut self, camera: PerspectiveCamera) -> usize {
        self.cameras.push(camera);
        self.cameras.len() - 1
    }

    /// The glTF JSON and the binary buffer (buffer 0's `uri` unset).
    pub fn build(&self) -> (Value, Vec<u8>) {
        let mut b = Builder::new(0);
        let mut quantized = false;
        let meshes: Vec<Value> = self
            .meshes
            .iter()
            .map(|prims| {
                let prims: Vec<Value> = prims
                    .iter()
                    .map(|p| {
                        b.padding = p.options.padding;
                        quantized |= p.options.position != Comp::F32;
                        json!({
                            "attributes": b.splat_attributes(&p.cloud, &p.options),
                            "mode": 0,
                            "extensions": {
                                "KHR_gaussian_splatting": extension_object(&p.cloud.meta)
                            },
                        })
                    })
                    .collect();
                json!({ "primitives": prims })
            })
            .collect();
        let nodes: Vec<Value> = self.nodes.iter().map(node_json).collect();
        let mut used = vec!["KHR_gaussian_splatting"];
        if quantized {
            used.push("KHR_mesh_quantization");
        }
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "splatgl"},
            "extensionsUsed": used,
            "scene": 0,
            "scenes": [{"nodes": self.roots}],
            "nodes": nodes,
            "meshes": meshes,
            "buffers": [{"byteLength": b.bin.len()}],
            "bufferViews": b.views,
            "accessors": b.accessors,
        });
        if quantized {
            doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
        }
        if !self.cameras.is_empty() {
            doc["cameras"] = self.cameras.iter().map(camera_json).collect();
        }
        (doc, b.bin)
    }

    /// A `.glb` file.
    pub fn to_glb(&self) -> Vec<u8> {
        let (doc, bin) = self.build();
        glb_bytes(&doc, &bin)
    }

    /// A `.gltf` file with the buffer as a data URI.
    pub fn to_gltf(&self) -> Vec<u8> {
        let (doc, bin) = self.build();
        gltf_bytes(doc, &bin)
    }
}

fn node_json(n: &SceneNode) -> Value {
    let mut v = json!({});
    if let Some(name) = &n.name {
        v["name"] = json!(name);
    }
    if let Some(m) = n.mesh {
        v["mesh"] = json!(m);
    }
    if let Some(c) = n.camera {
        v["camera"] = json!(c);
    }
    if !n.children.is_empty() {
        v["children"] = json!(n.children);
    }
    match n.transform {
        NodeTransform::Identity => {}
        NodeTransform::Matrix(m) => v["matrix"] = json!(m),
        NodeTransform::Trs {
            translation,
            rotation,
            scale,
        } => {
            if translation != [0.0; 3] {
                v["translation"] = json!(translation);
            }
            if rotation != [0.0, 0.0, 0.0, 1.0] {
                v["rotation"] = json!(rotation);
            }
            if scale != [1.0; 3] {
                v["scale"] = json!(scale);
            }
        }
    }
    v
}

fn camera_json(c: &PerspectiveCamera) -> Value {
    let mut p = json!({"yfov": c.yfov, "znear": c.znear});
    if let Some(a) = c.aspect_ratio {
        p["aspectRatio"] = json!(a);
    }
    if let Some(f) = c.zfar {
        p["zfar"] = json!(f);
    }
    json!({"type": "perspective", "perspective": p})
}

/// A perspective camera on a root node of its own: what `splatgl convert --camera` embeds
/// for each training view.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraNode {
    /// The node's and the camera's `name` (the view's `img_name`).
    pub name: String,
    /// The camera.
    pub camera: PerspectiveCamera,
    /// The node's `translation`: the eye.
    pub translation: [f64; 3],
    /// The node's `rotation` (unit quaternion `[x, y, z, w]`): the camera's axes, glTF
    /// convention (+X right, +Y up, looking along −Z).
    pub rotation: [f64; 4],
}

/// Appends `cameras` to a document made by [`super::build`] (or any document with a scene 0):
/// one camera each, on a new root node of scene 0.
pub fn add_camera_nodes(doc: &mut Value, cameras: &[CameraNode]) {
    if cameras.is_empty() {
        return;
    }
    if doc["scenes"].as_array().is_none_or(|s| s.is_empty()) {
        doc["scenes"] = json!([{ "nodes": [] }]);
        doc["scene"] = json!(0);
    }
    let (first_node, first_camera) = (
        doc["nodes"].as_array().map_or(0, Vec::len),
        doc["cameras"].as_array().map_or(0, Vec::len),
    );
    for (i, c) in cameras.iter().enumerate() {
        let node = SceneNode {
            name: Some(c.name.clone()),
            camera: Some(first_camera + i),
            transform: NodeTransform::Trs {
                translation: c.translation,
                rotation: c.rotation,
                scale: [1.0; 3],
            },
            ..Default::default()
        };
        let mut camera = camera_json(&c.camera);
        camera["name"] = json!(c.name);
        push(doc, "nodes", node_json(&node));
        push(doc, "cameras", camera);
        push(&mut doc["scenes"][0], "nodes", json!(first_node + i));
    }
}

/// Appends `v` to the array `doc[key]` (made if absent).
fn push(doc: &mut Value, key: &str, v: Value) {
    if !doc[key].is_array() {
        doc[key] = json!([]);
    }
    if let Some(a) = doc[key].as_array_mut() {
        a.push(v);
    }
}
