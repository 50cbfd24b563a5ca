//! Writers: a [`SplatCloud`] as INRIA PLY ([`to_inria_ply`]), Niantic SPZ ([`to_spz`]),
//! antimatter15 `.splat` ([`to_splat`]), or as glTF 2.0 with `KHR_gaussian_splatting` (RC), as
//! `.glb` ([`to_glb`]), `.gltf` with an embedded data-URI buffer ([`to_gltf`]), or `.glb` with
//! the splats SPZ-compressed by `KHR_gaussian_splatting_compression_spz_2` ([`to_glb_spz`]).
//! The output passes `splatgl validate`.
//!
//! The glTF writer stores every component type the RC allows per attribute ([`Comp`], the
//! converter's `--quantize`; [`quantize`] maps positions and scales into an integer type's
//! range with a dequantization node matrix). It can also pad elements (byteStride) and write
//! OPACITY as a sparse accessor, so the tests can round-trip every decoding path of the loader;
//! those two options are hidden from these docs. [`scene`] writes documents with several
//! nodes, meshes, primitives and cameras (the conformance suite's assets).
//!
//! Every file splatgl writes goes through [`write_atomic`]: a temporary file in the same
//! folder, renamed into place when complete, so a failed write never loses the previous file.

mod atomic;
mod comp;
mod ply;
pub mod quantize;
pub mod scene;
pub use atomic::{refuse_overwriting_inputs, write_atomic, write_bytes_atomic};
pub use comp::Comp;
pub use ply::{to_inria_ply, to_inria_ply_with_normals};
mod glb_spz;
mod sog;
mod splat;
mod spz;
pub(crate) use glb_spz::build_glb_spz;
pub use glb_spz::{to_glb_spz, to_glb_spz_with};
pub use sog::{SogFiles, SogWriteError, to_sog_bundle, to_sog_files};
pub use splat::to_splat;
pub use spz::{SpzVersion, SpzWriteError, SpzWriteOptions, to_spz, to_spz_with};

use crate::cloud::{ColorSpace, Kernel, Projection, SortingMethod, SplatCloud};
use base64::Engine;
use serde_json::{Value, json};

/// Component types the RC allows for `KHR_gaussian_splatting:ROTATION`.
pub const ROTATION_TYPES: [Comp; 3] = [Comp::F32, Comp::I8N, Comp::I16N];
/// Component types the RC allows for `KHR_gaussian_splatting:SCALE`.
pub const SCALE_TYPES: [Comp; 5] = [Comp::F32, Comp::U8, Comp::U8N, Comp::U16, Comp::U16N];
/// Component types the RC allows for `KHR_gaussian_splatting:OPACITY`.
pub const OPACITY_TYPES: [Comp; 3] = [Comp::F32, Comp::U8N, Comp::U16N];
/// POSITION types: float, and with `KHR_mesh_quantization` the 8/16-bit integer types.
pub const POSITION_TYPES: [Comp; 9] = Comp::ALL;

/// Writer options. The default writes float accessors under one node without a matrix.
#[derive(Debug, Clone)]
pub struct GltfWriteOptions {
    /// POSITION component type (non-float types need `KHR_mesh_quantization`, added
    /// automatically). No dequantization node matrix is added here: the positions must
    /// already lie in the type's [`Comp::range`] ([`quantize::dequantize_node`] maps them).
    pub position: Comp,
    /// ROTATION: one of [`ROTATION_TYPES`].
    pub rotation: Comp,
    /// SCALE: one of [`SCALE_TYPES`] (values in the type's [`Comp::range`]).
    pub scale: Comp,
    /// OPACITY: one of [`OPACITY_TYPES`].
    pub opacity: Comp,
    /// Extra bytes after each element (gives every view an explicit `byteStride`; the
    /// conformance suite's stride asset).
    pub padding: usize,
    /// Write OPACITY as a sparse accessor without a bufferView (zeros + overrides; the
    /// conformance suite's sparse asset).
    pub sparse_opacity: bool,
    /// Write SCALE as the review draft did, `ln(scale)` (float): a legacy file, for the
    /// conformance suite's legacy asset. Not RC-valid.
    pub legacy_log_scale: bool,
    /// Column-major 4×4 matrix of the node holding the mesh (`None`: no matrix).
    pub node_matrix: Option<[f64; 16]>,
    /// Also write a COLOR_0 attribute (the RC's fallback colour).
    pub color0: bool,
}

impl Default for GltfWriteOptions {
    fn default() -> Self {
        GltfWriteOptions {
            position: Comp::F32,
            rotation: Comp::F32,
            scale: Comp::F32,
            opacity: Comp::F32,
            padding: 0,
            sparse_opacity: false,
            legacy_log_scale: false,
            node_matrix: None,
            color0: false,
        }
    }
}

