//! Splat sorting benchmarks: ours vs `sort_unstable_by`, rayon `par_sort_unstable_by` and the
//! `rdst` radix crate on the same keys, N = 100k / 1M / 4M, uniform and clustered scenes; the
//! whole per-frame cost at 1M, full and culled (`sort_visible`, all and about half in view);
//! a memory-bandwidth baseline; and (printed once, not timed) the
//! order error of the quantized modes.
//!
//! Run: `cargo bench --features testing --bench sort` (filter with e.g. `-- 1000000`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use rayon::prelude::*;
use rdst::{RadixKey, RadixSort};
use splatgl::camera::Camera;
use splatgl::cull::{CullBounds, Frustum, visible_into};
use splatgl::sort::{Precision, SortRequest, Sorter, far_first_key, squared_distance};

use splatgl::synthetic::Rng;

/// A scene and the eye to sort it for.
struct Scene {
    name: &'static str,
    positions: Vec<[f32; 3]>,
    eye: [f32; 3],
}

/// Uniform in a 20 m cube, seen from outside.
fn uniform(n: usize) -> Scene {
    let mut rng = Rng::new(1);
    let positions = (0..n)
        .map(|_| {
            [
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
            ]
        })
        .collect();
    Scene {
        name: "uniform",
        positions,
        eye: [3.0, 5.0, -30.0],
    }
}

/// Like a captured scene, eye inside it: 90 % in ~300 Gaussian clusters of power-law sizes and
/// 5 cm – 3 m spreads over a 100 m × 20 m × 100 m area (objects, ground), 10 % on a far
/// "sky" shell at 150–250 m.
fn clustered(n: usize) -> Scene {
    let mut rng = Rng::new(2);
    let k = 300;
    let centres: Vec<([f32; 3], f32, f32)> = (0..k)
        .map(|i| {
            let c = [
                rng.range(-50.0, 50.0),
                rng.range(-2.0, 18.0),
                rng.range(-50.0, 50.0),
            ];
            let sigma = 0.05 * 60f32.powf(rng.unit());
            let weight = 1.0 / (i as f32 + 1.0); // Zipf cluster sizes
            (c, sigma, weight)
        })
        .collect();
    let total: f32 = centres.iter().map(|c| c.2).sum();
    let mut positions = Vec::with_capacity(n);
    let n_sky = n / 10;
    for (c, sigma, w) in &centres {
        let m = ((n - n_sky) as f32 * w / total) as usize;
        for _ in 0..m {
            positions.push([
                c[0] + sigma * rng.normal(),
                c[1] + sigma * rng.normal(),
                c[2] + sigma * rng.normal(),
            ]);
        }
    }
    while positions.len() < n {
        let d = [rng.normal(), rng.normal().abs(), rng.normal()];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-6);
        let r = rng.range(150.0, 250.0) / l;
        positions.push(d.map(|x| x * r));
    }
    Scene {
        name: "clustered",
        positions,
        eye: [1.0, 1.6, -3.0],
    }
}

/// An `rdst` item: sorted by the 4 bytes of the far-first key only (not the index).
#[derive(Clone, Copy)]
struct Item {
    key: u32,
    index: u32,
}
impl RadixKey for Item {
    const LEVELS: usize = 4;
    #[inline]
    fn get_level(&self, level: usize) -> u8 {
        (self.key >> (level * 8)) as u8
    }
}

fn config(c: &mut Criterion) -> criterion::BenchmarkGroup<'_, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group("sort");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    g
}

