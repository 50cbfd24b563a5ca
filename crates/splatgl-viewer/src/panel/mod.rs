//! The viewer's on-screen interface: a collapsible side panel (scene facts, frame statistics,
//! view settings, the camera list, the crop box) and the crop box's wireframe, drawn with
//! `egui` through `egui-winit` (input) and `egui_glow` (painting) after the splats.
//!
//! **A guest in the viewer's context.** The painter is drawn last, into the window's
//! framebuffer, after the screenshot read-back (so `P` and the panel's "Screenshot" never show
//! it). It leaves the scissor test disabled and changes program, VAO, buffer and texture
//! bindings, blend state, the viewport and (desktop) `GL_FRAMEBUFFER_SRGB`; the splat frame
//! path sets every one of those it uses for each draw (`gl/state.rs`), so nothing the panel
//! leaves reaches the splats — `crates/splatgl-viewer/tests/it/viewer_panel_gl.rs` holds it to that.
//!
//! **Input.** Every window event goes to egui while the panel is shown; the viewer's own
//! controls still get it unless it belongs to the interface: a press on the panel or on a crop
//! handle, a wheel turn over the panel, a key while a text field has focus. Releases and
//! cursor moves always reach the controls (so a drag that began on the scene ends there).
//!
//! **HiDPI.** egui lays out in points; the window's scale factor (and its changes) come from
//! winit through egui-winit, and the painter draws in the window's physical pixels.

mod crop;
mod model;
mod ui;

pub use model::{Action, Facts, Live, Settings, TileCounts};

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui::ViewportId;
use winit::event::{ElementState, WindowEvent};
use winit::window::Window;

use splatgl::camera::{Camera, UpAxis};

/// What one interface pass needs to know about the frame.
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    /// The scene's facts.
    pub facts: &'a Facts,
    /// The statistics.
    pub live: &'a Live,
    /// The scene's up axis.
    pub up: UpAxis,
    /// The camera drawn (image pixels).
    pub camera: &'a Camera,
    /// Image pixels per window pixel (`--resolution-scale`).
    pub resolution_scale: f32,
}

/// The interface: egui's context, its winit input state and its GL painter.
pub struct Panel {
    ctx: egui::Context,
    input: egui_winit::State,
    painter: egui_glow::Painter,
    /// Shown (`G` toggles it; `--no-ui` starts without it).
    pub visible: bool,
    primitives: Vec<egui::ClippedPrimitive>,
    textures: egui::TexturesDelta,
    pixels_per_point: f32,
    /// The pointer (points), from the newest cursor event: a press is routed by where it is
    /// now, not by the hover state of the last frame (input may arrive before a frame).
    pointer: Option<egui::Pos2>,
    /// Where the panel and the crop handles were in the last frame (points).
    panel_rect: egui::Rect,
    handle_rects: Vec<egui::Rect>,
    /// `SPLATGL_VIEWER_LAYOUT` is set: print where the camera buttons are.
    layout_log: bool,
    logged: Vec<String>,
    /// egui asked for another frame (an animation, a tooltip).
    pub wants_repaint: bool,
    /// An event reached egui since the last layout.
    fed: bool,
    /// When the interface was last laid out, and what it showed then.
    laid_out: Option<(Instant, Seen)>,
    /// CPU time of the last frame's layout (zero when the previous one was reused) and
    /// painting.
    pub cpu: Cpu,
}

/// CPU time of the interface in one frame.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cpu {
    /// egui's pass and tessellation (zero when the last layout was reused).
    pub layout: Duration,
    /// Texture updates and the GL calls of painting.
    pub paint: Duration,
}

/// How often the statistics are refreshed on screen (and so, without input, the interface
/// laid out again): the rate of the title bar.
const REFRESH: Duration = Duration::from_millis(250);

/// What a layout showed besides the statistics: when it changes the interface is laid out
/// again at once.
#[derive(Debug, Clone, PartialEq)]
struct Seen {
    settings: Settings,
    up: UpAxis,
    scene: (String, usize, usize),
    /// The camera and image size, when the crop box is drawn over the scene.
    camera: Option<([f32; 16], u32, u32, f32)>,
}

