//! [`Details`]: what a quantized container says about itself, beyond the splats — its version,
//! how many bits each attribute keeps, flags such as SPZ's antialiasing bit, and every lossy
//! step between the trainer's floats and the file. `splatgl info` prints it.

/// How one attribute is stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AttributeBits {
    /// `"position"`, `"scale"`, `"rotation"`, `"color"`, `"opacity"` or `"sh"`.
    pub attribute: &'static str,
    /// Bits per component as stored (before any entropy coding); 32 for f32.
    pub bits: u8,
    /// How the stored value maps to ours, e.g. `"24-bit fixed point, 12 fractional bits"`.
    pub encoding: String,
}

/// Container facts of a loaded file.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Details {
    /// Container version as the file states it (`"2"`, `"4"`, `"0.1"`), empty when the format
    /// has none (`.splat`).
    pub version: String,
    /// The wrapping: `"gzip"`, `"zstd streams"`, `"zip (bundled)"`, `"none"`, …
    pub container: String,
    /// One entry per attribute.
    pub quantization: Vec<AttributeBits>,
    /// SPZ flag 0x1: the splats were trained with antialiasing (Mip-Splatting style) and are
    /// meant to be rendered with the matching 2D filter compensation.
    pub antialiased: bool,
    /// What the format cannot keep (each a sentence, for `info`).
    pub lossy: Vec<String>,
}

impl Details {
    pub(crate) fn bits(&mut self, attribute: &'static str, bits: u8, encoding: impl Into<String>) {
        self.quantization.push(AttributeBits {
            attribute,
            bits,
            encoding: encoding.into(),
        });
    }
    pub(crate) fn lossy(&mut self, what: impl Into<String>) {
        self.lossy.push(what.into());
    }
}
