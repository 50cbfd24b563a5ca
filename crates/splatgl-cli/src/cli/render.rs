//! `splatgl render`: one image of a scene (or of the bundled default scene).

mod steps;

use super::camera_args::{Pick, background};
use super::progress::Progress;
use super::render_backend::Wanted;
use super::render_out::{Kind, Outputs};
use splatgl::camera::{Camera, SceneView};
use splatgl::load::Scene;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use steps::{check_image_sizes, describe_target, load_scene, render_options, render_views};

/// Rendering backends.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// GL when the headless EGL context is a hardware driver; the reference when it is a
    /// software rasterizer (llvmpipe, softpipe, SwiftShader), when no context can be made, and
    /// for `.pfm`, `--depth16` and `--sort view-depth` (more than 8 bits, a view-depth sort).
    /// `-v` says which and why.
    Auto,
    /// OpenGL ES 3 through headless EGL (Mesa surfaceless or a GPU driver); 8-bit output
    /// only (.pfm and --depth16 are refused rather than quantized).
    Gl,
    /// The CPU reference rasterizer (normative math, slow but exact).
    Reference,
}

/// GL framebuffer to blend in.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetArg {
    /// Blend in 8-bit RGBA (sRGB8_ALPHA8 for lin_rec709_display clouds): colours above 1 are
    /// clamped per splat.
    Rgba8,
    /// Blend in RGBA16F (the RC's recommendation; the default where the context can render
    /// to it), then resolve to 8 bits.
    Rgba16f,
}

/// Blending order.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortArg {
    /// Euclidean distance camera → mean (the RC's `cameraDistance`).
    Distance,
    /// Camera-space depth (original 3DGS).
    ViewDepth,
}

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (.ply, .gltf, .glb, .spz, .splat, .ksplat, .sog, SOG meta.json). Without it:
    /// the bundled default scene.
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub cam: super::camera_args::CameraArgs,
    /// Highest SH degree to evaluate, 0..=3 (the file's degree caps it).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(0..=3))]
    pub sh_degree: u8,
    /// The kernel: `auto` is antialiased when the file says it was trained so (SPZ flag 0x1);
    /// `on` scales each opacity by √(det Σ' / det(Σ' + 0.3 I)) (docs/rendering-profile.md).
    #[arg(long, value_enum, default_value_t = super::kernel::AntialiasArg::Auto)]
    pub antialiased: super::kernel::AntialiasArg,
    /// Draw only the splats whose mean lies in this box (scene coordinates, both ends
    /// included; splat-transform's --filter-box order). The default view frames what is left.
    #[arg(long, value_name = "minx,miny,minz,maxx,maxy,maxz", value_parser = splatgl::cull::CropBox::parse, allow_hyphen_values = true)]
    pub crop: Option<splatgl::cull::CropBox>,
    /// Background colour as it appears in the output image (display values in [0, 1]; for
    /// lin_rec709_display clouds it is decoded before blending so it comes out unchanged).
    #[arg(
        long,
        default_value = "0,0,0",
        value_name = "r,g,b",
        allow_hyphen_values = true
    )]
    pub background: String,
    /// Blending order.
    #[arg(long, value_enum, default_value_t = SortArg::Distance)]
    pub sort: SortArg,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// Framebuffer the GL backend blends in (default: rgba16f where the GL context can render
    /// to it, else rgba8 with a warning; asks auto for GL; an error with --backend reference).
    #[arg(long, value_enum)]
    pub target: Option<TargetArg>,
    /// Output: .png (8-bit, or 16-bit with --depth16), .pfm (32-bit float RGB) or - (PNG on
    /// stdout). Default out.png; for a batch (--view all, --gltf-camera all, --orbit) the
    /// name must hold {index}, default out_{index}.png.
    #[arg(short, long, value_name = "FILE", allow_hyphen_values = true)]
    pub output: Option<PathBuf>,
    /// Overwrite output files that exist.
    #[arg(short, long)]
    pub force: bool,
    /// Write a 16-bit PNG (reference backend).
    #[arg(long)]
    pub depth16: bool,
    /// Keep alpha (1 − T): RGBA PNG; for .pfm also writes NAME.alpha.pfm.
    #[arg(long)]
    pub alpha: bool,
    /// Render N frames on a circle around the framing pivot (the focus of the view: the
    /// content's centre, or the --look-at target), about the --up axis, frame 0 the view
    /// itself; writes -o's {index} pattern.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=3600))]
    #[arg(conflicts_with_all = ["camera", "gltf_camera"])]
    pub orbit: Option<u32>,
    /// Print only errors (no camera line, summary, warnings or progress).
    #[arg(short, long, conflicts_with_all = ["verbose", "progress"])]
    pub quiet: bool,
    /// Also say which backend was chosen and why.
    #[arg(short, long)]
    pub verbose: bool,
    /// Show progress even when stderr is not a terminal (one line per step).
    #[arg(long)]
    pub progress: bool,
    #[command(flatten)]
    pub tiles: super::tileset::TileArgs,
    /// For a tileset: wait at most S seconds per view for the tiles its selection wants, then
    /// draw what has loaded (coarser tiles where finer ones are still missing) and warn.
    /// Without it each view waits until its selection is complete.
    #[arg(long, value_name = "S", value_parser = parse_seconds)]
    pub max_wait: Option<f64>,
    #[command(flatten)]
    pub load: super::LoadArgs,
}

