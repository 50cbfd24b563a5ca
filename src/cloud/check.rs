//! The loader contract of a [`SplatCloud`], checkable: [`SplatCloud::validate`] and the
//! per-splat test [`SplatCloud::splat_problem`] that the loaders' numeric hygiene pass applies.

use super::{MAX_SH_DEGREE, SplatCloud};
use std::fmt;

/// How far ‖q‖ may be from 1 in a loaded cloud (f32 normalisation is far closer).
pub const UNIT_QUAT_TOLERANCE: f32 = 1e-3;

/// The field of a splat that breaks the contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Field {
    /// `positions`: not finite.
    Position,
    /// `scales`: not finite, negative, or its square overflows f32.
    Scale,
    /// `rotations`: not a finite unit quaternion.
    Rotation,
    /// `opacities`: not in [0, 1].
    Opacity,
    /// `sh`: a coefficient is not finite.
    Sh,
}

impl Field {
    /// The field's name in [`SplatCloud`].
    pub fn name(self) -> &'static str {
        match self {
            Field::Position => "position",
            Field::Scale => "scale",
            Field::Rotation => "rotation",
            Field::Opacity => "opacity",
            Field::Sh => "SH coefficient",
        }
    }
    /// What the contract says, as broken.
    pub fn rule(self) -> &'static str {
        match self {
            Field::Position => "is not finite",
            Field::Scale => "is not finite, negative, or its square overflows f32",
            Field::Rotation => "is not a finite unit quaternion",
            Field::Opacity => "is not in [0, 1]",
            Field::Sh => "is not finite",
        }
    }
}

/// The first way a cloud breaks the loader contract.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The splat, when the violation is one splat's (else the arrays' lengths or the degree).
    pub index: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index {
            Some(i) => write!(f, "splat {i}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for Violation {}

impl SplatCloud {
    /// The first field of splat `i` that breaks the contract every loader guarantees (module
    /// docs): every value finite, scales `≥ 0` with a finite square, unit quaternions,
    /// opacity in `[0, 1]`. `None` when the splat is fine.
    pub fn splat_problem(&self, i: usize) -> Option<Field> {
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !finite(&self.positions[i]) {
            return Some(Field::Position);
        }
        if !self.scales[i]
            .iter()
            .all(|&s| s >= 0.0 && (s * s).is_finite())
        {
            return Some(Field::Scale);
        }
        let q = self.rotations[i];
        let n = q.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
        if !finite(&q) || (n - 1.0).abs() > UNIT_QUAT_TOLERANCE as f64 {
            return Some(Field::Rotation);
        }
        if !(0.0..=1.0).contains(&self.opacities[i]) {
            return Some(Field::Opacity);
        }
        if !self.sh_of(i).iter().all(|c| finite(c)) {
            return Some(Field::Sh);
        }
        None
    }

    /// Checks the whole loader contract: consistent lengths ([`Self::check_lengths`]) and
    /// every splat per [`Self::splat_problem`]. Returns the first violation. Every cloud a
    /// loader returns passes; tests (and the fuzz targets) call it on every loaded cloud.
    pub fn validate(&self) -> Result<(), Violation> {
        self.check_lengths().map_err(|message| Violation {
            index: None,
            message: message.to_string(),
        })?;
        debug_assert!(self.sh_degree <= MAX_SH_DEGREE);
        for i in 0..self.len() {
            if let Some(f) = self.splat_problem(i) {
                return Err(Violation {
                    index: Some(i),
                    message: format!("{} {}", f.name(), f.rule()),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(
        pos: [f32; 3],
        scale: [f32; 3],
        rot: [f32; 4],
        opacity: f32,
        sh: [f32; 3],
    ) -> SplatCloud {
        let mut c = SplatCloud::new(0);
        c.push(pos, scale, rot, opacity, &[sh]);
        c
    }

    #[test]
    fn validate_names_the_first_broken_field() {
        let id = [0.0, 0.0, 0.0, 1.0];
        assert!(
            one([0.0; 3], [1.0; 3], id, 0.5, [0.0; 3])
                .validate()
                .is_ok()
        );
        let cases = [
            (
                one([f32::NAN, 0.0, 0.0], [1.0; 3], id, 0.5, [0.0; 3]),
                "position",
            ),
            (one([0.0; 3], [-1.0, 1.0, 1.0], id, 0.5, [0.0; 3]), "scale"),
            (
                one([0.0; 3], [1e20, 1.0, 1.0], id, 0.5, [0.0; 3]),
                "square overflows",
            ),
            (
                one([0.0; 3], [1.0; 3], [0.0, 0.0, 0.0, 0.5], 0.5, [0.0; 3]),
                "unit quaternion",
            ),
            (one([0.0; 3], [1.0; 3], id, f32::NAN, [0.0; 3]), "opacity"),
            (one([0.0; 3], [1.0; 3], id, 1.5, [0.0; 3]), "[0, 1]"),
            (
                one([0.0; 3], [1.0; 3], id, 0.5, [0.0, f32::INFINITY, 0.0]),
                "SH",
            ),
        ];
        for (c, needle) in cases {
            let e = c.validate().unwrap_err().to_string();
            assert!(e.starts_with("splat 0: ") && e.contains(needle), "{e}");
        }
        let mut bad = one([0.0; 3], [1.0; 3], id, 0.5, [0.0; 3]);
        bad.opacities.push(0.5);
        assert!(bad.validate().unwrap_err().index.is_none());
    }
}
