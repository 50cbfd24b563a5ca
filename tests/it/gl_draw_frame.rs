//! `SplatRenderer::draw_frame`, the host's default path: it culls and sorts for the host, and
//! draws exactly what the advanced path (the host's own full order) draws, for standard and
//! reversed-Z projections, synchronously and from the background sorter; and it refuses what
//! it cannot draw with an error instead of drawing something.

use crate::common;

use common::gl::*;
use glam::Mat4;
use splatgl::gl::{ColorFormat, FrameSort, GlError, ReadbackTarget, SplatRenderer, SplatScene};
use splatgl::sort::{Freshness, Sorter, StaleBound};

const W: u32 = 96;
const H: u32 = 72;
const VIEWPORT: [i32; 4] = [0, 0, W as i32, H as i32];

/// A cloud that reaches out of the view on every side (so the cull drops splats), seen from
/// a camera 4 units away.
fn scene() -> (SplatCloud, Camera) {
    let mut cloud = synthetic::random_cloud(3000, 1, 0.7, 21);
    for p in &mut cloud.positions {
        *p = p.map(|v| v * 3.0);
    }
    let cam = look_at_fov_deg(Vec3::new(0.3, 0.2, 4.0), Vec3::ZERO, 50.0, W, H);
    (cloud, cam)
}

/// `proj` with reversed-Z and an infinite far plane (GL's [-1, 1] depth: 2n/d − 1).
fn reversed_infinite(proj: Mat4, near: f32) -> Mat4 {
    let mut p = proj;
    p.z_axis.z = 1.0;
    p.w_axis.z = 2.0 * near;
    p
}

