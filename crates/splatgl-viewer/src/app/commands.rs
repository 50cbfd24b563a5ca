//! The command keys: views (F, Home/0, C, U), SH degree (1–4), modes (Tab, I, F11), output
//! (V, P), files (O), the panel (G), help (H/F1), quit (Esc); and the view changes the panel
//! asks for through the same functions.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{Key, KeyCode};
use winit::window::Fullscreen;

use super::{App, UserEvent};
use crate::controls::Mode;
use crate::rig::Rig;
use splatgl::camera::{Camera, UpAxis};

/// A path as a shell word (single-quoted unless plain).
fn shell_word(s: &str) -> String {
    let plain = s
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || "/._-+,:=@".contains(c));
    if plain && !s.is_empty() {
        s.to_owned()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

impl App {
    /// A command key was pressed.
    pub fn command(&mut self, el: &ActiveEventLoop, code: KeyCode, logical: &Key) {
        let ch = match logical {
            Key::Character(s) => s.chars().next().map(|c| c.to_ascii_lowercase()),
            _ => None,
        };
        match (code, ch) {
            (KeyCode::Escape, _) => el.exit(),
            (KeyCode::F1, _) | (_, Some('h')) => println!("{}", crate::HELP),
            (KeyCode::Tab, _) => {
                self.controls.mode = match self.controls.mode {
                    Mode::Orbit => Mode::Fly,
                    Mode::Fly => Mode::Orbit,
                };
                self.controls.stop();
                println!("mode: {:?}", self.controls.mode);
            }
            (KeyCode::F11, _) => {
                if let Some(w) = &self.win {
                    let full = w.window.fullscreen().is_some();
                    w.window
                        .set_fullscreen((!full).then_some(Fullscreen::Borderless(None)));
                }
            }
            (KeyCode::Home | KeyCode::Numpad0, _) | (_, Some('0')) => self.reset_view(),
            (_, Some(c @ '1'..='4')) => {
                let d = c as u8 - b'1';
                self.settings.sh_degree = Some(d);
                let file = self.shown.as_ref().map_or(0, |s| s.sh_degree);
                println!("SH degree {d} (the scene has degree {file})");
            }
            (_, Some('i')) => {
                self.controls.inertia = !self.controls.inertia;
                println!(
                    "inertia {}",
                    if self.controls.inertia { "on" } else { "off" }
                );
            }
            (_, Some('f')) => self.frame_cloud(None),
            (_, Some('u')) => {
                if let Some(s) = &self.shown {
                    self.frame_cloud(Some(s.up.next()));
                }
            }
            (_, Some('c')) => self.next_camera(),
            (_, Some('g')) => {
                if let Some(p) = &mut self.panel {
                    p.visible = !p.visible;
                    println!("panel {}", if p.visible { "shown" } else { "hidden" });
                }
            }
            (_, Some('v')) => self.print_camera(),
            (_, Some('p')) => self.screenshot = true,
            (_, Some('o')) => self.open_dialog(),
            _ => return,
        }
        self.update_title(true);
        self.request_redraw();
    }

    /// `Home` / `0`: back to the scene's initial view.
    pub(super) fn reset_view(&mut self) {
        if let (Some(s), Some(r)) = (&self.shown, &mut self.rig) {
            *r = s.home;
            self.controls.stop();
        }
    }

    /// `F` (`up` `None`): frames the cloud along the current view direction; `U` and the
    /// panel (`Some(axis)`): switches to that up axis and frames from its default direction.
    pub(super) fn frame_cloud(&mut self, up: Option<UpAxis>) {
        let (w, h) = self.render_size();
        let (Some(s), Some(r)) = (&mut self.shown, &mut self.rig) else {
            return;
        };
        let (Some(extent), Some(fit)) = (s.extent, s.fit) else {
            return;
        };
        let next_up = up.is_some();
        if let Some(a) = up {
            s.up = a;
            println!("up: {}", s.up.name());
        }
        let up = s.up.vector();
        let fwd = if next_up || r.forward().cross(up).length() < 1e-3 {
            s.up.default_forward()
        } else {
            r.forward()
        };
        if let Some(cam) = Camera::frame_boxes_along(&fit, &extent, fwd, up, r.fov_y(), w, h) {
            *r = Rig::from_camera(&cam, (fit.centre() - cam.eye()).length(), up);
            self.controls.stop();
        }
    }

    /// `C`: the next of the scene's glTF camera nodes, then the --camera cameras.json views.
    fn next_camera(&mut self) {
        let Some(s) = &self.shown else {
            return;
        };
        let n = s.cameras.len() + self.json_cameras.len();
        if n == 0 {
            println!("camera: the scene has no glTF camera nodes and there is no --camera list");
            return;
        }
        let i = self.camera_index % n;
        self.go_to_camera(i);
    }

    /// Camera `i` of the list (the scene's glTF camera nodes, then the cameras.json views),
    /// as `C` and the panel's camera list go to it.
    pub(super) fn go_to_camera(&mut self, i: usize) {
        let (w, h) = self.render_size();
        let (Some(s), Some(r)) = (&self.shown, &mut self.rig) else {
            return;
        };
        let (ng, nj) = (s.cameras.len(), self.json_cameras.len());
        if i >= ng + nj {
            return;
        }
        self.camera_index = i + 1;
        let (cam, what) = if i < ng {
            (
                Camera::from_gltf(&s.cameras[i], w, h),
                format!("glTF camera node {i}"),
            )
        } else {
            let e = &self.json_cameras[i - ng];
            let name = format!("cameras.json view {} ({})", i - ng, e.img_name);
            (Camera::from_3dgs(e), name)
        };
        match cam {
            Ok(cam) => {
                let focus = s.fit.map_or(1.0, |e| cam.focus_distance_to(e.centre()));
                *r = Rig::from_camera(&cam, focus, s.up.vector());
                self.controls.stop();
                println!("camera: {what} of {}", ng + nj);
            }
            Err(e) => eprintln!("error: {what}: {e}"),
        }
    }

    /// `V`: the current camera as a `splatgl render` line (and a cameras.json entry).
    pub(super) fn print_camera(&self) {
        let (w, h) = self.render_size();
        let (Some(s), Some(r)) = (&self.shown, &self.rig) else {
            return;
        };
        let cam = r.camera(w, h);
        let l = cam.as_look_at(r.pivot_distance);
        let mut line = String::from("splatgl render");
        if let Some(p) = &s.path {
            line += &format!(" {}", shell_word(&p.to_string_lossy()));
        }
        line += &format!(" {l}");
        if let Some(d) = self.settings.sh_degree.filter(|d| *d < s.sh_degree) {
            line += &format!(" --sh-degree {d}");
        }
        let bg = self.opts.background;
        if bg != [0.0; 3] {
            line += &format!(" --background {},{},{}", bg[0], bg[1], bg[2]);
        }
        println!("{line}");
        if !l.exact {
            println!("note: approximate (fx ≠ fy or off-centre principal point)");
        }
        if self.opts.print_camera_json {
            let entry = cam.to_3dgs_json(0, "splatgl-view");
            println!("{}", serde_json::Value::Array(vec![entry]));
        }
    }

    /// `O`: asks for a file (the platform's dialog: on Linux zenity or kdialog when installed,
    /// else a path typed on stdin; the common Open dialog on Windows; `choose file` on macOS);
    /// the answer arrives as [`UserEvent::Open`]. One question at a time.
    pub(super) fn open_dialog(&self) {
        if self.dialog_open.swap(true, Ordering::SeqCst) {
            return;
        }
        let proxy = self.proxy.clone();
        let busy: Arc<AtomicBool> = Arc::clone(&self.dialog_open);
        let ask = move || {
            if let Some(p) = ask_for_file() {
                let _ = proxy.send_event(UserEvent::Open(p));
            }
            busy.store(false, Ordering::SeqCst);
        };
        if std::thread::Builder::new()
            .name("splatgl-open".into())
            .spawn(ask)
            .is_err()
        {
            self.dialog_open.store(false, Ordering::SeqCst);
        }
    }
}

/// Whether `name` is an executable on `PATH`.
#[cfg(all(unix, not(target_os = "macos")))]
fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(name).is_file()))
}

