//! `splatgl conformance generate DIR` and `splatgl conformance run DIR (--images OTHER |
//! --backend gl|reference)`.

use splatgl::image::Image;
use splatgl_conformance::manifest::Manifest;
use splatgl_conformance::render::{Backend, render_suite};
use splatgl_conformance::runner::AssetResult;
use splatgl_conformance::{generate, report, runner};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Write the suite into DIR: manifest.json, assets/NAME.glb (with camera nodes) and
    /// NAME.cameras.json, reference/NAME/CAMERA.png (8-bit sRGB) and .pfm (float).
    /// Exit status: 0, or 2 on any error.
    Generate {
        /// The folder (created if needed).
        dir: PathBuf,
    },
    /// Compare images with the suite's references; write report.html and report.json.
    /// Exit status: 0 all pass, 1 some fail, 2 unusable input.
    Run(RunArgs),
}

/// Which images to check.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendArg {
    /// splatgl's GL backend (headless EGL).
    Gl,
    /// splatgl's CPU reference rasterizer.
    Reference,
}

/// Arguments of `run`.
#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["images", "backend"])))]
pub struct RunArgs {
    /// The suite folder (with manifest.json).
    pub dir: PathBuf,
    /// Another renderer's images: OTHER/ASSET/CAMERA.png or .pfm, named per the manifest's
    /// `image` (a copy of the suite's reference/ folder layout).
    #[arg(long, value_name = "OTHER_DIR")]
    pub images: Option<PathBuf>,
    /// Render the suite with one of splatgl's backends instead.
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Where report.html and report.json go (default DIR/report).
    #[arg(short, long, value_name = "OUT_DIR")]
    pub out: Option<PathBuf>,
    /// What --images were rendered from: `exact` (the suite's assets as written) or `spz`
    /// (SPZ-compressed copies, `splatgl convert --spz-compress`, for a renderer that reads
    /// only KHR_gaussian_splatting_compression_spz_2): each image is then judged against the
    /// model of its SPZ copy, and passes when it matches it.
    #[arg(long, value_enum, default_value = "exact", requires = "images")]
    pub input_precision: InputPrecisionArg,
}

/// What the images were rendered from (`--input-precision`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputPrecisionArg {
    /// The suite's assets as written.
    Exact,
    /// SPZ-compressed copies of them.
    Spz,
}

