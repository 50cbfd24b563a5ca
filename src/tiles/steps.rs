//! The bucketed build of [`super::build_streamed`] as steps that a driver hands out to workers
//! sharing one folder (a local disk for processes of one machine, a shared file system for a
//! cluster): Python's `splatgl.tiles.build_distributed` runs them on Ray.
//!
//! 1. [`plan`] (driver): one pass samples the means and places the bucket planes, as the
//!    single-process build does; the plan (planes, the rotation into glTF's frame decided on
//!    the file's first chunk, the input's row ranges) goes to `plan.json` in the scratch folder.
//! 2. [`route_range`] (one task per row range, in parallel): reads its rows and appends each
//!    splat to its bucket's part file `part-R-B.bin` (written aside, renamed when complete).
//! 3. [`build_bucket`] (one task per bucket, in parallel): reads the bucket's parts in row
//!    order — the order the single-process build writes them in — builds its subtree, writes
//!    its tiles' `.glb`s, and keeps its root's coarse content in `coarse-B.bin`.
//! 4. [`join`] (driver): makes the tiles above the buckets from their coarse content, depth
//!    first, writes `tileset.json` (last, atomically) and removes the scratch files.
//!
//! Each step's output depends on its inputs only, and is written whole or not at all: a task
//! run again after its worker died writes the same files. The result is the tileset
//! `convert IN out/tileset.json --scratch-dir D --bucket-splats B` writes, byte for byte.

use super::build::{BuiltTile, node, parent};
use super::scratch::{Buckets, Plane, bucket_count, read_rows, route, row_bytes, sample_planes};
use super::source::PlySource;
use super::{SplatSource, StreamOptions};
use crate::cloud::{SplatCloud, SplatMeta};
use crate::convert::{ConvertOptions, OutputFormat};
use crate::load::LoadOptions;
use glam::DMat3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// The folder, next to `tileset.json`, that holds the tiles' content.
pub const TILES_DIR: &str = "tiles";

/// The plan's file name in the scratch folder.
pub const PLAN_FILE: &str = "plan.json";

/// What went wrong in a step.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// A file of the build could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The input, the build or a tile's encoding failed (the message names the file).
    #[error("{0}")]
    Build(String),
    /// A step was handed something that does not fit the plan.
    #[error("{0}")]
    Plan(String),
}

impl From<String> for StepError {
    fn from(e: String) -> Self {
        StepError::Build(e)
    }
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> StepError + '_ {
    move |source| StepError::Io {
        path: path.to_owned(),
        source,
    }
}

/// What the driver decided: every step reads it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BuildPlan {
    /// The binary PLY built from.
    pub input: PathBuf,
    /// Where `tileset.json` goes (the tiles go to `tiles/` beside it).
    pub output: PathBuf,
    /// The folder every worker reaches, for the buckets' files.
    pub scratch_dir: PathBuf,
    /// At most this many splats per tile.
    pub chunk_splats: usize,
    /// The SH degree of every splat.
    pub sh_degree: u8,
    /// The rotation into glTF's +Y up frame (column-major), decided on the first chunk.
    pub rotation: [f64; 9],
    /// Rows of the input routed by each [`route_range`] task: `[start, end)`.
    pub ranges: Vec<[u64; 2]>,
    /// The planes over the buckets.
    pub planes: Plane,
    /// Buckets under the planes.
    pub buckets: usize,
}

/// What [`route_range`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RangeReport {
    /// The range's index in [`BuildPlan::ranges`].
    pub range: usize,
    /// Splats routed (after rows that could not be used and the crop were dropped).
    pub splats: u64,
    /// Bytes written to the part files.
    pub bytes: u64,
    /// What the rows showed (rows dropped, ±inf opacities), with row numbers.
    pub findings: Vec<String>,
}

/// What [`build_bucket`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BucketReport {
    /// The bucket.
    pub bucket: usize,
    /// Its splats.
    pub splats: u64,
    /// Its subtree (`None` when the bucket is empty).
    pub tile: Option<BuiltTile>,
    /// Bytes of content written.
    pub bytes: u64,
    /// Tiles written.
    pub tiles: usize,
    /// What encoding the tiles noted (e.g. SH degrees dropped).
    pub notes: Vec<String>,
}

/// What [`join`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JoinReport {
    /// The whole tree.
    pub root: BuiltTile,
    /// Splats built.
    pub splats: u64,
    /// Tiles above the buckets written by the join.
    pub tiles: usize,
    /// Bytes of content they hold.
    pub bytes: u64,
    /// What encoding them noted.
    pub notes: Vec<String>,
}

