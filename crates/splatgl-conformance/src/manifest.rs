//! `manifest.json`: the suite's table of contents, read by the runner (and by other
//! implementations' scripts: the keys are a contract, listed in `docs/conformance.md`).

use super::Erratum;
use super::model::Terms;
use serde_json::{Value, json};

/// Per-camera thresholds, derived from the asset's content ([`super::model`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Largest allowed absolute RGB error of any pixel (display values, 0..1).
    pub max_abs: f64,
    /// Smallest allowed PSNR (dB, peak 1).
    pub min_psnr: f64,
    /// The worst value of each error term over the image (what `max_abs` is made of).
    pub terms: Terms,
}

/// One camera of an asset: a glTF camera node and a `cameras.json` entry, and one image.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraEntry {
    /// Name (the image's file stem).
    pub name: String,
    /// Index among the asset's perspective camera nodes (= index in its `cameras.json`).
    pub gltf_camera: usize,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The image's path without extension, relative to an images folder: `ASSET/CAMERA`.
    pub image: String,
    /// Our reference, 8-bit sRGB PNG, relative to the suite folder.
    pub reference_png: String,
    /// Our reference, float PFM, relative to the suite folder (what the runner compares to).
    pub reference_pfm: String,
    /// Per-pixel error bound (grey PFM, relative to the suite folder): a pixel whose error
    /// exceeds its bound fails the camera.
    pub bound_pfm: String,
    /// The judged region (a PNG beside `bound_pfm`, relative to the suite folder):
    /// white pixels are judged; black ones are where a choice the asset does not test (a
    /// splat's rim between 2.83σ and where its α falls below 1/1020, two overlapping splats
    /// whose distance and view-depth orders disagree) can move the image, reported but never
    /// failing the camera ([`super::judge`]).
    pub judge_mask: String,
    /// Pass thresholds.
    pub tolerance: Tolerance,
}

/// What an asset checks: a rule of the RC, or a choice the RC leaves open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Checks {
    /// A rule of the Release Candidate (`"checks": "rc"`): a failure fails the run.
    #[default]
    Rc,
    /// A choice the RC leaves to the renderer, here splatgl's profile (3DGS's choice; `"checks":
    /// "profile"`): reported apart, informative, never fails a run.
    Profile,
}

impl Checks {
    /// The manifest's spelling: `rc` or `profile`.
    pub fn name(self) -> &'static str {
        match self {
            Checks::Rc => "rc",
            Checks::Profile => "profile",
        }
    }
}

/// One asset.
#[derive(Debug, Clone, PartialEq)]
pub struct AssetEntry {
    /// Name (names the rule).
    pub name: String,
    /// The glTF file, relative to the suite folder.
    pub file: String,
    /// Its cameras as a 3DGS `cameras.json`, relative to the suite folder.
    pub cameras_json: String,
    /// The rule it checks.
    pub rule: String,
    /// RC section.
    pub rc_section: String,
    /// What a failure usually means.
    pub failure_means: String,
    /// A rule of the RC or a profile choice.
    pub checks: Checks,
    /// Errata on which a renderer fails this asset (derived, see [`super::model`]).
    pub catches: Vec<Erratum>,
    /// Implementation variants this asset is designed to detect (their
    /// [`super::model::Variant::name`]s); every other asset's bound admits them.
    pub detects: Vec<String>,
    /// Not required of RC implementations.
    pub optional: bool,
    /// Valid per the RC (`splatgl validate` passes it).
    pub rc_valid: bool,
    /// Cameras.
    pub cameras: Vec<CameraEntry>,
}

/// The whole manifest.
#[derive(Debug, Clone, PartialEq)]
pub struct Manifest {
    /// Who wrote it (`splatgl X.Y.Z`).
    pub generator: String,
    /// The version of the verdict rules the suite was generated for ([`RULES_VERSION`]);
    /// the runner refuses another.
    pub rules_version: u32,
    /// Background every image is rendered over (display RGB).
    pub background: [f64; 3],
    /// Assets.
    pub assets: Vec<AssetEntry>,
}

/// The version of the verdict rules (`docs/conformance.md`, "The verdict rules"): written
/// into `manifest.json` and `report.json`; a suite of another version must be generated again.
/// 3: judged regions (`judge_mask`), the early-stop term, `unknown_kernel` a profile asset.
pub const RULES_VERSION: u32 = 3;

