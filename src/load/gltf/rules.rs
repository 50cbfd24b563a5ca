//! The RC's rules for a splat primitive's attributes: component counts and types, element
//! counts, finiteness, SH degree completeness, scale space and the opacity range. Each check
//! reports what it finds; `None` means a blocking finding was reported.

use super::accessor::{Decoded, component_name};
use super::container::PREFIX;
use super::primitive::{Attributes, Ctx, attr_path, semantic};
use crate::load::{Finding, ScaleSpace};
use gltf::accessor::DataType;

/// POSITION with `KHR_mesh_quantization`: float, or 8/16-bit integers, normalized or not.
const POSITION_QUANTIZED: &[(DataType, bool)] = &[
    (DataType::F32, false),
    (DataType::I8, false),
    (DataType::I8, true),
    (DataType::U8, false),
    (DataType::U8, true),
    (DataType::I16, false),
    (DataType::I16, true),
    (DataType::U16, false),
    (DataType::U16, true),
];

/// What the RC allows per attribute: (dims, allowed (type, normalized) pairs).
fn allowed(name: &str) -> (usize, &'static [(DataType, bool)]) {
    use DataType::*;
    match name {
        "ROTATION" => (4, &[(F32, false), (I8, true), (I16, true)]),
        "SCALE" => (
            3,
            &[
                (F32, false),
                (U8, false),
                (U8, true),
                (U16, false),
                (U16, true),
            ],
        ),
        "OPACITY" => (1, &[(F32, false), (U8, true), (U16, true)]),
        _ => (3, &[(F32, false)]), // SH
    }
}

/// An attribute to check: its path, its data, the components and the (type, normalized) pairs
/// the RC allows.
type Check<'d> = (String, &'d Decoded, usize, &'static [(DataType, bool)]);

/// Component counts, element counts, component types, alignment and finiteness of every
/// attribute. `None` after a blocking finding.
pub(super) fn check_types_and_counts(
    ctx: &Ctx,
    a: &Attributes,
    f: &mut Vec<Finding>,
) -> Option<()> {
    let path = &ctx.path;
    let n = a.position.count();
    if let Err(e) = ctx
        .opts
        .limits
        .check_splats(n as u64, &attr_path(path, "POSITION"))
    {
        f.push(Finding::fatal(attr_path(path, "POSITION"), e.to_string()));
        return None;
    }
    let typed = checks(ctx, a);
    let mut blocked = false;
    for check in &typed {
        blocked |= check_attribute(ctx, check, n, f);
    }
    if let Some(c) = &a.color0 {
        if c.count() != n || !(c.dims == 3 || c.dims == 4) {
            f.push(Finding::fatal(
                attr_path(path, "COLOR_0"),
                "COLOR_0 must be VEC3/VEC4 with POSITION's count",
            ));
            blocked = true;
        } else {
            non_finite(&attr_path(path, "COLOR_0"), c, ctx.opts.strict, f);
        }
    }
    (!blocked).then_some(())
}

/// The attributes to check with what the RC allows for each: POSITION (more types with
/// `KHR_mesh_quantization`), ROTATION, SCALE, OPACITY, then the SH coefficients present.
fn checks<'d>(ctx: &Ctx, a: &'d Attributes) -> Vec<Check<'d>> {
    let path = &ctx.path;
    let position_types: &[(DataType, bool)] = if ctx.quantization {
        POSITION_QUANTIZED
    } else {
        &[(DataType::F32, false)]
    };
    let mut typed: Vec<Check> = vec![(attr_path(path, "POSITION"), &a.position, 3, position_types)];
    for (name, d) in [
        ("ROTATION", &a.rotation),
        ("SCALE", &a.scale),
        ("OPACITY", &a.opacity),
    ] {
        let (dims, ok) = allowed(name);
        typed.push((attr_path(path, &semantic(name)), d, dims, ok));
    }
    if let Some(s) = &a.sh0 {
        typed.push((
            attr_path(path, &semantic("SH_DEGREE_0_COEF_0")),
            s,
            3,
            allowed("SH").1,
        ));
    }
    for (l, coefs) in a.higher.iter().enumerate() {
        for (c, d) in coefs.iter().enumerate() {
            if let Some(d) = d {
                let p = attr_path(path, &format!("{PREFIX}SH_DEGREE_{}_COEF_{c}", l + 1));
                typed.push((p, d, 3, allowed("SH").1));
            }
        }
    }
    typed
}

