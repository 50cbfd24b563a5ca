//! `splatgl.Renderer`: a renderer that stays open — one GL context (or the reference) and one
//! uploaded cloud kept across `render` calls, where `splatgl.render` makes both every call.

use crate::RenderError;
use crate::camera::PyCamera;
use crate::cloud::Cloud;
use numpy::PyArray3;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::engine::{Backend, Engine};
use splatgl::image::Image;
use splatgl::reference::RenderOptions;

/// An [`Engine`] that may be used inside `Python::detach` (the GIL released).
///
/// A GL engine is bound to the thread that made it. The `Renderer` that owns it is an
/// `unsendable` class (PyO3 refuses its use from any other thread), and `detach` runs its
/// closure on the calling thread, only releasing the GIL, so the engine never leaves the
/// thread it was made on.
struct ThreadBound(Engine);

// SAFETY: see the type's docs — the value is only ever touched on its creating thread (the
// owning pyclass is `unsendable`; `detach` does not move the closure to another thread).
unsafe impl Send for ThreadBound {}

impl ThreadBound {
    /// The engine (a method, so closures capture the `Send` wrapper, not its field).
    fn get(&mut self) -> &mut Engine {
        &mut self.0
    }
}

/// The backend a name asks for: "auto" (`None`: GL where headless EGL works, else the
/// reference), "gl" or "reference".
pub(crate) fn backend(name: &str) -> PyResult<Option<Backend>> {
    match name {
        "auto" => Ok(None),
        "gl" => Ok(Some(Backend::Gl)),
        "reference" => Ok(Some(Backend::Reference)),
        other => Err(PyValueError::new_err(format!(
            "backend {other:?}: expected \"auto\", \"gl\" or \"reference\""
        ))),
    }
}

/// The engine of [`backend`]'s answer (needs no GIL).
pub(crate) fn make_engine(wanted: Option<Backend>) -> Result<Engine, String> {
    match wanted {
        Some(b) => Ok(Engine::new(b)?),
        None => Ok(Engine::new(Backend::Gl).or_else(|_| Engine::new(Backend::Reference))?),
    }
}

/// The reference's options from `render`'s keyword arguments, checked.
pub(crate) fn render_options(
    sh_degree: u8,
    background: (f32, f32, f32),
    antialiased: bool,
) -> PyResult<RenderOptions> {
    let bg = [background.0, background.1, background.2];
    if bg.iter().any(|v| !v.is_finite()) || sh_degree > 3 {
        return Err(PyValueError::new_err(
            "background: finite RGB; sh_degree: 0–3",
        ));
    }
    Ok(RenderOptions {
        sh_degree,
        background: bg,
        antialiased,
        ..Default::default()
    })
}

/// `camera` checked against the image-size limit (at `size` when given).
pub(crate) fn sized(camera: &PyCamera, size: Option<(u32, u32)>) -> PyResult<Camera> {
    let cam = match size {
        Some((w, h)) if (w, h) != (camera.inner.width, camera.inner.height) => {
            camera.inner.resized(w, h)
        }
        _ => camera.inner,
    };
    splatgl::camera::check_image_size(cam.width, cam.height)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(cam)
}

/// One image of `cloud` (uploaded to `engine`) as an (H, W, 4) array.
fn draw(
    engine: &mut Engine,
    cloud: &SplatCloud,
    cam: &Camera,
    o: &RenderOptions,
) -> Result<Image, String> {
    Ok(engine.render(cloud, cam, o)?.0)
}

