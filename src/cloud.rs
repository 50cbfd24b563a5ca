//! [`SplatCloud`]: the one in-memory model of a Gaussian splat scene.
//!
//! Every loader produces it, every renderer consumes it. It is a struct of arrays with one
//! contiguous `Vec` per attribute, so it moves into the renderer cheaply and each array can be
//! cast to bytes with `bytemuck` for upload.
//!
//! # Conventions
//! - **Space**: everything is in *global* space. glTF node transforms were already applied by
//!   the loader (position by the full matrix, covariance as Σ = M C Cᵀ Mᵀ, SH rotated by the
//!   node's rotation). Renderers never see node transforms.
//! - **Scale**: linear standard deviations along the splat's principal axes, `≥ 0`.
//! - **Rotation**: unit quaternion, `[x, y, z, w]` (glTF order). Σ = R diag(s)² Rᵀ.
//! - **Opacity**: linear, in `[0, 1]`.
//! - **SH**: per splat `sh_coeff_count(sh_degree)` RGB triples, degree-major and, within a
//!   degree, m = −l..+l — exactly the order of the `KHR_gaussian_splatting:SH_DEGREE_l_COEF_n`
//!   attributes. Coefficient 0 is the DC term (`SH_DEGREE_0_COEF_0`); the colour is
//!   `Σ SH·Y + 0.5`, clamped at 0, with the Condon–Shortley phase in the basis (see [`crate::sh`]).
//!
//! Loaders guarantee more than the conventions: every value finite, scales with a finite
//! square, ‖q‖ within [`UNIT_QUAT_TOLERANCE`] of 1, opacity in `[0, 1]`.
//! [`SplatCloud::validate`] checks exactly that.

use bytemuck::{Pod, Zeroable};

mod check;
mod select;
pub use check::{Field, UNIT_QUAT_TOLERANCE, Violation};

/// Number of RGB coefficients per splat for SH degree `degree` (1, 4, 9, 16 for 0..=3).
pub const fn sh_coeff_count(degree: u8) -> usize {
    let d = degree as usize + 1;
    d * d
}

/// Highest SH degree the extension defines.
pub const MAX_SH_DEGREE: u8 = 3;

/// A value of one of the extension's open string enums: a known value, or an unknown one kept
/// verbatim (the schema allows any string; renderers fall back and say so).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Known<T> {
    /// A value this version of splatgl understands.
    Known(T),
    /// A value it doesn't; kept as written in the file.
    Unknown(String),
}

impl<T: Copy + Default> Known<T> {
    /// The value to render with: the known value, or the default when unknown.
    pub fn effective(&self) -> T {
        match self {
            Known::Known(v) => *v,
            Known::Unknown(_) => T::default(),
        }
    }
}

/// The `kernel` property.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kernel {
    /// `"ellipse"`: the 3DGS ellipse kernel with a 3σ cut-off.
    #[default]
    Ellipse,
}

/// The `colorSpace` property: the space the reconstructed colours (and blending) live in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorSpace {
    /// `"srgb_rec709_display"`: blend the values as stored, display them as they are.
    #[default]
    SrgbRec709Display,
    /// `"lin_rec709_display"`: blend linear values; convert to sRGB for display at the end.
    LinRec709Display,
}

/// The `projection` property.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Projection {
    /// `"perspective"` (the default).
    #[default]
    Perspective,
}

/// The `sortingMethod` property.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SortingMethod {
    /// `"cameraDistance"` (the default): Euclidean distance camera → global mean, back to front.
    #[default]
    CameraDistance,
}

impl Kernel {
    /// The spec's string for this value.
    pub fn as_str(self) -> &'static str {
        "ellipse"
    }
    /// Parses a spec string (unknown values kept verbatim).
    pub fn parse(s: &str) -> Known<Self> {
        match s {
            "ellipse" => Known::Known(Kernel::Ellipse),
            _ => Known::Unknown(s.to_owned()),
        }
    }
}

