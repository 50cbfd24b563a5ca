//! [`Finding`]: the one diagnostics type of loading and validation. Every reader records what it
//! notices as findings in its [`crate::load::LoadReport`]; `splatgl info` and `render` print
//! them as warnings, `splatgl validate` judges them.

use std::collections::HashMap;
use std::fmt;

/// How bad a finding is (more may come: match with a wildcard arm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[non_exhaustive]
pub enum Severity {
    /// The file breaks a MUST of glTF 2.0 or of `KHR_gaussian_splatting` (RC).
    Error,
    /// Valid as far as splatgl can tell, but splatgl cannot decode it (a required or
    /// compression extension it does not implement, a superseded draft extension).
    Unsupported,
    /// Allowed, but worth knowing (legacy draft data, unknown enum values, SHOULDs).
    Warning,
    /// Normal, for the record (e.g. the unnormalised quaternions 3DGS trainers write).
    Info,
}

impl Severity {
    /// `"error"`, `"unsupported"`, `"warning"` or `"info"`.
    pub fn name(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Unsupported => "unsupported",
            Severity::Warning => "warning",
            Severity::Info => "info",
        }
    }
}

/// One thing found in a file: where (JSON path or PLY element/property, and the first
/// offending element index), how bad, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// Error or warning.
    pub severity: Severity,
    /// Whether the loader cannot go on (the data is unusable, not merely off-spec).
    pub blocks_loading: bool,
    /// Where: a JSON path, e.g.
    /// `meshes[0].primitives[1].attributes["KHR_gaussian_splatting:SCALE"]`, or a PLY element
    /// and property (`vertex.rot_0..3`); empty when the finding concerns the whole file.
    pub path: String,
    /// What is wrong, and what was expected.
    pub message: String,
    /// First offending element index, where it applies.
    pub index: Option<u64>,
}

impl Finding {
    /// An error that stops loading.
    pub(crate) fn fatal(path: impl Into<String>, message: impl Into<String>) -> Self {
        let (path, message) = (path.into(), message.into());
        Finding {
            severity: Severity::Error,
            blocks_loading: true,
            path: printable(&path).into_owned(),
            message: printable(&message).into_owned(),
            index: None,
        }
    }
    /// A spec violation the loader can work around.
    pub(crate) fn error(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            blocks_loading: false,
            ..Finding::fatal(path, message)
        }
    }
    /// A warning.
    pub(crate) fn warning(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            severity: Severity::Warning,
            ..Finding::error(path, message)
        }
    }
    /// Something splatgl cannot decode in an otherwise valid file; stops loading.
    pub(crate) fn unsupported(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            severity: Severity::Unsupported,
            ..Finding::fatal(path, message)
        }
    }
    /// A note about something normal.
    pub(crate) fn info(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            severity: Severity::Info,
            ..Finding::error(path, message)
        }
    }
    /// Sets the offending index.
    pub(crate) fn at(mut self, index: u64) -> Self {
        self.index = Some(index);
        self
    }
    /// The line `splatgl info` and `render` print for it (and `info --json` lists under
    /// `warnings`): `PATH [index I]: MESSAGE`, an error's message prefixed with what it breaks.
    pub fn warning_line(&self) -> String {
        let message = match self.severity {
            Severity::Error => format!(
                "invalid per KHR_gaussian_splatting RC / glTF 2.0: {}",
                self.message
            ),
            Severity::Unsupported => format!("not decodable by splatgl: {}", self.message),
            Severity::Warning | Severity::Info => self.message.clone(),
        };
        let location = match self.index {
            Some(i) => format!("{} [index {i}]", self.path),
            None => self.path.clone(),
        };
        if location.is_empty() {
            message
        } else {
            format!("{location}: {message}")
        }
    }
}

/// Repeats collapsed: one entry per distinct (severity, message), holding the first finding
/// that said it and how many said it, in first-seen order.
pub(crate) fn collapse(findings: &[Finding]) -> Vec<(&Finding, usize)> {
    let mut groups: Vec<(&Finding, usize)> = Vec::new();
    let mut index: HashMap<(Severity, &str), usize> = HashMap::new();
    for f in findings {
        match index.get(&(f.severity, f.message.as_str())) {
            Some(&g) => groups[g].1 += 1,
            None => {
                index.insert((f.severity, &f.message), groups.len());
                groups.push((f, 1));
            }
        }
    }
    groups
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.severity.name())?;
        if !self.path.is_empty() {
            write!(f, " at {}", self.path)?;
        }
        if let Some(i) = self.index {
            write!(f, " [index {i}]")?;
        }
        write!(f, ": {}", self.message)
    }
}

/// `text` safe to print on a terminal: control characters but newline and tab (escape
/// sequences, carriage returns, bells, C1 controls) and the bidirectional-override characters
/// are written as `\u{…}` escapes. Every message that quotes a file's content goes through it
/// before it reaches a terminal ([`Finding`]s at construction; the CLI's, the C API's and the
/// Python package's error messages where they are printed or handed over).
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    let unsafe_char = |c: char| {
        (c.is_control() && c != '\n' && c != '\t')
            || matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
    };
    if !text.contains(unsafe_char) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if unsafe_char(c) {
            out.push_str(&c.escape_unicode().to_string());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printable_escapes_terminal_controls_and_keeps_lines() {
        assert_eq!(
            printable("a\x1b[31mb\rc\u{7}"),
            "a\\u{1b}[31mb\\u{d}c\\u{7}"
        );
        assert_eq!(printable("x\u{202E}y"), "x\\u{202e}y");
        assert!(matches!(
            printable("plain\nlines\tok é"),
            std::borrow::Cow::Borrowed(_)
        ));
        let f = Finding::warning("a\x1bb", "m\x1b]0;t\x07");
        assert!(!f.path.contains('\x1b') && !f.message.contains(['\x1b', '\x07']));
    }
}
