//! SPZ-compressed splat primitives: `KHR_gaussian_splatting_compression_spz_2` (nested in the
//! primitive's `KHR_gaussian_splatting` object) and the legacy draft
//! `KHR_spz_gaussian_splats_compression` (on the primitive itself).
//!
//! Both point a `bufferView` at an SPZ blob (the current extension pins SPZ v2, gzip) and list
//! placeholder attribute accessors whose `count` must equal the SPZ point count; the values
//! come from the SPZ data alone. Their text requires unpacking to glTF's LUF axes (SPZ stores
//! RUB: x and z negated), while CesiumJS and the real files take the payload as stored;
//! [`as_stored`] decides per primitive. The decoded primitive is in mesh space like any other
//! and the node transforms apply to it.

use super::accessor::view_bytes;
use super::container::PREFIX;
use super::primitive::{Ctx, LocalSplats, attr_path};
use crate::load::codec::flip_axes;
use crate::load::spz::{Frame, SpzAxes, decode_bytes};
use crate::load::{Details, Finding, ScaleSeen};
use serde_json::Value;

/// The current extension (nested in `KHR_gaussian_splatting`).
pub const SPZ_2: &str = "KHR_gaussian_splatting_compression_spz_2";
/// The legacy draft extension (primitive level, before `KHR_gaussian_splatting` existed in
/// its current form).
pub const LEGACY: &str = "KHR_spz_gaussian_splats_compression";

/// Which extension compresses a primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// [`SPZ_2`].
    Spz2,
    /// [`LEGACY`].
    Legacy,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Spz2 => SPZ_2,
            Kind::Legacy => LEGACY,
        }
    }
}

/// Reads an SPZ-compressed primitive: the blob of `ext.bufferView` decoded, converted RUB →
/// LUF or read as stored ([`as_stored`]), the placeholders checked against it. `ext_path` is
/// the extension object's JSON path. `None` after a blocking finding.
pub fn read(
    ctx: &Ctx,
    prim: &Value,
    kind: Kind,
    ext: &Value,
    ext_path: &str,
    f: &mut Vec<Finding>,
) -> Option<LocalSplats> {
    let bv_path = format!("{ext_path}.bufferView");
    let (index, bytes) = payload(ctx, ext, &bv_path, f)?;
    let (mut cloud, details, flips) = decode_payload(ctx, kind, bytes, index, &bv_path, f)?;
    check_placeholders(ctx, prim, kind, cloud.len(), cloud.sh_degree, f);
    let stored = as_stored(ctx, prim, kind, &cloud, flips, f);
    if stored {
        flip_axes(&mut cloud, flips);
    }
    if kind == Kind::Legacy {
        let axes = if stored {
            "payload read as stored, in glTF axes, as CesiumJS reads it"
        } else {
            "payload converted RUB → LUF"
        };
        f.push(Finding::warning(
            ext_path,
            format!(
                "legacy extension {LEGACY:?} (superseded by KHR_gaussian_splatting with {SPZ_2}); read, with kernel \"ellipse\" and colorSpace \"srgb_rec709_display\", {axes} (--spz-axes rub|raw to choose)"
            ),
        ));
    }
    Some(LocalSplats {
        cloud,
        scale_seen: ScaleSeen::Log,
        non_unit: 0,
        origin: None,
        details: Some(details),
    })
}

/// The bufferView the extension object `ext` names (`bv_path` is its JSON path): its index
/// and bytes. `None` after a blocking finding.
fn payload<'b>(
    ctx: &Ctx<'b>,
    ext: &Value,
    bv_path: &str,
    f: &mut Vec<Finding>,
) -> Option<(u64, &'b [u8])> {
    let Some(index) = ext.get("bufferView").and_then(Value::as_u64) else {
        f.push(Finding::fatal(
            bv_path,
            "required property 'bufferView' is missing or not an index",
        ));
        return None;
    };
    let Some(view) = ctx.doc.views().nth(index as usize) else {
        f.push(Finding::fatal(
            bv_path,
            format!("bufferViews[{index}] does not exist"),
        ));
        return None;
    };
    match view_bytes(&view, ctx.buffers, bv_path) {
        Ok(b) => Some((index, b)),
        Err(e) => {
            f.push(e);
            None
        }
    }
}

