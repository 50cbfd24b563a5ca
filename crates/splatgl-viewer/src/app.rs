//! The event loop: the window and its context, events → controls and commands, background
//! loads (installed when they finish; a failure keeps the previous scene).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::Vec3;
use winit::application::ApplicationHandler;
use winit::dpi::LogicalSize;
use winit::event::{MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::PhysicalKey;
use winit::window::{Fullscreen, Window, WindowId};

mod commands;
mod frame;
mod interface;
mod paging;
mod scene;

use super::controls::Controls;
use super::draw::Targets;
use super::loading::LoadEvent;
use super::panel::{Action, Facts, Live, Panel};
use super::rig::Rig;
use super::stats::Stats;
use super::surface::GlSurfaceWindow;
use super::{ViewerError, ViewerOptions};
use frame::BenchRun;
use splatgl::camera::{CamerasJsonEntry, Extent, GltfPerspective, UpAxis};
use splatgl::gl::{DrawSettings, SplatRenderer};
use splatgl::load::LoadOptions;
use splatgl::sort::StaleOrders as Orders;

/// Events from other threads.
#[derive(Debug)]
pub(super) enum UserEvent {
    /// From a loading thread.
    Load(LoadEvent),
    /// A path chosen in the `O` dialog (or typed on stdin).
    Open(PathBuf),
}

/// The scene on screen.
pub(super) struct Shown {
    name: String,
    path: Option<PathBuf>,
    len: usize,
    file_len: usize,
    sh_degree: u8,
    cameras: Vec<GltfPerspective>,
    extent: Option<Extent>,
    /// The part of the content default views fit to the image ([`splatgl::camera::FIT_SIGMAS`]
    /// boxes); its centre is the pivot.
    fit: Option<Extent>,
    orders: Orders,
    /// Generation of the order in the renderer's buffer.
    uploaded: Option<u64>,
    up: UpAxis,
    home: Rig,
    /// What the panel says about the scene.
    facts: Facts,
    /// A tileset's streaming thread, and the camera it was last given.
    streamer: Option<(splatgl::tiles::Streamer, Option<splatgl::camera::Camera>)>,
    /// A tileset's GPU pages (`None`: the cloud is uploaded whole).
    paged: Option<paging::Paged>,
}

/// The viewer's state.
pub(super) struct App {
    opts: ViewerOptions,
    load_opts: Arc<LoadOptions>,
    proxy: EventLoopProxy<UserEvent>,
    win: Option<GlSurfaceWindow>,
    renderer: Option<SplatRenderer>,
    targets: Targets,
    shown: Option<Shown>,
    rig: Option<Rig>,
    controls: Controls,
    settings: DrawSettings,
    stats: Stats,
    bench: Option<BenchRun>,
    load_id: u64,
    loading_name: String,
    /// Progress of the load under way (title).
    status: Option<String>,
    /// The last error, shown in the title for a few seconds.
    message: Option<(String, Instant)>,
    screenshot: bool,
    camera_index: usize,
    json_cameras: Vec<CamerasJsonEntry>,
    last_frame: Option<Instant>,
    last_title: Option<Instant>,
    frames_shown: u64,
    prev_eye: Option<Vec3>,
    /// The last frame wants a next one without new input.
    animating: bool,
    dialog_open: Arc<AtomicBool>,
    /// The interface (`None` where its painter could not be made).
    panel: Option<Panel>,
    /// The panel's statistics.
    live: Live,
    /// The crop box applied in the sort (splats outside are not drawn).
    crop: Option<splatgl::cull::CropBox>,
    /// Show the crop box's wireframe and handles.
    show_crop: bool,
    /// The panel changed the crop box since it was last printed.
    crop_edited: bool,
    /// The panel's `--max-splats` field (applied by reloading).
    budget_edit: Option<usize>,
    /// What the panel asked for in the last frame.
    actions: Vec<Action>,
    result: Result<(), ViewerError>,
}

pub(super) fn run(opts: ViewerOptions) -> Result<(), ViewerError> {
    let json_cameras = opts.view.cameras_json_entries()?;
    let event_loop = EventLoop::<UserEvent>::with_user_event()
        .build()
        .map_err(|e| ViewerError::Window(e.to_string()))?;
    event_loop.set_control_flow(ControlFlow::Wait);
    let (crop, budget_edit) = (opts.crop, opts.max_splats);
    let mut app = App {
        load_opts: Arc::new(opts.load),
        // (Struct update: DrawSettings may gain fields, e.g. state restoring.)
        settings: DrawSettings {
            sh_degree: Some(opts.sh_degree),
            ..DrawSettings::default()
        },
        opts: ViewerOptions {
            load: Default::default(),
            ..opts
        },
        proxy: event_loop.create_proxy(),
        win: None,
        renderer: None,
        targets: Targets::default(),
        shown: None,
        rig: None,
        controls: Controls::default(),
        stats: Stats::default(),
        bench: None,
        load_id: 0,
        loading_name: String::new(),
        status: None,
        message: None,
        screenshot: false,
        camera_index: 0,
        json_cameras,
        last_frame: None,
        last_title: None,
        frames_shown: 0,
        prev_eye: None,
        animating: false,
        dialog_open: Arc::new(AtomicBool::new(false)),
        panel: None,
        live: Live::default(),
        crop,
        show_crop: true,
        crop_edited: false,
        budget_edit,
        actions: Vec::new(),
        result: Ok(()),
    };
    app.settings.depth_test = false; // the viewer has no depth buffer to test against
    app.targets.force_rgba8 = app.opts.target == super::TargetChoice::Rgba8;
    event_loop
        .run_app(&mut app)
        .map_err(|e| ViewerError::Window(e.to_string()))?;
    app.result
}

impl App {
    /// The window's initial logical size: --width/--height, else the cameras.json view's,
    /// else 1280 × 720 (a missing side from the other's aspect ratio).
    fn window_size(&self) -> (u32, u32) {
        let v = &self.opts.view;
        match self.json_cameras.get(v.view) {
            Some(e) if v.width.is_none() && v.height.is_none() => (e.width, e.height),
            _ => v.size_or(1280, 720),
        }
    }

    /// The image size: the window's pixels × --resolution-scale.
    pub fn render_size(&self) -> (u32, u32) {
        let s = self.win.as_ref().map_or((1, 1), |w| {
            let p = w.window.inner_size();
            (p.width, p.height)
        });
        let k = self.opts.resolution_scale;
        let f = |v: u32| ((v as f32 * k).round() as u32).max(1);
        (f(s.0), f(s.1))
    }

    /// Stops with an error.
    pub fn fail(&mut self, el: &ActiveEventLoop, e: ViewerError) {
        self.result = Err(e);
        el.exit();
    }

    pub fn request_redraw(&self) {
        if let Some(w) = &self.win {
            w.window.request_redraw();
        }
    }

    /// A window event (also the test hook's injected `DroppedFile`).
    pub fn handle(&mut self, el: &ActiveEventLoop, event: WindowEvent) {
        if let (Some(panel), Some(w)) = (&mut self.panel, &self.win)
            && !matches!(event, WindowEvent::RedrawRequested)
            && panel.on_event(&w.window, &event)
        {
            self.request_redraw();
            return;
        }
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::Resized(_) => {
                if let Some(w) = &self.win {
                    w.resize();
                }
                self.request_redraw();
            }
            WindowEvent::RedrawRequested => self.frame(el),
            WindowEvent::DroppedFile(p) => {
                println!("open: {}", p.display());
                self.start_load(Some(p));
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                if self.controls.key(code, event.state) {
                    self.request_redraw();
                } else if event.state.is_pressed() && !event.repeat {
                    self.command(el, code, &event.logical_key);
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                // In image pixels (the window's × --resolution-scale), like the camera.
                let k = self.opts.resolution_scale;
                let p = glam::Vec2::new(position.x as f32, position.y as f32) * k;
                self.controls.cursor_moved(p);
                self.request_redraw();
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.controls.button(button, state);
                self.request_redraw();
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.controls.wheel(notches);
                self.request_redraw();
            }
            _ => {}
        }
    }

    /// The test hook (feature `testing`): a file "dropped" through [`App::handle`] after a few
    /// frames.
    #[cfg(feature = "testing")]
    pub fn test_drop(&mut self, el: &ActiveEventLoop) {
        if self.shown.is_some()
            && self.frames_shown >= 3
            && let Some(p) = self.opts.test_drop.take()
        {
            self.handle(el, WindowEvent::DroppedFile(p));
        }
    }
}

impl App {
    /// Whether the test hook still has a file to drop (never without feature `testing`).
    fn drop_pending(&self) -> bool {
        #[cfg(feature = "testing")]
        return self.opts.test_drop.is_some();
        #[cfg(not(feature = "testing"))]
        false
    }
}

impl ApplicationHandler<UserEvent> for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.win.is_some() {
            return;
        }
        let (w, h) = self.window_size();
        let mut attrs = Window::default_attributes()
            .with_title("splatgl")
            .with_inner_size(LogicalSize::new(w, h));
        if self.opts.fullscreen {
            attrs = attrs.with_fullscreen(Some(Fullscreen::Borderless(None)));
        }
        let win = match GlSurfaceWindow::new(el, attrs, self.opts.vsync) {
            Ok(w) => w,
            Err(e) => return self.fail(el, ViewerError::Window(e)),
        };
        match SplatRenderer::new(&win.gl) {
            Ok(r) => self.renderer = Some(r),
            Err(e) => return self.fail(el, e.into()),
        }
        eprintln!("GL: {}", win.info());
        match Panel::new(&win.window, Arc::clone(&win.gl), !self.opts.no_ui) {
            Ok(p) => self.panel = Some(p),
            Err(e) => eprintln!("warning: no on-screen panel: {e}"),
        }
        self.win = Some(win);
        self.start_load(self.opts.file.clone());
    }

    fn user_event(&mut self, el: &ActiveEventLoop, event: UserEvent) {
        match event {
            UserEvent::Load(LoadEvent::Progress { id, done, total }) if id == self.load_id => {
                let pct = (100 * done).checked_div(total).unwrap_or(100);
                self.status = Some(format!("loading {} {pct}%", self.loading_name));
                self.progress_line(pct);
                self.update_title(true);
            }
            UserEvent::Load(LoadEvent::Decoding { id }) if id == self.load_id => {
                self.status = Some(format!("decoding {}", self.loading_name));
                self.progress_line(100);
                self.update_title(true);
            }
            UserEvent::Load(LoadEvent::Done { id, result }) if id == self.load_id => {
                self.status = None;
                match result {
                    Ok(l) => self.install(el, *l),
                    Err(msg) => self.load_failed(el, msg),
                }
            }
            UserEvent::Load(LoadEvent::Tiles { id, frame }) if id == self.load_id => {
                self.install_tiles(el, *frame)
            }
            UserEvent::Load(_) => {} // a load superseded by a newer one
            UserEvent::Open(p) => self.start_load(Some(p)),
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        self.handle(el, event);
    }

    fn about_to_wait(&mut self, _el: &ActiveEventLoop) {
        let hook = cfg!(feature = "testing") && self.drop_pending() && self.shown.is_some();
        let ui = self
            .panel
            .as_ref()
            .is_some_and(|p| p.visible && p.wants_repaint);
        if self.animating || self.bench.is_some() || self.screenshot || hook || ui {
            self.request_redraw();
        }
    }

    fn exiting(&mut self, _el: &ActiveEventLoop) {
        if let (Some(win), Some(r)) = (&self.win, &mut self.renderer) {
            r.destroy(&win.gl);
            self.targets.destroy(&win.gl);
        }
        if let Some(p) = &mut self.panel {
            p.destroy();
        }
    }
}
