//! The numeric constants of the ellipse kernel as the 3DGS forward pass uses them. The shaders
//! receive every one of them as a `#define` generated from these values (see
//! [`super::program::defines`]); nothing is hand-copied into GLSL.

/// Low-pass dilation added to the diagonal of the 2D covariance, in px² (3DGS `computeCov2D`).
pub const DILATION: f32 = 0.3;
/// Cut-off in standard deviations: a pixel contributes while its Mahalanobis distance ≤ 3.
pub const SIGMA_CUTOFF: f32 = 3.0;
/// Cap on a splat's per-pixel alpha (3DGS `renderCUDA`).
pub const ALPHA_MAX: f32 = 0.99;
/// Contributions with alpha below this are skipped (3DGS `renderCUDA`).
pub const ALPHA_MIN: f32 = 1.0 / 255.0;
/// x/z and y/z are clamped to ±`FOV_CLAMP`·tan(half fov) inside the Jacobian (3DGS).
pub const FOV_CLAMP: f32 = 1.3;
/// Splats whose mean has camera depth ≤ this are culled (3DGS `in_frustum`).
pub const NEAR_CULL: f32 = 0.2;
/// Bias added to the SH sum to get the colour (RC §Lighting).
pub const SH_DC_BIAS: f32 = 0.5;
