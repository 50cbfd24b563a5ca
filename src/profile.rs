//! The rendering profile's numbers, in one place: every constant both backends use, and the
//! GPU data layout the GL backend and its shaders share.
//!
//! One section per section of `docs/rendering-profile.md` (its §8 tables them all). The CPU reference
//! ([`crate::reference`]) reads these constants directly; the GLSL in `glsl/` receives each
//! one as a generated `#define` (the GL backend's program assembly), so no value is written
//! twice. A unit test of the GL backend fails if a define disagrees with its constant or if a
//! shader spells one of these values as a literal.
//!
//! The spherical-harmonics basis constants (`SH_C0` … `SH_C3`) live with the basis in
//! [`crate::sh`] and reach the shaders the same way.

use crate::cloud::sh_coeff_count;

// ---------------------------------------------------------------------------------------------
// §1 Lighting: colour from SH
// ---------------------------------------------------------------------------------------------

/// Bias added to the SH sum to get the colour: `c = Σ SH·Y + 0.5` (RC §Lighting).
/// [`crate::sh::dc_from_color`] and [`crate::sh::color_from_dc`] convert with it.
pub const SH_DC_BIAS: f64 = 0.5;

// ---------------------------------------------------------------------------------------------
// §1 Display of lin_rec709_display: the sRGB transfer function (IEC 61966-2-1)
// ---------------------------------------------------------------------------------------------

/// Linear values up to this are encoded by the linear segment.
pub const SRGB_ENCODE_THRESHOLD: f64 = 0.003_130_8;
/// Encoded values up to this are decoded by the linear segment.
pub const SRGB_DECODE_THRESHOLD: f64 = 0.040_45;
/// Slope of the linear segment.
pub const SRGB_LINEAR_SLOPE: f64 = 12.92;
/// Scale of the power segment: `SCALE · v^(1/GAMMA) − OFFSET`.
pub const SRGB_SCALE: f64 = 1.055;
/// Offset of the power segment.
pub const SRGB_OFFSET: f64 = 0.055;
/// Exponent of the power segment.
pub const SRGB_GAMMA: f64 = 2.4;

/// sRGB encoding (linear → display). Negative input gives 0; input above 1 follows the curve.
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.0 {
        0.0
    } else if v <= SRGB_ENCODE_THRESHOLD {
        SRGB_LINEAR_SLOPE * v
    } else {
        SRGB_SCALE * v.powf(1.0 / SRGB_GAMMA) - SRGB_OFFSET
    }
}

/// sRGB decoding (display → linear).
pub fn srgb_decode(v: f64) -> f64 {
    if v <= SRGB_DECODE_THRESHOLD {
        v / SRGB_LINEAR_SLOPE
    } else {
        ((v + SRGB_OFFSET) / SRGB_SCALE).powf(SRGB_GAMMA)
    }
}

// ---------------------------------------------------------------------------------------------
// §2 Camera model
// ---------------------------------------------------------------------------------------------

/// x/z and y/z inside the Jacobian J are clamped to ±`JACOBIAN_CLAMP`·tan(half fov) (3DGS
/// `computeCov2D`); the mean itself is projected unclamped.
pub const JACOBIAN_CLAMP: f64 = 1.3;

// ---------------------------------------------------------------------------------------------
// §3 Per-pixel rule
// ---------------------------------------------------------------------------------------------

