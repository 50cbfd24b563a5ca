//! [`Deviation`]: one type for every way of rendering differently from the RC that the kit
//! knows — what an asset's bound admits (`isolation`) and what the diagnosis names
//! ([`super::diagnosis`]).

use super::Erratum;
use super::model::Variant;

/// A way of rendering differently from the RC that the diagnosis knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Deviation {
    /// A review-draft Appendix A erratum.
    Erratum(Erratum),
    /// An implementation variant.
    Variant(Variant),
    /// The image upside down (rows not flipped after a GL read-back, or y up vs down).
    UpsideDown,
    /// The image mirrored left-right (handedness or x axis flipped).
    Mirrored,
    /// Σ' dilated by this many thousandths of a px² instead of 0.3: a value the diagnosis
    /// estimates from the images ([`crate::diagnosis::Search::explain_with`]) when erratum i (no dilation)
    /// comes close but does not explain them.
    Dilation(u16),
}

impl Deviation {
    /// Every deviation tried singly.
    pub fn all() -> Vec<Deviation> {
        let mut v: Vec<Deviation> = Erratum::ALL.into_iter().map(Deviation::Erratum).collect();
        v.extend(Variant::ALL.into_iter().map(Deviation::Variant));
        v.extend([Deviation::UpsideDown, Deviation::Mirrored]);
        v
    }
    /// A short identifier (`rule` in `report.json`'s `diagnosis`).
    pub fn name(self) -> String {
        match self {
            Deviation::Erratum(e) => format!("erratum_{}", e.letter()),
            Deviation::Variant(v) => v.name().to_owned(),
            Deviation::UpsideDown => "upside_down".into(),
            Deviation::Mirrored => "mirrored".into(),
            Deviation::Dilation(_) => "dilation".into(),
        }
    }
    /// What the renderer does, in words.
    pub fn describe(self) -> String {
        match self {
            Deviation::Erratum(e) => {
                format!("review-draft erratum {}: {}", e.letter(), e.describe())
            }
            Deviation::Variant(v) => v.describe().to_owned(),
            Deviation::UpsideDown => {
                "the image is upside down (rows not flipped after a GL read-back, or y up vs down)"
                    .into()
            }
            Deviation::Mirrored => {
                "the image is mirrored left-right (handedness or x axis flipped)".into()
            }
            Deviation::Dilation(m) => format!(
                "Σ' dilated by {:.3} px² (estimated from the images) instead of 0.3",
                f64::from(m) / 1000.0
            ),
        }
    }
    /// The section of the RC whose rule it breaks (or allows, for the SH degree caps).
    pub fn rc_section(self) -> String {
        match self {
            Deviation::Erratum(e) => match e {
                Erratum::A => "RC Splat Reconstruction (C = R(q)·S)",
                Erratum::B => "RC Splat Projection (Σ' = J W Σ Wᵀ Jᵀ)",
                Erratum::D => "RC Splat Projection (pixel mapping)",
                Erratum::E => "RC Lighting (basis with Condon–Shortley signs, Σ SH·Y + 0.5)",
                Erratum::F => "RC Ellipse Kernel Rendering (3σ cut-off)",
                Erratum::G => "RC Splat Composition (premultiplied, back to front)",
                Erratum::I => "profile: dilation (RC: the training forward pass)",
                Erratum::K => "profile: J clamp and α cap (3DGS computeCov2D)",
            }
            .into(),
            Deviation::Variant(v) => v.rc_section().into(),
            Deviation::UpsideDown | Deviation::Mirrored => {
                "glTF 2.0 §3.4 coordinate system; image rows top to bottom".into()
            }
            Deviation::Dilation(_) => "profile: dilation (RC: the training forward pass)".into(),
        }
    }
    /// Whether the RC allows it (an image matching it passes).
    pub fn rc_allowed(self) -> bool {
        matches!(self, Deviation::Variant(v) if v.rc_allowed())
    }
}
