//! Findings: what the glTF reader and `splatgl validate` report about a file.

use std::fmt;

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// The file breaks a MUST of glTF 2.0 or of `KHR_gaussian_splatting` (RC).
    Error,
    /// Allowed, but worth knowing (legacy draft data, unknown enum values, SHOULDs).
    Warning,
}

impl Severity {
    /// `"error"` or `"warning"`.
    pub fn name(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
    }
}

/// One thing found in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// Error or warning.
    pub severity: Severity,
    /// Whether the loader cannot go on (the data is unusable, not merely off-spec).
    pub blocks_loading: bool,
    /// JSON path, e.g. `meshes[0].primitives[1].attributes["KHR_gaussian_splatting:SCALE"]`.
    pub path: String,
    /// What is wrong, and what was expected.
    pub message: String,
    /// First offending element index, where it applies.
    pub index: Option<u64>,
}

impl Finding {
    /// An error that stops loading.
    pub fn fatal(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            severity: Severity::Error,
            blocks_loading: true,
            path: path.into(),
            message: message.into(),
            index: None,
        }
    }
    /// A spec violation the loader can work around.
    pub fn error(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            blocks_loading: false,
            ..Finding::fatal(path, message)
        }
    }
    /// A warning.
    pub fn warning(path: impl Into<String>, message: impl Into<String>) -> Self {
        Finding {
            severity: Severity::Warning,
            ..Finding::error(path, message)
        }
    }
    /// Sets the offending index.
    pub fn at(mut self, index: u64) -> Self {
        self.index = Some(index);
        self
    }
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
