//! The WGL side of headless rendering (Windows): a [`HeadlessContext`] on a hidden window of
//! its own, made with `wglCreateContextAttribsARB`.
//!
//! WGL has no surfaceless contexts: a context needs a device context with a pixel format, so
//! each [`HeadlessContext`] creates a small window that is never shown, and renders into
//! framebuffer objects like the EGL path. GL functions come from `wglGetProcAddress`, and for
//! the OpenGL 1.1 entry points it does not return, from `opengl32.dll`.

use std::ffi::{CStr, c_void};
use std::marker::PhantomData;
use std::sync::OnceLock;

use glow::HasContext;
use windows_sys::Win32::Foundation::{ERROR_CLASS_ALREADY_EXISTS, GetLastError, HMODULE, HWND};
use windows_sys::Win32::Graphics::Gdi::{GetDC, HDC, ReleaseDC};
use windows_sys::Win32::Graphics::OpenGL::{
    ChoosePixelFormat, HGLRC, PFD_DOUBLEBUFFER, PFD_DRAW_TO_WINDOW, PFD_MAIN_PLANE,
    PFD_SUPPORT_OPENGL, PFD_TYPE_RGBA, PIXELFORMATDESCRIPTOR, SetPixelFormat, wglCreateContext,
    wglDeleteContext, wglGetCurrentContext, wglGetProcAddress, wglMakeCurrent,
};
use windows_sys::Win32::System::LibraryLoader::{GetModuleHandleW, GetProcAddress, LoadLibraryA};
use windows_sys::Win32::UI::WindowsAndMessaging::{
    CS_OWNDC, CreateWindowExW, DefWindowProcW, DestroyWindow, RegisterClassW, WNDCLASSW,
    WS_OVERLAPPEDWINDOW,
};

use super::{GlApi, HeadlessError};

const WGL_CONTEXT_MAJOR_VERSION_ARB: i32 = 0x2091;
const WGL_CONTEXT_MINOR_VERSION_ARB: i32 = 0x2092;
const WGL_CONTEXT_PROFILE_MASK_ARB: i32 = 0x9126;
const WGL_CONTEXT_CORE_PROFILE_BIT_ARB: i32 = 0x0001;
const WGL_CONTEXT_COMPATIBILITY_PROFILE_BIT_ARB: i32 = 0x0002;
/// `WGL_EXT_create_context_es2_profile` (covers ES 3.x too).
const WGL_CONTEXT_ES2_PROFILE_BIT_EXT: i32 = 0x0004;

type CreateContextAttribs = unsafe extern "system" fn(HDC, HGLRC, *const i32) -> HGLRC;
type GetExtensionsString = unsafe extern "system" fn(HDC) -> *const i8;

/// The window class name, NUL-terminated UTF-16.
fn class_name() -> &'static [u16] {
    static NAME: OnceLock<Vec<u16>> = OnceLock::new();
    NAME.get_or_init(|| "splatgl-headless\0".encode_utf16().collect())
}

/// Registers the hidden windows' class once per process.
fn register_class() -> Result<(), HeadlessError> {
    static CLASS: OnceLock<Result<(), String>> = OnceLock::new();
    CLASS
        .get_or_init(|| {
            // SAFETY: plain Win32 calls; the class name and window procedure live for the
            // process.
            unsafe {
                let wc = WNDCLASSW {
                    style: CS_OWNDC,
                    lpfnWndProc: Some(DefWindowProcW),
                    cbClsExtra: 0,
                    cbWndExtra: 0,
                    hInstance: GetModuleHandleW(std::ptr::null()),
                    hIcon: std::ptr::null_mut(),
                    hCursor: std::ptr::null_mut(),
                    hbrBackground: std::ptr::null_mut(),
                    lpszMenuName: std::ptr::null(),
                    lpszClassName: class_name().as_ptr(),
                };
                if RegisterClassW(&wc) == 0 && GetLastError() != ERROR_CLASS_ALREADY_EXISTS {
                    return Err(format!("RegisterClassW failed (error {})", GetLastError()));
                }
            }
            Ok(())
        })
        .clone()
        .map_err(HeadlessError::WglUnavailable)
}

/// `opengl32.dll`, for the OpenGL 1.1 functions `wglGetProcAddress` does not return.
fn opengl32() -> HMODULE {
    static LIB: OnceLock<usize> = OnceLock::new();
    // SAFETY: loading a system library by name; the handle is kept for the process.
    *LIB.get_or_init(|| unsafe { LoadLibraryA(c"opengl32.dll".as_ptr().cast()) } as usize)
        as HMODULE
}

/// The address of GL or WGL function `name` in the current context, or null.
fn proc_address(name: &CStr) -> *const c_void {
    // SAFETY: a NUL-terminated name; WGL returns null (or the small sentinels 1, 2, 3, -1 on
    // some drivers) for functions it does not know, and those are taken from opengl32.dll.
    unsafe {
        let p = wglGetProcAddress(name.as_ptr().cast()).map_or(0, |f| f as usize);
        if matches!(p, 0 | 1 | 2 | 3 | usize::MAX) {
            let lib = opengl32();
            if lib.is_null() {
                return std::ptr::null();
            }
            return GetProcAddress(lib, name.as_ptr().cast())
                .map_or(std::ptr::null(), |f| f as *const c_void);
        }
        p as *const c_void
    }
}

