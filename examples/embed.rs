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
use splatgl::gl::SplatRenderer;
use splatgl::headless::HeadlessContext;
use splatgl::image::{Image, PngDepth};
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
    // SAFETY: plain GL object creation and binding on the current context.
    let fbo = unsafe {
        let color = gl.create_renderbuffer()?;
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(color));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, W as i32, H as i32);
        let depth = gl.create_renderbuffer()?;
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
        gl.renderbuffer_storage(
            glow::RENDERBUFFER,
            glow::DEPTH_COMPONENT24,
            W as i32,
            H as i32,
        );
        let fbo = gl.create_framebuffer()?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        let (c, d) = (glow::COLOR_ATTACHMENT0, glow::DEPTH_ATTACHMENT);
        gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, c, glow::RENDERBUFFER, Some(color));
        gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, d, glow::RENDERBUFFER, Some(depth));
        gl.viewport(0, 0, W as i32, H as i32);
        fbo
    };

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
        // SAFETY: state changes on the host's own framebuffer.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.clear_color(0.1, 0.1, 0.12, 0.0);
            gl.depth_mask(true);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
        // splatgl pass: sort on the CPU, upload the order, draw.
        let order = sorter.sort_by_distance(&cloud.positions, camera.eye().to_array());
        renderer.draw(gl, &camera, order)?;

        let mut rgba = vec![0u8; (W * H * 4) as usize];
        // SAFETY: reads W×H RGBA8 pixels into a buffer of exactly that size.
        unsafe {
            gl.read_pixels(
                0,
                0,
                W as i32,
                H as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut rgba)),
            );
        }
        // GL rows start at the bottom.
        let row = (W * 4) as usize;
        let flipped: Vec<u8> = rgba.chunks_exact(row).rev().flatten().copied().collect();
        let out = format!("{prefix}-{frame}.png");
        Image::from_rgba8(W, H, &flipped).write_png(&out, PngDepth::Eight, false)?;
        eprintln!("frame {frame}: {} splats -> {out}", order.len());
    }
    renderer.destroy(gl);
    Ok(())
}
