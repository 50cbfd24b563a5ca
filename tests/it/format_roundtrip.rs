//! Writers (SPZ v2/v3/v4, `.splat`, `.glb` with SPZ compression) and the test encoders
//! (`.ksplat` levels 0-2, SOG bundled and unbundled) round-trip a random cloud within each
//! format's documented quantization error (docs/formats.md). Each bound is derived from the
//! format's step sizes.

use crate::common;
use common::packed::{glb_chunks, glb_of, read_spz};
use common::{packed, random_cloud};
use splatgl::SplatCloud;
use splatgl::load::spz::SpzAxes;
use splatgl::load::validate::{Status, validate_bytes};
use splatgl::load::{LoadOptions, Scene, load_bytes, load_path};
use splatgl::write::{SpzVersion, SpzWriteOptions, to_splat, to_spz, to_spz_with};
use std::f32::consts::FRAC_1_SQRT_2;
use std::path::Path;

fn load(bytes: &[u8], name: &str) -> Scene {
    load_bytes(bytes, Some(Path::new(name)), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Per-attribute bounds on |decoded − original|.
struct Bounds {
    position: f32,
    /// On |ln s' − ln s|.
    log_scale: f32,
    /// On each quaternion component, after aligning signs.
    rotation: f32,
    opacity: f32,
    dc: f32,
    /// Per SH degree 1..=3.
    sh: [f32; 3],
}

fn check(name: &str, a: &SplatCloud, b: &SplatCloud, bd: &Bounds) {
    assert_eq!(a.len(), b.len(), "{name}: count");
    let degree = a.sh_degree.min(b.sh_degree);
    let mut worst = [0.0f32; 6];
    for i in 0..a.len() {
        let e = |w: &mut f32, v: f32, bound: f32, what: &str| {
            *w = w.max(v);
            assert!(v <= bound, "{name} splat {i} {what}: error {v} > {bound}");
        };
        for k in 0..3 {
            let d = (a.positions[i][k] - b.positions[i][k]).abs();
            e(
                &mut worst[0],
                d,
                bd.position * (1.0 + a.positions[i][k].abs()),
                "position",
            );
            let d = (a.scales[i][k].ln() - b.scales[i][k].ln()).abs();
            e(&mut worst[1], d, bd.log_scale, "log scale");
            let d = (a.sh_of(i)[0][k] - b.sh_of(i)[0][k]).abs();
            e(&mut worst[3], d, bd.dc, "DC");
        }
        let (p, q) = (a.rotations[i], b.rotations[i]);
        let s = if p.iter().zip(&q).map(|(x, y)| x * y).sum::<f32>() < 0.0 {
            -1.0
        } else {
            1.0
        };
        let d = (0..4).map(|k| (p[k] - s * q[k]).abs()).fold(0.0, f32::max);
        e(&mut worst[2], d, bd.rotation, "rotation");
        e(
            &mut worst[4],
            (a.opacities[i] - b.opacities[i]).abs(),
            bd.opacity,
            "opacity",
        );
        for l in 1..=degree as usize {
            for j in l * l..(l + 1) * (l + 1) {
                for ch in 0..3 {
                    let d = (a.sh_of(i)[j][ch] - b.sh_of(i)[j][ch]).abs();
                    e(&mut worst[5], d, bd.sh[l - 1], "SH");
                }
            }
        }
    }
    eprintln!(
        "{name}: max error position {:.2e}, ln scale {:.2e}, rotation {:.2e}, DC {:.2e}, opacity {:.2e}, SH {:.2e}",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
    );
}

/// SPZ: positions ±2^-13 (12 fractional bits, rounded), ln scale ±1/32, opacity ±0.5/255,
/// DC ±0.5/(0.15·255), SH rounded to 1/128 then to buckets of 8 (degree 1, 5 bits) or 16
/// (4 bits): ±4.5/128 and ±8.5/128. Rotations: v2 keeps x, y, z to δ = ±0.5/127.5 and
/// rebuilds w = √(1 − r²), so |w′² − w²| ≤ 2√3δ + 3δ² and |w′ − w| ≤ √(2√3δ + 3δ²) ≈ 0.117
/// (reached as w → 0: v2's known weakness); v3+ keeps three components to ±½·√½/511 and
/// rebuilds the largest (≥ ½) with error ≤ 3·√½·that/½.
fn spz_bounds(version: u32) -> Bounds {
    let small = 0.5 * FRAC_1_SQRT_2 / 511.0;
    let d = 0.5f32 / 127.5;
    let v2 = (2.0 * 3f32.sqrt() * d + 3.0 * d * d).sqrt() + 1e-4;
    Bounds {
        position: 1.0 / 8192.0 + 1e-6,
        log_scale: 1.0 / 32.0 + 1e-5,
        rotation: if version >= 3 {
            6.0 * FRAC_1_SQRT_2 * small + 1e-5
        } else {
            v2
        },
        opacity: 0.5 / 255.0 + 1e-6,
        dc: 0.5 / (0.15 * 255.0) + 1e-5,
        sh: [4.5 / 128.0 + 1e-5, 8.5 / 128.0 + 1e-5, 8.5 / 128.0 + 1e-5],
    }
}

#[test]
fn spz_writer_round_trips_every_version() {
    let cloud = random_cloud(2000, 3, 5.0, 7);
    for version in 2..=4 {
        let o = SpzWriteOptions {
            version: SpzVersion::try_from(version).unwrap(),
            antialiased: version == 4,
            ..Default::default()
        };
        let bytes = to_spz_with(&cloud, &o).unwrap();
        let l = load(&bytes, "x.spz");
        let d = l.report.details.unwrap();
        assert_eq!(d.version, version.to_string());
        assert_eq!(
            d.antialiased,
            version == 4,
            "the antialiased flag round-trips"
        );
        assert!(l.report.findings.is_empty(), "{:?}", l.report.findings);
        check(
            &format!("SPZ v{version}"),
            &cloud,
            &l.cloud,
            &spz_bounds(version),
        );
    }
}

#[test]
fn spz_axes_flip_is_its_own_inverse_and_raw_keeps_numbers() {
    let cloud = random_cloud(300, 3, 5.0, 3);
    let raw = SpzWriteOptions {
        version: SpzVersion::V3,
        axes: SpzAxes::Raw,
        ..Default::default()
    };
    let bytes = to_spz_with(&cloud, &raw).unwrap();
    let c = read_spz(&bytes, raw.axes);
    check("SPZ v3 raw axes", &cloud, &c, &spz_bounds(3));
    // Read in Niantic's axes, the raw file is the cloud turned by 180° about x.
    let turned = load(&bytes, "x.spz").cloud;
    for i in 0..cloud.len() {
        let [x, y, z] = cloud.positions[i];
        let d = (0..3)
            .map(|k| (turned.positions[i][k] - [x, -y, -z][k]).abs())
            .fold(0.0, f32::max);
        assert!(d <= 1.0 / 8192.0 + 1e-6);
    }
}

#[test]
fn spz_writer_rejects_what_it_cannot_store() {
    let mut c = random_cloud(3, 0, 5.0, 1);
    c.positions[2][1] = 3000.0;
    let e = to_spz(&c, SpzVersion::V2).unwrap_err().to_string();
    assert!(e.contains("splat 2") && e.contains("3000"), "{e}");
    c.positions[2][1] = f32::NAN;
    let e = to_spz(&c, SpzVersion::V2).unwrap_err().to_string();
    assert!(e.contains("splat 2: non-finite position"), "{e}");
    assert!(
        SpzVersion::try_from(5)
            .unwrap_err()
            .to_string()
            .contains("version 5")
    );
    let o = SpzWriteOptions {
        version: SpzVersion::V3,
        ..Default::default()
    };
    let e = splatgl::write::to_glb_spz_with(&random_cloud(3, 0, 5.0, 1), &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("pins SPZ version 2"), "{e}");
}

/// `.splat`: f32 positions and scales are exact; DC ±0.5/255/Y₀₀ (inside the display
/// range), opacity ±0.5/255, rotation bytes ±0.5/128 per component, then renormalised (which
/// can double it).
#[test]
fn splat_writer_round_trips() {
    let cloud = random_cloud(1000, 0, 5.0, 11);
    let l = load(&to_splat(&cloud), "x.splat");
    let c0 = splatgl::sh::SH_C0 as f32;
    let b = Bounds {
        position: 0.0,
        log_scale: 1e-6,
        rotation: 1.0 / 128.0 + 1e-5,
        opacity: 0.5 / 255.0 + 1e-6,
        dc: 0.5 / 255.0 / c0 + 1e-5,
        sh: [0.0; 3],
    };
    check(".splat", &cloud, &l.cloud, &b);
}

/// `.ksplat`: level 0 is f32 (SH too); levels 1–2 keep positions to ±½ of (block/2)/32767
/// around the bucket centre, scales and rotations as f16 (relative 2^-11), SH as f16 (level 1)
/// or truncated to 255 steps of [−2, 2] (level 2: error < 4/255). Colour and opacity bytes
/// are truncated: DC < 1/255/Y₀₀, opacity < 1/255.
#[test]
fn ksplat_every_level_round_trips_with_buckets() {
    let cloud = random_cloud(600, 2, 5.0, 5);
    let c0 = splatgl::sh::SH_C0 as f32;
    for level in 0..=2u16 {
        let bytes = packed::ksplat(&cloud, level, 256, 25.0);
        let l = load(&bytes, "x.ksplat");
        assert_eq!(
            l.report.details.as_ref().unwrap().compression,
            format!("none (compression level {level})")
        );
        let f16 = if level == 0 { 1e-6 } else { 1.0 / 2048.0 };
        let sh = match level {
            0 => 1e-6,
            1 => 1.0 / 2048.0,
            _ => 4.0 / 255.0 + 1e-5,
        };
        let b = Bounds {
            position: if level == 0 {
                0.0
            } else {
                0.5 * 12.5 / 32767.0 + 1e-5
            },
            log_scale: f16,
            rotation: f16,
            opacity: 1.0 / 255.0,
            dc: 1.0 / 255.0 / c0 + 1e-5,
            sh: [sh; 3],
        };
        check(&format!(".ksplat level {level}"), &cloud, &l.cloud, &b);
    }
}

/// SOG (test encoder: linear codebooks, one palette entry per splat): positions ±½ of the
/// 16-bit step of ln(1 + |x|) (times 1 + |x| back in linear units), ln scale / DC / SH ±½ of
/// their codebook step, opacity ±0.5/255, the three stored quaternion components
/// ±½·(2/255)/√2 and the rebuilt one ≤ 3·√½·that/½.
fn sog_bounds(c: &SplatCloud) -> Bounds {
    let span = |f: &dyn Fn(usize) -> Vec<f32>| {
        let v: Vec<f32> = (0..c.len()).flat_map(f).collect();
        v.iter().copied().fold(f32::MIN, f32::max) - v.iter().copied().fold(f32::MAX, f32::min)
    };
    let log_t = |x: f32| x.abs().ln_1p();
    let pos = (0..3)
        .map(|a| span(&|i| vec![log_t(c.positions[i][a]) * c.positions[i][a].signum()]))
        .fold(0.0, f32::max);
    let small = 0.5 * (2.0 / 255.0) * FRAC_1_SQRT_2;
    let sh = 0.5 * span(&|i| c.sh_of(i)[1..].iter().flatten().copied().collect()) / 255.0 + 1e-5;
    Bounds {
        position: 0.5 * pos / 65535.0 * 1.001 + 1e-6,
        log_scale: 0.5 * span(&|i| c.scales[i].map(f32::ln).to_vec()) / 255.0 + 1e-5,
        rotation: 6.0 * FRAC_1_SQRT_2 * small + 1e-5,
        opacity: 0.5 / 255.0 + 1e-6,
        dc: 0.5 * span(&|i| c.sh_of(i)[0].to_vec()) / 255.0 + 1e-5,
        sh: [sh; 3],
    }
}

#[test]
fn sog_bundled_and_unbundled_round_trip() {
    let cloud = random_cloud(700, 3, 5.0, 9);
    let bounds = sog_bounds(&cloud);
    let l = load(&packed::sog_bundle(&cloud), "x.sog");
    assert_eq!(
        l.report.details.as_ref().unwrap().compression,
        "WebP lossless, in a zip"
    );
    check("SOG bundled", &cloud, &l.cloud, &bounds);

    let dir = std::env::temp_dir().join(format!("splatgl-sog-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in packed::sog_files(&cloud) {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let u = load_path(dir.join("meta.json"), &LoadOptions::default()).unwrap();
    assert!(u.report.findings.is_empty(), "{:?}", u.report.findings);
    assert_eq!(u.cloud, l.cloud, "both forms decode identically");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Legacy SOG (version 1): the same textures with linear ranges in meta.json, which decode to
/// the same values as v2's linear codebooks; the opacity byte is a logit in [−6, 6], so its
/// error is ≤ ¼ · ½ · 12/255 (the logistic's slope is at most ¼).
#[test]
fn legacy_sog_v1_round_trips() {
    let cloud = random_cloud(700, 2, 5.0, 9);
    let mut bounds = sog_bounds(&cloud);
    bounds.opacity = 0.25 * 0.5 * 2.0 * packed::SOG_V1_LOGIT / 255.0 + 1e-5;
    let files = packed::sog_files_v1(&cloud);
    let members: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    let l = load(&packed::zip_stored(&members), "x.sog");
    assert_eq!(l.report.details.as_ref().unwrap().version, "1");
    assert_eq!(l.cloud.sh_degree, 2);
    check("SOG v1 bundled", &cloud, &l.cloud, &bounds);
}

/// Two `.ksplat` sections of different SH degrees (2 and 1) read as one cloud: the second is
/// zero-padded to degree 2, with a warning.
#[test]
fn ksplat_sections_of_different_degrees_merge() {
    let (a, b) = (random_cloud(300, 2, 5.0, 12), random_cloud(200, 1, 5.0, 13));
    let (fa, fb) = (
        packed::ksplat(&a, 1, 64, 25.0),
        packed::ksplat(&b, 1, 64, 25.0),
    );
    let mut file = fa[..4096].to_vec();
    file[4..8].copy_from_slice(&2u32.to_le_bytes());
    file[8..12].copy_from_slice(&2u32.to_le_bytes());
    file[16..20].copy_from_slice(&500u32.to_le_bytes());
    file.extend_from_slice(&fa[4096..5120]);
    file.extend_from_slice(&fb[4096..5120]);
    file.extend_from_slice(&fa[5120..]);
    file.extend_from_slice(&fb[5120..]);
    let l = load(&file, "two.ksplat");
    assert_eq!((l.cloud.len(), l.cloud.sh_degree), (500, 2));
    assert!(
        l.report
            .warning_lines()
            .iter()
            .any(|w| w.contains("zero-padded to 2"))
    );
    let one = load(&packed::ksplat(&a, 1, 64, 25.0), "a.ksplat").cloud;
    let mut both = one.clone();
    let second = load(&packed::ksplat(&b, 1, 64, 25.0), "b.ksplat").cloud;
    assert!(both.append(second), "the second section is padded");
    assert_eq!(l.cloud, both, "sections decode as the files they came from");
    assert_eq!(
        l.cloud.sh_of(450)[4..],
        [[0.0; 3]; 5],
        "padded coefficients are zero"
    );
}

/// `.glb` with `KHR_gaussian_splatting_compression_spz_2`: loads back within SPZ v2's bounds
/// with its metadata, validates without a single finding, stores the payload in SPZ's RUB
/// (read as a plain SPZ file without conversion, it is the cloud with x and z negated), and
/// its node transform applies as for uncompressed primitives.
#[test]
fn glb_spz_round_trips_within_spz_v2_and_validates_clean() {
    let mut cloud = random_cloud(800, 3, 5.0, 17);
    cloud.meta.color_space =
        splatgl::cloud::Known::Known(splatgl::cloud::ColorSpace::LinRec709Display);
    let glb = splatgl::write::to_glb_spz(&cloud).unwrap();
    let l = load(&glb, "x.glb");
    let d = l.report.details.as_ref().unwrap();
    assert_eq!(
        (d.container, d.version.as_str(), d.gltf_extension),
        ("spz", "2", Some("KHR_gaussian_splatting_compression_spz_2"))
    );
    assert!(l.report.findings.is_empty(), "{:?}", l.report.findings);
    assert_eq!(l.cloud.meta, cloud.meta);
    check("glb SPZ v2", &cloud, &l.cloud, &spz_bounds(2));
    let v = validate_bytes(&glb, Some(Path::new("x.glb")), &LoadOptions::default());
    assert_eq!(v.status(), Status::Valid);
    assert!(v.findings.is_empty(), "{:?}", v.findings);

    let (mut doc, bin) = glb_chunks(&glb);
    let stored = read_spz(
        &bin[..doc["bufferViews"][0]["byteLength"].as_u64().unwrap() as usize],
        SpzAxes::Raw,
    );
    let mut luf = cloud.clone();
    for p in &mut luf.positions {
        *p = [-p[0], p[1], -p[2]];
    }
    for i in 0..stored.len() {
        for k in 0..3 {
            let e = (stored.positions[i][k] - luf.positions[i][k]).abs();
            assert!(
                e <= 1.0 / 8192.0 + 1e-6,
                "splat {i} axis {k}: stored {:?}",
                stored.positions[i]
            );
        }
    }

    doc["nodes"][0]["translation"] = serde_json::json!([1.0, -2.0, 0.5]);
    let moved = load(&glb_of(&doc, &bin), "moved.glb").cloud;
    let shift = [1.0f32, -2.0, 0.5];
    for (i, (m, p)) in moved.positions.iter().zip(&l.cloud.positions).enumerate() {
        let d = (0..3)
            .map(|k| (m[k] - p[k] - shift[k]).abs())
            .fold(0.0, f32::max);
        assert!(d < 1e-5, "splat {i}: {m:?} vs {p:?} + {shift:?}");
    }
}

/// A writer that skips the LUF → RUB conversion (as CesiumJS expects) leaves POSITION's
/// min/max equal to the payload as stored: `auto` reads it as stored and says so, `rub`
/// converts anyway and says the bounds disagree; a file written as the text says reads
/// without a finding under `auto` and `rub`, and with one under `raw`.
#[test]
fn glb_spz_axes_follow_position_bounds() {
    let cloud = random_cloud(300, 1, 5.0, 23);
    let with = |axes| LoadOptions {
        spz_axes: axes,
        ..Default::default()
    };
    let read = |glb: &[u8], axes| load_bytes(glb, Some(Path::new("x.glb")), &with(axes)).unwrap();
    let stored = splatgl::write::to_glb_spz_with(
        &cloud,
        &SpzWriteOptions {
            axes: SpzAxes::Raw,
            ..Default::default()
        },
    )
    .unwrap();
    let l = read(&stored, SpzAxes::Auto);
    let w = l.report.warning_lines();
    assert!(w.iter().any(|m| m.contains("read as stored")), "{w:?}");
    check(
        "glb SPZ v2 as stored, auto",
        &cloud,
        &l.cloud,
        &spz_bounds(2),
    );
    let r = read(&stored, SpzAxes::Raw);
    assert!(r.report.findings.is_empty(), "{:?}", r.report.findings);
    assert_eq!(r.cloud, l.cloud);
    let c = read(&stored, SpzAxes::Rub);
    let w = c.report.warning_lines();
    assert!(
        w.iter().any(|m| m.contains("--spz-axes auto or raw")),
        "{w:?}"
    );
    assert!((c.cloud.positions[0][0] + l.cloud.positions[0][0]).abs() < 1e-6);

    let converted = splatgl::write::to_glb_spz(&cloud).unwrap();
    for axes in [SpzAxes::Auto, SpzAxes::Rub] {
        let l = read(&converted, axes);
        assert!(l.report.findings.is_empty(), "{:?}", l.report.findings);
        check("glb SPZ v2 converted", &cloud, &l.cloud, &spz_bounds(2));
    }
    let w = read(&converted, SpzAxes::Raw).report.warning_lines();
    assert!(
        w.iter().any(|m| m.contains("--spz-axes auto or rub")),
        "{w:?}"
    );
}

/// The SOG writer (`splatgl::write::to_sog_files`, k-means codebooks): positions, rotations and
/// opacities within SOG's fixed steps (as the test encoder's), ln scales, DC and SH on the
/// nearest entry of the codebooks its meta.json carries; bundled and unbundled decode alike.
/// Past 65,536 splats the SH palette is a median cut: exactly 65,536 entries, rms error a few
/// percent of the SH's.
#[test]
fn sog_writer_round_trips_onto_its_codebooks_and_palettes_large_clouds() {
    let cloud = random_cloud(700, 3, 5.0, 17);
    let files = splatgl::write::to_sog_files(&cloud).unwrap();
    assert_eq!(files[0].0, "meta.json");
    let meta: serde_json::Value = serde_json::from_slice(&files[0].1).unwrap();
    let book = |k: &str| -> Vec<f32> {
        let v = if k == "shN" { &meta["shN"] } else { &meta[k] };
        v["codebook"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect()
    };
    let nearest = |b: &[f32], v: f32| b.iter().map(|c| (c - v).abs()).fold(f32::MAX, f32::min);
    let l = load(&splatgl::write::to_sog_bundle(&cloud).unwrap(), "x.sog");
    let mut bounds = sog_bounds(&cloud);
    // ln scale, DC and SH are checked against the codebooks below instead.
    (bounds.log_scale, bounds.dc, bounds.sh) = (f32::MAX, f32::MAX, [f32::MAX; 3]);
    check("SOG writer", &cloud, &l.cloud, &bounds);
    let (scales, dc, sh) = (book("scales"), book("sh0"), book("shN"));
    for i in 0..cloud.len() {
        for a in 0..3 {
            let v = cloud.scales[i][a].ln();
            assert!((l.cloud.scales[i][a].ln() - v).abs() <= nearest(&scales, v) + 1e-4);
            let v = cloud.sh_of(i)[0][a];
            assert!((l.cloud.sh_of(i)[0][a] - v).abs() <= nearest(&dc, v) + 1e-5);
        }
        let pairs = cloud.sh_of(i).iter().zip(l.cloud.sh_of(i)).enumerate();
        for (j, (c, got)) in pairs.skip(1) {
            for (v, g) in c.iter().zip(got) {
                let d = (g - v).abs();
                assert!(d <= nearest(&sh, *v) + 1e-5, "splat {i} coefficient {j}");
            }
        }
    }
    let dir = std::env::temp_dir().join(format!("splatgl-sog-writer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in &files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let u = load_path(dir.join("meta.json"), &LoadOptions::default()).unwrap();
    assert_eq!(u.cloud, l.cloud, "both forms decode identically");
    std::fs::remove_dir_all(&dir).unwrap();

    let big = random_cloud(70_000, 1, 5.0, 18);
    let files = splatgl::write::to_sog_files(&big).unwrap();
    let meta: serde_json::Value = serde_json::from_slice(&files[0].1).unwrap();
    assert_eq!(meta["shN"]["count"], 65_536);
    let back = load(&splatgl::write::to_sog_bundle(&big).unwrap(), "big.sog").cloud;
    let (mut err, mut energy) = (0f64, 0f64);
    for i in 0..big.len() {
        for (a, b) in big.sh_of(i)[1..].iter().zip(&back.sh_of(i)[1..]) {
            for ch in 0..3 {
                err += ((a[ch] - b[ch]) as f64).powi(2);
                energy += (a[ch] as f64).powi(2);
            }
        }
    }
    let rms = (err / energy).sqrt();
    eprintln!(
        "SOG writer, 70,000 splats: SH rms error {:.1} % of the SH",
        100.0 * rms
    );
    assert!(rms < 0.15, "SH rms error {rms}");
}
