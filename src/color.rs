//! The sRGB transfer function (IEC 61966-2-1), used where `colorSpace` says
//! `lin_rec709_display`: splats blend in linear, the result is encoded once at the end
//! (RC: all blending happens before any transfer-function conversion).

/// sRGB encoding (linear → display). Negative input gives 0; input above 1 follows the curve.
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.0 {
        0.0
    } else if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB decoding (display → linear).
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roundtrip_and_known_points() {
        for i in 0..=100 {
            let v = i as f64 / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-12);
        }
        assert!((srgb_encode(0.5) - 0.735_356_983_052_449_4).abs() < 1e-12);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-12);
    }
}
