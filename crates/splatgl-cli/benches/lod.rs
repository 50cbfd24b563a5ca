//! Scenes larger than memory (issue 21): a synthetic terrain of N splats is written to disk as
//! a binary PLY (generated in chunks, never held whole), built into a LOD tileset with
//! `splatgl convert … tileset.json --scratch-dir`, then rendered at `--splat-budget 1000000`
//! from a low camera looking across it. Reported per N: the build's time and peak memory,
//! the render's time to first frame (load, selection, tile loads, draw) and peak memory, and
//! the per-frame CPU time of selection and of assembling the selected tiles along a flight
//! over the terrain (tiles already loaded: the frame's own work), and — with `--bench`, under
//! `xvfb-run` — `splatgl view` of the tileset at the same budget: its frame times along an
//! orbit while tiles stream, and its peak memory. The first N is the
//! baseline: the others are given as ratios to it (peak memory should not grow with N).
//!
//! `cargo bench -p splatgl-cli --bench lod` (`SPLATGL_BENCH_LOD_SPLATS`, default `10000000,30000000`; run
//! without `--bench`, as `cargo test --all-targets` does, 50,000 and 150,000;
//! files under `target/tmp/lod-bench`, about 56 bytes a splat for the PLY and twice that for
//! the tileset, removed at the end unless `SPLATGL_BENCH_KEEP=1`).

use glam::DVec3;
use splatgl::camera::Camera;
use splatgl::synthetic::Rng;
use splatgl::tiles::{SelectOptions, TileCache};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const SPACING: f32 = 0.1;

/// Writes a terrain of `n` splats: a rolling heightfield over a square of side √n · SPACING,
/// flat splats a little larger than the spacing, coloured by height.
fn write_terrain(path: &Path, n: u64) {
    let f = std::fs::File::create(path).unwrap();
    let mut w = std::io::BufWriter::with_capacity(1 << 22, f);
    let h = splatgl_testkit::packed::ply_header_sh0(n);
    w.write_all(h.as_bytes()).unwrap();
    let side = (n as f32).sqrt() * SPACING;
    let mut rng = Rng::new(42);
    let height = |x: f32, y: f32| 2.0 * (x * 0.05).sin() * (y * 0.07).cos() + 0.5 * (x * 0.3).sin();
    for _ in 0..n {
        let (x, y) = (rng.range(0.0, side), rng.range(0.0, side));
        let z = height(x, y) + rng.normal() * 0.02;
        let t = (z + 2.5) / 5.0;
        let dc = [t - 0.5, 0.6 - t, 0.2].map(|c| c / 0.282_094_8);
        let a = rng.range(0.0, std::f32::consts::PI);
        let (s, c) = (a / 2.0).sin_cos();
        let row = [
            x,
            y,
            z,
            dc[0],
            dc[1],
            dc[2],
            1.5,
            (SPACING * 0.9).ln(),
            (SPACING * 0.5).ln(),
            (SPACING * 0.05).ln(),
            c,
            0.0,
            0.0,
            s,
        ];
        for v in row {
            w.write_all(&v.to_le_bytes()).unwrap();
        }
    }
    w.flush().unwrap();
}

/// Runs the binary; returns (wall seconds, peak MB from its `peak memory` line, stderr).
fn splatgl(args: &[&str]) -> (f64, Option<u64>, String) {
    let t = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(args)
        .output()
        .unwrap();
    let secs = t.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "splatgl {args:?}: {err}");
    let peak = err.split("peak memory").nth(1).and_then(|s| {
        s.trim_start_matches(':')
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    });
    (secs, peak, err)
}

/// A low camera over the terrain at `t` ∈ [0, 1] along a flight across it, looking ahead.
/// The tileset's frame: the terrain's thinnest axis of the root box is up.
fn flight(ts: &splatgl::tiles::Tileset, t: f64) -> (DVec3, DVec3, DVec3) {
    let Some(splatgl::tiles::Bounds::Box { centre, half_axes }) = ts.root.bounds else {
        panic!("the built root has a box");
    };
    let mut axes = [half_axes.x_axis, half_axes.y_axis, half_axes.z_axis];
    axes.sort_by(|a, b| a.length().total_cmp(&b.length()));
    let (up, across, along) = (axes[0], axes[1], axes[2]);
    let eye =
        centre + up.normalize() * (up.length() + 3.0) + along * (2.0 * t - 0.9) + across * 0.1;
    let target = eye + along.normalize() * 20.0 - up.normalize() * 4.0;
    (eye, target, up.normalize())
}

