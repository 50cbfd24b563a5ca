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

use super::codec::{self, build_cloud, finish_cloud};
use super::{Details, Finding, LimitExceeded, LoadOptions, LoadReport, ScaleSeen};
use crate::cloud::SplatCloud;
use records::Records;

mod records;

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

/// A [`KsplatError::Truncated`] for a file of `len` bytes.
fn truncated(what: String, start: u64, end: u64, len: usize) -> KsplatError {
    KsplatError::Truncated {
        what,
        start,
        end,
        len,
    }
}

/// Checks the main header (size, version, compression level) and that the section headers it
/// announces are present. Returns the level, the number of section headers and where they end.
fn main_header(b: &[u8]) -> Result<(u16, u64, u64), KsplatError> {
    let len = b.len();
    if len < HEADER {
        return Err(truncated("main header".into(), 0, HEADER as u64, len));
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
        return Err(truncated(
            format!("{max_sections} section headers"),
            HEADER as u64,
            headers_end,
            len,
        ));
    }
    Ok((level, max_sections, headers_end))
}

/// Parses the section headers; returns them and where the last section's data ends.
fn sections(b: &[u8]) -> Result<(Vec<Section>, u64), KsplatError> {
    let (level, max_sections, headers_end) = main_header(b)?;
    let mut out = Vec::with_capacity(max_sections as usize);
    let mut base = headers_end;
    for s in 0..max_sections as usize {
        let h = &b[HEADER + s * SECTION_HEADER..][..SECTION_HEADER];
        let (section, storage) = RawSection::parse(h).resolve(b, s, level, base)?;
        out.push(section);
        base += storage;
    }
    Ok((out, base))
}

/// One section header's fields as stored (the position range with 0 read as 32767).
struct RawSection {
    count: u64,
    max: u64,
    bucket_size: u64,
    buckets: u64,
    block: f32,
    bucket_bytes: u64,
    range: u32,
    full: u64,
    partial: u64,
    degree: u16,
}

impl RawSection {
    /// Reads the fields of the 1024-byte section header `h`.
    fn parse(h: &[u8]) -> RawSection {
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
        RawSection {
            count,
            max,
            bucket_size,
            buckets,
            block,
            bucket_bytes,
            range,
            full,
            partial,
            degree,
        }
    }

    /// Checks section `s` of a level-`level` file, whose data starts at `base`, against the
    /// file `b`. Returns the resolved section and the bytes its data takes.
    fn resolve(
        &self,
        b: &[u8],
        s: usize,
        level: u16,
        base: u64,
    ) -> Result<(Section, u64), KsplatError> {
        let len = b.len();
        let bad = |message: String| KsplatError::Section {
            section: s,
            message,
        };
        let (count, max, degree) = (self.count, self.max, self.degree);
        if degree > 3 {
            return Err(bad(format!("SH degree {degree} (expected 0-3)")));
        }
        if count > max {
            return Err(bad(format!("{count} splats but room for {max}")));
        }
        let (cb, shb) = component_bytes(level);
        let degree = degree as u8;
        let bytes_per_splat = 3 * cb + 3 * cb + 4 * cb + 4 + sh_values(degree) * shb;
        let meta = 4 * self.partial;
        let buckets_bytes = self.bucket_bytes * self.buckets;
        let storage = buckets_bytes + meta + bytes_per_splat as u64 * max;
        if base + storage > len as u64 {
            return Err(truncated(
                format!("section {s} data"),
                base,
                base + storage,
                len,
            ));
        }
        let full_splats = self.full.saturating_mul(self.bucket_size);
        let partial_ends = if level >= 1 && count > 0 {
            self.bucket_ends(b, base, full_splats).map_err(bad)?
        } else {
            Vec::new()
        };
        let range = self.range;
        let section = Section {
            count: count as usize,
            degree,
            bytes_per_splat,
            full: full_splats.min(count) as usize,
            bucket_size: self.bucket_size.max(1) as usize,
            partial_ends,
            centers: (base + meta) as usize,
            data: (base + buckets_bytes + meta) as usize,
            range: range as f32,
            factor: 0.5 * self.block / range as f32,
        };
        Ok((section, storage))
    }

    /// Levels 1–2: checks the buckets (storage size, counts, block size) and returns the end
    /// index of each partial bucket, whose lengths are stored at `base` in `b`. The error is
    /// the message of a [`KsplatError::Section`].
    fn bucket_ends(&self, b: &[u8], base: u64, full_splats: u64) -> Result<Vec<usize>, String> {
        let (count, full, partial, buckets) = (self.count, self.full, self.partial, self.buckets);
        let (bucket_bytes, block) = (self.bucket_bytes, self.block);
        if bucket_bytes != 12 {
            return Err(format!("bucket storage {bucket_bytes} bytes, expected 12"));
        }
        if full + partial > buckets {
            return Err(format!("{full} + {partial} buckets, {buckets} stored"));
        }
        let mut partial_ends = Vec::new();
        let mut end = full_splats;
        for k in 0..partial as usize {
            end += codec::u32_at(b, base as usize + 4 * k) as u64;
            partial_ends.push(end.min(count) as usize);
        }
        if end < count {
            return Err(format!("buckets hold {end} splats, the section {count}"));
        }
        if !(block.is_finite() && block > 0.0) {
            return Err(format!("bucket block size {block}"));
        }
        Ok(partial_ends)
    }
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
    let n = check_counts(bytes, &secs, end, opts, findings)?;
    let degree = secs.iter().map(|s| s.degree).max().unwrap_or(0);
    let records = Records::new(bytes, &secs, level);
    let cloud = build_cloud::<std::convert::Infallible>(n, degree, |g, s| {
        records.fill(g, s);
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

/// The splat count the sections hold, checked against the limits; bytes after the last
/// section (ending at `end`) and a main header stating another count are reported.
fn check_counts(
    bytes: &[u8],
    secs: &[Section],
    end: u64,
    opts: &LoadOptions,
    findings: &mut Vec<Finding>,
) -> Result<usize, KsplatError> {
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
    Ok(n)
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
