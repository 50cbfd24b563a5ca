//! The numeric constants of the ellipse kernel (3DGS forward pass + RC). They are the CPU
//! reference's constants ([`crate::reference::project`]), so the two backends cannot drift, and
//! the shaders receive each one as a `#define` generated from these values (see
//! [`super::program::defines`]); nothing is hand-copied into GLSL.

use crate::reference::project as reference;

/// Low-pass dilation added to the diagonal of the 2D covariance, in px² (3DGS `computeCov2D`).
pub const DILATION: f32 = reference::DILATION_PX2 as f32;
/// Mahalanobis² cut-off (the RC's 3σ): a pixel contributes while dᵀΣ'⁻¹d ≤ 9.
pub const CUTOFF_M2: f32 = reference::CUTOFF_M2;
/// Cap on a splat's per-pixel alpha (3DGS `renderCUDA`).
pub const ALPHA_MAX: f32 = reference::ALPHA_MAX;
/// Contributions with alpha below this are skipped (3DGS `renderCUDA`).
pub const ALPHA_MIN: f32 = reference::ALPHA_MIN;
/// x/z and y/z are clamped to ±`FOV_CLAMP`·tan(half fov) inside the Jacobian (3DGS).
pub const FOV_CLAMP: f32 = reference::JACOBIAN_CLAMP as f32;
/// Splats whose mean has camera depth ≤ max(this, camera near) are culled (3DGS `in_frustum`).
pub const NEAR_CULL: f32 = reference::NEAR_CULL_3DGS as f32;
/// Bias added to the SH sum to get the colour (RC §Lighting).
pub const SH_DC_BIAS: f32 = 0.5;
