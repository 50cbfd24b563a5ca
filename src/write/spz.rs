//! Niantic SPZ writer: version 2 (gzip, first-three quaternions — what
//! `KHR_gaussian_splatting_compression_spz_2` pins), 3 (gzip, smallest-three) or 4 (zstd
//! streams). The inverse of [`crate::load::spz`]: our PLY frame is converted to SPZ's RUB
//! (y and z negated) unless [`SpzWriteOptions::axes`] is [`SpzAxes::Raw`]; for glTF
//! ([`super::to_glb_spz`]) glTF's LUF is converted instead (x and z negated).

use crate::cloud::SplatCloud;
use crate::load::codec::{flip_signs, sh_flip_signs};
use crate::load::spz::{COLOR_SCALE, FLAG_ANTIALIASED, Frame, MAGIC, RUB, SpzAxes, axis_flips};
use std::io::Write;

/// The SPZ versions splatgl writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpzVersion {
    /// Gzip, first-three quaternions (8 bits each): what `KHR_gaussian_splatting_compression_spz_2`
    /// pins, and what most readers take.
    #[default]
    V2,
    /// Gzip, smallest-three quaternions (10 bits).
    V3,
    /// One zstd stream per attribute, smallest-three quaternions; not gzip-wrapped.
    V4,
}

impl SpzVersion {
    /// The number in the header.
    pub fn number(self) -> u32 {
        match self {
            SpzVersion::V2 => 2,
            SpzVersion::V3 => 3,
            SpzVersion::V4 => 4,
        }
    }
}

impl TryFrom<u32> for SpzVersion {
    type Error = SpzWriteError;
    fn try_from(v: u32) -> Result<Self, SpzWriteError> {
        match v {
            2 => Ok(SpzVersion::V2),
            3 => Ok(SpzVersion::V3),
            4 => Ok(SpzVersion::V4),
            v => Err(SpzWriteError::Options(format!(
                "version {v}, expected 2, 3 or 4"
            ))),
        }
    }
}

/// How to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpzWriteOptions {
    /// The version.
    pub version: SpzVersion,
    /// Fractional bits of the 24-bit fixed-point positions (Niantic writes 12: ±2048 units in
    /// steps of 1/4096).
    pub fractional_bits: u8,
    /// Bits kept of the 8-bit SH values of degree 1 (Niantic's default 5).
    pub sh1_bits: u8,
    /// Bits kept of degrees 2 and 3 (default 4).
    pub sh_rest_bits: u8,
    /// Header flag 0x1.
    pub antialiased: bool,
    /// Axes of the stored numbers (Niantic: RUB).
    pub axes: SpzAxes,
}

impl Default for SpzWriteOptions {
    fn default() -> Self {
        SpzWriteOptions {
            version: SpzVersion::V2,
            fractional_bits: 12,
            sh1_bits: 5,
            sh_rest_bits: 4,
            antialiased: false,
            axes: SpzAxes::Rub,
        }
    }
}

/// Why a cloud cannot be written as SPZ.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpzWriteError {
    /// Options outside what the format allows.
    #[error("options: {0}")]
    Options(String),
    /// A position outside the 24-bit fixed-point range.
    #[error(
        "splat {index}: position {value} does not fit 24-bit fixed point with {bits} fractional bits (|p| < {limit})"
    )]
    Range {
        /// Splat.
        index: usize,
        /// The component.
        value: f32,
        /// Fractional bits.
        bits: u8,
        /// Largest magnitude that fits.
        limit: f64,
    },
    /// A non-finite value.
    #[error("splat {index}: non-finite {attribute}")]
    NonFinite {
        /// Splat.
        index: usize,
        /// Which attribute.
        attribute: &'static str,
    },
}

fn byte(v: f32) -> u8 {
    v.round().clamp(0.0, 255.0) as u8
}

/// Niantic's SH quantisation: 8 bits, then rounded to the centre of a bucket of `2^(8−bits)`.
fn sh_byte(v: f32, bits: u8) -> u8 {
    let bucket = 1i32 << (8 - bits);
    let q = (v * 128.0).round() as i32 + 128;
    ((q + bucket / 2) / bucket * bucket).clamp(0, 255) as u8
}

