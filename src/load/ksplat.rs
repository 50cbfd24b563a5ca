//! mkkellogg `.ksplat` (GaussianSplats3D `SplatBuffer`, version 0.1), compression levels 0, 1
//! and 2 (`docs/formats.md` § ksplat).
//!
//! Layout: a 4096-byte main header (u8 major, u8 minor, u32 max sections @4, u32 sections @8,
//! u32 max splats @12, u32 splats @16, u16 compression level @20, f32 scene centre @24, f32 SH
//! min/max @36/@40, 0 meaning ∓1.5), `max sections` 1024-byte section headers (u32 splats @0,
//! u32 max splats @4, u32 bucket size @8, u32 bucket count @12, f32 bucket block size @16, u16
//! bucket storage bytes @20, u32 position range @24 (0: 32767), u32 full buckets @32, u32
//! partial buckets @36, u16 SH degree @40), then per section: the partial buckets' lengths
//! (u32 each), the bucket centres (f32×3 each), and `max splats` records of: centre, scale
//! (linear), rotation (w, x, y, z), colour u8×4 (like `.splat`) and SH (channel-major within
//! each degree). Level 0 stores f32; levels 1–2 store the centre as u16 offsets from the
//! bucket centre, `(v − range)·(block/2)/range`, and scale and rotation as f16; SH is f32 /
//! f16 / u8 in [min, max] for levels 0 / 1 / 2. PLY axes.

use super::codec::{self, build_cloud, f16_to_f32, finish_cloud};
use super::{Details, Finding, LimitExceeded, LoadOptions, LoadReport, ScaleSeen};
use crate::cloud::SplatCloud;

/// Size of the main header.
pub const HEADER: usize = 4096;
/// Size of one section header.
pub const SECTION_HEADER: usize = 1024;

/// What is wrong with a `.ksplat` file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KsplatError {
    /// The file ends before a header or section.
    #[error("{what} needs bytes {start}..{end}, the file has {len}")]
    Truncated {
        /// What does not fit (`"main header"`, `"section 3 data"`, …).
        what: String,
        /// First byte.
        start: u64,
        /// One past the last byte.
        end: u64,
        /// File length.
        len: usize,
    },
    /// Version other than 0.1+.
    #[error("main header: version {major}.{minor} (expected 0.1 or a later 0.x)")]
    Version {
        /// Major.
        major: u8,
        /// Minor.
        minor: u8,
    },
    /// Compression level other than 0, 1, 2.
    #[error("main header: compression level {0} (expected 0, 1 or 2)")]
    Level(u16),
    /// A section header field that cannot be right.
    #[error("section {section}: {message}")]
    Section {
        /// Section index.
        section: usize,
        /// What, with expected vs found.
        message: String,
    },
    /// The splat count exceeds [`crate::load::Limits::max_splats`].
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
}

/// One section, resolved.
struct Section {
    count: usize,
    degree: u8,
    bytes_per_splat: usize,
    /// Splats in full buckets, bucket size, and the end index of each partial bucket.
    full: usize,
    bucket_size: usize,
    partial_ends: Vec<usize>,
    centers: usize,
    data: usize,
    /// Dequantisation of level 1–2 centres: `(v − range)·factor + centre`.
    range: f32,
    factor: f32,
}

/// Per-component sizes (centre, scale, rotation, SH) for a level.
fn component_bytes(level: u16) -> (usize, usize) {
    match level {
        0 => (4, 4),
        1 => (2, 2),
        _ => (2, 1),
    }
}

fn sh_values(degree: u8) -> usize {
    ((degree as usize + 1).pow(2) - 1) * 3
}

/// Whether `bytes` has a consistent `.ksplat` layout (used for content detection).
pub(crate) fn looks_like(bytes: &[u8]) -> bool {
    bytes.len() >= HEADER + SECTION_HEADER
        && bytes[0] == 0
        && bytes[1] >= 1
        && sections(bytes).is_ok_and(|(_, end)| end == bytes.len() as u64)
}

