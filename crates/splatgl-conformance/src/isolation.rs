//! Isolation by terms: the small choices an asset's bound admits because the asset does not
//! test them (`docs/conformance.md`, "The RC-silent choices"), so that a renderer making them
//! fails only the assets designed for them. The large ones are left out of the judged region
//! ([`super::judge`]).

use super::Erratum;
use super::assets::AssetSpec;
use super::deviation::Deviation;
use super::model::{self, Variant};
use splatgl::camera::Camera;
use splatgl::image::Image;

/// The field of [`model::Terms`] a deviation widens.
type TermField = fn(&mut model::Terms) -> &mut f64;

/// The small choices every asset's bound admits unless it is designed to detect them, each
/// with the [`model::Terms`] field it widens: choices about Σ' at the scale of a pixel and
/// about storage precision, which change a pixel by a fraction of what a rule does. (The
/// choices that move whole rims or swap overlapping splats — the extent of a splat, the
/// blending order — are left out of the judged region instead, [`super::judge`].)
/// - the dilation of Σ' (erratum i: none; 0.1–0.3 px² in between): an RC-silent choice (the
///   RC leaves Σ' to "the same forward pass algorithm used during training"), detected by
///   `subpixel_dilation`, a profile asset;
/// - 8-bit storage of the DC colour and the opacity (rounded down), and half-float storage
///   of the 3D covariance: precisions the RC does not specify, admitted everywhere;
/// - Σ' rebuilt from eigenvalues floored at mid ± √0.1 (GaussianSplats3D's numerical
///   safeguard): like the dilation, detected by `subpixel_dilation` alone.
const ISOLATED: [(Deviation, TermField); 4] = [
    (Deviation::Erratum(Erratum::I), |t| &mut t.dilation),
    (Deviation::Variant(Variant::Colour8Bit), |t| {
        &mut t.colour_8bit
    }),
    (Deviation::Variant(Variant::HalfCovariance), |t| {
        &mut t.covariance_f16
    }),
    (Deviation::Variant(Variant::EigenvalueFloor), |t| {
        &mut t.eigenvalue_floor
    }),
];

/// Whether `spec` is designed to detect `d` (then its bound does not admit it).
fn detects(spec: &AssetSpec, d: Deviation) -> bool {
    match d {
        Deviation::Erratum(e) => spec.designed_for.contains(&e),
        Deviation::Variant(v) => spec.detects.contains(&v),
        _ => false,
    }
}

/// The errata `spec`'s bound admits (their margin check is skipped: they are not its to
/// catch).
pub(crate) fn admitted_errata(spec: &AssetSpec) -> Vec<Erratum> {
    ISOLATED
        .iter()
        .filter_map(|(d, _)| match d {
            Deviation::Erratum(e) if !detects(spec, *d) => Some(*e),
            _ => None,
        })
        .collect()
}

/// The deviations of [`ISOLATED`] that an asset which catches `catches` and detects
/// `detects` (its manifest entry) admits.
fn admitted_by(catches: &[Erratum], detects: &[String]) -> Vec<(Deviation, TermField)> {
    ISOLATED
        .iter()
        .copied()
        .filter(|&(d, _)| match d {
            Deviation::Erratum(e) => !catches.contains(&e),
            Deviation::Variant(v) => !detects.iter().any(|n| n == v.name()),
            _ => true,
        })
        .collect()
}

/// Whether two term fields are the same one (alternatives such as the cut-off shapes).
fn same_term(a: TermField, b: TermField) -> bool {
    let mut t = model::Terms::default();
    *a(&mut t) = 1.0;
    *b(&mut t) == 1.0
}

/// The deviations an asset that catches `catches` and detects `detects` admits (its bound is
/// widened for them), singly and in pairs of different terms, as the diagnosis names them:
/// what an image may still show and pass as (the runner's admitted choices).
pub(crate) fn admitted_sets(catches: &[Erratum], detects: &[String]) -> Vec<Vec<Deviation>> {
    let admitted = admitted_by(catches, detects);
    let mut out: Vec<Vec<Deviation>> = admitted.iter().map(|(d, _)| vec![*d]).collect();
    for (i, (a, fa)) in admitted.iter().enumerate() {
        for (b, fb) in &admitted[i + 1..] {
            if !same_term(*fa, *fb) {
                out.push(vec![*a, *b]);
            }
        }
    }
    out
}

/// The model images with the deviations `ds` at once: one, or where `ds` holds the eigenvalue
/// floor, one per major axis f32 rounding allows it ([`model::axis_samples`]) besides the
/// representative one — the term admits whichever GaussianSplats3D's rounding picks.
fn render_admitted(cloud: &splatgl::SplatCloud, cam: &Camera, ds: &[Deviation]) -> Vec<Image> {
    let (errata, variants) = split(ds);
    let mut axes = vec![None];
    if variants.contains(&Variant::EigenvalueFloor) {
        axes.extend(model::axis_samples.map(Some));
    }
    axes.into_iter()
        .map(|axis| model::render_with_axis(cloud, cam, &errata, &variants, axis).image)
        .collect()
}

