//! Headless rendering through EGL on Mesa's surfaceless platform (feature `gl`).
//!
//! * [`render`] — one call: cloud + camera + options → [`Image`]. This is what a CLI
//!   `--backend gl` calls.
//! * [`HeadlessRenderer`] — the same, keeping the context, the uploaded cloud and the
//!   framebuffers between renders (tests, benchmarks, many views of one cloud).
//! * [`HeadlessContext`] — just the EGL context and its [`glow::Context`], for driving
//!   [`crate::gl`] yourself.
//!
//! The EGL library is loaded at run time (`libEGL.so.1`); when it is missing or no display can
//! be initialised the error is [`HeadlessError::EglUnavailable`], which callers (and the test
//! suite) may treat as "no GL here". Every other failure is a real error.
//!
//! Contexts are current on the thread that created them and are not `Send`. The EGL display is
//! initialised once per process and never terminated (terminating it would destroy the
//! contexts of other threads sharing it).

use std::marker::PhantomData;
use std::sync::OnceLock;

use glow::HasContext;
use khronos_egl as egl;

use crate::camera::Camera;
use crate::cloud::{ColorSpace, SplatCloud};
use crate::gl::sort::DistanceSorter;
use crate::gl::{GlError, OffscreenTarget, SplatRenderer};
use crate::image::Image;

/// `EGL_PLATFORM_SURFACELESS_MESA`.
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

/// Errors of headless rendering.
#[derive(Debug, thiserror::Error)]
pub enum HeadlessError {
    /// EGL could not be opened here (no `libEGL.so.1`, or no surfaceless display).
    #[error("EGL unavailable: {0}")]
    EglUnavailable(String),
    /// An EGL call failed after EGL was opened.
    #[error("EGL call {call} failed: {error}")]
    Egl {
        /// The failing call.
        call: &'static str,
        /// EGL's error.
        error: egl::Error,
    },
    /// The GL layer failed.
    #[error(transparent)]
    Gl(#[from] GlError),
}

type EglInstance = egl::DynamicInstance<egl::EGL1_5>;

struct Egl {
    instance: EglInstance,
    /// The `EGLDisplay` pointer (stored as an address: the display handle is process-wide).
    display: usize,
}

impl Egl {
    fn display(&self) -> egl::Display {
        // SAFETY: `display` is the pointer of a display returned by eglGetPlatformDisplay and
        // initialised once; it is never terminated, so it stays valid for the process.
        unsafe { egl::Display::from_ptr(self.display as egl::EGLDisplay) }
    }
}

static EGL: OnceLock<Result<Egl, String>> = OnceLock::new();

fn egl() -> Result<&'static Egl, HeadlessError> {
    EGL.get_or_init(|| {
        // SAFETY: loads the system's libEGL, which implements the EGL 1.5 API.
        let instance =
            unsafe { EglInstance::load_required() }.map_err(|e| format!("loading libEGL: {e}"))?;
        // SAFETY: the surfaceless platform takes EGL_DEFAULT_DISPLAY (null) as native display.
        let display = unsafe {
            instance.get_platform_display(
                PLATFORM_SURFACELESS_MESA,
                egl::DEFAULT_DISPLAY,
                &[egl::ATTRIB_NONE],
            )
        }
        .map_err(|e| format!("eglGetPlatformDisplay(SURFACELESS_MESA): {e}"))?;
        instance
            .initialize(display)
            .map_err(|e| format!("eglInitialize: {e}"))?;
        Ok(Egl {
            instance,
            display: display.as_ptr() as usize,
        })
    })
    .as_ref()
    .map_err(|e| HeadlessError::EglUnavailable(e.clone()))
}

/// Which client API a [`HeadlessContext`] speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GlApi {
    /// OpenGL ES 3.0 or newer (shaders get `#version 300 es`). The default.
    #[default]
    Gles3,
    /// Desktop OpenGL 3.3 core profile (shaders get `#version 330 core`).
    DesktopCore33,
}

/// An OpenGL ES 3 (or desktop GL 3.3 core) context on the surfaceless platform (no window, no default framebuffer:
/// render into FBOs). Current on the creating thread; not `Send`.
pub struct HeadlessContext {
    context: egl::Context,
    gl: glow::Context,
    _not_send: PhantomData<*const ()>,
}

impl std::fmt::Debug for HeadlessContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeadlessContext")
            .field("version", self.gl.version())
            .finish()
    }
}

impl HeadlessContext {
    /// Creates a GLES 3.0 (or newer) context and makes it current on this thread.
    pub fn new() -> Result<Self, HeadlessError> {
        Self::with_api(GlApi::Gles3)
    }

