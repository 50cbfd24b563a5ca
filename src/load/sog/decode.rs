//! SOG textures → splats. Per texel `i` (RGBA8, lossless WebP):
//! - `means_l`, `means_u`: low and high bytes of 16-bit x, y, z; `l = min + (max − min)·v/65535`
//!   and the position is `sign(l)·(e^|l| − 1)` (the writer stores `sign(x)·ln(1 + |x|)`);
//! - `quats`: three components `(b/255·2 − 1)/√2` and in alpha `252 + index` of the dropped
//!   largest one, in the order w, x, y, z; the largest is rebuilt positive;
//! - `scales`: per axis a codebook index of ln(scale) (V1: a lerp in mins/maxs);
//! - `sh0`: r, g, b codebook indices of the DC coefficient, alpha = opacity·255 (V1: lerps, the
//!   alpha one a logit);
//! - `shN_labels`: 16-bit palette index (r + 256·g); `shN_centroids`: 64 palette entries per
//!   row, each `coeffs` texels wide, r/g/b codebook indices of one coefficient.

use super::{Meta, Quant, SogError};
use crate::cloud::SplatCloud;
use crate::load::codec::build_cloud;
use crate::load::{Details, Finding};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// Roles of the textures, in the order [`names`] lists them.
const ROLES: [&str; 7] = [
    "means_l",
    "means_u",
    "quats",
    "scales",
    "sh0",
    "shN_centroids",
    "shN_labels",
];

/// The texture files the meta names, with their roles.
pub(super) fn names(m: &Meta) -> Vec<(&'static str, String)> {
    let mut v = vec![
        m.means.2[0].clone(),
        m.means.2[1].clone(),
        m.quats.clone(),
        m.scales_file.clone(),
        m.sh0.1.clone(),
    ];
    if let Some((_, _, _, [c, l])) = &m.sh_n {
        v.push(c.clone());
        v.push(l.clone());
    }
    ROLES.iter().copied().zip(v).collect()
}

/// A decoded texture.
struct Tex {
    rgba: Vec<u8>,
}

fn texture_err(file: &str, role: &'static str, message: impl Into<String>) -> SogError {
    SogError::Texture {
        file: file.into(),
        role,
        message: message.into(),
    }
}

type Decoder<'a> = image_webp::WebPDecoder<std::io::Cursor<&'a [u8]>>;

/// Parses a WebP header: dimensions, lossless and still, or a precise error.
fn probe<'a>(bytes: &'a [u8], file: &str, role: &'static str) -> Result<Decoder<'a>, SogError> {
    let mut d = image_webp::WebPDecoder::new(std::io::Cursor::new(bytes))
        .map_err(|e| texture_err(file, role, format!("not a WebP image: {e}")))?;
    if d.is_animated() {
        return Err(texture_err(file, role, "animated WebP"));
    }
    if d.is_lossy() {
        return Err(texture_err(
            file,
            role,
            "lossy WebP (SOG textures must be lossless)",
        ));
    }
    Ok(d)
}

