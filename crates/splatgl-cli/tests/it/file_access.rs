//! Contained, bounded file access: external buffers only inside the asset's folder (or with
//! the opt-in, or through the embedder's resolver), only regular files of bounded size for
//! every path the library and the CLI open, and `Limits` that say what they stop.

use crate::common;
use common::random_cloud;
use serde_json::{Value, json};
use splatgl::load::validate::{Status, validate_path};
use splatgl::load::{LoadOptions, Severity, load_bytes, load_path};
use splatgl::write::{GltfWriteOptions, build};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::time::{Duration, Instant};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-access-{}-{name}", std::process::id()));
    // Fresh each time: a folder left by an earlier run with the same process id would hold
    // its FIFO and socket, and mkfifo / bind fail on existing names.
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `asset/scene.gltf` whose buffer is `uri`; the buffer's bytes are also returned.
fn scene_with_uri(asset: &Path, uri: &str) -> (PathBuf, Vec<u8>) {
    let (mut doc, bin) = build(&random_cloud(6, 1, 5.0, 1), &GltfWriteOptions::default());
    doc["buffers"][0]["uri"] = json!(uri);
    let p = asset.join("scene.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    (p, bin)
}

fn splatgl(args: &[&str]) -> (i32, String) {
    let r = common::cli::run(args);
    (r.code, r.all())
}

/// A folder `root` with `root/asset/` (the glTF's folder) and `root/outside.bin`.
fn layout(name: &str) -> (PathBuf, PathBuf, Vec<u8>) {
    let root = dir(name);
    let asset = root.join("asset");
    std::fs::create_dir_all(&asset).unwrap();
    let (_, bin) = scene_with_uri(&asset, "x.bin");
    std::fs::write(root.join("outside.bin"), &bin).unwrap();
    (root, asset, bin)
}

#[test]
fn escaping_uris_are_refused_by_info_render_and_validate() {
    let (root, asset, _) = layout("escape");
    let abs = root.join("outside.bin");
    for uri in ["../outside.bin", "..%2Foutside.bin", abs.to_str().unwrap()] {
        let (scene, _) = scene_with_uri(&asset, uri);
        let s = scene.to_str().unwrap();
        let (code, out) = splatgl(&["info", s]);
        assert_eq!(code, 2, "{uri}: {out}");
        assert!(
            out.contains("buffers[0].uri") && out.contains("--allow-outside-paths"),
            "{out}"
        );
        let out_png = root.join("o.png");
        let o = out_png.to_str().unwrap();
        let (code, out) = splatgl(&[
            "render",
            s,
            "--backend",
            "reference",
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            o,
        ]);
        assert_eq!(code, 2, "{uri}: {out}");
        assert!(
            out.contains("outside the asset's folder") || out.contains("absolute path"),
            "{out}"
        );
        assert!(!out_png.exists());
        let (code, out) = splatgl(&["validate", "--json", s]);
        assert_eq!(code, 1, "{uri}: {out}");
        let v: Value = serde_json::from_str(&out).unwrap();
        let f = &v["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["path"] == "buffers[0].uri")
            .expect("finding at the URI");
        assert_eq!(f["severity"], "error");
        // Accepted with the opt-in.
        let (code, out) = splatgl(&["info", "--allow-outside-paths", s]);
        assert_eq!(code, 0, "{uri}: {out}");
        let (code, out) = splatgl(&[
            "render",
            "--allow-outside-paths",
            s,
            "--backend",
            "reference",
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            o,
        ]);
        assert_eq!(code, 0, "{uri}: {out}");
        let (code, out) = splatgl(&["validate", "--allow-outside-paths", s]);
        assert_eq!(code, 0, "{uri}: {out}");
        std::fs::remove_file(&out_png).ok();
    }
    std::fs::remove_dir_all(&root).ok();
}

/// A glTF written on Windows is judged as Windows would read it, on every platform:
/// backslashes separate, a drive letter makes a path absolute.
#[test]
fn windows_style_escaping_uris_are_refused_on_every_platform() {
    let (root, asset, _) = layout("escape-windows");
    for (uri, says) in [
        ("..\\outside.bin", "outside the asset's folder"),
        ("..%5Coutside.bin", "outside the asset's folder"),
        ("sub\\..\\..\\outside.bin", "outside the asset's folder"),
        ("C:\\outside.bin", "absolute path"),
        ("C:/outside.bin", "absolute path"),
        ("\\\\server\\share\\outside.bin", "absolute path"),
    ] {
        let (scene, _) = scene_with_uri(&asset, uri);
        let (code, out) = splatgl(&["info", scene.to_str().unwrap()]);
        assert_eq!(code, 2, "{uri}: {out}");
        assert!(
            out.contains("buffers[0].uri") && out.contains(says),
            "{uri}: {out}"
        );
    }
    std::fs::remove_dir_all(&root).ok();
}

#[cfg(unix)]
#[test]
fn symlinks_are_followed_before_the_containment_check() {
    let (root, asset, bin) = layout("symlink");
    std::os::unix::fs::symlink(root.join("outside.bin"), asset.join("link.bin")).unwrap();
    let (scene, _) = scene_with_uri(&asset, "link.bin");
    let e = load_path(&scene, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside the asset's folder"), "{e}");
    let opt_in = LoadOptions {
        allow_outside_paths: true,
        ..LoadOptions::default()
    };
    assert_eq!(load_path(&scene, &opt_in).unwrap().cloud.len(), 6);
    // A link that stays inside (to a subfolder) is fine, and so is "sub/../x.bin".
    std::fs::create_dir_all(asset.join("sub")).unwrap();
    std::fs::write(asset.join("sub/real.bin"), &bin).unwrap();
    std::os::unix::fs::symlink(asset.join("sub/real.bin"), asset.join("inner.bin")).unwrap();
    for uri in ["inner.bin", "sub/../sub/real.bin"] {
        let (scene, _) = scene_with_uri(&asset, uri);
        assert_eq!(
            load_path(&scene, &LoadOptions::default())
                .unwrap()
                .cloud
                .len(),
            6,
            "{uri}"
        );
    }
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn a_resolver_serves_external_buffers_from_memory() {
    let (mut doc, bin) = build(&random_cloud(5, 0, 5.0, 2), &GltfWriteOptions::default());
    doc["buffers"][0]["uri"] = json!("mem/../../anything.bin");
    let json = serde_json::to_vec(&doc).unwrap();
    // Without a path (and without a resolver) the buffer cannot be found.
    let e = load_bytes(&json, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs the glTF file's path"), "{e}");
    let asked = Arc::new(std::sync::Mutex::new(Vec::new()));
    let log = asked.clone();
    let opts = LoadOptions {
        resolver: Some(Arc::new(move |uri: &str| {
            log.lock().unwrap().push(uri.to_owned());
            Ok(bin.clone())
        })),
        ..LoadOptions::default()
    };
    assert_eq!(load_bytes(&json, None, &opts).unwrap().cloud.len(), 5);
    assert_eq!(*asked.lock().unwrap(), ["mem/../../anything.bin"]);
    let failing = LoadOptions {
        resolver: Some(Arc::new(|_: &str| Err("not in the archive".to_owned()))),
        ..LoadOptions::default()
    };
    let e = load_bytes(&json, None, &failing).unwrap_err().to_string();
    assert!(
        e.contains("buffers[0].uri") && e.contains("not in the archive"),
        "{e}"
    );
}

/// Runs `f` on a thread and fails the test if it takes over a second (so a blocking open
/// cannot hang the suite: the thread is abandoned, the test fails).
fn within_a_second<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    let t0 = Instant::now();
    std::thread::spawn(move || tx.send(f()).ok());
    let r = rx
        .recv_timeout(Duration::from_secs(1))
        .unwrap_or_else(|_| panic!("{what}: no answer within 1 s"));
    assert!(t0.elapsed() < Duration::from_secs(1));
    r
}

/// Paths that are not regular files: `/dev/zero`, a directory, a FIFO, a socket.
fn special_files(d: &Path) -> Vec<(PathBuf, &'static str)> {
    let mut out = vec![
        (PathBuf::from("/dev/zero"), "character device"),
        (d.to_owned(), "directory"),
    ];
    #[cfg(unix)]
    {
        let fifo = d.join("fifo.ply");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path that lives through the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
        out.push((fifo, "FIFO"));
        let sock = d.join("sock.ply");
        let _listener = std::os::unix::net::UnixListener::bind(&sock).unwrap();
        std::mem::forget(_listener);
        out.push((sock, "socket"));
    }
    out
}

#[test]
fn devices_fifos_directories_and_sockets_are_errors_at_once() {
    let d = dir("special");
    for (p, kind) in special_files(&d) {
        let q = p.clone();
        let e = within_a_second("load_path", move || {
            load_path(&q, &LoadOptions::default())
                .unwrap_err()
                .to_string()
        });
        assert!(e.contains(kind) && e.contains("only regular files"), "{e}");
        let q = p.clone();
        let v = within_a_second("validate_path", move || {
            validate_path(&q, &LoadOptions::default())
        });
        assert_eq!(v.status(), Status::Unreadable);
        assert!(v.findings[0].message.contains(kind), "{:?}", v.findings);
        let q = p.clone();
        let e = within_a_second("cameras.json", move || {
            splatgl::camera::load_cameras_json(&q)
                .unwrap_err()
                .to_string()
        });
        assert!(e.contains(kind), "{e}");
        let q = p.clone();
        let e = within_a_second("image", move || {
            splatgl::image::Image::read(&q).unwrap_err().to_string()
        });
        assert!(e.contains(kind), "{e}");
        // The CLI, as a child process killed if it hangs.
        let mut child = Command::new(env!("CARGO_BIN_EXE_splatgl"))
            .args(["info", p.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let t0 = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if t0.elapsed() > Duration::from_secs(5) {
                child.kill().ok();
                panic!("splatgl info {} hangs", p.display());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains(kind));
    }
    let scene = d.join("s.ply");
    std::fs::write(
        &scene,
        splatgl::write::to_inria_ply(&random_cloud(2, 0, 5.0, 3)),
    )
    .unwrap();
    let s = scene.to_str().unwrap();
    // (An output that can be written: outputs are checked before any input is read.)
    let png = d.join("never-written.png");
    for (p, kind) in special_files(&dir("special-cli")) {
        let (code, out) = splatgl(&[
            "render",
            s,
            "--camera",
            p.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ]);
        assert!(code == 2 && out.contains(kind), "{out}");
        let (code, out) = splatgl(&["compare", p.to_str().unwrap(), p.to_str().unwrap()]);
        assert!(code == 2 && out.contains(kind), "{out}");
        let out_glb = d.join("out.glb");
        let (code, out) = splatgl(&["convert", p.to_str().unwrap(), out_glb.to_str().unwrap()]);
        assert!(code == 2 && out.contains(kind), "{out}");
        assert!(!out_glb.exists());
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn conformance_inputs_are_regular_files_inside_the_suite() {
    let d = dir("suite");
    // A FIFO as manifest.json: an error at once, not a blocked read.
    let fifo = d.join("fifo");
    std::fs::create_dir_all(&fifo).unwrap();
    let c = std::ffi::CString::new(fifo.join("manifest.json").to_str().unwrap()).unwrap();
    // SAFETY: a NUL-terminated path that lives through the call.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
    let f = fifo.to_str().unwrap().to_owned();
    let (code, out) = within_a_second("conformance run", move || {
        splatgl(&["conformance", "run", &f, "--backend", "reference"])
    });
    assert!(code == 2 && out.contains("FIFO"), "{out}");
    // A manifest naming an asset outside its folder.
    let suite = d.join("escape");
    std::fs::create_dir_all(&suite).unwrap();
    splatgl::write::save(&random_cloud(3, 0, 5.0, 5), &d.join("outside.glb"), &[]).unwrap();
    let manifest = serde_json::json!({
        "generator": "test", "background": [0, 0, 0],
        "rules_version": splatgl_conformance::manifest::RULES_VERSION,
        "assets": [{"name": "a", "file": "../outside.glb", "cameras_json": "a.json",
            "rule": "r", "rc_section": "s", "failure_means": "f", "catches": [],
            "cameras": []}]
    });
    std::fs::write(suite.join("manifest.json"), manifest.to_string()).unwrap();
    let (code, out) = splatgl(&[
        "conformance",
        "run",
        suite.to_str().unwrap(),
        "--backend",
        "reference",
    ]);
    assert!(
        code == 2 && out.contains("../outside.glb") && out.contains("outside the asset's folder"),
        "{out}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn limits_are_enforced_named_and_printed() {
    let d = dir("limits");
    let scene = d.join("s.ply");
    std::fs::write(
        &scene,
        splatgl::write::to_inria_ply(&random_cloud(20, 0, 5.0, 4)),
    )
    .unwrap();
    let s = scene.to_str().unwrap();
    let (code, out) = splatgl(&["info", "--max-splats", "19", s]);
    assert_eq!(code, 2);
    assert!(
        out.contains("20 splats exceed limits.max_splats = 19 (raise with --max-splats)"),
        "{out}"
    );
    let (code, out) = splatgl(&["info", "--max-bytes", "1K", s]);
    assert_eq!(code, 2);
    assert!(out.contains("more than the limit of 1024 bytes"), "{out}");
    let (code, out) = splatgl(&["info", "-v", "--max-splats", "20", "--max-bytes", "2M", s]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("max_splats              20")
            && out.contains("max_bytes               2097152"),
        "{out}"
    );
    let (code, out) = splatgl(&["validate", "-v", s]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("max_bytes               4294967296"), "{out}");
    let (code, out) = splatgl(&["validate", "-v", "--json", s]);
    assert_eq!(code, 0, "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["limits"]["max_json_depth"], 64);
    let (code, out) = splatgl(&["info", "-v", "--json", s]);
    assert_eq!(code, 0, "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["limits"]["max_json_depth"], 64);
    assert_eq!(v["limits"]["max_decompressed_bytes"], 4u64 << 30);
    // JSON nesting is checked before serde_json sees it.
    let deep = format!(
        "{{\"asset\": {{\"version\": \"2.0\"}}, \"extras\": {}{}}}",
        "[".repeat(70),
        "]".repeat(70)
    );
    let e = load_bytes(
        deep.as_bytes(),
        Some(Path::new("d.gltf")),
        &LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("limits.max_json_depth = 64"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn json_of_millions_of_values_is_refused_before_parsing_with_the_limit_named() {
    let d = dir("json_values");
    // 8 million empty nodes (24 MB): parsed, ~3.5 GB; refused before the parse.
    let nodes = format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"nodes\":[{}]}}",
        vec!["{}"; 8_000_000].join(",")
    );
    let gltf = d.join("nodes.gltf");
    std::fs::write(&gltf, &nodes).unwrap();
    let tileset = d.join("tileset.json");
    let tiles = vec![r#"{"geometricError":0}"#; 600_000].join(",");
    std::fs::write(
        &tileset,
        format!(r#"{{"asset":{{"version":"1.1"}},"geometricError":1,"root":{{"geometricError":1,"children":[{tiles}]}}}}"#),
    )
    .unwrap();
    for (file, cmd) in [
        (&gltf, "info"),
        (&gltf, "validate"),
        (&tileset, "info"),
        (&tileset, "validate"),
    ] {
        let (code, out) = splatgl(&[cmd, file.to_str().unwrap()]);
        assert_ne!(code, 0, "{cmd} {}: {out}", file.display());
        assert!(
            out.contains("limits.max_json_values = 1048576") && out.contains("--max-json-values"),
            "{cmd} {}: {out}",
            file.display()
        );
    }
    // Raised, the tileset parses (and is judged on its content).
    let (_, out) = splatgl(&[
        "validate",
        tileset.to_str().unwrap(),
        "--max-json-values",
        "4000000",
    ]);
    assert!(!out.contains("max_json_values"), "{out}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn external_buffers_count_against_max_bytes() {
    let (root, asset, bin) = layout("bytes");
    std::fs::write(asset.join("x.bin"), &bin).unwrap();
    let (scene, _) = scene_with_uri(&asset, "x.bin");
    let json = std::fs::read(&scene).unwrap();
    let limited = |max_bytes: u64| LoadOptions {
        limits: splatgl::load::Limits {
            max_bytes,
            ..Default::default()
        },
        ..LoadOptions::default()
    };
    // The bytes given to load_bytes are the caller's; only the buffer file is counted.
    let exact = bin.len() as u64;
    assert!(load_bytes(&json, Some(&scene), &limited(exact)).is_ok());
    let v = splatgl::load::validate::validate_bytes(&json, Some(&scene), &limited(exact - 1));
    let f = v
        .findings
        .iter()
        .find(|f| f.path == "buffers[0].uri")
        .expect("finding");
    assert!(
        f.severity == Severity::Error && f.message.contains("limits.max_bytes"),
        "{f}"
    );
    std::fs::remove_dir_all(&root).ok();
}

#[test]
fn scenes_can_come_from_standard_input_within_the_byte_limit() {
    let ply = splatgl::write::to_inria_ply(&random_cloud(20, 1, 5.0, 8));
    let run = |args: &[&str]| {
        use std::io::Write;
        let mut child = Command::new(env!("CARGO_BIN_EXE_splatgl"))
            .args(args)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // The reader may stop early (over the limit): a broken pipe is its answer, not ours.
        let _ = child.stdin.take().unwrap().write_all(&ply);
        let out = child.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        (out.status.code().unwrap_or(-1), text)
    };
    let (code, out) = run(&["info", "--json", "-"]);
    assert_eq!(code, 0, "{out}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (v["splat_count"].as_u64(), v["sh_degree"].as_u64()),
        (Some(20), Some(1))
    );
    let (code, out) = run(&["info", "--max-bytes", "1K", "-"]);
    assert_eq!(code, 2, "{out}");
    assert!(out.contains("more than the limit of 1024 bytes"), "{out}");
}

#[test]
fn mapped_and_read_scene_files_load_the_same_cloud() {
    let d = dir("mapped");
    let p = d.join("m.ply");
    let cloud = random_cloud(3000, 3, 5.0, 9);
    std::fs::write(&p, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let mapped = splatgl::files::map_bounded(&p, 1 << 30, "the scene file").unwrap();
    assert!(mapped.is_mapped());
    let from_map = load_bytes(&mapped, Some(&p), &LoadOptions::default()).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    let from_read = load_bytes(&bytes, Some(&p), &LoadOptions::default()).unwrap();
    // The mapped load released its pages as it went; the mapping still reads the file.
    assert_eq!(&mapped[..], &bytes[..]);
    assert_eq!(from_map.cloud, from_read.cloud);
    assert_eq!(
        load_path(&p, &LoadOptions::default()).unwrap().cloud,
        from_read.cloud
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn compare_reads_images_within_its_byte_limit() {
    let d = dir("compare-limit");
    let img = splatgl::image::Image {
        width: 64,
        height: 64,
        pixels: (0..64 * 64)
            .map(|i| [(i % 251) as f32 / 250.0, 0.5, 0.25, 1.0])
            .collect(),
    };
    let p = d.join("a.pfm");
    img.write_pfm(&p).unwrap();
    let s = p.to_str().unwrap();
    let (code, out) = splatgl(&["compare", s, s]);
    assert_eq!(code, 0, "{out}");
    let (code, out) = splatgl(&["compare", "--max-bytes", "1K", s, s]);
    assert_eq!(code, 2, "{out}");
    assert!(out.contains("more than the limit of 1024 bytes"), "{out}");
    std::fs::remove_dir_all(&d).ok();
}
