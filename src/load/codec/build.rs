//! The parallel cloud builder of the packed readers and the pass that finishes a cloud
//! (quaternions normalised, unusable splats dropped with a finding).

use super::super::{Finding, LoadOptions, Severity};
use crate::cloud::{SplatCloud, sh_coeff_count};
use rayon::prelude::*;

/// One splat's slots in a cloud being filled.
pub struct SplatMut<'a> {
    /// Mean.
    pub position: &'a mut [f32; 3],
    /// Linear scale.
    pub scale: &'a mut [f32; 3],
    /// Quaternion `[x, y, z, w]` (normalised when the reader finishes the cloud).
    pub rotation: &'a mut [f32; 4],
    /// Linear opacity.
    pub opacity: &'a mut f32,
    /// `sh_coeff_count(degree)` RGB triples, degree-major.
    pub sh: &'a mut [[f32; 3]],
}

/// Builds a cloud of `n` splats by calling `fill(i, slots)` for every index in parallel (no
/// allocation per splat). `n` must already be justified by the input (checked by the caller).
pub fn build_cloud<E: Send>(
    n: usize,
    degree: u8,
    fill: impl Fn(usize, SplatMut<'_>) -> Result<(), E> + Sync,
) -> Result<SplatCloud, E> {
    let k = sh_coeff_count(degree);
    let mut c = SplatCloud::new(degree);
    c.positions = vec![[0.0; 3]; n];
    c.scales = vec![[0.0; 3]; n];
    c.rotations = vec![[0.0, 0.0, 0.0, 1.0]; n];
    c.opacities = vec![0.0; n];
    c.sh = vec![[0.0; 3]; n * k];
    c.positions
        .par_iter_mut()
        .zip(c.scales.par_iter_mut())
        .zip(c.rotations.par_iter_mut())
        .zip(c.opacities.par_iter_mut())
        .zip(c.sh.par_chunks_mut(k.max(1)))
        .enumerate()
        .with_min_len(1024)
        .try_for_each(|(i, ((((position, scale), rotation), opacity), sh))| {
            fill(
                i,
                SplatMut {
                    position,
                    scale,
                    rotation,
                    opacity,
                    sh,
                },
            )
        })?;
    Ok(c)
}

/// Normalises every quaternion (zero and non-finite ones are left as they are) and, when
/// `drop_at` names a finding path, drops the splats that break the loader contract through the
/// numeric hygiene pass (`hygiene.rs`: any non-finite value, a negative scale or one whose
/// square overflows, an opacity outside [0, 1], a zero quaternion), with a warning per field
/// naming the count and the first index. With `None` the bad splats stay for the caller's pass:
/// in strict mode (the load fails naming the splat) and inside glTF (the primitive's pass names
/// the JSON path).
pub(crate) fn finish_cloud(c: &mut SplatCloud, drop_at: Option<&str>, findings: &mut Vec<Finding>) {
    c.rotations.par_iter_mut().for_each(|q| {
        if let Some((n, _)) = super::super::normalize_quat(*q) {
            *q = n;
        }
    });
    let Some(path) = drop_at else {
        return;
    };
    let site = super::super::hygiene::Site {
        path,
        what: "",
        severity: Severity::Warning,
        strict: false,
        origin: None,
    };
    // Not strict: the pass drops and reports, it never fails.
    super::super::hygiene::clean(c, &site, findings).ok();
}

/// Where a packed reader's [`finish_cloud`] drops bad splats: at `path`, unless the load is
/// strict (then the exit pass of `load::read` fails on the first one).
pub(crate) fn drop_site<'a>(path: &'a str, opts: &LoadOptions) -> Option<&'a str> {
    (!opts.strict).then_some(path)
}
