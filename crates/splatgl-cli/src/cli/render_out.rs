//! Where `render` writes: the output pattern (`-o`, `{index}` for batches, `-` for stdout),
//! checked before anything is loaded (extension, folder, existing files), and the writing.

use splatgl::image::{Image, PngDepth};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

/// What the output is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// 8- or 16-bit PNG.
    Png,
    /// 32-bit float PFM (and NAME.alpha.pfm with --alpha).
    Pfm,
}

/// The output of a render: stdout (`-o -`, PNG) or files named by a pattern.
#[derive(Debug, Clone)]
pub struct Outputs {
    /// `None`: stdout.
    pattern: Option<String>,
    /// PNG or PFM.
    pub kind: Kind,
    /// 16-bit PNG.
    depth16: bool,
    /// Keep alpha.
    alpha: bool,
}

/// The placeholder of a batch's output pattern.
pub const INDEX: &str = "{index}";

impl Outputs {
    /// The outputs for `-o` (`None`: `out.png`, or `out_{index}.png` for a batch), refusing
    /// what cannot be written before any work is done: an extension other than .png/.pfm, a
    /// folder that does not exist, `--depth16` with .pfm, `-` for a batch or with
    /// `--print-camera-json` (both on stdout), a batch pattern without `{index}`.
    pub fn plan(
        output: Option<&Path>,
        batch: bool,
        depth16: bool,
        alpha: bool,
        print_json: bool,
    ) -> Result<Self, String> {
        let default = if batch { "out_{index}.png" } else { "out.png" };
        let name = output.map_or(default.into(), |p| p.to_string_lossy().into_owned());
        if name == "-" {
            if batch {
                return Err(
                    "-o - (stdout) takes one image; a batch needs -o NAME_{index}.png".into(),
                );
            }
            if print_json {
                return Err(
                    "-o - and --print-camera-json both write to stdout; give -o FILE".into(),
                );
            }
            if std::io::stdout().is_terminal() {
                return Err(
                    "-o -: stdout is a terminal; redirect it (> out.png) or pipe it".into(),
                );
            }
            return Ok(Outputs {
                pattern: None,
                kind: Kind::Png,
                depth16,
                alpha,
            });
        }
        let path = Path::new(&name);
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let kind = match ext.to_ascii_lowercase().as_str() {
            "png" => Kind::Png,
            "pfm" => Kind::Pfm,
            _ => {
                return Err(format!(
                    "{name}: output must end in .png or .pfm (or be - for stdout)"
                ));
            }
        };
        if depth16 && kind == Kind::Pfm {
            return Err(format!(
                "--depth16 applies to .png outputs; {name} is a float .pfm already"
            ));
        }
        if batch && !name.contains(INDEX) {
            return Err(format!(
                "-o {name}: a batch writes several images; put {INDEX} in the name (e.g. -o out_{INDEX}.png)"
            ));
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
            && !dir.is_dir()
        {
            return Err(format!(
                "{name}: the folder {} does not exist",
                dir.display()
            ));
        }
        Ok(Outputs {
            pattern: Some(name),
            kind,
            depth16,
            alpha,
        })
    }

    /// The file of image `index` (`None`: stdout).
    pub fn path(&self, index: usize) -> Option<PathBuf> {
        self.pattern
            .as_ref()
            .map(|p| PathBuf::from(p.replace(INDEX, &index.to_string())))
    }

    /// How the output is named in messages.
    pub fn describe(&self, index: usize) -> String {
        self.path(index)
            .map_or("stdout".into(), |p| p.display().to_string())
    }

    /// Every file images `0..n` write (with the `.alpha.pfm` side files).
    fn files(&self, n: usize) -> Vec<PathBuf> {
        let mut v = Vec::new();
        for i in 0..n {
            if let Some(p) = self.path(i) {
                if self.alpha && self.kind == Kind::Pfm {
                    v.push(p.with_extension("alpha.pfm"));
                }
                v.push(p);
            }
        }
        v
    }

    /// Refuses, for images `0..n`, a file that is one of `inputs` (even with `force`) and an
    /// existing file without `force`.
    pub fn check_files(&self, n: usize, inputs: &[&Path], force: bool) -> Result<(), String> {
        for out in self.files(n) {
            splatgl::write::refuse_overwriting_inputs(&out, inputs)
                .map_err(|e| format!("{}: {e}", out.display()))?;
            if !force && out.exists() {
                return Err(format!(
                    "{} exists; pass -f/--force to overwrite it",
                    out.display()
                ));
            }
        }
        Ok(())
    }

    /// Writes image `index`.
    pub fn write(&self, img: &Image, index: usize) -> Result<(), String> {
        let depth = if self.depth16 {
            PngDepth::Sixteen
        } else {
            PngDepth::Eight
        };
        let Some(path) = self.path(index) else {
            let bytes = img
                .encode_png(depth, self.alpha)
                .map_err(|e| e.to_string())?;
            let mut out = std::io::stdout().lock();
            return out
                .write_all(&bytes)
                .and_then(|()| out.flush())
                .map_err(|e| format!("stdout: {e}"));
        };
        let r = match self.kind {
            Kind::Png => img.write_png(&path, depth, self.alpha),
            Kind::Pfm => img.write_pfm(&path).and_then(|()| {
                if self.alpha {
                    img.write_pfm_alpha(path.with_extension("alpha.pfm"))
                } else {
                    Ok(())
                }
            }),
        };
        r.map_err(|e| e.to_string())
    }
}
