//! Loading, saving, rendering, validating and comparing.

use crate::camera::PyCamera;
use crate::cloud::Cloud;
use crate::renderer;
use crate::{LoadError, RenderError, SaveError};
use numpy::{AllowTypeChange, PyArray3, PyArrayLike3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use splatgl::cloud::{ColorSpace, Known};
use splatgl::convert::{ConvertOptions, OutputFormat};
use splatgl::image::Image;
use splatgl::load::{LoadOptions, Scene};
use std::path::{Path, PathBuf};

/// The loader's options from `load`'s keyword arguments.
fn options(
    max_splats: Option<u64>,
    max_bytes: Option<u64>,
    strict: bool,
    allow_outside_paths: bool,
) -> LoadOptions {
    let mut o = LoadOptions {
        strict,
        allow_outside_paths,
        // Read, not mapped: a file truncated under a mapping kills the process with SIGBUS,
        // which an interpreter must not risk (the library's default for embedders).
        memory_map: false,
        ..Default::default()
    };
    if let Some(n) = max_splats {
        o.limits.max_splats = n;
    }
    if let Some(n) = max_bytes {
        o.limits.max_bytes = n;
    }
    o
}

/// A loaded scene as a Python cloud.
fn cloud_of(py: Python<'_>, s: Scene) -> PyResult<Cloud> {
    let findings = s
        .report
        .findings
        .iter()
        .map(|f| {
            (
                f.severity.name().to_owned(),
                f.path.clone(),
                f.message.clone(),
            )
        })
        .collect();
    let format = s.report.format.name().to_owned();
    Cloud::from_splat_cloud(py, s.cloud, findings, format)
}

/// Loads a splat file of any format splatgl reads (PLY, glTF/GLB with
/// KHR_gaussian_splatting, SPZ, .splat, .ksplat, SOG). Limits: `max_splats`, `max_bytes`;
/// `strict` fails on a non-finite value instead of dropping the splat;
/// `allow_outside_paths` lets glTF buffers leave the file's folder. Raises `LoadError`.
#[pyfunction]
#[pyo3(signature = (path, *, max_splats=None, max_bytes=None, strict=false, allow_outside_paths=false))]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    max_splats: Option<u64>,
    max_bytes: Option<u64>,
    strict: bool,
    allow_outside_paths: bool,
) -> PyResult<Cloud> {
    let o = options(max_splats, max_bytes, strict, allow_outside_paths);
    let scene = py
        .detach(|| splatgl::load::load_path(&path, &o))
        .map_err(|e| LoadError::new_err(crate::message(e)))?;
    cloud_of(py, scene)
}

/// Loads from bytes; `name` (a file name) helps detect the format and names it in errors.
/// No file is opened, whatever `name` says: a glTF's buffers must be in the bytes (GLB,
/// data URIs) and an unbundled SOG `meta.json` cannot load (its textures are files).
/// Raises `LoadError`.
#[pyfunction]
#[pyo3(signature = (data, name=None, *, max_splats=None, strict=false))]
pub fn load_bytes(
    py: Python<'_>,
    data: Vec<u8>,
    name: Option<String>,
    max_splats: Option<u64>,
    strict: bool,
) -> PyResult<Cloud> {
    let mut o = options(max_splats, None, strict, false);
    // Whatever the name: every file a document names goes to this resolver, which opens none.
    o.resolver = Some(std::sync::Arc::new(|uri: &str| {
        Err(format!(
            "{uri:?}: load_bytes opens no file (pass a GLB, data URIs, or use load)"
        ))
    }));
    let shown = name.map(PathBuf::from);
    let scene = py
        .detach(|| splatgl::load::load_bytes(&data, shown.as_deref(), &o))
        .map_err(|e| LoadError::new_err(crate::message(e)))?;
    cloud_of(py, scene)
}

/// Saves `cloud` by the extension of `path`, as `splatgl convert` writes it (.ply, .glb,
/// .gltf, .spz, .splat, .sog …); `sh_degree` truncates, `spz_compress` writes
/// KHR_gaussian_splatting_compression_spz_2 (.glb), `color_space` relabels. The axes are
/// written as they are. Raises `SaveError`.
#[pyfunction]
#[pyo3(signature = (cloud, path, *, sh_degree=None, spz_compress=false, color_space=None))]
pub fn save(
    py: Python<'_>,
    cloud: &Cloud,
    path: PathBuf,
    sh_degree: Option<u8>,
    spz_compress: bool,
    color_space: Option<&str>,
) -> PyResult<()> {
    let format = OutputFormat::from_path(&path).ok_or_else(|| {
        let exts: Vec<&str> = splatgl::convert::OUTPUTS.iter().map(|(e, _)| *e).collect();
        SaveError::new_err(format!(
            "{}: expected a file name ending in .{}",
            path.display(),
            exts.join(", .")
        ))
    })?;
    if sh_degree.is_some_and(|d| d > 3) {
        return Err(PyValueError::new_err("sh_degree: 0–3"));
    }
    let color_space = match color_space {
        None => None,
        Some(s) => match ColorSpace::parse(s) {
            Known::Known(c) => Some(c),
            Known::Unknown(_) => {
                return Err(PyValueError::new_err(format!(
                    "color_space {s:?}: expected \"srgb_rec709_display\" or \"lin_rec709_display\""
                )));
            }
        },
    };
    let o = ConvertOptions {
        sh_degree,
        spz_compress,
        color_space,
        ..Default::default()
    };
    if spz_compress && format != OutputFormat::Glb {
        return Err(SaveError::new_err(
            "spz_compress applies to .glb outputs only",
        ));
    }
    let mut c = cloud.to_splat_cloud(py)?;
    py.detach(|| {
        splatgl::convert::relabel(&mut c, &o);
        let (bytes, _notes) = splatgl::convert::encode(&c, format, &o)?;
        splatgl::write::write_bytes_atomic(&path, &[], &bytes)
            .map_err(|e| format!("{}: {e}", path.display()))
    })
    .map_err(|e| SaveError::new_err(crate::message(e)))
}