    /// Creates a context of the given API and makes it current on this thread.
    pub fn with_api(api: GlApi) -> Result<Self, HeadlessError> {
        let e = egl()?;
        let display = e.display();
        let err = |call| move |error| HeadlessError::Egl { call, error };
        let (bind, renderable, minor, profile): (_, _, _, &[egl::Int]) = match api {
            GlApi::Gles3 => (egl::OPENGL_ES_API, egl::OPENGL_ES3_BIT, 0, &[]),
            GlApi::DesktopCore33 => (
                egl::OPENGL_API,
                egl::OPENGL_BIT,
                3,
                &[
                    egl::CONTEXT_OPENGL_PROFILE_MASK,
                    egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
                ],
            ),
        };
        e.instance.bind_api(bind).map_err(err("eglBindAPI"))?;
        let config = e
            .instance
            .choose_first_config(
                display,
                // Surfaceless: no window surfaces, so don't let SURFACE_TYPE default to WINDOW_BIT.
                &[
                    egl::RENDERABLE_TYPE,
                    renderable,
                    egl::SURFACE_TYPE,
                    egl::DONT_CARE,
                    egl::NONE,
                ],
            )
            .map_err(err("eglChooseConfig"))?
            .ok_or(HeadlessError::Egl {
                call: "eglChooseConfig",
                error: egl::Error::BadConfig,
            })?;
        let mut attribs = vec![
            egl::CONTEXT_MAJOR_VERSION,
            3,
            egl::CONTEXT_MINOR_VERSION,
            minor,
        ];
        attribs.extend_from_slice(profile);
        attribs.push(egl::NONE);
        let context = e
            .instance
            .create_context(display, config, None, &attribs)
            .map_err(err("eglCreateContext"))?;
        if let Err(error) = e.instance.make_current(display, None, None, Some(context)) {
            let _ = e.instance.destroy_context(display, context);
            return Err(HeadlessError::Egl {
                call: "eglMakeCurrent",
                error,
            });
        }
        // SAFETY: the context is current on this thread; eglGetProcAddress returns core GLES
        // functions too on Mesa (EGL_KHR_get_all_proc_addresses), and null for unknown names,
        // which glow treats as missing.
        let gl = unsafe {
            glow::Context::from_loader_function(|name| {
                e.instance
                    .get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
            })
        };
        Ok(HeadlessContext {
            context,
            gl,
            _not_send: PhantomData,
        })
    }

    /// The GL function table (valid while this context is current).
    pub fn gl(&self) -> &glow::Context {
        &self.gl
    }

    /// Makes this context current on the calling thread (needed only when another context was
    /// made current on it since).
    pub fn make_current(&self) -> Result<(), HeadlessError> {
        let e = egl()?;
        e.instance
            .make_current(e.display(), None, None, Some(self.context))
            .map_err(|error| HeadlessError::Egl {
                call: "eglMakeCurrent",
                error,
            })
    }

    /// `"GL_VERSION / GL_RENDERER"` of the context.
    pub fn describe(&self) -> String {
        // SAFETY: string queries on the current context.
        unsafe {
            format!(
                "{} / {}",
                self.gl.get_parameter_string(glow::VERSION),
                self.gl.get_parameter_string(glow::RENDERER)
            )
        }
    }
}

impl Drop for HeadlessContext {
    fn drop(&mut self) {
        if let Ok(e) = egl() {
            let display = e.display();
            if e.instance.get_current_context() == Some(self.context) {
                let _ = e.instance.make_current(display, None, None, None);
            }
            let _ = e.instance.destroy_context(display, self.context);
        }
    }
}

/// Which framebuffer the splats are blended in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TargetKind {
    /// Blend directly in an 8-bit framebuffer: `RGBA8` for `srgb_rec709_display`,
    /// `SRGB8_ALPHA8` for `lin_rec709_display` (GL decodes, blends linear, re-encodes).
    #[default]
    Rgba8,
    /// Blend in an `RGBA16F` [`OffscreenTarget`], then resolve (sRGB-encoding linear clouds)
    /// into an `RGBA8` framebuffer.
    Rgba16fResolve,
}

/// Options of a headless render.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Framebuffer to blend in.
    pub target: TargetKind,
    /// Background colour as it appears in the output image (display-referred values). For
    /// `lin_rec709_display` it is sRGB-decoded before blending, so it comes out unchanged.
    pub background: [f32; 3],
    /// SH degree to evaluate; `None` = the cloud's.
    pub sh_degree: Option<u8>,
    /// Colour space override; `None` = the cloud's `meta.color_space` (unknown → default).
    pub color_space: Option<ColorSpace>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            target: TargetKind::Rgba8,
            background: [0.0; 3],
            sh_degree: None,
            color_space: None,
        }
    }
}

