//! PlayCanvas / SuperSplat "compressed PLY": splats in chunks of 256 sharing min/max ranges.
//!
//! Layout (binary little endian):
//! - `element chunk`: float `min_x..max_z`, `min_scale_x..max_scale_z` (log scale) and,
//!   optionally, `min_r..max_b` (colour range; [0, 1] when absent);
//! - `element vertex`: uint `packed_position` (11/10/11-bit unorm x/y/z within the chunk's
//!   box), `packed_rotation` (2-bit index of the largest component, then three 10-bit
//!   components scaled by √2), `packed_scale` (11/10/11 within the chunk's log-scale range),
//!   `packed_color` (8-bit r, g, b within the colour range, and linear opacity);
//! - optional `element sh`: uchar `f_rest_0..` (9/24/45, channel-major as INRIA), each byte
//!   `v` meaning `(n − 0.5)·8` with `n = 0` for 0, 1 for 255 and `(v + 0.5)/256` otherwise.
//!
//! The rotation's four components are in the INRIA order (w, x, y, z).

use super::header::{Element, Encoding, Header, Scalar};
use super::{PlyError, Unusable};
use crate::cloud::{SplatCloud, sh_coeff_count};
use crate::load::Details;

/// Splats per chunk.
const CHUNK: usize = 256;

/// Whether a vertex element is the compressed layout.
pub(super) fn is_compressed(vertex: &Element) -> bool {
    vertex.props.iter().any(|p| p.name == "packed_position")
}

/// Byte range of each element in the body (fixed-size rows only).
fn element_ranges(h: &Header, body: &[u8]) -> Result<Vec<(usize, usize)>, PlyError> {
    let mut out = Vec::new();
    let mut pos = 0usize;
    for el in &h.elements {
        if let Some(p) = el.props.iter().find(|p| p.list.is_some()) {
            return Err(PlyError::Unsupported(format!(
                "compressed PLY: list property '{}' in element '{}'",
                p.name, el.name
            )));
        }
        let (len, row) = super::fixed_rows_len(el, body.len() - pos)?;
        out.push((pos, row));
        pos += len;
    }
    Ok(out)
}

/// Column reader: value of property `name` (of type `ty`) in row `i` of element `e`.
struct Columns<'a> {
    data: &'a [u8],
    row: usize,
    offsets: Vec<(String, usize, Scalar)>,
}

