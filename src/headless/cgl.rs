//! The CGL side of headless rendering (macOS): a [`HeadlessContext`] made by CGL with no
//! drawable at all (render into framebuffer objects, as on EGL and WGL).
//!
//! OpenGL.framework is opened at run time (`dlopen`), like libEGL elsewhere, so nothing links
//! against it. macOS offers desktop core profiles only (3.2 and 4.1) and a legacy 2.1 one: a
//! GLES 3 request gets a 4.1 core context, and a compatibility-profile request is refused.
//!
//! Checked (`cargo clippy --target aarch64-apple-darwin`) but not run here: see
//! `docs/platforms.md`.

use std::ffi::{CStr, c_int, c_void};
use std::marker::PhantomData;
use std::sync::OnceLock;

use glow::HasContext;

use super::{GlApi, HeadlessError};

type PixelFormat = *mut c_void;
type Context = *mut c_void;
type CglError = c_int;

const PFA_COLOR_SIZE: c_int = 8;
const PFA_ALPHA_SIZE: c_int = 11;
const PFA_ACCELERATED: c_int = 73;
const PFA_ALLOW_OFFLINE_RENDERERS: c_int = 96;
const PFA_OPENGL_PROFILE: c_int = 99;
const PROFILE_3_2_CORE: c_int = 0x3200;
const PROFILE_GL4_CORE: c_int = 0x4100;

const FRAMEWORK: &CStr = c"/System/Library/Frameworks/OpenGL.framework/OpenGL";

type ChoosePixelFormat =
    unsafe extern "C" fn(*const c_int, *mut PixelFormat, *mut c_int) -> CglError;
type DestroyPixelFormat = unsafe extern "C" fn(PixelFormat) -> CglError;
type CreateContext = unsafe extern "C" fn(PixelFormat, Context, *mut Context) -> CglError;
type WithContext = unsafe extern "C" fn(Context) -> CglError;
type GetCurrentContext = unsafe extern "C" fn() -> Context;

/// The CGL entry points, from OpenGL.framework.
struct Cgl {
    /// The framework's `dlopen` handle (kept open for the process), as an address.
    lib: usize,
    choose_pixel_format: ChoosePixelFormat,
    destroy_pixel_format: DestroyPixelFormat,
    create_context: CreateContext,
    destroy_context: WithContext,
    set_current_context: WithContext,
    get_current_context: GetCurrentContext,
}

static CGL: OnceLock<Result<Cgl, String>> = OnceLock::new();

