//! Image files: PNG (8 or 16 bits per channel, RGB or RGBA) and PFM (32-bit float, the
//! Portable Float Map: `PF` = RGB, `Pf` = grey; rows stored bottom to top).
//!
//! Writing quantises `round(clamp(v, 0, 1) · (2ⁿ − 1))`; PFM stores the f32 values exactly
//! (little endian). Reading accepts any PNG the `png` crate decodes (palette, grey and low bit
//! depths are expanded) and both PFM endiannesses; images without alpha read as A = 1.

use super::Image;
use crate::write::write_bytes_atomic;
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// Why an image could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// File system error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// PNG encoding failed.
    #[error("PNG encoding: {0}")]
    PngEncode(#[from] png::EncodingError),
    /// PNG decoding failed.
    #[error("PNG decoding: {0}")]
    PngDecode(#[from] png::DecodingError),
    /// A malformed PFM file.
    #[error("PFM: {0}")]
    Pfm(String),
    /// A PNG whose decoded size does not fit in memory.
    #[error("PNG too large to decode")]
    PngTooLarge,
    /// Neither PNG nor PFM.
    #[error("{0}: unknown image format (expected .png or .pfm)")]
    UnknownFormat(PathBuf),
}

/// Bits per channel of a PNG.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PngDepth {
    /// 8 bits.
    #[default]
    Eight,
    /// 16 bits.
    Sixteen,
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> ImageError + '_ {
    move |source| ImageError::Io {
        path: path.to_owned(),
        source,
    }
}

