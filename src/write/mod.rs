//! Writers: a [`SplatCloud`] as INRIA PLY ([`to_inria_ply`]), Niantic SPZ ([`to_spz`]),
//! antimatter15 `.splat` ([`to_splat`]), or as glTF 2.0 with `KHR_gaussian_splatting` (RC), as
//! `.glb` ([`to_glb`]), `.gltf` with an embedded data-URI buffer ([`to_gltf`]), or `.glb` with
//! the splats SPZ-compressed by `KHR_gaussian_splatting_compression_spz_2` ([`to_glb_spz`]).
//! The output passes `splatgl validate`.
//!
//! The glTF writer can also store every component type the RC allows per attribute, pad
//! elements (byteStride) and write OPACITY as a sparse accessor, so the tests can round-trip
//! every decoding path of the loader; those options are hidden from these docs.

mod ply;
pub use ply::to_inria_ply;
mod glb_spz;
mod splat;
mod spz;
pub use glb_spz::{to_glb_spz, to_glb_spz_with};
pub use splat::to_splat;
pub use spz::{SpzVersion, SpzWriteError, SpzWriteOptions, to_spz, to_spz_with};

use crate::cloud::{ColorSpace, Kernel, Projection, SortingMethod, SplatCloud};
use base64::Engine;
use serde_json::{Value, json};

/// A stored component type (with normalization). For the loader's tests.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comp {
    /// float
    F32,
    /// signed byte
    I8,
    /// signed byte normalized
    I8N,
    /// unsigned byte
    U8,
    /// unsigned byte normalized
    U8N,
    /// signed short
    I16,
    /// signed short normalized
    I16N,
    /// unsigned short
    U16,
    /// unsigned short normalized
    U16N,
}

impl Comp {
    fn gl(self) -> u32 {
        match self {
            Comp::I8 | Comp::I8N => 5120,
            Comp::U8 | Comp::U8N => 5121,
            Comp::I16 | Comp::I16N => 5122,
            Comp::U16 | Comp::U16N => 5123,
            Comp::F32 => 5126,
        }
    }
    fn size(self) -> usize {
        match self {
            Comp::I8 | Comp::I8N | Comp::U8 | Comp::U8N => 1,
            Comp::I16 | Comp::I16N | Comp::U16 | Comp::U16N => 2,
            Comp::F32 => 4,
        }
    }
    fn normalized(self) -> bool {
        matches!(self, Comp::I8N | Comp::U8N | Comp::I16N | Comp::U16N)
    }
    /// The value as stored: the float, or the quantized integer (what glTF `min`/`max` hold).
    fn stored(self, v: f32) -> f64 {
        let q = |scale: f32, lo: f32, hi: f32| (v * scale).round().clamp(lo, hi) as f64;
        match self {
            Comp::F32 => v as f64,
            Comp::I8 => q(1.0, -128.0, 127.0),
            Comp::I8N => q(127.0, -127.0, 127.0),
            Comp::U8 => q(1.0, 0.0, 255.0),
            Comp::U8N => q(255.0, 0.0, 255.0),
            Comp::I16 => q(1.0, -32768.0, 32767.0),
            Comp::I16N => q(32767.0, -32767.0, 32767.0),
            Comp::U16 => q(1.0, 0.0, 65535.0),
            Comp::U16N => q(65535.0, 0.0, 65535.0),
        }
    }
    /// Encodes `v` (quantizing and clamping integer types).
    fn encode(self, v: f32, out: &mut Vec<u8>) {
        let q = |scale: f32, lo: f32, hi: f32| (v * scale).round().clamp(lo, hi);
        match self {
            Comp::F32 => out.extend_from_slice(&v.to_le_bytes()),
            Comp::I8 => out.push(q(1.0, -128.0, 127.0) as i8 as u8),
            Comp::I8N => out.push(q(127.0, -127.0, 127.0) as i8 as u8),
            Comp::U8 => out.push(q(1.0, 0.0, 255.0) as u8),
            Comp::U8N => out.push(q(255.0, 0.0, 255.0) as u8),
            Comp::I16 => out.extend_from_slice(&(q(1.0, -32768.0, 32767.0) as i16).to_le_bytes()),
            Comp::I16N => {
                out.extend_from_slice(&(q(32767.0, -32767.0, 32767.0) as i16).to_le_bytes())
            }
            Comp::U16 => out.extend_from_slice(&(q(1.0, 0.0, 65535.0) as u16).to_le_bytes()),
            Comp::U16N => out.extend_from_slice(&(q(65535.0, 0.0, 65535.0) as u16).to_le_bytes()),
        }
    }
}

