//! GL backend tests on Mesa EGL (llvmpipe).
use glam::Vec3;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::headless::{HeadlessError, HeadlessRenderer, RenderOptions};

/// A headless renderer, or `None` (test skipped, with a message) when EGL cannot be opened.
fn headless() -> Option<HeadlessRenderer> {
    match HeadlessRenderer::new() {
        Ok(r) => Some(r),
        Err(HeadlessError::EglUnavailable(msg)) => {
            eprintln!("SKIPPED: EGL cannot be opened here ({msg})");
            None
        }
        Err(e) => panic!("headless GL failed: {e}"),
    }
}

#[test]
fn one_splat_lands_in_the_right_place() {
    let Some(mut r) = headless() else { return };
    eprintln!("{}", r.context().describe());
    let mut cloud = SplatCloud::new(0);
    // Red-ish splat at world (0.5, 0, 0); camera at z=5 looking at the origin.
    cloud.push(
        [0.5, 0.0, 0.0],
        [0.1, 0.1, 0.1],
        [0.0, 0.0, 0.0, 1.0],
        0.9,
        &[[1.0, -1.0, -1.0]],
    );
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 64, 48);
    r.upload(&cloud).unwrap();
    let img = r.render(&cam, &RenderOptions::default()).unwrap();
    let (c, _) = cam.project(Vec3::new(0.5, 0.0, 0.0)).unwrap();
    let (cx, cy) = (c.x as u32, c.y as u32);
    let p = img.get(cx, cy);
    eprintln!("centre {c}: {p:?}");
    assert!(p[0] > 0.5 && p[1] < 0.3 && p[3] > 0.8, "{p:?}");
    assert_eq!(img.get(2, 2), [0.0; 4]);
}