/// One attribute's component count, element count (POSITION's `n`), component type,
/// alignment and finiteness. Returns whether a blocking finding was reported.
fn check_attribute(ctx: &Ctx, (p, d, dims, ok): &Check, n: usize, f: &mut Vec<Finding>) -> bool {
    let mut blocked = false;
    if d.dims != *dims {
        f.push(Finding::fatal(
            p.clone(),
            format!("expected {dims} components, found {}", d.dims),
        ));
        blocked = true;
    } else if d.count() != n {
        f.push(Finding::fatal(
            p.clone(),
            format!("count {} differs from POSITION's count {n}", d.count()),
        ));
        blocked = true;
    } else if !ok.is_empty() && !ok.contains(&(d.component, d.normalized)) {
        // Signed SCALE is the review draft's log space: reported by the scale-space check,
        // unless the caller insists on linear.
        let is_legacy_scale = p.ends_with("SCALE\"]")
            && matches!(d.component, DataType::I8 | DataType::I16)
            && ctx.scale_space != ScaleSpace::Linear;
        if !is_legacy_scale {
            f.push(Finding::error(
                p.clone(),
                format!(
                    "component type {} is not allowed by the RC",
                    component_name(d.component, d.normalized)
                ),
            ));
        }
    }
    if let Some(m) = &d.misaligned {
        f.push(Finding::error(p.clone(), format!("glTF 2.0 layout: {m}")));
    }
    non_finite(p, d, ctx.opts.strict, f);
    blocked
}

/// glTF 2.0: accessor values MUST be finite. An error at the first offending element with the
/// count; the splats stay for the hygiene pass to drop. In strict mode the error is blocking.
fn non_finite(path: &str, d: &Decoded, strict: bool, f: &mut Vec<Finding>) {
    let mut bad = d
        .data
        .chunks_exact(d.dims.max(1))
        .enumerate()
        .filter(|(_, e)| !e.iter().all(|v| v.is_finite()))
        .map(|(i, _)| i);
    let Some(first) = bad.next() else {
        return;
    };
    let n = 1 + bad.count();
    let s = if n == 1 { "" } else { "s" };
    let then = if strict {
        "strict mode"
    } else {
        "those splats are dropped"
    };
    let mut finding = Finding::error(
        path,
        format!("value is not finite in {n} element{s} (glTF 2.0: MUST be finite); {then}"),
    );
    finding.blocks_loading = strict;
    f.push(finding.at(first as u64));
}

/// The highest complete SH degree with every lower degree complete; incomplete degrees are
/// reported and not used.
pub(super) fn sh_degree(path: &str, higher: &[Vec<Option<Decoded>>], f: &mut Vec<Finding>) -> u8 {
    let mut degree = 0u8;
    for (l, coefs) in higher.iter().enumerate() {
        let present = coefs.iter().filter(|c| c.is_some()).count();
        if present == 0 {
            break;
        }
        if present < coefs.len() || degree as usize != l {
            f.push(Finding::error(
                format!("{path}.attributes"),
                format!(
                    "SH degree {} is partially defined ({present} of {} coefficients); using degree {degree}",
                    l + 1,
                    coefs.len()
                ),
            ));
            break;
        }
        degree = l as u8 + 1;
    }
    for (l, coefs) in higher.iter().enumerate().skip(degree as usize) {
        if coefs.iter().any(Option::is_some) && l > degree as usize {
            f.push(Finding::error(
                format!("{path}.attributes"),
                format!(
                    "SH degree {} is present but a lower degree is incomplete",
                    l + 1
                ),
            ));
        }
    }
    degree
}

/// Whether SCALE is read in log space (the review draft) rather than linear (the RC), by the
/// option or, under `auto`, by signed types or negative values. `None` after a blocking finding.
pub(super) fn scale_space(ctx: &Ctx, scale: &Decoded, f: &mut Vec<Finding>) -> Option<bool> {
    let scale_path = attr_path(&ctx.path, &semantic("SCALE"));
    let signed = matches!(scale.component, DataType::I8 | DataType::I16);
    let first_negative = scale
        .data
        .iter()
        .position(|v| *v < 0.0)
        .map(|i| (i / 3) as u64);
    let log = match ctx.scale_space {
        ScaleSpace::Log => true,
        ScaleSpace::Linear => {
            if let Some(i) = first_negative {
                f.push(Finding::fatal(&scale_path, "scale MUST NOT be negative").at(i));
                return None;
            }
            false
        }
        ScaleSpace::Auto => signed || first_negative.is_some(),
    };
    if log && ctx.scale_space == ScaleSpace::Auto {
        let why = if signed {
            format!(
                "signed component type ({})",
                component_name(scale.component, scale.normalized)
            )
        } else {
            "negative values".to_owned()
        };
        let mut fd = Finding::error(
            &scale_path,
            format!(
                "legacy draft: log-space scale ({why}); read as exp(v). RC scales are linear and MUST NOT be negative"
            ),
        );
        if let (false, Some(i)) = (signed, first_negative) {
            fd = fd.at(i);
        }
        f.push(fd);
    }
    Some(log)
}

/// Opacity in [0, 1] (with a rounding tolerance). `None` after a blocking finding.
pub(super) fn check_opacity(path: &str, opacity: &Decoded, f: &mut Vec<Finding>) -> Option<()> {
    // Non-finite values are reported (and dropped) by the finiteness check.
    let Some(i) = opacity
        .data
        .iter()
        .position(|v| v.is_finite() && !(-1e-6..=1.0 + 1e-6).contains(v))
    else {
        return Some(());
    };
    f.push(
        Finding::fatal(
            attr_path(path, &semantic("OPACITY")),
            format!("opacity {} is outside [0, 1]", opacity.data[i]),
        )
        .at(i as u64),
    );
    None
}
