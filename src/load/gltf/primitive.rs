//! One `KHR_gaussian_splatting` primitive → a local-space [`SplatCloud`], with every RC rule
//! about its attributes checked and reported as a [`Finding`].

use super::accessor::{Decoded, component_name, decode};
use super::container::PREFIX;
use crate::cloud::{ColorSpace, SplatCloud, SplatMeta};
use crate::load::Finding;
use crate::load::{ScaleSeen, ScaleSpace};
use gltf::accessor::DataType;
use serde_json::{Map, Value};

/// A decoded primitive in its mesh's local space.
#[derive(Debug, Clone)]
pub struct LocalSplats {
    /// The splats (local space).
    pub cloud: SplatCloud,
    /// Scale space read.
    pub scale_seen: ScaleSeen,
    /// Quaternions that were not unit within tolerance.
    pub non_unit: usize,
}

/// Context for reading one primitive.
pub struct Ctx<'a> {
    /// The document (validated).
    pub doc: &'a gltf::Document,
    /// Buffers.
    pub buffers: &'a [Vec<u8>],
    /// `meshes[m].primitives[p]`.
    pub path: String,
    /// Options.
    pub scale_space: ScaleSpace,
    /// Whether `KHR_mesh_quantization` is in `extensionsUsed` (quantized POSITION allowed).
    pub quantization: bool,
    /// Values the document may still decode (see [`decode`]).
    pub budget: &'a std::cell::Cell<u64>,
}

fn attr_path(base: &str, name: &str) -> String {
    format!("{base}.attributes[\"{name}\"]")
}

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

/// Reads and checks one primitive. Returns `None` after a blocking finding.
pub fn read(
    ctx: &Ctx,
    prim: &Value,
    meta: &SplatMeta,
    f: &mut Vec<Finding>,
) -> Option<LocalSplats> {
    check_primitive(&ctx.path, prim, f);
    let attrs = fetch(ctx, prim, f)?;
    check_types_and_counts(ctx, &attrs, f)?;
    let degree = sh_degree(&ctx.path, &attrs.higher, f);
    let log = scale_space(ctx, &attrs.scale, f)?;
    check_opacity(&ctx.path, &attrs.opacity, f)?;
    assemble(ctx, &attrs, meta, degree, log, f)
}

/// The attribute semantic as written in the file.
fn semantic(name: &str) -> String {
    if name == "POSITION" || name == "COLOR_0" {
        name.to_owned()
    } else {
        format!("{PREFIX}{name}")
    }
}

/// The primitive's attributes, decoded; the required ones are there.
struct Attributes {
    position: Decoded,
    rotation: Decoded,
    scale: Decoded,
    opacity: Decoded,
    sh0: Option<Decoded>,
    /// Read only without `SH_DEGREE_0_COEF_0` (the RC's fallback).
    color0: Option<Decoded>,
    /// Degrees 1..=3, coefficient by coefficient (`None`: absent).
    higher: Vec<Vec<Option<Decoded>>>,
}

/// Mode and material: the primitive's own properties.
fn check_primitive(path: &str, prim: &Value, f: &mut Vec<Finding>) {
    if prim.get("mode").and_then(Value::as_u64) != Some(0) {
        f.push(Finding::error(
            format!("{path}.mode"),
            "mode MUST be POINTS (0) for a splat primitive",
        ));
    }
    if prim.get("material").is_some() {
        f.push(Finding::warning(
            format!("{path}.material"),
            "material is ignored for splat rendering",
        ));
    }
}

