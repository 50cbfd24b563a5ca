//! One frame of splats into framebuffers splatgl owns, the path headless rendering, the
//! viewer and the conformance runner share: the targets (kept across frames, re-made when the
//! size or format changes), the background, the clear, the `RGBA16F` begin/resolve and the
//! sRGB-write decision (the context's, from [`SplatRenderer`]).
//!
//! Blending happens either in an `RGBA16F` [`OffscreenTarget`] resolved into 8 bits
//! (sRGB-encoding `lin_rec709_display` clouds), or directly in an 8-bit target: `RGBA8`, or
//! `SRGB8_ALPHA8` for linear clouds (GL decodes, blends linear, re-encodes). The result lands
//! in an 8-bit staging target ([`Output::Image`], read back) or in the window's default
//! framebuffer ([`Output::Window`], through the staging target and a blit when the image size
//! differs from the window's or the sRGB target is needed).

use glow::HasContext;

use super::{ColorFormat, DrawSettings, GlError, OffscreenTarget, ReadbackTarget, SplatRenderer};
use crate::camera::Camera;
use crate::cloud::ColorSpace;
use crate::image::Image;

/// Whether to blend in an `RGBA16F` target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blend {
    /// In 8 bits.
    Rgba8,
    /// In `RGBA16F`; an error when the context cannot render to it.
    Rgba16f,
    /// In `RGBA16F` where the context can, else (said once on stderr) in 8 bits from then on.
    Rgba16fOrRgba8,
}

/// Where the frame goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// The staging target, read back as an [`Image`] with alpha (background alpha 0).
    Image,
    /// The default framebuffer of a window of this size (background alpha 1).
    Window(u32, u32),
}

/// The framebuffers of a frame, kept across frames.
#[derive(Debug, Default)]
pub struct FrameTargets {
    float: Option<OffscreenTarget>,
    /// The float target could not be made ([`Blend::Rgba16fOrRgba8`]): 8 bits from then on.
    float_unavailable: bool,
    staging: Option<ReadbackTarget>,
}

impl FrameTargets {
    /// Whether `blend` blends in a float target (given what this context could make so far).
    pub fn uses_float(&self, blend: Blend) -> bool {
        match blend {
            Blend::Rgba8 => false,
            Blend::Rgba16f => true,
            Blend::Rgba16fOrRgba8 => !self.float_unavailable,
        }
    }

    /// The float target for a `w × h` image (`None`: blend in 8 bits).
    fn float_for(
        &mut self,
        gl: &glow::Context,
        (w, h): (u32, u32),
        blend: Blend,
    ) -> Result<bool, GlError> {
        if !self.uses_float(blend) {
            return Ok(false);
        }
        if self.float.as_ref().is_none_or(|t| t.size() != (w, h)) {
            if let Some(mut t) = self.float.take() {
                t.destroy(gl);
            }
            match (OffscreenTarget::new(gl, w, h), blend) {
                (Ok(t), _) => self.float = Some(t),
                (Err(e), Blend::Rgba16fOrRgba8) => {
                    eprintln!("note: no RGBA16F render target ({e}); blending in 8 bits");
                    self.float_unavailable = true;
                    return Ok(false);
                }
                (Err(e), _) => return Err(e),
            }
        }
        Ok(true)
    }

    /// The 8-bit staging target (`SRGB8_ALPHA8` when `srgb`), bound.
    fn bind_staging(
        &mut self,
        gl: &glow::Context,
        (w, h): (u32, u32),
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
        let t = self.staging.as_ref().expect("made above");
        t.bind(gl)?;
        Ok(t)
    }

