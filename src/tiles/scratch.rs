//! Building a LOD tree over more splats than memory holds ([`build_streamed`]): the input is
//! read in passes from a [`SplatSource`], and never held whole.
//!
//! 1. **Sample**: one pass keeps every k-th mean (at most [`SAMPLE`]), and splits the sample
//!    by planes along the longest axis into B = ⌈n / [`StreamOptions::bucket_splats`]⌉
//!    buckets of nearly equal size (a side with g of a plane's buckets gets that share of its
//!    splats) — the top levels of the k-d tree.
//! 2. **Scatter**: a second pass sends each splat through the planes to its bucket's file in
//!    the scratch folder (raw little-endian `f32`s).
//! 3. **Build**: bucket by bucket, its file is read back and built in memory as [`build`]
//!    builds a cloud, its tile named by its path through the planes; then deleted. As soon
//!    as both halves of a plane are built, their parent tile is made from their coarse
//!    content (as every inner tile is), so at most one coarse content per level of planes
//!    waits at any time.
//!
//! Peak memory is one bucket and its subtree's build, plus a coarse tile per level of planes:
//! independent of the scene's size for a fixed bucket size.
//!
//! [`build`]: super::build

use super::build::{BuiltTile, ContentSink, node, parent};
use crate::cloud::SplatCloud;
use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Splats read in passes, a chunk at a time.
pub trait SplatSource {
    /// Splats the source holds (an upper bound: unusable ones may be dropped as they are
    /// read).
    fn len(&self) -> u64;
    /// Whether it holds none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The SH degree of every chunk.
    fn sh_degree(&self) -> u8;
    /// Starts a new pass from the first splat.
    fn rewind(&mut self) -> Result<(), String>;
    /// The next chunk, `None` after the last.
    fn next_chunk(&mut self) -> Option<Result<SplatCloud, String>>;
}

/// At most this many buckets (files open at once while scattering); past it buckets grow.
pub const MAX_BUCKETS: usize = 256;

/// At most this many means are kept to place the bucket planes.
pub const SAMPLE: usize = 1 << 20;

/// Options of [`build_streamed`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamOptions {
    /// At most this many splats per tile (as [`super::BuildOptions::chunk_splats`]).
    pub chunk_splats: usize,
    /// About this many splats per bucket: what is built in memory at once.
    pub bucket_splats: usize,
    /// Where the buckets' files go (created if missing; the files are removed as they are
    /// read, and on error).
    pub scratch_dir: PathBuf,
}

impl StreamOptions {
    /// The default bucket: 2²¹ splats (about 120 MB at SH degree 0, 520 MB at degree 3).
    pub const DEFAULT_BUCKET_SPLATS: usize = 1 << 21;
}

/// What [`build_streamed`] did, besides the tree.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamReport {
    /// Splats read (after the source dropped unusable ones).
    pub splats: u64,
    /// Buckets the scene was cut into.
    pub buckets: usize,
    /// The largest bucket, in splats.
    pub largest_bucket: usize,
    /// Bytes written to the scratch folder.
    pub scratch_bytes: u64,
}

