//! Synthetic scenes: the bundled default scene (what `splatgl render` shows without a file)
//! and seeded random clouds for tests and benchmarks. Everything is deterministic: a SplitMix64
//! generator, no platform-dependent maths beyond IEEE `f32`/`f64` and `libm`-free formulas.

use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::sh::{SH_C1, dc_from_color};
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// SplitMix64: a tiny, seedable, deterministic generator.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform integer in `[0, n)` (n > 0; modulo bias is irrelevant for test data).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f32 {
        let u = self.unit().max(1e-7);
        let v = self.unit();
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
    /// A uniformly distributed unit quaternion `[x, y, z, w]`.
    pub fn quat(&mut self) -> [f32; 4] {
        let (u1, u2, u3) = (self.unit(), self.unit() * TAU, self.unit() * TAU);
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let q = Quat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos());
        q.normalize().to_array()
    }
}

/// A random cloud: `n` splats with means uniform in `[-extent, extent]³`, scales
/// `0.01..0.08 · extent`, random rotations, opacities `0.2..1`, DC colour `0.1..0.9` and higher
/// SH coefficients in `±0.3`.
pub fn random_cloud(n: usize, sh_degree: u8, extent: f32, seed: u64) -> SplatCloud {
    let mut rng = Rng::new(seed);
    let mut cloud = SplatCloud::with_capacity(sh_degree, n);
    let k = cloud.coeffs_per_splat();
    let mut sh = vec![[0.0f32; 3]; k];
    for _ in 0..n {
        let p = [(); 3].map(|_| rng.range(-extent, extent));
        let s = [(); 3].map(|_| rng.range(0.01, 0.08) * extent);
        let q = rng.quat();
        let o = rng.range(0.2, 1.0);
        sh[0] = [(); 3].map(|_| dc_from_color(rng.range(0.1, 0.9) as f64));
        for c in sh.iter_mut().skip(1) {
            *c = [(); 3].map(|_| rng.range(-0.3, 0.3));
        }
        cloud.push(p, s, q, o, &sh);
    }
    cloud
}

/// SH coefficients (degree 1) for colour `rgb` with a white sheen `k · max(0, −dir·n)`-like
/// term: `k · (−dir · n)` is added, brightest when the splat faces the viewer.
fn sheen_sh(rgb: [f32; 3], n: Vec3, k: f32) -> [[f32; 3]; 4] {
    let c1 = SH_C1 as f32;
    // Σ c·Y over degree 1 = −C1·y·c₋₁ + C1·z·c₀ − C1·x·c₁ = −k (nx x + ny y + nz z).
    let (cm1, c0, cp1) = (k * n.y / c1, -k * n.z / c1, k * n.x / c1);
    [
        rgb.map(|c| dc_from_color(c as f64)),
        [cm1; 3],
        [c0; 3],
        [cp1; 3],
    ]
}

fn hue(h: f32) -> [f32; 3] {
    let h6 = h.rem_euclid(1.0) * 6.0;
    let rgb = [
        (h6 - 3.0).abs() - 1.0,
        2.0 - (h6 - 2.0).abs(),
        2.0 - (h6 - 4.0).abs(),
    ];
    rgb.map(|c| c.clamp(0.0, 1.0) * 0.8 + 0.1)
}

fn push_surface(cloud: &mut SplatCloud, p: Vec3, n: Vec3, size: f32, rgb: [f32; 3], o: f32) {
    let n = n.normalize();
    let q = Quat::from_rotation_arc(Vec3::Z, n);
    // Baked key light from above-right-front, so shapes read as 3D.
    let shade = 0.4 + 0.6 * n.dot(Vec3::new(0.45, 0.8, 0.4).normalize()).max(0.0);
    let sh = sheen_sh(rgb.map(|c| c * shade), n, 0.18);
    cloud.push(
        p.to_array(),
        [size, size, 0.15 * size],
        q.to_array(),
        o,
        &sh,
    );
}

/// The bundled default scene (SH degree 1, about 6,000 splats, glTF axes: +Y up): a tilted
/// rainbow torus around a golden sphere above a checkered disc, every splat with a view-dependent
/// sheen.
pub fn default_scene() -> SplatCloud {
    let mut rng = Rng::new(0x5EED_5CA7);
    let mut cloud = SplatCloud::new(1);
    // Checkered ground disc, y = 0, radius 2.6.
    let step = 0.085;
    for i in -32..=32 {
        for j in -32..=32 {
            let (x, z) = (
                i as f32 * step + rng.range(-0.02, 0.02),
                j as f32 * step + rng.range(-0.02, 0.02),
            );
            if x * x + z * z > 2.6 * 2.6 {
                continue;
            }
            let dark = ((x / 0.5).floor() as i32 + (z / 0.5).floor() as i32) % 2 == 0;
            let rgb = if dark {
                [0.18, 0.2, 0.28]
            } else {
                [0.85, 0.83, 0.78]
            };
            push_surface(&mut cloud, Vec3::new(x, 0.0, z), Vec3::Y, 0.06, rgb, 0.95);
        }
    }
    // Golden sphere, radius 0.45, centre (0, 0.9, 0): Fibonacci points.
    let centre = Vec3::new(0.0, 0.9, 0.0);
    let m = 900;
    for k in 0..m {
        let y = 1.0 - 2.0 * (k as f32 + 0.5) / m as f32;
        let r = (1.0 - y * y).sqrt();
        let phi = k as f32 * 2.399_963;
        let n = Vec3::new(r * phi.cos(), y, r * phi.sin());
        push_surface(
            &mut cloud,
            centre + 0.45 * n,
            n,
            0.05,
            [0.95, 0.7, 0.2],
            0.98,
        );
    }
    // Rainbow torus around the sphere, tilted 30° about x.
    let tilt = Quat::from_rotation_x(0.52);
    let (big, small) = (1.05, 0.22);
    let (nu, nv) = (96, 28);
    for a in 0..nu {
        for b in 0..nv {
            let u = (a as f32 + rng.range(-0.2, 0.2)) / nu as f32 * TAU;
            let v = (b as f32 + rng.range(-0.2, 0.2)) / nv as f32 * TAU;
            let n = Vec3::new(v.cos() * u.cos(), v.sin(), v.cos() * u.sin());
            let p = Vec3::new(big * u.cos(), 0.0, big * u.sin()) + small * n;
            let rgb = hue(a as f32 / nu as f32);
            push_surface(&mut cloud, centre + tilt * p, tilt * n, 0.045, rgb, 0.97);
        }
    }
    cloud
}

/// The default scene's camera ([`Camera::default_scene_view`]).
pub fn default_camera(width: u32, height: u32) -> Camera {
    Camera::default_scene_view(width, height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_are_deterministic_and_well_formed() {
        let a = default_scene();
        assert_eq!(a, default_scene());
        assert!(a.check_lengths().is_ok() && a.sh_degree == 1 && a.len() > 3000);
        let r = random_cloud(100, 3, 2.0, 5);
        assert_eq!(r, random_cloud(100, 3, 2.0, 5));
        assert_ne!(r, random_cloud(100, 3, 2.0, 6));
        assert!(r.check_lengths().is_ok());
        assert!(r.rotations.iter().all(|q| {
            let n: f32 = q.iter().map(|v| v * v).sum();
            (n - 1.0).abs() < 1e-5
        }));
    }
}
