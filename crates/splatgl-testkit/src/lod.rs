//! Helpers of the LOD fidelity tests (`crates/splatgl-cli/tests/it/tiles_build.rs`, `crates/splatgl-cli/tests/it/tiles_streamed_sog.rs`):
//! reference renders, PSNR, cameras around a cloud, and the comparison with uniform
//! decimation to the same splat count.

use glam::Vec3;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::image::Image;

/// The reference rasterizer's image of `cloud` from `cam`.
pub fn render(cloud: &SplatCloud, cam: &Camera) -> Image {
    splatgl::reference::render(cloud, cam, &Default::default())
}

/// PSNR of `a` against `b`.
pub fn psnr(a: &Image, b: &Image) -> f64 {
    splatgl::compare::compare(a, b, 1.0 / 255.0).unwrap().psnr
}

/// A camera at `distance` × the cloud's bounding radius from its centre along `dir`, looking
/// at it with `up`, 320×240.
pub fn camera_at(cloud: &SplatCloud, dir: Vec3, distance: f32, up: Vec3) -> Camera {
    let b = cloud.bounds().unwrap();
    let c = Vec3::from(b.center());
    let r = b.diagonal() / 2.0;
    Camera::look_at(
        c + dir.normalize() * r * distance,
        c,
        up,
        50f32.to_radians(),
        320,
        240,
    )
}

/// PSNR against the whole scene's render from `cam` of `lod`, and of every k-th splat of
/// `full` (uniform decimation to `lod`'s splat count).
pub fn lod_and_uniform_psnr(full: &SplatCloud, lod: &SplatCloud, cam: &Camera) -> (f64, f64) {
    let step = full.len() as f64 / lod.len() as f64;
    let picked: Vec<u32> = (0..lod.len()).map(|i| (i as f64 * step) as u32).collect();
    let uniform = full.select(&picked);
    let reference = render(full, cam);
    (
        psnr(&render(lod, cam), &reference),
        psnr(&render(&uniform, cam), &reference),
    )
}
