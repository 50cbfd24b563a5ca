//! The `splatgl` command as a library: [`run`] is the binary's `main`, [`run_from`] runs it
//! with the arguments given (the Python package's console script runs it in-process).

mod cli;

use std::ffi::OsString;
use std::process::ExitCode;

/// Runs the command with the process's arguments (exits on `--help` or a usage error, as
/// the binary does).
pub fn run() -> ExitCode {
    cli::run()
}

/// Runs the command with `args` (the first is the program's name). A usage error or
/// `--help` prints what clap prints and returns its exit status instead of exiting.
pub fn run_from<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    cli::run_from(args)
}

/// The number an [`ExitCode`] the command returns stands for (0 success, 1 a failed
/// check, 2 an error).
pub fn exit_status(code: ExitCode) -> u8 {
    (0..=u8::MAX)
        .find(|&k| ExitCode::from(k) == code)
        .unwrap_or(1)
}
