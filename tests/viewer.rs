//! The desktop viewer in a virtual X server (`xvfb-run`), driven with `xdotool`: what it shows
//! equals the headless render of the same camera, mouse input moves the camera as the controls
//! say, and a file that fails to load keeps the previous scene. Every viewer gets a hard
//! timeout and is killed; without `xvfb-run` / `xdotool` / `import` the tests skip with a note.

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use glam::Vec3;
use splatgl::image::Image;

/// The view both the viewer and `render` use (the default scene's own camera, explicit).
const CAMERA: [&str; 8] = [
    "--look-at",
    "3.3,2.4,4.2,0,0.65,0,0,1,0",
    "--fov",
    "40",
    "--width",
    "320",
    "--height",
    "240",
];
/// Longest a viewer may live.
const HARD_TIMEOUT: Duration = Duration::from_secs(180);
/// Longest one expected line may take.
const WAIT: Duration = Duration::from_secs(60);

/// One X server at a time (`xvfb-run -a` picks a free display racily).
static X_LOCK: Mutex<()> = Mutex::new(());

fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(name).is_file()))
}

fn tools_or_skip() -> bool {
    let missing: Vec<_> = ["xvfb-run", "xdotool", "import", "timeout"]
        .into_iter()
        .filter(|t| !on_path(t))
        .collect();
    if missing.is_empty() {
        return true;
    }
    common::skip(&format!(
        "the viewer test: {missing:?} not installed (.ci/run installs them)"
    ));
    false
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-viewer-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A process group with a hard timeout: killed (whole group) on drop or when the time is up.
struct Guarded {
    child: Child,
    done: Arc<AtomicBool>,
}

impl Guarded {
    fn spawn(mut cmd: Command) -> Self {
        use std::os::unix::process::CommandExt;
        let child = cmd.process_group(0).spawn().expect("spawn");
        let done = Arc::new(AtomicBool::new(false));
        let (pid, flag) = (child.id() as i32, Arc::clone(&done));
        std::thread::spawn(move || {
            let end = Instant::now() + HARD_TIMEOUT;
            while Instant::now() < end {
                if flag.load(Ordering::SeqCst) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(200));
            }
            if !flag.load(Ordering::SeqCst) {
                eprintln!("hard timeout: killing process group {pid}");
                // SAFETY: signals the group this test started.
                unsafe { libc::kill(-pid, libc::SIGKILL) };
            }
        });
        Guarded { child, done }
    }
}

impl Drop for Guarded {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            // SAFETY: signals the group this test started.
            unsafe { libc::kill(-(self.child.id() as i32), libc::SIGKILL) };
            let _ = self.child.wait();
        }
        self.done.store(true, Ordering::SeqCst);
    }
}

/// Stdout and stderr lines of a child, merged.
fn lines_of(child: &mut Child) -> Receiver<String> {
    let (tx, rx) = channel();
    let out = child.stdout.take().unwrap();
    let err = child.stderr.take().unwrap();
    let tx2 = tx.clone();
    std::thread::spawn(move || {
        for l in BufReader::new(out).lines().map_while(Result::ok) {
            let _ = tx.send(l);
        }
    });
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx2.send(l);
        }
    });
    rx
}

/// A virtual X server (`xvfb-run -a`, which prints its DISPLAY and sleeps).
struct X {
    _server: Guarded,
    display: String,
    /// The cookie file xvfb-run made (clients need it).
    xauthority: String,
}

impl X {
    /// `cmd` as a client of this server.
    fn client(&self, cmd: &mut Command) {
        cmd.env("DISPLAY", &self.display)
            .env("XAUTHORITY", &self.xauthority);
    }
}

fn x_server() -> X {
    let mut cmd = Command::new("xvfb-run");
    cmd.args(["-a", "-s", "-screen 0 800x600x24", "sh", "-c"])
        .arg("echo \"X $DISPLAY $XAUTHORITY\"; exec sleep 600")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut server = Guarded::spawn(cmd);
    let rx = lines_of(&mut server.child);
    let line = wait_line(&rx, |l| l.starts_with("X "), &mut Vec::new())
        .expect("xvfb-run printed its display");
    let mut w = line.split_whitespace().skip(1);
    let (display, xauthority) = (
        w.next().unwrap().to_owned(),
        w.next().unwrap_or("").to_owned(),
    );
    X {
        _server: server,
        display,
        xauthority,
    }
}

/// The next line matching `pred` (all lines seen go to `log`).
fn wait_line(
    rx: &Receiver<String>,
    pred: impl Fn(&str) -> bool,
    log: &mut Vec<String>,
) -> Option<String> {
    let end = Instant::now() + WAIT;
    while let Some(left) = end.checked_duration_since(Instant::now()) {
        match rx.recv_timeout(left) {
            Ok(l) => {
                log.push(l.clone());
                if pred(&l) {
                    return Some(l);
                }
            }
            Err(_) => return None,
        }
    }
    None
}

/// A viewer on display `x`, started in `cwd` (where its screenshots go).
struct Viewer {
    proc: Guarded,
    rx: Receiver<String>,
    log: Vec<String>,
    display: String,
    xauthority: String,
    window: String,
}

