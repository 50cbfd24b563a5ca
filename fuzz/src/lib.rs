//! Shared checks of the fuzz targets: the loader contract on every successful load, not only
//! "no panic".
//!
//! On success a load must return a cloud that passes `SplatCloud::validate` (consistent
//! lengths, every value finite, scales with a finite square, unit quaternions, opacity in
//! [0, 1]) within `limits.max_splats`, cameras with finite values that make valid cameras or
//! precise errors, and `validate` must agree on the splat count. Hangs (> 1 s per input) and
//! allocations over 1 GiB are libFuzzer's `-timeout=1 -rss_limit_mb=1024` (`scripts/fuzz.sh`).

pub mod gltf_edit;

use splatgl::camera::Camera;
use splatgl::load::validate::validate_bytes;
use splatgl::load::{Format, LoadOptions, Scene, load_bytes};
use std::path::Path;
use std::sync::Arc;

/// Options of every target: default limits, and a resolver that refuses external buffers, so
/// no input can make the fuzzer read files.
pub fn options(strict: bool) -> LoadOptions {
    LoadOptions {
        strict,
        resolver: Some(Arc::new(|uri: &str| {
            Err(format!("the fuzzer serves no external buffers ({uri:?})"))
        })),
        ..LoadOptions::default()
    }
}

/// Loads and validates `data` as the file `name`, asserting the contract on success.
pub fn check_file(data: &[u8], name: &str) {
    check_with(data, name, &options(false));
}

/// [`check_file`] with given options.
pub fn check_with(data: &[u8], name: &str, opts: &LoadOptions) {
    let path = Path::new(name);
    let loaded = load_bytes(data, Some(path), opts);
    let report = validate_bytes(data, Some(path), opts);
    if let Ok(scene) = &loaded {
        check_scene(scene, opts);
        if matches!(scene.report.format, Format::Gltf | Format::Glb) {
            assert_eq!(
                report.splat_count,
                Some(scene.cloud.len()),
                "validate and load disagree on the splat count"
            );
        }
    }
}

/// The contract of a loaded scene.
pub fn check_scene(scene: &Scene, opts: &LoadOptions) {
    let c = &scene.cloud;
    if let Err(e) = c.validate() {
        panic!("loader contract broken: {e}");
    }
    assert!(c.len() as u64 <= opts.limits.max_splats, "max_splats");
    assert!(c.bounds().is_some() || c.is_empty());
    for g in &scene.cameras {
        assert!(
            g.node_to_world.is_finite(),
            "camera transform {:?}",
            g.node_to_world
        );
        assert!(g.yfov.is_finite() && g.znear.is_finite(), "{g:?}");
        assert!(g.aspect_ratio.is_none_or(f32::is_finite), "{g:?}");
        assert!(g.zfar.is_none_or(f32::is_finite), "{g:?}");
        if let Ok(cam) = Camera::from_gltf(g, 64, 48) {
            check_camera(&cam);
        }
    }
    for f in &scene.report.findings {
        assert!(
            !f.blocks_loading,
            "a blocking finding in a successful load: {f}"
        );
    }
}

/// A camera the renderers can use.
pub fn check_camera(cam: &Camera) {
    assert!(cam.width > 0 && cam.height > 0);
    assert!(
        [cam.fx, cam.fy].iter().all(|f| f.is_finite() && *f > 0.0),
        "{cam:?}"
    );
    assert!(cam.cx.is_finite() && cam.cy.is_finite(), "{cam:?}");
    assert!(
        cam.near.is_finite() && cam.near > 0.0 && cam.far > cam.near,
        "{cam:?}"
    );
    assert!(cam.world_to_camera.is_finite(), "{cam:?}");
}

/// `cameras.json` text: parsed entries are finite and each makes a valid camera or an error.
pub fn check_cameras_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(list) = splatgl::camera::parse_cameras_json(text) else {
        return;
    };
    for e in &list {
        let values = e.position.iter().chain(e.rotation.iter().flatten());
        let values = values
            .chain([&e.fx, &e.fy])
            .chain(e.cx.iter())
            .chain(e.cy.iter());
        for v in values {
            assert!(v.is_finite(), "{e:?}");
        }
        if let Ok(cam) = Camera::from_3dgs(e) {
            check_camera(&cam);
        }
    }
}
