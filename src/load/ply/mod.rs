//! INRIA 3DGS PLY: `x y z [nx ny nz] f_dc_0..2 f_rest_* opacity scale_0..2 rot_0..3`
//! (binary little/big endian or ASCII), or `red green blue` instead of `f_dc_*`.
//!
//! Conversions to [`SplatCloud`] conventions: logit opacity → sigmoid (±inf → 1/0), log scale
//! → exp, `(w, x, y, z)` → `[x, y, z, w]` normalised (counted when not unit), `f_rest`
//! channel-major → degree-major RGB triples, `red/green/blue` (u8 → /255, floats as they are)
//! → DC coefficient `(c − 0.5) / Y₀₀`. Extra properties are ignored.
//!
//! PlayCanvas compressed PLY (`packed_*` properties) is decoded by `compressed.rs` beside this file.
//!
//! Binary rows are decoded in parallel (rayon, blocks of rows) with property offsets resolved
//! once from the header: no per-property lookups in the inner loop.

use super::{Finding, LoadOptions, LoadReport, ScaleSeen};
use crate::cloud::SplatCloud;

mod error;
pub use error::PlyError;

mod ascii;
mod binary;
mod compressed;
mod header;
mod stream;
use binary::{decode_binary, skip_binary};
use header::{Element, Encoding, Header, Property, Scalar, parse_header};
pub use stream::{PlyRows, StreamError};

/// Which columns feed which output: offsets (binary) or column indices (ASCII) per field.
struct Layout {
    pos: [usize; 3],
    /// DC source: f_dc (SH) or red/green/blue (colour, with a divisor: 255 for u8).
    dc: [usize; 3],
    dc_is_color: Option<f64>,
    /// `f_rest_j` columns with their destination in the splat's flat SH array:
    /// channel-major `j = ch·K + coef` → degree-major `(1 + coef)·3 + ch`, resolved once.
    rest: Vec<(usize, usize)>,
    opacity: usize,
    scale: [usize; 3],
    rot: [usize; 4],
    /// (offset, type) per column, binary.
    cols: Vec<(usize, Scalar)>,
    stride: usize,
    sh_degree: u8,
}

fn layout(vertex: &Element) -> Result<Layout, PlyError> {
    if let Some(p) = vertex.props.iter().find(|p| p.list.is_some()) {
        return Err(PlyError::Unsupported(format!(
            "list property '{}' in element 'vertex'",
            p.name
        )));
    }
    let find = |name: &str| vertex.props.iter().position(|p| p.name == name);
    let n_rest = vertex
        .props
        .iter()
        .filter(|p| p.name.starts_with("f_rest_"))
        .count();
    let sh_degree = match n_rest {
        0 => 0,
        9 => 1,
        24 => 2,
        45 => 3,
        count => return Err(PlyError::BadShCount { count }),
    };
    let need = |name: &str| {
        find(name).ok_or_else(|| PlyError::MissingProperty {
            property: name.to_owned(),
        })
    };
    let mut cols = Vec::with_capacity(vertex.props.len());
    let mut off = 0;
    for p in &vertex.props {
        cols.push((off, p.ty));
        off += p.ty.size();
    }
    let (dc, dc_is_color) = match find("f_dc_0") {
        Some(_) => ([need("f_dc_0")?, need("f_dc_1")?, need("f_dc_2")?], None),
        None if find("red").is_some() => {
            let r = need("red")?;
            let div = match vertex.props[r].ty {
                Scalar::F32 | Scalar::F64 => 1.0,
                Scalar::U8 => 255.0,
                Scalar::U16 => 65535.0,
                t => {
                    return Err(PlyError::Unsupported(format!(
                        "colour property 'red' of type {t:?}"
                    )));
                }
            };
            ([r, need("green")?, need("blue")?], Some(div))
        }
        None => return Err(need("f_dc_0").unwrap_err()),
    };
    let k_rest = n_rest / 3;
    let rest = (0..n_rest)
        .map(|j| {
            Ok((
                need(&format!("f_rest_{j}"))?,
                (1 + j % k_rest) * 3 + j / k_rest,
            ))
        })
        .collect::<Result<Vec<_>, PlyError>>()?;
    Ok(Layout {
        pos: [need("x")?, need("y")?, need("z")?],
        dc,
        dc_is_color,
        rest,
        opacity: need("opacity")?,
        scale: [need("scale_0")?, need("scale_1")?, need("scale_2")?],
        rot: [
            need("rot_0")?,
            need("rot_1")?,
            need("rot_2")?,
            need("rot_3")?,
        ],
        cols,
        stride: off,
        sh_degree,
    })
}

/// Logit → opacity, in f64 (the PLY writer inverts exactly this function).
pub(crate) fn sigmoid(x: f64) -> f64 {
    if x >= 0.0 {
        1.0 / (1.0 + (-x).exp())
    } else {
        let e = x.exp();
        e / (1.0 + e)
    }
}

/// [`convert_row`]'s result flag: the quaternion was not unit length.
pub(super) const NON_UNIT: u8 = 1;
/// [`convert_row`]'s result flag: the opacity logit was ±inf (read as opacity 1 or 0).
pub(super) const INF_OPACITY: u8 = 2;