impl Seen {
    fn of(view: &FrameView<'_>, settings: &Settings) -> Self {
        let c = view.camera;
        let overlay = settings.show_crop && settings.crop.is_some();
        Seen {
            settings: settings.clone(),
            up: view.up,
            scene: (
                view.facts.name.clone(),
                view.facts.splats,
                view.facts.cameras.len(),
            ),
            camera: overlay.then(|| {
                let m = c.world_to_camera.to_cols_array();
                (m, c.width, c.height, c.fx)
            }),
        }
    }
}

impl std::fmt::Debug for Panel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Panel")
            .field("visible", &self.visible)
            .finish_non_exhaustive()
    }
}

impl Panel {
    /// The interface for `window`, painting with `gl` (current).
    ///
    /// # Errors
    /// When egui's shaders do not compile or its buffers cannot be made.
    pub fn new(window: &Window, gl: Arc<glow::Context>, visible: bool) -> Result<Self, String> {
        let painter = egui_glow::Painter::new(gl, "", None, true).map_err(|e| e.to_string())?;
        let ctx = egui::Context::default();
        let input = egui_winit::State::new(
            ctx.clone(),
            ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(painter.max_texture_side()),
        );
        Ok(Panel {
            ctx,
            input,
            painter,
            visible,
            primitives: Vec::new(),
            textures: egui::TexturesDelta::default(),
            pixels_per_point: window.scale_factor() as f32,
            pointer: None,
            panel_rect: egui::Rect::NOTHING,
            handle_rects: Vec::new(),
            layout_log: std::env::var_os("SPLATGL_VIEWER_LAYOUT").is_some(),
            logged: Vec::new(),
            wants_repaint: false,
            fed: true,
            laid_out: None,
            cpu: Cpu::default(),
        })
    }

    /// Gives `event` to the interface; whether it belongs to the interface only (the
    /// viewer's controls must not act on it).
    pub fn on_event(&mut self, window: &Window, event: &WindowEvent) -> bool {
        let scale = matches!(event, WindowEvent::ScaleFactorChanged { .. });
        if !(self.visible || scale) {
            return false;
        }
        let resp = self.input.on_window_event(window, event);
        self.wants_repaint |= resp.repaint;
        self.fed = true;
        match event {
            WindowEvent::CursorMoved { position, .. } => {
                let k = self.pixels_per_point.max(1e-3) as f64;
                self.pointer = Some(egui::pos2((position.x / k) as f32, (position.y / k) as f32));
            }
            WindowEvent::CursorLeft { .. } => self.pointer = None,
            _ => {}
        }
        let on = |r: &egui::Rect| self.pointer.is_some_and(|p| r.contains(p));
        let over = on(&self.panel_rect) || self.ctx.is_pointer_over_egui();
        match event {
            WindowEvent::MouseInput { state, .. } => {
                *state == ElementState::Pressed
                    && (over
                        || self.handle_rects.iter().any(on)
                        || self.ctx.egui_wants_pointer_input())
            }
            WindowEvent::MouseWheel { .. } => over,
            WindowEvent::KeyboardInput { event, .. } => {
                event.state.is_pressed() && self.ctx.egui_wants_keyboard_input()
            }
            _ => false,
        }
    }

