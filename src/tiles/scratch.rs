//! Building a LOD tree over more splats than memory holds ([`build_streamed`]): the input is
//! read in passes from a [`SplatSource`], and never held whole.
//!
//! 1. **Sample**: one pass keeps every k-th mean (at most [`SAMPLE`]), and splits the sample
//!    by median planes along the longest axis into B = 2^d buckets of about
//!    [`StreamOptions::bucket_splats`] splats each — the top d levels of the k-d tree.
//! 2. **Scatter**: a second pass sends each splat through the planes to its bucket's file in
//!    the scratch folder (raw little-endian `f32`s).
//! 3. **Build**: bucket by bucket, its file is read back and built in memory as [`build`]
//!    builds a cloud, its tile named by its path through the planes; then deleted. As soon
//!    as both halves of a plane are built, their parent tile is made from their coarse
//!    content (as every inner tile is), so at most d coarse contents wait at any time.
//!
//! Peak memory is one bucket and its subtree's build, plus d coarse tiles: independent of
//! the scene's size for a fixed bucket size.
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
) -> Result<(BuiltTile, StreamReport), String> {
    if o.chunk_splats < super::BuildOptions::MIN_CHUNK_SPLATS {
        return Err(format!(
            "chunk_splats {} is below the minimum {}",
            o.chunk_splats,
            super::BuildOptions::MIN_CHUNK_SPLATS
        ));
    }
    let n = src.len();
    let wanted = n
        .div_ceil(o.bucket_splats.max(o.chunk_splats) as u64)
        .max(1);
    let depth = (64 - (wanted - 1).leading_zeros()).min(12) as usize;
    let planes = sample_planes(src, depth, progress)?;
    std::fs::create_dir_all(&o.scratch_dir)
        .map_err(|e| format!("{}: {e}", o.scratch_dir.display()))?;
    let mut buckets = Buckets::create(&o.scratch_dir, 1 << depth, src.sh_degree())?;
    let result = scatter_and_build(src, &planes, &mut buckets, o.chunk_splats, sink, progress);
    buckets.remove_all();
    result
}

/// Median planes in heap order (`planes[i]` for i in 1..2^depth: `(axis, value)`), from a
/// sample of the source's means.
fn sample_planes(
    src: &mut dyn SplatSource,
    depth: usize,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<Vec<(usize, f32)>, String> {
    let n = src.len();
    let stride = n.div_ceil(SAMPLE as u64).max(1);
    let mut sample: Vec<[f32; 3]> = Vec::new();
    let mut seen = 0u64;
    src.rewind()?;
    while let Some(c) = src.next_chunk() {
        let c = c?;
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
    let mut planes = vec![(0, 0.0); 1 << depth];
    split_sample(&mut sample, 1, depth, &mut planes);
    Ok(planes)
}

fn split_sample(s: &mut [[f32; 3]], i: usize, depth: usize, planes: &mut [(usize, f32)]) {
    if depth == 0 {
        return;
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
    let mid = s.len() / 2;
    let value = if s.is_empty() {
        0.0
    } else {
        s.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
        s[mid][axis]
    };
    planes[i] = (axis, value);
    let (l, r) = s.split_at_mut(mid);
    split_sample(l, 2 * i, depth - 1, planes);
    split_sample(r, 2 * i + 1, depth - 1, planes);
}

/// The bucket of `p`: its path through the planes.
fn route(planes: &[(usize, f32)], p: [f32; 3]) -> usize {
    let b = planes.len();
    let mut i = 1;
    while i < b {
        let (axis, value) = planes[i];
        i = 2 * i + usize::from(p[axis] >= value);
    }
    i - b
}

/// The buckets' scratch files.
struct Buckets {
    paths: Vec<PathBuf>,
    writers: Vec<Option<BufWriter<File>>>,
    counts: Vec<usize>,
    sh_degree: u8,
    bytes: u64,
}

impl Buckets {
    fn create(dir: &Path, n: usize, sh_degree: u8) -> Result<Self, String> {
        let tag = std::process::id();
        let mut b = Buckets {
            paths: (0..n)
                .map(|i| dir.join(format!("splatgl-bucket-{tag}-{i}.bin")))
                .collect(),
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

    /// Floats per splat in a bucket file.
    fn floats(&self) -> usize {
        11 + 3 * crate::cloud::sh_coeff_count(self.sh_degree)
    }

    fn push(&mut self, b: usize, c: &SplatCloud, i: usize) -> Result<(), String> {
        let floats = self.floats();
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

    fn finish_writing(&mut self) -> Result<(), String> {
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
        let err = |e: std::io::Error| format!("{}: {e}", p.display());
        let mut f = std::io::BufReader::with_capacity(1 << 20, File::open(p).map_err(err)?);
        let k = crate::cloud::sh_coeff_count(self.sh_degree);
        let row = 4 * self.floats();
        let mut c = SplatCloud::with_capacity(self.sh_degree, self.counts[b]);
        let mut sh = vec![[0.0f32; 3]; k];
        let mut r = vec![0u8; row];
        for _ in 0..self.counts[b] {
            f.read_exact(&mut r).map_err(err)?;
            let f =
                |j: usize| f32::from_le_bytes([r[4 * j], r[4 * j + 1], r[4 * j + 2], r[4 * j + 3]]);
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
        drop(f);
        let _ = std::fs::remove_file(p);
        Ok(c)
    }

    fn remove_all(&mut self) {
        self.writers.clear();
        for p in &self.paths {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Passes 2 and 3 (see the module docs).
fn scatter_and_build(
    src: &mut dyn SplatSource,
    planes: &[(usize, f32)],
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
    let count = planes.len();
    let depth = count.trailing_zeros() as usize;
    // Built subtrees waiting for their sibling, by heap index.
    let mut waiting: Vec<(usize, Option<(BuiltTile, SplatCloud)>)> = Vec::new();
    for b in 0..count {
        let mut cloud = buckets.read(b)?;
        cloud.meta = meta.clone().unwrap_or_default();
        let name = format!(
            "r{}",
            (0..depth)
                .rev()
                .map(|k| if b >> k & 1 == 1 { '1' } else { '0' })
                .collect::<String>()
        );
        let built = if cloud.is_empty() {
            None
        } else {
            let mut idx: Vec<u32> = (0..cloud.len() as u32).collect();
            Some(node(&cloud, &mut idx, name, chunk, sink)?)
        };
        let mut at = count + b;
        let mut here = built;
        // Climb while this is a right child whose left sibling is waiting.
        while at > 1 && at % 2 == 1 {
            let (_, left) = waiting.pop().ok_or("bucket order broken")?;
            let parent_name = format!("r{}", heap_path(at / 2));
            here = match (left, here) {
                (Some(l), Some(r)) => Some(parent(parent_name, l, r, chunk, sink)?),
                (one, None) | (None, one) => one,
            };
            at /= 2;
        }
        waiting.push((at, here));
        progress("building", b as u64 + 1, count as u64);
    }
    let (_, root) = waiting.pop().ok_or("no buckets")?;
    let (root, _) = root.ok_or("no splats to build a tileset from")?;
    let report = StreamReport {
        splats: seen,
        buckets: count,
        largest_bucket: buckets.counts.iter().copied().max().unwrap_or(0),
        scratch_bytes: buckets.bytes,
    };
    Ok((root, report))
}

/// The path of heap node `i` (1 = root) as binary digits after the leading 1.
fn heap_path(i: usize) -> String {
    let bits = usize::BITS - i.leading_zeros() - 1;
    (0..bits)
        .rev()
        .map(|k| if i >> k & 1 == 1 { '1' } else { '0' })
        .collect()
}