/// What [`convert_row`] noticed over many rows: counts of its flags, and the first row with
/// an infinite opacity logit.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct RowNotes {
    /// Quaternions that were not unit length.
    pub non_unit: usize,
    /// Opacity logits that were ±inf.
    pub inf_opacity: usize,
    /// The first row with one.
    pub first_inf: Option<usize>,
}

impl RowNotes {
    /// Counts row `index`'s flags (rows in ascending order).
    pub fn add(&mut self, index: usize, flags: u8) {
        self.non_unit += (flags & NON_UNIT != 0) as usize;
        if flags & INF_OPACITY != 0 {
            self.inf_opacity += 1;
            self.first_inf.get_or_insert(index);
        }
    }
    /// Adds the notes of later rows.
    pub fn merge(&mut self, later: RowNotes) {
        self.non_unit += later.non_unit;
        self.inf_opacity += later.inf_opacity;
        self.first_inf = self.first_inf.or(later.first_inf);
    }
}

/// Converts one row (read through `get(column)`) into the outputs of splat `index`.
/// Returns [`NON_UNIT`] and [`INF_OPACITY`] flags.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn convert_row(
    l: &Layout,
    names: &[Property],
    index: usize,
    get: impl Fn(usize) -> f64,
    pos: &mut [f32; 3],
    scale: &mut [f32; 3],
    rot: &mut [f32; 4],
    opacity: &mut f32,
    sh: &mut [[f32; 3]],
) -> Result<u8, PlyError> {
    let bad = |col: usize, message: &str| PlyError::Value {
        index,
        property: names[col].name.clone(),
        message: message.to_owned(),
    };
    for k in 0..3 {
        let v = get(l.pos[k]);
        if !v.is_finite() {
            return Err(bad(l.pos[k], "position is not finite"));
        }
        pos[k] = v as f32;
        if !pos[k].is_finite() {
            return Err(bad(l.pos[k], "position overflows f32"));
        }
        let s = get(l.scale[k]);
        if s.is_nan() {
            return Err(bad(l.scale[k], "log scale is NaN"));
        }
        scale[k] = s.exp() as f32;
        if !scale[k].is_finite() {
            return Err(bad(l.scale[k], "exp(log scale) overflows f32"));
        }
        let d = get(l.dc[k]);
        if !d.is_finite() {
            return Err(bad(l.dc[k], "colour coefficient is not finite"));
        }
        sh[0][k] = match l.dc_is_color {
            None => d as f32,
            Some(div) => crate::sh::dc_from_color(d / div),
        };
        if !sh[0][k].is_finite() {
            return Err(bad(l.dc[k], "colour coefficient overflows f32"));
        }
    }
    // Branch-free copy; the (rare) error path finds the culprit afterwards.
    let flat: &mut [f32] = bytemuck::cast_slice_mut(sh);
    let mut finite = true;
    for &(col, dst) in &l.rest {
        let v = get(col) as f32;
        flat[dst] = v;
        finite &= v.is_finite();
    }
    if !finite {
        for &(col, _) in &l.rest {
            let v = get(col);
            if !v.is_finite() {
                return Err(bad(col, "SH coefficient is not finite"));
            }
            if !(v as f32).is_finite() {
                return Err(bad(col, "SH coefficient overflows f32"));
            }
        }
    }
    let o = get(l.opacity);
    if o.is_nan() {
        return Err(bad(l.opacity, "opacity logit is NaN"));
    }
    *opacity = sigmoid(o) as f32;
    let inf = if o.is_infinite() { INF_OPACITY } else { 0 };
    let q = [get(l.rot[1]), get(l.rot[2]), get(l.rot[3]), get(l.rot[0])].map(|v| v as f32);
    match super::normalize_quat(q) {
        Some((q, off)) => {
            *rot = q;
            Ok(inf | if off { NON_UNIT } else { 0 })
        }
        None => Err(bad(l.rot[0], "quaternion is zero or not finite")),
    }
}

/// Rows whose values cannot be used ([`PlyError::Value`] from [`convert_row`]): how many, and
/// the first one's error. Without strict mode they are dropped; with it, the first one fails.
#[derive(Debug, Default)]
pub(super) struct Unusable {
    /// Row indices, ascending.
    pub rows: Vec<usize>,
    /// The first row's error.
    pub first: Option<PlyError>,
}

impl Unusable {
    /// Records row `i` (rows must come in ascending order).
    pub(super) fn add(&mut self, i: usize, e: PlyError) {
        self.rows.push(i);
        self.first.get_or_insert(e);
    }
    /// Appends a later block's rows.
    pub(super) fn extend(&mut self, other: Unusable) {
        self.rows.extend(other.rows);
        if let Some(e) = other.first {
            self.first.get_or_insert(e);
        }
    }
    /// Strict: the first error. Otherwise the rows are dropped from `cloud` and one warning
    /// names the first row's property and problem and the count.
    fn settle(
        self,
        cloud: &mut SplatCloud,
        strict: bool,
        findings: &mut Vec<Finding>,
    ) -> Result<(), PlyError> {
        let Some(first) = self.first else {
            return Ok(());
        };
        if strict {
            return Err(first);
        }
        let n = self.rows.len();
        let (path, msg) = match &first {
            PlyError::Value {
                property, message, ..
            } => (format!("vertex.{property}"), message.clone()),
            e => ("vertex".to_owned(), e.to_string()),
        };
        let s = if n == 1 { "" } else { "s" };
        findings.push(
            Finding::warning(
                path,
                format!("{msg}; {n} splat{s} with unusable values dropped (the first is named)"),
            )
            .at(self.rows[0] as u64),
        );
        super::hygiene::drop_splats(cloud, &self.rows);
        Ok(())
    }
}

