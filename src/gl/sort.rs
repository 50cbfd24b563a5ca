//! Back-to-front ordering by camera distance (`sortingMethod: cameraDistance`, RC) for the
//! renderer: a thin wrapper over the crate's radix sorter ([`crate::sort::Sorter`]) that writes
//! into a caller-owned order buffer.

use glam::Vec3;

/// A reusable distance sorter (no allocation per frame once warm).
#[deprecated(
    since = "0.1.0",
    note = "use `splatgl::sort::Sorter` (its `sort_by_distance` / `sort_visible` return the order), or let `SplatRenderer::draw_frame` sort"
)]
#[derive(Debug, Default)]
pub struct DistanceSorter {
    sorter: crate::sort::Sorter,
}

#[allow(deprecated)]
impl DistanceSorter {
    /// Writes into `order` the indices of `positions` sorted back to front: squared Euclidean
    /// distance to `eye` descending, ties by index ascending (what a stable sort gives; NaN
    /// first), deterministic and independent of the thread count.
    pub fn sort(&mut self, positions: &[[f32; 3]], eye: Vec3, order: &mut Vec<u32>) {
        let sorted = self.sorter.sort_by_distance(positions, eye.to_array());
        order.clear();
        order.extend_from_slice(sorted);
    }
}

#[allow(deprecated)]
impl DistanceSorter {
    /// [`DistanceSorter::sort`] of only the splats `frustum` may see
    /// ([`crate::sort::Sorter::sort_visible`]): `bounds` are the cloud's
    /// [`CullBounds`](crate::cull::CullBounds), `frustum` from
    /// [`frustum_for_camera`](super::frustum_for_camera) or
    /// [`frustum_for_matrices`](super::frustum_for_matrices) of the draw. The image drawn from
    /// it is the one drawn from the full order; `order.len()` is the visible count.
    pub fn sort_visible(
        &mut self,
        positions: &[[f32; 3]],
        bounds: &crate::cull::CullBounds,
        frustum: &crate::cull::Frustum,
        eye: Vec3,
        order: &mut Vec<u32>,
    ) {
        let request = crate::sort::SortRequest::distance(eye.to_array());
        let sorted = self
            .sorter
            .sort_visible(positions, bounds, frustum, &request);
        order.clear();
        order.extend_from_slice(sorted);
    }
}

/// [`DistanceSorter::sort`] with fresh scratch (allocates on every call).
#[deprecated(
    since = "0.1.0",
    note = "use `splatgl::sort::Sorter::sort_by_distance` (keeps its scratch), or let `SplatRenderer::draw_frame` sort"
)]
#[allow(deprecated)]
pub fn sort_back_to_front(positions: &[[f32; 3]], eye: Vec3, order: &mut Vec<u32>) {
    DistanceSorter::default().sort(positions, eye, order);
}

#[cfg(test)]
#[allow(deprecated)]
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
