//! The view of one draw: what the splat maths needs (view and projection matrices, focal
//! lengths and tan(half fov) in pixels of the viewport, eye position, cull depth), derived in
//! one place from a host's matrices, and from a [`Camera`] through its matrices.

use glam::{Mat4, Vec2, Vec3};

use super::GlError;
use crate::camera::Camera;
use crate::cull::Frustum;

/// The per-draw view parameters (the splat program's view uniforms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ViewParams {
    pub(crate) view: Mat4,
    pub(crate) projection: Mat4,
    /// Focal lengths in viewport pixels.
    pub(crate) focal: Vec2,
    /// tan of half the field of view, x and y (for the 1.3·tan clamp of J).
    pub(crate) tan_half_fov: Vec2,
    /// Eye in world space.
    pub(crate) eye: Vec3,
    /// x, y, width, height in window pixels.
    pub(crate) viewport: [i32; 4],
    /// Splats at eye depths ≤ this are culled (`max(NEAR_CULL, near)`).
    pub(crate) cull_depth: f32,
}

/// Relative size of the entries a perspective matrix must not have (skew, x/y translation,
/// a w row other than −z).
const ZERO_TOL: f32 = 1e-6;

impl ViewParams {
    /// From a host's view matrix (world → GL eye space, looking down −z; any invertible affine
    /// matrix), perspective projection matrix and viewport.
    ///
    /// The projection must map eye space to clip space with `w = −k·z` (k > 0) and x, y
    /// depending only on eye x (resp. y) and z: every `glFrustum` / `gluPerspective` style
    /// matrix, off-centre, reversed-Z, infinite far, or for a `[0, 1]` depth range. Focal
    /// lengths are `P[0][0]/k · width/2` and `P[1][1]/k · height/2`; the near plane (for the
    /// cull depth) is where the projected depth reaches ±1 first.
    pub(crate) fn from_matrices(
        view: Mat4,
        projection: Mat4,
        viewport: [i32; 4],
    ) -> Result<Self, GlError> {
        let p = projection;
        if !p.is_finite() || !view.is_finite() {
            return Err(GlError::Matrix("non-finite view or projection".into()));
        }
        let k = -p.z_axis.w;
        let (a, b) = (p.x_axis.x, p.y_axis.y);
        let scale = a.abs().max(b.abs());
        let off = [p.x_axis.w, p.y_axis.w, p.w_axis.w, p.x_axis.y, p.y_axis.x];
        let off = [
            off[0], off[1], off[2], off[3], off[4], p.w_axis.x, p.w_axis.y,
        ];
        if !(k > 0.0 && a != 0.0 && b != 0.0) || off.iter().any(|v| v.abs() > ZERO_TOL * scale) {
            return Err(GlError::Matrix(format!(
                "the projection is not a perspective projection (w = -k·z, no skew): {p:?}"
            )));
        }
        let inverse_view = view.inverse();
        if !inverse_view.is_finite() {
            return Err(GlError::Matrix("the view matrix is not invertible".into()));
        }
        let (e, f) = (p.z_axis.z / k, p.w_axis.z / k);
        // Projected depth z/w = −e + f/d at eye depth d: ±1 at d = f/(e ± 1).
        let near = [f / (e - 1.0), f / (e + 1.0)]
            .into_iter()
            .filter(|d| d.is_finite() && *d > 0.0)
            .fold(f32::INFINITY, f32::min);
        let near = if near.is_finite() { near } else { 0.0 };
        let (vw, vh) = (viewport[2].max(1) as f32, viewport[3].max(1) as f32);
        let (a, b) = (a / k, b / k);
        Ok(ViewParams {
            view,
            projection,
            focal: Vec2::new(0.5 * a * vw, 0.5 * b * vh),
            tan_half_fov: Vec2::new(1.0 / a.abs(), 1.0 / b.abs()),
            eye: inverse_view.w_axis.truncate(),
            viewport,
            cull_depth: (crate::profile::NEAR_CULL as f32).max(near),
        })
    }

    /// The cull frustum of this view ([`crate::cull`]): camera space with +z forward (the GL
    /// eye space with z negated), pixels from the viewport's lower-left corner, the principal
    /// point where the projection puts the optical axis.
    pub(crate) fn frustum(&self) -> Frustum {
        let p = self.projection;
        let k = -p.z_axis.w;
        let (vw, vh) = (
            self.viewport[2].max(1) as f32,
            self.viewport[3].max(1) as f32,
        );
        let principal = Vec2::new(
            0.5 * vw * (1.0 - p.z_axis.x / k),
            0.5 * vh * (1.0 - p.z_axis.y / k),
        );
        let flip_z = Mat4::from_diagonal(glam::Vec4::new(1.0, 1.0, -1.0, 1.0));
        Frustum::new(
            flip_z * self.view,
            self.focal,
            principal,
            Vec2::new(vw, vh),
            self.tan_half_fov,
            self.cull_depth,
        )
    }

    /// From a camera drawn into `viewport`: its GL matrices after fitting it to the viewport
    /// ([`fit_camera`]).
    pub(crate) fn from_camera(camera: &Camera, viewport: [i32; 4]) -> Self {
        let c = fit_camera(camera, viewport);
        Self::from_matrices(c.gl_view(), c.gl_projection(), viewport)
            .expect("a camera's GL matrices are a perspective projection")
    }
}