/// Decodes the SPZ blob of `bufferViews[index]` converted (stored frame → LUF; the flips are
/// returned so they can be undone if it is read as stored), with its version checked for
/// `kind` and its values charged to the document's budget. `None` after a blocking finding.
fn decode_payload(
    ctx: &Ctx,
    kind: Kind,
    bytes: &[u8],
    index: u64,
    bv_path: &str,
    f: &mut Vec<Finding>,
) -> Option<(crate::SplatCloud, Details, [bool; 3])> {
    let (cloud, mut details, flips) = match decode_bytes(
        bytes,
        SpzAxes::Rub,
        Frame::Gltf,
        (&ctx.opts.limits, None),
        f,
    ) {
        Ok(d) => d,
        Err(e) => {
            f.push(Finding::fatal(
                bv_path,
                format!("bufferViews[{index}]: SPZ: {e}"),
            ));
            return None;
        }
    };
    if kind == Kind::Spz2 && details.version != "2" {
        f.push(Finding::error(
            bv_path,
            format!(
                "{SPZ_2} pins SPZ version 2, the payload is version {}; read anyway",
                details.version
            ),
        ));
    }
    details.gltf_extension = Some(kind.name());
    let values = cloud.len() as u64 * (11 + 3 * cloud.coeffs_per_splat() as u64);
    if values > ctx.budget.get() {
        f.push(Finding::fatal(
            bv_path,
            "the SPZ payload decodes to more values than this file can justify",
        ));
        return None;
    }
    ctx.budget.set(ctx.budget.get() - values);
    Some((cloud, details, flips))
}

/// The attribute's name without `KHR_gaussian_splatting:` or the legacy `_` prefix.
fn base_name(name: &str) -> &str {
    name.strip_prefix(PREFIX)
        .or_else(|| name.strip_prefix('_'))
        .unwrap_or(name)
}

/// Every placeholder's `count` against the payload's (the extensions' MUST; an error for the
/// current extension, a warning for the legacy one), and, for the current extension, the RC's
/// required attributes and the SH degree the placeholders declare (warnings: the payload
/// decides).
fn check_placeholders(
    ctx: &Ctx,
    prim: &Value,
    kind: Kind,
    n: usize,
    degree: u8,
    f: &mut Vec<Finding>,
) {
    let empty = serde_json::Map::new();
    let attrs = prim
        .get("attributes")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    for (name, idx) in attrs {
        let count = idx
            .as_u64()
            .and_then(|i| ctx.doc.accessors().nth(i as usize))
            .map(|a| a.count());
        if let Some(c) = count.filter(|&c| c != n) {
            let msg = format!(
                "placeholder accessor count {c}, but the SPZ payload holds {n} points (counts MUST match); the payload is used"
            );
            let p = attr_path(&ctx.path, name);
            f.push(match kind {
                Kind::Spz2 => Finding::error(p, msg),
                Kind::Legacy => Finding::warning(p, msg),
            });
        }
    }
    if kind == Kind::Legacy {
        return;
    }
    let has = |b: &str| attrs.keys().any(|k| base_name(k) == b);
    let color0 = has("COLOR_0");
    for (b, covered) in [
        ("POSITION", false),
        ("ROTATION", false),
        ("SCALE", false),
        ("OPACITY", color0),
        ("SH_DEGREE_0_COEF_0", color0),
    ] {
        if !has(b) && !covered {
            let full = if b == "POSITION" {
                b.to_owned()
            } else {
                format!("{PREFIX}{b}")
            };
            f.push(Finding::warning(
                attr_path(&ctx.path, &full),
                "no placeholder accessor for this required attribute; the SPZ payload supplies it",
            ));
        }
    }
    let declared = (1..=3u8)
        .take_while(|&l| (0..2 * l + 1).all(|c| has(&format!("SH_DEGREE_{l}_COEF_{c}"))))
        .last()
        .unwrap_or(0);
    if declared != degree {
        f.push(Finding::warning(
            format!("{}.attributes", ctx.path),
            format!(
                "placeholders declare SH degree {declared}, the SPZ payload has degree {degree}; the payload is used"
            ),
        ));
    }
}

