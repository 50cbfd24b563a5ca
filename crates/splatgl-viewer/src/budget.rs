//! `--max-splats N`: a deterministic subset of a cloud for weak GPUs.
//!
//! Rule: each splat scores `opacity × s₁ × s₂`, the product of its two largest standard
//! deviations (proportional to the area of its largest cross-section, i.e. how much it can
//! cover, weighted by how opaque it is). The `N` highest scores are kept, ties broken by lower
//! index, non-finite scores last; the kept splats stay in file order. The same file and `N`
//! always give the same subset.

use splatgl::cloud::SplatCloud;

/// The score of splat `i` (non-finite → −∞, so it is dropped first).
fn score(cloud: &SplatCloud, i: usize) -> f32 {
    let mut s = cloud.scales[i];
    s.sort_by(|a, b| b.total_cmp(a));
    let v = cloud.opacities[i] * s[0] * s[1];
    if v.is_finite() { v } else { f32::NEG_INFINITY }
}

/// The indices kept for a budget of `n` splats (all of them when `n ≥ len`), ascending.
pub fn kept_indices(cloud: &SplatCloud, n: usize) -> Vec<u32> {
    let len = cloud.len();
    if n >= len {
        return (0..len as u32).collect();
    }
    let mut ranked: Vec<(f32, u32)> = (0..len).map(|i| (score(cloud, i), i as u32)).collect();
    // Highest score first, then lowest index: a total order, so the cut is deterministic.
    let by_rank = |a: &(f32, u32), b: &(f32, u32)| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1));
    if n > 0 {
        ranked.select_nth_unstable_by(n - 1, by_rank);
    }
    let mut kept: Vec<u32> = ranked[..n].iter().map(|r| r.1).collect();
    kept.sort_unstable();
    kept
}

/// The subset of `cloud` for a budget of `n` splats (see the module docs); `None` when the
/// cloud fits.
pub fn subset(cloud: &SplatCloud, n: usize) -> Option<SplatCloud> {
    if n >= cloud.len() {
        return None;
    }
    let kept = kept_indices(cloud, n);
    let out = cloud.select(&kept);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budget_keeps_the_largest_contributions_deterministically() {
        let mut c = SplatCloud::new(0);
        // Scores: 0.5·1·1, 1·0.1·0.1, 1·2·2 (largest), NaN, 0.5·1·1 (tie with 0).
        let rows = [
            ([1.0, 1.0, 0.1], 0.5),
            ([0.1, 0.1, 0.1], 1.0),
            ([2.0, 0.5, 2.0], 1.0),
            ([f32::NAN, 1.0, 1.0], 1.0),
            ([1.0, 0.1, 1.0], 0.5),
        ];
        for (i, (s, o)) in rows.iter().enumerate() {
            c.push(
                [i as f32, 0.0, 0.0],
                *s,
                [0.0, 0.0, 0.0, 1.0],
                *o,
                &[[0.0; 3]],
            );
        }
        assert_eq!(kept_indices(&c, 2), vec![0, 2]);
        assert_eq!(kept_indices(&c, 3), vec![0, 2, 4]);
        assert_eq!(kept_indices(&c, 4), vec![0, 1, 2, 4]);
        let s = subset(&c, 2).unwrap();
        assert_eq!(s.positions, vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
        assert!(subset(&c, 5).is_none());
        assert!(kept_indices(&c, 0).is_empty());
    }
}