impl ColorSpace {
    /// The spec's string for this value.
    pub fn as_str(self) -> &'static str {
        match self {
            ColorSpace::SrgbRec709Display => "srgb_rec709_display",
            ColorSpace::LinRec709Display => "lin_rec709_display",
        }
    }
    /// Parses a spec string (unknown values kept verbatim).
    pub fn parse(s: &str) -> Known<Self> {
        match s {
            "srgb_rec709_display" => Known::Known(ColorSpace::SrgbRec709Display),
            "lin_rec709_display" => Known::Known(ColorSpace::LinRec709Display),
            _ => Known::Unknown(s.to_owned()),
        }
    }
}

impl Projection {
    /// The spec's string for this value.
    pub fn as_str(self) -> &'static str {
        "perspective"
    }
    /// Parses a spec string (unknown values kept verbatim).
    pub fn parse(s: &str) -> Known<Self> {
        match s {
            "perspective" => Known::Known(Projection::Perspective),
            _ => Known::Unknown(s.to_owned()),
        }
    }
}

impl SortingMethod {
    /// The spec's string for this value.
    pub fn as_str(self) -> &'static str {
        "cameraDistance"
    }
    /// Parses a spec string (unknown values kept verbatim).
    pub fn parse(s: &str) -> Known<Self> {
        match s {
            "cameraDistance" => Known::Known(SortingMethod::CameraDistance),
            _ => Known::Unknown(s.to_owned()),
        }
    }
}

impl<T: Copy> Known<T> {
    /// The string as written (known values through `name`).
    pub fn to_string_with(&self, name: impl Fn(T) -> &'static str) -> String {
        match self {
            Known::Known(v) => name(*v).to_owned(),
            Known::Unknown(s) => s.clone(),
        }
    }
}

/// The extension's metadata for a cloud. When primitives with different values are merged, the
/// first primitive's values are kept and the loader warns.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplatMeta {
    /// `kernel`.
    pub kernel: Known<Kernel>,
    /// `colorSpace`.
    pub color_space: Known<ColorSpace>,
    /// `projection`.
    pub projection: Known<Projection>,
    /// `sortingMethod`.
    pub sorting_method: Known<SortingMethod>,
}

impl Default for SplatMeta {
    fn default() -> Self {
        SplatMeta {
            kernel: Known::Known(Kernel::Ellipse),
            color_space: Known::Known(ColorSpace::SrgbRec709Display),
            projection: Known::Known(Projection::Perspective),
            sorting_method: Known::Known(SortingMethod::CameraDistance),
        }
    }
}

/// Axis-aligned bounds of the splat means.
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Bounds {
    /// Component-wise minimum.
    pub min: [f32; 3],
    /// Component-wise maximum.
    pub max: [f32; 3],
}

impl Bounds {
    /// Centre of the box.
    pub fn center(&self) -> [f32; 3] {
        std::array::from_fn(|i| 0.5 * (self.min[i] + self.max[i]))
    }
    /// Length of the box's diagonal.
    pub fn diagonal(&self) -> f32 {
        (0..3)
            .map(|i| (self.max[i] - self.min[i]).powi(2))
            .sum::<f32>()
            .sqrt()
    }
}

/// A Gaussian splat scene in global space, struct of arrays. See the module docs for the
/// conventions every field follows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SplatCloud {
    /// Means, global space.
    pub positions: Vec<[f32; 3]>,
    /// Linear scales (standard deviations), `≥ 0`.
    pub scales: Vec<[f32; 3]>,
    /// Unit quaternions `[x, y, z, w]`.
    pub rotations: Vec<[f32; 4]>,
    /// Linear opacity in `[0, 1]`.
    pub opacities: Vec<f32>,
    /// SH degree of every splat, `0..=3`.
    pub sh_degree: u8,
    /// `len() * sh_coeff_count(sh_degree)` RGB coefficients, splat-major, then degree-major
    /// with m = −l..+l inside a degree.
    pub sh: Vec<[f32; 3]>,
    /// Extension metadata.
    pub meta: SplatMeta,
}

