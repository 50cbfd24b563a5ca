//! One frame: controls (or the benchmark's orbit) → camera → order (staleness bound) → upload
//! if it changed → draw → screenshot → prefetch the next sort → swap; and the title bar.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

use glow::HasContext;
use winit::event_loop::ActiveEventLoop;

use super::App;
use crate::rig::Rig;
use crate::stats::{BenchLog, thousands};
use crate::{Bench, ViewerError};
use splatgl::sort::Freshness;

/// Frames drawn before `--bench-frames` starts measuring (upload, first sort, shader warm-up).
const BENCH_WARMUP: usize = 2;

/// A `--bench-frames` run.
#[derive(Debug)]
pub(super) struct BenchRun {
    spec: Bench,
    home: Rig,
    done: usize,
    last_end: Option<Instant>,
    log: BenchLog,
}

impl BenchRun {
    pub fn new(spec: Bench, home: Rig) -> Self {
        BenchRun {
            spec,
            home,
            done: 0,
            last_end: None,
            log: BenchLog::default(),
        }
    }

    /// The camera of frame `i`: one full turn around the up axis through the pivot over the
    /// measured frames (`--orbit`), else the initial camera.
    fn rig(&self) -> Rig {
        let mut r = self.home;
        if self.spec.orbit {
            let i = self.done.saturating_sub(BENCH_WARMUP) as f32;
            r.orbit(
                std::f32::consts::TAU * i / self.spec.frames.max(1) as f32,
                0.0,
            );
        }
        r
    }
}

