//! `splatgl view`: the desktop viewer (feature `viewer`).

use std::path::PathBuf;
use std::process::ExitCode;

use super::camera_args::{CameraArgs, Pick, background};
use super::kernel::AntialiasArg;
use super::render::TargetArg;
use splatgl::camera::ViewOptions;

/// `--stale-bound`.
fn stale_bound(s: &str) -> Result<splatgl_viewer::StaleBound, String> {
    use splatgl_viewer::StaleBound;
    match s {
        "auto" => Ok(StaleBound::Auto),
        "strict" => Ok(StaleBound::Strict),
        _ => match s.parse::<f32>() {
            Ok(d) if d.is_finite() && d >= 0.0 => Ok(StaleBound::Distance(d)),
            _ => Err(format!(
                "expected auto, strict or a distance ≥ 0 in world units, got {s:?}"
            )),
        },
    }
}

/// `--resolution-scale`.
fn scale(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.1..=2.0).contains(&v) => Ok(v),
        _ => Err(format!("expected a number in 0.1..=2, got {s:?}")),
    }
}

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (.ply, .gltf, .glb, …), or a tileset (3D Tiles tileset.json, streamed SOG
    /// lod-meta.json; a path or an http(s) URL), streamed as the camera moves. Without it: the
    /// bundled default scene. More files can be
    /// dropped on the window or opened with O.
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub cam: CameraArgs,
    /// Start in fullscreen (F11 toggles).
    #[arg(long)]
    pub fullscreen: bool,
    /// Do not wait for the display's refresh (swap interval 0).
    #[arg(long)]
    pub no_vsync: bool,
    /// Render at this fraction of the window's pixels (0.1..=2), stretched to the window.
    #[arg(long, default_value = "1", value_parser = scale, value_name = "S")]
    pub resolution_scale: f32,
    /// Draw at most N splats: those with the largest opacity × (two largest scales), in
    /// file order (deterministic). Files may hold up to max(N, 33,554,432) splats (the
    /// loader's limit, which `info`, `render` and `convert` set with their --max-splats).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_splats: Option<u64>,
    /// Every frame waits for the sort of its own camera (screenshots, tests).
    #[arg(long)]
    pub sort_sync: bool,
    /// How far the camera may be from the eye of the order drawn: auto (the median splat
    /// size), strict (provably exact orders only) or a distance; beyond it a frame waits
    /// for the sort.
    #[arg(long, default_value = "auto", value_parser = stale_bound, value_name = "auto|strict|D")]
    pub stale_bound: splatgl_viewer::StaleBound,
    /// Framebuffer to blend in (rgba16f falls back to 8 bits where the context cannot render
    /// to it).
    #[arg(long, value_enum, default_value_t = TargetArg::Rgba16f)]
    pub target: TargetArg,
    /// SH degree to evaluate at start (keys 1-4 change it).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(0..=3))]
    pub sh_degree: u8,
    /// Background colour (display values, 0..1).
    #[arg(
        long,
        default_value = "0,0,0",
        value_name = "r,g,b",
        allow_hyphen_values = true
    )]
    pub background: String,
    /// Draw only the splats whose mean lies in this box (scene coordinates, both ends
    /// included; splat-transform's --filter-box order). The panel's crop box starts as this
    /// box and can be edited (numbers, or drag its faces).
    #[arg(long, value_name = "minx,miny,minz,maxx,maxy,maxz", value_parser = splatgl::cull::CropBox::parse, allow_hyphen_values = true)]
    pub crop: Option<splatgl::cull::CropBox>,
    /// The kernel: `auto` is antialiased when the file says it was trained so (SPZ flag 0x1).
    #[arg(long, value_enum, default_value_t = AntialiasArg::Auto)]
    pub antialiased: AntialiasArg,
    /// Start with the on-screen panel hidden (G shows and hides it).
    #[arg(long)]
    pub no_ui: bool,
    /// Render N frames (along one orbit with --orbit, else from the initial camera), print
    /// frame time min/median/p99, sort ms and the GL driver, and exit. The panel is not
    /// drawn in these frames (unless --bench-panel).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub bench_frames: Option<u32>,
    /// With --bench-frames: one full orbit around the initial pivot.
    #[arg(long, requires = "bench_frames")]
    pub orbit: bool,
    /// With --bench-frames: draw the panel in the measured frames too and report its CPU time
    /// per frame (layout, tessellation and GL calls).
    #[arg(long, requires = "bench_frames")]
    pub bench_panel: bool,
    /// Test hook (feature `testing`): deliver FILE as a dropped file once the first scene is
    /// shown.
    #[cfg(feature = "testing")]
    #[arg(long, hide = true, value_name = "FILE")]
    pub test_drop: Option<PathBuf>,
    #[command(flatten)]
    pub tiles: super::tileset::TileArgs,
    #[command(flatten)]
    pub load: super::LoadCommonArgs,
}

fn go(a: Args) -> Result<(), String> {
    let bg = background(&a.background)?;
    if a.cam.view == Some(Pick::All) || a.cam.gltf_camera == Some(Pick::All) {
        return Err(
            "--view all / --gltf-camera all render one image per view: use `splatgl render`".into(),
        );
    }
    let default = splatgl::load::Limits::DEFAULT_MAX_SPLATS;
    let load = a
        .load
        .options(a.max_splats.map_or(default, |n| n.max(default)));
    let opts = splatgl_viewer::ViewerOptions {
        file: a.scene,
        view: ViewOptions {
            limits: load.limits,
            ..a.cam.options()?
        },
        load,
        fullscreen: a.fullscreen,
        vsync: !a.no_vsync,
        resolution_scale: a.resolution_scale,
        max_splats: a.max_splats.map(|n| n as usize),
        sort_sync: a.sort_sync,
        stale: a.stale_bound,
        target: match a.target {
            TargetArg::Rgba8 => splatgl_viewer::TargetChoice::Rgba8,
            TargetArg::Rgba16f => splatgl_viewer::TargetChoice::Float,
        },
        sh_degree: a.sh_degree,
        background: bg,
        antialiased: a.antialiased.mode(),
        crop: a.crop,
        bench: a.bench_frames.map(|n| splatgl_viewer::Bench {
            frames: n as usize,
            orbit: a.orbit,
            panel: a.bench_panel,
        }),
        print_camera_json: a.cam.print_camera_json,
        no_ui: a.no_ui,
        tiles: a.tiles.settings(),
        #[cfg(feature = "testing")]
        test_drop: a.test_drop,
    };
    splatgl_viewer::run(opts).map_err(|e| e.to_string())
}

/// Runs it. Exit status 0 when the window is closed, 2 on errors.
pub fn run(a: Args) -> ExitCode {
    super::exit_status(go(a))
}
