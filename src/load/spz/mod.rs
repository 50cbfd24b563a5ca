//! Niantic SPZ, versions 1–4 (`docs/formats.md` § SPZ has the conventions and error bounds).
//!
//! - v1–v3: one gzip member holding a 16-byte header (`NGSP`, version, count, SH degree,
//!   fractional bits, flags, reserved) and the attribute blocks one after the other:
//!   positions, alphas, colours, scales, rotations, SH. An uncompressed legacy file (the
//!   header straight away) is read too, with a warning.
//! - v4: a 32-byte header (adds stream count and table-of-contents offset), optional extension
//!   records, the table (u64 compressed, u64 uncompressed per stream) and one zstd frame per
//!   non-empty attribute, in the same order.
//!
//! Stored axes are RUB (x right, y up, z back; Niantic's reference packs from its PLY frame RDF
//! into RUB). splatgl keeps PLY files in their own (RDF) frame, so by default the reader maps
//! RUB → RDF: y and z are negated, quaternions become (x, −y, −z, w) and each SH coefficient
//! takes the sign of its basis function's parity. Inside glTF (the SPZ compression
//! extensions) the payload is unpacked to glTF's LUF instead: x and z negated. [`SpzAxes::Raw`]
//! reads the numbers as they are (what `splat-transform` 3.x writes).

use super::codec::{
    self, BUDGET_RULE, InflateError, budget_for, build_cloud, finish_cloud, sh_flip_signs,
};
use super::{Details, Finding, LimitExceeded, Limits, LoadOptions, LoadReport, ScaleSeen};
use crate::cloud::{MAX_SH_DEGREE, SplatCloud};

mod container;
use container::Blocks;

/// First four bytes of an SPZ header.
pub const MAGIC: &[u8; 4] = b"NGSP";
/// DC colour scale of the format: byte = f_dc · 0.15 · 255 + 127.5.
pub const COLOR_SCALE: f32 = 0.15;
/// Highest version read.
pub const MAX_VERSION: u32 = 4;
/// Header flag: trained with antialiasing.
pub const FLAG_ANTIALIASED: u8 = 0x1;
/// Header flag: extension records present.
pub const FLAG_EXTENSIONS: u8 = 0x2;
/// SPZ_ADOBE_coordinate_system extension: a u32 coordinate-system code.
const EXT_COORDINATE_SYSTEM: u32 = 0xADBE_0003;

/// Which axes the stored SPZ numbers are taken to be in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpzAxes {
    /// SPZ files: [`SpzAxes::Rub`]. Inside glTF, per primitive: what POSITION's `min`/`max`
    /// show (the payload converted RUB → LUF, or as stored); without that evidence, converted
    /// for `KHR_gaussian_splatting_compression_spz_2` (its text) and as stored for the legacy
    /// `KHR_spz_gaussian_splats_compression` (how its implementation, CesiumJS, reads it).
    /// See docs/formats.md § glTF with SPZ compression. Writers treat it as `Rub`.
    #[default]
    Auto,
    /// Niantic's convention: RUB, converted to splatgl's PLY frame (RDF) for SPZ files and to
    /// glTF's LUF inside glTF.
    Rub,
    /// No conversion: the numbers are already in the target frame (what `splat-transform` 3.x
    /// writes into SPZ files, and CesiumJS expects inside glTF).
    Raw,
}

/// The frame an SPZ payload is converted to (from its stored frame, RUB unless a
/// coordinate-system extension record says otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Frame {
    /// splatgl's PLY frame, RDF: SPZ files, like PLY files, stay in the trainer's axes.
    Ply,
    /// glTF's LUF: the glTF SPZ compression extensions require unpacking to LUF.
    Gltf,
}

/// Niantic's `CoordinateSystem` code of RUB, the frame SPZ stores.
pub(crate) const RUB: u32 = 4;

impl Frame {
    /// Niantic's `CoordinateSystem` code (RDF = 6, LUF = 7).
    pub(crate) fn code(self) -> u32 {
        match self {
            Frame::Ply => 6,
            Frame::Gltf => 7,
        }
    }
}

/// Which axes (x, y, z) differ between two frames of the same family, by Niantic's codes:
/// code − 1 is 3 bits, x right, y up, z front (RUB = 0b011, RDF = 0b101, LUF = 0b110).
pub(crate) fn axis_flips(from: u32, to: u32) -> [bool; 3] {
    std::array::from_fn(|a| ((from - 1) >> a) & 1 != ((to - 1) >> a) & 1)
}

