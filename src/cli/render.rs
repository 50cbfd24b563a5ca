//! `splatgl render`: one image of a scene (or of the bundled default scene).

use super::camera_args::{camera_json_line, floats, look_at_line};
use splatgl::camera::{Camera, SceneView};
use splatgl::image::{Image, PngDepth};
use splatgl::load::Scene;
use splatgl::reference::{RenderOptions, SortMode};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Rendering backends.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// GL for 8-bit PNG output when a headless EGL context can be made here (else the
    /// reference, with a note); the reference for `.pfm`, `--depth16` and `--sort view-depth`,
    /// which need more than an 8-bit framebuffer or a distance sort.
    Auto,
    /// OpenGL ES 3 through headless EGL (Mesa surfaceless or a GPU driver).
    Gl,
    /// The CPU reference rasterizer (normative math, slow but exact).
    Reference,
}

/// GL framebuffer to blend in.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetArg {
    /// Blend in 8-bit RGBA (sRGB8_ALPHA8 for lin_rec709_display clouds).
    Rgba8,
    /// Blend in RGBA16F (the RC's recommendation), then resolve to 8 bits.
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
    /// Highest SH degree to evaluate (the file's degree caps it).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(0..=3))]
    pub sh_degree: u8,
    /// Background colour as it appears in the output image (display values, 0..1; for
    /// lin_rec709_display clouds it is decoded before blending so it comes out unchanged).
    #[arg(long, default_value = "0,0,0", value_name = "r,g,b")]
    pub background: String,
    /// Blending order.
    #[arg(long, value_enum, default_value_t = SortArg::Distance)]
    pub sort: SortArg,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// Framebuffer the GL backend blends in.
    #[arg(long, value_enum, default_value_t = TargetArg::Rgba8)]
    pub target: TargetArg,
    /// Output: .png (8-bit, or 16-bit with --depth16) or .pfm (32-bit float RGB).
    #[arg(short, long, default_value = "out.png")]
    pub output: PathBuf,
    /// Write a 16-bit PNG.
    #[arg(long)]
    pub depth16: bool,
    /// Keep alpha (1 − T): RGBA PNG; for .pfm also writes NAME.alpha.pfm.
    #[arg(long)]
    pub alpha: bool,
    #[command(flatten)]
    pub load: super::LoadArgs,
}

/// The view (see [`splatgl::camera::ViewOptions::camera`]) and the distance to print its
/// target at.
fn camera(a: &Args, scene: SceneView<'_>) -> Result<(Camera, f32), String> {
    let opts = a.cam.options()?;
    let cam = opts.camera(scene, (640, 480)).map_err(|e| e.to_string())?;
    Ok((cam, opts.focus_distance(&cam, scene.cloud)))
}

fn write(img: &Image, a: &Args) -> Result<(), String> {
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("");
    let r = match ext.to_ascii_lowercase().as_str() {
        "png" => {
            let depth = if a.depth16 {
                PngDepth::Sixteen
            } else {
                PngDepth::Eight
            };
            img.write_png(&a.output, depth, a.alpha)
        }
        "pfm" => img.write_pfm(&a.output).and_then(|()| {
            if a.alpha {
                img.write_pfm_alpha(a.output.with_extension("alpha.pfm"))
            } else {
                Ok(())
            }
        }),
        _ => {
            return Err(format!(
                "{}: output must end in .png or .pfm",
                a.output.display()
            ));
        }
    };
    r.map_err(|e| e.to_string())
}

