//! Camera constructors against independent computations (f64, written from the formats' text).

use crate::common;

use glam::{DMat3, DQuat, DVec3, Mat4, Quat, Vec3};
use splatgl::camera::{Camera, CameraError, GltfPerspective, parse_cameras_json};

/// Projects with an explicit camera → world rotation `r` (rows as in cameras.json) and centre.
fn project_3dgs(r: [[f64; 3]; 3], c: [f64; 3], f: [f64; 2], pp: [f64; 2], p: DVec3) -> [f64; 2] {
    let d = p - DVec3::from_array(c);
    // camera = Rᵀ (p − c): component j = Σ_i r[i][j] d_i.
    let x: Vec<f64> = (0..3)
        .map(|j| (0..3).map(|i| r[i][j] * d[i]).sum())
        .collect();
    [f[0] * x[0] / x[2] + pp[0], f[1] * x[1] / x[2] + pp[1]]
}

fn rows(m: DMat3) -> [[f64; 3]; 3] {
    let t = m.transpose(); // columns of the transpose are rows
    [
        t.x_axis.to_array(),
        t.y_axis.to_array(),
        t.z_axis.to_array(),
    ]
}

const POINTS: [[f64; 3]; 4] = [
    [0.1, 0.2, 0.3],
    [-0.7, 0.4, 1.1],
    [0.5, -0.6, -0.2],
    [0.0, 0.0, 0.9],
];

#[test]
fn cameras_json_projects_like_the_trainer() {
    let r = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::YXZ, 2.7, 0.3, -0.2));
    let centre = [0.4, -0.3, 4.5];
    let text = format!(
        r#"[{{"id": 0, "img_name": "a", "width": 320, "height": 240, "position": {:?},
              "rotation": {:?}, "fx": 300.5, "fy": 290.25}},
            {{"id": 1, "img_name": "b", "width": 320, "height": 240, "position": {:?},
              "rotation": {:?}, "fx": 250, "fy": 260, "cx": 150.5, "cy": 130.25}}]"#,
        centre,
        rows(r),
        centre,
        rows(r)
    );
    let list = parse_cameras_json(&text).unwrap();
    assert_eq!(list.len(), 2);
    for (e, pp) in list.iter().zip([[160.0, 120.0], [150.5, 130.25]]) {
        let cam = Camera::from_3dgs(e).unwrap();
        for p in POINTS {
            // Move each point in front of the camera: centre + 3·forward + offset.
            let p = DVec3::from_array(centre) + r.z_axis * 3.0 + DVec3::from_array(p);
            let want = project_3dgs(rows(r), centre, [e.fx, e.fy], pp, p);
            let (got, _) = cam.project(p.as_vec3()).expect("in front");
            assert!(
                (got.x as f64 - want[0]).abs() < 1e-3 && (got.y as f64 - want[1]).abs() < 1e-3,
                "{got} vs {want:?}"
            );
        }
        assert!((cam.eye().as_dvec3() - DVec3::from_array(centre)).length() < 1e-5);
    }
}

#[test]
fn cameras_json_errors_name_the_entry_and_key() {
    let bad = r#"[{"id":0,"width":10,"height":10,"position":[0,0,0],
                  "rotation":[[1,0,0],[0,1,0]],"fx":1,"fy":1}]"#;
    match parse_cameras_json(bad) {
        Err(CameraError::Invalid { location, .. }) => assert_eq!(location, "[0].rotation"),
        other => panic!("{other:?}"),
    }
    let missing = r#"[{"width":10,"height":10,"position":[0,0,0],
                      "rotation":[[1,0,0],[0,1,0],[0,0,1]],"fy":1}]"#;
    assert!(matches!(
        parse_cameras_json(missing),
        Err(CameraError::Invalid { location, .. }) if location == "[0].fx"
    ));
    assert!(matches!(parse_cameras_json("{"), Err(CameraError::Json(_))));
    let mirror = r#"[{"width":10,"height":10,"position":[0,0,0],
                     "rotation":[[1,0,0],[0,1,0],[0,0,-1]],"fx":1,"fy":1}]"#;
    let e = &parse_cameras_json(mirror).unwrap()[0];
    assert!(matches!(
        Camera::from_3dgs(e),
        Err(CameraError::Degenerate(_))
    ));
}

fn gltf(node: Mat4, aspect: Option<f32>) -> GltfPerspective {
    GltfPerspective {
        yfov: 0.8,
        aspect_ratio: aspect,
        znear: 0.05,
        zfar: None,
        node_to_world: node,
    }
}

