//! Explaining failures with models: each failing camera's image is tested against the f64
//! model ([`super::model`]) with known deviations switched on — the review draft's errata,
//! the implementation [`Variant`]s, flipped images — singly, in pairs and in triples; then the smallest
//! set of deviations that explains every failing camera is chosen ([`diagnose`]).
//!
//! A deviation *explains* a camera when the image passes that camera's tolerance (per-pixel
//! bound, `max_abs`, `min_psnr`) against the model rendered with the deviation instead of
//! against the reference.

use super::Erratum;
pub use super::deviation::Deviation;
use super::manifest::{AssetEntry, CameraEntry};
use super::model::{self, Variant};
use super::verdict::{measure, over_bound};
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::image::Image;

/// One candidate that explains a camera, with its evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct Explanation {
    /// The deviations switched on (one to three).
    pub deviations: Vec<Deviation>,
    /// PSNR of the image against the model with them.
    pub psnr: f64,
    /// Largest error against it.
    pub max_abs: f64,
}

/// The image a renderer with `devs` draws for `cam` (the model's, display RGB).
pub fn model_image(cloud: &SplatCloud, cam: &Camera, devs: &[Deviation]) -> Image {
    let errata: Vec<Erratum> = devs
        .iter()
        .filter_map(|d| match d {
            Deviation::Erratum(e) => Some(*e),
            _ => None,
        })
        .collect();
    let variants: Vec<Variant> = devs
        .iter()
        .filter_map(|d| match d {
            Deviation::Variant(v) => Some(*v),
            _ => None,
        })
        .collect();
    let dilation = devs.iter().find_map(|d| match d {
        Deviation::Dilation(m) => Some(f64::from(*m) / 1000.0),
        _ => None,
    });
    let mut img = match dilation {
        Some(d) => model::render_with_dilation(cloud, cam, (&errata, &variants), None, d).image,
        None => model::render_with(cloud, cam, &errata, &variants).image,
    };
    if devs.contains(&Deviation::UpsideDown) {
        img = flipped(&img, true);
    }
    if devs.contains(&Deviation::Mirrored) {
        img = flipped(&img, false);
    }
    img
}

/// `img` flipped vertically (`vertical`) or mirrored left-right.
pub fn flipped(img: &Image, vertical: bool) -> Image {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut out = img.clone();
    for y in 0..h {
        for x in 0..w {
            let (sx, sy) = if vertical {
                (x, h - 1 - y)
            } else {
                (w - 1 - x, y)
            };
            out.pixels[y * w + x] = img.pixels[sy * w + sx];
        }
    }
    out
}

/// At most this many of the single deviations that bring the image closest are combined
/// (in pairs, then triples: 10 + 10 model renders at most).
const PAIRED: usize = 5;

/// The `k`-element subsets of `items`, in order.
fn combinations(items: &[Deviation], k: usize) -> Vec<Vec<Deviation>> {
    if k == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for (i, d) in items.iter().enumerate() {
        for mut rest in combinations(&items[i + 1..], k - 1) {
            rest.insert(0, *d);
            out.push(rest);
        }
    }
    out
}

/// The nearest the search came for a camera that nothing explains: the deviations whose
/// model the image is closest to (fewest pixels over their bound, then the smaller worst
/// ratio), when that is clearly nearer (by a quarter of its pixels over) than the model without
/// any deviation.
#[derive(Debug, Clone, PartialEq)]
pub struct Closest {
    /// The deviations switched on.
    pub deviations: Vec<Deviation>,
    /// Pixels over their bound against that model.
    pub over: usize,
    /// The largest ratio of a pixel's error to its bound against it.
    pub worst: f64,
    /// Pixels over their bound against the model without deviations (the reference, or
    /// with SPZ input the SPZ copy): at least ⁴⁄₃ of `over`.
    pub baseline_over: usize,
}

