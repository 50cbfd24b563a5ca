//! One `KHR_gaussian_splatting` primitive → a local-space [`SplatCloud`], with every RC rule
//! about its attributes checked and reported as a [`Finding`].

use super::accessor::{Decoded, component_name, decode};
use super::container::{EXT, PREFIX};
use crate::cloud::{ColorSpace, Kernel, Known, Projection, SortingMethod, SplatCloud, SplatMeta};
use crate::load::finding::Finding;
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

/// Reads the extension object into [`SplatMeta`], reporting missing/unknown values.
/// `used` is the document's `extensionsUsed` (extensions nested in the object must be listed
/// there, RC §Extending the Base Extension).
pub fn read_meta(
    ext: &Map<String, Value>,
    path: &str,
    used: &[&str],
    f: &mut Vec<Finding>,
) -> SplatMeta {
    let p = format!("{path}.extensions.{EXT}");
    let mut get = |key: &str, required: bool| -> Option<String> {
        match ext.get(key) {
            Some(Value::String(s)) => Some(s.clone()),
            Some(_) => {
                f.push(Finding::error(format!("{p}.{key}"), "must be a string"));
                None
            }
            None if required => {
                f.push(Finding::error(
                    format!("{p}.{key}"),
                    format!("required property '{key}' is missing"),
                ));
                None
            }
            None => None,
        }
    };
    let (k, c) = (get("kernel", true), get("colorSpace", true));
    let (pr, s) = (get("projection", false), get("sortingMethod", false));
    let mut meta = SplatMeta::default();
    if let Some(k) = k {
        meta.kernel = Kernel::parse(&k);
    }
    if let Some(c) = c {
        meta.color_space = ColorSpace::parse(&c);
    }
    if let Some(v) = pr {
        meta.projection = Projection::parse(&v);
    }
    if let Some(v) = s {
        meta.sorting_method = SortingMethod::parse(&v);
    }
    let unknown = [
        ("kernel", unknown_of(&meta.kernel), "ellipse"),
        (
            "colorSpace",
            unknown_of(&meta.color_space),
            "srgb_rec709_display",
        ),
        ("projection", unknown_of(&meta.projection), "perspective"),
        (
            "sortingMethod",
            unknown_of(&meta.sorting_method),
            "cameraDistance",
        ),
    ];
    for (key, val, fallback) in unknown {
        if let Some(v) = val {
            f.push(Finding::warning(
                format!("{p}.{key}"),
                format!("unknown value {v:?}; rendering as {fallback:?}"),
            ));
        }
    }
    if let Some(exts) = ext.get("extensions").and_then(Value::as_object) {
        for name in exts.keys() {
            let ep = format!("{p}.extensions.{name}");
            if !used.contains(&name.as_str()) {
                f.push(Finding::error(
                    &ep,
                    format!("{name:?} MUST also be listed in extensionsUsed"),
                ));
            }
            if name.to_ascii_lowercase().contains("compression") {
                f.push(Finding::fatal(
                    ep,
                    format!("compression extension {name:?} is not supported (yet)"),
                ));
            } else {
                f.push(Finding::warning(
                    ep,
                    format!("extension {name:?} is not known to splatgl; ignored"),
                ));
            }
        }
    }
    meta
}

