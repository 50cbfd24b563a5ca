//! Writes a random cloud of N splats with SH degree 3 (benchmark input) as INRIA PLY (or GLB /
//! glTF by the extension): `cargo run --release --example gen_ply -- OUT.ply [N]`.
fn main() {
    let mut args = std::env::args().skip(1);
    let Some(out) = args.next() else {
        eprintln!("usage: gen_ply OUT.ply [N]");
        std::process::exit(2);
    };
    let n: usize = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let cloud = splatgl::scene::random_cloud(n, 3, 10.0, 7);
    if let Err(e) = splatgl::write::save(&cloud, std::path::Path::new(&out), &[]) {
        eprintln!("{out}: {e}");
        std::process::exit(2);
    }
}