fn competitors(c: &mut Criterion) {
    print_quantized_errors();
    let mut g = config(c);
    for n in [100_000usize, 1_000_000, 4_000_000] {
        for scene in [uniform(n), clustered(n)] {
            let Scene {
                name,
                positions,
                eye,
            } = &scene;
            let keys: Vec<f32> = positions
                .iter()
                .map(|&p| squared_distance(p, *eye))
                .collect();
            let id = |what: &str| BenchmarkId::new(format!("{name}/{what}"), n);

            let mut ours = Sorter::new();
            g.bench_function(id("ours keys+sort"), |b| {
                b.iter(|| black_box(ours.sort_by_distance(positions, *eye)).len())
            });
            g.bench_function(id("ours sort_keys"), |b| {
                b.iter(|| black_box(ours.sort_keys(&keys)).len())
            });
            let mut ours8 = Sorter::new();
            ours8.set_max_digit_bits(8);
            g.bench_function(id("ours 4x8bit sort_keys"), |b| {
                b.iter(|| black_box(ours8.sort_keys(&keys)).len())
            });
            for bits in [16, 24] {
                let mut q = Sorter::new().with_precision(Precision::Quantized { bits });
                g.bench_function(id(&format!("ours q{bits} keys+sort")), |b| {
                    b.iter(|| black_box(q.sort_by_distance(positions, *eye)).len())
                });
            }

            // Competitors sort (key, index) pairs built from the same keys, reusing buffers;
            // building the pairs and extracting the indices is timed, as ours maps keys too.
            let mut pairs: Vec<(f32, u32)> = Vec::with_capacity(n);
            let mut out: Vec<u32> = Vec::with_capacity(n);
            g.bench_function(id("std sort_unstable_by"), |b| {
                b.iter(|| {
                    pairs.clear();
                    pairs.extend(keys.iter().enumerate().map(|(i, &k)| (k, i as u32)));
                    pairs.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
                    out.clear();
                    out.extend(pairs.iter().map(|p| p.1));
                    black_box(out.len())
                })
            });
            g.bench_function(id("rayon par_sort_unstable_by"), |b| {
                b.iter(|| {
                    pairs.clear();
                    pairs.par_extend(keys.par_iter().enumerate().map(|(i, &k)| (k, i as u32)));
                    pairs.par_sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
                    out.clear();
                    out.par_extend(pairs.par_iter().map(|p| p.1));
                    black_box(out.len())
                })
            });
            let mut items: Vec<Item> = Vec::with_capacity(n);
            g.bench_function(id("rdst radix_sort_unstable"), |b| {
                b.iter(|| {
                    items.clear();
                    items.par_extend(keys.par_iter().enumerate().map(|(i, &k)| Item {
                        key: far_first_key(k),
                        index: i as u32,
                    }));
                    items.radix_sort_unstable();
                    out.clear();
                    out.par_extend(items.par_iter().map(|p| p.index));
                    black_box(out.len())
                })
            });
        }
    }
    g.finish();
}

/// A camera at `eye` looking at the origin turned by `a` radians about +Y.
fn turned(eye: Vec3, a: f32) -> Camera {
    let dir = glam::Quat::from_rotation_y(a) * (-eye);
    Camera::look_at(eye, eye + dir, Vec3::Y, 1.0, 1280, 720)
}