fn terms_json(t: &Terms) -> Value {
    json!({
        "output_quantization": t.output, "blend_rounding": t.blend, "cutoff_edge": t.cutoff,
        "alpha_threshold": t.threshold, "alpha_cap": t.cap, "sh_f16": t.sh_f16,
        "overbright": t.overbright, "float": t.float, "early_stop": t.early_stop,
        "dilation": t.dilation,
        "colour_8bit": t.colour_8bit, "covariance_f16": t.covariance_f16,
        "eigenvalue_floor": t.eigenvalue_floor, "combined": t.combined,
    })
}

/// The terms as written by [`terms_json`]; a missing key is an error naming it.
fn terms_from_json(v: &Value) -> Result<Terms, String> {
    let mut missing = None;
    let mut f = |k: &'static str| {
        v[k].as_f64().unwrap_or_else(|| {
            missing.get_or_insert(k);
            0.0
        })
    };
    let t = Terms {
        output: f("output_quantization"),
        blend: f("blend_rounding"),
        cutoff: f("cutoff_edge"),
        threshold: f("alpha_threshold"),
        cap: f("alpha_cap"),
        sh_f16: f("sh_f16"),
        overbright: f("overbright"),
        float: f("float"),
        early_stop: f("early_stop"),
        dilation: f("dilation"),
        colour_8bit: f("colour_8bit"),
        covariance_f16: f("covariance_f16"),
        eigenvalue_floor: f("eigenvalue_floor"),
        combined: f("combined"),
    };
    match missing {
        Some(k) => Err(format!(
            "manifest: `tolerance.terms.{k}` missing or not a number"
        )),
        None => Ok(t),
    }
}

impl Manifest {
    /// The JSON text.
    pub fn to_json(&self) -> Value {
        let assets: Vec<Value> = self
            .assets
            .iter()
            .map(|a| {
                let cams: Vec<Value> = a
                    .cameras
                    .iter()
                    .map(|c| {
                        json!({
                            "name": c.name, "gltf_camera": c.gltf_camera,
                            "cameras_json_index": c.gltf_camera,
                            "width": c.width, "height": c.height, "image": c.image,
                            "reference_png": c.reference_png, "reference_pfm": c.reference_pfm,
                            "bound_pfm": c.bound_pfm, "judge_mask": c.judge_mask,
                            "tolerance": {
                                "max_abs": c.tolerance.max_abs, "min_psnr": c.tolerance.min_psnr,
                                "terms": terms_json(&c.tolerance.terms),
                            },
                        })
                    })
                    .collect();
                json!({
                    "name": a.name, "file": a.file, "cameras_json": a.cameras_json,
                    "rule": a.rule, "rc_section": a.rc_section, "checks": a.checks.name(),
                    "failure_means": a.failure_means,
                    "catches": a.catches.iter().map(|e| e.letter()).collect::<Vec<_>>(),
                    "detects": a.detects,
                    "optional": a.optional, "rc_valid": a.rc_valid, "cameras": cams,
                })
            })
            .collect();
        json!({
            "suite": "KHR_gaussian_splatting conformance",
            "spec": "KHR_gaussian_splatting, Release Candidate",
            "generator": self.generator,
            "rules_version": self.rules_version,
            "background": self.background,
            "color": "display-referred RGB (sRGB-encoded for lin_rec709_display), over the background, clamped to [0, 1]",
            "assets": assets,
        })
    }

    /// Parses a manifest; the error names the key.
    pub fn from_json(v: &Value) -> Result<Manifest, crate::KitError> {
        Self::parse(v).map_err(crate::KitError::Manifest)
    }

    fn parse(v: &Value) -> Result<Manifest, String> {
        let mut assets = Vec::new();
        for a in list(v, "assets")? {
            assets.push(asset_from_json(&a)?);
        }
        let bg = list(v, "background")?;
        let bgv: Vec<f64> = bg.iter().filter_map(Value::as_f64).collect();
        if bgv.len() != 3 {
            return Err("manifest: `background` must be 3 numbers".into());
        }
        let rules_version = v["rules_version"].as_u64().unwrap_or(0) as u32;
        if rules_version != RULES_VERSION {
            return Err(format!(
                "manifest: `rules_version` is {rules_version}, this splatgl judges by rules \
                 version {RULES_VERSION}: generate the suite again with this splatgl"
            ));
        }
        Ok(Manifest {
            rules_version,
            generator: string(v, "generator")?,
            background: [bgv[0], bgv[1], bgv[2]],
            assets,
        })
    }

