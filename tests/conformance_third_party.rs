//! The conformance kit grading renderers splatgl did not write, each rendering the suite in
//! headless Chromium and graded by `splatgl conformance run`; what their source says they do
//! (docs/conformance.md, "Independent renderers", cites the lines) is what the verdicts must
//! show.
//!
//! GaussianSplats3D 0.4.7 (npm `@mkkellogg/gaussian-splats-3d`, with three 0.170.0, through
//! `scripts/conformance/gs3d.mjs`): the 2.83σ cut-off fails the cut-off asset and is named
//! (erratum f); its eigenvalue floor drops sub-pixel splats and is named; SH above degree 2 is
//! not evaluated, which the RC allows, so the degree-3 assets pass; view-depth order fails the
//! sort asset.
//!
//! Spark 2.2.0 (npm `@sparkjsdev/spark`, with three 0.180.0 as `three-spark`, through
//! `scripts/conformance/spark.mjs`): its default opacity compensation for the 0.3 px² blur is
//! named; its 2.83σ cut fails the cut-off asset; it evaluates SH degree 3; the off-screen
//! centre cull makes the Jacobian-clamp profile asset differ. Its packed splats (8-bit log
//! scales, 8-bit quaternions, opacity in 7 bits) fail most RC assets by margins the diagnosis
//! does not model; with its own options set to the RC's rules (3σ, blur without compensation,
//! extended precision) the cut-off and sort assets pass, and `sortRadial: false` would fail the
//! sort asset.
//!
//! Needs node, chromium and the npm tools (`.ci/run` and `scripts/test.sh` install them);
//! without them the tests are skipped, which fails under `SPLATGL_REQUIRE=all`.

mod common;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-3p-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Why the renderer installed as npm `package` cannot run here, if it cannot.
fn missing_tools(package: &str) -> Option<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let npm = root.join(".npm-tools/node_modules").join(package);
    if !npm.exists() {
        return Some(format!("{} not installed", npm.display()));
    }
    if Command::new("node").arg("--version").output().is_err() {
        return Some("node not runnable".into());
    }
    // The browsers gs3d.mjs looks for.
    let browser = ["chromium", "chromium-browser"]
        .iter()
        .any(|b| Command::new(b).arg("--version").output().is_ok());
    (!browser).then(|| "chromium (or chromium-browser) not runnable".into())
}

