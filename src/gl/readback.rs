//! [`ReadbackTarget`]: a framebuffer with a colour texture (and optionally a depth buffer)
//! that can be read back into an [`Image`] — the one place the crate creates a framebuffer and
//! turns GL's bottom-up rows into an image's top-down ones.
//!
//! Used by the headless renderer, the benchmarks, the GL tests and `examples/embed.rs` (a
//! host-owned context), and under [`super::OffscreenTarget`] (its `RGBA16F` accumulation).

use crate::gl::bound::Bound;
use glow::HasContext;

use super::GlError;
use super::caps;
use super::error::ErrorScope;
use super::objects::{Creating, Owned};
use crate::image::Image;

/// Colour format of a [`ReadbackTarget`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ColorFormat {
    /// `RGBA8`: 8-bit UNORM, values stored as written.
    Rgba8,
    /// `SRGB8_ALPHA8`: GL sRGB-encodes RGB on write and decodes for blending (on desktop GL
    /// only while `GL_FRAMEBUFFER_SRGB` is enabled). Read back as the stored (encoded) bytes.
    Srgb8Alpha8,
    /// `RGBA16F`: half float, unclamped. On OpenGL ES needs `EXT_color_buffer_float` or
    /// `EXT_color_buffer_half_float`.
    Rgba16f,
    /// `RGBA32F`: single float, unclamped. On OpenGL ES needs `EXT_color_buffer_float`, and
    /// `EXT_float_blend` to blend in it.
    Rgba32f,
}

impl ColorFormat {
    fn internal_format(self) -> u32 {
        match self {
            ColorFormat::Rgba8 => glow::RGBA8,
            ColorFormat::Srgb8Alpha8 => glow::SRGB8_ALPHA8,
            ColorFormat::Rgba16f => glow::RGBA16F,
            ColorFormat::Rgba32f => glow::RGBA32F,
        }
    }
}

/// Depth buffer of a [`ReadbackTarget`] (a renderbuffer: not sampled, not read back).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum DepthFormat {
    /// `DEPTH_COMPONENT24`.
    Depth24,
}

impl DepthFormat {
    fn internal_format(self) -> u32 {
        match self {
            DepthFormat::Depth24 => glow::DEPTH_COMPONENT24,
        }
    }
}

/// A `width × height` framebuffer: a colour texture of a [`ColorFormat`] and, optionally, a
/// depth renderbuffer of a [`DepthFormat`] (e.g. for a host's opaque pass). It works on any context, the host's included: it binds
/// only when asked ([`ReadbackTarget::bind`]) and [`ReadbackTarget::read_image`] restores the
/// read-framebuffer binding it found.
///
/// Owns GL objects but not the context: call [`ReadbackTarget::destroy`] with the context
/// current before dropping it (dropping it live leaks them and warns once).
#[derive(Debug)]
pub struct ReadbackTarget {
    fbo: glow::Framebuffer,
    color: glow::Texture,
    width: u32,
    height: u32,
    format: ColorFormat,
    depth: Option<DepthFormat>,
    owned: Owned,
}