/// One camera's search: the image, what it is judged by, and the nearest model so far.
pub struct Search<'a> {
    cloud: &'a SplatCloud,
    cam: &'a Camera,
    camera: &'a CameraEntry,
    actual: &'a Image,
    bound: &'a [f64],
    /// Pixels over their bound against the model without deviations.
    baseline_over: usize,
    /// The nearest model tried so far that is nearer than the baseline (updated by every
    /// set scored).
    pub closest: Option<Closest>,
}

impl<'a> Search<'a> {
    /// A search for `actual`, splatgl's camera `cam` of `cloud` and its manifest entry
    /// `camera` with the per-pixel `bound`.
    pub fn new(
        cloud: &'a SplatCloud,
        cam: &'a Camera,
        camera: &'a CameraEntry,
        actual: &'a Image,
        bound: &'a [f64],
    ) -> Self {
        let m = model_image(cloud, cam, &[]);
        Search {
            cloud,
            cam,
            camera,
            actual,
            bound,
            baseline_over: over_bound(actual, &m, bound),
            closest: None,
        }
    }

    /// Pixels over their bound against the model without deviations (the reference, or with
    /// SPZ input the SPZ copy).
    pub fn baseline_over(&self) -> usize {
        self.baseline_over
    }

    /// `devs` tried: the explanation when the image passes the camera's tolerance against
    /// the model with them, else `None`; its PSNR against that model either way.
    fn score(&mut self, devs: &[Deviation]) -> (Option<Explanation>, f64) {
        let m = model_image(self.cloud, self.cam, devs);
        let (c, ratio) = measure(self.actual, &m, self.bound);
        let t = &self.camera.tolerance;
        let ok = ratio <= 1.0 && c.max_abs as f64 <= t.max_abs && c.psnr >= t.min_psnr;
        let over = over_bound(self.actual, &m, self.bound);
        // Nearer by a quarter of the baseline's pixels at least: a pixel or two fewer is noise.
        let nearer = over * 4 <= self.baseline_over * 3
            && over < self.baseline_over
            && self
                .closest
                .as_ref()
                .is_none_or(|b| (over, ratio) < (b.over, b.worst));
        if !ok && nearer && ratio.is_finite() {
            self.closest = Some(Closest {
                deviations: devs.to_vec(),
                over,
                worst: ratio,
                baseline_over: self.baseline_over,
            });
        }
        let e = ok.then(|| Explanation {
            deviations: devs.to_vec(),
            psnr: c.psnr,
            max_abs: c.max_abs as f64,
        });
        (e, c.psnr)
    }

    /// The candidates (single deviations, then pairs and triples of the singles that come
    /// closest) that explain the camera: the image passes its tolerance against the model
    /// with them.
    pub fn explain(&mut self) -> Vec<Explanation> {
        let mut singles = Vec::new();
        let mut out = Vec::new();
        for d in Deviation::all() {
            let (e, psnr) = self.score(&[d]);
            out.extend(e);
            singles.push((psnr, d));
        }
        if !out.is_empty() {
            return out;
        }
        singles.sort_by(|a, b| b.0.total_cmp(&a.0));
        let best: Vec<Deviation> = singles.iter().take(PAIRED).map(|(_, d)| *d).collect();
        // Pairs, then (only when no pair explains it) triples of the closest singles.
        for size in [2, 3] {
            self.sets(&best, size, &mut out);
            if !out.is_empty() {
                break;
            }
        }
        out
    }

    /// A second look at a camera [`Search::explain`] left unexplained, with `named`, the
    /// deviations the run's diagnosis chose for its other cameras: a renderer has one set of
    /// deviations, and a camera may need more of them at once than the pairs and triples of
    /// the deviations that come closest alone (Spark's packed precision, 2.83σ cut and
    /// compensation). Subsets of two or more (of the first [`SECOND_LOOK`]), smallest first;
    /// the explaining sets of the first size that has any.
    pub fn explain_with(&mut self, named: &[Deviation]) -> Vec<Explanation> {
        let named = &named[..named.len().min(SECOND_LOOK)];
        let mut out = Vec::new();
        for size in 2..=named.len() {
            self.sets(named, size, &mut out);
            if !out.is_empty() {
                break;
            }
        }
        let no_dilation = Deviation::Erratum(Erratum::I);
        if out.is_empty() && named.contains(&no_dilation) {
            let others: Vec<Deviation> = named
                .iter()
                .copied()
                .filter(|d| *d != no_dilation)
                .collect();
            self.estimate_dilation(&others, &mut out);
        }
        out
    }

