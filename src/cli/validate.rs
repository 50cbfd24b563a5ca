//! `splatgl validate FILE [--json]`.
use std::process::ExitCode;

/// Help of `validate --json`.
pub const JSON_HELP: &str = "Print the findings as JSON (keys: file, format, status, valid, \
    errors, warnings, splat_count, findings[{severity, path, message, index}])";

/// Runs `validate`; the exit status is 0 valid, 1 invalid, 2 unreadable.
pub fn run(a: super::FileArgs) -> ExitCode {
    let opts = a.load.options();
    let report = splatgl::load::validate::validate_path(&a.file, &opts);
    if a.json {
        println!("{:#}", report.to_json(&a.file));
    } else {
        for f in &report.findings {
            println!("{f}");
        }
        let verdict = match report.status() {
            splatgl::load::validate::Status::Valid => "valid",
            splatgl::load::validate::Status::Invalid => "INVALID",
            splatgl::load::validate::Status::Unreadable => "UNREADABLE",
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
