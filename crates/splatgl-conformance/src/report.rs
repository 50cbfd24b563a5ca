//! `report.html` (self-contained: thumbnails embedded as data URIs, so the folder can be
//! zipped and shared) and `report.json`.

use super::diagnosis::Diagnosis;
use super::manifest::Checks;
use super::runner::{AssetResult, diagnosis};
use base64::Engine;
use serde_json::{Value, json};
use splatgl::compare::diff_image;
use splatgl::image::{Image, PngDepth};

/// Counts over a run. `passed` and `failed` count the required assets that check a rule of
/// the RC (`"checks": "rc"`), `skipped` the optional ones without images; the optional
/// assets rendered and the profile assets (choices the RC leaves open) are counted apart and
/// never fail a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Summary {
    /// RC assets that passed.
    pub passed: usize,
    /// Required RC assets that failed.
    pub failed: usize,
    /// Optional assets without images.
    pub skipped: usize,
    /// Profile assets whose images match splatgl's choice.
    pub profile_matched: usize,
    /// Profile assets whose images differ from it (informative: another RC-silent choice, or
    /// an error the RC assets do not see).
    pub profile_differ: usize,
    /// Optional assets rendered that pass.
    pub optional_passed: usize,
    /// Optional assets rendered that fail (informative: they never fail a run).
    pub optional_failed: usize,
}

/// Counts the results.
pub fn summary(results: &[AssetResult]) -> Summary {
    let mut s = Summary::default();
    for r in results {
        let profile = r.asset.checks == Checks::Profile;
        let count = match (r.skipped, r.asset.optional, profile, r.pass()) {
            (true, ..) => &mut s.skipped,
            (false, true, _, true) => &mut s.optional_passed,
            (false, true, _, false) => &mut s.optional_failed,
            (false, false, true, true) => &mut s.profile_matched,
            (false, false, true, false) => &mut s.profile_differ,
            (false, false, false, true) => &mut s.passed,
            (false, false, false, false) => &mut s.failed,
        };
        *count += 1;
    }
    s
}

fn num(v: Option<f64>) -> Value {
    match v {
        Some(x) if x.is_finite() => json!(x),
        _ => Value::Null,
    }
}

/// `report.json`: `diagnosis` (the smallest set of deviations that explains every failing
/// camera: `rule`, `rc_section`, `description`, `rc_allowed`, `assets`, `evidence`), `assets` (per asset `name`, `rule`, `checks`, `pass`, `psnr`, `max_abs`,
/// `skipped`, `catches`, `cause`, `cameras` with the same per camera plus the tolerance, `cause`
/// and `nearest`: the model an unexplained failure came nearest to, `rules`, `pixels_over`,
/// `worst_ratio`),
/// `passed`, `failed` (counts of the required RC assets), `skipped` (optional assets without
/// images), `optional` {`passed`, `failed`} (optional assets rendered), `profile` {`matched`,
/// `differ`}, `rules_version`, `source`.
pub fn to_json(results: &[AssetResult], source: &str) -> Value {
    let s = summary(results);
    let diagnosis = diagnosis(results);
    let assets: Vec<Value> = results
        .iter()
        .map(|r| {
            let cams: Vec<Value> = r
                .cameras
                .iter()
                .map(|c| {
                    json!({
                        "name": c.camera.name, "image": c.camera.image, "pass": c.pass,
                        "psnr": num(c.comparison.map(|x| x.psnr)),
                        "max_abs": num(c.comparison.map(|x| x.max_abs as f64)),
                        "tolerance": {"max_abs": c.camera.tolerance.max_abs,
                                      "min_psnr": c.camera.tolerance.min_psnr},
                        "cause": c.cause,
                        "nearest": c.closest.as_ref().map(|n| json!({
                            "rules": n.deviations.iter().map(|d| d.name()).collect::<Vec<_>>(),
                            "pixels_over": n.over, "worst_ratio": n.worst,
                        })),
                    })
                })
                .collect();
            json!({
                "name": r.asset.name, "rule": r.asset.rule, "rc_section": r.asset.rc_section,
                "checks": r.asset.checks.name(),
                "pass": !r.skipped && r.pass(), "skipped": r.skipped, "optional": r.asset.optional,
                "psnr": num(r.psnr()), "max_abs": num(r.max_abs()),
                "catches": r.asset.catches.iter().map(|e| e.letter()).collect::<Vec<_>>(),
                "cause": asset_cause(r, &diagnosis),
                "cameras": cams,
            })
        })
        .collect();
    json!({
        "source": source,
        "diagnosis": diagnosis.iter().map(diagnosis_json).collect::<Vec<_>>(),
        "passed": s.passed,
        "failed": s.failed,
        "skipped": s.skipped,
        "profile": {"matched": s.profile_matched, "differ": s.profile_differ},
        "optional": {"passed": s.optional_passed, "failed": s.optional_failed},
        "rules_version": super::manifest::RULES_VERSION,
        "assets": assets,
    })
}

/// A failing asset's `cause`: the deviations the diagnosis attributes its cameras to
/// (`explained by …`), or `unexplained:` with its stock hint; `null` when it passes or is
/// skipped.
fn asset_cause(r: &AssetResult, diagnosis: &[Diagnosis]) -> Value {
    if r.skipped || r.pass() {
        return Value::Null;
    }
    let named: Vec<String> = diagnosis
        .iter()
        .filter(|d| d.assets.contains(&r.asset.name))
        .map(|d| d.deviation.name())
        .collect();
    if named.is_empty() {
        json!(format!("unexplained: {}", r.asset.failure_means))
    } else {
        json!(format!("explained by {}", named.join(" + ")))
    }
}

