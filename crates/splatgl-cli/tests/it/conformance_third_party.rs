//! The conformance kit grading renderers splatgl did not write, each rendering the suite in
//! headless Chromium and graded by `splatgl conformance run`; what their source says they do
//! (docs/conformance-engines.md cites the lines) is what the verdicts must
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
//! centre cull makes the Jacobian-clamp profile asset differ. Its packed splats (f16 centres,
//! 8-bit log scales, 8-bit octahedral quaternions, 8-bit colour and opacity) fail most RC
//! assets, and the diagnosis names that (`packed_splat_precision`; every other RC failure but
//! the adapter's colour-space one is a near miss of its deviations); with its own options set to
//! the RC's rules (3σ, blur without compensation, extended precision) the cut-off and sort
//! assets pass, and `sortRadial: false` would fail the sort asset.
//!
//! Needs node, chromium and the npm tools (`.ci/run` and `scripts/test.sh` install them);
//! without them the tests are skipped, which fails under `SPLATGL_REQUIRE=all`.

use crate::common;
use common::third_party::*;

#[test]
fn gaussian_splats_3d_is_graded_by_the_rules_its_source_breaks() {
    if let Some(why) = missing_tools("@mkkellogg/gaussian-splats-3d") {
        common::skip(&why);
        return;
    }
    let (suite, images, report) = (generate("gs3d-suite"), tmp("gs3d"), tmp("gs3d-report"));
    render("gs3d.mjs", &suite, &images, &[], &[]);
    let (code, json) = grade(&suite, &images, &report, &[]);
    assert_eq!(code, 1, "GaussianSplats3D breaks RC rules");
    let named_for = |rule: &str| {
        named_for(&json, rule).unwrap_or_else(|| panic!("{rule} not named: {:?}", named(&json)))
    };
    // build/gaussian-splats-3d.module.js:8274 `if (A > 8.0) discard;` (2.83σ).
    assert!(!passes(&json, "cutoff_three_sigma"));
    assert!(named_for("erratum_f").contains(&"cutoff_three_sigma".to_owned()));
    // :8212, :8220 `sqrt(max(0.1, …))`, `if (eigenValue2 <= 0.0) return;`: sub-pixel splats
    // vanish (the profile asset differs, and the diagnosis says why).
    assert!(!passes(&json, "subpixel_dilation"));
    assert!(named_for("eigenvalue_floor").contains(&"subpixel_dilation".to_owned()));
    // src/worker/sorter.cpp: the key is clip-space z (view depth), not camera distance.
    assert!(!passes(&json, "sort_distance_not_depth"));
    assert!(named_for("view_depth_order").contains(&"sort_distance_not_depth".to_owned()));
    // The diagnosis names its three deviations that an asset decides (the eigenvalue floor
    // rather than erratum d, which 30 passing assets contradict), and the colour space the
    // PLY the adapter gives it cannot carry (the linear asset shown as display values), its
    // 8-bit colour storage on the asset with colours above 1 (clamped before blending: the
    // profile asset `overbright_blending` differs), and nothing else.
    assert_eq!(
        named(&json),
        [
            "color_space_ignored",
            "colour_and_opacity_8bit",
            "eigenvalue_floor",
            "erratum_f",
            "view_depth_order"
        ]
    );
    assert!(
        named_for("colour_and_opacity_8bit") == ["overbright_blending"],
        "{:?}",
        named(&json)
    );
    // :12364 "Valid values are 0 - 2": degree 3 ignored, which the RC allows.
    for a in ["sh_degree_3", "sh_rotated_node"] {
        let a = asset(&json, a);
        assert!(a["pass"].as_bool().unwrap(), "{a:#}");
        let cause = a["cameras"][0]["cause"].as_str().unwrap_or("");
        assert!(cause.contains("the RC allows it"), "{cause}");
    }
    // :8210–8222 the major axis `normalize(vec2(b, eigenValue1 - a))` in f32: vertical for
    // near-round footprints (the floor, or b below the rounding of mid² − det), which swaps
    // the axes of `opacity_one_cap`'s red splat and turns `sh_degree_1`'s; the
    // `eigenvalue_floor` term follows it (crates/splatgl-conformance/src/model/footprint.rs).
    // Where b is comparable with that rounding the axis may come out anywhere in the range
    // the rounding allows (`color0_fallback`'s faint tilted fringe); the term samples it.
    assert!(passes(&json, "sh_degree_1") && passes(&json, "opacity_one_cap"));
    assert!(passes(&json, "color0_fallback"));
    // Measured 26 of 29 (docs/conformance.md): its other choices (8-bit colour, half-float
    // covariances, the 2.83σ cut and the floor together) are admitted where not tested, so
    // the RC assets it fails are exactly those of its two RC deviations and the adapter's
    // colour space, each explained.
    let failed: Vec<&str> = rc_assets(&json)
        .filter(|a| !a["pass"].as_bool().unwrap_or(false))
        .map(|a| a["name"].as_str().unwrap_or(""))
        .collect();
    assert_eq!(
        failed,
        [
            "sort_distance_not_depth",
            "color_space_linear",
            "cutoff_three_sigma"
        ]
    );
    for a in rc_assets(&json).filter(|a| !a["pass"].as_bool().unwrap_or(false)) {
        let cause = a["cause"].as_str().unwrap_or("");
        assert!(cause.starts_with("explained by"), "{a:#}");
    }
    clean(&[&suite, &images, &report]);
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
    let (suite, images, report) = (generate("spark-suite"), tmp("spark"), tmp("spark-report"));

    // Spark as shipped: SparkRenderer and SplatMesh with their default options.
    render("spark.mjs", &suite, &images, &[], &[]);
    let (code, json) = grade(&suite, &images, &report, &[]);
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
    // the mean); what differs on the near-plane asset is the packed precision (defs 171-177,
    // colour and opacity `round(... * 255)`; f16 centres, 8-bit log scales and quaternions),
    // which the diagnosis names alone or as its 8-bit colour part.
    let near = "near_plane_crossing".to_owned();
    let explained = ["packed_splat_precision", "colour_and_opacity_8bit"]
        .iter()
        .any(|r| named_for(&json, r).is_some_and(|a| a.contains(&near)));
    assert!(
        passes(&json, "near_plane_crossing") || explained,
        "{:?}",
        named(&json)
    );
    // The packed splats are what most of the other assets fail by, and the diagnosis says so.
    let packed = named_for(&json, "packed_splat_precision").expect("packed_splat_precision");
    assert!(packed.len() >= 5, "{packed:?}");
    // Every other failing RC camera is a near miss of Spark's own deviations (a few pixels
    // the emulation of its packing does not reproduce), not a stock hint — but the linear
    // colour-space asset, which the adapter cannot give it (PLY has no colour space).
    // (`erratum_i`, no dilation, is the model's stand-in for the compensation where it dims
    // small footprints: the misattribution docs/conformance-engines.md lists for Spark.)
    let own = [
        "packed_splat_precision",
        "antialiasing_compensation",
        "erratum_f",
        "colour_and_opacity_8bit",
        "erratum_i",
    ];
    for a in json["assets"].as_array().unwrap() {
        if a["checks"] != "rc" || a["name"] == "color_space_linear" {
            continue;
        }
        for cam in a["cameras"].as_array().unwrap() {
            let cause = cam["cause"].as_str().unwrap_or("");
            if cam["pass"].as_bool().unwrap() || cause.contains("explained by") {
                continue;
            }
            let rules = cam["nearest"]["rules"]
                .as_array()
                .cloned()
                .unwrap_or_default();
            assert!(
                cause.contains("a near miss of")
                    && !rules.is_empty()
                    && rules
                        .iter()
                        .all(|r| own.contains(&r.as_str().unwrap_or(""))),
                "{}: {cause}",
                cam["image"]
            );
        }
    }

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
    let (_, exact_json) = grade(&suite, &exact, &exact_report, &[]);
    for a in ["cutoff_three_sigma", "sort_distance_not_depth"] {
        assert!(passes(&exact_json, a), "{:#}", asset(&exact_json, a));
    }
    clean(&[&suite, &images, &report, &exact, &exact_report]);
}