pub(crate) struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    pub(crate) padding: usize,
}

impl Builder {
    fn align(&mut self) {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
    }
    /// Adds an accessor over `n` elements of `dims` components from `get(i, k)`.
    fn add(
        &mut self,
        n: usize,
        dims: usize,
        comp: Comp,
        get: impl Fn(usize, usize) -> f32,
    ) -> usize {
        self.align();
        let esize = dims * comp.size();
        // Vertex attribute elements start on 4-byte boundaries (glTF 2.0): pad small elements.
        let stride = if self.padding > 0 || !esize.is_multiple_of(4) {
            (esize + self.padding).div_ceil(4) * 4
        } else {
            0
        };
        let start = self.bin.len();
        for i in 0..n {
            let e0 = self.bin.len();
            for k in 0..dims {
                comp.encode(get(i, k), &mut self.bin);
            }
            if stride > 0 {
                self.bin.resize(e0 + stride, 0xAB);
            }
        }
        // target ARRAY_BUFFER: vertex attribute data (glTF-Validator hints without it).
        let mut view = json!({"buffer": 0, "byteOffset": start,
            "byteLength": self.bin.len() - start, "target": 34962});
        if stride > 0 {
            view["byteStride"] = json!(stride);
        }
        self.views.push(view);
        self.push_accessor(n, dims, comp, Some(self.views.len() - 1))
    }
    fn push_accessor(&mut self, n: usize, dims: usize, comp: Comp, view: Option<usize>) -> usize {
        let ty = ["SCALAR", "VEC2", "VEC3", "VEC4"][dims - 1];
        let mut acc = json!({"componentType": comp.gl(), "count": n, "type": ty});
        if let Some(v) = view {
            acc["bufferView"] = json!(v);
        }
        if comp.normalized() {
            acc["normalized"] = json!(true);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }
    fn raw_view(&mut self, bytes: &[u8]) -> usize {
        self.align();
        let start = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": bytes.len()}));
        self.views.len() - 1
    }
}

impl Builder {
    pub(crate) fn new(padding: usize) -> Self {
        Builder {
            bin: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
            padding,
        }
    }

    /// Writes the accessors of one splat primitive holding `cloud` (local space) and returns
    /// its `attributes` object.
    pub(crate) fn splat_attributes(
        &mut self,
        cloud: &SplatCloud,
        o: &GltfWriteOptions,
    ) -> serde_json::Map<String, Value> {
        let b = self;
        let n = cloud.len();
        let mut attrs = serde_json::Map::new();
        let pos = b.add(n, 3, o.position, |i, k| cloud.positions[i][k]);
        if n > 0 {
            // min/max hold the stored values (quantized integers for integer types).
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in &cloud.positions {
                for k in 0..3 {
                    let v = o.position.stored(p[k]);
                    lo[k] = lo[k].min(v);
                    hi[k] = hi[k].max(v);
                }
            }
            b.accessors[pos]["min"] = json!(lo);
            b.accessors[pos]["max"] = json!(hi);
        }
        attrs.insert("POSITION".into(), json!(pos));
        let p = "KHR_gaussian_splatting:";
        let rot = b.add(n, 4, o.rotation, |i, k| cloud.rotations[i][k]);
        attrs.insert(format!("{p}ROTATION"), json!(rot));
        let sc = if o.legacy_log_scale {
            b.add(n, 3, Comp::F32, |i, k| cloud.scales[i][k].ln())
        } else {
            b.add(n, 3, o.scale, |i, k| cloud.scales[i][k])
        };
        attrs.insert(format!("{p}SCALE"), json!(sc));
        let op = b.opacity(cloud, o);
        attrs.insert(format!("{p}OPACITY"), json!(op));
        let k = cloud.coeffs_per_splat();
        for l in 0..=cloud.sh_degree as usize {
            for c in 0..2 * l + 1 {
                let j = l * l + c;
                let a = b.add(n, 3, Comp::F32, |i, ch| cloud.sh[i * k + j][ch]);
                attrs.insert(format!("{p}SH_DEGREE_{l}_COEF_{c}"), json!(a));
            }
        }
        if o.color0 {
            let srgb = cloud.meta.color_space.effective() == ColorSpace::SrgbRec709Display;
            let a = b.add(n, 4, Comp::F32, |i, ch| {
                if ch == 3 {
                    return cloud.opacities[i];
                }
                let v = crate::sh::color_from_dc(cloud.sh[i * k][ch]).clamp(0.0, 1.0);
                (if srgb {
                    crate::profile::srgb_decode(v)
                } else {
                    v
                }) as f32
            });
            attrs.insert("COLOR_0".into(), json!(a));
        }
        b.align();
        attrs
    }

