//! [`Variant`]: implementation variants the model can switch on beside the errata.

/// Implementation variants beside the errata: choices and mistakes seen in real renderers,
/// which the runner's diagnosis tests an image against ([`render_with`](super::render_with)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    /// Splats cut by their oriented 3.33σ bounding box instead of the 3σ ellipse.
    BoxCut,
    /// Splats cut by a 2√2σ ≈ 2.83σ square along the footprint's axes, its corners at 4σ
    /// (CesiumJS: quads of ±√(2λ) in its units, never discarded inside, every fragment drawn —
    /// no 1/255 skip) instead of the 3σ ellipse: the ring 2.83σ–3σ lost along the axes, faint
    /// corners up to 4σ drawn.
    SquareCut,
    /// Blending order by view depth (camera-space z; per tile or global, the same per pixel)
    /// instead of camera distance.
    ViewDepthOrder,
    /// Opacity scaled by √(det Σ' / det(Σ' + 0.3 I)) (Mip-Splatting / gsplat antialiasing).
    AaCompensation,
    /// SH evaluated up to degree 0 only (the RC: "MAY ignore higher-degree coefficients").
    ShDegree0,
    /// SH evaluated up to degree 1 only (allowed likewise).
    ShDegree1,
    /// SH evaluated up to degree 2 only (allowed likewise).
    ShDegree2,
    /// ROTATION read as `(w, x, y, z)` instead of glTF's `(x, y, z, w)`.
    QuatWxyz,
    /// SCALE read as log-space (`exp(s)`, the review draft) instead of linear.
    LogScale,
    /// Colour as `sigmoid(Σ SH·Y)` instead of `Σ SH·Y + 0.5`.
    SigmoidColour,
    /// The DC colour (`SH_C0·DC + 0.5`) and the opacity stored in 8 bits, rounded down
    /// (GaussianSplats3D's splat buffers).
    Colour8Bit,
    /// Σ' rebuilt from eigenvalues `mid ± √max(0.1, mid² − det)`, and dropped when the smaller
    /// is ≤ 0 (GaussianSplats3D's vertex shader): near-round footprints come out slightly
    /// anisotropic, sub-pixel splats vanish.
    EigenvalueFloor,
    /// The 3D covariance Σ stored as half floats (GaussianSplats3D's covariance textures,
    /// Spark's packed splats): footprints off by up to ~0.05 % of their size.
    HalfCovariance,
    /// The splats as `KHR_gaussian_splatting_compression_spz_2` carries them (SPZ v2: 12-bit
    /// fixed-point positions, 8-bit log scales, quaternions, colour and opacity, 5/4-bit SH):
    /// what a renderer given the SPZ-compressed asset draws. `conformance run
    /// --input-precision spz` accepts it (the images were rendered from SPZ copies).
    SpzPrecision,
    /// The asset's `colorSpace` ignored: `lin_rec709_display` values blended and shown as if
    /// they were display values (no sRGB encoding at the end).
    ColorSpaceIgnored,
    /// Spark's default packed splats (half-float centres, 8-bit colour, opacity in steps of
    /// 2/255, 8-bit ln scales over [−12, 9], 8+8+8-bit octahedral quaternions, SH 7/8/6 bits).
    PackedSplat,
    /// PlayCanvas's kernel: α = opacity·(G − e⁻⁴)/(1 − e⁻⁴), which reaches 0 at 2√2σ where
    /// it cuts (its `normExp`, gsplat fragment shader): every splat a little more opaque
    /// inside and fainter towards its edge than α = opacity·G.
    NormalizedKernel,
    /// Σ' rebuilt from its eigenvalues `mid ± r + 10⁻⁴` along the eigenvector
    /// `normalize(b, λ₁ − a)`, which degenerates when `|b|` ≪ 10⁻⁴: a footprint wider than
    /// tall with no x–y covariance (a round splat off the image's centre row, an axis-aligned
    /// one) is drawn taller than wide (Babylon.js 9's vertex shader, as the review draft's
    /// Appendix A).
    AxesSwapped,
    /// Babylon.js 9's splat buffer: colour, opacity and quaternion in 8 bits (rounded), SH
    /// above degree 0 in 8 bits over ±1, the covariance in half floats.
    Attributes8Bit,
    /// PlayCanvas 2.23's compact work buffer: scales as 8-bit ln σ over [−12, 9] (σ off by
    /// up to ±4.2 %), opacity in 8 bits, the quaternion in 11-11-10 bits.
    ScaleLog8,
    /// Each splat's colour clamped to 1 before it is blended (a straight-alpha or 8-bit
    /// colour path): colours above 1 lose what they add under translucent splats.
    ColourClamped,
    /// Blending into an 8-bit (UNORM) target: each fragment's premultiplied colour and each
    /// blended result clamped to 1, so a sum above 1 behind a translucent splat is lost.
    Unorm8Blending,
}

