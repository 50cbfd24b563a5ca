//! Reference rasterizer: 50,000 random splats (SH degree 3) at 640×480.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use splatgl::camera::Camera;
use splatgl::reference::{RenderOptions, render_with_stats};
use splatgl::scene::random_cloud;
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
    c.bench_function("reference 50k splats 640x480", |b| {
        b.iter(|| render_with_stats(&cloud, &cam, &opts))
    });
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
