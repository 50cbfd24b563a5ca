//! The antialiased kernel (`--antialiased`, `DrawSettings::antialiased`,
//! `RenderOptions::antialiased`): opacity × √(det Σ' / det(Σ' + 0.3 I)). The reference matches
//! an independent f64 evaluation of the formula; GL matches the reference with it on real
//! scenes as with the plain kernel; the compensation really changes the image; and `auto`
//! follows the file's SPZ flag.

use crate::common;

use common::gl::*;
use glam::{DMat3, DQuat, DVec3};
use splatgl::reference::RenderOptions;

/// Σ' (before dilation) of a splat on the optical axis of a camera looking down its axis, in
/// f64, written out directly: J W Σ Wᵀ Jᵀ with J = diag(f/z, f/z) on the axis.
fn screen_cov(cam: &Camera, scale: [f32; 3], rot: [f32; 4], z: f64) -> [f64; 3] {
    let r = DMat3::from_quat(DQuat::from_array(rot.map(f64::from)).normalize());
    let s = DMat3::from_diagonal(DVec3::from_array(scale.map(f64::from)));
    let sigma = r * s * s.transpose() * r.transpose();
    let w = DMat3::from_mat4(cam.world_to_camera.as_dmat4());
    let v = w * sigma * w.transpose();
    let (fx, fy) = (cam.fx as f64 / z, cam.fy as f64 / z);
    [
        fx * fx * v.x_axis.x,
        fx * fy * v.y_axis.x,
        fy * fy * v.y_axis.y,
    ]
}

#[test]
fn reference_compensation_matches_an_independent_f64_formula() {
    let mut rng = Rng::new(41);
    let mut checked = 0;
    for k in 0..40 {
        // One white splat at the origin, seen from z = 4 by a 33×33 camera whose centre pixel
        // is on the axis: that pixel's alpha is the (compensated) opacity itself.
        let cam = look_at_fov_deg(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0, 33, 33);
        let size = 10f32.powf(rng.range(-2.3, -0.7)); // σ of 0.2 to 9 pixels
        let scale = [size, size * rng.range(0.2, 1.0), size * rng.range(0.2, 1.0)];
        let q = Quat::from_euler(
            glam::EulerRot::XYZ,
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        );
        let rot = q.to_array();
        let opacity = rng.range(0.3, 0.95);
        let mut cloud = SplatCloud::new(0);
        cloud.push([0.0; 3], scale, rot, opacity, &sh_for([1.0, 1.0, 1.0], 0));
        let [a, b, c] = screen_cov(&cam, scale, rot, 4.0);
        let d = splatgl::profile::DILATION_PX2;
        let factor = ((a * c - b * b) / ((a + d) * (c + d) - b * b))
            .max(0.0)
            .sqrt();
        let want = (f64::from(opacity) * factor).min(f64::from(splatgl::profile::ALPHA_MAX));
        let opts = RenderOptions {
            sh_degree: 0,
            antialiased: true,
            ..Default::default()
        };
        let img = reference::render(&cloud, &cam, &opts);
        let got = f64::from(img.pixels[16 * 33 + 16][3]);
        if want < f64::from(splatgl::profile::ALPHA_MIN) {
            assert_eq!(
                got, 0.0,
                "case {k}: below the α threshold, nothing is drawn"
            );
            continue;
        }
        assert!(
            (got - want).abs() <= 2e-6,
            "case {k}: scale {scale:?}: alpha {got}, formula {want} (factor {factor})"
        );
        // The plain kernel draws the opacity itself.
        let plain = reference::render(
            &cloud,
            &cam,
            &RenderOptions {
                sh_degree: 0,
                ..opts_off()
            },
        );
        let plain = f64::from(plain.pixels[16 * 33 + 16][3]);
        assert!(
            (plain - f64::from(opacity)).abs() <= 2e-6,
            "case {k}: {plain}"
        );
        checked += 1;
    }
    assert!(checked >= 30, "{checked} cases drawn");
}

fn opts_off() -> RenderOptions {
    RenderOptions::default()
}

#[test]
fn gl_matches_the_reference_with_the_antialiased_kernel_on_real_scenes() {
    let Some(scenes) = common::large_real_scenes() else {
        return;
    };
    let Some(mut r) = headless() else { return };
    let (mut checked, mut changed_views) = (0, 0);
    for common::RealScene { name, cloud, views } in scenes {
        r.upload(&cloud).unwrap();
        for (view, cam) in views {
            let on = HeadlessOptions {
                antialiased: true,
                ..Default::default()
            };
            let gl = r.render(&cam, &on).unwrap();
            let gl_plain = r.render(&cam, &HeadlessOptions::default()).unwrap();
            let space = cloud.meta.color_space.effective();
            let ro = RenderOptions {
                antialiased: true,
                ..Default::default()
            };
            let want = reference::render_display(&cloud, &cam, &ro, space).0;
            let s = score(&gl, &want);
            let changed = score(&gl, &gl_plain);
            eprintln!(
                "[{name} {view}] antialiased GL vs reference: PSNR {:.2} dB, max {:.2}/255; \
                 vs the plain kernel: PSNR {:.2} dB, max {:.2}/255",
                s.psnr,
                s.max_rgb * 255.0,
                changed.psnr,
                changed.max_rgb * 255.0
            );
            assert!(s.psnr >= MIN_PSNR, "[{name} {view}] PSNR {:.2}", s.psnr);
            changed_views += usize::from(changed.max_rgb > 16.0 / 255.0);
            checked += 1;
        }
    }
    assert!(checked >= 6, "{checked} views");
    // The compensation is visible (some views show little of their scene).
    assert!(
        changed_views * 4 >= checked * 3,
        "the compensation changed only {changed_views} of {checked} views"
    );
}
