//! The one place where the reference decides the blending order: the crate's radix sorter
//! ([`crate::sort::Sorter`]) with the reference's camera, so the reference, the GL backend and
//! embedders all draw in exactly the same order.

use crate::camera::Camera;
pub use crate::sort::SortMode;

/// The key of one mean, in f32: for [`SortMode::Distance`] the squared distance
/// `dx·dx + dy·dy + dz·dz` ([`crate::sort::squared_distance`]); for [`SortMode::ViewDepth`]
/// the depth `(p − eye)·forward` along the camera's optical axis ([`crate::sort::view_depth`]).
/// Evaluated left to right, without fused multiply-add.
#[deprecated(
    since = "0.1.0",
    note = "use `splatgl::sort::{squared_distance, view_depth}`"
)]
pub fn sort_key(p: [f32; 3], camera: &Camera, mode: SortMode) -> f32 {
    let eye = camera.eye().to_array();
    match mode {
        SortMode::Distance => crate::sort::squared_distance(p, eye),
        SortMode::ViewDepth => {
            let forward = camera.world_to_camera.row(2).truncate().to_array();
            crate::sort::view_depth(p, eye, forward)
        }
    }
}

/// Indices of `positions` in blending order: back to front (largest [`sort_key`] first), ties
/// broken by ascending index — exactly a stable sort by key descending. NaN keys come first
/// (the rasterizer culls non-finite means anyway); see [`crate::sort::far_first_key`].
#[deprecated(since = "0.1.0", note = "use `splatgl::sort::Sorter::sort_for_camera`")]
pub fn back_to_front(positions: &[[f32; 3]], camera: &Camera, mode: SortMode) -> Vec<u32> {
    crate::sort::Sorter::new()
        .sort_for_camera(positions, camera, mode)
        .to_vec()
}

#[cfg(test)]
#[allow(deprecated)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn farthest_first_ties_by_index() {
        let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 1.0, 8, 8);
        // Distances 2, 5, 2, 1 (indices 0 and 2 tie); view depths 2, 3, 0, 1.
        let p = [
            [0.0, 0.0, 2.0],
            [4.0, 0.0, 3.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(back_to_front(&p, &cam, SortMode::Distance), [1, 0, 2, 3]);
        assert_eq!(back_to_front(&p, &cam, SortMode::ViewDepth), [1, 0, 3, 2]);
    }
}
