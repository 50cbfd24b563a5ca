//! Comparing a set of images with the suite's references, per the manifest's tolerances, and
//! naming the likely cause of known failure patterns: [`run`] here (each camera compared),
//! `judge` (what an image is judged by, and the choices it may pass with), `explain`
//! (the models' search, the second look and the causes).

mod explain;
mod judge;

pub use explain::diagnosis;

use super::diagnosis::{Closest, Explanation};
use super::manifest::{AssetEntry, CameraEntry, Manifest, suite_path};
use super::render;
use super::verdict::{clamped, measure, over_bound};
use explain::{Budget, MAX_EXPLAINED, allow_or_explain, name_causes, second_look};
use judge::reference_and_bound;
use splatgl::compare::Comparison;
use splatgl::image::{Image, ImageError};
use std::path::Path;

/// The outcome of one camera.
#[derive(Debug, Clone)]
pub struct CameraResult {
    /// The manifest's entry.
    pub camera: CameraEntry,
    /// The comparison (`None` when the image is missing or unusable).
    pub comparison: Option<Comparison>,
    /// Within tolerance.
    pub pass: bool,
    /// The likely cause of a failure (or the RC-allowed choice a pass was found with).
    pub cause: Option<String>,
    /// What explains a failure ([`crate::diagnosis::Search::explain`]; empty when it passes or has no image).
    pub explained_by: Vec<Explanation>,
    /// For a failure nothing explains, the model it came nearest to (reported as `nearest`).
    pub closest: Option<Closest>,
    /// PSNR and max error against the reference (when an image of the right size was given).
    pub against_reference: Option<(f64, f64)>,
    /// Expected (reference) and actual images (clamped), for the report.
    pub expected: Image,
    /// The image compared (`None` when missing).
    pub actual: Option<Image>,
    /// No image was given for this camera.
    pub missing: bool,
    /// For a failure the models looked at: its pixels over their bound against the model
    /// without deviations (the reference; with SPZ input, the SPZ copy).
    pub baseline_over: Option<usize>,
}

/// The outcome of one asset: passes when every camera passes.
#[derive(Debug, Clone)]
pub struct AssetResult {
    /// The manifest's entry.
    pub asset: AssetEntry,
    /// Per camera.
    pub cameras: Vec<CameraResult>,
    /// Optional asset without images: not counted.
    pub skipped: bool,
}

impl AssetResult {
    /// All cameras pass.
    pub fn pass(&self) -> bool {
        self.cameras.iter().all(|c| c.pass)
    }
    /// Lowest PSNR over the cameras (`None` if any image is missing).
    pub fn psnr(&self) -> Option<f64> {
        self.cameras
            .iter()
            .map(|c| c.comparison.map(|x| x.psnr))
            .try_fold(f64::INFINITY, |a, p| p.map(|p| a.min(p)))
    }
    /// Largest error over the cameras.
    pub fn max_abs(&self) -> Option<f64> {
        self.cameras
            .iter()
            .map(|c| c.comparison.map(|x| x.max_abs as f64))
            .try_fold(0.0f64, |a, p| p.map(|p| a.max(p)))
    }
}

/// Where another renderer's image for `c` is: `IMAGES/ASSET/CAMERA.pfm`, else `.png` (inside
/// `images`: see [`suite_path`]).
pub fn find_image(images: &Path, c: &CameraEntry) -> Option<std::path::PathBuf> {
    ["pfm", "png"]
        .iter()
        .filter_map(|e| suite_path(images, &format!("{}.{e}", c.image)).ok())
        .find(|p| p.is_file())
}

/// What the images of a run were rendered from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputPrecision {
    /// The suite's assets as written (float attributes).
    #[default]
    Exact,
    /// SPZ-compressed copies of them (`splatgl convert --spz-compress`: an adapter for a
    /// renderer that reads only `KHR_gaussian_splatting_compression_spz_2`). The images are
    /// then judged against the model of what those copies carry: an image that matches it
    /// passes, with that said, and the diagnosis explains failures from the SPZ copy.
    Spz,
}

/// Options of [`run_with`].
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// What the images were rendered from.
    pub input: InputPrecision,
}

/// An asset as the models need it: the scene (with SPZ input, its SPZ copy) and its cameras.
struct ModelInput {
    /// The scene, as loaded (its cloud in global space).
    scene: splatgl::load::Scene,
    /// Its cameras, in the manifest's order.
    cameras: Vec<splatgl::camera::Camera>,
}

/// Compares the images `get(camera)` returns (`None`: missing; `Err`: unreadable) with the
/// references in `dir`; a failing camera is explained with the diagnosis's models, and its
/// `cause` names the deviation the whole run's [`diagnosis()`] attributes it to (or says
/// `unexplained`, with the asset's stock hint). `Err` only when a reference cannot be read
/// (a broken suite).
pub fn run(
    dir: &Path,
    m: &Manifest,
    get: impl FnMut(&CameraEntry) -> Option<Result<Image, ImageError>>,
) -> Result<Vec<AssetResult>, crate::KitError> {
    run_with(dir, m, &RunOptions::default(), get)
}