    /// The dilation estimated from the image: with each set of at most [`DILATION_WITH`] of
    /// `others` (none included), Σ' dilated by every value of [`DILATION_GRID`] is tried; the
    /// sets that then explain the camera go into `out` (every value that does, so that the
    /// run's cover can pick the one most cameras share).
    fn estimate_dilation(&mut self, others: &[Deviation], out: &mut Vec<Explanation>) {
        for size in 0..=others.len().min(DILATION_WITH) {
            for set in combinations(others, size) {
                for m in DILATION_GRID.into_iter().filter(|m| *m != 300) {
                    let mut with = set.clone();
                    with.push(Deviation::Dilation(m));
                    if let (Some(e), _) = self.score(&with) {
                        out.push(e);
                    }
                }
            }
            if !out.is_empty() {
                return;
            }
        }
    }

    /// The `size`-element subsets of `items` that explain the camera, into `out`.
    fn sets(&mut self, items: &[Deviation], size: usize, out: &mut Vec<Explanation>) {
        for set in combinations(items, size) {
            if let (Some(e), _) = self.score(&set) {
                out.push(e);
            }
        }
    }
}

/// The dilations (thousandths of a px²) [`Search::explain_with`] estimates between: 0 to
/// 0.6 px² in steps of 0.025.
const DILATION_GRID: [u16; 25] = {
    let mut g = [0u16; 25];
    let mut i = 0;
    while i < 25 {
        g[i] = 25 * i as u16;
        i += 1;
    }
    g
};

/// At most this many other deviations go with an estimated dilation.
const DILATION_WITH: usize = 2;

/// At most this many of a run's named deviations are combined on a second look.
pub const SECOND_LOOK: usize = 6;

/// Evidence for one camera: the image against the reference and against the deviation's
/// model.
#[derive(Debug, Clone, PartialEq)]
pub struct Evidence {
    /// `ASSET/CAMERA`.
    pub image: String,
    /// PSNR and max error against splatgl's reference.
    pub reference: (f64, f64),
    /// PSNR and max error against the model with the deviation(s).
    pub model: (f64, f64),
}

/// One entry of the diagnosis: a deviation and the failing cameras it explains.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnosis {
    /// The deviation.
    pub deviation: Deviation,
    /// Assets with a camera it explains.
    pub assets: Vec<String>,
    /// Per explained camera.
    pub evidence: Vec<Evidence>,
}

/// A failing camera and what explains it.
#[derive(Debug, Clone)]
pub struct Failure<'a> {
    /// Its asset.
    pub asset: &'a AssetEntry,
    /// The camera.
    pub camera: &'a CameraEntry,
    /// PSNR and max error against the reference.
    pub reference: (f64, f64),
    /// The candidates that explain it.
    pub explained_by: &'a [Explanation],
}

