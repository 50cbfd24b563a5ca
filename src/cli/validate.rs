//! `splatgl validate FILE [--json]`.
use std::process::ExitCode;

/// Arguments of `validate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The file to check (.gltf, .glb, .ply, .spz, .splat, .ksplat, .sog or a SOG meta.json).
    pub file: std::path::PathBuf,
    /// Print the findings as JSON (keys: file, format, status, valid, errors, warnings,
    /// splat_count, findings[{severity, path, message, index}]).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub load: super::LoadArgs,
}

/// Runs `validate`; the exit status is 0 valid, 1 invalid, 2 unreadable.
pub fn run(a: Args) -> ExitCode {
    let opts = a.load.options();
    let report = splatgl::validate::validate_path(&a.file, &opts);
    if a.json {
        println!("{:#}", report.to_json(&a.file));
    } else {
        for f in &report.findings {
            println!("{f}");
        }
        let verdict = match report.status() {
            splatgl::validate::Status::Valid => "valid",
            splatgl::validate::Status::Invalid => "INVALID",
            splatgl::validate::Status::Unreadable => "UNREADABLE",
        };
        println!(
            "{}: {verdict} ({} errors, {} warnings)",
            a.file.display(),
            report.errors(),
            report.warnings()
        );
    }
    ExitCode::from(report.status() as u8)
}
