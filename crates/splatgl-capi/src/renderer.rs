//! The renderer from C: made on the host's current context through the host's GL loader,
//! used and freed on that context's thread.

use std::ffi::{CStr, c_char, c_int, c_uint, c_void};
use std::thread::{self, ThreadId};

use glam::Mat4;

use super::cloud::SplatglCloud;
use super::error::{
    CError, SPLATGL_ERROR_CONTEXT_VERSION, SPLATGL_ERROR_WRONG_THREAD, call, status,
};
use splatgl::gl::{DepthFunc, SplatRenderer};

/// The host's GL function loader: the address of the GL function `name` in the current
/// context (`glfwGetProcAddress`, `eglGetProcAddress`, `SDL_GL_GetProcAddress`, …), `user`
/// passed through unchanged. `NULL` for a function the context lacks.
pub type SplatglGetProc =
    Option<unsafe extern "C" fn(name: *const c_char, user: *mut c_void) -> *mut c_void>;

/// A splat renderer on one GL context (opaque). Made by `splatgl_renderer_new` with the
/// context current; every call, `splatgl_renderer_free` included, must be made on the thread
/// that made it with the same context current. It owns GL objects (textures, buffers, a
/// program, vertex arrays), never the context.
#[derive(Debug)]
pub struct SplatglRenderer {
    gl: glow::Context,
    renderer: SplatRenderer,
    thread: ThreadId,
}

/// The renderer behind `r`, checked: not `NULL`, and used on its own thread.
///
/// # Safety
/// `r` is `NULL` or a live renderer.
unsafe fn renderer<'a>(r: *mut SplatglRenderer) -> Result<&'a mut SplatglRenderer, CError> {
    // SAFETY: NULL or live (the caller's contract).
    let r = unsafe { r.as_mut() }.ok_or_else(|| CError::null("renderer"))?;
    if r.thread != thread::current().id() {
        return Err(CError::new(
            SPLATGL_ERROR_WRONG_THREAD,
            format!(
                "renderer made on thread {:?}, called from {:?}: a GL context is current on \
                 one thread; no GL call was made",
                r.thread,
                thread::current().id()
            ),
        ));
    }
    Ok(r)
}

/// `glGetString(GL_VERSION)` through the loader, before any other GL call: the loader must
/// know `glGetString` and a context must be current.
///
/// # Safety
/// `get_proc` behaves as [`SplatglGetProc`] documents.
unsafe fn current_version(
    get_proc: unsafe extern "C" fn(*const c_char, *mut c_void) -> *mut c_void,
    user: *mut c_void,
) -> Result<String, CError> {
    // SAFETY: a NUL-terminated name; the loader's contract.
    let f = unsafe { get_proc(c"glGetString".as_ptr(), user) };
    if f.is_null() {
        return Err(CError::invalid(
            "the GL loader returned NULL for glGetString",
        ));
    }
    // SAFETY: glGetString's signature (GLenum) -> const GLubyte*.
    let get_string: unsafe extern "system" fn(c_uint) -> *const c_char =
        unsafe { std::mem::transmute(f) };
    // SAFETY: GL_VERSION is a valid name; NULL means no current context.
    let v = unsafe { get_string(glow::VERSION) };
    if v.is_null() {
        return Err(CError::new(
            SPLATGL_ERROR_CONTEXT_VERSION,
            "glGetString(GL_VERSION) returned NULL: no GL context is current on this thread",
        ));
    }
    // SAFETY: GL returns a NUL-terminated static string.
    Ok(unsafe { CStr::from_ptr(v) }.to_string_lossy().into_owned())
}

/// `major.minor…`, after `OpenGL ES ` on ES: what a GL_VERSION string starts with.
fn looks_like_version(v: &str) -> bool {
    let v = v.strip_prefix("OpenGL ES ").unwrap_or(v);
    let mut parts = v.split(['.', ' ']);
    let digits =
        |p: Option<&str>| p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    digits(parts.next()) && digits(parts.next())
}

/// Makes a renderer on the context current on this thread (OpenGL ≥ 3.3 core or
/// compatibility, or OpenGL ES ≥ 3.0), loading GL functions through `get_proc`. Returns
/// `NULL` on failure: `splatgl_last_error_code()` says why (`SPLATGL_ERROR_CONTEXT_VERSION`
/// for an older context or none current, `SPLATGL_ERROR_GL` for a shader the driver
/// refuses, `SPLATGL_ERROR_NULL_POINTER` for no loader). Changes no GL state of the host.
///
/// # Safety
/// `get_proc` is `NULL` or a loader for the current context that behaves as
/// [`SplatglGetProc`] documents.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_new(
    get_proc: SplatglGetProc,
    user: *mut c_void,
) -> *mut SplatglRenderer {
    call(std::ptr::null_mut(), || {
        let get_proc = get_proc.ok_or_else(|| CError::null("get_proc"))?;
        // SAFETY: the loader's contract.
        let version = unsafe { current_version(get_proc, user) }?;
        if !looks_like_version(&version) {
            return Err(CError::new(
                SPLATGL_ERROR_CONTEXT_VERSION,
                format!("GL_VERSION `{version}` is not a GL version string"),
            ));
        }
        // SAFETY: the loader returns function addresses of the current context (its contract).
        let gl = unsafe {
            glow::Context::from_loader_function_cstr(|name| get_proc(name.as_ptr(), user).cast())
        };
        let renderer = SplatRenderer::new(&gl)?;
        let r = SplatglRenderer {
            gl,
            renderer,
            thread: thread::current().id(),
        };
        Ok(Box::into_raw(Box::new(r)))
    })
    .0
}

