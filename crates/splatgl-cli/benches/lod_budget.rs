//! Does the selection spend its budget (issue 42)? A synthetic city of N splats (SH 0: a
//! ground plane and box buildings, z up) is written as a binary PLY, built into a 3D Tiles
//! tileset with `splatgl convert … tileset.json -v` (which prints the matrix from the PLY's
//! coordinates to the tileset's), and rendered from a far, a middle and a near camera twice:
//! the PLY whole (the reference picture) and the tileset at `--splat-budget 1000000` with
//! default options, the same view carried over by that matrix. Reported per N and camera: the
//! splats selected, the PSNR of the budgeted render against the whole one, and the budgeted
//! render's peak memory; then the ratio of the largest N's peak memory to the first's (it
//! should not grow with the scene).
//!
//! `cargo bench -p splatgl-cli --bench lod_budget` (`SPLATGL_BENCH_CITY_SPLATS`, default
//! `4000000,12000000`; run without `--bench`, as the test command does, 60,000 and 180,000
//! with a budget of 20,000; files under `target/tmp/lod-budget`, removed at the end unless
//! `SPLATGL_BENCH_KEEP=1`).

use splatgl::synthetic::Rng;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Splats per unit of surface: the city's side grows with √N.
const DENSITY: f32 = 100.0;

/// A building: footprint `[x0, y0, x1, y1]`, height, colour.
struct Building {
    rect: [f32; 4],
    height: f32,
    rgb: [f32; 3],
}

/// The city's side and its buildings (a grid of blocks, one building per block).
fn layout(n: u64) -> (f32, Vec<Building>) {
    let side = ((n as f32) / DENSITY / 3.0).sqrt();
    let blocks = ((side / 12.0).round() as usize).max(3);
    let cell = side / blocks as f32;
    let mut rng = Rng::new(7);
    let mut b = Vec::new();
    for i in 0..blocks {
        for j in 0..blocks {
            let (x, y) = (i as f32 * cell, j as f32 * cell);
            let (w, d) = (rng.range(0.4, 0.8) * cell, rng.range(0.4, 0.8) * cell);
            let (ox, oy) = (
                rng.range(0.1, 0.9 - w / cell) * cell,
                rng.range(0.1, 0.9 - d / cell) * cell,
            );
            b.push(Building {
                rect: [x + ox, y + oy, x + ox + w, y + oy + d],
                height: rng.range(0.3, 2.0) * cell,
                rgb: [
                    rng.range(0.3, 0.9),
                    rng.range(0.3, 0.9),
                    rng.range(0.3, 0.9),
                ],
            });
        }
    }
    (side, b)
}

/// Each building's surfaces (building, face: 4 walls then the roof, area), and their
/// cumulative share of the total area (to pick one in proportion to its area).
fn surfaces(buildings: &[Building]) -> (Vec<(usize, usize, f32)>, Vec<f32>) {
    let faces: Vec<(usize, usize, f32)> = buildings
        .iter()
        .enumerate()
        .flat_map(|(k, b)| {
            let [x0, y0, x1, y1] = b.rect;
            let (wx, wy) = (x1 - x0, y1 - y0);
            [
                wx * b.height,
                wx * b.height,
                wy * b.height,
                wy * b.height,
                wx * wy,
            ]
            .into_iter()
            .enumerate()
            .map(move |(f, a)| (k, f, a))
        })
        .collect();
    let total: f32 = faces.iter().map(|f| f.2).sum();
    let mut cumulative = Vec::with_capacity(faces.len());
    let mut acc = 0.0;
    for f in &faces {
        acc += f.2 / total;
        cumulative.push(acc);
    }
    (faces, cumulative)
}

