//! The C API's error paths, called as a C host calls them: each is a documented code and a
//! message, never a crash — null pointers, a draw before an upload, bad viewports, non-finite
//! or non-perspective matrices, contexts of the wrong version (or none), calls from another
//! thread, bad splat arrays, load failures and containment, and a panic inside the library.

use crate::common;

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::ptr::{null, null_mut};
use std::sync::OnceLock;

use common::gl::*;
use splatgl_capi::*;

type Egl = khronos_egl::DynamicInstance<khronos_egl::EGL1_4>;

fn egl() -> &'static Egl {
    static EGL: OnceLock<Egl> = OnceLock::new();
    // SAFETY: loads the system's libEGL (the headless context below already did).
    EGL.get_or_init(|| unsafe { Egl::load_required() }.expect("libEGL"))
}

/// The real loader (EGL's).
unsafe extern "C" fn loader(name: *const c_char, _user: *mut c_void) -> *mut c_void {
    // SAFETY: a NUL-terminated name from splatgl.
    let name = unsafe { CStr::from_ptr(name) }.to_str().unwrap();
    egl()
        .get_proc_address(name)
        .map_or(null_mut(), |f| f as *mut c_void)
}

/// The version string the fake `glGetString` reports (`user` of [`old_loader`]).
static REAL_GET_STRING: OnceLock<usize> = OnceLock::new();
static FAKE_VERSION: &CStr = c"2.1 Mesa 22.3.6";

extern "system" fn fake_get_string(name: u32) -> *const c_char {
    if name == glow::VERSION {
        return FAKE_VERSION.as_ptr();
    }
    // SAFETY: the real glGetString, looked up by `old_loader`.
    let real: extern "system" fn(u32) -> *const c_char =
        unsafe { std::mem::transmute(*REAL_GET_STRING.get().unwrap()) };
    real(name)
}

/// A loader whose context claims to be OpenGL 2.1 (a host with an old context).
unsafe extern "C" fn old_loader(name: *const c_char, user: *mut c_void) -> *mut c_void {
    // SAFETY: passed on.
    let real = unsafe { loader(name, user) };
    // SAFETY: a NUL-terminated name.
    if unsafe { CStr::from_ptr(name) } == c"glGetString" {
        REAL_GET_STRING.get_or_init(|| real as usize);
        return fake_get_string as *mut c_void;
    }
    real
}

/// A loader for a thread with no current context: glGetString returns NULL there.
unsafe extern "C" fn no_context_loader(name: *const c_char, user: *mut c_void) -> *mut c_void {
    // SAFETY: passed on.
    unsafe { loader(name, user) }
}

fn last() -> (c_int, String) {
    // SAFETY: the library's last error is a NUL-terminated string it keeps alive.
    let msg = unsafe { CStr::from_ptr(splatgl_last_error()) };
    (
        splatgl_last_error_code(),
        msg.to_string_lossy().into_owned(),
    )
}

fn context() -> Option<HeadlessContext> {
    let ctx = or_skip(HeadlessContext::new(), "headless context")?;
    ctx.make_current().unwrap();
    Some(ctx)
}

/// A cloud of `n` unit splats from arrays.
fn arrays_cloud(n: usize) -> *mut SplatglCloud {
    let pos: Vec<f32> = (0..n).flat_map(|i| [i as f32 * 0.1, 0.0, 0.0]).collect();
    let scale = vec![0.1f32; 3 * n];
    let rot: Vec<f32> = (0..n).flat_map(|_| [0.0, 0.0, 0.0, 1.0]).collect();
    let (opacity, sh) = (vec![0.8f32; n], vec![0.5f32; 3 * n]);
    let mut c = null_mut();
    let (p, s, r, o, h) = (
        pos.as_ptr(),
        scale.as_ptr(),
        rot.as_ptr(),
        opacity.as_ptr(),
        sh.as_ptr(),
    );
    // SAFETY: arrays of the documented lengths.
    let code = unsafe { splatgl_cloud_from_arrays(n, p, s, r, o, 0, h, &mut c) };
    assert_eq!(code, SPLATGL_OK, "{:?}", last());
    c
}

const VIEW: [f32; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -3.0, 1.0,
];
const PROJ: [f32; 16] = [
    1.5, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, -1.002, -1.0, 0.0, 0.0, -0.2002, 0.0,
];
const VIEWPORT: [c_int; 4] = [0, 0, 64, 48];