    /// Reads `DIR/manifest.json`: a regular file within the default `max_bytes`, nested at
    /// most `max_json_depth` deep (like every file splatgl reads).
    pub fn read(dir: &std::path::Path) -> Result<Manifest, crate::KitError> {
        let p = dir.join("manifest.json");
        let limits = splatgl::load::Limits::default();
        let err =
            |e: &dyn std::fmt::Display| crate::KitError::Manifest(format!("{}: {e}", p.display()));
        let text = splatgl::files::read_bounded(&p, limits.max_bytes, "the manifest")
            .map_err(|e| err(&e))?;
        splatgl::load::check_json(&text, &limits).map_err(|e| err(&e))?;
        let v: Value = serde_json::from_slice(&text).map_err(|e| err(&e))?;
        Manifest::from_json(&v)
    }
}

/// A file the manifest names (`file`, `reference_pfm`, `bound_pfm`, an `image` under
/// `--images`), resolved inside `dir` by the containment rule every document's files follow
/// (`..`, absolute paths and symlinks out of the folder are refused; the file must exist).
pub fn suite_path(dir: &std::path::Path, rel: &str) -> Result<std::path::PathBuf, crate::KitError> {
    splatgl::files::contained_path(dir, std::path::Path::new(rel), false).map_err(|source| {
        crate::KitError::File {
            rel: rel.to_owned(),
            source,
        }
    })
}

/// The string at key `k` of `v`.
fn string(v: &Value, k: &str) -> Result<String, String> {
    v[k].as_str()
        .map(str::to_owned)
        .ok_or_else(|| format!("manifest: `{k}` missing or not a string"))
}

/// The number at key `k` of `v`.
fn number(v: &Value, k: &str) -> Result<f64, String> {
    v[k].as_f64()
        .ok_or_else(|| format!("manifest: `{k}` missing or not a number"))
}

/// The array at key `k` of `v`.
fn list(v: &Value, k: &str) -> Result<Vec<Value>, String> {
    v[k].as_array()
        .cloned()
        .ok_or_else(|| format!("manifest: `{k}` missing or not an array"))
}

/// One asset of the manifest, its cameras first (the error names the key).
fn asset_from_json(a: &Value) -> Result<AssetEntry, String> {
    let mut cameras = Vec::new();
    for c in list(a, "cameras")? {
        cameras.push(camera_from_json(&c)?);
    }
    let catches = list(a, "catches")?
        .iter()
        .map(|e| {
            e.as_str()
                .and_then(Erratum::from_letter)
                .ok_or_else(|| format!("manifest: unknown erratum {e}"))
        })
        .collect::<Result<_, _>>()?;
    let checks = checks_from_json(a)?;
    let detects = a["detects"]
        .as_array()
        .map(|l| {
            l.iter()
                .filter_map(|x| x.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default();
    Ok(AssetEntry {
        checks,
        detects,
        name: string(a, "name")?,
        file: string(a, "file")?,
        cameras_json: string(a, "cameras_json")?,
        rule: string(a, "rule")?,
        rc_section: string(a, "rc_section")?,
        failure_means: string(a, "failure_means")?,
        catches,
        optional: a["optional"].as_bool().unwrap_or(false),
        rc_valid: a["rc_valid"].as_bool().unwrap_or(true),
        cameras,
    })
}

/// An asset's `checks`: `rc` (also when absent) or `profile`.
fn checks_from_json(a: &Value) -> Result<Checks, String> {
    match a["checks"].as_str() {
        None | Some("rc") => Ok(Checks::Rc),
        Some("profile") => Ok(Checks::Profile),
        Some(other) => Err(format!(
            "manifest: `checks` is {other:?}, expected \"rc\" or \"profile\""
        )),
    }
}

/// One camera of an asset, with its tolerance.
fn camera_from_json(c: &Value) -> Result<CameraEntry, String> {
    let t = &c["tolerance"];
    Ok(CameraEntry {
        name: string(c, "name")?,
        gltf_camera: number(c, "gltf_camera")? as usize,
        width: number(c, "width")? as u32,
        height: number(c, "height")? as u32,
        image: string(c, "image")?,
        reference_png: string(c, "reference_png")?,
        reference_pfm: string(c, "reference_pfm")?,
        bound_pfm: string(c, "bound_pfm")?,
        judge_mask: string(c, "judge_mask")?,
        tolerance: Tolerance {
            max_abs: number(t, "max_abs")?,
            min_psnr: number(t, "min_psnr")?,
            terms: terms_from_json(&t["terms"])?,
        },
    })
}