/// A cloud whose arrays do not agree ([`SplatCloud::check_lengths`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LengthError {
    /// The SH degree is above [`MAX_SH_DEGREE`].
    #[error("sh_degree {0} > {MAX_SH_DEGREE}")]
    ShDegree(u8),
    /// An attribute has another length than the positions.
    #[error("{name} has {len} entries, positions {n}")]
    Attribute {
        /// Its name.
        name: &'static str,
        /// Its length.
        len: usize,
        /// The positions'.
        n: usize,
    },
    /// The SH array is not `n × k` triples.
    #[error("sh has {len} triples, expected {n} × {k}")]
    Sh {
        /// Its length in triples.
        len: usize,
        /// Splats.
        n: usize,
        /// Coefficients per splat.
        k: usize,
    },
}

impl From<LengthError> for String {
    fn from(e: LengthError) -> String {
        e.to_string()
    }
}

impl SplatCloud {
    /// An empty cloud of the given SH degree.
    pub fn new(sh_degree: u8) -> Self {
        SplatCloud {
            sh_degree,
            ..Default::default()
        }
    }

    /// An empty cloud with room for `n` splats.
    pub fn with_capacity(sh_degree: u8, n: usize) -> Self {
        SplatCloud {
            positions: Vec::with_capacity(n),
            scales: Vec::with_capacity(n),
            rotations: Vec::with_capacity(n),
            opacities: Vec::with_capacity(n),
            sh_degree,
            sh: Vec::with_capacity(n * sh_coeff_count(sh_degree)),
            meta: SplatMeta::default(),
        }
    }

    /// Number of splats.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no splats.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// RGB coefficients per splat.
    pub fn coeffs_per_splat(&self) -> usize {
        sh_coeff_count(self.sh_degree)
    }

    /// The SH coefficients of splat `i`.
    pub fn sh_of(&self, i: usize) -> &[[f32; 3]] {
        let k = self.coeffs_per_splat();
        &self.sh[i * k..(i + 1) * k]
    }

    /// Appends one splat. `sh` must hold exactly [`Self::coeffs_per_splat`] triples.
    pub fn push(
        &mut self,
        position: [f32; 3],
        scale: [f32; 3],
        rotation: [f32; 4],
        opacity: f32,
        sh: &[[f32; 3]],
    ) {
        assert_eq!(sh.len(), self.coeffs_per_splat(), "SH coefficient count");
        self.positions.push(position);
        self.scales.push(scale);
        self.rotations.push(rotation);
        self.opacities.push(opacity);
        self.sh.extend_from_slice(sh);
    }

    /// Checks the invariants (equal lengths, SH length). Loaders guarantee them; this is for
    /// clouds built by hand.
    pub fn check_lengths(&self) -> Result<(), LengthError> {
        let n = self.len();
        let k = self.coeffs_per_splat();
        if self.sh_degree > MAX_SH_DEGREE {
            return Err(LengthError::ShDegree(self.sh_degree));
        }
        for (name, len) in [
            ("scales", self.scales.len()),
            ("rotations", self.rotations.len()),
            ("opacities", self.opacities.len()),
        ] {
            if len != n {
                return Err(LengthError::Attribute { name, len, n });
            }
        }
        if self.sh.len() != n * k {
            return Err(LengthError::Sh {
                len: self.sh.len(),
                n,
                k,
            });
        }
        Ok(())
    }