/// Writes the city of `n` splats: a third on the ground, the rest on the buildings' walls and
/// roofs in proportion to their areas; flat splats about as large as their spacing.
fn write_city(path: &Path, n: u64) -> f32 {
    let (side, buildings) = layout(n);
    let f = std::fs::File::create(path).unwrap();
    let mut w = std::io::BufWriter::with_capacity(1 << 22, f);
    let h = splatgl_testkit::packed::ply_header_sh0(n);
    w.write_all(h.as_bytes()).unwrap();
    let (faces, cumulative) = surfaces(&buildings);
    let spacing = (1.0 / DENSITY).sqrt() * 2.0;
    let mut rng = Rng::new(42);
    let dc = |rgb: [f32; 3]| rgb.map(|c| (c - 0.5) / 0.282_094_8);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    for _ in 0..n {
        // (position, colour, normal axis: 0 x, 1 y, 2 z)
        let (p, rgb, axis) = if rng.unit() < 1.0 / 3.0 {
            let (x, y) = (rng.range(0.0, side), rng.range(0.0, side));
            let g = 0.35 + 0.1 * rng.unit();
            ([x, y, 0.0], [g, g + 0.05, g], 2)
        } else {
            let u = rng.unit();
            let i = cumulative.partition_point(|&c| c < u).min(faces.len() - 1);
            let (k, face, _) = faces[i];
            let b = &buildings[k];
            let [x0, y0, x1, y1] = b.rect;
            let (a, t) = (rng.unit(), rng.unit());
            let z = t * b.height;
            let shade = |f: f32| b.rgb.map(|c| c * f);
            match face {
                0 => ([x0 + a * (x1 - x0), y0, z], shade(0.8), 1),
                1 => ([x0 + a * (x1 - x0), y1, z], shade(0.9), 1),
                2 => ([x0, y0 + a * (y1 - y0), z], shade(0.7), 0),
                3 => ([x1, y0 + a * (y1 - y0), z], shade(1.0), 0),
                _ => (
                    [x0 + a * (x1 - x0), y0 + t * (y1 - y0), b.height],
                    shade(0.6),
                    2,
                ),
            }
        };
        // Flat along the face's normal: scale_2 along local z, turned onto x or y.
        let q = match axis {
            0 => [s, 0.0, s, 0.0],
            1 => [s, -s, 0.0, 0.0],
            _ => [1.0, 0.0, 0.0, 0.0],
        };
        let c = dc(rgb);
        let row = [
            p[0],
            p[1],
            p[2],
            c[0],
            c[1],
            c[2],
            3.0,
            (spacing * 0.6).ln(),
            (spacing * 0.6).ln(),
            (spacing * 0.05).ln(),
            q[0],
            q[1],
            q[2],
            q[3],
        ];
        for v in row {
            w.write_all(&v.to_le_bytes()).unwrap();
        }
    }
    w.flush().unwrap();
    side
}

/// Runs the binary; returns (peak MB from its `peak memory` line, stderr).
fn splatgl(args: &[&str]) -> (Option<u64>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "splatgl {args:?}: {err}");
    let peak = err.split("peak memory").nth(1).and_then(|s| {
        s.trim_start_matches(':')
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    });
    (peak, err)
}

/// The 4 × 4 matrix of `convert -v`'s `transform:` line (rows), or the identity.
fn printed_transform(log: &str) -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let Some(line) = log.lines().find(|l| l.starts_with("transform:")) else {
        return m;
    };
    let Some(body) = line.split('[').nth(1).and_then(|s| s.split(']').next()) else {
        return m;
    };
    for (r, row) in body.split(';').enumerate().take(4) {
        for (c, v) in row.split_whitespace().enumerate().take(4) {
            m[r][c] = v.parse().unwrap();
        }
    }
    m
}

/// `m` applied to a point (`w` 1) or a direction (`w` 0).
fn apply(m: &[[f64; 4]; 4], v: [f64; 3], w: f64) -> [f64; 3] {
    let mut o = [0.0; 3];
    for (r, out) in o.iter_mut().enumerate() {
        *out = m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] + m[r][3] * w;
    }
    o
}