impl ReadbackTarget {
    /// Creates the target (`depth: None` for colour only). Fails with
    /// [`GlError::MissingExtension`] for `Rgba16f` on an ES context without
    /// `GL_EXT_color_buffer_float` or `GL_EXT_color_buffer_half_float`, and for `Rgba32f` on
    /// one without `GL_EXT_color_buffer_float` and `GL_EXT_float_blend` (splats blend in it),
    /// [`GlError::Framebuffer`] when incomplete, [`GlError::Gl`] on a GL error (the host's
    /// pending errors are kept, see [`super::state`]).
    pub fn new(
        gl: &glow::Context,
        width: u32,
        height: u32,
        format: ColorFormat,
        depth: Option<DepthFormat>,
    ) -> Result<Self, GlError> {
        if format == ColorFormat::Rgba16f && !caps::can_render_rgba16f(gl) {
            return Err(GlError::MissingExtension {
                extension: "GL_EXT_color_buffer_float or GL_EXT_color_buffer_half_float",
                needed_for: "an RGBA16F render target on OpenGL ES",
            });
        }
        if format == ColorFormat::Rgba32f && !caps::can_blend_rgba32f(gl) {
            return Err(GlError::MissingExtension {
                extension: "GL_EXT_color_buffer_float and GL_EXT_float_blend",
                needed_for: "blending in an RGBA32F render target on OpenGL ES",
            });
        }
        let errors = ErrorScope::begin(gl)?;
        let (w, h) = (width as i32, height as i32);
        let mut objects = Creating::new(gl);
        let color = objects.texture()?;
        let depth_rb = match depth {
            Some(d) => Some((objects.renderbuffer()?, d.internal_format())),
            None => None,
        };
        let fbo = objects.framebuffer()?;
        // SAFETY: allocates and attaches objects created just above; the texture, renderbuffer
        // and draw-framebuffer bindings are restored to what they were (0 for the first two).
        let status = unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(color));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, format.internal_format(), w, h);
            for pname in [glow::TEXTURE_MIN_FILTER, glow::TEXTURE_MAG_FILTER] {
                gl.tex_parameter_i32(glow::TEXTURE_2D, pname, glow::NEAREST as i32);
            }
            gl.bind_texture(glow::TEXTURE_2D, None);
            if let Some((rb, internal)) = depth_rb {
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
                gl.renderbuffer_storage(glow::RENDERBUFFER, internal, w, h);
                gl.bind_renderbuffer(glow::RENDERBUFFER, None);
            }
            let prev = gl.bound_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(fbo));
            let (target, attach) = (glow::DRAW_FRAMEBUFFER, glow::COLOR_ATTACHMENT0);
            gl.framebuffer_texture_2d(target, attach, glow::TEXTURE_2D, Some(color), 0);
            if let Some((rb, _)) = depth_rb {
                let attach = glow::DEPTH_ATTACHMENT;
                gl.framebuffer_renderbuffer(target, attach, glow::RENDERBUFFER, Some(rb));
            }
            let status = gl.check_framebuffer_status(target);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, prev);
            status
        };
        errors.end("creating a framebuffer")?;
        if status != glow::FRAMEBUFFER_COMPLETE {
            return Err(GlError::Framebuffer(status));
        }
        Ok(ReadbackTarget {
            fbo,
            color,
            width,
            height,
            format,
            depth,
            owned: objects.keep("ReadbackTarget"),
        })
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The colour format.
    pub fn format(&self) -> ColorFormat {
        self.format
    }

    /// The depth buffer's format, if it has one.
    pub fn depth_format(&self) -> Option<DepthFormat> {
        self.depth
    }

    /// The framebuffer object (to bind it as the host would, e.g. as `DRAW_FRAMEBUFFER`).
    pub fn framebuffer(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// The colour texture (`NEAREST` filtering; sample it with `texelFetch`).
    pub fn color_texture(&self) -> glow::Texture {
        self.color
    }

    /// Binds the target as `GL_FRAMEBUFFER` (draw and read) and sets the viewport to all of it.
    pub fn bind(&self, gl: &glow::Context) -> Result<(), GlError> {
        self.owned.check()?;
        // SAFETY: binds this target's own framebuffer.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo));
            gl.viewport(0, 0, self.width as i32, self.height as i32);
        }
        Ok(())
    }

    /// Reads the whole colour buffer into an [`Image`], top row first (GL's row 0, the bottom
    /// one, becomes the image's last row). 8-bit formats give `v / 255` of the stored bytes (for
    /// `Srgb8Alpha8` the encoded values); `Rgba16f` gives the stored floats.
    ///
    /// State: binds `GL_READ_FRAMEBUFFER` and restores the binding it found; leaves the pack
    /// state at the defaults it relies on (`GL_PIXEL_PACK_BUFFER` 0, `GL_PACK_ALIGNMENT` 4,
    /// `GL_PACK_ROW_LENGTH`, `GL_PACK_SKIP_ROWS`, `GL_PACK_SKIP_PIXELS` 0). Checks `glGetError`
    /// around its own calls (keeping the host's pending errors).
    pub fn read_image(&self, gl: &glow::Context) -> Result<Image, GlError> {
        self.owned.check()?;
        let errors = ErrorScope::begin(gl)?;
        let (w, h) = (self.width as usize, self.height as usize);
        let image = match self.format {
            ColorFormat::Rgba8 | ColorFormat::Srgb8Alpha8 => {
                let mut bytes = vec![0u8; w * h * 4];
                self.read_into(gl, glow::UNSIGNED_BYTE, &mut bytes);
                flip_rows(&mut bytes, w * 4);
                Image::from_rgba8(self.width, self.height, &bytes)
            }
            ColorFormat::Rgba16f | ColorFormat::Rgba32f => {
                let mut pixels = vec![[0.0f32; 4]; w * h];
                self.read_into(gl, glow::FLOAT, bytemuck::cast_slice_mut(&mut pixels));
                flip_rows(&mut pixels, w);
                Image {
                    width: self.width,
                    height: self.height,
                    pixels,
                }
            }
        };
        errors.end("reading back a framebuffer")?;
        Ok(image)
    }

    /// `glReadPixels` of the whole target as RGBA of `kind` into `out` (exactly w·h pixels).
    fn read_into(&self, gl: &glow::Context, kind: u32, out: &mut [u8]) {
        // SAFETY: reads width·height RGBA pixels of `kind` from this target's framebuffer into
        // `out`, which the callers size to exactly that (tight rows: PACK_ALIGNMENT 4 divides
        // the 4- and 16-byte pixels, row length and skips 0, no pack buffer bound).
        unsafe {
            let prev = gl.bound_framebuffer(glow::READ_FRAMEBUFFER_BINDING);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.fbo));
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 0);
            gl.pixel_store_i32(glow::PACK_SKIP_ROWS, 0);
            gl.pixel_store_i32(glow::PACK_SKIP_PIXELS, 0);
            let (w, h) = (self.width as i32, self.height as i32);
            let data = glow::PixelPackData::Slice(Some(out));
            gl.read_pixels(0, 0, w, h, glow::RGBA, kind, data);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, prev);
        }
    }

    /// Deletes the target's objects (once; afterwards every method returns
    /// [`GlError::Destroyed`]).
    pub fn destroy(&mut self, gl: &glow::Context) {
        self.owned.destroy(gl);
    }

    /// Forgets the objects without GL calls (their context is already gone).
    pub(crate) fn abandon(&mut self) {
        self.owned.abandon();
    }
}

/// Reverses the order of the `row`-long rows of `data` in place.
fn flip_rows<T>(data: &mut [T], row: usize) {
    let rows = data.len() / row.max(1);
    for r in 0..rows / 2 {
        let (top, bottom) = data.split_at_mut((rows - 1 - r) * row);
        top[r * row..(r + 1) * row].swap_with_slice(&mut bottom[..row]);
    }
}

#[cfg(test)]
mod tests {
    use super::flip_rows;

    #[test]
    fn flip_rows_reverses_row_order() {
        let mut odd = [1, 2, 3, 4, 5, 6];
        flip_rows(&mut odd, 2);
        assert_eq!(odd, [5, 6, 3, 4, 1, 2]);
        let mut even = [1, 2, 3, 4];
        flip_rows(&mut even, 1);
        assert_eq!(even, [4, 3, 2, 1]);
        let mut empty: [u8; 0] = [];
        flip_rows(&mut empty, 0);
    }
}