    /// Bounds of the means (`None` when empty). Non-finite means are skipped.
    pub fn bounds(&self) -> Option<Bounds> {
        let mut it = self
            .positions
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()));
        let first = *it.next()?;
        let mut b = Bounds {
            min: first,
            max: first,
        };
        for p in it {
            b.min = std::array::from_fn(|i| b.min[i].min(p[i]));
            b.max = std::array::from_fn(|i| b.max[i].max(p[i]));
        }
        Some(b)
    }

    /// Bytes held by the attribute arrays (their lengths, not capacities).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.positions.as_slice())
            + std::mem::size_of_val(self.scales.as_slice())
            + std::mem::size_of_val(self.rotations.as_slice())
            + std::mem::size_of_val(self.opacities.as_slice())
            + std::mem::size_of_val(self.sh.as_slice())
    }

    /// Raises the SH degree to `degree` by appending zero coefficients (a zero coefficient
    /// adds nothing to the colour, so the rendered result is unchanged).
    fn pad_sh(&mut self, degree: u8) {
        if degree <= self.sh_degree {
            return;
        }
        let (old, new) = (self.coeffs_per_splat(), sh_coeff_count(degree));
        let mut out = Vec::with_capacity(self.len() * new);
        for chunk in self.sh.chunks_exact(old) {
            out.extend_from_slice(chunk);
            out.resize(out.len() + new - old, [0.0; 3]);
        }
        self.sh = out;
        self.sh_degree = degree;
    }

    /// Appends another cloud. SH degrees are unified to the higher of the two by zero-padding
    /// (lossless: the colours do not change). Returns whether padding happened.
    pub fn append(&mut self, mut other: SplatCloud) -> bool {
        let target = self.sh_degree.max(other.sh_degree);
        let padded = self.sh_degree != other.sh_degree && !(self.is_empty() || other.is_empty());
        if self.is_empty() {
            self.sh_degree = other.sh_degree;
            self.sh.clear();
        } else if !other.is_empty() {
            self.pad_sh(target);
            other.pad_sh(target);
        }
        self.positions.append(&mut other.positions);
        self.scales.append(&mut other.scales);
        self.rotations.append(&mut other.rotations);
        self.opacities.append(&mut other.opacities);
        self.sh.append(&mut other.sh);
        padded
    }

    /// Whether splat `i` can be drawn at all: finite position, scale, rotation and SH
    /// coefficients, and an opacity that is not NaN (+inf opacity is capped at α = 0.99 like
    /// any other). Both renderers skip splats that are not (loaders never produce them; this
    /// is for clouds built by library callers).
    pub fn is_drawable(&self, i: usize) -> bool {
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        finite(&self.positions[i])
            && finite(&self.scales[i])
            && finite(&self.rotations[i])
            && !self.opacities[i].is_nan()
            && self.sh_of(i).iter().all(|c| finite(c))
    }

    /// The 3×3 covariance Σ = R diag(s)² Rᵀ of splat `i`, as the upper triangle
    /// `[xx, xy, xz, yy, yz, zz]`, computed in f64.
    pub fn covariance(&self, i: usize) -> [f64; 6] {
        crate::covariance::covariance_from_scale_rotation(self.scales[i], self.rotations[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coeff_counts() {
        assert_eq!(
            [0, 1, 2, 3].map(sh_coeff_count),
            [1, 4, 9, 16],
            "degree → coefficient count"
        );
    }

    #[test]
    fn append_unifies_degree() {
        let mut a = SplatCloud::new(3);
        a.push(
            [0.0; 3],
            [1.0; 3],
            [0.0, 0.0, 0.0, 1.0],
            0.5,
            &[[1.0; 3]; 16],
        );
        let mut b = SplatCloud::new(1);
        b.push(
            [1.0; 3],
            [1.0; 3],
            [0.0, 0.0, 0.0, 1.0],
            0.5,
            &[[2.0; 3]; 4],
        );
        assert!(a.append(b));
        assert_eq!(a.sh_degree, 3);
        assert_eq!(a.sh.len(), 32);
        assert!(a.check_lengths().is_ok());
        assert_eq!(a.sh_of(1)[0], [2.0; 3]);
        assert_eq!(a.sh_of(1)[4], [0.0; 3], "padded with zeros");
    }

    #[test]
    fn bounds_skip_nonfinite() {
        let mut a = SplatCloud::new(0);
        for p in [[1.0, 2.0, 3.0], [f32::NAN, 0.0, 0.0], [-1.0, 5.0, 0.0]] {
            a.push(p, [1.0; 3], [0.0, 0.0, 0.0, 1.0], 1.0, &[[0.0; 3]]);
        }
        let b = a.bounds().unwrap();
        assert_eq!(b.min, [-1.0, 2.0, 0.0]);
        assert_eq!(b.max, [1.0, 5.0, 3.0]);
    }
}