/// The compression extension of a primitive (`path` is its JSON path): which one, its object
/// and the object's JSON path. The current extension wins over a legacy one beside it.
pub fn compression<'v>(prim: &'v Value, path: &str) -> Option<(Kind, &'v Value, String)> {
    let exts = prim.get("extensions")?;
    let nested = exts
        .get(super::container::EXT)
        .and_then(|k| k.get("extensions"))
        .and_then(|e| e.get(SPZ_2));
    if let Some(v) = nested {
        let p = format!(
            "{path}.extensions.{}.extensions.{SPZ_2}",
            super::container::EXT
        );
        return Some((Kind::Spz2, v, p));
    }
    let v = exts.get(LEGACY)?;
    Some((Kind::Legacy, v, format!("{path}.extensions.{LEGACY}")))
}

/// What POSITION's `min`/`max` (a glTF MUST, so placeholders carry them) say about the
/// payload's axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shows {
    /// They match the payload converted RUB → LUF (what the extensions' text requires).
    Converted,
    /// They match the payload as stored: its writer put glTF-axis numbers in it.
    Stored,
    /// Neither, or both (placeholder bounds such as ±1, or no flip at all).
    Nothing,
}

fn evidence(ctx: &Ctx, prim: &Value, converted: &crate::SplatCloud, flips: [bool; 3]) -> Shows {
    let Some(b) = converted.bounds() else {
        return Shows::Nothing;
    };
    let acc = prim["attributes"]["POSITION"]
        .as_u64()
        .and_then(|i| ctx.doc.accessors().nth(i as usize));
    let vec3 = |v: Option<gltf::json::Value>| -> Option<[f64; 3]> {
        let a = v?;
        let a = a.as_array()?;
        (a.len() == 3).then(|| std::array::from_fn(|k| a[k].as_f64().unwrap_or(f64::NAN)))
    };
    let lo = vec3(acc.as_ref().and_then(|a| a.min()));
    let (Some(lo), Some(hi)) = (lo, vec3(acc.and_then(|a| a.max()))) else {
        return Shows::Nothing;
    };
    let (cmin, cmax) = (b.min.map(f64::from), b.max.map(f64::from));
    // As stored, a flipped axis has its min and max negated and swapped.
    let smin: [f64; 3] = std::array::from_fn(|a| if flips[a] { -cmax[a] } else { cmin[a] });
    let smax: [f64; 3] = std::array::from_fn(|a| if flips[a] { -cmin[a] } else { cmax[a] });
    let near = |a: [f64; 3], b: [f64; 3]| {
        (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-3 * (1.0 + a[k].abs().max(b[k].abs())))
    };
    match (
        near(lo, cmin) && near(hi, cmax),
        near(lo, smin) && near(hi, smax),
    ) {
        (true, false) => Shows::Converted,
        (false, true) => Shows::Stored,
        _ => Shows::Nothing,
    }
}

/// Whether the payload is read as stored (no RUB → LUF conversion). The extensions' text says
/// convert; CesiumJS (their named implementation) reads as stored, and so were the real files
/// written (docs/formats.md § glTF with SPZ compression). `--spz-axes rub|raw` decides;
/// `auto` follows POSITION's `min`/`max` where they tell, else the text for the current
/// extension and CesiumJS for the legacy one. A choice the bounds contradict is reported.
fn as_stored(
    ctx: &Ctx,
    prim: &Value,
    kind: Kind,
    converted: &crate::SplatCloud,
    flips: [bool; 3],
    f: &mut Vec<Finding>,
) -> bool {
    let shows = evidence(ctx, prim, converted, flips);
    let path = attr_path(&ctx.path, "POSITION");
    let mut say = |m: &str| f.push(Finding::warning(&path, m));
    match (ctx.spz_axes, shows) {
        (SpzAxes::Rub, Shows::Stored) => {
            say(
                "min/max match the SPZ payload as stored, not converted RUB → LUF: its writer probably skipped the conversion (--spz-axes auto or raw reads it as stored)",
            );
            false
        }
        (SpzAxes::Raw, Shows::Converted) => {
            say(
                "min/max match the SPZ payload converted RUB → LUF, as the extension requires (--spz-axes auto or rub converts it)",
            );
            true
        }
        (SpzAxes::Rub, _) => false,
        (SpzAxes::Raw, _) => true,
        (SpzAxes::Auto, Shows::Converted) => false,
        (SpzAxes::Auto, Shows::Stored) => {
            say(
                "min/max match the SPZ payload as stored, not converted RUB → LUF as the extension's text requires: read as stored, as CesiumJS reads it (--spz-axes rub converts)",
            );
            true
        }
        (SpzAxes::Auto, Shows::Nothing) => kind == Kind::Legacy,
    }
}
