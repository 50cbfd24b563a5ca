//! The one place where the reference decides the blending order.
//!
//! Keep the sort behind [`back_to_front`]: the rayon radix sorter (`splatgl::sort`) will
//! replace its body, and it must produce exactly this order (same key, same tie rule).

use crate::camera::Camera;

/// What splats are sorted by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SortMode {
    /// The RC's `cameraDistance`: Euclidean distance camera centre → global mean (default).
    #[default]
    Distance,
    /// Camera-space depth z (OpenCV, +z forward), as the original 3DGS rasterizer sorts.
    ViewDepth,
}

/// The key of one mean, in f32: for [`SortMode::Distance`] the squared distance
/// `dx·dx + dy·dy + dz·dz` (same order as the distance, no square root); for
/// [`SortMode::ViewDepth`] `r₂·p + t₂` (row 2 of world → camera). Evaluated left to right,
/// without fused multiply-add.
pub fn sort_key(p: [f32; 3], eye: [f32; 3], depth_row: [f32; 4], mode: SortMode) -> f32 {
    match mode {
        SortMode::Distance => {
            let (dx, dy, dz) = (p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]);
            dx * dx + dy * dy + dz * dz
        }
        SortMode::ViewDepth => {
            depth_row[0] * p[0] + depth_row[1] * p[1] + depth_row[2] * p[2] + depth_row[3]
        }
    }
}

/// Indices of `positions` in blending order: back to front (largest key first), ties broken
/// by ascending index (stable sort). Keys are compared with `f32::total_cmp`; non-finite
/// means get arbitrary but deterministic places (the rasterizer culls them anyway).
pub fn back_to_front(positions: &[[f32; 3]], camera: &Camera, mode: SortMode) -> Vec<u32> {
    let eye = camera.eye().to_array();
    let m = camera.world_to_camera;
    let depth_row = [m.x_axis.z, m.y_axis.z, m.z_axis.z, m.w_axis.z];
    let keys: Vec<f32> = positions
        .iter()
        .map(|&p| sort_key(p, eye, depth_row, mode))
        .collect();
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_by(|&a, &b| keys[b as usize].total_cmp(&keys[a as usize]));
    order
}
