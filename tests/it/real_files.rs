//! Every file in ../shared/data/real/ loads with the right count and SH degree (glTF, also
//! SPZ-compressed, PLY, SPZ, .splat, .ksplat), with the warnings it deserves.

use crate::common;
use common::{real, real_files};
use splatgl::load::validate::{Status, validate_path};
use splatgl::load::{LoadError, LoadOptions, ScaleSeen, load_path};

fn load_ok(name: &str, count: usize, degree: u8) -> Option<splatgl::load::Scene> {
    let path = real(name)?;
    let l = load_path(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(l.cloud.len(), count, "{name}: splat count");
    assert_eq!(l.cloud.sh_degree, degree, "{name}: SH degree");
    assert!(l.cloud.check_lengths().is_ok());
    for q in &l.cloud.rotations {
        let n: f32 = q.iter().map(|v| v * v).sum();
        assert!((n - 1.0).abs() < 1e-5, "{name}: quaternions are normalised");
    }
    assert!(l.cloud.opacities.iter().all(|o| (0.0..=1.0).contains(o)));
    assert!(
        l.cloud
            .scales
            .iter()
            .flatten()
            .all(|s| *s >= 0.0 && s.is_finite())
    );
    Some(l)
}

fn has_warning(l: &splatgl::load::Scene, needle: &str) -> bool {
    l.report.warning_lines().iter().any(|w| w.contains(needle))
}

/// Whether an `info`-level note (a normal trainer artefact) mentions `needle`.
fn has_note(l: &splatgl::load::Scene, needle: &str) -> bool {
    l.report.note_lines().iter().any(|w| w.contains(needle))
}

#[test]
fn inria_ply_files() {
    if let Some(l) = load_ok("supersplat_fruit_drops_minimal_sh3.ply", 4721, 3) {
        assert!(
            l.report.non_unit_quaternions > 4000,
            "|q| ranges 0.60..1.93"
        );
        assert!(has_note(&l, "not unit length"));
        assert!(!has_warning(&l, "not unit length"), "a note, not a warning");
    }
    if let Some(l) = load_ok("mujoco_warp_fox_sh0.ply", 50_000, 0) {
        // +inf logits become opacity 1.
        assert!(l.cloud.opacities.contains(&1.0));
    }
    if let Some(l) = load_ok("splatapult_test_16splats_sh3.ply", 16, 3) {
        // log scale -2.996 → 0.05; logit 100 → 1.
        assert!((l.cloud.scales[0][0] - (-2.996f32).exp()).abs() < 1e-4);
        assert!((l.cloud.opacities[0] - 1.0).abs() < 1e-6);
    }
    if let Some(l) = load_ok("jsplat_unitCube-ascii.ply", 20, 0) {
        let b = l.cloud.bounds().unwrap();
        let extent: Vec<f32> = (0..3).map(|i| b.max[i] - b.min[i]).collect();
        assert!(
            extent.iter().all(|e| (e - 10.0).abs() < 1e-3),
            "10-unit cube: {extent:?}"
        );
    }
}

#[test]
fn playcanvas_compressed_ply() {
    for (name, count) in [
        ("playcanvas_guitar.compressed.ply", 90_854),
        ("playcanvas_biker.compressed.ply", 152_746),
    ] {
        let Some(l) = load_ok(name, count, 0) else {
            continue;
        };
        assert!(has_warning(&l, "compressed PLY"));
        let b = l.cloud.bounds().unwrap();
        assert!(b.diagonal() > 0.1 && b.diagonal() < 100.0, "{b:?}");
    }
    // Truncating the file is a precise error, not a panic.
    if let Some(p) = real("playcanvas_guitar.compressed.ply") {
        let mut bytes = std::fs::read(&p).unwrap();
        bytes.truncate(bytes.len() - 100);
        let e = splatgl::load::load_bytes(&bytes, Some(&p), &LoadOptions::default()).unwrap_err();
        assert!(
            matches!(e, LoadError::Ply { .. }) && e.to_string().contains("vertex"),
            "{e}"
        );
    }
}

#[test]
fn bevy_conformance_matrix_legacy_draft() {
    for name in [
        "bevy_khr_conformance_matrix.glb",
        "bevy_khr_conformance_matrix.gltf",
    ] {
        let Some(l) = load_ok(name, 15, 3) else {
            continue;
        };
        assert_eq!(l.report.scale_space, Some(ScaleSeen::Log));
        assert!(has_warning(&l, "legacy draft: log-space scale"), "{name}");
        assert!(has_warning(&l, "different SH degrees"), "{name}");
        // Every component type decodes to the same splat: position (1,2,3) everywhere.
        assert!(l.cloud.positions.iter().all(|p| *p == [1.0, 2.0, 3.0]));
        // rotation f32 / i8 norm / i16 norm decode to the same quaternion.
        assert!(l.cloud.rotations.iter().all(|q| *q == [1.0, 0.0, 0.0, 0.0]));
        // opacity f32 / u8 norm / u16 norm (meshes 8..=10; mesh 8 stores 0.75).
        assert!((l.cloud.opacities[9] - 64.0 / 255.0).abs() < 1e-6);
        assert!((l.cloud.opacities[10] - 0.25).abs() < 1.0 / 65535.0);
        let v = validate_path(&real(name).unwrap(), &LoadOptions::default());
        assert_eq!(v.status(), Status::Invalid, "legacy scale violates the RC");
    }
}

#[test]
fn bevy_extensible_fallback_unknown_values() {
    let Some(l) = load_ok("bevy_khr_extensible_fallback.gltf", 1, 0) else {
        return;
    };
    assert!(has_warning(&l, "unknown value \"customShape\""));
    assert!(has_warning(&l, "unknown value \"custom_space_display\""));
    assert!(has_warning(&l, "derived from COLOR_0"));
    assert_eq!(
        l.cloud.meta.kernel,
        splatgl::cloud::Known::Unknown("customShape".into())
    );
}

/// The SPZ-compressed glTF files load with the counts and degrees of SOURCES.md: the two
/// legacy `KHR_spz_gaussian_splats_compression` files with a "legacy extension" warning, the
/// `KHR_gaussian_splatting_compression_spz_2` one with its missing `kernel`/`colorSpace` among
/// the warnings (errors in `validate`, below) and the container in the report.
#[test]
fn spz_compressed_gltf_files_load() {
    for (name, count, degree, version) in [
        ("sharpgltf_tower_legacy_spz_v2.glb", 73_172, 3, "2"),
        ("tiles_tools_UnitSH_legacy.glb", 9, 3, "3"),
    ] {
        let Some(l) = load_ok(name, count, degree) else {
            continue;
        };
        assert!(
            has_warning(
                &l,
                "legacy extension \"KHR_spz_gaussian_splats_compression\""
            ),
            "{name}: {:?}",
            l.report.warning_lines()
        );
        let d = l.report.details.expect("container details");
        assert_eq!(
            (d.container, d.version.as_str(), d.gltf_extension),
            ("spz", version, Some("KHR_spz_gaussian_splats_compression")),
            "{name}"
        );
    }
    if let Some(l) = load_ok("cesium_native_spz2_basic.glb", 1, 0) {
        for needle in ["'kernel' is missing", "'colorSpace' is missing"] {
            assert!(has_warning(&l, needle), "{needle}");
        }
        assert!(!has_warning(&l, "not supported"));
        let d = l.report.details.as_ref().expect("container details");
        assert_eq!(
            d.gltf_extension,
            Some("KHR_gaussian_splatting_compression_spz_2")
        );
        // The payload stores (1, 2, 3), and so do POSITION's min/max: its writer put glTF-axis
        // numbers in it, without the RUB → LUF conversion the extension's text requires, and
        // cesium-native's own test expects (1, 2, 3) back. Read as stored (auto follows the
        // bounds); the node matrix (column-major [1,0,0,0, 0,0,−1,0, 0,1,0,0, 0,0,0,1]) maps
        // (x, y, z) to (x, z, −y).
        assert_eq!(l.cloud.positions[0], [1.0, 3.0, -2.0]);
        assert!(has_warning(&l, "read as stored"));
        let rub = splatgl::load::LoadOptions {
            spz_axes: splatgl::load::spz::SpzAxes::Rub,
            ..Default::default()
        };
        let r = load_path(real("cesium_native_spz2_basic.glb").unwrap(), &rub).unwrap();
        assert_eq!(r.cloud.positions[0], [-1.0, -3.0, -2.0]);
        assert!(has_warning(&r, "--spz-axes auto or raw"));
    }
}

/// The legacy tower, read as CesiumJS reads it (as stored), stands upright after its node's
/// Z-up → Y-up matrix: the top quarter of its height (the antenna platform) spreads more than
/// twice as wide around its axis as the bottom quarter (the lattice foot). Converted RUB → LUF,
/// it would stand on its antennas.
#[test]
fn legacy_tower_stands_upright() {
    let spread = |l: &splatgl::load::Scene| -> (f32, f32) {
        let p = &l.cloud.positions;
        let mut ys: Vec<f32> = p.iter().map(|v| v[1]).collect();
        ys.sort_by(f32::total_cmp);
        let (lo, hi) = (ys[ys.len() / 100], ys[ys.len() * 99 / 100]);
        let q = (hi - lo) / 4.0;
        let radius = |a: f32, b: f32| {
            let sel: Vec<_> = p.iter().filter(|v| v[1] >= a && v[1] < b).collect();
            let n = sel.len() as f32;
            let (cx, cz) = (
                sel.iter().map(|v| v[0]).sum::<f32>() / n,
                sel.iter().map(|v| v[2]).sum::<f32>() / n,
            );
            sel.iter()
                .map(|v| (v[0] - cx).hypot(v[2] - cz))
                .sum::<f32>()
                / n
        };
        (radius(lo, lo + q), radius(hi - q, hi))
    };
    let Some(l) = load_ok("sharpgltf_tower_legacy_spz_v2.glb", 73_172, 3) else {
        return;
    };
    let (bottom, top) = spread(&l);
    assert!(top > 2.0 * bottom, "bottom {bottom}, top {top}");
    let rub = LoadOptions {
        spz_axes: splatgl::load::spz::SpzAxes::Rub,
        ..Default::default()
    };
    let r = load_path(real("sharpgltf_tower_legacy_spz_v2.glb").unwrap(), &rub).unwrap();
    let (bottom, top) = spread(&r);
    assert!(bottom > 2.0 * top, "converted: bottom {bottom}, top {top}");
}

/// `validate` reads the compressed file like any other: it is invalid for its missing
/// `kernel`/`colorSpace` only, not for being compressed.
#[test]
fn validate_flags_cesium_profile() {
    let Some(p) = real("cesium_native_spz2_basic.glb") else {
        return;
    };
    let r = validate_path(&p, &LoadOptions::default());
    assert_eq!(r.status(), Status::Invalid);
    assert_eq!(r.splat_count, Some(1));
    let errors: Vec<String> = r
        .findings
        .iter()
        .filter(|f| f.severity == splatgl::load::Severity::Error)
        .map(|f| format!("{} {}", f.path, f.message))
        .collect();
    assert_eq!(errors.len(), 2, "{errors:#?}");
    for needle in ["'kernel' is missing", "'colorSpace' is missing"] {
        assert!(
            errors.iter().any(|m| m.contains(needle)),
            "{needle} in {errors:#?}"
        );
    }
    for legacy in [
        "sharpgltf_tower_legacy_spz_v2.glb",
        "tiles_tools_UnitSH_legacy.glb",
    ] {
        let Some(p) = real(legacy) else { continue };
        let r = validate_path(&p, &LoadOptions::default());
        assert_eq!(r.status(), Status::Valid, "{legacy}: {:#?}", r.findings);
    }
}

#[test]
fn bevy_camera_node() {
    let Some(p) = real("bevy_khr_conformance_matrix.gltf") else {
        return;
    };
    let cams = load_path(&p, &LoadOptions::default()).unwrap().cameras;
    assert_eq!(cams.len(), 1);
    assert_eq!(
        cams[0].node_to_world.w_axis.truncate(),
        glam::Vec3::new(4.0, 5.0, 6.0)
    );
    let cam = splatgl::camera::Camera::from_gltf(&cams[0], 64, 48).unwrap();
    assert!((cam.eye() - glam::Vec3::new(4.0, 5.0, 6.0)).length() < 1e-5);
    // glTF cameras look down −Z: a point straight ahead projects to the centre.
    let (px, _) = cam.project(glam::Vec3::new(4.0, 5.0, 0.0)).unwrap();
    assert!((px - glam::Vec2::new(32.0, 24.0)).length() < 1e-3, "{px}");
}

/// SPZ (v2 raw, v2, v3, v4), `.splat` and `.ksplat` used to be "not supported yet" errors;
/// they load now, with the counts and degrees of SOURCES.md (details: tests/it/formats.rs).
#[test]
fn spz_splat_and_ksplat_files_load() {
    for (name, count) in [
        ("playcanvas_biker_v4.spz", 152_746),
        ("splat_transform_minimal-raw.spz", 4),
        ("splat_transform_minimal-v2.spz", 4),
        ("splat_transform_minimal-v3.spz", 4),
        ("splat_transform_minimal-v4.spz", 4),
        ("splat_transform_minimal.splat", 4),
        ("splat_transform_minimal.ksplat", 4),
    ] {
        load_ok(name, count, 0);
    }
}

/// `validate` and `load` read a file with the same readers: for every real file that loads,
/// validate lists exactly the findings of the load report, in the same order.
#[test]
fn validate_lists_the_findings_of_the_load_report() {
    let Some(paths) = real_files() else { return };
    let mut compared = 0;
    for p in paths {
        let Ok(l) = load_path(&p, &LoadOptions::default()) else {
            continue;
        };
        let v = validate_path(&p, &LoadOptions::default());
        assert_eq!(v.findings, l.report.findings, "{}", p.display());
        assert_eq!(v.splat_count, Some(l.cloud.len()), "{}", p.display());
        compared += 1;
    }
    // SOURCES.md lists 19 splat files, and splatgl reads them all.
    assert!(compared >= 19, "only {compared} real files load");
}