    /// Draws the renderer's current order seen by `camera` (whose size is the image size)
    /// over `background` (display values; sRGB-decoded for linear clouds so it comes out
    /// unchanged) with `settings` (its `color_space` is the cloud's when `None`). Returns the
    /// image for [`Output::Image`], `None` for a window. `during` names the frame in a GL
    /// error.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        gl: &glow::Context,
        renderer: &SplatRenderer,
        camera: &Camera,
        settings: &DrawSettings,
        background: [f32; 3],
        blend: Blend,
        output: Output,
        during: &'static str,
    ) -> Result<Option<Image>, GlError> {
        let size = (camera.width, camera.height);
        let space = settings.color_space.unwrap_or(renderer.color_space());
        let linear = space == ColorSpace::LinRec709Display;
        let bg = if linear {
            background.map(|c| crate::profile::srgb_decode(c as f64) as f32)
        } else {
            background
        };
        let float = self.float_for(gl, size, blend)?;
        let srgb = linear && !float;
        let (staged, alpha) = match output {
            Output::Image => (true, 0.0),
            Output::Window(w, h) => (size != (w, h) || srgb, 1.0),
        };
        if staged {
            self.bind_staging(gl, size, srgb)?;
        } else if let Output::Window(w, h) = output {
            // SAFETY: binding the default framebuffer and setting the viewport to the window.
            unsafe {
                gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                gl.viewport(0, 0, w as i32, h as i32);
            }
        }
        // Where GL_FRAMEBUFFER_SRGB can be switched (desktop GL, ES with
        // EXT_sRGB_write_control) the sRGB target encodes only with it on: the clear needs it
        // as the draw does (which sets it itself from the colour space).
        let switch = srgb && renderer.srgb_write_switch();
        clear_bound(gl, [bg[0], bg[1], bg[2], alpha], switch);
        // Where the float target resolves into: the staging target, else the window.
        let into = self
            .staging
            .as_ref()
            .filter(|_| staged)
            .map(ReadbackTarget::framebuffer);
        let drawn = match self.float.as_mut().filter(|_| float) {
            Some(t) => t
                .begin_into(gl, [bg[0], bg[1], bg[2], 0.0], into)
                .and_then(|()| {
                    renderer.draw_current_with(gl, camera, settings)?;
                    t.resolve(gl, linear)
                }),
            None => renderer.draw_current_with(gl, camera, settings),
        };
        if switch {
            // SAFETY: back to the default (disabled).
            unsafe { gl.disable(glow::FRAMEBUFFER_SRGB) };
        }
        drawn?;
        let staging = self.staging.as_ref().filter(|_| staged);
        deliver(gl, output, staging, size, during)
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

    /// Forgets the targets without GL calls (their context is gone).
    pub fn abandon(&mut self) {
        self.float.iter_mut().for_each(OffscreenTarget::abandon);
        self.staging.iter_mut().for_each(ReadbackTarget::abandon);
    }
}

/// Copies the staging target to the window (stretched, linear filtering, when sizes differ).
fn blit_to_window(gl: &glow::Context, t: &ReadbackTarget, (w, h): (u32, u32), window: (u32, u32)) {
    let filter = if (w, h) == window {
        glow::NEAREST
    } else {
        glow::LINEAR
    };
    // SAFETY: a blit from our own framebuffer into the default one.
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
    }
}

/// Clears the bound framebuffer to `rgba` with the scissor test off, leaving
/// `GL_FRAMEBUFFER_SRGB` on when `srgb_switch` (the draw that follows needs it on).
fn clear_bound(gl: &glow::Context, rgba: [f32; 4], srgb_switch: bool) {
    // SAFETY: capability switches and a clear of the bound framebuffer.
    unsafe {
        gl.disable(glow::SCISSOR_TEST);
        if srgb_switch {
            gl.enable(glow::FRAMEBUFFER_SRGB);
        }
        gl.clear_color(rgba[0], rgba[1], rgba[2], rgba[3]);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
}

/// Hands the drawn frame over: read back from `staging` for an image, blitted from it to the
/// window, or (drawn in the window) nothing; then the default framebuffer is bound again.
fn deliver(
    gl: &glow::Context,
    output: Output,
    staging: Option<&ReadbackTarget>,
    size: (u32, u32),
    during: &'static str,
) -> Result<Option<Image>, GlError> {
    let result = match (output, staging) {
        (Output::Image, Some(t)) => {
            super::check_error(gl, during)?;
            Some(t.read_image(gl)?)
        }
        (Output::Window(w, h), Some(t)) => {
            blit_to_window(gl, t, size, (w, h));
            None
        }
        _ => None,
    };
    // SAFETY: back to the default framebuffer.
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    super::check_error(gl, during)?;
    Ok(result)
}
