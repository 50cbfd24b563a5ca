//! The reference rasterizer against analytic expectations written here from the RC text and
//! the 3DGS forward pass (independent of `src/reference`), plus invariance tests and degenerate
//! splats and cameras.

use crate::common;
use common::{look_at_focal_px, real_files};
use glam::{DMat3, DMat4, DQuat, DVec3, Vec3};
use splatgl::camera::{Camera, parse_cameras_json};
use splatgl::cloud::SplatCloud;
use splatgl::covariance::{scale_rotation_from_covariance, transformed_covariance};
use splatgl::image::Image;
use splatgl::reference::{RenderOptions, SortMode, render};
use splatgl::sh::ShRotation;
use splatgl::synthetic::random_cloud;

const C0: f64 = 0.282_094_791_773_878_1; // RC §Lighting
const C1: f64 = 0.488_602_511_902_919_9;

fn dc(rgb: [f32; 3]) -> [f32; 3] {
    rgb.map(|c| ((c as f64 - 0.5) / C0) as f32)
}

fn one(p: [f32; 3], s: [f32; 3], q: [f32; 4], o: f32, rgb: [f32; 3]) -> SplatCloud {
    let mut c = SplatCloud::new(0);
    c.push(p, s, q, o, &[dc(rgb)]);
    c
}

fn opts() -> RenderOptions {
    RenderOptions::default()
}

/// Σ' = J W Σ Wᵀ Jᵀ + 0.3 I (3DGS `computeCov2D`), with or without the 1.3·tan clamp.
fn cov2d(cam: &Camera, mean: DVec3, s: [f64; 3], q: DQuat, clamp: bool) -> [f64; 3] {
    let w2c: DMat4 = cam.world_to_camera.as_dmat4();
    let t = w2c.transform_point3(mean);
    let w = DMat3::from_mat4(w2c);
    let r = DMat3::from_quat(q);
    let sigma = r * DMat3::from_diagonal(DVec3::from_array(s.map(|v| v * v))) * r.transpose();
    let (fx, fy) = (cam.fx as f64, cam.fy as f64);
    let lim = [
        1.3 * 0.5 * cam.width as f64 / fx,
        1.3 * 0.5 * cam.height as f64 / fy,
    ];
    let (mut x, mut y) = (t.x / t.z, t.y / t.z);
    if clamp {
        (x, y) = (x.clamp(-lim[0], lim[0]), y.clamp(-lim[1], lim[1]));
    }
    let j = DMat3::from_cols(
        DVec3::new(fx / t.z, 0.0, 0.0),
        DVec3::new(0.0, fy / t.z, 0.0),
        DVec3::new(-fx * x / t.z, -fy * y / t.z, 0.0),
    );
    let c = j * w * sigma * w.transpose() * j.transpose();
    [c.x_axis.x + 0.3, c.y_axis.x, c.y_axis.y + 0.3]
}

/// Expected α at pixel (x, y) (centre +0.5) of a splat with mean `m` px, Σ' `c`, opacity `o`;
/// `None` near the 3σ border where rounding may decide.
fn alpha_at(x: u32, y: u32, m: [f64; 2], c: [f64; 3], o: f64) -> Option<f64> {
    let det = c[0] * c[2] - c[1] * c[1];
    let (dx, dy) = (x as f64 + 0.5 - m[0], y as f64 + 0.5 - m[1]);
    let m2 = (c[2] * dx * dx - 2.0 * c[1] * dx * dy + c[0] * dy * dy) / det;
    let a = (o * (-0.5 * m2).exp()).min(0.99);
    if (m2 - 9.0).abs() < 1e-3 || (a - 1.0 / 255.0).abs() < 1e-5 {
        return None;
    }
    Some(if m2 > 9.0 || a < 1.0 / 255.0 { 0.0 } else { a })
}

/// Least-squares fit of ln α = ln o − ½ (p − μ)ᵀ Q (p − μ) over the covered pixels.
struct Fit {
    mean: [f64; 2],
    q: [f64; 3],
    ln_o: f64,
}

