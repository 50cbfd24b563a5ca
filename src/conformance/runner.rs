//! Comparing a set of images with the suite's references, per the manifest's tolerances, and
//! naming the likely cause of known failure patterns.

use super::generate::{clamped, fails, measure};
use super::manifest::{AssetEntry, CameraEntry, Manifest, suite_path};
use super::{Erratum, model, render};
use crate::compare::{Comparison, compare};
use crate::image::Image;
use std::path::Path;

/// The outcome of one camera.
#[derive(Debug, Clone)]
pub struct CameraResult {
    /// The manifest's entry.
    pub camera: CameraEntry,
    /// The comparison (`None` when the image is missing or unusable).
    pub comparison: Option<Comparison>,
    /// Within tolerance.
    pub pass: bool,
    /// The likely cause of a failure.
    pub cause: Option<String>,
    /// Expected (reference) and actual images (clamped), for the report.
    pub expected: Image,
    /// The image compared (`None` when missing).
    pub actual: Option<Image>,
}

/// The outcome of one asset: passes when every camera passes.
#[derive(Debug, Clone)]
pub struct AssetResult {
    /// The manifest's entry.
    pub asset: AssetEntry,
    /// Per camera.
    pub cameras: Vec<CameraResult>,
    /// Optional asset without images: not counted.
    pub skipped: bool,
}

impl AssetResult {
    /// All cameras pass.
    pub fn pass(&self) -> bool {
        self.cameras.iter().all(|c| c.pass)
    }
    /// Lowest PSNR over the cameras (`None` if any image is missing).
    pub fn psnr(&self) -> Option<f64> {
        self.cameras
            .iter()
            .map(|c| c.comparison.map(|x| x.psnr))
            .try_fold(f64::INFINITY, |a, p| p.map(|p| a.min(p)))
    }
    /// Largest error over the cameras.
    pub fn max_abs(&self) -> Option<f64> {
        self.cameras
            .iter()
            .map(|c| c.comparison.map(|x| x.max_abs as f64))
            .try_fold(0.0f64, |a, p| p.map(|p| a.max(p)))
    }
}

/// Where another renderer's image for `c` is: `IMAGES/ASSET/CAMERA.pfm`, else `.png` (inside
/// `images`: see [`suite_path`]).
pub fn find_image(images: &Path, c: &CameraEntry) -> Option<std::path::PathBuf> {
    ["pfm", "png"]
        .iter()
        .filter_map(|e| suite_path(images, &format!("{}.{e}", c.image)).ok())
        .find(|p| p.is_file())
}

fn flipped(img: &Image, vertical: bool) -> Image {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut out = img.clone();
    for y in 0..h {
        for x in 0..w {
            let (sx, sy) = if vertical {
                (x, h - 1 - y)
            } else {
                (w - 1 - x, y)
            };
            out.pixels[y * w + x] = img.pixels[sy * w + sx];
        }
    }
    out
}

/// The likely cause of a failing camera: a flipped image, an erratum whose model the image
/// matches, else the asset's `failure_means`.
fn cause(
    dir: &Path,
    m: &Manifest,
    (ai, ci): (usize, usize),
    actual: &Image,
    want: &Image,
    bound: &[f64],
) -> String {
    let a = &m.assets[ai];
    let t = &a.cameras[ci].tolerance;
    if !fails(&flipped(actual, true), want, bound, t) {
        return "the image is upside down (rows not flipped after a GL read-back, or y up vs down)"
            .into();
    }
    if !fails(&flipped(actual, false), want, bound, t) {
        return "the image is mirrored left-right (handedness or x axis flipped)".into();
    }
    if let Ok((scene, cams)) = render::load_asset(dir, m, ai) {
        for e in Erratum::ALL {
            let model = model::render(&scene.cloud, &cams[ci], &[e]).image;
            if !fails(actual, &model, bound, t) {
                return format!(
                    "matches review-draft erratum {}: {}",
                    e.letter(),
                    e.describe()
                );
            }
        }
    }
    a.failure_means.clone()
}

fn over_bound(a: &Image, b: &Image, bound: &[f64]) -> usize {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .zip(bound)
        .filter(|((p, q), bd)| {
            (0..3).any(|k| {
                let e = (p[k] - q[k]).abs() as f64;
                e.is_nan() || e > **bd
            })
        })
        .count()
}

/// Compares the images `get(camera)` returns (`None`: missing; `Err`: unreadable) with the
/// references in `dir`. `Err` only when a reference cannot be read (a broken suite).
pub fn run(
    dir: &Path,
    m: &Manifest,
    mut get: impl FnMut(&CameraEntry) -> Option<Result<Image, String>>,
) -> Result<Vec<AssetResult>, String> {
    let mut results = Vec::new();
    for (ai, a) in m.assets.iter().enumerate() {
        let mut cams = Vec::new();
        let mut missing = 0;
        for (ci, c) in a.cameras.iter().enumerate() {
            let want =
                Image::read(suite_path(dir, &c.reference_pfm)?).map_err(|e| e.to_string())?;
            let want = clamped(&want);
            let bound: Vec<f64> = Image::read(suite_path(dir, &c.bound_pfm)?)
                .map_err(|e| e.to_string())?
                .pixels
                .iter()
                .map(|p| p[0] as f64)
                .collect();
            if bound.len() != want.pixels.len() {
                return Err(format!("{}: wrong size", c.bound_pfm));
            }
            let got = get(c);
            let (comparison, pass, cause_text, actual) = match got {
                None => {
                    missing += 1;
                    let why = format!("no image {}.png or {}.pfm", c.image, c.image);
                    (None, false, Some(why), None)
                }
                Some(Err(e)) => (None, false, Some(format!("unreadable image: {e}")), None),
                Some(Ok(img)) if (img.width, img.height) != (c.width, c.height) => {
                    let why = format!(
                        "image is {}x{}, expected {}x{}",
                        img.width, img.height, c.width, c.height
                    );
                    (None, false, Some(why), Some(clamped(&img)))
                }
                Some(Ok(img)) => {
                    let img = clamped(&img);
                    let (_, ratio) = measure(&img, &want, &bound);
                    let cmp = compare(&img, &want, 1.0 / 255.0).map_err(|e| e.to_string())?;
                    let t = &c.tolerance;
                    let pass =
                        ratio <= 1.0 && cmp.max_abs as f64 <= t.max_abs && cmp.psnr >= t.min_psnr;
                    let why = (!pass).then(|| {
                        let over = format!(
                            "{} pixels over their bound (worst {ratio:.2}×); ",
                            over_bound(&img, &want, &bound)
                        );
                        over + &cause(dir, m, (ai, ci), &img, &want, &bound)
                    });
                    (Some(cmp), pass, why, Some(img))
                }
            };
            cams.push(CameraResult {
                camera: c.clone(),
                comparison,
                pass,
                cause: cause_text,
                expected: want,
                actual,
            });
        }
        results.push(AssetResult {
            asset: a.clone(),
            skipped: a.optional && missing == a.cameras.len(),
            cameras: cams,
        });
    }
    Ok(results)
}
