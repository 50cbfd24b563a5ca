//! `splatgl compare`: metrics between two images, optional heat-map and tolerances.

use splatgl::compare::{compare, diff_image};
use splatgl::image::{Image, PngDepth};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// First image (.png or .pfm).
    pub a: PathBuf,
    /// Second image (.png or .pfm).
    pub b: PathBuf,
    /// Write a heat-map of per-pixel errors (PNG).
    #[arg(long, value_name = "diff.png")]
    pub diff: Option<PathBuf>,
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
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

fn go(a: &Args) -> Result<bool, String> {
    let ia = Image::read(&a.a).map_err(|e| e.to_string())?;
    let ib = Image::read(&a.b).map_err(|e| e.to_string())?;
    let c = compare(&ia, &ib, a.threshold).map_err(|e| e.to_string())?;
    if let Some(path) = &a.diff {
        splatgl::write::refuse_overwriting_inputs(path, &[&a.a, &a.b])
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let d = diff_image(&ia, &ib, a.diff_scale).map_err(|e| e.to_string())?;
        d.write_png(path, PngDepth::Eight, false)
            .map_err(|e| e.to_string())?;
    }
    if a.json {
        println!("{}", c.to_json());
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
    }
    let ok = a.max_abs.is_none_or(|t| c.max_abs <= t) && a.min_psnr.is_none_or(|p| c.psnr >= p);
    Ok(ok)
}

/// Runs it. Exit status: 0 within tolerances, 1 outside them, 2 on errors.
pub fn run(a: Args) -> ExitCode {
    match go(&a) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
