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

/// The folder the tileset target works in: `ts/` holds `c.ply` (4 splats) and gets each
/// input as `ts/tileset.json`; beside `ts/` lies `secret.ply` (1001 splats), which no content
/// URI may reach.
fn tileset_dir() -> &'static Path {
    static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let root =
            std::env::temp_dir().join(format!("splatgl-fuzz-tileset-{}", std::process::id()));
        std::fs::create_dir_all(root.join("ts")).expect("fuzz folder");
        let cloud = |n: usize| {
            let mut c = splatgl::SplatCloud::with_capacity(0, n);
            for i in 0..n {
                c.push(
                    [i as f32 * 0.01, 0.0, 0.0],
                    [0.1; 3],
                    [0.0, 0.0, 0.0, 1.0],
                    0.5,
                    &[[0.0; 3]],
                );
            }
            splatgl::write::to_inria_ply(&c)
        };
        std::fs::write(root.join("ts/c.ply"), cloud(4)).expect("content");
        std::fs::write(root.join("secret.ply"), cloud(1001)).expect("secret");
        root
    })
}

/// A tileset's JSON and URIs: read, checked and its content loaded (every URI resolved under
/// the containment rule) without a panic, and no splat from outside its folder — every
/// content it can reach holds 4 splats, the one outside 1001. The input as a URI is also
/// resolved against an http tileset's URL: a URL it gives stays under the folder, with no
/// segment that decodes to `.` or `..` or holds a separator.
pub fn check_tileset(data: &[u8]) {
    let dir = tileset_dir();
    let path = dir.join("ts").join("tileset.json");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let r = splatgl::tiles::check(&path, &options(false), true);
    if let Some(n) = r.report.splat_count {
        assert_eq!(
            n % 4,
            0,
            "{n} splats: content from outside the tileset's folder"
        );
    }
    let Ok(uri) = std::str::from_utf8(data) else {
        return;
    };
    let base = "http://h:8/a/b/tileset.json";
    if let Ok(url) = splatgl::files::http::resolve(base, uri, false) {
        let rest = url
            .strip_prefix("http://h:8/a/b/")
            .unwrap_or_else(|| panic!("{uri:?} resolved outside the folder: {url}"));
        for seg in rest.split('/') {
            let decoded = percent_decoded(seg);
            assert!(
                decoded != b"."
                    && decoded != b".."
                    && !decoded.contains(&b'/')
                    && !decoded.contains(&b'\\'),
                "{uri:?} gave {url}: segment {seg:?}"
            );
        }
    }
}

/// `%XX` escapes decoded (as a server does).
fn percent_decoded(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && let (Some(h), Some(l)) = (
                b.get(i + 1).and_then(|c| hex(*c)),
                b.get(i + 2).and_then(|c| hex(*c)),
            )
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    out
}