fn fit(img: &Image) -> Fit {
    let (mut ata, mut atb) = ([[0.0f64; 6]; 6], [0.0f64; 6]);
    let (mut x0, mut y0, mut best) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            if img.get(x, y)[3] > best {
                (best, x0, y0) = (img.get(x, y)[3], x as f64 + 0.5, y as f64 + 0.5);
            }
        }
    }
    for y in 0..img.height {
        for x in 0..img.width {
            let a = img.get(x, y)[3] as f64;
            if a <= 0.0 {
                continue;
            }
            let (u, v) = (x as f64 + 0.5 - x0, y as f64 + 0.5 - y0);
            let row = [1.0, u, v, u * u, u * v, v * v];
            for i in 0..6 {
                atb[i] += row[i] * a.ln();
                for j in 0..6 {
                    ata[i][j] += row[i] * row[j];
                }
            }
        }
    }
    let k = solve6(ata, atb);
    let q = [-2.0 * k[3], -k[4], -2.0 * k[5]];
    let det = q[0] * q[2] - q[1] * q[1];
    let mu = [
        (q[2] * k[1] - q[1] * k[2]) / det,
        (q[0] * k[2] - q[1] * k[1]) / det,
    ];
    let ln_o =
        k[0] + 0.5 * (q[0] * mu[0] * mu[0] + 2.0 * q[1] * mu[0] * mu[1] + q[2] * mu[1] * mu[1]);
    Fit {
        mean: [mu[0] + x0, mu[1] + y0],
        q,
        ln_o,
    }
}

