//! Cross-check against the most used converter, `@playcanvas/splat-transform` (npm), and for
//! `.ksplat` (which splat-transform reads but cannot write) the format author's own generator
//! (`@mkkellogg/gaussian-splats-3d`, through scripts/create_ksplat.mjs).
//!
//! Forward: a generated SH-3 INRIA PLY is converted to `.spz` (v3, v4), `.splat`, `.sog` and
//! compressed PLY by splat-transform, and to `.ksplat` levels 0-2 by GaussianSplats3D; splatgl
//! loads each and compares with its own load of the PLY, splat by splat (matched by position:
//! SOG, compressed PLY and `.ksplat` reorder), within each format's quantization error as
//! docs/formats.md derives it. Reverse: splat-transform reads the `.splat`, `.spz` (v2, v3,
//! v4) and `.sog` splatgl writes, and its PLY output matches splatgl's input within the same
//! bounds.
//!
//! splat-transform 3.x stores SPZ numbers in PLY axes, without Niantic's RUB conversion; the
//! test reads its SPZ raw and checks that our Niantic-axes files come back turned by 180°
//! about x, so a change on either side shows up here.
//!
//! The tools are found through `SPLAT_TRANSFORM` / `GAUSSIAN_SPLATS_3D` (the CLI and the
//! `gaussian-splats-3d.module.js` paths) or under `.npm-tools/` (where `.ci/run` installs
//! them); without them the test prints "skipped: splat-transform not installed".

use crate::common;
use common::packed::{read_spz, truncate_sh};
use common::random_cloud;
use splatgl::SplatCloud;
use splatgl::load::spz::SpzAxes;
use splatgl::load::{LoadOptions, load_bytes};
use splatgl::write::{
    SpzVersion, SpzWriteOptions, to_inria_ply, to_sog_bundle, to_splat, to_spz_with,
};
use std::f32::consts::FRAC_1_SQRT_2;
use std::path::{Path, PathBuf};
use std::process::Command;

const C0: f32 = splatgl::sh::SH_C0 as f32;

fn tool(var: &str, rel: &str) -> Option<PathBuf> {
    let p = std::env::var_os(var)
        .map(PathBuf::from)
        .unwrap_or_else(|| common::root().join(".npm-tools/node_modules").join(rel));
    p.exists().then_some(p)
}

