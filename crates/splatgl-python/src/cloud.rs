//! `splatgl.Cloud`: a splat cloud whose attributes are NumPy arrays it owns (moved out of the
//! loader's vectors, no copy), and the way back to a [`SplatCloud`] for saving and rendering.

use numpy::{
    AllowTypeChange, PyArray1, PyArray2, PyArray3, PyArrayLike1, PyArrayLike2, PyArrayLike3,
    PyArrayMethods, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use splatgl::SplatCloud;
use splatgl::cloud::{ColorSpace, Kernel, Known, Projection, SortingMethod, SplatMeta};

/// A splat cloud: `positions (N, 3)`, `scales (N, 3)` (linear standard deviations),
/// `rotations (N, 4)` (unit quaternions x, y, z, w), `opacities (N,)` (linear, 0–1), `sh
/// (N, K, 3)` (K = (degree + 1)², degree-major, m = −l..l), all float32; `meta` (the
/// extension's kernel, color space, projection and sorting method) and `findings` (what the
/// loader noticed). The arrays are the cloud's own: writing into them edits it.
#[pyclass(module = "splatgl", name = "Cloud", frozen)]
pub struct Cloud {
    positions: Py<PyArray2<f32>>,
    scales: Py<PyArray2<f32>>,
    rotations: Py<PyArray2<f32>>,
    opacities: Py<PyArray1<f32>>,
    sh: Py<PyArray3<f32>>,
    sh_degree: u8,
    meta: SplatMeta,
    findings: Vec<(String, String, String)>,
    format: String,
}

impl Cloud {
    /// `c` as a Python cloud: its vectors become the arrays (moved, not copied).
    pub fn from_splat_cloud(
        py: Python<'_>,
        c: SplatCloud,
        findings: Vec<(String, String, String)>,
        format: String,
    ) -> PyResult<Self> {
        let n = c.len();
        let k = c.coeffs_per_splat();
        let arr2 = |v: Vec<f32>, w: usize| -> PyResult<Py<PyArray2<f32>>> {
            Ok(PyArray1::from_vec(py, v).reshape([n, w])?.unbind())
        };
        Ok(Cloud {
            positions: arr2(c.positions.into_flattened(), 3)?,
            scales: arr2(c.scales.into_flattened(), 3)?,
            rotations: arr2(c.rotations.into_flattened(), 4)?,
            opacities: PyArray1::from_vec(py, c.opacities).unbind(),
            sh: PyArray1::from_vec(py, c.sh.into_flattened())
                .reshape([n, k, 3])?
                .unbind(),
            sh_degree: c.sh_degree,
            meta: c.meta,
            findings,
            format,
        })
    }

    /// The cloud as the library's [`SplatCloud`] (a copy of the arrays, checked: shapes that
    /// agree, finite values, scales ≥ 0, opacities in [0, 1], non-zero quaternions, which are
    /// normalized).
    pub fn to_splat_cloud(&self, py: Python<'_>) -> PyResult<SplatCloud> {
        let p = self.positions.bind(py).readonly();
        let s = self.scales.bind(py).readonly();
        let r = self.rotations.bind(py).readonly();
        let o = self.opacities.bind(py).readonly();
        let sh = self.sh.bind(py).readonly();
        build(
            (p.as_array(), s.as_array(), r.as_array()),
            o.as_array(),
            sh.as_array(),
            self.meta.clone(),
        )
    }
}

/// A [`SplatCloud`] from array views, checked (see [`Cloud::to_splat_cloud`]).
/// The default metadata with `color_space` (`None`: the default one); `Err` for a name that
/// is not one of the two.
fn meta_with(color_space: Option<&str>) -> PyResult<SplatMeta> {
    let mut meta = SplatMeta::default();
    if let Some(cs) = color_space {
        meta.color_space = match ColorSpace::parse(cs) {
            Known::Known(c) => Known::Known(c),
            Known::Unknown(_) => {
                return Err(PyValueError::new_err(format!(
                    "color_space {cs:?}: expected \"srgb_rec709_display\" or \"lin_rec709_display\""
                )));
            }
        };
    }
    Ok(meta)
}

/// `Err` naming row `i` of `name` when a value of `v` is not finite.
fn finite(i: usize, name: &str, v: &[f32]) -> PyResult<()> {
    match v.iter().all(|x| x.is_finite()) {
        true => Ok(()),
        false => Err(PyValueError::new_err(format!(
            "{name}[{i}]: {v:?} is not finite"
        ))),
    }
}

/// Checks row `i` as a loaded file's splat is checked; returns the quaternion's norm.
fn check_row(i: usize, pos: [f32; 3], scale: [f32; 3], q: [f32; 4], a: f32) -> PyResult<f32> {
    finite(i, "positions", &pos)?;
    finite(i, "scales", &scale)?;
    finite(i, "rotations", &q)?;
    if scale.iter().any(|x| *x < 0.0) {
        return Err(PyValueError::new_err(format!(
            "scales[{i}]: {scale:?}: scales are linear standard deviations, ≥ 0 (log scales: pass numpy.exp of them)"
        )));
    }
    if scale.iter().any(|x| !(x * x).is_finite()) {
        return Err(PyValueError::new_err(format!(
            "scales[{i}]: {scale:?}: a scale whose square overflows f32 (the covariance)"
        )));
    }
    let norm = q.iter().map(|x| x * x).sum::<f32>().sqrt();
    if norm == 0.0 || !norm.is_finite() {
        return Err(PyValueError::new_err(format!(
            "rotations[{i}]: the zero quaternion has no rotation"
        )));
    }
    if !(0.0..=1.0).contains(&a) {
        return Err(PyValueError::new_err(format!(
            "opacities[{i}]: {a} is outside [0, 1] (logits: pass 1 / (1 + numpy.exp(-x)))"
        )));
    }
    Ok(norm)
}

fn build(
    (p, s, r): (
        numpy::ndarray::ArrayView2<'_, f32>,
        numpy::ndarray::ArrayView2<'_, f32>,
        numpy::ndarray::ArrayView2<'_, f32>,
    ),
    o: numpy::ndarray::ArrayView1<'_, f32>,
    sh: numpy::ndarray::ArrayView3<'_, f32>,
    meta: SplatMeta,
) -> PyResult<SplatCloud> {
    let n = p.nrows();
    let shape = |name: &str, got: &[usize], want: &[usize]| -> PyResult<()> {
        if got == want {
            Ok(())
        } else {
            Err(PyValueError::new_err(format!(
                "{name}: shape {got:?}, expected {want:?}"
            )))
        }
    };
    shape("positions", p.shape(), &[n, 3])?;
    shape("scales", s.shape(), &[n, 3])?;
    shape("rotations", r.shape(), &[n, 4])?;
    shape("opacities", o.shape(), &[n])?;
    let k = sh.shape()[1];
    let degree = match k {
        1 => 0,
        4 => 1,
        9 => 2,
        16 => 3,
        _ => {
            return Err(PyValueError::new_err(format!(
                "sh: {k} coefficients per splat, expected 1, 4, 9 or 16 (degree 0–3)"
            )));
        }
    };
    shape("sh", sh.shape(), &[n, k, 3])?;
    let mut c = SplatCloud::with_capacity(degree, n);
    c.meta = meta;
    let mut coeffs = vec![[0f32; 3]; k];
    for i in 0..n {
        let pos = [p[[i, 0]], p[[i, 1]], p[[i, 2]]];
        let scale = [s[[i, 0]], s[[i, 1]], s[[i, 2]]];
        let q = [r[[i, 0]], r[[i, 1]], r[[i, 2]], r[[i, 3]]];
        let a = o[i];
        let norm = check_row(i, pos, scale, q, a)?;
        for (j, cf) in coeffs.iter_mut().enumerate() {
            *cf = [sh[[i, j, 0]], sh[[i, j, 1]], sh[[i, j, 2]]];
            finite(i, "sh", cf)?;
        }
        // Unit already (as loaded) within f32 rounding: kept bit for bit.
        let q = if (norm - 1.0).abs() > 4.0 * f32::EPSILON {
            q.map(|x| x / norm)
        } else {
            q
        };
        c.push(pos, scale, q, a, &coeffs);
    }
    Ok(c)
}

/// Refuses an array (NumPy's, before conversion) of more than `max` rows, or of more values
/// than `max` splats at SH degree 3 hold: the loaders' splat limit, applied to arrays.
fn rows_within(a: &Bound<'_, PyAny>, name: &str, max: u64) -> PyResult<()> {
    let Ok(a) = a.cast::<numpy::PyUntypedArray>() else {
        return Ok(()); // a list or the like: already whole in memory
    };
    let shape = a.shape();
    let rows = shape.first().copied().unwrap_or(0) as u128;
    let values: u128 = shape.iter().map(|&d| d as u128).product();
    if rows > u128::from(max) || values > u128::from(max) * 48 {
        return Err(PyValueError::new_err(format!(
            "{name}: shape {shape:?}: more than max_splats = {max} splats (raise with max_splats=)"
        )));
    }
    Ok(())
}

/// A meta value as written (known values by name).
fn known<T: Copy>(k: &Known<T>, name: fn(T) -> &'static str) -> String {
    k.to_string_with(name)
}

#[pymethods]
impl Cloud {
    /// Builds a cloud from arrays (any array-like NumPy converts, e.g. a trainer's tensors'
    /// `.numpy()`): positions (N, 3), scales (N, 3) linear, rotations (N, 4) x y z w,
    /// opacities (N,) in [0, 1], and either `sh` (N, K, 3) or `colors` (N, 3) display RGB
    /// (the degree-0 coefficient `(c − 0.5) / 0.2820948`); `color_space` one of
    /// "srgb_rec709_display" (default) or "lin_rec709_display".
    #[staticmethod]
    #[pyo3(signature = (positions, scales, rotations, opacities, sh=None, colors=None, color_space=None, *, max_splats=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        py: Python<'_>,
        positions: &Bound<'_, PyAny>,
        scales: &Bound<'_, PyAny>,
        rotations: &Bound<'_, PyAny>,
        opacities: &Bound<'_, PyAny>,
        sh: Option<&Bound<'_, PyAny>>,
        colors: Option<&Bound<'_, PyAny>>,
        color_space: Option<&str>,
        max_splats: Option<u64>,
    ) -> PyResult<Self> {
        // Sizes first, before any conversion copies an array (a broadcast view of a billion
        // rows takes no memory until converted).
        let max = max_splats.unwrap_or(splatgl::load::Limits::DEFAULT_MAX_SPLATS);
        for (name, a) in [
            ("positions", Some(positions)),
            ("scales", Some(scales)),
            ("rotations", Some(rotations)),
            ("opacities", Some(opacities)),
            ("sh", sh),
            ("colors", colors),
        ] {
            if let Some(a) = a {
                rows_within(a, name, max)?;
            }
        }
        let positions: PyArrayLike2<'_, f32, AllowTypeChange> = positions.extract()?;
        let scales: PyArrayLike2<'_, f32, AllowTypeChange> = scales.extract()?;
        let rotations: PyArrayLike2<'_, f32, AllowTypeChange> = rotations.extract()?;
        let opacities: PyArrayLike1<'_, f32, AllowTypeChange> = opacities.extract()?;
        let sh: Option<PyArrayLike3<'_, f32, AllowTypeChange>> =
            sh.map(|a| a.extract()).transpose()?;
        let colors: Option<PyArrayLike2<'_, f32, AllowTypeChange>> =
            colors.map(|a| a.extract()).transpose()?;
        let meta = meta_with(color_space)?;
        let n = positions.as_array().nrows();
        let from_colors;
        let sh_view = match (&sh, &colors) {
            (Some(sh), None) => sh.as_array(),
            (None, Some(c)) => {
                let c = c.as_array();
                if c.shape() != [n, 3] {
                    return Err(PyValueError::new_err(format!(
                        "colors: shape {:?}, expected [{n}, 3]",
                        c.shape()
                    )));
                }
                // In logical order whatever the strides (a broadcast view has zero ones).
                let dc = c.iter().map(|v| (v - 0.5) / splatgl::sh::SH_C0 as f32);
                from_colors = numpy::ndarray::Array3::from_shape_vec((n, 1, 3), dc.collect())
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                from_colors.view()
            }
            _ => {
                return Err(PyValueError::new_err(
                    "give either sh (N, K, 3) or colors (N, 3)",
                ));
            }
        };
        let c = build(
            (
                positions.as_array(),
                scales.as_array(),
                rotations.as_array(),
            ),
            opacities.as_array(),
            sh_view,
            meta,
        )?;
        c.validate()
            .map_err(|v| PyValueError::new_err(v.to_string()))?;
        Cloud::from_splat_cloud(py, c, Vec::new(), "arrays".into())
    }

    /// Positions (N, 3), float32.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        self.positions.bind(py).clone()
    }
    /// Scales (N, 3), linear standard deviations, float32.
    #[getter]
    fn scales<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        self.scales.bind(py).clone()
    }
    /// Rotations (N, 4), unit quaternions x, y, z, w, float32.
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        self.rotations.bind(py).clone()
    }
    /// Opacities (N,), linear in [0, 1], float32.
    #[getter]
    fn opacities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        self.opacities.bind(py).clone()
    }
    /// SH coefficients (N, K, 3), K = (sh_degree + 1)², float32.
    #[getter]
    fn sh<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        self.sh.bind(py).clone()
    }
    /// The SH degree (0–3).
    #[getter]
    fn sh_degree(&self) -> u8 {
        self.sh_degree
    }
    /// The format it was loaded from ("ply", "glb", …; "arrays" for `from_arrays`).
    #[getter]
    fn format(&self) -> &str {
        &self.format
    }
    /// The extension's metadata: kernel, color_space, projection, sorting_method (as
    /// written in the file; unknown values kept).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("kernel", known(&self.meta.kernel, Kernel::as_str))?;
        d.set_item(
            "color_space",
            known(&self.meta.color_space, ColorSpace::as_str),
        )?;
        d.set_item(
            "projection",
            known(&self.meta.projection, Projection::as_str),
        )?;
        d.set_item(
            "sorting_method",
            known(&self.meta.sorting_method, SortingMethod::as_str),
        )?;
        Ok(d)
    }
    /// What the loader noticed: (severity, path, message) tuples.
    #[getter]
    fn findings(&self) -> Vec<(String, String, String)> {
        self.findings.clone()
    }
    fn __len__(&self, py: Python<'_>) -> usize {
        self.positions.bind(py).shape()[0]
    }
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<splatgl.Cloud {} splats, SH degree {}, from {}>",
            self.__len__(py),
            self.sh_degree,
            self.format
        )
    }
}
