//! The Windows build, run here: `splatgl.exe`, `splatgl.dll` and the C legacy host that
//! `scripts/windows/build.sh` cross-builds with mingw-w64, run under Wine on a virtual X server
//! (Wine's WGL draws through the X server's GLX: Mesa llvmpipe), held to the Linux build's
//! images. Paths reach the Windows programs as Windows writes them: `Z:\…` with backslashes.
//!
//! Without the staged build (`target/windows/debug`) or `wine64` these skip, which fails under
//! `SPLATGL_REQUIRE=all` (the slow lane of `scripts/test.sh` builds it first).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use splatgl::image::Image;
use splatgl::write::{GltfWriteOptions, build};

use crate::common;
use crate::common::random_cloud;
use crate::common::viewer::{self, CAMERA, Viewer, X};

/// The staged Windows build, or `None` (skipped) when it or Wine is missing.
fn staged() -> Option<PathBuf> {
    let dir = common::target_tmp().join("../windows/debug");
    let wine = Path::new("/usr/lib/wine/wine64").is_file() || viewer::on_path("wine64");
    if !dir.join("splatgl.exe").is_file() || !wine {
        common::skip(&format!(
            "the Windows build: {} or wine64 missing (scripts/windows/build.sh; .ci/run installs \
             wine64 and mingw-w64)",
            dir.join("splatgl.exe").display()
        ));
        return None;
    }
    Some(dir)
}

/// `path` as a Windows program under Wine names it: drive `Z:` is `/`.
fn win(path: &Path) -> String {
    format!("Z:{}", path.display()).replace('/', "\\")
}

/// `scripts/windows/wine.sh exe args…` on `x`'s display.
fn wine_command(x: &X, exe: &Path, args: &[&str]) -> Command {
    let mut cmd = Command::new(common::root().join("scripts/windows/wine.sh"));
    cmd.arg(exe).args(args);
    x.client(&mut cmd);
    cmd
}

fn run(cmd: &mut Command) -> (Output, String) {
    let o = cmd.output().expect("scripts/windows/wine.sh runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o, text)
}

/// Renders `scene` with the Linux command and with `splatgl.exe` under Wine (same options)
/// and returns both images.
fn both_renders(x: &X, dir: &Path, scene: &Path, backend: &str) -> (Image, Image) {
    let tmp = common::fresh_dir("windows", backend);
    let name = scene.file_name().unwrap().to_string_lossy().into_owned();
    let (linux_png, windows_png) = (
        tmp.join(format!("{name}-linux.png")),
        tmp.join(format!("{name}-windows.png")),
    );
    let opts = ["--backend", backend, "--width", "320", "--height", "240"];
    let (o, text) = run(Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .arg("render")
        .arg(scene)
        .args(opts)
        .arg("-o")
        .arg(&linux_png));
    assert!(o.status.success(), "Linux render: {text}");
    let (scene_w, out_w) = (win(scene), win(&windows_png));
    let args = [&["render", &scene_w][..], &opts, &["-o", &out_w]].concat();
    let (o, text) = run(&mut wine_command(x, &dir.join("splatgl.exe"), &args));
    assert!(o.status.success(), "splatgl.exe render: {text}");
    eprintln!("splatgl.exe: {}", text.trim());
    (
        Image::read(&linux_png).unwrap(),
        Image::read(&windows_png).unwrap(),
    )
}

#[test]
fn windows_render_matches_the_linux_render_with_both_backends() {
    let Some(dir) = staged() else { return };
    let scenes: Option<Vec<PathBuf>> = [
        "supersplat_fruit_drops_minimal_sh3.ply",
        "playcanvas_biker.compressed.ply",
    ]
    .into_iter()
    .map(common::real)
    .collect();
    let Some(scenes) = scenes else { return };
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let x = viewer::x_server();
    for scene in &scenes {
        for (backend, min_db) in [("reference", 60.0), ("gl", 45.0)] {
            let (linux, windows) = both_renders(&x, &dir, scene, backend);
            let db = viewer::psnr(&linux, &windows);
            eprintln!("{} --backend {backend}: {db:.1} dB", scene.display());
            assert!(
                db >= min_db,
                "{} --backend {backend}: Windows vs Linux {db:.1} dB < {min_db}",
                scene.display()
            );
        }
    }
}

#[test]
fn windows_viewer_window_matches_the_headless_render() {
    let Some(dir) = staged() else { return };
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let cwd = viewer::dir("windows");
    let Some(headless) = viewer::reference(&cwd, &[]) else {
        return;
    };
    let x = viewer::x_server();
    let args = [&["view", "--no-ui"][..], &CAMERA].concat();
    let mut v = Viewer::start_command(&x, &cwd, wine_command(&x, &dir.join("splatgl.exe"), &args));
    // The screenshot (`P`) is read back from a drawn frame; the window shows it once Wine has
    // presented it, so a capture still blank (one colour) is taken again, for up to 10 s.
    let shot = v.screenshot(&cwd);
    let mut window = v.capture(&x, &cwd, "windows-capture.png");
    for _ in 0..20 {
        if window.pixels.iter().any(|p| *p != window.pixels[0]) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(500));
        window = v.capture(&x, &cwd, "windows-capture.png");
    }
    v.quit();
    for (what, img) in [("window capture", &window), ("P screenshot", &shot)] {
        let db = viewer::psnr(&headless, img);
        eprintln!("splatgl.exe view --no-ui, {what}: {db:.1} dB against the headless render");
        assert!(db >= 40.0, "{what}: {db:.1} dB < 40");
    }
}

