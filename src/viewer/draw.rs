//! One frame into the window's framebuffer, on the colour-space path of the headless renderer:
//! blend in an `RGBA16F` [`OffscreenTarget`] and resolve (sRGB-encoding `lin_rec709_display`
//! clouds) when the context can render to `RGBA16F`; otherwise blend in 8 bits (`RGBA8`, or an
//! `SRGB8_ALPHA8` target for linear clouds). With `--resolution-scale` ≠ 1 the image is made
//! at the scaled size in an 8-bit target and stretched to the window (`glBlitFramebuffer`,
//! linear filtering). Also the screenshot read-back of the window's back buffer.

use glow::HasContext;

use crate::camera::Camera;
use crate::cloud::ColorSpace;
use crate::gl::{
    ColorFormat, DrawSettings, GlError, OffscreenTarget, ReadbackTarget, SplatRenderer,
};
use crate::image::Image;

/// The framebuffers of the viewer's frames, kept across frames and re-made on resize.
#[derive(Debug, Default)]
pub struct Targets {
    float: Option<OffscreenTarget>,
    /// The float target could not be made: 8 bits from then on.
    float_unavailable: bool,
    /// Blend in 8 bits even where a float target works (`--target rgba8`).
    pub force_rgba8: bool,
    staging: Option<ReadbackTarget>,
}

impl Targets {
    /// Whether the last frame blended in a float target.
    pub fn float_in_use(&self) -> bool {
        !self.force_rgba8 && !self.float_unavailable
    }

    /// The float target for a `w × h` image, `None` when 8 bits are used.
    fn float_for(&mut self, gl: &glow::Context, w: u32, h: u32) -> Option<&mut OffscreenTarget> {
        if !self.float_in_use() {
            return None;
        }
        if self.float.as_ref().is_none_or(|t| t.size() != (w, h)) {
            if let Some(mut t) = self.float.take() {
                t.destroy(gl);
            }
            match OffscreenTarget::new(gl, w, h) {
                Ok(t) => self.float = Some(t),
                Err(e) => {
                    eprintln!("note: no RGBA16F render target ({e}); blending in 8 bits");
                    self.float_unavailable = true;
                    return None;
                }
            }
        }
        self.float.as_mut()
    }

    /// The 8-bit staging target (`SRGB8_ALPHA8` when `srgb`).
    fn staging_for(
        &mut self,
        gl: &glow::Context,
        w: u32,
        h: u32,
        srgb: bool,
    ) -> Result<&ReadbackTarget, GlError> {
        let format = if srgb {
            ColorFormat::Srgb8Alpha8
        } else {
            ColorFormat::Rgba8
        };
        if self
            .staging
            .as_ref()
            .is_none_or(|t| (t.size(), t.format()) != ((w, h), format))
        {
            if let Some(mut t) = self.staging.take() {
                t.destroy(gl);
            }
            self.staging = Some(ReadbackTarget::new(gl, w, h, format, None)?);
        }
        Ok(self.staging.as_ref().expect("made above"))
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
        let (w, h) = (cam.width, cam.height);
        let linear = renderer.color_space() == ColorSpace::LinRec709Display;
        let bg = if linear {
            background.map(|c| crate::profile::srgb_decode(c as f64) as f32)
        } else {
            background
        };
        let float = self.float_for(gl, w, h).is_some();
        let srgb = linear && !float;
        let staged = (w, h) != window || srgb;
        if staged {
            self.staging_for(gl, w, h, srgb)?.bind(gl)?;
        } else {
            // SAFETY: binding the default framebuffer and setting the viewport to the window.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                gl.viewport(0, 0, window.0 as i32, window.1 as i32);
            }
        }
        let desktop_srgb = srgb && !gl.version().is_embedded;
        // SAFETY: capability switches and a clear of the framebuffer bound just above (the
        // float path's resolve replaces every pixel, so only the 8-bit path clears it).
        unsafe {
            gl.disable(glow::SCISSOR_TEST);
            if desktop_srgb {
                gl.enable(glow::FRAMEBUFFER_SRGB);
            }
            if !float {
                gl.clear_color(bg[0], bg[1], bg[2], 1.0);
                gl.clear(glow::COLOR_BUFFER_BIT);
            }
        }
        let drawn = match self.float.as_mut().filter(|_| float) {
            Some(t) => t.begin(gl, [bg[0], bg[1], bg[2], 0.0]).and_then(|()| {
                renderer.draw_current_with(gl, cam, settings)?;
                t.resolve(gl, linear)
            }),
            None => renderer.draw_current_with(gl, cam, settings),
        };
        if desktop_srgb {
            // SAFETY: restoring the default (disabled).
            unsafe { gl.disable(glow::FRAMEBUFFER_SRGB) };
        }
        drawn?;
        if let Some(t) = self.staging.as_ref().filter(|_| staged) {
            let filter = if (w, h) == window {
                glow::NEAREST
            } else {
                glow::LINEAR
            };
            // SAFETY: a blit from our own framebuffer into the default one; both bindings are
            // left at the default framebuffer.
            unsafe {
                gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(t.framebuffer()));
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
                gl.blit_framebuffer(
                    0,
                    0,
                    w as i32,
                    h as i32,
                    0,
                    0,
                    window.0 as i32,
                    window.1 as i32,
                    glow::COLOR_BUFFER_BIT,
                    filter,
                );
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            }
        }
        // SAFETY: glGetError has no preconditions (once per frame, after the frame's calls).
        match unsafe { gl.get_error() } {
            glow::NO_ERROR => Ok(()),
            code => Err(GlError::Gl {
                code,
                during: "drawing a viewer frame",
            }),
        }
    }

    /// Deletes the targets (context current).
    pub fn destroy(&mut self, gl: &glow::Context) {
        if let Some(mut t) = self.float.take() {
            t.destroy(gl);
        }
        if let Some(mut t) = self.staging.take() {
            t.destroy(gl);
        }
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
