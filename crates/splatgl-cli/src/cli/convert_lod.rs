//! `splatgl convert IN out/tileset.json`: a level-of-detail 3D Tiles 1.1 tileset built by
//! [`splatgl::tiles::build`], each tile's content a `.glb` in `out/tiles/` encoded like any
//! `.glb` output (`--quantize`, `--spz-compress`, `--sh-degree` apply).

use super::convert::{Args, Progress, check_output, write_output};
use splatgl::SplatCloud;
use splatgl::convert::{self, ConvertOptions, OutputFormat};
use splatgl::tiles::{BuildOptions, BuiltTile, PlySource, SplatSource, StreamOptions, TILES_DIR};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The kind of LOD tree an output asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum TreeOutput {
    /// A 3D Tiles 1.1 tileset (OUT ending in `.json`, e.g. `out/tileset.json`).
    Tiles3d,
    /// A streamed SOG (OUT named `lod-meta.json`).
    LodMeta,
}

/// The LOD tree OUT asks for, if any: `lod-meta.json` a streamed SOG, any other `.json` a 3D
/// Tiles tileset.
pub(super) fn tree_output(out: &Path) -> Option<TreeOutput> {
    let json = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    match (json, out.file_name().is_some_and(|n| n == "lod-meta.json")) {
        (true, true) => Some(TreeOutput::LodMeta),
        (true, false) => Some(TreeOutput::Tiles3d),
        _ => None,
    }
}

/// The options that mean nothing for a tileset.
pub(super) fn check_args(a: &Args) -> Result<(), String> {
    if a.camera.is_some() {
        return Err("--camera does not apply to tileset outputs".into());
    }
    if a.bucket_splats.is_some() && a.scratch_dir.is_none() {
        return Err("--bucket-splats applies with --scratch-dir only".into());
    }
    if a.chunk_splats.unwrap_or(BuildOptions::DEFAULT_CHUNK_SPLATS) < BuildOptions::MIN_CHUNK_SPLATS
    {
        return Err(format!(
            "--chunk-splats must be at least {}",
            BuildOptions::MIN_CHUNK_SPLATS
        ));
    }
    Ok(())
}

/// Writes each tile's `.glb` as the builder hands it over, counting files and bytes.
struct TileWriter<'a> {
    a: &'a Args,
    o: &'a ConvertOptions,
    p: &'a Progress,
    tiles: PathBuf,
    expected: usize,
    written: AtomicUsize,
    bytes: AtomicUsize,
    notes: Mutex<BTreeSet<String>>,
}

impl<'a> TileWriter<'a> {
    /// Creates `tiles/` beside OUT; `splats` sizes the progress bar.
    fn new(
        a: &'a Args,
        o: &'a ConvertOptions,
        p: &'a Progress,
        splats: u64,
    ) -> Result<Self, String> {
        let folder = match a.output.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => ".".into(),
        };
        let tiles = folder.join(TILES_DIR);
        std::fs::create_dir_all(&tiles).map_err(|e| format!("{}: {e}", tiles.display()))?;
        // A k-d tree of ⌈n / chunk⌉ leaves, rounded up to a power of two (median splits).
        let leaves = splats.div_ceil(chunk(a) as u64).max(1).next_power_of_two();
        let expected = (2 * leaves - 1) as usize;
        p.stage(&format!(
            "building a tileset of about {expected} tiles of at most {} splats",
            chunk(a)
        ));
        Ok(TileWriter {
            a,
            o,
            p,
            tiles,
            expected,
            written: AtomicUsize::new(0),
            bytes: AtomicUsize::new(0),
            notes: Mutex::new(BTreeSet::new()),
        })
    }

    fn write(&self, name: &str, c: &SplatCloud) -> Result<(), String> {
        let (glb, n) = convert::encode_with_cameras(c, OutputFormat::Glb, self.o, &[])?;
        let path = self.tiles.join(format!("{name}.glb"));
        write_output(&path, &self.a.input, &glb, true)?;
        self.notes
            .lock()
            .map_err(|_| "a tile writer failed")?
            .extend(n);
        self.bytes.fetch_add(glb.len(), Ordering::Relaxed);
        let done = self.written.fetch_add(1, Ordering::Relaxed) + 1;
        self.p
            .bar("writing tiles", done.min(self.expected), self.expected);
        Ok(())
    }

    /// Writes OUT (last, atomically: an interrupted build leaves no tileset.json) and says
    /// what was built.
    fn finish(self, root: &BuiltTile, splats: u64, t0: Instant) -> Result<(), String> {
        for n in self.notes.into_inner().unwrap_or_default() {
            eprintln!("note: {n}");
        }
        let uri = |name: &str| format!("{TILES_DIR}/{name}.glb");
        // SPZ rounds positions to its fixed point: the boxes keep one step of room.
        let margin = if self.o.spz_compress {
            let bits = splatgl::write::SpzWriteOptions::default().fractional_bits;
            1.0 / f64::from(1u32 << bits)
        } else {
            0.0
        };
        let doc = splatgl::tiles::tileset_json(
            root,
            &uri,
            &splatgl::tiles::content_extensions(self.o),
            margin,
        );
        let text = serde_json::to_vec_pretty(&doc).map_err(|e| e.to_string())?;
        let a = self.a;
        check_output(&a.output, &a.input, a.force)?;
        write_output(&a.output, &a.input, &text, a.force)?;
        let all = root.walk();
        let levels = all.iter().map(|t| t.name.len()).max().unwrap_or(1);
        eprintln!(
            "splatgl convert: {splats} splats -> {} ({} tiles in {levels} levels, {} bytes of \
             content in {}/; root: {} splats, geometric error {:.4}) in {:.1} s{}",
            a.output.display(),
            all.len(),
            self.bytes.load(Ordering::Relaxed),
            self.tiles.display(),
            root.splats,
            root.geometric_error,
            t0.elapsed().as_secs_f64(),
            super::progress::peak_memory_note()
        );
        Ok(())
    }
}

