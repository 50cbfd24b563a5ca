//! GL backend vs the CPU reference on Mesa EGL / llvmpipe: scene families, SH degrees, colour
//! spaces, both targets, edge cases (near plane, image border, non-finite splats, orders), real
//! files. Helpers and the error bound: `crates/splatgl-testkit/src/gl.rs`.

use crate::common;
use common::gl::*;

#[test]
fn single_splats_many_anisotropies_and_rotations() {
    let Some(mut r) = headless() else { return };
    let c = look_at_fov_deg(Vec3::new(0.3, 0.4, 4.0), Vec3::ZERO, 50.0, 64, 64);
    let scales = [
        [0.4, 0.05, 0.05],
        [0.05, 0.5, 0.02],
        [0.25, 0.25, 0.25],
        [0.6, 0.02, 0.2],
        [0.01, 0.3, 0.3],
        // Needle: the oriented quad must still contain the whole 3σ ellipse.
        [1.5, 0.004, 0.004],
    ];
    let rotations = [
        Quat::IDENTITY,
        Quat::from_rotation_z(0.5),
        Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
        Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 1.2),
    ];
    let mut worst = f64::INFINITY;
    for (i, s) in scales.iter().enumerate() {
        for (j, q) in rotations.iter().enumerate() {
            let mut cloud = SplatCloud::new(0);
            cloud.push(
                [0.1, -0.1, 0.2],
                *s,
                q.to_array(),
                0.9,
                &sh_for([0.9, 0.4, 0.1], 0),
            );
            let sc = check(
                &format!("single s{i} q{j}"),
                &mut r,
                &cloud,
                &c,
                &HeadlessOptions {
                    background: [0.1, 0.2, 0.3],
                    ..Default::default()
                },
                MAX_ERR_SPARSE,
            );
            worst = worst.min(sc.psnr);
        }
    }
    eprintln!("[single] worst PSNR {worst:.2} dB");
}

