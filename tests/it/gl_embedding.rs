//! The renderer embedded in a host's GL context: the host's state survives every call (or is
//! left as `splatgl::gl::state` documents) in ES, desktop core and desktop compatibility
//! contexts; hostile inherited state does not change the splats; host matrices (reversed-Z
//! included) and the host's depth buffer; several clouds in one order; the two embedding
//! examples, rendered and checked by pixels.

use crate::common;
#[path = "../../examples/host/mod.rs"]
mod host;
#[path = "gl_embedding/host_state.rs"]
mod host_state;

use common::gl::*;
use glam::Mat4;
use glow::HasContext;
use host_state::{Host, Piece, pieces, query_all};
use splatgl::gl::state::{Contexts, LEFT_WITHOUT_RESTORE, Left, LeftValue};
use splatgl::gl::{
    ColorFormat, DepthFormat, DepthFunc, DrawPath, DrawSettings, PAGE_SPLATS, Pipeline,
    ReadbackTarget, SplatRenderer, SplatScene,
};

const APIS: [GlApi; 3] = [GlApi::Gles3, GlApi::DesktopCore33, GlApi::DesktopCompat];

/// The host error left pending in each context (one of each kind splatgl raises again).
fn host_error(api: GlApi) -> u32 {
    match api {
        GlApi::Gles3 => glow::INVALID_OPERATION,
        GlApi::DesktopCore33 => glow::INVALID_VALUE,
        _ => glow::INVALID_ENUM,
    }
}

/// Leaves `code` pending with a call that changes nothing.
fn raise_host_error(gl: &glow::Context, code: u32) {
    // SAFETY: invalid calls GL rejects without any effect.
    unsafe {
        match code {
            glow::INVALID_OPERATION => {
                gl.bind_vertex_array(Some(host_state::ungenerated_vertex_array()))
            }
            glow::INVALID_VALUE => gl.line_width(-1.0),
            _ => gl.enable(0xDEAD),
        }
    }
}

/// Every call of the renderer and the scene, in `settings`' mode.
fn every_call(gl: &glow::Context, settings: DrawSettings) {
    let cloud = synthetic::random_cloud(40, 3, 0.8, 7);
    let other = synthetic::random_cloud(30, 1, 0.6, 8);
    let cam = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 50.0, 50, 60);
    let order: Vec<u32> = (0..40).rev().collect();
    let mut r = SplatRenderer::new(gl).unwrap();
    *r.settings_mut() = settings;
    r.upload(gl, &cloud).unwrap();
    r.set_order(gl, &order).unwrap();
    r.draw_current(gl, &cam).unwrap();
    let (view, proj) = (cam.gl_view(), cam.gl_projection());
    r.draw_with_matrices(gl, view, proj, [3, 4, 50, 60], &order)
        .unwrap();
    r.draw_frame(gl, view, proj, [3, 4, 50, 60]).unwrap();
    // The same through the transform-feedback pre-pass (its program, vertex arrays,
    // transform-feedback object and rasterizer discard), created after the upload.
    r.set_draw_path(gl, prepass()).unwrap();
    r.draw_current(gl, &cam).unwrap();
    assert!(r.last_draw_used_prepass());
    r.draw_with_matrices(gl, view, proj, [3, 4, 50, 60], &order)
        .unwrap();
    // Paged storage (streamed tilesets): allocated, a page written, drawn by slots.
    r.allocate_pages(gl, 2, 3, Default::default()).unwrap();
    r.write_page(gl, 1, &cloud, 0).unwrap();
    let slots: Vec<u32> = order.iter().map(|i| i + PAGE_SPLATS as u32).collect();
    r.draw_with_matrices(gl, view, proj, [3, 4, 50, 60], &slots)
        .unwrap();
    r.destroy(gl);
    for path in [DrawPath::default(), prepass()] {
        let mut s = SplatScene::new(gl).unwrap();
        *s.settings_mut() = settings;
        s.set_draw_path(gl, path).unwrap();
        let model = Mat4::from_rotation_y(0.5) * Mat4::from_scale(Vec3::new(1.0, 1.5, 0.7));
        s.upload(gl, &[(&cloud, Mat4::IDENTITY), (&other, model)])
            .unwrap();
        s.draw(gl, &cam).unwrap();
        assert_eq!(s.renderer().last_draw_used_prepass(), path == prepass());
        s.destroy(gl);
    }
}

