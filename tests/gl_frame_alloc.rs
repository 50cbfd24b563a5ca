//! The per-frame path allocates nothing: after the first frame, `SplatRenderer::draw_frame`
//! makes no Rust heap allocation on any thread (the sorter's scratch and the order buffer are
//! sized by the first frame). Its own test binary, so no other test allocates meanwhile. The
//! GL driver's own allocations (Mesa's, through libc) are not ours and not counted.

use splatgl_testkit as common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use common::gl::*;
use splatgl::gl::{ColorFormat, ReadbackTarget, SplatRenderer};

/// Counts allocations while `COUNTING` is set.
struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: the caller's layout, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: a pointer this allocator returned, with its layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: as `realloc`'s contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn draw_frame_allocates_nothing_after_the_first_frame() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    ctx.make_current().unwrap();
    let gl = ctx.gl();
    // Large enough that the sort runs on rayon's threads (they are counted too).
    let cloud = synthetic::random_cloud(200_000, 0, 0.5, 5);
    let (w, h) = (64, 48);
    let mut target = ReadbackTarget::new(gl, w, h, ColorFormat::Rgba8, None).unwrap();
    target.bind(gl).unwrap();
    let mut r = SplatRenderer::new(gl).unwrap();
    r.upload(gl, &cloud).unwrap();
    let viewport = [0, 0, w as i32, h as i32];
    let frame = |r: &mut SplatRenderer, k: usize| {
        let eye = Vec3::new(0.2 * (k as f32).sin(), 0.1, 3.0 + 0.05 * k as f32);
        let cam = look_at_fov_deg(eye, Vec3::ZERO, 60.0, w, h);
        r.draw_frame(gl, cam.gl_view(), cam.gl_projection(), viewport)
            .unwrap();
    };
    frame(&mut r, 0); // warms the sorter's scratch
    let mut counts = Vec::new();
    for k in 1..=8 {
        ALLOCATIONS.store(0, Ordering::Relaxed);
        COUNTING.store(true, Ordering::Relaxed);
        frame(&mut r, k);
        COUNTING.store(false, Ordering::Relaxed);
        counts.push(ALLOCATIONS.load(Ordering::Relaxed));
    }
    // The counter itself works: a frame that must allocate is seen.
    COUNTING.store(true, Ordering::Relaxed);
    let seen = std::hint::black_box(vec![0u8; 64]);
    COUNTING.store(false, Ordering::Relaxed);
    drop(seen);
    assert!(
        ALLOCATIONS.load(Ordering::Relaxed) > 0,
        "the counter counts"
    );
    assert!(
        counts.iter().all(|&c| c == 0),
        "allocations per frame: {counts:?}"
    );
    r.destroy(gl);
    target.destroy(gl);
}
