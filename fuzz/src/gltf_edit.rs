//! The structure-aware glTF target: a valid document generated from a few input bytes (SH
//! degree 0–3, component types, stride, sparse opacity, COLOR_0, a node hierarchy with TRS and
//! matrix transforms, a second instance, a camera), then edited by the rest of the input — JSON
//! values replaced, members inserted or removed, buffer floats and bytes overwritten — and
//! written as `.gltf` (data URI) or `.glb`. Byte-level mutation rarely gets past the JSON
//! parser and the schema; these edits keep the document mostly valid, so the transform, SH
//! rotation, decoding and hygiene paths are what gets fuzzed.

use arbitrary::Arbitrary;
use base64::Engine;
use serde_json::{Value, json};
use splatgl::write::{Comp, GltfWriteOptions, build};

/// The fuzz input.
#[derive(Arbitrary, Debug)]
pub struct Input {
    seed: u8,
    splats: u8,
    degree: u8,
    types: u8,
    glb: bool,
    strict: bool,
    padding: bool,
    sparse: bool,
    color0: bool,
    edits: Vec<Edit>,
}

/// One edit of the generated document.
#[derive(Arbitrary, Debug)]
pub enum Edit {
    /// Replace the `at`-th value (document order, containers included) with `value`.
    Set { at: u16, value: Val },
    /// Insert (or replace) member `KEYS[key]` of the `at`-th object.
    Put { at: u16, key: u8, value: Val },
    /// Remove the `at`-th value from its parent.
    Remove { at: u16 },
    /// Overwrite the `at`-th f32 of the binary buffer.
    Float { at: u16, value: F },
    /// Overwrite the `at`-th byte of the binary buffer.
    Byte { at: u16, value: u8 },
}

/// A JSON value to write.
#[derive(Arbitrary, Debug)]
pub enum Val {
    /// `null`.
    Null,
    /// A boolean.
    Bool(bool),
    /// A small index.
    Index(u8),
    /// An integer.
    Int(i32),
    /// A large unsigned integer.
    Big(u64),
    /// A float (non-finite ones become `null`: JSON cannot hold them).
    Float(F),
    /// `STRINGS[i]`.
    Str(u8),
    /// An array of floats (at most 16).
    Floats(Vec<F>),
}

/// A float, with the interesting ones spelled out.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum F {
    /// Any f32.
    Value(f32),
    /// `f32::MAX`.
    Max,
    /// `-f32::MAX`.
    NegMax,
    /// `10^k` (beyond f32 in JSON for k > 38).
    Pow10(i8),
    /// The smallest positive subnormal.
    Tiny,
    /// `-0.0`.
    NegZero,
    /// NaN.
    Nan,
    /// +inf.
    Inf,
    /// -inf.
    NegInf,
}

impl F {
    fn value(self) -> f64 {
        match self {
            F::Value(v) => v as f64,
            F::Max => f32::MAX as f64,
            F::NegMax => -f32::MAX as f64,
            F::Pow10(k) => 10f64.powi(k as i32),
            F::Tiny => f32::from_bits(1) as f64,
            F::NegZero => -0.0,
            F::Nan => f64::NAN,
            F::Inf => f64::INFINITY,
            F::NegInf => f64::NEG_INFINITY,
        }
    }
}

/// Member names worth inserting.
const KEYS: &[&str] = &[
    "translation",
    "rotation",
    "scale",
    "matrix",
    "children",
    "mesh",
    "camera",
    "count",
    "byteOffset",
    "byteStride",
    "byteLength",
    "componentType",
    "normalized",
    "type",
    "sparse",
    "min",
    "max",
    "mode",
    "kernel",
    "colorSpace",
    "projection",
    "sortingMethod",
    "extensions",
    "yfov",
    "znear",
    "zfar",
    "aspectRatio",
    "perspective",
    "nodes",
    "scene",
    "buffer",
    "bufferView",
    "uri",
    "indices",
    "values",
    "POSITION",
    "COLOR_0",
    "KHR_gaussian_splatting:ROTATION",
    "KHR_gaussian_splatting:SCALE",
    "KHR_gaussian_splatting:OPACITY",
    "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0",
    "KHR_gaussian_splatting:SH_DEGREE_1_COEF_0",
    "KHR_gaussian_splatting:SH_DEGREE_3_COEF_6",
    "KHR_gaussian_splatting",
    "KHR_mesh_quantization",
    "extensionsUsed",
    "extensionsRequired",
];