/// The draw path that always runs the transform-feedback pre-pass.
fn prepass() -> DrawPath {
    DrawPath {
        pipeline: Pipeline::PrePass,
    }
}

/// What `piece` must read after the calls without restore: the documented value where
/// `LEFT_WITHOUT_RESTORE` lists it, else the host's.
fn expected_without_restore(p: &Piece, host: &Host, before: &[f64], s: &DrawSettings) -> Vec<f64> {
    let exists = |l: &Left| match l.contexts {
        Contexts::All => true,
        Contexts::Desktop => host.api != GlApi::Gles3,
        Contexts::Compatibility => host.api == GlApi::DesktopCompat,
        Contexts::SrgbSwitch => host.srgb_switch,
        // ES 3.x and desktop GL ≥ 4.0: every context Mesa gives.
        Contexts::TransformFeedbackObjects => true,
        _ => unreachable!(),
    };
    let Some(l) = LEFT_WITHOUT_RESTORE
        .iter()
        .find(|l| exists(l) && l.pname == p.pname && l.unit == p.unit)
    else {
        return before.to_vec();
    };
    let b = |v: bool| f64::from(u8::from(v));
    let one = match l.value {
        LeftValue::Zero => 0.0,
        LeftValue::Enum(e, _) => e as f64,
        LeftValue::Enabled(v) | LeftValue::Bool(v) => b(v),
        LeftValue::AllChannels => 1.0,
        LeftValue::DepthTestSetting => b(s.depth_test),
        LeftValue::DepthFuncSetting if s.depth_test => s.depth_func.gl_enum() as f64,
        LeftValue::DepthFuncSetting => return before.to_vec(),
        LeftValue::LinearColorSpace => 0.0, // the clouds drawn are srgb_rec709_display
        _ => unreachable!(),
    };
    vec![one; before.len()]
}

