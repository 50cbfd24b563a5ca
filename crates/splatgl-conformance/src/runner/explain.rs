//! Explaining failures: the models' search per camera ([`allow_or_explain`]), the second
//! look with the deviations named for the others ([`second_look`]), the run's diagnosis and
//! each failure's cause ([`name_causes`]).

use super::judge::{Allowed, Judge, against_copy, allowed_choice, reference_and_bound};
use super::{AssetResult, CameraResult, InputPrecision, Loaded, ModelInput, load_for_models};
use crate::diagnosis::{self, Deviation, Diagnosis, Failure, Search};
use crate::manifest::{AssetEntry, Manifest};
use splatgl::image::Image;
use std::path::Path;

/// The cameras the per-camera search left unexplained, tried with the deviations the
/// diagnosis named for the others ([`diagnosis::explain_with`]), within the run's budget.
pub(super) fn second_look(
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
        let mut loaded = Loaded::default();
        for (ci, c) in r.cameras.iter_mut().enumerate() {
            let open = !c.pass && c.explained_by.is_empty() && c.against_reference.is_some();
            let Some(img) = c
                .actual
                .as_ref()
                .filter(|_| open && budget.cameras_left > 0)
            else {
                continue;
            };
            let input = budget.input;
            let Some(l) = loaded.get(|| load_for_models(dir, m, ai, input)) else {
                break;
            };
            let work = (c.camera.width as u64 * c.camera.height as u64)
                .saturating_mul(l.scene.cloud.len() as u64);
            if work > MAX_MODEL_WORK {
                break;
            }
            budget.cameras_left -= 1;
            let (_, bound) = reference_and_bound(dir, &c.camera)?;
            let judge = Judge::new(l, (&r.asset, ci), &bound, budget.input);
            let mut search = Search::new(
                &l.scene.cloud,
                &l.cameras[ci],
                &judge.camera,
                img,
                &judge.bound,
            );
            search.closest = c.closest.take();
            c.explained_by = search.explain_with(&named);
            c.closest = search.closest;
        }
    }
    Ok(())
}

/// An unexplained failure with at most this many pixels over their bound (against the
/// model without deviations) gets no stock hint: the hints describe gross failures.
pub(super) const FEW_PIXELS: usize = 8;

/// At most this many failing cameras are explained with the models in one run (each costs up
/// to ~45 model renders); the rest say "not diagnosed".
pub(super) const MAX_EXPLAINED: usize = 256;

/// A camera is explained only while pixels × splats stays below this (the model is O(W·H·N)).
pub(super) const MAX_MODEL_WORK: u64 = 1 << 28;

/// What is left of a run's diagnosis work, and what its images were rendered from.
pub(super) struct Budget {
    pub(super) cameras_left: usize,
    pub(super) input: InputPrecision,
}

/// A failing camera `ci` (of result `r`) with the image `img`, and the asset loaded as `l`:
/// passed when it matches an RC-allowed SH cap (or, with SPZ input, its SPZ copy), else
/// explained with the models while the budget and the model's work allow; returns the note
/// for the cause when it is not diagnosed (else empty).
pub(super) fn allow_or_explain(
    l: Option<&ModelInput>,
    (asset, ci): (&AssetEntry, usize),
    img: &Image,
    bound: &[f64],
    budget: &mut Budget,
    r: &mut CameraResult,
) -> String {
    let c = &r.camera;
    let work = l.map_or(u64::MAX, |l| {
        (c.width as u64 * c.height as u64).saturating_mul(l.scene.cloud.len() as u64)
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
                let mut search = Search::new(
                    &l.scene.cloud,
                    &l.cameras[ci],
                    &judge.camera,
                    img,
                    &judge.bound,
                );
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

/// The failing cameras that had an image to explain.
pub(super) fn failures(results: &[AssetResult]) -> Vec<Failure<'_>> {
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
pub(super) fn contradicted(results: &[AssetResult]) -> Vec<diagnosis::Deviation> {
    use diagnosis::Deviation;
    let mut out = Vec::new();
    for r in results.iter().filter(|r| !r.skipped && r.pass()) {
        out.extend(r.asset.catches.iter().map(|&e| Deviation::Erratum(e)));
        out.extend(
            crate::model::Variant::ALL
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
pub(super) fn rule_names(devs: &[Deviation]) -> String {
    let names: Vec<String> = devs.iter().map(|d| d.name()).collect();
    names.join(" + ")
}

/// Completes each explained failure's `cause` with the deviation the diagnosis attributes it
/// to, or `unexplained` and the asset's stock hint.
pub(super) fn name_causes(results: &mut [AssetResult]) {
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
