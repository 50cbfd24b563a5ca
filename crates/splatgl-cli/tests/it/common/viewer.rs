//! The desktop viewer in a virtual X server (`xvfb-run`), driven with `xdotool`: the helpers
//! of `crates/splatgl-cli/tests/it/viewer.rs` and `crates/splatgl-cli/tests/it/viewer_panel.rs`. Every viewer gets a hard timeout and is
//! killed; without `xvfb-run` / `xdotool` / `import` the tests skip with a note.
#![allow(dead_code)]

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
pub const CAMERA: [&str; 8] = [
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
pub const HARD_TIMEOUT: Duration = Duration::from_secs(180);
/// Longest one expected line may take.
pub const WAIT: Duration = Duration::from_secs(60);

/// One X server at a time (`xvfb-run -a` picks a free display racily).
pub static X_LOCK: Mutex<()> = Mutex::new(());

pub fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(name).is_file()))
}

pub fn tools_or_skip() -> bool {
    let missing: Vec<_> = ["xvfb-run", "xdotool", "import", "timeout"]
        .into_iter()
        .filter(|t| !on_path(t))
        .collect();
    if missing.is_empty() {
        return true;
    }
    super::skip(&format!(
        "the viewer test: {missing:?} not installed (.ci/run installs them)"
    ));
    false
}

pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-viewer-{name}-{}", std::process::id()));
    // Empty first: an earlier run with the same pid may have left files.
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A process group with a hard timeout: killed (whole group) on drop or when the time is up.
pub struct Guarded {
    pub child: Child,
    pub done: Arc<AtomicBool>,
}

impl Guarded {
    pub fn spawn(mut cmd: Command) -> Self {
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
pub fn lines_of(child: &mut Child) -> Receiver<String> {
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
pub struct X {
    pub _server: Guarded,
    pub display: String,
    /// The cookie file xvfb-run made (clients need it).
    pub xauthority: String,
}

impl X {
    /// `cmd` as a client of this server.
    pub fn client(&self, cmd: &mut Command) {
        cmd.env("DISPLAY", &self.display)
            .env("XAUTHORITY", &self.xauthority);
    }
}

pub fn x_server() -> X {
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
pub fn wait_line(
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
pub struct Viewer {
    pub proc: Guarded,
    pub rx: Receiver<String>,
    pub log: Vec<String>,
    pub display: String,
    pub xauthority: String,
    pub window: String,
}

impl Viewer {
    pub fn start(x: &X, cwd: &Path, args: &[&str]) -> Self {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_splatgl"));
        cmd.arg("view").args(args);
        Self::start_command(x, cwd, cmd)
    }

    /// A viewer started by `cmd` (the `view` command and its options already given: e.g.
    /// `splatgl.exe view` under Wine).
    pub fn start_command(x: &X, cwd: &Path, mut cmd: Command) -> Self {
        cmd.current_dir(cwd)
            .env("WINIT_X11_SCALE_FACTOR", "1")
            .env("SPLATGL_VIEWER_LAYOUT", "1")
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

    pub fn expect(&mut self, pred: impl Fn(&str) -> bool) -> String {
        match wait_line(&self.rx, pred, &mut self.log) {
            Some(l) => l,
            None => panic!("viewer output so far:\n{}", self.log.join("\n")),
        }
    }

    /// Runs xdotool (10 s limit) on the viewer's display.
    pub fn xdo(&self, args: &[&str]) -> String {
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

    pub fn key(&self, k: &str) {
        self.xdo(&["key", k]);
    }

    /// `P`: the screenshot the viewer wrote.
    pub fn screenshot(&mut self, cwd: &Path) -> Image {
        self.key("p");
        let l = self.expect(|l| l.starts_with("screenshot: "));
        let name = l["screenshot: ".len()..]
            .split(" (")
            .next()
            .unwrap()
            .to_owned();
        Image::read(cwd.join(name)).expect("screenshot PNG")
    }

    /// The window as an X client sees it (`import -window`): the panel included.
    pub fn capture(&self, x: &X, cwd: &Path, name: &str) -> Image {
        let path = cwd.join(name);
        let mut import = Command::new("timeout");
        import
            .args(["20", "import", "-window", &self.window])
            .arg(&path);
        x.client(&mut import);
        assert!(import.status().unwrap().success(), "import -window");
        Image::read(&path).expect("capture PNG")
    }

    /// The window position of `layout: WHAT X Y …` (the viewer prints it with
    /// `SPLATGL_VIEWER_LAYOUT`): the first two numbers after `what`, plus the next two.
    pub fn layout(&mut self, what: &str) -> Vec<i32> {
        let prefix = format!("layout: {what} ");
        let l = self.expect(|l| l.starts_with(&prefix));
        l[prefix.len()..]
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect()
    }

    /// The widest of every `layout: WHAT` rectangle the viewer has printed so far (it prints
    /// one each time the layout changes: the panel widens with its statistics' text), so a
    /// region beside it is clear of it in any frame shown until now.
    pub fn widest_layout(&mut self, what: &str) -> Vec<i32> {
        while let Ok(l) = self.rx.try_recv() {
            self.log.push(l);
        }
        let prefix = format!("layout: {what} ");
        self.log
            .iter()
            .filter_map(|l| l.strip_prefix(&prefix))
            .map(|r| {
                r.split_whitespace()
                    .map(|v| v.parse().unwrap())
                    .collect::<Vec<i32>>()
            })
            .max_by_key(|r| r[0] + r[2])
            .unwrap_or_else(|| panic!("no {prefix:?} line: {}", self.log.join("\n")))
    }

    /// `V`: eye and target of the printed `--look-at`.
    pub fn camera(&mut self) -> (Vec3, Vec3) {
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
    pub fn quit(mut self) {
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

/// `splatgl render --backend gl --target rgba16f` of the default scene with `args` (None when
/// there is no EGL here: a skip, which fails under `SPLATGL_REQUIRE=all`).
pub fn render_gl(cwd: &Path, args: &[&str]) -> Option<Image> {
    let out = cwd.join("render.png");
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
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() && err.contains("EGL unavailable") {
        super::skip(&format!("the viewer test: {err}"));
        return None;
    }
    assert!(o.status.success(), "{err}");
    Some(Image::read(&out).unwrap())
}

/// [`render_gl`] from [`CAMERA`] (and `extra` options).
pub fn reference(cwd: &Path, extra: &[&str]) -> Option<Image> {
    render_gl(cwd, &[&CAMERA[..], extra].concat())
}

/// Columns `x0..x1` of `img`.
pub fn columns(img: &Image, x0: u32, x1: u32) -> Image {
    let mut out = Image::filled(x1 - x0, img.height, [0.0; 4]);
    for y in 0..img.height {
        for x in x0..x1 {
            out.pixels[(y * out.width + x - x0) as usize] = img.get(x, y);
        }
    }
    out
}

pub fn psnr(a: &Image, b: &Image) -> f64 {
    splatgl::compare::compare(a, b, 1.0 / 255.0).unwrap().psnr
}

/// Azimuth of the eye around the target about +Y, and the eye–target distance.
pub fn azimuth_distance((eye, target): (Vec3, Vec3)) -> (f32, f32) {
    let v = eye - target;
    (v.x.atan2(v.z), v.length())
}