#[test]
fn gltf_camera_looks_down_minus_z_with_y_up() {
    let cam = Camera::from_gltf(&gltf(Mat4::IDENTITY, None), 200, 100).unwrap();
    let t = (0.4f32).tan();
    let (c, z) = cam.project(Vec3::new(0.0, 0.0, -5.0)).unwrap();
    assert!((c.x - 100.0).abs() < 1e-4 && (c.y - 50.0).abs() < 1e-4 && (z - 5.0).abs() < 1e-5);
    // yfov: the top edge of the view is at y = 5·tan(yfov/2) → row 0.
    let (top, _) = cam.project(Vec3::new(0.0, 5.0 * t, -5.0)).unwrap();
    assert!(top.y.abs() < 1e-3, "{top}");
    // No aspectRatio: the viewport's (2), square pixels → right edge at x = 5·2·tan.
    let (right, _) = cam.project(Vec3::new(10.0 * t, 0.0, -5.0)).unwrap();
    assert!((right.x - 200.0).abs() < 1e-3, "{right}");
    assert!(
        cam.project(Vec3::new(0.0, 0.0, 5.0)).is_none(),
        "+Z is behind"
    );
    // aspectRatio 1.5 on a 200×100 viewport: x edge at 5·1.5·tan maps to the right border.
    let cam = Camera::from_gltf(&gltf(Mat4::IDENTITY, Some(1.5)), 200, 100).unwrap();
    let (right, _) = cam.project(Vec3::new(7.5 * t, 0.0, -5.0)).unwrap();
    assert!((right.x - 200.0).abs() < 1e-3, "{right}");
}

#[test]
fn gltf_node_transform_moves_the_camera_and_ignores_scale() {
    let rot = Quat::from_euler(glam::EulerRot::YXZ, 0.6, -0.3, 0.1);
    let pos = Vec3::new(1.0, 2.0, 3.0);
    let plain = Mat4::from_rotation_translation(rot, pos);
    let scaled = Mat4::from_scale_rotation_translation(Vec3::new(2.0, 0.5, 3.0), rot, pos);
    let a = Camera::from_gltf(&gltf(plain, None), 160, 120).unwrap();
    let b = Camera::from_gltf(&gltf(scaled, None), 160, 120).unwrap();
    // A point 4 units in front of the camera (local −Z) is at the image centre.
    let p = pos + rot * Vec3::new(0.3, -0.2, -4.0);
    for cam in [a, b] {
        let (px, z) = cam.project(p).unwrap();
        let want = [80.0 + cam.fx * 0.3 / 4.0, 60.0 + cam.fy * 0.2 / 4.0];
        assert!((px.x - want[0]).abs() < 1e-3 && (px.y - want[1]).abs() < 1e-3);
        assert!((z - 4.0).abs() < 1e-4);
        assert!((cam.eye() - pos).length() < 1e-5);
    }
}

#[test]
fn gl_matrices_match_pixels_also_with_infinite_far() {
    let cam = Camera::from_gltf(&gltf(Mat4::from_rotation_y(0.3), None), 128, 96).unwrap();
    assert!(cam.far.is_infinite());
    let proj = cam.gl_projection();
    assert!(proj.is_finite());
    for p in [Vec3::new(0.2, 0.1, -3.0), Vec3::new(-1.0, 0.5, -7.0)] {
        let (px, _) = cam.project(p).unwrap();
        let clip = proj * cam.gl_view() * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (u, v) = ((ndc.x + 1.0) * 64.0, (1.0 - ndc.y) * 48.0);
        assert!((u - px.x).abs() < 1e-3 && (v - px.y).abs() < 1e-3);
        assert!(ndc.z > -1.0 && ndc.z < 1.0);
    }
}

#[test]
fn resized_scales_pixel_coordinates() {
    let cam = Camera::look_at(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 0.9, 320, 240);
    let half = cam.resized(160, 120);
    let p = Vec3::new(0.3, -0.2, 0.5);
    let (a, _) = cam.project(p).unwrap();
    let (b, _) = half.project(p).unwrap();
    assert!((a * 0.5 - b).length() < 1e-4);
}

#[test]
fn framing_keeps_the_bulk_of_the_points_in_view() {
    let mut pts: Vec<[f32; 3]> = (0..1000)
        .map(|i| {
            let t = i as f32 * 0.37;
            [
                t.sin() * 3.0 + 10.0,
                (t * 1.3).cos() - 5.0,
                (t * 0.7).sin() * 2.0,
            ]
        })
        .collect();
    pts.push([1e6, 0.0, 0.0]); // a stray splat must not shrink the view
    pts.push([f32::NAN, 0.0, 0.0]);
    let cam = common::frame_points(&pts, 0.8, 160, 120).unwrap();
    let inside = pts[..1000]
        .iter()
        .filter_map(|p| cam.project(Vec3::from_array(*p)))
        .filter(|(px, _)| px.x >= 0.0 && px.x <= 160.0 && px.y >= 0.0 && px.y <= 120.0)
        .count();
    assert_eq!(inside, 1000);
    assert!(common::frame_points(&[], 0.8, 10, 10).is_none());
}

