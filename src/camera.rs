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
//!
//! # Constructors
//! - [`Camera::look_at`]: eye, target, up, vertical field of view.
//! - [`Camera::from_3dgs`]: one entry of a 3DGS `cameras.json` ([`parse_cameras_json`]).
//! - [`Camera::from_gltf`]: a glTF perspective camera on a node ([`GltfPerspective`]).
//! - [`Camera::frame_cloud`]: frames a cloud's content (its splats' 3σ boxes) with an
//!   [`UpAxis`] (the CLI's and the viewer's default view); [`Camera::frame_points`] frames
//!   bare points.
//! - [`ViewOptions::camera`]: the camera options of `splatgl render` and `splatgl view`
//!   (cameras.json, glTF camera node, look-at, framing) for a scene.
//!
//! The way back: [`Camera::as_look_at`] (a paste-able `--look-at` line) and
//! [`Camera::to_3dgs_json`] (a `cameras.json` entry).
//!
//! All of them produce the same type, so both backends and every test see one camera model.

use glam::{DMat3, DVec3, Mat3, Mat4, Vec2, Vec3, Vec4};

mod choose;
mod frame;
mod json;
mod up;
pub use choose::{LookAtSpec, SceneView, ViewOptions};
pub use frame::{Extent, FIT_SIGMAS, FRAME_MARGIN, LookAt};
pub use json::{
    CamerasJsonEntry, load_cameras_json, load_cameras_json_limited, parse_cameras_json,
};
pub use up::{UpAxis, Z_UP_BELOW, Z_UP_TALLER};

/// The largest image side any entry point renders (the CLI's `--width`/`--height`, the Python
/// package, [`crate::engine::Engine::render`]): 16384 pixels, an f32 RGBA image of at most
/// 4 GiB.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// An image size outside `1..=MAX_IMAGE_SIDE` per side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("image size {width}x{height} is outside 1..={MAX_IMAGE_SIDE} pixels per side")]
pub struct ImageSizeError {
    /// The width asked for.
    pub width: u32,
    /// The height asked for.
    pub height: u32,
}

impl From<ImageSizeError> for String {
    fn from(e: ImageSizeError) -> String {
        e.to_string()
    }
}

/// `Ok` when a `width` × `height` image is within `1..=MAX_IMAGE_SIDE` per side; else the
/// error naming the size and the limit.
pub fn check_image_size(width: u32, height: u32) -> Result<(), ImageSizeError> {
    let side = 1..=MAX_IMAGE_SIDE;
    if side.contains(&width) && side.contains(&height) {
        return Ok(());
    }
    Err(ImageSizeError { width, height })
}

/// Why a camera could not be built.
#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Not JSON.
    #[error("cameras.json: {0}")]
    Json(#[from] serde_json::Error),
    /// JSON of the wrong shape or with out-of-range values.
    #[error("cameras.json: {location}: {message}")]
    Invalid {
        /// Where, e.g. `[3].rotation[1][2]`.
        location: String,
        /// What was expected.
        message: String,
    },
    /// A `cameras.json` file that is not JSON or has the wrong shape ([`CameraError::Json`],
    /// [`CameraError::Invalid`]), with the file's name.
    #[error("{}: {}", path.display(), source.detail())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong in it.
        source: Box<CameraError>,
    },
    /// Parameters that give no usable camera (zero size, non-finite or non-positive focal
    /// length, degenerate pose).
    #[error("invalid camera: {0}")]
    Degenerate(String),
    /// The camera options ask for a view the scene or the options cannot give (a cameras.json
    /// index or glTF camera node that does not exist, a field of view out of range, nothing to
    /// frame).
    #[error("{0}")]
    Unavailable(String),
}

impl CameraError {
    /// The message without the `cameras.json: ` prefix: a JSON error, or `LOCATION: MESSAGE`
    /// (`$` for the top level, else a path such as `$[3].rotation[1]`).
    fn detail(&self) -> String {
        match self {
            CameraError::Json(e) => format!("not JSON: {e}"),
            CameraError::Invalid { location, message } if location.is_empty() => {
                format!("$: {message}")
            }
            CameraError::Invalid { location, message } => format!("${location}: {message}"),
            other => other.to_string(),
        }
    }
}

