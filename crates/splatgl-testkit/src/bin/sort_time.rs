//! Milliseconds per sort of N random splats by camera distance, natively: the counterpart of
//! the web build's `sort_ms` (crates/splatgl-web), for docs/web.md's table. Same cloud, same
//! eyes, one warm-up; THREADS=1 (RAYON_NUM_THREADS=1) matches the web's single thread.
//!
//! `cargo run --release -p splatgl-testkit --bin sort_time -- [N] [REPS]`
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let reps: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let cloud = splatgl::synthetic::random_cloud(n, 0, 5.0, 7);
    let mut sorter = splatgl::sort::Sorter::new();
    sorter.sort_by_distance(&cloud.positions, [0.0, 0.0, -20.0]);
    let started = Instant::now();
    for i in 0..reps {
        sorter.sort_by_distance(&cloud.positions, [0.01 * i as f32, 0.0, -20.0]);
    }
    let ms = started.elapsed().as_secs_f64() * 1e3 / f64::from(reps.max(1));
    println!(
        "{n} splats: {ms:.2} ms per sort ({} rayon threads)",
        rayon::current_num_threads()
    );
}
