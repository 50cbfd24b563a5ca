//! The viewer's panel is a guest in the splats' GL context: whatever egui_glow's painter
//! leaves bound or enabled (its program, VAO, buffers and font texture, its blend function,
//! the scissor box, the viewport, `GL_FRAMEBUFFER_SRGB` off on desktop GL) never reaches the
//! next frame of splats. Each case draws a frame, paints an egui frame (a side panel with
//! text, a slider and a button, and lines over the scene, as the viewer's crop box) into a
//! framebuffer of its own, draws the same frame again, and requires the two images to be
//! identical; also that egui really drew. On GLES 3 and desktop GL core, 8-bit and float
//! targets, sRGB and linear clouds.

use crate::common;

use std::sync::Arc;

use common::gl::*;
use glow::HasContext;

const W: u32 = 96;
const H: u32 = 64;

/// An RGBA8 framebuffer for egui to paint into.
struct Canvas {
    fbo: glow::Framebuffer,
    tex: glow::Texture,
}

impl Canvas {
    fn new(gl: &glow::Context) -> Canvas {
        // SAFETY: creates and binds a complete RGBA8 colour attachment of W × H.
        unsafe {
            let tex = gl.create_texture().unwrap();
            gl.bind_texture(glow::TEXTURE_2D, Some(tex));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, glow::RGBA8, W as i32, H as i32);
            let fbo = gl.create_framebuffer().unwrap();
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(tex),
                0,
            );
            assert_eq!(
                gl.check_framebuffer_status(glow::FRAMEBUFFER),
                glow::FRAMEBUFFER_COMPLETE
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.bind_texture(glow::TEXTURE_2D, None);
            Canvas { fbo, tex }
        }
    }

    /// Pixels of the canvas that are not black.
    fn painted(&self, gl: &glow::Context) -> usize {
        let mut px = vec![0u8; (W * H * 4) as usize];
        // SAFETY: reads W × H RGBA8 pixels of the canvas into a buffer of that size.
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.fbo));
            gl.read_pixels(
                0,
                0,
                W as i32,
                H as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut px)),
            );
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        }
        px.chunks_exact(4).filter(|p| p[..3] != [0, 0, 0]).count()
    }

    fn delete(self, gl: &glow::Context) {
        // SAFETY: deletes objects this test made.
        unsafe {
            gl.delete_framebuffer(self.fbo);
            gl.delete_texture(self.tex);
        }
    }
}

/// One egui frame as the viewer's panel paints it.
fn paint_egui(painter: &mut egui_glow::Painter, ctx: &egui::Context) {
    let raw = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(W as f32, H as f32),
        )),
        ..Default::default()
    };
    let mut value = 0.5f32;
    let out = ctx.run_ui(raw, |root| {
        egui::Panel::left("panel").show(root, |ui| {
            ui.label("splats 1,234");
            ui.add(egui::Slider::new(&mut value, 0.0..=1.0));
            let _ = ui.button("Reset");
        });
        let p = root.painter();
        p.line_segment(
            [egui::pos2(50.0, 5.0), egui::pos2(90.0, 60.0)],
            egui::Stroke::new(1.5, egui::Color32::YELLOW),
        );
    });
    let prims = ctx.tessellate(out.shapes, out.pixels_per_point);
    let mut textures = out.textures_delta;
    painter.paint_and_update_textures([W, H], out.pixels_per_point, &prims, &mut textures);
}

fn scene() -> SplatCloud {
    synthetic::random_cloud(300, 1, 0.8, 41)
}

fn check(api: GlApi, target: TargetKind, color_space: ColorSpace) {
    let what = format!("{api:?} {target:?} {color_space:?}");
    let Some(ctx) = or_skip(HeadlessContext::with_api(api), &what) else {
        return;
    };
    let mut hr = HeadlessRenderer::with_context(ctx).expect("renderer");
    let cloud = scene();
    hr.upload(&cloud).expect("upload");
    let cam = common::frame_points(&cloud.positions, 0.9, W, H).expect("framing");
    let opts = HeadlessOptions {
        target,
        color_space: Some(color_space),
        background: [0.1, 0.2, 0.3],
        ..Default::default()
    };
    let before = hr.render(&cam, &opts).expect("render");
    // egui's own function table over the same current context, as the viewer shares its
    // context with the painter.
    // SAFETY: the loader returns the current context's function pointers.
    let gl = Arc::new(unsafe {
        glow::Context::from_loader_function(|s| hr.context().get_proc_address(s))
    });
    let mut painter = egui_glow::Painter::new(Arc::clone(&gl), "", None, false).expect("painter");
    let ectx = egui::Context::default();
    let canvas = Canvas::new(&gl);
    for _ in 0..2 {
        // SAFETY: binds the canvas for egui, as the viewer binds the window's framebuffer.
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, Some(canvas.fbo)) };
        paint_egui(&mut painter, &ectx);
        // SAFETY: back to no framebuffer, as the viewer's swap leaves it.
        unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    }
    let painted = canvas.painted(&gl);
    assert!(painted > 200, "{what}: egui painted only {painted} pixels");
    let after = hr.render(&cam, &opts).expect("render after egui");
    let c = compare(&before, &after, 0.0).expect("same size");
    assert_eq!(
        c.max_abs, 0.0,
        "{what}: the frame after an egui frame differs from the one before: {c:?}"
    );
    canvas.delete(&gl);
    painter.destroy();
}

#[test]
fn panel_leaves_nothing_that_changes_the_next_gles_frame() {
    for target in [TargetKind::Rgba8, TargetKind::Rgba16fResolve] {
        for cs in [ColorSpace::SrgbRec709Display, ColorSpace::LinRec709Display] {
            check(GlApi::Gles3, target, cs);
        }
    }
}

#[test]
fn panel_leaves_nothing_that_changes_the_next_desktop_frame() {
    for target in [TargetKind::Rgba8, TargetKind::Rgba16fResolve] {
        for cs in [ColorSpace::SrgbRec709Display, ColorSpace::LinRec709Display] {
            check(GlApi::DesktopCore33, target, cs);
        }
    }
}
