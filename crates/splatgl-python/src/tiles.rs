//! The steps of the bucketed LOD build ([`splatgl::tiles::steps`]) for a driver in Python
//! (`splatgl.tiles.build_distributed` hands them to Ray workers). Plans and reports travel
//! as JSON text: small, and picklable by any scheduler.

use crate::TilesError;
use pyo3::prelude::*;
use splatgl::tiles::StreamOptions;
use splatgl::tiles::steps::{self, BucketReport, BuildPlan};
use std::path::PathBuf;

fn to_json<T: serde::Serialize>(v: &T) -> Result<String, String> {
    serde_json::to_string(v).map_err(|e| e.to_string())
}

fn plan_of(plan: &str) -> Result<BuildPlan, String> {
    serde_json::from_str(plan).map_err(|e| format!("not a build plan: {e}"))
}

fn fail(e: impl std::fmt::Display) -> PyErr {
    TilesError::new_err(crate::message(e))
}

/// Step 1 (driver): samples `input` (a binary PLY) and writes the plan to
/// `scratch_dir/plan.json`; the plan as JSON text.
#[pyfunction]
#[pyo3(signature = (input, output, scratch_dir, bucket_splats, chunk_splats, ranges))]
pub fn tiles_plan(
    py: Python<'_>,
    input: PathBuf,
    output: PathBuf,
    scratch_dir: PathBuf,
    bucket_splats: usize,
    chunk_splats: usize,
    ranges: usize,
) -> PyResult<String> {
    let o = StreamOptions {
        chunk_splats,
        bucket_splats: bucket_splats.max(1),
        scratch_dir,
    };
    py.detach(|| {
        let p =
            steps::plan(&input, &output, &o, ranges, &|_, _, _| {}).map_err(|e| e.to_string())?;
        to_json(&p)
    })
    .map_err(fail)
}

/// Step 2 (a task per range): routes range `range`'s rows to the buckets' part files; the
/// range's report as JSON text.
#[pyfunction]
pub fn tiles_route(py: Python<'_>, plan: &str, range: usize) -> PyResult<String> {
    py.detach(|| {
        let p = plan_of(plan)?;
        to_json(&steps::route_range(&p, range).map_err(|e| e.to_string())?)
    })
    .map_err(fail)
}

/// Step 3 (a task per bucket): builds bucket `bucket` and writes its tiles; its report as
/// JSON text.
#[pyfunction]
pub fn tiles_build_bucket(py: Python<'_>, plan: &str, bucket: usize) -> PyResult<String> {
    py.detach(|| {
        let p = plan_of(plan)?;
        to_json(&steps::build_bucket(&p, bucket).map_err(|e| e.to_string())?)
    })
    .map_err(fail)
}

/// Step 4 (driver): the tiles above the buckets and `tileset.json`, from every bucket's
/// report; the join's report as JSON text (scratch files removed).
#[pyfunction]
pub fn tiles_join(py: Python<'_>, plan: &str, buckets: Vec<String>) -> PyResult<String> {
    py.detach(|| {
        let p = plan_of(plan)?;
        let reports = buckets
            .iter()
            .map(|b| {
                serde_json::from_str::<BucketReport>(b)
                    .map_err(|e| format!("not a bucket report: {e}"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        to_json(&steps::join(&p, &reports).map_err(|e| e.to_string())?)
    })
    .map_err(fail)
}
