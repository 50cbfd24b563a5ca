//! Error codes, the thread-local last error, and the guard every entry point runs in
//! ([`call`]): a `Result` becomes a code and a message, a panic becomes
//! [`SPLATGL_ERROR_PANIC`].

use std::cell::{Cell, RefCell};
use std::ffi::{CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};

use splatgl::gl::GlError;

/// Success.
pub const SPLATGL_OK: c_int = 0;
/// A pointer argument that must not be `NULL` was `NULL`.
pub const SPLATGL_ERROR_NULL_POINTER: c_int = -1;
/// An argument out of its range (a GL enum that is not a depth function, an SH degree above
/// 3, a splat count beyond the limit, a splat value that is not finite or out of range…).
pub const SPLATGL_ERROR_INVALID_ARGUMENT: c_int = -2;
/// A file could not be loaded (the message names the file, the element and what was wrong).
pub const SPLATGL_ERROR_LOAD: c_int = -3;
/// A GL call failed (a shader, an object, `GL_OUT_OF_MEMORY`, a cloud beyond the texture
/// limits, a GL error the host left pending).
pub const SPLATGL_ERROR_GL: c_int = -4;
/// `splatgl_renderer_draw` before a successful `splatgl_renderer_upload`.
pub const SPLATGL_ERROR_NOT_UPLOADED: c_int = -5;
/// A renderer used from another thread than the one that made it (no GL call was made).
pub const SPLATGL_ERROR_WRONG_THREAD: c_int = -6;
/// The current context is older than OpenGL 3.3 / OpenGL ES 3.0 (or no context is current).
pub const SPLATGL_ERROR_CONTEXT_VERSION: c_int = -7;
/// A view or projection matrix that is not finite, not invertible or not a perspective
/// projection.
pub const SPLATGL_ERROR_MATRIX: c_int = -8;
/// A viewport with a width or height ≤ 0.
pub const SPLATGL_ERROR_VIEWPORT: c_int = -9;
/// splatgl panicked (a bug: please report the message); the call had no effect on the
/// objects passed, which may still be freed.
pub const SPLATGL_ERROR_PANIC: c_int = -10;

/// An error of one call: its code and message.
#[derive(Debug)]
pub(super) struct CError {
    pub(super) code: c_int,
    pub(super) message: String,
}

impl CError {
    pub(super) fn new(code: c_int, message: impl Into<String>) -> Self {
        CError {
            code,
            message: message.into(),
        }
    }

    pub(super) fn null(what: &str) -> Self {
        CError::new(SPLATGL_ERROR_NULL_POINTER, format!("{what} is NULL"))
    }

    pub(super) fn invalid(message: impl Into<String>) -> Self {
        CError::new(SPLATGL_ERROR_INVALID_ARGUMENT, message)
    }
}

impl From<GlError> for CError {
    fn from(e: GlError) -> Self {
        let code = match e {
            GlError::NotUploaded => SPLATGL_ERROR_NOT_UPLOADED,
            GlError::ContextVersion { .. } => SPLATGL_ERROR_CONTEXT_VERSION,
            GlError::Matrix(_) => SPLATGL_ERROR_MATRIX,
            GlError::Viewport(_) => SPLATGL_ERROR_VIEWPORT,
            GlError::OrderTooLong { .. } | GlError::Upload(_) => SPLATGL_ERROR_INVALID_ARGUMENT,
            _ => SPLATGL_ERROR_GL,
        };
        CError::new(code, e.to_string())
    }
}

thread_local! {
    // The code needs no destructor, so it stays readable while the thread's locals are torn
    // down; the message's slot may already be gone then (a host calling splatgl from another
    // thread-local's destructor), and every access to it is `try_with`.
    static CODE: Cell<c_int> = const { Cell::new(SPLATGL_OK) };
    static LAST: RefCell<CString> = RefCell::new(CString::default());
}

/// What [`splatgl_last_error`] returns once this thread's message slot is destroyed.
const GONE: &std::ffi::CStr =
    c"the message is unavailable: this thread is exiting (splatgl_last_error_code has the code)";

fn set_last(code: c_int, message: &str) {
    CODE.set(code);
    // A message with a NUL byte is cut there (C strings end at the first NUL).
    let message = message.split('\0').next().unwrap_or_default();
    let message = splatgl::load::printable(message);
    let text = CString::new(message.as_bytes()).unwrap_or_default();
    let _ = LAST.try_with(|l| {
        if let Ok(mut slot) = l.try_borrow_mut() {
            *slot = text;
        }
    });
}

/// Runs one entry point: `Ok` clears the last error, `Err` records it, a panic records
/// [`SPLATGL_ERROR_PANIC`] with the panic's message. Returns the value, or `fallback` with
/// the error's code.
pub(super) fn call<T>(fallback: T, f: impl FnOnce() -> Result<T, CError>) -> (T, c_int) {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(v)) => {
            set_last(SPLATGL_OK, "");
            (v, SPLATGL_OK)
        }
        Ok(Err(e)) => {
            set_last(e.code, &e.message);
            (fallback, e.code)
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into());
            set_last(SPLATGL_ERROR_PANIC, &format!("splatgl panicked: {what}"));
            (fallback, SPLATGL_ERROR_PANIC)
        }
    }
}

/// [`call`] for entry points that return only a code.
pub(super) fn status(f: impl FnOnce() -> Result<(), CError>) -> c_int {
    call((), f).1
}

/// The message of the last failed call on this thread (`""` after a call that succeeded).
/// The string belongs to splatgl and stays valid until the next splatgl call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn splatgl_last_error() -> *const c_char {
    LAST.try_with(|l| l.try_borrow().map(|m| m.as_ptr()).ok())
        .ok()
        .flatten()
        .unwrap_or(GONE.as_ptr())
}

/// The code of the last call on this thread ([`SPLATGL_OK`] after a call that succeeded):
/// what a constructor that returned `NULL` failed with.
#[unsafe(no_mangle)]
pub extern "C" fn splatgl_last_error_code() -> c_int {
    CODE.get()
}

/// The library's version, e.g. `"0.1.0"` (a static string).
#[unsafe(no_mangle)]
pub extern "C" fn splatgl_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Panics inside the guard (feature `testing`: the test that no panic crosses the boundary).
#[cfg(feature = "testing")]
#[doc(hidden)]
#[unsafe(no_mangle)]
pub extern "C" fn splatgl_testing_panic() -> c_int {
    status(|| panic!("the test hook's panic"))
}