/// `--chunk-splats` or its default.
fn chunk(a: &Args) -> usize {
    a.chunk_splats.unwrap_or(BuildOptions::DEFAULT_CHUNK_SPLATS)
}

/// Builds the tree over `cloud` (already in the output's frame: glTF's +Y up for a tileset,
/// the PLY side's for a streamed SOG) in memory.
pub(super) fn write_tree(
    a: &Args,
    kind: TreeOutput,
    cloud: &SplatCloud,
    o: &ConvertOptions,
    p: &Progress,
    t0: Instant,
) -> Result<(), String> {
    if kind == TreeOutput::LodMeta {
        return super::convert_sog::write_lod_meta(a, cloud, p, t0, chunk(a));
    }
    let w = TileWriter::new(a, o, p, cloud.len() as u64)?;
    let opts = BuildOptions {
        chunk_splats: chunk(a),
    };
    let root = splatgl::tiles::build(cloud, &opts, &|n: &str, c: &SplatCloud| w.write(n, c))?;
    w.finish(&root, cloud.len() as u64, t0)
}

/// Builds the tree from a binary PLY read in passes, never whole (`--scratch-dir`).
pub(super) fn write_tileset_streamed(
    a: &Args,
    o: &ConvertOptions,
    scratch: &Path,
    t0: Instant,
) -> Result<(), String> {
    let mut src = PlySource::open(&a.input, &a.load.options(), o.clone(), a.crop)
        .map_err(|e| format!("--scratch-dir reads binary PLY in chunks: {e}"))?;
    let p = Progress::new(true);
    let w = TileWriter::new(a, o, &p, src.len())?;
    let opts = StreamOptions {
        chunk_splats: chunk(a),
        bucket_splats: a
            .bucket_splats
            .unwrap_or(StreamOptions::DEFAULT_BUCKET_SPLATS),
        scratch_dir: scratch.to_owned(),
    };
    let shown = |stage: &str, done: u64, total: u64| p.bar(stage, done as usize, total as usize);
    let (root, report) = splatgl::tiles::build_streamed(
        &mut src,
        &opts,
        &|n: &str, c: &SplatCloud| w.write(n, c),
        &shown,
    )?;
    for f in &src.rows.findings {
        eprintln!("warning: {}: {f}", a.input.display());
    }
    if src.dropped > 0 {
        eprintln!("--crop: dropped {} splats outside the box", src.dropped);
    }
    p.stage(&format!(
        "{} buckets (largest {} splats), {} bytes of scratch in {}",
        report.buckets,
        report.largest_bucket,
        report.scratch_bytes,
        scratch.display()
    ));
    if let (true, Some(r)) = (a.verbose, src.rotation) {
        eprintln!(
            "{}",
            super::convert::transform_note(r, Some(TreeOutput::Tiles3d))
        );
    }
    w.finish(&root, report.splats, t0)
}