impl std::str::FromStr for SpzAxes {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(SpzAxes::Auto),
            "rub" => Ok(SpzAxes::Rub),
            "raw" => Ok(SpzAxes::Raw),
            _ => Err(format!("expected auto, rub or raw, found {s:?}")),
        }
    }
}

/// What is wrong with an SPZ file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpzError {
    /// Neither a gzip member nor an `NGSP` header.
    #[error("not SPZ: expected gzip (1f 8b) or magic 'NGSP' at byte 0, found {found}")]
    BadMagic {
        /// The first bytes, in hex.
        found: String,
    },
    /// The gzip member is corrupt, truncated or too large.
    #[error("gzip: {0}")]
    Gzip(InflateError),
    /// A version this reader does not know, or one that does not fit the wrapping.
    #[error("header: version {version} is not supported in {container} (expected {expected})")]
    Version {
        /// The stated version.
        version: u32,
        /// `"a gzip member"` or `"an uncompressed file"`.
        container: &'static str,
        /// Accepted versions.
        expected: &'static str,
    },
    /// SH degree above 4.
    #[error("header: SH degree {0} (expected 0-4)")]
    ShDegree(u8),
    /// The data ends before what the header claims.
    #[error("header claims {count} points: {what} needs {needed} bytes, only {available} present")]
    Truncated {
        /// Claimed count.
        count: u32,
        /// The block (or header) that does not fit.
        what: &'static str,
        /// Bytes it needs.
        needed: u64,
        /// Bytes present.
        available: u64,
    },
    /// The count would decompress to more than the budget allows.
    #[error(
        "header claims {count} points ({needed} bytes decompressed and decoded), over the budget of {limit} bytes for a {input}-byte file ({BUDGET_RULE})"
    )]
    OverBudget {
        /// Claimed count.
        count: u32,
        /// Bytes the streams would take.
        needed: u64,
        /// Budget.
        limit: u64,
        /// Input size.
        input: usize,
    },
    /// The point count exceeds [`Limits::max_splats`].
    #[error(transparent)]
    Limit(#[from] LimitExceeded),
    /// The v4 table of contents is inconsistent.
    #[error("v4 table of contents: {0}")]
    Toc(String),
    /// One v4 stream does not decompress to its size.
    #[error("stream {index} ({attribute}): {source}")]
    Stream {
        /// Stream index.
        index: usize,
        /// Its attribute.
        attribute: &'static str,
        /// What went wrong.
        source: InflateError,
    },
    /// An extension record runs past its block.
    #[error("extension record at byte {offset}: {message}")]
    Extension {
        /// Offset within the extension block.
        offset: usize,
        /// What is wrong.
        message: String,
    },
}

/// The header fields both layouts share.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Header {
    pub version: u32,
    pub count: u32,
    pub degree: u8,
    pub fractional_bits: u8,
    pub flags: u8,
}

/// Per-point byte sizes of the six blocks, in file order.
pub(crate) const ATTRIBUTES: [&str; 6] =
    ["positions", "alphas", "colors", "scales", "rotations", "sh"];

pub(crate) fn sizes(h: &Header) -> [u64; 6] {
    let n = h.count as u64;
    let sh_dim = ((h.degree as u64 + 1).pow(2) - 1) * 3;
    let pos = if h.version == 1 { 6 } else { 9 };
    let rot = if h.version >= 3 { 4 } else { 3 };
    [pos, 1, 3, 3, rot, sh_dim].map(|b| b * n)
}

pub(crate) fn header(b: &[u8]) -> Header {
    Header {
        version: codec::u32_at(b, 4),
        count: codec::u32_at(b, 8),
        degree: b[12],
        fractional_bits: b[13],
        flags: b[14],
    }
}

/// Reads an SPZ file into `report` (findings, container details, log scale space).
pub(crate) fn read(
    bytes: &[u8],
    opts: &LoadOptions,
    report: &mut LoadReport,
) -> Result<SplatCloud, SpzError> {
    let drop_at = codec::drop_site("points", opts);
    let (cloud, details, _) = decode_bytes(
        bytes,
        opts.spz_axes,
        Frame::Ply,
        (&opts.limits, drop_at),
        &mut report.findings,
    )?;
    report.details = Some(details);
    report.scale_space = Some(ScaleSeen::Log);
    Ok(cloud)
}

