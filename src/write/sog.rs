//! PlayCanvas SOG (version 2) writer, the inverse of [`crate::load::sog`]: a `meta.json` and
//! lossless WebP textures, one texel per splat (row-major) —
//! - `means_l`, `means_u`: the low and high bytes of x, y, z as `sign(x)·ln(1 + |x|)` in 65535
//!   steps of the meta's per-axis range;
//! - `quats`: the three smallest components of the unit quaternion (w, x, y, z order, the
//!   largest made positive), each `(c·√2 + 1)/2` in 8 bits, and `252 + index` of the largest;
//! - `scales`: per axis an index into a 256-entry codebook of ln(scale);
//! - `sh0`: per channel an index into a 256-entry codebook of the DC coefficient, opacity·255;
//! - with SH: `shN_labels` a 16-bit palette index per splat and `shN_centroids` the palette
//!   (64 entries a row, one texel per coefficient, per channel an index into a 256-entry
//!   codebook).
//!
//! The codebooks are 1D k-means (Lloyd's iterations from quantiles and evenly spaced values,
//! over the sorted values); the
//! SH palette holds every splat's coefficients exactly when there are at most 65,536 splats,
//! else a median cut of them into 65,536 boxes (their means). Texture sizes follow
//! splat-transform: width ⌈√n / 4⌉·4, height ⌈n / width / 4⌉·4. [`to_sog_bundle`] stores the
//! files in a zip (`.sog`), as splat-transform writes them.

use crate::cloud::{SplatCloud, sh_coeff_count};
use serde_json::json;

/// The files of one SOG: `(name, bytes)`, `meta.json` first.
pub type SogFiles = Vec<(String, Vec<u8>)>;

/// Entries of each codebook.
const CODEBOOK: usize = 256;
/// Most SH palette entries (16-bit labels).
const PALETTE: usize = 65_536;
/// Lloyd iterations of the codebooks.
const ITERATIONS: usize = 64;

