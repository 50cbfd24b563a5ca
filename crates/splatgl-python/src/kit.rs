//! The conformance kit and the `splatgl` command, in-process.

use crate::ConformanceError;
use pyo3::prelude::*;
use splatgl::image::Image;
use splatgl_conformance::manifest::Manifest;
use splatgl_conformance::{report, runner};
use std::path::PathBuf;

/// Writes the conformance suite into `dir` (created if needed): manifest.json, the assets,
/// their cameras and the reference images. Raises `ConformanceError`.
#[pyfunction]
pub fn conformance_generate(py: Python<'_>, dir: PathBuf) -> PyResult<()> {
    py.detach(|| splatgl_conformance::generate(&dir).map(|_| ()))
        .map_err(|e| ConformanceError::new_err(crate::message(e)))
}

/// Grades another renderer's images (`images/ASSET/CAMERA.png` or `.pfm`) against the suite
/// in `dir`: the report as JSON text (`splatgl.conformance.run` parses it), and, with
/// `out`, report.json and report.html written there. `input_precision`: "exact" or "spz".
#[pyfunction]
#[pyo3(signature = (dir, images, out=None, input_precision="exact"))]
pub fn conformance_run(
    py: Python<'_>,
    dir: PathBuf,
    images: PathBuf,
    out: Option<PathBuf>,
    input_precision: &str,
) -> PyResult<String> {
    let input = match input_precision {
        "exact" => runner::InputPrecision::Exact,
        "spz" => runner::InputPrecision::Spz,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "input_precision {other:?}: expected \"exact\" or \"spz\""
            )));
        }
    };
    py.detach(|| -> Result<String, String> {
        if !images.is_dir() {
            return Err(format!("{}: not a folder", images.display()));
        }
        let m = Manifest::read(&dir)?;
        let opts = runner::RunOptions { input };
        let results = runner::run_with(&dir, &m, &opts, |c| {
            runner::find_image(&images, c).map(Image::read)
        })?;
        let source = images.display().to_string();
        let json = report::to_json(&results, &source);
        let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
        if let Some(out) = &out {
            std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
            let write = |name: &str, bytes: &[u8]| {
                let p = out.join(name);
                splatgl::write::write_bytes_atomic(&p, &[], bytes)
                    .map_err(|e| format!("{}: {e}", p.display()))
            };
            write("report.json", text.as_bytes())?;
            write("report.html", report::to_html(&results, &source).as_bytes())?;
        }
        Ok(text)
    })
    .map_err(ConformanceError::new_err)
}

/// Runs the `splatgl` command with `argv` (the first item the program's name) in this
/// process: its exit status (0, 1 a failed check, 2 an error). The package's `splatgl`
/// console script.
#[pyfunction]
pub fn cli(py: Python<'_>, argv: Vec<String>) -> u8 {
    py.detach(|| splatgl_cli::exit_status(splatgl_cli::run_from(argv)))
}
