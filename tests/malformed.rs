//! A corpus of malformed inputs, each returning its specific error (never a panic, never a
//! huge allocation): lying headers, truncation, wrong types, partial SH, out-of-range values,
//! NaN, bad JSON, missing buffers, bad indices.

mod common;
use base64::Engine;
use common::random_cloud;
use serde_json::{Value, json};
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{LoadOptions, ScaleSpace, load_bytes};
use splatgl::write::{GltfWriteOptions, build, to_glb};
use std::path::Path;

/// The load error in strict mode (without it, splats with unusable values are dropped: see
/// `tests/hygiene.rs`).
fn err_of(bytes: &[u8], name: &str) -> String {
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    match load_bytes(bytes, Some(Path::new(name)), &strict) {
        Ok(_) => panic!("{name}: expected an error"),
        Err(e) => e.to_string(),
    }
}

fn expect(bytes: &[u8], name: &str, needles: &[&str]) {
    let e = err_of(bytes, name);
    for n in needles {
        assert!(e.contains(n), "error for {name} lacks {n:?}: {e}");
    }
}

// ---------- PLY ----------

fn ply_header(body: &str) -> Vec<u8> {
    format!("ply\nformat binary_little_endian 1.0\n{body}end_header\n").into_bytes()
}

fn good_ply() -> Vec<u8> {
    splatgl::write::to_inria_ply(&random_cloud(1, 4, 1))
}

/// Overwrites float property `prop` (column index in the INRIA layout of degree 1) of row `row`.
fn poke_ply(mut bytes: Vec<u8>, row: usize, col: usize, v: f32) -> Vec<u8> {
    let body = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let stride = (14 + 9) * 4;
    let off = body + row * stride + col * 4;
    bytes[off..off + 4].copy_from_slice(&v.to_le_bytes());
    bytes
}

#[test]
fn ply_corpus() {
    let mut cases: Vec<(Vec<u8>, &[&str])> = vec![
        (b"".to_vec(), &["header line 1"]),
        (b"plx\nformat ascii 1.0\nend_header\n".to_vec(), &["expected 'ply'"]),
        (b"ply\nformat ascii 1.0\n".to_vec(), &["no 'end_header'"]),
        (b"ply\nformat binary_middle_endian 1.0\nend_header\n".to_vec(), &["binary_middle_endian"]),
        (ply_header("element vertex many\n"), &["not a number"]),
        (ply_header("property float x\n"), &["property before any element"]),
        (ply_header("element vertex 1\nproperty float128 x\n"), &["unknown type"]),
        (ply_header("element face 0\nproperty list uchar int vertex_indices\n"), &["no 'vertex' element"]),
        (
            {
                let mut h = String::new();
                h += "element vertex 1099511627776\n";
                for p in ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"] {
                    h += &format!("property float {p}\n");
                }
                let mut b = ply_header(&h);
                b.extend(std::iter::repeat_n(0u8, 1000));
                b
            },
            &["1099511627776 splats exceed limits.max_splats"],
        ),
        (
            {
                let mut h = String::new();
                h += "element vertex 1000000\n";
                for p in ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"] {
                    h += &format!("property float {p}\n");
                }
                let mut b = ply_header(&h);
                b.extend(std::iter::repeat_n(0u8, 1000));
                b
            },
            &["1000000 rows", "only 1000 bytes"],
        ),
        ({ let mut b = good_ply(); b.truncate(b.len() - 10); b }, &["header claims 4 rows"]),
        (
            ply_header("element vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\n"),
            &["missing property 'opacity'"],
        ),
        (
            {
                let mut h = String::from("element vertex 0\n");
                for i in 0..10 { h += &format!("property float f_rest_{i}\n"); }
                ply_header(&h)
            },
            &["10 f_rest_*"],
        ),
        (poke_ply(good_ply(), 2, 1, f32::NAN), &["index 2", "'y'", "not finite"]),
        (poke_ply(good_ply(), 1, 15, f32::NAN), &["index 1", "opacity logit is NaN"]),
        (poke_ply(good_ply(), 1, 8, f32::NAN), &["index 1", "'f_rest_2'", "SH coefficient is not finite"]),
        (
            {
                let mut b = good_ply();
                for c in 19..23 { b = poke_ply(b, 3, c, 0.0); }
                b
            },
            &["index 3", "quaternion is zero"],
        ),
        (poke_ply(good_ply(), 0, 16, 1000.0), &["index 0", "overflows"]),
        (
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\nproperty float opacity\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 zero 0 0 0 0 0 0 0 1 0 0 0\n".to_vec(),
            &["line 19", "\"zero\"", "'z'"],
        ),
        (
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\nproperty float opacity\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 0 0 0 0 1 0 0 0\n0 0 0 0 0 0 0 0 0 0 1 0                \n".to_vec(),
            &["expected 14 values, found 12"],
        ),
        (
            ply_header("element vertex 1\nproperty float x\nproperty list uchar float y\n"),
            &["list property 'y'"],
        ),
    ];
    // Compressed PLY: too few chunks for the splats, and a missing chunk property.
    let mut packed = String::from("element chunk 0\nproperty float min_x\nelement vertex 1\n");
    for p in [
        "packed_position",
        "packed_rotation",
        "packed_scale",
        "packed_color",
    ] {
        packed += &format!("property uint {p}\n");
    }
    let mut too_few = ply_header(&packed);
    too_few.extend_from_slice(&[0u8; 16]);
    cases.push((too_few, &["0 chunks cannot hold 1 splats"]));
    let mut missing = ply_header(&packed.replace("chunk 0", "chunk 1"));
    missing.extend_from_slice(&[0u8; 20]);
    cases.push((missing, &["chunk.min_y"]));
    assert!(cases.len() >= 17);
    for (i, (bytes, needles)) in cases.iter().enumerate() {
        let e = err_of(bytes, "bad.ply");
        for n in *needles {
            assert!(e.contains(n), "PLY case {i}: {e:?} lacks {n:?}");
        }
    }
}

