//! Batch renders: `--view all` (every view of a cameras.json), `--gltf-camera all` (every
//! camera node), `--orbit N` (N frames around the framing pivot), the `{index}` output
//! pattern, and progress output (absent when stderr is not a terminal or with `--quiet`).

use crate::common;

use splatgl::image::Image;
use std::path::{Path, PathBuf};
use std::process::Command;

fn splatgl_in(cwd: &Path, args: &[&str]) -> (i32, String) {
    let r = common::cli::run_in(cwd, args);
    (r.code, r.stderr)
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-cli-batch-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ply(d: &Path) -> String {
    let p = d.join("s.ply");
    let cloud = splatgl::synthetic::random_cloud(120, 0, 1.0, 21);
    std::fs::write(&p, splatgl::write::to_inria_ply(&cloud)).unwrap();
    p.to_str().unwrap().to_owned()
}

fn pfm(d: &Path, name: &str) -> Image {
    Image::read(d.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn view_all_renders_every_view_of_a_cameras_json() {
    let d = dir("views");
    let s = ply(&d);
    let eyes = [[0.0, 0.0, 4.0], [3.0, 0.5, 3.0], [-3.0, -0.5, 3.0]];
    let entries: Vec<String> = eyes
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let c = splatgl::camera::Camera::look_at(
                glam::Vec3::from_array(*e),
                glam::Vec3::ZERO,
                -glam::Vec3::Y,
                0.9,
                24,
                18,
            );
            c.to_3dgs_json(i as i64, "v").to_string()
        })
        .collect();
    std::fs::write(d.join("cameras.json"), format!("[{}]", entries.join(","))).unwrap();
    let base = [
        "render",
        &s,
        "--backend",
        "reference",
        "--camera",
        "cameras.json",
    ];
    let (code, err) = splatgl_in(
        &d,
        &[&base[..], &["--view", "all", "-o", "v_{index}.pfm"]].concat(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(!d.join("v_3.pfm").exists());
    assert_eq!(
        err.lines().filter(|l| l.starts_with("camera: [")).count(),
        3,
        "{err}"
    );
    for i in 0..3 {
        let one = format!("one_{i}.pfm");
        let view = i.to_string();
        let (code, err) = splatgl_in(&d, &[&base[..], &["--view", &view, "-o", &one]].concat());
        assert_eq!(code, 0, "{err}");
        assert_eq!(
            pfm(&d, &format!("v_{i}.pfm")).pixels,
            pfm(&d, &one).pixels,
            "view {i}"
        );
    }
    assert_ne!(pfm(&d, "v_0.pfm").pixels, pfm(&d, "v_1.pfm").pixels);
    // A second run needs -f; the default name is out_{index}.png.
    let (code, err) = splatgl_in(
        &d,
        &[&base[..], &["--view", "all", "-o", "v_{index}.pfm"]].concat(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("v_0.pfm exists"), "{err}");
    let (code, err) = splatgl_in(&d, &[&base[..], &["--view", "all"]].concat());
    assert_eq!(code, 0, "{err}");
    assert!((0..3).all(|i| d.join(format!("out_{i}.png")).exists()));
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn gltf_camera_all_renders_every_camera_node() {
    use base64::Engine;
    let d = dir("gltf");
    let cloud = splatgl::synthetic::random_cloud(100, 0, 1.0, 22);
    let (mut doc, bin) = splatgl::write::build(&cloud, &Default::default());
    let nodes = doc["nodes"].as_array_mut().unwrap();
    let first = nodes.len();
    nodes.push(serde_json::json!({"camera": 0, "translation": [0.0, 0.0, 5.0]}));
    nodes.push(serde_json::json!({"camera": 0, "translation": [0.5, 0.0, 6.0]}));
    doc["scenes"][0]["nodes"] = serde_json::json!([0, first, first + 1]);
    doc["cameras"] = serde_json::json!([{"type": "perspective",
        "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.0}}]);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"][0]["uri"] = format!("data:application/octet-stream;base64,{b64}").into();
    std::fs::write(d.join("c.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
    let base = [
        "render",
        "c.gltf",
        "--backend",
        "reference",
        "--height",
        "16",
    ];
    let (code, err) = splatgl_in(
        &d,
        &[&base[..], &["--gltf-camera", "all", "-o", "g{index}.pfm"]].concat(),
    );
    assert_eq!(code, 0, "{err}");
    for i in 0..2 {
        let one = format!("one{i}.pfm");
        let n = i.to_string();
        let (code, err) = splatgl_in(
            &d,
            &[&base[..], &["--gltf-camera", &n, "-o", &one]].concat(),
        );
        assert_eq!(code, 0, "{err}");
        assert_eq!(
            pfm(&d, &format!("g{i}.pfm")).pixels,
            pfm(&d, &one).pixels,
            "camera {i}"
        );
    }
    assert!(!d.join("g2.pfm").exists());
    std::fs::remove_dir_all(&d).ok();
}

/// The `--look-at` eye and target of each `camera: [k]` line.
fn printed_views(err: &str) -> Vec<([f32; 3], [f32; 3])> {
    err.lines()
        .filter_map(|l| l.strip_prefix("camera: ["))
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .nth(2)
                .unwrap()
                .split(',')
                .map(|x| x.parse().unwrap())
                .collect();
            ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
        })
        .collect()
}

#[test]
fn orbit_renders_n_frames_around_the_framing_pivot() {
    let d = dir("orbit");
    let s = ply(&d);
    let base = [
        "render",
        &s,
        "--backend",
        "reference",
        "--width",
        "24",
        "--height",
        "18",
    ];
    let (code, err) = splatgl_in(
        &d,
        &[&base[..], &["--orbit", "8", "-o", "o{index}.pfm"]].concat(),
    );
    assert_eq!(code, 0, "{err}");
    let views = printed_views(&err);
    assert_eq!(views.len(), 8, "{err}");
    assert!((0..8).all(|i| d.join(format!("o{i}.pfm")).exists()));
    assert!(!d.join("o8.pfm").exists());
    // Frame 0 is the default view.
    let (code, err0) = splatgl_in(&d, &[&base[..], &["-o", "still.pfm"]].concat());
    assert_eq!(code, 0, "{err0}");
    assert_eq!(pfm(&d, "o0.pfm").pixels, pfm(&d, "still.pfm").pixels);
    // One pivot, one radius, one height along the up axis (−Y for PLY), eight angles.
    let pivot = glam::Vec3::from_array(views[0].1);
    let r0 = (glam::Vec3::from_array(views[0].0) - pivot).length();
    let mut angles = Vec::new();
    for (eye, target) in &views {
        let (e, t) = (
            glam::Vec3::from_array(*eye),
            glam::Vec3::from_array(*target),
        );
        assert!((t - pivot).length() < 1e-3 * r0, "{t} vs {pivot}");
        assert!(((e - pivot).length() - r0).abs() < 1e-3 * r0);
        assert!((e.y - views[0].0[1]).abs() < 1e-3 * r0, "height along up");
        angles.push((e.x - pivot.x).atan2(e.z - pivot.z));
    }
    for k in 1..8 {
        let step = (angles[k] - angles[k - 1]).rem_euclid(std::f32::consts::TAU);
        let want = std::f32::consts::TAU / 8.0;
        assert!(
            (step - want).abs() < 1e-3 || (step - (std::f32::consts::TAU - want)).abs() < 1e-3,
            "step {k}: {step}"
        );
    }
    assert_ne!(pfm(&d, "o0.pfm").pixels, pfm(&d, "o4.pfm").pixels);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn progress_is_absent_without_a_terminal_and_with_quiet() {
    let d = dir("progress");
    let s = ply(&d);
    let base = [
        "render",
        &s,
        "--backend",
        "reference",
        "--width",
        "16",
        "--height",
        "12",
    ];
    let orbit = ["--orbit", "3", "-f", "-o", "p{index}.png"];
    // stderr is a pipe here: no bar, no progress lines.
    let (code, err) = splatgl_in(&d, &[&base[..], &orbit].concat());
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains('\r') && !err.contains("progress"), "{err:?}");
    // --progress forces it on (one line per step) ...
    let (code, err) = splatgl_in(&d, &[&base[..], &orbit, &["--progress"]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("progress: loading"), "{err}");
    assert!(err.contains("progress: rendering 3/3"), "{err}");
    // ... and --quiet keeps stderr empty.
    let (code, err) = splatgl_in(&d, &[&base[..], &orbit, &["-q"]].concat());
    assert_eq!((code, err.as_str()), (0, ""));
    std::fs::remove_dir_all(&d).ok();
}

/// `--print-camera-json` on a batch prints one cameras.json for all of it: rendered again with
/// `--camera … --view all`, it gives the same images.
#[test]
fn a_batch_prints_one_cameras_json_that_renders_it_again() {
    let d = dir("json");
    let s = ply(&d);
    let base = [
        "render",
        &s,
        "--backend",
        "reference",
        "--width",
        "20",
        "--height",
        "16",
    ];
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(base)
        .args(["--orbit", "4", "--print-camera-json", "-o", "a{index}.pfm"])
        .current_dir(&d)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON value");
    assert_eq!(json.as_array().map(Vec::len), Some(4), "{json}");
    assert_eq!(json[2]["img_name"], "a2");
    std::fs::write(d.join("cams.json"), &out.stdout).unwrap();
    let again = [
        "--camera",
        "cams.json",
        "--view",
        "all",
        "-o",
        "b{index}.pfm",
    ];
    let (code, err) = splatgl_in(&d, &[&base[..], &again].concat());
    assert_eq!(code, 0, "{err}");
    for i in 0..4 {
        let (a, b) = (pfm(&d, &format!("a{i}.pfm")), pfm(&d, &format!("b{i}.pfm")));
        let c = splatgl::compare::compare(&a, &b, 1.0 / 255.0).unwrap();
        assert!(c.psnr > 50.0, "frame {i}: {} dB", c.psnr);
    }
    std::fs::remove_dir_all(&d).ok();
}