/// Parses the section headers; returns them and where the last section's data ends.
fn sections(b: &[u8]) -> Result<(Vec<Section>, u64), KsplatError> {
    let len = b.len();
    let short = |what: String, start: u64, end: u64| KsplatError::Truncated {
        what,
        start,
        end,
        len,
    };
    if len < HEADER {
        return Err(short("main header".into(), 0, HEADER as u64));
    }
    let (major, minor) = (b[0], b[1]);
    if major != 0 || minor < 1 {
        return Err(KsplatError::Version { major, minor });
    }
    let level = codec::u16_at(b, 20);
    if level > 2 {
        return Err(KsplatError::Level(level));
    }
    let max_sections = codec::u32_at(b, 4) as u64;
    let headers_end = HEADER as u64 + SECTION_HEADER as u64 * max_sections;
    if headers_end > len as u64 {
        return Err(short(
            format!("{max_sections} section headers"),
            HEADER as u64,
            headers_end,
        ));
    }
    let (cb, shb) = component_bytes(level);
    let mut out = Vec::with_capacity(max_sections as usize);
    let mut base = headers_end;
    for s in 0..max_sections as usize {
        let h = &b[HEADER + s * SECTION_HEADER..][..SECTION_HEADER];
        let bad = |message: String| KsplatError::Section {
            section: s,
            message,
        };
        let (count, max) = (codec::u32_at(h, 0) as u64, codec::u32_at(h, 4) as u64);
        let (bucket_size, buckets) = (codec::u32_at(h, 8) as u64, codec::u32_at(h, 12) as u64);
        let block = codec::f32_at(h, 16);
        let bucket_bytes = codec::u16_at(h, 20) as u64;
        let range = match codec::u32_at(h, 24) {
            0 => 32767,
            r => r,
        };
        let (full, partial) = (codec::u32_at(h, 32) as u64, codec::u32_at(h, 36) as u64);
        let degree = codec::u16_at(h, 40);
        if degree > 3 {
            return Err(bad(format!("SH degree {degree} (expected 0-3)")));
        }
        if count > max {
            return Err(bad(format!("{count} splats but room for {max}")));
        }
        let degree = degree as u8;
        let bytes_per_splat = 3 * cb + 3 * cb + 4 * cb + 4 + sh_values(degree) * shb;
        let meta = 4 * partial;
        let storage = bucket_bytes * buckets + meta + bytes_per_splat as u64 * max;
        if base + storage > len as u64 {
            return Err(short(format!("section {s} data"), base, base + storage));
        }
        let mut partial_ends = Vec::new();
        let full_splats = full.saturating_mul(bucket_size);
        if level >= 1 && count > 0 {
            if bucket_bytes != 12 {
                return Err(bad(format!(
                    "bucket storage {bucket_bytes} bytes, expected 12"
                )));
            }
            if full + partial > buckets {
                return Err(bad(format!("{full} + {partial} buckets, {buckets} stored")));
            }
            let mut end = full_splats;
            for k in 0..partial as usize {
                end += codec::u32_at(b, base as usize + 4 * k) as u64;
                partial_ends.push(end.min(count) as usize);
            }
            if end < count {
                return Err(bad(format!(
                    "buckets hold {end} splats, the section {count}"
                )));
            }
            if !(block.is_finite() && block > 0.0) {
                return Err(bad(format!("bucket block size {block}")));
            }
        }
        out.push(Section {
            count: count as usize,
            degree,
            bytes_per_splat,
            full: full_splats.min(count) as usize,
            bucket_size: bucket_size.max(1) as usize,
            partial_ends,
            centers: (base + meta) as usize,
            data: (base + bucket_bytes * buckets + meta) as usize,
            range: range as f32,
            factor: 0.5 * block / range as f32,
        });
        base += storage;
    }
    Ok((out, base))
}

impl Section {
    fn bucket_of(&self, i: usize) -> usize {
        if i < self.full {
            return i / self.bucket_size;
        }
        self.full / self.bucket_size + self.partial_ends.partition_point(|&e| e <= i)
    }
}