/// The glTF extensions every tile's content uses (and requires), for `3DTILES_content_gltf`.
pub fn content_extensions(o: &ConvertOptions) -> Vec<&'static str> {
    let mut e = vec!["KHR_gaussian_splatting"];
    if o.spz_compress {
        e.push("KHR_gaussian_splatting_compression_spz_2");
    }
    if o.quantize.position != crate::write::Comp::F32 {
        e.push("KHR_mesh_quantization");
    }
    e
}

/// Step 1 (driver): samples `input`, places the planes for buckets of about
/// `o.bucket_splats`, cuts the rows into `ranges` ranges, and writes the plan to
/// `o.scratch_dir/plan.json`. Errors: the input's (a binary PLY), an empty input, the
/// scratch folder's.
pub fn plan(
    input: &Path,
    output: &Path,
    o: &StreamOptions,
    ranges: usize,
    progress: &dyn Fn(&str, u64, u64),
) -> Result<BuildPlan, StepError> {
    check_chunk(o.chunk_splats)?;
    let mut src = open(input)?;
    let buckets = bucket_count(src.len(), o);
    let (planes, meta) = sample_planes(&mut src, buckets, progress)?;
    if meta != SplatMeta::default() {
        return Err(StepError::Plan(format!(
            "{}: the distributed build writes the extension's default metadata, and this \
             input has other values ({meta:?})",
            input.display()
        )));
    }
    let rows = src.rows.len();
    let parts = ranges.clamp(1, MAX_RANGES) as u64;
    let plan = BuildPlan {
        input: input.to_owned(),
        output: output.to_owned(),
        scratch_dir: o.scratch_dir.clone(),
        chunk_splats: o.chunk_splats,
        sh_degree: src.sh_degree(),
        rotation: src.rotation.unwrap_or(DMat3::IDENTITY).to_cols_array(),
        ranges: (0..parts)
            .map(|i| [rows * i / parts, rows * (i + 1) / parts])
            .collect(),
        planes,
        buckets,
    };
    std::fs::create_dir_all(&o.scratch_dir).map_err(io(&o.scratch_dir))?;
    let text = serde_json::to_vec_pretty(&plan).map_err(|e| StepError::Plan(e.to_string()))?;
    let path = o.scratch_dir.join(PLAN_FILE);
    crate::write::write_bytes_atomic(&path, &[input], &text).map_err(io(&path))?;
    Ok(plan)
}

/// At most this many row ranges (part files per bucket).
pub const MAX_RANGES: usize = 1024;

fn check_chunk(chunk: usize) -> Result<(), StepError> {
    let min = super::BuildOptions::MIN_CHUNK_SPLATS;
    if chunk < min {
        return Err(StepError::Plan(format!(
            "chunk_splats {chunk} is below the minimum {min}"
        )));
    }
    Ok(())
}

fn open(input: &Path) -> Result<PlySource, StepError> {
    let load = LoadOptions::default();
    PlySource::open(input, &load, ConvertOptions::default(), None)
        .map_err(|e| StepError::Build(format!("the distributed build reads binary PLY: {e}")))
}

impl BuildPlan {
    /// Reads a plan written by [`plan`].
    pub fn read(path: &Path) -> Result<Self, StepError> {
        let text = std::fs::read(path).map_err(io(path))?;
        serde_json::from_slice(&text)
            .map_err(|e| StepError::Plan(format!("{}: {e}", path.display())))
    }

    fn part(&self, range: usize, bucket: usize) -> PathBuf {
        self.scratch_dir.join(format!("part-{range}-{bucket}.bin"))
    }

    fn coarse(&self, bucket: usize) -> PathBuf {
        self.scratch_dir.join(format!("coarse-{bucket}.bin"))
    }

    fn tiles_dir(&self) -> PathBuf {
        match self.output.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.join(TILES_DIR),
            _ => PathBuf::from(TILES_DIR),
        }
    }

    fn check_bucket(&self, b: usize) -> Result<(), StepError> {
        if b >= self.buckets {
            return Err(StepError::Plan(format!(
                "bucket {b} is not in the plan (it has {})",
                self.buckets
            )));
        }
        Ok(())
    }
}

/// Appends ".tmp" to a path's file name.
fn aside(p: &Path) -> PathBuf {
    let mut s = p.as_os_str().to_owned();
    s.push(".tmp");
    PathBuf::from(s)
}

