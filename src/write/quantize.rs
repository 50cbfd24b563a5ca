//! Quantized positions and scales: a cloud mapped into an integer component type's range,
//! with the node matrix that maps it back (the `KHR_mesh_quantization` way).
//!
//! The dequantization matrix is a uniform scale `k` and a translation `o`, `p = k·p_local + o`.
//! Per the RC the node matrix also scales the covariance (Σ = M C Cᵀ Mᵀ), so the stored scales
//! are `s / k`; a uniform positive scale without rotation leaves rotations and SH unchanged.

use super::Comp;
use crate::cloud::SplatCloud;

/// A cloud in the local space of its dequantization node.
#[derive(Debug, Clone)]
pub struct Dequantized {
    /// Positions and scales in local space (within the chosen types' ranges).
    pub cloud: SplatCloud,
    /// The node matrix (column-major `T(o)·S(k)`), `None` when no mapping is needed.
    pub matrix: Option<[f64; 16]>,
    /// The uniform scale `k` (1 without a matrix): one quantization step of POSITION is
    /// `k · position.step()` in scene units, of SCALE `k · scale.step()`.
    pub k: f64,
    /// Scale values that exceeded the scale type's range and were clamped to it.
    pub clamped_scales: usize,
}

/// Maps `cloud` so that POSITION fits `position` and SCALE fits `scale`:
/// - quantized positions: the bounding box, scaled uniformly, spans the type's range;
/// - otherwise, non-normalized integer scales (u8/u16): `k = max scale / type max`, so the
///   scales use the whole integer range; normalized scales above 1: `k = max scale`;
/// - otherwise no matrix (the cloud is returned as it is).
pub fn dequantize_node(cloud: &SplatCloud, position: Comp, scale: Comp) -> Dequantized {
    let max_scale = cloud
        .scales
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f32, f32::max) as f64;
    let (k, o) = if let (Some((lo, hi)), Some(b)) = (position.range(), cloud.bounds()) {
        let extent = (0..3)
            .map(|j| (b.max[j] - b.min[j]) as f64)
            .fold(0.0, f64::max);
        let k = if extent > 0.0 {
            extent / (hi - lo)
        } else {
            1.0
        };
        (k, [0, 1, 2].map(|j| b.min[j] as f64 - lo * k))
    } else {
        let k = match scale.range() {
            Some((_, hi)) if !scale.is_normalized() && max_scale > 0.0 => max_scale / hi,
            Some((_, hi)) if max_scale > hi => max_scale / hi,
            _ => 1.0,
        };
        (k, [0.0; 3])
    };
    if k == 1.0 && o == [0.0; 3] {
        return Dequantized {
            cloud: cloud.clone(),
            matrix: None,
            k,
            clamped_scales: 0,
        };
    }
    let mut local = cloud.clone();
    for p in &mut local.positions {
        *p = [0, 1, 2].map(|j| ((p[j] as f64 - o[j]) / k) as f32);
    }
    let hi = scale.range().map_or(f64::INFINITY, |r| r.1);
    let mut clamped = 0;
    for s in local.scales.iter_mut().flatten() {
        let v = *s as f64 / k;
        if v > hi {
            clamped += 1;
        }
        *s = v.min(hi) as f32;
    }
    #[rustfmt::skip]
    let matrix = [
        k, 0.0, 0.0, 0.0,
        0.0, k, 0.0, 0.0,
        0.0, 0.0, k, 0.0,
        o[0], o[1], o[2], 1.0,
    ];
    Dequantized {
        cloud: local,
        matrix: Some(matrix),
        k,
        clamped_scales: clamped,
    }
}