/// sRGB decoding (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    crate::color::srgb_decode(c as f64) as f32
}

#[derive(Debug)]
struct Fbo8 {
    fbo: glow::Framebuffer,
    rb: glow::Renderbuffer,
    width: u32,
    height: u32,
    srgb: bool,
}

/// A headless context with a [`SplatRenderer`], an uploaded cloud and cached framebuffers.
#[derive(Debug)]
pub struct HeadlessRenderer {
    renderer: SplatRenderer,
    fbo: Option<Fbo8>,
    offscreen: Option<OffscreenTarget>,
    positions: Vec<[f32; 3]>,
    sorter: DistanceSorter,
    order: Vec<u32>,
    bytes: Vec<u8>,
    // Declared last: dropped after the GL objects above are deleted in `Drop`.
    ctx: HeadlessContext,
}

impl HeadlessRenderer {
    /// A new context with a renderer (no cloud yet).
    pub fn new() -> Result<Self, HeadlessError> {
        Self::with_errata(crate::gl::Errata::default())
    }

    /// Like [`HeadlessRenderer::new`] with Appendix A errata switched in (tests only).
    pub fn with_errata(errata: crate::gl::Errata) -> Result<Self, HeadlessError> {
        Self::with_api(GlApi::Gles3, errata)
    }

    /// A renderer on a context of the given API, with `errata` (use `Errata::default()`).
    pub fn with_api(api: GlApi, errata: crate::gl::Errata) -> Result<Self, HeadlessError> {
        let ctx = HeadlessContext::with_api(api)?;
        let renderer = SplatRenderer::with_errata(ctx.gl(), errata)?;
        Ok(HeadlessRenderer {
            renderer,
            fbo: None,
            offscreen: None,
            positions: Vec::new(),
            sorter: DistanceSorter::default(),
            order: Vec::new(),
            bytes: Vec::new(),
            ctx,
        })
    }

    /// The context.
    pub fn context(&self) -> &HeadlessContext {
        &self.ctx
    }

    /// The renderer.
    pub fn renderer(&self) -> &SplatRenderer {
        &self.renderer
    }

    /// The renderer, mutable (for driving draws by hand, e.g. in benchmarks).
    pub fn renderer_mut(&mut self) -> &mut SplatRenderer {
        &mut self.renderer
    }

    /// Uploads a cloud (replacing the previous one).
    pub fn upload(&mut self, cloud: &SplatCloud) -> Result<(), HeadlessError> {
        self.ctx.make_current()?;
        self.renderer.upload(self.ctx.gl(), cloud)?;
        self.positions.clear();
        self.positions.extend_from_slice(&cloud.positions);
        Ok(())
    }

    /// Renders the uploaded cloud, sorted back to front for `camera`.
    pub fn render(
        &mut self,
        camera: &Camera,
        opts: &RenderOptions,
    ) -> Result<Image, HeadlessError> {
        let mut order = std::mem::take(&mut self.order);
        self.sorter.sort(&self.positions, camera.eye(), &mut order);
        let result = self.render_with_order(camera, opts, &order);
        self.order = order;
        result
    }