/// Decodes every attribute the extension defines, then checks the required ones are there.
/// `None` after the first accessor that cannot be decoded, or a missing required attribute.
fn fetch(ctx: &Ctx, prim: &Value, f: &mut Vec<Finding>) -> Option<Attributes> {
    let path = &ctx.path;
    let empty = Map::new();
    let attrs = prim
        .get("attributes")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    // `Some(None)`: absent; `None`: present but undecodable (a finding says why).
    let mut get = |name: &str| -> Option<Option<Decoded>> {
        let full = semantic(name);
        let ap = attr_path(path, &full);
        let Some(idx) = attrs.get(&full) else {
            return Some(None);
        };
        let acc = idx
            .as_u64()
            .and_then(|i| ctx.doc.accessors().nth(i as usize));
        let Some(acc) = acc else {
            f.push(Finding::fatal(
                ap,
                format!("accessor index {idx} out of range"),
            ));
            return None;
        };
        match decode(&acc, ctx.buffers, &ap, ctx.budget) {
            Ok(d) => Some(Some(d)),
            Err(e) => {
                f.push(e);
                None
            }
        }
    };
    let required = [
        get("POSITION")?,
        get("ROTATION")?,
        get("SCALE")?,
        get("OPACITY")?,
    ];
    let sh0 = get("SH_DEGREE_0_COEF_0")?;
    let color0 = if sh0.is_none() { get("COLOR_0")? } else { None };
    let mut higher: Vec<Vec<Option<Decoded>>> = Vec::new();
    for l in 1..=3usize {
        let mut coefs = Vec::new();
        for n in 0..2 * l + 1 {
            coefs.push(get(&format!("SH_DEGREE_{l}_COEF_{n}"))?);
        }
        higher.push(coefs);
    }
    let mut missing = false;
    for (name, a) in ["POSITION", "ROTATION", "SCALE", "OPACITY"]
        .iter()
        .zip(&required)
    {
        if a.is_none() {
            f.push(Finding::fatal(
                attr_path(path, &semantic(name)),
                "required attribute is missing",
            ));
            missing = true;
        }
    }
    if sh0.is_none() {
        let sh0_path = attr_path(path, &semantic("SH_DEGREE_0_COEF_0"));
        if color0.is_some() {
            f.push(Finding::error(
                sh0_path,
                "required attribute is missing; diffuse colour derived from COLOR_0",
            ));
        } else {
            f.push(Finding::fatal(
                sh0_path,
                "required attribute is missing (and there is no COLOR_0 to fall back on)",
            ));
            missing = true;
        }
    }
    let [Some(position), Some(rotation), Some(scale), Some(opacity)] = required else {
        return None;
    };
    if missing {
        return None;
    }
    Some(Attributes {
        position,
        rotation,
        scale,
        opacity,
        sh0,
        color0,
        higher,
    })
}

/// An attribute to check: its path, its data, the components and the (type, normalized) pairs
/// the RC allows.
type Check<'d> = (String, &'d Decoded, usize, &'static [(DataType, bool)]);

/// Component counts, element counts, component types, alignment and finiteness of every
/// attribute. `None` after a blocking finding.
fn check_types_and_counts(ctx: &Ctx, a: &Attributes, f: &mut Vec<Finding>) -> Option<()> {
    let path = &ctx.path;
    let n = a.position.count();
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
    let mut blocked = false;
    for (p, d, dims, ok) in &typed {
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
        if let Some(i) = d.data.iter().position(|v| !v.is_finite()) {
            f.push(Finding::fatal(p.clone(), "value is not finite").at((i / d.dims) as u64));
            blocked = true;
        }
    }
    if let Some(c) = &a.color0
        && (c.count() != n || !(c.dims == 3 || c.dims == 4))
    {
        f.push(Finding::fatal(
            attr_path(path, "COLOR_0"),
            "COLOR_0 must be VEC3/VEC4 with POSITION's count",
        ));
        blocked = true;
    }
    (!blocked).then_some(())
}

