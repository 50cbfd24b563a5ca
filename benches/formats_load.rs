//! Load speed of the quantized containers: 1M splats with SH degree 3 as SPZ v2 (gzip), SPZ v4
//! (zstd streams) and PlayCanvas compressed PLY, generated in memory.
//!
//! Two views of the same loads: `payload` reports bytes/s of the **decompressed payload** (the
//! SPZ header and attribute blocks after gzip/zstd; for compressed PLY, which has no entropy
//! coding, the file), `splats` reports splats/s. The baselines in the same run are the bare
//! decompression of each SPZ file (flate2 gunzip, ruzstd per stream) and a `memcpy` of the
//! payload, so the ratios say how much of a load is decompression and how much is decoding.
//!
//! With `SPLATGL_BENCH_WRITE=DIR` the three files are also written to DIR (for timing another
//! reader on the very same bytes: `node scripts/formats_load_splat_transform.mjs DIR`).

use criterion::{Criterion, Throughput, criterion_group};
use splatgl::SplatCloud;
use splatgl::write::{SpzVersion, to_spz};
use std::hint::black_box;
use std::io::Read;

const N: usize = 1_000_000;

/// The header of a PlayCanvas compressed PLY of `n` splats in `chunks` chunks, `k` higher SH
/// coefficients per colour channel.
fn compressed_header(n: usize, chunks: usize, k: usize) -> String {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\nelement chunk {chunks}\n{}element vertex {n}\n",
        ["min_x", "min_y", "min_z", "max_x", "max_y", "max_z"]
            .iter()
            .chain(&["min_scale_x", "min_scale_y", "min_scale_z"])
            .chain(&["max_scale_x", "max_scale_y", "max_scale_z"])
            .map(|p| format!("property float {p}\n"))
            .collect::<String>()
    );
    for p in ["position", "rotation", "scale", "color"] {
        h += &format!("property uint packed_{p}\n");
    }
    h += &format!("element sh {n}\n");
    for j in 0..3 * k {
        h += &format!("property uchar f_rest_{j}\n");
    }
    h + "end_header\n"
}

/// `packed_rotation`: the largest component's index in the top 2 bits, the other three in 10
/// bits each, signed by the largest.
fn packed_rotation([x, y, z, w]: [f32; 4]) -> u32 {
    let unorm = |v: f32| (v.clamp(0.0, 1.0) * 1023.0).round() as u32;
    let q = [w, x, y, z];
    let l = (0..4)
        .max_by(|&a, &b| q[a].abs().total_cmp(&q[b].abs()))
        .unwrap_or(0);
    let sign = if q[l] < 0.0 { -1.0 } else { 1.0 };
    let mut pr = l as u32;
    for (_, v) in q.iter().enumerate().filter(|(j, _)| *j != l) {
        pr = pr << 10 | unorm(sign * v / std::f32::consts::SQRT_2 + 0.5);
    }
    pr
}

