//! Node transforms: a splat under a rotated / scaled / translated node equals the same splat
//! pre-transformed (Σ = M C Cᵀ Mᵀ), SH are rotated so that colour(d) = colour_local(Rᵀd),
//! hierarchies compose, and instanced meshes are merged.

use crate::common;
use common::random_cloud;
use glam::{DMat3, DMat4, DQuat, DVec3};
use splatgl::covariance::{covariance_from_scale_rotation, unpack_sym};
use splatgl::load::{LoadOptions, load_bytes};
use splatgl::write::{GltfWriteOptions, build, to_glb};
use std::path::Path;

fn load_glb(bytes: &[u8]) -> splatgl::load::Scene {
    load_bytes(bytes, Some(Path::new("t.glb")), &LoadOptions::default()).expect("loads")
}

fn sigma(c: &splatgl::SplatCloud, i: usize) -> DMat3 {
    unpack_sym(covariance_from_scale_rotation(c.scales[i], c.rotations[i]))
}

fn assert_close(a: DMat3, b: DMat3, rel: f64) {
    let scale = b.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (x, y) in a.to_cols_array().iter().zip(b.to_cols_array()) {
        assert!((x - y).abs() <= rel * scale, "{a:?}\nvs\n{b:?}");
    }
}

fn check_transform(m: DMat4) {
    let local = random_cloud(50, 3, 5.0, 42);
    let o = GltfWriteOptions {
        node_matrix: Some(m.to_cols_array()),
        ..Default::default()
    };
    let got = load_glb(&to_glb(&local, &o)).cloud;
    let m3 = DMat3::from_mat4(m);
    for i in 0..local.len() {
        let p = local.positions[i].map(f64::from);
        let want = m.transform_point3(DVec3::from_array(p));
        let g = DVec3::from_array(got.positions[i].map(f64::from));
        assert!(
            (want - g).length() < 1e-5 * (1.0 + want.length()),
            "position {i}"
        );
        let want_sigma = m3 * sigma(&local, i) * m3.transpose();
        assert_close(sigma(&got, i), want_sigma, 1e-5);
    }
}

#[test]
fn translation_rotation_uniform_scale() {
    let r = DQuat::from_euler(glam::EulerRot::YXZ, 0.4, -1.1, 2.3);
    check_transform(DMat4::from_translation(DVec3::new(1.0, -2.0, 3.5)));
    check_transform(DMat4::from_quat(r));
    check_transform(DMat4::from_scale_rotation_translation(
        DVec3::splat(2.5),
        r,
        DVec3::X,
    ));
}

#[test]
fn non_uniform_scale_and_shear_keep_exact_covariance() {
    let r = DQuat::from_rotation_z(0.8);
    check_transform(DMat4::from_scale_rotation_translation(
        DVec3::new(0.5, 2.0, 3.0),
        r,
        DVec3::Y,
    ));
    let shear = DMat4::from_cols_array(&[
        1.0, 0.3, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.4, 0.0, 1.2, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    check_transform(shear);
}

#[test]
fn sh_rotated_by_node_rotation() {
    let local = random_cloud(20, 3, 5.0, 7);
    let r = DQuat::from_euler(glam::EulerRot::ZXY, 1.3, 0.2, -0.7);
    let m = DMat4::from_scale_rotation_translation(DVec3::splat(1.7), r, DVec3::new(0.0, 1.0, 0.0));
    let o = GltfWriteOptions {
        node_matrix: Some(m.to_cols_array()),
        ..Default::default()
    };
    let got = load_glb(&to_glb(&local, &o)).cloud;
    let rm = DMat3::from_quat(r);
    for i in 0..local.len() {
        for d in [
            DVec3::new(0.2, 0.9, -0.3),
            DVec3::new(-0.6, 0.1, 0.8),
            DVec3::Z,
        ] {
            let d = d.normalize();
            let local_dir = (rm.transpose() * d).to_array().map(|v| v as f32);
            let want = splatgl::sh::eval_color(local.sh_of(i), 3, local_dir);
            let have = splatgl::sh::eval_color(got.sh_of(i), 3, d.to_array().map(|v| v as f32));
            for ch in 0..3 {
                assert!(
                    (want[ch] - have[ch]).abs() < 1e-4,
                    "splat {i}: {want:?} vs {have:?}"
                );
            }
        }
    }
}

#[test]
fn hierarchy_composes_and_instances_merge() {
    let local = random_cloud(10, 1, 5.0, 3);
    let (mut doc, bin) = build(&local, &GltfWriteOptions::default());
    let a = DMat4::from_scale_rotation_translation(
        DVec3::splat(2.0),
        DQuat::from_rotation_x(0.5),
        DVec3::new(1.0, 0.0, 0.0),
    );
    let b = DMat4::from_translation(DVec3::new(0.0, 3.0, 0.0));
    doc["nodes"] = serde_json::json!([
        {"children": [1], "matrix": a.to_cols_array()},
        {"mesh": 0, "matrix": b.to_cols_array()},
        {"mesh": 0}
    ]);
    doc["scenes"] = serde_json::json!([{"nodes": [0, 2]}]);
    doc["buffers"][0]["uri"] =
        serde_json::json!(format!("data:application/octet-stream;base64,{}", {
            use base64::Engine;
            base64::engine::general_purpose::STANDARD.encode(&bin)
        }));
    let bytes = serde_json::to_vec(&doc).unwrap();
    let got = load_bytes(&bytes, Some(Path::new("h.gltf")), &LoadOptions::default())
        .unwrap()
        .cloud;
    assert_eq!(got.len(), 20, "mesh instanced twice");
    let ab = a * b;
    for i in 0..10 {
        let p = DVec3::from_array(local.positions[i].map(f64::from));
        let want = ab.transform_point3(p);
        let g = DVec3::from_array(got.positions[i].map(f64::from));
        assert!((want - g).length() < 1e-5 * (1.0 + want.length()));
        assert_eq!(
            got.positions[10 + i],
            local.positions[i],
            "identity instance"
        );
    }
}

#[test]
fn mirrored_node_is_flagged() {
    let local = random_cloud(4, 0, 5.0, 1);
    let m = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let o = GltfWriteOptions {
        node_matrix: Some(m.to_cols_array()),
        ..Default::default()
    };
    let l = load_glb(&to_glb(&local, &o));
    assert!(
        l.report
            .findings
            .iter()
            .any(|w| w.message.contains("undefined")),
        "{:?}",
        l.report.findings
    );
}