/// The smallest set of deviations that explains the failures, greedily: the candidate that
/// explains most of the cameras not yet explained is taken (a pair brings both its
/// deviations), until no candidate explains another; ties go to the earlier deviation.
/// Returns the entries and, per failure, the candidate chosen for it (`None`: unexplained).
///
/// Deviations in `contradicted` (those an asset that *passed* is known to catch or detect: a
/// renderer with them would have failed it) are chosen only after every consistent
/// explanation: a tiny sub-pixel asset cannot tell erratum d from an eigenvalue floor, the
/// passing assets can.
pub fn diagnose(
    failures: &[Failure],
    contradicted: &[Deviation],
) -> (Vec<Diagnosis>, Vec<Option<Explanation>>) {
    let mut chosen: Vec<Deviation> = Vec::new();
    let mut assigned: Vec<Option<Explanation>> = vec![None; failures.len()];
    while let Some(devs) = best_candidate(failures, &assigned, &chosen, contradicted) {
        chosen.extend(
            devs.iter()
                .copied()
                .filter(|d| !chosen.contains(d))
                .collect::<Vec<_>>(),
        );
        for (f, a) in failures.iter().zip(assigned.iter_mut()) {
            if a.is_none() {
                *a = f
                    .explained_by
                    .iter()
                    .filter(|x| covered(x, &chosen))
                    .max_by(|x, y| x.psnr.total_cmp(&y.psnr))
                    .cloned();
            }
        }
    }
    (entries(failures, &assigned), assigned)
}

/// Whether every deviation of `e` is among `with`.
fn covered(e: &Explanation, with: &[Deviation]) -> bool {
    e.deviations.iter().all(|d| with.contains(d))
}

/// The next deviation set of [`diagnose`]'s cover (`None` when none explains another open
/// camera). Candidates: every distinct set that explains some camera still open. Key:
/// consistent with the passing assets, the open cameras it (with what is `chosen`) would
/// explain, then how closely (the sum of the best PSNRs, capped at 200 dB each).
fn best_candidate(
    failures: &[Failure],
    assigned: &[Option<Explanation>],
    chosen: &[Deviation],
    contradicted: &[Deviation],
) -> Option<Vec<Deviation>> {
    let open = || failures.iter().zip(assigned).filter(|(_, a)| a.is_none());
    let mut candidates: Vec<&Vec<Deviation>> = open()
        .flat_map(|(f, _)| f.explained_by.iter().map(|e| &e.deviations))
        .collect();
    candidates.sort();
    candidates.dedup();
    let mut best: Option<((bool, usize, f64), Vec<Deviation>)> = None;
    for devs in candidates {
        let mut with = chosen.to_vec();
        with.extend(devs.iter().copied());
        let (mut n, mut fit) = (0, 0.0);
        for (g, _) in open() {
            let psnr = g
                .explained_by
                .iter()
                .filter(|x| covered(x, &with))
                .map(|x| x.psnr.min(200.0))
                .fold(f64::NEG_INFINITY, f64::max);
            if psnr > f64::NEG_INFINITY {
                n += 1;
                fit += psnr;
            }
        }
        let consistent = !devs.iter().any(|d| contradicted.contains(d));
        let key = (consistent && n > 0, n, fit);
        if best.as_ref().is_none_or(|(m, _)| key > *m) {
            best = Some((key, devs.clone()));
        }
    }
    best.filter(|((_, n, _), _)| *n > 0).map(|(_, devs)| devs)
}

/// [`diagnose`]'s entries: per deviation of the chosen explanations, the assets and the
/// evidence of the cameras it explains (in the failures' order).
fn entries(failures: &[Failure], assigned: &[Option<Explanation>]) -> Vec<Diagnosis> {
    let mut entries: Vec<Diagnosis> = Vec::new();
    for (f, a) in failures.iter().zip(assigned) {
        let Some(e) = a else { continue };
        for d in &e.deviations {
            let entry = match entries.iter_mut().position(|x| x.deviation == *d) {
                Some(i) => &mut entries[i],
                None => {
                    entries.push(Diagnosis {
                        deviation: *d,
                        assets: Vec::new(),
                        evidence: Vec::new(),
                    });
                    entries.last_mut().expect("just pushed")
                }
            };
            if !entry.assets.contains(&f.asset.name) {
                entry.assets.push(f.asset.name.clone());
            }
            entry.evidence.push(Evidence {
                image: f.camera.image.clone(),
                reference: f.reference,
                model: (e.psnr, e.max_abs),
            });
        }
    }
    entries
}