/// Sets the host's state in a context of `api`, runs every call of the renderer and reads
/// every piece back: identical with `restore_state`, else as documented.
fn state_survives(api: GlApi, restore: bool) {
    let Some(ctx) = or_skip(HeadlessContext::with_api(api), "context") else {
        return;
    };
    let host = Host::new(&ctx, api);
    let pieces = pieces(&host);
    // The host's values must differ from a fresh context's, or the test proves nothing.
    let fresh = {
        let other = HeadlessContext::with_api(api).unwrap();
        query_all(other.gl(), &host.lgl, &pieces)
    };
    ctx.make_current().unwrap();
    let gl = ctx.gl();
    host.apply(&pieces);
    // SAFETY: glGetError.
    assert_eq!(unsafe { gl.get_error() }, glow::NO_ERROR, "host set-up");
    let before = query_all(gl, &host.lgl, &pieces);
    let distinct = pieces.iter().zip(&before).zip(&fresh);
    for ((p, b), f) in distinct.clone() {
        assert!(
            !p.distinct || b != f,
            "{api:?}: {} is not distinctive ({b:?})",
            p.name
        );
    }
    let count = distinct.filter(|((p, _), _)| p.distinct).count();
    eprintln!(
        "{api:?}: {count} distinctive pieces of host state ({} checked)",
        pieces.len()
    );
    assert!(count >= 60, "{count} pieces");

    if restore {
        raise_host_error(gl, host_error(api));
    }
    let settings = DrawSettings {
        restore_state: restore,
        ..DrawSettings::default()
    };
    every_call(gl, settings);
    // SAFETY: glGetError.
    let errors = unsafe { [gl.get_error(), gl.get_error()] };
    let pending = if restore {
        host_error(api)
    } else {
        glow::NO_ERROR
    };
    assert_eq!(
        errors,
        [pending, glow::NO_ERROR],
        "{api:?}: glGetError after the calls"
    );

    let mut after = query_all(gl, &host.lgl, &pieces);
    if !restore {
        // The VAO binding is left 0 (documented): the host's own VAO must be untouched.
        host.bind_vao();
        for (p, a) in pieces.iter().zip(&mut after) {
            if p.vao_state {
                *a = host_state::query(gl, &host.lgl, p);
            }
        }
        for l in LEFT_WITHOUT_RESTORE {
            let covered = pieces
                .iter()
                .any(|p| p.pname == l.pname && p.unit == l.unit);
            let exists = match l.contexts {
                Contexts::Desktop => api != GlApi::Gles3,
                Contexts::Compatibility => api == GlApi::DesktopCompat,
                Contexts::SrgbSwitch => host.srgb_switch,
                _ => true,
            };
            assert!(
                covered || !exists,
                "{api:?}: {} not in the host's pieces",
                l.name
            );
        }
    }
    let mut wrong = Vec::new();
    for ((p, b), a) in pieces.iter().zip(&before).zip(&after) {
        let want = if restore {
            b.clone()
        } else {
            expected_without_restore(p, &host, b, &settings)
        };
        if *a != want {
            wrong.push(format!(
                "{}{:?}: {a:?}, expected {want:?} (host {b:?})",
                p.name, p.unit
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{api:?} restore {restore}:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn restore_mode_puts_back_every_piece_of_host_state_and_its_pending_error() {
    for api in APIS {
        state_survives(api, true);
    }
}

#[test]
fn without_restore_host_state_is_left_exactly_as_documented() {
    for api in APIS {
        state_survives(api, false);
    }
}

/// Renders the uploaded `cloud` for `cam` into `target` (cleared to transparent black), after
/// `hostile` sets state of the host's; returns the image.
fn render_with(
    gl: &glow::Context,
    target: &ReadbackTarget,
    (r, cloud): (&mut SplatRenderer, &SplatCloud),
    cam: &Camera,
    hostile: impl Fn(),
) -> Image {
    let order = splatgl::sort::Sorter::new()
        .sort_by_distance(&cloud.positions, cam.eye().to_array())
        .to_vec();
    target.bind(gl).unwrap();
    // SAFETY: a clear of the bound target.
    unsafe {
        gl.clear_color(0.0, 0.0, 0.0, 0.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
    hostile();
    r.draw(gl, cam, &order).unwrap();
    target.read_image(gl).unwrap()
}

#[test]
fn hostile_inherited_state_does_not_change_the_splats() {
    let Some(ctx) = or_skip(HeadlessContext::with_api(GlApi::DesktopCompat), "context") else {
        return;
    };
    let gl = ctx.gl();
    let lgl = host::legacy_gl::LegacyGl::load(|n| ctx.get_proc_address(n)).unwrap();
    let cloud = synthetic::random_cloud(300, 2, 0.8, 21);
    let cam = look_at_fov_deg(Vec3::new(0.3, 0.2, 3.0), Vec3::ZERO, 50.0, 64, 64);
    // An sRGB target: a host's GL_FRAMEBUFFER_SRGB would re-encode srgb_rec709 colours.
    let target = ReadbackTarget::new(gl, 64, 64, ColorFormat::Srgb8Alpha8, None).unwrap();
    // SAFETY: a transform-feedback object of the host's (bound, never active).
    let host_tf = unsafe { gl.create_transform_feedback().unwrap() };
    let mut first_clean: Option<Image> = None;
    let runs = [false, true].map(|restore| (restore, DrawPath::default()));
    for (restore, path) in runs
        .into_iter()
        .chain([(false, prepass()), (true, prepass())])
    {
        let mut r = SplatRenderer::new(gl).unwrap();
        r.settings_mut().restore_state = restore;
        r.set_draw_path(gl, path).unwrap();
        r.upload(gl, &cloud).unwrap();
        let clean = render_with(gl, &target, (&mut r, &cloud), &cam, || {});
        // SAFETY: host state changes with valid enums of a compatibility context.
        let hostile = render_with(gl, &target, (&mut r, &cloud), &cam, || unsafe {
            gl.color_mask(false, false, false, false);
            gl.polygon_mode(glow::FRONT_AND_BACK, glow::LINE);
            gl.enable(glow::COLOR_LOGIC_OP);
            (lgl.logic_op)(host::legacy_gl::XOR);
            gl.enable(glow::RASTERIZER_DISCARD);
            gl.enable(host::legacy_gl::ALPHA_TEST);
            (lgl.alpha_func)(glow::GREATER, 0.99);
            gl.enable(glow::POLYGON_OFFSET_FILL);
            gl.polygon_offset(4.0, 4.0);
            gl.enable(glow::CULL_FACE);
            gl.cull_face(glow::FRONT_AND_BACK);
            gl.enable(glow::SAMPLE_ALPHA_TO_COVERAGE);
            gl.enable(glow::FRAMEBUFFER_SRGB);
            gl.enable(glow::DEPTH_TEST); // no depth buffer: always passes
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(host_tf));
        });
        assert_eq!(r.last_draw_used_prepass(), path == prepass());
        // SAFETY: back to the defaults for the next clear.
        unsafe {
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, None);
            gl.color_mask(true, true, true, true);
            gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
            for cap in [
                glow::COLOR_LOGIC_OP,
                glow::RASTERIZER_DISCARD,
                host::legacy_gl::ALPHA_TEST,
                glow::POLYGON_OFFSET_FILL,
                glow::CULL_FACE,
                glow::SAMPLE_ALPHA_TO_COVERAGE,
                glow::FRAMEBUFFER_SRGB,
                glow::DEPTH_TEST,
            ] {
                gl.disable(cap);
            }
        }
        let covered = clean.pixels.iter().filter(|p| p[3] > 0.1).count();
        assert!(
            covered > 500,
            "the clean render shows splats ({covered} px)"
        );
        assert!(
            clean == hostile,
            "restore {restore}, {path:?}: hostile state changed the splats"
        );
        let first = first_clean.get_or_insert_with(|| clean.clone());
        assert!(
            *first == clean,
            "{path:?}: the pre-pass draws the same image"
        );
        r.destroy(gl);
    }
    // SAFETY: deleting the host's object created above.
    unsafe { gl.delete_transform_feedback(host_tf) };
}

#[test]
fn host_depth_buffer_and_viewport_are_respected() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    let (w, h) = (32u32, 32u32);
    // The "host": an RGBA8 + DEPTH24 framebuffer with a viewport offset inside a larger one.
    let mut host =
        ReadbackTarget::new(gl, 2 * w, h, ColorFormat::Rgba8, Some(DepthFormat::Depth24)).unwrap();
    host.bind(gl).unwrap();
    let mut cloud = SplatCloud::new(0);
    cloud.push(
        [0.0; 3],
        [0.3; 3],
        [0.0, 0.0, 0.0, 1.0],
        0.95,
        &sh_for([1.0; 3], 0),
    );
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 50.0, w, h);
    let mut renderer = SplatRenderer::new(gl).unwrap();
    renderer.upload(gl, &cloud).unwrap();
    let order = [0u32];
    // Right half of the framebuffer is the host's viewport for the splats.
    let mut centre_red = |depth_clear: f32, depth_test: bool| -> u8 {
        // SAFETY: clears the bound framebuffer.
        unsafe {
            gl.viewport(0, 0, 2 * w as i32, h as i32);
            gl.depth_mask(true);
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.clear_depth_f32(depth_clear);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            gl.viewport(w as i32, 0, w as i32, h as i32);
        }
        renderer.settings_mut().depth_test = depth_test;
        renderer.draw(gl, &c, &order).unwrap();
        let px = host.read_image(gl).unwrap().get(w + w / 2, h - 1 - h / 2);
        (px[0] * 255.0).round() as u8
    };
    assert!(centre_red(0.0, false) > 200, "drawn without depth test");
    assert!(centre_red(1.0, true) > 200, "host depth far: splat passes");
    assert_eq!(
        centre_red(0.0, true),
        0,
        "host geometry in front: splat hidden"
    );
    // The left half (outside the viewport) stays untouched.
    assert_eq!(host.read_image(gl).unwrap().get(w / 2, h / 2), [0.0; 4]);
    renderer.destroy(gl);
    host.destroy(gl);
    // A destroyed renderer refuses to draw instead of touching deleted objects.
    assert!(matches!(
        renderer.draw(gl, &c, &order),
        Err(splatgl::gl::GlError::Destroyed("SplatRenderer"))
    ));
}

#[test]
fn shader_errors_carry_log_and_numbered_source() {
    let Some(r) = headless() else { return };
    let gl = r.context().gl();
    let vs = "#version 300 es\nvoid main() {\n  gl_Position = vec4(0.0);\n}\n";
    let fs = "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() {\n  o = undefined_thing;\n}\n";
    let err = splatgl::gl::build_program(gl, "broken", vs, fs).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, splatgl::gl::GlError::Compile { .. }), "{msg}");
    assert!(msg.contains("undefined_thing"), "{msg}");
    assert!(msg.contains("   5 |   o = undefined_thing;"), "{msg}");
}

/// A plane of near-opaque white splats at z = 0 covering the whole view of the host cameras.
fn splat_wall() -> SplatCloud {
    let mut cloud = SplatCloud::new(0);
    for i in -35..=35 {
        for j in -35..=35 {
            let p = [i as f32 * 0.1, j as f32 * 0.1, 0.0];
            cloud.push(
                p,
                [0.07, 0.07, 0.01],
                [0.0, 0.0, 0.0, 1.0],
                0.9,
                &sh_for([0.95; 3], 0),
            );
        }
    }
    cloud
}

#[test]
fn reversed_z_host_occludes_splats_exactly_where_its_geometry_is_in_front() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    let (w, h) = (64u32, 48u32);
    let window =
        ReadbackTarget::new(gl, w, h, ColorFormat::Rgba8, Some(DepthFormat::Depth24)).unwrap();
    window.bind(gl).unwrap();
    let host = host::modern::ModernHost::new(gl).unwrap();
    let cam = host::modern::camera(w, h);
    let view = cam.gl_view();
    // Reversed-Z, infinite far, GL's [-1, 1] depth: z_ndc = 2n/d - 1 (+1 at the near plane).
    let near = 0.1;
    let mut reversed = cam.gl_projection();
    reversed.z_axis.z = 1.0;
    reversed.w_axis.z = 2.0 * near;
    let front = host::modern::cube_model(); // between the camera and the wall
    let back =
        Mat4::from_translation(Vec3::new(-0.6, -0.2, -1.5)) * Mat4::from_scale(Vec3::splat(1.2));
    let cloud = splat_wall();
    let order = splatgl::sort::Sorter::new()
        .sort_by_distance(&cloud.positions, cam.eye().to_array())
        .to_vec();
    let mut r = SplatRenderer::new(gl).unwrap();
    r.upload(gl, &cloud).unwrap();
    r.settings_mut().restore_state = true;
    let viewport = [0, 0, w as i32, h as i32];
    // One frame: both cubes, then (optionally) the splats, with the host's depth convention.
    let mut frame = |proj: Mat4, reversed_z: bool, splats: bool, cubes: &[Mat4]| -> Image {
        // SAFETY: the host's depth convention and clear.
        unsafe {
            gl.clear_depth_f32(if reversed_z { 0.0 } else { 1.0 });
            gl.depth_func(if reversed_z {
                glow::GREATER
            } else {
                glow::LESS
            });
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        for m in cubes {
            host.draw_cube(gl, proj * view * *m);
        }
        if splats {
            r.settings_mut().depth_func = if reversed_z {
                DepthFunc::Greater
            } else {
                DepthFunc::Less
            };
            r.draw_with_matrices(gl, view, proj, viewport, &order)
                .unwrap();
        }
        window.read_image(gl).unwrap()
    };
    let front_only = frame(reversed, true, false, &[front]);
    let cubes_only = frame(reversed, true, false, &[front, back]);
    let with_splats = frame(reversed, true, true, &[front, back]);
    let standard = frame(cam.gl_projection(), false, true, &[front, back]);
    let clear = host::modern::CLEAR;
    let is_front = |p: [f32; 4]| (0..3).any(|c| (p[c] - clear[c]).abs() > 0.01);
    let (mut front_px, mut behind_px) = (0, 0);
    for (k, px) in with_splats.pixels.iter().enumerate() {
        if is_front(front_only.pixels[k]) {
            // The front cube hides the splats: its pixels are untouched.
            assert_eq!(
                *px, cubes_only.pixels[k],
                "pixel {k} in front of the splats"
            );
            front_px += 1;
        } else {
            // Everywhere else the wall of splats is in front (of the back cube too).
            assert_ne!(*px, cubes_only.pixels[k], "pixel {k} behind the splats");
            behind_px += 1;
        }
    }
    assert!(
        front_px > 200 && behind_px > 1000,
        "{front_px} / {behind_px}"
    );
    // Reversed-Z with GREATER gives the same image as the standard projection with LESS.
    assert!(
        with_splats == standard,
        "reversed-Z and standard depth differ"
    );
    r.destroy(gl);
    host.destroy(gl);
}

#[test]
fn draw_with_a_cameras_matrices_equals_draw_with_the_camera() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    let cloud = synthetic::random_cloud(400, 3, 0.8, 5);
    let mut r = SplatRenderer::new(gl).unwrap();
    r.upload(gl, &cloud).unwrap();
    r.settings_mut().depth_test = false;
    let mut cam = look_at_fov_deg(Vec3::new(0.4, 0.3, 2.8), Vec3::ZERO, 55.0, 64, 48);
    cam.cx = 30.0; // off-centre principal point
    let target = ReadbackTarget::new(gl, 96, 48, ColorFormat::Rgba8, None).unwrap();
    let order = splatgl::sort::Sorter::new()
        .sort_by_distance(&cloud.positions, cam.eye().to_array())
        .to_vec();
    let mut draw = |viewport: [i32; 4], f: &mut dyn FnMut(&mut SplatRenderer)| -> Image {
        target.bind(gl).unwrap();
        // SAFETY: clear and viewport of the bound target.
        unsafe {
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.clear(glow::COLOR_BUFFER_BIT);
            gl.viewport(viewport[0], viewport[1], viewport[2], viewport[3]);
        }
        f(&mut r);
        target.read_image(gl).unwrap()
    };
    let vp = [0, 0, 64, 48];
    let by_camera = draw(vp, &mut |r| r.draw(gl, &cam, &order).unwrap());
    let (view, proj) = (cam.gl_view(), cam.gl_projection());
    let by_matrices = draw(vp, &mut |r| {
        r.draw_with_matrices(gl, view, proj, vp, &order).unwrap()
    });
    assert!(by_camera.pixels.iter().filter(|p| p[3] > 0.1).count() > 300);
    assert!(by_camera == by_matrices, "camera and its matrices differ");

    // A camera of another aspect than the viewport keeps its vertical fov and square pixels:
    // the same as a camera made for the viewport's size (principal point centred too).
    let wide_vp = [0, 0, 96, 48];
    let mut centred = cam;
    centred.cx = 32.0;
    let fitted = draw(wide_vp, &mut |r| r.draw(gl, &centred, &order).unwrap());
    let made_wide = look_at_fov_deg(Vec3::new(0.4, 0.3, 2.8), Vec3::ZERO, 55.0, 96, 48);
    let direct = draw(wide_vp, &mut |r| r.draw(gl, &made_wide, &order).unwrap());
    assert!(
        fitted == direct,
        "camera fitted to a wider viewport is squashed"
    );
    r.destroy(gl);
}