struct Row {
    n: u64,
    build_s: f64,
    build_mb: u64,
    first_frame_s: f64,
    render_mb: u64,
    select_ms: f64,
    assemble_ms: f64,
    selected: u64,
    /// The viewer's (median, p99) frame ms and peak MB (`None`: not run).
    viewed: Option<(f64, f64, u64)>,
}

/// `splatgl view` of the tileset under Xvfb (`--bench-frames 40 --orbit` from the render's
/// camera, 640×360, the budget of the render): the viewer's median and p99 frame time and its
/// peak memory (MB), as its `bench:` line reports them. `None` without `xvfb-run`.
fn view_tileset(ts: &Path, look: &str) -> Option<(f64, f64, u64)> {
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_splatgl"))
        .args(["view", ts.to_str().unwrap(), "--splat-budget", "1000000"])
        .args([
            "--look-at",
            look,
            "--width",
            "640",
            "--height",
            "360",
            "--no-ui",
        ])
        .args(["--no-vsync", "--bench-frames", "40", "--orbit"])
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let line = text
        .lines()
        .find(|l| l.starts_with("bench: ") && l.contains("frames:"));
    let Some(line) = line else {
        panic!(
            "view {}: no bench line: {text}{}",
            ts.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let after = |key: &str| -> f64 {
        let rest = line.split(key).nth(1).unwrap_or("");
        rest.split_whitespace()
            .next()
            .and_then(|w| w.trim_end_matches(';').parse().ok())
            .unwrap_or(f64::NAN)
    };
    let last = text
        .lines()
        .rev()
        .find(|l| l.starts_with("tiles: "))
        .unwrap_or("");
    eprintln!("lod: view: {line} | {last}");
    Some((
        after("median "),
        after("p99 "),
        after("peak memory ") as u64,
    ))
}

/// Per frame along the 24-frame flight, tiles already loaded (a first pass loads them): the
/// selection's and the assembly's milliseconds, and the splats selected, on average.
fn flight_costs(ts: &splatgl::tiles::Tileset) -> (f64, f64, u64) {
    // Per frame along the flight, tiles already loaded (a first pass loads them).
    let mut cache = TileCache::new(ts, &Default::default());
    let opts = SelectOptions::default();
    let frames = 24;
    let cam = |i: usize| {
        let (e, t, u) = flight(ts, i as f64 / frames as f64);
        Camera::look_at(
            e.as_vec3(),
            t.as_vec3(),
            u.as_vec3(),
            50f32.to_radians(),
            1280,
            720,
        )
    };
    for i in 0..frames {
        let s = splatgl::tiles::select(ts, &cam(i), &opts, &mut |t| cache.splats(t)).unwrap();
        let _ = cache.merged(&s.tiles);
    }
    let (mut select_s, mut assemble_s, mut selected) = (0.0, 0.0, 0);
    for i in 0..frames {
        let c = cam(i);
        let t = Instant::now();
        let s = splatgl::tiles::select(ts, &c, &opts, &mut |t| cache.splats(t)).unwrap();
        select_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let cloud = cache.merged(&s.tiles);
        assemble_s += t.elapsed().as_secs_f64();
        selected += cloud.len() as u64;
    }
    (
        select_s * 1e3 / frames as f64,
        assemble_s * 1e3 / frames as f64,
        selected / frames as u64,
    )
}

fn measure(dir: &Path, n: u64, view: bool) -> Row {
    let ply = dir.join(format!("terrain-{n}.ply"));
    let t = Instant::now();
    write_terrain(&ply, n);
    eprintln!(
        "lod: wrote {} ({n} splats) in {:.1} s",
        ply.display(),
        t.elapsed().as_secs_f64()
    );
    let out = dir.join(format!("tiles-{n}"));
    let ts_path = out.join("tileset.json");
    let scratch = dir.join("scratch");
    let (build_s, build_mb, log) = splatgl(&[
        "convert",
        ply.to_str().unwrap(),
        ts_path.to_str().unwrap(),
        "--scratch-dir",
        scratch.to_str().unwrap(),
        "-f",
    ]);
    eprintln!("lod: {}", log.lines().last().unwrap_or(""));
    let _ = std::fs::remove_file(&ply);
    let ts = splatgl::tiles::read(&ts_path, &Default::default()).unwrap();
    let (eye, target, up) = flight(&ts, 0.0);
    let look = [eye, target, up]
        .iter()
        .flat_map(|v| v.to_array())
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(",");
    let png = dir.join(format!("frame-{n}.png"));
    let (first_frame_s, render_mb, log) = splatgl(&[
        "render",
        ts_path.to_str().unwrap(),
        "--splat-budget",
        "1000000",
        "--look-at",
        &look,
        "-v",
        "-f",
        "-o",
        png.to_str().unwrap(),
    ]);
    eprintln!(
        "lod: {}",
        log.lines()
            .filter(|l| l.starts_with("tiles:"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let (select_ms, assemble_ms, selected) = flight_costs(&ts);
    let viewed = if view {
        view_tileset(&ts_path, &look)
    } else {
        None
    };
    if std::env::var("SPLATGL_BENCH_KEEP").as_deref() != Ok("1") {
        let _ = std::fs::remove_dir_all(&out);
    }
    Row {
        n,
        build_s,
        build_mb: build_mb.unwrap_or(0),
        first_frame_s,
        render_mb: render_mb.unwrap_or(0),
        select_ms,
        assemble_ms,
        selected,
        viewed,
    }
}

fn main() {
    // `cargo test --all-targets` runs this without `--bench`: a smoke run at small sizes.
    let smoke = !std::env::args().any(|a| a == "--bench");
    let default = if smoke {
        "50000,150000"
    } else {
        "10000000,30000000"
    };
    let sizes: Vec<u64> = std::env::var("SPLATGL_BENCH_LOD_SPLATS")
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|s| s.trim().parse().expect("SPLATGL_BENCH_LOD_SPLATS: numbers"))
        .collect();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("lod-bench");
    std::fs::create_dir_all(&dir).unwrap();
    // The viewer needs an X server (xvfb-run); the smoke run leaves it out.
    let view = !smoke && Command::new("xvfb-run").arg("--help").output().is_ok();
    let rows: Vec<Row> = sizes.iter().map(|&n| measure(&dir, n, view)).collect();
    println!(
        "{:>11} | {:>8} {:>9} | {:>11} {:>9} | {:>9} {:>10} {:>9}",
        "splats",
        "build s",
        "build MB",
        "1st frame s",
        "render MB",
        "select ms",
        "assemble ms",
        "selected"
    );
    for r in &rows {
        println!(
            "{:>11} | {:>8.1} {:>9} | {:>11.2} {:>9} | {:>9.3} {:>10.1} {:>9}",
            r.n,
            r.build_s,
            r.build_mb,
            r.first_frame_s,
            r.render_mb,
            r.select_ms,
            r.assemble_ms,
            r.selected
        );
    }
    for r in &rows {
        if let Some((med, p99, mb)) = r.viewed {
            println!(
                "{:>11} | view at budget 1000000, 640x360 orbit: frame ms median {med:.1} p99 {p99:.1}, peak memory {mb} MB",
                r.n
            );
        }
    }
    let base = &rows[0];
    for r in &rows[1..] {
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
        println!(
            "{} vs {} splats ({:.1}×): build memory {:.2}×, render memory {:.2}×, build time \
             {:.2}×, first frame {:.2}×, selection {:.2}×",
            r.n,
            base.n,
            r.n as f64 / base.n as f64,
            ratio(r.build_mb as f64, base.build_mb as f64),
            ratio(r.render_mb as f64, base.render_mb as f64),
            ratio(r.build_s, base.build_s),
            ratio(r.first_frame_s, base.first_frame_s),
            ratio(r.select_ms, base.select_ms),
        );
        if let (Some(a), Some(b)) = (r.viewed, base.viewed) {
            println!(
                "{} vs {} splats: view memory {:.2}×, view frame time {:.2}×",
                r.n,
                base.n,
                ratio(a.2 as f64, b.2 as f64),
                ratio(a.0, b.0)
            );
        }
    }
    let _ = std::fs::remove_dir_all(dir.join("scratch"));
}
