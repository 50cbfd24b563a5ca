//! Comparing a set of images with the suite's references, per the manifest's tolerances, and
//! naming the likely cause of known failure patterns.

use super::diagnosis::{self, Closest, Deviation, Diagnosis, Explanation, Failure, Search};
use super::generate::{clamped, fails, measure, over_bound, tolerance};
use super::isolation::derived_bound;
use super::manifest::{AssetEntry, CameraEntry, Manifest, suite_path};
use super::model::Variant;
use super::render;
use splatgl::compare::Comparison;
use splatgl::image::Image;
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
    /// What explains a failure ([`diagnosis::Search::explain`]; empty when it passes or has no image).
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

/// What an image that differs from the reference may still pass as.
enum Allowed {
    /// A renderer that ignores SH above some degree (the RC allows it).
    ShCap(Deviation),
    /// A renderer with these choices, which the asset admits because it does not test them
    /// (none: with SPZ input, the SPZ copy as it is).
    Admitted(Vec<Deviation>),
}

/// What an image is judged by when it fails against the reference: the per-pixel bound and
/// the camera's entry with its tolerance. For float input the suite's own; for SPZ input the
/// bound and tolerance the generator would derive from the asset's SPZ copy
/// ([`super::isolation::derived_bound`]: the copy's own terms and the choices the asset
/// admits, acting on the copy's footprints), with the copy's model image.
struct Judge {
    bound: Vec<f64>,
    camera: CameraEntry,
    /// For SPZ input, the SPZ copy's model image.
    copy: Option<Image>,
}

impl Judge {
    /// The judge of camera `ci` of asset `a` loaded as `l`, with the suite's `bound`.
    fn new(
        l: &ModelInput,
        (a, ci): (&AssetEntry, usize),
        bound: &[f64],
        input: InputPrecision,
    ) -> Self {
        let c = &a.cameras[ci];
        let own = || Judge {
            bound: bound.to_vec(),
            camera: c.clone(),
            copy: None,
        };
        if input != InputPrecision::Spz {
            return own();
        }
        let mut m = derived_bound(&l.0.cloud, &l.1[ci], (&a.catches, &a.detects));
        // The camera's judged region (the suite's bound is infinite outside it).
        let judged: Vec<bool> = bound.iter().map(|b| b.is_finite()).collect();
        super::judge::apply(&mut m.bound, &judged);
        Judge {
            camera: CameraEntry {
                tolerance: tolerance(&m),
                ..c.clone()
            },
            bound: m.bound,
            copy: Some(m.image),
        }
    }
    /// Whether `img` fails against `want` under this judge.
    fn fails(&self, img: &Image, want: &Image) -> bool {
        fails(img, want, &self.bound, &self.camera.tolerance)
    }
}

/// An asset as the models need it: the scene (with SPZ input, its SPZ copy) and its cameras.
type ModelInput = (splatgl::load::Scene, Vec<splatgl::camera::Camera>);

/// The choices an image may pass with although it differs from the reference: a renderer
/// that makes one or two of the choices the asset admits
/// ([`super::isolation::admitted_sets`]: the asset's bound is widened for each, but an image
/// drawn with them may still differ from the model with them by the model's own terms), a
/// renderer that ignores SH coefficients above some degree (the RC allows it), and with SPZ
/// input the SPZ copy as it is (`l` holds that copy then). Each is judged by the asset's
/// bound and, with SPZ input, also by the bound derived from the copy ([`Judge`]). `None`:
/// it matches none.
fn allowed_choice(
    l: &ModelInput,
    (a, ci): (&AssetEntry, usize),
    (bound, judge): (&[f64], &Judge),
    img: &Image,
) -> Option<Allowed> {
    let c = &a.cameras[ci];
    let model = |devs: &[Deviation]| diagnosis::model_image(&l.0.cloud, &l.1[ci], devs);
    // The suite's bound, and with SPZ input also the copy's.
    let passes = |m: &Image| {
        !fails(img, m, bound, &c.tolerance) || (judge.copy.is_some() && !judge.fails(img, m))
    };
    if judge.copy.as_ref().is_some_and(&passes) {
        return Some(Allowed::Admitted(Vec::new()));
    }
    // Of the sets it passes with, the one it matches closest is named.
    let closest = super::isolation::admitted_sets(&a.catches, &a.detects)
        .into_iter()
        .filter_map(|ds| {
            let m = model(&ds);
            passes(&m).then(|| (measure(img, &m, bound).0.psnr, ds))
        })
        .max_by(|x, y| x.0.total_cmp(&y.0));
    if let Some((_, ds)) = closest {
        return Some(Allowed::Admitted(ds));
    }
    let degree = l.0.cloud.sh_degree as usize;
    [Variant::ShDegree2, Variant::ShDegree1, Variant::ShDegree0]
        .into_iter()
        .skip(3 - degree.min(3))
        .map(Deviation::Variant)
        .find(|&d| passes(&model(&[d])))
        .map(Allowed::ShCap)
}