/// Renders a scene's clouds through `draw` into a fresh RGBA16F target cleared to `bg`, as
/// displayed (clamped to [0, 1], as `score` clamps the reference).
fn render_scene(gl: &glow::Context, cam: &Camera, bg: [f32; 3], draw: &mut dyn FnMut()) -> Image {
    let target =
        ReadbackTarget::new(gl, cam.width, cam.height, ColorFormat::Rgba16f, None).unwrap();
    target.bind(gl).unwrap();
    // SAFETY: clear of the bound target.
    unsafe {
        gl.clear_color(bg[0], bg[1], bg[2], 0.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
    draw();
    let mut image = target.read_image(gl).unwrap();
    for p in &mut image.pixels {
        *p = p.map(|v| v.clamp(0.0, 1.0));
    }
    let mut target = target;
    target.destroy(gl);
    image
}

/// `cloud` under `model`, placed by the glTF loader's node-transform code.
fn place(cloud: &SplatCloud, model: Mat4) -> SplatCloud {
    splatgl::load::gltf::apply_node_transform(cloud, model.as_dmat4(), 0, &mut Vec::new())
        .expect("finite")
}

#[test]
fn interleaved_clouds_render_like_the_merged_cloud_through_the_reference() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    // Two clouds in the same volume (their splats interleave in depth), SH degree 3, placed by
    // a similarity and by a non-uniform scale with rotation and translation.
    let a = synthetic::random_cloud(700, 3, 0.7, 31);
    let b = synthetic::random_cloud(700, 3, 0.7, 32);
    let ma = Mat4::from_translation(Vec3::new(-0.15, 0.05, 0.1))
        * Mat4::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9)
        * Mat4::from_scale(Vec3::splat(1.1));
    let mb = |t: f32| {
        Mat4::from_translation(Vec3::new(0.2, -0.1, -0.05 + t))
            * Mat4::from_rotation_y(-0.6 + t)
            * Mat4::from_scale(Vec3::new(1.3, 0.8, 1.0))
    };
    let cam = look_at_fov_deg(Vec3::new(0.5, 0.6, 3.2), Vec3::ZERO, 50.0, 80, 64);
    let bg = [0.05, 0.05, 0.08];
    let merged = |mb: Mat4| {
        let mut m = place(&a, ma);
        let tb = place(&b, mb);
        m.append(tb);
        m
    };
    let mut scene = SplatScene::new(gl).unwrap();
    scene.settings_mut().depth_test = false;
    scene.upload(gl, &[(&a, ma), (&b, mb(0.0))]).unwrap();
    for t in [0.0, 0.3] {
        scene.set_model(1, mb(t)).unwrap();
        let got = render_scene(gl, &cam, bg, &mut || scene.draw(gl, &cam).unwrap());
        let want = reference_image(&merged(mb(t)), &cam, 3, bg, false);
        let s = score(&got, &want);
        eprintln!(
            "[two interleaved clouds, t = {t}] PSNR {:.2} dB, max err {:.2}/255",
            s.psnr,
            s.max_rgb * 255.0
        );
        assert!(s.psnr >= MIN_PSNR, "PSNR {:.2}", s.psnr);
    }
    // Drawn one after the other, each sorted on its own, the same clouds blend in the wrong
    // order: the common order is what makes the match.
    let mut r = SplatRenderer::new(gl).unwrap();
    r.settings_mut().depth_test = false;
    let separate = render_scene(gl, &cam, bg, &mut || {
        for (cloud, model) in [(&a, ma), (&b, mb(0.3))] {
            let placed = place(cloud, model);
            r.upload(gl, &placed).unwrap();
            let order = splatgl::sort::Sorter::new()
                .sort_by_distance(&placed.positions, cam.eye().to_array())
                .to_vec();
            r.draw(gl, &cam, &order).unwrap();
        }
    });
    let s = score(
        &separate,
        &reference_image(&merged(mb(0.3)), &cam, 3, bg, false),
    );
    eprintln!("[two clouds drawn separately] PSNR {:.2} dB", s.psnr);
    assert!(
        s.psnr < MIN_PSNR - 5.0,
        "separate draws should not match ({:.2} dB)",
        s.psnr
    );
    r.destroy(gl);
    scene.destroy(gl);
}