/// Renders `cloud` from `camera`: an (H, W, 4) float32 array, display-referred RGB and
/// alpha = 1 − transmittance. `backend`: "auto" (GL through headless EGL where it works,
/// else the CPU reference), "gl" or "reference". Raises `RenderError`.
#[pyfunction]
#[pyo3(signature = (cloud, camera, backend="auto", sh_degree=3, background=(0.0, 0.0, 0.0), antialiased=false))]
pub fn render<'py>(
    py: Python<'py>,
    cloud: &Cloud,
    camera: &PyCamera,
    backend: &str,
    sh_degree: u8,
    background: (f32, f32, f32),
    antialiased: bool,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    // One-shot: a renderer made, used once and closed (splatgl.Renderer keeps it open).
    let o = renderer::render_options(sh_degree, background, antialiased)?;
    let cam = renderer::sized(camera, None)?;
    let wanted = renderer::backend(backend)?;
    let c = cloud.to_splat_cloud(py)?;
    let img = py
        .detach(|| -> Result<Image, String> {
            let mut engine = renderer::make_engine(wanted)?;
            engine.upload(&c)?;
            Ok(engine.render(&c, &cam, &o)?.0)
        })
        .map_err(|e| RenderError::new_err(crate::message(e)))?;
    renderer::image_array(py, img)
}

/// Validates a file against KHR_gaussian_splatting (and the formats' own rules): a list of
/// (severity, path, message) findings, empty when valid.
#[pyfunction]
pub fn validate(py: Python<'_>, path: PathBuf) -> Vec<(String, String, String)> {
    let report =
        py.detach(|| splatgl::load::validate::validate_path(&path, &LoadOptions::default()));
    report
        .findings
        .iter()
        .map(|f| {
            (
                f.severity.name().to_owned(),
                f.path.clone(),
                f.message.clone(),
            )
        })
        .collect()
}

/// An image from a path (PNG, PFM) or an (H, W, 3|4) array.
fn image_of(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Image> {
    if let Ok(p) = v.extract::<PathBuf>() {
        return read_image(&p);
    }
    // The size before any conversion copies the array (a broadcast view takes no memory).
    if let Ok(arr) = v.cast::<numpy::PyUntypedArray>()
        && let [h, w, _] = arr.shape()
    {
        let side = |n: &usize| u32::try_from(*n).unwrap_or(u32::MAX);
        splatgl::camera::check_image_size(side(w), side(h))
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    }
    let a: PyArrayLike3<'_, f32, AllowTypeChange> = v
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{name}: a path or an (H, W, 3|4) array")))?;
    let a = a.as_array();
    let (h, w, ch) = a.dim();
    let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    splatgl::camera::check_image_size(side(w), side(h))
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    if !(ch == 3 || ch == 4) {
        return Err(PyValueError::new_err(format!(
            "{name}: shape {:?}, expected (H, W, 3) or (H, W, 4)",
            a.shape()
        )));
    }
    let mut img = Image::filled(w as u32, h as u32, [0.0, 0.0, 0.0, 1.0]);
    for (i, px) in img.pixels.iter_mut().enumerate() {
        let (y, x) = (i / w, i % w);
        for c in 0..ch {
            px[c] = a[[y, x, c]];
        }
    }
    Ok(img)
}

/// Writes an (H, W, 3|4) float array (as `render` returns) by `path`'s extension: `.png`
/// (8-bit RGBA, sRGB-encoded values as given, clamped to 0–1; written atomically) or `.pfm`
/// (32-bit float RGB). Raises `ValueError` for another extension or shape, `OSError`'s
/// message as `SaveError` when the file cannot be written.
#[pyfunction]
pub fn save_image(py: Python<'_>, image: &Bound<'_, PyAny>, path: PathBuf) -> PyResult<()> {
    let img = image_of(image, "image")?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let result = match ext.as_deref() {
        Some("png") => py.detach(|| img.write_png(&path, splatgl::image::PngDepth::Eight, true)),
        Some("pfm") => py.detach(|| img.write_pfm(&path)),
        _ => {
            return Err(PyValueError::new_err(format!(
                "{}: expected a file name ending in .png or .pfm",
                path.display()
            )));
        }
    };
    result.map_err(|e| SaveError::new_err(crate::message(format!("{}: {e}", path.display()))))
}

/// Reads an image file.
fn read_image(p: &Path) -> PyResult<Image> {
    Image::read(p).map_err(|e| PyValueError::new_err(format!("{}: {e}", p.display())))
}

/// Compares two images (paths or arrays): a dict of psnr, max_abs, mean_abs, pixels and
/// pixels_over (pixels whose largest channel error exceeds `threshold`).
#[pyfunction]
#[pyo3(signature = (a, b, threshold=1.0 / 255.0))]
pub fn compare<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    threshold: f32,
) -> PyResult<Bound<'py, PyDict>> {
    let (ia, ib) = (image_of(a, "a")?, image_of(b, "b")?);
    let c = splatgl::compare::compare(&ia, &ib, threshold)
        .map_err(|e| PyValueError::new_err(crate::message(e)))?;
    let d = PyDict::new(py);
    d.set_item("psnr", c.psnr)?;
    d.set_item("max_abs", c.max_abs)?;
    d.set_item("mean_abs", c.mean_abs)?;
    d.set_item("pixels", c.pixels)?;
    d.set_item("pixels_over", c.over_threshold)?;
    Ok(d)
}
