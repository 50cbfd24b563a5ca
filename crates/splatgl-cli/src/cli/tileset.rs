//! `info` and `validate` of a 3D Tiles tileset (`splatgl::tiles`): a `.json` file with
//! `asset` and `root`.
use splatgl::load::LoadOptions;
use splatgl::tiles::{SelectOptions, StreamSettings};
use std::path::Path;
use std::process::ExitCode;

/// `--cache-mb`'s default: 2 GB of resident tile content (about 36M splats at SH degree 0,
/// 8M at degree 3).
pub const DEFAULT_CACHE_MB: u64 = 2048;

/// The options of `render` and `view` that choose a tileset's tiles.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct TileArgs {
    /// For a tileset (3D Tiles or streamed SOG): draw at most N splats per view (the tiles
    /// are chosen by screen-space error, coarse to fine, within it).
    #[arg(long, value_name = "N", default_value_t = SelectOptions::DEFAULT_SPLAT_BUDGET)]
    pub splat_budget: u64,
    /// For a tileset: never refine a tile whose screen-space error is at or below PX pixels
    /// (a floor; above it the tiles with the largest error are refined first until the
    /// budget is spent).
    #[arg(long, value_name = "PX", default_value_t = SelectOptions::DEFAULT_MAX_SCREEN_ERROR)]
    pub max_screen_error: f64,
    /// For a tileset: keep at most about MB megabytes of tile content in memory across
    /// views, evicting the least recently used tiles (a view's own tiles stay).
    #[arg(long, value_name = "MB", default_value_t = DEFAULT_CACHE_MB)]
    pub cache_mb: u64,
}

impl TileArgs {
    /// As the library's streaming settings.
    pub fn settings(&self) -> StreamSettings {
        StreamSettings {
            select: SelectOptions {
                splat_budget: self.splat_budget,
                max_screen_error: self.max_screen_error,
            },
            cache_bytes: self.cache_mb.saturating_mul(1 << 20),
        }
    }
}

/// Whether `file` is a tileset: an http(s) URL, or a `.json` within the size limit whose
/// object has `asset` and `root` (anything else goes to the scene loaders, which name their
/// own errors).
pub fn is_tileset_file(file: &Path, opts: &LoadOptions) -> bool {
    // A URL is read as a tileset (the one kind of scene splatgl fetches); its errors say why.
    if file.to_str().is_some_and(splatgl::files::http::is_url) {
        return true;
    }
    let json = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    json && splatgl::files::read_bounded(file, opts.limits.max_bytes, "the file")
        .is_ok_and(|b| splatgl::tiles::is_tileset(&b))
}

/// The frame a tileset's coordinates (and a camera given for it) are in.
fn frame_name(ts: &splatgl::tiles::Tileset) -> &'static str {
    match ts.format {
        splatgl::tiles::TilesetFormat::Tiles3d => {
            "z-up (3D Tiles: glTF content turned +Y → +Z, then the tiles' transforms)"
        }
        splatgl::tiles::TilesetFormat::StreamedSog => "the content's own (streamed SOG)",
    }
}

/// A 4 × 4 matrix as `identity` or its rows, `[a b c d; …]`.
pub fn matrix_text(m: glam::DMat4) -> String {
    if m == glam::DMat4::IDENTITY {
        return "identity".into();
    }
    let rows: Vec<String> = (0..4)
        .map(|r| {
            let row = m.row(r);
            format!("{} {} {} {}", row.x, row.y, row.z, row.w)
        })
        .collect();
    format!("[{}]", rows.join("; "))
}

/// `info` of a tileset: per level the tiles, content files, splats and largest geometric
/// error, and the root's bounding sphere. Exit status 0, or 2 when it cannot be read.
pub fn info(a: &super::FileArgs, opts: &LoadOptions) -> ExitCode {
    let t = splatgl::tiles::check(&a.file, opts, true);
    let Some(ts) = &t.tileset else {
        for line in t.report.summarized() {
            eprintln!("{}", splatgl::load::printable(&line));
        }
        return ExitCode::from(2);
    };
    let sphere = ts.root.bounds.map(|b| b.sphere());
    let levels: Vec<serde_json::Value> = t
        .levels
        .iter()
        .map(|l| {
            serde_json::json!({
                "level": l.level, "tiles": l.tiles, "contents": l.contents,
                "splats": l.splats, "geometric_error": l.geometric_error,
            })
        })
        .collect();
    let problems = t.report.summarized();
    let json = serde_json::json!({
        "file": a.file.display().to_string(),
        "format": ts.format.name(),
        "version": ts.version,
        "tiles": t.levels.iter().map(|l| l.tiles).sum::<usize>(),
        "levels": levels,
        "splat_count": t.report.splat_count,
        "bounds_centre": sphere.map(|s| s.0.to_array()),
        "bounds_radius": sphere.map(|s| s.1),
        "frame": frame_name(ts),
        "root_transform": ts.root.transform.to_cols_array(),
        "problems": problems,
    });
    if a.json {
        println!("{json:#}");
        return ExitCode::SUCCESS;
    }
    println!("file:           {}", a.file.display());
    match ts.format {
        splatgl::tiles::TilesetFormat::Tiles3d => {
            println!("format:         3D Tiles {} tileset", ts.version)
        }
        splatgl::tiles::TilesetFormat::StreamedSog => {
            println!(
                "format:         streamed SOG (lod-meta.json) version {}",
                ts.version
            )
        }
    }
    println!("tiles:          {}", json["tiles"]);
    println!("splats:         {}", t.report.splat_count.unwrap_or(0));
    if let Some((c, r)) = sphere {
        println!(
            "bounds:         sphere ({:.3}, {:.3}, {:.3}) r {r:.3}",
            c.x, c.y, c.z
        );
    }
    println!("frame:          {}", frame_name(ts));
    println!("root transform: {}", matrix_text(ts.root.transform));
    println!("levels:");
    for l in &t.levels {
        println!(
            "  {:>2}: {:>6} tiles, {:>6} contents, {:>10} splats, geometric error ≤ {}",
            l.level, l.tiles, l.contents, l.splats, l.geometric_error
        );
    }
    if !a.quiet {
        for p in problems {
            println!("warning: {p}");
        }
    }
    ExitCode::SUCCESS
}
