//! Numeric hygiene: no non-finite or overflowing value leaves a loader. Each reproducer of
//! issue 13 (NaN `COLOR_0`, SH near f32::MAX rotated by a node to ±inf, huge-but-finite node
//! chains giving NaN rotations or NaN SH) loads with the bad splats dropped and a finding that
//! names the place, the first index and the count, fails in strict mode, and is an error for
//! `validate`. (`load::read` also `debug_assert!`s `SplatCloud::validate` on every cloud it
//! returns, so every load in every test checks the contract.)

use crate::common;
use base64::Engine;
use common::random_cloud;
use serde_json::{Value, json};
use splatgl::SplatCloud;
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{LoadOptions, Scene, Severity, load_bytes};
use splatgl::write::{GltfWriteOptions, build, to_inria_ply};
use std::path::Path;

const P: &str = "KHR_gaussian_splatting:";

/// `cloud` as a `.gltf` (data-URI buffer) with `edit` applied to the JSON and the binary.
fn gltf(
    cloud: &SplatCloud,
    o: &GltfWriteOptions,
    edit: impl FnOnce(&mut Value, &mut Vec<u8>),
) -> Vec<u8> {
    let (mut doc, mut bin) = build(cloud, o);
    edit(&mut doc, &mut bin);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    serde_json::to_vec(&doc).unwrap()
}

