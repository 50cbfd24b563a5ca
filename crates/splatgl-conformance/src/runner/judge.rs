//! What a camera's image is judged by ([`Judge`]: the suite's bound, or with SPZ input the
//! bound derived from the asset's SPZ copy) and the choices an image that differs from the
//! reference may still pass with ([`allowed_choice`]).

use super::{InputPrecision, ModelInput};
use crate::diagnosis::{self, Deviation};
use crate::isolation::derived_bound;
use crate::manifest::{AssetEntry, CameraEntry, suite_path};
use crate::model::Variant;
use crate::verdict::{clamped, fails, measure, over_bound, tolerance};
use splatgl::image::Image;
use std::path::Path;

/// What an image that differs from the reference may still pass as.
pub(super) enum Allowed {
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
pub(super) struct Judge {
    pub(super) bound: Vec<f64>,
    pub(super) camera: CameraEntry,
    /// For SPZ input, the SPZ copy's model image.
    pub(super) copy: Option<Image>,
}

impl Judge {
    /// The judge of camera `ci` of asset `a` loaded as `l`, with the suite's `bound`.
    pub(super) fn new(
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
        let mut m = derived_bound(&l.scene.cloud, &l.cameras[ci], (&a.catches, &a.detects));
        // The camera's judged region (the suite's bound is infinite outside it).
        let judged: Vec<bool> = bound.iter().map(|b| b.is_finite()).collect();
        crate::judge::apply(&mut m.bound, &judged);
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
    pub(super) fn fails(&self, img: &Image, want: &Image) -> bool {
        fails(img, want, &self.bound, &self.camera.tolerance)
    }
}

/// The reference and the per-pixel bound of camera `c`.
pub(super) fn reference_and_bound(
    dir: &Path,
    c: &CameraEntry,
) -> Result<(Image, Vec<f64>), String> {
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
    crate::judge::apply(&mut bound, &judged);
    Ok((want, bound))
}

/// The choices an image may pass with although it differs from the reference: a renderer
/// that makes one or two of the choices the asset admits
/// ([`super::isolation::admitted_sets`]: the asset's bound is widened for each, but an image
/// drawn with them may still differ from the model with them by the model's own terms), a
/// renderer that ignores SH coefficients above some degree (the RC allows it), and with SPZ
/// input the SPZ copy as it is (`l` holds that copy then). Each is judged by the asset's
/// bound and, with SPZ input, also by the bound derived from the copy ([`Judge`]). `None`:
/// it matches none.
pub(super) fn allowed_choice(
    l: &ModelInput,
    (a, ci): (&AssetEntry, usize),
    (bound, judge): (&[f64], &Judge),
    img: &Image,
) -> Option<Allowed> {
    let c = &a.cameras[ci];
    let model = |devs: &[Deviation]| diagnosis::model_image(&l.scene.cloud, &l.cameras[ci], devs);
    // The suite's bound, and with SPZ input also the copy's.
    let passes = |m: &Image| {
        !fails(img, m, bound, &c.tolerance) || (judge.copy.is_some() && !judge.fails(img, m))
    };
    if judge.copy.as_ref().is_some_and(&passes) {
        return Some(Allowed::Admitted(Vec::new()));
    }
    // Of the sets it passes with, the one it matches closest is named.
    let closest = crate::isolation::admitted_sets(&a.catches, &a.detects)
        .into_iter()
        .filter_map(|ds| {
            let m = model(&ds);
            passes(&m).then(|| (measure(img, &m, bound).0.psnr, ds))
        })
        .max_by(|x, y| x.0.total_cmp(&y.0));
    if let Some((_, ds)) = closest {
        return Some(Allowed::Admitted(ds));
    }
    let degree = l.scene.cloud.sh_degree as usize;
    [Variant::ShDegree2, Variant::ShDegree1, Variant::ShDegree0]
        .into_iter()
        .skip(3 - degree.min(3))
        .map(Deviation::Variant)
        .find(|&d| passes(&model(&[d])))
        .map(Allowed::ShCap)
}

/// With SPZ input, how far `img` is from the model of the SPZ copy it was rendered from,
/// under the copy's bound (the pixel count above is against the float reference), for the
/// cause; empty otherwise.
pub(super) fn against_copy(judge: &Judge, img: &Image) -> String {
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