/// `--look-at` text of eye, target, up.
fn look_text(e: [f64; 3], t: [f64; 3], u: [f64; 3]) -> String {
    [e, t, u]
        .iter()
        .flatten()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// One camera's budgeted renders: `(splats selected, PSNR against the whole, peak MB)` with
/// the default options and with `--max-screen-error 16`.
struct Row {
    camera: &'static str,
    filled: (u64, f64, u64),
    at_16px: (u64, f64, u64),
}

/// The splats a `render -v` of a tileset selected (its `tiles:` line; 0 if none).
fn selected_splats(log: &str) -> u64 {
    log.lines()
        .find(|l| l.starts_with("tiles:"))
        .and_then(|l| {
            l.split(" selected, ")
                .nth(1)?
                .split_whitespace()
                .next()?
                .parse()
                .ok()
        })
        .unwrap_or(0)
}

/// `splatgl compare`'s PSNR of two images (infinite when identical).
fn psnr_between(a: &Path, b: &Path) -> f64 {
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args([
            "compare",
            a.to_str().unwrap(),
            b.to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    json["psnr"].as_f64().unwrap_or(f64::INFINITY)
}

/// The options of every render: 1280 × 720, GL, overwrite, verbose.
const COMMON: [&str; 8] = [
    "--width",
    "1280",
    "--height",
    "720",
    "--backend",
    "gl",
    "-f",
    "-v",
];

/// The three cameras over a city of side `side`: (name, eye, target).
fn cameras(side: f64) -> [(&'static str, [f64; 3], [f64; 3]); 3] {
    let c = [side / 2.0, side / 2.0, 0.0];
    [
        ("far", [-0.4 * side, -0.4 * side, 0.9 * side], c),
        ("middle", [0.15 * side, 0.2 * side, 0.25 * side], c),
        (
            "near",
            [0.42 * side, 0.3 * side, 0.03 * side],
            [c[0], c[1], 0.03 * side],
        ),
    ]
}

/// One city: a row per camera.
fn measure(dir: &Path, n: u64, budget: u64) -> Vec<Row> {
    let ply = dir.join(format!("city-{n}.ply"));
    let side = write_city(&ply, n) as f64;
    let ts = dir.join(format!("city-{n}/tileset.json"));
    let mut args = vec![
        "convert",
        ply.to_str().unwrap(),
        ts.to_str().unwrap(),
        "-v",
        "-f",
    ];
    // The smoke run's small cities in small tiles (the default chunk would hold them whole).
    if budget < 100_000 {
        args.extend(["--chunk-splats", "2048"]);
    }
    let (_, log) = splatgl(&args);
    let m = printed_transform(&log);
    let mut rows = Vec::new();
    for (name, eye, target) in cameras(side) {
        let up = [0.0, 0.0, 1.0];
        let whole = dir.join(format!("{n}-{name}-whole.png"));
        let part = dir.join(format!("{n}-{name}-budget.png"));
        let common = COMMON;
        let look = look_text(eye, target, up);
        let mut args = vec!["render", ply.to_str().unwrap(), "--look-at", &look];
        args.extend(["-o", whole.to_str().unwrap()]);
        args.extend(common);
        splatgl(&args);
        let tlook = look_text(
            apply(&m, eye, 1.0),
            apply(&m, target, 1.0),
            apply(&m, up, 0.0),
        );
        let b = budget.to_string();
        // The default floor, then CesiumJS's 16 px (the old default) as the baseline.
        let mut got = Vec::new();
        for floor in [None, Some("16")] {
            let mut args = vec![
                "render",
                ts.to_str().unwrap(),
                "--look-at",
                &tlook,
                "--splat-budget",
                &b,
                "-o",
                part.to_str().unwrap(),
            ];
            if let Some(f) = floor {
                args.extend(["--max-screen-error", f]);
            }
            args.extend(common);
            let (peak, log) = splatgl(&args);
            let selected = selected_splats(&log);
            let psnr = psnr_between(&whole, &part);
            assert!(
                selected <= budget,
                "{name}: {selected} over the budget {budget}"
            );
            assert!(selected > 0, "{name}: nothing selected");
            got.push((selected, psnr, peak.unwrap_or(0)));
        }
        rows.push(Row {
            camera: name,
            filled: got[0],
            at_16px: got[1],
        });
    }
    let _ = std::fs::remove_file(&ply);
    if std::env::var("SPLATGL_BENCH_KEEP").as_deref() != Ok("1") {
        let _ = std::fs::remove_dir_all(ts.parent().unwrap());
    }
    rows
}

fn main() {
    let smoke = !std::env::args().any(|a| a == "--bench");
    let (default, budget) = if smoke {
        ("60000,180000", 20_000)
    } else {
        ("4000000,12000000", 1_000_000)
    };
    let sizes: Vec<u64> = std::env::var("SPLATGL_BENCH_CITY_SPLATS")
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|s| {
            s.trim()
                .parse()
                .expect("SPLATGL_BENCH_CITY_SPLATS: numbers")
        })
        .collect();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("lod-budget");
    std::fs::create_dir_all(&dir).unwrap();
    println!(
        "{:>10} | {:>6} | {:>9} {:>7} {:>7} | {:>9} {:>7} {:>7}",
        "splats", "camera", "selected", "PSNR dB", "peak MB", "16px sel", "PSNR dB", "peak MB"
    );
    let mut peaks = Vec::new();
    for &n in &sizes {
        let rows = measure(&dir, n, budget);
        for r in &rows {
            let ((s, p, m), (s16, p16, m16)) = (r.filled, r.at_16px);
            println!(
                "{n:>10} | {:>6} | {s:>9} {p:>7.1} {m:>7} | {s16:>9} {p16:>7.1} {m16:>7}",
                r.camera
            );
        }
        peaks.push(rows.iter().map(|r| r.filled.2).max().unwrap_or(0));
    }
    if let (Some(first), Some(last)) = (peaks.first(), peaks.last()) {
        println!(
            "peak memory {} vs {} splats: {:.2}× (budget {budget}, default options)",
            sizes.last().unwrap(),
            sizes[0],
            *last as f64 / (*first).max(1) as f64
        );
    }
}
