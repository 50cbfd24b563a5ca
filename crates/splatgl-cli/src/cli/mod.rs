//! Command-line interface: one file per subcommand.

use clap::{Parser, Subcommand};
use splatgl::load::Limits;
use std::process::ExitCode;

mod camera_args;
mod compare;
mod conformance;
mod convert;
mod convert_lod;
mod convert_sog;
mod info;
mod kernel;
mod progress;
mod render;
mod render_backend;
mod render_out;
mod tileset;
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
    #[command(mut_arg("verbose", |a| a.help("Also print the loader's limits (`limits` in JSON)")))]
    Validate(FileArgs),
    /// Render an image (without a scene: the bundled default scene).
    /// Exit status: 0, or 2 on any error (message on stderr).
    Render(render::Args),
    /// Compare two images (PNG/PFM): PSNR, max error, pixels over a threshold, heat-map.
    /// Exit status: 0 within --max-abs/--min-psnr, 1 outside, 2 on errors.
    Compare(compare::Args),
    /// Convert a splat file to glTF (.glb/.gltf, KHR_gaussian_splatting RC; SPZ-compressed .glb
    /// with --spz-compress), INRIA PLY, Niantic SPZ (.spz) or antimatter15 .splat.
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
    /// The file (.gltf, .glb, .ply, .spz, .splat, .ksplat, .sog, a SOG meta.json, or a 3D Tiles
    /// tileset.json).
    pub file: std::path::PathBuf,
    /// Print JSON (each command lists its keys).
    #[arg(long)]
    pub json: bool,
    /// Also print the loader's limits (`limits` in JSON).
    #[arg(short, long)]
    pub verbose: bool,
    /// Less text: `info` without warnings and notes, `validate` only its verdict line
    /// (text output only: JSON is always whole).
    #[arg(short, long, conflicts_with_all = ["verbose", "json"])]
    pub quiet: bool,
    #[command(flatten)]
    pub load: LoadArgs,
}

/// Loader options shared by every command that reads a scene: [`LoadCommonArgs`] and
/// `--max-splats`.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct LoadArgs {
    #[command(flatten)]
    pub common: LoadCommonArgs,
    /// Most splats a scene may hold.
    #[arg(long, value_name = "N", default_value_t = Limits::DEFAULT_MAX_SPLATS)]
    pub max_splats: u64,
}

/// The loader options but `--max-splats` (which `view` spells as its drawing budget).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct LoadCommonArgs {
    /// How glTF SCALE values are read: auto (signed types or negatives mean the review
    /// draft's log space), linear (RC) or log.
    /// glTF only (an error for other inputs).
    #[arg(long, value_name = "auto|linear|log")]
    pub scale_space: Option<splatgl::load::ScaleSpace>,
    /// Axes of SPZ data: rub (Niantic's RUB, converted to splatgl's frame: RDF for .spz files,
    /// glTF's LUF inside glTF), raw (no conversion: what splat-transform 3.x writes into .spz,
    /// and CesiumJS expects inside glTF) or auto (.spz: rub; glTF: what POSITION min/max show,
    /// else rub for KHR_gaussian_splatting_compression_spz_2 and raw for the legacy extension).
    /// .spz and glTF only (an error for other inputs).
    #[arg(long, value_name = "auto|rub|raw")]
    pub spz_axes: Option<splatgl::load::spz::SpzAxes>,
    /// Fail on a splat with a non-finite or overflowing value instead of dropping it.
    #[arg(long)]
    pub strict: bool,
    /// Let external glTF buffers lie outside the asset's folder (absolute paths, `..`,
    /// symlinks pointing out). Only for files you trust.
    #[arg(long)]
    pub allow_outside_paths: bool,
    /// Most bytes read from files for one scene (scene file and external buffers; also
    /// cameras.json). Plain bytes or with a K, M or G suffix (powers of 1024).
    #[arg(long, value_name = "BYTES", default_value = "4G", value_parser = parse_bytes)]
    pub max_bytes: u64,
    /// Most values one JSON document may hold (glTF, tileset.json, meta.json, cameras.json:
    /// objects, arrays, strings, numbers, literals), checked before parsing: parsing costs up
    /// to ~450 bytes per value, so this bounds its memory.
    #[arg(long, value_name = "N", default_value_t = Limits::DEFAULT_MAX_JSON_VALUES)]
    pub max_json_values: u64,
}

