//! The image type both backends produce and `compare` consumes.
//!
//! Pixels are RGBA `f32`, row 0 at the top. RGB is the composited colour *including* the
//! background (C = Σ cᵢ αᵢ Tᵢ + T·background), A is the accumulated opacity 1 − T. This is
//! exactly what premultiplied `ONE, ONE_MINUS_SRC_ALPHA` blending over a clear colour of
//! (background, 0) leaves in a framebuffer, so GL read-backs and reference renders compare
//! directly.

/// An RGBA float image, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    /// An image filled with one value.
    pub fn filled(width: u32, height: u32, value: [f32; 4]) -> Self {
        Image {
            width,
            height,
            pixels: vec![value; width as usize * height as usize],
        }
    }

    /// The pixel at column `x`, row `y` (row 0 = top).
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Quantises to 8 bits per channel: `round(clamp(v, 0, 1) · 255)`.
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect()
    }

    /// From 8-bit RGBA bytes (`v / 255`), row 0 at the top.
    pub fn from_rgba8(width: u32, height: u32, bytes: &[u8]) -> Self {
        assert_eq!(bytes.len(), width as usize * height as usize * 4);
        Image {
            width,
            height,
            pixels: bytes
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]].map(|v| v as f32 / 255.0))
                .collect(),
        }
    }
}

mod io;
pub use io::{ImageError, PngDepth};