/// Builds the LOD tree over `src` in passes (see the module docs), handing each tile's
/// content to `sink`; `progress(stage, done, total)` is called as it goes. Errors: an
/// empty source, the source's or the sink's first error, or the scratch folder's.
pub fn build_streamed(
    src: &mut dyn SplatSource,
    o: &StreamOptions,
    sink: &ContentSink,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<(BuiltTile, StreamReport), super::TilesError> {
    use super::TilesError;
    let min = super::BuildOptions::MIN_CHUNK_SPLATS;
    if o.chunk_splats < min {
        return Err(TilesError::ChunkTooSmall {
            chunk: o.chunk_splats,
            min,
        });
    }
    streamed(src, o, sink, progress).map_err(TilesError::Build)
}

fn streamed(
    src: &mut dyn SplatSource,
    o: &StreamOptions,
    sink: &ContentSink,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<(BuiltTile, StreamReport), String> {
    let buckets = bucket_count(src.len(), o);
    let (planes, _) = sample_planes(src, buckets, progress)?;
    std::fs::create_dir_all(&o.scratch_dir)
        .map_err(|e| format!("{}: {e}", o.scratch_dir.display()))?;
    let tag = std::process::id();
    let paths = (0..buckets)
        .map(|i| o.scratch_dir.join(format!("splatgl-bucket-{tag}-{i}.bin")))
        .collect();
    let mut files = Buckets::create(paths, src.sh_degree())?;
    let result = scatter_and_build(src, &planes, &mut files, o.chunk_splats, sink, progress);
    files.remove_all();
    result
}

/// Checks the options and counts the buckets of `n` splats.
pub(super) fn bucket_count(n: u64, o: &StreamOptions) -> usize {
    n.div_ceil(o.bucket_splats.max(o.chunk_splats) as u64)
        .clamp(1, MAX_BUCKETS as u64) as usize
}

/// The top of the tree: a plane over two sides, or a bucket.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Plane {
    /// Splats with `p[axis] >= value` go `above`, the others `below`.
    Split {
        /// 0, 1 or 2: x, y or z.
        axis: usize,
        /// The plane's place on its axis (as bits: it may be +∞, which JSON cannot hold).
        #[serde(with = "f32_bits")]
        value: f32,
        /// The side below the plane (its tile's first child).
        below: Box<Plane>,
        /// The side above (the second child).
        above: Box<Plane>,
    },
    /// A bucket, numbered left to right.
    Bucket(usize),
}

impl Plane {
    /// The tile name of bucket `b` (its path through the planes from `r`), if it is here.
    pub fn bucket_name(&self, b: usize) -> Option<String> {
        match self {
            Plane::Bucket(x) => (*x == b).then(|| "r".to_string()),
            Plane::Split { below, above, .. } => {
                let (side, digit) = match below.bucket_name(b) {
                    Some(n) => (n, '0'),
                    None => (above.bucket_name(b)?, '1'),
                };
                Some(format!("r{digit}{}", &side[1..]))
            }
        }
    }
}

/// An `f32` kept exactly, as its bits.
mod f32_bits {
    pub fn serialize<S: serde::Serializer>(v: &f32, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u32(v.to_bits())
    }
    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
        <u32 as serde::Deserialize>::deserialize(d).map(f32::from_bits)
    }
}

