//! One `KHR_gaussian_splatting` primitive → a local-space [`SplatCloud`]: its attributes
//! fetched, checked against the RC's rules (`rules.rs` beside this file), and assembled.

use super::accessor::{Decoded, decode};
use super::container::PREFIX;
use super::rules;
use crate::cloud::{ColorSpace, SplatCloud, SplatMeta};
use crate::load::spz::SpzAxes;
use crate::load::{Details, Finding, LoadOptions, ScaleSeen, ScaleSpace, Severity, hygiene};
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
    /// Accessor index of each splat, when the hygiene pass dropped some.
    pub origin: Option<Vec<u32>>,
    /// Container facts of a compressed primitive (SPZ), `None` for plain accessors.
    pub details: Option<Details>,
}

/// Context for reading one primitive.
pub struct Ctx<'a> {
    /// The document (validated).
    pub doc: &'a gltf::Document,
    /// Buffers.
    pub buffers: &'a [Vec<u8>],
    /// `meshes[m].primitives[p]`.
    pub path: String,
    /// How SCALE values are read.
    pub scale_space: ScaleSpace,
    /// All options (limits, strict mode).
    pub opts: &'a LoadOptions,
    /// Axes of SPZ payloads (compressed primitives).
    pub spz_axes: SpzAxes,
    /// Whether `KHR_mesh_quantization` is in `extensionsUsed` (quantized POSITION allowed).
    pub quantization: bool,
    /// Values the document may still decode (see [`decode`]).
    pub budget: &'a std::cell::Cell<u64>,
}

pub(super) fn attr_path(base: &str, name: &str) -> String {
    format!("{base}.attributes[\"{name}\"]")
}

/// Reads and checks one primitive. Returns `None` after a blocking finding.
pub fn read(
    ctx: &Ctx,
    prim: &Value,
    meta: &SplatMeta,
    f: &mut Vec<Finding>,
) -> Option<LocalSplats> {
    check_primitive(&ctx.path, prim, f);
    let mut ls = if let Some((kind, ext, ext_path)) = super::spz::compression(prim, &ctx.path) {
        let mut ls = super::spz::read(ctx, prim, kind, ext, &ext_path, f)?;
        ls.cloud.meta = meta.clone();
        ls
    } else {
        let attrs = fetch(ctx, prim, f)?;
        rules::check_types_and_counts(ctx, &attrs, f)?;
        let degree = rules::sh_degree(&ctx.path, &attrs.higher, f);
        let log = rules::scale_space(ctx, &attrs.scale, f)?;
        rules::check_opacity(&ctx.path, &attrs.opacity, f)?;
        assemble(ctx, &attrs, meta, degree, log, f)
    };
    let site = hygiene::Site {
        path: &ctx.path,
        what: "",
        severity: Severity::Error,
        strict: ctx.opts.strict,
        origin: None,
    };
    match hygiene::clean(&mut ls.cloud, &site, f) {
        Ok(origin) => ls.origin = origin,
        Err(e) => {
            f.push(e);
            return None;
        }
    }
    Some(ls)
}

/// The attribute semantic as written in the file.
pub(super) fn semantic(name: &str) -> String {
    if name == "POSITION" || name == "COLOR_0" {
        name.to_owned()
    } else {
        format!("{PREFIX}{name}")
    }
}

