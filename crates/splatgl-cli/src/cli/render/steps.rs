//! The steps of [`super::go`], the `render` command's main path: the scene, the size check,
//! the render options, the render loop with its camera lines, the summary's target.

use super::super::camera_args::{camera_json_line, look_at_line};
use super::super::progress::Progress;
use super::super::render_out::Outputs;
use super::super::tileset::is_tileset_file;
use super::{Args, SortArg, load};
use splatgl::SplatCloud;
use splatgl::camera::{Camera, GltfPerspective};
use splatgl::engine::Engine;
use splatgl::load::Format;
use splatgl::reference::{RenderOptions, SortMode};
use std::path::Path;
use std::time::{Duration, Instant};

/// The scene to render (the file's cloud, format and camera nodes, or the bundled default
/// scene), with the load options checked against its format.
pub(super) fn load_scene(a: &Args, progress: Progress) -> Result<LoadedScene, String> {
    let opts = a.load.options();
    if let Some(p) = a.scene.as_deref().filter(|p| is_tileset_file(p, &opts)) {
        return load_tileset(a, p, &opts);
    }
    tiles_only_options(a)?;
    let (cloud, format, cameras, trained_antialiased) = match &a.scene {
        Some(p) => {
            progress.stage(&format!("loading {}", p.display()));
            let s = load(p, a, progress)?;
            let trained = s.report.trained_antialiased();
            (s.cloud, Some(s.report.format), s.cameras, trained)
        }
        None => (splatgl::synthetic::default_scene(), None, Vec::new(), false),
    };
    let file = a
        .scene
        .as_ref()
        .map_or(String::new(), |p| p.display().to_string());
    a.load.common.check_applies(&file, format)?;
    let cloud = match a.crop.and_then(|b| b.apply(&cloud)) {
        Some(c) if c.is_empty() => {
            return Err(format!(
                "--crop: none of the {} splats is inside the box",
                cloud.len()
            ));
        }
        Some(c) => c,
        None => cloud,
    };
    Ok(LoadedScene {
        cloud,
        format,
        cameras,
        trained_antialiased,
        tileset: None,
    })
}

/// The scene `render` draws: the file's splats (inside `--crop`), format and cameras.
pub(super) struct LoadedScene {
    /// The splats inside the crop box.
    pub(super) cloud: SplatCloud,
    /// The file's format (`None`: the default scene).
    pub(super) format: Option<Format>,
    /// The file's glTF cameras.
    pub(super) cameras: Vec<GltfPerspective>,
    /// The file's SPZ antialiasing flag (`--antialiased auto`).
    pub(super) trained_antialiased: bool,
    /// A 3D Tiles tileset: each view draws the tiles chosen for it; `cloud` is then its
    /// coarsest level with content, for framing.
    pub(super) tileset: Option<splatgl::tiles::Tileset>,
}

/// `--splat-budget` and `--max-screen-error` choose tiles: an error for any other scene.
fn tiles_only_options(a: &Args) -> Result<(), String> {
    let d = splatgl::tiles::SelectOptions::default();
    let given = [
        ("--splat-budget", a.tiles.splat_budget != d.splat_budget),
        (
            "--max-screen-error",
            a.tiles.max_screen_error != d.max_screen_error,
        ),
        (
            "--cache-mb",
            a.tiles.cache_mb != super::super::tileset::DEFAULT_CACHE_MB,
        ),
        ("--max-wait", a.max_wait.is_some()),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((flag, _)) => Err(format!("{flag} applies to 3D Tiles tilesets only")),
        None => Ok(()),
    }
}

/// A tileset: read, and its coarsest level with content loaded for framing the views (each
/// view then draws its own selection, [`render_tileset_views`]).
fn load_tileset(
    a: &Args,
    p: &Path,
    opts: &splatgl::load::LoadOptions,
) -> Result<LoadedScene, String> {
    if a.crop.is_some() {
        return Err("--crop does not apply to tilesets yet".into());
    }
    let ts = splatgl::tiles::read(p, opts)?;
    if !a.quiet {
        for pr in &ts.problems {
            let line = format!("{}: {}: {}", p.display(), pr.path, pr.message);
            eprintln!("warning: {}", splatgl::load::printable(&line));
        }
    }
    let mut cache = splatgl::tiles::TileCache::new(&ts, opts);
    if ts.coarsest().is_empty() {
        return Err(format!("{}: no tile has content", p.display()));
    }
    // The coarsest content on every path; where it does not load, the tiles below it.
    let coarse = splatgl::tiles::coarse_cover(&ts, &mut cache);
    let cloud = cache.merged(&coarse);
    warn_skipped(a, &mut cache);
    if cloud.is_empty() {
        return Err(format!(
            "{}: the coarsest tiles hold no splats",
            p.display()
        ));
    }
    drop(cache);
    let format = match ts.format {
        splatgl::tiles::TilesetFormat::Tiles3d => Format::Glb,
        splatgl::tiles::TilesetFormat::StreamedSog => Format::Sog,
    };
    Ok(LoadedScene {
        cloud,
        format: Some(format),
        cameras: Vec::new(),
        trained_antialiased: false,
        tileset: Some(ts),
    })
}