/// String values worth writing.
const STRINGS: &[&str] = &[
    "ellipse",
    "srgb_rec709_display",
    "lin_rec709_display",
    "perspective",
    "orthographic",
    "cameraDistance",
    "SCALAR",
    "VEC2",
    "VEC3",
    "VEC4",
    "MAT4",
    "KHR_gaussian_splatting",
    "KHR_mesh_quantization",
    "",
    "x.bin",
    "data:application/octet-stream;base64,AAAA",
];

impl Val {
    fn json(&self) -> Value {
        let float =
            |f: F| serde_json::Number::from_f64(f.value()).map_or(Value::Null, Value::Number);
        match self {
            Val::Null => Value::Null,
            Val::Bool(b) => json!(b),
            Val::Index(i) => json!(i),
            Val::Int(i) => json!(i),
            Val::Big(u) => json!(u),
            Val::Float(f) => float(*f),
            Val::Str(i) => json!(STRINGS[*i as usize % STRINGS.len()]),
            Val::Floats(v) => Value::Array(v.iter().take(16).map(|f| float(*f)).collect()),
        }
    }
}

/// The generated document before edits: (JSON, binary buffer).
fn base(input: &Input) -> (Value, Vec<u8>) {
    let n = input.splats as usize % 9;
    let cloud = splatgl::synthetic::random_cloud(n, input.degree % 4, 3.0, input.seed as u64);
    let pick =
        |options: &[Comp], shift: u8| options[(input.types >> shift) as usize % options.len()];
    let o = GltfWriteOptions {
        rotation: pick(&[Comp::F32, Comp::I8N, Comp::I16N], 0),
        scale: pick(&[Comp::F32, Comp::U8N, Comp::U16, Comp::U16N], 2),
        opacity: pick(&[Comp::F32, Comp::U8N, Comp::U16N], 4),
        position: pick(&[Comp::F32, Comp::F32, Comp::I16N, Comp::U8N], 6),
        padding: if input.padding { 4 } else { 0 },
        sparse_opacity: input.sparse,
        color0: input.color0,
        ..GltfWriteOptions::default()
    };
    let (mut doc, bin) = build(&cloud, &o);
    doc["nodes"] = json!([
        {"children": [1], "translation": [1.0, -2.0, 0.5], "rotation": [0.0, 0.0, 0.3826834, 0.9238795], "scale": [1.0, 2.0, 0.5]},
        {"matrix": [1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0], "mesh": 0, "children": [2]},
        {"camera": 0, "translation": [0.0, 0.0, 5.0]},
        {"mesh": 0, "scale": [3.0, 3.0, 3.0], "rotation": [0.5, 0.5, 0.5, 0.5]}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 3]}]);
    doc["scene"] = json!(0);
    doc["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100.0, "aspectRatio": 1.5}}]);
    (doc, bin)
}

/// JSON pointers of every value, document order; objects only when `objects`.
fn pointers(v: &Value, at: &mut String, objects: bool, out: &mut Vec<String>) {
    if !objects || v.is_object() {
        out.push(at.clone());
    }
    let len = at.len();
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                at.push('/');
                at.push_str(&k.replace('~', "~0").replace('/', "~1"));
                pointers(c, at, objects, out);
                at.truncate(len);
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                at.push_str(&format!("/{i}"));
                pointers(c, at, objects, out);
                at.truncate(len);
            }
        }
        _ => {}
    }
}

