//! The `splatgl` command-line tool.

fn main() -> std::process::ExitCode {
    // Behave like other Unix tools when the reader of our output goes away (`| head`): exit
    // quietly instead of panicking on a failed write to stdout.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    splatgl_cli::run()
}
