//! The camera both backends use: pinhole intrinsics in pixels and a world → camera pose.
//!
//! # Conventions
//! - Camera axes are **OpenCV**: +x right, +y down, +z forward (the 3DGS trainer's axes).
//! - Pixel coordinates: the image's top-left *corner* is (0, 0); pixel (i, j) covers
//!   [i, i+1) × [j, j+1) and its centre is (i + 0.5, j + 0.5). Row 0 is the top row.
//! - A camera-space point (x, y, z), z > 0, projects to (fx·x/z + cx, fy·y/z + cy).
//! - [`Camera::gl_view`] / [`Camera::gl_projection`] give the same mapping in OpenGL's
//!   conventions (camera looks down −z, +y up, NDC y = +1 at the top image row). A renderer that
//!   reads an FBO back must flip rows (GL row 0 is the bottom).

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Focal length in pixels, x.
    pub fx: f32,
    /// Focal length in pixels, y.
    pub fy: f32,
    /// Principal point x in pixels (image centre: `width / 2`).
    pub cx: f32,
    /// Principal point y in pixels.
    pub cy: f32,
    /// World → camera (OpenCV axes), a rigid transform.
    pub world_to_camera: Mat4,
    /// Near plane distance (> 0) along +z.
    pub near: f32,
    /// Far plane distance along +z.
    pub far: f32,
}

impl Camera {
    /// A camera at `eye` looking at `target`, `up` roughly up in the image, vertical field of
    /// view `fov_y` in radians, principal point at the image centre, square pixels.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_y: f32, width: u32, height: u32) -> Self {
        let fwd = (target - eye).normalize();
        let right = fwd.cross(up).normalize();
        let down = fwd.cross(right);
        // Rows of the rotation are the camera axes in world coordinates.
        let r = Mat3::from_cols(right, down, fwd).transpose();
        let t = -(r * eye);
        let world_to_camera = Mat4::from_cols(
            r.x_axis.extend(0.0),
            r.y_axis.extend(0.0),
            r.z_axis.extend(0.0),
            t.extend(1.0),
        );
        let fy = 0.5 * height as f32 / (0.5 * fov_y).tan();
        Camera {
            width,
            height,
            fx: fy,
            fy,
            cx: 0.5 * width as f32,
            cy: 0.5 * height as f32,
            world_to_camera,
            near: 0.01,
            far: 1000.0,
        }
    }

    /// Camera centre in world space.
    pub fn eye(&self) -> Vec3 {
        self.world_to_camera.inverse().w_axis.truncate()
    }

    /// A world point in camera space (OpenCV axes).
    pub fn to_camera(&self, p: Vec3) -> Vec3 {
        self.world_to_camera.transform_point3(p)
    }

    /// Pixel coordinates and depth z of a world point (`None` when z ≤ 0).
    pub fn project(&self, p: Vec3) -> Option<(Vec2, f32)> {
        let c = self.to_camera(p);
        (c.z > 0.0).then(|| {
            (
                Vec2::new(self.fx * c.x / c.z + self.cx, self.fy * c.y / c.z + self.cy),
                c.z,
            )
        })
    }

    /// OpenGL view matrix: world → GL eye space (+x right, +y up, looking down −z).
    pub fn gl_view(&self) -> Mat4 {
        Mat4::from_diagonal(Vec4::new(1.0, -1.0, -1.0, 1.0)) * self.world_to_camera
    }

    /// OpenGL projection matrix that reproduces [`Camera::project`]: NDC x = 2u/W − 1,
    /// NDC y = 1 − 2v/H, depth mapped from [near, far] to [−1, 1].
    pub fn gl_projection(&self) -> Mat4 {
        let (w, h) = (self.width as f32, self.height as f32);
        let (n, f) = (self.near, self.far);
        Mat4::from_cols(
            Vec4::new(2.0 * self.fx / w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 * self.fy / h, 0.0, 0.0),
            Vec4::new(
                1.0 - 2.0 * self.cx / w,
                2.0 * self.cy / h - 1.0,
                -(f + n) / (f - n),
                -1.0,
            ),
            Vec4::new(0.0, 0.0, -2.0 * f * n / (f - n), 0.0),
        )
    }

    /// tan of half the horizontal and vertical field of view (for the 1.3·tan clamp of 3DGS).
    pub fn tan_half_fov(&self) -> Vec2 {
        Vec2::new(
            0.5 * self.width as f32 / self.fx,
            0.5 * self.height as f32 / self.fy,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gl_matrices_reproduce_pixel_projection() {
        let mut cam = Camera::look_at(
            Vec3::new(1.0, 2.0, -3.0),
            Vec3::new(0.2, 0.1, 0.4),
            Vec3::Y,
            0.9,
            640,
            480,
        );
        cam.cx = 300.0; // off-centre principal point
        cam.cy = 250.0;
        for p in [Vec3::new(0.2, 0.1, 0.4), Vec3::new(0.5, -0.3, 1.0)] {
            let (px, _) = cam.project(p).unwrap();
            let clip = cam.gl_projection() * cam.gl_view() * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let u = (ndc.x + 1.0) * 0.5 * 640.0;
            let v = (1.0 - ndc.y) * 0.5 * 480.0;
            assert!(
                (u - px.x).abs() < 1e-3 && (v - px.y).abs() < 1e-3,
                "{u},{v} vs {px}"
            );
        }
    }

    #[test]
    fn look_at_centres_target_and_keeps_up_up() {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 100, 80);
        let (c, z) = cam.project(Vec3::ZERO).unwrap();
        assert!((c - Vec2::new(50.0, 40.0)).length() < 1e-4 && (z - 5.0).abs() < 1e-5);
        let (up, _) = cam.project(Vec3::Y).unwrap();
        assert!(
            up.y < 40.0,
            "world +y must be above the centre (smaller row)"
        );
        assert!((cam.eye() - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-5);
    }
}