/// Writes an output atomically (temporary file renamed into place), never over `inputs`.
fn write(path: &Path, inputs: &[&Path], bytes: &[u8]) -> Result<(), String> {
    splatgl::write::write_bytes_atomic(path, inputs, bytes)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Runs the comparison; `Err` = unusable input (exit 2).
fn run_cmd(a: &RunArgs) -> Result<bool, String> {
    let m = Manifest::read(&a.dir)?;
    let manifest = a.dir.join("manifest.json");
    let out = a.out.clone().unwrap_or_else(|| a.dir.join("report"));
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let (results, source) = if let Some(images) = &a.images {
        (
            run_images(&a.dir, &m, images, a.input_precision)?,
            images.display().to_string(),
        )
    } else {
        run_backend(a, &m, &manifest, &out)?
    };
    write_reports(&results, &source, &out, &manifest)?;
    let s = report::summary(&results);
    print_failures(&results);
    println!(
        "{} passed, {} failed, {} skipped (RC rules); optional: {} pass, {} fail; \
         profile: {} match, {} differ -> {}",
        s.passed,
        s.failed,
        s.skipped,
        s.optional_passed,
        s.optional_failed,
        s.profile_matched,
        s.profile_differ,
        out.join("report.html").display()
    );
    Ok(s.failed == 0)
}

/// Compares another renderer's images, found in the folder `images`, with the suite's.
fn run_images(
    dir: &Path,
    m: &Manifest,
    images: &Path,
    input: InputPrecisionArg,
) -> Result<Vec<AssetResult>, String> {
    if !images.is_dir() {
        return Err(format!("--images {}: not a folder", images.display()));
    }
    let opts = runner::RunOptions {
        input: match input {
            InputPrecisionArg::Exact => runner::InputPrecision::Exact,
            InputPrecisionArg::Spz => runner::InputPrecision::Spz,
        },
    };
    runner::run_with(dir, m, &opts, |c| {
        runner::find_image(images, c).map(Image::read)
    })
    .map_err(Into::into)
}

/// Renders the suite with `--backend`'s renderer, keeps the images under `out/images`, and
/// compares them; returns the results and the source's name for the report.
fn run_backend(
    a: &RunArgs,
    m: &Manifest,
    manifest: &Path,
    out: &Path,
) -> Result<(Vec<AssetResult>, String), String> {
    let backend = match a.backend {
        Some(BackendArg::Gl) => Backend::Gl,
        _ => Backend::Reference,
    };
    let imgs: HashMap<String, Image> = render_suite(&a.dir, m, backend)?.into_iter().collect();
    save_images(&a.dir, &imgs, backend, manifest, out)?;
    let r = runner::run(&a.dir, m, |c| imgs.get(&c.image).cloned().map(Ok))?;
    let name = match backend {
        Backend::Gl => "splatgl --backend gl",
        Backend::Reference => "splatgl --backend reference",
    };
    Ok((r, name.to_owned()))
}

/// Keeps the rendered images beside the report, laid out like --images expects (PNG for GL,
/// PFM for the reference), never over the suite's files.
fn save_images(
    dir: &Path,
    imgs: &HashMap<String, Image>,
    backend: Backend,
    manifest: &Path,
    out: &Path,
) -> Result<(), String> {
    for (name, img) in imgs {
        let (ext, bytes) = match backend {
            Backend::Gl => ("png", img.encode_png(Default::default(), false)),
            Backend::Reference => ("pfm", Ok(img.encode_pfm())),
        };
        let p = out.join("images").join(format!("{name}.{ext}"));
        std::fs::create_dir_all(p.parent().expect("has a parent"))
            .map_err(|e| format!("{}: {e}", p.display()))?;
        let reference = dir.join("reference").join(format!("{name}.{ext}"));
        write(
            &p,
            &[manifest, &reference],
            &bytes.map_err(|e| e.to_string())?,
        )?;
    }
    Ok(())
}

/// Writes report.json and report.html into `out`.
fn write_reports(
    results: &[AssetResult],
    source: &str,
    out: &Path,
    manifest: &Path,
) -> Result<(), String> {
    let json = report::to_json(results, source);
    write(
        &out.join("report.json"),
        &[manifest],
        &serde_json::to_vec_pretty(&json).unwrap_or_default(),
    )?;
    write(
        &out.join("report.html"),
        &[manifest],
        report::to_html(results, source).as_bytes(),
    )
}

/// Prints the run's diagnosis, then one line per failing camera (FAIL, or DIFFERS for a
/// profile asset).
fn print_failures(results: &[AssetResult]) {
    for d in splatgl_conformance::runner::diagnosis(results) {
        println!(
            "DIAGNOSIS {}: {} [{}] — assets: {}",
            d.deviation.name(),
            d.deviation.describe(),
            d.deviation.rc_section(),
            d.assets.join(", ")
        );
    }
    for r in results.iter().filter(|r| !r.skipped && !r.pass()) {
        let word = match r.asset.checks {
            splatgl_conformance::manifest::Checks::Rc => "FAIL",
            splatgl_conformance::manifest::Checks::Profile => "DIFFERS (profile, informative)",
        };
        for c in r.cameras.iter().filter(|c| !c.pass) {
            println!(
                "{word} {}/{}: {}",
                r.asset.name,
                c.camera.name,
                c.cause.as_deref().unwrap_or("")
            );
        }
    }
}

/// Runs a subcommand.
pub fn run(c: Command) -> ExitCode {
    let r = match c {
        Command::Generate { dir } => generate(&dir).map(|m| {
            let cams: usize = m.assets.iter().map(|a| a.cameras.len()).sum();
            println!(
                "{} assets, {cams} cameras -> {}",
                m.assets.len(),
                dir.join("manifest.json").display()
            );
            true
        }),
        Command::Run(a) => return exit(run_cmd(&a)),
    };
    exit(r.map_err(|e| e.to_string()))
}

fn exit(r: Result<bool, String>) -> ExitCode {
    match r {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
            ExitCode::from(2)
        }
    }
}
