//! `splatgl convert IN out/tileset.json`: a level-of-detail 3D Tiles 1.1 tileset built by
//! [`splatgl::tiles::build`], each tile's content a `.glb` in `out/tiles/` encoded like any
//! `.glb` output (`--quantize`, `--spz-compress`, `--sh-degree` apply).

use super::convert::{Args, Progress, check_output, write_output};
use splatgl::SplatCloud;
use splatgl::convert::{self, ConvertOptions, OutputFormat};
use splatgl::tiles::BuildOptions;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The folder, next to the tileset, that holds the tiles' content.
const TILES_DIR: &str = "tiles";

/// Whether OUT asks for a tileset (a `.json` file); a streamed SOG `lod-meta.json` is an
/// error for now.
pub(super) fn is_tileset_output(out: &Path) -> Result<bool, String> {
    let json = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if json && out.file_name().is_some_and(|n| n == "lod-meta.json") {
        return Err(format!(
            "{}: writing streamed SOG (lod-meta.json) is not supported yet; write a 3D Tiles \
             tileset (e.g. out/tileset.json)",
            out.display()
        ));
    }
    Ok(json)
}

/// The options that mean nothing for a tileset.
pub(super) fn check_args(a: &Args) -> Result<(), String> {
    if a.camera.is_some() {
        return Err("--camera does not apply to tileset outputs".into());
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

/// The glTF extensions every tile's content uses (and requires), for `3DTILES_content_gltf`.
fn content_extensions(o: &ConvertOptions) -> Vec<&'static str> {
    let mut e = vec!["KHR_gaussian_splatting"];
    if o.spz_compress {
        e.push("KHR_gaussian_splatting_compression_spz_2");
    }
    if o.quantize.position != splatgl::write::Comp::F32 {
        e.push("KHR_mesh_quantization");
    }
    e
}

/// Builds the tree over `cloud` (already in glTF's +Y-up frame), writes each tile's `.glb`
/// into `tiles/` beside OUT, then OUT itself (last, atomically: an interrupted build leaves
/// no tileset.json).
pub(super) fn write_tileset(
    a: &Args,
    cloud: &SplatCloud,
    o: &ConvertOptions,
    p: &Progress,
    t0: Instant,
) -> Result<(), String> {
    let folder = match a.output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => ".".into(),
    };
    let tiles = folder.join(TILES_DIR);
    std::fs::create_dir_all(&tiles).map_err(|e| format!("{}: {e}", tiles.display()))?;
    let chunk = a.chunk_splats.unwrap_or(BuildOptions::DEFAULT_CHUNK_SPLATS);
    // A k-d tree with ⌈n / chunk⌉ leaves has about twice as many tiles.
    let expected = 2 * cloud.len().div_ceil(chunk) - 1;
    let written = AtomicUsize::new(0);
    let bytes = AtomicUsize::new(0);
    let notes = Mutex::new(BTreeSet::new());
    p.stage(&format!(
        "building a tileset of about {expected} tiles of at most {chunk} splats"
    ));
    let sink = |name: &str, c: &SplatCloud| -> Result<(), String> {
        let (glb, n) = convert::encode_with_cameras(c, OutputFormat::Glb, o, &[])?;
        let path = tiles.join(format!("{name}.glb"));
        write_output(&path, &a.input, &glb, true)?;
        notes.lock().map_err(|_| "a tile writer failed")?.extend(n);
        bytes.fetch_add(glb.len(), Ordering::Relaxed);
        let done = written.fetch_add(1, Ordering::Relaxed) + 1;
        p.bar("writing tiles", done.min(expected), expected);
        Ok(())
    };
    let opts = BuildOptions {
        chunk_splats: chunk,
    };
    let root = splatgl::tiles::build(cloud, &opts, &sink)?;
    for n in notes.into_inner().unwrap_or_default() {
        eprintln!("note: {n}");
    }
    let uri = |name: &str| format!("{TILES_DIR}/{name}.glb");
    // SPZ rounds positions to its fixed point: the boxes keep one step of room.
    let margin = if o.spz_compress {
        let bits = splatgl::write::SpzWriteOptions::default().fractional_bits;
        1.0 / f64::from(1u32 << bits)
    } else {
        0.0
    };
    let doc = splatgl::tiles::tileset_json(&root, &uri, &content_extensions(o), margin);
    let text = serde_json::to_vec_pretty(&doc).map_err(|e| e.to_string())?;
    check_output(&a.output, &a.input, a.force)?;
    write_output(&a.output, &a.input, &text, a.force)?;
    let all = root.walk();
    let levels = all.iter().map(|t| t.name.len()).max().unwrap_or(1);
    eprintln!(
        "splatgl convert: {} splats -> {} ({} tiles in {levels} levels, {} bytes of content in \
         {}/; root: {} splats, geometric error {:.4}) in {:.1} s",
        cloud.len(),
        a.output.display(),
        all.len(),
        bytes.load(Ordering::Relaxed),
        tiles.display(),
        root.splats,
        root.geometric_error,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