impl Viewer {
    fn start(x: &X, cwd: &Path, args: &[&str]) -> Self {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_splatgl"));
        cmd.arg("view")
            .args(args)
            .current_dir(cwd)
            .env("WINIT_X11_SCALE_FACTOR", "1")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        x.client(&mut cmd);
        let mut proc = Guarded::spawn(cmd);
        let rx = lines_of(&mut proc.child);
        let mut v = Viewer {
            proc,
            rx,
            log: Vec::new(),
            display: x.display.clone(),
            xauthority: x.xauthority.clone(),
            window: String::new(),
        };
        v.expect(|l| l.starts_with("loaded: "));
        let ids = v.xdo(&["search", "--sync", "--name", "^splatgl"]);
        v.window = ids.lines().next().expect("a splatgl window").to_owned();
        let w = v.window.clone();
        v.xdo(&["windowfocus", &w]);
        v.xdo(&["mousemove", "--window", &w, "160", "120"]);
        v
    }

    fn expect(&mut self, pred: impl Fn(&str) -> bool) -> String {
        match wait_line(&self.rx, pred, &mut self.log) {
            Some(l) => l,
            None => panic!("viewer output so far:\n{}", self.log.join("\n")),
        }
    }

    /// Runs xdotool (10 s limit) on the viewer's display.
    fn xdo(&self, args: &[&str]) -> String {
        let out = Command::new("timeout")
            .arg("10")
            .arg("xdotool")
            .args(args)
            .env("DISPLAY", &self.display)
            .env("XAUTHORITY", &self.xauthority)
            .output()
            .expect("xdotool runs");
        assert!(out.status.success(), "xdotool {args:?}: {out:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    fn key(&self, k: &str) {
        self.xdo(&["key", k]);
    }

    /// `P`: the screenshot the viewer wrote.
    fn screenshot(&mut self, cwd: &Path) -> Image {
        self.key("p");
        let l = self.expect(|l| l.starts_with("screenshot: "));
        let name = l["screenshot: ".len()..]
            .split(" (")
            .next()
            .unwrap()
            .to_owned();
        Image::read(cwd.join(name)).expect("screenshot PNG")
    }

    /// `V`: eye and target of the printed `--look-at`.
    fn camera(&mut self) -> (Vec3, Vec3) {
        self.key("v");
        let l = self.expect(|l| l.starts_with("splatgl render"));
        let words: Vec<&str> = l.split_whitespace().collect();
        let i = words
            .iter()
            .position(|w| *w == "--look-at")
            .expect("--look-at");
        let v: Vec<f32> = words[i + 1]
            .split(',')
            .map(|s| s.parse().unwrap())
            .collect();
        (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
    }

    /// Escape quits with status 0.
    fn quit(mut self) {
        self.key("Escape");
        let end = Instant::now() + Duration::from_secs(20);
        loop {
            if let Some(s) = self.proc.child.try_wait().unwrap() {
                assert!(s.success(), "exit {s:?}:\n{}", self.log.join("\n"));
                return;
            }
            assert!(
                Instant::now() < end,
                "did not quit:\n{}",
                self.log.join("\n")
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

/// `splatgl render --backend gl --target rgba16f` of the default scene from [`CAMERA`] (and
/// `extra` options)
/// (None when there is no EGL here).
fn reference(cwd: &Path, extra: &[&str]) -> Option<Image> {
    let out = cwd.join("reference.png");
    let o = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args([
            "render",
            "--backend",
            "gl",
            "--target",
            "rgba16f",
            "-f",
            "-o",
        ])
        .arg(&out)
        .args(CAMERA)
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() && err.contains("EGL unavailable") {
        common::skip(&format!("the viewer test: {err}"));
        return None;
    }
    assert!(o.status.success(), "{err}");
    Some(Image::read(&out).unwrap())
}

fn psnr(a: &Image, b: &Image) -> f64 {
    splatgl::compare::compare(a, b, 1.0 / 255.0).unwrap().psnr
}

/// Azimuth of the eye around the target about +Y, and the eye–target distance.
fn azimuth_distance((eye, target): (Vec3, Vec3)) -> (f32, f32) {
    let v = eye - target;
    (v.x.atan2(v.z), v.length())
}

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
    let mut v = Viewer::start(&x, &cwd, &[&CAMERA[..], &["--sort-sync"]].concat());
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
    // The README's screenshot comes from here.
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
    let args = [&CAMERA[..], &["--sort-sync", "--test-drop", t]].concat();
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
    let mut v = Viewer::start(&x, &cwd, &[&CAMERA[..], &crop, &["--sort-sync"]].concat());
    let shot = v.screenshot(&cwd);
    let (p_view, p_whole) = (psnr(&shot, &want), psnr(&want, &whole));
    eprintln!("view --crop vs render --crop: {p_view:.1} dB; cropped vs whole: {p_whole:.1} dB");
    assert!(p_view >= 40.0, "view --crop vs render --crop: {p_view} dB");
    assert!(p_whole < 30.0, "the crop removed little: {p_whole} dB");
    v.quit();
    std::fs::remove_dir_all(&cwd).ok();
}
