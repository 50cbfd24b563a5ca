//! `splatgl info`.
use std::process::ExitCode;
/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The file.
    pub file: std::path::PathBuf,
}
/// Runs it.
pub fn run(a: Args) -> ExitCode {
    match splatgl::load::load_path(&a.file, &Default::default()) {
        Ok(l) => {
            println!("{} splats, degree {}", l.cloud.len(), l.cloud.sh_degree);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