/// Draws into a fresh RGBA8 target with `draw`, returns the image.
fn image(
    gl: &glow::Context,
    r: &mut SplatRenderer,
    draw: impl FnOnce(&mut SplatRenderer) -> Result<(), GlError>,
) -> Image {
    let mut target = ReadbackTarget::new(gl, W, H, ColorFormat::Rgba8, None).unwrap();
    target.bind(gl).unwrap();
    // SAFETY: clears the target just bound.
    unsafe {
        use glow::HasContext;
        gl.viewport(0, 0, W as i32, H as i32);
        gl.clear_color(0.0, 0.0, 0.0, 0.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
    draw(r).unwrap();
    let img = target.read_image(gl).unwrap();
    target.destroy(gl);
    img
}

/// A renderer with `cloud` uploaded, drawing without a depth test (the targets have none).
fn uploaded(gl: &glow::Context, cloud: &SplatCloud) -> SplatRenderer {
    let mut r = SplatRenderer::new(gl).unwrap();
    r.settings_mut().depth_test = false;
    r.upload(gl, cloud).unwrap();
    r
}

#[test]
fn draw_frame_draws_what_the_full_order_draws() {
    let Some(ctx) = current_context() else { return };
    let gl = ctx.gl();
    let (cloud, cam) = scene();
    let mut r = uploaded(gl, &cloud);
    let view = cam.gl_view();
    let eye = cam.eye().to_array();
    let full = Sorter::new()
        .sort_by_distance(&cloud.positions, eye)
        .to_vec();
    for proj in [
        cam.gl_projection(),
        reversed_infinite(cam.gl_projection(), 0.05),
    ] {
        let host_sorted = image(gl, &mut r, |r| {
            r.draw_with_matrices(gl, view, proj, VIEWPORT, &full)
        });
        let framed = image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
        assert_eq!(r.last_frame_order(), Some(Freshness::Exact));
        assert_eq!(
            framed.pixels, host_sorted.pixels,
            "draw_frame vs the full order"
        );
        let lit = framed.pixels.iter().filter(|p| p[3] > 0.05).count();
        assert!(lit > (W * H / 4) as usize, "only {lit} pixels drawn");
    }
    r.destroy(gl);
}

#[test]
fn draw_frame_in_the_background_draws_exact_or_bounded_orders() {
    let Some(ctx) = current_context() else { return };
    let gl = ctx.gl();
    let (cloud, cam) = scene();
    let mut r = uploaded(gl, &cloud);
    let (view, proj) = (cam.gl_view(), cam.gl_projection());
    let want = image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
    // Strict: only provably exact orders are drawn, so the image is the synchronous one.
    r.settings_mut().sort = FrameSort::Async(StaleBound::Strict);
    for _ in 0..3 {
        let got = image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
        assert_eq!(got.pixels, want.pixels, "strict background order");
        let fresh = r.last_frame_order().unwrap();
        assert!(
            matches!(fresh, Freshness::Exact | Freshness::Waited),
            "{fresh:?}"
        );
    }
    // A generous bound: a small move may draw a stale order, never one beyond the bound.
    r.settings_mut().sort = FrameSort::Async(StaleBound::Distance(0.5));
    let mut kinds = Vec::new();
    for k in 0..6 {
        let moved = Mat4::from_translation(Vec3::new(0.01 * k as f32, 0.0, 0.0)) * view;
        let img = image(gl, &mut r, |r| r.draw_frame(gl, moved, proj, VIEWPORT));
        let fresh = r.last_frame_order().unwrap();
        if let Freshness::Stale { moved } = fresh {
            assert!(2.0 * moved <= 0.5, "stale by {moved}");
        }
        kinds.push(fresh);
        assert!(img.pixels.iter().any(|p| p[3] > 0.05));
    }
    r.destroy(gl);
}

#[test]
fn draw_frame_refuses_what_it_cannot_draw() {
    let Some(ctx) = current_context() else { return };
    let gl = ctx.gl();
    let (cloud, cam) = scene();
    let (view, proj) = (cam.gl_view(), cam.gl_projection());
    let mut r = SplatRenderer::new(gl).unwrap();
    let err = r.draw_frame(gl, view, proj, VIEWPORT).unwrap_err();
    assert!(matches!(err, GlError::NotUploaded), "{err}");
    r.upload(gl, &cloud).unwrap();
    for viewport in [[0, 0, 0, 10], [0, 0, 10, -1]] {
        let err = r.draw_frame(gl, view, proj, viewport).unwrap_err();
        assert!(
            matches!(err, GlError::Viewport(v) if v == viewport),
            "{err}"
        );
    }
    let mut nan = view;
    nan.w_axis.x = f32::NAN;
    let err = r.draw_frame(gl, nan, proj, VIEWPORT).unwrap_err();
    assert!(matches!(err, GlError::Matrix(_)), "{err}");
    let ortho = Mat4::from_diagonal(glam::Vec4::new(1.0, 1.0, -0.2, 1.0)); // orthographic
    let err = r.draw_frame(gl, view, ortho, VIEWPORT).unwrap_err();
    assert!(matches!(err, GlError::Matrix(_)), "{err}");
    r.destroy(gl);
    let err = r.draw_frame(gl, view, proj, VIEWPORT).unwrap_err();
    assert!(matches!(err, GlError::Destroyed(_)), "{err}");
    // A scene's renderer sorts its own clouds: its draw_frame has no cloud of its own.
    let mut s = SplatScene::new(gl).unwrap();
    s.upload(gl, &[(&cloud, Mat4::IDENTITY)]).unwrap();
    s.draw_with_matrices(gl, view, proj, VIEWPORT).unwrap();
    s.destroy(gl);
}

#[test]
fn stage_timing_reports_the_stages_each_path_ran_and_changes_no_pixel() {
    use splatgl::gl::StageTimes;
    let Some(ctx) = or_skip(HeadlessContext::with_api(GlApi::DesktopCore33), "context") else {
        return;
    };
    ctx.make_current().unwrap();
    let gl = ctx.gl();
    let (cloud, cam) = scene();
    let mut r = uploaded(gl, &cloud);
    let (view, proj) = (cam.gl_view(), cam.gl_projection());
    assert_eq!(r.stage_times(gl), None, "off by default");
    let untimed = image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
    r.set_stage_timing(gl, true).unwrap();
    let timed = image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
    assert_eq!(timed.pixels, untimed.pixels, "timing changed the image");
    // 3000 splats: the pre-pass path, all three stages.
    let t = r.stage_times(gl).unwrap();
    let ok = |v: Option<f64>| v.is_some_and(|ms| ms.is_finite() && ms >= 0.0);
    assert!(ok(t.prepass_ms) && ok(t.copy_ms) && ok(t.quads_ms), "{t:?}");
    assert!(t.quads_ms.unwrap() > 0.0, "{t:?}");
    // A few splats: the direct path, quads only.
    let few = synthetic::random_cloud(10, 1, 0.7, 3);
    r.upload(gl, &few).unwrap();
    image(gl, &mut r, |r| r.draw_frame(gl, view, proj, VIEWPORT));
    let t = r.stage_times(gl).unwrap();
    assert!(
        t.prepass_ms.is_none() && t.copy_ms.is_none() && ok(t.quads_ms),
        "{t:?}"
    );
    r.set_stage_timing(gl, false).unwrap();
    assert_eq!(r.stage_times(gl), None::<StageTimes>);
    r.destroy(gl);
}
