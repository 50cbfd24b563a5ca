//! Shared test helpers: a seeded PRNG and random clouds.
#![allow(dead_code)]

use splatgl::SplatCloud;

pub mod packed;

pub use splatgl::scene::Rng;

/// A random cloud of `n` splats, SH degree `degree`.
pub fn random_cloud(seed: u64, n: usize, degree: u8) -> SplatCloud {
    let mut r = Rng::new(seed);
    let mut c = SplatCloud::with_capacity(degree, n);
    let k = c.coeffs_per_splat();
    for _ in 0..n {
        let p = [0; 3].map(|_| r.range(-5.0, 5.0));
        let s = [0; 3].map(|_| r.range(0.01, 0.5));
        let q = r.quat();
        let o = r.range(0.05, 1.0);
        let sh: Vec<[f32; 3]> = (0..k)
            .map(|j| [0; 3].map(|_| r.range(-1.0, 1.0) / (1 + j) as f32))
            .collect();
        c.push(p, s, q, o, &sh);
    }
    c
}

/// Path of a file in the shared real-data folder (None, with a note, if absent).
pub fn real(name: &str) -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/real")
        .join(name);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipping: {} not found", p.display());
        None
    }
}