/// PlayCanvas compressed PLY (the layout `load::ply` documents): chunks of 256 splats with
/// position and log-scale ranges, colours in [0, 1], 8-bit SH.
fn compressed_ply(c: &SplatCloud) -> Vec<u8> {
    let n = c.len();
    let chunks = n.div_ceil(256);
    let k = c.coeffs_per_splat() - 1;
    let mut out = compressed_header(n, chunks, k).into_bytes();
    let unorm = |v: f32, bits: u32| {
        let max = ((1u32 << bits) - 1) as f32;
        (v.clamp(0.0, 1.0) * max).round() as u32
    };
    let mut ranges = Vec::with_capacity(chunks);
    for ch in 0..chunks {
        let idx = ch * 256..((ch + 1) * 256).min(n);
        let (mut lo, mut hi) = ([f32::MAX; 6], [f32::MIN; 6]);
        for i in idx {
            let ls = c.scales[i].map(f32::ln);
            for a in 0..3 {
                lo[a] = lo[a].min(c.positions[i][a]);
                hi[a] = hi[a].max(c.positions[i][a]);
                lo[3 + a] = lo[3 + a].min(ls[a]);
                hi[3 + a] = hi[3 + a].max(ls[a]);
            }
        }
        for v in lo[..3]
            .iter()
            .chain(&hi[..3])
            .chain(&lo[3..])
            .chain(&hi[3..])
        {
            out.extend_from_slice(&v.to_le_bytes());
        }
        ranges.push((lo, hi));
    }
    for i in 0..n {
        let (lo, hi) = ranges[i / 256];
        let t = |a: usize, v: f32| (v - lo[a]) / (hi[a] - lo[a]).max(1e-20);
        let p = c.positions[i];
        let pp = unorm(t(0, p[0]), 11) << 21 | unorm(t(1, p[1]), 10) << 11 | unorm(t(2, p[2]), 11);
        let pr = packed_rotation(c.rotations[i]);
        let s = c.scales[i].map(f32::ln);
        let ps = unorm(t(3, s[0]), 11) << 21 | unorm(t(4, s[1]), 10) << 11 | unorm(t(5, s[2]), 11);
        let dc = c.sh_of(i)[0].map(|d| splatgl::sh::color_from_dc(d) as f32);
        let pc = unorm(dc[0], 8) << 24
            | unorm(dc[1], 8) << 16
            | unorm(dc[2], 8) << 8
            | unorm(c.opacities[i], 8);
        for v in [pp, pr, ps, pc] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in 0..n {
        let sh = c.sh_of(i);
        for ch in 0..3 {
            for coef in &sh[1..] {
                let v = coef[ch] / 8.0 + 0.5;
                out.push((v * 256.0 - 0.5).round().clamp(0.0, 255.0) as u8);
            }
        }
    }
    out
}

/// The SPZ payload after decompression: gzip (v2) or every zstd stream (v4).
fn decompress(spz: &[u8]) -> Vec<u8> {
    if spz.starts_with(&[0x1f, 0x8b]) {
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(spz)
            .read_to_end(&mut out)
            .expect("gzip");
        return out;
    }
    let u64_at = |o: usize| u64::from_le_bytes(spz[o..o + 8].try_into().unwrap()) as usize;
    let streams = spz[15] as usize;
    let toc = u32::from_le_bytes(spz[16..20].try_into().unwrap()) as usize;
    let mut at = toc + 16 * streams;
    let mut out = spz[..32].to_vec();
    for s in 0..streams {
        let (z, raw) = (u64_at(toc + 16 * s), u64_at(toc + 16 * s + 8));
        let mut src = &spz[at..at + z];
        let mut d = ruzstd::decoding::StreamingDecoder::new(&mut src).expect("zstd");
        let start = out.len();
        d.read_to_end(&mut out).expect("zstd");
        assert_eq!(out.len() - start, raw);
        at += z;
    }
    out
}

fn bench(c: &mut Criterion) {
    let cloud = splatgl::synthetic::random_cloud(N, 3, 5.0, 1);
    let files = [
        ("spz_v2", to_spz(&cloud, SpzVersion::V2).expect("SPZ v2")),
        ("spz_v4", to_spz(&cloud, SpzVersion::V4).expect("SPZ v4")),
        ("compressed_ply", compressed_ply(&cloud)),
    ];
    if let Some(dir) = std::env::var_os("SPLATGL_BENCH_WRITE") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).expect("output folder");
        for (name, bytes) in &files {
            let ext = if name.starts_with("spz") {
                "spz"
            } else {
                "compressed.ply"
            };
            std::fs::write(dir.join(format!("{name}.{ext}")), bytes).expect("written");
        }
    }
    for (name, bytes) in &files {
        let payload = if name.starts_with("spz") {
            decompress(bytes)
        } else {
            bytes.clone()
        };
        let load = || {
            let s = splatgl::load::load_bytes(black_box(bytes), None, &Default::default());
            let s = s.expect("loads");
            assert_eq!(s.cloud.len(), N);
            s
        };
        // The bench measures real decodes: every file reads back to the cloud it came from
        // (within a chunk step of 10/1023 for compressed PLY, 2^-13 for SPZ).
        let got = load().cloud;
        let err = got
            .positions
            .iter()
            .zip(&cloud.positions)
            .flat_map(|(g, c)| (0..3).map(move |a| (g[a] - c[a]).abs()))
            .fold(0.0f32, f32::max);
        assert!(err <= 10.0 / 1023.0, "{name}: position error {err}");
        eprintln!(
            "{name}: file {:.1} MB, decompressed payload {:.1} MB, max position error {err:.2e}",
            bytes.len() as f64 / 1e6,
            payload.len() as f64 / 1e6
        );
        let mut g = c.benchmark_group(format!("payload_{name}_1M_sh3"));
        g.sample_size(10);
        g.throughput(Throughput::Bytes(payload.len() as u64));
        g.bench_function("memcpy_baseline", |b| b.iter(|| black_box(payload.clone())));
        if name.starts_with("spz") {
            g.bench_function("decompress_only", |b| {
                b.iter(|| decompress(black_box(bytes)))
            });
        }
        g.bench_function("splatgl_load", |b| b.iter(load));
        g.finish();
        let mut g = c.benchmark_group(format!("splats_{name}_1M_sh3"));
        g.sample_size(10);
        g.throughput(Throughput::Elements(N as u64));
        g.bench_function("splatgl_load", |b| b.iter(load));
        g.finish();
    }
}

criterion_group!(benches, bench);

/// `cargo bench` passes `--bench`; under `cargo test` (which builds and runs bench targets in
/// test mode) the 1M-splat generation is skipped: the test command only compiles this.
fn main() {
    if !std::env::args().any(|a| a == "--bench") {
        eprintln!("formats_load: skipped outside `cargo bench`");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