/// Byte offset of component `k` of element `i` of the float accessor behind attribute `name`.
fn offset(doc: &Value, name: &str, i: usize, k: usize) -> usize {
    let a = doc["meshes"][0]["primitives"][0]["attributes"][name]
        .as_u64()
        .unwrap() as usize;
    let dims = match doc["accessors"][a]["type"].as_str().unwrap() {
        "VEC4" => 4,
        "VEC3" => 3,
        _ => 1,
    };
    let v = doc["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
    doc["bufferViews"][v]["byteOffset"].as_u64().unwrap() as usize + (i * dims + k) * 4
}

fn poke(bin: &mut [u8], at: usize, v: f32) {
    bin[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn load(bytes: &[u8], name: &str) -> Scene {
    let s = load_bytes(bytes, Some(Path::new(name)), &LoadOptions::default()).expect("loads");
    s.cloud.validate().expect("loader contract");
    s
}

fn strict_err(bytes: &[u8], name: &str) -> String {
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    match load_bytes(bytes, Some(Path::new(name)), &strict) {
        Ok(_) => panic!("strict mode must fail"),
        Err(e) => e.to_string(),
    }
}

/// The finding at `path` whose message contains `needle`.
fn finding<'s>(s: &'s Scene, path: &str, needle: &str) -> &'s splatgl::load::Finding {
    s.report
        .findings
        .iter()
        .find(|f| f.path == path && f.message.contains(needle))
        .unwrap_or_else(|| panic!("no {needle:?} at {path}: {:#?}", s.report.findings))
}

/// A doc whose only node is `node` (holding mesh 0), or a chain of `chain` copies of `node`
/// with mesh 0 at its end.
fn with_nodes(doc: &mut Value, node: Value, chain: usize) {
    let mut nodes: Vec<Value> = (0..chain)
        .map(|i| {
            let mut n = node.clone();
            if i + 1 < chain {
                n["children"] = json!([i + 1]);
            } else {
                n["mesh"] = json!(0);
            }
            n
        })
        .collect();
    if chain == 1 {
        nodes[0]["mesh"] = json!(0);
    }
    doc["nodes"] = json!(nodes);
    doc["scenes"] = json!([{"nodes": [0]}]);
}

#[test]
fn nan_and_infinite_color0_splats_are_dropped_not_clamped() {
    let cloud = random_cloud(6, 0, 5.0, 3);
    let o = GltfWriteOptions {
        color0: true,
        ..Default::default()
    };
    let bytes = gltf(&cloud, &o, |d, b| {
        let attrs = d["meshes"][0]["primitives"][0]["attributes"]
            .as_object_mut()
            .unwrap();
        attrs.remove(&format!("{P}SH_DEGREE_0_COEF_0"));
        let (nan, inf) = (offset(d, "COLOR_0", 2, 1), offset(d, "COLOR_0", 4, 0));
        poke(b, nan, f32::NAN);
        poke(b, inf, f32::INFINITY); // f32::clamp would have made this a finite 1.0
    });
    let s = load(&bytes, "c.gltf");
    assert_eq!(s.cloud.len(), 4);
    assert_eq!(
        s.cloud.positions[2], cloud.positions[3],
        "the others keep their order"
    );
    let spec = finding(
        &s,
        "meshes[0].primitives[0].attributes[\"COLOR_0\"]",
        "not finite in 2 elements",
    );
    assert_eq!((spec.index, spec.severity), (Some(2), Severity::Error));
    let drop = finding(
        &s,
        "meshes[0].primitives[0]",
        "2 splats dropped: SH coefficient is not finite",
    );
    assert_eq!(drop.index, Some(2));
    let e = strict_err(&bytes, "c.gltf");
    assert!(e.contains("COLOR_0") && e.contains("[index 2]"), "{e}");
    let v = validate_bytes(&bytes, Some(Path::new("c.gltf")), &LoadOptions::default());
    assert_eq!(v.status(), Status::Invalid);
    assert!(
        v.findings
            .iter()
            .any(|f| f.path.ends_with("[\"COLOR_0\"]") && f.index == Some(2))
    );
}

/// A degree-1 cloud whose splat 1 has its m = −1 and m = +1 coefficients (y and x) at
/// `v` (near ±f32::MAX) in every channel, under a 45° rotation about z, which adds them:
/// |v|·√2 overflows f32.
fn sh_overflow_case(v: f32) -> (Vec<u8>, SplatCloud) {
    assert!(v.is_finite());
    let mut cloud = random_cloud(3, 1, 5.0, 4);
    for c in [1, 3] {
        cloud.sh[4 + c] = [v; 3];
    }
    let (s, c) = (
        std::f64::consts::FRAC_PI_8.sin(),
        std::f64::consts::FRAC_PI_8.cos(),
    );
    let bytes = gltf(&cloud, &GltfWriteOptions::default(), |d, _| {
        with_nodes(d, json!({"rotation": [0.0, 0.0, s, c]}), 1)
    });
    (bytes, cloud)
}

#[test]
fn sh_near_f32_max_rotated_to_plus_infinity_is_dropped() {
    {
        let (bytes, cloud) = sh_overflow_case(f32::MAX * 0.9);
        let s = load(&bytes, "r.gltf");
        assert_eq!(s.cloud.len(), 2);
        assert_eq!(s.cloud.opacities, [cloud.opacities[0], cloud.opacities[2]]);
        let f = finding(
            &s,
            "nodes[0]",
            "1 splat dropped: SH coefficient is not finite",
        );
        assert_eq!((f.index, f.severity), (Some(1), Severity::Error), "{f}");
        assert!(f.message.contains("meshes[0].primitives[0]"), "{f}");
        let e = strict_err(&bytes, "r.gltf");
        assert!(
            e.contains("nodes[0]") && e.contains("[index 1]") && e.contains("strict mode"),
            "{e}"
        );
        let v = validate_bytes(&bytes, Some(Path::new("r.gltf")), &LoadOptions::default());
        assert!(
            v.findings.iter().any(|f| f.path == "nodes[0]"
                && f.index == Some(1)
                && f.severity == Severity::Error)
        );
    }
}

#[test]
fn sh_near_f32_max_rotated_to_minus_infinity_is_dropped() {
    let (bytes, cloud) = sh_overflow_case(-f32::MAX * 0.95);
    let s = load(&bytes, "r.gltf");
    assert_eq!(s.cloud.opacities, [cloud.opacities[0], cloud.opacities[2]]);
    assert_eq!(
        finding(
            &s,
            "nodes[0]",
            "1 splat dropped: SH coefficient is not finite"
        )
        .index,
        Some(1)
    );
    assert!(strict_err(&bytes, "r.gltf").contains("SH coefficient is not finite (strict mode)"));
}

/// Splats at the origin with zero scale: only the covariance and the SH rotation can break.
fn origin_cloud(n: usize, degree: u8, scale: f32) -> SplatCloud {
    let mut c = random_cloud(n, degree, 5.0, 5);
    for i in 0..n {
        c.positions[i] = [0.0; 3];
        c.scales[i] = [scale; 3];
    }
    c
}

#[test]
fn huge_nonuniform_node_chain_giving_nan_rotations_is_dropped() {
    // Six nodes of scale (1e38, 1, 1): the product 1e228 is finite in f64, the covariance
    // (1e456) is not, so the eigen-decomposition returns NaN rotations and scales.
    let bytes = gltf(
        &origin_cloud(4, 0, 0.5),
        &GltfWriteOptions::default(),
        |d, _| with_nodes(d, json!({"scale": [1e38, 1.0, 1.0]}), 6),
    );
    let s = load(&bytes, "h.gltf");
    assert!(s.cloud.is_empty());
    let f = finding(&s, "nodes[5]", "4 splats dropped");
    assert_eq!(f.index, Some(0));
    assert!(
        f.message.contains("scale") || f.message.contains("rotation"),
        "{f}"
    );
    assert!(strict_err(&bytes, "h.gltf").contains("nodes[5]"));
}

#[test]
fn huge_uniform_node_chain_keeps_sh_finite_and_rotated() {
    // Six nodes of uniform scale 1e38 and a 45° turn about z: M = 1e228·R is finite, and its
    // SH rotation is R. (MᵀM = 1e456 used to overflow in the polar decomposition and make
    // every SH coefficient NaN; the rotation is now taken from M / max|Mᵢⱼ|.) Zero-scale
    // splats at the origin stay finite, so they must all be kept, with SH rotated by R⁶.
    let (s8, c8) = (
        std::f64::consts::FRAC_PI_8.sin(),
        std::f64::consts::FRAC_PI_8.cos(),
    );
    let cloud = origin_cloud(3, 1, 0.0);
    let bytes = gltf(&cloud, &GltfWriteOptions::default(), |d, _| {
        with_nodes(
            d,
            json!({"scale": [1e38, 1e38, 1e38], "rotation": [0.0, 0.0, s8, c8]}),
            6,
        )
    });
    let s = load(&bytes, "h.gltf");
    assert_eq!(s.cloud.len(), 3, "{:#?}", s.report.findings);
    // Six 45° turns = 270° about z: degree-1 (y, z, x) → x' = cos·x − sin·y with angle 270°,
    // so y' = −x and x' = y (the m = −1 coefficient is y).
    for i in 0..3 {
        let (a, b) = (cloud.sh_of(i), s.cloud.sh_of(i));
        for ch in 0..3 {
            assert!((b[1][ch] + a[3][ch]).abs() < 1e-5, "y' = −x");
            assert!((b[3][ch] - a[1][ch]).abs() < 1e-5, "x' = y");
            assert!((b[2][ch] - a[2][ch]).abs() < 1e-5, "z unchanged");
        }
    }
}

#[test]
fn node_chain_overflowing_f64_drops_every_value_it_touches() {
    // Nine nodes of scale 1e38: 1e342 is infinite even in f64; the SH rotation is NaN.
    let bytes = gltf(
        &origin_cloud(3, 2, 0.0),
        &GltfWriteOptions::default(),
        |d, _| with_nodes(d, json!({"scale": [1e38, 1e38, 1e38]}), 9),
    );
    let s = load(&bytes, "h.gltf");
    assert!(s.cloud.is_empty());
    let f = finding(&s, "nodes[8]", "3 splats dropped");
    assert_eq!(f.index, Some(0));
    let v = validate_bytes(&bytes, Some(Path::new("h.gltf")), &LoadOptions::default());
    assert_eq!(v.status(), Status::Invalid);
}

#[test]
fn drops_after_a_transform_name_the_accessor_index() {
    // Splat 1 has a NaN position (dropped while decoding), splat 3 SH that overflow under the
    // node: the second finding names accessor index 3, not 2 (its index after the first drop).
    let mut cloud = random_cloud(5, 1, 5.0, 6);
    for c in [1, 3] {
        cloud.sh[3 * 4 + c] = [f32::MAX * 0.9; 3];
    }
    let (s, c) = (
        std::f64::consts::FRAC_PI_8.sin(),
        std::f64::consts::FRAC_PI_8.cos(),
    );
    let bytes = gltf(&cloud, &GltfWriteOptions::default(), |d, b| {
        poke(b, offset(d, "POSITION", 1, 0), f32::NAN);
        with_nodes(d, json!({"rotation": [0.0, 0.0, s, c]}), 1)
    });
    let s = load(&bytes, "o.gltf");
    assert_eq!(s.cloud.len(), 3);
    assert_eq!(
        finding(&s, "meshes[0].primitives[0]", "position").index,
        Some(1)
    );
    assert_eq!(finding(&s, "nodes[0]", "SH coefficient").index, Some(3));
}

#[test]
fn ply_rows_with_unusable_values_are_dropped_with_a_warning() {
    let cloud = random_cloud(5, 0, 5.0, 7);
    let mut bytes = to_inria_ply(&cloud);
    let body = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let stride = 14 * 4;
    for (row, col, v) in [(1, 1, f32::NAN), (3, 3, f32::INFINITY)] {
        let o = body + row * stride + col * 4;
        bytes[o..o + 4].copy_from_slice(&v.to_le_bytes());
    }
    let s = load(&bytes, "d.ply");
    assert_eq!(s.cloud.len(), 3);
    assert_eq!(s.cloud.positions[1], cloud.positions[2]);
    let f = finding(&s, "vertex.y", "2 splats with unusable values dropped");
    assert_eq!((f.index, f.severity), (Some(1), Severity::Warning));
    let e = strict_err(&bytes, "d.ply");
    assert!(e.contains("index 1") && e.contains("'y'"), "{e}");
}

#[test]
fn cli_warns_about_dropped_splats_and_strict_fails() {
    let mut bytes = to_inria_ply(&random_cloud(3, 0, 5.0, 8));
    let body = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    bytes[body + 4..body + 8].copy_from_slice(&f32::NAN.to_le_bytes()); // row 0, y
    let p = std::env::temp_dir().join(format!("splatgl-hygiene-{}.ply", std::process::id()));
    std::fs::write(&p, &bytes).unwrap();
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_splatgl"))
            .args(args)
            .arg(&p)
            .output()
            .unwrap();
        let text =
            String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        (o.status.code(), text)
    };
    let (code, out) = run(&["info"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("splats:         2"), "{out}");
    assert!(out.contains("warning: vertex.y [index 0]: position is not finite; 1 splat with unusable values dropped"), "{out}");
    let (code, out) = run(&["info", "--strict"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("index 0") && out.contains("'y'"), "{out}");
    std::fs::remove_file(&p).ok();
}
