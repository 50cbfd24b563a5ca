//! The panel's side of the viewer: the facts it shows about a scene, one interface pass per
//! frame (after the splats and the screenshot read-back, before the swap), and the settings
//! and actions it hands back.

use super::App;
use crate::loading::Loaded;
use crate::panel::{Action, Facts, FrameView, Settings};
use splatgl::camera::Camera;
use splatgl::cloud::ColorSpace;

impl App {
    /// What the panel says about `l`.
    pub(super) fn facts_of(&self, l: &Loaded, name: &str) -> Facts {
        let c = &l.cloud;
        let bounds = (!c.positions.is_empty()).then(|| {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in c
                .positions
                .iter()
                .filter(|p| p.iter().all(|v| v.is_finite()))
            {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            (lo, hi)
        });
        let mut cameras: Vec<String> = (0..l.cameras.len())
            .map(|i| format!("glTF camera node {i}"))
            .collect();
        cameras.extend(
            self.json_cameras
                .iter()
                .enumerate()
                .map(|(i, e)| format!("view {i}: {}", e.img_name)),
        );
        let aa = self.settings.antialiased;
        Facts {
            name: name.to_owned(),
            path: l.path.as_ref().map(|p| p.display().to_string()),
            format: l.format.map_or("built in", |f| f.name()).to_owned(),
            container: l.container.clone(),
            splats: c.len(),
            file_splats: l.file_len,
            sh_degree: c.sh_degree,
            colour_space: c.meta.color_space.to_string_with(ColorSpace::as_str),
            kernel: format!(
                "{}{}",
                if aa { "antialiased" } else { "plain" },
                if l.trained_antialiased {
                    " (the file says: trained antialiased)"
                } else {
                    ""
                }
            ),
            bounds: bounds.filter(|(lo, hi)| lo[0] <= hi[0]),
            warnings: l.warnings.clone(),
            cameras,
        }
    }

    /// Runs and paints the panel over the frame in the back buffer (when shown), then
    /// applies what it changed.
    pub(super) fn interface_pass(&mut self, camera: &Camera, window: (u32, u32)) {
        let (Some(panel), Some(win), Some(shown)) = (&mut self.panel, &self.win, &self.shown)
        else {
            return;
        };
        if !panel.visible {
            return;
        }
        let (fps, mean, p99, sort) = self.stats.summary();
        self.live.fps = fps;
        self.live.frame_ms = (mean, p99);
        self.live.sort_ms = sort;
        self.live.order = self.stats.order_text();
        let ms = |d: std::time::Duration| d.as_secs_f32() * 1e3;
        self.live.ui_ms = (ms(panel.cpu.layout), ms(panel.cpu.paint));
        let before = Settings {
            sh_degree: self.settings.sh_degree.unwrap_or(3).min(shown.sh_degree),
            background: self.opts.background,
            resolution_scale: self.opts.resolution_scale,
            crop: self.crop,
            show_crop: self.show_crop,
            budget: self.budget_edit,
        };
        let mut s = before.clone();
        let view = FrameView {
            facts: &shown.facts,
            live: &self.live,
            up: shown.up,
            camera,
            resolution_scale: self.opts.resolution_scale,
        };
        panel.run(&win.window, view, &mut s, &mut self.actions);
        panel.paint(window);
        let dragging = panel.pointer_down();
        if s != before {
            self.apply(&before, s);
        }
        if self.crop_edited && !dragging {
            self.crop_edited = false;
            self.print_crop();
        }
        let mut actions = std::mem::take(&mut self.actions);
        for a in actions.drain(..) {
            self.act(a);
        }
        self.actions = actions;
    }

    /// Takes the settings the panel edited.
    fn apply(&mut self, before: &Settings, s: Settings) {
        if s.sh_degree != before.sh_degree {
            self.settings.sh_degree = Some(s.sh_degree);
        }
        self.opts.background = s.background;
        self.opts.resolution_scale = s.resolution_scale;
        if s.crop != before.crop {
            self.crop = s.crop;
            self.crop_edited = true;
            if let Some(shown) = &mut self.shown {
                shown.orders.set_crop(s.crop);
            }
        }
        self.show_crop = s.show_crop;
        self.budget_edit = s.budget;
        self.request_redraw();
    }

    /// Prints the crop box as `render --crop` takes it (after an edit in the panel ends).
    fn print_crop(&self) {
        match self.crop {
            Some(b) => {
                let v: Vec<String> = [b.min, b.max].concat().iter().map(f32::to_string).collect();
                let v = v.join(",");
                println!("crop: --crop {v} ({} splats drawn)", self.live.drawn);
            }
            None => println!("crop: off"),
        }
    }

    /// Does what the panel asked for.
    fn act(&mut self, a: Action) {
        match a {
            Action::Camera(i) => self.go_to_camera(i),
            Action::Up(axis) => self.frame_cloud(Some(axis)),
            Action::Budget(b) => {
                self.opts.max_splats = b;
                let path = self.shown.as_ref().and_then(|s| s.path.clone());
                self.start_load(path);
            }
            Action::Reset => self.reset_view(),
            Action::Frame => self.frame_cloud(None),
            Action::Screenshot => self.screenshot = true,
            Action::Open => self.open_dialog(),
        }
        self.request_redraw();
    }
}
