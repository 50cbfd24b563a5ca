//! `splatgl` for Python (PyO3 + NumPy, built by maturin: `pip install .` at the repository
//! root). The native module `splatgl._splatgl`; the package `python/splatgl` re-exports it
//! with docstrings and type stubs (`docs/python.md`).
//!
//! Every entry point checks its input and raises a Python exception with the library's
//! message (`splatgl.LoadError`, `splatgl.RenderError`, … all subclasses of
//! `splatgl.SplatglError`; `ValueError` for arrays of the wrong shape or values); loads,
//! saves, renders and conformance runs release the GIL.

mod camera;
mod cloud;
mod io;
mod kit;
mod renderer;
mod tiles;

use pyo3::prelude::*;

pyo3::create_exception!(
    _splatgl,
    SplatglError,
    pyo3::exceptions::PyException,
    "Base class of splatgl's errors."
);
pyo3::create_exception!(
    _splatgl,
    LoadError,
    SplatglError,
    "A file splatgl cannot load (the message names the file, element and index)."
);
pyo3::create_exception!(
    _splatgl,
    SaveError,
    SplatglError,
    "A cloud splatgl cannot write to that path or format."
);
pyo3::create_exception!(
    _splatgl,
    RenderError,
    SplatglError,
    "A render that cannot be done (no GL for backend=\"gl\", a cloud too large)."
);
pyo3::create_exception!(
    _splatgl,
    CameraError,
    SplatglError,
    "A camera that cannot be built (a cameras.json entry, a non-rigid matrix)."
);
pyo3::create_exception!(
    _splatgl,
    ConformanceError,
    SplatglError,
    "A conformance suite that cannot be generated or graded."
);

pyo3::create_exception!(
    _splatgl,
    TilesError,
    SplatglError,
    "A tileset that cannot be built (the input, a step's files, or a plan that does not fit)."
);

/// The native module.
#[pymodule]
fn _splatgl(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SplatglError", py.get_type::<SplatglError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("SaveError", py.get_type::<SaveError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add("CameraError", py.get_type::<CameraError>())?;
    m.add("ConformanceError", py.get_type::<ConformanceError>())?;
    m.add("TilesError", py.get_type::<TilesError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let (chunk, bucket) = (
        splatgl::tiles::BuildOptions::DEFAULT_CHUNK_SPLATS,
        splatgl::tiles::StreamOptions::DEFAULT_BUCKET_SPLATS,
    );
    m.add("TILE_CHUNK_SPLATS", chunk)?;
    m.add("TILE_BUCKET_SPLATS", bucket)?;
    m.add_class::<cloud::Cloud>()?;
    m.add_class::<camera::PyCamera>()?;
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(io::load, m)?)?;
    m.add_function(wrap_pyfunction!(io::load_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(io::save, m)?)?;
    m.add_function(wrap_pyfunction!(io::save_image, m)?)?;
    m.add_function(wrap_pyfunction!(io::render, m)?)?;
    m.add_function(wrap_pyfunction!(io::validate, m)?)?;
    m.add_function(wrap_pyfunction!(io::compare, m)?)?;
    m.add_function(wrap_pyfunction!(kit::conformance_generate, m)?)?;
    m.add_function(wrap_pyfunction!(kit::conformance_run, m)?)?;
    m.add_function(wrap_pyfunction!(kit::cli, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_plan, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_route, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_build_bucket, m)?)?;
    m.add_function(wrap_pyfunction!(tiles::tiles_join, m)?)?;
    Ok(())
}

/// An error's message as Python sees it: file content in it made safe to print
/// ([`splatgl::load::printable`]: terminal control characters escaped).
pub(crate) fn message(e: impl std::fmt::Display) -> String {
    splatgl::load::printable(&e.to_string()).into_owned()
}