/// Writer options. The default writes float accessors under one node without a matrix.
#[derive(Debug, Clone)]
pub struct GltfWriteOptions {
    /// POSITION component type (non-float types need `KHR_mesh_quantization`, added
    /// automatically). No dequantization node matrix is written: with normalized types the
    /// positions must already lie in [−1, 1] (signed) or [0, 1] (unsigned).
    #[doc(hidden)]
    pub position: Comp,
    /// ROTATION: F32, I8N or I16N per the RC.
    #[doc(hidden)]
    pub rotation: Comp,
    /// SCALE: F32, U8, U8N, U16 or U16N per the RC.
    #[doc(hidden)]
    pub scale: Comp,
    /// OPACITY: F32, U8N or U16N per the RC.
    #[doc(hidden)]
    pub opacity: Comp,
    /// Extra bytes after each element (gives every view an explicit `byteStride`).
    #[doc(hidden)]
    pub padding: usize,
    /// Write OPACITY as a sparse accessor without a bufferView (zeros + overrides).
    #[doc(hidden)]
    pub sparse_opacity: bool,
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
            node_matrix: None,
            color0: false,
        }
    }
}

struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    padding: usize,
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
        let mut view =
            json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start});
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

/// Builds the glTF JSON and the binary buffer (the buffer's `uri` is left unset), for tests
/// that edit the document before writing it.
#[doc(hidden)]
pub fn build(cloud: &SplatCloud, o: &GltfWriteOptions) -> (Value, Vec<u8>) {
    let n = cloud.len();
    let mut b = Builder {
        bin: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
        padding: o.padding,
    };
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
    let sc = b.add(n, 3, o.scale, |i, k| cloud.scales[i][k]);
    attrs.insert(format!("{p}SCALE"), json!(sc));
    let nonzero: Vec<u32> = (0..n as u32)
        .filter(|&i| cloud.opacities[i as usize] != 0.0)
        .collect();
    let op = if o.sparse_opacity && nonzero.is_empty() {
        // All zero: an accessor without bufferView is zero-filled (sparse.count must be ≥ 1).
        b.push_accessor(n, 1, o.opacity, None)
    } else if o.sparse_opacity {
        let idx = nonzero;
        let mut vals = Vec::new();
        for &i in &idx {
            o.opacity.encode(cloud.opacities[i as usize], &mut vals);
        }
        let iv = b.raw_view(bytemuck::cast_slice(&idx));
        let vv = b.raw_view(&vals);
        let a = b.push_accessor(n, 1, o.opacity, None);
        b.accessors[a]["sparse"] = json!({
            "count": idx.len(),
            "indices": {"bufferView": iv, "componentType": 5125},
            "values": {"bufferView": vv},
        });
        a
    } else {
        b.add(n, 1, o.opacity, |i, _| cloud.opacities[i])
    };
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
    let m = &cloud.meta;
    let mut used = vec!["KHR_gaussian_splatting"];
    if o.position != Comp::F32 {
        used.push("KHR_mesh_quantization");
    }
    let mut node = json!({"mesh": 0});
    if let Some(mat) = o.node_matrix {
        node["matrix"] = json!(mat);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "splatgl"},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [node],
        "meshes": [{"primitives": [{
            "attributes": attrs,
            "mode": 0,
            "extensions": {"KHR_gaussian_splatting": extension_object(m)},
        }]}],
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    let mut doc = doc;
    if o.position != Comp::F32 {
        doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    }
    (doc, b.bin)
}

/// A `.gltf` file (JSON) with the buffer embedded as a base64 data URI.
pub fn to_gltf(cloud: &SplatCloud, o: &GltfWriteOptions) -> Vec<u8> {
    let (mut doc, bin) = build(cloud, o);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    serde_json::to_vec_pretty(&doc).unwrap_or_default()
}

/// The primitive's `KHR_gaussian_splatting` object for `meta`.
fn extension_object(m: &crate::cloud::SplatMeta) -> Value {
    json!({
        "kernel": m.kernel.to_string_with(Kernel::as_str),
        "colorSpace": m.color_space.to_string_with(ColorSpace::as_str),
        "projection": m.projection.to_string_with(Projection::as_str),
        "sortingMethod": m.sorting_method.to_string_with(SortingMethod::as_str),
    })
}

/// A `.glb` file.
pub fn to_glb(cloud: &SplatCloud, o: &GltfWriteOptions) -> Vec<u8> {
    let (doc, bin) = build(cloud, o);
    glb(&doc, &bin)
}

/// GLB framing: header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(&doc).unwrap_or_default();
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