/// Compares the images `get(camera)` returns (`None`: missing; `Err`: unreadable) with the
/// references in `dir`; a failing camera is explained with the diagnosis's models, and its
/// `cause` names the deviation the whole run's [`diagnosis()`] attributes it to (or says
/// `unexplained`, with the asset's stock hint). `Err` only when a reference cannot be read
/// (a broken suite).
pub fn run(
    dir: &Path,
    m: &Manifest,
    get: impl FnMut(&CameraEntry) -> Option<Result<Image, String>>,
) -> Result<Vec<AssetResult>, String> {
    run_with(dir, m, &RunOptions::default(), get)
}

/// [`run`] with options (what the images were rendered from).
pub fn run_with(
    dir: &Path,
    m: &Manifest,
    opts: &RunOptions,
    mut get: impl FnMut(&CameraEntry) -> Option<Result<Image, String>>,
) -> Result<Vec<AssetResult>, String> {
    let mut results = Vec::new();
    let mut budget = Budget {
        cameras_left: MAX_EXPLAINED,
        input: opts.input,
    };
    for (ai, a) in m.assets.iter().enumerate() {
        let mut cams = Vec::new();
        let mut loaded = None;
        for (ci, c) in a.cameras.iter().enumerate() {
            let got = get(c);
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

/// The cameras the per-camera search left unexplained, tried with the deviations the
/// diagnosis named for the others ([`diagnosis::explain_with`]), within the run's budget.
fn second_look(
    dir: &Path,
    m: &Manifest,
    budget: &mut Budget,
    results: &mut [AssetResult],
) -> Result<(), String> {
    let named: Vec<_> = diagnosis(results).iter().map(|d| d.deviation).collect();
    if named.len() < 2 {
        return Ok(());
    }
    for (ai, r) in results.iter_mut().enumerate().filter(|(_, r)| !r.skipped) {
        let mut loaded: Loaded = None;
        for (ci, c) in r.cameras.iter_mut().enumerate() {
            let open = !c.pass && c.explained_by.is_empty() && c.against_reference.is_some();
            let Some(img) = c
                .actual
                .as_ref()
                .filter(|_| open && budget.cameras_left > 0)
            else {
                continue;
            };
            let l = loaded.get_or_insert_with(|| load_for_models(dir, m, ai, budget.input));
            let Some(l) = l.as_ref() else {
                break;
            };
            let work = (c.camera.width as u64 * c.camera.height as u64)
                .saturating_mul(l.0.cloud.len() as u64);
            if work > MAX_MODEL_WORK {
                break;
            }
            budget.cameras_left -= 1;
            let (_, bound) = reference_and_bound(dir, &c.camera)?;
            let judge = Judge::new(l, (&r.asset, ci), &bound, budget.input);
            let mut search = Search::new(&l.0.cloud, &l.1[ci], &judge.camera, img, &judge.bound);
            search.closest = c.closest.take();
            c.explained_by = search.explain_with(&named);
            c.closest = search.closest;
        }
    }
    Ok(())
}

/// An unexplained failure with at most this many pixels over their bound (against the
/// model without deviations) gets no stock hint: the hints describe gross failures.
const FEW_PIXELS: usize = 8;

/// At most this many failing cameras are explained with the models in one run (each costs up
/// to ~45 model renders); the rest say "not diagnosed".
const MAX_EXPLAINED: usize = 256;
/// A camera is explained only while pixels × splats stays below this (the model is O(W·H·N)).
const MAX_MODEL_WORK: u64 = 1 << 28;

/// What is left of a run's diagnosis work, and what its images were rendered from.
struct Budget {
    cameras_left: usize,
    input: InputPrecision,
}

/// An asset loaded for the models, once: `None` until needed, `Some(None)` when it failed.
type Loaded = Option<Option<ModelInput>>;

/// The reference and the per-pixel bound of camera `c`.
fn reference_and_bound(dir: &Path, c: &CameraEntry) -> Result<(Image, Vec<f64>), String> {
    let want = Image::read(suite_path(dir, &c.reference_pfm)?).map_err(|e| e.to_string())?;
    if (want.width, want.height) != (c.width, c.height) {
        return Err(format!(
            "{}: {}x{}, the manifest says {}x{}",
            c.reference_pfm, want.width, want.height, c.width, c.height
        ));
    }
    let want = clamped(&want);
    let bound: Vec<f64> = Image::read(suite_path(dir, &c.bound_pfm)?)
        .map_err(|e| e.to_string())?
        .pixels
        .iter()
        .map(|p| p[0] as f64)
        .collect();
    if bound.len() != want.pixels.len() {
        return Err(format!("{}: wrong size", c.bound_pfm));
    }
    let mask = Image::read(suite_path(dir, &c.judge_mask)?).map_err(|e| e.to_string())?;
    if mask.pixels.len() != want.pixels.len() {
        return Err(format!("{}: wrong size", c.judge_mask));
    }
    let judged: Vec<bool> = mask.pixels.iter().map(|p| p[0] > 0.5).collect();
    let mut bound = bound;
    super::judge::apply(&mut bound, &judged);
    Ok((want, bound))
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
        let l = loaded.get_or_insert_with(|| load_for_models(dir, m, ai, budget.input));
        let note = allow_or_explain(
            l.as_ref(),
            (&m.assets[ai], ci),
            &img,
            &bound,
            budget,
            &mut r,
        );
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
    Some((scene, cams))
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

/// A failing camera `ci` (of result `r`) with the image `img`, and the asset loaded as `l`:
/// passed when it matches an RC-allowed SH cap (or, with SPZ input, its SPZ copy), else
/// explained with the models while the budget and the model's work allow; returns the note
/// for the cause when it is not diagnosed (else empty).
fn allow_or_explain(
    l: Option<&ModelInput>,
    (asset, ci): (&AssetEntry, usize),
    img: &Image,
    bound: &[f64],
    budget: &mut Budget,
    r: &mut CameraResult,
) -> String {
    let c = &r.camera;
    let work = l.map_or(u64::MAX, |l| {
        (c.width as u64 * c.height as u64).saturating_mul(l.0.cloud.len() as u64)
    });
    match l {
        Some(l) if work <= MAX_MODEL_WORK => {
            let judge = Judge::new(l, (asset, ci), bound, budget.input);
            if let Some(d) = allowed_choice(l, (asset, ci), (bound, &judge), img) {
                r.pass = true;
                r.cause = Some(match d {
                    Allowed::ShCap(d) => format!(
                        "passes as a renderer that {} (the RC allows it: {})",
                        d.describe().to_lowercase(),
                        d.rc_section()
                    ),
                    Allowed::Admitted(ds) if ds.is_empty() => "passes against the SPZ copy it was rendered from (--input-precision spz: the model of what KHR_gaussian_splatting_compression_spz_2 carries)".into(),
                    Allowed::Admitted(ds) => format!(
                        "passes {}as a renderer with {}, which this asset admits (it does not test it)",
                        if judge.copy.is_some() { "against the SPZ copy it was rendered from (--input-precision spz) " } else { "" },
                        rule_names(&ds)
                    ),
                });
            } else if budget.cameras_left > 0 {
                budget.cameras_left -= 1;
                let mut search =
                    Search::new(&l.0.cloud, &l.1[ci], &judge.camera, img, &judge.bound);
                r.explained_by = search.explain();
                r.baseline_over = Some(search.baseline_over());
                r.closest = search.closest;
            } else {
                return format!(
                    "{}not diagnosed (the run's diagnosis budget is spent); ",
                    against_copy(&judge, img)
                );
            }
            against_copy(&judge, img)
        }
        Some(_) => "not diagnosed (too large for the models); ".into(),
        None => "not diagnosed (the asset does not load); ".into(),
    }
}

/// With SPZ input, how far `img` is from the model of the SPZ copy it was rendered from,
/// under the copy's bound (the pixel count above is against the float reference), for the
/// cause; empty otherwise.
fn against_copy(judge: &Judge, img: &Image) -> String {
    let Some(m) = &judge.copy else {
        return String::new();
    };
    let (_, ratio) = measure(img, m, &judge.bound);
    format!(
        "against its SPZ copy {} (worst {ratio:.2}×); ",
        match over_bound(img, m, &judge.bound) {
            0 => "no pixel over its bound, but the PSNR or largest error fails".to_owned(),
            n => format!("{n} pixels over their bound"),
        }
    )
}

/// The failing cameras that had an image to explain.
fn failures(results: &[AssetResult]) -> Vec<Failure<'_>> {
    results
        .iter()
        .filter(|r| !r.skipped)
        .flat_map(|r| {
            r.cameras.iter().filter(|c| !c.pass).filter_map(|c| {
                Some(Failure {
                    asset: &r.asset,
                    camera: &c.camera,
                    reference: c.against_reference?,
                    explained_by: &c.explained_by,
                })
            })
        })
        .collect()
}

/// The deviations that an asset which passed catches (its `catches` errata) or detects (its
/// `detects` variants): a renderer with one of them would have failed it.
fn contradicted(results: &[AssetResult]) -> Vec<diagnosis::Deviation> {
    use diagnosis::Deviation;
    let mut out = Vec::new();
    for r in results.iter().filter(|r| !r.skipped && r.pass()) {
        out.extend(r.asset.catches.iter().map(|&e| Deviation::Erratum(e)));
        out.extend(
            super::model::Variant::ALL
                .into_iter()
                .filter(|v| r.asset.detects.iter().any(|n| n == v.name()))
                .map(Deviation::Variant),
        );
    }
    out.sort();
    out.dedup();
    out
}

/// The smallest set of deviations that explains every failing camera of a run (see
/// [`diagnosis::diagnose`]).
pub fn diagnosis(results: &[AssetResult]) -> Vec<Diagnosis> {
    diagnosis::diagnose(&failures(results), &contradicted(results)).0
}

/// `a + b + …` of the deviations' rule names.
fn rule_names(devs: &[Deviation]) -> String {
    let names: Vec<String> = devs.iter().map(|d| d.name()).collect();
    names.join(" + ")
}

/// Completes each explained failure's `cause` with the deviation the diagnosis attributes it
/// to, or `unexplained` and the asset's stock hint.
fn name_causes(results: &mut [AssetResult]) {
    let (_, assigned) = diagnosis::diagnose(&failures(results), &contradicted(results));
    let mut it = assigned.into_iter();
    for r in results.iter_mut().filter(|r| !r.skipped) {
        let hint = r.asset.failure_means.clone();
        for c in r.cameras.iter_mut().filter(|c| !c.pass) {
            if c.against_reference.is_none() {
                continue;
            }
            let text = match it.next().flatten() {
                Some(e) => {
                    c.closest = None;
                    let what: Vec<String> = e.deviations.iter().map(|d| d.describe()).collect();
                    format!(
                        "explained by {} ({:.1} dB against that model)",
                        what.join(" + "),
                        e.psnr
                    )
                }
                None => match &c.closest {
                    // Far nearer to a model than to the correct one: the stock hint (a guess
                    // from the reference alone) would name a fault the model rules out.
                    Some(n) if n.over * 4 <= n.baseline_over => format!(
                        "unexplained, a near miss of {} ({} pixels over their bound, worst {:.2}×)",
                        rule_names(&n.deviations),
                        n.over,
                        n.worst
                    ),
                    Some(n) => format!(
                        "unexplained (nearest: {}, {} pixels over their bound): {hint}",
                        rule_names(&n.deviations),
                        n.over
                    ),
                    // A few stray pixels match no failure pattern: the hint would mislead.
                    None => match c.baseline_over.filter(|&n| n <= FEW_PIXELS) {
                        Some(n) => format!(
                            "unexplained: {n} pixels over their bound, too few for any rule's failure pattern (likely a renderer's rounding that the models do not follow)"
                        ),
                        None => format!("unexplained: {hint}"),
                    },
                },
            };
            c.cause = Some(c.cause.take().unwrap_or_default() + &text);
        }
    }
}
