//! Embedding `SplatRenderer` in a host that owns its GL context, framebuffer and depth buffer.
//!
//! The "host" here is a headless EGL context with its own FBO (colour + depth), standing in
//! for an application's window. Each frame it clears colour and depth (a real host draws its
//! opaque scene here), then lets splatgl draw the splats with the depth test on (splats never
//! write depth), for a short orbit of the camera. Per frame only the sorted order is uploaded, sorted by one
//! reused `splatgl::sort::Sorter` (no allocation once warm).
//!
//! `cargo run --release --example embed -- [SCENE] [OUT_PREFIX]` writes OUT_PREFIX-N.png.

use glam::Vec3;
use glow::HasContext;
use splatgl::camera::Camera;
use splatgl::gl::{ColorFormat, DepthFormat, ReadbackTarget, SplatRenderer};
use splatgl::headless::HeadlessContext;
use splatgl::image::PngDepth;
use splatgl::sort::Sorter;

const W: u32 = 320;
const H: u32 = 240;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cloud = match args.next() {
        Some(p) => splatgl::load::load_path(&p, &Default::default())?.cloud,
        None => splatgl::scene::default_scene(),
    };
    let prefix = args.next().unwrap_or_else(|| "embed".into());

    // --- the host: a context and a framebuffer with a depth buffer ---
    let ctx = HeadlessContext::new()?;
    let gl = ctx.gl();
    // (A real host has its window's framebuffer here; `ReadbackTarget` stands in for it and
    // reads the frames back.)
    let mut host = ReadbackTarget::new(gl, W, H, ColorFormat::Rgba8, Some(DepthFormat::Depth24))?;

    // --- splatgl: created once, data uploaded once ---
    let mut renderer = SplatRenderer::new(gl)?;
    renderer.upload(gl, &cloud)?;
    renderer.settings_mut().depth_test = true; // respect the host's depth buffer
    let mut sorter = Sorter::new();

    let target = cloud
        .bounds()
        .map_or(Vec3::ZERO, |b| Vec3::from_array(b.center()));
    let radius = cloud.bounds().map_or(3.0, |b| b.diagonal().max(0.1));
    for frame in 0..4 {
        let a = frame as f32 * 0.5;
        let eye = target + Vec3::new(a.sin(), 0.4, a.cos()) * radius;
        let camera = Camera::look_at(eye, target, Vec3::Y, 50f32.to_radians(), W, H);
        // Host pass: clear colour and depth (a real host would draw its scene here).
        host.bind(gl)?;
        // SAFETY: state changes on the host's own framebuffer.
        unsafe {
            gl.clear_color(0.1, 0.1, 0.12, 0.0);
            gl.depth_mask(true);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        // splatgl pass: sort on the CPU, upload the order, draw.
        let order = sorter.sort_by_distance(&cloud.positions, camera.eye().to_array());
        renderer.draw(gl, &camera, order)?;

        let out = format!("{prefix}-{frame}.png");
        host.read_image(gl)?
            .write_png(&out, PngDepth::Eight, false)?;
        eprintln!("frame {frame}: {} splats -> {out}", order.len());
    }
    renderer.destroy(gl);
    host.destroy(gl);
    Ok(())
}