/// The file dialog on Linux and the other Unixes: zenity, kdialog, or a line typed on stdin.
#[cfg(all(unix, not(target_os = "macos")))]
fn ask_for_file() -> Option<PathBuf> {
    let dialog = [
        (
            "zenity",
            &["--file-selection", "--title=Open a splat file"][..],
        ),
        ("kdialog", &["--getopenfilename", "."][..]),
    ]
    .into_iter()
    .find(|(exe, _)| on_path(exe));
    match dialog {
        Some((exe, args)) => answer_of(exe, args),
        None => {
            println!("open: type a file path and press Enter");
            let mut line = String::new();
            std::io::stdin().read_line(&mut line).ok()?;
            non_empty(&line)
        }
    }
}

/// The file dialog on macOS: the system's own, through AppleScript's `choose file`.
#[cfg(target_os = "macos")]
fn ask_for_file() -> Option<PathBuf> {
    answer_of(
        "osascript",
        &[
            "-e",
            "POSIX path of (choose file with prompt \"Open a splat file\")",
        ],
    )
}

/// The file dialog on Windows: the common Open dialog (`GetOpenFileNameW`).
#[cfg(windows)]
fn ask_for_file() -> Option<PathBuf> {
    use std::os::windows::ffi::OsStringExt;
    use windows_sys::Win32::UI::Controls::Dialogs::{
        GetOpenFileNameW, OFN_FILEMUSTEXIST, OFN_NOCHANGEDIR, OFN_PATHMUSTEXIST, OPENFILENAMEW,
    };
    let wide = |s: &str| s.encode_utf16().collect::<Vec<u16>>();
    // Pairs of (label, patterns), each NUL-terminated, the list ending in a second NUL.
    let filter = wide(
        "Splat files\0*.glb;*.gltf;*.ply;*.spz;*.splat;*.ksplat;*.sog;*.json\0All files\0*.*\0\0",
    );
    let title = wide("Open a splat file\0");
    let mut file = vec![0u16; 32 * 1024];
    // SAFETY: every pointer in the struct points at a live buffer of the stated size; the
    // rest is zero (no owner window, no hook).
    let chosen = unsafe {
        let mut ofn: OPENFILENAMEW = std::mem::zeroed();
        ofn.lStructSize = size_of::<OPENFILENAMEW>() as u32;
        ofn.lpstrFilter = filter.as_ptr();
        ofn.lpstrFile = file.as_mut_ptr();
        ofn.nMaxFile = file.len() as u32;
        ofn.lpstrTitle = title.as_ptr();
        ofn.Flags = OFN_FILEMUSTEXIST | OFN_PATHMUSTEXIST | OFN_NOCHANGEDIR;
        GetOpenFileNameW(&mut ofn) != 0
    };
    let len = file.iter().position(|&c| c == 0).unwrap_or(file.len());
    (chosen && len > 0).then(|| PathBuf::from(std::ffi::OsString::from_wide(&file[..len])))
}

/// What a dialog program printed on stdout (the chosen path), if anything.
#[cfg(unix)]
fn answer_of(exe: &str, args: &[&str]) -> Option<PathBuf> {
    let out = std::process::Command::new(exe).args(args).output().ok()?;
    non_empty(&String::from_utf8_lossy(&out.stdout))
}

/// A path typed or printed, trimmed; `None` when empty (the question was cancelled).
#[cfg(unix)]
fn non_empty(answer: &str) -> Option<PathBuf> {
    let p = answer.trim();
    (!p.is_empty()).then(|| PathBuf::from(p))
}
