//! splatgl's web build (`crates/splatgl-web`, `web/dist` from `./scripts/web.sh build`) in
//! headless Chromium (SwiftShader WebGL2): the same renderer compiled to wasm32 renders the
//! default, fruit and biker scenes like the native reference, passes the generated
//! conformance suite, its viewer page shows a malformed file's error and keeps working, and
//! the npm package packs, type-checks and draws its example.
//!
//! Needs `web/dist`, node and chromium; without them the tests skip, which fails under
//! `SPLATGL_REQUIRE=all` (the slow lane of `scripts/test.sh` builds `web/dist` first).

use std::path::{Path, PathBuf};
use std::process::Command;

use splatgl::image::Image;

use crate::common;
use common::third_party::{clean, generate, grade, missing_node_or_browser, rc_assets, tmp};

/// Why the web build cannot run here, if it cannot.
fn missing() -> Option<String> {
    let wasm = common::root().join("web/dist/pkg/splatgl_web_bg.wasm");
    if !wasm.is_file() {
        return Some(format!(
            "{} not built (./scripts/web.sh build)",
            wasm.display()
        ));
    }
    missing_node_or_browser()
}

/// `node scripts/web/NAME args…`: its stderr, after checking it succeeded.
fn node(script: &str, args: &[&str]) -> String {
    let out = Command::new("node")
        .arg(common::root().join("scripts/web").join(script))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{script} {args:?}: {err}");
    err
}

/// The web build's and the native reference's image of `scene` (`None`: the default
/// scene) from the default view at 320 × 240.
fn both(scene: Option<&Path>, dir: &Path) -> (Image, Image) {
    let name = scene.map_or("default".into(), |s| {
        s.file_name().unwrap().to_string_lossy().into_owned()
    });
    let (web, native) = (
        dir.join(format!("{name}.web.png")),
        dir.join(format!("{name}.native.png")),
    );
    let input = scene.map_or("--default".to_string(), |s| s.display().to_string());
    node(
        "render.mjs",
        &[
            &input,
            web.to_str().unwrap(),
            "--width",
            "320",
            "--height",
            "240",
        ],
    );
    let mut args = vec!["render"];
    let s = scene.map(|s| s.display().to_string());
    if let Some(s) = &s {
        args.push(s);
    }
    args.extend([
        "--backend",
        "reference",
        "--width",
        "320",
        "--height",
        "240",
        "-f",
        "-o",
        native.to_str().unwrap(),
    ]);
    let r = common::cli::run(&args);
    assert_eq!(r.code, 0, "{}", r.all());
    (Image::read(&web).unwrap(), Image::read(&native).unwrap())
}

#[test]
fn web_build_renders_the_default_fruit_and_biker_scenes_like_the_native_reference() {
    if let Some(why) = missing() {
        common::skip(&why);
        return;
    }
    let real: Option<Vec<PathBuf>> = [
        "supersplat_fruit_drops_minimal_sh3.ply",
        "playcanvas_biker.compressed.ply",
    ]
    .into_iter()
    .map(common::real)
    .collect();
    let Some(real) = real else { return };
    let dir = tmp("web-render");
    std::fs::create_dir_all(&dir).unwrap();
    let scenes = [None, Some(real[0].as_path()), Some(real[1].as_path())];
    for scene in scenes {
        let (web, native) = both(scene, &dir);
        let db = splatgl::compare::compare(&web, &native, 1.0 / 255.0)
            .unwrap()
            .psnr;
        let name = scene.map_or("default scene".into(), |s| s.display().to_string());
        eprintln!("{name}: web build vs native reference {db:.1} dB");
        assert!(db >= 40.0, "{name}: {db:.1} dB < 40");
    }
    clean(&[&dir]);
}