/// A number of seconds ≥ 0.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a number of seconds ≥ 0")),
    }
}

impl Args {
    /// The files read: the scene and the cameras.json (never written over).
    fn inputs(&self) -> Vec<&Path> {
        self.scene
            .iter()
            .chain(&self.cam.camera)
            .map(PathBuf::as_path)
            .collect()
    }

    /// Prints `s` to stderr unless `--quiet`.
    fn say(&self, s: String) {
        if !self.quiet {
            eprintln!("{s}");
        }
    }

    fn batch(&self) -> bool {
        self.orbit.is_some()
            || self.cam.view == Some(Pick::All)
            || self.cam.gltf_camera == Some(Pick::All)
    }

    fn wanted(&self, kind: Kind) -> Wanted {
        Wanted {
            backend: self.backend,
            target: self.target,
            float_output: kind == Kind::Pfm || self.depth16,
            view_depth: self.sort == SortArg::ViewDepth,
        }
    }

    /// The options that do not apply to the chosen view source, found before loading.
    fn check_camera_options(&self) -> Result<(), String> {
        let given = if self.cam.camera.is_some() {
            Some("--camera")
        } else if self.cam.gltf_camera.is_some() {
            Some("--gltf-camera")
        } else {
            None
        };
        if let Some(src) = given {
            if self.cam.up != super::camera_args::UpArg::Auto {
                return Err(format!(
                    "--up applies to automatic framing and --look-at; {src} gives the whole view"
                ));
            }
            if self.cam.fov.is_some() {
                return Err(format!(
                    "--fov applies to automatic framing and --look-at; {src} gives the field of view"
                ));
            }
        }
        let auto_up = self.cam.up == super::camera_args::UpArg::Auto;
        let look_at_up = (self.cam.look_at.as_deref()).is_some_and(|l| l.split(',').count() == 9);
        if !auto_up && look_at_up {
            return Err(
                "--up has no effect: --look-at gives its own up vector (its last three values)"
                    .into(),
            );
        }
        if self.scene.is_none()
            && given.is_none()
            && self.cam.look_at.is_none()
            && auto_up
            && let Some(fov) = self.cam.fov
        {
            return Err(format!(
                "--fov {fov}: the bundled default scene has a fixed camera (40°); give --look-at, or --up to frame it automatically"
            ));
        }
        Ok(())
    }
}

/// The views to render, each with the distance to print its target at.
fn views(
    a: &Args,
    scene: SceneView<'_>,
    up: Option<splatgl::camera::UpAxis>,
) -> Result<Vec<(Camera, f32)>, String> {
    let mut opts = splatgl::camera::ViewOptions {
        limits: a.load.options().limits,
        ..a.cam.options()?
    };
    opts.up = opts.up.or(up);
    // One extent for every view of a batch (it walks the whole cloud).
    let extent = opts.focus_extent(scene.cloud);
    let focus = |cam: Camera| (cam, opts.focus_distance_in(&cam, extent.as_ref()));
    let one = |o: &splatgl::camera::ViewOptions| -> Result<(Camera, f32), String> {
        o.camera(scene, (640, 480))
            .map(focus)
            .map_err(|e| e.to_string())
    };
    if a.cam.view == Some(Pick::All) {
        // The cameras.json is read and parsed once, however many views it holds.
        let entries = opts.cameras_json_entries().map_err(|e| e.to_string())?;
        let file = a.cam.camera.as_deref().unwrap_or(Path::new("cameras.json"));
        if entries.is_empty() {
            return Err(format!("--view all: {} has no views", file.display()));
        }
        return entries
            .iter()
            .enumerate()
            .map(|(i, e)| {
                opts.camera_for_entry(e)
                    .map(focus)
                    .map_err(|err| format!("--view all: {} view {i}: {err}", file.display()))
            })
            .collect();
    }
    if a.cam.gltf_camera == Some(Pick::All) {
        if scene.cameras.is_empty() {
            return Err("--gltf-camera all: the scene has no perspective camera nodes".into());
        }
        return (0..scene.cameras.len())
            .map(|i| {
                let o = splatgl::camera::ViewOptions {
                    gltf_camera: Some(i),
                    ..opts.clone()
                };
                one(&o).map_err(|err| format!("--gltf-camera all: camera {i}: {err}"))
            })
            .collect();
    }
    let (cam, distance) = one(&opts)?;
    let Some(n) = a.orbit else {
        return Ok(vec![(cam, distance)]);
    };
    let up = opts
        .look_at
        .and_then(|l| l.up)
        .unwrap_or_else(|| opts.up_for_scene(scene).vector())
        .normalize();
    Ok(orbit(&cam, distance, up, n))
}

