use super::*;

fn cam() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 64, 48)
}

#[test]
fn margins_cover_the_quad_and_the_dilation() {
    // The GL quad: half-axes f·3√λ + m along Σ''s axes; its x-extent is at most
    // √2·(f·3√Σ'xx + m), and 3√Σ'xx ≤ |f|/z·R·√(1 + lim²) + 3√0.3.
    use crate::profile::{DILATION_PX2, QUAD_AXIS_FACTOR, QUAD_MARGIN_PX};
    let quad = QUAD_AXIS_FACTOR * 2f64.sqrt();
    assert!(f64::from(CULL_RADIUS_FACTOR) >= quad);
    let dilation = f64::from(CUTOFF_M2).sqrt() * DILATION_PX2.sqrt();
    assert!(f64::from(CULL_MARGIN_PX) >= quad * dilation + QUAD_MARGIN_PX * 2f64.sqrt());
}

#[test]
fn planes_cull_outside_and_keep_inside() {
    let c = cam();
    let f = Frustum::from_camera(&c, 0.2);
    assert!(f.may_see([0.0, 0.0, 0.0], 0.0));
    assert!(!f.may_see([0.0, 0.0, 6.0], 0.0), "behind the camera");
    assert!(
        !f.may_see([0.0, 0.0, 4.9], 0.0),
        "closer than the near cull"
    );
    assert!(f.may_see([0.0, 0.0, 4.7], 0.0));
    assert!(!f.may_see([50.0, 0.0, 0.0], 1.0), "far to the side");
    assert!(
        f.may_see([50.0, 0.0, 0.0], 60.0),
        "but a huge splat reaches in"
    );
    assert!(!f.may_see([0.0, -40.0, 0.0], 1.0));
    assert!(!f.may_see([0.0, 0.0, 0.0], NEVER));
    assert!(
        f.may_see([f32::NAN, 0.0, 0.0], 1.0),
        "NaN is left to the backends"
    );
}

#[test]
fn a_splat_whose_footprint_touches_the_border_is_kept() {
    // Place splats just outside the left image border: centre at pixel −e + 1 where e is
    // the (dilated) 3σ half-extent of a sphere of radius R; they must be kept.
    let c = cam();
    let f = Frustum::from_camera(&c, 0.2);
    for (depth, r) in [(2.0f32, 0.01f32), (5.0, 0.3), (9.0, 1.0)] {
        let z = 5.0 - depth; // world z of a point at that depth
        let s = r / 3.0; // σ of a sphere whose 3σ radius is r
        let e = 3.0 * ((c.fx / depth * s).powi(2) + 0.3).sqrt();
        let u = -e + 1.0; // its box still reaches pixel column 0
        let x = (u - c.cx) / c.fx * depth;
        assert!(f.may_see([x, 0.0, z], r), "depth {depth}, r {r}");
        // Far enough outside, it goes.
        let x_out = (-3.0 * e - 10.0 - c.cx) / c.fx * depth;
        assert!(!f.may_see([x_out, 0.0, z], r), "depth {depth}, r {r}");
    }
}

#[test]
fn visible_indices_ascend_and_match_the_predicate() {
    let c = cam();
    let f = Frustum::from_camera(&c, 0.2);
    let n = 70_000;
    let positions: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let t = i as f32 * 0.618;
            [
                20.0 * t.sin(),
                10.0 * (1.3 * t).cos(),
                8.0 * (0.7 * t).sin(),
            ]
        })
        .collect();
    let bounds = CullBounds::from_radii((0..n).map(|i| (i % 7) as f32 * 0.1).collect());
    let mut out = Vec::new();
    let m = visible_into(&f, &positions, &bounds, &mut out);
    let want: Vec<u32> = (0..n as u32)
        .filter(|&i| f.may_see(positions[i as usize], bounds.radii()[i as usize]))
        .collect();
    assert!(m > 1000 && m < n / 2, "{m}");
    assert_eq!(&out[..m], &want[..]);
}