fn nth_pointer(doc: &Value, at: u16, objects: bool) -> Option<String> {
    let mut out = Vec::new();
    pointers(doc, &mut String::new(), objects, &mut out);
    (!out.is_empty()).then(|| out[at as usize % out.len()].clone())
}

fn apply(doc: &mut Value, bin: &mut [u8], e: &Edit) {
    match e {
        Edit::Set { at, value } => {
            if let Some(p) = nth_pointer(doc, *at, false)
                && let Some(slot) = doc.pointer_mut(&p)
            {
                *slot = value.json();
            }
        }
        Edit::Put { at, key, value } => {
            if let Some(p) = nth_pointer(doc, *at, true)
                && let Some(Value::Object(m)) = doc.pointer_mut(&p)
            {
                m.insert(KEYS[*key as usize % KEYS.len()].to_owned(), value.json());
            }
        }
        Edit::Remove { at } => {
            let Some(p) = nth_pointer(doc, *at, false) else {
                return;
            };
            let Some((parent, last)) = p.rsplit_once('/') else {
                return;
            };
            let key = last.replace("~1", "/").replace("~0", "~");
            match doc.pointer_mut(parent) {
                Some(Value::Object(m)) => {
                    m.remove(&key);
                }
                Some(Value::Array(a)) => {
                    if let Ok(i) = key.parse::<usize>()
                        && i < a.len()
                    {
                        a.remove(i);
                    }
                }
                _ => {}
            }
        }
        Edit::Float { at, value } => {
            let n = bin.len() / 4;
            if n > 0 {
                let o = 4 * (*at as usize % n);
                bin[o..o + 4].copy_from_slice(&(value.value() as f32).to_le_bytes());
            }
        }
        Edit::Byte { at, value } => {
            if !bin.is_empty() {
                let n = bin.len();
                bin[*at as usize % n] = *value;
            }
        }
    }
}

/// The document as file bytes: GLB (JSON + BIN chunks) or glTF JSON with a data URI.
fn serialize(mut doc: Value, bin: Vec<u8>, glb: bool) -> Vec<u8> {
    let b0 = doc.pointer_mut("/buffers/0").filter(|b| b.is_object());
    if glb {
        return splatgl::write::glb_bytes(&doc, &bin);
    }
    if let Some(b) = b0
        && b.get("uri").is_none()
    {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        b["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    }
    serde_json::to_vec(&doc).unwrap()
}

/// Generates, edits, writes and checks one document.
pub fn run(input: &Input) {
    let (mut doc, mut bin) = base(input);
    for e in input.edits.iter().take(24) {
        apply(&mut doc, &mut bin, e);
    }
    let (bytes, name) = match input.glb {
        true => (serialize(doc, bin, true), "fuzz.glb"),
        false => (serialize(doc, bin, false), "fuzz.gltf"),
    };
    crate::check_with(&bytes, name, &crate::options(input.strict));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unedited_document_loads_with_every_instance() {
        for degree in 0..4 {
            for glb in [false, true] {
                let input = Input {
                    seed: 1,
                    splats: 5,
                    degree,
                    types: 0,
                    glb,
                    strict: true,
                    padding: false,
                    sparse: false,
                    color0: false,
                    edits: Vec::new(),
                };
                let (doc, bin) = base(&input);
                let bytes = serialize(doc, bin, glb);
                let name = if glb { "t.glb" } else { "t.gltf" };
                let s = splatgl::load::load_bytes(
                    &bytes,
                    Some(std::path::Path::new(name)),
                    &crate::options(true),
                )
                .expect("the base document is valid");
                assert_eq!(s.cloud.len(), 10, "two instances of five splats");
                assert_eq!(s.cloud.sh_degree, degree);
                assert_eq!(s.cameras.len(), 1);
            }
        }
    }
}
