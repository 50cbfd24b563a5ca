//! The two SPZ layouts: v1–v3 (16-byte header and the blocks back to back, normally inside
//! gzip) and v4 (32-byte header, extensions, table of contents, one zstd frame per block).
//! Sizes claimed by a header are checked against the budget before anything is allocated.

use super::{ATTRIBUTES, FLAG_EXTENSIONS, Header, MAGIC, MAX_VERSION, SpzError, header, sizes};
use crate::load::codec::{self, InflateError, cloud_bytes};
use crate::load::{Finding, Limits};
use rayon::prelude::*;
use std::io::Read;

/// The six attribute blocks (borrowed from the decompressed legacy buffer or owned v4 streams).
pub(crate) type Blocks<'a> = Vec<std::borrow::Cow<'a, [u8]>>;

/// Checks a header's version, degree and count (`limits.max_splats`), and that its blocks plus
/// the cloud they decode to fit the budget `limit`. Returns the total size of the blocks.
fn check(
    h: &Header,
    versions: std::ops::RangeInclusive<u32>,
    container: &'static str,
    (limit, limits): (u64, &Limits),
    input: usize,
) -> Result<u64, SpzError> {
    if !versions.contains(&h.version) {
        let expected = if *versions.start() == 1 {
            "1-3; version 4 is not gzip-wrapped"
        } else {
            "4 (or 1-3 inside gzip)"
        };
        return Err(SpzError::Version {
            version: h.version,
            container,
            expected,
        });
    }
    if h.degree > 4 {
        return Err(SpzError::ShDegree(h.degree));
    }
    let total: u64 = sizes(h).iter().sum();
    let needed = total + cloud_bytes(h.count as u64, h.degree.min(3));
    if needed > limit {
        return Err(SpzError::OverBudget {
            count: h.count,
            needed,
            limit,
            input,
        });
    }
    limits.check_splats(h.count as u64, "header")?;
    Ok(total)
}

/// Most bytes of extension records read from a gzip member.
const MAX_EXTENSIONS: u64 = 1 << 20;

/// Decompresses a v1–v3 gzip member header first: the header's claims are checked before the
/// blocks are read into one allocation of exactly their size. Extension records (flag 0x2)
/// are kept (at most 1 MiB); other trailing data is read (so the CRC is checked) but not kept, and its length
/// returned. Everything decompressed counts against `limit`.
pub(crate) fn gunzip_legacy(
    bytes: &[u8],
    limit: u64,
    limits: &Limits,
) -> Result<(Vec<u8>, u64), SpzError> {
    let gz = |e: std::io::Error| SpzError::Gzip(InflateError::Corrupt(e.to_string()));
    let mut d = flate2::read::GzDecoder::new(bytes);
    let mut head = [0u8; 16];
    let mut got = 0;
    while got < 16 {
        match d.read(&mut head[got..]).map_err(gz)? {
            0 => break,
            n => got += n,
        }
    }
    if got < 16 || &head[..4] != MAGIC {
        // Not an SPZ header: let `legacy` name what is wrong.
        return Ok((head[..got].to_vec(), 0));
    }
    let h = header(&head);
    let total = 16 + check(&h, 1..=3, "a gzip member", (limit, limits), bytes.len())?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(&head);
    (&mut d)
        .take(total - 16)
        .read_to_end(&mut out)
        .map_err(gz)?;
    // `check` bounded the payload and the cloud, not the 16 header bytes: saturate.
    let left = limit
        .saturating_sub(total)
        .saturating_sub(cloud_bytes(h.count as u64, h.degree.min(3)));
    let over = || SpzError::Gzip(InflateError::OverBudget { limit });
    if h.flags & FLAG_EXTENSIONS != 0 {
        // Extension records are small (a coordinate system, a camera): at most 1 MiB.
        let cap = left.min(MAX_EXTENSIONS);
        out.reserve_exact(cap as usize + 1);
        let before = out.len() as u64;
        (&mut d).take(cap + 1).read_to_end(&mut out).map_err(gz)?;
        if out.len() as u64 - before > cap {
            return Err(SpzError::Extension {
                offset: 0,
                message: format!("more than {cap} bytes of extension records"),
            });
        }
        return Ok((out, 0));
    }
    let mut scratch = vec![0u8; 64 << 10];
    let mut trailing = 0u64;
    loop {
        match d.read(&mut scratch).map_err(gz)? {
            0 => return Ok((out, trailing)),
            n => trailing += n as u64,
        }
        if trailing > left {
            return Err(over());
        }
    }
}