// ---------- glTF ----------

/// A valid document (data-URI buffer) with `edit` applied to the JSON and the binary.
fn gltf_with(edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> Vec<u8> {
    let (mut doc, mut bin) = build(&random_cloud(2, 8, 1), &GltfWriteOptions::default());
    edit(&mut doc, &mut bin);
    if doc["buffers"][0].get("uri").is_none() {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    }
    serde_json::to_vec(&doc).unwrap()
}

fn attr(doc: &Value, name: &str) -> usize {
    doc["meshes"][0]["primitives"][0]["attributes"][name]
        .as_u64()
        .unwrap() as usize
}

const P: &str = "KHR_gaussian_splatting:";

/// Byte offset of element `i` of the accessor behind attribute `name` (tight packing).
fn elem_offset(doc: &Value, name: &str, i: usize, esize: usize) -> usize {
    let a = attr(doc, name);
    let v = doc["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
    doc["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize + i * esize
}

#[test]
fn gltf_corpus() {
    let sc = format!("{P}SCALE");
    let op = format!("{P}OPACITY");
    let rot = format!("{P}ROTATION");
    let cases: Vec<(Vec<u8>, Vec<&str>)> = vec![
        (b"{\"asset\": {\"version\": ".to_vec(), vec!["JSON"]),
        (b"[1, 2, 3]".to_vec(), vec!["not an object"]),
        (
            gltf_with(|d, _| d["accessors"][0]["count"] = json!(2147483648u64)),
            vec!["accessors[0]", "count 2147483648"],
        ),
        (
            gltf_with(|d, _| d["meshes"][0]["primitives"][0]["attributes"][&sc] = json!(999)),
            vec!["index out of bounds"],
        ),
        (
            gltf_with(|d, _| {
                d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(999)
            }),
            vec!["POSITION", "out of range"],
        ),
        (
            gltf_with(|d, _| d["buffers"][0]["uri"] = json!("missing.bin")),
            vec!["buffers[0]", "missing.bin"],
        ),
        (
            gltf_with(|d, b| {
                d["buffers"][0]["byteLength"] = json!(b.len() + 100);
            }),
            vec!["buffers[0]", "bytes are present"],
        ),
        (
            gltf_with(|d, _| {
                d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@")
            }),
            vec!["invalid base64"],
        ),
        (
            gltf_with(|d, _| {
                d["meshes"][0]["primitives"][0]["attributes"]
                    .as_object_mut()
                    .unwrap()
                    .remove(&sc);
            }),
            vec!["SCALE", "required attribute is missing"],
        ),
        (
            gltf_with(|d, b| {
                let o = elem_offset(d, &op, 5, 4);
                b[o..o + 4].copy_from_slice(&1.5f32.to_le_bytes());
            }),
            vec!["OPACITY", "index 5", "outside [0, 1]"],
        ),
        (
            gltf_with(|d, b| {
                let o = elem_offset(d, "POSITION", 3, 12);
                b[o..o + 4].copy_from_slice(&f32::NAN.to_le_bytes());
            }),
            vec!["POSITION", "index 3", "not finite"],
        ),
        (
            gltf_with(|d, _| {
                let a = attr(d, &op);
                d["accessors"][a]["count"] = json!(7);
            }),
            vec!["OPACITY", "differs from POSITION's count"],
        ),
        (
            gltf_with(|d, _| {
                let a = attr(d, &rot);
                d["accessors"][a]["type"] = json!("VEC3");
            }),
            vec!["ROTATION", "expected 4 components"],
        ),
        (
            gltf_with(|d, _| {
                d["extensionsUsed"] = json!(["KHR_gaussian_splatting", "EXT_fancy"]);
                d["extensionsRequired"] = json!(["EXT_fancy"]);
            }),
            vec!["extensionsRequired[0]", "EXT_fancy"],
        ),
        (
            gltf_with(|d, _| d["nodes"] = json!([{"children": [1]}, {"children": [0], "mesh": 0}])),
            vec!["cycle"],
        ),
        (
            gltf_with(|d, _| d["nodes"] = json!([{"children": [1, 1], "mesh": 0}, {}])),
            vec!["more than one parent"],
        ),
        (
            gltf_with(|d, _| d["bufferViews"][0]["byteStride"] = json!(8)),
            vec!["byteStride 8"],
        ),
        (
            gltf_with(|d, _| {
                let a = attr(d, &op);
                d["accessors"][a]["componentType"] = json!(1234);
            }),
            vec!["componentType", "invalid value"],
        ),
        (
            gltf_with(|d, _| {
                d["meshes"][0]["primitives"][0]["extensions"] = json!({});
            }),
            vec!["no primitive with KHR_gaussian_splatting"],
        ),
        (
            gltf_with(|d, b| {
                let o = elem_offset(d, &rot, 4, 16);
                b[o..o + 16].copy_from_slice(&[0u8; 16]);
            }),
            vec!["ROTATION", "index 4", "quaternion is zero"],
        ),
        (
            gltf_with(|d, _| {
                d["meshes"][0]["primitives"][0]["extensions"]["KHR_gaussian_splatting"]["extensions"] =
                    json!({"KHR_gaussian_splatting_compression_spz_2": {"bufferView": 0}});
            }),
            vec!["compression_spz_2"],
        ),
        (
            gltf_with(|d, _| {
                d["bufferViews"][0]["byteOffset"] = json!(1u64 << 40);
            }),
            vec!["bufferViews[0]", "exceeds buffers[0]"],
        ),
        (
            gltf_with(|d, b| {
                let a = attr(d, &op);
                let start = b.len() as u64;
                b.extend_from_slice(&100u32.to_le_bytes());
                b.extend_from_slice(&0.5f32.to_le_bytes());
                d["buffers"][0]["byteLength"] = json!(b.len());
                d["bufferViews"]
                    .as_array_mut()
                    .unwrap()
                    .push(json!({"buffer": 0, "byteOffset": start, "byteLength": 4}));
                d["bufferViews"]
                    .as_array_mut()
                    .unwrap()
                    .push(json!({"buffer": 0, "byteOffset": start + 4, "byteLength": 4}));
                let n = d["bufferViews"].as_array().unwrap().len();
                d["accessors"][a]["sparse"] = json!({"count": 1, "indices": {"bufferView": n - 2, "componentType": 5125}, "values": {"bufferView": n - 1}});
            }),
            vec!["sparse", "index 100"],
        ),
    ];
    for (i, (bytes, needles)) in cases.iter().enumerate() {
        let e = err_of(bytes, "bad.gltf");
        for n in needles {
            assert!(e.contains(n), "glTF case {i}: {e:?} lacks {n:?}");
        }
        // validate reports the same problem as invalid or unreadable, never valid.
        let v = validate_bytes(bytes, Some(Path::new("bad.gltf")), &LoadOptions::default());
        assert_ne!(v.status(), Status::Valid, "glTF case {i}");
    }
}

#[test]
fn glb_framing() {
    let good = to_glb(&random_cloud(4, 3, 0), &GltfWriteOptions::default());
    let mut truncated = good.clone();
    truncated.truncate(good.len() - 7);
    expect(&truncated, "t.glb", &["GLB"]);
    let mut version = good.clone();
    version[4] = 1;
    expect(&version, "t.glb", &["GLB"]);
    let mut chunk = good.clone();
    chunk[12] = 0xFF; // JSON chunk length far past the end
    chunk[13] = 0xFF;
    expect(&chunk, "t.glb", &["GLB"]);
    let v = validate_bytes(
        &truncated,
        Some(Path::new("t.glb")),
        &LoadOptions::default(),
    );
    assert_eq!(v.status(), Status::Unreadable);
}

#[test]
fn spec_violations_the_loader_survives_are_validation_errors() {
    let validate =
        |bytes: &[u8]| validate_bytes(bytes, Some(Path::new("v.gltf")), &LoadOptions::default());
    let msgs = |bytes: &[u8]| -> Vec<String> {
        validate(bytes)
            .findings
            .iter()
            .map(|f| f.to_string())
            .collect()
    };
    // Partial SH degree: degree 1 with one coefficient missing → degree 0 + error.
    let partial = gltf_with(|d, _| {
        d["meshes"][0]["primitives"][0]["attributes"]
            .as_object_mut()
            .unwrap()
            .remove(&format!("{P}SH_DEGREE_1_COEF_2"));
    });
    assert!(
        msgs(&partial)
            .iter()
            .any(|m| m.contains("partially defined"))
    );
    let l = load_bytes(&partial, Some(Path::new("v.gltf")), &LoadOptions::default()).unwrap();
    assert_eq!(l.cloud.sh_degree, 0);
    // Mode not POINTS.
    let tri = gltf_with(|d, _| d["meshes"][0]["primitives"][0]["mode"] = json!(4));
    assert!(msgs(&tri).iter().any(|m| m.contains("POINTS")));
    // Missing kernel.
    let nok = gltf_with(|d, _| {
        d["meshes"][0]["primitives"][0]["extensions"]["KHR_gaussian_splatting"]
            .as_object_mut()
            .unwrap()
            .remove("kernel");
    });
    assert!(msgs(&nok).iter().any(|m| m.contains("'kernel' is missing")));
    // Non-unit quaternion: normalised by the loader, an error for validate, first index given.
    let nonunit = gltf_with(|d, b| {
        let a = attr(d, &format!("{P}ROTATION"));
        let v = d["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
        let o = d["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize + 2 * 16;
        b[o..o + 16].copy_from_slice(bytemuck::cast_slice(&[0.0f32, 0.0, 0.0, 2.0]));
    });
    let v = validate(&nonunit);
    let f = v
        .findings
        .iter()
        .find(|f| f.message.contains("not unit length"))
        .expect("finding");
    assert_eq!(f.index, Some(2));
    assert!(
        f.path
            .ends_with("attributes[\"KHR_gaussian_splatting:ROTATION\"]"),
        "{}",
        f.path
    );
    // Negative scale: log space under auto, an error under --scale-space linear.
    let neg = gltf_with(|d, b| {
        let a = attr(d, &format!("{P}SCALE"));
        let v = d["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
        let o = d["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize + 12;
        b[o..o + 4].copy_from_slice(&(-1.0f32).to_le_bytes());
    });
    assert!(
        msgs(&neg)
            .iter()
            .any(|m| m.contains("legacy draft: log-space scale"))
    );
    let e = load_bytes(
        &neg,
        Some(Path::new("v.gltf")),
        &LoadOptions {
            scale_space: ScaleSpace::Linear,
            ..LoadOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("MUST NOT be negative") && e.contains("index 1"),
        "{e}"
    );
    // A nested extension must also be in extensionsUsed (RC).
    let nested = gltf_with(|d, _| {
        d["meshes"][0]["primitives"][0]["extensions"]["KHR_gaussian_splatting"]["extensions"] =
            json!({"EXT_gaussian_splatting_kernel_customShape": {}});
    });
    assert!(
        msgs(&nested)
            .iter()
            .any(|m| m.contains("MUST also be listed in extensionsUsed"))
    );
    // And the file the writer produces is valid.
    assert_eq!(validate(&gltf_with(|_, _| {})).status(), Status::Valid);
}