/// Prints (once) the content files the cache skipped.
fn warn_skipped(a: &Args, cache: &mut splatgl::tiles::TileCache<'_>) {
    if !a.quiet {
        for w in cache.warnings.drain(..) {
            eprintln!("warning: {w}");
        }
    }
}

/// The selection for `cam` as far as it loads within `wait` (`--max-wait`): the coarsest
/// content first, then the tiles selection wants, a batch at a time, until none is missing or
/// the time is up (then a warning says how many were left).
fn select_within<'t>(
    a: &Args,
    ts: &'t splatgl::tiles::Tileset,
    cam: &Camera,
    select: &splatgl::tiles::SelectOptions,
    cache: &mut splatgl::tiles::TileCache<'_>,
    wait: Duration,
) -> Result<splatgl::tiles::Selection<'t>, String> {
    let deadline = Instant::now() + wait;
    splatgl::tiles::coarse_cover(ts, cache);
    loop {
        let (sel, wanted) = splatgl::tiles::select_resident(ts, cam, select, cache)?;
        if wanted.is_empty() {
            return Ok(sel);
        }
        if Instant::now() >= deadline {
            if !a.quiet {
                eprintln!(
                    "warning: --max-wait {}: {} tiles of this view's selection had not loaded; \
                     drawn with the coarser tiles that had",
                    wait.as_secs_f64(),
                    wanted.len()
                );
            }
            return Ok(sel);
        }
        cache.load_all(&wanted[..wanted.len().min(splatgl::tiles::LOAD_BATCH)]);
    }
}

/// [`render_views`] for a tileset: per view, the tiles chosen by screen-space error within
/// `--splat-budget`, their content uploaded and drawn. Returns the last view's visible count
/// and its selected splats.
pub(super) fn render_tileset_views(
    a: &Args,
    out: &Outputs,
    engine: &mut Engine,
    ts: &splatgl::tiles::Tileset,
    views: &[(Camera, f32)],
    opts: &RenderOptions,
    progress: Progress,
) -> Result<(Option<usize>, usize), String> {
    let select = splatgl::tiles::SelectOptions {
        splat_budget: a.tiles.splat_budget,
        max_screen_error: a.tiles.max_screen_error,
    };
    let mut cache = splatgl::tiles::TileCache::with_max_bytes(
        ts,
        &a.load.options(),
        a.tiles.cache_mb.saturating_mul(1 << 20),
    );
    let (mut visible, mut drawn) = (None, 0);
    let mut entries = Vec::new();
    // The selection uploaded last (tile paths) and its cloud: a view that selects the same
    // tiles (an orbit at one distance, say) draws what is on the GPU already.
    let (mut uploaded, mut cloud): (Vec<String>, SplatCloud) = (Vec::new(), SplatCloud::default());
    for (i, (cam, distance)) in views.iter().enumerate() {
        progress.step("selecting tiles", i, views.len());
        cache.next_frame();
        let sel = match a.max_wait {
            None => splatgl::tiles::select(ts, cam, &select, &mut |t| cache.splats(t))?,
            Some(s) => select_within(a, ts, cam, &select, &mut cache, Duration::from_secs_f64(s))?,
        };
        let paths: Vec<String> = sel.tiles.iter().map(|t| t.path.clone()).collect();
        let same = i > 0 && paths == uploaded;
        if !same {
            cloud = cache.merged(&sel.tiles);
        }
        progress.clear();
        warn_skipped(a, &mut cache);
        if a.verbose {
            eprintln!(
                "tiles: {} selected, {} splats (budget {}), {} held back by the budget{}; cache: {} \
                 tiles, {} MB resident, {} loads, {} evicted, {} more skipped as warned",
                sel.tiles.len(),
                cloud.len(),
                select.splat_budget,
                sel.held_back,
                if same {
                    ", the previous view's selection (not uploaded again)"
                } else {
                    ""
                },
                cache.resident_tiles(),
                cache.resident_bytes().div_ceil(1 << 20),
                cache.loads,
                cache.evictions,
                cache.skipped_alike
            );
        }
        if !same {
            engine.upload(&cloud)?;
            uploaded = paths;
        }
        progress.stage("rendering");
        let (img, v) = engine.render(&cloud, cam, opts)?;
        (visible, drawn) = (v, cloud.len());
        out.write(&img, i)?;
        progress.clear();
        report_view(a, out, i, cam, *distance, &mut entries);
    }
    if a.batch() && a.cam.print_camera_json {
        println!("{}", serde_json::Value::Array(entries));
    }
    Ok((visible, drawn))
}