/// `n` cameras on a circle around `cam`'s focus (`distance` ahead of its eye), about `up`,
/// the first `cam` itself; intrinsics unchanged.
pub fn orbit(cam: &Camera, distance: f32, up: glam::Vec3, n: u32) -> Vec<(Camera, f32)> {
    let c2w = cam.world_to_camera.inverse();
    let pivot = cam.eye() + c2w.transform_vector3(glam::Vec3::Z) * distance;
    (0..n)
        .map(|k| {
            let angle = std::f32::consts::TAU * k as f32 / n as f32;
            // Moving the world by the inverse rotation about the pivot turns the camera.
            let turn = glam::Mat4::from_translation(pivot)
                * glam::Mat4::from_axis_angle(up, angle)
                * glam::Mat4::from_translation(-pivot);
            let mut c = *cam;
            c.world_to_camera = cam.world_to_camera * turn.inverse();
            (c, distance)
        })
        .collect()
}

/// Everything that can be checked without the scene, before it is loaded: the outputs, the
/// backend's options, the view options, the background.
fn preflight(a: &Args) -> Result<(Outputs, Wanted, [f32; 3]), String> {
    let out = Outputs::plan(
        a.output.as_deref(),
        a.batch(),
        a.depth16,
        a.alpha,
        a.cam.print_camera_json,
    )?;
    let wanted = a.wanted(out.kind);
    wanted.check()?;
    a.check_camera_options()?;
    if a.scene.is_none() {
        // The default scene's format is known before anything is loaded.
        a.load.common.check_applies("", None)?;
    }
    let bg = background(&a.background)?;
    let _ = a.cam.options()?; // --look-at syntax
    // An orbit's image count is known now; a --view / --gltf-camera batch's after loading.
    out.check_files(a.orbit.map_or(1, |n| n as usize), &a.inputs(), a.force)?;
    Ok((out, wanted, bg))
}

/// The `render` command: preflight, load, frame the views, render and write each, then the
/// summary line.
fn go(a: &Args) -> Result<(), String> {
    let t0 = Instant::now();
    let batch = a.batch();
    let (out, wanted, bg) = preflight(a)?;
    let inputs = a.inputs();
    let progress = Progress::new(a.quiet, a.progress);
    let loaded = load_scene(a, progress)?;
    let cloud = loaded.cloud;
    let scene = SceneView {
        cloud: &cloud,
        format: loaded.format,
        cameras: &loaded.cameras,
    };
    let views = views(a, scene, loaded.tileset.as_ref().and_then(|t| t.up()))?;
    check_image_sizes(&views)?;
    out.check_files(views.len(), &inputs, a.force)?;
    let opts = render_options(a, bg, loaded.trained_antialiased);
    let t1 = Instant::now();
    let (mut engine, why) = wanted.engine(&cloud, &opts)?;
    if let Some(w) = engine.fallback() {
        eprintln!("warning: {w}");
    }
    if a.verbose {
        eprintln!("backend: {} ({why})", engine.name());
        let kernel = if opts.antialiased {
            "antialiased"
        } else {
            "plain"
        };
        eprintln!("kernel: {kernel} (--antialiased {:?})", a.antialiased);
    }
    let (visible, drawn) = match &loaded.tileset {
        Some(ts) => steps::render_tileset_views(a, &out, &mut engine, ts, &views, &opts, progress)?,
        None => (
            render_views(a, &out, &mut engine, &cloud, &views, &opts, progress)?,
            cloud.len(),
        ),
    };
    let render_ms = t1.elapsed().as_secs_f64() * 1e3;
    let visible = match (visible, batch) {
        (Some(v), false) => format!(" ({v} visible)"),
        _ => String::new(),
    };
    let (w, h) = (views[0].0.width, views[0].0.height);
    let target = describe_target(&out, views.len(), batch);
    a.say(format!(
        "splatgl render: {} splats{visible}, {w}x{h}, backend {}: render {render_ms:.1} ms, \
         total {:.1} ms -> {target}",
        drawn,
        engine.name(),
        t0.elapsed().as_secs_f64() * 1e3,
    ));
    if a.verbose
        && let Some(b) = super::progress::peak_memory()
    {
        eprintln!("peak memory: {} MB", b.div_ceil(1 << 20));
    }
    Ok(())
}

/// The scene file, parsed once (cloud and cameras); its findings go to stderr as warnings
/// (notes with `-v`).
/// Loads the scene and prints its warnings (notes with `-v`), the progress line cleared
/// first, also on an error.
fn load(p: &Path, a: &Args, progress: Progress) -> Result<Scene, String> {
    let scene = splatgl::load::load_path(p, &a.load.options());
    progress.clear();
    let scene = scene.map_err(|e| e.to_string())?;
    if !a.quiet {
        for w in scene.report.summarized_warnings() {
            eprintln!("warning: {w}");
        }
        if a.verbose {
            for n in scene.report.summarized_notes() {
                eprintln!("note: {n}");
            }
        }
    }
    Ok(scene)
}

/// Runs it. Exit status 0 on success, 2 on any error.
pub fn run(a: Args) -> ExitCode {
    super::exit_status(go(&a))
}
