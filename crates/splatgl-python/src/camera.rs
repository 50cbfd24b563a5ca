//! `splatgl.Camera`: a pinhole camera in the OpenCV convention the 3DGS trainers use (x
//! right, y down, z forward; `world_to_camera` a rigid 4 × 4 matrix).

use crate::CameraError;
use glam::{Mat4, Vec3, Vec4};
use numpy::{AllowTypeChange, PyArray2, PyArrayLike1, PyArrayLike2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use splatgl::camera::Camera;

/// A pinhole camera: intrinsics in pixels (fx, fy, cx, cy), the image size, and the rigid
/// world → camera transform in OpenCV axes (x right, y down, z forward), as 3DGS's
/// `cameras.json` and COLMAP give it.
#[pyclass(module = "splatgl", name = "Camera", frozen)]
#[derive(Clone)]
pub struct PyCamera {
    pub inner: Camera,
}

/// A 3-vector from an array-like of 3 numbers.
fn vec3(name: &str, v: &PyArrayLike1<'_, f64, AllowTypeChange>) -> PyResult<Vec3> {
    let a = v.as_array();
    if a.len() != 3 || a.iter().any(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}: expected 3 finite numbers, got {a}"
        )));
    }
    Ok(Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32))
}

/// Checks an image size (the CLI's limit, [`splatgl::camera::MAX_IMAGE_SIDE`] per side).
fn size(width: u32, height: u32) -> PyResult<()> {
    splatgl::camera::check_image_size(width, height)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

#[pymethods]
impl PyCamera {
    /// `Camera(fx, fy, cx, cy, width, height, world_to_camera, near=0.01, far=1000.0)`:
    /// `world_to_camera` a rigid 4 × 4 matrix (rows), OpenCV axes.
    #[new]
    #[pyo3(signature = (fx, fy, cx, cy, width, height, world_to_camera, near=0.01, far=1000.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        fx: f32,
        fy: f32,
        cx: f32,
        cy: f32,
        width: u32,
        height: u32,
        world_to_camera: PyArrayLike2<'_, f64, AllowTypeChange>,
        near: f32,
        far: f32,
    ) -> PyResult<Self> {
        size(width, height)?;
        let good = |v: f32| v.is_finite() && v > 0.0;
        if !(good(fx) && good(fy) && cx.is_finite() && cy.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "intrinsics fx {fx}, fy {fy}, cx {cx}, cy {cy}: focal lengths > 0, all finite"
            )));
        }
        if !(good(near) && far.is_finite() && far > near) {
            return Err(PyValueError::new_err(format!(
                "near {near}, far {far}: 0 < near < far"
            )));
        }
        let m = world_to_camera.as_array();
        if m.shape() != [4, 4] || m.iter().any(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "world_to_camera: expected a finite 4 × 4 matrix, shape {:?}",
                m.shape()
            )));
        }
        let col = |c: usize| {
            Vec4::new(
                m[[0, c]] as f32,
                m[[1, c]] as f32,
                m[[2, c]] as f32,
                m[[3, c]] as f32,
            )
        };
        let w2c = Mat4::from_cols(col(0), col(1), col(2), col(3));
        let r = glam::Mat3::from_mat4(w2c);
        let orthonormal = (r * r.transpose()).abs_diff_eq(glam::Mat3::IDENTITY, 1e-3)
            && (r.determinant() - 1.0).abs() < 1e-3;
        let last = w2c.row(3);
        if !orthonormal || !last.abs_diff_eq(Vec4::W, 1e-6) {
            return Err(CameraError::new_err(
                "world_to_camera: not rigid (a rotation with determinant 1, then a translation; last row 0 0 0 1)",
            ));
        }
        Ok(PyCamera {
            inner: Camera {
                width,
                height,
                fx,
                fy,
                cx,
                cy,
                world_to_camera: w2c,
                near,
                far,
            },
        })
    }

    /// A camera at `eye` looking at `target`, `up` roughly up in the image, vertical field
    /// of view in degrees, principal point at the centre.
    #[staticmethod]
    #[pyo3(signature = (eye, target, up=None, fov_y_deg=50.0, width=1280, height=720))]
    fn look_at(
        eye: PyArrayLike1<'_, f64, AllowTypeChange>,
        target: PyArrayLike1<'_, f64, AllowTypeChange>,
        up: Option<PyArrayLike1<'_, f64, AllowTypeChange>>,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> PyResult<Self> {
        size(width, height)?;
        let (e, t) = (vec3("eye", &eye)?, vec3("target", &target)?);
        let u = match &up {
            Some(u) => vec3("up", u)?,
            None => Vec3::Y,
        };
        let fwd = t - e;
        if fwd.length() < 1e-9 || fwd.cross(u).length() < 1e-9 * fwd.length() * u.length() {
            return Err(CameraError::new_err(
                "look_at: eye and target coincide, or up is along the view direction",
            ));
        }
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
            return Err(PyValueError::new_err(format!(
                "fov_y_deg {fov_y_deg}: expected 0 < fov < 180"
            )));
        }
        Ok(PyCamera {
            inner: Camera::look_at(e, t, u, fov_y_deg.to_radians(), width, height),
        })
    }

    /// Camera `index` of a 3DGS `cameras.json`, at its own image size or resized to
    /// `width` × `height`.
    #[staticmethod]
    #[pyo3(signature = (path, index=0, width=None, height=None))]
    fn from_cameras_json(
        py: Python<'_>,
        path: std::path::PathBuf,
        index: usize,
        width: Option<u32>,
        height: Option<u32>,
    ) -> PyResult<Self> {
        let entries = py
            .detach(|| splatgl::camera::load_cameras_json(&path))
            .map_err(|e| CameraError::new_err(crate::message(e)))?;
        let n = entries.len();
        let e = entries.get(index).ok_or_else(|| {
            CameraError::new_err(format!(
                "{}: camera {index} asked for, the file has {n}",
                path.display()
            ))
        })?;
        let mut cam = Camera::from_3dgs(e).map_err(|e| CameraError::new_err(crate::message(e)))?;
        // The file's own size is bounded like one given here (a camera of 65536 × 65536
        // would make `render` allocate 64 GiB).
        let (w, h) = (width.unwrap_or(cam.width), height.unwrap_or(cam.height));
        size(w, h)?;
        if width.is_some() || height.is_some() {
            cam = cam.resized(w, h);
        }
        Ok(PyCamera { inner: cam })
    }

    /// Image width (pixels).
    #[getter]
    fn width(&self) -> u32 {
        self.inner.width
    }
    /// Image height (pixels).
    #[getter]
    fn height(&self) -> u32 {
        self.inner.height
    }
    /// Focal length x (pixels).
    #[getter]
    fn fx(&self) -> f32 {
        self.inner.fx
    }
    /// Focal length y (pixels).
    #[getter]
    fn fy(&self) -> f32 {
        self.inner.fy
    }
    /// Principal point x (pixels).
    #[getter]
    fn cx(&self) -> f32 {
        self.inner.cx
    }
    /// Principal point y (pixels).
    #[getter]
    fn cy(&self) -> f32 {
        self.inner.cy
    }
    /// The camera's position in the world.
    #[getter]
    fn eye(&self) -> [f32; 3] {
        self.inner.eye().to_array()
    }
    /// World → camera (4 × 4, rows, OpenCV axes), float64.
    #[getter]
    fn world_to_camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let m = self.inner.world_to_camera;
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|r| m.row(r).to_array().iter().map(|&v| f64::from(v)).collect())
            .collect();
        Ok(PyArray2::from_vec2(py, &rows)?)
    }
    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "<splatgl.Camera {}×{} fx {} fy {} at {:?}>",
            c.width,
            c.height,
            c.fx,
            c.fy,
            c.eye().to_array()
        )
    }
}
