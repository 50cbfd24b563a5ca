//! One frame into the window's framebuffer through the frame path headless rendering uses
//! ([`splatgl::gl::frame`]): blend in `RGBA16F` and resolve where the context can render to it,
//! else in 8 bits; with `--resolution-scale` ≠ 1 the image is made at the scaled size and
//! stretched to the window. Also the screenshot read-back of the window's back buffer.

use glow::HasContext;

use splatgl::camera::Camera;
use splatgl::gl::frame::{Blend, FrameTargets, Output};
use splatgl::gl::{DrawSettings, GlError, SplatRenderer};
use splatgl::image::Image;

/// The framebuffers of the viewer's frames ([`FrameTargets`], the frame path headless
/// rendering uses too), kept across frames and re-made on resize.
#[derive(Debug, Default)]
pub struct Targets {
    frame: FrameTargets,
    /// Blend in 8 bits even where a float target works (`--target rgba8`).
    pub force_rgba8: bool,
}

impl Targets {
    fn blend(&self) -> Blend {
        if self.force_rgba8 {
            Blend::Rgba8
        } else {
            Blend::Rgba16fOrRgba8
        }
    }

    /// Draws the renderer's current order seen by `cam` (whose size is the image size) over
    /// `background` (display values) into the window's framebuffer of size `window`.
    pub fn draw(
        &mut self,
        gl: &glow::Context,
        renderer: &SplatRenderer,
        cam: &Camera,
        settings: &DrawSettings,
        background: [f32; 3],
        window: (u32, u32),
    ) -> Result<(), GlError> {
        let blend = self.blend();
        let out = Output::Window(window.0, window.1);
        self.frame
            .draw(
                gl,
                renderer,
                cam,
                settings,
                background,
                blend,
                out,
                "drawing a viewer frame",
            )
            .map(|_| ())
    }

    /// Deletes the targets (context current).
    pub fn destroy(&mut self, gl: &glow::Context) {
        self.frame.destroy(gl);
    }
}

/// The window's back buffer as drawn (before the swap), top row first, alpha 1: exactly the
/// pixels shown.
pub fn read_back_buffer(gl: &glow::Context, width: u32, height: u32) -> Image {
    let row = width as usize * 4;
    let mut bytes = vec![0u8; row * height as usize];
    // SAFETY: reads `width × height` RGBA8 pixels of the default framebuffer into a buffer of
    // exactly that size (pack alignment 4 divides a row of RGBA8 pixels).
    unsafe {
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
        gl.read_pixels(
            0,
            0,
            width as i32,
            height as i32,
            glow::RGBA,
            glow::UNSIGNED_BYTE,
            glow::PixelPackData::Slice(Some(&mut bytes)),
        );
    }
    let mut flipped = Vec::with_capacity(bytes.len());
    for r in bytes.chunks_exact(row).rev() {
        flipped.extend_from_slice(r);
    }
    for px in flipped.chunks_exact_mut(4) {
        px[3] = 255;
    }
    Image::from_rgba8(width, height, &flipped)
}
