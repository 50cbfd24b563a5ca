//! The crop box (`render --crop`, `view --crop`, `convert --crop`): an axis-aligned box in
//! scene coordinates; splats whose mean lies outside it are neither sorted nor drawn (nor
//! written). The convention of splat-transform's `--filter-box`: `minx,miny,minz,maxx,maxy,maxz`,
//! a splat is kept when `min ≤ mean ≤ max` on every axis (both ends inclusive).

use crate::cloud::SplatCloud;

/// An axis-aligned box, `min ≤ max` on every axis, finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CropBox {
    /// Lower corner.
    pub min: [f32; 3],
    /// Upper corner.
    pub max: [f32; 3],
}

/// Why a crop box could not be read ([`CropBox::parse`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CropError {
    /// A value that is not a finite number.
    #[error("`{0}` is not a finite number")]
    NotANumber(String),
    /// Not six values.
    #[error("{0} values; a crop box is minx,miny,minz,maxx,maxy,maxz")]
    Count(usize),
    /// A min above its max.
    #[error("min {axis} {min} > max {axis} {max}")]
    Inverted {
        /// `x`, `y` or `z`.
        axis: &'static str,
        /// The min given.
        min: f32,
        /// The max given.
        max: f32,
    },
}

impl From<CropError> for String {
    fn from(e: CropError) -> String {
        e.to_string()
    }
}

impl CropBox {
    /// The box of `minx,miny,minz,maxx,maxy,maxz`; an error naming the problem when a value
    /// is not a finite number, there are not six, or a min exceeds its max.
    pub fn parse(s: &str) -> Result<Self, CropError> {
        let v: Vec<f32> = s
            .split(',')
            .map(|t| {
                t.trim()
                    .parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| CropError::NotANumber(t.trim().to_owned()))
            })
            .collect::<Result<_, _>>()?;
        let [x0, y0, z0, x1, y1, z1] = v[..] else {
            return Err(CropError::Count(v.len()));
        };
        let b = CropBox {
            min: [x0, y0, z0],
            max: [x1, y1, z1],
        };
        for (a, axis) in ["x", "y", "z"].into_iter().enumerate() {
            if b.min[a] > b.max[a] {
                return Err(CropError::Inverted {
                    axis,
                    min: b.min[a],
                    max: b.max[a],
                });
            }
        }
        Ok(b)
    }

    /// Whether `p` lies inside (ends included; NaN is outside).
    pub fn contains(&self, p: [f32; 3]) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] && p[a] <= self.max[a])
    }

    /// The indices of `cloud`'s splats inside, ascending.
    pub fn inside(&self, cloud: &SplatCloud) -> Vec<u32> {
        (0..cloud.len() as u32)
            .filter(|&i| self.contains(cloud.positions[i as usize]))
            .collect()
    }

    /// `cloud` without the splats outside (`None` when every splat is inside: nothing to do).
    pub fn apply(&self, cloud: &SplatCloud) -> Option<SplatCloud> {
        let kept = self.inside(cloud);
        (kept.len() < cloud.len()).then(|| cloud.select(&kept))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_six_values_and_keeps_both_ends() {
        let b = CropBox::parse("-1,-2,-3, 1,2,3").unwrap();
        assert_eq!(b.min, [-1.0, -2.0, -3.0]);
        assert!(b.contains([1.0, -2.0, 0.0]));
        assert!(!b.contains([1.0001, 0.0, 0.0]));
        assert!(!b.contains([f32::NAN, 0.0, 0.0]));
        assert!(
            CropBox::parse("1,2,3")
                .unwrap_err()
                .to_string()
                .contains("3 values")
        );
        assert!(
            CropBox::parse("0,0,0,1,1,x")
                .unwrap_err()
                .to_string()
                .contains("`x`")
        );
        assert!(CropBox::parse("0,0,0,1,1,inf").is_err());
        assert!(
            CropBox::parse("2,0,0,1,1,1")
                .unwrap_err()
                .to_string()
                .contains("min x 2 > max x 1")
        );
    }

    #[test]
    fn apply_keeps_exactly_the_splats_inside_in_order() {
        let mut c = SplatCloud::new(0);
        for (k, x) in [-2.0f32, 0.5, 3.0, 0.0].iter().enumerate() {
            c.push(
                [*x, 0.0, 0.0],
                [0.1; 3],
                [0.0, 0.0, 0.0, 1.0],
                0.1 * k as f32,
                &[[0.0; 3]],
            );
        }
        let b = CropBox::parse("-1,-1,-1,1,1,1").unwrap();
        let out = b.apply(&c).unwrap();
        assert_eq!(out.positions, [[0.5, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        assert_eq!(out.opacities, [0.1, 0.3]);
        assert!(
            CropBox::parse("-9,-9,-9,9,9,9")
                .unwrap()
                .apply(&c)
                .is_none()
        );
    }
}