/// Added to the diagonal of Σ' (px²) before inversion: the 3DGS low-pass / dilation.
pub const DILATION_PX2: f64 = 0.3;
/// Mahalanobis² cut-off, the RC's 3σ: a pixel contributes while dᵀΣ'⁻¹d ≤ 9.
pub const CUTOFF_M2: f32 = 9.0;
/// Cap on a splat's per-pixel α (3DGS `min(0.99, …)`).
pub const ALPHA_MAX: f32 = 0.99;
/// Contributions with α below this are skipped (3DGS `alpha < 1/255`).
pub const ALPHA_MIN: f32 = 1.0 / 255.0;
/// Added to the opacity-aware Mahalanobis² bound ([`opacity_cutoff_m2`]) wherever a bound
/// must contain every pixel whose α can pass the [`ALPHA_MIN`] test: the reference's
/// early-out before the exponential and the GL quad. Covers the rounding of `ln` and `exp`
/// (≤ 10⁻⁵ in m² for any GLSL ES 3.00 implementation, exactly 0 in the f64 reference).
pub const OPACITY_M2_MARGIN: f64 = 1e-3;

/// The opacity-aware extent (`docs/rendering-profile.md` §3 "extent"): the Mahalanobis²
/// `2·ln(opacity / ALPHA_MIN)` beyond which `min(ALPHA_MAX, opacity·exp(−½m²))` is below
/// [`ALPHA_MIN`] (because `ALPHA_MAX ≥ ALPHA_MIN`), capped at [`CUTOFF_M2`]. NaN or −∞ for
/// opacities the α test rejects everywhere (NaN, ≤ 0); ≥ [`CUTOFF_M2`] (so the cap) for
/// opacities ≥ 0.0353 = ALPHA_MIN·e^4.5.
pub fn opacity_cutoff_m2(opacity: f32) -> f64 {
    let m2 = 2.0 * (f64::from(opacity) / f64::from(ALPHA_MIN)).ln();
    // Written so that NaN stays NaN (`f64::min` would turn it into the cap).
    if m2 > f64::from(CUTOFF_M2) {
        f64::from(CUTOFF_M2)
    } else {
        m2
    }
}

/// Splats whose camera-space depth is ≤ max(this, camera near) are culled (3DGS `in_frustum`),
/// in scene units. `reference::RenderOptions::near_cull` overrides it for the reference.
pub const NEAR_CULL: f64 = 0.2;

/// The GL quad: the rectangle along Σ''s eigenvectors with half-axes
/// `QUAD_AXIS_FACTOR·√(k²λᵢ) + QUAD_MARGIN_PX` (capped by the 3DGS radius), i.e. 2 % and
/// ⅛ px beyond the bounding rectangle of the ellipse m² ≤ k². Any quad that contains every
/// pixel centre the fragment test can pass gives the same image; the margins cover the f32
/// eigen-decomposition (≪ 2 %) and the rasterizer's vertex snapping (≤ 1/32 px at the 4
/// sub-pixel bits GLES 3.0 guarantees; llvmpipe has 8).
pub const QUAD_AXIS_FACTOR: f64 = 1.02;
/// See [`QUAD_AXIS_FACTOR`] (pixels).
pub const QUAD_MARGIN_PX: f64 = 0.125;
/// The quad margin before the opacity-aware extent (pixels): what the erratum variants and
/// the benchmarks' "former" path draw with (programs built only in test builds; the
/// production shaders never see it).
pub const FORMER_QUAD_MARGIN_PX: f64 = 0.5;

// ---------------------------------------------------------------------------------------------
// §8 GPU data layout (the GL backend's textures; docs/gl-backend.md "Data layout")
// ---------------------------------------------------------------------------------------------

/// Splat slots per page of the GL backend's paged storage (streamed tilesets: each tile
/// holds whole pages, see `tiles::pages`). A multiple of every data-texture width the
/// backend uses (≤ 8192 texels), so a page is whole texture rows.
pub const PAGE_SPLATS: usize = 8192;

