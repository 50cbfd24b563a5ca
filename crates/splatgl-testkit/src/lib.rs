//! splatgl's shared test helpers, one crate for every member's test binary: the seeded
//! generator and random clouds (from `splatgl::synthetic`), the real-data folder, cameras and
//! single-colour SH. The GL helpers (headless renderer, scores, error bounds) are in `gl`
//! (feature `gl`); test-side encoders of the packed formats in [`packed`]; a local HTTP server
//! in `http`. Running the `splatgl` binary is the CLI crate's test helper (it needs the binary's
//! path, which cargo gives that crate's tests alone).

use glam::Vec3;
use splatgl::camera::Camera;
use std::path::{Path, PathBuf};

pub use splatgl::synthetic::{Rng, random_cloud};

#[cfg(feature = "gl")]
pub mod gl;
#[cfg(feature = "http")]
pub mod http;
pub mod lod;
pub mod packed;

/// Reports that the calling test cannot run here because `what` is missing. Under
/// `SPLATGL_REQUIRE=all` (`.ci/run` sets it) that is a failure naming what is missing, so a
/// machine where EGL, the real data or an npm tool broke cannot pass by skipping; otherwise a
/// note on stderr and a line in `target/tmp/skipped-tests.txt`, which `scripts/test.sh`
/// prints at the end. The caller returns after it.
pub fn skip(what: &str) {
    let test = format!(
        "{}::{}",
        test_binary(),
        std::thread::current().name().unwrap_or("?")
    );
    if std::env::var("SPLATGL_REQUIRE").is_ok_and(|v| v == "all") {
        panic!("SPLATGL_REQUIRE=all, but {test} cannot run: {what}");
    }
    eprintln!("SKIPPED {test}: {what}");
    let list = target_tmp().join("skipped-tests.txt");
    let line = format!("{test}: {}\n", what.replace('\n', " "));
    let _ = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(list)
        .and_then(|mut f| std::io::Write::write_all(&mut f, line.as_bytes()));
}

/// The repository's root (the workspace and the `splatgl` package).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The running test binary's name without cargo's hash (`it`, `sort`, …), and its package's
/// folder under `target/`: the test binaries of every member land in `target/<profile>/deps`.
fn test_binary() -> String {
    let exe = std::env::current_exe().unwrap_or_default();
    let stem = exe.file_stem().and_then(|s| s.to_str()).unwrap_or("?");
    stem.rsplit_once('-')
        .map_or(stem, |(name, _)| name)
        .to_owned()
}

