//! `splatgl convert`: round trips PLY → glTF → PLY per component type, the RC content of the
//! output, the options, and the Khronos glTF-Validator on what it writes.

mod common;
use splatgl::SplatCloud;
use splatgl::load::{LoadOptions, load_path};
use std::path::{Path, PathBuf};
use std::process::Command;

fn splatgl(args: &[&str]) -> (i32, String) {
    let r = common::cli::run(args);
    (r.code, r.all())
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-convert-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn load(p: &Path) -> SplatCloud {
    load_path(p, &LoadOptions::default()).unwrap().cloud
}

/// Runs the Khronos glTF-Validator through scripts/gltf_validate.mjs; `None` (with a note)
/// when node or the npm package is not installed here (.ci/run installs both).
pub fn khronos_validate(file: &Path) -> Option<serde_json::Value> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/gltf_validate.mjs");
    let pkg = Path::new(env!("CARGO_MANIFEST_DIR")).join(".npm-tools/node_modules/gltf-validator");
    if !pkg.exists() {
        eprintln!(
            "SKIPPED glTF-Validator: {} not installed (.ci/run installs it)",
            pkg.display()
        );
        return None;
    }
    let out = match Command::new("node").arg(&script).arg(file).output() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("SKIPPED glTF-Validator: node not runnable ({e})");
            return None;
        }
    };
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{}: validator output is not JSON ({e}): {}",
            file.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let errors = report["issues"]["numErrors"].as_u64().unwrap();
    assert_eq!(
        errors,
        0,
        "{}: glTF-Validator errors: {:#}",
        file.display(),
        report["issues"]["messages"]
    );
    assert_eq!(out.status.code(), Some(0));
    Some(report)
}