/// One `diagnosis` entry: `rule`, `rc_section`, `description`, `rc_allowed`, `assets`,
/// `evidence` (per camera `image`, `psnr_reference`, `max_abs_reference`, `psnr_model`,
/// `max_abs_model`).
fn diagnosis_json(d: &Diagnosis) -> Value {
    let evidence: Vec<Value> = d
        .evidence
        .iter()
        .map(|e| {
            json!({
                "image": e.image,
                "psnr_reference": num(Some(e.reference.0)), "max_abs_reference": e.reference.1,
                "psnr_model": num(Some(e.model.0)), "max_abs_model": e.model.1,
            })
        })
        .collect();
    json!({
        "rule": d.deviation.name(), "rc_section": d.deviation.rc_section(),
        "description": d.deviation.describe(), "rc_allowed": d.deviation.rc_allowed(),
        "assets": d.assets, "evidence": evidence,
    })
}

/// The HTML list that leads the report: each deviation found, its RC section, the assets.
fn diagnosis_html(results: &[AssetResult]) -> String {
    let d = diagnosis(results);
    if d.is_empty() {
        return "<p id=\"diagnosis\">Diagnosis: no failure to explain.</p>\n".into();
    }
    let items: String = d
        .iter()
        .map(|x| {
            let worst = x
                .evidence
                .iter()
                .map(|e| e.reference.0)
                .fold(f64::INFINITY, f64::min);
            format!(
                "<li><b>{}</b> — {} <small>({})</small><br>assets: {}<br>\
                 <small>worst camera {worst:.1} dB against the reference; each explained camera \
                 passes against the model with this deviation</small></li>\n",
                esc(&x.deviation.name()),
                esc(&x.deviation.describe()),
                esc(&x.deviation.rc_section()),
                esc(&x.assets.join(", ")),
            )
        })
        .collect();
    format!("<h2>Diagnosis</h2>\n<ul id=\"diagnosis\">\n{items}</ul>\n")
}

fn data_uri(img: &Image) -> String {
    let png = img.encode_png(PngDepth::Eight, false).unwrap_or_default();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png)
    )
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `report.html`: one table row (`tr.result`) per camera.
pub fn to_html(results: &[AssetResult], source: &str) -> String {
    let s = summary(results);
    let mut rows = String::new();
    for r in results {
        for c in &r.cameras {
            let profile = r.asset.checks == Checks::Profile;
            let (status, class) = match (r.skipped, c.pass, profile) {
                (true, _, _) => ("skipped", "skip"),
                (false, true, false) => ("pass", "pass"),
                (false, false, false) => ("FAIL", "fail"),
                (false, true, true) => ("matches profile", "pass"),
                (false, false, true) => ("differs (profile, informative)", "skip"),
            };
            let img = |i: &Image| format!("<img src=\"{}\" alt=\"\">", data_uri(i));
            let actual = c.actual.as_ref().map_or("—".into(), img);
            let diff = c
                .actual
                .as_ref()
                .and_then(|a| diff_image(a, &c.expected, c.camera.tolerance.max_abs as f32).ok())
                .map_or("—".into(), |d| img(&d));
            let f = |v: Option<f64>, p: usize| v.map_or("—".into(), |x| format!("{x:.p$}"));
            let t = &c.camera.tolerance;
            rows += &format!(
                "<tr class=\"result {class}\"><td><b>{}</b><br>{}<br><small>{}</small></td>\
                 <td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
                 <td>{} dB<br><small>≥ {:.1}</small></td><td>{}<br><small>≤ {:.4}</small></td>\
                 <td class=\"{class}\">{status}</td><td>{}</td></tr>\n",
                esc(&r.asset.name),
                esc(&c.camera.name),
                esc(&r.asset.rule),
                esc(&r.asset.rc_section),
                img(&c.expected),
                actual,
                diff,
                f(c.comparison.map(|x| x.psnr), 1),
                t.min_psnr,
                f(c.comparison.map(|x| x.max_abs as f64), 4),
                t.max_abs,
                esc(c.cause.as_deref().unwrap_or("")),
            );
        }
    }
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>KHR_gaussian_splatting conformance report</title><style>\
         body{{font-family:sans-serif;margin:1em}} table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:4px;vertical-align:top;font-size:13px}}\
         td small{{color:#555}} img{{image-rendering:pixelated;width:128px}}\
         .pass{{color:#060}} .fail{{color:#b00;font-weight:bold}} .skip{{color:#777}}\
         </style></head><body>\n<h1>KHR_gaussian_splatting conformance report</h1>\n\
         {}<p id=\"summary\">{} passed, {} failed, {} skipped — images: {}</p>\n\
         <p id=\"profile\">Profile assets (choices the RC leaves open; informative, never a \
         failure): {} match splatgl's choice, {} differ.</p>\n\
         <p>Expected: splatgl's reference; diff: per-pixel error, white at the tolerance.</p>\n\
         <table id=\"results\"><thead><tr><th>asset / camera / rule</th><th>RC section</th>\
         <th>expected</th><th>actual</th><th>diff</th><th>PSNR</th><th>max error</th>\
         <th>result</th><th>likely cause</th></tr></thead><tbody>\n{rows}</tbody></table>\
         </body></html>\n",
        diagnosis_html(results),
        s.passed,
        s.failed,
        s.skipped,
        esc(source),
        s.profile_matched,
        s.profile_differ
    )
}