/// The cull frustum ([`crate::cull`]) of `camera` drawn into `viewport` with
/// [`SplatRenderer::draw`](super::SplatRenderer::draw): what
/// [`Sorter::sort_visible`](crate::sort::Sorter::sort_visible) needs to sort only the splats
/// that draw can show. Derived from the same view parameters as the draw itself.
pub fn frustum_for_camera(camera: &Camera, viewport: [i32; 4]) -> Frustum {
    ViewParams::from_camera(camera, viewport).frustum()
}

/// The cull frustum of a host's camera drawn with
/// [`SplatRenderer::draw_with_matrices`](super::SplatRenderer::draw_with_matrices)
/// (the same matrices and viewport); refused like that draw refuses them.
pub fn frustum_for_matrices(
    view: Mat4,
    projection: Mat4,
    viewport: [i32; 4],
) -> Result<Frustum, GlError> {
    Ok(ViewParams::from_matrices(view, projection, viewport)?.frustum())
}

/// The camera as drawn into a viewport of another size: the same size → unchanged; the same
/// aspect ratio (e.g. a camera in logical pixels on a HiDPI surface) → scaled
/// ([`Camera::resized`]); another aspect → scaled to the viewport's height, keeping the
/// vertical field of view and square pixels, the image centred horizontally (its horizontal
/// field of view follows the viewport: nothing is squashed).
pub(crate) fn fit_camera(camera: &Camera, viewport: [i32; 4]) -> Camera {
    let (vw, vh) = (viewport[2].max(0) as u32, viewport[3].max(0) as u32);
    let (w, h) = (camera.width, camera.height);
    if (w, h) == (vw, vh) || vw == 0 || vh == 0 || w == 0 || h == 0 {
        return *camera;
    }
    if u64::from(w) * u64::from(vh) == u64::from(h) * u64::from(vw) {
        return camera.resized(vw, vh);
    }
    let s = vh as f32 / h as f32;
    Camera {
        width: vw,
        height: vh,
        fx: camera.fx * s,
        fy: camera.fy * s,
        cx: camera.cx * s + 0.5 * (vw as f32 - w as f32 * s),
        cy: camera.cy * s,
        ..*camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        let mut c = Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y, 0.9, 64, 48);
        c.near = 0.5;
        c.far = 40.0;
        c
    }

    #[test]
    fn matrices_give_the_cameras_intrinsics() {
        let c = cam();
        let v = ViewParams::from_camera(&c, [0, 0, 64, 48]);
        assert!((v.focal - Vec2::new(c.fx, c.fy)).abs().max_element() < 1e-3);
        assert!((v.tan_half_fov - c.tan_half_fov()).abs().max_element() < 1e-6);
        assert!((v.eye - c.eye()).length() < 1e-5);
        assert!((v.cull_depth - 0.5).abs() < 1e-4, "{}", v.cull_depth);
    }

    #[test]
    fn reversed_z_infinite_projection_is_accepted() {
        let c = cam();
        // z_ndc = 2n/d − 1: +1 at the near plane, −1 at infinity.
        let n = 0.7;
        let mut p = c.gl_projection();
        p.z_axis.z = 1.0;
        p.w_axis.z = 2.0 * n;
        let v = ViewParams::from_matrices(c.gl_view(), p, [0, 0, 64, 48]).unwrap();
        assert!((v.cull_depth - n).abs() < 1e-6);
        assert!((v.focal - Vec2::new(c.fx, c.fy)).abs().max_element() < 1e-3);
    }

    #[test]
    fn orthographic_or_skewed_projections_are_refused() {
        let mut ortho = Mat4::from_diagonal(glam::Vec4::new(1.0, 1.0, -0.2, 1.0));
        ortho.w_axis.z = -1.0;
        let e = ViewParams::from_matrices(Mat4::IDENTITY, ortho, [0, 0, 8, 8]).unwrap_err();
        assert!(e.to_string().contains("not a perspective"), "{e}");
        let mut skew = cam().gl_projection();
        skew.y_axis.x = 0.3;
        assert!(ViewParams::from_matrices(Mat4::IDENTITY, skew, [0, 0, 8, 8]).is_err());
    }

    #[test]
    fn the_gl_frustum_is_the_cameras() {
        // Off-centre principal point, another viewport aspect: the GL-derived frustum culls
        // exactly like the camera's own (fitted to the viewport), up to rounding.
        let mut c = cam();
        c.cx = 20.0;
        c.cy = 30.0;
        for viewport in [[0, 0, 64, 48], [5, 7, 128, 48]] {
            let gl = frustum_for_camera(&c, viewport);
            let fitted = fit_camera(&c, viewport);
            let want = Frustum::from_camera(&fitted, 0.5);
            let mut differ = 0;
            for i in 0..20_000 {
                let t = i as f32 * 0.377;
                let p = [9.0 * t.sin(), 7.0 * (1.7 * t).cos(), 6.0 * (0.3 * t).sin()];
                let r = (i % 5) as f32 * 0.05;
                differ += usize::from(gl.may_see(p, r) != want.may_see(p, r));
            }
            assert!(differ <= 2, "{viewport:?}: {differ} of 20000 differ");
        }
    }

    #[test]
    fn another_aspect_keeps_vertical_fov_and_square_pixels() {
        let c = cam(); // 64 × 48
        let f = fit_camera(&c, [0, 0, 128, 48]);
        assert_eq!((f.fx, f.fy), (c.fx, c.fy));
        assert_eq!((f.cx, f.cy), (64.0, c.cy));
        let hidpi = fit_camera(&c, [0, 0, 128, 96]);
        assert_eq!(hidpi, c.resized(128, 96));
    }
}
