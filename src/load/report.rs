//! [`LoadReport`]: what a reader learnt about a file besides the splats.

use super::{Details, Finding, Format, finding};

/// Scale space as read from the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScaleSeen {
    /// Linear scales.
    Linear,
    /// Log-space scales (exp applied).
    Log,
    /// Primitives of both kinds.
    Mixed,
}

impl ScaleSeen {
    /// `"linear"`, `"log"` or `"mixed"`.
    pub fn name(self) -> &'static str {
        match self {
            ScaleSeen::Linear => "linear",
            ScaleSeen::Log => "log",
            ScaleSeen::Mixed => "mixed",
        }
    }
    pub(crate) fn merge(a: Option<Self>, b: Self) -> Self {
        match a {
            None => b,
            Some(a) if a == b => a,
            Some(_) => ScaleSeen::Mixed,
        }
    }
}

/// What the loader learnt besides the splats.
#[derive(Debug, Clone)]
pub struct LoadReport {
    /// Detected format.
    pub format: Format,
    /// Scale space seen (`None` when there were no splats to look at).
    pub scale_space: Option<ScaleSeen>,
    /// Quaternions that were not unit length (within 1e-3) and were normalised.
    pub non_unit_quaternions: usize,
    /// PLY opacity logits that were ±inf (read as opacity 1 or 0; NaN ones are dropped with
    /// the splat, as a finding).
    pub non_finite_opacities: usize,
    /// What the reader noticed, in file order. None of them stopped the load (a finding that
    /// does is the [`super::LoadError`]); `splatgl validate` lists the same findings.
    pub findings: Vec<Finding>,
    /// Container version, quantization, flags and lossy steps (quantized containers: SPZ,
    /// `.splat`, `.ksplat`, SOG, compressed PLY, glTF with SPZ compression).
    pub details: Option<Details>,
}

impl LoadReport {
    pub(crate) fn new(format: Format) -> Self {
        LoadReport {
            format,
            scale_space: None,
            non_unit_quaternions: 0,
            non_finite_opacities: 0,
            findings: Vec::new(),
            details: None,
        }
    }

    /// Whether the file says its splats were trained with antialiasing (SPZ header flag 0x1,
    /// also inside glTF SPZ payloads): what `--antialiased auto` follows.
    pub fn trained_antialiased(&self) -> bool {
        self.details.as_ref().is_some_and(|d| d.antialiased)
    }

    /// Every finding as one line ([`Finding::warning_line`]): the `warnings` of
    /// `splatgl info --json`.
    pub fn warning_lines(&self) -> Vec<String> {
        self.findings
            .iter()
            .filter(|f| f.severity != super::Severity::Info)
            .map(Finding::warning_line)
            .collect()
    }

    /// The [`Severity::Info`](super::Severity::Info) notes (normal trainer artefacts such as
    /// non-unit quaternions), one line each in the form of [`LoadReport::warning_lines`]
    /// (`info --json` key `notes`).
    pub fn note_lines(&self) -> Vec<String> {
        self.findings
            .iter()
            .filter(|f| f.severity == super::Severity::Info)
            .map(Finding::warning_line)
            .collect()
    }

    /// The warnings for people: identical messages merged into one line naming the first
    /// location and how many more there are, in first-seen order; without the
    /// [`Severity::Info`](super::Severity::Info) notes ([`LoadReport::summarized_notes`]).
    pub fn summarized_warnings(&self) -> Vec<String> {
        self.summarized(|s| s != super::Severity::Info)
    }

    /// The [`Severity::Info`](super::Severity::Info) notes, merged like
    /// [`LoadReport::summarized_warnings`].
    pub fn summarized_notes(&self) -> Vec<String> {
        self.summarized(|s| s == super::Severity::Info)
    }

    fn summarized(&self, keep: impl Fn(super::Severity) -> bool) -> Vec<String> {
        finding::collapse(&self.findings)
            .into_iter()
            .filter(|(f, _)| keep(f.severity))
            .map(|(f, n)| match n {
                1 => f.warning_line(),
                n => format!("{} (and {} more like it)", f.warning_line(), n - 1),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(findings: Vec<Finding>) -> LoadReport {
        LoadReport {
            findings,
            ..LoadReport::new(Format::Glb)
        }
    }

    #[test]
    fn warning_lines_keep_the_info_json_form() {
        let r = report(vec![
            Finding::error("meshes[0]", "bad").at(3),
            Finding::warning("", "whole file"),
            Finding::warning("vertex.rot_0..3", "odd"),
        ]);
        assert_eq!(
            r.warning_lines(),
            [
                "meshes[0] [index 3]: invalid per KHR_gaussian_splatting RC / glTF 2.0: bad",
                "whole file",
                "vertex.rot_0..3: odd",
            ]
        );
    }

    #[test]
    fn summarized_warnings_merge_repeats_of_one_severity_in_first_seen_order() {
        // nodes[1] says the same as the others, but as an error.
        let r = report(
            (0..4)
                .map(|i| match i {
                    1 => Finding::error(format!("nodes[{i}]"), "undefined"),
                    _ => Finding::warning(format!("nodes[{i}]"), "undefined"),
                })
                .collect(),
        );
        assert_eq!(
            r.summarized_warnings(),
            [
                "nodes[0]: undefined (and 2 more like it)",
                "nodes[1]: invalid per KHR_gaussian_splatting RC / glTF 2.0: undefined",
            ]
        );
    }
}

/// `--antialiased auto|on|off`: whether to draw with the antialiased kernel
/// ([`DrawSettings::antialiased`](crate::gl::DrawSettings::antialiased),
/// [`RenderOptions::antialiased`](crate::reference::RenderOptions::antialiased)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AntialiasMode {
    /// On when the file says its splats were trained with antialiasing (the SPZ flag,
    /// [`LoadReport::trained_antialiased`]), off otherwise (the default).
    #[default]
    Auto,
    /// Always the antialiased kernel.
    On,
    /// Always the plain 3DGS kernel.
    Off,
}

impl AntialiasMode {
    /// The kernel for a file whose [`LoadReport::trained_antialiased`] is `trained`:
    /// `true` = antialiased.
    pub fn resolve(self, trained: bool) -> bool {
        match self {
            AntialiasMode::Auto => trained,
            AntialiasMode::On => true,
            AntialiasMode::Off => false,
        }
    }
}