    /// Renders the uploaded cloud in the given order (first index drawn first).
    pub fn render_with_order(
        &mut self,
        camera: &Camera,
        opts: &RenderOptions,
        order: &[u32],
    ) -> Result<Image, HeadlessError> {
        self.ctx.make_current()?;
        let linear =
            opts.color_space.unwrap_or(self.renderer.color_space()) == ColorSpace::LinRec709Display;
        let (w, h) = (camera.width, camera.height);
        if w == 0 || h == 0 {
            return Ok(Image::filled(w, h, [0.0; 4])); // no pixels (a 0-sized FBO is incomplete)
        }
        let srgb_fbo = linear && opts.target == TargetKind::Rgba8;
        self.ensure_fbo(w, h, srgb_fbo)?;
        if opts.target == TargetKind::Rgba16fResolve
            && self.offscreen.as_ref().is_none_or(|t| t.size() != (w, h))
        {
            if let Some(t) = self.offscreen.take() {
                t.destroy(self.ctx.gl());
            }
            self.offscreen = Some(OffscreenTarget::new(self.ctx.gl(), w, h)?);
        }
        let bg = if linear {
            opts.background.map(srgb_to_linear)
        } else {
            opts.background
        };
        self.renderer.settings_mut().sh_degree = opts.sh_degree;
        self.renderer.settings_mut().depth_test = false;
        let gl = self.ctx.gl();
        let fbo = self.fbo.as_ref().expect("ensured above");
        // Desktop GL converts to sRGB on write only with GL_FRAMEBUFFER_SRGB (ES always does).
        let desktop_srgb = srgb_fbo && !gl.version().is_embedded;
        if desktop_srgb {
            // SAFETY: enabling a capability on the current context.
            unsafe { gl.enable(glow::FRAMEBUFFER_SRGB) };
        }
        // SAFETY: binds this renderer's own framebuffer and clears it.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo.fbo));
            gl.viewport(0, 0, w as i32, h as i32);
            gl.clear_color(bg[0], bg[1], bg[2], 0.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
        }
        match opts.target {
            TargetKind::Rgba8 => self.renderer.draw(gl, camera, order)?,
            TargetKind::Rgba16fResolve => {
                let target = self.offscreen.as_mut().expect("created above");
                target.begin(gl, [bg[0], bg[1], bg[2], 0.0]);
                self.renderer.draw(gl, camera, order)?;
                target.resolve(gl, linear);
            }
        }
        if desktop_srgb {
            // SAFETY: restoring the default (disabled).
            unsafe { gl.disable(glow::FRAMEBUFFER_SRGB) };
        }
        self.bytes.resize(w as usize * h as usize * 4, 0);
        // SAFETY: reads w·h RGBA8 pixels from our framebuffer into a buffer of exactly that
        // size (PACK_ALIGNMENT 4 divides the 4-byte pixel rows).
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(fbo.fbo));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.read_pixels(
                0,
                0,
                w as i32,
                h as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut self.bytes)),
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        crate::gl::check_error(gl, "rendering")?;
        // GL row 0 is the bottom row; Image row 0 is the top.
        let row = w as usize * 4;
        let mut flipped = Vec::with_capacity(self.bytes.len());
        for r in self.bytes.chunks_exact(row).rev() {
            flipped.extend_from_slice(r);
        }
        Ok(Image::from_rgba8(w, h, &flipped))
    }

    /// Blocks until the GL has finished all commands (for timing).
    pub fn finish(&self) {
        // SAFETY: glFinish has no preconditions.
        unsafe { self.ctx.gl().finish() }
    }

    fn ensure_fbo(&mut self, width: u32, height: u32, srgb: bool) -> Result<(), HeadlessError> {
        if let Some(f) = &self.fbo
            && (f.width, f.height, f.srgb) == (width, height, srgb)
        {
            return Ok(());
        }
        let gl = self.ctx.gl();
        if let Some(f) = self.fbo.take() {
            // SAFETY: deleting our own objects.
            unsafe {
                gl.delete_framebuffer(f.fbo);
                gl.delete_renderbuffer(f.rb);
            }
        }
        // SAFETY: creates a renderbuffer-backed framebuffer owned by this renderer.
        unsafe {
            let rb = crate::gl::created(gl.create_renderbuffer(), "renderbuffer")?;
            let fbo = match crate::gl::created(gl.create_framebuffer(), "framebuffer") {
                Ok(f) => f,
                Err(e) => {
                    gl.delete_renderbuffer(rb);
                    return Err(e.into());
                }
            };
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            let format = if srgb {
                glow::SRGB8_ALPHA8
            } else {
                glow::RGBA8
            };
            gl.renderbuffer_storage(glow::RENDERBUFFER, format, width as i32, height as i32);
            gl.bind_renderbuffer(glow::RENDERBUFFER, None);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(rb),
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            self.fbo = Some(Fbo8 {
                fbo,
                rb,
                width,
                height,
                srgb,
            });
            if status != glow::FRAMEBUFFER_COMPLETE {
                return Err(GlError::Framebuffer(status).into());
            }
        }
        Ok(())
    }
}

impl Drop for HeadlessRenderer {
    fn drop(&mut self) {
        if self.ctx.make_current().is_err() {
            return;
        }
        let gl = self.ctx.gl();
        self.renderer.destroy(gl);
        if let Some(t) = self.offscreen.take() {
            t.destroy(gl);
        }
        if let Some(f) = self.fbo.take() {
            // SAFETY: deleting our own objects.
            unsafe {
                gl.delete_framebuffer(f.fbo);
                gl.delete_renderbuffer(f.rb);
            }
        }
    }
}

/// Renders `cloud` seen by `camera` headlessly: creates an EGL context, uploads, sorts back to
/// front, draws and reads back. The image has the camera's size; RGB is display-referred
/// (sRGB-encoded for `lin_rec709_display`) and composited over `opts.background`, A = 1 − T.
///
/// For many renders of one cloud keep a [`HeadlessRenderer`] instead.
pub fn render(
    cloud: &SplatCloud,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<Image, HeadlessError> {
    let mut r = HeadlessRenderer::new()?;
    r.upload(cloud)?;
    r.render(camera, opts)
}