/// Reads a `.ksplat` file from memory into `report` (findings, details, linear scales).
pub(crate) fn read(
    bytes: &[u8],
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<SplatCloud, KsplatError> {
    let findings = &mut report.findings;
    let (secs, end) = sections(bytes)?;
    let level = codec::u16_at(bytes, 20);
    if end < bytes.len() as u64 {
        findings.push(Finding::warning(
            "sections",
            format!(
                "{} bytes after the last section ignored",
                bytes.len() as u64 - end
            ),
        ));
    }
    let n: usize = secs.iter().map(|s| s.count).sum();
    opts.limits.check_splats(n as u64, "the sections")?;
    let stated = codec::u32_at(bytes, 16) as usize;
    if stated != n {
        findings.push(Finding::warning(
            "main header",
            format!("states {stated} splats, the sections hold {n}; the sections are read"),
        ));
    }
    let degree = secs.iter().map(|s| s.degree).max().unwrap_or(0);
    let (lo, hi) = match (codec::f32_at(bytes, 36), codec::f32_at(bytes, 40)) {
        (a, b) if a != 0.0 && b != 0.0 => (a, b),
        _ => (-1.5, 1.5),
    };
    // Global splat index → section: start index of each section.
    let starts: Vec<usize> = secs
        .iter()
        .scan(0, |acc, s| {
            let st = *acc;
            *acc += s.count;
            Some(st)
        })
        .collect();
    let (cb, shb) = component_bytes(level);
    let cloud = build_cloud::<std::convert::Infallible>(n, degree, |g, s| {
        let si = starts.partition_point(|&st| st <= g) - 1;
        let sec = &secs[si];
        let i = g - starts[si];
        let r = &bytes[sec.data + i * sec.bytes_per_splat..][..sec.bytes_per_splat];
        let val = |k: usize| match cb {
            4 => codec::f32_at(r, 4 * k),
            _ => f16_to_f32(codec::u16_at(r, 2 * k)),
        };
        *s.position = if level == 0 {
            std::array::from_fn(|a| codec::f32_at(r, 4 * a))
        } else {
            let c = sec.centers + 12 * sec.bucket_of(i);
            std::array::from_fn(|a| {
                (codec::u16_at(r, 2 * a) as f32 - sec.range) * sec.factor
                    + codec::f32_at(bytes, c + 4 * a)
            })
        };
        *s.scale = std::array::from_fn(|a| val(3 + a));
        *s.rotation = [val(7), val(8), val(9), val(6)];
        let col = &r[10 * cb..];
        s.sh[0] = std::array::from_fn(|c| crate::sh::dc_from_color(col[c] as f64 / 255.0));
        *s.opacity = col[3] as f32 / 255.0;
        let sh = &col[4..];
        let value = |k: usize| match shb {
            4 => codec::f32_at(sh, 4 * k),
            2 => f16_to_f32(codec::u16_at(sh, 2 * k)),
            _ => lo + sh[k] as f32 / 255.0 * (hi - lo),
        };
        // Degree l's 2l+1 coefficients per channel, channel-major, one degree after another.
        let mut base = 0;
        for l in 1..=sec.degree as usize {
            let m = 2 * l + 1;
            for c in 0..3 {
                for j in 0..m {
                    s.sh[l * l + j][c] = value(base + c * m + j);
                }
            }
            base += 3 * m;
        }
        Ok(())
    });
    let Ok(mut cloud) = cloud;
    finish_cloud(&mut cloud, codec::drop_site("splats", opts), findings);
    if secs.iter().any(|s| s.degree < degree) {
        findings.push(Finding::warning(
            "sections",
            format!("sections of lower SH degree zero-padded to {degree}"),
        ));
    }
    report.details = Some(describe(bytes, level, degree));
    report.scale_space = Some(ScaleSeen::Linear);
    Ok(cloud)
}

fn describe(bytes: &[u8], level: u16, degree: u8) -> Details {
    // The level is the format's own name for its quantization; no entropy coding follows.
    let mut d = Details::new("ksplat", format!("none (compression level {level})"));
    d.version = format!("{}.{}", bytes[0], bytes[1]);
    if level == 0 {
        d.bits("position", 32, "f32");
        d.bits("scale", 32, "f32, linear");
        d.bits("rotation", 32, "f32 w, x, y, z");
    } else {
        d.bits("position", 16, "u16 offset from the bucket centre");
        d.bits("scale", 16, "f16, linear");
        d.bits("rotation", 16, "f16 w, x, y, z");
        d.lossy("positions in steps of (bucket block size / 2) / 32767 around each bucket centre");
        d.lossy("scales and rotations rounded to half floats (11 significant bits)");
    }
    d.bits("color", 8, "b/255 = 0.5 + Y00·DC");
    d.bits("opacity", 8, "b/255 (linear)");
    d.lossy("DC colour clamped to [0, 1] and truncated to 1/255; opacity truncated to 1/255");
    if degree > 0 {
        match level {
            0 => d.bits("sh", 32, "f32"),
            1 => d.bits("sh", 16, "f16"),
            _ => d.bits("sh", 8, "u8 in the header's [min, max]"),
        }
        if level == 2 {
            d.lossy("SH truncated to 255 steps of the header's [min, max] range");
        }
    }
    d.lossy("the GaussianSplats3D writer drops SH degree 3 and splats below its alpha threshold");
    d
}