impl<'a> Columns<'a> {
    fn new(el: &Element, body: &'a [u8], (start, row): (usize, usize)) -> Self {
        let mut off = 0;
        let offsets = el
            .props
            .iter()
            .map(|p| {
                let o = off;
                off += p.ty.size();
                (p.name.clone(), o, p.ty)
            })
            .collect();
        Columns {
            data: &body[start..start + row * el.count as usize],
            row,
            offsets,
        }
    }
    /// Offset of a property of the expected type, or a precise error.
    fn find(&self, el: &str, name: &str, ty: Scalar) -> Result<usize, PlyError> {
        match self.offsets.iter().find(|(n, _, _)| n == name) {
            Some((_, o, t)) if *t == ty => Ok(*o),
            Some((_, _, t)) => Err(PlyError::Unsupported(format!(
                "compressed PLY: element '{el}' property '{name}' is {t:?}, expected {ty:?}"
            ))),
            None => Err(PlyError::MissingProperty {
                property: format!("{el}.{name}"),
            }),
        }
    }
    fn f32_at(&self, i: usize, off: usize) -> f32 {
        let b = &self.data[i * self.row + off..];
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
    fn u32_at(&self, i: usize, off: usize) -> u32 {
        let b = &self.data[i * self.row + off..];
        u32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
}

/// The decoding is in f64, as the format's own JavaScript readers compute it: positions and
/// log scales are rounded to f32 once after the lerp (as they store them; an f32 lerp rounds
/// three times, which `exp` of a log scale turns into ~1e-6 relative), colours only when their
/// DC term is.
fn unorm(v: u32, bits: u32) -> f64 {
    let max = (1u32 << bits) - 1;
    (v & max) as f64 / max as f64
}

/// `a·(1 − t) + b·t`, rounded once.
fn lerp(a: f32, b: f32, t: f64) -> f32 {
    lerp64(a, b, t) as f32
}

/// `a·(1 − t) + b·t` in f64.
fn lerp64(a: f32, b: f32, t: f64) -> f64 {
    let (a, b) = (a as f64, b as f64);
    a * (1.0 - t) + b * t
}

/// 11/10/11 unorm triple (x in the high bits).
fn unpack_111011(v: u32) -> [f64; 3] {
    [unorm(v >> 21, 11), unorm(v >> 11, 10), unorm(v, 11)]
}

/// Smallest-three quaternion → the four stored components in the file's order.
fn unpack_rotation(v: u32) -> [f32; 4] {
    let k = std::f64::consts::SQRT_2; // components lie in [−1/√2, 1/√2]
    let a = (unorm(v >> 20, 10) - 0.5) * k;
    let b = (unorm(v >> 10, 10) - 0.5) * k;
    let c = (unorm(v, 10) - 0.5) * k;
    let m = (1.0 - (a * a + b * b + c * c)).max(0.0).sqrt();
    let [a, b, c, m] = [a, b, c, m].map(|x| x as f32);
    match v >> 30 {
        0 => [m, a, b, c],
        1 => [a, m, b, c],
        2 => [a, b, m, c],
        _ => [a, b, c, m],
    }
}

fn sh_byte(v: u8) -> f32 {
    let n = match v {
        0 => 0.0,
        255 => 1.0,
        v => (v as f32 + 0.5) / 256.0,
    };
    (n - 0.5) * 8.0
}

/// Offsets of the fields of the `chunk` and `vertex` rows.
struct Fields {
    /// `min_x, min_y, min_z, max_x, max_y, max_z`.
    bounds: [usize; 6],
    /// `min_scale_x..max_scale_z` (log scale).
    scales: [usize; 6],
    /// `min_r..max_b`, where present.
    colours: [Option<usize>; 6],
    /// `packed_position, packed_rotation, packed_scale, packed_color`.
    packed: [usize; 4],
}

impl Fields {
    fn find(chunks: &Columns, verts: &Columns) -> Result<Self, PlyError> {
        let f = |name: &str| chunks.find("chunk", name, Scalar::F32);
        let six = |infix: &str, axes: [&str; 3]| -> [String; 6] {
            std::array::from_fn(|i| {
                let side = if i < 3 { "min" } else { "max" };
                format!("{side}_{infix}{}", axes[i % 3])
            })
        };
        let (xyz, rgb) = (["x", "y", "z"], ["r", "g", "b"]);
        let mut bounds = [0; 6];
        let mut scales = [0; 6];
        for (o, n) in bounds.iter_mut().zip(six("", xyz)) {
            *o = f(&n)?;
        }
        for (o, n) in scales.iter_mut().zip(six("scale_", xyz)) {
            *o = f(&n)?;
        }
        let colours = six("", rgb).map(|c| f(&c).ok());
        let u = |name: &str| verts.find("vertex", name, Scalar::U32);
        let packed = [
            u("packed_position")?,
            u("packed_rotation")?,
            u("packed_scale")?,
            u("packed_color")?,
        ];
        Ok(Fields {
            bounds,
            scales,
            colours,
            packed,
        })
    }
}

/// The optional `sh` element: its columns, the offset of each `f_rest_j`, and the degree.
fn sh_element<'a>(
    h: &Header,
    body: &'a [u8],
    ranges: &[(usize, usize)],
    n: usize,
) -> Result<Option<(Columns<'a>, Vec<usize>, u8)>, PlyError> {
    let Some(si) = h.elements.iter().position(|e| e.name == "sh") else {
        return Ok(None);
    };
    let el = &h.elements[si];
    if el.count as usize != n {
        return Err(PlyError::Unsupported(format!(
            "compressed PLY: element 'sh' has {} rows, 'vertex' {n}",
            el.count
        )));
    }
    let cols = Columns::new(el, body, ranges[si]);
    let k = el.props.len();
    let degree = match k {
        9 => 1,
        24 => 2,
        45 => 3,
        count => return Err(PlyError::BadShCount { count }),
    };
    let offs = (0..k)
        .map(|j| cols.find("sh", &format!("f_rest_{j}"), Scalar::U8))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Some((cols, offs, degree)))
}

/// Decodes a compressed PLY whose header is `h` and body `body`. Quaternions are rebuilt unit
/// from their smallest three components, so none is reported as non-unit. Rows that decode to
/// unusable values are returned beside the cloud (which holds a placeholder for each).
pub(super) fn decode(h: &Header, body: &[u8]) -> Result<(SplatCloud, Unusable), PlyError> {
    if h.encoding != Encoding::Le {
        return Err(PlyError::Unsupported(
            "compressed PLY must be binary_little_endian".into(),
        ));
    }
    let ranges = element_ranges(h, body)?;
    let find = |name: &str| h.elements.iter().position(|e| e.name == name);
    let (ci, vi) = match (find("chunk"), find("vertex")) {
        (Some(c), Some(v)) => (c, v),
        _ => {
            return Err(PlyError::MissingProperty {
                property: "element 'chunk' (compressed PLY)".into(),
            });
        }
    };
    let (chunk_el, vertex_el) = (&h.elements[ci], &h.elements[vi]);
    let n = vertex_el.count as usize;
    if (chunk_el.count as usize).saturating_mul(CHUNK) < n {
        return Err(PlyError::Unsupported(format!(
            "compressed PLY: {} chunks cannot hold {n} splats (256 per chunk)",
            chunk_el.count
        )));
    }
    let chunks = Columns::new(chunk_el, body, ranges[ci]);
    let verts = Columns::new(vertex_el, body, ranges[vi]);
    let fields = Fields::find(&chunks, &verts)?;
    let sh = sh_element(h, body, &ranges, n)?;
    let degree = sh.as_ref().map_or(0, |s| s.2);
    let mut cloud = SplatCloud::with_capacity(degree, n);
    let mut coeffs = vec![[0.0f32; 3]; sh_coeff_count(degree)];
    let mut bad = Unusable::default();
    for i in 0..n {
        if let Some((cols, offs, _)) = &sh {
            let per = offs.len() / 3;
            for (j, &o) in offs.iter().enumerate() {
                coeffs[1 + j % per][j / per] = sh_byte(cols.data[i * cols.row + o]);
            }
        }
        if let Err(e) = push_splat(&chunks, &verts, &fields, i, &mut coeffs, &mut cloud) {
            bad.add(i, e);
            cloud.push([0.0; 3], [0.0; 3], [0.0, 0.0, 0.0, 1.0], 0.0, &coeffs);
        }
    }
    Ok((cloud, bad))
}