/// Smallest three: index of the largest |component| in the top 2 bits, then for each other
/// component (ascending index, most significant first) a sign bit and 9 bits of |c|/√½, the
/// largest made positive.
fn smallest_three(q: [f32; 4]) -> [u8; 4] {
    let largest = (0..4)
        .max_by(|&a, &b| q[a].abs().total_cmp(&q[b].abs()))
        .unwrap_or(3);
    let negate = q[largest] < 0.0;
    let mut comp = largest as u32;
    for (i, &c) in q.iter().enumerate() {
        if i != largest {
            let neg = ((c < 0.0) ^ negate) as u32;
            let mag = (511.0 * (c.abs() / std::f32::consts::FRAC_1_SQRT_2) + 0.5) as u32;
            comp = (comp << 10) | (neg << 9) | mag.min(511);
        }
    }
    comp.to_le_bytes()
}

fn check(cloud: &SplatCloud, o: &SpzWriteOptions) -> Result<(), SpzWriteError> {
    if o.fractional_bits > 23
        || !(1..=8).contains(&o.sh1_bits)
        || !(1..=8).contains(&o.sh_rest_bits)
    {
        return Err(SpzWriteError::Options(
            "fractional bits must be 0-23 and SH bits 1-8".into(),
        ));
    }
    if cloud.len() > u32::MAX as usize {
        return Err(SpzWriteError::Options(format!("{} splats", cloud.len())));
    }
    let step = (1u64 << o.fractional_bits) as f64;
    let limit = 8_388_607.5 / step;
    for i in 0..cloud.len() {
        let bad = |attribute| SpzWriteError::NonFinite {
            index: i,
            attribute,
        };
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !finite(&cloud.positions[i]) {
            return Err(bad("position"));
        }
        if !finite(&cloud.rotations[i]) {
            return Err(bad("rotation"));
        }
        if !cloud.opacities[i].is_finite() || !cloud.sh_of(i).iter().all(|c| finite(c)) {
            return Err(bad("opacity or SH"));
        }
        if !cloud.scales[i].iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(bad("scale (or a negative one)"));
        }
        let too_far = |v: &&f32| (v.abs() as f64 * step).round() > 8_388_607.0;
        if let Some(&value) = cloud.positions[i].iter().find(too_far) {
            let bits = o.fractional_bits;
            return Err(SpzWriteError::Range {
                index: i,
                value,
                bits,
                limit,
            });
        }
    }
    Ok(())
}

/// Encodes `cloud` (in splatgl's PLY frame, as SPZ, PLY and the other packed formats load) as
/// an SPZ file of `version` with Niantic's defaults: 12 fractional bits, SH kept to 5 bits
/// (degree 1) and 4 bits (degrees 2, 3), RUB axes. See [`to_spz_with`] for the options.
pub fn to_spz(cloud: &SplatCloud, version: SpzVersion) -> Result<Vec<u8>, SpzWriteError> {
    to_spz_with(
        cloud,
        &SpzWriteOptions {
            version,
            ..Default::default()
        },
    )
}

/// Encodes `cloud` (PLY frame) as SPZ with the given options.
pub fn to_spz_with(cloud: &SplatCloud, o: &SpzWriteOptions) -> Result<Vec<u8>, SpzWriteError> {
    encode(cloud, o, Frame::Ply)
}

/// Encodes `cloud`, whose axes are those of `frame`, as SPZ (RUB unless `o.axes` is raw).
pub(crate) fn encode(
    cloud: &SplatCloud,
    o: &SpzWriteOptions,
    frame: Frame,
) -> Result<Vec<u8>, SpzWriteError> {
    check(cloud, o)?;
    let blocks = attribute_blocks(cloud, o, frame);
    let header = header(cloud, o);
    if o.version != SpzVersion::V4 {
        return Ok(gzip_file(header, &blocks));
    }
    Ok(zstd_file(header, &blocks))
}