/// `RGBA32F` texels per splat in the geometry texture.
pub const GEOM_TEXELS: usize = 3;
/// Geometry texel holding (position.xyz, opacity).
pub const GEOM_TEXEL_POSITION_OPACITY: usize = 0;
/// Geometry texel holding the rotation quaternion (x, y, z, w).
pub const GEOM_TEXEL_ROTATION: usize = 1;
/// Geometry texel holding (scale.xyz, 0).
pub const GEOM_TEXEL_SCALE: usize = 2;
/// `RGBA32F` texels of one pre-pass record in the records texture: (clip-space centre),
/// (clip-space corner offsets), (colour, opacity), (conic, unused).
pub const RECORD_TEXELS: usize = 4;
/// Quads (splats) per instance of the quad draw after the pre-pass: one instance of this many
/// quads instead of one per splat, so a renderer that pays per instance (SwiftShader runs
/// each instance as a draw of its own; llvmpipe sets up each one) pays it once per batch.
/// Their indices (`6 ·` this many, u16) must stay below 65 536.
pub const QUADS_PER_INSTANCE: usize = 256;

/// `RGBA16F` texels per splat holding the SH coefficients of degrees `0..=degree`: the
/// (d+1)² RGB triples packed tightly, coefficient k's channel c at float `3k + c`, so
/// ⌈3·(d+1)²/4⌉ texels (1, 3, 7, 12 for degree 0–3).
pub const fn sh_texels(degree: u8) -> usize {
    (3 * sh_coeff_count(degree)).div_ceil(4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_roundtrip_and_known_points() {
        for i in 0..=100 {
            let v = i as f64 / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-12);
        }
        assert!((srgb_encode(0.5) - 0.735_356_983_052_449_4).abs() < 1e-12);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn srgb_segments_meet() {
        // The two segments of each direction agree at the threshold (IEC 61966-2-1's values).
        let t = SRGB_ENCODE_THRESHOLD;
        let power = SRGB_SCALE * t.powf(1.0 / SRGB_GAMMA) - SRGB_OFFSET;
        assert!((SRGB_LINEAR_SLOPE * t - power).abs() < 1e-6);
        assert!((srgb_decode(SRGB_DECODE_THRESHOLD) - t).abs() < 1e-6);
    }

    #[test]
    fn opacity_cutoff_is_where_alpha_meets_the_threshold() {
        for o in [
            0.004_f32,
            0.01,
            0.02,
            0.0353,
            0.1,
            0.5,
            0.99,
            1.0,
            7.0,
            f32::INFINITY,
        ] {
            let m2 = opacity_cutoff_m2(o);
            assert!(m2 <= f64::from(CUTOFF_M2), "{o}: {m2}");
            if m2 < f64::from(CUTOFF_M2) {
                // Exactly at the bound α = ALPHA_MIN (below the cap ALPHA_MAX).
                let alpha = (f64::from(o) * (-0.5 * m2).exp()).min(f64::from(ALPHA_MAX));
                assert!(
                    (alpha / f64::from(ALPHA_MIN) - 1.0).abs() < 1e-12,
                    "{o}: {alpha}"
                );
            }
        }
        assert_eq!(opacity_cutoff_m2(1.0), f64::from(CUTOFF_M2));
        assert!(opacity_cutoff_m2(0.03) < f64::from(CUTOFF_M2));
        assert!(opacity_cutoff_m2(f32::NAN).is_nan());
        assert!(opacity_cutoff_m2(-1.0).is_nan());
        assert_eq!(opacity_cutoff_m2(0.0), f64::NEG_INFINITY);
        assert!(opacity_cutoff_m2(ALPHA_MIN * 0.5) < 0.0);
    }

    #[test]
    fn layout_sizes() {
        assert_eq!([0, 1, 2, 3].map(sh_texels), [1, 3, 7, 12]);
        // Each geometry texel has its own slot inside the splat's GEOM_TEXELS.
        let mut texels = [
            GEOM_TEXEL_POSITION_OPACITY,
            GEOM_TEXEL_ROTATION,
            GEOM_TEXEL_SCALE,
        ];
        texels.sort();
        assert_eq!(texels, [0, 1, 2].map(|i: usize| i.min(GEOM_TEXELS)));
        assert_eq!(texels.len(), GEOM_TEXELS);
    }
}
