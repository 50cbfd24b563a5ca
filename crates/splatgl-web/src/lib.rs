//! splatgl in the browser: the library's loaders, cull, sort and GL backend over a WebGL2
//! canvas, exported to JavaScript with `wasm-bindgen` (`web/splatgl.js` wraps it as
//! `splatgl.create(canvas)`; `docs/web.md`).
//!
//! Everything here is `wasm32` only; natively the crate is empty. The sort runs on the page's
//! thread: rayon's pool has no threads on `wasm32-unknown-unknown`, so the same radix sort
//! runs single-threaded behind the same API (`FrameSort::Sync`, the default).
#![cfg(target_arch = "wasm32")]

use glam::{Mat4, Vec3};
use glow::HasContext;
use splatgl::SplatCloud;
use splatgl::camera::{Camera, GltfPerspective, SceneView, ViewOptions};
use splatgl::cloud::ColorSpace;
use splatgl::files::Format;
use splatgl::gl::frame::{Blend, FrameTargets, Output};
use splatgl::gl::{ColorFormat, DrawSettings, OffscreenTarget, SplatRenderer};
use splatgl::image::PngDepth;
use splatgl::load::{LoadOptions, load_bytes};
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use web_sys::{HtmlCanvasElement, WebGl2RenderingContext};

mod offline;

/// What the renderer holds of the loaded file besides the GPU copy: the cloud (for framing
/// and the info), its glTF cameras and its format.
struct Loaded {
    cloud: SplatCloud,
    cameras: Vec<GltfPerspective>,
    format: Option<Format>,
    name: String,
}

/// A splat renderer on a WebGL2 canvas.
#[wasm_bindgen]
pub struct Renderer {
    gl: glow::Context,
    renderer: SplatRenderer,
    targets: FrameTargets,
    loaded: Option<Loaded>,
    view: Mat4,
    projection: Mat4,
    sh_degree: Option<u8>,
    canvas: HtmlCanvasElement,
    /// `draw` blends in a float target resolved into the canvas (the default, as the RC
    /// recommends), else directly in the canvas's 8 bits ([`Renderer::set_target`]).
    float_blending: bool,
    /// The float target of `draw` (made at the canvas's size on first use).
    float: Option<OffscreenTarget>,
    /// [`Renderer::dispose`] ran: every GPU object is gone.
    disposed: bool,
    /// What one load may take ([`Renderer::set_limits`]).
    limits: splatgl::load::Limits,
}

/// Default [`Renderer::set_limits`] `max_bytes`: 1 GiB. A load holds the file, the cloud
/// (~250 bytes per splat at SH degree 3) and the upload's staging copy in wasm's 4 GiB at
/// once, and wasm cannot recover from a failed allocation: the bounds keep a load within it.
pub const WEB_MAX_BYTES: u64 = 1 << 30;
/// Default [`Renderer::set_limits`] `max_splats`: 4 Mi (about 1 GiB of cloud at SH degree 3).
pub const WEB_MAX_SPLATS: u64 = 1 << 22;

/// The loader's limits in the browser: [`WEB_MAX_BYTES`] for the file and what it inflates
/// to, [`WEB_MAX_SPLATS`].
fn web_limits() -> splatgl::load::Limits {
    splatgl::load::Limits {
        max_splats: WEB_MAX_SPLATS,
        max_bytes: WEB_MAX_BYTES,
        max_decompressed_bytes: WEB_MAX_BYTES,
        ..Default::default()
    }
}

