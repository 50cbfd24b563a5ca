//! `splatgl validate FILE [--json]`.
use std::process::ExitCode;

/// Help of `validate --json`.
pub const JSON_HELP: &str = "Print the findings as JSON (keys: file, format, status, valid, \
    errors, warnings, unsupported, notes, splat_count, findings[{severity (error, unsupported, \
    warning or info), path, message, index}]; with -v also limits)";

/// Runs `validate`; the exit status is 0 valid, 1 invalid, 2 unreadable.
pub fn run(a: super::FileArgs) -> ExitCode {
    let opts = a.load.options();
    if super::tileset::is_tileset_file(&a.file, &opts) {
        let t = splatgl::tiles::check(&a.file, &opts, true);
        return print(&a, &t.report, &opts, Some("3dtiles"));
    }
    let report = splatgl::load::validate::validate_path(&a.file, &opts);
    if let Some(format) = report.format
        && let Err(e) = a
            .load
            .common
            .check_applies(&a.file.display().to_string(), Some(format))
    {
        eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
        return ExitCode::from(2);
    }
    print(&a, &report, &opts, None)
}

/// Prints `report` (JSON or text, with its `format` named `format` where the report has none:
/// a tileset) and returns the exit status.
fn print(
    a: &super::FileArgs,
    report: &splatgl::load::validate::Report,
    opts: &splatgl::load::LoadOptions,
    format: Option<&str>,
) -> ExitCode {
    if a.json {
        let mut json = report.to_json(&a.file);
        if let Some(f) = format {
            json["format"] = f.into();
        }
        if a.verbose {
            json["limits"] = super::limits_json(&opts.limits);
        }
        println!("{json:#}");
    } else {
        if !a.quiet {
            // Each line names the file, as `info` and `render` do in their errors.
            for line in report.summarized() {
                println!("{}: {line}", a.file.display());
            }
        }
        let status = report.status();
        let verdict = match status {
            splatgl::load::validate::Status::Valid => "valid",
            splatgl::load::validate::Status::Invalid => "INVALID",
            splatgl::load::validate::Status::Unreadable => "UNREADABLE",
        };
        let mut counts = format!("{} errors, {} warnings", report.errors(), report.warnings());
        for (n, what) in [
            (report.unsupported(), "unsupported"),
            (report.notes(), "notes"),
        ] {
            if n > 0 {
                counts += &format!(", {n} {what}");
            }
        }
        println!("{}: {verdict} ({counts})", a.file.display());
        if a.verbose {
            super::print_limits(&opts.limits);
        }
        if report.unsupported() > 0 && status == splatgl::load::validate::Status::Valid && !a.quiet
        {
            println!(
                "note: valid, but splatgl cannot decode it (the `unsupported` findings above); \
                 exit status 0"
            );
        }
    }
    ExitCode::from(report.status() as u8)
}