fn cgl() -> Result<&'static Cgl, HeadlessError> {
    CGL.get_or_init(|| {
        // SAFETY: opens a system framework by path; the handle is kept for the process.
        let lib = unsafe { libc::dlopen(FRAMEWORK.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
        if lib.is_null() {
            return Err(format!("dlopen {}", FRAMEWORK.to_string_lossy()));
        }
        let sym = |name: &CStr| {
            // SAFETY: a symbol lookup in the handle opened above.
            let p = unsafe { libc::dlsym(lib, name.as_ptr()) };
            if p.is_null() {
                Err(format!(
                    "OpenGL.framework has no {}",
                    name.to_string_lossy()
                ))
            } else {
                Ok(p)
            }
        };
        // SAFETY: each symbol is the CGL function of that name, whose C signature the field's
        // type spells (CGLTypes.h, CGLCurrent.h).
        unsafe {
            use std::mem::transmute;
            type P = *mut c_void;
            Ok(Cgl {
                lib: lib as usize,
                choose_pixel_format: transmute::<P, ChoosePixelFormat>(sym(
                    c"CGLChoosePixelFormat",
                )?),
                destroy_pixel_format: transmute::<P, DestroyPixelFormat>(sym(
                    c"CGLDestroyPixelFormat",
                )?),
                create_context: transmute::<P, CreateContext>(sym(c"CGLCreateContext")?),
                destroy_context: transmute::<P, WithContext>(sym(c"CGLDestroyContext")?),
                set_current_context: transmute::<P, WithContext>(sym(c"CGLSetCurrentContext")?),
                get_current_context: transmute::<P, GetCurrentContext>(sym(
                    c"CGLGetCurrentContext",
                )?),
            })
        }
    })
    .as_ref()
    .map_err(|e| HeadlessError::CglUnavailable(e.clone()))
}

/// The address of GL function `name` in OpenGL.framework, or null.
fn proc_address(name: &CStr) -> *const c_void {
    match cgl() {
        // SAFETY: a symbol lookup in the framework's handle, open for the process.
        Ok(c) => unsafe { libc::dlsym(c.lib as *mut c_void, name.as_ptr()) },
        Err(_) => std::ptr::null(),
    }
}

/// The CGL profile for `api` at `version`, and a note when it stands in for another API.
fn cgl_request(api: GlApi, (major, minor): (i32, i32)) -> Result<(c_int, &'static str), String> {
    match api {
        GlApi::Gles3 => Ok((
            PROFILE_GL4_CORE,
            "desktop 4.1 core for GLES 3 (macOS has no OpenGL ES)",
        )),
        GlApi::DesktopCore33 if (major, minor) <= (3, 2) => Ok((PROFILE_3_2_CORE, "")),
        GlApi::DesktopCore33 => Ok((PROFILE_GL4_CORE, "")),
        GlApi::DesktopCompat => Err(
            "macOS has no compatibility profile above OpenGL 2.1 (use GlApi::DesktopCore33)"
                .to_string(),
        ),
    }
}

/// A desktop core context ([`GlApi`]; GLES 3 requests get 4.1 core) with no drawable: render
/// into framebuffer objects such as a [`ReadbackTarget`](crate::gl::ReadbackTarget). Current
/// on the creating thread; not `Send`.
pub struct HeadlessContext {
    context: Context,
    gl: glow::Context,
    note: &'static str,
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
    /// Creates a context for GLES 3 shaders (on macOS a desktop 4.1 core context, whose
    /// shaders get `#version 330 core`) and makes it current on this thread.
    pub fn new() -> Result<Self, HeadlessError> {
        Self::with_api(GlApi::Gles3)
    }

    /// Creates a context of the given API and makes it current on this thread.
    pub fn with_api(api: GlApi) -> Result<Self, HeadlessError> {
        Self::with_api_version(api, api.default_version())
    }

    /// Like [`HeadlessContext::with_api`] for a `(major, minor)` version: CGL picks its 3.2
    /// core profile for versions up to 3.2 (below the renderer's minimum, so
    /// [`crate::gl::SplatRenderer::new`] refuses it) and 4.1 core above.
    pub fn with_api_version(api: GlApi, version: (i32, i32)) -> Result<Self, HeadlessError> {
        let c = cgl()?;
        let (profile, note) = cgl_request(api, version).map_err(HeadlessError::CglUnavailable)?;
        let attribs = [
            PFA_OPENGL_PROFILE,
            profile,
            PFA_COLOR_SIZE,
            24,
            PFA_ALPHA_SIZE,
            8,
            PFA_ACCELERATED,
            PFA_ALLOW_OFFLINE_RENDERERS,
            0,
        ];
        let fail = |call, code| HeadlessError::Cgl { call, code };
        // SAFETY: CGL calls with a zero-terminated attribute list and out-pointers to locals;
        // the pixel format is destroyed once the context holds it.
        unsafe {
            let (mut pixel_format, mut count) = (std::ptr::null_mut(), 0);
            let e = (c.choose_pixel_format)(attribs.as_ptr(), &mut pixel_format, &mut count);
            if e != 0 || pixel_format.is_null() {
                return Err(fail("CGLChoosePixelFormat", e));
            }
            let mut context = std::ptr::null_mut();
            let e = (c.create_context)(pixel_format, std::ptr::null_mut(), &mut context);
            (c.destroy_pixel_format)(pixel_format);
            if e != 0 || context.is_null() {
                return Err(fail("CGLCreateContext", e));
            }
            let e = (c.set_current_context)(context);
            if e != 0 {
                (c.destroy_context)(context);
                return Err(fail("CGLSetCurrentContext", e));
            }
            let gl = glow::Context::from_loader_function_cstr(proc_address);
            Ok(HeadlessContext {
                context,
                gl,
                note,
                _not_send: PhantomData,
            })
        }
    }

    /// The GL function table (valid while this context is current).
    pub fn gl(&self) -> &glow::Context {
        &self.gl
    }

    /// The address of a GL function in OpenGL.framework, or null when it has none. Valid
    /// while this context is current.
    pub fn get_proc_address(&self, name: &str) -> *const c_void {
        match std::ffi::CString::new(name) {
            Ok(c) => proc_address(&c),
            Err(_) => std::ptr::null(),
        }
    }

    /// Makes this context current on the calling thread (needed only when another context was
    /// made current on it since).
    pub fn make_current(&self) -> Result<(), HeadlessError> {
        let c = cgl()?;
        // SAFETY: this value's live context.
        match unsafe { (c.set_current_context)(self.context) } {
            0 => Ok(()),
            code => Err(HeadlessError::Cgl {
                call: "CGLSetCurrentContext",
                code,
            }),
        }
    }

    /// Whether the context can render to (and blend in) an RGBA16F framebuffer (desktop GL:
    /// yes).
    pub fn can_render_rgba16f(&self) -> bool {
        crate::gl::can_render_rgba16f(&self.gl)
    }

    /// `"GL_VERSION / GL_RENDERER"` of the context (and, when a desktop context stands in
    /// for the GLES 3 one asked for, a note saying so).
    pub fn describe(&self) -> String {
        // SAFETY: string queries on the current context.
        let s = unsafe {
            format!(
                "{} / {}",
                self.gl.get_parameter_string(glow::VERSION),
                self.gl.get_parameter_string(glow::RENDERER)
            )
        };
        if self.note.is_empty() {
            s
        } else {
            format!("{s} ({})", self.note)
        }
    }
}

impl Drop for HeadlessContext {
    fn drop(&mut self) {
        if let Ok(c) = cgl() {
            // SAFETY: this value's context, on the creating thread (not `Send`).
            unsafe {
                if (c.get_current_context)() == self.context {
                    (c.set_current_context)(std::ptr::null_mut());
                }
                (c.destroy_context)(self.context);
            }
        }
    }
}