/// An image as an (H, W, 4) float32 array.
pub(crate) fn image_array(py: Python<'_>, img: Image) -> PyResult<Bound<'_, PyArray3<f32>>> {
    use numpy::{PyArray1, PyArrayMethods};
    let (w, h) = (img.width as usize, img.height as usize);
    PyArray1::from_vec(py, img.pixels.into_flattened()).reshape([h, w, 4])
}

/// A renderer kept open: `Renderer(backend="auto", width=None, height=None)`, then
/// `upload(cloud)` once and `render(camera)` (or `render_many(cameras)`) as often as needed;
/// `close()` or a `with` block frees the GL context. Images equal `splatgl.render`'s for the
/// same cloud, camera and options. `width` and `height`, when given, are the size every
/// camera is rendered at (resized like `Camera.from_cameras_json(..., width, height)`);
/// otherwise each camera's own. The GIL is released while it uploads and draws. A renderer
/// belongs to the thread that made it (GL contexts do): use one per thread.
#[pyclass(module = "splatgl", name = "Renderer", unsendable)]
pub struct Renderer {
    engine: Option<ThreadBound>,
    cloud: Option<SplatCloud>,
    size: Option<(u32, u32)>,
    name: &'static str,
}

impl Renderer {
    /// The engine and the uploaded cloud, or the error saying why there are none.
    fn ready(&mut self) -> PyResult<(&mut ThreadBound, &SplatCloud)> {
        let engine = self
            .engine
            .as_mut()
            .ok_or_else(|| RenderError::new_err("this Renderer is closed"))?;
        let cloud = self
            .cloud
            .as_ref()
            .ok_or_else(|| RenderError::new_err("nothing uploaded: call upload(cloud) first"))?;
        Ok((engine, cloud))
    }
}

#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (backend="auto", width=None, height=None))]
    fn new(backend: &str, width: Option<u32>, height: Option<u32>) -> PyResult<Self> {
        let size = match (width, height) {
            (None, None) => None,
            (Some(w), Some(h)) => {
                splatgl::camera::check_image_size(w, h)
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                Some((w, h))
            }
            _ => {
                return Err(PyValueError::new_err(
                    "give both width and height, or neither",
                ));
            }
        };
        let wanted = self::backend(backend)?;
        let engine = make_engine(wanted).map_err(|e| RenderError::new_err(crate::message(e)))?;
        let name = engine.name();
        Ok(Renderer {
            engine: Some(ThreadBound(engine)),
            cloud: None,
            size,
            name,
        })
    }

    /// Makes `cloud` the one drawn (checked and copied; on GL uploaded once), replacing any
    /// cloud uploaded before.
    fn upload(&mut self, py: Python<'_>, cloud: &Cloud) -> PyResult<()> {
        let c = cloud.to_splat_cloud(py)?;
        let engine = self
            .engine
            .as_mut()
            .ok_or_else(|| RenderError::new_err("this Renderer is closed"))?;
        py.detach(|| engine.get().upload(&c))
            .map_err(|e| RenderError::new_err(crate::message(e)))?;
        self.cloud = Some(c);
        Ok(())
    }

    /// The uploaded cloud from `camera`: an (H, W, 4) float32 array, as `splatgl.render`
    /// returns it.
    #[pyo3(signature = (camera, sh_degree=3, background=(0.0, 0.0, 0.0), antialiased=false))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        camera: &PyCamera,
        sh_degree: u8,
        background: (f32, f32, f32),
        antialiased: bool,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let o = render_options(sh_degree, background, antialiased)?;
        let cam = sized(camera, self.size)?;
        let (engine, cloud) = self.ready()?;
        let img = py
            .detach(|| draw(engine.get(), cloud, &cam, &o))
            .map_err(|e| RenderError::new_err(crate::message(e)))?;
        image_array(py, img)
    }

    /// [`render`] of each camera, in order: a list of arrays.
    #[pyo3(signature = (cameras, sh_degree=3, background=(0.0, 0.0, 0.0), antialiased=false))]
    fn render_many<'py>(
        &mut self,
        py: Python<'py>,
        cameras: Vec<PyRef<'py, PyCamera>>,
        sh_degree: u8,
        background: (f32, f32, f32),
        antialiased: bool,
    ) -> PyResult<Vec<Bound<'py, PyArray3<f32>>>> {
        let o = render_options(sh_degree, background, antialiased)?;
        let cams = cameras
            .iter()
            .map(|c| sized(c, self.size))
            .collect::<PyResult<Vec<Camera>>>()?;
        let (engine, cloud) = self.ready()?;
        let images = py
            .detach(|| {
                cams.iter()
                    .map(|cam| draw(engine.get(), cloud, cam, &o))
                    .collect::<Result<Vec<Image>, String>>()
            })
            .map_err(|e| RenderError::new_err(crate::message(e)))?;
        images.into_iter().map(|img| image_array(py, img)).collect()
    }

    /// Frees the GL context and the uploaded cloud; later calls raise `RenderError`. Closing
    /// twice is fine.
    fn close(&mut self) {
        self.cloud = None;
        self.engine = None;
    }

    /// "gl" or "reference": the backend it draws with.
    #[getter]
    fn backend(&self) -> &'static str {
        self.name
    }

    /// Whether `close` ran.
    #[getter]
    fn closed(&self) -> bool {
        self.engine.is_none()
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&mut self, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.close();
        false
    }

    fn __repr__(&self) -> String {
        let state = match (&self.engine, &self.cloud) {
            (None, _) => "closed".to_owned(),
            (Some(_), None) => "nothing uploaded".to_owned(),
            (Some(_), Some(c)) => format!("{} splats uploaded", c.len()),
        };
        format!("<splatgl.Renderer {} ({state})>", self.name)
    }
}