/// [`run`] with options (what the images were rendered from).
pub fn run_with(
    dir: &Path,
    m: &Manifest,
    opts: &RunOptions,
    get: impl FnMut(&CameraEntry) -> Option<Result<Image, ImageError>>,
) -> Result<Vec<AssetResult>, crate::KitError> {
    grade(dir, m, opts, get).map_err(crate::KitError::Reference)
}

fn grade(
    dir: &Path,
    m: &Manifest,
    opts: &RunOptions,
    mut get: impl FnMut(&CameraEntry) -> Option<Result<Image, ImageError>>,
) -> Result<Vec<AssetResult>, String> {
    let mut results = Vec::new();
    let mut budget = Budget {
        cameras_left: MAX_EXPLAINED,
        input: opts.input,
    };
    for (ai, a) in m.assets.iter().enumerate() {
        let mut cams = Vec::new();
        let mut loaded = Loaded::default();
        for (ci, c) in a.cameras.iter().enumerate() {
            let got = get(c).map(|r| r.map_err(|e| e.to_string()));
            cams.push(camera_result(
                dir,
                m,
                (ai, ci),
                got,
                &mut loaded,
                &mut budget,
            )?);
        }
        let missing = cams.iter().filter(|c| c.missing).count();
        results.push(AssetResult {
            asset: a.clone(),
            skipped: a.optional && missing == a.cameras.len(),
            cameras: cams,
        });
    }
    second_look(dir, m, &mut budget, &mut results)?;
    name_causes(&mut results);
    Ok(results)
}

/// An asset loaded for the models, once: not yet, failed, or loaded.
#[derive(Default)]
enum Loaded {
    /// Not needed yet.
    #[default]
    NotYet,
    /// It does not load (or SPZ cannot carry it).
    Failed,
    /// Loaded.
    Ready(Box<ModelInput>),
}

impl Loaded {
    /// The asset, loaded by `load` the first time it is asked for.
    fn get(&mut self, load: impl FnOnce() -> Option<ModelInput>) -> Option<&ModelInput> {
        if matches!(self, Loaded::NotYet) {
            *self = load().map_or(Loaded::Failed, |l| Loaded::Ready(Box::new(l)));
        }
        match self {
            Loaded::Ready(l) => Some(l),
            _ => None,
        }
    }
}

/// Camera `ci` of asset `ai` with the image `got`: compared with the reference; when it fails,
/// checked against the RC-allowed SH caps and explained with the models (the asset is loaded
/// into `loaded` the first time it is needed).
fn camera_result(
    dir: &Path,
    m: &Manifest,
    (ai, ci): (usize, usize),
    got: Option<Result<Image, String>>,
    loaded: &mut Loaded,
    budget: &mut Budget,
) -> Result<CameraResult, String> {
    let c = &m.assets[ai].cameras[ci];
    let (want, bound) = reference_and_bound(dir, c)?;
    let mut r = not_compared(c, &want);
    let img = match got {
        None => {
            r.missing = true;
            r.cause = Some(format!("no image {}.png or {}.pfm", c.image, c.image));
            return Ok(r);
        }
        Some(Err(e)) => {
            r.cause = Some(format!("unreadable image: {e}"));
            return Ok(r);
        }
        Some(Ok(img)) => clamped(&img),
    };
    if (img.width, img.height) != (c.width, c.height) {
        r.cause = Some(format!(
            "image is {}x{}, expected {}x{}",
            img.width, img.height, c.width, c.height
        ));
        r.actual = Some(img);
        return Ok(r);
    }
    // Over the judged region: the pixels outside it count as equal (the verdict rules).
    let (cmp, ratio) = measure(&img, &want, &bound);
    let t = &c.tolerance;
    r.pass = ratio <= 1.0 && cmp.max_abs as f64 <= t.max_abs && cmp.psnr >= t.min_psnr;
    r.against_reference = Some((cmp.psnr, cmp.max_abs as f64));
    r.comparison = Some(cmp);
    if !r.pass {
        let input = budget.input;
        let l = loaded.get(|| load_for_models(dir, m, ai, input));
        let note = allow_or_explain(l, (&m.assets[ai], ci), &img, &bound, budget, &mut r);
        if !r.pass {
            r.cause = Some(format!(
                "{} pixels over their bound (worst {ratio:.2}×); {note}",
                over_bound(&img, &want, &bound)
            ));
        }
    }
    r.actual = Some(img);
    Ok(r)
}

/// Asset `ai` as the models need it: as written, or its SPZ copy for SPZ input (`None` when
/// it does not load, or SPZ cannot carry it).
fn load_for_models(
    dir: &Path,
    m: &Manifest,
    ai: usize,
    input: InputPrecision,
) -> Option<ModelInput> {
    let (mut scene, cams) = render::load_asset(dir, m, ai).ok()?;
    if input == InputPrecision::Spz {
        scene.cloud = super::model::spz_copy(&scene.cloud)?;
    }
    Some(ModelInput {
        scene,
        cameras: cams,
    })
}

/// The result of camera `c` before any comparison: not passing, nothing explained.
fn not_compared(c: &CameraEntry, want: &Image) -> CameraResult {
    CameraResult {
        camera: c.clone(),
        comparison: None,
        pass: false,
        cause: None,
        explained_by: Vec::new(),
        closest: None,
        against_reference: None,
        expected: want.clone(),
        actual: None,
        missing: false,
        baseline_over: None,
    }
}
