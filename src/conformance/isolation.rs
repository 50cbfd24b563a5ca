//! Isolation: the deviations an asset's bound admits because the asset does not test them
//! (`docs/conformance.md`, "RC rules and profile choices"), so that a renderer with one of
//! them fails only the assets designed for it.

use super::Erratum;
use super::assets::AssetSpec;
use super::model::{self, Variant};
use crate::camera::Camera;

/// A deviation an asset's bound can admit: an erratum or an implementation variant.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Admitted {
    Erratum(Erratum),
    Variant(Variant),
}

/// The field of [`model::Terms`] a deviation widens.
type TermField = fn(&mut model::Terms) -> &mut f64;

/// The deviations every asset admits unless it is designed to detect them, each with the
/// [`model::Terms`] field it widens. Isolation: a renderer that makes one of them fails the
/// assets designed for it and no other.
/// - the 0.3 px² dilation (erratum i): an RC-silent choice (the RC leaves Σ' to "the same
///   forward pass algorithm used during training"), detected by `subpixel_dilation`;
/// - the shape of the cut-off (erratum f's 2.83σ, a 3.33σ bounding box): an RC rule,
///   detected by `cutoff_three_sigma` alone;
/// - the order by view depth instead of camera distance: an RC rule, detected by the sorting
///   assets;
/// - 8-bit storage of the DC colour and the opacity (rounded down): a precision the RC does
///   not specify, admitted everywhere (no asset detects it).
const ISOLATED: [(Admitted, TermField); 5] = [
    (Admitted::Erratum(Erratum::I), |t| &mut t.dilation),
    (Admitted::Erratum(Erratum::F), |t| &mut t.cutoff_shape),
    (Admitted::Variant(Variant::BoxCut), |t| &mut t.cutoff_shape),
    (Admitted::Variant(Variant::ViewDepthOrder), |t| {
        &mut t.sort_order
    }),
    (Admitted::Variant(Variant::Colour8Bit), |t| {
        &mut t.colour_8bit
    }),
];

/// Whether `spec` is designed to detect `d` (then its bound does not admit it).
fn detects(spec: &AssetSpec, d: Admitted) -> bool {
    match d {
        Admitted::Erratum(e) => spec.designed_for.contains(&e),
        Admitted::Variant(v) => spec.detects.contains(&v),
    }
}

/// The errata `spec`'s bound admits (their margin check is skipped: they are not its to
/// catch).
pub(crate) fn admitted_errata(spec: &AssetSpec) -> Vec<Erratum> {
    ISOLATED
        .iter()
        .filter_map(|(d, _)| match d {
            Admitted::Erratum(e) if !detects(spec, *d) => Some(*e),
            _ => None,
        })
        .collect()
}

/// Widens the bound by every deviation `spec` admits: per pixel, the largest channel
/// difference between the model with and without it, added to its term.
pub(crate) fn admit(
    exact: &mut model::ModelImage,
    spec: &AssetSpec,
    cloud: &crate::SplatCloud,
    cam: &Camera,
) {
    let mut worst = model::Terms::default();
    for (d, field) in ISOLATED.iter().filter(|(d, _)| !detects(spec, *d)) {
        let other = match d {
            Admitted::Erratum(e) => model::render(cloud, cam, &[*e]).image,
            Admitted::Variant(v) => model::render_with(cloud, cam, &[], &[*v]).image,
        };
        // Terms of one field (the two cut-off shapes) take the larger difference.
        let mut per_field = model::Terms::default();
        for (i, (p, q)) in exact.image.pixels.iter().zip(&other.pixels).enumerate() {
            let diff = (0..3)
                .map(|k| (p[k] as f64 - q[k] as f64).abs())
                .fold(0.0, f64::max);
            let extra = (diff - *field(&mut exact.extra[i])).max(0.0);
            *field(&mut exact.extra[i]) += extra;
            exact.bound[i] += extra;
            let w = field(&mut per_field);
            *w = w.max(*field(&mut exact.extra[i]));
        }
        worst = worst.max(per_field);
    }
    exact.worst = exact.worst.max(worst);
}
