//! PLY parsing throughput: 1M splats, SH degree 3 (248 MB), generated in memory.
//! Reported as bytes/s by criterion; the baseline in the same run is a plain `memcpy` of the
//! same bytes, so the ratio says how close to memory bandwidth the parser runs.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use splatgl::SplatCloud;
use std::hint::black_box;

fn cloud(n: usize) -> SplatCloud {
    let mut c = SplatCloud::with_capacity(3, n);
    let mut s = 0x1234_5678u32;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut sh = [[0.0f32; 3]; 16];
    for _ in 0..n {
        for c in sh.iter_mut() {
            *c = [r() - 0.5, r() - 0.5, r() - 0.5];
        }
        let q = [r() - 0.5, r() - 0.5, r() - 0.5, r() + 0.5];
        let qn = q.iter().map(|v| v * v).sum::<f32>().sqrt();
        c.push(
            [r() * 10.0, r() * 10.0, r() * 10.0],
            [r() * 0.1 + 0.01; 3],
            q.map(|v| v / qn),
            r() * 0.98 + 0.01,
            &sh,
        );
    }
    c
}

fn bench(c: &mut Criterion) {
    let bytes = splatgl::write::to_inria_ply(&cloud(1_000_000));
    let mut g = c.benchmark_group("ply_1M_sh3");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(5));
    g.throughput(Throughput::Bytes(bytes.len() as u64));
    g.bench_function("memcpy_baseline", |b| b.iter(|| black_box(bytes.clone())));
    g.bench_function("splatgl_ply_load", |b| {
        b.iter(|| {
            splatgl::load::load_bytes(black_box(&bytes), None, &Default::default()).expect("parses")
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