/// Decodes splat `i` and appends it to `cloud` with `coeffs`, whose DC term it sets (the
/// higher ones are the caller's).
fn push_splat(
    chunks: &Columns,
    verts: &Columns,
    fields: &Fields,
    i: usize,
    coeffs: &mut [[f32; 3]],
    cloud: &mut SplatCloud,
) -> Result<(), PlyError> {
    let c = i / CHUNK;
    let chunk_val = |off: usize| chunks.f32_at(c, off);
    let range =
        |offs: &[usize; 6], a: usize, t: f64| lerp(chunk_val(offs[a]), chunk_val(offs[a + 3]), t);
    let [pp, pr, ps, pc] = fields.packed;
    let p = unpack_111011(verts.u32_at(i, pp));
    let pos: [f32; 3] = std::array::from_fn(|a| range(&fields.bounds, a, p[a]));
    let s = unpack_111011(verts.u32_at(i, ps));
    let scale: [f32; 3] =
        std::array::from_fn(|a| (range(&fields.scales, a, s[a]) as f64).exp() as f32);
    let [w, x, y, z] = unpack_rotation(verts.u32_at(i, pr));
    let Some((rot, _)) = super::super::normalize_quat([x, y, z, w]) else {
        return Err(PlyError::Value {
            index: i,
            property: "packed_rotation".into(),
            message: "decodes to a zero quaternion".into(),
        });
    };
    let col = verts.u32_at(i, pc);
    let rgba = [
        unorm(col >> 24, 8),
        unorm(col >> 16, 8),
        unorm(col >> 8, 8),
        unorm(col, 8),
    ];
    for ch in 0..3 {
        // The colour stays in f64 until its DC term is rounded (once).
        let v = match (fields.colours[ch], fields.colours[ch + 3]) {
            (Some(lo), Some(hi)) => lerp64(chunk_val(lo), chunk_val(hi), rgba[ch]),
            _ => rgba[ch],
        };
        coeffs[0][ch] = crate::sh::dc_from_color(v);
    }
    let finite = pos
        .iter()
        .chain(&scale)
        .chain(coeffs[0].iter())
        .all(|v| v.is_finite());
    if !finite {
        return Err(PlyError::Value {
            index: i,
            property: "chunk ranges".into(),
            message: "decode to a non-finite position, scale or colour".into(),
        });
    }
    cloud.push(pos, scale, rot, rgba[3] as f32, coeffs);
    Ok(())
}

/// What the compressed layout keeps of each attribute (`splatgl info`).
pub(super) fn details(degree: u8) -> Details {
    let mut d = Details::new("compressed_ply", "none");
    d.bits(
        "position",
        11,
        "11/10/11-bit unorm x/y/z in the chunk's box",
    );
    d.bits(
        "scale",
        11,
        "11/10/11-bit unorm ln(scale) in the chunk's range",
    );
    d.bits(
        "rotation",
        10,
        "smallest three: 2-bit index, 3 × 10-bit components",
    );
    d.bits("color", 8, "8-bit colour in the chunk's range (or [0, 1])");
    d.bits("opacity", 8, "b/255 (linear)");
    d.lossy("positions and log scales in 2047/1023 steps of each 256-splat chunk's range");
    d.lossy("rotation components in 1023 steps of [−1/√2, 1/√2]");
    d.lossy("colours and opacity in 255 steps");
    if degree > 0 {
        d.bits("sh", 8, "((b + 0.5)/256 − 0.5) · 8");
        d.lossy("SH in steps of 1/32, clamped to [−4, 4]");
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_unpacking_is_unit_and_places_the_largest() {
        // a = b = c = 0 (512 ≈ 0.5 → 0), largest = w (index 3).
        let v = (3 << 30) | (512 << 20) | (512 << 10) | 512;
        let q = unpack_rotation(v);
        assert!((q[3] - 1.0).abs() < 1e-2 && q[0].abs() < 1e-2);
        assert_eq!(unpack_111011(u32::MAX), [1.0, 1.0, 1.0]);
        assert_eq!(sh_byte(0), -4.0);
        assert_eq!(sh_byte(255), 4.0);
    }
}
