//! ASCII PLY bodies: one row per line, values parsed at their declared precision.

use super::header::{Element, Header, Property, Scalar};
use super::{Layout, PlyError, RowNotes, Unusable, convert_row};
use crate::cloud::{SplatCloud, sh_coeff_count};

/// Decodes the `vertex` rows (element `vi`) of an ASCII body; returns the cloud, the number of
/// non-unit quaternions and the rows whose values cannot be used (still in the cloud).
pub(super) fn decode(
    header: &Header,
    vi: usize,
    l: &Layout,
    body: &[u8],
) -> Result<(SplatCloud, RowNotes, Unusable), PlyError> {
    let vertex = &header.elements[vi];
    let text = std::str::from_utf8(body).map_err(|e| PlyError::Ascii {
        line: header.lines + 1,
        message: format!("body is not text ({e})"),
    })?;
    let mut lines = text.lines().enumerate();
    skip_elements(&header.elements[..vi], &mut lines)?;
    let ncols = vertex.props.len();
    // Each value needs at least one digit and one separator.
    let min_bytes = vertex.count.saturating_mul(2 * ncols as u64);
    if min_bytes > body.len() as u64 {
        return Err(PlyError::Truncated {
            element: "vertex".into(),
            count: vertex.count,
            needed: min_bytes,
            available: body.len() as u64,
        });
    }
    let n = vertex.count as usize;
    let k = sh_coeff_count(l.sh_degree);
    let mut cloud = SplatCloud::with_capacity(l.sh_degree, n);
    let mut vals = vec![0.0f64; ncols];
    let mut sh = vec![[0.0f32; 3]; k];
    let (mut notes, mut bad) = (RowNotes::default(), Unusable::default());
    for i in 0..n {
        let (ln, line) = lines.next().ok_or_else(|| PlyError::EndsEarly {
            element: "vertex".into(),
            count: vertex.count,
            rows_read: i as u64,
        })?;
        parse_row(line, header.lines + ln + 1, &vertex.props, &mut vals)?;
        let (mut p, mut s, mut r, mut o) = ([0.0; 3], [0.0; 3], [0.0; 4], 0.0);
        let off = convert_row(
            l,
            &vertex.props,
            i,
            |c| vals[c],
            &mut p,
            &mut s,
            &mut r,
            &mut o,
            &mut sh,
        );
        match off {
            Ok(flags) => notes.add(i, flags),
            Err(e) => bad.add(i, e),
        }
        cloud.push(p, s, r, o, &sh);
    }
    Ok((cloud, notes, bad))
}

/// Skips the rows of `elements` (those before the vertex element, or after it), one line each.
pub(super) fn skip_elements<'t>(
    elements: &[Element],
    lines: &mut impl Iterator<Item = (usize, &'t str)>,
) -> Result<(), PlyError> {
    for el in elements {
        for r in 0..el.count {
            if lines.next().is_none() {
                return Err(PlyError::EndsEarly {
                    element: el.name.clone(),
                    count: el.count,
                    rows_read: r,
                });
            }
        }
    }
    Ok(())
}

/// Parses the values of one row (file line `line_no`) into `vals`, one per property, each at
/// its declared precision.
#[inline]
fn parse_row(
    line: &str,
    line_no: usize,
    props: &[Property],
    vals: &mut [f64],
) -> Result<(), PlyError> {
    let ncols = props.len();
    let mut it = line.split_ascii_whitespace();
    for (c, v) in vals.iter_mut().enumerate() {
        let tok = it.next().ok_or_else(|| PlyError::Ascii {
            line: line_no,
            message: format!("expected {ncols} values, found {c}"),
        })?;
        // Parse at the declared precision so ASCII equals the binary encoding exactly.
        let parsed = match props[c].ty {
            Scalar::F32 => tok.parse::<f32>().map(f64::from).ok(),
            _ => tok.parse::<f64>().ok(),
        };
        *v = parsed.ok_or_else(|| PlyError::Ascii {
            line: line_no,
            message: format!(
                "value {tok:?} of property '{}' is not a number",
                props[c].name
            ),
        })?;
    }
    Ok(())
}