/// The turn (bisected) at which about half of what the unturned camera sees is in view.
fn half_view_angle(eye: Vec3, positions: &[[f32; 3]], bounds: &CullBounds) -> f32 {
    let mut ids = Vec::new();
    let mut seen = |a: f32| {
        let f = Frustum::from_camera(&turned(eye, a), 0.2);
        visible_into(&f, positions, bounds, &mut ids)
    };
    let (mut lo, mut hi) = (0.0f32, std::f32::consts::PI);
    let all = seen(0.0);
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if seen(mid) > all / 2 {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}

/// Whole per-frame CPU cost at 1M: keys + sort + filling the index upload buffer (a plain
/// `Vec<u32>` standing in for a mapped GL buffer).
fn per_frame(c: &mut Criterion) {
    let mut g = config(c);
    let n = 1_000_000;
    for scene in [uniform(n), clustered(n)] {
        let mut sorter = Sorter::new();
        let mut upload = vec![0u32; n];
        let mut frame = 0u32;
        g.bench_function(
            BenchmarkId::new(format!("{}/per-frame", scene.name), n),
            |b| {
                b.iter(|| {
                    // A moving camera: a different eye every frame.
                    frame = frame.wrapping_add(1);
                    let mut eye = scene.eye;
                    eye[0] += frame as f32 * 1e-3;
                    let order = sorter.sort_by_distance(&scene.positions, eye);
                    upload.copy_from_slice(order);
                    black_box(upload[n / 2])
                })
            },
        );
        // The culled sort (`Sorter::sort_visible`): a camera at the scene's eye seeing all of
        // it, and one turned until about half is in view; and the cull pass alone.
        let mut bounds = CullBounds::from_radii(vec![0.05; n]);
        bounds.set_extent(&scene.positions);
        let eye = Vec3::from_array(scene.eye);
        let mut ids = Vec::new();
        let half = half_view_angle(eye, &scene.positions, &bounds);
        let wide = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 2.4, 1280, 720);
        for cam in [wide, turned(eye, half)] {
            let frustum = Frustum::from_camera(&cam, 0.2);
            let m = visible_into(&frustum, &scene.positions, &bounds, &mut ids);
            let share = format!("{:.0}% in view", 100.0 * m as f64 / n as f64);
            let what = format!("{}/cull pass, {share}", scene.name);
            g.bench_function(BenchmarkId::new(what, n), |b| {
                b.iter(|| black_box(visible_into(&frustum, &scene.positions, &bounds, &mut ids)))
            });
            let what = format!("{}/culled per-frame, {share}", scene.name);
            g.bench_function(BenchmarkId::new(what, n), |b| {
                b.iter(|| {
                    frame = frame.wrapping_add(1);
                    let mut e = scene.eye;
                    e[0] += frame as f32 * 1e-3;
                    let r = SortRequest::distance(e);
                    let order = sorter.sort_visible(&scene.positions, &bounds, &frustum, &r);
                    upload[..order.len()].copy_from_slice(order);
                    black_box(upload[order.len() / 2])
                })
            });
        }
    }
    // Bandwidth baselines: one 2-thread copy of 1M u64 (one radix pass moves as much:
    // 8 MB read + 8 MB written) and one random scatter of the same.
    let src: Vec<u64> = (0..n as u64).collect();
    let mut dst = vec![0u64; n];
    g.bench_function(BenchmarkId::new("bandwidth/copy 8MB 2 threads", n), |b| {
        b.iter(|| {
            dst.par_chunks_mut(n / 2)
                .zip(src.par_chunks(n / 2))
                .for_each(|(d, s)| d.copy_from_slice(s));
            black_box(dst[7])
        })
    });
    g.finish();
}

/// Order errors of the quantized modes at 1M, against the full-precision order.
fn print_quantized_errors() {
    eprintln!(
        "quantized order error at N = 1M (distance keys, misordered = a nearer splat drawn before a farther one)"
    );
    for scene in [uniform(1_000_000), clustered(1_000_000)] {
        let dist: Vec<f32> = scene
            .positions
            .iter()
            .map(|&p| squared_distance(p, scene.eye).sqrt())
            .collect();
        let (lo, hi) = dist
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            });
        for bits in [16u32, 20, 24] {
            let mut q = Sorter::new().with_precision(Precision::Quantized { bits });
            let order = q.sort_by_distance(&scene.positions, scene.eye);
            let w = splatgl::sort::quantized_bucket_width(lo, hi, bits);
            // Adjacent inversions and the largest inversion over all pairs.
            let adjacent = order
                .windows(2)
                .filter(|p| dist[p[0] as usize] < dist[p[1] as usize])
                .count();
            let (mut min_before, mut worst) = (f32::INFINITY, 0f32);
            for &i in order {
                let k = dist[i as usize];
                worst = worst.max(k - min_before);
                min_before = min_before.min(k);
            }
            eprintln!(
                "  {:9} {bits} bits: bucket {:.3e} m, adjacent inversions {adjacent} ({:.3} %), worst inversion {:.3e} m",
                scene.name,
                w,
                100.0 * adjacent as f64 / order.len() as f64,
                worst
            );
        }
    }
}

criterion_group!(benches, competitors, per_frame);
criterion_main!(benches);