/// Refuses views whose image size is outside `1..=16384` per side
/// ([`splatgl::camera::MAX_IMAGE_SIDE`]).
pub(super) fn check_image_sizes(views: &[(Camera, f32)]) -> Result<(), String> {
    for (cam, _) in views {
        // cameras.json sizes and derived sizes are bounded like the flags (an image is 16
        // bytes per pixel in f32).
        splatgl::camera::check_image_size(cam.width, cam.height)
            .map_err(|e| format!("{e}; give --width/--height"))?;
    }
    Ok(())
}

/// The reference's render options from the flags and the parsed background.
pub(super) fn render_options(a: &Args, bg: [f32; 3], trained_antialiased: bool) -> RenderOptions {
    RenderOptions {
        sh_degree: a.sh_degree,
        antialiased: a.antialiased.mode().resolve(trained_antialiased),
        background: bg,
        sort: match a.sort {
            SortArg::Distance => SortMode::Distance,
            SortArg::ViewDepth => SortMode::ViewDepth,
        },
        ..Default::default()
    }
}

/// Renders and writes every view with its progress and camera lines (a batch's cameras.json
/// printed at the end); returns the last image's visible count.
pub(super) fn render_views(
    a: &Args,
    out: &Outputs,
    engine: &mut Engine,
    cloud: &SplatCloud,
    views: &[(Camera, f32)],
    opts: &RenderOptions,
    progress: Progress,
) -> Result<Option<usize>, String> {
    let batch = a.batch();
    let mut visible = None;
    let mut entries = Vec::new();
    for (i, (cam, distance)) in views.iter().enumerate() {
        if batch {
            progress.step("rendering", i, views.len());
        } else {
            progress.stage("rendering");
        }
        let (img, v) = engine.render(cloud, cam, opts)?;
        visible = v;
        out.write(&img, i)?;
        progress.clear();
        report_view(a, out, i, cam, *distance, &mut entries);
    }
    if batch {
        progress.step("rendering", views.len(), views.len());
        progress.clear();
        if a.cam.print_camera_json {
            // One cameras.json for the batch: `--camera` on it with `--view all` renders it again.
            println!("{}", serde_json::Value::Array(entries));
        }
    }
    Ok(visible)
}

/// View `i`'s camera line, and its `--print-camera-json` line (one image) or cameras.json
/// entry (a batch, pushed to `entries`).
fn report_view(
    a: &Args,
    out: &Outputs,
    i: usize,
    cam: &Camera,
    distance: f32,
    entries: &mut Vec<serde_json::Value>,
) {
    let batch = a.batch();
    let index = if batch {
        format!("[{i}] ")
    } else {
        String::new()
    };
    a.say(format!("camera: {index}{}", look_at_line(cam, distance)));
    if a.cam.print_camera_json && !batch {
        println!("{}", camera_json_line(cam));
    } else if a.cam.print_camera_json {
        let name = out
            .path(i)
            .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()));
        entries.push(cam.to_3dgs_json(i as i64, &name.unwrap_or_default()));
    }
}

/// Where the summary says the images went: the one output, or a batch's count and range.
pub(super) fn describe_target(out: &Outputs, n: usize, batch: bool) -> String {
    if batch {
        format!(
            "{} images -> {} .. {}",
            n,
            out.describe(0),
            out.describe(n - 1)
        )
    } else {
        out.describe(0)
    }
}