/// Decodes an SPZ payload (gzip v1–v3, uncompressed legacy, or v4 zstd streams): the cloud,
/// the container's details and the axis flips applied — from the stored frame to `frame`, none
/// when `axes` is [`SpzAxes::Raw`]. The glTF SPZ compression extensions call this on a
/// bufferView. `limits` bound the count and the budget ([`budget_for`]); splats with unusable
/// values are dropped at `drop_at` (see [`codec::finish_cloud`]).
pub(crate) fn decode_bytes(
    bytes: &[u8],
    axes: SpzAxes,
    frame: Frame,
    (limits, drop_at): (&Limits, Option<&str>),
    findings: &mut Vec<Finding>,
) -> Result<(SplatCloud, Details, [bool; 3]), SpzError> {
    let limit = budget_for(bytes.len(), limits);
    let mut d = Details::new("spz", "");
    let inner;
    let (h, blocks, ext) = if bytes.starts_with(&[0x1f, 0x8b]) {
        let trailing;
        (inner, trailing) = container::gunzip_legacy(bytes, limit, limits)?;
        d.compression = "gzip".into();
        container::legacy(&inner, "a gzip member", trailing, (limit, limits), findings)?
    } else if bytes.starts_with(MAGIC) && bytes.len() >= 8 && codec::u32_at(bytes, 4) >= 4 {
        d.compression = "zstd (one stream per attribute)".into();
        container::v4(bytes, limit, limits)?
    } else if bytes.starts_with(MAGIC) {
        findings.push(Finding::warning(
            "container",
            "legacy SPZ without its gzip wrapping (read as is)",
        ));
        d.compression = "none".into();
        container::legacy(bytes, "an uncompressed file", 0, (limit, limits), findings)?
    } else {
        let found = bytes.iter().take(4).map(|b| format!("{b:02x}")).collect();
        return Err(SpzError::BadMagic { found });
    };
    let flips = flips(axes, frame, ext, findings)?;
    d.version = h.version.to_string();
    d.antialiased = h.flags & FLAG_ANTIALIASED != 0;
    describe(&h, &mut d);
    let cloud = decode(&h, &blocks, flips, drop_at, findings);
    Ok((cloud, d, flips))
}

/// Axis flips (x, y, z) from the stored frame to `frame`: Niantic's RUB unless a
/// coordinate-system extension names another frame of the same family.
fn flips(
    axes: SpzAxes,
    frame: Frame,
    ext: &[u8],
    f: &mut Vec<Finding>,
) -> Result<[bool; 3], SpzError> {
    let mut stored = RUB;
    let mut off = 0;
    while off < ext.len() {
        if ext.len() - off < 8 {
            return Err(SpzError::Extension {
                offset: off,
                message: format!("{} bytes left, a record header needs 8", ext.len() - off),
            });
        }
        let (ty, len) = (
            codec::u32_at(ext, off),
            codec::u32_at(ext, off + 4) as usize,
        );
        if len > ext.len() - off - 8 {
            return Err(SpzError::Extension {
                offset: off,
                message: format!("payload of {len} bytes runs past the block"),
            });
        }
        let payload = &ext[off + 8..off + 8 + len];
        match (ty, payload.len()) {
            (EXT_COORDINATE_SYSTEM, 4) => match codec::u32_at(payload, 0) {
                0 => {}
                c @ 1..=8 => stored = c,
                c => f.push(Finding::warning(
                    "extensions",
                    format!("coordinate system {c} needs a quarter turn; read as RUB"),
                )),
            },
            _ => f.push(Finding::warning(
                "extensions",
                format!("extension 0x{ty:08x} ({len} bytes) ignored"),
            )),
        }
        off += 8 + len;
    }
    Ok(match axes {
        SpzAxes::Raw => [false; 3],
        SpzAxes::Rub | SpzAxes::Auto => axis_flips(stored, frame.code()),
    })
}

fn describe(h: &Header, d: &mut Details) {
    let fb = h.fractional_bits;
    if h.version == 1 {
        d.bits("position", 16, "half float");
    } else {
        d.bits(
            "position",
            24,
            format!("signed fixed point, {fb} fractional bits"),
        );
        d.lossy(format!("positions rounded to steps of 2^-{fb}"));
    }
    d.bits("scale", 8, "ln(scale) = b/16 − 10");
    d.lossy("scales in steps of e^(1/16), clamped to [e^-10, e^5.94]");
    if h.version >= 3 {
        d.bits(
            "rotation",
            10,
            "smallest three: 2-bit index, sign + 9-bit magnitude",
        );
    } else {
        d.bits("rotation", 8, "x, y, z as b/127.5 − 1; w ≥ 0 rebuilt");
    }
    d.lossy("rotations quantised");
    d.bits("opacity", 8, "b/255 (linear)");
    d.bits("color", 8, "DC = (b/255 − 0.5)/0.15");
    d.lossy("DC colour in steps of 1/38.25, clamped to [-3.33, 3.33]; opacity in steps of 1/255");
    if h.degree > 0 {
        d.bits("sh", 8, "(b − 128)/128");
        d.lossy("SH in steps of 1/128 (writers keep 5 bits for degree 1, 4 above), clamped to [-1, 0.99]");
    }
    if h.degree > MAX_SH_DEGREE {
        d.lossy("SH degree 4 dropped (splatgl renders up to degree 3)");
    }
}

