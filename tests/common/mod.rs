//! Shared test helpers: a seeded PRNG and random clouds.
#![allow(dead_code)]

use splatgl::SplatCloud;

/// SplitMix64: small, seeded, reproducible.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    /// A random unit quaternion (xyzw).
    pub fn quat(&mut self) -> [f32; 4] {
        loop {
            let q = [0; 4].map(|_| self.range(-1.0, 1.0));
            let n = q.iter().map(|v| v * v).sum::<f32>().sqrt();
            if n > 0.1 && n <= 1.0 {
                return q.map(|v| v / n);
            }
        }
    }
}

/// A random cloud of `n` splats, SH degree `degree`.
pub fn random_cloud(seed: u64, n: usize, degree: u8) -> SplatCloud {
    let mut r = Rng(seed);
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
