//! Progress on stderr for `render`: a bar redrawn in place on a terminal, off when stderr is
//! not a terminal (logs, pipes, tests) or with `--quiet`; `--progress` forces it on as one
//! line per step (for logs).

use std::io::{IsTerminal, Write};

/// Where progress goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// Nothing.
    Off,
    /// A bar redrawn with `\r` (stderr is a terminal).
    Bar,
    /// One `progress:` line per step (`--progress` without a terminal).
    Lines,
}

impl Progress {
    /// The mode for the flags: off with `quiet`; a bar on a terminal; lines when `forced`
    /// and stderr is not a terminal; else off.
    pub fn new(quiet: bool, forced: bool) -> Self {
        Self::for_terminal(quiet, forced, std::io::stderr().is_terminal())
    }

    /// [`Progress::new`] with the terminal test given.
    pub fn for_terminal(quiet: bool, forced: bool, terminal: bool) -> Self {
        match (quiet, terminal, forced) {
            (true, _, _) => Progress::Off,
            (false, true, _) => Progress::Bar,
            (false, false, true) => Progress::Lines,
            (false, false, false) => Progress::Off,
        }
    }

    /// A stage without a count (`loading FILE`).
    pub fn stage(self, what: &str) {
        match self {
            Progress::Off => {}
            Progress::Bar => {
                eprint!("\r\x1b[K{what}…");
                let _ = std::io::stderr().flush();
            }
            Progress::Lines => eprintln!("progress: {what}"),
        }
    }

    /// `done` of `total` steps of `what`.
    pub fn step(self, what: &str, done: usize, total: usize) {
        match self {
            Progress::Off => {}
            Progress::Bar => {
                let w = 30;
                let filled = (done * w).checked_div(total).unwrap_or(w).min(w);
                eprint!(
                    "\r\x1b[K{what} [{}{}] {done}/{total}",
                    "#".repeat(filled),
                    " ".repeat(w - filled)
                );
                let _ = std::io::stderr().flush();
            }
            Progress::Lines => eprintln!("progress: {what} {done}/{total}"),
        }
    }

    /// Ends the bar's line (before other output).
    pub fn clear(self) {
        if self == Progress::Bar {
            eprint!("\r\x1b[K");
            let _ = std::io::stderr().flush();
        }
    }
}

pub use splatgl::files::peak_memory;

/// [`peak_memory`] for a message: `", peak memory 123 MB"`, or nothing.
pub fn peak_memory_note() -> String {
    peak_memory().map_or(String::new(), |b| {
        format!(", peak memory {} MB", b.div_ceil(1 << 20))
    })
}

#[cfg(test)]
mod tests {
    use super::Progress;

    #[test]
    fn progress_is_off_when_quiet_or_not_a_terminal_unless_forced() {
        assert_eq!(Progress::for_terminal(true, true, true), Progress::Off);
        assert_eq!(Progress::for_terminal(true, false, true), Progress::Off);
        assert_eq!(Progress::for_terminal(false, false, true), Progress::Bar);
        assert_eq!(Progress::for_terminal(false, false, false), Progress::Off);
        assert_eq!(Progress::for_terminal(false, true, false), Progress::Lines);
    }
}
