//! Writes a random cloud of N splats with SH degree 3 (benchmark input) as INRIA PLY (or GLB /
//! glTF by the extension): `cargo run --release -p splatgl-testkit --bin gen_ply -- OUT.ply [N] [--normals]`.
//! With `--normals` (PLY only) the rows carry `nx ny nz` (zero) after `x y z`, as the INRIA
//! trainer writes them: 248 bytes a splat (a 248 MB file for 1M splats) instead of 236.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let normals = args.iter().any(|a| a == "--normals");
    let mut args = args.into_iter().filter(|a| a != "--normals");
    let Some(out) = args.next() else {
        eprintln!("usage: gen_ply OUT.ply [N] [--normals]");
        std::process::exit(2);
    };
    let n: usize = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let cloud = splatgl::synthetic::random_cloud(n, 3, 10.0, 7);
    let path = std::path::Path::new(&out);
    let result = if normals {
        let bytes = splatgl::write::to_inria_ply_with_normals(&cloud);
        splatgl::write::write_bytes_atomic(path, &[], &bytes)
    } else {
        splatgl::write::save(&cloud, path, &[])
    };
    if let Err(e) = result {
        eprintln!("{out}: {e}");
        std::process::exit(2);
    }
}
