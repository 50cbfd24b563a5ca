//! `splatgl convert`: round trips PLY → glTF → PLY per component type, the RC content of the
//! output, the options, and the Khronos glTF-Validator on what it writes.

use crate::common;
use splatgl::SplatCloud;
use splatgl::load::{LoadOptions, load_path};
use std::path::{Path, PathBuf};
use std::process::Command;

fn splatgl(args: &[&str]) -> (i32, String) {
    let r = common::cli::run(args);
    (r.code, r.all())
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-convert-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn load(p: &Path) -> SplatCloud {
    load_path(p, &LoadOptions::default()).unwrap().cloud
}

/// Runs the Khronos glTF-Validator through scripts/gltf_validate.mjs; `None` (with a note)
/// when node or the npm package is not installed here (.ci/run installs both).
pub fn khronos_validate(file: &Path) -> Option<serde_json::Value> {
    let script = common::root().join("scripts/gltf_validate.mjs");
    let pkg = common::root().join(".npm-tools/node_modules/gltf-validator");
    if !pkg.exists() {
        common::skip(&format!(
            "glTF-Validator: {} not installed (.ci/run and scripts/test.sh install it)",
            pkg.display()
        ));
        return None;
    }
    let out = match Command::new("node").arg(&script).arg(file).output() {
        Ok(o) => o,
        Err(e) => {
            common::skip(&format!("glTF-Validator: node not runnable ({e})"));
            return None;
        }
    };
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{}: validator output is not JSON ({e}): {}",
            file.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let errors = report["issues"]["numErrors"].as_u64().unwrap();
    assert_eq!(
        errors,
        0,
        "{}: glTF-Validator errors: {:#}",
        file.display(),
        report["issues"]["messages"]
    );
    assert_eq!(out.status.code(), Some(0));
    Some(report)
}

/// A random INRIA PLY with positions in [−5, 5], SH degree 3.
fn source(d: &Path) -> (PathBuf, SplatCloud) {
    let cloud = common::random_cloud(300, 3, 5.0, 7);
    let p = d.join("in.ply");
    std::fs::write(&p, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let loaded = load(&p);
    (p, loaded)
}

/// Which fields of two clouds differ (bit for bit), with a count and the first index.
fn differences(a: &SplatCloud, b: &SplatCloud) -> Vec<String> {
    fn field<T: PartialEq + std::fmt::Debug>(name: &str, a: &[T], b: &[T], out: &mut Vec<String>) {
        let bad: Vec<usize> = (0..a.len().min(b.len()))
            .filter(|&i| a[i] != b[i])
            .collect();
        if a.len() != b.len() || !bad.is_empty() {
            let first = bad.first().map(|&i| format!("{:?} vs {:?}", a[i], b[i]));
            out.push(format!(
                "{name}: {} differ, lengths {} / {}, first {first:?}",
                bad.len(),
                a.len(),
                b.len()
            ));
        }
    }
    let mut out = Vec::new();
    field("positions", &a.positions, &b.positions, &mut out);
    field("scales", &a.scales, &b.scales, &mut out);
    field("rotations", &a.rotations, &b.rotations, &mut out);
    field("opacities", &a.opacities, &b.opacities, &mut out);
    field("sh", &a.sh, &b.sh, &mut out);
    if a.meta != b.meta || a.sh_degree != b.sh_degree {
        out.push(format!(
            "meta {:?}/{} vs {:?}/{}",
            a.meta, a.sh_degree, b.meta, b.sh_degree
        ));
    }
    out
}

fn max_diff<const N: usize>(a: &[[f32; N]], b: &[[f32; N]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (*p as f64 - *q as f64).abs()))
        .fold(0.0, f64::max)
}

/// `cloud` turned by 180° about Z, written out independently of the converter: (x, y, z) →
/// (−x, −y, z); the quaternion (0, 0, 1, 0) · q = (−y, x, w, −z) in xyzw (up to sign: both
/// are the same rotation); each SH coefficient of order m times (−1)^m (the real SH of order
/// m go as cos(mφ) or sin(|m|φ), and φ → φ + π).
fn turned_about_z(cloud: &SplatCloud) -> SplatCloud {
    let mut t = cloud.clone();
    for p in &mut t.positions {
        *p = [-p[0], -p[1], p[2]];
    }
    for q in &mut t.rotations {
        *q = [-q[1], q[0], q[3], -q[2]];
    }
    let k = t.coeffs_per_splat();
    for c in t.sh.chunks_exact_mut(k) {
        for l in 1..=t.sh_degree as usize {
            for (i, v) in c[l * l..l * l + 2 * l + 1].iter_mut().enumerate() {
                if (i as i64 - l as i64) % 2 != 0 {
                    *v = v.map(|x| -x);
                }
            }
        }
    }
    t
}

/// Quaternions compared up to sign (q and −q are one rotation), the rest bit for bit.
fn differences_up_to_quaternion_sign(a: &SplatCloud, b: &SplatCloud) -> Vec<String> {
    let mut b = b.clone();
    for (q, p) in b.rotations.iter_mut().zip(&a.rotations) {
        if q.map(|v| -v) == *p {
            *q = *p;
        }
    }
    differences(a, &b)
}

#[test]
fn float_round_trip_ply_glb_ply_is_exact() {
    let d = dir("float");
    let (input, want) = source(&d);
    let turned = turned_about_z(&want);
    for ext in ["glb", "gltf"] {
        let mid = d.join(format!("mid.{ext}"));
        let out = d.join(format!("out-{ext}.ply"));
        assert_eq!(splatgl(&["convert", s(&input), s(&mid)]).0, 0);
        // --up auto: the PLY's −Y up becomes glTF's +Y by 180° about Z, without rounding.
        let d1 = differences_up_to_quaternion_sign(&load(&mid), &turned);
        assert!(d1.is_empty(), "PLY → {ext}: {d1:?}");
        assert_eq!(splatgl(&["convert", s(&mid), s(&out)]).0, 0);
        let d2 = differences_up_to_quaternion_sign(&load(&out), &want);
        assert!(d2.is_empty(), "PLY → {ext} → PLY: {d2:?}");
        khronos_validate(&mid);
        let (code, text) = splatgl(&["validate", s(&mid)]);
        assert_eq!(code, 0, "{text}");
    }
}

/// An explicit `--up y` keeps the numbers as they are (what `convert` did before `auto`), and
/// `--up -y` is the rotation `auto` picks for a PLY.
#[test]
fn explicit_up_y_keeps_the_axes_and_up_minus_y_is_what_auto_does_for_ply() {
    let d = dir("up-explicit");
    let (input, want) = source(&d);
    let (kept, neg) = (d.join("kept.glb"), d.join("neg.glb"));
    assert_eq!(splatgl(&["convert", s(&input), s(&kept), "--up", "y"]).0, 0);
    let d1 = differences(&load(&kept), &want);
    assert!(d1.is_empty(), "--up y: {d1:?}");
    assert_eq!(splatgl(&["convert", s(&input), s(&neg), "--up", "-y"]).0, 0);
    let d2 = differences_up_to_quaternion_sign(&load(&neg), &turned_about_z(&want));
    assert!(d2.is_empty(), "--up -y: {d2:?}");
    // A glTF input written as PLY turns back to −Y; one written as glTF does not turn.
    let (ply, glb) = (d.join("back.ply"), d.join("again.glb"));
    assert_eq!(splatgl(&["convert", s(&kept), s(&ply)]).0, 0);
    let d3 = differences_up_to_quaternion_sign(&load(&ply), &turned_about_z(&want));
    assert!(d3.is_empty(), "glTF → PLY: {d3:?}");
    assert_eq!(splatgl(&["convert", s(&kept), s(&glb)]).0, 0);
    let d4 = differences(&load(&glb), &want);
    assert!(d4.is_empty(), "glTF → glTF: {d4:?}");
}

/// Quantizing one attribute moves it by at most half a step (plus f32 rounding), where a
/// step is the type's step in decoded units times the dequantization scale; everything else
/// stays within f32 rounding of the node matrix (none for rotation and opacity).
#[test]
fn quantized_round_trip_stays_within_one_step_per_component_type() {
    use splatgl::write::{Comp, OPACITY_TYPES, POSITION_TYPES, ROTATION_TYPES, SCALE_TYPES};
    let d = dir("quant");
    let (input, want) = source(&d);
    let extent = 10.0f64; // positions span about [−5, 5]
    let max_scale = want.scales.iter().flatten().fold(0.0f32, |a, &b| a.max(b)) as f64;
    let cases = [
        ("position", &POSITION_TYPES[..]),
        ("rotation", &ROTATION_TYPES[..]),
        ("scale", &SCALE_TYPES[..]),
        ("opacity", &OPACITY_TYPES[..]),
    ];
    let mut checked = 0;
    for (attr, types) in cases {
        for &comp in types.iter().filter(|c| **c != Comp::F32) {
            let name = format!("{attr}-{}", comp.name());
            let mid = d.join(format!("{name}.glb"));
            let out = d.join(format!("{name}.ply"));
            let q = format!("{attr}={}", comp.name());
            let (code, text) = splatgl(&["convert", s(&input), s(&mid), "--quantize", &q]);
            assert_eq!(code, 0, "{text}");
            assert_eq!(splatgl(&["convert", s(&mid), s(&out)]).0, 0);
            let back = load(&out);
            let (lo, hi) = comp.range().unwrap();
            // Dequantization scale k (see write::quantize): positions span the range.
            let k = match attr {
                "position" => max_diff_extent(&want) / (hi - lo),
                "scale" if !comp.is_normalized() => max_scale / hi,
                _ => 1.0,
            };
            let step = comp.step() * k;
            let f32_tol = 1e-6 * extent;
            let (dp, ds) = (
                max_diff(&back.positions, &want.positions),
                max_diff(&back.scales, &want.scales),
            );
            // Up to sign: the round trip turns by 180° about Z twice, q → −q.
            let flipped: Vec<[f32; 4]> = back.rotations.iter().map(|q| q.map(|v| -v)).collect();
            let (dr, dop) = (
                max_diff(&back.rotations, &want.rotations).min(max_diff(&flipped, &want.rotations)),
                back.opacities
                    .iter()
                    .zip(&want.opacities)
                    .map(|(a, b)| (*a as f64 - *b as f64).abs())
                    .fold(0.0, f64::max),
            );
            let bound = |on: bool, rel: f64| if on { 0.5 * step + rel } else { rel };
            // Rotations are renormalised after quantization: a unit quaternion's components
            // move by at most the rounding error plus the normalisation's correction (≤ 2×).
            let rot_bound = if attr == "rotation" {
                2.0 * comp.step()
            } else {
                1e-6
            };
            eprintln!(
                "{name}: step {step:.3e} Δpos {dp:.2e} Δscale {ds:.2e} Δrot {dr:.2e} Δopacity {dop:.2e}"
            );
            assert!(
                dp <= bound(attr == "position", f32_tol),
                "{name}: Δpos {dp}"
            );
            assert!(
                ds <= bound(attr == "scale", 1e-6 * max_scale),
                "{name}: Δscale {ds}"
            );
            assert!(dr <= rot_bound, "{name}: Δrot {dr}");
            assert!(
                dop <= bound(attr == "opacity", 1e-7),
                "{name}: Δopacity {dop}"
            );
            assert_eq!(back.sh, want.sh, "{name}: SH stays float");
            khronos_validate(&mid);
            let (code, text) = splatgl(&["validate", s(&mid)]);
            assert_eq!(code, 0, "{name}: {text}");
            checked += 1;
        }
    }
    assert_eq!(checked, 8 + 2 + 4 + 2, "every non-float type the RC allows");
}

fn max_diff_extent(c: &SplatCloud) -> f64 {
    let b = c.bounds().unwrap();
    (0..3)
        .map(|j| (b.max[j] - b.min[j]) as f64)
        .fold(0.0, f64::max)
}

#[test]
fn spz_splat_and_spz_compressed_glb_outputs_load_back_within_their_quantization() {
    let d = dir("packed");
    let (input, src) = source(&d);
    // SPZ stores positions in 24-bit fixed point with 12 fractional bits (error ≤ 2^-13);
    // .splat stores them as f32 (exact). docs/formats.md has every bound.
    let half_step = 2f64.powi(-13) * 1.0001;
    for (name, extra, pos_bound) in [
        ("v2.spz", &[][..], half_step),
        ("v3.spz", &["--spz-version", "3"][..], half_step),
        ("v4.spz", &["--spz-version", "4"][..], half_step),
        ("c.splat", &[][..], 0.0),
        ("spz.glb", &["--spz-compress"][..], half_step),
    ] {
        let out = d.join(name);
        let mut args = vec!["convert", s(&input), s(&out)];
        args.extend_from_slice(extra);
        let (code, text) = splatgl(&args);
        assert_eq!(code, 0, "{name}: {text}");
        if name.ends_with(".splat") {
            assert!(text.contains("SH degrees 1..=3 dropped"), "{text}");
        }
        if name.ends_with(".glb") {
            khronos_validate(&out); // asserts 0 errors (when installed)
        }
        let back = load(&out);
        assert_eq!(back.len(), src.len(), "{name}");
        // The .glb is glTF's +Y up (--up auto): 180° about Z from the PLY's −Y.
        let want = if name.ends_with(".glb") {
            turned_about_z(&src)
        } else {
            src.clone()
        };
        let err = max_diff(&back.positions, &want.positions);
        assert!(
            err <= pos_bound,
            "{name}: position error {err} > {pos_bound}"
        );
    }
}

#[test]
fn spz_options_that_do_not_apply_are_errors() {
    let d = dir("packed-opts");
    let (input, _) = source(&d);
    for (out, flag, want) in [
        ("a.glb", "--spz-version", "applies to .spz outputs only"),
        ("b.ply", "--spz-compress", "applies to .glb outputs only"),
    ] {
        let out = d.join(out);
        let mut args = vec!["convert", s(&input), s(&out), flag];
        if flag == "--spz-version" {
            args.push("3");
        }
        let (code, text) = splatgl(&args);
        assert_eq!(code, 2, "{text}");
        assert!(text.contains(want), "{text}");
        assert!(!out.exists());
    }
}

/// `convert IN OUT.glb --camera cameras.json` embeds the views as camera nodes named after
/// `img_name`, turned with the scene: `render OUT --gltf-camera all` shows what `render IN
/// --camera cameras.json --view all` shows (≥ 50 dB per view), for a real SH-3 scene and a
/// real compressed PLY, with views of several sizes and one with fx ≠ fy.
#[test]
fn camera_nodes_reproduce_the_training_views() {
    use glam::Vec3;
    use splatgl::camera::Camera;
    let d = dir("cameras");
    for name in [
        "supersplat_fruit_drops_minimal_sh3.ply",
        "playcanvas_biker.compressed.ply",
    ] {
        let Some(input) = common::real(name) else {
            return;
        };
        let cloud = load(&input);
        let b = cloud.bounds().unwrap();
        let (c, size) = (
            Vec3::from_array(b.center()),
            Vec3::from_array(b.max) - Vec3::from_array(b.min),
        );
        let r = 1.5 * size.max_element();
        // Views in the PLY's axes (−Y up), as a trainer writes them.
        let views = [
            ("front.png", Vec3::new(0.2, -0.3, -1.0), 320, 240),
            ("side.png", Vec3::new(1.0, -0.5, 0.1), 200, 300),
            ("", Vec3::new(-0.4, -1.0, 0.6), 256, 256),
        ];
        let mut json = Vec::new();
        for (i, (img, dir, w, h)) in views.into_iter().enumerate() {
            let cam = Camera::look_at(c + r * dir.normalize(), c, -Vec3::Y, 0.8, w, h);
            let mut e = cam.to_3dgs_json(i as i64, img);
            if i == 1 {
                e["fx"] = (cam.fx * 0.9).into();
            }
            json.push(e);
        }
        let cams = d.join(format!("{name}.cameras.json"));
        std::fs::write(&cams, serde_json::to_string(&json).unwrap()).unwrap();
        let out = d.join(format!("{name}.glb"));
        let (code, text) = splatgl(&["convert", s(&input), s(&out), "--camera", s(&cams)]);
        assert_eq!(code, 0, "{text}");
        khronos_validate(&out);
        let glb = std::fs::read(&out).unwrap();
        let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + len]).unwrap();
        let names: Vec<&str> = doc["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|n| n.get("camera").is_some())
            .map(|n| n["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["front.png", "side.png", "view 2"], "{name}");
        let size = [
            "--width",
            "96",
            "--height",
            "72",
            "--backend",
            "reference",
            "-f",
        ];
        let a = d.join(format!("{name}.a_{{index}}.pfm"));
        let b = d.join(format!("{name}.b_{{index}}.pfm"));
        let from_json = [
            "render",
            s(&input),
            "--camera",
            s(&cams),
            "--view",
            "all",
            "-o",
            s(&a),
        ];
        let (code, text) = splatgl(&[&from_json[..], &size].concat());
        assert_eq!(code, 0, "{text}");
        let from_nodes = ["render", s(&out), "--gltf-camera", "all", "-o", s(&b)];
        let (code, text) = splatgl(&[&from_nodes[..], &size].concat());
        assert_eq!(code, 0, "{text}");
        for i in 0..3 {
            let at = |p: &Path| PathBuf::from(s(p).replace("{index}", &i.to_string()));
            let (x, y) = (
                splatgl::image::Image::read(at(&a)).unwrap(),
                splatgl::image::Image::read(at(&b)).unwrap(),
            );
            let psnr = splatgl::compare::compare(&x, &y, 1.0 / 255.0).unwrap().psnr;
            let lit = x
                .pixels
                .iter()
                .filter(|p| p[0] + p[1] + p[2] > 0.02)
                .count() as f64
                / x.pixels.len() as f64;
            eprintln!("{name} view {i}: {psnr:.1} dB, {:.0} % lit", 100.0 * lit);
            assert!(psnr >= 50.0, "{name} view {i}: {psnr:.1} dB");
            assert!(lit > 0.05, "{name} view {i}: the scene is not in view");
        }
    }
}

#[test]
fn camera_needs_a_gltf_output_and_a_readable_cameras_json() {
    let d = dir("cameras-errors");
    let (input, _) = source(&d);
    let (cams, out) = (d.join("cams.json"), d.join("o.ply"));
    std::fs::write(&cams, "[]").unwrap();
    let (code, text) = splatgl(&["convert", s(&input), s(&out), "--camera", s(&cams)]);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("--camera applies to .glb/.gltf outputs"),
        "{text}"
    );
    std::fs::write(&cams, r#"[{"id": 0}]"#).unwrap();
    let glb = d.join("o.glb");
    let (code, text) = splatgl(&["convert", s(&input), s(&glb), "--camera", s(&cams)]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("cams.json") && text.contains("[0]"), "{text}");
    assert!(!glb.exists() && !out.exists());
}