#[test]
fn gaussian_splats_3d_is_graded_by_the_rules_its_source_breaks() {
    if let Some(why) = missing_tools("@mkkellogg/gaussian-splats-3d") {
        common::skip(&why);
        return;
    }
    let (suite, images, report) = (tmp("suite"), tmp("gs3d"), tmp("report"));
    let r = common::cli::run(&["conformance", "generate", suite.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.all());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/conformance/gs3d.mjs");
    let out = Command::new("node")
        .arg(&script)
        .args([&suite, &images])
        .args([
            "--splatgl",
            env!("CARGO_BIN_EXE_splatgl"),
            "--timeout",
            "300",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "gs3d.mjs: {err}");
    let r = common::cli::run(&[
        "conformance",
        "run",
        suite.to_str().unwrap(),
        "--images",
        images.to_str().unwrap(),
        "-o",
        report.to_str().unwrap(),
    ]);
    eprintln!("{}", r.all());
    assert_eq!(r.code, 1, "GaussianSplats3D breaks RC rules: {}", r.all());
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("report.json")).unwrap()).unwrap();
    let asset = |name: &str| {
        json["assets"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["name"] == name)
            .unwrap_or_else(|| panic!("{name}"))
            .clone()
    };
    let named: Vec<&str> = json["diagnosis"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["rule"].as_str().unwrap())
        .collect();
    // build/gaussian-splats-3d.module.js:8274 `if (A > 8.0) discard;` (2.83σ).
    assert!(!asset("cutoff_three_sigma")["pass"].as_bool().unwrap());
    assert!(named.contains(&"erratum_f"), "{named:?}");
    // The assets the diagnosis attributes to `rule`.
    let named_for = |rule: &str| -> Vec<String> {
        json["diagnosis"]
            .as_array()
            .unwrap()
            .iter()
            .find(|d| d["rule"] == rule)
            .unwrap_or_else(|| panic!("{rule} not named: {named:?}"))["assets"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap().to_owned())
            .collect()
    };
    assert!(named_for("erratum_f").contains(&"cutoff_three_sigma".to_owned()));
    // :8212, :8220 `sqrt(max(0.1, …))`, `if (eigenValue2 <= 0.0) return;`: sub-pixel splats
    // vanish (the profile asset differs, and the diagnosis says why).
    assert!(!asset("subpixel_dilation")["pass"].as_bool().unwrap());
    assert!(named_for("eigenvalue_floor").contains(&"subpixel_dilation".to_owned()));
    // src/worker/sorter.cpp: the key is clip-space z (view depth), not camera distance.
    assert!(!asset("sort_distance_not_depth")["pass"].as_bool().unwrap());
    assert!(named_for("view_depth_order").contains(&"sort_distance_not_depth".to_owned()));
    // The diagnosis names its three deviations that an asset decides, and nothing else (the
    // eigenvalue floor rather than erratum d, which 30 passing assets contradict).
    let mut all = named.clone();
    all.sort();
    assert_eq!(all, ["eigenvalue_floor", "erratum_f", "view_depth_order"]);
    // :12364 "Valid values are 0 - 2": degree 3 ignored, which the RC allows.
    for a in ["sh_degree_3", "sh_rotated_node"] {
        let a = asset(a);
        assert!(a["pass"].as_bool().unwrap(), "{a:#}");
        let cause = a["cameras"][0]["cause"].as_str().unwrap_or("");
        assert!(cause.contains("the RC allows it"), "{cause}");
    }
    let passed = json["passed"].as_u64().unwrap();
    // Measured 23 of 29 (docs/conformance.md): its other choices (8-bit colour, half-float
    // covariances, the 2.83σ cut and the floor together) are admitted where not tested.
    assert!(passed >= 20, "{passed} RC assets pass");
    for d in [&suite, &images, &report] {
        std::fs::remove_dir_all(d).ok();
    }
}

/// Renders `suite` into `images` with `scripts/conformance/ADAPTER`, with `env` set and, when
/// `only` is not empty, only those assets.
fn render(adapter: &str, suite: &Path, images: &Path, only: &[&str], env: &[(&str, &str)]) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scripts/conformance")
        .join(adapter);
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

/// `splatgl conformance run` of `images`: its exit code and report.json.
fn grade(suite: &Path, images: &Path, report: &Path) -> (i32, serde_json::Value) {
    let r = common::cli::run(&[
        "conformance",
        "run",
        suite.to_str().unwrap(),
        "--images",
        images.to_str().unwrap(),
        "-o",
        report.to_str().unwrap(),
    ]);
    eprintln!("{}", r.all());
    let json = serde_json::from_slice(&std::fs::read(report.join("report.json")).unwrap());
    (r.code, json.unwrap())
}

fn asset<'a>(json: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    json["assets"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("{name}"))
}

fn passes(json: &serde_json::Value, name: &str) -> bool {
    asset(json, name)["pass"].as_bool().unwrap()
}