/// A random INRIA PLY with positions in [−5, 5], SH degree 3.
fn source(d: &Path) -> (PathBuf, SplatCloud) {
    let cloud = common::random_cloud(300, 3, 5.0, 7);
    let p = d.join("in.ply");
    std::fs::write(&p, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let loaded = load(&p);
    (p, loaded)
}

/// Which fields of two clouds differ (bit for bit), with a count and the first index.
fn differences(a: &SplatCloud, b: &SplatCloud) -> Vec<String> {
    fn field<T: PartialEq + std::fmt::Debug>(name: &str, a: &[T], b: &[T], out: &mut Vec<String>) {
        let bad: Vec<usize> = (0..a.len().min(b.len()))
            .filter(|&i| a[i] != b[i])
            .collect();
        if a.len() != b.len() || !bad.is_empty() {
            let first = bad.first().map(|&i| format!("{:?} vs {:?}", a[i], b[i]));
            out.push(format!(
                "{name}: {} differ, lengths {} / {}, first {first:?}",
                bad.len(),
                a.len(),
                b.len()
            ));
        }
    }
    let mut out = Vec::new();
    field("positions", &a.positions, &b.positions, &mut out);
    field("scales", &a.scales, &b.scales, &mut out);
    field("rotations", &a.rotations, &b.rotations, &mut out);
    field("opacities", &a.opacities, &b.opacities, &mut out);
    field("sh", &a.sh, &b.sh, &mut out);
    if a.meta != b.meta || a.sh_degree != b.sh_degree {
        out.push(format!(
            "meta {:?}/{} vs {:?}/{}",
            a.meta, a.sh_degree, b.meta, b.sh_degree
        ));
    }
    out
}

fn max_diff<const N: usize>(a: &[[f32; N]], b: &[[f32; N]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (*p as f64 - *q as f64).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn float_round_trip_ply_glb_ply_is_exact() {
    let d = dir("float");
    let (input, want) = source(&d);
    for ext in ["glb", "gltf"] {
        let mid = d.join(format!("mid.{ext}"));
        let out = d.join(format!("out-{ext}.ply"));
        assert_eq!(splatgl(&["convert", s(&input), s(&mid)]).0, 0);
        let d1 = differences(&load(&mid), &want);
        assert!(d1.is_empty(), "PLY → {ext}: {d1:?}");
        assert_eq!(splatgl(&["convert", s(&mid), s(&out)]).0, 0);
        let d2 = differences(&load(&out), &want);
        assert!(d2.is_empty(), "PLY → {ext} → PLY: {d2:?}");
        khronos_validate(&mid);
        let (code, text) = splatgl(&["validate", s(&mid)]);
        assert_eq!(code, 0, "{text}");
    }
}

/// Quantizing one attribute moves it by at most half a step (plus f32 rounding), where a
/// step is the type's step in decoded units times the dequantization scale; everything else
/// stays within f32 rounding of the node matrix (none for rotation and opacity).
#[test]
fn quantized_round_trip_stays_within_one_step_per_component_type() {
    use splatgl::write::{Comp, OPACITY_TYPES, POSITION_TYPES, ROTATION_TYPES, SCALE_TYPES};
    let d = dir("quant");
    let (input, want) = source(&d);
    let extent = 10.0f64; // positions span about [−5, 5]
    let max_scale = want.scales.iter().flatten().fold(0.0f32, |a, &b| a.max(b)) as f64;
    let cases = [
        ("position", &POSITION_TYPES[..]),
        ("rotation", &ROTATION_TYPES[..]),
        ("scale", &SCALE_TYPES[..]),
        ("opacity", &OPACITY_TYPES[..]),
    ];
    let mut checked = 0;
    for (attr, types) in cases {
        for &comp in types.iter().filter(|c| **c != Comp::F32) {
            let name = format!("{attr}-{}", comp.name());
            let mid = d.join(format!("{name}.glb"));
            let out = d.join(format!("{name}.ply"));
            let q = format!("{attr}={}", comp.name());
            let (code, text) = splatgl(&["convert", s(&input), s(&mid), "--quantize", &q]);
            assert_eq!(code, 0, "{text}");
            assert_eq!(splatgl(&["convert", s(&mid), s(&out)]).0, 0);
            let back = load(&out);
            let (lo, hi) = comp.range().unwrap();
            // Dequantization scale k (see write::quantize): positions span the range.
            let k = match attr {
                "position" => max_diff_extent(&want) / (hi - lo),
                "scale" if !comp.is_normalized() => max_scale / hi,
                _ => 1.0,
            };
            let step = comp.step() * k;
            let f32_tol = 1e-6 * extent;
            let (dp, ds) = (
                max_diff(&back.positions, &want.positions),
                max_diff(&back.scales, &want.scales),
            );
            let (dr, dop) = (
                max_diff(&back.rotations, &want.rotations),
                back.opacities
                    .iter()
                    .zip(&want.opacities)
                    .map(|(a, b)| (*a as f64 - *b as f64).abs())
                    .fold(0.0, f64::max),
            );
            let bound = |on: bool, rel: f64| if on { 0.5 * step + rel } else { rel };
            // Rotations are renormalised after quantization: a unit quaternion's components
            // move by at most the rounding error plus the normalisation's correction (≤ 2×).
            let rot_bound = if attr == "rotation" {
                2.0 * comp.step()
            } else {
                1e-6
            };
            eprintln!(
                "{name}: step {step:.3e} Δpos {dp:.2e} Δscale {ds:.2e} Δrot {dr:.2e} Δopacity {dop:.2e}"
            );
            assert!(
                dp <= bound(attr == "position", f32_tol),
                "{name}: Δpos {dp}"
            );
            assert!(
                ds <= bound(attr == "scale", 1e-6 * max_scale),
                "{name}: Δscale {ds}"
            );
            assert!(dr <= rot_bound, "{name}: Δrot {dr}");
            assert!(
                dop <= bound(attr == "opacity", 1e-7),
                "{name}: Δopacity {dop}"
            );
            assert_eq!(back.sh, want.sh, "{name}: SH stays float");
            khronos_validate(&mid);
            let (code, text) = splatgl(&["validate", s(&mid)]);
            assert_eq!(code, 0, "{name}: {text}");
            checked += 1;
        }
    }
    assert_eq!(checked, 8 + 2 + 4 + 2, "every non-float type the RC allows");
}

fn max_diff_extent(c: &SplatCloud) -> f64 {
    let b = c.bounds().unwrap();
    (0..3)
        .map(|j| (b.max[j] - b.min[j]) as f64)
        .fold(0.0, f64::max)
}

#[test]
fn spz_splat_and_spz_compressed_glb_outputs_load_back_within_their_quantization() {
    let d = dir("packed");
    let (input, src) = source(&d);
    // SPZ stores positions in 24-bit fixed point with 12 fractional bits (error ≤ 2^-13);
    // .splat stores them as f32 (exact). docs/formats.md has every bound.
    let half_step = 2f64.powi(-13) * 1.0001;
    for (name, extra, pos_bound) in [
        ("v2.spz", &[][..], half_step),
        ("v3.spz", &["--spz-version", "3"][..], half_step),
        ("v4.spz", &["--spz-version", "4"][..], half_step),
        ("c.splat", &[][..], 0.0),
        ("spz.glb", &["--spz-compress"][..], half_step),
    ] {
        let out = d.join(name);
        let mut args = vec!["convert", s(&input), s(&out)];
        args.extend_from_slice(extra);
        let (code, text) = splatgl(&args);
        assert_eq!(code, 0, "{name}: {text}");
        if name.ends_with(".splat") {
            assert!(text.contains("SH degrees 1..=3 dropped"), "{text}");
        }
        if name.ends_with(".glb") {
            khronos_validate(&out); // asserts 0 errors (when installed)
        }
        let back = load(&out);
        assert_eq!(back.len(), src.len(), "{name}");
        let err = max_diff(&back.positions, &src.positions);
        assert!(
            err <= pos_bound,
            "{name}: position error {err} > {pos_bound}"
        );
    }
}

#[test]
fn spz_options_that_do_not_apply_are_errors() {
    let d = dir("packed-opts");
    let (input, _) = source(&d);
    for (out, flag, want) in [
        ("a.glb", "--spz-version", "applies to .spz outputs only"),
        ("b.ply", "--spz-compress", "applies to .glb outputs only"),
    ] {
        let out = d.join(out);
        let mut args = vec!["convert", s(&input), s(&out), flag];
        if flag == "--spz-version" {
            args.push("3");
        }
        let (code, text) = splatgl(&args);
        assert_eq!(code, 2, "{text}");
        assert!(text.contains(want), "{text}");
        assert!(!out.exists());
    }
}