#[test]
fn null_pointers_are_error_codes_with_messages() {
    // SAFETY: every call below is given NULL where the contract allows NULL.
    unsafe {
        assert!(splatgl_renderer_new(None, null_mut()).is_null());
        assert_eq!(last().0, SPLATGL_ERROR_NULL_POINTER);
        assert!(last().1.contains("get_proc"), "{:?}", last());
        let mut out = null_mut();
        assert_eq!(
            splatgl_cloud_load(null(), &mut out),
            SPLATGL_ERROR_NULL_POINTER
        );
        assert_eq!(
            splatgl_cloud_load(c"x.ply".as_ptr(), null_mut()),
            SPLATGL_ERROR_NULL_POINTER
        );
        let n = 2;
        let code =
            splatgl_cloud_from_arrays(n, null(), null(), null(), null(), 0, null(), &mut out);
        assert_eq!(code, SPLATGL_ERROR_NULL_POINTER);
        assert!(last().1.contains("positions"), "{:?}", last());
        assert!(out.is_null());
        assert_eq!(splatgl_cloud_len(null()), 0);
        assert_eq!(splatgl_cloud_sh_degree(null()), SPLATGL_ERROR_NULL_POINTER);
        let v = VIEW.as_ptr();
        assert_eq!(
            splatgl_renderer_draw(null_mut(), v, v, VIEWPORT.as_ptr()),
            SPLATGL_ERROR_NULL_POINTER
        );
        assert_eq!(
            splatgl_renderer_upload(null_mut(), null()),
            SPLATGL_ERROR_NULL_POINTER
        );
        assert_eq!(
            splatgl_renderer_set_restore_state(null_mut(), 1),
            SPLATGL_ERROR_NULL_POINTER
        );
        assert_eq!(
            splatgl_load_options_default(null_mut()),
            SPLATGL_ERROR_NULL_POINTER
        );
        splatgl_cloud_free(null_mut());
        splatgl_renderer_free(null_mut());
        assert_eq!(last(), (SPLATGL_OK, String::new()), "free(NULL) succeeds");
    }
}

