//! The default view of `splatgl render FILE` (no camera option) on the real third-party
//! files: the content covers at least a fifth of the frame and is upright.
//!
//! "Covers" is the on-screen extent: the bounding box of the pixels with alpha > 0.1 (a thin
//! object such as the guitar on its stand cannot fill a fifth of the *pixels* of any uncropped
//! view; what framing controls is how much of the frame the object spans). Rendered with the
//! reference backend at 64×48 to stay fast.

use crate::common;

use splatgl::image::Image;
use std::path::{Path, PathBuf};
use std::process::Command;

fn real(name: &str) -> PathBuf {
    common::root().join("../shared/data/real").join(name)
}

/// Every readable real file but the two whose content cannot fill a frame (below).
const FILES: [&str; 15] = [
    "supersplat_fruit_drops_minimal_sh3.ply",
    "mujoco_warp_fox_sh0.ply",
    "playcanvas_guitar.compressed.ply",
    "playcanvas_biker.compressed.ply",
    "playcanvas_biker_v4.spz",
    "sharpgltf_tower_legacy_spz_v2.glb",
    "cesium_native_spz2_basic.glb",
    "tiles_tools_UnitSH_legacy.glb",
    "splatapult_test_16splats_sh3.ply",
    "jsplat_unitCube-ascii.ply",
    "splat_transform_minimal.splat",
    "splat_transform_minimal.ksplat",
    "splat_transform_minimal-v2.spz",
    "splat_transform_minimal-v3.spz",
    "splat_transform_minimal-v4.spz",
];
// Not here, on purpose:
// - bevy_khr_conformance_matrix.{glb,gltf}: 15 test primitives at one point, one of them a
//   splat of scale (7.4, 0.05, 54.6); the eye must stay outside its 3σ box (tests/it/camera.rs,
//   framing_from_extents_keeps_the_eye_outside_every_splat), which puts the 14 others at ~3 %
//   of the frame.
// - bevy_khr_extensible_fallback.gltf: one splat of scale 1.7e-48, a point at any distance.