/// A glTF 2.0 perspective camera as instanced by a node, in the glTF convention: the camera
/// looks down its local −Z with +Y up and +X right.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GltfPerspective {
    /// Vertical field of view, radians.
    pub yfov: f32,
    /// Aspect ratio (width / height) of the field of view; `None`: the viewport's.
    pub aspect_ratio: Option<f32>,
    /// Near clipping distance (> 0).
    pub znear: f32,
    /// Far clipping distance; `None`: infinite projection.
    pub zfar: Option<f32>,
    /// The node's global transform (local → world).
    pub node_to_world: Mat4,
}

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
    /// The view of the bundled default scene (`splatgl render` without a file): from
    /// (3.3, 2.4, 4.2) towards (0, 0.65, 0), +Y up, 40° vertical fov.
    pub fn default_scene_view(width: u32, height: u32) -> Self {
        Camera::look_at(
            Vec3::new(3.3, 2.4, 4.2),
            Vec3::new(0.0, 0.65, 0.0),
            Vec3::Y,
            40f32.to_radians(),
            width,
            height,
        )
    }

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

    /// A camera from a rotation camera → world (OpenCV axes) and the camera centre. The
    /// rotation is orthonormalised first (Gram–Schmidt on its columns, in f64).
    fn from_pose(r_c2w: DMat3, centre: DVec3) -> Result<Mat4, CameraError> {
        let x = r_c2w.x_axis.normalize_or_zero();
        let y = (r_c2w.y_axis - x * x.dot(r_c2w.y_axis)).normalize_or_zero();
        let z = x.cross(y);
        if x == DVec3::ZERO || y == DVec3::ZERO || !centre.is_finite() {
            return Err(CameraError::Degenerate(
                "pose rotation is singular or non-finite".into(),
            ));
        }
        if z.dot(r_c2w.z_axis) <= 0.0 {
            return Err(CameraError::Degenerate(
                "pose rotation is a mirror (det < 0)".into(),
            ));
        }
        // world → camera = [Rᵀ | −Rᵀ c].
        let rt = DMat3::from_cols(x, y, z).transpose();
        let t = -(rt * centre);
        Ok(Mat4::from_cols(
            rt.x_axis.as_vec3().extend(0.0),
            rt.y_axis.as_vec3().extend(0.0),
            rt.z_axis.as_vec3().extend(0.0),
            t.as_vec3().extend(1.0),
        ))
    }

    /// Checks that the intrinsics give a usable camera.
    fn validated(self) -> Result<Self, CameraError> {
        let ok = self.width > 0
            && self.height > 0
            && [self.fx, self.fy].iter().all(|f| f.is_finite() && *f > 0.0)
            && self.cx.is_finite()
            && self.cy.is_finite()
            && self.near.is_finite()
            && self.near > 0.0
            && self.far > self.near
            && self.world_to_camera.is_finite();
        if ok {
            Ok(self)
        } else {
            Err(CameraError::Degenerate(format!(
                "{}x{} fx {} fy {} cx {} cy {} near {} far {}",
                self.width, self.height, self.fx, self.fy, self.cx, self.cy, self.near, self.far
            )))
        }
    }

    /// A camera from one `cameras.json` entry of the INRIA 3DGS trainer: `rotation` is
    /// camera → world (row i = `rotation[i]`), `position` the camera centre, OpenCV axes;
    /// principal point `(cx, cy)` when present, else the image centre. `near`/`far` are the
    /// trainer's 0.01 / 100.
    pub fn from_3dgs(e: &CamerasJsonEntry) -> Result<Self, CameraError> {
        let r = DMat3::from_cols_array_2d(&e.rotation).transpose(); // rows as written
        let world_to_camera = Self::from_pose(r, DVec3::from_array(e.position))?;
        Camera {
            width: e.width,
            height: e.height,
            fx: e.fx as f32,
            fy: e.fy as f32,
            cx: e.cx.map_or(0.5 * e.width as f32, |v| v as f32),
            cy: e.cy.map_or(0.5 * e.height as f32, |v| v as f32),
            world_to_camera,
            near: 0.01,
            far: 100.0,
        }
        .validated()
    }

    /// A camera from a glTF perspective camera on a node, rendering `width × height` pixels.
    ///
    /// Follows the glTF projection matrix: `fy = (H/2) / tan(yfov/2)` and
    /// `fx = (W/2) / (aspectRatio · tan(yfov/2))`; without `aspectRatio` the viewport's is
    /// used, so `fx = fy`. (An `aspectRatio` different from W/H stretches the image, exactly as
    /// the glTF matrix does on such a viewport.) The pose is the node's global transform with
    /// scale removed (columns normalised, then Gram–Schmidt); GL axes (+Y up, −Z forward) are
    /// converted to OpenCV axes by negating Y and Z. `far` is infinite without `zfar`.
    pub fn from_gltf(g: &GltfPerspective, width: u32, height: u32) -> Result<Self, CameraError> {
        let t = (0.5 * g.yfov as f64).tan();
        if !(t.is_finite() && t > 0.0) || g.yfov >= std::f32::consts::PI {
            return Err(CameraError::Degenerate(format!("yfov {}", g.yfov)));
        }
        let aspect = g
            .aspect_ratio
            .map_or(width as f64 / height.max(1) as f64, f64::from);
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(CameraError::Degenerate(format!("aspectRatio {aspect}")));
        }
        let m = g.node_to_world.as_dmat4();
        let r = DMat3::from_cols(
            m.x_axis.truncate(),
            -m.y_axis.truncate(),
            -m.z_axis.truncate(),
        );
        let world_to_camera = Self::from_pose(r, m.w_axis.truncate())?;
        let fy = 0.5 * height as f64 / t;
        let fx = 0.5 * width as f64 / (aspect * t);
        Camera {
            width,
            height,
            fx: fx as f32,
            fy: fy as f32,
            cx: 0.5 * width as f32,
            cy: 0.5 * height as f32,
            world_to_camera,
            near: g.znear,
            far: g.zfar.unwrap_or(f32::INFINITY),
        }
        .validated()
    }

    /// A camera that frames `points` in glTF's convention (+Y up), looking from +Z slightly
    /// from above: [`Self::frame_points_along`] with `forward = (0, −0.35, −1)`, `up = +Y`.
    #[deprecated(
        since = "0.1.0",
        note = "use `Camera::frame_extent_along(&Extent::of_points(points)?, …)` (or `frame_cloud`)"
    )]
    pub fn frame_points(points: &[[f32; 3]], fov_y: f32, width: u32, height: u32) -> Option<Self> {
        let fwd = Vec3::new(0.0, -0.35, -1.0);
        Self::frame_extent_along(
            &Extent::of_points(points)?,
            fwd,
            Vec3::Y,
            fov_y,
            width,
            height,
        )
    }

    /// A camera looking along `forward` with `up` roughly up that frames the box of `points`
    /// ([`Extent::of_points`]) by the one framing rule ([`Self::frame_extent_along`]).
    #[deprecated(
        since = "0.1.0",
        note = "use `Camera::frame_extent_along(&Extent::of_points(points)?, …)`"
    )]
    pub fn frame_points_along(
        points: &[[f32; 3]],
        forward: Vec3,
        up: Vec3,
        fov_y: f32,
        width: u32,
        height: u32,
    ) -> Option<Self> {
        Self::frame_extent_along(
            &Extent::of_points(points)?,
            forward,
            up,
            fov_y,
            width,
            height,
        )
    }

    /// The same view at another resolution: focal lengths and principal point scale with the
    /// size (`fx · W'/W`, `cx · W'/W`, likewise for y).
    pub fn resized(&self, width: u32, height: u32) -> Self {
        let (sx, sy) = (
            width as f32 / self.width as f32,
            height as f32 / self.height as f32,
        );
        Camera {
            width,
            height,
            fx: self.fx * sx,
            fy: self.fy * sy,
            cx: self.cx * sx,
            cy: self.cy * sy,
            ..*self
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
    /// NDC y = 1 − 2v/H, depth mapped from [near, far] to [−1, 1]. With `far` infinite (glTF
    /// cameras without `zfar`) it is the limit matrix: depth from [near, ∞) to [−1, 1).
    pub fn gl_projection(&self) -> Mat4 {
        let (w, h) = (self.width as f32, self.height as f32);
        let (n, f) = (self.near, self.far);
        let (zz, zw) = if f.is_infinite() {
            (-1.0, -2.0 * n)
        } else {
            (-(f + n) / (f - n), -2.0 * f * n / (f - n))
        };
        Mat4::from_cols(
            Vec4::new(2.0 * self.fx / w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 * self.fy / h, 0.0, 0.0),
            Vec4::new(1.0 - 2.0 * self.cx / w, 2.0 * self.cy / h - 1.0, zz, -1.0),
            Vec4::new(0.0, 0.0, zw, 0.0),
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
