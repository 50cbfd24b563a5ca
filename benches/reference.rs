//! Reference rasterizer at 640×480: 50,000 random splats (SH degree 3, large overlapping
//! footprints: a worst case), and the real 50,000-splat `mujoco_warp_fox_sh0.ply` when
//! `../shared/data/real/` is present.

use splatgl_testkit as common;

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use glam::Vec3;
use splatgl::camera::Camera;
use splatgl::reference::{RenderOptions, render_with_stats};
use splatgl::synthetic::random_cloud;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let cloud = random_cloud(50_000, 3, 1.0, 42);
    let cam = Camera::look_at(
        Vec3::new(0.8, 1.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        50f32.to_radians(),
        640,
        480,
    );
    let opts = RenderOptions::default();
    let (_, stats) = render_with_stats(&cloud, &cam, &opts);
    eprintln!(
        "50k bench scene: {} visible, {} splat-tile pairs",
        stats.visible, stats.tile_entries
    );
    // Flat sampling: 10 samples of one render each fit the 5 s budget.
    let mut g = c.benchmark_group("reference");
    g.sampling_mode(SamplingMode::Flat);
    g.bench_function("random 50k splats 640x480", |b| {
        b.iter(|| render_with_stats(&cloud, &cam, &opts))
    });
    let fox = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/real/mujoco_warp_fox_sh0.ply");
    match splatgl::load::load_path(&fox, &Default::default()) {
        Ok(l) => {
            let cam = common::frame_points(&l.cloud.positions, 50f32.to_radians(), 640, 480)
                .expect("finite means");
            g.bench_function("fox 50k splats 640x480", |b| {
                b.iter(|| render_with_stats(&l.cloud, &cam, &opts))
            });
        }
        Err(e) => eprintln!("skipping the fox benchmark: {e}"),
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    targets = bench
}
criterion_main!(benches);