impl Image {
    /// Encodes as PNG; `alpha` adds the A channel (1 − T), else RGB only (what a viewer shows:
    /// RGB already includes the background).
    pub fn encode_png(&self, depth: PngDepth, alpha: bool) -> Result<Vec<u8>, ImageError> {
        let channels = if alpha { 4 } else { 3 };
        let mut data = Vec::with_capacity(self.pixels.len() * channels * 2);
        for p in &self.pixels {
            for v in &p[..channels] {
                let v = v.clamp(0.0, 1.0); // NaN stays NaN and casts to 0
                match depth {
                    PngDepth::Eight => data.push((v * 255.0).round() as u8),
                    PngDepth::Sixteen => {
                        data.extend_from_slice(&((v * 65535.0).round() as u16).to_be_bytes())
                    }
                }
            }
        }
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width, self.height);
        enc.set_color(if alpha {
            png::ColorType::Rgba
        } else {
            png::ColorType::Rgb
        });
        enc.set_depth(match depth {
            PngDepth::Eight => png::BitDepth::Eight,
            PngDepth::Sixteen => png::BitDepth::Sixteen,
        });
        let mut w = enc.write_header()?;
        w.write_image_data(&data)?;
        w.finish()?;
        Ok(out)
    }

    /// Decodes a PNG into RGBA f32 (`v / (2ⁿ − 1)`; A = 1 without alpha).
    pub fn decode_png(bytes: &[u8]) -> Result<Image, ImageError> {
        let mut dec = png::Decoder::new(Cursor::new(bytes));
        dec.set_transformations(png::Transformations::EXPAND);
        let mut reader = dec.read_info()?;
        // Checked before allocating: a header can claim any size. At most 2^28 pixels, and no
        // more decoded bytes than DEFLATE can expand the file to (≈1032×).
        let (w, h) = (reader.info().width as u64, reader.info().height as u64);
        let size = reader.output_buffer_size().ok_or(ImageError::PngTooLarge)?;
        if w * h > 1 << 28 || size as u64 > 1032 * bytes.len() as u64 + 65536 {
            return Err(ImageError::PngTooLarge);
        }
        let mut buf = vec![0; size];
        let info = reader.next_frame(&mut buf)?;
        let channels = info.color_type.samples();
        let sixteen = info.bit_depth == png::BitDepth::Sixteen;
        let bytes_per = if sixteen { 2 } else { 1 };
        let (w, h) = (info.width as usize, info.height as usize);
        let mut pixels = Vec::with_capacity(w * h);
        for row in buf.chunks_exact(info.line_size).take(h) {
            for px in row[..w * channels * bytes_per].chunks_exact(channels * bytes_per) {
                let s = |k: usize| -> f32 {
                    if sixteen {
                        u16::from_be_bytes([px[2 * k], px[2 * k + 1]]) as f32 / 65535.0
                    } else {
                        px[k] as f32 / 255.0
                    }
                };
                pixels.push(match channels {
                    1 => [s(0), s(0), s(0), 1.0],
                    2 => [s(0), s(0), s(0), s(1)],
                    3 => [s(0), s(1), s(2), 1.0],
                    _ => [s(0), s(1), s(2), s(3)],
                });
            }
        }
        Ok(Image {
            width: info.width,
            height: info.height,
            pixels,
        })
    }

    /// Encodes the RGB channels as a colour PFM (`PF`, little endian, scale −1).
    pub fn encode_pfm(&self) -> Vec<u8> {
        self.encode_pfm_channels(&[0, 1, 2])
    }

    /// Encodes the alpha channel as a grey PFM (`Pf`).
    pub fn encode_pfm_alpha(&self) -> Vec<u8> {
        self.encode_pfm_channels(&[3])
    }

    fn encode_pfm_channels(&self, ch: &[usize]) -> Vec<u8> {
        let tag = if ch.len() == 3 { "PF" } else { "Pf" };
        let mut out = format!("{tag}\n{} {}\n-1.0\n", self.width, self.height).into_bytes();
        let w = self.width as usize;
        for row in self.pixels.chunks_exact(w.max(1)).rev() {
            for p in row {
                for &c in ch {
                    out.extend_from_slice(&p[c].to_le_bytes());
                }
            }
        }
        out
    }

    /// Decodes a PFM (`PF` or `Pf`, either endianness). Grey images fill R = G = B; A = 1.
    pub fn decode_pfm(bytes: &[u8]) -> Result<Image, ImageError> {
        let bad = |m: &str| ImageError::Pfm(m.to_owned());
        // Header: three whitespace-separated tokens after the tag, then one whitespace byte.
        let mut pos = 0;
        let mut tokens = Vec::new();
        while tokens.len() < 4 {
            while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            let start = pos;
            while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if start == pos || pos - start > 32 {
                return Err(bad("truncated or malformed header"));
            }
            tokens.push(std::str::from_utf8(&bytes[start..pos]).map_err(|_| bad("header"))?);
        }
        // The single whitespace byte ending the header (a CRLF counts as one line end).
        pos += if bytes.get(pos..pos + 2) == Some(b"\r\n") {
            2
        } else {
            1
        };
        let channels = match tokens[0] {
            "PF" => 3,
            "Pf" => 1,
            t => return Err(ImageError::Pfm(format!("unknown tag {t:?}"))),
        };
        let dim = |t: &str| t.parse::<u32>().ok().filter(|v| (1..=1 << 16).contains(v));
        let (w, h) = dim(tokens[1])
            .zip(dim(tokens[2]))
            .ok_or_else(|| bad("width/height must be integers in 1..=65536"))?;
        let scale: f32 = tokens[3]
            .parse()
            .map_err(|_| bad("scale is not a number"))?;
        if !(scale.is_finite() && scale != 0.0) {
            return Err(bad("scale must be a finite non-zero number"));
        }
        let little = scale.is_sign_negative();
        let n = w as usize * h as usize * channels;
        let data = bytes
            .get(pos..)
            .filter(|d| d.len() >= n * 4)
            .ok_or_else(|| bad("fewer samples than width × height"))?;
        let sample = |k: usize| {
            let b = [
                data[4 * k],
                data[4 * k + 1],
                data[4 * k + 2],
                data[4 * k + 3],
            ];
            if little {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        };
        let mut pixels = Vec::with_capacity(w as usize * h as usize);
        for y in (0..h as usize).rev() {
            for x in 0..w as usize {
                let k = (y * w as usize + x) * channels;
                pixels.push(if channels == 3 {
                    [sample(k), sample(k + 1), sample(k + 2), 1.0]
                } else {
                    [sample(k), sample(k), sample(k), 1.0]
                });
            }
        }
        Ok(Image {
            width: w,
            height: h,
            pixels,
        })
    }

    /// Reads a PNG or PFM file (by magic bytes): a regular file of at most
    /// [`Limits::DEFAULT_MAX_BYTES`](crate::load::Limits::DEFAULT_MAX_BYTES).
    pub fn read(path: impl AsRef<Path>) -> Result<Image, ImageError> {
        Image::read_limited(path, crate::load::Limits::DEFAULT_MAX_BYTES)
    }

    /// Reads a PNG or PFM file (by magic bytes): a regular file of at most `max_bytes`
    /// (checked before reading; FIFOs, devices and directories are errors at once).
    pub fn read_limited(path: impl AsRef<Path>, max_bytes: u64) -> Result<Image, ImageError> {
        let path = path.as_ref();
        let bytes =
            crate::files::read_bounded(path, max_bytes, "the image").map_err(io_err(path))?;
        if bytes.starts_with(b"\x89PNG") {
            Image::decode_png(&bytes)
        } else if bytes.starts_with(b"PF") || bytes.starts_with(b"Pf") {
            Image::decode_pfm(&bytes)
        } else {
            Err(ImageError::UnknownFormat(path.to_owned()))
        }
    }

    /// Writes a PNG file (atomically: a failed write keeps the previous file, see
    /// [`crate::write::write_atomic`]).
    pub fn write_png(
        &self,
        path: impl AsRef<Path>,
        depth: PngDepth,
        alpha: bool,
    ) -> Result<(), ImageError> {
        let path = path.as_ref();
        let bytes = self.encode_png(depth, alpha)?;
        write_bytes_atomic(path, &[], &bytes).map_err(io_err(path))
    }

    /// Writes the RGB channels to a PFM file (atomically).
    pub fn write_pfm(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        write_bytes_atomic(path, &[], &self.encode_pfm()).map_err(io_err(path))
    }

    /// Writes the alpha channel to a grey PFM file (atomically).
    pub fn write_pfm_alpha(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        write_bytes_atomic(path, &[], &self.encode_pfm_alpha()).map_err(io_err(path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Image {
        let pixels = (0..12)
            .map(|i| [i as f32 / 11.0, 0.25, 1.5, (11 - i) as f32 / 11.0])
            .collect();
        Image {
            width: 4,
            height: 3,
            pixels,
        }
    }

    #[test]
    fn pfm_roundtrip_is_exact_and_bottom_up() {
        let img = sample();
        let bytes = img.encode_pfm();
        assert!(bytes.starts_with(b"PF\n4 3\n-1.0\n"));
        let back = Image::decode_pfm(&bytes).unwrap();
        for (a, b) in img.pixels.iter().zip(&back.pixels) {
            assert_eq!(a[..3], b[..3]);
        }
        // First stored row is the bottom row (y = 2, first pixel index 8).
        let first = f32::from_le_bytes(bytes[12..16].try_into().unwrap());
        assert_eq!(first, img.pixels[8][0]);
        assert!(Image::decode_pfm(&bytes[..bytes.len() - 1]).is_err());
    }

    #[test]
    fn png_roundtrip_quantises() {
        let img = sample();
        for (depth, q) in [(PngDepth::Eight, 255.0), (PngDepth::Sixteen, 65535.0)] {
            let back = Image::decode_png(&img.encode_png(depth, true).unwrap()).unwrap();
            for (a, b) in img.pixels.iter().zip(&back.pixels) {
                for c in 0..4 {
                    let want = (a[c].clamp(0.0, 1.0) * q).round() / q;
                    assert!((want - b[c]).abs() < 1e-6, "{a:?} {b:?}");
                }
            }
            let rgb = Image::decode_png(&img.encode_png(depth, false).unwrap()).unwrap();
            assert!(rgb.pixels.iter().all(|p| p[3] == 1.0));
        }
    }
}