/// `123`, `64K`, `512M`, `4G` (binary multiples).
pub(crate) fn parse_bytes(s: &str) -> Result<u64, String> {
    let (num, shift) = match s.char_indices().last() {
        Some((i, 'k' | 'K')) => (&s[..i], 10),
        Some((i, 'm' | 'M')) => (&s[..i], 20),
        Some((i, 'g' | 'G')) => (&s[..i], 30),
        _ => (s, 0),
    };
    num.parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(1 << shift))
        .ok_or_else(|| format!("expected a byte count like 1048576, 64K, 512M or 4G, found {s:?}"))
}

impl LoadArgs {
    /// The library's options.
    pub fn options(&self) -> splatgl::load::LoadOptions {
        self.common.options(self.max_splats)
    }
}

impl LoadCommonArgs {
    /// The library's options, with `max_splats` as the splat limit.
    pub fn options(&self, max_splats: u64) -> splatgl::load::LoadOptions {
        splatgl::load::LoadOptions {
            scale_space: self.scale_space.unwrap_or_default(),
            spz_axes: self.spz_axes.unwrap_or_default(),
            strict: self.strict,
            allow_outside_paths: self.allow_outside_paths,
            resolver: None,
            limits: Limits {
                max_splats,
                max_bytes: self.max_bytes,
                max_json_values: self.max_json_values,
                ..Limits::default()
            },
            // The command maps scene files (SPLATGL_NO_MMAP=1: read them).
            memory_map: true,
        }
    }
}

impl LoadCommonArgs {
    /// Refuses the format-specific options given for a file of another format (`None`: the
    /// bundled default scene), naming the option and the format.
    pub fn check_applies(
        &self,
        file: &str,
        format: Option<splatgl::load::Format>,
    ) -> Result<(), String> {
        use splatgl::load::Format;
        let what = format.map_or(
            "no file was given (the bundled default scene)".into(),
            |f| format!("{file} is a {} file", f.name()),
        );
        let gltf = matches!(format, Some(Format::Gltf | Format::Glb));
        if self.scale_space.is_some() && !gltf {
            return Err(format!("--scale-space applies to glTF scenes only; {what}"));
        }
        if self.spz_axes.is_some() && !(gltf || format == Some(Format::Spz)) {
            return Err(format!(
                "--spz-axes applies to .spz and glTF scenes only; {what}"
            ));
        }
        Ok(())
    }
}

/// The loader's limits as `info -v` / `validate -v` show them: a JSON object (`limits`).
pub(crate) fn limits_json(limits: &Limits) -> serde_json::Value {
    let map: serde_json::Map<_, _> = (limits.entries().iter())
        .map(|&(k, v)| (k.to_owned(), serde_json::json!(v)))
        .collect();
    serde_json::Value::Object(map)
}

/// The loader's limits as text lines (`limits:` then one per limit).
pub(crate) fn print_limits(limits: &Limits) {
    println!("limits:");
    for (k, v) in limits.entries() {
        println!("  {k:<24}{v}");
    }
}

/// The exit status of a command that succeeds with 0 or fails with an `error:` line and 2.
pub(crate) fn exit_status(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

/// Parses the arguments and runs the subcommand.
pub fn run() -> ExitCode {
    dispatch(Cli::parse())
}

/// [`run`] with `args`: a usage error or `--help` is printed and its status returned.
pub fn run_from<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    match Cli::try_parse_from(args) {
        Ok(cli) => dispatch(cli),
        Err(e) => {
            let _ = e.print();
            ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
        }
    }
}

/// Runs the parsed command.
fn dispatch(cli: Cli) -> ExitCode {
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
