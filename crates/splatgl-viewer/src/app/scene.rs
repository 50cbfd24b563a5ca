//! A scene's life in the viewer: the background load of a file (or the default scene), a
//! failed load (the previous scene stays), the first camera of a new scene, and installing it
//! (upload, sorter, panel facts, title).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use winit::event_loop::ActiveEventLoop;

use super::frame::BenchRun;
use super::paging;
use super::{App, Shown, UserEvent};
use crate::ViewerError;
use crate::loading::{self, Loaded, display_name, spawn};
use crate::panel::TileCounts;
use crate::rig::Rig;
use splatgl::camera::{Camera, Extent, SceneView, UpAxis};
use splatgl::load::Format;
use splatgl::sort::StaleOrders as Orders;

impl App {
    /// Starts loading `path` (`None`: the default scene) in the background.
    pub fn start_load(&mut self, path: Option<PathBuf>) {
        self.load_id += 1;
        self.loading_name = display_name(path.as_deref());
        self.status = Some(format!("loading {}", self.loading_name));
        eprintln!("loading {}", self.loading_name);
        let proxy = self.proxy.clone();
        let send = move |ev| {
            // The loop is gone only while exiting: nothing to report to.
            let _ = proxy.send_event(UserEvent::Load(ev));
        };
        let opts = Arc::clone(&self.load_opts);
        let keep = loading::Keep {
            max_splats: self.opts.max_splats,
            tiles: self.opts.tiles,
        };
        spawn(self.load_id, path, opts, keep, send);
        self.update_title(true);
    }

    /// Reports a failed load; without a scene to keep it ends the viewer.
    pub(super) fn load_failed(&mut self, el: &ActiveEventLoop, msg: String) {
        self.status = None;
        if self.shown.is_none() {
            self.fail(el, ViewerError::Load(msg));
            return;
        }
        eprintln!(
            "error: {msg} (keeping {})",
            self.shown.as_ref().map_or("", |s| &s.name)
        );
        self.message = Some((format!("error: {msg}"), Instant::now()));
        self.update_title(true);
    }

    /// The first camera of a scene: the command-line options for the first file, a framing
    /// with the scene's up axis for later ones; and the pivot distance.
    fn first_camera(&self, l: &Loaded, up: UpAxis) -> Result<(Camera, f32), String> {
        let (w, h) = self.render_size();
        if self.shown.is_none() {
            let mut v = self.opts.view.clone();
            (v.width, v.height) = (Some(w), Some(h));
            v.up = v.up.or(l.up);
            let scene = SceneView {
                cloud: &l.cloud,
                format: l.format,
                cameras: &l.cameras,
            };
            let cam = v.camera(scene, (w, h)).map_err(|e| e.to_string())?;
            return Ok((cam, v.focus_distance(&cam, &l.cloud)));
        }
        let fov = self
            .rig
            .map_or(self.opts.view.fov_deg.to_radians(), |r| r.fov_y());
        let cam = Camera::frame_cloud(&l.cloud, up, fov, w, h)
            .ok_or("no splat that can be drawn, nothing to frame")?;
        let fit = Extent::of_cloud_at(&l.cloud, splatgl::camera::FIT_SIGMAS);
        let focus = fit.map_or(1.0, |e| cam.focus_distance_to(e.centre()));
        Ok((cam, focus))
    }

    /// Shows a loaded scene (or keeps the previous one when it cannot be shown).
    pub(super) fn install(&mut self, el: &ActiveEventLoop, mut l: Loaded) {
        let name = l.name();
        let up = (self.opts.view.up)
            .or(l.up)
            .unwrap_or_else(|| splatgl::camera::UpAxis::for_cloud(l.format, &l.cloud));
        let (cam, focus) = match self.first_camera(&l, up) {
            Ok(c) => c,
            Err(e) if self.shown.is_none() => {
                return self.fail(el, ViewerError::Load(format!("{name}: {e}")));
            }
            Err(e) => return self.load_failed(el, format!("{name}: {e}")),
        };
        let positions: Arc<[[f32; 3]]> = l.cloud.positions.as_slice().into();
        let tau = self.opts.stale.tolerance(&l.cloud);
        let mut orders = match Orders::new(positions, tau, self.opts.sort_sync) {
            Ok(o) => o,
            Err(e) => return self.load_failed(el, format!("{name}: sorter thread: {e}")),
        };
        orders.set_crop(self.crop);
        let paged = match self.upload_loaded(&l) {
            Ok(Some(p)) => p,
            Ok(None) => return,
            Err(e) => return self.load_failed(el, format!("{name}: {e}")),
        };
        for w in &l.warnings {
            eprintln!("warning: {w}");
        }
        self.settings.antialiased = self.opts.antialiased.resolve(l.trained_antialiased);
        let extent = Extent::of_cloud(&l.cloud);
        let fit = Extent::of_cloud_at(&l.cloud, splatgl::camera::FIT_SIGMAS);
        let rig = Rig::from_camera(&cam, focus, up.vector());
        self.controls.fly_speed = extent.map_or(1.0, |e| (0.5 * e.radius()).max(0.05));
        self.controls.stop();
        let budget = if l.cloud.len() < l.file_len {
            format!(" (of {}, --max-splats)", l.file_len)
        } else {
            String::new()
        };
        let format = l.format.map_or("built in", Format::name);
        println!(
            "loaded: {name}: {} splats{budget}, SH degree {}, {format}, up {}, stale tolerance {tau}, \
             kernel {}",
            l.cloud.len(),
            l.cloud.sh_degree,
            up.name(),
            if self.settings.antialiased {
                "antialiased"
            } else {
                "plain"
            }
        );
        let facts = self.facts_of(&l, &name);
        let streamer = l.streamer.take().map(|s| (s, None));
        self.shown = Some(Shown {
            streamer,
            paged,
            facts,
            name,
            path: l.path,
            len: l.cloud.len(),
            file_len: l.file_len,
            sh_degree: l.cloud.sh_degree,
            cameras: l.cameras,
            extent,
            fit,
            orders,
            uploaded: None,
            up,
            home: rig,
        });
        self.rig = Some(rig);
        self.camera_index = 0;
        self.frames_shown = 0;
        self.prev_eye = None;
        if let Some(b) = self.opts.bench.filter(|_| self.bench.is_none()) {
            self.bench = Some(BenchRun::new(b, rig));
        }
        self.update_title(true);
        self.request_redraw();
    }