#[test]
fn windows_legacy_c_host_draws_splats_and_keeps_its_state() {
    let Some(dir) = staged() else { return };
    let tmp = common::fresh_dir("windows", "legacy-host");
    let wall = tmp.join("wall.ply");
    common::write_legacy_host_wall(&wall);
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let x = viewer::x_server();
    let wall_w = win(&wall);
    let (o, text) = run(&mut wine_command(
        &x,
        &dir.join("legacy_host.exe"),
        &[&wall_w],
    ));
    eprintln!("{text}");
    assert!(o.status.success(), "legacy_host.exe failed: {text}");
    assert!(
        text.contains("state pieces checked") && text.contains("ok"),
        "{text}"
    );
}

/// A glTF whose buffer URI escapes its folder the Windows way is refused by `splatgl.exe`,
/// and loads with `--allow-outside-paths` (so the refusal was the rule's, not a path Windows
/// could not open).
#[test]
fn windows_refuses_a_gltf_whose_uri_escapes_with_backslashes() {
    let Some(dir) = staged() else { return };
    let tmp = common::fresh_dir("windows", "escape");
    let asset = tmp.join("asset");
    std::fs::create_dir_all(&asset).unwrap();
    let (mut doc, bin) = build(&random_cloud(6, 1, 5.0, 1), &GltfWriteOptions::default());
    std::fs::write(tmp.join("outside.bin"), &bin).unwrap();
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let x = viewer::x_server();
    let exe = dir.join("splatgl.exe");
    let absolute = win(&tmp.join("outside.bin"));
    for (uri, says) in [
        ("..\\outside.bin", "outside the asset's folder"),
        (absolute.as_str(), "absolute path"),
    ] {
        doc["buffers"][0]["uri"] = serde_json::json!(uri);
        let scene = asset.join("scene.gltf");
        std::fs::write(&scene, serde_json::to_vec(&doc).unwrap()).unwrap();
        let scene_w = win(&scene);
        let (o, text) = run(&mut wine_command(&x, &exe, &["info", &scene_w]));
        assert_eq!(o.status.code(), Some(2), "{uri}: {text}");
        assert!(text.contains(says), "{uri}: {text}");
        let (o, text) = run(&mut wine_command(
            &x,
            &exe,
            &["info", "--allow-outside-paths", &scene_w],
        ));
        assert!(
            o.status.success(),
            "{uri} with --allow-outside-paths: {text}"
        );
    }
}

/// Windows file semantics: a second render replaces the first output (the atomic write's
/// rename onto an existing file), and `-o -` writes the PNG's bytes to standard output
/// unchanged (no text-mode line-end translation).
#[test]
fn windows_output_replaces_an_existing_file_and_stdout_is_binary() {
    let Some(dir) = staged() else { return };
    let tmp = common::fresh_dir("windows", "output");
    let out = tmp.join("out.png");
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let x = viewer::x_server();
    let exe = dir.join("splatgl.exe");
    let out_w = win(&out);
    let render = |width: &str, o: &str| {
        let args = [
            "render",
            "--backend",
            "reference",
            "--width",
            width,
            "--height",
            "24",
            "-f",
            "-o",
            o,
        ];
        run(&mut wine_command(&x, &exe, &args))
    };
    std::fs::write(&out, b"an older file").unwrap();
    for width in ["32", "40"] {
        let (o, text) = render(width, &out_w);
        assert!(o.status.success(), "{text}");
        let img = Image::read(&out).unwrap_or_else(|e| panic!("{e}: {text}"));
        assert_eq!(img.width.to_string(), width, "the output was not replaced");
    }
    let (o, text) = render("40", "-");
    assert!(o.status.success(), "{text}");
    assert_eq!(
        o.stdout,
        std::fs::read(&out).unwrap(),
        "-o - differs from the file"
    );
}

/// `O` in the viewer opens Windows' common Open dialog; a path typed there is loaded.
#[test]
fn windows_viewer_opens_the_file_chosen_in_the_open_dialog() {
    let Some(dir) = staged() else { return };
    let Some(scene) = common::real("jsplat_unitCube-ascii.ply") else {
        return;
    };
    let _x_lock = viewer::X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let cwd = viewer::dir("windows-dialog");
    let x = viewer::x_server();
    let args = [&["view", "--no-ui"][..], &CAMERA].concat();
    let mut v = Viewer::start_command(&x, &cwd, wine_command(&x, &dir.join("splatgl.exe"), &args));
    v.key("o");
    let ids = v.xdo(&["search", "--sync", "--name", "^Open a splat file"]);
    let dialog = ids.lines().next().expect("the Open dialog").to_owned();
    v.xdo(&["windowfocus", "--sync", &dialog]);
    v.xdo(&["type", "--delay", "20", &win(&scene)]);
    v.xdo(&["key", "Return"]);
    let line = v.expect(|l| l.starts_with("loaded: jsplat_unitCube-ascii.ply"));
    assert!(line.contains("20 splats"), "{line}");
    v.quit();
}