/// The primitive's attributes, decoded; the required ones are there.
pub(super) struct Attributes {
    pub position: Decoded,
    pub rotation: Decoded,
    pub scale: Decoded,
    pub opacity: Decoded,
    pub sh0: Option<Decoded>,
    /// Read only without `SH_DEGREE_0_COEF_0` (the RC's fallback).
    pub color0: Option<Decoded>,
    /// Degrees 1..=3, coefficient by coefficient (`None`: absent).
    pub higher: Vec<Vec<Option<Decoded>>>,
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

/// Decodes the attribute `name` (its semantic as in [`semantic`]) from the primitive's
/// `attrs`. `Some(None)`: absent; `None`: present but undecodable (a finding says why).
fn attribute(
    ctx: &Ctx,
    attrs: &Map<String, Value>,
    name: &str,
    f: &mut Vec<Finding>,
) -> Option<Option<Decoded>> {
    let full = semantic(name);
    let ap = attr_path(&ctx.path, &full);
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
}

/// Decodes every attribute the extension defines, then checks the required ones are there.
/// `None` after the first accessor that cannot be decoded, or a missing required attribute.
fn fetch(ctx: &Ctx, prim: &Value, f: &mut Vec<Finding>) -> Option<Attributes> {
    let empty = Map::new();
    let attrs = prim
        .get("attributes")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let mut get = |name: &str| attribute(ctx, attrs, name, f);
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
    let missing = report_missing(&ctx.path, &required, sh0.is_some(), color0.is_some(), f);
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

/// Reports each missing required attribute (POSITION, ROTATION, SCALE, OPACITY, then
/// SH_DEGREE_0_COEF_0, which COLOR_0 may stand in for). Returns whether one is missing with
/// nothing to stand in for it.
fn report_missing(
    path: &str,
    required: &[Option<Decoded>; 4],
    has_sh0: bool,
    has_color0: bool,
    f: &mut Vec<Finding>,
) -> bool {
    let mut missing = false;
    for (name, a) in ["POSITION", "ROTATION", "SCALE", "OPACITY"]
        .iter()
        .zip(required)
    {
        if a.is_none() {
            f.push(Finding::fatal(
                attr_path(path, &semantic(name)),
                "required attribute is missing",
            ));
            missing = true;
        }
    }
    if !has_sh0 {
        let sh0_path = attr_path(path, &semantic("SH_DEGREE_0_COEF_0"));
        if has_color0 {
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
    missing
}

/// Counts splats with one problem and remembers the first.
#[derive(Default)]
struct Tally {
    count: usize,
    first: Option<usize>,
}

impl Tally {
    fn add(&mut self, i: usize) {
        self.count += 1;
        self.first.get_or_insert(i);
    }
    /// An error at `path` and the first index, its message made from the count (blocking
    /// when `strict`).
    fn report(
        &self,
        path: &str,
        msg: impl Fn(usize) -> String,
        strict: bool,
        f: &mut Vec<Finding>,
    ) {
        if let Some(i) = self.first {
            let mut e = Finding::error(path, msg(self.count));
            e.blocks_loading = strict;
            f.push(e.at(i as u64));
        }
    }
}

/// Builds the local cloud: quaternions normalised (unit within a tolerance that allows for the
/// quantization step, the others counted), scales linearised, opacity rounding clamped, SH
/// gathered splat by splat. Unusable values (zero quaternions, non-finite values, log scales
/// whose `exp` overflows) are reported and stay in the cloud for the hygiene pass to drop.
fn assemble(
    ctx: &Ctx,
    a: &Attributes,
    meta: &SplatMeta,
    degree: u8,
    log: bool,
    f: &mut Vec<Finding>,
) -> LocalSplats {
    let n = a.position.count();
    let tol = match a.rotation.component {
        DataType::I8 => 1e-2,
        _ => 1e-3,
    };
    let rot_path = attr_path(&ctx.path, &semantic("ROTATION"));
    let scale_path = attr_path(&ctx.path, &semantic("SCALE"));
    let mut cloud = SplatCloud::with_capacity(degree, n);
    let k = cloud.coeffs_per_splat();
    let (mut non_unit, mut zero, mut overflow) =
        (Tally::default(), Tally::default(), Tally::default());
    let mut sh = vec![[0.0f32; 3]; k];
    cloud.meta = meta.clone();
    let srgb = cloud.meta.color_space.effective() == ColorSpace::SrgbRec709Display;
    for i in 0..n {
        let q = unit_rotation(a.rotation.get(i), tol, i, &mut zero, &mut non_unit);
        let s = linear_scale(a.scale.get(i), log, i, &mut overflow);
        gather_sh(a, i, degree, srgb, &mut sh);
        // Opacity is within 1e-6 of [0, 1] here (rules::check_opacity); NaN stays NaN.
        let o = a.opacity.data[i].clamp(0.0, 1.0);
        cloud.push(a.position.get(i), s, q, o, &sh);
    }
    let strict = ctx.opts.strict;
    let by = written_by(ctx);
    let unit = |n| format!("{n} quaternions are not unit length (tolerance {tol}); normalised{by}");
    non_unit.report(&rot_path, unit, false, f);
    let then = |n: usize| match (strict, n) {
        (true, _) => "strict mode".to_owned(),
        (false, 1) => "1 splat dropped".to_owned(),
        (false, n) => format!("{n} splats dropped"),
    };
    let zero_msg = |n| format!("quaternion is zero; {}", then(n));
    zero.report(&rot_path, zero_msg, strict, f);
    let overflow_msg = |n| format!("exp(log-space scale) overflows f32; {}", then(n));
    overflow.report(&scale_path, overflow_msg, strict, f);
    let scale_seen = if log {
        ScaleSeen::Log
    } else {
        ScaleSeen::Linear
    };
    LocalSplats {
        cloud,
        scale_seen,
        non_unit: non_unit.count,
        origin: None,
        details: None,
    }
}

/// Splat `i`'s quaternion normalised: kept bit for bit when unit to f32 rounding, left as it
/// is when zero (counted in `zero`, for the hygiene pass to drop); one off unit by more than
/// `tol` is counted in `non_unit`.
#[inline]
fn unit_rotation(
    q: [f32; 4],
    tol: f64,
    i: usize,
    zero: &mut Tally,
    non_unit: &mut Tally,
) -> [f32; 4] {
    let norm = q.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
    if norm < 1e-12 {
        zero.add(i);
        q // not unit: dropped by the hygiene pass
    } else {
        if (norm - 1.0).abs() > tol {
            non_unit.add(i);
        }
        if (norm - 1.0).abs() <= crate::load::UNIT_NORM_ROUNDING {
            q // unit to f32 rounding: kept bit for bit
        } else {
            q.map(|v| (v as f64 / norm) as f32)
        }
    }
}

/// Splat `i`'s scale made linear: `exp` of a log-space scale (an overflow of finite values is
/// counted in `overflow`), a linear one with -0 as 0.
#[inline]
fn linear_scale(s: [f32; 3], log: bool, i: usize, overflow: &mut Tally) -> [f32; 3] {
    if log {
        let e = s.map(f32::exp);
        if s.iter().all(|v| v.is_finite()) && !e.iter().all(|v| v.is_finite()) {
            overflow.add(i);
        }
        e
    } else {
        // -0 → 0; NaN stays NaN (f32::max would turn it into 0).
        s.map(|v| if v.is_nan() { v } else { v.max(0.0) })
    }
}

/// Splat `i`'s SH coefficients into `sh`: DC from SH_DEGREE_0_COEF_0 (or derived from COLOR_0),
/// then the present coefficients of degrees 1..=`degree`.
#[inline]
fn gather_sh(a: &Attributes, i: usize, degree: u8, srgb: bool, sh: &mut [[f32; 3]]) {
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
}

/// " (the file was written by …)" naming the asset's generator, or nothing without one.
///
/// The RC: "Rotation values are stored as unit quaternions" (so that renderers need not
/// renormalise); glTF-Validator holds node rotations and animated rotations to the same rule as
/// errors (ROTATION_NON_UNIT). Naming the writer tells the user whom to ask.
fn written_by(ctx: &Ctx) -> String {
    match ctx.doc.as_json().asset.generator.as_deref() {
        Some(g) if !g.trim().is_empty() => {
            // A file's own text, at most 80 characters: control, zero-width and bidirectional
            // characters (which would let a file rewrite what the terminal shows) as '?'.
            let g: String = g
                .trim()
                .chars()
                .take(80)
                .map(|c| if shown(c) { c } else { '?' })
                .collect();
            format!(" (the file was written by {g})")
        }
        _ => String::new(),
    }
}

/// Whether a character of the file's own text may be shown as it is: not a control, zero-width
/// or bidirectional character.
fn shown(c: char) -> bool {
    !(c.is_control()
        || ('\u{200B}'..='\u{200F}').contains(&c)
        || ('\u{202A}'..='\u{202E}').contains(&c)
        || ('\u{2066}'..='\u{2069}').contains(&c)
        || c == '\u{FEFF}')
}

/// Inverts the RC's COLOR_0 fallback: COLOR_0 = clamp(SH0·Y₀₀ + 0.5) (sRGB-decoded to linear
/// when the colour space is sRGB), so SH0 = (c − 0.5) / Y₀₀ with c re-encoded where needed.
/// A non-finite component gives NaN, never a clamped colour (`f32::clamp` would pass NaN on and
/// turn ±inf into 1 or 0): the rules report it and the hygiene pass drops the splat.
fn dc_from_color0(c: [f32; 3], srgb: bool) -> [f32; 3] {
    c.map(|v| {
        if !v.is_finite() {
            return f32::NAN;
        }
        let v = v.clamp(0.0, 1.0) as f64;
        let v = if srgb {
            crate::profile::srgb_encode(v)
        } else {
            v
        };
        crate::sh::dc_from_color(v)
    })
}