/// `target/tmp` (cargo's `CARGO_TARGET_TMPDIR` for integration tests), found from the running
/// test binary (`target/<profile>/deps/<test>`), so that it follows `CARGO_TARGET_DIR`.
pub fn target_tmp() -> PathBuf {
    let exe = std::env::current_exe().unwrap_or_default();
    let target = exe.ancestors().nth(3).map(Path::to_path_buf);
    let dir = target.unwrap_or_else(|| root().join("target")).join("tmp");
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// The shared real-data folder (`../shared/data/real`, beside the checkout).
fn real_dir() -> PathBuf {
    root().join("../shared/data/real")
}

/// Path of a file in the shared real-data folder (None, with a note, if absent).
pub fn real(name: &str) -> Option<PathBuf> {
    let p = real_dir().join(name);
    if p.exists() {
        Some(p)
    } else {
        skip(&format!("{} not found", p.display()));
        None
    }
}

/// Every file in the shared real-data folder, sorted by name (None, with a note, if the folder
/// is absent).
pub fn real_files() -> Option<Vec<PathBuf>> {
    let dir = real_dir();
    let Ok(entries) = std::fs::read_dir(&dir) else {
        skip(&format!("{} not found", dir.display()));
        return None;
    };
    let mut paths: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    Some(paths)
}

/// A real scene of at least 1000 splats with its two 160×120 test views: `framed` (the whole
/// scene from the front in PLY axes, −Y up) and `inside` (from its centre, looking sideways:
/// roughly half of it in view).
pub struct RealScene {
    /// The file name.
    pub name: String,
    /// Its splats.
    pub cloud: splatgl::SplatCloud,
    /// `framed` and `inside`.
    pub views: [(&'static str, Camera); 2],
}

/// Every real file that loads with at least 1000 splats, as a [`RealScene`] (None, with a
/// note, when the real-data folder is absent).
pub fn large_real_scenes() -> Option<Vec<RealScene>> {
    let mut out = Vec::new();
    for path in real_files()? {
        let Ok(l) = splatgl::load::load_path(&path, &Default::default()) else {
            continue;
        };
        let cloud = l.cloud;
        if cloud.len() < 1000 {
            continue;
        }
        let (fwd, up) = (Vec3::new(0.0, 0.35, -1.0), -Vec3::Y);
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let framed = frame_points_along(&cloud.positions, fwd, up, 0.9, 160, 120)
            .unwrap_or_else(|| panic!("{name}: no camera frames it"));
        let centre = Vec3::from_array(cloud.bounds().unwrap().center());
        let inside = Camera::look_at(centre, centre + Vec3::X, up, 1.2, 160, 120);
        out.push(RealScene {
            name,
            cloud,
            views: [("framed", framed), ("inside", inside)],
        });
    }
    Some(out)
}

/// A camera at `eye` looking at `target` (up +Y) with vertical field of view `fov_deg` degrees.
pub fn look_at_fov_deg(eye: Vec3, target: Vec3, fov_deg: f32, w: u32, h: u32) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, fov_deg.to_radians(), w, h)
}

/// A camera at `eye` looking at `target` (up +Y) with vertical focal length `focal_px` pixels.
pub fn look_at_focal_px(eye: Vec3, target: Vec3, focal_px: f32, w: u32, h: u32) -> Camera {
    let fov = 2.0 * (0.5 * h as f32 / focal_px).atan();
    Camera::look_at(eye, target, Vec3::Y, fov, w, h)
}

/// SH coefficients of degree `degree` showing the constant colour `rgb` (higher bands zero).
pub fn sh_for(rgb: [f32; 3], degree: u8) -> Vec<[f32; 3]> {
    let mut sh = vec![[0.0; 3]; splatgl::cloud::sh_coeff_count(degree)];
    sh[0] = rgb.map(|c| splatgl::sh::dc_from_color(c as f64));
    sh
}

/// A camera looking along `forward` (`up` roughly up) that frames the box of `points` by the
/// library's one framing rule (`Camera::frame_extent_along` of `Extent::of_points`).
pub fn frame_points_along(
    points: &[[f32; 3]],
    forward: Vec3,
    up: Vec3,
    fov_y: f32,
    w: u32,
    h: u32,
) -> Option<Camera> {
    let extent = splatgl::camera::Extent::of_points(points)?;
    Camera::frame_extent_along(&extent, forward, up, fov_y, w, h)
}

/// [`frame_points_along`] in glTF's convention: from +Z slightly above, +Y up.
pub fn frame_points(points: &[[f32; 3]], fov_y: f32, w: u32, h: u32) -> Option<Camera> {
    frame_points_along(points, Vec3::new(0.0, -0.35, -1.0), Vec3::Y, fov_y, w, h)
}

/// A fresh, empty folder `splatgl-KIND-PID-NAME` in the temporary folder, for one test.
pub fn fresh_dir(kind: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-{kind}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The splat wall the C legacy host (`examples/c/legacy_host.c`) expects, as an INRIA PLY
/// written to `path`: opaque splats at z = 0 over x ∈ [−1, 1], y ∈ [−0.6, 0.6].
pub fn write_legacy_host_wall(path: &Path) {
    let mut cloud = splatgl::SplatCloud::new(0);
    for j in 0..16 {
        for i in 0..24 {
            let (x, y) = (-1.0 + 2.0 * i as f32 / 23.0, -0.6 + 1.2 * j as f32 / 15.0);
            let dc = [1.2, -0.4, 0.8];
            cloud.push(
                [x, y, 0.0],
                [0.05, 0.05, 0.01],
                [0.0, 0.0, 0.0, 1.0],
                0.95,
                &[dc],
            );
        }
    }
    std::fs::write(path, splatgl::write::to_inria_ply(&cloud)).unwrap();
}