/// Clears the default framebuffer to `bg` (the window before anything is loaded).
fn clear_window(gl: &glow::Context, window: (u32, u32), bg: [f32; 3]) {
    // SAFETY: clearing the default framebuffer.
    unsafe {
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.viewport(0, 0, window.0 as i32, window.1 as i32);
        gl.clear_color(bg[0], bg[1], bg[2], 1.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
}

/// Writes the default framebuffer as a timestamped PNG in the current folder (`P`).
fn screenshot(gl: &glow::Context, window: (u32, u32)) {
    let img = crate::draw::read_back_buffer(gl, window.0, window.1);
    let path = screenshot_name();
    match img.write_png(&path, splatgl::image::PngDepth::Eight, false) {
        Ok(()) => println!("screenshot: {} ({}x{})", path.display(), window.0, window.1),
        Err(e) => eprintln!("error: screenshot {}: {e}", path.display()),
    }
}

/// What [`App::draw_splats`] drew.
struct DrawnFrame {
    camera: splatgl::camera::Camera,
    fresh: Freshness,
    sort_time: Duration,
    moving: bool,
}

impl BenchRun {
    /// Times the frame just drawn (after `glFinish`; warm-up frames are not logged); whether
    /// the run has all its frames.
    fn record(
        &mut self,
        gl: &glow::Context,
        sort_time: Duration,
        fresh: Freshness,
        ui: crate::panel::Cpu,
    ) -> bool {
        // SAFETY: glFinish has no preconditions: the frame is complete when timed.
        unsafe { gl.finish() };
        let end = Instant::now();
        if self.done >= BENCH_WARMUP
            && let Some(last) = self.last_end
        {
            self.log.push(end - last, sort_time, fresh);
            if self.spec.panel {
                self.log.push_panel(ui.layout, ui.paint);
            }
        }
        self.last_end = Some(end);
        self.done += 1;
        self.done >= self.spec.frames + BENCH_WARMUP
    }
}

impl App {
    /// Draws one frame (on `RedrawRequested`).
    pub fn frame(&mut self, el: &ActiveEventLoop) {
        if let Err(e) = self.draw_frame(el) {
            self.fail(el, e);
        }
        #[cfg(feature = "testing")]
        self.test_drop(el);
    }

    fn draw_frame(&mut self, el: &ActiveEventLoop) -> Result<(), ViewerError> {
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32());
        self.last_frame = Some(now);
        let Some(window) = self.win.as_ref().map(|w| w.window.inner_size()) else {
            return Ok(());
        };
        if window.width == 0 || window.height == 0 {
            return Ok(());
        }
        let window = (window.width, window.height);
        let Some(drawn) = self.draw_splats(dt, window)? else {
            // Nothing loaded yet: the background, and the title says what is loading.
            let win = self.win.as_ref().expect("checked above");
            clear_window(&win.gl, window, self.opts.background);
            return win.swap().map_err(ViewerError::Window);
        };
        if std::mem::take(&mut self.screenshot)
            && let Some(win) = &self.win
        {
            screenshot(&win.gl, window);
        }
        if self.bench.as_ref().is_none_or(|b| b.spec.panel) {
            self.interface_pass(&drawn.camera, window);
        }
        let win = self.win.as_ref().expect("checked above");
        win.swap().map_err(ViewerError::Window)?;
        self.frames_shown += 1;
        self.animating = drawn.moving || matches!(drawn.fresh, Freshness::Stale { .. });
        self.stats.push(
            now,
            Duration::from_secs_f32(dt),
            drawn.sort_time,
            drawn.fresh,
        );
        let ui_time = self.panel.as_ref().map_or(Default::default(), |p| p.cpu);
        let render = self.render_size();
        if let (Some(b), Some(shown)) = (&mut self.bench, &self.shown)
            && b.record(&win.gl, drawn.sort_time, drawn.fresh, ui_time)
        {
            let what = format!(
                "{} ({} splats, {}x{}{}{})",
                shown.name,
                thousands(shown.len),
                render.0,
                render.1,
                if b.spec.orbit { ", orbit" } else { ", still" },
                if b.spec.panel { ", with the panel" } else { "" }
            );
            println!("{}", b.log.report(&what, &win.info()));
            el.exit();
        }
        self.update_title(false);
        Ok(())
    }

    /// Moves the camera, takes the order to draw (uploading it if it changed), posts the next
    /// sort and draws the splats into the window's back buffer. `None`: no scene yet.
    fn draw_splats(
        &mut self,
        dt: f32,
        window: (u32, u32),
    ) -> Result<Option<DrawnFrame>, ViewerError> {
        let render = self.render_size();
        let (Some(win), Some(renderer)) = (&self.win, &mut self.renderer) else {
            return Ok(None);
        };
        let gl = &win.gl;
        let (Some(shown), Some(rig)) = (&mut self.shown, &mut self.rig) else {
            return Ok(None);
        };
        let moving = match &self.bench {
            Some(b) => {
                *rig = b.rig();
                b.spec.orbit
            }
            None => self.controls.update(rig, dt, render),
        };
        let camera = rig.camera(render.0, render.1);
        if let Some((streamer, last)) = &mut shown.streamer
            && *last != Some(camera)
        {
            streamer.set_camera(&camera);
            *last = Some(camera);
        }
        let eye = camera.eye();
        let Some((order, fresh)) = shown.orders.for_frame(eye) else {
            return Err(ViewerError::Window("the sorter thread stopped".into()));
        };
        let sort_time = order.sort_time();
        self.live.drawn = order.order().len();
        if shown.uploaded != Some(order.generation()) {
            let t = Instant::now();
            match &mut shown.paged {
                Some(p) => renderer.set_order(gl, p.map(order.order()))?,
                None => renderer.set_order(gl, order.order())?,
            }
            self.live.upload_ms = t.elapsed().as_secs_f32() * 1e3;
            shown.uploaded = Some(order.generation());
        } else {
            self.live.upload_ms = 0.0;
        }
        // Prefetch, before drawing so the sort overlaps the draw: sort for where the camera
        // will be next frame (linear prediction), so the next frame finds a close order.
        let next = match self.prev_eye {
            Some(p) if moving => eye + (eye - p),
            _ => eye,
        };
        shown.orders.request(next);
        self.prev_eye = Some(eye);
        let bg = self.opts.background;
        self.targets
            .draw(gl, renderer, &camera, &self.settings, bg, window)?;
        Ok(Some(DrawnFrame {
            camera,
            fresh,
            sort_time,
            moving,
        }))
    }

    /// Sets the title (at most every 250 ms unless `now`): file, splats, SH degree, frame
    /// and sort times, order freshness, mode; a load in progress; the last error.
    pub fn update_title(&mut self, now: bool) {
        let due = self
            .last_title
            .is_none_or(|t| t.elapsed() >= Duration::from_millis(250));
        if !(now || due) {
            return;
        }
        self.last_title = Some(Instant::now());
        let mut t = String::from("splatgl");
        if let Some(s) = &self.shown {
            t += &format!(" — {} — {} splats", s.name, thousands(s.len));
            if s.len < s.file_len {
                t += &format!(" of {}", thousands(s.file_len));
            }
            let d = self.settings.sh_degree.unwrap_or(3).min(s.sh_degree);
            t += &format!(" — SH {d}/{} — {}", s.sh_degree, self.stats.title_part());
            if self.controls.mode == crate::controls::Mode::Fly {
                t += " — fly";
            }
        }
        if let Some(st) = &self.status {
            t += &format!(" — {st}");
        }
        if let Some((m, at)) = &self.message
            && at.elapsed() < Duration::from_secs(8)
        {
            t += &format!(" — {m}");
        }
        if let Some(w) = &self.win {
            w.window.set_title(&t);
        }
    }

    /// The terminal progress bar (on a terminal only; the title shows it anyway).
    pub fn progress_line(&self, pct: u64) {
        let mut err = std::io::stderr();
        if !err.is_terminal() {
            return;
        }
        let filled = (pct.min(100) / 5) as usize;
        let bar = format!("{}{}", "#".repeat(filled), "-".repeat(20 - filled));
        let _ = write!(err, "\r{} [{bar}] {pct:3}%", self.loading_name);
        if pct >= 100 {
            let _ = writeln!(err);
        }
        let _ = err.flush();
    }
}

/// `splatgl-YYYYMMDD-HHMMSS-mmm.png` (UTC) in the current directory.
fn screenshot_name() -> std::path::PathBuf {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    let secs = t.as_secs();
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let (hh, mm, ss) = (rem / 3600, rem / 60 % 60, rem % 60);
    let ms = t.subsec_millis();
    format!("splatgl-{y:04}{m:02}{d:02}-{hh:02}{mm:02}{ss:02}-{ms:03}.png").into()
}