/// Planes over `buckets` buckets from a sample of the source's means.
pub(super) fn sample_planes(
    src: &mut dyn SplatSource,
    buckets: usize,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<(Plane, crate::cloud::SplatMeta), String> {
    let n = src.len();
    let mut meta = None;
    let stride = n.div_ceil(SAMPLE as u64).max(1);
    let mut sample: Vec<[f32; 3]> = Vec::new();
    let mut seen = 0u64;
    src.rewind()?;
    while let Some(c) = src.next_chunk() {
        let c = c?;
        meta.get_or_insert_with(|| c.meta.clone());
        for (i, p) in c.positions.iter().enumerate() {
            if (seen + i as u64).is_multiple_of(stride) {
                sample.push(*p);
            }
        }
        seen += c.len() as u64;
        progress("sampling", seen, n);
    }
    if seen == 0 {
        return Err("no splats to build a tileset from".into());
    }
    let mut next = 0;
    let planes = split_sample(&mut sample, buckets, &mut next);
    Ok((planes, meta.unwrap_or_default()))
}

/// Splits `s` for `buckets` buckets, numbered from `next` left to right.
fn split_sample(s: &mut [[f32; 3]], buckets: usize, next: &mut usize) -> Plane {
    if buckets <= 1 {
        *next += 1;
        return Plane::Bucket(*next - 1);
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in s.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let left = buckets / 2;
    let at = s.len() * left / buckets;
    let value = if at < s.len() {
        s.select_nth_unstable_by(at, |a, b| a[axis].total_cmp(&b[axis]));
        s[at][axis]
    } else {
        f32::INFINITY
    };
    let (l, r) = s.split_at_mut(at);
    let below = Box::new(split_sample(l, left, next));
    let above = Box::new(split_sample(r, buckets - left, next));
    Plane::Split {
        axis,
        value,
        below,
        above,
    }
}

/// The bucket of `p`: its path through the planes.
pub(super) fn route(mut plane: &Plane, p: [f32; 3]) -> usize {
    loop {
        match plane {
            Plane::Bucket(b) => return *b,
            Plane::Split {
                axis,
                value,
                below,
                above,
            } => plane = if p[*axis] >= *value { above } else { below },
        }
    }
}

/// The buckets' scratch files.
pub(super) struct Buckets {
    paths: Vec<PathBuf>,
    writers: Vec<Option<BufWriter<File>>>,
    counts: Vec<usize>,
    sh_degree: u8,
    bytes: u64,
}

impl Buckets {
    /// One file per bucket, at `paths`.
    pub(super) fn create(paths: Vec<PathBuf>, sh_degree: u8) -> Result<Self, String> {
        let n = paths.len();
        let mut b = Buckets {
            paths,
            writers: Vec::with_capacity(n),
            counts: vec![0; n],
            sh_degree,
            bytes: 0,
        };
        for p in b.paths.clone() {
            match File::create(&p) {
                Ok(f) => b.writers.push(Some(BufWriter::with_capacity(1 << 16, f))),
                Err(e) => {
                    b.remove_all();
                    return Err(format!("{}: {e}", p.display()));
                }
            }
        }
        Ok(b)
    }

    /// Splats written to each bucket, and bytes in all.
    pub(super) fn written(&self) -> (&[usize], u64) {
        (&self.counts, self.bytes)
    }

    pub(super) fn push(&mut self, b: usize, c: &SplatCloud, i: usize) -> Result<(), String> {
        let floats = row_floats(self.sh_degree);
        let w = self.writers[b].as_mut().ok_or("bucket already closed")?;
        let values = c.positions[i]
            .iter()
            .chain(&c.scales[i])
            .chain(&c.rotations[i])
            .chain(std::iter::once(&c.opacities[i]))
            .chain(c.sh_of(i).iter().flatten());
        for v in values {
            w.write_all(&v.to_le_bytes())
                .map_err(|e| format!("{}: {e}", self.paths[b].display()))?;
        }
        self.counts[b] += 1;
        self.bytes += 4 * floats as u64;
        Ok(())
    }

    pub(super) fn finish_writing(&mut self) -> Result<(), String> {
        for (w, p) in self.writers.iter_mut().zip(&self.paths) {
            if let Some(mut w) = w.take() {
                w.flush().map_err(|e| format!("{}: {e}", p.display()))?;
            }
        }
        Ok(())
    }

    /// Reads bucket `b` back (and removes its file).
    fn read(&self, b: usize) -> Result<SplatCloud, String> {
        let p = &self.paths[b];
        let mut c = SplatCloud::with_capacity(self.sh_degree, self.counts[b]);
        read_rows(p, self.sh_degree, self.counts[b], &mut c)?;
        let _ = std::fs::remove_file(p);
        Ok(c)
    }

    pub(super) fn remove_all(&mut self) {
        self.writers.clear();
        for p in &self.paths {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Floats per splat in a bucket file.
fn row_floats(sh_degree: u8) -> usize {
    11 + 3 * crate::cloud::sh_coeff_count(sh_degree)
}

/// Bytes per splat in a bucket file.
pub(super) fn row_bytes(sh_degree: u8) -> u64 {
    4 * row_floats(sh_degree) as u64
}

/// Appends `count` splats read from the bucket file at `p` to `c`.
pub(super) fn read_rows(
    p: &Path,
    sh_degree: u8,
    count: usize,
    c: &mut SplatCloud,
) -> Result<(), String> {
    let err = |e: std::io::Error| format!("{}: {e}", p.display());
    let mut f = std::io::BufReader::with_capacity(1 << 20, File::open(p).map_err(err)?);
    let k = crate::cloud::sh_coeff_count(sh_degree);
    let mut sh = vec![[0.0f32; 3]; k];
    let mut r = vec![0u8; row_bytes(sh_degree) as usize];
    for _ in 0..count {
        f.read_exact(&mut r).map_err(err)?;
        let f = |j: usize| f32::from_le_bytes([r[4 * j], r[4 * j + 1], r[4 * j + 2], r[4 * j + 3]]);
        for (j, t) in sh.iter_mut().enumerate() {
            *t = [f(11 + 3 * j), f(12 + 3 * j), f(13 + 3 * j)];
        }
        c.push(
            [f(0), f(1), f(2)],
            [f(3), f(4), f(5)],
            [f(6), f(7), f(8), f(9)],
            f(10),
            &sh,
        );
    }
    Ok(())
}

/// Passes 2 and 3 (see the module docs).
fn scatter_and_build(
    src: &mut dyn SplatSource,
    planes: &Plane,
    buckets: &mut Buckets,
    chunk: usize,
    sink: &ContentSink,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<(BuiltTile, StreamReport), String> {
    let n = src.len();
    let mut meta = None;
    let mut seen = 0u64;
    src.rewind()?;
    while let Some(c) = src.next_chunk() {
        let c = c?;
        for i in 0..c.len() {
            buckets.push(route(planes, c.positions[i]), &c, i)?;
        }
        seen += c.len() as u64;
        meta.get_or_insert(c.meta);
        progress("scattering", seen, n);
    }
    buckets.finish_writing()?;
    let mut b = BucketBuild {
        buckets,
        meta: meta.unwrap_or_default(),
        chunk,
        sink,
        progress,
        done: 0,
    };
    let (root, _) = b
        .build(planes, "r".into())?
        .ok_or("no splats to build a tileset from")?;
    let report = StreamReport {
        splats: seen,
        buckets: buckets.counts.len(),
        largest_bucket: buckets.counts.iter().copied().max().unwrap_or(0),
        scratch_bytes: buckets.bytes,
    };
    Ok((root, report))
}

/// Pass 3: the tree built bucket by bucket, depth first.
struct BucketBuild<'a> {
    buckets: &'a Buckets,
    meta: crate::cloud::SplatMeta,
    chunk: usize,
    sink: &'a ContentSink<'a>,
    progress: &'a dyn Fn(&str, u64, u64),
    done: u64,
}

impl BucketBuild<'_> {
    /// The subtree under `plane`, named `name` (`None` when its buckets are empty).
    fn build(
        &mut self,
        plane: &Plane,
        name: String,
    ) -> Result<Option<(BuiltTile, SplatCloud)>, String> {
        match plane {
            Plane::Bucket(b) => {
                let mut cloud = self.buckets.read(*b)?;
                cloud.meta = self.meta.clone();
                self.done += 1;
                (self.progress)("building", self.done, self.buckets.counts.len() as u64);
                if cloud.is_empty() {
                    return Ok(None);
                }
                let mut idx: Vec<u32> = (0..cloud.len() as u32).collect();
                node(&cloud, &mut idx, name, self.chunk, self.sink).map(Some)
            }
            Plane::Split { below, above, .. } => {
                let l = self.build(below, format!("{name}0"))?;
                let r = self.build(above, format!("{name}1"))?;
                Ok(match (l, r) {
                    (Some(l), Some(r)) => Some(parent(name, l, r, self.chunk, self.sink)?),
                    (one, None) | (None, one) => one,
                })
            }
        }
    }
}