/// Step 2 (one task per range): routes the rows of range `range` to the buckets' part files.
pub fn route_range(plan: &BuildPlan, range: usize) -> Result<RangeReport, StepError> {
    let &[start, end] = plan
        .ranges
        .get(range)
        .ok_or_else(|| StepError::Plan(format!("range {range} is not in the plan")))?;
    let rotation = DMat3::from_cols_array(&plan.rotation);
    let mut src = open(&plan.input)?.with_range(start, end, rotation);
    let finals: Vec<PathBuf> = (0..plan.buckets).map(|b| plan.part(range, b)).collect();
    let mut files = Buckets::create(finals.iter().map(|p| aside(p)).collect(), plan.sh_degree)?;
    let routed = route_into(&mut src, &plan.planes, &mut files);
    let (counts, bytes) = files.written();
    let splats = counts.iter().map(|&c| c as u64).sum();
    if let Err(e) = routed {
        files.remove_all();
        return Err(e);
    }
    for p in &finals {
        std::fs::rename(aside(p), p).map_err(io(p))?;
    }
    Ok(RangeReport {
        range,
        splats,
        bytes,
        findings: src.rows.findings.iter().map(|f| f.to_string()).collect(),
    })
}

fn route_into(src: &mut PlySource, planes: &Plane, files: &mut Buckets) -> Result<(), StepError> {
    src.rewind()?;
    while let Some(c) = src.next_chunk() {
        let c = c?;
        for i in 0..c.len() {
            files.push(route(planes, c.positions[i]), &c, i)?;
        }
    }
    Ok(files.finish_writing()?)
}

/// Writes tiles' content as `.glb`s in a folder, counting them.
struct TileFiles {
    dir: PathBuf,
    input: PathBuf,
    options: ConvertOptions,
    bytes: AtomicU64,
    tiles: AtomicU64,
    notes: Mutex<BTreeSet<String>>,
}

impl TileFiles {
    fn new(plan: &BuildPlan) -> Result<Self, StepError> {
        let dir = plan.tiles_dir();
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        Ok(TileFiles {
            dir,
            input: plan.input.clone(),
            options: ConvertOptions::default(),
            bytes: AtomicU64::new(0),
            tiles: AtomicU64::new(0),
            notes: Mutex::new(BTreeSet::new()),
        })
    }

    fn write(&self, name: &str, c: &SplatCloud) -> Result<(), String> {
        let (glb, n) =
            crate::convert::encode_with_cameras(c, OutputFormat::Glb, &self.options, &[])?;
        let path = self.dir.join(format!("{name}.glb"));
        crate::write::write_bytes_atomic(&path, &[&self.input], &glb)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.notes
            .lock()
            .map_err(|_| "a tile writer failed")?
            .extend(n);
        self.bytes.fetch_add(glb.len() as u64, Ordering::Relaxed);
        self.tiles.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }

    fn notes(self) -> Vec<String> {
        self.notes
            .into_inner()
            .unwrap_or_default()
            .into_iter()
            .collect()
    }
}

/// Reads bucket `b`'s part files (all ranges, in row order); an error if any is missing.
fn read_parts(plan: &BuildPlan, b: usize) -> Result<SplatCloud, StepError> {
    let row = row_bytes(plan.sh_degree);
    let mut c = SplatCloud::with_capacity(plan.sh_degree, 0);
    for r in 0..plan.ranges.len() {
        let p = plan.part(r, b);
        let len = std::fs::metadata(&p).map_err(io(&p))?.len();
        if len % row != 0 {
            return Err(StepError::Plan(format!(
                "{}: {len} bytes is not a whole number of {row}-byte splats",
                p.display()
            )));
        }
        read_rows(&p, plan.sh_degree, (len / row) as usize, &mut c)?;
    }
    Ok(c)
}

/// Step 3 (one task per bucket): builds bucket `b`'s subtree from its part files, writes its
/// tiles, and keeps its root's coarse content for [`join`].
pub fn build_bucket(plan: &BuildPlan, b: usize) -> Result<BucketReport, StepError> {
    plan.check_bucket(b)?;
    let cloud = read_parts(plan, b)?;
    let name = plan
        .planes
        .bucket_name(b)
        .ok_or_else(|| StepError::Plan(format!("bucket {b} is under no plane")))?;
    let files = TileFiles::new(plan)?;
    let splats = cloud.len() as u64;
    let tile = if cloud.is_empty() {
        None
    } else {
        let mut idx: Vec<u32> = (0..cloud.len() as u32).collect();
        let sink = |n: &str, c: &SplatCloud| files.write(n, c);
        let (tile, coarse) = node(&cloud, &mut idx, name, plan.chunk_splats, &sink)?;
        write_cloud(&plan.coarse(b), &coarse)?;
        Some(tile)
    };
    Ok(BucketReport {
        bucket: b,
        splats,
        tile,
        bytes: files.bytes.load(Ordering::Relaxed),
        tiles: files.tiles.load(Ordering::Relaxed) as usize,
        notes: files.notes(),
    })
}