/// Deletes the renderer's GL objects and frees it (`NULL` is ignored). Call it on the
/// renderer's thread with its context current, before the context is destroyed. From another
/// thread no GL call is made: the GL objects are left to the context (freed with it) and the
/// last error says so.
///
/// # Safety
/// `r` is `NULL` or a renderer from this library not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_free(r: *mut SplatglRenderer) {
    status(|| {
        if r.is_null() {
            return Ok(());
        }
        // SAFETY: made by `Box::into_raw` in `splatgl_renderer_new` (the caller's contract).
        let mut owned = unsafe { Box::from_raw(r) };
        if owned.thread != thread::current().id() {
            owned.renderer.abandon();
            return Err(CError::new(
                SPLATGL_ERROR_WRONG_THREAD,
                "splatgl_renderer_free from another thread than the renderer's: freed without \
                 GL calls (its GL objects go with the context)",
            ));
        }
        owned.renderer.destroy(&owned.gl);
        Ok(())
    });
}

/// Uploads `cloud` (replacing the previous one; on failure the previous one stays drawn).
/// The cloud may be freed afterwards.
///
/// # Safety
/// `r` and `cloud` are each `NULL` or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_upload(
    r: *mut SplatglRenderer,
    cloud: *const SplatglCloud,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        let r = unsafe { renderer(r) }?;
        // SAFETY: NULL or live (the caller's contract).
        let cloud = unsafe { cloud.as_ref() }.ok_or_else(|| CError::null("cloud"))?;
        r.renderer.upload(&r.gl, cloud.cloud())?;
        Ok(())
    })
}

/// Non-zero: every draw puts back every piece of GL state it changes (recommended for legacy
/// hosts; `docs/embedding.md` lists them). Zero (the default): the draw leaves the documented
/// values and makes no state queries.
///
/// # Safety
/// `r` is `NULL` or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_set_restore_state(
    r: *mut SplatglRenderer,
    on: c_int,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        unsafe { renderer(r) }?
            .renderer
            .settings_mut()
            .restore_state = on != 0;
        Ok(())
    })
}

/// The depth comparison against the host's depth buffer: `GL_LESS` (the default),
/// `GL_LEQUAL`, or for a reversed-Z buffer `GL_GREATER` / `GL_GEQUAL`. Any other value is
/// `SPLATGL_ERROR_INVALID_ARGUMENT`. Splats never write depth.
///
/// # Safety
/// `r` is `NULL` or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_set_depth_func(
    r: *mut SplatglRenderer,
    gl_enum: c_uint,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        let r = unsafe { renderer(r) }?;
        let func = match gl_enum {
            glow::LESS => DepthFunc::Less,
            glow::LEQUAL => DepthFunc::LessEqual,
            glow::GREATER => DepthFunc::Greater,
            glow::GEQUAL => DepthFunc::GreaterEqual,
            other => {
                return Err(CError::invalid(format!(
                    "0x{other:04X} is not GL_LESS, GL_LEQUAL, GL_GREATER or GL_GEQUAL"
                )));
            }
        };
        r.renderer.settings_mut().depth_func = func;
        Ok(())
    })
}

/// Non-zero (the default): test splats against the bound depth buffer. Zero: no depth test.
///
/// # Safety
/// `r` is `NULL` or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_set_depth_test(
    r: *mut SplatglRenderer,
    on: c_int,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        unsafe { renderer(r) }?.renderer.settings_mut().depth_test = on != 0;
        Ok(())
    })
}

/// The SH degree to evaluate, 0..3 (clamped to the cloud's), or -1 for the cloud's own (the
/// default).
///
/// # Safety
/// `r` is `NULL` or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_set_sh_degree(
    r: *mut SplatglRenderer,
    degree: c_int,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        let r = unsafe { renderer(r) }?;
        r.renderer.settings_mut().sh_degree = match degree {
            -1 => None,
            0..=3 => Some(degree as u8),
            _ => return Err(CError::invalid(format!("SH degree {degree} is not -1..3"))),
        };
        Ok(())
    })
}

/// Reads `n` values from `p`.
///
/// # Safety
/// `p` is `NULL` or points to `N` readable values.
unsafe fn array<T: Copy, const N: usize>(p: *const T, what: &str) -> Result<[T; N], CError> {
    // SAFETY: NULL or N readable values (the caller's contract).
    unsafe { p.cast::<[T; N]>().as_ref() }
        .copied()
        .ok_or_else(|| CError::null(what))
}

/// Culls, sorts back to front and draws the uploaded cloud into the bound framebuffer for
/// the host's camera: `view` (world → GL eye space, looking down −z) and `projection` as 16
/// floats each, column-major (as `glUniformMatrix4fv` with `transpose = GL_FALSE` takes them;
/// any perspective projection: off-centre, reversed-Z, infinite far), `viewport` the host's
/// bound viewport `x, y, width, height`. Blends premultiplied colour, tests the host's depth
/// buffer without writing it.
///
/// # Safety
/// `r` is `NULL` or live; `view` and `projection` are `NULL` or point to 16 floats, `viewport`
/// to 4 ints.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_renderer_draw(
    r: *mut SplatglRenderer,
    view: *const f32,
    projection: *const f32,
    viewport: *const c_int,
) -> c_int {
    status(|| {
        // SAFETY: NULL or live (the caller's contract).
        let r = unsafe { renderer(r) }?;
        // SAFETY: NULL or 16 floats, 16 floats, 4 ints (the caller's contract).
        let (v, p, vp) = unsafe {
            (
                array::<f32, 16>(view, "view")?,
                array::<f32, 16>(projection, "projection")?,
                array::<c_int, 4>(viewport, "viewport")?,
            )
        };
        let (v, p) = (Mat4::from_cols_array(&v), Mat4::from_cols_array(&p));
        r.renderer.draw_frame(&r.gl, v, p, vp)?;
        Ok(())
    })
}
