//! `splatgl convert IN out/lod-meta.json`: the LOD tree of [`splatgl::tiles::build`] written
//! as a streamed SOG ([`splatgl::tiles::lod_meta_layout`]): `out/lod-meta.json` and one
//! unbundled SOG per unit (`out/{level}_{k}/meta.json` and its WebP textures).

use super::convert::{Args, Progress, check_output, write_output};
use rayon::prelude::*;
use splatgl::SplatCloud;
use splatgl::tiles::BuildOptions;
use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Builds the tree over `cloud` (in the PLY side's frame, as SOG holds it) with tiles of
/// `chunk` splats, and writes it with units of about `chunk` splats.
pub(super) fn write_lod_meta(
    a: &Args,
    cloud: &SplatCloud,
    p: &Progress,
    t0: Instant,
    chunk: usize,
) -> Result<(), String> {
    p.stage(&format!(
        "building a LOD tree of tiles of at most {chunk} splats"
    ));
    let contents = Mutex::new(HashMap::new());
    let opts = BuildOptions {
        chunk_splats: chunk,
    };
    let root = splatgl::tiles::build(cloud, &opts, &|n: &str, c: &SplatCloud| {
        contents
            .lock()
            .map_err(|_| "a tile builder failed")?
            .insert(n.to_owned(), c.clone());
        Ok(())
    })?;
    let contents = contents.into_inner().map_err(|_| "a tile builder failed")?;
    let layout = splatgl::tiles::lod_meta_layout(&root, &contents, chunk)?;
    drop(contents);
    let folder = match a.output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => ".".into(),
    };
    let (written, bytes) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let total = layout.units.len();
    layout
        .units
        .par_iter()
        .try_for_each(|(name, unit)| -> Result<(), String> {
            let dir = folder.join(name).parent().map(|d| d.to_path_buf());
            let dir = dir.ok_or_else(|| format!("{name}: no folder"))?;
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            for (file, data) in splatgl::write::to_sog_files(unit)? {
                write_output(&dir.join(&file), &a.input, &data, true)?;
                bytes.fetch_add(data.len(), Ordering::Relaxed);
            }
            let done = written.fetch_add(1, Ordering::Relaxed) + 1;
            p.bar("writing SOG units", done, total);
            Ok(())
        })?;
    // The manifest last, atomically: an interrupted build leaves no lod-meta.json.
    let text = serde_json::to_vec(&layout.manifest).map_err(|e| e.to_string())?;
    check_output(&a.output, &a.input, a.force)?;
    write_output(&a.output, &a.input, &text, a.force)?;
    let m = &layout.manifest;
    eprintln!(
        "splatgl convert: {} splats -> {} (streamed SOG: {} levels, {:?} splats per level, {} \
         units, {} bytes) in {:.1} s{}",
        cloud.len(),
        a.output.display(),
        m["lodLevels"],
        m["counts"].as_array().map_or(Vec::new(), |c| c
            .iter()
            .filter_map(serde_json::Value::as_u64)
            .collect()),
        total,
        bytes.load(Ordering::Relaxed),
        t0.elapsed().as_secs_f64(),
        super::progress::peak_memory_note()
    );
    Ok(())
}
