//! Shared steps of the tests that grade renderers splatgl did not write
//! (`crates/splatgl-cli/tests/it/conformance_third_party.rs`, `crates/splatgl-cli/tests/it/conformance_cesium.rs`): the tools they need,
//! the suite generated, rendered by an adapter in `scripts/conformance/`, graded by
//! `splatgl conformance run`, and lookups in its report.json.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh temporary folder for one test's `name` (removed first if a run left it).
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-3p-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Why the renderer installed as `file` under `.npm-tools/node_modules` cannot run here (no
/// such file, no node, no chromium), if it cannot.
pub fn missing_tools(file: &str) -> Option<String> {
    let root = super::root();
    let npm = root.join(".npm-tools/node_modules").join(file);
    if !npm.exists() {
        return Some(format!("{} not installed", npm.display()));
    }
    missing_node_or_browser()
}

/// Why node or chromium cannot run here (what every page-driving test needs), if they cannot.
pub fn missing_node_or_browser() -> Option<String> {
    if Command::new("node").arg("--version").output().is_err() {
        return Some("node not runnable".into());
    }
    // The browsers the adapters look for (common.mjs).
    let browser = ["chromium", "chromium-browser"]
        .iter()
        .any(|b| Command::new(b).arg("--version").output().is_ok());
    (!browser).then(|| "chromium (or chromium-browser) not runnable".into())
}

/// `splatgl conformance generate` into a fresh folder `name`.
pub fn generate(name: &str) -> PathBuf {
    let suite = tmp(name);
    let r = super::cli::run(&["conformance", "generate", suite.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.all());
    suite
}

/// Renders `suite` into `images` with `scripts/conformance/ADAPTER`, with `env` set and, when
/// `only` is not empty, only those assets.
pub fn render(adapter: &str, suite: &Path, images: &Path, only: &[&str], env: &[(&str, &str)]) {
    let script = super::root().join("scripts/conformance").join(adapter);
    let mut cmd = Command::new("node");
    cmd.arg(&script).args([suite, images]).args([
        "--splatgl",
        env!("CARGO_BIN_EXE_splatgl"),
        "--timeout",
        "300",
    ]);
    if !only.is_empty() {
        cmd.args(["--only", &only.join(",")]);
    }
    let out = cmd.envs(env.iter().copied()).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{adapter}: {err}");
}

/// `splatgl conformance run SUITE --images IMAGES -o REPORT` with `extra` arguments: its exit
/// code and report.json.
pub fn grade(
    suite: &Path,
    images: &Path,
    report: &Path,
    extra: &[&str],
) -> (i32, serde_json::Value) {
    let mut args = vec![
        "conformance",
        "run",
        suite.to_str().unwrap(),
        "--images",
        images.to_str().unwrap(),
        "-o",
        report.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let r = super::cli::run(&args);
    eprintln!("{}", r.all());
    let json = serde_json::from_slice(&std::fs::read(report.join("report.json")).unwrap());
    (r.code, json.unwrap())
}

/// The report's entry of asset `name`.
pub fn asset<'a>(json: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    json["assets"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("{name}"))
}

/// The report's entries of the RC assets (`"checks": "rc"`), in the manifest's order.
pub fn rc_assets(json: &serde_json::Value) -> impl Iterator<Item = &serde_json::Value> {
    json["assets"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["checks"] == "rc")
}

/// Whether asset `name` passed.
pub fn passes(json: &serde_json::Value, name: &str) -> bool {
    asset(json, name)["pass"].as_bool().unwrap()
}

/// Asset `name`'s lowest PSNR (∞ when the report has none: identical images).
pub fn psnr(json: &serde_json::Value, name: &str) -> f64 {
    asset(json, name)["psnr"].as_f64().unwrap_or(f64::INFINITY)
}

/// The rules the diagnosis names, sorted.
pub fn named(json: &serde_json::Value) -> Vec<String> {
    let mut v: Vec<String> = json["diagnosis"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["rule"].as_str().unwrap().to_owned())
        .collect();
    v.sort();
    v
}

/// The assets the diagnosis attributes to `rule` (None: the rule is not named).
pub fn named_for(json: &serde_json::Value, rule: &str) -> Option<Vec<String>> {
    let d = json["diagnosis"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["rule"] == rule)?;
    let assets = d["assets"].as_array().unwrap();
    Some(
        assets
            .iter()
            .map(|a| a.as_str().unwrap().to_owned())
            .collect(),
    )
}

/// The required RC assets with a camera the diagnosis leaves `unexplained`, sorted.
pub fn unexplained_rc(json: &serde_json::Value) -> Vec<String> {
    let mut v: Vec<String> = rc_assets(json)
        .filter(|a| a["optional"] != true)
        .filter(|a| {
            a["cameras"].as_array().unwrap().iter().any(|c| {
                c["cause"]
                    .as_str()
                    .is_some_and(|t| t.contains("unexplained"))
            })
        })
        .map(|a| a["name"].as_str().unwrap().to_owned())
        .collect();
    v.sort();
    v
}

/// Removes the test's folders.
pub fn clean(dirs: &[&Path]) {
    for d in dirs {
        std::fs::remove_dir_all(d).ok();
    }
}