    /// Uploads what was loaded: the cloud, or a tileset's first selection into GPU pages
    /// (its counts shown). `Ok(None)` without a window or renderer; `Ok(Some(pages))` else
    /// (`None` pages for a plain cloud).
    fn upload_loaded(&mut self, l: &Loaded) -> Result<Option<Option<paging::Paged>>, String> {
        let (Some(win), Some(renderer)) = (&self.win, &mut self.renderer) else {
            return Ok(None);
        };
        let mut paged = None;
        if l.tiles.is_empty() {
            renderer
                .upload(&win.gl, &l.cloud)
                .map_err(|e| e.to_string())?;
            self.live.tiles = None;
            return Ok(Some(paged));
        }
        let budget = self.opts.tiles.select.splat_budget;
        let p = paging::place(renderer, &win.gl, &mut paged, &l.tiles, budget)?;
        println!("{}", p.summary());
        self.live.tiles = Some(TileCounts {
            selected: l.tiles.len(),
            splats: l.cloud.len() as u64,
            budget,
            pages_used: p.used,
            pages: p.pages,
            ..Default::default()
        });
        Ok(Some(paged))
    }

    /// A tileset's new selection: its new tiles written into GPU pages (the others stay where
    /// they are), with a sorter for its splats; the camera stays. Prints the counts (`tiles:
    /// …`, `gpu: …`) and the tiles skipped.
    pub(super) fn install_tiles(&mut self, el: &ActiveEventLoop, f: splatgl::tiles::StreamFrame) {
        for w in &f.warnings {
            eprintln!("warning: {w}");
        }
        println!("{}", f.summary());
        self.status = (f.pending > 0).then(|| format!("loading {} tiles", f.pending));
        let mut counts = self.live.tiles.unwrap_or_default();
        counts.selected = f.tiles;
        counts.splats = f.splats;
        counts.budget = f.budget;
        counts.loading = f.pending;
        counts.resident = f.resident_tiles;
        counts.resident_mb = f.resident_bytes.div_ceil(1 << 20);
        self.live.tiles = Some(counts);
        let (Some(shown), Some(tiles)) = (&mut self.shown, f.selection) else {
            self.update_title(true);
            return;
        };
        let positions: Vec<[f32; 3]> = tiles
            .iter()
            .flat_map(|(_, c)| c.positions.iter().copied())
            .collect();
        let len = positions.len();
        let tau = match tiles.iter().max_by_key(|(_, c)| c.len()) {
            Some((_, c)) => self.opts.stale.tolerance(c),
            None => 0.0,
        };
        let mut orders = match Orders::new(positions.into(), tau, self.opts.sort_sync) {
            Ok(o) => o,
            Err(e) => return self.load_failed(el, format!("sorter thread: {e}")),
        };
        orders.set_crop(self.crop);
        let (Some(win), Some(renderer)) = (&self.win, &mut self.renderer) else {
            return;
        };
        let budget = self.opts.tiles.select.splat_budget;
        match paging::place(renderer, &win.gl, &mut shown.paged, &tiles, budget) {
            Ok(p) => {
                println!("{}", p.summary());
                if let Some(t) = &mut self.live.tiles {
                    (t.pages_used, t.pages) = (p.used, p.pages);
                }
            }
            Err(e) => return self.load_failed(el, e),
        }
        shown.orders = orders;
        shown.uploaded = None;
        shown.len = len;
        (shown.facts.splats, shown.facts.file_splats, shown.file_len) = (len, len, len);
        shown.sh_degree = tiles.iter().map(|(_, c)| c.sh_degree).max().unwrap_or(0);
        self.update_title(true);
        self.request_redraw();
    }
}
