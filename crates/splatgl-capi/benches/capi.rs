//! Per-draw overhead of the C API: `splatgl_renderer_draw` (the entry point C and C++ hosts
//! call: panic guard, pointer and thread checks, matrices read from C arrays, last-error
//! bookkeeping) against `SplatRenderer::draw_frame` from Rust (the baseline, same run, same
//! renderer settings), alternating draw by draw on one headless context (llvmpipe here).
//!
//! Three loads: 1000 splats seen from behind the camera (all culled: the call's own cost,
//! nothing drawn), 1000 splats in view, and 100,000 splats (the sort and the draw dominate).
//! glFinish after each draw, so each time is the whole frame; medians.
//!
//! `cargo bench -p splatgl-capi --bench capi` (`SPLATGL_BENCH_DRAWS`, default 2000).

use splatgl_testkit as common;

use std::ffi::{CStr, c_char, c_void};
use std::time::Instant;

use common::gl::or_skip;
use glam::Vec3;
use glow::HasContext;
use splatgl::gl::{ColorFormat, ReadbackTarget, SplatRenderer};
use splatgl::headless::HeadlessContext;
use splatgl::{SplatCloud, synthetic};
use splatgl_capi::*;

type Egl = khronos_egl::DynamicInstance<khronos_egl::EGL1_4>;

static EGL: std::sync::OnceLock<Egl> = std::sync::OnceLock::new();

unsafe extern "C" fn loader(name: *const c_char, _user: *mut c_void) -> *mut c_void {
    // SAFETY: a NUL-terminated name from splatgl; libEGL loaded once.
    let name = unsafe { CStr::from_ptr(name) }.to_str().unwrap();
    // SAFETY: libEGL's initialisation run once, by the OnceLock.
    let egl = EGL.get_or_init(|| unsafe { Egl::load_required() }.unwrap());
    egl.get_proc_address(name)
        .map_or(std::ptr::null_mut(), |f| f as *mut c_void)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Uploads `cloud` through the C API: `splatgl_cloud_from_arrays` of its arrays (SH degree
/// 0), then `splatgl_renderer_upload`.
///
/// # Safety
/// `c` is a live renderer made on this thread, its context current.
unsafe fn upload_through_c(c: *mut SplatglRenderer, cloud: &SplatCloud) {
    let mut c_cloud = std::ptr::null_mut();
    let arrays: Vec<f32> = cloud.positions.iter().flatten().copied().collect();
    let scales: Vec<f32> = cloud.scales.iter().flatten().copied().collect();
    let rots: Vec<f32> = cloud.rotations.iter().flatten().copied().collect();
    let sh: Vec<f32> = cloud.sh.iter().flatten().copied().collect();
    // SAFETY: the arrays hold the cloud's splats each, as the call is told; `out` is
    // writable; `c` as the caller promises.
    unsafe {
        let code = splatgl_cloud_from_arrays(
            cloud.len(),
            arrays.as_ptr(),
            scales.as_ptr(),
            rots.as_ptr(),
            cloud.opacities.as_ptr(),
            0,
            sh.as_ptr(),
            &mut c_cloud,
        );
        assert_eq!(code, SPLATGL_OK);
        assert_eq!(splatgl_renderer_upload(c, c_cloud), SPLATGL_OK);
        splatgl_cloud_free(c_cloud);
    }
}

fn main() {
    let smoke = !std::env::args().any(|a| a == "--bench");
    let draws: usize = std::env::var("SPLATGL_BENCH_DRAWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let draws = if smoke { 10 } else { draws.max(10) };
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    ctx.make_current().unwrap();
    let gl = ctx.gl();
    let (w, h) = (64u32, 64u32);
    let mut target = ReadbackTarget::new(gl, w, h, ColorFormat::Rgba8, None).unwrap();
    target.bind(gl).unwrap();
    let viewport = [0, 0, w as i32, h as i32];
    println!("splats | Rust draw_frame µs | C splatgl_renderer_draw µs | C / Rust");
    for (n, away) in [(1000usize, true), (1000, false), (100_000, false)] {
        let cloud = synthetic::random_cloud(n, 0, 0.5, 9);
        let mut rust = SplatRenderer::new(gl).unwrap();
        rust.upload(gl, &cloud).unwrap();
        // SAFETY: a current context, EGL's loader, live pointers, arrays of 16/16/4 values.
        let c = unsafe { splatgl_renderer_new(Some(loader), std::ptr::null_mut()) };
        assert!(!c.is_null());
        let eye = Vec3::new(0.3, 0.2, 3.0);
        let target_point = if away {
            Vec3::new(0.3, 0.2, 6.0)
        } else {
            Vec3::ZERO
        };
        let cam = common::look_at_fov_deg(eye, target_point, 60.0, w, h);
        let (view, proj) = (cam.gl_view(), cam.gl_projection());
        let (v, p) = (view.to_cols_array(), proj.to_cols_array());
        // SAFETY: `c` is a live renderer on this thread, its context current.
        unsafe { upload_through_c(c, &cloud) };
        let (mut t_rust, mut t_c) = (Vec::new(), Vec::new());
        for k in 0..draws + 2 {
            let t0 = Instant::now();
            rust.draw_frame(gl, view, proj, viewport).unwrap();
            // SAFETY: glFinish has no preconditions.
            unsafe { gl.finish() };
            let t1 = Instant::now();
            // SAFETY: as above.
            let code =
                unsafe { splatgl_renderer_draw(c, v.as_ptr(), p.as_ptr(), viewport.as_ptr()) };
            // SAFETY: glFinish has no preconditions.
            unsafe { gl.finish() };
            let t2 = Instant::now();
            assert_eq!(code, SPLATGL_OK);
            if k >= 2 {
                t_rust.push((t1 - t0).as_secs_f64() * 1e6);
                t_c.push((t2 - t1).as_secs_f64() * 1e6);
            }
        }
        let (r, cc) = (median(t_rust), median(t_c));
        let what = if away { " (all culled)" } else { "" };
        println!("{n}{what} | {r:.1} | {cc:.1} | {:.3}", cc / r);
        rust.destroy(gl);
        // SAFETY: the renderer's thread, its context current.
        unsafe { splatgl_renderer_free(c) };
    }
    target.destroy(gl);
}