    /// Lays out one frame of the interface (and the crop box over the scene); edits
    /// `settings` in place and pushes what the viewer must do to `actions`. Without input,
    /// a change of what it shows, or an animation, the last layout is reused for
    /// [`REFRESH`] (only the statistics would change).
    pub fn run(
        &mut self,
        window: &Window,
        view: FrameView<'_>,
        settings: &mut Settings,
        actions: &mut Vec<Action>,
    ) {
        let started = Instant::now();
        let seen = Seen::of(&view, settings);
        let fresh = self
            .laid_out
            .as_ref()
            .is_some_and(|(t, s)| t.elapsed() < REFRESH && *s == seen);
        if fresh && !self.fed && !self.wants_repaint {
            self.cpu.layout = Duration::ZERO;
            return;
        }
        self.fed = false;
        let raw = self.input.take_egui_input(window);
        let mut rects = ui::CameraRects::new();
        let mut overlay = crop::Overlay::default();
        let mut panel_rect = egui::Rect::NOTHING;
        let mut asked = Vec::new();
        let out = self.ctx.run_ui(raw, |root| {
            // egui may run the closure twice in a frame (a discarded sizing pass): only the
            // last pass counts.
            rects.clear();
            asked.clear();
            overlay = crop::Overlay::default();
            panel_rect = egui::Panel::left("splatgl-panel")
                .default_size(280.0)
                .show(root, |ui| {
                    ui::contents(
                        ui, view.facts, view.live, view.up, settings, &mut asked, &mut rects,
                    );
                })
                .response
                .rect;
            let px_to_points = 1.0 / (view.resolution_scale * root.ctx().pixels_per_point());
            if settings.show_crop
                && let Some(b) = &mut settings.crop
            {
                let area = root.available_rect_before_wrap();
                overlay = crop::show(root, area, view.camera, px_to_points, b);
            }
        });
        actions.append(&mut asked);
        self.panel_rect = panel_rect;
        self.handle_rects = overlay
            .handles
            .iter()
            .flatten()
            .map(|&c| crop::handle_rect(c))
            .collect();
        self.input
            .handle_platform_output(window, out.platform_output);
        self.pixels_per_point = out.pixels_per_point;
        self.primitives = self.ctx.tessellate(out.shapes, out.pixels_per_point);
        self.textures.append(out.textures_delta);
        self.wants_repaint = out
            .viewport_output
            .get(&ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        self.log_layout(panel_rect, &rects, &overlay.handles);
        // What the pass may have edited counts as seen: no second layout for it.
        self.laid_out = Some((Instant::now(), Seen::of(&view, settings)));
        self.cpu.layout = started.elapsed();
    }

    /// Paints the last [`Panel::run`] into the bound framebuffer of `size` physical pixels.
    pub fn paint(&mut self, size: (u32, u32)) {
        let started = Instant::now();
        for (id, deltas) in self.textures.set.drain() {
            for d in deltas {
                self.painter.set_texture(id, &d);
            }
        }
        let prims = std::mem::take(&mut self.primitives);
        self.painter
            .paint_primitives([size.0, size.1], self.pixels_per_point, &prims);
        self.primitives = prims;
        for id in self.textures.free.drain() {
            self.painter.free_texture(id);
        }
        self.cpu.paint = started.elapsed();
    }

    /// With `SPLATGL_VIEWER_LAYOUT` set: prints `layout: panel X Y W H`, `layout: camera I X
    /// Y W H` for each camera button and `layout: crop-face F X Y` for each crop handle
    /// (window pixels, top left origin) whenever they move, so that scripted input
    /// (`xdotool`) can click them.
    fn log_layout(
        &mut self,
        panel: egui::Rect,
        rects: &[egui::Rect],
        handles: &[Option<egui::Pos2>; 6],
    ) {
        if !self.layout_log {
            return;
        }
        let k = self.pixels_per_point;
        let px = |v: f32| (v * k).round() as i32;
        let rect = |r: &egui::Rect| {
            let [x, y, w, h] = [r.min.x, r.min.y, r.width(), r.height()].map(px);
            format!("{x} {y} {w} {h}")
        };
        let mut now = vec![format!("layout: panel {}", rect(&panel))];
        now.extend(
            rects
                .iter()
                .enumerate()
                .map(|(i, r)| format!("layout: camera {i} {}", rect(r))),
        );
        now.extend(handles.iter().enumerate().filter_map(|(f, p)| {
            p.map(|p| format!("layout: crop-face {f} {} {}", px(p.x), px(p.y)))
        }));
        if now != self.logged {
            for l in &now {
                println!("{l}");
            }
            self.logged = now;
        }
    }

    /// Whether a pointer button is held on the interface (a drag in progress).
    pub fn pointer_down(&self) -> bool {
        self.ctx.input(|i| i.pointer.any_down())
    }

    /// Deletes the painter's GL objects (context current).
    pub fn destroy(&mut self) {
        self.painter.destroy();
    }
}