#[test]
fn renderer_calls_refuse_what_they_cannot_draw() {
    let Some(_ctx) = context() else { return };
    // SAFETY: a current context, pointers to arrays of the documented sizes.
    unsafe {
        let r = splatgl_renderer_new(Some(loader), null_mut());
        assert!(!r.is_null(), "{:?}", last());
        let (v, p, vp) = (VIEW.as_ptr(), PROJ.as_ptr(), VIEWPORT.as_ptr());
        assert_eq!(
            splatgl_renderer_draw(r, v, p, vp),
            SPLATGL_ERROR_NOT_UPLOADED
        );
        assert!(last().1.contains("before upload"), "{:?}", last());
        assert_eq!(
            splatgl_renderer_upload(r, null()),
            SPLATGL_ERROR_NULL_POINTER
        );
        let cloud = arrays_cloud(10);
        assert_eq!(splatgl_renderer_upload(r, cloud), SPLATGL_OK);
        splatgl_cloud_free(cloud); // freed after its upload: the renderer still draws
        assert_eq!(
            splatgl_renderer_draw(r, v, p, vp),
            SPLATGL_OK,
            "{:?}",
            last()
        );
        assert_eq!(
            splatgl_renderer_draw(r, null(), p, vp),
            SPLATGL_ERROR_NULL_POINTER
        );
        assert_eq!(
            splatgl_renderer_draw(r, v, p, null()),
            SPLATGL_ERROR_NULL_POINTER
        );
        for bad in [[0, 0, 0, 48], [0, 0, 64, -2]] {
            assert_eq!(
                splatgl_renderer_draw(r, v, p, bad.as_ptr()),
                SPLATGL_ERROR_VIEWPORT
            );
        }
        let mut nan = VIEW;
        nan[13] = f32::INFINITY;
        assert_eq!(
            splatgl_renderer_draw(r, nan.as_ptr(), p, vp),
            SPLATGL_ERROR_MATRIX
        );
        let mut ortho = [0.0f32; 16];
        for k in [0, 5, 10, 15] {
            ortho[k] = 1.0;
        }
        assert_eq!(
            splatgl_renderer_draw(r, v, ortho.as_ptr(), vp),
            SPLATGL_ERROR_MATRIX
        );
        assert!(last().1.contains("perspective"), "{:?}", last());
        assert_eq!(
            splatgl_renderer_set_depth_func(r, 0x0207),
            SPLATGL_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(splatgl_renderer_set_depth_func(r, glow::GEQUAL), SPLATGL_OK);
        assert_eq!(
            splatgl_renderer_set_sh_degree(r, 4),
            SPLATGL_ERROR_INVALID_ARGUMENT
        );
        assert_eq!(splatgl_renderer_set_sh_degree(r, -1), SPLATGL_OK);
        assert_eq!(splatgl_renderer_set_depth_test(r, 0), SPLATGL_OK);
        assert_eq!(
            last(),
            (SPLATGL_OK, String::new()),
            "a success clears the message"
        );
        splatgl_renderer_free(r);
    }
}

#[test]
fn contexts_of_the_wrong_version_or_none_are_refused() {
    let Some(_ctx) = context() else { return };
    // SAFETY: loaders that behave as documented.
    unsafe {
        assert!(splatgl_renderer_new(Some(old_loader), null_mut()).is_null());
        let (code, msg) = last();
        assert_eq!(code, SPLATGL_ERROR_CONTEXT_VERSION, "{msg}");
        assert!(msg.contains("2.1"), "{msg}");
    }
    // A thread with no context current: glGetString returns NULL.
    std::thread::spawn(|| {
        // SAFETY: EGL's loader; no context is current on this thread.
        let r = unsafe { splatgl_renderer_new(Some(no_context_loader), null_mut()) };
        assert!(r.is_null());
        let (code, msg) = last();
        assert_eq!(code, SPLATGL_ERROR_CONTEXT_VERSION, "{msg}");
        assert!(msg.contains("no GL context is current"), "{msg}");
    })
    .join()
    .unwrap();
}

#[test]
fn calls_from_another_thread_are_refused_without_gl_calls() {
    let Some(_ctx) = context() else { return };
    // SAFETY: a current context; the renderer is used on its thread except where refused.
    unsafe {
        let r = splatgl_renderer_new(Some(loader), null_mut());
        assert!(!r.is_null(), "{:?}", last());
        let cloud = arrays_cloud(4);
        assert_eq!(splatgl_renderer_upload(r, cloud), SPLATGL_OK);
        let (addr, caddr) = (r as usize, cloud as usize);
        std::thread::spawn(move || {
            let r = addr as *mut SplatglRenderer;
            let (v, p, vp) = (VIEW.as_ptr(), PROJ.as_ptr(), VIEWPORT.as_ptr());
            assert_eq!(
                splatgl_renderer_draw(r, v, p, vp),
                SPLATGL_ERROR_WRONG_THREAD
            );
            assert!(last().1.contains("thread"), "{:?}", last());
            let c = caddr as *const SplatglCloud;
            assert_eq!(splatgl_renderer_upload(r, c), SPLATGL_ERROR_WRONG_THREAD);
            assert_eq!(
                splatgl_renderer_set_restore_state(r, 1),
                SPLATGL_ERROR_WRONG_THREAD
            );
            // Clouds are plain memory: any thread may use them.
            assert_eq!(splatgl_cloud_len(c), 4);
        })
        .join()
        .unwrap();
        let (v, p, vp) = (VIEW.as_ptr(), PROJ.as_ptr(), VIEWPORT.as_ptr());
        assert_eq!(
            splatgl_renderer_draw(r, v, p, vp),
            SPLATGL_OK,
            "{:?}",
            last()
        );
        splatgl_cloud_free(cloud);
        // Freed from another thread: no GL call, the objects go with the context.
        std::thread::spawn(move || {
            splatgl_renderer_free(addr as *mut SplatglRenderer);
            assert_eq!(last().0, SPLATGL_ERROR_WRONG_THREAD);
        })
        .join()
        .unwrap();
    }
}

#[test]
fn bad_splat_arrays_name_the_splat_and_field() {
    let n = 3;
    let pos = [0.0f32, 0.0, 0.0, 1.0, f32::NAN, 0.0, 2.0, 0.0, 0.0];
    let scale = [0.1f32; 9];
    let mut rot = [0.0f32, 0.0, 0.0, 2.0].repeat(3); // not unit: normalised, accepted
    let opacity = [0.5f32; 3];
    let sh = [0.1f32; 9];
    let mut out = null_mut();
    let call =
        |pos: &[f32], rot: &[f32], opacity: &[f32], degree: c_int, out: &mut *mut SplatglCloud| {
            // SAFETY: arrays at least as long as the documented lengths.
            unsafe {
                splatgl_cloud_from_arrays(
                    n,
                    pos.as_ptr(),
                    scale.as_ptr(),
                    rot.as_ptr(),
                    opacity.as_ptr(),
                    degree,
                    sh.as_ptr(),
                    out,
                )
            }
        };
    assert_eq!(
        call(&pos, &rot, &opacity, 0, &mut out),
        SPLATGL_ERROR_INVALID_ARGUMENT
    );
    assert!(last().1.contains("splat 1: position"), "{:?}", last());
    let good_pos = [0.0f32; 9];
    assert_eq!(
        call(&good_pos, &rot, &opacity, 4, &mut out),
        SPLATGL_ERROR_INVALID_ARGUMENT
    );
    assert!(last().1.contains("sh_degree 4"), "{:?}", last());
    assert_eq!(
        call(&good_pos, &rot, &[0.5, 2.0, 0.5], 0, &mut out),
        SPLATGL_ERROR_INVALID_ARGUMENT
    );
    assert!(last().1.contains("splat 1: opacity"), "{:?}", last());
    rot[8..12].copy_from_slice(&[0.0; 4]);
    assert_eq!(
        call(&good_pos, &rot, &opacity, 0, &mut out),
        SPLATGL_ERROR_INVALID_ARGUMENT
    );
    assert!(last().1.contains("splat 2: rotation"), "{:?}", last());
    assert!(out.is_null(), "no cloud on failure");
    rot[8..12].copy_from_slice(&[0.0, 0.0, 0.0, 3.0]);
    assert_eq!(
        call(&good_pos, &rot, &opacity, 0, &mut out),
        SPLATGL_OK,
        "{:?}",
        last()
    );
    // SAFETY: a live cloud.
    unsafe {
        assert_eq!(splatgl_cloud_len(out), 3);
        splatgl_cloud_free(out);
    }
}

#[test]
fn loads_fail_with_the_file_named_and_stay_inside_the_root() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-load");
    let inside = dir.join("inside");
    std::fs::create_dir_all(&inside).unwrap();
    let cloud = synthetic::random_cloud(50, 0, 0.5, 3);
    let file = dir.join("outside.ply");
    std::fs::write(&file, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let path = CString::new(file.to_str().unwrap()).unwrap();
    let mut out = null_mut();
    // SAFETY: NUL-terminated strings, a valid options struct, a writable out.
    unsafe {
        let missing = CString::new(dir.join("missing.ply").to_str().unwrap()).unwrap();
        assert_eq!(
            splatgl_cloud_load(missing.as_ptr(), &mut out),
            SPLATGL_ERROR_LOAD
        );
        assert!(last().1.contains("missing.ply"), "{:?}", last());
        let mut opts = std::mem::zeroed();
        assert_eq!(splatgl_load_options_default(&mut opts), SPLATGL_OK);
        let root = CString::new(inside.to_str().unwrap()).unwrap();
        opts.root = root.as_ptr();
        assert_eq!(
            splatgl_cloud_load_with(path.as_ptr(), &opts, &mut out),
            SPLATGL_ERROR_LOAD
        );
        assert!(
            last().1.contains("outside the allowed folder"),
            "{:?}",
            last()
        );
        opts.root = null();
        opts.max_splats = 10;
        assert_eq!(
            splatgl_cloud_load_with(path.as_ptr(), &opts, &mut out),
            SPLATGL_ERROR_LOAD
        );
        assert!(last().1.contains("max_splats"), "{:?}", last());
        assert!(out.is_null());
        assert_eq!(
            splatgl_cloud_load_with(path.as_ptr(), null(), &mut out),
            SPLATGL_OK
        );
        assert_eq!(splatgl_cloud_len(out), 50);
        assert_eq!(splatgl_cloud_sh_degree(out), 0);
        splatgl_cloud_free(out);
    }
}

#[test]
fn a_panic_inside_becomes_an_error_code() {
    assert_eq!(splatgl_testing_panic(), SPLATGL_ERROR_PANIC);
    let (code, msg) = last();
    assert_eq!(code, SPLATGL_ERROR_PANIC);
    assert!(msg.contains("the test hook's panic"), "{msg}");
    // The library still works afterwards.
    // SAFETY: a plain C struct, for which all zero bytes are a valid value.
    let mut opts = unsafe { std::mem::zeroed() };
    assert_eq!(
        // SAFETY: a writable struct.
        unsafe { splatgl_load_options_default(&mut opts) },
        SPLATGL_OK
    );
}

/// Calls into the C API from its destructor: a host's thread-local torn down after splatgl's.
struct CallsOnDrop(std::sync::mpsc::Sender<(c_int, c_int, String)>);

impl Drop for CallsOnDrop {
    fn drop(&mut self) {
        // SAFETY: NULL `out` is a documented error.
        let code = unsafe {
            splatgl_cloud_from_arrays(0, null(), null(), null(), null(), 0, null(), null_mut())
        };
        let (last_code, msg) = last();
        let _ = self.0.send((code, last_code, msg));
    }
}

thread_local! {
    static HOST: std::cell::RefCell<Option<CallsOnDrop>> = const { std::cell::RefCell::new(None) };
}

#[test]
fn calls_during_thread_teardown_return_codes_instead_of_aborting() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        // The host's local first, then splatgl's: destroyed in reverse, so splatgl's message
        // slot is gone when the host's destructor calls in.
        HOST.with(|h| *h.borrow_mut() = Some(CallsOnDrop(tx)));
        assert_eq!(splatgl_testing_panic(), SPLATGL_ERROR_PANIC);
    })
    .join()
    .unwrap();
    let (code, last_code, msg) = rx.recv().expect("the destructor ran and reported");
    assert_eq!(
        (code, last_code),
        (SPLATGL_ERROR_NULL_POINTER, SPLATGL_ERROR_NULL_POINTER)
    );
    assert!(!msg.is_empty(), "{msg}");
}
