//! The viewer's on-screen panel in a virtual X server: it appears in an external capture of
//! the window and `G` hides it (the capture then equals `render --backend gl` of the same
//! camera); a click on a camera of its list moves the view there; dragging a face of the crop
//! box removes the splats that `render --crop` removes with the box the viewer prints. The
//! viewer prints where its buttons and handles are (`SPLATGL_VIEWER_LAYOUT`), and `xdotool`
//! clicks them. Helpers in `crates/splatgl-cli/tests/it/common/viewer.rs`.

use crate::common;

use std::time::Duration;

use common::viewer::*;
use glam::Vec3;
use splatgl::camera::Camera;

const W: u32 = 800;
const H: u32 = 450;

/// Two views of the default scene in a cameras.json: its own view, and one from the other
/// side.
fn cameras_json(dir: &std::path::Path) -> (std::path::PathBuf, Vec3) {
    let target = Vec3::new(0.0, 0.65, 0.0);
    let other = Vec3::new(-4.0, 1.5, 3.0);
    let views = [Vec3::new(3.3, 2.4, 4.2), other]
        .map(|eye| Camera::look_at(eye, target, Vec3::Y, 40f32.to_radians(), W, H));
    let entries: Vec<_> = views
        .iter()
        .enumerate()
        .map(|(i, c)| c.to_3dgs_json(i as i64, &format!("view{i}")))
        .collect();
    let path = dir.join("cameras.json");
    std::fs::write(&path, serde_json::Value::Array(entries).to_string()).unwrap();
    (path, other)
}

/// [`render_gl`], which has EGL here (the test checked with [`reference`]).
fn render(dir: &std::path::Path, args: &[&str]) -> splatgl::image::Image {
    render_gl(dir, args).expect("EGL was there a moment ago")
}

#[test]
fn panel_shows_hides_and_its_camera_list_moves_the_view() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("panel");
    if reference(&cwd, &[]).is_none() {
        return; // no EGL here (skipped, with a note)
    }
    let (json, other_eye) = cameras_json(&cwd);
    let json = json.to_str().unwrap().to_owned();
    let x = x_server();
    let mut v = Viewer::start(&x, &cwd, &["--camera", &json, "--view", "0", "--sort-sync"]);
    // The panel is laid out (its later, wider layouts are read before the capture).
    v.layout("panel");
    // Click the second camera of the list.
    let b = v.layout("camera 1");
    let (cx, cy) = ((b[0] + b[2] / 2).to_string(), (b[1] + b[3] / 2).to_string());
    let w = v.window.clone();
    v.xdo(&["mousemove", "--window", &w, &cx, &cy, "click", "1"]);
    let said = v.expect(|l| l.starts_with("camera: "));
    assert!(said.contains("cameras.json view 1"), "{said}");
    let (eye, _) = v.camera();
    assert!(
        (eye - other_eye).length() < 1e-3,
        "camera 1 at {other_eye}, the viewer at {eye}"
    );
    std::thread::sleep(Duration::from_millis(300));
    let want = render(&cwd, &["--camera", &json, "--view", "1"]);
    let shown = v.capture(&x, &cwd, "with-panel.png");
    assert_eq!((shown.width, shown.height), (W, H));
    // The panel covers the left; right of it the scene is as rendered. The panel grows with
    // its statistics' text (three-digit frame times on a slow machine): its widest so far.
    let panel = v.widest_layout("panel");
    let panel_w = (panel[0] + panel[2] + 2) as u32;
    let (p_left, p_right) = (
        psnr(&columns(&shown, 0, panel_w), &columns(&want, 0, panel_w)),
        psnr(&columns(&shown, panel_w, W), &columns(&want, panel_w, W)),
    );
    eprintln!("panel shown: {p_left:.1} dB over the panel, {p_right:.1} dB right of it");
    assert!(p_left < 25.0, "no panel in the capture: {p_left} dB");
    assert!(p_right >= 40.0, "the scene beside the panel: {p_right} dB");
    // docs/guide.md's screenshot with the panel open comes from here.
    let keep = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("viewer-panel.png");
    shown
        .write_png(&keep, splatgl::image::PngDepth::Eight, false)
        .unwrap();
    v.key("g");
    v.expect(|l| l == "panel hidden");
    std::thread::sleep(Duration::from_millis(300));
    let hidden = v.capture(&x, &cwd, "without-panel.png");
    let p = psnr(&hidden, &want);
    eprintln!("panel hidden: {p:.1} dB against render");
    assert!(p >= 40.0, "with the panel hidden: {p} dB against render");
    v.key("g");
    v.expect(|l| l == "panel shown");
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}

#[test]
fn dragging_a_crop_face_removes_what_render_crop_removes() {
    let _x = X_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if !tools_or_skip() {
        return;
    }
    let cwd = dir("panel-crop");
    if reference(&cwd, &[]).is_none() {
        return;
    }
    let size = ["--width", "640", "--height", "400"];
    let look = &CAMERA[..4]; // --look-at … --fov …
    let start_box = "-1.5,-1,-1.5,1.5,2.5,1.5";
    let args = [look, &size, &["--crop", start_box, "--sort-sync"]].concat();
    let x = x_server();
    let mut v = Viewer::start(&x, &cwd, &args);
    // A face handle right of the panel, dragged 40 px towards the window's centre line.
    // Handles under the panel are not drawn (nor printed): take the lines of the first layout.
    v.expect(|l| l.starts_with("layout: crop-face "));
    std::thread::sleep(Duration::from_millis(300));
    while let Ok(l) = v.rx.try_recv() {
        v.log.push(l);
    }
    let handle = v
        .log
        .iter()
        .filter_map(|l| l.strip_prefix("layout: crop-face "))
        .map(|l| -> Vec<i32> {
            l.split_whitespace()
                .skip(1)
                .map(|n| n.parse().unwrap())
                .collect()
        })
        .find(|p| p[0] > 340 && p[0] < 620 && p[1] > 20 && p[1] < 380);
    let p = handle.expect("a crop handle right of the panel");
    let w = v.window.clone();
    let dx = if p[0] > 480 { -40 } else { 40 };
    let mut drag = vec!["mousemove".to_owned(), "--window".into(), w.clone()];
    drag.extend([
        p[0].to_string(),
        p[1].to_string(),
        "mousedown".into(),
        "1".into(),
    ]);
    for step in 1..=4 {
        drag.extend(["mousemove", "--window", &w].map(String::from));
        drag.extend([(p[0] + dx * step / 4).to_string(), p[1].to_string()]);
        drag.push("sleep".into());
        drag.push("0.2".into());
    }
    drag.extend(["mouseup".to_owned(), "1".into()]);
    let drag: Vec<&str> = drag.iter().map(String::as_str).collect();
    v.xdo(&drag);
    let said = v.expect(|l| l.starts_with("crop: --crop "));
    let crop = said["crop: --crop ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .to_owned();
    assert_ne!(crop, start_box, "the drag moved no face");
    let shot = v.screenshot(&cwd);
    let want = render(&cwd, &[look, &size, &["--crop", &crop]].concat());
    let before = render(&cwd, &[look, &size, &["--crop", start_box]].concat());
    let (p_same, p_moved) = (psnr(&shot, &want), psnr(&want, &before));
    eprintln!(
        "crop {start_box} → {crop}: view vs render {p_same:.1} dB; box moved {p_moved:.1} dB"
    );
    assert!(p_same >= 40.0, "view vs render --crop {crop}: {p_same} dB");
    assert!(
        p_moved < 35.0,
        "the dragged face removed little: {p_moved} dB"
    );
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}