fn run(cmd: &mut Command) {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// splat-transform IN OUT (overwrite, quiet, CPU only).
fn convert(st: &Path, input: &Path, output: &Path, extra: &[&str]) {
    run(Command::new(st)
        .args(["-w", "-q", "-g", "cpu"])
        .arg(input)
        .args(extra)
        .arg(output));
}

fn load(path: &Path) -> SplatCloud {
    let bytes = std::fs::read(path).unwrap();
    load_bytes(&bytes, Some(path), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .cloud
}

/// For each splat of `got`, the index of the splat of `reference` nearest to it (each used once).
fn matching(reference: &SplatCloud, got: &SplatCloud) -> Vec<usize> {
    let mut used = vec![false; reference.len()];
    let d2 = |a: &[f32; 3], b: &[f32; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>();
    got.positions
        .iter()
        .map(|p| {
            let j = (0..reference.len())
                .min_by(|&a, &b| {
                    d2(p, &reference.positions[a]).total_cmp(&d2(p, &reference.positions[b]))
                })
                .unwrap();
            assert!(!used[j], "two splats match splat {j}");
            used[j] = true;
            j
        })
        .collect()
}

/// Error bounds; each closure gets (index in `got`, axis or channel, reference value).
struct Tol<'a> {
    position: &'a dyn Fn(usize, usize, f32) -> f32,
    log_scale: &'a dyn Fn(usize, usize, f32) -> f32,
    dc: &'a dyn Fn(usize, usize, f32) -> f32,
    rotation: f32,
    opacity: f32,
    /// Per SH degree; `None`: checked statistically (SOG's k-means palette, see [`sog`]).
    sh: Option<[f32; 3]>,
}

fn compare(name: &str, reference: &SplatCloud, got: &SplatCloud, tol: &Tol) {
    assert_eq!(got.len(), reference.len(), "{name}: count");
    let m = matching(reference, got);
    let mut worst = [0.0f32; 6];
    let (mut sh_err, mut sh_sq) = (0.0f64, 0.0f64);
    let degree = reference.sh_degree.min(got.sh_degree);
    for (i, &j) in m.iter().enumerate() {
        let mut e = |w: usize, v: f32, bound: f32, what: &str| {
            worst[w] = worst[w].max(v);
            assert!(
                v <= bound,
                "{name} splat {i} (ref {j}) {what}: error {v} > {bound}"
            );
        };
        for a in 0..3 {
            let r = reference.positions[j][a];
            e(
                0,
                (got.positions[i][a] - r).abs(),
                (tol.position)(i, a, r),
                "position",
            );
            let r = reference.scales[j][a].ln();
            e(
                1,
                (got.scales[i][a].ln() - r).abs(),
                (tol.log_scale)(i, a, r),
                "ln scale",
            );
            let r = reference.sh_of(j)[0][a];
            e(3, (got.sh_of(i)[0][a] - r).abs(), (tol.dc)(i, a, r), "DC");
        }
        let (p, q) = (reference.rotations[j], got.rotations[i]);
        let s = if p.iter().zip(&q).map(|(x, y)| x * y).sum::<f32>() < 0.0 {
            -1.0
        } else {
            1.0
        };
        let d = (0..4).map(|k| (p[k] - s * q[k]).abs()).fold(0.0, f32::max);
        e(2, d, tol.rotation, "rotation");
        e(
            4,
            (got.opacities[i] - reference.opacities[j]).abs(),
            tol.opacity,
            "opacity",
        );
        for l in 1..=degree as usize {
            for k in l * l..(l + 1) * (l + 1) {
                for c in 0..3 {
                    let (g, r) = (got.sh_of(i)[k][c], reference.sh_of(j)[k][c]);
                    sh_err += ((g - r) as f64).powi(2);
                    sh_sq += (r as f64).powi(2);
                    if let Some(b) = tol.sh {
                        e(5, (g - r).abs(), b[l - 1], "SH");
                    }
                }
            }
        }
    }
    let rel = (sh_err / sh_sq.max(1e-30)).sqrt();
    eprintln!(
        "{name}: max error position {:.2e}, ln scale {:.2e}, rotation {:.2e}, DC {:.2e}, opacity {:.2e}, SH {:.2e} (rms {:.1}% of the SH)",
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4],
        worst[5],
        100.0 * rel
    );
    if tol.sh.is_none() && degree > 0 {
        assert!(rel < 0.5, "{name}: SH rms error {rel} of the SH rms");
    }
}

/// `c` turned by 180° about x (y and z negated), exactly.
fn flipped(c: &SplatCloud) -> SplatCloud {
    let mut f = c.clone();
    let signs = splatgl::load::codec::sh_flip_signs([false, true, true]);
    let k = f.coeffs_per_splat();
    for i in 0..f.len() {
        let [x, y, z] = f.positions[i];
        f.positions[i] = [x, -y, -z];
        let [qx, qy, qz, qw] = f.rotations[i];
        f.rotations[i] = [qx, -qy, -qz, qw];
        for j in 1..k {
            f.sh[i * k + j] = f.sh[i * k + j].map(|v| v * signs[j - 1]);
        }
    }
    f
}

/// SPZ with Niantic's packing (sh1Bits 5, shRestBits 4): see tests/it/format_roundtrip.rs.
fn spz_tol(version: u32) -> (f32, f32, [f32; 3]) {
    let d = 0.5f32 / 127.5;
    let rot = if version >= 3 {
        6.0 * FRAC_1_SQRT_2 * 0.5 * FRAC_1_SQRT_2 / 511.0 + 1e-5
    } else {
        (2.0 * 3f32.sqrt() * d + 3.0 * d * d).sqrt() + 1e-4
    };
    (
        rot,
        0.5 / 255.0 + 1e-6,
        [4.5 / 128.0 + 1e-5, 8.5 / 128.0 + 1e-5, 8.5 / 128.0 + 1e-5],
    )
}

fn spz_check(name: &str, reference: &SplatCloud, got: &SplatCloud, version: u32) {
    let (rotation, opacity, sh) = spz_tol(version);
    let tol = Tol {
        position: &|_, _, _| 1.0 / 8192.0 + 1e-6,
        log_scale: &|_, _, _| 1.0 / 32.0 + 1e-5,
        dc: &|_, _, _| 0.5 / (0.15 * 255.0) + 1e-5,
        rotation,
        opacity,
        sh: Some(sh),
    };
    compare(name, reference, got, &tol);
}

#[test]
fn splat_transform_and_splatgl_agree_on_every_format() {
    let Some(st) = tool("SPLAT_TRANSFORM", ".bin/splat-transform") else {
        common::skip(
            "splat-transform not installed (run .ci/run or scripts/test.sh, or npm install --prefix .npm-tools @playcanvas/splat-transform)",
        );
        return;
    };
    let dir = std::env::temp_dir().join(format!("splatgl-st-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = |n: &str| dir.join(n);
    let cloud = random_cloud(1500, 3, 5.0, 21);
    std::fs::write(f("in.ply"), to_inria_ply(&cloud)).unwrap();
    let ply = load(&f("in.ply"));

    // Forward: splat-transform writes, splatgl reads.
    for v in ["3", "4"] {
        convert(
            &st,
            &f("in.ply"),
            &f(&format!("v{v}.spz")),
            &["--spz-version", v],
        );
        let bytes = std::fs::read(f(&format!("v{v}.spz"))).unwrap();
        let raw = read_spz(&bytes, SpzAxes::Raw);
        spz_check(
            &format!("splat-transform .spz v{v} (read raw)"),
            &ply,
            &raw,
            v.parse().unwrap(),
        );
    }
    convert(&st, &f("in.ply"), &f("st.splat"), &[]);
    let d0 = truncate_sh(&ply, 0);
    compare(
        "splat-transform .splat",
        &d0,
        &load(&f("st.splat")),
        &Tol {
            position: &|_, _, _| 0.0,
            log_scale: &|_, _, _| 1e-5,
            dc: &|_, _, _| 1.0 / 255.0 / C0 + 1e-5,
            rotation: 2.0 / 128.0,
            opacity: 1.0 / 255.0 + 1e-6,
            sh: Some([0.0; 3]),
        },
    );
    compressed_ply(&st, &f, &ply);
    sog(&st, &f, &ply);
    ksplat(&f, &ply);

    // Reverse: splatgl writes, splat-transform reads and writes PLY.
    std::fs::write(f("ours.splat"), to_splat(&cloud)).unwrap();
    convert(&st, &f("ours.splat"), &f("back_splat.ply"), &[]);
    compare(
        "splatgl .splat → splat-transform",
        &d0,
        &load(&f("back_splat.ply")),
        &Tol {
            position: &|_, _, _| 0.0,
            log_scale: &|_, _, _| 1e-5,
            dc: &|_, _, _| 0.5 / 255.0 / C0 + 1e-5,
            // Our bytes round (v − 128)/128; splat-transform reads v/255·2 − 1: up to 1/255 more.
            rotation: 1.0 / 128.0 + 1.0 / 255.0 + 1e-3,
            opacity: 0.5 / 255.0 + 1e-5,
            sh: Some([0.0; 3]),
        },
    );
    // Our SOG writer (k-means codebooks, one palette entry per splat): splat-transform's
    // decode is within the same bounds of the PLY as its own files are.
    std::fs::write(f("ours.sog"), to_sog_bundle(&cloud).unwrap()).unwrap();
    convert(&st, &f("ours.sog"), &f("back_sog.ply"), &[]);
    sog_check(
        "splatgl .sog → splat-transform",
        &f("ours.sog"),
        &ply,
        &load(&f("back_sog.ply")),
    );
    for version in 2..=4u32 {
        for axes in [SpzAxes::Raw, SpzAxes::Rub] {
            let o = SpzWriteOptions {
                version: SpzVersion::try_from(version).unwrap(),
                axes,
                ..Default::default()
            };
            std::fs::write(f("ours.spz"), to_spz_with(&cloud, &o).unwrap()).unwrap();
            convert(&st, &f("ours.spz"), &f("back_spz.ply"), &[]);
            let back = load(&f("back_spz.ply"));
            let (name, expect) = match axes {
                SpzAxes::Raw => (
                    format!("splatgl .spz v{version} raw axes → splat-transform"),
                    ply.clone(),
                ),
                SpzAxes::Rub | SpzAxes::Auto => (
                    format!("splatgl .spz v{version} RUB → splat-transform (turned 180° about x)"),
                    flipped(&ply),
                ),
            };
            spz_check(&name, &expect, &back, version);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Float property values of element `el` in a binary little-endian PLY whose properties are
/// all 4 bytes wide: (names, rows).
fn ply_rows(bytes: &[u8], el: &str) -> (Vec<String>, Vec<Vec<f32>>) {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let (mut off, mut names, mut count, mut cur) = (end, Vec::new(), 0, String::new());
    let mut before = 0;
    for line in header.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.as_slice() {
            ["element", name, n] => {
                if cur == el {
                    break;
                }
                off += before;
                cur = name.to_string();
                count = n.parse().unwrap();
                before = 0;
                names.clear();
            }
            ["property", _, name] => {
                before += 4 * count;
                names.push(name.to_string());
            }
            _ => {}
        }
    }
    assert_eq!(cur, el);
    let w = names.len();
    let rows = (0..count)
        .map(|i| {
            (0..w)
                .map(|k| {
                    f32::from_le_bytes(bytes[off + 4 * (i * w + k)..][..4].try_into().unwrap())
                })
                .collect()
        })
        .collect();
    (names, rows)
}

/// Compressed PLY: positions 11/10/11 bits and ln scales 11/10/11 of each chunk's ranges, DC
/// 8 bits of the chunk's colour range, opacity 8 bits, rotation 10-bit smallest three, SH
/// bytes of [−4, 4]. Full steps, since the writer may truncate.
fn compressed_ply(st: &Path, f: &dyn Fn(&str) -> PathBuf, ply: &SplatCloud) {
    convert(st, &f("in.ply"), &f("st.compressed.ply"), &[]);
    let bytes = std::fs::read(f("st.compressed.ply")).unwrap();
    let (names, chunks) = ply_rows(&bytes, "chunk");
    let col = |n: &str| names.iter().position(|x| x == n).unwrap();
    let at = move |i: usize, lo: &str, hi: &str, bits: u32| {
        let c = &chunks[i / 256];
        (c[col(hi)] - c[col(lo)]).abs() / ((1u32 << bits) - 1) as f32
    };
    let axes = ["x", "y", "z"];
    let bits = [11, 10, 11];
    let pos = |i: usize, a: usize, _| {
        at(
            i,
            &format!("min_{}", axes[a]),
            &format!("max_{}", axes[a]),
            bits[a],
        ) + 1e-5
    };
    let scale = |i: usize, a: usize, _| {
        at(
            i,
            &format!("min_scale_{}", axes[a]),
            &format!("max_scale_{}", axes[a]),
            bits[a],
        ) + 1e-5
    };
    let rgb = ["r", "g", "b"];
    let dc = |i: usize, c: usize, _| {
        at(i, &format!("min_{}", rgb[c]), &format!("max_{}", rgb[c]), 8) / C0 + 1e-4
    };
    let step = std::f32::consts::SQRT_2 / 1023.0;
    let tol = Tol {
        position: &pos,
        log_scale: &scale,
        dc: &dc,
        rotation: step + 3.0 * FRAC_1_SQRT_2 * step / 0.5,
        opacity: 1.0 / 255.0 + 1e-6,
        sh: Some([1.0 / 32.0 + 1e-5; 3]),
    };
    compare(
        "splat-transform compressed PLY",
        ply,
        &load(&f("st.compressed.ply")),
        &tol,
    );
}

/// SOG: positions 16 bits of sign·ln(1 + |x|) in the meta's range (truncated: one full step,
/// ×(1 + |x|) back in linear units), ln scale and DC snapped to the nearest entry of their
/// 256-entry codebooks (checked against the codebook in meta.json), opacity and the three
/// stored quaternion components truncated to 8 bits; SH through a k-means palette, which has
/// no a-priori bound: its rms error must stay below half the SH's rms (no SH at all is 100 %,
/// a decode with channels or coefficients mixed up about 140 %; SPZ's 4-bit SH is ~30 %).
fn sog(st: &Path, f: &dyn Fn(&str) -> PathBuf, ply: &SplatCloud) {
    convert(st, &f("in.ply"), &f("st.sog"), &[]);
    sog_check(
        "splat-transform .sog",
        &f("st.sog"),
        ply,
        &load(&f("st.sog")),
    );
}

/// `got` (a decode of the SOG bundle `sog`, by splatgl or splat-transform) against `ply`
/// within the bounds of [`sog`], the codebooks taken from `sog`'s meta.json.
fn sog_check(name: &str, sog: &Path, ply: &SplatCloud, got: &SplatCloud) {
    let bytes = std::fs::read(sog).unwrap();
    let zip = splatgl::load::sog::zip::Archive::new(&bytes).unwrap();
    let meta: serde_json::Value =
        serde_json::from_slice(&zip.read("meta.json", &mut u64::MAX.clone()).unwrap()).unwrap();
    let nums = |p: &str, k: &str| -> Vec<f32> {
        meta[p][k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect()
    };
    let (mins, maxs) = (nums("means", "mins"), nums("means", "maxs"));
    let (sbook, cbook) = (nums("scales", "codebook"), nums("sh0", "codebook"));
    let nearest =
        |book: &[f32], v: f32| book.iter().map(|c| (c - v).abs()).fold(f32::MAX, f32::min);
    let pos = |_, a: usize, x: f32| (maxs[a] - mins[a]) / 65535.0 * (1.0 + x.abs()) * 1.01 + 1e-5;
    let scale = |_, _, v: f32| nearest(&sbook, v) + 1e-4;
    let dc = |_, _, v: f32| nearest(&cbook, v) + 1e-4;
    let small = (2.0 / 255.0) * FRAC_1_SQRT_2;
    let tol = Tol {
        position: &pos,
        log_scale: &scale,
        dc: &dc,
        rotation: small + 3.0 * FRAC_1_SQRT_2 * small / 0.5,
        opacity: 1.0 / 255.0 + 1e-6,
        sh: None,
    };
    compare(name, ply, got, &tol);
}

/// `.ksplat` from GaussianSplats3D (SH degree 2, its maximum): level 0 f32 (colour and opacity
/// bytes truncated); levels 1-2 positions ±½·(5/2)/32767 around bucket centres (its default
/// block of 5), scale and rotation as f16 (three.js's `toHalfFloat` truncates the mantissa:
/// relative 2^-10), SH f16 (level 1) or truncated to
/// 255 steps of the header's [min, max] (level 2).
fn ksplat(f: &dyn Fn(&str) -> PathBuf, ply: &SplatCloud) {
    let Some(module) = tool(
        "GAUSSIAN_SPLATS_3D",
        "@mkkellogg/gaussian-splats-3d/build/gaussian-splats-3d.module.js",
    ) else {
        common::skip(".ksplat: @mkkellogg/gaussian-splats-3d not installed");
        return;
    };
    let script = common::root().join("scripts/create_ksplat.mjs");
    let d2 = truncate_sh(ply, 2);
    for level in 0..=2 {
        let out = f(&format!("l{level}.ksplat"));
        run(Command::new("node")
            .arg(&script)
            .arg(&module)
            .arg(f("in.ply"))
            .arg(&out)
            .arg(level.to_string())
            .arg("2"));
        let bytes = std::fs::read(&out).unwrap();
        let (lo, hi) = (
            f32::from_le_bytes(bytes[36..40].try_into().unwrap()),
            f32::from_le_bytes(bytes[40..44].try_into().unwrap()),
        );
        let h = 1.0 / 1024.0;
        let sh = match level {
            0 => 1e-6,
            1 => h,
            _ => (hi - lo) / 255.0 + 1e-5,
        };
        let tol = Tol {
            position: &|_, _, _| {
                if level == 0 {
                    1e-6
                } else {
                    0.5 * 2.5 / 32767.0 + 1e-5
                }
            },
            log_scale: &|_, _, _| if level == 0 { 1e-5 } else { h },
            dc: &|_, _, _| 1.0 / 255.0 / C0 + 1e-5,
            rotation: if level == 0 { 1e-5 } else { h },
            opacity: 1.0 / 255.0 + 1e-6,
            sh: Some([sh; 3]),
        };
        compare(
            &format!("GaussianSplats3D .ksplat level {level}"),
            &d2,
            &load(&out),
            &tol,
        );
    }
}

/// `--crop` keeps what splat-transform's `--filter-box` keeps: the same splats, in the same
/// order. splat-transform's box is in its engine coordinates, which for a PLY are the file's
/// turned 180° about Z ((x, y, z) → (−x, −y, z)); splatgl's is in the file's own coordinates.
#[test]
fn crop_box_keeps_what_splat_transform_filter_box_keeps() {
    let Some(st) = tool("SPLAT_TRANSFORM", ".bin/splat-transform") else {
        common::skip("splat-transform not installed (run .ci/run or scripts/test.sh)");
        return;
    };
    let dir = std::env::temp_dir().join(format!("splatgl-st-crop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = random_cloud(3000, 1, 3.0, 77);
    let input = dir.join("in.ply");
    std::fs::write(&input, to_inria_ply(&cloud)).unwrap();
    let ply = load(&input);
    let (lo, hi) = ([-2.0f32, -1.5, -2.5], [1.8, 2.2, 1.0]);
    let arg = format!(
        "{},{},{},{},{},{}",
        lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
    );
    let out = dir.join("cropped.ply");
    convert(&st, &input, &out, &["-B", &arg]);
    let theirs = load(&out);
    let ours = splatgl::cull::CropBox {
        min: [-hi[0], -hi[1], lo[2]],
        max: [-lo[0], -lo[1], hi[2]],
    }
    .apply(&ply)
    .expect("the box leaves some splats out");
    assert!(
        ours.len() > 100 && ours.len() < ply.len() - 100,
        "{}",
        ours.len()
    );
    assert_eq!(theirs.len(), ours.len(), "splats kept");
    assert_eq!(
        theirs.positions, ours.positions,
        "the same splats, in order"
    );
    eprintln!("crop: {} of {} kept by both", ours.len(), ply.len());
}