/// Smallest-three quaternion (v3+): 2-bit index of the largest component, then for the other
/// three (from the highest index down in the low bits) a sign bit and a 9-bit magnitude of
/// |c|/√½. Returns `[x, y, z, w]`.
fn smallest_three(b: &[u8]) -> [f32; 4] {
    let mut comp = codec::u32_at(b, 0);
    let largest = (comp >> 30) as usize;
    let mut q = [0.0f32; 4];
    let mut sum = 0.0;
    for i in (0..4).rev().filter(|&i| i != largest) {
        let mag = (comp & 511) as f32 / 511.0 * std::f32::consts::FRAC_1_SQRT_2;
        q[i] = if (comp >> 9) & 1 == 1 { -mag } else { mag };
        sum += q[i] * q[i];
        comp >>= 10;
    }
    q[largest] = (1.0 - sum).max(0.0).sqrt();
    q
}

fn decode(
    h: &Header,
    b: &Blocks<'_>,
    flip: [bool; 3],
    drop_at: Option<&str>,
    f: &mut Vec<Finding>,
) -> SplatCloud {
    let degree = h.degree.min(MAX_SH_DEGREE);
    if h.degree > MAX_SH_DEGREE {
        f.push(Finding::warning(
            "header",
            "SH degree 4 read as degree 3 (the extra 9 coefficients are dropped)",
        ));
    }
    // Σ' = F R S² Rᵀ F with F = diag(sx, sy, sz).
    let ([sx, sy, sz], qs) = codec::flip_signs(flip);
    let shs = sh_flip_signs(flip);
    let file_dim = ((h.degree as usize + 1).pow(2) - 1) * 3;
    let scale = (2.0f64).powi(-(h.fractional_bits as i32)) as f32;
    let v1 = h.version == 1;
    let rot_bytes = if h.version >= 3 { 4 } else { 3 };
    let cloud = build_cloud::<std::convert::Infallible>(h.count as usize, degree, |i, s| {
        let p = &b[0][i * if v1 { 6 } else { 9 }..];
        let pos: [f32; 3] = std::array::from_fn(|a| {
            if v1 {
                codec::f16_to_f32(codec::u16_at(p, 2 * a))
            } else {
                let v = p[3 * a] as i32 | (p[3 * a + 1] as i32) << 8 | (p[3 * a + 2] as i32) << 16;
                ((v << 8) >> 8) as f32 * scale
            }
        });
        *s.position = [pos[0] * sx, pos[1] * sy, pos[2] * sz];
        *s.scale = std::array::from_fn(|a| (b[3][3 * i + a] as f32 / 16.0 - 10.0).exp());
        let r = &b[4][i * rot_bytes..];
        let q = if rot_bytes == 4 {
            smallest_three(r)
        } else {
            let xyz: [f32; 3] = std::array::from_fn(|a| r[a] as f32 / 127.5 - 1.0);
            let w = (1.0 - xyz.iter().map(|v| v * v).sum::<f32>())
                .max(0.0)
                .sqrt();
            [xyz[0], xyz[1], xyz[2], w]
        };
        *s.rotation = [q[0] * qs[0], q[1] * qs[1], q[2] * qs[2], q[3]];
        *s.opacity = b[1][i] as f32 / 255.0;
        s.sh[0] = std::array::from_fn(|c| (b[2][3 * i + c] as f32 / 255.0 - 0.5) / COLOR_SCALE);
        let sh = &b[5][i * file_dim..];
        for k in 0..s.sh.len() - 1 {
            s.sh[k + 1] = std::array::from_fn(|c| (sh[3 * k + c] as f32 - 128.0) / 128.0 * shs[k]);
        }
        Ok(())
    });
    let Ok(mut cloud) = cloud;
    finish_cloud(&mut cloud, drop_at, f);
    cloud
}