impl Variant {
    /// All of them.
    pub const ALL: [Variant; 22] = [
        Variant::BoxCut,
        Variant::SquareCut,
        Variant::ViewDepthOrder,
        Variant::AaCompensation,
        Variant::ShDegree0,
        Variant::ShDegree1,
        Variant::ShDegree2,
        Variant::QuatWxyz,
        Variant::LogScale,
        Variant::SigmoidColour,
        Variant::Colour8Bit,
        Variant::EigenvalueFloor,
        Variant::HalfCovariance,
        Variant::SpzPrecision,
        Variant::PackedSplat,
        Variant::ColorSpaceIgnored,
        Variant::NormalizedKernel,
        Variant::AxesSwapped,
        Variant::Attributes8Bit,
        Variant::ScaleLog8,
        Variant::ColourClamped,
        Variant::Unorm8Blending,
    ];
    /// A short identifier (the diagnosis's `rule`).
    pub fn name(self) -> &'static str {
        match self {
            Variant::BoxCut => "bounding_box_cutoff",
            Variant::SquareCut => "square_cutoff",
            Variant::ViewDepthOrder => "view_depth_order",
            Variant::AaCompensation => "antialiasing_compensation",
            Variant::ShDegree0 => "sh_ignored_above_degree_0",
            Variant::ShDegree1 => "sh_ignored_above_degree_1",
            Variant::ShDegree2 => "sh_ignored_above_degree_2",
            Variant::QuatWxyz => "quaternion_read_as_wxyz",
            Variant::LogScale => "scale_read_as_log",
            Variant::SigmoidColour => "sigmoid_colour",
            Variant::Colour8Bit => "colour_and_opacity_8bit",
            Variant::EigenvalueFloor => "eigenvalue_floor",
            Variant::HalfCovariance => "covariance_f16",
            Variant::SpzPrecision => "spz_precision",
            Variant::PackedSplat => "packed_splat_precision",
            Variant::ColorSpaceIgnored => "color_space_ignored",
            Variant::NormalizedKernel => "normalized_kernel",
            Variant::AxesSwapped => "footprint_axes_swapped",
            Variant::Attributes8Bit => "attributes_8bit",
            Variant::ScaleLog8 => "scale_log8",
            Variant::ColourClamped => "colour_clamped_per_splat",
            Variant::Unorm8Blending => "blending_8bit",
        }
    }
    /// What a renderer with this variant does, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Variant::BoxCut => "splats cut by a 3.33σ bounding box instead of the 3σ ellipse",
            Variant::SquareCut => {
                "splats cut by a 2.83σ square along the footprint's axes (corners at 4σ, every fragment drawn) instead of the 3σ ellipse"
            }
            Variant::ViewDepthOrder => {
                "splats ordered by view depth (camera-space z) instead of distance to the camera"
            }
            Variant::AaCompensation => {
                "opacity scaled by √(det Σ' / det(Σ' + 0.3 I)) (antialiased kernel)"
            }
            Variant::ShDegree0 => "SH coefficients above degree 0 ignored",
            Variant::ShDegree1 => "SH coefficients above degree 1 ignored",
            Variant::ShDegree2 => "SH coefficients above degree 2 ignored",
            Variant::QuatWxyz => "ROTATION read as (w, x, y, z) instead of (x, y, z, w)",
            Variant::LogScale => "SCALE read as ln(scale) (the review draft) instead of linear",
            Variant::SigmoidColour => "colour = sigmoid(Σ SH·Y) instead of Σ SH·Y + 0.5",
            Variant::Colour8Bit => {
                "DC colour and opacity stored in 8 bits, rounded down (lossy storage)"
            }
            Variant::EigenvalueFloor => {
                "Σ' rebuilt from eigenvalues mid ± √max(0.1, mid² − det) (near-round footprints anisotropic, sub-pixel splats dropped)"
            }
            Variant::HalfCovariance => "3D covariance stored as half floats (lossy storage)",
            Variant::SpzPrecision => {
                "splats at SPZ precision (KHR_gaussian_splatting_compression_spz_2: 8-bit log scales, quaternions, colour and opacity)"
            }
            Variant::PackedSplat => {
                "packed splats (Spark): 8-bit ln scales, 8-bit octahedral quaternions, opacity in steps of 2/255, half-float centres"
            }
            Variant::ColorSpaceIgnored => {
                "colorSpace ignored: lin_rec709_display blended and shown as display values"
            }
            Variant::NormalizedKernel => {
                "kernel α = opacity·(G − e⁻⁴)/(1 − e⁻⁴), cut at 2.83σ (PlayCanvas's normExp) instead of opacity·G cut at 3σ"
            }
            Variant::AxesSwapped => {
                "footprint axes swapped where Σ' has no x–y term: the eigenvector normalize(b, λ₁ − a) degenerates, so a footprint wider than tall is drawn taller than wide"
            }
            Variant::Attributes8Bit => {
                "colour, opacity and quaternion stored in 8 bits, SH in 8 bits over ±1, covariance in half floats (Babylon.js's splat buffer)"
            }
            Variant::ScaleLog8 => {
                "scales stored as 8-bit ln σ over [−12, 9] (σ off by up to ±4.2 %), opacity in 8 bits, quaternions in 11-11-10 bits (PlayCanvas's compact work buffer)"
            }
            Variant::ColourClamped => "each splat's colour clamped to 1 before blending",
            Variant::Unorm8Blending => {
                "blended in an 8-bit target: colour sums above 1 clamped between blends"
            }
        }
    }
    /// The RC section whose rule the variant departs from.
    pub fn rc_section(self) -> &'static str {
        match self {
            Variant::BoxCut | Variant::SquareCut => "RC Ellipse Kernel Rendering (3σ cut-off)",
            Variant::ViewDepthOrder => "RC Sorting Method (cameraDistance)",
            Variant::AaCompensation => "RC Ellipse Kernel Rendering (α = opacity · G(x))",
            Variant::ShDegree0 | Variant::ShDegree1 | Variant::ShDegree2 => {
                "RC Splat Projection: \"Implementations MAY ignore higher-degree coefficients\""
            }
            Variant::QuatWxyz => "RC Attributes (ROTATION: xyzw, the usual glTF order)",
            Variant::LogScale => "RC Attributes (SCALE: linear)",
            Variant::SigmoidColour => "RC Lighting (colour = Σ SH·Y + 0.5)",
            Variant::Colour8Bit => {
                "RC Attributes (float SH, OPACITY); the RC does not specify a renderer's precision"
            }
            Variant::EigenvalueFloor => "RC Splat Projection (Σ' = J W Σ Wᵀ Jᵀ)",
            Variant::HalfCovariance => {
                "RC Splat Reconstruction (Σ = R S Sᵀ Rᵀ); the RC does not specify a renderer's precision"
            }
            Variant::SpzPrecision => {
                "RC Attributes (float SCALE, ROTATION, OPACITY); SPZ precision is the input's when the asset was given as KHR_gaussian_splatting_compression_spz_2"
            }
            Variant::PackedSplat => {
                "RC Attributes (float SCALE, ROTATION, OPACITY); the RC does not specify a renderer's precision, but scales off by up to ±4 % change footprints beyond any bound"
            }
            Variant::ColorSpaceIgnored => {
                "RC Color Space (all blending before any transfer-function conversion)"
            }
            Variant::NormalizedKernel => "RC Ellipse Kernel Rendering (α = opacity · G(x))",
            Variant::AxesSwapped => "RC Splat Projection (Σ' = J W Σ Wᵀ Jᵀ)",
            Variant::ColourClamped | Variant::Unorm8Blending => {
                "RC Splat Composition (note: \"blending should be performed using floating-point color buffer formats\"); profile"
            }
            Variant::ScaleLog8 => {
                "RC Attributes (float SCALE); the RC does not specify a renderer's precision, but scales off by up to ±4.2 % change footprints beyond any bound"
            }
            Variant::Attributes8Bit => {
                "RC Attributes (float ROTATION, SH, OPACITY); the RC does not specify a renderer's precision, but 8-bit quaternions turn long splats by up to ~0.5°"
            }
        }
    }
    /// Whether the RC allows it: an image that matches it passes.
    pub fn rc_allowed(self) -> bool {
        matches!(
            self,
            Variant::ShDegree0 | Variant::ShDegree1 | Variant::ShDegree2
        )
    }
    /// Whether it is only a precision the RC does not specify (8-bit colour, half-float
    /// covariance): every asset's bound admits it, so an image with it passes.
    pub fn precision_only(self) -> bool {
        matches!(self, Variant::Colour8Bit | Variant::HalfCovariance)
    }
    /// The highest SH degree evaluated (3: all).
    pub(super) fn sh_cap(v: &[Variant]) -> usize {
        [
            (Variant::ShDegree0, 0),
            (Variant::ShDegree1, 1),
            (Variant::ShDegree2, 2),
        ]
        .into_iter()
        .filter(|(x, _)| v.contains(x))
        .map(|(_, d)| d)
        .min()
        .unwrap_or(3)
    }
}