/// The six attribute blocks of the splats, quantised in SPZ's axes: positions, opacities,
/// colours, scales, rotations, higher SH.
fn attribute_blocks(cloud: &SplatCloud, o: &SpzWriteOptions, frame: Frame) -> [Vec<u8>; 6] {
    let n = cloud.len();
    let flip = match o.axes {
        SpzAxes::Rub | SpzAxes::Auto => axis_flips(frame.code(), RUB),
        SpzAxes::Raw => [false; 3],
    };
    let (s, qs) = flip_signs(flip);
    let shs = sh_flip_signs(flip);
    let k = cloud.coeffs_per_splat() - 1;
    let scale = (1u32 << o.fractional_bits) as f32;
    let mut blocks: [Vec<u8>; 6] = Default::default();
    for i in 0..n {
        for (a, p) in cloud.positions[i].iter().enumerate() {
            let v = (p * s[a] * scale).round() as i32;
            blocks[0].extend_from_slice(&v.to_le_bytes()[..3]);
        }
        blocks[1].push(byte(cloud.opacities[i] * 255.0));
        let sh = cloud.sh_of(i);
        for c in sh[0] {
            blocks[2].push(byte(c * COLOR_SCALE * 255.0 + 127.5));
        }
        for v in cloud.scales[i] {
            blocks[3].push(byte((v.ln() + 10.0) * 16.0));
        }
        let q = match crate::load::normalize_quat(cloud.rotations[i]) {
            Some((q, _)) => q,
            None => [0.0, 0.0, 0.0, 1.0],
        };
        let q = [q[0] * qs[0], q[1] * qs[1], q[2] * qs[2], q[3]];
        push_rotation(&mut blocks[4], q, o.version);
        for (j, c) in sh[1..].iter().enumerate() {
            let bits = if j < 3 { o.sh1_bits } else { o.sh_rest_bits };
            for v in c {
                blocks[5].push(sh_byte(v * shs[j], bits));
            }
        }
    }
    debug_assert_eq!(blocks[5].len(), n * k * 3);
    blocks
}

/// Appends the unit quaternion `q` (x, y, z, w): smallest three from version 3, else the
/// first three bytes with `w` made positive.
fn push_rotation(block: &mut Vec<u8>, q: [f32; 4], version: SpzVersion) {
    if version != SpzVersion::V2 {
        block.extend_from_slice(&smallest_three(q));
    } else {
        let w = if q[3] < 0.0 { -1.0 } else { 1.0 };
        for c in &q[..3] {
            block.push(byte(c * w * 127.5 + 127.5));
        }
    }
}

/// The header up to the flags byte: magic, version, splat count, SH degree, fractional
/// bits, flags.
fn header(cloud: &SplatCloud, o: &SpzWriteOptions) -> Vec<u8> {
    let mut header = Vec::with_capacity(32);
    header.extend_from_slice(MAGIC);
    header.extend_from_slice(&o.version.number().to_le_bytes());
    header.extend_from_slice(&(cloud.len() as u32).to_le_bytes());
    let degree = cloud.sh_degree;
    let flags = if o.antialiased { FLAG_ANTIALIASED } else { 0 };
    header.extend_from_slice(&[degree, o.fractional_bits, flags]);
    header
}

/// Versions 2 and 3: the header (with its reserved byte) and the blocks, gzipped.
fn gzip_file(mut header: Vec<u8>, blocks: &[Vec<u8>; 6]) -> Vec<u8> {
    header.push(0);
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    let io = |r: std::io::Result<()>| r.expect("writing to a Vec cannot fail");
    io(e.write_all(&header));
    for b in blocks {
        io(e.write_all(b));
    }
    e.finish().expect("writing to a Vec cannot fail")
}

/// Version 4: the 32-byte header, the table of (compressed, raw) sizes, then one zstd stream
/// per non-empty block.
fn zstd_file(mut header: Vec<u8>, blocks: &[Vec<u8>; 6]) -> Vec<u8> {
    let streams: Vec<Vec<u8>> = blocks
        .iter()
        .filter(|b| !b.is_empty())
        .map(|b| {
            ruzstd::encoding::compress_to_vec(
                b.as_slice(),
                ruzstd::encoding::CompressionLevel::Fastest,
            )
        })
        .collect();
    header.push(streams.len() as u8);
    header.extend_from_slice(&32u32.to_le_bytes());
    header.resize(32, 0);
    let mut out = header;
    for (z, b) in streams.iter().zip(blocks.iter().filter(|b| !b.is_empty())) {
        out.extend_from_slice(&(z.len() as u64).to_le_bytes());
        out.extend_from_slice(&(b.len() as u64).to_le_bytes());
    }
    for z in streams {
        out.extend_from_slice(&z);
    }
    out
}
