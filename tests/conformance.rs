//! The conformance suite: generation, both backends passing it, the erratum proof (the GL
//! backend's erratum switches fail exactly the assets whose derived `catches` name them), the
//! runner's exit codes and causes, the Khronos glTF-Validator on every asset, and the HTML
//! report in headless Chromium.

use splatgl::conformance::manifest::Manifest;
use splatgl::conformance::{Erratum, generate, model, render, runner};
use splatgl::image::Image;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn splatgl(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(args)
        .output()
        .expect("runs");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-conf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The suite, generated once per test binary.
fn suite() -> &'static (PathBuf, Manifest) {
    static S: OnceLock<(PathBuf, Manifest)> = OnceLock::new();
    S.get_or_init(|| {
        let d = tmp("suite");
        let m = generate(&d).expect("suite generates");
        (d, m)
    })
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn gl_available() -> bool {
    match splatgl::headless::HeadlessContext::new() {
        Ok(_) => true,
        Err(e) => {
            eprintln!("SKIPPED GL part: {e}");
            false
        }
    }
}

#[test]
fn generated_suite_covers_every_erratum_and_writes_its_files() {
    let (d, m) = suite();
    assert!(m.assets.len() >= 30, "{} assets", m.assets.len());
    for e in Erratum::ALL {
        assert!(
            m.assets.iter().any(|a| a.catches.contains(&e)),
            "no asset catches erratum {}",
            e.letter()
        );
    }
    for a in &m.assets {
        assert!(d.join(&a.file).is_file() && d.join(&a.cameras_json).is_file());
        for c in &a.cameras {
            assert!(d.join(&c.reference_png).is_file() && d.join(&c.reference_pfm).is_file());
            assert!(
                c.tolerance.max_abs > 0.0 && c.tolerance.max_abs < 0.1,
                "{}",
                a.name
            );
            assert!(
                c.tolerance.min_psnr > 35.0,
                "{}: {}",
                a.name,
                c.tolerance.min_psnr
            );
        }
    }
    let again = Manifest::read(d).unwrap();
    assert_eq!(again.assets.len(), m.assets.len());
    assert_eq!(again.assets[3].catches, m.assets[3].catches);
}

#[test]
fn model_without_errata_reproduces_the_reference() {
    let (d, m) = suite();
    let mut worst = 0.0f32;
    for (i, a) in m.assets.iter().enumerate() {
        let (scene, cams) = render::load_asset(d, m, i).unwrap();
        for (c, cam) in a.cameras.iter().zip(&cams) {
            let want = Image::read(d.join(&c.reference_pfm)).unwrap();
            let got = model::render(&scene.cloud, cam, &[]).image;
            let mut want = want;
            for p in &mut want.pixels {
                p[..3].iter_mut().for_each(|v| *v = v.clamp(0.0, 1.0));
            }
            let cmp = splatgl::compare::compare(&got, &want, 0.0).unwrap();
            worst = worst.max(cmp.max_abs);
            assert!(cmp.max_abs < 2e-4, "{}/{}: {}", a.name, c.name, cmp.max_abs);
        }
    }
    eprintln!("model vs reference: max {worst:e}");
}

#[test]
fn both_backends_pass_the_suite() {
    let (d, m) = suite();
    let backends: &[&str] = if gl_available() {
        &["reference", "gl"]
    } else {
        &["reference"]
    };
    for b in backends {
        let out = tmp(&format!("run-{b}"));
        let (code, text) = splatgl(&["conformance", "run", s(d), "--backend", b, "-o", s(&out)]);
        assert_eq!(code, 0, "--backend {b}: {text}");
        let r: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        assert_eq!(r["passed"], m.assets.len(), "{b}");
        assert_eq!(r["failed"], 0);
        let a0 = &r["assets"][0];
        // PSNR is null (infinite) when the images are identical.
        assert!(a0["pass"].as_bool().unwrap() && a0["max_abs"].is_number());
        assert!(a0["psnr"].is_number() || a0["max_abs"] == 0.0);
        eprintln!("--backend {b}: {}", text.trim());
    }
}

#[test]
fn erratum_proof_gl_fails_exactly_the_assets_that_catch_it() {
    let (d, m) = suite();
    if !gl_available() {
        return;
    }
    let mut table = Vec::new();
    for e in Erratum::ALL {
        let imgs: std::collections::HashMap<String, Image> =
            render::render_suite_gl(d, m, e.gl_errata(), e == Erratum::G)
                .unwrap()
                .into_iter()
                .collect();
        let results = runner::run(d, m, |c| imgs.get(&c.image).cloned().map(Ok)).unwrap();
        let failed: BTreeSet<&str> = results
            .iter()
            .filter(|r| !r.pass())
            .map(|r| r.asset.name.as_str())
            .collect();
        let expected: BTreeSet<&str> = m
            .assets
            .iter()
            .filter(|a| a.catches.contains(&e))
            .map(|a| a.name.as_str())
            .collect();
        table.push(format!(
            "{}: {} of {} fail",
            e.letter(),
            failed.len(),
            m.assets.len()
        ));
        assert_eq!(
            failed,
            expected,
            "erratum {}: GL fail set (left) vs derived `catches` (right)",
            e.letter()
        );
        // The designated assets say which erratum they saw.
        for r in results.iter().filter(|r| !r.pass()) {
            assert!(r.cameras.iter().any(|c| c.cause.is_some()));
        }
    }
    eprintln!("{}", table.join("\n"));
}