#[test]
fn modern_host_example_occludes_splats_and_its_next_frame_is_bit_identical() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let (w, h) = (96, 72);
    let frames = host::modern::run(&ctx, &splat_wall(), 2, w, h).unwrap();
    assert!(
        frames.host_only_after == frames.host_only_before,
        "host frame changed by splatgl"
    );
    let clear = host::modern::CLEAR;
    let is_cube = |p: [f32; 4]| (0..3).any(|c| (p[c] - clear[c]).abs() > 0.01);
    for image in &frames.with_splats {
        let (mut cube, mut splats) = (0, 0);
        for (k, px) in image.pixels.iter().enumerate() {
            let host_px = frames.host_only_before.pixels[k];
            if is_cube(host_px) {
                assert_eq!(*px, host_px, "cube pixel {k}: splats must be occluded");
                cube += 1;
            } else {
                assert_ne!(*px, host_px, "background pixel {k}: splats in front");
                splats += 1;
            }
        }
        assert!(cube > 300 && splats > 2000, "{cube} / {splats}");
    }
    assert!(frames.with_splats[1] == frames.with_splats[0]);
}

#[test]
fn legacy_host_example_keeps_its_texture_arrays_and_vbo_frame_after_frame() {
    let Some(ctx) = or_skip(HeadlessContext::with_api(GlApi::DesktopCompat), "context") else {
        return;
    };
    let (w, h) = (96, 72);
    // Splats well above the ground, so the ground's lower rows stay free of them.
    let mut cloud = synthetic::random_cloud(300, 1, 0.5, 41);
    for p in &mut cloud.positions {
        p[1] += 0.6;
    }
    let (without, frames) = host::legacy::run(&ctx, &cloud, 3, w, h).unwrap();
    let checker = host::legacy::CHECKER.map(|c| c.map(|v| v as f32 / 255.0));
    let bottom_row = (0..w).map(|x| without.get(x, h - 1));
    // The ground is textured (only checker colours in its bottom row, both of them).
    let colours: Vec<[f32; 4]> = bottom_row.collect();
    for c in &checker {
        assert!(
            colours.contains(c),
            "checker colour {c:?} missing from the ground"
        );
    }
    assert!(
        colours.iter().all(|p| checker.contains(p)),
        "untextured ground pixels"
    );
    let cube_px = without.get(w / 2 + 8, h / 2 + 4);
    assert!(
        cube_px[0] > 0.5 && cube_px[2] < 0.3,
        "the cube is there: {cube_px:?}"
    );
    for (k, f) in frames.iter().enumerate() {
        // Ground and cube as in the frame without splats (splats are above and behind the
        // cube); splats over the sky.
        for x in 0..w {
            assert_eq!(
                f.get(x, h - 1),
                without.get(x, h - 1),
                "frame {k} ground x {x}"
            );
        }
        assert_eq!(f.get(w / 2 + 8, h / 2 + 4), cube_px, "frame {k} cube");
        let changed = (f.pixels.iter().zip(&without.pixels))
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed > 300, "frame {k}: splats drawn ({changed} px)");
        assert!(*f == frames[0], "frame {k} differs from frame 0");
    }
}
