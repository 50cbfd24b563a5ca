//! [`Terms`]: the per-pixel error terms a camera's bound is the sum of.

/// Per-pixel error terms, each a worst case over the pixel (see `docs/conformance.md`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Terms {
    /// 8-bit output quantization, 0.5/255.
    pub output: f64,
    /// 8-bit framebuffer rounding, 2 × 0.5/255 per contributing splat (source and result).
    pub blend: f64,
    /// Pixel centres within rounding of a splat's 3σ cut (in for one renderer, out for another).
    pub cutoff: f64,
    /// Layers with α near or below 1/255 (skipped by 3DGS, drawn by others).
    pub threshold: f64,
    /// Layers whose α exceeds the 0.99 cap (capped by 3DGS, not by others).
    pub cap: f64,
    /// f16 storage of SH coefficients.
    pub sh_f16: f64,
    /// Colours above 1 clamped by a UNORM framebuffer between blends.
    pub overbright: f64,
    /// f32 arithmetic.
    pub float: f64,
    /// A stop at T < 10⁻⁴ (3DGS; the RC is silent), under any admitted α cap.
    pub early_stop: f64,
    /// Deviations an asset admits because it does not test them (set by the generator, not by
    /// [`super::render`]; isolation): the difference the model shows with another dilation,
    pub dilation: f64,
    /// …with the DC colour and the opacity stored in 8 bits (rounded down),
    pub colour_8bit: f64,
    /// …with the 3D covariance stored as half floats,
    pub covariance_f16: f64,
    /// …with Σ' rebuilt from floored eigenvalues (GaussianSplats3D's safeguard),
    pub eigenvalue_floor: f64,
    /// …and with two or three of them at once, beyond the sum of their own terms (a
    /// footprint a little smaller *and* cut at 2.83σ loses pixels neither does alone).
    pub combined: f64,
}

impl Terms {
    /// The bound: the sum of the terms.
    pub fn total(&self) -> f64 {
        self.output
            + self.blend
            + self.cutoff
            + self.threshold
            + self.cap
            + self.sh_f16
            + self.overbright
            + self.float
            + self.early_stop
            + self.dilation
            + self.colour_8bit
            + self.covariance_f16
            + self.eigenvalue_floor
            + self.combined
    }
    pub(crate) fn max(self, o: Terms) -> Terms {
        Terms {
            output: self.output.max(o.output),
            blend: self.blend.max(o.blend),
            cutoff: self.cutoff.max(o.cutoff),
            threshold: self.threshold.max(o.threshold),
            cap: self.cap.max(o.cap),
            sh_f16: self.sh_f16.max(o.sh_f16),
            overbright: self.overbright.max(o.overbright),
            float: self.float.max(o.float),
            early_stop: self.early_stop.max(o.early_stop),
            dilation: self.dilation.max(o.dilation),
            colour_8bit: self.colour_8bit.max(o.colour_8bit),
            covariance_f16: self.covariance_f16.max(o.covariance_f16),
            eigenvalue_floor: self.eigenvalue_floor.max(o.eigenvalue_floor),
            combined: self.combined.max(o.combined),
        }
    }
}
