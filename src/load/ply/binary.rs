//! Binary PLY bodies (little or big endian): the elements before `vertex` skipped, the
//! `vertex` rows decoded in parallel blocks.

use super::header::{Element, Property, Scalar};
use super::{Layout, PlyError, RowNotes, Unusable, convert_row, fixed_rows_len};
use crate::cloud::{SplatCloud, sh_coeff_count};
use rayon::prelude::*;

/// Byte offset just past the elements before `vertex` (binary).
pub(super) fn skip_binary(before: &[Element], body: &[u8], be: bool) -> Result<usize, PlyError> {
    let mut pos = 0usize;
    for el in before {
        let ends = |rows_read: u64| PlyError::EndsEarly {
            element: el.name.clone(),
            count: el.count,
            rows_read,
        };
        if el.props.is_empty() {
            if el.count > 0 {
                return Err(PlyError::Unsupported(format!(
                    "element '{}' has rows but no properties",
                    el.name
                )));
            }
            continue;
        }
        if el.props.iter().all(|p| p.list.is_none()) {
            pos += fixed_rows_len(el, body.len() - pos)?.0;
            continue;
        }
        // Rows with lists: walk them (each row takes at least one byte, so the count is
        // bounded by the data before the walk starts).
        if el.count > (body.len() - pos) as u64 {
            return Err(PlyError::Truncated {
                element: el.name.clone(),
                count: el.count,
                needed: el.count,
                available: (body.len() - pos) as u64,
            });
        }
        for r in 0..el.count {
            for p in &el.props {
                let n = match p.list {
                    Some(ct) => {
                        if pos + ct.size() > body.len() {
                            return Err(ends(r));
                        }
                        let n = ct.read(&body[pos..], be);
                        pos += ct.size();
                        if !(0.0..=u32::MAX as f64).contains(&n) {
                            return Err(PlyError::Unsupported(format!(
                                "element '{}': negative list length",
                                el.name
                            )));
                        }
                        n as usize
                    }
                    None => 1,
                };
                let len = n.saturating_mul(p.ty.size());
                if len > body.len() - pos {
                    return Err(ends(r));
                }
                pos += len;
            }
        }
    }
    Ok(pos)
}

const BLOCK: usize = 4096;

/// Decodes the `vertex` rows; returns the cloud, what the rows showed ([`RowNotes`]) and the
/// rows whose values cannot be used (left in the cloud for the caller to drop or fail on).
pub(super) fn decode_binary(
    l: &Layout,
    props: &[Property],
    rows: &[u8],
    be: bool,
) -> Result<(SplatCloud, RowNotes, Unusable), PlyError> {
    let n = rows.len().checked_div(l.stride).unwrap_or(0);
    let k = sh_coeff_count(l.sh_degree);
    let all_f32_le = !be && l.cols.iter().all(|&(_, t)| t == Scalar::F32);
    let mut cloud = SplatCloud::new(l.sh_degree);
    cloud.positions = vec![[0.0; 3]; n];
    cloud.scales = vec![[0.0; 3]; n];
    cloud.rotations = vec![[0.0; 4]; n];
    cloud.opacities = vec![0.0; n];
    cloud.sh = vec![[0.0; 3]; n * k];
    crate::files::advise_huge(&mut cloud.positions);
    crate::files::advise_huge(&mut cloud.scales);
    crate::files::advise_huge(&mut cloud.rotations);
    crate::files::advise_huge(&mut cloud.opacities);
    crate::files::advise_huge(&mut cloud.sh);
    let results: Vec<(RowNotes, Unusable)> = cloud
        .positions
        .par_chunks_mut(BLOCK)
        .zip(cloud.scales.par_chunks_mut(BLOCK))
        .zip(cloud.rotations.par_chunks_mut(BLOCK))
        .zip(cloud.opacities.par_chunks_mut(BLOCK))
        .zip(cloud.sh.par_chunks_mut(BLOCK * k))
        .zip(rows.par_chunks(BLOCK * l.stride))
        .enumerate()
        .map(|(b, (((((p, s), r), o), sh), raw))| {
            let (mut notes, mut bad) = (RowNotes::default(), Unusable::default());
            for i in 0..p.len() {
                let row = &raw[i * l.stride..(i + 1) * l.stride];
                let out = (&mut p[i], &mut s[i], &mut r[i], &mut o[i]);
                let sh = &mut sh[i * k..(i + 1) * k];
                // The common case (every column f32, little endian) gets its own
                // monomorphised copy of `convert_row` without the per-value type dispatch.
                let index = b * BLOCK + i;
                let off = if all_f32_le {
                    let get = |c: usize| {
                        let off = l.cols[c].0;
                        f32::from_le_bytes([row[off], row[off + 1], row[off + 2], row[off + 3]])
                            as f64
                    };
                    convert_row(l, props, index, get, out.0, out.1, out.2, out.3, sh)
                } else {
                    let get = |c: usize| {
                        let (off, ty) = l.cols[c];
                        ty.read(&row[off..], be)
                    };
                    convert_row(l, props, index, get, out.0, out.1, out.2, out.3, sh)
                };
                match off {
                    Ok(flags) => notes.add(index, flags),
                    Err(e) => bad.add(index, e),
                }
            }
            // Each row is read once: a mapped file's pages of this block leave the resident
            // set now, so peak memory is the cloud plus the blocks in flight.
            crate::files::release_consumed(raw);
            (notes, bad)
        })
        .collect();
    let (mut notes, mut bad) = (RowNotes::default(), Unusable::default());
    for (n, b) in results {
        notes.merge(n);
        bad.extend(b);
    }
    Ok((cloud, notes, bad))
}
