//! Frame-time benchmark of the GL backend on the headless context (llvmpipe here), split into
//! sort / upload / draw, for 100k and 1M splats at 1280×720.
//!
//! Each size runs twice: blending directly in the `RGBA8` framebuffer, and in an `RGBA16F`
//! [`OffscreenTarget`] plus its resolve pass (the draw column then includes the resolve).
//!
//! `cargo bench --bench gl` (set `SPLATGL_BENCH_FRAMES`, default 5, and `SPLATGL_BENCH_SIZES`,
//! default `100000,1000000`, and `SPLATGL_BENCH_SCALE`, default 1, a factor on the splat scales). A short, plain timing loop rather than criterion: one 1M-splat
//! frame on llvmpipe takes long enough that criterion's minimum sample counts would make the
//! run minutes long. Each phase ends with `glFinish`, so GPU work is attributed to it.
//!
//! `draw CPU ms` is the process's CPU time (all threads) during the draw: on a machine shared
//! with other jobs it moves far less than wall time.
//!
//! Scene: `scene::random_cloud(n, 3, 1.0, seed)` (means uniform in [-1, 1]³, SH degree 3)
//! with scales × 0.2·(10⁵/n)^(1/3), so the covered screen area is about the same for both sizes;
//! camera at distance 3.2, 50° vertical fov.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use common::gl::or_skip;
use glam::Vec3;
use glow::HasContext;
use splatgl::camera::Camera;
use splatgl::gl::{ColorFormat, DistanceSorter, OffscreenTarget, ReadbackTarget, SplatRenderer};
use splatgl::headless::HeadlessContext;
use splatgl::scene;

/// CPU time of the whole process (all threads, so llvmpipe's rasterizer threads count), which
/// is far less disturbed than wall time when other jobs share the machine.
fn cpu_time() -> Duration {
    let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a rusage struct into the valid, writable pointer it is given.
    let u = unsafe {
        libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr());
        u.assume_init()
    };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(u.ru_utime) + tv(u.ru_stime)
}

fn median(v: &mut [Duration]) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    // `cargo test --all-targets` runs bench binaries without `--bench`: then only smoke-test
    // the code path on a tiny cloud instead of timing 1M splats in a debug build.
    let smoke = !std::env::args().any(|a| a == "--bench");
    let frames: usize = std::env::var("SPLATGL_BENCH_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5)
        .max(1);
    let sizes: Vec<usize> = std::env::var("SPLATGL_BENCH_SIZES")
        .unwrap_or_else(|_| "100000,1000000".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let (frames, sizes) = if smoke {
        (1, vec![1000])
    } else {
        (frames, sizes)
    };
    // Extra factor on the splat scales (e.g. 0.01: sub-pixel splats, to see the vertex cost).
    let scale_factor: f32 = std::env::var("SPLATGL_BENCH_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    println!("context: {}", ctx.describe());
    let (w, h) = (1280u32, 720u32);
    // An RGBA8 framebuffer of the frame size, bound for the whole benchmark.
    let mut frame = ReadbackTarget::new(gl, w, h, ColorFormat::Rgba8, None).unwrap();
    frame.bind(gl).unwrap();
    let mut renderer = SplatRenderer::new(gl).unwrap();
    let mut offscreen = OffscreenTarget::new(gl, w, h).unwrap();
    let mut sorter = DistanceSorter::default();
    let mut order = Vec::new();
    println!(
        "{:>9} | {:>8} | {:>9} | {:>9} | {:>9} | {:>12} | {:>9} | {:>12} | {:>10}",
        "splats",
        "target",
        "sort ms",
        "upload ms",
        "draw ms",
        "draw CPU ms",
        "frame ms",
        "bytes/frame",
        "upload once"
    );
    for (n, float_target) in sizes.iter().flat_map(|&n| [(n, false), (n, true)]) {
        let mut cloud = scene::random_cloud(n, 3, 1.0, 1234);
        let k = scale_factor * 0.2 * (1e5 / n as f32).cbrt();
        for s in &mut cloud.scales {
            *s = s.map(|v| v * k);
        }
        let t = Instant::now();
        renderer.upload(gl, &cloud).unwrap();
        // SAFETY: glFinish has no preconditions.
        unsafe { gl.finish() };
        let upload_once = t.elapsed();
        let (mut ts, mut tu, mut td, mut tc) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for f in 0..frames + 1 {
            // Orbit a little so every frame sorts a new order.
            let a = 0.05 * f as f32;
            let eye = Vec3::new(3.2 * a.sin(), 0.4, 3.2 * a.cos());
            let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 50f32.to_radians(), w, h);
            // SAFETY: clearing the bound FBO.
            unsafe {
                gl.clear_color(0.0, 0.0, 0.0, 0.0);
                gl.clear(glow::COLOR_BUFFER_BIT);
                gl.finish();
            }
            let t0 = Instant::now();
            sorter.sort(&cloud.positions, cam.eye(), &mut order);
            let t1 = Instant::now();
            renderer.set_order(gl, &order).unwrap();
            // SAFETY: glFinish has no preconditions.
            unsafe { gl.finish() };
            let t2 = Instant::now();
            let c2 = cpu_time();
            if float_target {
                offscreen.begin(gl, [0.0; 4]).unwrap();
                renderer.draw_current(gl, &cam).unwrap();
                offscreen.resolve(gl, false).unwrap();
            } else {
                renderer.draw_current(gl, &cam).unwrap();
            }
            // SAFETY: glFinish has no preconditions.
            unsafe { gl.finish() };
            let t3 = Instant::now();
            let c3 = cpu_time();
            if f > 0 {
                // Frame 0 warms up (shader variants, caches).
                ts.push(t1 - t0);
                tu.push(t2 - t1);
                td.push(t3 - t2);
                tc.push(c3 - c2);
            }
        }
        let (s, u, d, dc) = (
            median(&mut ts),
            median(&mut tu),
            median(&mut td),
            median(&mut tc),
        );
        println!(
            "{:>9} | {:>8} | {:>9.2} | {:>9.2} | {:>9.2} | {:>12.2} | {:>9.2} | {:>12} | {:>8.0}ms",
            n,
            if float_target { "RGBA16F" } else { "RGBA8" },
            ms(s),
            ms(u),
            ms(d),
            ms(dc),
            ms(s + u + d),
            4 * order.len(),
            ms(upload_once)
        );
    }
    renderer.destroy(gl);
    offscreen.destroy(gl);
    frame.destroy(gl);
}
