//! Running the `splatgl` binary from tests: one way to spawn it and read what it said.

use std::path::Path;
use std::process::Command;

/// What one run of the binary gave.
pub struct Run {
    /// Exit status (-1 when killed by a signal).
    pub code: i32,
    /// Standard output, as bytes (`-o -` writes a PNG there).
    pub stdout: Vec<u8>,
    /// Standard error.
    pub stderr: String,
}

impl Run {
    /// Standard output as text.
    pub fn out(&self) -> String {
        String::from_utf8_lossy(&self.stdout).into_owned()
    }

    /// Standard output then standard error, as text.
    pub fn all(&self) -> String {
        self.out() + &self.stderr
    }
}

/// Runs `splatgl ARGS` in this process's working directory.
pub fn run(args: &[&str]) -> Run {
    run_command(Command::new(env!("CARGO_BIN_EXE_splatgl")).args(args))
}

/// Runs `splatgl ARGS` in `cwd`.
pub fn run_in(cwd: &Path, args: &[&str]) -> Run {
    run_command(
        Command::new(env!("CARGO_BIN_EXE_splatgl"))
            .args(args)
            .current_dir(cwd),
    )
}

fn run_command(cmd: &mut Command) -> Run {
    let out = cmd.output().expect("splatgl runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: out.stdout,
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `render SCENE --look-at LOOK` with the reference backend, 96×72, `-f -v`, into `out`, then
/// `extra`: the small render the tileset tests compare.
pub fn render_small(scene: &str, look: &str, out: &Path, extra: &[&str]) -> Run {
    let out = out.to_str().unwrap();
    let mut args = vec![
        "render",
        scene,
        "--backend",
        "reference",
        "--look-at",
        look,
        "--width",
        "96",
        "--height",
        "72",
        "-f",
        "-v",
        "-o",
        out,
    ];
    args.extend_from_slice(extra);
    run(&args)
}
