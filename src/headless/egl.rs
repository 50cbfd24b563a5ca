//! The EGL side of headless rendering: [`HeadlessContext`] on Mesa's surfaceless platform, and
//! the [`GlApi`] it speaks.
//!
//! The EGL library is loaded at run time (`libEGL.so.1`) and its display initialised once per
//! process and never terminated (terminating it would destroy the contexts of other threads
//! sharing it).

use std::marker::PhantomData;
use std::sync::OnceLock;

use glow::HasContext;
use khronos_egl as egl;

use super::{GlApi, HeadlessError};

/// `EGL_PLATFORM_SURFACELESS_MESA`.
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

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

/// What to ask EGL for: the `eglBindAPI` value, the `EGL_RENDERABLE_TYPE` bit a config
/// needs, and the `eglCreateContext` attributes (`EGL_NONE`-terminated) for `version`.
fn egl_request(api: GlApi, (major, minor): (i32, i32)) -> (egl::Enum, egl::Int, Vec<egl::Int>) {
    let mut attribs = vec![
        egl::CONTEXT_MAJOR_VERSION,
        major,
        egl::CONTEXT_MINOR_VERSION,
        minor,
    ];
    let profile = |bit| [egl::CONTEXT_OPENGL_PROFILE_MASK, bit];
    let (bind, renderable) = match api {
        GlApi::Gles3 => (egl::OPENGL_ES_API, egl::OPENGL_ES3_BIT),
        GlApi::DesktopCore33 => {
            attribs.extend(profile(egl::CONTEXT_OPENGL_CORE_PROFILE_BIT));
            (egl::OPENGL_API, egl::OPENGL_BIT)
        }
        GlApi::DesktopCompat => {
            attribs.extend(profile(egl::CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT));
            (egl::OPENGL_API, egl::OPENGL_BIT)
        }
    };
    attribs.push(egl::NONE);
    (bind, renderable, attribs)
}

/// An OpenGL ES 3, desktop core or desktop compatibility context ([`GlApi`]) on the surfaceless
/// platform (no window, no default framebuffer: render into framebuffer objects such as a
/// [`ReadbackTarget`](crate::gl::ReadbackTarget)). Current on the creating thread; not `Send`.
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
        Self::with_api_version(api, api.default_version())
    }

    /// Like [`HeadlessContext::with_api`], asking EGL for the given `(major, minor)` version
    /// (which the driver may raise: Mesa gives the newest compatible one): e.g. a host that
    /// wants a specific GL version, or a test of old versions. A context below the renderer's
    /// minimum (OpenGL 3.3, OpenGL ES 3.0) is created, but [`crate::gl::SplatRenderer::new`]
    /// refuses it with [`crate::gl::GlError::ContextVersion`].
    pub fn with_api_version(api: GlApi, version: (i32, i32)) -> Result<Self, HeadlessError> {
        let e = egl()?;
        let display = e.display();
        let err = |call| move |error| HeadlessError::Egl { call, error };
        let (bind, renderable, attribs) = egl_request(api, version);
        e.instance.bind_api(bind).map_err(err("eglBindAPI"))?;
        // Surfaceless: no window surfaces, so don't let SURFACE_TYPE default to WINDOW_BIT.
        let config_attribs = [
            egl::RENDERABLE_TYPE,
            renderable,
            egl::SURFACE_TYPE,
            egl::DONT_CARE,
            egl::NONE,
        ];
        let config = e
            .instance
            .choose_first_config(display, &config_attribs)
            .map_err(err("eglChooseConfig"))?
            .ok_or(HeadlessError::Egl {
                call: "eglChooseConfig",
                error: egl::Error::BadConfig,
            })?;
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

    /// The address of a GL function (`eglGetProcAddress`), or null when the driver does not
    /// know it. For functions `glow` does not load, such as the fixed-function and
    /// client-array calls of compatibility-profile hosts (`glMatrixMode`, `glBegin`,
    /// `glVertexPointer`, …): cast it to the function's `extern "system"` pointer type.
    /// Valid while this context is current.
    pub fn get_proc_address(&self, name: &str) -> *const std::ffi::c_void {
        egl()
            .ok()
            .and_then(|e| e.instance.get_proc_address(name))
            .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
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

    /// Whether the context can render to (and blend in) an RGBA16F framebuffer: desktop GL,
    /// or ES with `EXT_color_buffer_half_float` or `EXT_color_buffer_float`.
    pub fn can_render_rgba16f(&self) -> bool {
        crate::gl::can_render_rgba16f(&self.gl)
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
