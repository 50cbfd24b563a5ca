//! Image comparison: PSNR, maximum absolute error, pixels over a threshold, and a diff
//! heat-map. Only the RGB channels are compared (they already include the background; alpha is
//! not stored by every format). A pixel's error is the largest of its three channel errors;
//! a non-finite value in either image counts as an infinite error.

use crate::image::Image;

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// Different sizes.
    #[error("image sizes differ: {0}x{1} vs {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
}

/// The result of [`compare`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Pixels compared.
    pub pixels: usize,
    /// Mean squared error over all RGB samples.
    pub mse: f64,
    /// PSNR in dB for a peak of 1.0: `10·log10(1 / mse)`; `+∞` for identical images.
    pub psnr: f64,
    /// Largest absolute channel difference.
    pub max_abs: f32,
    /// Where `max_abs` occurs first (column, row).
    pub max_at: (u32, u32),
    /// Mean absolute difference over all RGB samples.
    pub mean_abs: f64,
    /// The threshold used for `over_threshold`.
    pub threshold: f32,
    /// Pixels whose error exceeds `threshold`.
    pub over_threshold: usize,
}

fn pixel_error(a: &[f32; 4], b: &[f32; 4]) -> [f32; 3] {
    std::array::from_fn(|c| {
        // Bit-equal samples (including the same inf or NaN) are no error.
        if a[c].to_bits() == b[c].to_bits() {
            return 0.0;
        }
        let e = (a[c] - b[c]).abs();
        if e.is_finite() { e } else { f32::INFINITY }
    })
}

fn check_size(a: &Image, b: &Image) -> Result<(), CompareError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CompareError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    Ok(())
}

/// Compares the RGB channels of two images of the same size.
pub fn compare(a: &Image, b: &Image, threshold: f32) -> Result<Comparison, CompareError> {
    check_size(a, b)?;
    let (mut sq, mut abs, mut max_abs, mut max_at, mut over) = (0.0f64, 0.0f64, 0.0f32, 0, 0);
    for (i, (pa, pb)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        let e = pixel_error(pa, pb);
        for v in e {
            sq += (v as f64) * (v as f64);
            abs += v as f64;
        }
        let m = e[0].max(e[1]).max(e[2]);
        if m > max_abs {
            (max_abs, max_at) = (m, i);
        }
        over += (m > threshold) as usize;
    }
    let n = a.pixels.len();
    let samples = (3 * n).max(1) as f64;
    let mse = sq / samples;
    let w = a.width.max(1) as usize;
    Ok(Comparison {
        pixels: n,
        mse,
        psnr: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (1.0 / mse).log10()
        },
        max_abs,
        max_at: ((max_at % w) as u32, (max_at / w) as u32),
        mean_abs: abs / samples,
        threshold,
        over_threshold: over,
    })
}

impl Comparison {
    /// One JSON object; an infinite PSNR (identical images) is written as `null`.
    pub fn to_json(&self) -> String {
        let num = |v: f64| {
            if v.is_finite() {
                serde_json::json!(v)
            } else {
                serde_json::Value::Null
            }
        };
        serde_json::json!({
            "pixels": self.pixels,
            "psnr": num(self.psnr),
            "mse": num(self.mse),
            "max_abs": num(self.max_abs as f64),
            "max_at": [self.max_at.0, self.max_at.1],
            "mean_abs": num(self.mean_abs),
            "threshold": self.threshold,
            "over_threshold": self.over_threshold,
            "identical": self.mse == 0.0,
        })
        .to_string()
    }
}

/// Colour ramp for `t` in [0, 1]: black → blue → magenta → red → yellow → white.
pub fn heat(t: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) } * 5.0;
    let k = (t.floor() as usize).min(4);
    let f = t - k as f32;
    std::array::from_fn(|c| STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f)
}

/// A heat-map of per-pixel errors: error / `scale` through [`heat`] (opaque). `scale ≤ 0`
/// means "the largest error" (all black when the images are equal).
pub fn diff_image(a: &Image, b: &Image, scale: f32) -> Result<Image, CompareError> {
    check_size(a, b)?;
    let errs: Vec<f32> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(pa, pb)| {
            let e = pixel_error(pa, pb);
            e[0].max(e[1]).max(e[2])
        })
        .collect();
    let scale = if scale > 0.0 {
        scale
    } else {
        errs.iter()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0, f32::max)
    };
    let pixels = errs
        .iter()
        .map(|&e| {
            let t = if scale > 0.0 { e / scale } else { 0.0 };
            let [r, g, b] = heat(t);
            [r, g, b, 1.0]
        })
        .collect();
    Ok(Image {
        width: a.width,
        height: a.height,
        pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_a_known_difference() {
        let a = Image::filled(4, 2, [0.5, 0.5, 0.5, 1.0]);
        let mut b = a.clone();
        b.pixels[5] = [0.5, 0.6, 0.5, 1.0]; // (1, 1), error 0.1 in one channel
        let c = compare(&a, &b, 0.05).unwrap();
        assert!((c.max_abs - 0.1).abs() < 1e-6);
        assert_eq!((c.max_at, c.over_threshold), ((1, 1), 1));
        let mse = 0.01 / 24.0;
        assert!((c.mse - mse).abs() < 1e-9);
        assert!((c.psnr - 10.0 * (1.0 / mse).log10()).abs() < 1e-3);
        assert_eq!(compare(&a, &a, 0.0).unwrap().psnr, f64::INFINITY);
        assert!(compare(&a, &Image::filled(2, 4, [0.0; 4]), 0.1).is_err());
        let d = diff_image(&a, &b, 0.0).unwrap();
        assert_eq!(d.pixels[5], [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(d.pixels[0], [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn nan_is_an_infinite_error() {
        let a = Image::filled(1, 1, [0.0; 4]);
        let b = Image::filled(1, 1, [f32::NAN, 0.0, 0.0, 0.0]);
        let c = compare(&a, &b, 1.0).unwrap();
        assert_eq!((c.max_abs, c.over_threshold), (f32::INFINITY, 1));
    }
}