fn go(a: &Args) -> Result<(), String> {
    let t0 = Instant::now();
    let (cloud, format, cameras) = match &a.scene {
        Some(p) => {
            let s = load(p, a.load.options())?;
            (s.cloud, Some(s.report.format), s.cameras)
        }
        None => (splatgl::scene::default_scene(), None, Vec::new()),
    };
    let scene = SceneView {
        cloud: &cloud,
        format,
        cameras: &cameras,
    };
    let (cam, distance) = camera(a, scene)?;
    // cameras.json sizes and derived sizes are bounded like the flags (an image is 16 bytes
    // per pixel in f32).
    if !(1..=16384).contains(&cam.width) || !(1..=16384).contains(&cam.height) {
        return Err(format!(
            "image size {}x{} is outside 1..=16384 per side; give --width/--height",
            cam.width, cam.height
        ));
    }
    let bg = floats(&a.background, "--background", &[3])?;
    let opts = RenderOptions {
        sh_degree: a.sh_degree,
        background: [bg[0], bg[1], bg[2]],
        sort: match a.sort {
            SortArg::Distance => SortMode::Distance,
            SortArg::ViewDepth => SortMode::ViewDepth,
        },
        ..Default::default()
    };
    let t1 = Instant::now();
    // Auto: GL unless the reference is the only backend that can honour the options (view-
    // depth sorting) or no GL context can be made here.
    let use_gl = match a.backend {
        Backend::Gl => true,
        Backend::Reference => false,
        Backend::Auto => {
            let exact_output = a.depth16
                || a.output
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("pfm"));
            a.sort == SortArg::Distance && !exact_output
        }
    };
    let gl = if use_gl {
        match render_gl(a, &cloud, &cam, &opts) {
            Ok(img) => Some(img),
            Err(e) if a.backend == Backend::Gl => return Err(format!("--backend gl: {e}")),
            Err(e) => {
                eprintln!("note: GL backend unavailable ({e}); using the reference rasterizer");
                None
            }
        }
    } else {
        None
    };
    let (img, backend, visible) = match gl {
        Some(img) => (img, "gl", None),
        None => {
            // As displayed (sRGB-encoded for lin_rec709_display): what the GL backend gives.
            let space = cloud.meta.color_space.effective();
            let (img, stats) = splatgl::reference::render_display(&cloud, &cam, &opts, space);
            (img, "reference", Some(stats.visible))
        }
    };
    let render_ms = t1.elapsed().as_secs_f64() * 1e3;
    write(&img, a)?;
    let visible = visible.map_or(String::new(), |v| format!(" ({v} visible)"));
    eprintln!("camera: {}", look_at_line(&cam, distance));
    if a.cam.print_camera_json {
        println!("{}", camera_json_line(&cam));
    }
    eprintln!(
        "splatgl render: {} splats{visible}, {}x{}, backend {backend}: render {render_ms:.1} ms, \
         total {:.1} ms -> {}",
        cloud.len(),
        cam.width,
        cam.height,
        t0.elapsed().as_secs_f64() * 1e3,
        a.output.display()
    );
    Ok(())
}

#[cfg(feature = "gl")]
fn render_gl(
    a: &Args,
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
    opts: &RenderOptions,
) -> Result<Image, String> {
    use splatgl::headless::{HeadlessOptions, TargetKind};
    if a.sort != SortArg::Distance {
        return Err("--sort view-depth is only implemented by --backend reference".into());
    }
    let o = HeadlessOptions {
        target: match a.target {
            TargetArg::Rgba8 => TargetKind::Rgba8,
            TargetArg::Rgba16f => TargetKind::Rgba16fResolve,
        },
        background: opts.background,
        sh_degree: Some(opts.sh_degree),
        color_space: None,
    };
    splatgl::headless::render(cloud, cam, &o).map_err(|e| e.to_string())
}

#[cfg(not(feature = "gl"))]
fn render_gl(
    _a: &Args,
    _cloud: &splatgl::SplatCloud,
    _cam: &Camera,
    _opts: &RenderOptions,
) -> Result<Image, String> {
    Err("this splatgl was built without the `gl` feature".into())
}

/// The scene file, parsed once (cloud and cameras); its findings go to stderr as warnings.
fn load(p: &Path, opts: splatgl::load::LoadOptions) -> Result<Scene, String> {
    let scene = splatgl::load::load_path(p, &opts).map_err(|e| e.to_string())?;
    for w in scene.report.summarized_warnings() {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// Runs it. Exit status 0 on success, 2 on any error.
pub fn run(a: Args) -> ExitCode {
    match go(&a) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