#[test]
fn web_build_passes_every_required_asset_of_the_generated_suite() {
    if let Some(why) = missing() {
        common::skip(&why);
        return;
    }
    let (suite, images, report) = (generate("web-suite"), tmp("web"), tmp("web-report"));
    let out = Command::new("node")
        .arg(common::root().join("scripts/conformance/splatgl-web.mjs"))
        .args([&suite, &images])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "splatgl-web.mjs: {err}");
    eprintln!("{}", err.lines().next().unwrap_or(""));
    let (code, json) = grade(&suite, &images, &report, &[]);
    let failed: Vec<String> = rc_assets(&json)
        .filter(|a| a["optional"] != true && a["pass"] != true)
        .map(|a| format!("{}: {}", a["name"], a["psnr"]))
        .collect();
    assert!(failed.is_empty(), "required assets not passed: {failed:?}");
    assert_eq!(code, 0, "conformance run exit code");
    clean(&[&suite, &images, &report]);
}

#[test]
fn web_viewer_shows_a_malformed_or_oversized_files_error_and_keeps_drawing() {
    if let Some(why) = missing() {
        common::skip(&why);
        return;
    }
    let Some(good) = common::real("supersplat_fruit_drops_minimal_sh3.ply") else {
        return;
    };
    let err = node("viewer-check.mjs", &[good.to_str().unwrap()]);
    let line = err
        .lines()
        .find_map(|l| l.strip_prefix("page: RESULT "))
        .unwrap_or_else(|| panic!("no RESULT line: {err}"));
    let r: serde_json::Value = serde_json::from_str(line).unwrap();
    eprintln!("{r:#}");
    assert!(r.get("failure").is_none(), "{r}");
    let shown = r["malformedError"].as_str().unwrap();
    assert!(
        shown.contains("malformed.ply") && shown.contains("vertex"),
        "the malformed file's error as shown: {shown:?}"
    );
    assert_eq!(r["errorAfterGood"], "", "{r}");
    assert_eq!(r["splats"], 4721, "{r}");
    assert!(r["litPixels"].as_u64().unwrap() > 1000, "{r}");
    // Over the size limit: refused by name, the previous scene kept and drawn.
    let over = r["overLimitError"].as_str().unwrap();
    assert!(over.contains("limit of 1000 bytes"), "{r}");
    assert_eq!(r["splatsAfterOverLimit"], 4721, "{r}");
    assert!(r["litPixelsAfterOverLimit"].as_u64().unwrap() > 1000, "{r}");
    let fetched = r["fetchOverLimitError"].as_str().unwrap();
    assert!(fetched.contains("limit of 1000 bytes"), "{r}");
}

#[test]
fn web_package_packs_type_checks_and_its_example_renders() {
    if let Some(why) = missing() {
        common::skip(&why);
        return;
    }
    let tsc = common::root().join(".npm-tools/node_modules/typescript/bin/tsc");
    if !tsc.is_file() {
        common::skip(&format!("{} (scripts/npm-tools.sh)", tsc.display()));
        return;
    }
    // npm pack, install beside web/example, tsc --noEmit --checkJs --strict, the page drawn.
    let err = node("pack-check.mjs", &[]);
    let field = |prefix: &str| {
        err.lines()
            .find_map(|l| l.strip_prefix(prefix))
            .unwrap_or_else(|| panic!("no {prefix:?} line: {err}"))
    };
    let files: Vec<String> = serde_json::from_str(field("page: FILES ")).unwrap();
    assert!(files.contains(&"splatgl.d.ts".to_string()), "{files:?}");
    let r: serde_json::Value = serde_json::from_str(field("page: RESULT ")).unwrap();
    assert!(r.get("failure").is_none(), "{r}");
    // The default scene, loaded through the installed package: `format` is absent
    // (undefined), not null, and the splats are on the canvas.
    assert_eq!(r["splats"], 6527, "{r}");
    assert!(r.get("format").is_none(), "{r}");
    assert!(r["litPixels"].as_u64().unwrap() > 10_000, "{r}");
}