    fn opacity(&mut self, cloud: &SplatCloud, o: &GltfWriteOptions) -> usize {
        let n = cloud.len();
        if !o.sparse_opacity {
            return self.add(n, 1, o.opacity, |i, _| cloud.opacities[i]);
        }
        let idx: Vec<u32> = (0..n as u32)
            .filter(|&i| cloud.opacities[i as usize] != 0.0)
            .collect();
        if idx.is_empty() {
            // All zero: an accessor without bufferView is zero-filled (sparse.count must be ≥ 1).
            return self.push_accessor(n, 1, o.opacity, None);
        }
        let mut vals = Vec::new();
        for &i in &idx {
            o.opacity.encode(cloud.opacities[i as usize], &mut vals);
        }
        let iv = self.raw_view(bytemuck::cast_slice(&idx));
        let vv = self.raw_view(&vals);
        let a = self.push_accessor(n, 1, o.opacity, None);
        self.accessors[a]["sparse"] = json!({
            "count": idx.len(),
            "indices": {"bufferView": iv, "componentType": 5125},
            "values": {"bufferView": vv},
        });
        a
    }
}

/// The `KHR_gaussian_splatting` object of a primitive with metadata `m`.
pub(crate) fn extension_object(m: &crate::cloud::SplatMeta) -> Value {
    json!({
        "kernel": m.kernel.to_string_with(Kernel::as_str),
        "colorSpace": m.color_space.to_string_with(ColorSpace::as_str),
        "projection": m.projection.to_string_with(Projection::as_str),
        "sortingMethod": m.sorting_method.to_string_with(SortingMethod::as_str),
    })
}

/// Builds the glTF JSON and the binary buffer (the buffer's `uri` is left unset), for callers
/// that edit the document before writing it (then [`glb_bytes`]).
pub fn build(cloud: &SplatCloud, o: &GltfWriteOptions) -> (Value, Vec<u8>) {
    let mut b = Builder::new(o.padding);
    let attrs = b.splat_attributes(cloud, o);
    let mut used = vec!["KHR_gaussian_splatting"];
    if o.position != Comp::F32 {
        used.push("KHR_mesh_quantization");
    }
    let mut node = json!({"mesh": 0});
    if let Some(mat) = o.node_matrix {
        node["matrix"] = json!(mat);
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "splatgl"},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [node],
        "meshes": [{"primitives": [{
            "attributes": attrs,
            "mode": 0,
            "extensions": {"KHR_gaussian_splatting": extension_object(&cloud.meta)},
        }]}],
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    if o.position != Comp::F32 {
        doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    }
    (doc, b.bin)
}

/// A `.gltf` file (JSON) with the buffer embedded as a base64 data URI.
pub fn to_gltf(cloud: &SplatCloud, o: &GltfWriteOptions) -> Vec<u8> {
    let (doc, bin) = build(cloud, o);
    gltf_bytes(doc, &bin)
}

/// A `.glb` file.
pub fn to_glb(cloud: &SplatCloud, o: &GltfWriteOptions) -> Vec<u8> {
    let (doc, bin) = build(cloud, o);
    glb_bytes(&doc, &bin)
}

/// `.gltf` bytes of a document whose buffer 0 is `bin` (embedded as a data URI).
pub(crate) fn gltf_bytes(mut doc: Value, bin: &[u8]) -> Vec<u8> {
    let b64 = base64::engine::general_purpose::STANDARD.encode(bin);
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    serde_json::to_vec_pretty(&doc).unwrap_or_default()
}

/// `.glb` bytes of a document whose buffer 0 is `bin` (the JSON chunk space-padded and the
/// BIN chunk zero-padded to 4 bytes): a document from [`build`], edited or not.
pub fn glb_bytes(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap_or_default();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// Saves `cloud` by the extension of `path`: `.ply` (INRIA binary), `.glb`, or `.gltf` (one
/// embedded data-URI buffer), with default [`GltfWriteOptions`]. The file is written atomically
/// ([`write_atomic`]); `inputs` are files it must not replace.
pub fn save(
    cloud: &SplatCloud,
    path: &std::path::Path,
    inputs: &[&std::path::Path],
) -> std::io::Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match ext.as_deref() {
        Some("ply") => to_inria_ply(cloud),
        Some("glb") => to_glb(cloud, &GltfWriteOptions::default()),
        Some("gltf") => to_gltf(cloud, &GltfWriteOptions::default()),
        _ => {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{}: expected a .ply, .glb or .gltf file name",
                    path.display()
                ),
            ));
        }
    };
    write_bytes_atomic(path, inputs, &bytes)
}