fn solve6(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> [f64; 6] {
    for c in 0..6 {
        let p = (c..6)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        let (pivot, pb) = (a[c], b[c]);
        for r in (0..6).filter(|&r| r != c) {
            let f = a[r][c] / pivot[c];
            for (x, p) in a[r].iter_mut().zip(pivot) {
                *x -= f * p;
            }
            b[r] -= f * pb;
        }
    }
    std::array::from_fn(|i| b[i] / a[i][i])
}

fn inverse2(c: [f64; 3]) -> [f64; 3] {
    let det = c[0] * c[2] - c[1] * c[1];
    [c[2] / det, -c[1] / det, c[0] / det]
}

#[test]
fn isotropic_splat_is_the_predicted_gaussian() {
    let z = 4.0f32;
    for s in [0.2f32, 0.01] {
        let c = look_at_focal_px(Vec3::ZERO, Vec3::Z, 100.0, 96, 96);
        let img = render(
            &one([0.0, 0.0, z], [s; 3], [0.0, 0.0, 0.0, 1.0], 0.8, [1.0; 3]),
            &c,
            &opts(),
        );
        let var = (100.0 * s as f64 / z as f64).powi(2) + 0.3;
        let (mut checked, mut max_err) = (0, 0.0f64);
        for y in 0..96 {
            for x in 0..96 {
                if let Some(a) = alpha_at(x, y, [48.0, 48.0], [var, 0.0, var], 0.8) {
                    max_err = max_err.max((img.get(x, y)[3] as f64 - a).abs());
                    checked += 1;
                }
            }
        }
        assert!(
            checked > 9000 && max_err < 1e-5,
            "s {s}: max α error {max_err}"
        );
        let f = fit(&img);
        let sigma_fit = (1.0 / f.q[0]).sqrt();
        assert!(
            (sigma_fit - var.sqrt()).abs() < 1e-3,
            "σ {sigma_fit} vs {}",
            var.sqrt()
        );
        assert!(f.q[1].abs() < 1e-6 && (f.q[0] - f.q[2]).abs() < 1e-6);
        assert!((f.mean[0] - 48.0).abs() < 1e-3 && (f.mean[1] - 48.0).abs() < 1e-3);
        assert!((f.ln_o.exp() - 0.8).abs() < 1e-3);
    }
}

#[test]
fn anisotropic_splat_axes_match_the_eigen_decomposition_of_sigma_prime() {
    let c = look_at_focal_px(
        Vec3::new(0.3, -0.2, -1.0),
        Vec3::new(0.5, 0.1, 5.0),
        90.0,
        128,
        96,
    );
    let q = DQuat::from_euler(glam::EulerRot::ZXY, 0.7, -0.4, 1.1);
    let (mean, s) = (DVec3::new(0.9, 0.4, 5.0), [0.6, 0.15, 0.05]);
    let cloud = one(
        mean.as_vec3().to_array(),
        s.map(|v| v as f32),
        q.as_quat().to_array(),
        0.9,
        [0.2, 0.6, 0.9],
    );
    let img = render(&cloud, &c, &opts());
    let want = cov2d(&c, mean, s, q, true);
    let got = inverse2(fit(&img).q);
    let eig = |c: [f64; 3]| {
        let (m, d) = (
            0.5 * (c[0] + c[2]),
            (0.25 * (c[0] - c[2]).powi(2) + c[1] * c[1]).sqrt(),
        );
        let angle = 0.5 * (2.0 * c[1]).atan2(c[0] - c[2]); // major axis direction
        (m + d, m - d, angle)
    };
    let (w, g) = (eig(want), eig(got));
    assert!(
        w.0 / w.1 > 4.0,
        "the test needs a clearly anisotropic ellipse"
    );
    assert!(
        (g.0 / w.0 - 1.0).abs() < 1e-3 && (g.1 / w.1 - 1.0).abs() < 1e-3,
        "{w:?} {g:?}"
    );
    let da = (g.2 - w.2).rem_euclid(std::f64::consts::PI);
    assert!(da.min(std::f64::consts::PI - da) < 1e-3, "{w:?} {g:?}");
    // Support: exactly the 3σ ellipse of Σ'.
    let (m, _) = c.project(mean.as_vec3()).unwrap();
    for y in 0..96 {
        for x in 0..128 {
            if let Some(a) = alpha_at(x, y, [m.x as f64, m.y as f64], want, 0.9) {
                let e = (img.get(x, y)[3] as f64 - a).abs();
                assert!(e < 1e-4, "({x},{y}) {} vs {a}", img.get(x, y)[3]);
            }
        }
    }
}

#[test]
fn jacobian_clamp_applies_outside_the_view() {
    let c = look_at_focal_px(Vec3::ZERO, Vec3::Z, 40.0, 65, 65);
    let (mean, s, q) = (DVec3::new(8.0, 0.0, 5.0), [3.0, 0.3, 2.0], DQuat::IDENTITY);
    let img = render(
        &one(
            [8.0, 0.0, 5.0],
            [3.0, 0.3, 2.0],
            [0.0, 0.0, 0.0, 1.0],
            0.9,
            [1.0; 3],
        ),
        &c,
        &opts(),
    );
    let (m, _) = c.project(mean.as_vec3()).unwrap();
    let m = [m.x as f64, m.y as f64];
    let (clamped, free) = (cov2d(&c, mean, s, q, true), cov2d(&c, mean, s, q, false));
    let mut differs = 0.0f64;
    for y in 0..65 {
        for x in 0..65 {
            let (Some(a), Some(b)) = (
                alpha_at(x, y, m, clamped, 0.9),
                alpha_at(x, y, m, free, 0.9),
            ) else {
                continue;
            };
            assert!((img.get(x, y)[3] as f64 - a).abs() < 1e-4);
            differs = differs.max((a - b).abs());
        }
    }
    assert!(
        differs > 0.05,
        "the clamp must matter in this set-up ({differs})"
    );
}

/// Back-to-front composite of single-splat renders (background 0): C_f + C_b·(1 − A_f).
fn composite(back: &Image, front: &Image) -> Image {
    let mut out = back.clone();
    for (o, f) in out.pixels.iter_mut().zip(&front.pixels) {
        let keep = 1.0 - f[3];
        for ch in 0..3 {
            o[ch] = f[ch] + o[ch] * keep;
        }
        o[3] = f[3] + o[3] * keep;
    }
    out
}

fn max_diff(a: &Image, b: &Image) -> f32 {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0, f32::max)
}

