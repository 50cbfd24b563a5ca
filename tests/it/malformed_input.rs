//! Malformed and hostile input files, each ending in its specific error or a correct load
//! (never a panic, a stack overflow, an endless read or an allocation far beyond the input
//! size): lying headers, truncation, wrong types, partial SH, out-of-range values, NaN, bad
//! JSON, missing buffers, bad indices, deep or cyclic node graphs, instance bombs; SPZ (truncated
//! or bomb gzip, lying counts, bad versions and magic), `.splat`, `.ksplat` and SOG (zips with
//! missing members, WebP of the wrong size, paths out of the folder); PNG and PFM images that
//! `compare` reads. Peak memory of hostile packed files: tests/format_memory.rs.

use crate::common;
use base64::Engine;
use common::{packed, random_cloud};
use serde_json::{Value, json};
use splatgl::image::Image;
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{LoadOptions, ScaleSpace, load_bytes};
use splatgl::write::{Comp, GltfWriteOptions, build, to_glb};
use splatgl::write::{SpzWriteOptions, to_splat, to_spz_with};
use std::io::{Read, Write};
use std::path::Path;

/// The load error in strict mode (without it, splats with unusable values are dropped: see
/// `crates/splatgl-cli/tests/it/hygiene.rs`).
#[track_caller]
fn err_of(bytes: &[u8], name: &str) -> String {
    match load_bytes(bytes, Some(Path::new(name)), &strict()) {
        Ok(l) => panic!("{name}: expected an error, loaded {} splats", l.cloud.len()),
        Err(e) => e.to_string(),
    }
}

fn strict() -> LoadOptions {
    LoadOptions {
        strict: true,
        ..LoadOptions::default()
    }
}

#[track_caller]
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
    splatgl::write::to_inria_ply(&random_cloud(4, 1, 5.0, 1))
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
fn malformed_ply_files_give_precise_errors() {
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
    let (mut doc, mut bin) = build(&random_cloud(8, 1, 5.0, 2), &GltfWriteOptions::default());
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
fn malformed_gltf_files_give_precise_errors() {
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
        // validate reports the same problem as invalid or unreadable, or (a required
        // extension splatgl lacks) as valid but `unsupported`; never valid without a word.
        let v = validate_bytes(bytes, Some(Path::new("bad.gltf")), &LoadOptions::default());
        assert!(
            v.status() != Status::Valid || v.unsupported() > 0,
            "glTF case {i}: {:?}",
            v.findings
        );
    }
}