/// Why a SOG could not be written.
#[derive(Debug, thiserror::Error)]
pub enum SogWriteError {
    /// The WebP encoder failed on a texture.
    #[error("WebP encoder: {0}")]
    WebP(#[from] image_webp::EncodingError),
    /// The bundle would be past the 4 GiB a zip without zip64 addresses.
    #[error("a SOG bundle of {0} bytes is past the zip limit of 4 GiB")]
    TooLarge(usize),
    /// `meta.json` could not be written.
    #[error("meta.json: {0}")]
    Meta(#[from] serde_json::Error),
}

impl From<SogWriteError> for String {
    fn from(e: SogWriteError) -> String {
        e.to_string()
    }
}

/// The textures' layout: `width × height` texels (multiples of 4), splat `i` at texel `i`.
struct Grid {
    n: usize,
    width: usize,
    height: usize,
}

impl Grid {
    fn for_splats(n: usize) -> Self {
        let width = (((n as f64).sqrt() / 4.0).ceil() as usize * 4).max(4);
        let height = (n.div_ceil(width).div_ceil(4) * 4).max(4);
        Grid { n, width, height }
    }

    /// The lossless WebP of the texels `f(i)` (zero past the splats), added to `files`.
    fn add(
        &self,
        files: &mut SogFiles,
        name: &str,
        f: &dyn Fn(usize) -> [u8; 4],
    ) -> Result<(), SogWriteError> {
        let rgba: Vec<u8> = (0..self.width * self.height)
            .flat_map(|i| if i < self.n { f(i) } else { [0; 4] })
            .collect();
        files.push((name.to_owned(), webp(&rgba, self.width, self.height)?));
        Ok(())
    }
}

/// Encodes `cloud` as the files of an unbundled SOG (`meta.json` and its WebP textures).
/// `Err` only if the WebP encoder fails.
pub fn to_sog_files(cloud: &SplatCloud) -> Result<SogFiles, SogWriteError> {
    let n = cloud.len();
    let g = Grid::for_splats(n);
    let mut files: SogFiles = vec![(String::new(), Vec::new())];
    let (mins, maxs) = add_means(&mut files, cloud, &g)?;
    g.add(&mut files, "quats.webp", &|i| {
        quat_texel(cloud.rotations[i])
    })?;

    // Scales: a codebook of ln(scale), shared by the three axes.
    let ln_scales: Vec<f32> = cloud
        .scales
        .iter()
        .flat_map(|s| s.map(|v| v.max(1e-12).ln()))
        .collect();
    let scales = Codebook::fit(&ln_scales);
    g.add(&mut files, "scales.webp", &|i| {
        let b = |a: usize| scales.index(ln_scales[3 * i + a]);
        [b(0), b(1), b(2), 255]
    })?;

    // DC colour and opacity.
    let dc: Vec<f32> = (0..n).flat_map(|i| cloud.sh_of(i)[0]).collect();
    let sh0 = Codebook::fit(&dc);
    g.add(&mut files, "sh0.webp", &|i| {
        let b = |c: usize| sh0.index(dc[3 * i + c]);
        let alpha = (cloud.opacities[i] * 255.0).round().clamp(0.0, 255.0) as u8;
        [b(0), b(1), b(2), alpha]
    })?;

    let mut meta = json!({
        "version": 2,
        "asset": {"generator": concat!("splatgl ", env!("CARGO_PKG_VERSION"))},
        "count": n,
        "means": {"mins": mins, "maxs": maxs, "files": ["means_l.webp", "means_u.webp"]},
        "scales": {"codebook": scales.values, "files": ["scales.webp"]},
        "quats": {"files": ["quats.webp"]},
        "sh0": {"codebook": sh0.values, "files": ["sh0.webp"]},
    });
    if cloud.sh_degree > 0 && n > 0 {
        let (sh_n, centroids, labels) = palette(cloud, g.width, g.height)?;
        meta["shN"] = sh_n;
        files.push(("shN_centroids.webp".into(), centroids));
        files.push(("shN_labels.webp".into(), labels));
    }
    files[0] = ("meta.json".into(), serde_json::to_vec(&meta)?);
    Ok(files)
}

/// Means: log-transformed, 16 bits in the range of each axis (low and high bytes in two
/// textures); returns the range.
fn add_means(
    files: &mut SogFiles,
    cloud: &SplatCloud,
    g: &Grid,
) -> Result<([f64; 3], [f64; 3]), SogWriteError> {
    let logs: Vec<[f64; 3]> = cloud
        .positions
        .iter()
        .map(|p| p.map(|x| (x as f64).signum() * (x as f64).abs().ln_1p()))
        .collect();
    let (mut mins, mut maxs) = ([0f64; 3], [0f64; 3]);
    for a in 0..3 {
        // Finite values only: the meta's range must be JSON numbers.
        let axis = logs.iter().map(|l| l[a]).filter(|x| x.is_finite());
        if axis.clone().next().is_some() {
            mins[a] = axis.clone().fold(f64::INFINITY, f64::min);
            maxs[a] = axis.fold(f64::NEG_INFINITY, f64::max);
        }
    }
    let step = |i: usize, a: usize| -> u16 {
        let span = maxs[a] - mins[a];
        if span <= 0.0 {
            return 0;
        }
        ((logs[i][a] - mins[a]) / span * 65535.0)
            .round()
            .clamp(0.0, 65535.0) as u16
    };
    let byte_of = |i: usize, high: bool| -> [u8; 4] {
        let b = |a| (step(i, a) >> if high { 8 } else { 0 }) as u8;
        [b(0), b(1), b(2), 255]
    };
    g.add(files, "means_l.webp", &|i| byte_of(i, false))?;
    g.add(files, "means_u.webp", &|i| byte_of(i, true))?;
    Ok((mins, maxs))
}

/// [`to_sog_files`] stored (uncompressed: WebP is compressed already) in one zip, `.sog`.
pub fn to_sog_bundle(cloud: &SplatCloud) -> Result<Vec<u8>, SogWriteError> {
    zip_stored(&to_sog_files(cloud)?)
}

/// One texel of `quats` for `[x, y, z, w]`: see the module docs (a zero quaternion is the
/// identity).
fn quat_texel(q: [f32; 4]) -> [u8; 4] {
    let [x, y, z, w] = match crate::load::normalize_quat(q) {
        Some((q, _)) => q,
        None => [0.0, 0.0, 0.0, 1.0],
    };
    let mut wxyz = [w, x, y, z];
    let largest = (0..4)
        .max_by(|&a, &b| wxyz[a].abs().total_cmp(&wxyz[b].abs()))
        .unwrap_or(0);
    if wxyz[largest] < 0.0 {
        wxyz = wxyz.map(|v| -v);
    }
    let mut out = [0u8; 4];
    let others = (0..4).filter(|&j| j != largest);
    for (k, j) in others.enumerate() {
        let v = (wxyz[j] * std::f32::consts::SQRT_2 + 1.0) / 2.0;
        out[k] = (v * 255.0).round().clamp(0.0, 255.0) as u8;
    }
    out[3] = 252 + largest as u8;
    out
}

/// A 256-entry codebook of one quantity (sorted).
struct Codebook {
    values: Vec<f32>,
}

impl Codebook {
    /// 1D k-means of `v`: centroids start half at quantiles of the sorted values and half
    /// evenly spaced over their range (finite values only), then each
    /// iteration moves every centroid to the mean of the values nearer to it than to its
    /// neighbours (ranges of the sorted values, summed by prefix sums).
    fn fit(v: &[f32]) -> Codebook {
        let mut s: Vec<f64> = v
            .iter()
            .map(|&x| x as f64)
            .filter(|x| x.is_finite())
            .collect();
        if s.is_empty() {
            return Codebook {
                values: vec![0.0; CODEBOOK],
            };
        }
        s.sort_by(f64::total_cmp);
        let mut prefix = Vec::with_capacity(s.len() + 1);
        prefix.push(0.0);
        for x in &s {
            prefix.push(prefix.last().unwrap() + x);
        }
        let n = s.len();
        // Half the entries at quantiles, half evenly over the range: quantiles alone leave
        // the tails (the largest splats, the brightest colours) to one far entry.
        let (lo, hi) = (s[0], s[n - 1]);
        let half = CODEBOOK / 2;
        let mut c: Vec<f64> = (0..half)
            .map(|k| s[((k as f64 + 0.5) / half as f64 * n as f64) as usize % n])
            .chain((0..half).map(|k| lo + (hi - lo) * k as f64 / (half - 1) as f64))
            .collect();
        c.sort_by(f64::total_cmp);
        for _ in 0..ITERATIONS {
            c.dedup();
            let mut next = Vec::with_capacity(c.len());
            let mut start = 0;
            for k in 0..c.len() {
                let end = if k + 1 == c.len() {
                    n
                } else {
                    let mid = (c[k] + c[k + 1]) / 2.0;
                    start + s[start..].partition_point(|&x| x <= mid)
                };
                if end > start {
                    next.push((prefix[end] - prefix[start]) / (end - start) as f64);
                }
                start = end;
            }
            c = next;
        }
        let mut values: Vec<f32> = c.iter().map(|&x| x as f32).collect();
        values.dedup();
        while values.len() < CODEBOOK {
            values.push(*values.last().unwrap());
        }
        Codebook { values }
    }

    /// The index of the entry nearest to `x`.
    fn index(&self, x: f32) -> u8 {
        let v = &self.values;
        let i = v.partition_point(|&c| c < x);
        let best = match i {
            0 => 0,
            i if i >= v.len() => v.len() - 1,
            i if (x - v[i - 1]) <= (v[i] - x) => i - 1,
            i => i,
        };
        best as u8
    }
}

/// The SH palette: `shN` of the meta, the centroids and the labels textures.
fn palette(
    cloud: &SplatCloud,
    width: usize,
    height: usize,
) -> Result<(serde_json::Value, Vec<u8>, Vec<u8>), SogWriteError> {
    let n = cloud.len();
    let k = sh_coeff_count(cloud.sh_degree) - 1;
    let rest = |i: usize| cloud.sh_of(i)[1..].iter().flatten().copied();
    // Entry e's 3k values, and each splat's entry.
    let (entries, labels): (Vec<Vec<f32>>, Vec<usize>) = if n <= PALETTE {
        (
            (0..n).map(|i| rest(i).collect()).collect(),
            (0..n).collect(),
        )
    } else {
        median_cut(&(0..n).map(|i| rest(i).collect()).collect::<Vec<Vec<f32>>>())
    };
    let all: Vec<f32> = entries.iter().flatten().copied().collect();
    let book = Codebook::fit(&all);
    let rows = entries.len().div_ceil(64);
    let cw = 64 * k;
    let mut centroids = vec![0u8; 4 * cw * rows];
    for (e, vals) in entries.iter().enumerate() {
        let (row, col) = (e / 64, (e % 64) * k);
        for j in 0..k {
            let t = 4 * (row * cw + col + j);
            for ch in 0..3 {
                centroids[t + ch] = book.index(vals[3 * j + ch]);
            }
            centroids[t + 3] = 255;
        }
    }
    let mut lab = vec![0u8; 4 * width * height];
    for (i, &l) in labels.iter().enumerate() {
        lab[4 * i..4 * i + 4].copy_from_slice(&[l as u8, (l >> 8) as u8, 0, 255]);
    }
    let meta = json!({
        "count": entries.len(), "bands": cloud.sh_degree, "codebook": book.values,
        "files": ["shN_centroids.webp", "shN_labels.webp"],
    });
    Ok((
        meta,
        webp(&centroids, cw, rows)?,
        webp(&lab, width, height)?,
    ))
}

/// Median cut of `points` into [`PALETTE`] boxes: the box with the most points is split at the
/// median of its widest dimension until there are enough. The boxes' means and each point's box.
fn median_cut(points: &[Vec<f32>]) -> (Vec<Vec<f32>>, Vec<usize>) {
    let dim = points.first().map_or(0, Vec::len);
    let mut boxes: Vec<Vec<u32>> = vec![(0..points.len() as u32).collect()];
    // The boxes by size, largest first.
    let mut largest = std::collections::BinaryHeap::from([(points.len(), 0usize)]);
    while boxes.len() < PALETTE {
        let Some((len, b)) = largest.pop() else {
            break;
        };
        if len < 2 {
            break;
        }
        let mut members = std::mem::take(&mut boxes[b]);
        let span = |d: usize| {
            let it = members.iter().map(|&i| points[i as usize][d]);
            it.clone().fold(f32::NEG_INFINITY, f32::max) - it.fold(f32::INFINITY, f32::min)
        };
        let spans: Vec<f32> = (0..dim).map(span).collect();
        let widest = (0..dim)
            .max_by(|&x, &y| spans[x].total_cmp(&spans[y]))
            .unwrap_or(0);
        let mid = members.len() / 2;
        members.select_nth_unstable_by(mid, |&a, &b| {
            points[a as usize][widest].total_cmp(&points[b as usize][widest])
        });
        let upper = members.split_off(mid);
        largest.push((members.len(), b));
        largest.push((upper.len(), boxes.len()));
        boxes[b] = members;
        boxes.push(upper);
    }
    let mut labels = vec![0usize; points.len()];
    let means = boxes
        .iter()
        .enumerate()
        .map(|(e, members)| {
            let mut m = vec![0f64; dim];
            for &i in members {
                labels[i as usize] = e;
                for (acc, v) in m.iter_mut().zip(&points[i as usize]) {
                    *acc += *v as f64;
                }
            }
            m.iter()
                .map(|v| (v / members.len().max(1) as f64) as f32)
                .collect()
        })
        .collect();
    (means, labels)
}

/// A lossless WebP of `rgba` (`w × h` RGBA8 texels).
fn webp(rgba: &[u8], w: usize, h: usize) -> Result<Vec<u8>, SogWriteError> {
    let mut out = Vec::new();
    image_webp::WebPEncoder::new(&mut out).encode(
        rgba,
        w as u32,
        h as u32,
        image_webp::ColorType::Rgba8,
    )?;
    Ok(out)
}

/// A zip of `files`, each stored (method 0) with its CRC-32, dated 1980-01-01. `Err` past
/// the 4 GiB a zip without zip64 can address.
fn zip_stored(files: &[(String, Vec<u8>)]) -> Result<Vec<u8>, SogWriteError> {
    let total: usize = files.iter().map(|(n, d)| 2 * n.len() + d.len() + 128).sum();
    if total > u32::MAX as usize || files.len() > u16::MAX as usize {
        return Err(SogWriteError::TooLarge(total));
    }
    let (mut out, mut dir) = (Vec::new(), Vec::new());
    for (name, data) in files {
        let (crc, len, at) = (crc32fast::hash(data), data.len() as u32, out.len() as u32);
        let common = |v: &mut Vec<u8>| {
            for x in [20u16, 0, 0, 0, 0x0021] {
                v.extend_from_slice(&x.to_le_bytes()); // version, flags, method, time, date
            }
            for x in [crc, len, len] {
                v.extend_from_slice(&x.to_le_bytes());
            }
            v.extend_from_slice(&(name.len() as u16).to_le_bytes());
            v.extend_from_slice(&0u16.to_le_bytes()); // extra
        };
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        common(&mut out);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        dir.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        dir.extend_from_slice(&20u16.to_le_bytes()); // made by
        common(&mut dir);
        for x in [0u16, 0, 0] {
            dir.extend_from_slice(&x.to_le_bytes()); // comment, disk, internal attributes
        }
        dir.extend_from_slice(&0u32.to_le_bytes()); // external attributes
        dir.extend_from_slice(&at.to_le_bytes());
        dir.extend_from_slice(name.as_bytes());
    }
    let (dir_at, dir_len) = (out.len() as u32, dir.len() as u32);
    out.extend_from_slice(&dir);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    let count = files.len() as u16;
    for x in [0u16, 0, count, count] {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out.extend_from_slice(&dir_len.to_le_bytes());
    out.extend_from_slice(&dir_at.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_codebook_of_few_distinct_values_holds_them_exactly() {
        let v = [0.5f32, -2.0, 0.5, 7.25, -2.0];
        let book = Codebook::fit(&v);
        for x in v {
            assert_eq!(book.values[book.index(x) as usize], x);
        }
        assert_eq!(book.values.len(), CODEBOOK);
    }

    #[test]
    fn quaternion_texels_decode_to_the_same_rotation() {
        for q in [
            [0.0f32, 0.0, 0.0, 1.0],
            [0.5, -0.5, 0.5, -0.5],
            [0.1, 0.9, -0.3, 0.2],
        ] {
            let t = quat_texel(q);
            assert!((252..=255).contains(&t[3]));
            let n = crate::load::normalize_quat(q).unwrap().0;
            let largest = (t[3] - 252) as usize;
            let wxyz = [n[3], n[0], n[1], n[2]];
            let sign = wxyz[largest].signum();
            let mut k = 0;
            for (j, c) in wxyz.iter().enumerate() {
                if j != largest {
                    let back = (t[k] as f32 / 255.0 * 2.0 - 1.0) / std::f32::consts::SQRT_2;
                    assert!((back - c * sign).abs() < 0.006, "{q:?}: {back} vs {c}");
                    k += 1;
                }
            }
        }
    }
}
