//! Parses a PLY file N times and prints the throughput (profiling aid):
//! `cargo run --release -p splatgl-testkit --bin ply_parse -- FILE [N]`.
fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: ply_parse FILE [N]");
        std::process::exit(2);
    };
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(5);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    for _ in 0..n {
        let t = std::time::Instant::now();
        match splatgl::load::load_bytes(&bytes, None, &Default::default()) {
            Ok(l) => {
                let s = t.elapsed().as_secs_f64();
                println!(
                    "{} splats in {:.1} ms: {:.2} GB/s",
                    l.cloud.len(),
                    s * 1e3,
                    bytes.len() as f64 / s / 1e9
                );
            }
            Err(e) => {
                eprintln!("{path}: {e}");
                std::process::exit(2);
            }
        }
    }
}