#[test]
fn broken_glb_framing_is_an_error() {
    let good = to_glb(&random_cloud(3, 0, 5.0, 4), &GltfWriteOptions::default());
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
    assert_eq!(
        f.severity,
        splatgl::load::Severity::Error,
        "as glTF-Validator's ROTATION_NON_UNIT"
    );
    assert!(
        f.path
            .ends_with("attributes[\"KHR_gaussian_splatting:ROTATION\"]"),
        "{}",
        f.path
    );
    // …and names the file's writer when the asset says who that was.
    let written = gltf_with(|d, b| {
        d["asset"]["generator"] = "splat-transform 3.7.0".into();
        let a = attr(d, &format!("{P}ROTATION"));
        let v = d["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
        let o = d["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize;
        b[o..o + 16].copy_from_slice(bytemuck::cast_slice(&[0.0f32, 0.0, 0.0, 2.0]));
    });
    assert!(
        msgs(&written).iter().any(
            |m| m.contains("not unit length") && m.contains("written by splat-transform 3.7.0")
        ),
        "{:?}",
        msgs(&written)
    );
    assert!(f.message.contains("written by splatgl"), "{}", f.message);
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
            ..Default::default()
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

// ---------- glTF: hostile documents found in review ----------

#[test]
fn huge_byte_offsets_are_errors() {
    let e = err_of(
        &gltf_with(|d, _| d["accessors"][0]["byteOffset"] = json!(u64::MAX)),
        "h.gltf",
    );
    assert!(e.contains("accessors[0]") && e.contains("needs"), "{e}");
}

#[test]
fn deep_node_chain_loads_without_recursion() {
    const DEPTH: usize = 20_000;
    let bytes = gltf_with(|d, _| {
        let mut nodes: Vec<Value> = (0..DEPTH).map(|i| json!({"children": [i + 1]})).collect();
        nodes.push(json!({"mesh": 0, "translation": [0.0, 0.0, 1.0]}));
        d["nodes"] = json!(nodes);
    });
    // Run on a small stack to prove the walk is iterative.
    let l = std::thread::Builder::new()
        .stack_size(256 * 1024)
        .spawn(move || load_bytes(&bytes, Some(Path::new("h.gltf")), &LoadOptions::default()))
        .unwrap()
        .join()
        .expect("no stack overflow")
        .expect("loads");
    assert_eq!(l.cloud.len(), 8);
}

#[test]
fn long_chain_cycle_check_is_linear() {
    // 200k nodes in one chain closed into a cycle: found quickly, not in O(n²).
    const N: usize = 200_000;
    let bytes = gltf_with(|d, _| {
        let mut nodes: Vec<Value> = (0..N).map(|i| json!({"children": [(i + 1) % N]})).collect();
        nodes[0]["mesh"] = json!(0);
        d["nodes"] = json!(nodes);
        d["scenes"] = json!([{"nodes": []}]);
    });
    assert!(err_of(&bytes, "h.gltf").contains("cycle"));
}

#[test]
fn camera_type_without_its_object_is_skipped_with_a_warning() {
    let bytes = gltf_with(|d, _| {
        d["cameras"] = json!([{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}]);
        d["nodes"][0]["camera"] = json!(0);
    });
    // The splats still load; the camera is reported and skipped.
    let scene = load_bytes(&bytes, None, &LoadOptions::default()).expect("loads");
    let e = scene.report.warning_lines().join("\n");
    assert!(e.contains("cameras[0]"), "{e}");
    assert!(scene.cameras.is_empty());
}

#[test]
fn glb_header_length_below_12_is_an_error() {
    let mut glb = to_glb(&random_cloud(2, 0, 5.0, 1), &GltfWriteOptions::default());
    glb[8..12].copy_from_slice(&5u32.to_le_bytes());
    let e = load_bytes(&glb, Some(Path::new("h.glb")), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("GLB: header length 5"), "{e}");
}

#[test]
fn repeated_scene_roots_and_instance_bombs_are_errors() {
    let e = err_of(
        &gltf_with(|d, _| d["scenes"] = json!([{"nodes": [0, 0]}])),
        "h.gltf",
    );
    assert!(e.contains("scenes[0].nodes[1]"), "{e}");
    // 20k nodes instancing one mesh of 2M zero-filled splats (sparse-free, no bufferView):
    // the budget stops it before the output is built.
    let bytes = gltf_with(|d, _| {
        for a in d["accessors"].as_array_mut().unwrap() {
            a.as_object_mut().unwrap().remove("bufferView");
            a.as_object_mut().unwrap().remove("min");
            a.as_object_mut().unwrap().remove("max");
            a["count"] = json!(2_000_000);
        }
        let nodes: Vec<Value> = (0..20_000).map(|_| json!({"mesh": 0})).collect();
        d["nodes"] = json!(nodes);
        d["scenes"] = json!([{"nodes": (0..20_000).collect::<Vec<_>>()}]);
    });
    let e = err_of(&bytes, "h.gltf");
    assert!(e.contains("budget") || e.contains("justify"), "{e}");
}

#[cfg(unix)] // a Unix device
#[test]
fn external_buffer_must_be_a_regular_file() {
    let dir = std::env::temp_dir().join(format!("splatgl-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bytes = gltf_with(|d, _| d["buffers"][0]["uri"] = json!("/dev/zero"));
    let p = dir.join("z.gltf");
    std::fs::write(&p, &bytes).unwrap();
    // Outside the folder: refused by the containment rule; allowed, it is still a device.
    let e = splatgl::load::load_path(&p, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("absolute path"), "{e}");
    let outside = LoadOptions {
        allow_outside_paths: true,
        ..LoadOptions::default()
    };
    let e = splatgl::load::load_path(&p, &outside)
        .unwrap_err()
        .to_string();
    assert!(e.contains("character device"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn log_scale_and_node_matrix_overflows_drop_the_splats() {
    let bytes = gltf_with(|d, b| {
        let a = d["meshes"][0]["primitives"][0]["attributes"]["KHR_gaussian_splatting:SCALE"]
            .as_u64()
            .unwrap() as usize;
        let v = d["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
        let o = d["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize;
        b[o..o + 4].copy_from_slice(&(-1.0f32).to_le_bytes()); // makes it log space
        b[o + 4..o + 8].copy_from_slice(&100.0f32.to_le_bytes());
    });
    // The overflowing splat is dropped and named; in strict mode the load fails.
    let l = load_bytes(&bytes, Some(Path::new("h.gltf")), &LoadOptions::default()).unwrap();
    assert_eq!(l.cloud.len(), 7);
    let w = l.report.warning_lines().join("\n");
    assert!(w.contains("SCALE\"] [index 0]: invalid per KHR_gaussian_splatting RC / glTF 2.0: exp(log-space scale) overflows f32; 1 splat dropped"), "{w}");
    assert!(err_of(&bytes, "h.gltf").contains("overflow"));
    let huge = gltf_with(|d, _| {
        d["nodes"][0]["matrix"] = json!([1e38, 0, 0, 0, 0, 1e38, 0, 0, 0, 0, 1e38, 0, 0, 0, 0, 1])
    });
    let l = load_bytes(&huge, Some(Path::new("h.gltf")), &LoadOptions::default()).unwrap();
    assert!(l.cloud.is_empty() && l.cloud.validate().is_ok());
    let w = l.report.warning_lines().join("\n");
    // Each splat goes with the first field that broke (positions of 1e38 × 5 overflow f32).
    let dropped: usize = l
        .report
        .findings
        .iter()
        .filter(|f| f.path == "nodes[0]" && f.message.contains("under this node's transform"))
        .map(|f| {
            f.message
                .split(" splat")
                .next()
                .unwrap()
                .rsplit(' ')
                .next()
                .unwrap()
                .parse::<usize>()
                .unwrap()
        })
        .sum();
    assert_eq!(dropped, 8, "{w}");
    assert!(err_of(&huge, "h.gltf").contains("strict mode"));
}

#[test]
fn position_types_and_alignment_are_validated() {
    let validate = |b: &[u8]| validate_bytes(b, Some(Path::new("v.gltf")), &LoadOptions::default());
    // u32 positions: not allowed even with quantization.
    let u32pos = gltf_with(|d, _| d["accessors"][0]["componentType"] = json!(5125));
    let v = validate(&u32pos);
    assert!(
        v.findings
            .iter()
            .any(|f| f.message.contains("unsigned int")),
        "{:#?}",
        v.findings
    );
    // Quantized positions written by us are valid (KHR_mesh_quantization, aligned stride).
    let mut c = random_cloud(5, 0, 5.0, 3);
    for p in &mut c.positions {
        *p = p.map(|x| x / 10.0);
    }
    let o = GltfWriteOptions {
        position: Comp::I8N,
        scale: Comp::U8N,
        opacity: Comp::U8N,
        ..Default::default()
    };
    let (mut doc, bin) = build(&c, &o);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    let ok = serde_json::to_vec(&doc).unwrap();
    assert_eq!(
        validate(&ok).status(),
        Status::Valid,
        "{:#?}",
        validate(&ok).findings
    );
    // Tightly packed u8 VEC3 (stride 3) breaks the 4-byte rule.
    for view in doc["bufferViews"].as_array_mut().unwrap() {
        if view["byteStride"] == json!(4) {
            view.as_object_mut().unwrap().remove("byteStride");
        }
    }
    let packed = serde_json::to_vec(&doc).unwrap();
    assert!(
        validate(&packed)
            .findings
            .iter()
            .any(|f| f.message.contains("4-byte"))
    );
    // Without KHR_mesh_quantization, quantized positions are an error.
    doc["extensionsUsed"] = json!(["KHR_gaussian_splatting"]);
    doc.as_object_mut().unwrap().remove("extensionsRequired");
    let noq = serde_json::to_vec(&doc).unwrap();
    assert!(
        validate(&noq)
            .findings
            .iter()
            .any(|f| f.path.ends_with("[\"POSITION\"]"))
    );
}

#[test]
fn non_splat_primitive_without_position_is_fine() {
    let bytes = gltf_with(|d, _| {
        let other = json!({"attributes": {"NORMAL": 0}, "mode": 0});
        d["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(other);
    });
    let l = load_bytes(&bytes, Some(Path::new("h.gltf")), &LoadOptions::default()).unwrap();
    assert_eq!(l.cloud.len(), 8);
}

#[test]
fn sparse_all_zero_opacity_writes_a_valid_file() {
    let mut c = random_cloud(6, 0, 5.0, 4);
    c.opacities.iter_mut().for_each(|o| *o = 0.0);
    let o = GltfWriteOptions {
        sparse_opacity: true,
        ..Default::default()
    };
    let glb = to_glb(&c, &o);
    let v = validate_bytes(&glb, Some(Path::new("s.glb")), &LoadOptions::default());
    assert_eq!(v.status(), Status::Valid, "{:#?}", v.findings);
}

#[test]
fn a_ply_trailing_element_the_file_ends_inside_is_a_warning_saying_how_much_is_missing() {
    let good = good_ply();
    let text_end = good.windows(11).position(|w| w == b"end_header\n").unwrap();
    // The same vertex data, then an element of 4 billion one-byte rows over 13 bytes.
    let mut short = good[..text_end].to_vec();
    short.extend_from_slice(b"element face 4000000000\nproperty uchar a\nend_header\n");
    short.extend_from_slice(&good[text_end + 11..]);
    short.extend_from_slice(&[0u8; 13]);
    let v = validate_bytes(&short, Some(Path::new("t.ply")), &LoadOptions::default());
    let f = v
        .findings
        .iter()
        .find(|f| f.path == "face")
        .expect("a finding on 'face'");
    assert_eq!(f.severity.name(), "warning");
    assert!(
        f.message.contains("4000000000") && f.message.contains("13"),
        "{}",
        f.message
    );
    // Complete, it is valid; the vertex data loads either way.
    let mut ok = good[..text_end].to_vec();
    ok.extend_from_slice(b"element face 2\nproperty uchar a\nend_header\n");
    ok.extend_from_slice(&good[text_end + 11..]);
    ok.extend_from_slice(&[0u8; 2]);
    let v = validate_bytes(&ok, Some(Path::new("t.ply")), &LoadOptions::default());
    assert!(
        v.findings.iter().all(|f| f.path != "face"),
        "{:#?}",
        v.findings
    );
    assert_eq!(
        load_bytes(&short, Some(Path::new("t.ply")), &strict())
            .unwrap()
            .cloud
            .len(),
        4
    );
}

// ---------- SPZ, .splat, .ksplat, SOG: errors name the block, member, section or texture ----------

fn gunzip(b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(b)
        .read_to_end(&mut out)
        .unwrap();
    out
}

fn gzip(b: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}

fn spz_of(c: &splatgl::SplatCloud, version: u32) -> Vec<u8> {
    let o = SpzWriteOptions {
        version: splatgl::write::SpzVersion::try_from(version).unwrap(),
        ..Default::default()
    };
    to_spz_with(c, &o).unwrap()
}

fn spz(version: u32, degree: u8) -> Vec<u8> {
    spz_of(&random_cloud(40, degree, 5.0, 2), version)
}

#[test]
fn spz_corpus() {
    let v2 = spz(2, 1);
    let inner = gunzip(&v2);
    let with = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = inner.clone();
        f(&mut b);
        gzip(&b)
    };
    expect(&v2[..v2.len() - 20], "a.spz", &["SPZ: gzip:"]);
    expect(
        b"hello world, not a splat",
        "a.spz",
        &["not SPZ", "found 68656c6c"],
    );
    expect(&with(&|b| b[4] = 7), "a.spz", &["version 7", "gzip member"]);
    expect(&with(&|b| b[4] = 0), "a.spz", &["version 0"]);
    expect(&with(&|b| b[12] = 5), "a.spz", &["SH degree 5"]);
    expect(
        &with(&|b| b[8..12].copy_from_slice(&1000u32.to_le_bytes())),
        "a.spz",
        &[
            "claims 1000 points",
            "positions needs 28016 bytes, only 1136 present",
        ],
    );
    expect(
        &with(&|b| b[8..12].copy_from_slice(&1_000_000u32.to_le_bytes())),
        "a.spz",
        &["claims 1000000 points", "over the budget"],
    );
    expect(
        &with(&|b| b.truncate(b.len() - 5)),
        "a.spz",
        &["claims 40 points", "sh needs"],
    );
    // A gzip bomb: 64 MiB of zeros after a valid header, far over 16 MiB + 64 × ~65 KB.
    let mut bomb = inner[..16].to_vec();
    bomb.resize(64 << 20, 0);
    let bomb = gzip(&bomb);
    expect(&bomb, "a.spz", &["gzip", "budget"]);

    let v4 = spz(4, 1);
    let toc = u32::from_le_bytes(v4[16..20].try_into().unwrap()) as usize;
    let mut b = v4.clone();
    b[4] = 9;
    expect(&b, "a.spz", &["version 9"]);
    let mut b = v4.clone();
    b[15] = 3;
    expect(&b, "a.spz", &["3 streams, expected 6"]);
    let mut b = v4.clone();
    b[toc + 8] ^= 1; // stream 0 uncompressed size
    expect(&b, "a.spz", &["stream 0 (positions) holds", "expected 360"]);
    let mut b = v4.clone();
    b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    expect(&b, "a.spz", &["4294967295 points", "budget"]);
    let mut b = v4.clone();
    b.truncate(b.len() - 3);
    expect(&b, "a.spz", &["sh needs"]);
    let mut b = v4.clone();
    b[toc + 6 * 16] ^= 0xff; // the first stream's zstd magic
    expect(&b, "a.spz", &["stream 0 (positions): zstd frame header"]);
    let mut b = v4.clone();
    b.extend_from_slice(b"junk");
    expect(&b, "a.spz", &["streams end at byte", "the file at"]);
}

#[test]
fn splat_and_ksplat_corpus() {
    let s = to_splat(&random_cloud(5, 0, 5.0, 1));
    expect(
        &s[..s.len() - 7],
        "a.splat",
        &["length 153", "record 4 is truncated (25 of 32"],
    );
    // A NaN position is dropped and counted, not loaded and not an error.
    let mut b = s.clone();
    b[32..36].copy_from_slice(&f32::NAN.to_le_bytes());
    let l = load_bytes(&b, Some(Path::new("a.splat")), &LoadOptions::default()).unwrap();
    assert_eq!(l.cloud.len(), 4);
    let w = l.report.warning_lines().join("\n");
    assert!(
        w.contains("records [index 1]: 1 splat dropped: position is not finite"),
        "{w}"
    );
    expect(
        &b,
        "a.splat",
        &["position is not finite (strict mode)", "index 1"],
    );

    let k = packed::ksplat(&random_cloud(300, 1, 5.0, 3), 1, 128, 25.0);
    expect(
        &k[..5000],
        "a.ksplat",
        &["section headers needs", "the file has 5000"],
    );
    expect(&k[..k.len() - 1], "a.ksplat", &["section 0 data needs"]);
    let poke = |at: usize, v: &[u8]| {
        let mut b = k.clone();
        b[at..at + v.len()].copy_from_slice(v);
        b
    };
    expect(&poke(0, &[1]), "a.ksplat", &["version 1.1"]);
    expect(&poke(20, &[3, 0]), "a.ksplat", &["compression level 3"]);
    expect(
        &poke(4096, &301u32.to_le_bytes()),
        "a.ksplat",
        &["301 splats but room for 300"],
    );
    expect(&poke(4096 + 40, &[4, 0]), "a.ksplat", &["SH degree 4"]);
    expect(
        &poke(4096 + 32, &[1, 0, 0, 0]),
        "a.ksplat",
        &["buckets hold", "the section 300"],
    );
    let l = load_bytes(
        &poke(16, &[7, 0, 0, 0]),
        Some(Path::new("a.ksplat")),
        &LoadOptions::default(),
    )
    .unwrap();
    assert!(
        l.report
            .warning_lines()
            .iter()
            .any(|w| w.contains("states 7 splats"))
    );
}

/// The files of a SOG bundle: (name, bytes).
type Files = Vec<(String, Vec<u8>)>;

fn sog_members(edit: &dyn Fn(&mut Files)) -> Vec<u8> {
    let mut files = packed::sog_files(&random_cloud(50, 1, 5.0, 4));
    edit(&mut files);
    let m: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    packed::zip_stored(&m)
}

#[test]
fn sog_corpus() {
    let good = sog_members(&|_| {});
    expect(
        &sog_members(&|f| f.retain(|(n, _)| n != "quats.webp")),
        "a.sog",
        &["SOG: 'quats.webp' is missing"],
    );
    expect(
        &sog_members(&|f| f.retain(|(n, _)| n != "meta.json")),
        "a.sog",
        &["'meta.json' is missing"],
    );
    expect(
        &sog_members(&|f| f[3].1 = packed::webp(&[0; 4 * 12], 4, 3)),
        "a.sog",
        &[
            "texture 'scales.webp' (scales)",
            "4×3 = 12 texels, fewer than the 50 splats",
        ],
    );
    expect(
        &sog_members(&|f| f[0].1 = b"RIFF....WEBPnope".to_vec()),
        "a.sog",
        &["'means_l.webp' (means_l)", "not a WebP image"],
    );
    let meta = |f: &mut Files, from: &str, to: &str| {
        let m = f.last_mut().unwrap();
        m.1 = String::from_utf8(m.1.clone())
            .unwrap()
            .replace(from, to)
            .into_bytes();
    };
    expect(
        &sog_members(&|f| meta(f, "\"version\":2", "\"version\":3")),
        "a.sog",
        &["meta.json: version: 3"],
    );
    expect(
        &sog_members(&|f| meta(f, "\"bands\":1", "\"bands\":7")),
        "a.sog",
        &["shN.bands: 7, expected 1-3"],
    );
    expect(
        &sog_members(&|f| meta(f, "\"count\":50", "\"count\":5000")),
        "a.sog",
        &["fewer than the 5000 splats"],
    );
    // Zip-level damage: truncated, a corrupt member, a member claiming a huge size.
    expect(
        &good[..good.len() - 30],
        "a.sog",
        &["zip: no end-of-central-directory record"],
    );
    let mut b = good.clone();
    b[50] ^= 0xff; // inside means_l.webp's data (after the 30-byte header and its name)
    expect(&b, "a.sog", &["'means_l.webp'", "CRC-32"]);
    let cd = u32::from_le_bytes(good[good.len() - 6..good.len() - 2].try_into().unwrap()) as usize;
    let mut b = good.clone();
    b[cd + 24..cd + 28].copy_from_slice(&u32::MAX.to_le_bytes()); // first member's size
    expect(&b, "a.sog", &["'means_l.webp'", "over the", "budget"]);
    expect(
        b"PK\x03\x04 not really a zip at all",
        "a.sog",
        &["SOG: zip:"],
    );
}

#[cfg(unix)] // the symlink case
#[test]
fn unbundled_sog_rejects_paths_outside_its_folder() {
    let root = std::env::temp_dir().join(format!("splatgl-sogbad-{}", std::process::id()));
    let dir = root.join("asset");
    std::fs::create_dir_all(&dir).unwrap();
    let files = packed::sog_files(&random_cloud(20, 0, 5.0, 4));
    for (n, b) in &files {
        std::fs::write(dir.join(n), b).unwrap();
        std::fs::write(root.join(n), b).unwrap();
    }
    let meta = String::from_utf8(files.last().unwrap().1.clone()).unwrap();
    let p = dir.join("meta.json");
    let name = p.to_str().unwrap();
    let bad = meta.replace("\"quats.webp\"", "\"../quats.webp\"");
    expect(
        bad.as_bytes(),
        name,
        &[
            "'../quats.webp'",
            "outside the asset's folder",
            "--allow-outside-paths",
        ],
    );
    let abs = root.join("quats.webp");
    let absolute = meta.replace("\"quats.webp\"", &format!("{:?}", abs.to_str().unwrap()));
    expect(absolute.as_bytes(), name, &["is an absolute path"]);
    // A symlink inside the folder that points out is followed before the check.
    std::os::unix::fs::symlink(&abs, dir.join("link.webp")).unwrap();
    let linked = meta.replace("\"quats.webp\"", "\"link.webp\"");
    expect(
        linked.as_bytes(),
        name,
        &["'link.webp'", "outside the asset's folder"],
    );
    // With the opt-in all three load.
    let outside = LoadOptions {
        allow_outside_paths: true,
        ..LoadOptions::default()
    };
    for m in [&bad, &absolute, &linked] {
        let l = load_bytes(m.as_bytes(), Some(&p), &outside).unwrap();
        assert_eq!(l.cloud.len(), 20);
    }
    let gone = meta.replace("\"quats.webp\"", "\"nothere.webp\"");
    expect(gone.as_bytes(), name, &["'nothere.webp' is missing"]);
    // Containment before existence: outside the folder, a file that is there and one that is
    // not are refused alike (a meta.json cannot probe for files), through `..` or a symlink.
    std::os::unix::fs::symlink(&root, dir.join("up")).unwrap();
    for (there, absent) in [
        ("../quats.webp", "../absent.webp"),
        ("up/quats.webp", "up/absent.webp"),
    ] {
        let e = |n: &str| {
            err_of(
                meta.replace("\"quats.webp\"", &format!("{n:?}")).as_bytes(),
                name,
            )
        };
        let (a, b) = (e(there), e(absent));
        assert!(a.contains("outside the asset's folder"), "{a}");
        assert_eq!(a.replace(there, "X"), b.replace(absent, "X"));
    }
    // Only regular files, within --max-bytes (all textures together).
    let fifo = dir.join("fifo.webp");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let piped = meta.replace("\"quats.webp\"", "\"fifo.webp\"");
    let t = std::time::Instant::now();
    expect(piped.as_bytes(), name, &["'fifo.webp'", "FIFO"]);
    assert!(t.elapsed().as_secs_f64() < 1.0);
    let small = LoadOptions {
        limits: splatgl::load::Limits {
            max_bytes: 200,
            ..Default::default()
        },
        ..LoadOptions::default()
    };
    let e = load_bytes(meta.as_bytes(), Some(&p), &small)
        .unwrap_err()
        .to_string();
    assert!(e.contains("limit of") || e.contains("max_bytes"), "{e}");
    let e = load_bytes(meta.as_bytes(), None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs its path"), "{e}");
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn unbundled_sog_textures_come_from_the_resolver_when_there_is_one() {
    let files = packed::sog_files(&random_cloud(20, 0, 5.0, 4));
    let meta = files.last().unwrap().1.clone();
    let served: std::collections::HashMap<String, Vec<u8>> = files.iter().cloned().collect();
    let opts = LoadOptions {
        resolver: Some(std::sync::Arc::new(move |name: &str| {
            served
                .get(name)
                .cloned()
                .ok_or_else(|| format!("no {name}"))
        })),
        ..LoadOptions::default()
    };
    let l = load_bytes(&meta, None, &opts).unwrap();
    assert_eq!(l.cloud.len(), 20);
    let other = String::from_utf8(meta)
        .unwrap()
        .replace("\"quats.webp\"", "\"q.webp\"");
    let e = load_bytes(other.as_bytes(), None, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("'q.webp': resolver: no q.webp"), "{e}");
}

#[test]
fn packed_formats_obey_max_splats_max_decompressed_bytes_and_json_depth() {
    let c = random_cloud(50, 1, 5.0, 9);
    let cases: Vec<(&str, Vec<u8>, bool)> = vec![
        (
            "a.spz",
            to_spz_with(&c, &SpzWriteOptions::default()).unwrap(),
            true,
        ),
        ("a.splat", to_splat(&c), false),
        ("a.ksplat", packed::ksplat(&c, 1, 16, 25.0), false),
        ("a.sog", packed::sog_bundle(&c), true),
        ("a.glb", splatgl::write::to_glb_spz(&c).unwrap(), true),
    ];
    for (name, bytes, compressed) in &cases {
        let fewer = LoadOptions {
            limits: splatgl::load::Limits {
                max_splats: 49,
                ..Default::default()
            },
            ..LoadOptions::default()
        };
        let e = load_bytes(bytes, Some(Path::new(name)), &fewer)
            .map(|l| format!("loaded {}", l.cloud.len()))
            .unwrap_or_else(|e| e.to_string());
        assert!(
            e.contains("50 splats exceed limits.max_splats = 49"),
            "{name}: {e}"
        );
        // The embedder's cap on decompressed bytes is the budget when it is the smaller one.
        let tight = LoadOptions {
            limits: splatgl::load::Limits {
                max_decompressed_bytes: 1000,
                ..Default::default()
            },
            ..LoadOptions::default()
        };
        let r = load_bytes(bytes, Some(Path::new(name)), &tight);
        match (compressed, r) {
            (true, Err(e)) => {
                let e = e.to_string();
                assert!(
                    e.contains("1000") && e.contains("limits.max_decompressed_bytes"),
                    "{name}: {e}"
                );
            }
            (false, Ok(l)) => assert_eq!(l.cloud.len(), 50, "{name}"),
            (_, r) => panic!("{name}: {:?}", r.map(|l| l.cloud.len())),
        }
    }
    // SOG meta.json is depth-checked before it is parsed.
    let deep = sog_members(&|f| {
        let m = f.last_mut().unwrap();
        let text = String::from_utf8(m.1.clone()).unwrap();
        let nest = format!("{}{}", "[".repeat(100), "]".repeat(100));
        m.1 = text
            .replacen('{', &format!("{{\"x\":{nest},"), 1)
            .into_bytes();
    });
    expect(&deep, "a.sog", &["meta.json", "max_json_depth = 64"]);
}

// ---------- glTF with SPZ compression ----------

/// A `.glb` with `KHR_gaussian_splatting_compression_spz_2` (8 splats, SH 1) whose JSON and
/// BIN `edit` changes.
fn glb_spz_with(edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> Vec<u8> {
    let glb = splatgl::write::to_glb_spz(&random_cloud(8, 1, 5.0, 3)).unwrap();
    let (mut doc, mut bin) = packed::glb_chunks(&glb);
    edit(&mut doc, &mut bin);
    packed::glb_of(&doc, &bin)
}

const SPZ_EXT: &str = "/meshes/0/primitives/0/extensions/KHR_gaussian_splatting/extensions/KHR_gaussian_splatting_compression_spz_2";

#[test]
fn malformed_spz_compressed_gltf_gives_precise_errors() {
    let ext_path =
        "extensions.KHR_gaussian_splatting.extensions.KHR_gaussian_splatting_compression_spz_2";
    expect(
        &glb_spz_with(|d, _| d.pointer_mut(SPZ_EXT).unwrap()["bufferView"] = json!("zero")),
        "a.glb",
        &[ext_path, "'bufferView' is missing or not an index"],
    );
    expect(
        &glb_spz_with(|d, _| d.pointer_mut(SPZ_EXT).unwrap()["bufferView"] = json!(7)),
        "a.glb",
        &["bufferViews[7] does not exist"],
    );
    // A view running past its buffer.
    expect(
        &glb_spz_with(|d, _| d["bufferViews"][0]["byteLength"] = json!(1 << 20)),
        "a.glb",
        &["exceeds buffers[0]"],
    );
    // A truncated gzip member.
    expect(
        &glb_spz_with(|d, b| {
            let half = b.len() / 2;
            b.truncate(half);
            d["buffers"][0]["byteLength"] = json!(half);
            d["bufferViews"][0]["byteLength"] = json!(half);
        }),
        "a.glb",
        &["bufferViews[0]: SPZ: gzip"],
    );
    // A gzip bomb: a header claiming 10⁷ points, then zeros.
    expect(
        &glb_spz_with(|d, b| {
            let mut raw = gunzip(b);
            raw[8..12].copy_from_slice(&10_000_000u32.to_le_bytes());
            raw.resize(raw.len() + (32 << 20), 0);
            *b = gzip(&raw);
            d["buffers"][0]["byteLength"] = json!(b.len());
            d["bufferViews"][0]["byteLength"] = json!(b.len());
        }),
        "a.glb",
        &["SPZ:", "budget"],
    );
}

/// What the loader works around is still an error for `validate`: placeholder counts that
/// differ from the payload's, an SPZ version the extension does not pin.
#[test]
fn spz_compressed_gltf_spec_violations_are_validation_errors() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (
            glb_spz_with(|d, _| d["accessors"][2]["count"] = json!(9)),
            "placeholder accessor count 9, but the SPZ payload holds 8 points",
        ),
        (
            glb_spz_with(|d, b| {
                *b = to_spz_with(
                    &random_cloud(8, 1, 5.0, 3),
                    &SpzWriteOptions {
                        version: splatgl::write::SpzVersion::V3,
                        ..Default::default()
                    },
                )
                .unwrap();
                d["buffers"][0]["byteLength"] = json!(b.len());
                d["bufferViews"][0]["byteLength"] = json!(b.len());
            }),
            "pins SPZ version 2, the payload is version 3",
        ),
    ];
    for (glb, needle) in cases {
        let scene = load_bytes(&glb, None, &LoadOptions::default()).unwrap();
        assert_eq!(scene.cloud.len(), 8);
        let r = validate_bytes(&glb, None, &LoadOptions::default());
        assert_eq!(r.status(), Status::Invalid, "{needle}");
        assert!(
            r.findings.iter().any(|f| f.message.contains(needle)),
            "{needle}: {:#?}",
            r.findings
        );
    }
}

// ---------- Images (PNG, PFM) read by `compare` ----------

fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn png_header_claiming_a_huge_image_is_rejected_before_allocation() {
    let mut png = Image::filled(1, 1, [0.5; 4])
        .encode_png(splatgl::image::PngDepth::Eight, false)
        .unwrap();
    // IHDR data starts at byte 16 (8 signature + 4 length + 4 type): width, height.
    png[16..20].copy_from_slice(&(1u32 << 30).to_be_bytes());
    png[20..24].copy_from_slice(&(1u32 << 30).to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    assert!(Image::decode_png(&png).is_err());
}

#[test]
fn pfm_accepts_crlf_and_rejects_a_nan_scale() {
    let mut ok = b"PF\r\n1 1\r\n-1.0\r\n".to_vec();
    for v in [0.25f32, 0.5, 0.75] {
        ok.extend_from_slice(&v.to_le_bytes());
    }
    let img = Image::decode_pfm(&ok).unwrap();
    assert_eq!(img.pixels[0][..3], [0.25, 0.5, 0.75]);
    let mut nan = b"PF\n1 1\nnan\n".to_vec();
    nan.extend_from_slice(&[0; 12]);
    assert!(Image::decode_pfm(&nan).is_err());
}

#[test]
fn comparing_an_image_with_itself_is_identical_even_with_inf() {
    let mut a = Image::filled(2, 2, [0.5; 4]);
    a.pixels[1] = [f32::INFINITY, f32::NAN, 0.0, 1.0];
    let c = splatgl::compare::compare(&a, &a, 1.0 / 255.0).unwrap();
    assert_eq!(c.max_abs, 0.0);
}