#[test]
fn overlapping_splats_blend_in_camera_distance_order() {
    let red = one(
        [0.0, 0.0, 0.0],
        [0.3; 3],
        [0.0, 0.0, 0.0, 1.0],
        0.7,
        [1.0, 0.0, 0.0],
    );
    let blue = one(
        [0.0, 0.1, 1.0],
        [0.3; 3],
        [0.0, 0.0, 0.0, 1.0],
        0.6,
        [0.0, 0.0, 1.0],
    );
    let mut both = red.clone();
    both.append(blue.clone());
    let target = Vec3::new(0.0, 0.0, 0.5);
    for (eye, red_in_front) in [
        (Vec3::new(0.2, 0.0, -4.0), true),
        (Vec3::new(0.2, 0.0, 5.0), false),
    ] {
        let c = look_at_focal_px(eye, target, 60.0, 64, 48);
        let (r, b) = (render(&red, &c, &opts()), render(&blue, &c, &opts()));
        let got = render(&both, &c, &opts());
        let (want, wrong) = if red_in_front {
            (composite(&b, &r), composite(&r, &b))
        } else {
            (composite(&r, &b), composite(&b, &r))
        };
        assert!(max_diff(&got, &want) < 1e-6, "eye {eye}");
        assert!(
            max_diff(&got, &wrong) > 0.1,
            "the orders must be distinguishable"
        );
    }
}

#[test]
fn distance_and_view_depth_sorting_differ_where_they_should() {
    // P on the axis at depth 5; Q off-axis: nearer in depth (4.5), farther in distance (5.41).
    let p = one(
        [0.0, 0.0, 5.0],
        [0.5; 3],
        [0.0, 0.0, 0.0, 1.0],
        0.8,
        [1.0, 0.2, 0.2],
    );
    let q = one(
        [3.0, 0.0, 4.5],
        [2.0, 0.5, 0.5],
        [0.0, 0.0, 0.0, 1.0],
        0.8,
        [0.2, 0.2, 1.0],
    );
    let mut both = p.clone();
    both.append(q.clone());
    let c = look_at_focal_px(Vec3::ZERO, Vec3::Z, 40.0, 65, 65);
    let (ip, iq) = (render(&p, &c, &opts()), render(&q, &c, &opts()));
    let by_distance = render(&both, &c, &opts());
    let by_depth = render(
        &both,
        &c,
        &RenderOptions {
            sort: SortMode::ViewDepth,
            ..opts()
        },
    );
    assert!(max_diff(&by_distance, &composite(&iq, &ip)) < 1e-6);
    assert!(max_diff(&by_depth, &composite(&ip, &iq)) < 1e-6);
    assert!(max_diff(&by_distance, &by_depth) > 0.05);
}

#[test]
fn sh_degree_1_colour_follows_the_basis() {
    let coeffs = [
        [0.0f32, 0.0, 0.0],
        [0.3, -0.2, 0.1],    // m = −1
        [-0.25, 0.15, 0.05], // m = 0
        [0.2, 0.3, -1.5],    // m = +1 (blue goes negative from some sides: clamped)
    ];
    let mut cloud = SplatCloud::new(1);
    cloud.push([0.0; 3], [0.2; 3], [0.0, 0.0, 0.0, 1.0], 0.9, &coeffs);
    let mut clamped = 0;
    for eye in [
        [0.0, 0.0, 4.0],
        [4.0, 0.0, 0.0],
        [-4.0, 0.0, 0.0],
        [0.0, 3.0, 2.0],
        [1.0, -2.0, -3.0],
    ] {
        let c = look_at_focal_px(Vec3::from_array(eye), Vec3::ZERO, 60.0, 65, 65);
        let d = -DVec3::from_array(eye.map(f64::from)).normalize();
        for (degree, want_sh) in [(1u8, true), (0, false)] {
            let img = render(
                &cloud,
                &c,
                &RenderOptions {
                    sh_degree: degree,
                    ..opts()
                },
            );
            let px = img.get(32, 32);
            assert!((px[3] - 0.9).abs() < 1e-6);
            for ch in 0..3 {
                let mut want = 0.5;
                if want_sh {
                    want += -C1 * d.y * coeffs[1][ch] as f64 + C1 * d.z * coeffs[2][ch] as f64
                        - C1 * d.x * coeffs[3][ch] as f64;
                }
                clamped += (want < 0.0) as usize;
                let got = px[ch] as f64 / 0.9;
                assert!(
                    (got - want.max(0.0)).abs() < 1e-5,
                    "eye {eye:?} ch {ch}: {got} vs {want}"
                );
            }
        }
    }
    assert!(clamped > 0, "some view must exercise the clamp at 0");
}