/// v1–v3 layout: 16-byte header, then the blocks back to back, then optional extensions.
/// `trailing` counts bytes after the blocks that the caller already dropped.
pub(crate) fn legacy<'a>(
    data: &'a [u8],
    container: &'static str,
    trailing: u64,
    (limit, limits): (u64, &Limits),
    findings: &mut Vec<Finding>,
) -> Result<(Header, Blocks<'a>, &'a [u8]), SpzError> {
    if data.len() < 16 {
        return Err(SpzError::Truncated {
            count: 0,
            what: "the 16-byte header",
            needed: 16,
            available: data.len() as u64,
        });
    }
    if &data[..4] != MAGIC {
        let found = data[..4].iter().map(|b| format!("{b:02x}")).collect();
        return Err(SpzError::BadMagic { found });
    }
    let h = header(data);
    let total = 16 + check(&h, 1..=3, container, (limit, limits), data.len())?;
    let sz = sizes(&h);
    if total > data.len() as u64 {
        let mut off = 16u64;
        let what = sz
            .iter()
            .zip(ATTRIBUTES)
            .find(|(s, _)| {
                off += **s;
                off > data.len() as u64
            })
            .map_or(ATTRIBUTES[5], |(_, a)| a);
        return Err(SpzError::Truncated {
            count: h.count,
            what,
            needed: total,
            available: data.len() as u64,
        });
    }
    let mut blocks = Vec::with_capacity(6);
    let mut off = 16usize;
    for s in sz {
        blocks.push(std::borrow::Cow::Borrowed(&data[off..off + s as usize]));
        off += s as usize;
    }
    let rest = &data[off..];
    let ignored = trailing
        + if h.flags & FLAG_EXTENSIONS == 0 {
            rest.len() as u64
        } else {
            0
        };
    if ignored > 0 {
        findings.push(Finding::warning(
            "container",
            format!("{ignored} bytes after the last block ignored"),
        ));
    }
    let ext = if h.flags & FLAG_EXTENSIONS != 0 {
        rest
    } else {
        &[]
    };
    Ok((h, blocks, ext))
}

/// v4 layout: 32-byte header, extensions up to the TOC, TOC, zstd streams to the end.
pub(crate) fn v4<'a>(
    bytes: &'a [u8],
    limit: u64,
    limits: &Limits,
) -> Result<(Header, Blocks<'static>, &'a [u8]), SpzError> {
    if bytes.len() < 32 {
        return Err(SpzError::Truncated {
            count: 0,
            what: "the 32-byte v4 header",
            needed: 32,
            available: bytes.len() as u64,
        });
    }
    let h = header(bytes);
    check(
        &h,
        4..=MAX_VERSION,
        "an uncompressed file",
        (limit, limits),
        bytes.len(),
    )?;
    let toc = codec::u32_at(bytes, 16) as usize;
    let sz = sizes(&h);
    let ranges = streams(bytes, &h, &sz)?;
    let blocks = unpack(bytes, &ranges, &sz)?;
    let ext = if h.flags & FLAG_EXTENSIONS != 0 {
        &bytes[32..toc]
    } else {
        &[]
    };
    Ok((h, blocks, ext))
}

/// One zstd stream of a v4 file: its index in the TOC, the attribute it holds and its bytes'
/// range in the file.
type Stream = (usize, usize, usize, usize);

/// Reads the v4 table of contents: one stream per non-empty attribute block, each unpacking
/// to the block's size, the streams filling the file from the TOC's end to its last byte.
fn streams(bytes: &[u8], h: &Header, sz: &[u64; 6]) -> Result<Vec<Stream>, SpzError> {
    let (streams, toc) = (bytes[15] as usize, codec::u32_at(bytes, 16) as usize);
    let wanted: Vec<usize> = (0..6).filter(|&i| sz[i] > 0).collect();
    if streams != wanted.len() {
        return Err(SpzError::Toc(format!(
            "{streams} streams, expected {} for SH degree {}",
            wanted.len(),
            h.degree
        )));
    }
    let toc_end = toc as u64 + 16 * streams as u64;
    if toc < 32 || toc_end > bytes.len() as u64 {
        return Err(SpzError::Toc(format!(
            "offset {toc} + {streams} × 16 bytes lies outside 32..{}",
            bytes.len()
        )));
    }
    let mut off = toc_end;
    let mut ranges = Vec::with_capacity(streams);
    for (k, &attr) in wanted.iter().enumerate() {
        let e = toc + 16 * k;
        let (packed, unpacked) = (codec::u64_at(bytes, e), codec::u64_at(bytes, e + 8));
        if unpacked != sz[attr] {
            return Err(SpzError::Toc(format!(
                "stream {k} ({}) holds {unpacked} bytes, expected {} for {} points",
                ATTRIBUTES[attr], sz[attr], h.count
            )));
        }
        if packed > bytes.len() as u64 - off {
            return Err(SpzError::Truncated {
                count: h.count,
                what: ATTRIBUTES[attr],
                needed: off.saturating_add(packed),
                available: bytes.len() as u64,
            });
        }
        ranges.push((k, attr, off as usize, (off + packed) as usize));
        off += packed;
    }
    if off != bytes.len() as u64 {
        return Err(SpzError::Toc(format!(
            "streams end at byte {off}, the file at {}",
            bytes.len()
        )));
    }
    Ok(ranges)
}

/// Decompresses the streams in parallel into the six attribute blocks (empty where the block
/// size `sz` is 0).
fn unpack(bytes: &[u8], ranges: &[Stream], sz: &[u64; 6]) -> Result<Blocks<'static>, SpzError> {
    let out: Vec<Vec<u8>> = ranges
        .par_iter()
        .map(|&(k, attr, a, b)| {
            codec::unzstd_exact(&bytes[a..b], sz[attr]).map_err(|source| SpzError::Stream {
                index: k,
                attribute: ATTRIBUTES[attr],
                source,
            })
        })
        .collect::<Result<_, _>>()?;
    let mut out = out.into_iter();
    let blocks = (0..6)
        .map(|i| {
            std::borrow::Cow::Owned(if sz[i] > 0 {
                out.next().unwrap()
            } else {
                vec![]
            })
        })
        .collect();
    Ok(blocks)
}