/// Renders `file` with the default view; returns the image (with alpha) and stderr.
fn render_default(file: &Path, dir: &Path) -> (Image, String) {
    let name = file.file_name().unwrap().to_str().unwrap();
    let out = dir.join(format!("{name}.pfm"));
    let o = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(["render", file.to_str().unwrap(), "--backend", "reference"])
        .args(["--width", "64", "--height", "48", "--alpha", "-f", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{name}: {err}");
    let mut img = Image::read(&out).unwrap();
    let alpha = Image::read(out.with_extension("alpha.pfm")).unwrap();
    for (p, a) in img.pixels.iter_mut().zip(&alpha.pixels) {
        p[3] = a[0];
    }
    (img, err)
}

/// The fraction of the frame that the bounding box of pixels with alpha > `t` spans.
fn covered(img: &Image, t: f32) -> f64 {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..img.height {
        for x in 0..img.width {
            if img.get(x, y)[3] > t {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    if x0 > x1 {
        return 0.0;
    }
    ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64 / (img.width * img.height) as f64
}

/// The up vector of the printed `camera: --look-at e,e,e,t,t,t,u,u,u` line.
fn printed_up(err: &str) -> [f32; 3] {
    let line = err
        .lines()
        .find_map(|l| l.strip_prefix("camera: --look-at "))
        .expect("camera line");
    let v: Vec<f32> = line
        .split_whitespace()
        .next()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    [v[6], v[7], v[8]]
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-cli-framing-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn default_framing_covers_a_fifth_of_the_frame_on_every_real_file() {
    let d = dir("cover");
    let mut report = Vec::new();
    for name in FILES {
        let (img, _) = render_default(&real(name), &d);
        let c = covered(&img, 0.1);
        report.push(format!("{name}: {c:.3}"));
    }
    let failed: Vec<&String> = report
        .iter()
        .filter(|l| l.rsplit(' ').next().unwrap().parse::<f64>().unwrap() < 0.2)
        .collect();
    assert!(
        failed.is_empty(),
        "covered below 0.2: {failed:?}\nall: {report:#?}"
    );
    std::fs::remove_dir_all(&d).ok();
}

/// Mean rows of the jsplat cube's green pixels and of its dark ones (un-premultiplied green of
/// the opaque-enough pixels above 0.6 or below 0.4).
fn green_and_dark_rows(img: &Image) -> (f64, f64) {
    let (mut green, mut dark) = ((0.0, 0), (0.0, 0));
    for y in 0..img.height {
        for x in 0..img.width {
            let p = img.get(x, y);
            if p[3] < 0.5 {
                continue;
            }
            let g = p[1] / p[3];
            let bin = if g > 0.6 {
                &mut green
            } else if g < 0.4 {
                &mut dark
            } else {
                continue;
            };
            bin.0 += y as f64;
            bin.1 += 1;
        }
    }
    assert!(green.1 > 0 && dark.1 > 0, "{green:?} {dark:?}");
    (green.0 / green.1 as f64, dark.0 / dark.1 as f64)
}

/// The jsplat cube's corners are coloured by position (red = x/10, green = −y/10, blue =
/// −z/10): with its −Y up (PLY), the green corners (y = −10) are at the top of the image.
/// The Z-up fox is framed with +Z up, the COLMAP-axis biker with −Y up.
#[test]
fn default_framing_is_upright() {
    let d = dir("upright");
    let (img, err) = render_default(&real("jsplat_unitCube-ascii.ply"), &d);
    let (g, k) = green_and_dark_rows(&img);
    assert!(
        g + 4.0 < k,
        "green corners (y = −10) at mean row {g}, the others at {k}"
    );
    let up = printed_up(&err);
    assert!(up[1] < -0.9, "cube up {up:?}");
    let (_, err) = render_default(&real("mujoco_warp_fox_sh0.ply"), &d);
    let up = printed_up(&err);
    assert!(up[2] > 0.9, "fox up {up:?}: {err}");
    let (_, err) = render_default(&real("playcanvas_biker.compressed.ply"), &d);
    let up = printed_up(&err);
    assert!(up[1] < -0.9, "biker up {up:?}: {err}");
    std::fs::remove_dir_all(&d).ok();
}

/// `convert FILE.ply OUT.glb` (`--up auto`) then `render OUT.glb`: the glTF is +Y up, framed
/// with +Y up, and shows the same upright picture as `render FILE.ply` (≥ 60 dB): the cube's
/// green corners stay at the top, the −Y-up biker and the +Z-up fox come out upright.
#[test]
fn converted_to_gltf_the_real_files_stay_upright() {
    let d = dir("converted");
    for name in [
        "jsplat_unitCube-ascii.ply",
        "playcanvas_biker.compressed.ply",
        "mujoco_warp_fox_sh0.ply",
    ] {
        let glb = d.join(format!("{name}.glb"));
        let o = Command::new(env!("CARGO_BIN_EXE_splatgl"))
            .args([
                "convert",
                real(name).to_str().unwrap(),
                glb.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (from_ply, _) = render_default(&real(name), &d);
        let (from_glb, err) = render_default(&glb, &d);
        let up = printed_up(&err);
        assert!(up[1] > 0.9, "{name} converted: up {up:?}: {err}");
        let psnr = splatgl::compare::compare(&from_ply, &from_glb, 1.0 / 255.0)
            .unwrap()
            .psnr;
        assert!(
            psnr >= 60.0,
            "{name}: converted renders {psnr:.1} dB from the PLY"
        );
        if name.starts_with("jsplat") {
            let (g, k) = green_and_dark_rows(&from_glb);
            assert!(
                g + 4.0 < k,
                "converted cube: green at row {g}, others at {k}"
            );
        }
    }
    std::fs::remove_dir_all(&d).ok();
}