fn unknown_of<T>(k: &Known<T>) -> Option<&str> {
    match k {
        Known::Unknown(s) => Some(s),
        Known::Known(_) => None,
    }
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
    let path = &ctx.path;
    let empty = Map::new();
    let attrs = prim
        .get("attributes")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
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
    let mut get = |name: &str| -> Option<Option<Decoded>> {
        let full = if name == "POSITION" || name == "COLOR_0" {
            name.to_owned()
        } else {
            format!("{PREFIX}{name}")
        };
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
    let position = get("POSITION")?;
    let rotation = get("ROTATION")?;
    let scale = get("SCALE")?;
    let opacity = get("OPACITY")?;
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
    for (name, a) in [
        ("POSITION", &position),
        ("ROTATION", &rotation),
        ("SCALE", &scale),
        ("OPACITY", &opacity),
    ] {
        if a.is_none() {
            let full = if name == "POSITION" {
                name.to_owned()
            } else {
                format!("{PREFIX}{name}")
            };
            f.push(Finding::fatal(
                attr_path(path, &full),
                "required attribute is missing",
            ));
            missing = true;
        }
    }
    let sh0_path = attr_path(path, &format!("{PREFIX}SH_DEGREE_0_COEF_0"));
    if sh0.is_none() {
        if color0.is_some() {
            f.push(Finding::error(
                sh0_path.clone(),
                "required attribute is missing; diffuse colour derived from COLOR_0",
            ));
        } else {
            f.push(Finding::fatal(
                sh0_path.clone(),
                "required attribute is missing (and there is no COLOR_0 to fall back on)",
            ));
            missing = true;
        }
    }
    if missing {
        return None;
    }
    let (position, rotation, scale, opacity) = (position?, rotation?, scale?, opacity?);

    // Types and counts.
    let n = position.count();
    type Check<'d> = (String, &'d Decoded, usize, &'static [(DataType, bool)]);
    let mut typed: Vec<Check> = vec![
        (
            attr_path(path, "POSITION"),
            &position,
            3,
            if ctx.quantization {
                POSITION_QUANTIZED
            } else {
                &[(DataType::F32, false)]
            },
        ),
        (
            attr_path(path, &format!("{PREFIX}ROTATION")),
            &rotation,
            4,
            allowed("ROTATION").1,
        ),
        (
            attr_path(path, &format!("{PREFIX}SCALE")),
            &scale,
            3,
            allowed("SCALE").1,
        ),
        (
            attr_path(path, &format!("{PREFIX}OPACITY")),
            &opacity,
            1,
            allowed("OPACITY").1,
        ),
    ];
    if let Some(s) = &sh0 {
        typed.push((sh0_path.clone(), s, 3, allowed("SH").1));
    }
    for (l, coefs) in higher.iter().enumerate() {
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
            // Signed SCALE is the review draft's log space: reported by the scale-space check
            // below, unless the caller insists on linear.
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
    if let Some(c) = &color0
        && (c.count() != n || !(c.dims == 3 || c.dims == 4))
    {
        f.push(Finding::fatal(
            attr_path(path, "COLOR_0"),
            "COLOR_0 must be VEC3/VEC4 with POSITION's count",
        ));
        blocked = true;
    }
    if blocked {
        return None;
    }

    // SH degree: the highest complete degree with every lower degree complete.
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

    // Scale space.
    let scale_path = attr_path(path, &format!("{PREFIX}SCALE"));
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

    // Opacity.
    let op_path = attr_path(path, &format!("{PREFIX}OPACITY"));
    if let Some(i) = opacity
        .data
        .iter()
        .position(|v| !(-1e-6..=1.0 + 1e-6).contains(v))
    {
        f.push(
            Finding::fatal(
                &op_path,
                format!("opacity {} is outside [0, 1]", opacity.data[i]),
            )
            .at(i as u64),
        );
        return None;
    }

    // Rotation: unit within a tolerance that allows for the quantization step.
    let tol = match rotation.component {
        DataType::I8 => 1e-2,
        _ => 1e-3,
    };
    let rot_path = attr_path(path, &format!("{PREFIX}ROTATION"));
    let mut cloud = SplatCloud::with_capacity(degree, n);
    let k = cloud.coeffs_per_splat();
    let mut non_unit = 0;
    let mut first_non_unit = None;
    let mut sh = vec![[0.0f32; 3]; k];
    cloud.meta = meta.clone();
    let srgb = cloud.meta.color_space.effective() == ColorSpace::SrgbRec709Display;
    for i in 0..n {
        let q: [f32; 4] = rotation.get(i);
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
        let s: [f32; 3] = scale.get(i);
        let s = if log {
            s.map(f32::exp)
        } else {
            s.map(|v| v.max(0.0))
        };
        if !s.iter().all(|v| v.is_finite()) {
            f.push(Finding::fatal(&scale_path, "exp(log-space scale) overflows f32").at(i as u64));
            return None;
        }
        sh[0] = match (&sh0, &color0) {
            (Some(d), _) => d.get(i),
            (None, Some(c)) => dc_from_color0(c.get::<3>(i), srgb),
            (None, None) => [0.0; 3],
        };
        for (l, coefs) in higher.iter().enumerate().take(degree as usize) {
            for (c, d) in coefs.iter().enumerate() {
                if let Some(d) = d {
                    sh[(l + 1) * (l + 1) + c] = d.get(i);
                }
            }
        }
        cloud.push(position.get(i), s, q, opacity.data[i], &sh);
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