fn read_rgba(mut d: Decoder<'_>, file: &str, role: &'static str) -> Result<Tex, SogError> {
    let (w, h) = d.dimensions();
    let n = w as usize * h as usize;
    let size = d
        .output_buffer_size()
        .ok_or_else(|| texture_err(file, role, "image too large"))?;
    let mut buf = vec![0u8; size];
    d.read_image(&mut buf)
        .map_err(|e| texture_err(file, role, format!("WebP decode: {e}")))?;
    let rgba = if d.has_alpha() {
        buf
    } else {
        let mut out = Vec::with_capacity(4 * n);
        for p in buf.chunks_exact(3) {
            out.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
        out
    };
    Ok(Tex { rgba })
}

/// SH coefficients per channel for `bands`.
fn coeffs(bands: u8) -> usize {
    (bands as usize + 1).pow(2) - 1
}

/// Decodes the textures (in [`names`] order) into a cloud; `limit` bounds the decoded pixels
/// and the cloud; splats with unusable values are dropped at `drop_at`
/// ([`crate::load::codec::finish_cloud`]).
pub(super) fn decode(
    m: &Meta,
    textures: &[Vec<u8>],
    (limit, drop_at): (u64, Option<&str>),
    findings: &mut Vec<Finding>,
) -> Result<(SplatCloud, Details), SogError> {
    let names = names(m);
    let mut decoders = Vec::with_capacity(names.len());
    let mut needed = 0u64;
    let mut sh = None; // (bands, palette entries, centroid texture width)
    for ((role, file), bytes) in names.iter().zip(textures) {
        let d = probe(bytes, file, role)?;
        let (w, h) = d.dimensions();
        let texels = w as u64 * h as u64;
        needed += 4 * texels;
        if *role == "shN_centroids" {
            let (count, bands, _, _) = m.sh_n.as_ref().expect("listed only with shN");
            let bands = match (m.version, w) {
                (2, _) => *bands,
                (_, 192) => 1,
                (_, 512) => 2,
                (_, 960) => 3,
                _ => {
                    return Err(texture_err(
                        file,
                        role,
                        format!("width {w}, expected 192, 512 or 960"),
                    ));
                }
            };
            let k = coeffs(bands) as u64;
            if w as u64 != 64 * k {
                return Err(texture_err(
                    file,
                    role,
                    format!("width {w}, expected 64 × {k}"),
                ));
            }
            let palette = if m.version == 2 {
                *count
            } else {
                (64 * h) as usize
            };
            if (palette as u64).div_ceil(64) > h as u64 {
                return Err(texture_err(
                    file,
                    role,
                    format!("{h} rows for {palette} entries"),
                ));
            }
            sh = Some((bands, palette, w as usize));
        } else if texels < m.count as u64 {
            return Err(texture_err(
                file,
                role,
                format!(
                    "{w}×{h} = {texels} texels, fewer than the {} splats",
                    m.count
                ),
            ));
        }
        decoders.push((d, file.as_str(), *role));
    }
    let degree = sh.map_or(0, |s| s.0);
    needed += crate::load::codec::cloud_bytes(m.count as u64, degree);
    if needed > limit {
        return Err(SogError::OverBudget { needed, limit });
    }
    let tex: Vec<Tex> = decoders
        .into_par_iter()
        .map(|(d, file, role)| read_rgba(d, file, role))
        .collect::<Result<_, _>>()?;
    let cloud = splats(m, &tex, sh, drop_at, findings);
    Ok((cloud, describe(m, sh)))
}

fn lerp(q: &Quant, axis: usize, b: u8) -> f32 {
    match q {
        Quant::Codebook(c) => c[b as usize],
        Quant::Range(lo, hi) => {
            let (l, h) = (lo[axis.min(lo.len() - 1)], hi[axis.min(hi.len() - 1)]);
            (l + (h - l) * b as f64 / 255.0) as f32
        }
    }
}

/// Decodes the texels of the textures `t` (in [`names`] order) into the cloud of `m.count`
/// splats; `sh` is (bands, palette entries, centroid texture width) with SH. Out-of-range
/// labels and tags are reported, unusable splats dropped at `drop_at`.
fn splats(
    m: &Meta,
    t: &[Tex],
    sh: Option<(u8, usize, usize)>,
    drop_at: Option<&str>,
    findings: &mut Vec<Finding>,
) -> SplatCloud {
    let (lo, hi) = (&t[0].rgba, &t[1].rgba);
    let (mins, maxs) = (&m.means.0, &m.means.1);
    let span: [f64; 3] = std::array::from_fn(|a| match maxs[a] - mins[a] {
        0.0 => 1.0,
        s => s,
    });
    let degree = sh.map_or(0, |s| s.0);
    let (bad_tag, bad_label) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let cloud = build_cloud::<std::convert::Infallible>(m.count, degree, |i, s| {
        let o = 4 * i;
        *s.position = std::array::from_fn(|a| {
            let v = lo[o + a] as u32 | (hi[o + a] as u32) << 8;
            let l = mins[a] + span[a] * v as f64 / 65535.0;
            (l.signum() * (l.abs().exp() - 1.0)) as f32
        });
        *s.rotation = quaternion(&t[2].rgba[o..o + 4]).unwrap_or_else(|| {
            bad_tag.fetch_add(1, Relaxed);
            [0.0; 4]
        });
        let sc = &t[3].rgba[o..o + 3];
        *s.scale = std::array::from_fn(|a| lerp(&m.scales, a, sc[a]).exp());
        let c = &t[4].rgba[o..o + 4];
        s.sh[0] = std::array::from_fn(|ch| lerp(&m.sh0.0, ch, c[ch]));
        *s.opacity = match &m.sh0.0 {
            Quant::Codebook(_) => c[3] as f32 / 255.0,
            q => 1.0 / (1.0 + (-lerp(q, 3, c[3])).exp()),
        };
        if let (Some((bands, palette, cw)), Some((_, _, q, _))) = (sh, &m.sh_n) {
            let k = coeffs(bands);
            let label = t[6].rgba[o] as usize | (t[6].rgba[o + 1] as usize) << 8;
            if label >= palette {
                bad_label.fetch_add(1, Relaxed);
                return Ok(());
            }
            let (row, col) = (label / 64, (label % 64) * k);
            for j in 0..k {
                let p = &t[5].rgba[4 * (row * cw + col + j)..];
                s.sh[1 + j] = std::array::from_fn(|ch| lerp(q, 0, p[ch]));
            }
        }
        Ok(())
    });
    let Ok(mut cloud) = cloud;
    report_bad(bad_tag.into_inner(), bad_label.into_inner(), findings);
    crate::load::codec::finish_cloud(&mut cloud, drop_at, findings);
    cloud
}

/// One texel of `quats` as a quaternion `[x, y, z, w]`: the three smallest components and, from
/// the tag in alpha (252 + its index in w, x, y, z), the largest rebuilt positive. `None` for a
/// tag outside 252–255.
#[inline]
fn quaternion(q: &[u8]) -> Option<[f32; 4]> {
    let sqrt2 = std::f32::consts::SQRT_2;
    match q[3] {
        tag @ 252..=255 => {
            let largest = (tag - 252) as usize;
            let mut wxyz = [0.0f32; 4];
            let others = wxyz.iter_mut().enumerate().filter(|(j, _)| *j != largest);
            for (k, (_, c)) in others.enumerate() {
                *c = (q[k] as f32 / 255.0 * 2.0 - 1.0) / sqrt2;
            }
            let sum: f32 = wxyz.iter().map(|v| v * v).sum();
            wxyz[largest] = (1.0 - sum).max(0.0).sqrt();
            Some([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])
        }
        _ => None,
    }
}

/// Warnings for the splats with an out-of-range palette label (`labels`) or quats tag (`tags`).
fn report_bad(tags: usize, labels: usize, findings: &mut Vec<Finding>) {
    if labels > 0 {
        findings.push(Finding::warning(
            "shN_labels",
            format!("{labels} palette labels out of range: those splats get no SH beyond DC"),
        ));
    }
    if tags > 0 {
        findings.push(Finding::warning(
            "quats",
            format!("{tags} splats with a quats tag outside 252-255 (no rotation: dropped)"),
        ));
    }
}

fn describe(m: &Meta, sh: Option<(u8, usize, usize)>) -> Details {
    let mut d = Details::new("sog", "WebP lossless");
    d.version = m.version.to_string();
    d.bits(
        "position",
        16,
        "sign(x)·ln(1 + |x|) in the meta's [min, max], 16 bits",
    );
    d.bits("rotation", 8, "smallest three, 3 × 8 bits + tag");
    d.lossy("positions in 65535 steps of the log-transformed range (coarser far from 0)");
    d.lossy("rotation components truncated to 8 bits");
    if m.version == 2 {
        d.bits("scale", 8, "index into a 256-entry codebook of ln(scale)");
        d.bits("color", 8, "index into a 256-entry codebook of DC");
        d.lossy("scales and DC colours snapped to 256-entry k-means codebooks");
    } else {
        d.bits("scale", 8, "ln(scale) in the meta's per-axis range");
        d.bits("color", 8, "DC in the meta's per-channel range");
        d.lossy("scales and DC colours in 255 steps of their range");
    }
    d.bits("opacity", 8, "b/255");
    if let Some((_, palette, _)) = sh {
        d.bits(
            "sh",
            8,
            format!("palette of {palette} k-means centroids, 8-bit codebook per coefficient"),
        );
        d.lossy(format!(
            "SH replaced by the nearest of {palette} k-means centroids"
        ));
    }
    d
}