/// Writes `c` as a bucket file (aside, then renamed).
fn write_cloud(path: &Path, c: &SplatCloud) -> Result<(), StepError> {
    let tmp = aside(path);
    let mut f = Buckets::create(vec![tmp.clone()], c.sh_degree)?;
    for i in 0..c.len() {
        f.push(0, c, i)?;
    }
    f.finish_writing()?;
    std::fs::rename(&tmp, path).map_err(io(path))
}

/// Step 4 (driver): the tiles above the buckets from their coarse content, then
/// `tileset.json`; removes the scratch files. `buckets` holds every bucket's report.
pub fn join(plan: &BuildPlan, buckets: &[BucketReport]) -> Result<JoinReport, StepError> {
    let mut tiles: Vec<Option<&BuiltTile>> = vec![None; plan.buckets];
    let mut splats = 0;
    for r in buckets {
        plan.check_bucket(r.bucket)?;
        tiles[r.bucket] = r.tile.as_ref();
        splats += r.splats;
    }
    if buckets.len() != plan.buckets {
        return Err(StepError::Plan(format!(
            "{} bucket reports for {} buckets",
            buckets.len(),
            plan.buckets
        )));
    }
    let files = TileFiles::new(plan)?;
    let mut j = Join {
        plan,
        tiles: &tiles,
        files: &files,
    };
    let (root, _) = j
        .tree(&plan.planes, "r".into())?
        .ok_or_else(|| StepError::Build("no splats to build a tileset from".into()))?;
    write_tileset(plan, &root)?;
    remove_scratch(plan);
    Ok(JoinReport {
        root,
        splats,
        tiles: files.tiles.load(Ordering::Relaxed) as usize,
        bytes: files.bytes.load(Ordering::Relaxed),
        notes: files.notes(),
    })
}

/// The join's walk over the planes.
struct Join<'a> {
    plan: &'a BuildPlan,
    tiles: &'a [Option<&'a BuiltTile>],
    files: &'a TileFiles,
}

impl Join<'_> {
    fn tree(
        &mut self,
        plane: &Plane,
        name: String,
    ) -> Result<Option<(BuiltTile, SplatCloud)>, StepError> {
        match plane {
            Plane::Bucket(b) => {
                let Some(t) = self.tiles[*b] else {
                    return Ok(None);
                };
                let p = self.plan.coarse(*b);
                let mut c = SplatCloud::with_capacity(self.plan.sh_degree, t.splats);
                read_rows(&p, self.plan.sh_degree, t.splats, &mut c)?;
                Ok(Some((t.clone(), c)))
            }
            Plane::Split { below, above, .. } => {
                let l = self.tree(below, format!("{name}0"))?;
                let r = self.tree(above, format!("{name}1"))?;
                let sink = |n: &str, c: &SplatCloud| self.files.write(n, c);
                Ok(match (l, r) {
                    (Some(l), Some(r)) => Some(parent(name, l, r, self.plan.chunk_splats, &sink)?),
                    (one, None) | (None, one) => one,
                })
            }
        }
    }
}

fn write_tileset(plan: &BuildPlan, root: &BuiltTile) -> Result<(), StepError> {
    let uri = |name: &str| format!("{TILES_DIR}/{name}.glb");
    let ext = content_extensions(&ConvertOptions::default());
    let doc = super::tileset_json(root, &uri, &ext, 0.0);
    let text = serde_json::to_vec_pretty(&doc).map_err(|e| StepError::Plan(e.to_string()))?;
    crate::write::write_bytes_atomic(&plan.output, &[&plan.input], &text).map_err(io(&plan.output))
}

/// Removes the plan's part, coarse and plan files (what is already gone is no error).
pub fn remove_scratch(plan: &BuildPlan) {
    for b in 0..plan.buckets {
        for r in 0..plan.ranges.len() {
            let _ = std::fs::remove_file(plan.part(r, b));
        }
        let _ = std::fs::remove_file(plan.coarse(b));
    }
    let _ = std::fs::remove_file(plan.scratch_dir.join(PLAN_FILE));
}