fn scene_camera(w: u32, h: u32) -> Camera {
    Camera::look_at(
        Vec3::new(0.6, 0.8, 3.6),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        0.9,
        w,
        h,
    )
}

#[test]
fn re_render_is_bit_identical_whatever_the_thread_count() {
    let cloud = random_cloud(600, 3, 1.0, 7);
    let c = scene_camera(96, 72);
    let a = render(&cloud, &c, &opts());
    let b = render(&cloud, &c, &opts());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let single = pool.install(|| render(&cloud, &c, &opts()));
    let bits = |i: &Image| {
        i.pixels
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(bits(&a), bits(&single));
    assert!(
        a.pixels.iter().filter(|p| p[3] > 0.5).count() > 1000,
        "scene covers the image"
    );
}

#[test]
fn splats_behind_or_outside_change_nothing() {
    let cloud = random_cloud(500, 2, 1.0, 11);
    let c = scene_camera(96, 72);
    let base = render(&cloud, &c, &opts());
    let c2w = c.world_to_camera.inverse();
    let mut extra = random_cloud(300, 2, 1.0, 12);
    for (k, p) in extra.positions.iter_mut().enumerate() {
        let z = 0.5 + (k % 7) as f32;
        let local = match k % 3 {
            0 => Vec3::new(p[0], p[1], -z),          // behind the camera
            1 => Vec3::new(4.0 * z, p[1], z),        // far right of the view
            _ => Vec3::new(p[0], -5.0 * z - 1.0, z), // far above
        };
        *p = c2w.transform_point3(local).to_array();
    }
    let mut more = cloud.clone();
    more.append(extra);
    assert_eq!(render(&more, &c, &opts()), base);
}

#[test]
fn no_splats_give_the_background() {
    let bg = [0.25, 0.5, 0.75];
    let img = render(
        &SplatCloud::new(3),
        &scene_camera(33, 17),
        &RenderOptions {
            background: bg,
            ..opts()
        },
    );
    assert!(img.pixels.iter().all(|p| *p == [0.25, 0.5, 0.75, 0.0]));
}

#[test]
fn transformed_cloud_and_camera_render_the_same() {
    let cloud = random_cloud(800, 3, 1.0, 3);
    let c = scene_camera(96, 72);
    let (rot, k, t) = (
        DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.3),
        1.7,
        DVec3::new(2.0, -1.0, 0.5),
    );
    let m = DMat3::from_quat(rot) * k;
    let xf = |p: Vec3| (m * p.as_dvec3() + t).as_vec3();
    let shr = ShRotation::new(DMat3::from_quat(rot));
    let mut moved = cloud.clone();
    for i in 0..cloud.len() {
        moved.positions[i] = xf(Vec3::from_array(cloud.positions[i])).to_array();
        let sigma = transformed_covariance(m, cloud.scales[i], cloud.rotations[i]);
        (moved.scales[i], moved.rotations[i]) = scale_rotation_from_covariance(sigma);
        let n = cloud.coeffs_per_splat();
        shr.apply(&mut moved.sh[i * n..(i + 1) * n]);
    }
    let up = (rot * DVec3::Y).as_vec3();
    let c2 = Camera::look_at(xf(c.eye()), xf(Vec3::new(0.0, 0.1, 0.0)), up, 0.9, 96, 72);
    let (a, b) = (render(&cloud, &c, &opts()), render(&moved, &c2, &opts()));
    let d = max_diff(&a, &b);
    assert!(d < 1e-4, "max difference {d}");
    assert!(a.pixels.iter().filter(|p| p[3] > 0.5).count() > 1000);
}

