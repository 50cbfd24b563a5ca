//! `splatgl conformance generate|run` (WIP).
use std::process::ExitCode;

/// Subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Write the suite.
    Generate,
}

/// Runs it.
pub fn run(_c: Command) -> ExitCode {
    ExitCode::from(2)
}
