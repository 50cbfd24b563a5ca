//! The desktop viewer in a virtual X server (`xvfb-run`), driven with `xdotool`: what it shows
//! equals the headless render of the same camera, mouse input moves the camera as the controls
//! say, a file that fails to load keeps the previous scene, and `--crop` removes what
//! `render --crop` removes. Helpers in `crates/splatgl-cli/tests/it/common/viewer.rs`.

//! A tileset streams in the viewer to the selection `render` makes for the same camera.
//!
//! The interface is hidden (`--no-ui`) in these tests; `crates/splatgl-cli/tests/it/viewer_panel.rs` tests it.

use crate::common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::viewer::*;
use splatgl::image::Image;

/// The viewer shows what `render` renders from the same options (its own `P` screenshot and
/// an external `import -window` capture, PSNR ≥ 40 dB); a left drag to the right orbits
/// (the azimuth falls: the content turns with the cursor, the pivot and distance stay), and
/// the wheel moves closer.
#[test]
fn viewer_shows_the_render_and_mouse_input_moves_the_camera() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("render");
    let Some(want) = reference(&cwd, &[]) else {
        return;
    };
    let x = x_server();
    let mut v = Viewer::start(
        &x,
        &cwd,
        &[&CAMERA[..], &["--sort-sync", "--no-ui"]].concat(),
    );
    let shot = v.screenshot(&cwd);
    let captured = cwd.join("import.png");
    let mut import = Command::new("timeout");
    import
        .args(["20", "import", "-window", &v.window])
        .arg(&captured);
    x.client(&mut import);
    let status = import.status().unwrap();
    assert!(status.success());
    let imported = Image::read(&captured).unwrap();
    assert_eq!((shot.width, shot.height), (320, 240));
    let (p_shot, p_import) = (psnr(&shot, &want), psnr(&imported, &want));
    assert!(p_shot >= 40.0, "P screenshot vs render: {p_shot} dB");
    assert!(p_import >= 40.0, "import -window vs render: {p_import} dB");
    // docs/guide.md's screenshot comes from here.
    let keep = Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer-screenshot.png");
    shot.write_png(&keep, splatgl::image::PngDepth::Eight, false)
        .unwrap();
    eprintln!(
        "viewer screenshot: {} ({p_shot:.1} dB, import {p_import:.1} dB)",
        keep.display()
    );

    // Inertia off: the printed camera is then exactly the drag's (π per window height).
    v.key("i");
    v.expect(|l| l == "inertia off");
    let c0 = v.camera();
    let w = v.window.clone();
    let drag = [
        "mousemove",
        "--window",
        &w,
        "120",
        "120",
        "mousedown",
        "1",
        "mousemove",
        "--window",
        &w,
        "150",
        "120",
        "mousemove",
        "--window",
        &w,
        "180",
        "120",
        "mouseup",
        "1",
    ];
    v.xdo(&drag);
    std::thread::sleep(Duration::from_millis(300));
    let c1 = v.camera();
    let ((a0, d0), (a1, d1)) = (azimuth_distance(c0), azimuth_distance(c1));
    let turn =
        (a1 - a0 + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
    // 60 px to the right of a 240 px high window: −45° (the content turns with the cursor).
    assert!(
        (turn.to_degrees() + 45.0).abs() < 1.0,
        "azimuth {a0} → {a1}"
    );
    assert!((d1 - d0).abs() < 0.02 * d0 && (c1.1 - c0.1).length() < 1e-3 * d0);
    v.xdo(&[
        "mousemove",
        "--window",
        &w,
        "160",
        "120",
        "click",
        "4",
        "click",
        "4",
    ]);
    std::thread::sleep(Duration::from_millis(500));
    let (_, d2) = azimuth_distance(v.camera());
    eprintln!("orbit: azimuth {a0} → {a1}, distance {d0} → {d1}; wheel: distance → {d2}");
    // Each notch is × 0.85 (winit 0.30 counts both the press and the release of an XTEST
    // wheel button as a notch, so two clicks may be four notches): closer, at least 0.85².
    assert!(d2 < 0.8 * d1, "wheel: distance {d1} → {d2}");
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}

