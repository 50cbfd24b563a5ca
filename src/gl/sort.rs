//! Back-to-front ordering by camera distance (`sortingMethod: cameraDistance`, RC): the one
//! place the draw order is made, so a faster sorter (the rayon radix sorter) replaces this
//! function's body without touching the renderer.

use glam::Vec3;
use rayon::slice::ParallelSliceMut;

/// Reusable scratch for [`DistanceSorter::sort`] (no allocation per frame once warm).
#[derive(Debug, Default, Clone)]
pub struct DistanceSorter {
    keys: Vec<u64>,
}

/// The sort key of splat `i`: farther first, then lower index first. Squared distances are
/// non-negative, so their f32 bit patterns order like the values; NaN (a non-finite mean)
/// sorts as farthest.
fn key(p: [f32; 3], eye: Vec3, i: u32) -> u64 {
    let d = Vec3::from_array(p) - eye;
    let d2 = d.length_squared();
    let bits = if d2.is_nan() { u32::MAX } else { d2.to_bits() };
    (u64::from(!bits) << 32) | u64::from(i)
}

impl DistanceSorter {
    /// Writes into `order` the indices of `positions` sorted back to front: squared Euclidean
    /// distance to `eye` descending, ties by index ascending (a total order, so the result is
    /// what a stable sort gives and is deterministic).
    pub fn sort(&mut self, positions: &[[f32; 3]], eye: Vec3, order: &mut Vec<u32>) {
        assert!(
            positions.len() <= u32::MAX as usize,
            "more than 2^32 splats"
        );
        self.keys.clear();
        self.keys.extend(
            positions
                .iter()
                .enumerate()
                .map(|(i, p)| key(*p, eye, i as u32)),
        );
        self.keys.par_sort_unstable();
        order.clear();
        order.extend(self.keys.iter().map(|k| *k as u32));
    }
}

/// [`DistanceSorter::sort`] with fresh scratch (allocates; keep a [`DistanceSorter`] per frame
/// loop instead).
pub fn sort_back_to_front(positions: &[[f32; 3]], eye: Vec3, order: &mut Vec<u32>) {
    DistanceSorter::default().sort(positions, eye, order);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn farthest_first_ties_by_index() {
        let pos = [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 3.0],
            [0.0, 3.0, 0.0], // same distance as 1
            [0.0, 0.0, 2.0],
        ];
        let mut order = Vec::new();
        sort_back_to_front(&pos, Vec3::ZERO, &mut order);
        assert_eq!(order, [1, 2, 3, 0]);
    }

    #[test]
    fn nan_sorts_first() {
        let pos = [[0.0, 0.0, 1.0], [f32::NAN, 0.0, 0.0]];
        let mut order = Vec::new();
        sort_back_to_front(&pos, Vec3::ZERO, &mut order);
        assert_eq!(order, [1, 0]);
    }
}