/// Framing uses the splats' 3σ boxes, not their centres: coincident splats with large scales
/// (the bevy conformance matrix has 15 at one point) put the eye outside every box, and a
/// single tiny splat stays beyond the near cull.
#[test]
fn framing_from_extents_keeps_the_eye_outside_every_splat() {
    use splatgl::camera::UpAxis;
    let mut cloud = splatgl::SplatCloud::new(0);
    for (i, s) in [[1.0, 1.6, 0.6], [2.7, 0.1, 20.0], [7.4, 0.05, 54.6]]
        .iter()
        .enumerate()
    {
        let q = Quat::from_rotation_y(0.3 * i as f32).to_array();
        cloud.push([1.0, 2.0, 3.0], *s, q, 0.25, &[[0.2; 3]]);
    }
    for up in [UpAxis::Y, UpAxis::NegY, UpAxis::Z] {
        let cam = Camera::frame_cloud(&cloud, up, 0.8, 160, 120).unwrap();
        let e = cam.eye() - Vec3::new(1.0, 2.0, 3.0);
        for i in 0..cloud.len() {
            // Mahalanobis distance of the eye from the splat's centre: > 3 means outside.
            let r = glam::Mat3::from_quat(Quat::from_array(cloud.rotations[i]));
            let local = r.transpose() * e;
            let m = (local / Vec3::from_array(cloud.scales[i])).length();
            assert!(m > 3.0, "{up:?}: eye inside splat {i} (m = {m})");
        }
        // Image "up" is the up axis: it projects above the centre.
        let (c, _) = cam.project(Vec3::new(1.0, 2.0, 3.0)).unwrap();
        let (u, _) = cam.project(Vec3::new(1.0, 2.0, 3.0) + up.vector()).unwrap();
        assert!(u.y < c.y && (c.x - 80.0).abs() < 1e-2, "{up:?}: {c} {u}");
    }
    let mut one = splatgl::SplatCloud::new(0);
    one.push([0.0; 3], [0.01; 3], [0.0, 0.0, 0.0, 1.0], 1.0, &[[0.2; 3]]);
    let cam = Camera::frame_cloud(&one, UpAxis::Y, 0.8, 160, 120).unwrap();
    let depth = cam.to_camera(Vec3::ZERO).z;
    assert!(depth - 0.03 > splatgl::profile::NEAR_CULL as f32, "{depth}");
    // Nothing drawable (zero opacity, NaN position): no framing.
    let mut none = splatgl::SplatCloud::new(0);
    none.push([0.0; 3], [1.0; 3], [0.0, 0.0, 0.0, 1.0], 0.0, &[[0.2; 3]]);
    none.push(
        [f32::NAN; 3],
        [1.0; 3],
        [0.0, 0.0, 0.0, 1.0],
        1.0,
        &[[0.2; 3]],
    );
    assert!(Camera::frame_cloud(&none, UpAxis::Y, 0.8, 160, 120).is_none());
}

/// `--up auto`: glTF is +Y up, PLY (COLMAP axes) −Y, the default scene +Y.
#[test]
fn auto_up_axis_follows_the_format() {
    use splatgl::camera::UpAxis;
    use splatgl::load::Format;
    assert_eq!(UpAxis::for_format(Some(Format::Glb)), UpAxis::Y);
    assert_eq!(UpAxis::for_format(Some(Format::Gltf)), UpAxis::Y);
    assert_eq!(UpAxis::for_format(Some(Format::Ply)), UpAxis::NegY);
    assert_eq!(UpAxis::for_format(None), UpAxis::Y);
}

/// `--up auto` with the cloud: PLY is −Y up unless the content stands on z = 0 and is clearly
/// taller along +Z than wide (the MuJoCo fox); glTF stays +Y whatever its shape.
#[test]
fn auto_up_axis_takes_z_for_content_standing_on_z_zero() {
    use splatgl::camera::UpAxis;
    use splatgl::load::Format;
    let column = |z0: f32| {
        let mut c = splatgl::SplatCloud::new(0);
        for i in 0..200 {
            let t = i as f32 / 199.0;
            let p = [0.3 * (t * 17.0).sin(), 0.3 * (t * 23.0).cos(), z0 + 2.0 * t];
            c.push(p, [0.02; 3], [0.0, 0.0, 0.0, 1.0], 0.8, &[[0.2; 3]]);
        }
        c
    };
    let standing = column(0.0);
    assert_eq!(UpAxis::for_cloud(Some(Format::Ply), &standing), UpAxis::Z);
    assert_eq!(UpAxis::for_cloud(Some(Format::Spz), &standing), UpAxis::Z);
    assert_eq!(UpAxis::for_cloud(Some(Format::Glb), &standing), UpAxis::Y);
    // Spanning both sides of z = 0 (COLMAP scenes around the origin): −Y.
    assert_eq!(
        UpAxis::for_cloud(Some(Format::Ply), &column(-1.0)),
        UpAxis::NegY
    );
    // Not taller along z than wide: −Y.
    let wide = splatgl::synthetic::random_cloud(200, 0, 1.0, 5);
    assert_eq!(UpAxis::for_cloud(Some(Format::Ply), &wide), UpAxis::NegY);
}