/// The highest complete SH degree with every lower degree complete; incomplete degrees are
/// reported and not used.
fn sh_degree(path: &str, higher: &[Vec<Option<Decoded>>], f: &mut Vec<Finding>) -> u8 {
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
fn scale_space(ctx: &Ctx, scale: &Decoded, f: &mut Vec<Finding>) -> Option<bool> {
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
fn check_opacity(path: &str, opacity: &Decoded, f: &mut Vec<Finding>) -> Option<()> {
    let Some(i) = opacity
        .data
        .iter()
        .position(|v| !(-1e-6..=1.0 + 1e-6).contains(v))
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

/// Builds the local cloud: quaternions normalised (unit within a tolerance that allows for the
/// quantization step, the others counted), scales linearised, SH gathered splat by splat.
fn assemble(
    ctx: &Ctx,
    a: &Attributes,
    meta: &SplatMeta,
    degree: u8,
    log: bool,
    f: &mut Vec<Finding>,
) -> Option<LocalSplats> {
    let n = a.position.count();
    let tol = match a.rotation.component {
        DataType::I8 => 1e-2,
        _ => 1e-3,
    };
    let rot_path = attr_path(&ctx.path, &semantic("ROTATION"));
    let scale_path = attr_path(&ctx.path, &semantic("SCALE"));
    let mut cloud = SplatCloud::with_capacity(degree, n);
    let k = cloud.coeffs_per_splat();
    let mut non_unit = 0;
    let mut first_non_unit = None;
    let mut sh = vec![[0.0f32; 3]; k];
    cloud.meta = meta.clone();
    let srgb = cloud.meta.color_space.effective() == ColorSpace::SrgbRec709Display;
    for i in 0..n {
        let q: [f32; 4] = a.rotation.get(i);
        let norm = q.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
        if norm < 1e-12 {
            f.push(Finding::fatal(&rot_path, "quaternion is zero").at(i as u64));
            return None;
        }
        if (norm - 1.0).abs() > tol {
            non_unit += 1;
            first_non_unit.get_or_insert(i);
        }
        let q = q.map(|v| (v as f64 / norm) as f32);
        let s: [f32; 3] = a.scale.get(i);
        let s = if log {
            s.map(f32::exp)
        } else {
            s.map(|v| v.max(0.0))
        };
        if !s.iter().all(|v| v.is_finite()) {
            f.push(Finding::fatal(&scale_path, "exp(log-space scale) overflows f32").at(i as u64));
            return None;
        }
        sh[0] = match (&a.sh0, &a.color0) {
            (Some(d), _) => d.get(i),
            (None, Some(c)) => dc_from_color0(c.get::<3>(i), srgb),
            (None, None) => [0.0; 3],
        };
        for (l, coefs) in a.higher.iter().enumerate().take(degree as usize) {
            for (c, d) in coefs.iter().enumerate() {
                if let Some(d) = d {
                    sh[(l + 1) * (l + 1) + c] = d.get(i);
                }
            }
        }
        cloud.push(a.position.get(i), s, q, a.opacity.data[i], &sh);
    }
    if let Some(i) = first_non_unit {
        f.push(
            Finding::error(
                &rot_path,
                format!("{non_unit} quaternions are not unit length (tolerance {tol}); normalised"),
            )
            .at(i as u64),
        );
    }
    let scale_seen = if log {
        ScaleSeen::Log
    } else {
        ScaleSeen::Linear
    };
    Some(LocalSplats {
        cloud,
        scale_seen,
        non_unit,
    })
}

/// Inverts the RC's COLOR_0 fallback: COLOR_0 = clamp(SH0·Y₀₀ + 0.5) (sRGB-decoded to linear
/// when the colour space is sRGB), so SH0 = (c − 0.5) / Y₀₀ with c re-encoded where needed.
fn dc_from_color0(c: [f32; 3], srgb: bool) -> [f32; 3] {
    c.map(|v| {
        let v = v.clamp(0.0, 1.0) as f64;
        let v = if srgb {
            crate::color::srgb_encode(v)
        } else {
            v
        };
        ((v - 0.5) / crate::sh::SH_C0) as f32
    })
}