fn js_error(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// A column-major 4×4 matrix from 16 finite numbers.
fn matrix(what: &str, m: &[f32]) -> Result<Mat4, JsError> {
    if m.len() != 16 || m.iter().any(|v| !v.is_finite()) {
        return Err(JsError::new(&format!(
            "{what}: expected 16 finite numbers (column-major), got {}",
            m.len()
        )));
    }
    Ok(Mat4::from_cols_slice(m))
}

#[wasm_bindgen]
impl Renderer {
    /// A renderer drawing on `canvas` (a WebGL2 context is created on it: no antialiasing,
    /// premultiplied alpha, the drawing buffer kept for `toDataURL`).
    #[wasm_bindgen(constructor)]
    pub fn new(canvas: HtmlCanvasElement) -> Result<Renderer, JsError> {
        // A panic (a bug: every input error is a JsError) says where on the console before
        // the module traps.
        static HOOK: std::sync::Once = std::sync::Once::new();
        HOOK.call_once(|| {
            std::panic::set_hook(Box::new(|info| {
                web_sys::console::error_1(&format!("splatgl: {info}").into());
            }))
        });
        let attrs = js_sys::Object::new();
        for (k, v) in [
            ("antialias", false),
            ("premultipliedAlpha", true),
            ("preserveDrawingBuffer", true),
            ("depth", true),
        ] {
            js_sys::Reflect::set(&attrs, &k.into(), &v.into())
                .map_err(|_| JsError::new("cannot build the context attributes"))?;
        }
        let context = canvas
            .get_context_with_context_options("webgl2", &attrs)
            .map_err(|_| JsError::new("getContext('webgl2') threw"))?
            .ok_or_else(|| JsError::new("this browser gives no WebGL2 context"))?
            .dyn_into::<WebGl2RenderingContext>()
            .map_err(|_| JsError::new("getContext('webgl2') returned something else"))?;
        let gl = glow::Context::from_webgl2_context(context);
        let canvas = canvas.clone();
        let renderer = SplatRenderer::new(&gl).map_err(js_error)?;
        Ok(Renderer {
            gl,
            renderer,
            targets: FrameTargets::default(),
            loaded: None,
            view: Mat4::IDENTITY,
            projection: Mat4::IDENTITY,
            sh_degree: None,
            canvas,
            float_blending: true,
            float: None,
            disposed: false,
            limits: web_limits(),
        })
    }

    /// Loads a splat file from its bytes (`name`'s extension helps detect the format: any
    /// format splatgl reads; a glTF must be self-contained: `.glb`, or `.gltf` with data URIs)
    /// and uploads it, replacing what was loaded. Returns a JSON object: `name`, `format`,
    /// `splats`, `sh_degree`, `cameras` (glTF camera nodes), `warnings` (the loader's
    /// findings). A file that cannot be loaded is an error with the loader's message, and
    /// the previous cloud stays.
    pub fn load(&mut self, bytes: &[u8], name: &str) -> Result<String, JsError> {
        self.live()?;
        let limits = self.limits;
        if bytes.len() as u64 > limits.max_bytes {
            return Err(JsError::new(&format!(
                "{name}: {} bytes, more than the renderer's limit of {} bytes (setLimits({{ maxBytes }}))",
                bytes.len(),
                limits.max_bytes
            )));
        }
        let opts = LoadOptions {
            limits,
            ..LoadOptions::default()
        };
        let scene = load_bytes(bytes, Some(std::path::Path::new(name)), &opts).map_err(js_error)?;
        let warnings: Vec<String> = scene
            .report
            .findings
            .iter()
            .map(|f| f.to_string())
            .collect();
        let format = scene.report.format;
        self.upload(Loaded {
            cloud: scene.cloud,
            cameras: scene.cameras,
            format: Some(format),
            name: name.to_string(),
        })?;
        Ok(self.info(&warnings))
    }

    /// Bounds what one load may take: `max_bytes` of file (and what a compressed format
    /// inflates to; default [`WEB_MAX_BYTES`]) and `max_splats` (default [`WEB_MAX_SPLATS`]).
    /// `None` keeps a bound as it is. A load over a bound is an error naming it, and the
    /// previous scene stays.
    pub fn set_limits(
        &mut self,
        max_bytes: Option<f64>,
        max_splats: Option<f64>,
    ) -> Result<(), JsError> {
        let count = |what: &str, v: f64| -> Result<u64, JsError> {
            if v.is_finite() && v >= 1.0 && v <= 2f64.powi(53) {
                Ok(v as u64)
            } else {
                Err(JsError::new(&format!(
                    "{what}: expected a positive whole number, got {v}"
                )))
            }
        };
        if let Some(b) = max_bytes {
            self.limits.max_bytes = count("maxBytes", b)?;
            self.limits.max_decompressed_bytes = self.limits.max_bytes;
        }
        if let Some(n) = max_splats {
            self.limits.max_splats = count("maxSplats", n)?;
        }
        Ok(())
    }

    /// The bounds of a load: `{"max_bytes": …, "max_splats": …}`.
    pub fn limits(&self) -> String {
        serde_json::json!({
            "max_bytes": self.limits.max_bytes,
            "max_splats": self.limits.max_splats,
        })
        .to_string()
    }

    /// Loads the bundled default scene (what `splatgl render` draws without a file).
    pub fn load_default(&mut self) -> Result<String, JsError> {
        self.live()?;
        self.upload(Loaded {
            cloud: splatgl::synthetic::default_scene(),
            cameras: Vec::new(),
            format: None,
            name: "default scene".into(),
        })?;
        Ok(self.info(&[]))
    }

    /// Uploads `loaded`; when the GPU refuses it, the previous cloud is uploaded again (the
    /// renderer keeps drawing what it had) and the error returned.
    fn upload(&mut self, loaded: Loaded) -> Result<(), JsError> {
        if let Err(e) = self.renderer.upload(&self.gl, &loaded.cloud) {
            if let Some(previous) = &self.loaded {
                // Best effort: it fitted before.
                let _ = self.renderer.upload(&self.gl, &previous.cloud);
            }
            return Err(js_error(e));
        }
        self.loaded = Some(loaded);
        Ok(())
    }

    fn info(&self, warnings: &[String]) -> String {
        let Some(l) = &self.loaded else {
            return "{}".into();
        };
        serde_json::json!({
            "name": l.name,
            "format": l.format.map(|f| format!("{f:?}").to_lowercase()),
            "splats": l.cloud.len(),
            "sh_degree": l.cloud.sh_degree,
            "cameras": l.cameras.len(),
            "warnings": warnings,
        })
        .to_string()
    }

    /// The number of splats loaded (0 before a load).
    pub fn splat_count(&self) -> usize {
        self.loaded.as_ref().map_or(0, |l| l.cloud.len())
    }

    /// The SH degree drawn: `undefined` = the cloud's own, else at most the cloud's.
    pub fn set_sh_degree(&mut self, degree: Option<u8>) {
        self.sh_degree = degree;
    }

    /// The view (world → GL eye space, looking down −z) and projection matrices, each 16
    /// numbers, column-major (as WebGL's `uniformMatrix4fv` takes them).
    pub fn set_camera(&mut self, view: &[f32], projection: &[f32]) -> Result<(), JsError> {
        self.view = matrix("view", view)?;
        self.projection = matrix("projection", projection)?;
        Ok(())
    }

    /// Clears the canvas to `background` (RGB, 0–1) and draws the loaded cloud for the camera
    /// of [`Renderer::set_camera`]: culled, sorted back to front and blended — by default in
    /// a float target (RGBA32F where the browser can blend it, else RGBA16F) resolved into the
    /// canvas (sRGB-encoding `lin_rec709_display` clouds), with `set_target("rgba8")` directly
    /// in the canvas. Returns the milliseconds it
    /// took on the CPU (sort and GL calls; the GPU may still be drawing).
    pub fn draw(&mut self, r: f32, g: f32, b: f32) -> Result<f64, JsError> {
        self.live()?;
        let started = now_ms();
        let (w, h) = self.size();
        let linear = self.renderer.color_space() == ColorSpace::LinRec709Display;
        let bg = if linear {
            [r, g, b].map(|c| splatgl::profile::srgb_decode(c as f64) as f32)
        } else {
            [r, g, b]
        };
        // SAFETY: state calls on the canvas's context, current by construction on the web.
        unsafe {
            self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            self.gl.viewport(0, 0, w, h);
            self.gl.clear_color(r, g, b, 1.0);
            self.gl.clear_depth_f32(1.0);
            self.gl
                .clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        if self.loaded.is_none() || w <= 0 || h <= 0 {
            return Ok(now_ms() - started);
        }
        self.renderer.settings_mut().sh_degree = self.sh_degree;
        let (view, projection) = (self.view, self.projection);
        let viewport = [0, 0, w, h];
        if !self.float_blending {
            self.renderer
                .draw_frame(&self.gl, view, projection, viewport)
                .map_err(js_error)?;
            return Ok(now_ms() - started);
        }
        let size = (w as u32, h as u32);
        if self.float.as_ref().is_none_or(|t| t.size() != size) {
            if let Some(mut t) = self.float.take() {
                t.destroy(&self.gl);
            }
            // Single floats where the browser blends them (EXT_float_blend): SwiftShader blends
            // them as fast as bytes, half floats 1.7× slower (docs/performance.md).
            let format = if splatgl::gl::can_blend_rgba32f(&self.gl) {
                ColorFormat::Rgba32f
            } else {
                ColorFormat::Rgba16f
            };
            let t =
                OffscreenTarget::with_format(&self.gl, size.0, size.1, format).map_err(|e| {
                    JsError::new(&format!(
                        "no float target to blend in ({e}); set_target(\"rgba8\") blends \
                     in the canvas's 8 bits"
                    ))
                })?;
            self.float = Some(t);
        }
        let target = self.float.as_mut().expect("made above");
        // The canvas (the default framebuffer, bound above) is where it resolves.
        target
            .begin(&self.gl, [bg[0], bg[1], bg[2], 1.0])
            .map_err(js_error)?;
        let drawn = self
            .renderer
            .draw_frame(&self.gl, view, projection, viewport);
        target.resolve(&self.gl, linear).map_err(js_error)?;
        drawn.map_err(js_error)?;
        Ok(now_ms() - started)
    }

    /// Where `draw` blends: `"float"` (the default: floating-point blending — RGBA32F where
    /// the browser can blend it, else RGBA16F — resolved into the canvas, as the RC
    /// recommends) or `"rgba8"` (directly in the canvas: no target to resolve, but colours
    /// above 1 are clamped per splat — the kit's `overbright_blending` asset fails it).
    pub fn set_target(&mut self, target: &str) -> Result<(), JsError> {
        self.float_blending = match target {
            "float" => true,
            "rgba8" => false,
            other => {
                return Err(JsError::new(&format!(
                    "target {other:?}: expected \"float\" or \"rgba8\""
                )));
            }
        };
        Ok(())
    }

    /// Times each GPU stage of every draw from now on (`true`) or stops (`false`): an error
    /// where the browser has no `EXT_disjoint_timer_query_webgl2`.
    pub fn set_stage_timing(&mut self, on: bool) -> Result<(), JsError> {
        self.live()?;
        self.renderer
            .set_stage_timing(&self.gl, on)
            .map_err(js_error)
    }

    /// The GPU milliseconds of each stage of the last draw as JSON: `prepass_ms`, `copy_ms`,
    /// `quads_ms` (each absent when that stage did not run, the timer was disturbed, or the
    /// result is not available yet: WebGL gives results only after the page returned to its
    /// event loop — ask a frame later); `{}` when stage timing is off.
    pub fn stage_times(&self) -> String {
        let Some(t) = self.renderer.stage_times(&self.gl) else {
            return "{}".into();
        };
        serde_json::json!({
            "prepass_ms": t.prepass_ms,
            "copy_ms": t.copy_ms,
            "quads_ms": t.quads_ms,
        })
        .to_string()
    }

    /// Frees every GPU object the renderer made (textures, buffers, programs, targets; the
    /// canvas's context stays the page's). Afterwards every call but `dispose` is an error.
    pub fn dispose(&mut self) {
        if self.disposed {
            return;
        }
        self.renderer.destroy(&self.gl);
        self.targets.destroy(&self.gl);
        if let Some(mut t) = self.float.take() {
            t.destroy(&self.gl);
        }
        self.loaded = None;
        self.disposed = true;
    }

    fn live(&self) -> Result<(), JsError> {
        if self.disposed {
            return Err(JsError::new("this renderer was disposed"));
        }
        Ok(())
    }

    /// Waits until the GL has drawn everything asked of it (reads one pixel back: WebGL has
    /// no blocking finish), for timing frames.
    pub fn finish(&self) {
        let mut px = [0u8; 4];
        // SAFETY: a 1×1 read of the bound framebuffer into a 4-byte buffer.
        unsafe {
            self.gl.read_pixels(
                0,
                0,
                1,
                1,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut px)),
            );
        }
    }

    /// `GL_VERSION / GL_RENDERER` and whether RGBA16F blending is available.
    pub fn gl_info(&self) -> String {
        // SAFETY: string queries on the canvas's context.
        let (v, r) = unsafe {
            (
                self.gl.get_parameter_string(glow::VERSION),
                self.gl.get_parameter_string(glow::RENDERER),
            )
        };
        format!(
            "{v} / {r}; RGBA16F blending: {}",
            splatgl::gl::can_render_rgba16f(&self.gl)
        )
    }

    fn size(&self) -> (i32, i32) {
        (
            self.canvas.width().min(16384) as i32,
            self.canvas.height().min(16384) as i32,
        )
    }
}

/// Milliseconds per sort of `n` random splats by camera distance (the renderer's radix sort,
/// on this thread: wasm has no rayon threads), averaged over `reps` sorts after one warm-up.
/// `crates/splatgl-testkit/src/bin/sort_time.rs` measures the same natively.
#[wasm_bindgen]
pub fn sort_ms(n: usize, reps: u32) -> f64 {
    let cloud = splatgl::synthetic::random_cloud(n, 0, 5.0, 7);
    let mut sorter = splatgl::sort::Sorter::new();
    sorter.sort_by_distance(&cloud.positions, [0.0, 0.0, -20.0]);
    let started = now_ms();
    for i in 0..reps {
        sorter.sort_by_distance(&cloud.positions, [0.01 * i as f32, 0.0, -20.0]);
    }
    (now_ms() - started) / f64::from(reps.max(1))
}

/// Milliseconds since the page started (`performance.now()`).
fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or(0.0, |p| p.now())
}
