//! Command-line interface: one file per subcommand.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod camera_args;
mod compare;
mod conformance;
mod convert;
mod info;
mod render;
mod validate;
#[cfg(feature = "viewer")]
mod view;

/// splatgl: render, inspect and validate 3D Gaussian splat files (glTF KHR_gaussian_splatting,
/// INRIA PLY, Niantic SPZ, .splat, .ksplat, PlayCanvas SOG).
#[derive(Parser, Debug)]
#[command(name = "splatgl", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print what a splat file holds: format, count, SH degree, colour space, bounds, warnings.
    /// Exit status: 0, or 2 when the file cannot be loaded.
    #[command(mut_arg("json", |a| a.help(info::JSON_HELP)))]
    Info(FileArgs),
    /// Check a file against every MUST of KHR_gaussian_splatting (RC) and report findings.
    /// Exit status: 0 valid (warnings allowed), 1 invalid, 2 unreadable.
    #[command(mut_arg("json", |a| a.help(validate::JSON_HELP)))]
    #[command(mut_arg("file", |a| a.help(
        "The file to check (.gltf, .glb, .ply, .spz, .splat, .ksplat, .sog or a SOG meta.json)"
    )))]
    Validate(FileArgs),
    /// Render an image (without a scene: the bundled default scene).
    /// Exit status: 0, or 2 on any error (message on stderr).
    Render(render::Args),
    /// Compare two images (PNG/PFM): PSNR, max error, pixels over a threshold, heat-map.
    /// Exit status: 0 within --max-abs/--min-psnr, 1 outside, 2 on errors.
    Compare(compare::Args),
    /// Convert a splat file to glTF (.glb/.gltf, KHR_gaussian_splatting RC) or INRIA PLY.
    /// Exit status: 0, or 2 on any error.
    Convert(convert::Args),
    /// Open a window and fly through a scene (without a scene: the bundled default scene).
    /// H or F1 in the window prints the controls. Exit status: 0, or 2 on errors.
    #[cfg(feature = "viewer")]
    View(view::Args),
    /// The KHR_gaussian_splatting conformance suite: generate it, or run it on images.
    #[command(subcommand)]
    Conformance(conformance::Command),
}

/// The arguments of `info` and `validate`: one file, read with the loader options.
#[derive(clap::Args, Debug)]
pub struct FileArgs {
    /// The file (.gltf, .glb, .ply, .spz, .splat, .ksplat, .sog or a SOG meta.json).
    pub file: std::path::PathBuf,
    /// Print JSON (each command lists its keys).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub load: LoadArgs,
}

/// Loader options shared by every command that reads a scene.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct LoadArgs {
    /// How glTF SCALE values are read: auto (signed types or negatives mean the review
    /// draft's log space), linear (RC) or log.
    #[arg(long, default_value = "auto", value_name = "auto|linear|log")]
    pub scale_space: splatgl::load::ScaleSpace,
    /// Axes of SPZ data: rub (Niantic's RUB, converted to splatgl's frame: RDF for .spz files,
    /// glTF's LUF inside glTF), raw (no conversion: what splat-transform 3.x writes into .spz,
    /// and CesiumJS expects inside glTF) or auto (.spz: rub; glTF: what POSITION min/max show,
    /// else rub for KHR_gaussian_splatting_compression_spz_2 and raw for the legacy extension).
    #[arg(long, default_value = "auto", value_name = "auto|rub|raw")]
    pub spz_axes: splatgl::load::spz::SpzAxes,
}

impl LoadArgs {
    /// The library's options.
    pub fn options(&self) -> splatgl::load::LoadOptions {
        splatgl::load::LoadOptions {
            scale_space: self.scale_space,
            spz_axes: self.spz_axes,
        }
    }
}

/// Parses the arguments and runs the subcommand.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Info(a) => info::run(a),
        Command::Validate(a) => validate::run(a),
        Command::Render(a) => render::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Conformance(c) => conformance::run(c),
        #[cfg(feature = "viewer")]
        Command::View(a) => view::run(a),
    }
}