#[test]
fn sh_degrees_0_to_3_from_several_views() {
    let Some(mut r) = headless() else { return };
    let mut cloud = synthetic::random_cloud(80, 3, 1.0, 7);
    // Stronger view dependence than random_cloud's ±0.3.
    for (k, c) in cloud.sh.iter_mut().enumerate() {
        if k % 16 != 0 {
            *c = c.map(|v| v * 2.0);
        }
    }
    for (v, eye) in [
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::new(3.0, 1.5, -2.0),
        Vec3::new(-1.0, -3.5, 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        let c = look_at_fov_deg(eye, Vec3::ZERO, 45.0, 64, 64);
        let mut prev: Option<Image> = None;
        for degree in 0..=3u8 {
            let opts = HeadlessOptions {
                sh_degree: Some(degree),
                ..Default::default()
            };
            check(
                &format!("sh view{v} deg{degree}"),
                &mut r,
                &cloud,
                &c,
                &opts,
                MAX_ERR_DENSE,
            );
            // The run-time degree really changes the colours.
            let img = r.render(&c, &opts).unwrap();
            if let Some(p) = &prev {
                assert!(
                    score(&img, p).max_rgb > 0.02,
                    "degree {degree} looks like {}",
                    degree - 1
                );
            }
            prev = Some(img);
        }
    }
}

#[test]
fn dense_random_cloud_both_targets() {
    let Some(mut r) = headless() else { return };
    let cloud = synthetic::random_cloud(4000, 1, 1.0, 42);
    let c = look_at_fov_deg(Vec3::new(2.0, 1.0, 3.0), Vec3::ZERO, 50.0, 96, 72);
    for opts in both_targets() {
        check("dense", &mut r, &cloud, &c, &opts, MAX_ERR_DENSE);
    }
}

#[test]
fn default_scene_both_targets() {
    let Some(mut r) = headless() else { return };
    let cloud = synthetic::default_scene();
    let c = synthetic::default_camera(96, 72);
    for mut opts in both_targets() {
        opts.background = [1.0, 1.0, 1.0];
        check("default scene", &mut r, &cloud, &c, &opts, MAX_ERR_DENSE);
    }
}

#[test]
fn splats_crossing_the_near_plane() {
    let Some(mut r) = headless() else { return };
    // Camera at the origin inside a cloud: means at every depth around the 0.2 cull depth,
    // large splats reaching behind the camera.
    let mut cloud = SplatCloud::new(0);
    let mut rng = Rng::new(3);
    for _ in 0..300 {
        let p = [
            rng.range(-0.6, 0.6),
            rng.range(-0.6, 0.6),
            rng.range(-0.3, 1.5),
        ];
        let s = [(); 3].map(|_| rng.range(0.02, 0.25));
        let rgb = [(); 3].map(|_| rng.range(0.1, 0.9));
        cloud.push(p, s, rng.quat(), rng.range(0.3, 1.0), &sh_for(rgb, 0));
    }
    let mut c = look_at_fov_deg(Vec3::ZERO, Vec3::Z, 70.0, 64, 64);
    c.near = 0.05;
    check(
        "near plane",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
    // A camera near larger than 0.2 moves the cull depth (max(0.2, near)).
    c.near = 0.5;
    check(
        "near plane 0.5",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
}

#[test]
fn splats_crossing_the_image_border_and_fov_clamp() {
    let Some(mut r) = headless() else { return };
    let mut cloud = SplatCloud::new(0);
    let mut rng = Rng::new(11);
    // Means on a ring around the view, from just inside to far outside the image, some large
    // enough that the 1.3·tan(fov) clamp of J matters.
    for k in 0..60 {
        let a = k as f32 * 0.37;
        let rad = 0.8 + 0.05 * k as f32;
        let p = [rad * a.cos(), rad * a.sin() * 0.75, 0.0];
        let s = [
            rng.range(0.05, 0.6),
            rng.range(0.05, 0.6),
            rng.range(0.05, 0.6),
        ];
        let rgb = [(); 3].map(|_| rng.range(0.1, 0.9));
        cloud.push(p, s, rng.quat(), 0.8, &sh_for(rgb, 0));
    }
    let mut c = look_at_fov_deg(Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO, 55.0, 80, 60);
    check(
        "border",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
    // Off-centre principal point.
    c.cx = 30.0;
    c.cy = 36.0;
    check(
        "border off-centre",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
}

#[test]
fn tiny_sub_pixel_splats() {
    let Some(mut r) = headless() else { return };
    let mut cloud = SplatCloud::new(0);
    let mut rng = Rng::new(5);
    for _ in 0..400 {
        let p = [
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ];
        let s = [(); 3].map(|_| rng.range(0.0005, 0.004));
        let rgb = [(); 3].map(|_| rng.range(0.3, 1.0));
        cloud.push(p, s, rng.quat(), 1.0, &sh_for(rgb, 0));
    }
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 45.0, 64, 64);
    check(
        "tiny",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_SPARSE,
    );
}

#[test]
fn lin_rec709_display_both_targets() {
    let Some(mut r) = headless() else { return };
    let mut cloud = synthetic::random_cloud(1500, 2, 1.0, 9);
    cloud.meta.color_space = splatgl::cloud::Known::Known(ColorSpace::LinRec709Display);
    let c = look_at_fov_deg(Vec3::new(-2.0, 1.5, 3.0), Vec3::ZERO, 50.0, 80, 64);
    for mut opts in both_targets() {
        opts.background = [0.2, 0.25, 0.3];
        check("lin_rec709", &mut r, &cloud, &c, &opts, MAX_ERR_DENSE);
    }
    // And it is really different from blending the stored values as sRGB.
    let lin = r.render(&c, &HeadlessOptions::default()).unwrap();
    let srgb = r
        .render(
            &c,
            &HeadlessOptions {
                color_space: Some(ColorSpace::SrgbRec709Display),
                ..Default::default()
            },
        )
        .unwrap();
    assert!(score(&lin, &srgb).max_rgb > 0.05);
}

#[test]
fn desktop_gl_330_core_matches_reference() {
    // The same GLSL files compiled as `#version 330 core` on a desktop GL 3.3 core context.
    let desktop = HeadlessContext::with_api(GlApi::DesktopCore33);
    let r = desktop.and_then(HeadlessRenderer::with_context);
    let Some(mut r) = or_skip(r, "desktop GL context failed") else {
        return;
    };
    eprintln!("{}", r.context().describe());
    assert!(!glow::HasContext::version(r.context().gl()).is_embedded);
    let mut cloud = synthetic::random_cloud(1500, 3, 1.0, 31);
    let c = look_at_fov_deg(Vec3::new(1.5, -1.0, 3.0), Vec3::ZERO, 50.0, 64, 48);
    for opts in both_targets() {
        check("desktop 330 core", &mut r, &cloud, &c, &opts, MAX_ERR_DENSE);
    }
    cloud.meta.color_space = splatgl::cloud::Known::Known(ColorSpace::LinRec709Display);
    for mut opts in both_targets() {
        opts.background = [0.3, 0.3, 0.3];
        check(
            "desktop 330 core lin",
            &mut r,
            &cloud,
            &c,
            &opts,
            MAX_ERR_DENSE,
        );
    }
}

#[test]
fn same_scene_twice_is_bit_identical() {
    let Some(mut r) = headless() else { return };
    let cloud = synthetic::random_cloud(2000, 3, 1.0, 1);
    let c = look_at_fov_deg(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, 50.0, 64, 48);
    for opts in both_targets() {
        r.upload(&cloud).unwrap();
        let a = r.render(&c, &opts).unwrap();
        let b = r.render(&c, &opts).unwrap();
        assert_eq!(a.to_rgba8(), b.to_rgba8());
        // A fresh context and upload gives the same bytes too.
        let mut r2 = headless().unwrap();
        r2.upload(&cloud).unwrap();
        let d = r2.render(&c, &opts).unwrap();
        assert_eq!(a.to_rgba8(), d.to_rgba8());
        r.context().make_current().unwrap();
    }
}

#[test]
fn a_render_does_not_depend_on_the_colour_space_of_the_one_before() {
    // The draw switches GL_FRAMEBUFFER_SRGB per colour space and leaves it so: the next
    // render's clear of an sRGB target must not inherit it.
    let cloud = synthetic::random_cloud(500, 1, 0.8, 2);
    let c = look_at_fov_deg(Vec3::new(0.5, 0.5, 3.0), Vec3::ZERO, 50.0, 48, 40);
    let bg = [0.3, 0.5, 0.7];
    let linear = HeadlessOptions {
        background: bg,
        color_space: Some(ColorSpace::LinRec709Display),
        ..Default::default()
    };
    let srgb = HeadlessOptions {
        color_space: Some(ColorSpace::SrgbRec709Display),
        ..linear
    };
    for api in [GlApi::Gles3, GlApi::DesktopCore33] {
        let Some(ctx) = or_skip(HeadlessContext::with_api(api), "context") else {
            return;
        };
        let mut r = HeadlessRenderer::with_context(ctx).unwrap();
        r.upload(&cloud).unwrap();
        let first = r.render(&c, &linear).unwrap();
        r.render(&c, &srgb).unwrap();
        let again = r.render(&c, &linear).unwrap();
        assert_eq!(first.to_rgba8(), again.to_rgba8(), "{api:?}");
    }
}

#[test]
fn rgba16f_resolve_is_closer_to_the_reference_than_rgba8() {
    let Some(mut r) = headless() else { return };
    // Many low-opacity layers: where 8-bit blending loses most.
    let mut cloud = synthetic::random_cloud(3000, 0, 0.6, 21);
    for o in &mut cloud.opacities {
        *o *= 0.15;
    }
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO, 50.0, 64, 64);
    let s8 = check(
        "low-alpha RGBA8",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
    let s16 = check(
        "low-alpha RGBA16F",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions {
            target: TargetKind::Rgba16fResolve,
            ..Default::default()
        },
        MAX_ERR_DENSE,
    );
    eprintln!(
        "[low-alpha] RGBA8 {:.2} dB / {:.2}/255 vs RGBA16F {:.2} dB / {:.2}/255",
        s8.psnr,
        s8.max_rgb * 255.0,
        s16.psnr,
        s16.max_rgb * 255.0
    );
    assert!(
        s16.psnr > s8.psnr,
        "float blending should be closer to the reference"
    );
}

#[test]
fn non_finite_splats_are_skipped_like_the_reference() {
    let Some(mut r) = headless() else { return };
    let mut cloud = synthetic::random_cloud(200, 1, 1.0, 77);
    let n = cloud.len();
    cloud.positions[3] = [f32::NAN, 0.0, 0.0];
    cloud.positions[5] = [0.0, f32::INFINITY, 0.0];
    cloud.scales[7] = [f32::INFINITY, 0.1, 0.1];
    cloud.scales[9] = [f32::NAN, 0.1, 0.1];
    cloud.opacities[11] = f32::NAN;
    cloud.opacities[13] = f32::INFINITY; // seen in real files: alpha = 0.99 on both backends
    cloud.rotations[15] = [0.0; 4]; // degenerate quaternion
    cloud.sh[17 * 4] = [f32::NAN, 0.0, 0.0];
    cloud.sh[19 * 4 + 1] = [f32::INFINITY; 3];
    assert_eq!(cloud.len(), n);
    let c = look_at_fov_deg(Vec3::new(0.5, 0.5, 3.0), Vec3::ZERO, 50.0, 64, 64);
    check(
        "non-finite",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
}

#[test]
fn empty_cloud_and_partial_orders() {
    let Some(mut r) = headless() else { return };
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 50.0, 32, 32);
    r.upload(&SplatCloud::new(0)).unwrap();
    let img = r
        .render(
            &c,
            &HeadlessOptions {
                background: [0.2, 0.4, 0.6],
                ..Default::default()
            },
        )
        .unwrap();
    let want = [0.2f32, 0.4, 0.6].map(|v| (v * 255.0).round() / 255.0);
    assert!(img.pixels.iter().all(|p| p[..3] == want && p[3] == 0.0));
    // An order longer than the cloud is an error, not a GPU read out of bounds.
    let cloud = synthetic::random_cloud(10, 0, 1.0, 2);
    r.upload(&cloud).unwrap();
    let err = r.render_with_order(&c, &HeadlessOptions::default(), &[0; 11]);
    assert!(matches!(
        err,
        Err(HeadlessError::Gl(splatgl::gl::GlError::OrderTooLong {
            got: 11,
            capacity: 10
        }))
    ));
    // A zero-sized camera gives an empty image, not an incomplete-framebuffer error.
    let mut z = c;
    z.width = 0;
    assert!(
        r.render(&z, &HeadlessOptions::default())
            .unwrap()
            .pixels
            .is_empty()
    );
    // Indices past the cloud are culled by the shader: the same image as without them.
    let order = splatgl::sort::Sorter::new()
        .sort_by_distance(&cloud.positions[..5], c.eye().to_array())
        .to_vec();
    let five = r
        .render_with_order(&c, &HeadlessOptions::default(), &order)
        .unwrap();
    let mut bad = order.clone();
    bad.extend([10, u32::MAX, 1_000_000, 15, 99]);
    let with_bad = r
        .render_with_order(&c, &HeadlessOptions::default(), &bad)
        .unwrap();
    assert_eq!(five, with_bad);
    // An empty order draws nothing.
    let img = r
        .render_with_order(&c, &HeadlessOptions::default(), &[])
        .unwrap();
    assert!(img.pixels.iter().all(|p| p[3] == 0.0));
}

#[test]
fn one_shot_render_function_matches_the_renderer() {
    // `splatgl::headless::render` is what a CLI `--backend gl` calls.
    let cloud = synthetic::default_scene();
    let c = synthetic::default_camera(48, 36);
    let opts = HeadlessOptions {
        background: [0.1, 0.1, 0.1],
        sh_degree: Some(3), // above the cloud's degree 1: clamped, like the reference
        ..Default::default()
    };
    let Some(img) = or_skip(splatgl::headless::render(&cloud, &c, &opts), "render") else {
        return;
    };
    assert_eq!((img.width, img.height), (48, 36));
    let mut r = headless().unwrap();
    r.upload(&cloud).unwrap();
    let again = r.render(&c, &opts).unwrap();
    assert_eq!(img.to_rgba8(), again.to_rgba8());
    let want = reference_image(&cloud, &c, 1, opts.background, false);
    let s = score(&img, &want);
    assert!(s.psnr >= MIN_PSNR, "{s:?}");
}

/// Every real file that loads renders through GL without a GL error (`glGetError` is checked
/// after the upload and after the draw) and within the suite's PSNR of the reference.
#[test]
fn real_files_render_without_gl_errors() {
    let Some(paths) = real_files() else { return };
    let Some(mut r) = headless() else { return };
    let mut rendered = 0;
    for path in paths {
        let Ok(l) = splatgl::load::load_path(&path, &Default::default()) else {
            continue;
        };
        let cloud = l.cloud;
        let c = common::frame_points(&cloud.positions, 0.9, 80, 60).expect("finite means");
        r.upload(&cloud)
            .unwrap_or_else(|e| panic!("{}: upload: {e}", path.display()));
        let img = r
            .render(&c, &HeadlessOptions::default())
            .unwrap_or_else(|e| panic!("{}: render: {e}", path.display()));
        assert!(
            img.pixels.iter().any(|p| p[3] > 0.05),
            "{}: nothing drawn",
            path.display()
        );
        let space = cloud.meta.color_space.effective();
        let want = reference::render_display(&cloud, &c, &ref_opts(3, [0.0; 3]), space).0;
        let s = score(&img, &want);
        eprintln!(
            "{}: {} splats, PSNR {:.2} dB vs reference",
            path.display(),
            cloud.len(),
            s.psnr
        );
        assert!(s.psnr >= MIN_PSNR, "{}: PSNR {:.2}", path.display(), s.psnr);
        rendered += 1;
    }
    assert!(rendered >= 3, "the real files that load must render");
}

/// No far cull in either backend (3DGS has none): splats beyond the camera's far plane are
/// drawn by GL exactly like by the reference, not clipped.
#[test]
fn splats_beyond_the_far_plane_are_drawn() {
    let Some(mut r) = headless() else { return };
    let mut cloud = synthetic::random_cloud(60, 0, 1.0, 4);
    for p in &mut cloud.positions {
        p[2] -= 40.0;
    }
    for s in &mut cloud.scales {
        *s = s.map(|v| v * 20.0);
    }
    let mut c = look_at_fov_deg(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::new(0.0, 0.0, -40.0),
        50.0,
        64,
        48,
    );
    c.far = 10.0;
    check(
        "beyond far",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
    let img = r.render(&c, &HeadlessOptions::default()).unwrap();
    assert!(
        img.pixels.iter().any(|p| p[3] > 0.1),
        "splats must be visible"
    );
}

/// Long needles whose 3σ major axis spans thousands of pixels while the minor axis is below a
/// pixel: Σ''s determinant must not lose its digits to f32 cancellation (spec: the kernel is
/// the same for every splat shape).
#[test]
fn long_thin_needles() {
    let Some(mut r) = headless() else { return };
    let mut cloud = SplatCloud::new(0);
    for k in 0..6 {
        let q = Quat::from_rotation_z(0.3 + 0.45 * k as f32) * Quat::from_rotation_x(0.2);
        let y = -0.06 + 0.024 * k as f32;
        cloud.push(
            [0.0, y, 0.0],
            [8.0 + 4.0 * k as f32, 0.0015, 0.0015],
            q.to_array(),
            0.9,
            &sh_for([0.9, 0.5 + 0.08 * k as f32, 0.2], 0),
        );
    }
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 8.0, 64, 48);
    check(
        "needles",
        &mut r,
        &cloud,
        &c,
        &HeadlessOptions::default(),
        MAX_ERR_DENSE,
    );
}

/// Renders `cloud` from `cam` by the former path (3σ quads, every splat, direct vertex stage)
/// and by each new one (opacity-aware quads; culled before the sort; direct or through the
/// transform-feedback pre-pass), both targets; returns, per new path, the pixels (RGBA8
/// channels) that differ from the former path's and the largest difference (in 1/255).
fn differences_from_the_former_path(
    [r, former_r]: [&mut HeadlessRenderer; 2],
    cloud: &SplatCloud,
    cam: &Camera,
) -> Vec<(&'static str, usize, f32)> {
    use splatgl::gl::{DrawPath, Pipeline};
    r.upload(cloud).unwrap();
    former_r.upload(cloud).unwrap();
    let direct = DrawPath {
        pipeline: Pipeline::Direct,
    };
    let mut out = Vec::new();
    for opts in both_targets() {
        former_r.set_path(direct, false).unwrap();
        let former = former_r.render(cam, &opts).unwrap();
        assert!(!former_r.renderer().last_draw_used_prepass());
        let covered = former.pixels.iter().filter(|p| p[3] > 0.1).count();
        out.push(("covered pixels", covered, 0.0));
        let prepass = DrawPath {
            pipeline: Pipeline::PrePass,
        };
        for (name, former_quads, path, cull) in [
            ("opacity-aware quads", false, direct, false),
            ("culled", true, direct, true),
            ("pre-pass", false, prepass, false),
            ("all (default)", false, DrawPath::default(), true),
        ] {
            let r = if former_quads {
                &mut *former_r
            } else {
                &mut *r
            };
            r.set_path(path, cull).unwrap();
            let img = r.render(cam, &opts).unwrap();
            let prepass = r.renderer().last_draw_used_prepass();
            match path.pipeline {
                Pipeline::Direct => assert!(!prepass, "{name}: drawn directly"),
                Pipeline::PrePass => assert!(prepass, "{name}: through the pre-pass"),
                _ => {}
            }
            let diff = former
                .pixels
                .iter()
                .flatten()
                .zip(img.pixels.iter().flatten())
                .map(|(a, b)| (a - b).abs() * 255.0)
                .filter(|d| *d > 0.0);
            let (n, max) = diff.fold((0, 0.0f32), |(n, m), d| (n + 1, m.max(d)));
            out.push((name, n, max));
        }
    }
    out
}

/// The opacity-aware quads, the cull before the sort and the pre-pass change no pixel of
/// the GL image of the real scenes (framed, and from inside with about half in view).
#[test]
fn new_draw_paths_leave_real_scenes_bit_identical() {
    let Some(scenes) = common::large_real_scenes() else {
        return;
    };
    let Some(mut r) = headless() else { return };
    let Some(mut former) = headless_with(splatgl::gl::Errata::FORMER_QUADS) else {
        return;
    };
    let (mut checked, mut covered_views) = (0, 0);
    for common::RealScene { name, cloud, views } in scenes {
        for (view, cam) in views {
            let diffs = differences_from_the_former_path([&mut r, &mut former], &cloud, &cam);
            eprintln!("{name} {view}: {diffs:?}");
            for (what, n, max) in diffs {
                if what == "covered pixels" {
                    covered_views += usize::from(n > 160 * 120 / 20);
                    continue;
                }
                assert_eq!(n, 0, "{name} {view} {what}: max {max}/255");
            }
        }
        checked += 1;
    }
    assert!(checked >= 3, "the real scenes must be there");
    assert!(
        covered_views >= 2 * checked,
        "most views show their scene: {covered_views}"
    );
}