#[test]
fn cameras_json_views_place_means_where_the_trainer_projects_them() {
    let r = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::YXZ, 0.4, -0.2, 0.1));
    let centre = DVec3::new(0.5, -0.4, -6.0);
    let rows = {
        let t = r.transpose();
        [
            t.x_axis.to_array(),
            t.y_axis.to_array(),
            t.z_axis.to_array(),
        ]
    };
    let text = format!(
        r#"[{{"id": 0, "img_name": "x", "width": 120, "height": 90, "position": {:?},
              "rotation": {rows:?}, "fx": 110.0, "fy": 105.0, "cx": 57.25, "cy": 47.5}}]"#,
        centre.to_array()
    );
    let c = Camera::from_3dgs(&parse_cameras_json(&text).unwrap()[0]).unwrap();
    for p in [[0.0, 0.0, 0.0], [0.7, -0.5, 0.3], [-0.9, 0.6, -0.4]] {
        let p = centre + r.z_axis * 6.0 + DVec3::from_array(p); // in front of the camera
        let x = r.transpose() * (p - centre);
        let want = [110.0 * x.x / x.z + 57.25, 105.0 * x.y / x.z + 47.5];
        let img = render(
            &one(
                p.as_vec3().to_array(),
                [0.08; 3],
                [0.0, 0.0, 0.0, 1.0],
                0.9,
                [1.0; 3],
            ),
            &c,
            &opts(),
        );
        let got = fit(&img).mean;
        assert!(
            (got[0] - want[0]).abs() < 1e-3 && (got[1] - want[1]).abs() < 1e-3,
            "{got:?} vs {want:?}"
        );
    }
}

#[test]
fn renders_every_real_file_that_loads() {
    let Some(mut paths) = real_files() else {
        return;
    };
    paths.retain(|p| {
        p.extension()
            .is_some_and(|e| e == "ply" || e == "gltf" || e == "glb")
    });
    let mut rendered = 0;
    for path in paths {
        let cloud = match splatgl::load::load_path(&path, &Default::default()) {
            Ok(l) => l.cloud,
            Err(e) => {
                eprintln!("skipping {}: does not load: {e}", path.display());
                continue;
            }
        };
        let c = common::frame_points(&cloud.positions, 0.9, 80, 60).expect("finite means");
        let img = render(&cloud, &c, &opts());
        assert!(
            img.pixels.iter().flatten().all(|v| v.is_finite()),
            "{}",
            path.display()
        );
        let covered = img.pixels.iter().filter(|p| p[3] > 0.05).count();
        assert!(covered > 0, "{}: nothing visible", path.display());
        eprintln!(
            "{}: {} splats, {covered} covered pixels",
            path.display(),
            cloud.len()
        );
        rendered += 1;
    }
    assert!(rendered > 0, "at least one real glTF/PLY file must load");
}

// Degenerate splats and cameras: a sane image, never a panic or a frame painted by one splat.

fn one_splat(scale: [f32; 3], rot: [f32; 4]) -> SplatCloud {
    let mut c = SplatCloud::new(0);
    c.push([0.0; 3], scale, rot, 0.9, &[[1.0, 0.0, 0.0]]);
    c
}

#[test]
fn end_on_needle_does_not_paint_the_frame() {
    // Long axis (z, 1e9) along the view ray: rounding can make Σ' negative definite.
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 48, 32);
    for k in 0..50 {
        let t = k as f32 * 0.001;
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, t, -t, 0.0).to_array();
        let img = render(
            &one_splat([0.01, 0.01, 1e9], q),
            &cam,
            &RenderOptions::default(),
        );
        let covered = img.pixels.iter().filter(|p| p[3] > 0.5).count();
        assert!(
            covered < img.pixels.len(),
            "rotation {k}: the whole frame is painted"
        );
    }
}

#[test]
fn degenerate_cameras_do_not_panic() {
    let cloud = one_splat([0.1; 3], [0.0, 0.0, 0.0, 1.0]);
    let mut cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 16, 16);
    for (w, h, fx, fy) in [
        (0, 0, 10.0, 10.0),
        (16, 16, 0.0, 0.0),
        (16, 16, f32::NAN, 1.0),
        (16, 16, -5.0, 5.0),
    ] {
        cam.width = w;
        cam.height = h;
        cam.fx = fx;
        cam.fy = fy;
        let img = render(&cloud, &cam, &RenderOptions::default());
        assert_eq!(img.pixels.len(), (w * h) as usize);
    }
}