#[test]
fn a_view_of_the_whole_cloud_keeps_every_splat_without_testing() {
    let mut cloud = SplatCloud::new(0);
    for i in 0..300 {
        let t = i as f32 * 0.1;
        let p = [t.sin(), t.cos(), (0.3 * t).sin()];
        cloud.push(p, [0.01; 3], [0.0, 0.0, 0.0, 1.0], 0.5, &[[0.0; 3]]);
    }
    let b = CullBounds::new(&cloud);
    let wide = Frustum::from_camera(&cam(), 0.2);
    assert!(b.all_visible(&wide));
    let all = (0..300).all(|i| wide.may_see(cloud.positions[i], b.radii()[i]));
    assert!(all, "the box test agrees with the per-splat test");
    let mut ids = Vec::new();
    assert_eq!(visible_into(&wide, &cloud.positions, &b, &mut ids), 300);
    // Turned away: not all; a splat that is never drawn: not all either.
    let away = Camera::look_at(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(9.0, 0.0, 5.0),
        Vec3::Y,
        0.8,
        64,
        48,
    );
    assert!(!b.all_visible(&Frustum::from_camera(&away, 0.2)));
    cloud.opacities[7] = 0.0;
    let never = CullBounds::new(&cloud);
    assert!(!never.all_visible(&wide));
    assert_eq!(visible_into(&wide, &cloud.positions, &never, &mut ids), 299);
    let mut moved = b.clone();
    moved.radii_mut()[0] = 1.0;
    assert!(
        !moved.all_visible(&wide),
        "radii changed: the box is forgotten"
    );
}

#[test]
fn radius_is_the_3_sigma_sphere_or_never() {
    let mut cloud = SplatCloud::new(0);
    for (o, s) in [(1.0, [0.1, -0.3, 0.2]), (0.02, [1.0; 3]), (0.001, [1.0; 3])] {
        cloud.push([0.0; 3], s, [0.0, 0.0, 0.0, 1.0], o, &[[0.0; 3]]);
    }
    cloud.push(
        [f32::NAN, 0.0, 0.0],
        [1.0; 3],
        [0.0, 0.0, 0.0, 1.0],
        1.0,
        &[[0.0; 3]],
    );
    let b = CullBounds::new(&cloud);
    let r = b.radii();
    assert!((r[0] - 0.9).abs() < 1e-5 && r[0] >= 0.9, "{r:?}");
    assert!((r[1] - 3.0).abs() < 1e-4, "{r:?}");
    assert!(r[2] < 0.0, "α < 1/255 everywhere: never visible");
    assert!(r[3] < 0.0, "not drawable: never visible");
    assert!((radius_scale(Mat4::from_scale(Vec3::splat(2.0))) - 2.0).abs() < 1e-4);
    let shear = Mat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.7, 1.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let a = glam::Mat3::from_mat4(shear);
    for v in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(0.6, 0.8, 0.0)] {
        assert!((a * v).length() <= radius_scale(shear));
    }
}

#[test]
fn a_scaled_view_matrix_keeps_what_the_rigid_one_keeps() {
    // A host view of 2·V projects every point and every footprint as V does (x = f·X/Z with
    // X and Z both doubled; J's 1/z cancels W's scale), so it must keep at least the same
    // splats.
    let c = Camera::look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        0.8,
        1000,
        750,
    );
    let rigid = Frustum::from_camera(&c, 0.2);
    let scaled = Frustum::new(
        Mat4::from_scale(Vec3::splat(2.0)) * c.world_to_camera,
        Vec2::new(c.fx, c.fy),
        Vec2::new(c.cx, c.cy),
        Vec2::new(c.width as f32, c.height as f32),
        c.tan_half_fov(),
        0.2,
    );
    let mut rng = crate::synthetic::Rng::new(11);
    let mut kept = 0;
    for _ in 0..20_000 {
        let p = [
            rng.range(-30.0, 30.0),
            rng.range(-30.0, 30.0),
            rng.range(-10.0, 9.0),
        ];
        let r = rng.range(0.0, 3.0);
        if rigid.may_see(p, r) {
            kept += 1;
            assert!(
                scaled.may_see(p, r),
                "{p:?} r {r}: kept by V, culled by 2·V"
            );
        }
    }
    assert!(kept > 1000 && kept < 20_000, "{kept}");
}
