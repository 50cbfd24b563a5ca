//! Synthetic clouds written in every component type the RC allows (and KHR_mesh_quantization
//! positions, padded strides, sparse accessors, .gltf and .glb, external buffers) load back
//! to the same splats within the quantization step, and validate cleanly.

use crate::common;
use common::random_cloud;
use splatgl::SplatCloud;
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{Format, LoadOptions, load_bytes, load_path};
use splatgl::sh::color_from_dc;
use splatgl::write::{Comp, GltfWriteOptions, to_glb, to_gltf};
use std::path::Path;

/// A cloud whose values are representable by the quantized types under test.
fn quantizable(seed: u64, degree: u8) -> SplatCloud {
    let mut c = random_cloud(64, degree, 5.0, seed);
    for s in &mut c.scales {
        *s = s.map(|v| v.min(0.99));
    }
    c
}

fn max_err(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

fn check(
    orig: &SplatCloud,
    got: &SplatCloud,
    tol_pos: f32,
    tol_rot: f32,
    tol_scale: f32,
    tol_op: f32,
) {
    assert_eq!(got.len(), orig.len());
    assert_eq!(got.sh_degree, orig.sh_degree);
    let flat3 = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();
    assert!(max_err(&flat3(&orig.positions), &flat3(&got.positions)) <= tol_pos);
    assert!(max_err(&flat3(&orig.scales), &flat3(&got.scales)) <= tol_scale);
    assert!(max_err(&orig.opacities, &got.opacities) <= tol_op);
    assert_eq!(flat3(&orig.sh), flat3(&got.sh), "SH are float: exact");
    for (a, b) in orig.rotations.iter().zip(&got.rotations) {
        // q and -q are the same rotation.
        let d = a.iter().zip(b).map(|(x, y)| x * y).sum::<f32>().abs();
        assert!(1.0 - d <= tol_rot, "{a:?} vs {b:?}");
    }
}

fn roundtrip(c: &SplatCloud, o: &GltfWriteOptions) -> Vec<SplatCloud> {
    let mut out = Vec::new();
    for (bytes, name) in [(to_glb(c, o), "t.glb"), (to_gltf(c, o), "t.gltf")] {
        let p = Path::new(name);
        let v = validate_bytes(&bytes, Some(p), &LoadOptions::default());
        assert_eq!(v.status(), Status::Valid, "{o:?}: {:#?}", v.findings);
        let l = load_bytes(&bytes, Some(p), &LoadOptions::default()).expect("loads");
        assert_eq!(
            l.report.format,
            if name.ends_with("glb") {
                Format::Glb
            } else {
                Format::Gltf
            }
        );
        out.push(l.cloud);
    }
    out
}

#[test]
fn float_everything_is_exact() {
    for degree in 0..=3 {
        let c = quantizable(degree as u64, degree);
        for got in roundtrip(&c, &GltfWriteOptions::default()) {
            check(&c, &got, 0.0, 1e-6, 0.0, 0.0);
        }
    }
}

#[test]
fn every_rc_component_type() {
    let c = quantizable(7, 1);
    for rotation in [Comp::F32, Comp::I8N, Comp::I16N] {
        for scale in [Comp::F32, Comp::U8N, Comp::U16N] {
            for opacity in [Comp::F32, Comp::U8N, Comp::U16N] {
                let o = GltfWriteOptions {
                    rotation,
                    scale,
                    opacity,
                    ..Default::default()
                };
                let step = |t: Comp| match t {
                    Comp::U8N => 0.5 / 255.0 + 1e-6,
                    Comp::U16N => 0.5 / 65535.0 + 1e-6,
                    _ => 1e-6,
                };
                let tol_rot = if rotation == Comp::I8N { 2e-3 } else { 1e-6 };
                for got in roundtrip(&c, &o) {
                    check(&c, &got, 0.0, tol_rot, step(scale), step(opacity));
                }
            }
        }
    }
}

#[test]
fn integer_scales_unnormalized() {
    let mut c = quantizable(3, 0);
    for (i, s) in c.scales.iter_mut().enumerate() {
        *s = [(i % 5) as f32, 1.0, 2.0];
    }
    for scale in [Comp::U8, Comp::U16] {
        let o = GltfWriteOptions {
            scale,
            ..Default::default()
        };
        for got in roundtrip(&c, &o) {
            check(&c, &got, 0.0, 1e-6, 0.0, 0.0);
        }
    }
}

#[test]
fn quantized_positions_stride_and_sparse() {
    let mut c = quantizable(11, 2);
    for p in &mut c.positions {
        *p = p.map(|v| (v / 5.0).clamp(-1.0, 1.0)); // normalized range
    }
    c.opacities[3] = 0.0; // sparse keeps only non-zero entries
    for position in [Comp::I16N, Comp::I8N, Comp::F32] {
        let o = GltfWriteOptions {
            position,
            padding: 5,
            sparse_opacity: true,
            ..Default::default()
        };
        let tol = match position {
            Comp::I8N => 0.5 / 127.0 + 1e-6,
            Comp::I16N => 0.5 / 32767.0 + 1e-6,
            _ => 0.0,
        };
        for got in roundtrip(&c, &o) {
            check(&c, &got, tol, 1e-6, 0.0, 0.0);
            assert_eq!(got.opacities[3], 0.0);
        }
    }
}

#[test]
fn external_buffer_file() {
    let c = quantizable(5, 3);
    let (mut doc, bin) = splatgl::write::build(&c, &GltfWriteOptions::default());
    let dir = std::env::temp_dir().join(format!("splatgl-ext-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("data file.bin"), &bin).unwrap();
    doc["buffers"][0]["uri"] = serde_json::json!("data%20file.bin");
    let gltf = dir.join("scene.gltf");
    std::fs::write(&gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    let l = load_path(&gltf, &LoadOptions::default()).expect("external buffer");
    check(&c, &l.cloud, 0.0, 1e-6, 0.0, 0.0);
    std::fs::remove_file(dir.join("data file.bin")).unwrap();
    let e = load_path(&gltf, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("buffers[0]") && e.contains("data file.bin"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn ply_roundtrip_all_degrees() {
    for degree in 0..=3 {
        let c = quantizable(20 + degree as u64, degree);
        let bytes = splatgl::write::to_inria_ply(&c);
        let l = load_bytes(&bytes, Some(Path::new("x.ply")), &LoadOptions::default()).unwrap();
        let got = l.cloud;
        assert_eq!(got.sh, c.sh, "f_rest channel-major ↔ degree-major");
        check(&c, &got, 0.0, 1e-6, 1e-6, 1e-6);
    }
}

#[test]
fn color0_fallback_inverts_the_rc_formula() {
    let c = quantizable(9, 0);
    let o = GltfWriteOptions {
        color0: true,
        ..Default::default()
    };
    let (mut doc, bin) = splatgl::write::build(&c, &o);
    let attrs = doc["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap();
    attrs.remove("KHR_gaussian_splatting:SH_DEGREE_0_COEF_0");
    doc["buffers"][0]["uri"] = serde_json::json!(format!(
        "data:application/octet-stream;base64,{}",
        base64_encode(&bin)
    ));
    let bytes = serde_json::to_vec(&doc).unwrap();
    let l = load_bytes(&bytes, Some(Path::new("c.gltf")), &LoadOptions::default()).unwrap();
    for i in 0..c.len() {
        for ch in 0..3 {
            let want = color_from_dc(c.sh[i][ch]).clamp(0.0, 1.0);
            let got = color_from_dc(l.cloud.sh[i][ch]);
            assert!((want - got).abs() < 1e-5, "{want} {got}");
        }
    }
}

fn base64_encode(b: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(b)
}