/// A hidden window and its device context (with a pixel format set), destroyed on drop.
struct HiddenWindow {
    hwnd: HWND,
    hdc: HDC,
}

impl HiddenWindow {
    fn new() -> Result<Self, HeadlessError> {
        register_class()?;
        let fail = |what: &str| {
            // SAFETY: reads the calling thread's last error.
            HeadlessError::WglUnavailable(format!("{what} failed (error {})", unsafe {
                GetLastError()
            }))
        };
        // SAFETY: plain Win32 calls on a window this value owns; it is never shown.
        unsafe {
            let hwnd = CreateWindowExW(
                0,
                class_name().as_ptr(),
                class_name().as_ptr(),
                WS_OVERLAPPEDWINDOW,
                0,
                0,
                16,
                16,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                GetModuleHandleW(std::ptr::null()),
                std::ptr::null(),
            );
            if hwnd.is_null() {
                return Err(fail("CreateWindowExW"));
            }
            let hdc = GetDC(hwnd);
            let window = HiddenWindow { hwnd, hdc };
            if hdc.is_null() {
                return Err(fail("GetDC"));
            }
            let pfd = PIXELFORMATDESCRIPTOR {
                nSize: size_of::<PIXELFORMATDESCRIPTOR>() as u16,
                nVersion: 1,
                dwFlags: PFD_DRAW_TO_WINDOW | PFD_SUPPORT_OPENGL | PFD_DOUBLEBUFFER,
                iPixelType: PFD_TYPE_RGBA,
                cColorBits: 32,
                cAlphaBits: 8,
                cDepthBits: 24,
                cStencilBits: 8,
                iLayerType: PFD_MAIN_PLANE as u8,
                ..std::mem::zeroed()
            };
            let format = ChoosePixelFormat(hdc, &pfd);
            if format == 0 {
                return Err(fail("ChoosePixelFormat"));
            }
            if SetPixelFormat(hdc, format, &pfd) == 0 {
                return Err(fail("SetPixelFormat"));
            }
            Ok(window)
        }
    }
}

impl Drop for HiddenWindow {
    fn drop(&mut self) {
        // SAFETY: the window and DC this value created, on the creating thread (not `Send`).
        unsafe {
            if !self.hdc.is_null() {
                ReleaseDC(self.hwnd, self.hdc);
            }
            DestroyWindow(self.hwnd);
        }
    }
}

/// The `wglCreateContextAttribsARB` attributes (zero-terminated) for `api` at `version`.
fn wgl_request(api: GlApi, (major, minor): (i32, i32)) -> [i32; 7] {
    let profile = match api {
        GlApi::Gles3 => WGL_CONTEXT_ES2_PROFILE_BIT_EXT,
        GlApi::DesktopCore33 => WGL_CONTEXT_CORE_PROFILE_BIT_ARB,
        GlApi::DesktopCompat => WGL_CONTEXT_COMPATIBILITY_PROFILE_BIT_ARB,
    };
    [
        WGL_CONTEXT_MAJOR_VERSION_ARB,
        major,
        WGL_CONTEXT_MINOR_VERSION_ARB,
        minor,
        WGL_CONTEXT_PROFILE_MASK_ARB,
        profile,
        0,
    ]
}

/// An OpenGL ES 3, desktop core or desktop compatibility context ([`GlApi`]) on a hidden
/// window of its own (render into framebuffer objects such as a
/// [`ReadbackTarget`](crate::gl::ReadbackTarget)). Current on the creating thread; not `Send`.
pub struct HeadlessContext {
    context: HGLRC,
    gl: glow::Context,
    window: HiddenWindow,
    /// What was asked for, and what stood in for it (`GlApi::Gles3` without ES on WGL).
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
    /// Creates a GLES 3.0 (or newer) context and makes it current on this thread; on WGL
    /// without `WGL_EXT_create_context_es2_profile`, a desktop 3.3 core context.
    pub fn new() -> Result<Self, HeadlessError> {
        Self::with_api(GlApi::Gles3)
    }

    /// Creates a context of the given API and makes it current on this thread.
    pub fn with_api(api: GlApi) -> Result<Self, HeadlessError> {
        Self::with_api_version(api, api.default_version())
    }