/// The assets the diagnosis attributes to `rule` (None: the rule is not named).
fn named_for(json: &serde_json::Value, rule: &str) -> Option<Vec<String>> {
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

// Line numbers: .npm-tools/node_modules/@sparkjsdev/spark/dist/spark.module.js (2.2.0). Its
// shaders are one-line strings: "splatVertex" is line 6802, "splatFragment" 6801,
// "splatDefines" 6800; "vs N" / "fs N" / "defs N" are lines of those shader texts.
#[test]
fn spark_is_graded_by_the_rules_its_source_breaks() {
    if let Some(why) = missing_tools("@sparkjsdev/spark") {
        common::skip(&why);
        return;
    }
    let (suite, images, report) = (tmp("spark-suite"), tmp("spark"), tmp("spark-report"));
    let r = common::cli::run(&["conformance", "generate", suite.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.all());

    // Spark as shipped: SparkRenderer and SplatMesh with their default options.
    render("spark.mjs", &suite, &images, &[], &[]);
    let (code, json) = grade(&suite, &images, &report);
    assert_eq!(code, 1, "Spark breaks RC rules");
    // :13555 maxStdDev = sqrt(8); fs 30-31 `if (z2 > adjustedStdDev²) discard;`, vs 254-255
    // (quad half-axes adjustedStdDev·√λ): a 2.83σ cut.
    assert!(!passes(&json, "cutoff_three_sigma"));
    // :13563 blurAmount = 0.3; vs 231-238: `a += blur; d += blur;` and `rgba.a *=
    // sqrt(max(0, detOrig / det))`, always on: the antialiasing compensation, named.
    let aa = named_for(&json, "antialiasing_compensation").expect("antialiasing_compensation");
    assert!(aa.contains(&"subpixel_dilation".to_owned()), "{aa:?}");
    assert!(!passes(&json, "subpixel_dilation"));
    // :12167 SplatMesh.maxSh = 3, :9779-9831 evaluatePackedSH3: degree 3 is evaluated, so no
    // camera of the degree-3 asset passes as "SH above degree 2 ignored".
    for cam in asset(&json, "sh_degree_3")["cameras"].as_array().unwrap() {
        let cause = cam["cause"].as_str().unwrap_or("");
        assert!(!cause.contains("the RC allows it"), "{cause}");
    }
    assert!(passes(&json, "sh_degree_1") && passes(&json, "sh_degree_2"));
    // :13567 clipXY = 1.4; vs 141-142: splats whose centre lies beyond 1.4× the clip box are
    // dropped, so the large off-screen splats of the Jacobian-clamp profile asset are missing.
    assert!(!passes(&json, "jacobian_clamp_offscreen"));
    // vs 128, 136: culled when the centre is outside the near/far planes (the profile's cull by
    // the mean); what differs on the near-plane asset is 8-bit colour (defs 171-177, packed
    // colour and opacity `round(... * 255)`), as the diagnosis says.
    let c8 = named_for(&json, "colour_and_opacity_8bit").unwrap_or_default();
    assert!(
        passes(&json, "near_plane_crossing") || c8.contains(&"near_plane_crossing".to_owned()),
        "{c8:?}"
    );

    // Spark with its own options set to what the RC asks: maxStdDev 3 (a 3σ cut), the 0.3 px²
    // blur as preBlurAmount (vs 216-217: added before detOrig, so no compensation) and extended
    // splats (f32 centres, f16 colour, opacity and log scales; defs 350-393) instead of the
    // packed ones. The cut-off asset then passes, and so does the sort asset: :13569 sortRadial
    // = true, :1808-1809 the sort key is `length(center)`, the camera distance.
    let (exact, exact_report) = (tmp("spark-rc-options"), tmp("spark-rc-report"));
    render(
        "spark.mjs",
        &suite,
        &exact,
        &["cutoff_three_sigma", "sort_distance_not_depth"],
        &[
            (
                "SPARK_RENDERER",
                r#"{"maxStdDev":3,"blurAmount":0,"preBlurAmount":0.3,"accumExtSplats":true}"#,
            ),
            ("SPARK_MESH", r#"{"extSplats":true}"#),
        ],
    );
    let (_, exact_json) = grade(&suite, &exact, &exact_report);
    for a in ["cutoff_three_sigma", "sort_distance_not_depth"] {
        assert!(passes(&exact_json, a), "{:#}", asset(&exact_json, a));
    }
    for d in [&suite, &images, &report, &exact, &exact_report] {
        std::fs::remove_dir_all(d).ok();
    }
}
