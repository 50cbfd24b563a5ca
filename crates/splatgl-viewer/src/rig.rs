//! [`Rig`]: the viewer's camera — a pose (eye + orientation), a pivot at a distance in front,
//! the world's up axis and intrinsics relative to the image height — and the moves the
//! controls make with it (orbit, pan, zoom to cursor, roll, fly, look).

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};

use splatgl::camera::Camera;

/// Elevation limit of orbit and look: the view direction stays at least this far (radians)
/// from the up axis, so the orbit never flips over the pole.
const POLE_MARGIN: f32 = 0.02;

/// The viewer's camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rig {
    /// Camera centre.
    pub eye: Vec3,
    /// Camera → world rotation (OpenCV axes: x right, y down, z forward).
    pub rot: Quat,
    /// Distance from the eye to the pivot (orbit centre) along the view axis.
    pub pivot_distance: f32,
    /// World up (the orbit axis).
    pub up: Vec3,
    /// `fy / height`.
    fy_rel: f32,
    /// `fx / fy`.
    aspect: f32,
    /// `(cx − W/2) / H`, `(cy − H/2) / H`.
    offset: Vec2,
    near: f32,
    far: f32,
    /// The camera this rig was made from, while no move has changed it: returned as is at its
    /// own size, so the first frame is exactly the camera `render` would use.
    exact: Option<Camera>,
}

impl Rig {
    /// A rig at `cam`'s pose and intrinsics, its pivot `pivot_distance` in front, orbiting
    /// around `up`.
    pub fn from_camera(cam: &Camera, pivot_distance: f32, up: Vec3) -> Self {
        let inv = cam.world_to_camera.inverse();
        let r = Mat3::from_mat4(inv);
        let h = cam.height.max(1) as f32;
        Rig {
            eye: inv.w_axis.truncate(),
            rot: Quat::from_mat3(&r).normalize(),
            pivot_distance: pivot_distance.max(1e-4),
            up: up.normalize(),
            fy_rel: cam.fy / h,
            aspect: cam.fx / cam.fy,
            offset: Vec2::new(
                (cam.cx - 0.5 * cam.width as f32) / h,
                (cam.cy - 0.5 * h) / h,
            ),
            near: cam.near,
            far: cam.far,
            exact: Some(*cam),
        }
    }

