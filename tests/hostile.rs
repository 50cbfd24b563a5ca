//! Hostile inputs found in review: each must end in a precise error (or a correct load), never
//! a panic, a stack overflow, an endless read or an allocation far beyond the input size.

mod common;
use base64::Engine;
use common::random_cloud;
use serde_json::{Value, json};
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{LoadOptions, load_bytes};
use splatgl::write::{Comp, GltfWriteOptions, build, to_glb};
use std::path::Path;

fn doc_with(edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> Vec<u8> {
    let (mut doc, mut bin) = build(&random_cloud(2, 8, 0), &GltfWriteOptions::default());
    edit(&mut doc, &mut bin);
    if doc["buffers"][0].get("uri").is_none() {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    }
    serde_json::to_vec(&doc).unwrap()
}

fn load_err(bytes: &[u8]) -> String {
    match load_bytes(bytes, Some(Path::new("h.gltf")), &LoadOptions::default()) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn huge_byte_offsets_are_errors() {
    let e = load_err(&doc_with(|d, _| {
        d["accessors"][0]["byteOffset"] = json!(u64::MAX)
    }));
    assert!(e.contains("accessors[0]") && e.contains("needs"), "{e}");
}

#[test]
fn deep_node_chain_loads_without_recursion() {
    const DEPTH: usize = 20_000;
    let bytes = doc_with(|d, _| {
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
    let bytes = doc_with(|d, _| {
        let mut nodes: Vec<Value> = (0..N).map(|i| json!({"children": [(i + 1) % N]})).collect();
        nodes[0]["mesh"] = json!(0);
        d["nodes"] = json!(nodes);
        d["scenes"] = json!([{"nodes": []}]);
    });
    assert!(load_err(&bytes).contains("cycle"));
}

#[test]
fn camera_type_without_its_object() {
    let bytes = doc_with(|d, _| {
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
fn glb_header_length_below_12() {
    let mut glb = to_glb(&random_cloud(1, 2, 0), &GltfWriteOptions::default());
    glb[8..12].copy_from_slice(&5u32.to_le_bytes());
    let e = load_bytes(&glb, Some(Path::new("h.glb")), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("GLB: header length 5"), "{e}");
}

#[test]
fn repeated_scene_roots_and_instance_bombs() {
    let e = load_err(&doc_with(|d, _| d["scenes"] = json!([{"nodes": [0, 0]}])));
    assert!(e.contains("scenes[0].nodes[1]"), "{e}");
    // 20k nodes instancing one mesh of 2M zero-filled splats (sparse-free, no bufferView):
    // the budget stops it before the output is built.
    let bytes = doc_with(|d, _| {
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
    let e = load_err(&bytes);
    assert!(e.contains("budget") || e.contains("justify"), "{e}");
}

#[test]
fn external_buffer_must_be_a_regular_file() {
    let dir = std::env::temp_dir().join(format!("splatgl-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bytes = doc_with(|d, _| d["buffers"][0]["uri"] = json!("/dev/zero"));
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
fn log_scale_overflow_and_transform_overflow() {
    let bytes = doc_with(|d, b| {
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
    assert!(load_strict_err(&bytes).contains("overflow"));
    let huge = doc_with(|d, _| {
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
    assert!(load_strict_err(&huge).contains("strict mode"));
}

fn load_strict_err(bytes: &[u8]) -> String {
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    match load_bytes(bytes, Some(Path::new("h.gltf")), &strict) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn position_types_and_alignment_are_validated() {
    let validate = |b: &[u8]| validate_bytes(b, Some(Path::new("v.gltf")), &LoadOptions::default());
    // u32 positions: not allowed even with quantization.
    let u32pos = doc_with(|d, _| d["accessors"][0]["componentType"] = json!(5125));
    let v = validate(&u32pos);
    assert!(
        v.findings
            .iter()
            .any(|f| f.message.contains("unsigned int")),
        "{:#?}",
        v.findings
    );
    // Quantized positions written by us are valid (KHR_mesh_quantization, aligned stride).
    let mut c = random_cloud(3, 5, 0);
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
    let bytes = doc_with(|d, _| {
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
    let mut c = random_cloud(4, 6, 0);
    c.opacities.iter_mut().for_each(|o| *o = 0.0);
    let o = GltfWriteOptions {
        sparse_opacity: true,
        ..Default::default()
    };
    let glb = to_glb(&c, &o);
    let v = validate_bytes(&glb, Some(Path::new("s.glb")), &LoadOptions::default());
    assert_eq!(v.status(), Status::Valid, "{:#?}", v.findings);
}