/// The errata and the variants of `ds`.
fn split(ds: &[Deviation]) -> (Vec<Erratum>, Vec<Variant>) {
    let mut out = (Vec::new(), Vec::new());
    for d in ds {
        match *d {
            Deviation::Erratum(e) => out.0.push(e),
            Deviation::Variant(v) => out.1.push(v),
            _ => {}
        }
    }
    out
}

/// The largest channel difference at pixel `i` between `a` and any of `others`.
fn diff_at(a: &Image, others: &[Image], i: usize) -> f64 {
    let p = a.pixels[i];
    others
        .iter()
        .flat_map(|o| (0..3).map(move |k| (p[k] as f64 - o.pixels[i][k] as f64).abs()))
        .fold(0.0, f64::max)
}

/// Widens the bound by every deviation `spec` admits: per pixel, the largest channel
/// difference between the model with and without it, added to its term; then by what two or
/// three of them do together beyond the sum of their terms (`combined`), so a renderer that
/// makes several of the admitted choices at once (GaussianSplats3D: the 2.83σ cut, the
/// eigenvalue floor, 8-bit colour, half-float covariances) passes as one that makes one.
pub(crate) fn admit(
    exact: &mut model::ModelImage,
    spec: &AssetSpec,
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
) {
    let admitted: Vec<(Deviation, TermField)> = ISOLATED
        .iter()
        .copied()
        .filter(|(d, _)| !detects(spec, *d))
        .collect();
    admit_all(exact, &admitted, cloud, cam);
    if spec.detects.contains(&Variant::Unorm8Blending) {
        drop_overbright(exact);
    }
}

/// Takes the `overbright` term out of `exact`'s bound: the asset tests float blending, so an
/// 8-bit target's clamping is what it judges.
fn drop_overbright(exact: &mut model::ModelImage) {
    for (b, o) in exact.bound.iter_mut().zip(&exact.overbright) {
        *b = (*b - o).max(0.0);
    }
}

/// [`admit`] with the admitted deviations given.
fn admit_all(
    exact: &mut model::ModelImage,
    admitted: &[(Deviation, TermField)],
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
) {
    let mut worst = model::Terms::default();
    for (d, field) in admitted {
        let others = render_admitted(cloud, cam, &[*d]);
        // Terms of one field (the two cut-off shapes) take the larger difference.
        let mut per_field = model::Terms::default();
        for i in 0..exact.bound.len() {
            let diff = diff_at(&exact.image, &others, i);
            let extra = (diff - *field(&mut exact.extra[i])).max(0.0);
            *field(&mut exact.extra[i]) += extra;
            exact.bound[i] += extra;
            let w = field(&mut per_field);
            *w = w.max(*field(&mut exact.extra[i]));
        }
        worst = worst.max(per_field);
    }
    worst.combined = admit_combined(exact, admitted, cloud, cam);
    exact.worst = exact.worst.max(worst);
}

/// The `combined` term: per pixel, the most that any two or three admitted deviations
/// together change the image beyond the sum of their own terms there. Pairs of the same term
/// (the two cut-off shapes) are alternatives, not a combination, and are skipped.
fn admit_combined(
    exact: &mut model::ModelImage,
    admitted: &[(Deviation, TermField)],
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
) -> f64 {
    let n = admitted.len();
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            sets.push(vec![i, j]);
            for k in j + 1..n {
                sets.push(vec![i, j, k]);
            }
        }
    }
    let same_term = |a: usize, b: usize| same_term(admitted[a].1, admitted[b].1);
    sets.retain(|s| {
        s.iter()
            .enumerate()
            .all(|(x, &a)| s[x + 1..].iter().all(|&b| !same_term(a, b)))
    });
    let mut worst = 0.0f64;
    for s in sets {
        let ds: Vec<Deviation> = s.iter().map(|&i| admitted[i].0).collect();
        let others = render_admitted(cloud, cam, &ds);
        for i in 0..exact.bound.len() {
            let mut own: f64 = 0.0;
            for &k in &s {
                own += *(admitted[k].1)(&mut exact.extra[i]);
            }
            let beyond = diff_at(&exact.image, &others, i) - own - exact.extra[i].combined;
            if beyond > 0.0 {
                exact.extra[i].combined += beyond;
                exact.bound[i] += beyond;
            }
            worst = worst.max(exact.extra[i].combined);
        }
    }
    worst
}

/// The model of `cloud` seen by `cam` and the bound the suite's generator derives around it
/// for an asset that catches `catches` and detects `detects`: the model's own terms and every
/// deviation the asset admits, alone, in pairs and in triples ([`admit`]). The runner judges
/// an image rendered from an asset's SPZ copy by it (`cloud` the copy): the admitted choices
/// then act on the copy's footprints, which differ a little from the asset's.
pub(crate) fn derived_bound(
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
    (catches, detects): (&[Erratum], &[String]),
) -> model::ModelImage {
    let mut exact = model::render(cloud, cam, &[]);
    admit_all(&mut exact, &admitted_by(catches, detects), cloud, cam);
    if detects.iter().any(|d| d == Variant::Unorm8Blending.name()) {
        drop_overbright(&mut exact);
    }
    exact
}