    /// Like [`HeadlessContext::with_api`], asking WGL for the given `(major, minor)` version
    /// (which the driver may raise). A context below the renderer's minimum (OpenGL 3.3,
    /// OpenGL ES 3.0) is created, but [`crate::gl::SplatRenderer::new`] refuses it with
    /// [`crate::gl::GlError::ContextVersion`].
    pub fn with_api_version(api: GlApi, version: (i32, i32)) -> Result<Self, HeadlessError> {
        let window = HiddenWindow::new()?;
        let last_error = |call| HeadlessError::Wgl {
            call,
            // SAFETY: reads the calling thread's last error.
            code: unsafe { GetLastError() },
        };
        // SAFETY: WGL calls on the window's DC; the bootstrap context is deleted before
        // returning, the real one is owned by the returned value.
        unsafe {
            let bootstrap = wglCreateContext(window.hdc);
            if bootstrap.is_null() {
                return Err(HeadlessError::WglUnavailable(format!(
                    "wglCreateContext failed (error {})",
                    GetLastError()
                )));
            }
            if wglMakeCurrent(window.hdc, bootstrap) == 0 {
                let e = last_error("wglMakeCurrent");
                wglDeleteContext(bootstrap);
                return Err(e);
            }
            let create = proc_address(c"wglCreateContextAttribsARB");
            let tries = context_tries(api, version, has_es_profile(window.hdc));
            let mut made = None;
            if !create.is_null() {
                let create: CreateContextAttribs = std::mem::transmute(create);
                for (api, version, note) in tries {
                    let attribs = wgl_request(api, version);
                    let c = create(window.hdc, std::ptr::null_mut(), attribs.as_ptr());
                    if !c.is_null() {
                        made = Some((c, note));
                        break;
                    }
                }
            }
            wglMakeCurrent(std::ptr::null_mut(), std::ptr::null_mut());
            wglDeleteContext(bootstrap);
            let Some((context, note)) = made else {
                return Err(HeadlessError::WglUnavailable(if create.is_null() {
                    "the driver has no wglCreateContextAttribsARB".to_string()
                } else {
                    format!(
                        "wglCreateContextAttribsARB refused {api:?} {}.{} (error {})",
                        version.0,
                        version.1,
                        GetLastError()
                    )
                }));
            };
            if wglMakeCurrent(window.hdc, context) == 0 {
                let e = last_error("wglMakeCurrent");
                wglDeleteContext(context);
                return Err(e);
            }
            let gl = glow::Context::from_loader_function_cstr(proc_address);
            Ok(HeadlessContext {
                context,
                gl,
                window,
                note,
                _not_send: PhantomData,
            })
        }
    }

    /// The GL function table (valid while this context is current).
    pub fn gl(&self) -> &glow::Context {
        &self.gl
    }

    /// The address of a GL function (`wglGetProcAddress`, else `opengl32.dll`), or null when
    /// the driver does not know it. For functions `glow` does not load, such as the
    /// fixed-function and client-array calls of compatibility-profile hosts: cast it to the
    /// function's `extern "system"` pointer type. Valid while this context is current.
    pub fn get_proc_address(&self, name: &str) -> *const c_void {
        match std::ffi::CString::new(name) {
            Ok(c) => proc_address(&c),
            Err(_) => std::ptr::null(),
        }
    }

    /// Makes this context current on the calling thread (needed only when another context was
    /// made current on it since).
    pub fn make_current(&self) -> Result<(), HeadlessError> {
        // SAFETY: the window's DC and this value's context, on the creating thread.
        if unsafe { wglMakeCurrent(self.window.hdc, self.context) } == 0 {
            return Err(HeadlessError::Wgl {
                call: "wglMakeCurrent",
                // SAFETY: reads the calling thread's last error.
                code: unsafe { GetLastError() },
            });
        }
        Ok(())
    }

    /// Whether the context can render to (and blend in) an RGBA16F framebuffer: desktop GL,
    /// or ES with `EXT_color_buffer_half_float` or `EXT_color_buffer_float`.
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
        // SAFETY: this value's context, on the creating thread; the window drops after.
        unsafe {
            if wglGetCurrentContext() == self.context {
                wglMakeCurrent(std::ptr::null_mut(), std::ptr::null_mut());
            }
            wglDeleteContext(self.context);
        }
    }
}

/// The contexts to ask for, in order: `api` at `version`, and for GLES 3 a desktop 3.3 core
/// context (the only one where the driver has no ES profile), with the note that says so.
fn context_tries(
    api: GlApi,
    version: (i32, i32),
    has_es: bool,
) -> Vec<(GlApi, (i32, i32), &'static str)> {
    let mut tries = vec![(api, version, "")];
    if api == GlApi::Gles3 {
        if !has_es {
            tries.clear();
        }
        tries.push((
            GlApi::DesktopCore33,
            (3, 3),
            "desktop 3.3 core for GLES 3 (no WGL_EXT_create_context_es2_profile)",
        ));
    }
    tries
}

/// Whether the driver offers `WGL_EXT_create_context_es2_profile`.
///
/// # Safety
/// A context is current on `hdc`.
unsafe fn has_es_profile(hdc: HDC) -> bool {
    // SAFETY: the caller's contract; the extension string is NUL-terminated, owned by WGL.
    unsafe {
        let extensions = proc_address(c"wglGetExtensionsStringARB");
        !extensions.is_null() && {
            let get: GetExtensionsString = std::mem::transmute(extensions);
            let s = get(hdc);
            !s.is_null()
                && CStr::from_ptr(s)
                    .to_string_lossy()
                    .split(' ')
                    .any(|e| e == "WGL_EXT_create_context_es2_profile")
        }
    }
}
