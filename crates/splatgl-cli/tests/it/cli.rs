//! The command line: `info` and `validate` JSON keys (a contract for users' scripts) and exit
//! codes, `render` with both backends and from a glTF camera, `compare`, and errors reported as
//! messages, not panics.

use crate::common;
use splatgl::image::Image;

fn splatgl(args: &[&str]) -> (i32, String, String) {
    let r = common::cli::run(args);
    (r.code, r.out(), r.stderr)
}

fn tmp(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("splatgl-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn validate_exit_codes() {
    let cloud = common::random_cloud(10, 2, 5.0, 1);
    let good = tmp(
        "good.glb",
        &splatgl::write::to_glb(&cloud, &Default::default()),
    );
    let (code, out, _) = splatgl(&["validate", good.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    let bad = tmp("bad.gltf", br#"{"asset":{"version":"2.0"}}"#);
    let (code, out, _) = splatgl(&["validate", "--json", bad.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["valid"], false);
    assert!(v["findings"][0]["path"].is_string());
    let junk = tmp("junk.glb", b"glTF\x02\0\0\0\xff\xff");
    let (code, _, _) = splatgl(&["validate", junk.to_str().unwrap()]);
    assert_eq!(code, 2);
    let (code, _, _) = splatgl(&["validate", "/nonexistent/file.ply"]);
    assert_eq!(code, 2);
}

#[test]
fn info_json_keys() {
    let cloud = common::random_cloud(33, 1, 5.0, 2);
    let p = tmp("c.ply", &splatgl::write::to_inria_ply(&cloud));
    let (code, out, err) = splatgl(&["info", "--json", p.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for key in [
        "format",
        "splat_count",
        "sh_degree",
        "color_space",
        "bounds_min",
        "bounds_max",
        "warnings",
    ] {
        assert!(v.get(key).is_some(), "key {key} in {v}");
    }
    assert_eq!(v["format"], "ply");
    assert_eq!(v["splat_count"], 33);
    assert_eq!(v["sh_degree"], 1);
    assert_eq!(v["scale_space"], "log");
    let (code, _, err) = splatgl(&["info", "/nonexistent.glb"]);
    assert_eq!(code, 2);
    assert!(err.contains("nonexistent.glb"), "{err}");
}

/// `info` on quantized containers: the container keys (`container`, `container_version`,
/// `compression`, `gltf_extension`, `quantization`, `lossy`, `antialiased`) in `--json`, null
/// for plain files, and the same facts as text; `validate` takes the SPZ-compressed `.glb` as
/// valid, and `--spz-axes` is accepted by both.
#[test]
fn info_reports_the_container_and_validate_accepts_spz_compression() {
    let cloud = common::random_cloud(20, 1, 5.0, 4);
    let o = splatgl::write::SpzWriteOptions {
        version: splatgl::write::SpzVersion::V3,
        antialiased: true,
        ..Default::default()
    };
    let spz = tmp("c.spz", &splatgl::write::to_spz_with(&cloud, &o).unwrap());
    let glb = tmp("c_spz.glb", &splatgl::write::to_glb_spz(&cloud).unwrap());
    let ply = tmp("plain.ply", &splatgl::write::to_inria_ply(&cloud));
    let json = |p: &std::path::Path| -> serde_json::Value {
        let (code, out, err) = splatgl(&["info", "--json", p.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str(&out).unwrap()
    };
    let v = json(&spz);
    assert_eq!(v["format"], "spz");
    assert_eq!(v["container"], "spz");
    assert_eq!(v["container_version"], "3");
    assert_eq!(v["compression"], "gzip");
    assert_eq!(v["gltf_extension"], serde_json::Value::Null);
    assert_eq!(v["antialiased"], true);
    let q = v["quantization"].as_array().unwrap();
    let bits = |a: &str| {
        q.iter()
            .find(|e| e["attribute"] == a)
            .map(|e| e["bits"].clone())
    };
    assert_eq!(bits("position"), Some(serde_json::json!(24)));
    assert_eq!(bits("rotation"), Some(serde_json::json!(10)));
    assert_eq!(bits("sh"), Some(serde_json::json!(8)));
    assert!(!v["lossy"].as_array().unwrap().is_empty());
    let v = json(&glb);
    assert_eq!(v["format"], "glb");
    assert_eq!(v["container_version"], "2");
    assert_eq!(
        v["gltf_extension"],
        "KHR_gaussian_splatting_compression_spz_2"
    );
    assert_eq!(v["antialiased"], false);
    let v = json(&ply);
    for key in [
        "container",
        "container_version",
        "quantization",
        "lossy",
        "antialiased",
    ] {
        assert_eq!(v[key], serde_json::Value::Null, "{key} of a plain PLY");
    }
    let (code, out, _) = splatgl(&["info", spz.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(out.contains("container:      spz v3, gzip"), "{out}");
    assert!(out.contains("antialiased:    yes"), "{out}");
    assert!(out.contains("position  24 bits"), "{out}");
    let (code, out, _) = splatgl(&["validate", "--spz-axes", "raw", glb.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    let (code, out, _) = splatgl(&["validate", "--json", glb.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (v["status"].as_str(), v["splat_count"].as_u64()),
        (Some("valid"), Some(20))
    );
    let (code, _, err) = splatgl(&["info", "--spz-axes", "sideways", spz.to_str().unwrap()]);
    assert_eq!(code, 2, "clap's usage error");
    assert!(err.contains("expected auto, rub or raw"), "{err}");
}

/// Both backends show a `lin_rec709_display` cloud the same way: blended in linear, encoded
/// to sRGB once at the end, over a background given in display values.
#[test]
fn backends_agree_on_linear_colour_space() {
    let mut cloud = splatgl::synthetic::default_scene();
    cloud.meta.color_space =
        splatgl::cloud::Known::Known(splatgl::cloud::ColorSpace::LinRec709Display);
    let scene = tmp(
        "lin.glb",
        &splatgl::write::to_glb(&cloud, &Default::default()),
    );
    let out = |b: &str| tmp(&format!("lin-{b}.png"), b"");
    let common = [
        "--look-at",
        "0,2,5,0,0,0",
        "--width",
        "96",
        "--height",
        "72",
        "--background",
        "0.2,0.3,0.4",
    ];
    // (The outputs exist, made by `tmp`: -f.)
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--backend",
        "reference",
        "-f",
        "-o",
    ];
    let r = out("reference");
    args.push(r.to_str().unwrap());
    args.extend(common);
    let (code, _, err) = splatgl(&args);
    assert_eq!(code, 0, "{err}");
    let g = out("gl");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--backend",
        "gl",
        "-f",
        "-o",
        g.to_str().unwrap(),
    ];
    args.extend(common);
    let (code, _, err) = splatgl(&args);
    if code != 0 && err.contains("EGL unavailable") {
        common::skip(&format!("the GL half: {err}"));
        return;
    }
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = splatgl(&[
        "compare",
        g.to_str().unwrap(),
        r.to_str().unwrap(),
        "--min-psnr",
        "40",
        "--json",
    ]);
    assert_eq!(code, 0, "{out} {err}");
    // The background is the display value given, in both.
    let img = splatgl::image::Image::read(&r).unwrap();
    let px = img.get(0, 0);
    assert!(
        (px[0] - 0.2).abs() < 1.0 / 255.0 && (px[2] - 0.4).abs() < 1.0 / 255.0,
        "{px:?}"
    );
}

/// `render --gltf-camera N` takes the view from the N-th camera node of the file it loaded:
/// the image equals the reference render from that camera, and a missing index is an error
/// that says how many cameras there are.
#[test]
fn render_takes_the_view_from_a_gltf_camera_node() {
    use base64::Engine;
    let cloud = common::random_cloud(200, 1, 5.0, 7);
    let (mut doc, bin) = splatgl::write::build(&cloud, &Default::default());
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"camera": 0, "translation": [0.3, 0.2, 6.0]}));
    doc["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
    doc["cameras"] = serde_json::json!([{"type": "perspective",
        "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}]);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    doc["buffers"][0]["uri"] = format!("data:application/octet-stream;base64,{b64}").into();
    let scene = tmp("cam.gltf", &serde_json::to_vec(&doc).unwrap());
    let out = tmp("cam.pfm", b"");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let args = [
        "render",
        s,
        "--gltf-camera",
        "0",
        "--backend",
        "reference",
        "-f",
    ];
    let (code, _, err) = splatgl(&[&args[..], &["--height", "40", "-o", o]].concat());
    assert_eq!(code, 0, "{err}");
    let img = splatgl::image::Image::read(&out).unwrap();
    assert_eq!(
        (img.width, img.height),
        (60, 40),
        "width from the aspect ratio"
    );

    let loaded = splatgl::load::load_path(&scene, &Default::default()).unwrap();
    assert_eq!(loaded.cameras.len(), 1);
    let cam = splatgl::camera::Camera::from_gltf(&loaded.cameras[0], 60, 40).unwrap();
    let want = splatgl::reference::render(&loaded.cloud, &cam, &Default::default());
    let rgb = |p: &[f32; 4]| [p[0], p[1], p[2]];
    assert!(
        want.pixels.iter().any(|p| p[3] > 0.0),
        "the camera sees the splats"
    );
    assert!(
        img.pixels.iter().map(rgb).eq(want.pixels.iter().map(rgb)),
        "same image as the reference from that camera"
    );

    let (code, _, err) = splatgl(&[&args[..2], &["-f", "--gltf-camera", "1", "-o", o]].concat());
    assert_eq!(code, 2);
    assert!(err.contains("1 perspective camera node"), "{err}");
}

#[test]
fn renders_the_default_scene_and_compares() {
    let dir = std::env::temp_dir().join(format!("splatgl-cli-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (png, pfm, png16) = (dir.join("a.png"), dir.join("a.pfm"), dir.join("b.png"));
    let p = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    let size = ["--width", "64", "--height", "48"];
    for (out, extra) in [(&png, None), (&pfm, None), (&png16, Some("--depth16"))] {
        let mut args = vec!["render", "--backend", "reference", "-o"];
        let out = p(out);
        args.push(&out);
        args.extend(size);
        args.extend(extra);
        let (code, _, err) = splatgl(&args);
        assert_eq!(code, 0, "{err}");
        assert!(
            err.contains("splats") && err.contains("ms"),
            "progress line: {err}"
        );
    }
    let a = Image::read(&png).unwrap();
    let f = Image::read(&pfm).unwrap();
    assert_eq!((a.width, a.height), (64, 48));
    // The 8-bit PNG is the float image quantised.
    for (q, x) in a.pixels.iter().zip(&f.pixels) {
        for c in 0..3 {
            assert!((q[c] - x[c].clamp(0.0, 1.0)).abs() <= 0.5 / 255.0 + 1e-6);
        }
    }
    let (code, out, _) = splatgl(&["compare", &p(&pfm), &p(&pfm), "--json", "--max-abs", "0"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["identical"], true);
    let diff = p(&dir.join("d.png"));
    let (code, out, _) = splatgl(&[
        "compare",
        &p(&png),
        &p(&png16),
        "--diff",
        &diff,
        "--max-abs",
        "0",
    ]);
    assert_eq!(code, 1, "8- and 16-bit quantisations differ: {out}");
    assert!(Image::read(&diff).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn errors_are_reported_not_panics() {
    let cases: [&[&str]; 5] = [
        &["render", "--look-at", "1,2,3", "-o", "x.png"],
        &["render", "--gltf-camera", "0", "-o", "x.png"],
        &["render", "-o", "x.jpg", "--width", "8", "--height", "8"],
        &["render", "/nonexistent/scene.ply"],
        &["compare", "/nonexistent/a.png", "/nonexistent/b.png"],
    ];
    for args in cases {
        let (code, _, err) = splatgl(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}

/// The `camera:` line `render` prints on stderr, pasted back, renders the same image; and
/// `--print-camera-json` writes a cameras.json that does too.
#[test]
fn printed_camera_renders_the_same_image() {
    let cloud = splatgl::synthetic::random_cloud(300, 1, 1.0, 11);
    let ply = tmp("printed.ply", &splatgl::write::to_inria_ply(&cloud));
    let dir = ply.parent().unwrap().to_owned();
    let out = |n: &str| dir.join(n).to_str().unwrap().to_owned();
    let base = ["render", ply.to_str().unwrap(), "--backend", "reference"];
    let size = ["--width", "80", "--height", "60"];
    let (code, json, err) = splatgl(
        &[
            &base[..],
            &size,
            &["--print-camera-json", "-o", &out("a.pfm")],
        ]
        .concat(),
    );
    assert_eq!(code, 0, "{err}");
    let line = err
        .lines()
        .find_map(|l| l.strip_prefix("camera: "))
        .expect("camera line");
    let pasted: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(pasted[0], "--look-at");
    let (code, _, err) = splatgl(&[&base[..], &pasted, &["-o", &out("b.pfm")]].concat());
    assert_eq!(code, 0, "{err}");
    let cams = tmp("printed-cameras.json", json.trim().as_bytes());
    let c = ["--camera", cams.to_str().unwrap(), "-o"];
    let (code, _, err) = splatgl(&[&base[..], &c, &[&out("c.pfm")]].concat());
    assert_eq!(code, 0, "{err}");
    let a = Image::read(out("a.pfm")).unwrap();
    for other in ["b.pfm", "c.pfm"] {
        let b = Image::read(out(other)).unwrap();
        let s = splatgl::compare::compare(&a, &b, 1.0 / 255.0).unwrap();
        assert!(s.psnr > 50.0, "{other}: {} dB", s.psnr);
    }
}

/// `--look-at` without an up vector takes the scene's up axis: −Y for PLY (as the automatic
/// framing does), or the `--up` given.
#[test]
fn look_at_default_up_is_the_up_axis() {
    let cloud = splatgl::synthetic::random_cloud(200, 0, 1.0, 12);
    let ply = tmp("up.ply", &splatgl::write::to_inria_ply(&cloud));
    let dir = ply.parent().unwrap().to_owned();
    let render = |extra: &[&str], name: &str| {
        let o = dir.join(name);
        let args = ["render", ply.to_str().unwrap(), "--backend", "reference"];
        let size = ["--width", "40", "--height", "30", "-o", o.to_str().unwrap()];
        let (code, _, err) = splatgl(&[&args[..], &size, extra].concat());
        assert_eq!(code, 0, "{err}");
        Image::read(&o).unwrap()
    };
    let auto = render(&["--look-at", "0.3,0.2,4,0,0,0"], "auto.pfm");
    let minus_y = render(&["--look-at", "0.3,0.2,4,0,0,0,0,-1,0"], "my.pfm");
    let plus_y = render(&["--look-at", "0.3,0.2,4,0,0,0", "--up", "y"], "py.pfm");
    let y_given = render(&["--look-at", "0.3,0.2,4,0,0,0,0,1,0"], "yg.pfm");
    assert_eq!(auto.pixels, minus_y.pixels);
    assert_eq!(plus_y.pixels, y_given.pixels);
    assert_ne!(auto.pixels, plus_y.pixels);
}
