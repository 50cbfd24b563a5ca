//! The command line refuses what it would otherwise ignore or get wrong: options that do not
//! apply, values out of range, outputs that cannot be written (checked before loading),
//! existing outputs without `-f`, float outputs from the 8-bit GL readback; and it writes PNG
//! to stdout with `-o -`, says PASS/FAIL in `compare`, names the file of a bad cameras.json.

use crate::common;

use std::path::PathBuf;

fn splatgl(args: &[&str]) -> (i32, Vec<u8>, String) {
    let r = common::cli::run(args);
    (r.code, r.stdout, r.stderr)
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-cli-opt-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small PLY scene in `d`.
fn ply(d: &std::path::Path) -> String {
    let p = d.join("s.ply");
    let cloud = splatgl::synthetic::random_cloud(50, 0, 1.0, 3);
    std::fs::write(&p, splatgl::write::to_inria_ply(&cloud)).unwrap();
    p.to_str().unwrap().to_owned()
}

/// Runs `args`, expects exit 2 with an `error:` line holding each of `want`, and no file at
/// `out`.
fn refused(args: &[&str], want: &[&str], out: &std::path::Path) {
    let (code, _, err) = splatgl(args);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    for w in want {
        assert!(err.contains(w), "{args:?}: expected {w:?} in {err}");
    }
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

#[test]
fn options_that_do_not_apply_are_errors_naming_the_conflict() {
    let d = dir("apply");
    let s = ply(&d);
    let out = d.join("o.png");
    let o = out.to_str().unwrap();
    let pfm = d.join("o.pfm");
    let p = pfm.to_str().unwrap();
    let base = ["render", &s, "--width", "8", "--height", "8"];
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--view", "3", "-o", o], &["--camera"]),
        (&["--depth16", "-o", p], &["--depth16", ".pfm"]),
        (
            &["--target", "rgba16f", "--backend", "reference", "-o", o],
            &["--target", "--backend reference"],
        ),
        (
            &["--scale-space", "linear", "-o", o],
            &["--scale-space", "glTF", "ply"],
        ),
        (&["--spz-axes", "raw", "-o", o], &["--spz-axes", "ply"]),
        (&["--print-camera-json", "-o", "-"], &["stdout"]),
        (&["--orbit", "4", "-o", o], &["{index}"]),
    ];
    for (extra, want) in cases {
        refused(&[&base[..], extra].concat(), want, &out);
        refused(&[&base[..], extra].concat(), want, &pfm);
    }
    // The view source decides fov and up.
    let cams = d.join("cameras.json");
    let cam = splatgl::camera::Camera::look_at(
        glam::Vec3::new(0.0, 0.0, 5.0),
        glam::Vec3::ZERO,
        glam::Vec3::Y,
        0.8,
        8,
        8,
    );
    std::fs::write(&cams, format!("[{}]", cam.to_3dgs_json(0, "x"))).unwrap();
    let c = cams.to_str().unwrap();
    refused(
        &[&base[..], &["--camera", c, "--fov", "30", "-o", o]].concat(),
        &["--fov", "--camera"],
        &out,
    );
    refused(
        &[&base[..], &["--camera", c, "--up", "z", "-o", o]].concat(),
        &["--up", "--camera"],
        &out,
    );
    // Accepted as given.
    let (code, _, err) = splatgl(&[&base[..], &["--camera", c, "--view", "0", "-o", o]].concat());
    assert_eq!(code, 0, "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn values_out_of_range_are_errors_and_negative_numbers_are_values() {
    let d = dir("range");
    let out = d.join("o.png");
    let o = out.to_str().unwrap();
    let cases: [(&[&str], &str); 8] = [
        (&["--background", "2,0,0"], "outside [0, 1]"),
        (&["--background", "-0.1,0,0"], "outside [0, 1]"),
        (&["--width", "0"], "1..=16384"),
        (&["--height", "0"], "1..=16384"),
        (&["--sh-degree", "7"], "0..=3"),
        (&["--fov", "-10"], "outside (0, 180)"),
        (&["--fov", "180"], "outside (0, 180)"),
        (&["--fov", "0"], "outside (0, 180)"),
    ];
    for (extra, want) in cases {
        let args = [&["render", "-o", o][..], extra].concat();
        let (code, _, err) = splatgl(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn typos_get_a_did_you_mean() {
    let (code, _, err) = splatgl(&["render", "--bakend", "gl"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("similar argument exists: '--backend'"),
        "{err}"
    );
    let (code, _, err) = splatgl(&["rendr"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("'render'"), "{err}");
}

/// The scene does not exist: an error about the output proves it was checked first.
#[test]
fn outputs_are_checked_before_the_scene_is_loaded() {
    let d = dir("first");
    let missing = d.join("missing.ply");
    let m = missing.to_str().unwrap();
    refused(
        &["render", m, "-o", "/nonexistent/x.png"],
        &["/nonexistent", "does not exist"],
        &missing,
    );
    refused(
        &["render", m, "-o", "x.jpg"],
        &["x.jpg", ".png or .pfm"],
        &missing,
    );
    let jpg = d.join("d.jpg");
    refused(
        &["compare", m, m, "--diff", jpg.to_str().unwrap()],
        &["d.jpg", ".png"],
        &jpg,
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn an_existing_output_is_kept_without_force() {
    let d = dir("force");
    let out = d.join("o.png");
    std::fs::write(&out, b"mine").unwrap();
    let o = out.to_str().unwrap();
    let args = [
        "render",
        "--width",
        "8",
        "--height",
        "8",
        "--backend",
        "reference",
        "-o",
        o,
    ];
    let (code, _, err) = splatgl(&args);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("exists") && err.contains("-f/--force"),
        "{err}"
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"mine");
    let (code, _, err) = splatgl(&[&args[..], &["-f"]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(splatgl::image::Image::read(&out).is_ok());
    // compare --diff likewise.
    let diff = d.join("d.png");
    std::fs::write(&diff, b"mine").unwrap();
    let (code, _, err) = splatgl(&["compare", o, o, "--diff", diff.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read(&diff).unwrap(), b"mine");
    let (code, _, err) = splatgl(&["compare", o, o, "--diff", diff.to_str().unwrap(), "-f"]);
    assert_eq!(code, 0, "{err}");
    assert!(splatgl::image::Image::read(&diff).is_ok());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn dash_output_writes_the_png_to_stdout() {
    let args = [
        "render",
        "--width",
        "12",
        "--height",
        "10",
        "--backend",
        "reference",
    ];
    let (code, png, err) = splatgl(&[&args[..], &["-o", "-"]].concat());
    assert_eq!(code, 0, "{err}");
    let img = splatgl::image::Image::decode_png(&png).expect("a PNG on stdout");
    assert_eq!((img.width, img.height), (12, 10));
    assert!(err.contains("-> stdout"), "{err}");
}

#[test]
fn float_outputs_are_never_quantized_by_the_gl_readback() {
    let d = dir("float");
    let pfm = d.join("o.pfm");
    let png = d.join("o.png");
    let (p, o) = (pfm.to_str().unwrap(), png.to_str().unwrap());
    for args in [
        vec!["render", "--backend", "gl", "-o", p],
        vec!["render", "--backend", "gl", "--depth16", "-o", o],
        vec!["render", "--target", "rgba16f", "-o", p],
    ] {
        refused(&args, &["8 bits", "quantized", "--backend reference"], &pfm);
        assert!(!png.exists());
    }
    // auto writes float files from the reference.
    let (code, _, err) = splatgl(&["render", "--width", "8", "--height", "8", "-v", "-o", p]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("backend: reference"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn compare_says_pass_or_fail_and_which_threshold_failed() {
    let d = dir("compare");
    let a = d.join("a.png");
    let b = d.join("b.png");
    use splatgl::image::{Image, PngDepth};
    Image::filled(4, 4, [0.5, 0.5, 0.5, 1.0])
        .write_png(&a, PngDepth::Eight, false)
        .unwrap();
    Image::filled(4, 4, [0.6, 0.5, 0.5, 1.0])
        .write_png(&b, PngDepth::Eight, false)
        .unwrap();
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let text = |args: &[&str]| {
        let (code, out, err) = splatgl(&[&["compare", a, b][..], args].concat());
        (code, String::from_utf8(out).unwrap() + &err)
    };
    let (code, out) = text(&["--max-abs", "0.5", "--min-psnr", "10"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("PASS"), "{out}");
    let (code, out) = text(&["--max-abs", "0.01", "--min-psnr", "10"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("FAIL") && out.contains("--max-abs 0.01"),
        "{out}"
    );
    assert!(
        !out.contains("--min-psnr 10:"),
        "only the failed one: {out}"
    );
    let (code, out) = text(&["--min-psnr", "60"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("FAIL: --min-psnr 60"), "{out}");
    let (code, out) = text(&["--min-psnr", "60", "--json"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(out.lines().next().unwrap()).unwrap();
    assert_eq!(v["pass"], false);
    assert!(
        v["failed"][0].as_str().unwrap().contains("--min-psnr"),
        "{v}"
    );
    let (code, out) = text(&["--min-psnr", "60", "-q"]);
    assert_eq!((code, out.as_str()), (1, ""));
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_bad_cameras_json_is_named_with_a_json_path() {
    let d = dir("cams");
    let cams = d.join("my-views.json");
    let out = d.join("o.png");
    let o = out.to_str().unwrap();
    for (text, path) in [("{}", "$:"), (r#"[{"id": 0}]"#, "$[0]")] {
        std::fs::write(&cams, text).unwrap();
        let (code, _, err) = splatgl(&["render", "--camera", cams.to_str().unwrap(), "-o", o]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("my-views.json") && err.contains(path), "{err}");
        assert!(!err.contains(": :"), "{err}");
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn camera_options_that_would_be_ignored_or_overflow_are_errors() {
    let d = dir("camera-ignored");
    let s = ply(&d);
    let out = d.join("o.png");
    let o = out.to_str().unwrap();
    let small = ["--width", "8", "--height", "8", "-o", o];
    // Finite points whose difference overflows f32: no NaN camera reaches a renderer.
    let far = ["render", &s, "--look-at", "-3e38,0,0,3e38,0,0"];
    refused(
        &[&far[..], &small[..]].concat(),
        &["--look-at", "too far apart"],
        &out,
    );
    // --up beside a look-at that gives its own up vector.
    let up = ["render", &s, "--look-at", "0,0,5,0,0,0,0,1,0", "--up", "z"];
    refused(
        &[&up[..], &small[..]].concat(),
        &["--up has no effect"],
        &out,
    );
    // --fov for the default scene, whose camera is fixed.
    refused(
        &[&["render", "--fov", "30"][..], &small[..]].concat(),
        &["--fov 30", "fixed camera"],
        &out,
    );
    // …but with --up the default scene is framed with it.
    let (code, _, err) =
        splatgl(&[&["render", "--fov", "30", "--up", "y"][..], &small[..]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("--fov 30"), "{err}");
    // -q has nothing to leave out of JSON.
    let (code, _, err) = splatgl(&["info", "-q", "--json", &s]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--json"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn every_orbit_frame_is_checked_before_the_first_is_rendered() {
    let d = dir("orbit-exists");
    let s = ply(&d);
    let pattern = d.join("t_{index}.png");
    std::fs::write(d.join("t_3.png"), b"keep").unwrap();
    let args = [
        "render", &s, "--orbit", "4", "--width", "8", "--height", "8",
    ];
    let (code, _, err) = splatgl(&[&args[..], &["-o", pattern.to_str().unwrap()]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("t_3.png exists"), "{err}");
    assert!(
        !d.join("t_0.png").exists(),
        "frame 0 was rendered before the check"
    );
    assert_eq!(std::fs::read(d.join("t_3.png")).unwrap(), b"keep");
    std::fs::remove_dir_all(&d).ok();
}
