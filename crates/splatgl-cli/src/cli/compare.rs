//! `splatgl compare`: metrics between two images, optional heat-map and tolerances.

use splatgl::compare::{compare, diff_image};
use splatgl::image::{Image, PngDepth};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// First image (.png or .pfm).
    pub a: PathBuf,
    /// Second image (.png or .pfm).
    pub b: PathBuf,
    /// Write a heat-map of per-pixel errors (PNG; the name must end in .png).
    #[arg(long, value_name = "diff.png")]
    pub diff: Option<PathBuf>,
    /// Overwrite the --diff file if it exists.
    #[arg(short, long, requires = "diff")]
    pub force: bool,
    /// Error that maps to white in the heat-map (default: the largest error).
    #[arg(long, default_value_t = 0.0)]
    pub diff_scale: f32,
    /// Per-pixel error above which a pixel counts as different.
    #[arg(long, default_value_t = 1.0 / 255.0)]
    pub threshold: f32,
    /// Fail (exit 1) when the largest error exceeds this.
    #[arg(long)]
    pub max_abs: Option<f32>,
    /// Fail (exit 1) when the PSNR is below this (dB).
    #[arg(long)]
    pub min_psnr: Option<f64>,
    /// Print JSON instead of text (adds `pass` and `failed`, the thresholds not met).
    #[arg(long)]
    pub json: bool,
    /// Print nothing; the exit status says it.
    #[arg(short, long, conflicts_with = "json")]
    pub quiet: bool,
    /// Most bytes read from each image file. Plain bytes or with a K, M or G suffix (powers
    /// of 1024).
    #[arg(long, value_name = "BYTES", default_value = "4G", value_parser = super::parse_bytes)]
    pub max_bytes: u64,
}

/// Refuses a --diff file that cannot or should not be written, before the images are read.
fn check_diff(a: &Args, path: &Path) -> Result<(), String> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(format!(
            "{}: --diff writes a PNG heat-map; the name must end in .png",
            path.display()
        ));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        return Err(format!(
            "{}: the folder {} does not exist",
            path.display(),
            dir.display()
        ));
    }
    splatgl::write::refuse_overwriting_inputs(path, &[&a.a, &a.b])
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if !a.force && path.exists() {
        return Err(format!(
            "{} exists; pass -f/--force to overwrite it",
            path.display()
        ));
    }
    Ok(())
}

fn go(a: &Args) -> Result<bool, String> {
    if let Some(path) = &a.diff {
        check_diff(a, path)?;
    }
    let ia = Image::read_limited(&a.a, a.max_bytes).map_err(|e| e.to_string())?;
    let ib = Image::read_limited(&a.b, a.max_bytes).map_err(|e| e.to_string())?;
    let c = compare(&ia, &ib, a.threshold).map_err(|e| e.to_string())?;
    if let Some(path) = &a.diff {
        let d = diff_image(&ia, &ib, a.diff_scale).map_err(|e| e.to_string())?;
        d.write_png(path, PngDepth::Eight, false)
            .map_err(|e| e.to_string())?;
    }
    let mut failed = Vec::new();
    // (NaN metrics fail: the tests are written as "within".)
    let within_abs = |t: f32| c.max_abs <= t;
    let within_psnr = |p: f64| c.psnr >= p;
    if let Some(t) = a.max_abs.filter(|&t| !within_abs(t)) {
        failed.push(format!("--max-abs {t}: max abs {:.6} > {t}", c.max_abs));
    }
    if let Some(p) = a.min_psnr.filter(|&p| !within_psnr(p)) {
        failed.push(format!("--min-psnr {p}: PSNR {:.2} dB < {p} dB", c.psnr));
    }
    let ok = failed.is_empty();
    if a.quiet {
        return Ok(ok);
    }
    if a.json {
        let mut v: serde_json::Value =
            serde_json::from_str(&c.to_json()).map_err(|e| e.to_string())?;
        v["pass"] = ok.into();
        v["failed"] = failed.clone().into();
        println!("{v}");
    } else {
        println!(
            "PSNR {:.2} dB, max abs {:.6} at ({}, {}), mean abs {:.6}, {} of {} pixels over {}",
            c.psnr,
            c.max_abs,
            c.max_at.0,
            c.max_at.1,
            c.mean_abs,
            c.over_threshold,
            c.pixels,
            c.threshold
        );
        let given = a.max_abs.is_some() || a.min_psnr.is_some();
        match (ok, given) {
            (true, true) => println!("PASS: within {}", thresholds(a)),
            (true, false) => println!("PASS (no --max-abs or --min-psnr given)"),
            (false, _) => println!("FAIL: {}", failed.join("; ")),
        }
    }
    Ok(ok)
}

/// The thresholds given, as flags.
fn thresholds(a: &Args) -> String {
    let mut v = Vec::new();
    if let Some(t) = a.max_abs {
        v.push(format!("--max-abs {t}"));
    }
    if let Some(p) = a.min_psnr {
        v.push(format!("--min-psnr {p}"));
    }
    v.join(" and ")
}

/// Runs it. Exit status: 0 within tolerances, 1 outside them, 2 on errors.
pub fn run(a: Args) -> ExitCode {
    match go(&a) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
            ExitCode::from(2)
        }
    }
}
