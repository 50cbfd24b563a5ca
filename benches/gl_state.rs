//! Per-draw cost of `restore_state` on the headless context (llvmpipe here): µs per draw
//! with `restore_state: false` (the baseline, same run) and `true`, and the GL calls the
//! state handling makes in each mode (counted in the code: `SplatRenderer::last_state_calls`).
//!
//! Two loads: an empty order (nothing rasterised: the draw call's CPU overhead, where the
//! state handling is all the difference; 100 draws per timed block, glFinish after the block)
//! and 1000 small splats at 64×64 (glFinish after each draw, so the GPU work is included).
//! The µs include the host's three state calls before each draw, the same in both modes;
//! each is the median over the timed blocks. Before every draw the "host" sets its own opaque-pass
//! state (blending off, `ONE, ZERO`, depth writes on), so restore mode changes and puts back
//! the usual pieces (bindings, blend, depth mask); the modes alternate draw by draw.
//!
//! `cargo bench --features testing --bench gl_state` (`SPLATGL_BENCH_DRAWS`, default 4000).

use splatgl_testkit as common;

use std::time::Instant;

use common::gl::or_skip;
use glam::Vec3;
use glow::HasContext;
use splatgl::camera::Camera;
use splatgl::gl::{ColorFormat, ReadbackTarget, SplatRenderer};
use splatgl::headless::{GlApi, HeadlessContext};
use splatgl::synthetic;

fn main() {
    let smoke = !std::env::args().any(|a| a == "--bench");
    let draws: usize = std::env::var("SPLATGL_BENCH_DRAWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4000);
    let draws = if smoke { 20 } else { draws.max(10) };
    for api in [GlApi::Gles3, GlApi::DesktopCore33, GlApi::DesktopCompat] {
        let Some(ctx) = or_skip(HeadlessContext::with_api(api), "headless context") else {
            return;
        };
        println!("context: {}", ctx.describe());
        run(&ctx, draws);
    }
}

/// Both loads in both modes on `ctx`.
fn run(ctx: &HeadlessContext, draws: usize) {
    let gl = ctx.gl();
    let mut frame = ReadbackTarget::new(gl, 64, 64, ColorFormat::Rgba8, None).unwrap();
    frame.bind(gl).unwrap();
    let cloud = synthetic::random_cloud(1000, 1, 0.8, 5);
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 0.9, 64, 64);
    let order = splatgl::sort::Sorter::new()
        .sort_by_distance(&cloud.positions, cam.eye().to_array())
        .to_vec();
    let mut r = SplatRenderer::new(gl).unwrap();
    r.upload(gl, &cloud).unwrap();
    r.settings_mut().depth_test = false;
    println!(
        "{:>12} | {:>8} | {:>10} | {:>13} | {:>12}",
        "load", "restore", "µs / draw", "state queries", "state sets"
    );
    // The host's own state, set again before every draw in both modes: blending off, its
    // blend func, depth writes on (what a host's opaque pass wants).
    let host_state = || {
        // SAFETY: plain state setters.
        unsafe {
            gl.disable(glow::BLEND);
            gl.blend_func(glow::ONE, glow::ZERO);
            gl.depth_mask(true);
        }
    };
    for (load, n) in [("empty order", 0), ("1000 splats", order.len())] {
        r.set_order(gl, &order[..n]).unwrap();
        // Blocks of draws (of both modes in turn, which one first alternating), so drifting
        // machine load hits both alike. Empty order: 100 draws back to back per block, as in a
        // frame (host calls queued before each draw); 1000 splats: one draw + glFinish.
        let per_block = if n == 0 { 100 } else { 1 };
        let blocks = (draws / per_block).max(2);
        let mut times: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
        let mut calls = [Default::default(); 2];
        for b in 0..blocks + 2 {
            let modes = if b % 2 == 0 { [0, 1] } else { [1, 0] };
            for k in modes {
                r.settings_mut().restore_state = k == 1;
                // SAFETY: glFinish has no preconditions.
                unsafe { gl.finish() };
                let t = Instant::now();
                for _ in 0..per_block {
                    host_state();
                    r.draw_current(gl, &cam).unwrap();
                }
                // SAFETY: as above.
                unsafe { gl.finish() };
                if b >= 2 {
                    // The first blocks warm up (shader variants, caches).
                    times[k].push(t.elapsed().as_secs_f64() / per_block as f64);
                }
                calls[k] = r.last_state_calls();
            }
        }
        // The median block: robust to the scheduler hiccups of a shared machine.
        let us = times.map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2] * 1e6
        });
        for (k, restore) in [false, true].into_iter().enumerate() {
            let c: splatgl::gl::StateCalls = calls[k];
            let delta = if restore {
                format!("   ({:+.2} µs, ×{:.2})", us[1] - us[0], us[1] / us[0])
            } else {
                String::new()
            };
            println!(
                "{load:>12} | {restore:>8} | {:>10.2} | {:>13} | {:>12}{delta}",
                us[k], c.queries, c.sets
            );
        }
    }
    r.destroy(gl);
    frame.destroy(gl);
}