/// Bit patterns of an image's pixels (f32 equality would let −0 = +0 and NaN ≠ NaN pass).
#[cfg(feature = "testing")] // used only by the path tests below
fn pixel_bits(img: &Image) -> Vec<u32> {
    img.pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

/// Renders with the former rules (3σ boxes, every splat projected and sorted), the
/// opacity-aware boxes alone, and the default (opacity-aware boxes, culled before the sort);
/// asserts the images are bit-identical and returns the tile entries of the first two.
#[cfg(feature = "testing")] // reference::render_with_path
fn same_image_by_every_path(what: &str, cloud: &SplatCloud, cam: &Camera) -> (usize, usize) {
    use splatgl::reference::{Path, PixelBox, render_with_path};
    let o = opts();
    let (full, full_stats) = render_with_path(cloud, cam, &o, Path::FULL);
    let extent_only = Path {
        extent: PixelBox::OpacityAware,
        cull: false,
    };
    let (boxed, boxed_stats) = render_with_path(cloud, cam, &o, extent_only);
    let (culled, culled_stats) = render_with_path(cloud, cam, &o, Path::default());
    assert_eq!(
        pixel_bits(&full),
        pixel_bits(&boxed),
        "{what}: opacity-aware boxes"
    );
    assert_eq!(
        pixel_bits(&full),
        pixel_bits(&culled),
        "{what}: culled before the sort"
    );
    assert_eq!(
        boxed_stats.visible, culled_stats.visible,
        "{what}: the cull keeps every splat whose box touches the image"
    );
    assert!(
        boxed_stats.tile_entries <= full_stats.tile_entries,
        "{what}"
    );
    (full_stats.tile_entries, boxed_stats.tile_entries)
}

/// The opacity-aware pixel box and the cull before the sort change no bit of the reference
/// image on the real scenes, from outside (framed) and from inside (about half the scene in
/// view), while the boxes really shrink and the cull really removes splats.
#[cfg(feature = "testing")] // reference::render_with_path
#[test]
fn opacity_aware_extent_and_cull_leave_real_scenes_bit_identical() {
    use splatgl::cull::{CullBounds, Frustum, visible_into};
    let Some(scenes) = common::large_real_scenes() else {
        return;
    };
    let mut checked = 0;
    for common::RealScene { name, cloud, views } in scenes {
        let [(_, framed), (_, inside)] = views;
        let bounds = CullBounds::new(&cloud);
        let mut ids = Vec::new();
        let frustum = Frustum::from_camera(&inside, 0.2);
        let seen = visible_into(&frustum, &cloud.positions, &bounds, &mut ids);
        assert!(seen < cloud.len(), "{name}: the inside view culls nothing");
        let (a, b) = same_image_by_every_path(&format!("{name} framed"), &cloud, &framed);
        let (c, d) = same_image_by_every_path(&format!("{name} inside"), &cloud, &inside);
        eprintln!(
            "{name}: {} splats, {seen} in the inside view; tile entries framed {a} → {b}, inside {c} → {d}",
            cloud.len()
        );
        checked += 1;
    }
    assert!(checked >= 3, "the real scenes must be there");
}

/// The same on synthetic worst cases: low opacities (small k), long needles (where the f32
/// rounding bound takes over), splats across the image border and the near plane.
#[cfg(feature = "testing")] // reference::render_with_path
#[test]
fn opacity_aware_extent_is_exact_for_needles_low_opacity_and_borders() {
    let mut cloud = random_cloud(3000, 1, 1.0, 77);
    let mut rng = common::Rng::new(5);
    for i in 0..cloud.len() {
        cloud.opacities[i] = [0.004, 0.0045, 0.01, 0.03, 0.2, 1.0, 7.0][i % 7];
        if i % 5 == 0 {
            let len = rng.range(0.5, 3.5);
            cloud.scales[i] = [len, 0.0005, 0.002];
        }
    }
    let cams = [
        scene_camera(96, 72),
        look_at_focal_px(
            Vec3::new(0.0, 0.0, 1.1),
            Vec3::new(2.0, 0.3, 0.0),
            60.0,
            96,
            72,
        ),
        look_at_focal_px(
            Vec3::new(0.3, 0.2, 0.0),
            Vec3::new(0.0, 0.0, -3.0),
            200.0,
            96,
            72,
        ),
    ];
    for (k, cam) in cams.iter().enumerate() {
        let (full, boxed) = same_image_by_every_path(&format!("camera {k}"), &cloud, cam);
        assert!(boxed < full, "camera {k}: boxes shrink ({full} → {boxed})");
    }
}