/// Reads a PLY file from memory; what it notices goes to `report`.
pub(crate) fn read(
    bytes: &[u8],
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<SplatCloud, PlyError> {
    let header = parse_header(bytes)?;
    let vi = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or(PlyError::NoVertexElement)?;
    let vertex = &header.elements[vi];
    opts.limits.check_splats(vertex.count, "element 'vertex'")?;
    let body = &bytes[header.body..];
    report.scale_space = Some(ScaleSeen::Log);
    if compressed::is_compressed(vertex) {
        let (mut cloud, bad) = compressed::decode(&header, body)?;
        report.details = Some(compressed::details(cloud.sh_degree));
        report.findings.push(Finding::warning(
            "",
            "PlayCanvas compressed PLY: quantised positions, scales, rotations and colours",
        ));
        bad.settle(&mut cloud, opts.strict, &mut report.findings)?;
        return Ok(cloud);
    }
    let l = layout(vertex)?;

    if let Some(e) = trailing_problem(&header, vi, body, l.stride) {
        report.findings.push(Finding::warning(
            header.elements[vi + 1].name.clone(),
            format!("{e} (after the vertex data, which is read; the rest is ignored)"),
        ));
    }
    let (mut cloud, notes, bad) = match header.encoding {
        Encoding::Ascii => ascii::decode(&header, vi, &l, body)?,
        enc => {
            let start = skip_binary(&header.elements[..vi], body, enc == Encoding::Be)?;
            let rows = &body[start..];
            let n = vertex.count;
            let needed = n.saturating_mul(l.stride as u64);
            if needed > rows.len() as u64 || (n > 0 && l.stride == 0) {
                return Err(PlyError::Truncated {
                    element: "vertex".into(),
                    count: n,
                    needed,
                    available: rows.len() as u64,
                });
            }
            decode_binary(
                &l,
                &vertex.props,
                &rows[..needed as usize],
                enc == Encoding::Be,
            )?
        }
    };
    bad.settle(&mut cloud, opts.strict, &mut report.findings)?;
    let non_unit = notes.non_unit;
    if let Some(first) = notes.first_inf {
        let n = notes.inf_opacity;
        report.findings.push(
            Finding::warning(
                "vertex.opacity",
                format!("{n} opacity logits are ±inf (non-finite; read as opacity 1 or 0)"),
            )
            .at(first as u64),
        );
    }
    if non_unit > 0 {
        // Normal for trained output (3DGS trainers store raw, unnormalised quaternions).
        report.findings.push(Finding::info(
            "vertex.rot_0..3",
            format!("{non_unit} quaternions were not unit length and were normalised"),
        ));
    }
    report.non_unit_quaternions = non_unit;
    report.non_finite_opacities = notes.inf_opacity;
    Ok(cloud)
}

/// Whether the elements after `vertex` (element `vi`) are all there: the first one that the
/// body ends inside, as the error that says how much is missing. `None` when there are none
/// after it, or the vertex rows themselves are short (the decode reports that).
fn trailing_problem(header: &Header, vi: usize, body: &[u8], stride: usize) -> Option<PlyError> {
    let after = &header.elements[vi + 1..];
    if after.is_empty() {
        return None;
    }
    match header.encoding {
        Encoding::Ascii => {
            let text = std::str::from_utf8(body).ok()?;
            let mut lines = text.lines().enumerate();
            ascii::skip_elements(&header.elements[..=vi], &mut lines).ok()?;
            ascii::skip_elements(after, &mut lines).err()
        }
        enc => {
            let be = enc == Encoding::Be;
            let start = skip_binary(&header.elements[..vi], body, be).ok()?;
            let n = header.elements[vi].count;
            let end = (start as u64).checked_add(n.checked_mul(stride as u64)?)?;
            let rest = body.get(usize::try_from(end).ok()?..)?;
            skip_binary(after, rest, be).err()
        }
    }
}

/// (bytes, row size) of an element of fixed-size rows, checked against the `available` bytes
/// before anything is read or allocated.
fn fixed_rows_len(el: &Element, available: usize) -> Result<(usize, usize), PlyError> {
    let row: usize = el.props.iter().map(|p| p.ty.size()).sum();
    let needed = el.count.saturating_mul(row as u64);
    if needed > available as u64 {
        return Err(PlyError::Truncated {
            element: el.name.clone(),
            count: el.count,
            needed,
            available: available as u64,
        });
    }
    Ok((needed as usize, row))
}