/// A truncated file dropped on the window (the `DroppedFile` code path, through the hidden
/// test hook) is reported, and the viewer stays alive showing the previous scene.
#[test]
fn failed_drop_keeps_the_previous_scene() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("drop");
    let Some(want) = reference(&cwd, &[]) else {
        return;
    };
    let ply = splatgl::write::to_inria_ply(&splatgl::synthetic::default_scene());
    let truncated = cwd.join("truncated.ply");
    std::fs::write(&truncated, &ply[..ply.len() / 2]).unwrap();
    let x = x_server();
    let t = truncated.to_str().unwrap();
    let args = [&CAMERA[..], &["--sort-sync", "--no-ui", "--test-drop", t]].concat();
    let mut v = Viewer::start(&x, &cwd, &args);
    let err = v.expect(|l| l.starts_with("error: "));
    assert!(
        err.contains("truncated.ply") && err.contains("keeping default scene"),
        "{err}"
    );
    let shot = v.screenshot(&cwd);
    assert!(v.proc.child.try_wait().unwrap().is_none(), "alive");
    let p = psnr(&shot, &want);
    assert!(
        p >= 40.0,
        "after the failed load: {p} dB against the previous scene"
    );
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}

/// `view --crop` shows what `render --crop` renders with the same options (≥ 40 dB), and the
/// box removes splats that show (the cropped render is far from the whole one).
#[test]
fn crop_box_removes_the_same_splats_in_view_and_render() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("crop");
    let crop = ["--crop", "0,-100,-100,100,100,100"]; // the half x ≥ 0
    let Some(whole) = reference(&cwd, &[]) else {
        return;
    };
    let want = reference(&cwd, &crop).unwrap();
    let x = x_server();
    let mut v = Viewer::start(
        &x,
        &cwd,
        &[&CAMERA[..], &crop, &["--sort-sync", "--no-ui"]].concat(),
    );
    let shot = v.screenshot(&cwd);
    let (p_view, p_whole) = (psnr(&shot, &want), psnr(&want, &whole));
    eprintln!("view --crop vs render --crop: {p_view:.1} dB; cropped vs whole: {p_whole:.1} dB");
    assert!(p_view >= 40.0, "view --crop vs render --crop: {p_view} dB");
    assert!(p_whole < 30.0, "the crop removed little: {p_whole} dB");
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}

/// A tileset in the viewer: its tiles stream in the background (`tiles: … loading` lines) until
/// nothing is pending, and what it then shows is what `render` of the tileset shows from the
/// same camera and budget (the same selection, ≥ 40 dB).
#[test]
fn a_streamed_tileset_settles_on_the_selection_render_makes() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("tiles");
    let input = cwd.join("in.glb");
    let cloud = common::random_cloud(3000, 1, 1.0, 5);
    std::fs::write(&input, splatgl::write::to_glb(&cloud, &Default::default())).unwrap();
    let ts = cwd.join("ts/tileset.json");
    let (i, t) = (input.to_str().unwrap(), ts.to_str().unwrap());
    let st = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(["convert", i, t, "--chunk-splats", "256"])
        .status()
        .unwrap();
    assert!(st.success());
    let camera = [
        "--look-at",
        "0.4,-2.2,0.9,0,0,0,0,0,1",
        "--fov",
        "50",
        "--width",
        "320",
        "--height",
        "240",
        "--splat-budget",
        "1500",
    ];
    let Some(want) = render_gl(&cwd, &[&[t][..], &camera].concat()) else {
        return;
    };
    let x = x_server();
    let mut v = Viewer::start(
        &x,
        &cwd,
        &[&[t][..], &camera, &["--sort-sync", "--no-ui"]].concat(),
    );
    let done = v.expect(|l| l.starts_with("tiles: ") && l.contains(", 0 loading;"));
    let loads: Vec<&String> = v.log.iter().filter(|l| l.starts_with("tiles: ")).collect();
    assert!(loads.len() >= 2, "the tiles streamed in steps: {loads:?}");
    // Each new selection writes only its new tiles' pages: some later selection wrote fewer
    // splats than it selected, into the storage already allocated.
    let lines: Vec<&String> = v
        .log
        .iter()
        .filter(|l| l.starts_with("tiles: ") || l.starts_with("gpu: "))
        .collect();
    let number_after = |l: &str, key: &str| -> u64 {
        let head = l.split(key).next().unwrap_or("");
        let word = head.trim_end().rsplit([' ', '(']).next().unwrap_or("");
        word.parse()
            .unwrap_or_else(|_| panic!("no number before {key:?} in {l:?}"))
    };
    let partial = lines.windows(2).skip(1).any(|w| {
        w[0].starts_with("tiles: ")
            && w[1].starts_with("gpu: ")
            && !w[1].contains("storage allocated")
            && number_after(w[1], " splats)") < number_after(w[0], " splats (budget")
    });
    assert!(partial, "no selection kept its resident tiles: {lines:#?}");
    let shot = v.screenshot(&cwd);
    let p = psnr(&shot, &want);
    assert!(
        p >= 40.0,
        "viewer vs render of the tileset: {p} dB ({done})"
    );
}