    /// The camera for a `width × height` image: the same vertical field of view, pixel aspect
    /// and relative principal point at any size (the exact source camera at its own size while
    /// unmoved).
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        if let Some(c) = self.exact
            && (c.width, c.height) == (width, height)
        {
            return c;
        }
        let h = height.max(1) as f32;
        let fy = self.fy_rel * h;
        let r = Mat3::from_quat(self.rot).transpose();
        let t = -(r * self.eye);
        Camera {
            width,
            height,
            fx: fy * self.aspect,
            fy,
            cx: 0.5 * width as f32 + self.offset.x * h,
            cy: 0.5 * h + self.offset.y * h,
            world_to_camera: Mat4::from_cols(
                r.x_axis.extend(0.0),
                r.y_axis.extend(0.0),
                r.z_axis.extend(0.0),
                t.extend(1.0),
            ),
            near: self.near,
            far: self.far.max(4.0 * self.pivot_distance),
        }
    }

    /// Vertical field of view in radians.
    pub fn fov_y(&self) -> f32 {
        2.0 * (0.5 / self.fy_rel).atan()
    }

    /// The view direction.
    pub fn forward(&self) -> Vec3 {
        self.rot * Vec3::Z
    }

    /// The image's right axis in world space.
    pub fn right(&self) -> Vec3 {
        self.rot * Vec3::X
    }

    /// The image's down axis in world space.
    pub fn down(&self) -> Vec3 {
        self.rot * Vec3::Y
    }

    /// The orbit centre.
    pub fn pivot(&self) -> Vec3 {
        self.eye + self.forward() * self.pivot_distance
    }

    /// Rotates the pose by `q` around `centre`.
    fn turn(&mut self, q: Quat, centre: Vec3) {
        self.exact = None;
        self.eye = centre + q * (self.eye - centre);
        self.rot = (q * self.rot).normalize();
    }

    /// The rotation that tilts the view `angle` radians towards the up axis (around the
    /// horizontal axis `forward × up`), limited so the view direction keeps [`POLE_MARGIN`]
    /// from the up axis.
    fn pitch(&self, angle: f32) -> Quat {
        let f = self.forward();
        let axis = f.cross(self.up);
        let axis = if axis.length_squared() > 1e-12 {
            axis.normalize()
        } else {
            -self.right()
        };
        let elev = f.dot(self.up).clamp(-1.0, 1.0).acos(); // 0: looking straight up
        let limited = (elev - angle).clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
        // A positive rotation around f × up turns f towards up.
        Quat::from_axis_angle(axis, elev - limited)
    }

    /// Orbits around the pivot: `yaw` radians around the up axis, `pitch` radians of elevation
    /// (positive: the camera rises and looks further down).
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        let pivot = self.pivot();
        self.turn(Quat::from_axis_angle(self.up, yaw), pivot);
        // The camera rising = the view tilting down.
        let q = self.pitch(-pitch);
        self.turn(q, pivot);
    }

    /// Turns the view around the eye (fly mode's mouse look): `yaw` around up, `pitch` up.
    pub fn look(&mut self, yaw: f32, pitch: f32) {
        let eye = self.eye;
        self.turn(Quat::from_axis_angle(self.up, yaw), eye);
        let q = self.pitch(pitch);
        self.turn(q, eye);
    }

    /// Rolls around the view axis by `angle` radians.
    pub fn roll(&mut self, angle: f32) {
        let eye = self.eye;
        self.turn(Quat::from_axis_angle(self.forward(), angle), eye);
    }

    /// Moves eye and pivot so the content follows a cursor moved by `delta` pixels, for an
    /// image `height` pixels high.
    pub fn pan(&mut self, delta: Vec2, height: u32) {
        self.exact = None;
        let per_px = self.pivot_distance / (self.fy_rel * height.max(1) as f32);
        self.eye -= (self.right() * delta.x + self.down() * delta.y) * per_px;
    }

    /// Zooms by `factor` (< 1: closer) towards the point at pivot depth under `cursor`
    /// (pixels of a `width × height` image): a scaling about that point, so it stays under
    /// the cursor, and the pivot distance scales by `factor`.
    pub fn zoom_at(&mut self, factor: f32, cursor: Vec2, width: u32, height: u32) {
        let cam = self.camera(width, height);
        let ray = Vec3::new(
            (cursor.x - cam.cx) / cam.fx,
            (cursor.y - cam.cy) / cam.fy,
            1.0,
        );
        let p = self.eye + self.rot * ray * self.pivot_distance;
        self.exact = None;
        self.eye = p + (self.eye - p) * factor;
        self.pivot_distance *= factor;
    }

    /// Moves the eye (and the pivot with it) by `delta` in world space.
    pub fn translate(&mut self, delta: Vec3) {
        if delta != Vec3::ZERO {
            self.exact = None;
            self.eye += delta;
        }
    }

    /// Azimuth of the eye around the pivot (radians, about the up axis) and the eye–pivot
    /// distance: what an orbit and a zoom change.
    #[cfg(test)]
    pub fn azimuth_distance(&self) -> (f32, f32) {
        let v = self.eye - self.pivot();
        let (a, b) = self.up.any_orthonormal_pair();
        (v.dot(b).atan2(v.dot(a)), v.length())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig() -> Rig {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 0.9, 200, 100);
        Rig::from_camera(&cam, Vec3::new(0.0, 1.0, 5.0).length(), Vec3::Y)
    }

    #[test]
    fn unmoved_rig_returns_its_camera_and_refits_keep_the_fov() {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 0.9, 200, 100);
        let r = rig();
        assert_eq!(r.camera(200, 100), cam);
        let big = r.camera(400, 300);
        assert!((big.fy / 300.0 - cam.fy / 100.0).abs() < 1e-5);
        assert!((big.eye() - cam.eye()).length() < 1e-5);
        assert!((r.pivot()).length() < 1e-5, "pivot at the target");
    }

    #[test]
    fn orbit_keeps_pivot_and_distance_and_changes_azimuth() {
        let mut r = rig();
        let (a0, d0) = r.azimuth_distance();
        r.orbit(0.5, 0.2);
        let (a1, d1) = r.azimuth_distance();
        assert!(r.pivot().length() < 1e-4 && (d1 - d0).abs() < 1e-4);
        assert!((a1 - a0).abs() > 0.4, "{a0} {a1}");
        // Rising: the eye goes up, the view looks further down.
        assert!(r.eye.y > 1.0 + 0.1 && r.forward().y < 0.0);
        // The image stays upright: world up projects above the centre.
        let cam = r.camera(200, 100);
        let (c, _) = cam.project(Vec3::ZERO).unwrap();
        let (u, _) = cam.project(Vec3::Y * 0.1).unwrap();
        assert!(u.y < c.y && (u.x - c.x).abs() < 1e-2);
        // Never over the pole.
        r.orbit(0.0, 10.0);
        assert!(r.forward().dot(-Vec3::Y) < (POLE_MARGIN * 0.5).cos());
    }

    #[test]
    fn zoom_to_cursor_keeps_the_point_under_the_cursor() {
        let mut r = rig();
        let cursor = Vec2::new(150.0, 30.0);
        let cam = r.camera(200, 100);
        let ray = Vec3::new(
            (cursor.x - cam.cx) / cam.fx,
            (cursor.y - cam.cy) / cam.fy,
            1.0,
        );
        let p = r.eye + r.rot * ray * r.pivot_distance;
        let d0 = r.pivot_distance;
        r.zoom_at(0.5, cursor, 200, 100);
        let (px, _) = r.camera(200, 100).project(p).unwrap();
        assert!((px - cursor).length() < 1e-2, "{px}");
        assert!((r.pivot_distance - 0.5 * d0).abs() < 1e-5);
    }

    #[test]
    fn pan_moves_content_with_the_cursor() {
        let mut r = rig();
        let p = r.pivot();
        let (before, _) = r.camera(200, 100).project(p).unwrap();
        r.pan(Vec2::new(12.0, -7.0), 100);
        let (after, _) = r.camera(200, 100).project(p).unwrap();
        assert!((after - before - Vec2::new(12.0, -7.0)).length() < 1e-2);
    }
}
