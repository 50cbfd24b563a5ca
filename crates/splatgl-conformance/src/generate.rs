//! `splatgl conformance generate DIR`: writes the assets, their cameras, our reference images
//! and `manifest.json`, deriving each camera's tolerance and each asset's `catches`.

use super::assets::{AssetSpec, CameraSpec};
use super::isolation::{admit, admitted_errata};
use super::manifest::{AssetEntry, CameraEntry, Manifest, Tolerance};
use super::verdict::{measure, tolerance};
use super::{Erratum, HEIGHT, WIDTH, judge, model};
use glam::{DMat3, DQuat, DVec3};
use serde_json::json;
use splatgl::camera::Camera;
use splatgl::image::{Image, PngDepth};
use splatgl::load::{LoadOptions, load_bytes, validate::validate_bytes};
use splatgl::write::scene::{NodeTransform, PerspectiveCamera, SceneNode};
use std::path::{Path, PathBuf};

/// Why the suite could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// An asset does not do what it was designed for (a bug in the suite).
    #[error("asset {asset}: {message}")]
    Design {
        /// The asset.
        asset: String,
        /// What is wrong.
        message: String,
    },
}

/// Writes one file of the suite atomically (`write::write_bytes_atomic`: a failed or
/// interrupted write leaves the previous suite's file as it was).
fn write(path: &Path, bytes: &[u8]) -> Result<(), GenerateError> {
    let io = |source| GenerateError::Io {
        path: path.to_owned(),
        source,
    };
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    splatgl::write::write_bytes_atomic(path, &[], bytes).map_err(io)
}

/// Camera axes (right, up, back) of a look-at in glTF's convention (looking down −Z).
fn gltf_axes(c: &CameraSpec) -> DMat3 {
    let (eye, target, up) = (
        DVec3::from_array(c.eye),
        DVec3::from_array(c.target),
        DVec3::from_array(c.up),
    );
    let fwd = (target - eye).normalize();
    let right = fwd.cross(up).normalize();
    DMat3::from_cols(right, right.cross(fwd), -fwd)
}

/// How far from its tolerance an erratum's model must land for the prediction to be robust
/// to the renderer's own rounding: max error ×/÷ this factor, PSNR ± [`PSNR_MARGIN`] dB.
pub const ABS_MARGIN: f64 = 1.3;
/// See [`ABS_MARGIN`].
pub const PSNR_MARGIN: f64 = 2.0;

/// `Some(true)`: the image fails the tolerance clearly; `Some(false)`: it passes clearly;
/// `None`: it lands within the margins (the suite must not contain such a case).
fn verdict(img: &Image, want: &Image, bound: &[f64], t: &Tolerance) -> Option<bool> {
    let (c, ratio) = measure(img, want, bound);
    let r = ratio.max(c.max_abs as f64 / t.max_abs);
    if r > ABS_MARGIN || c.psnr < t.min_psnr - PSNR_MARGIN {
        Some(true)
    } else if r < 1.0 / ABS_MARGIN && c.psnr > t.min_psnr + PSNR_MARGIN {
        Some(false)
    } else {
        None
    }
}

fn margin_text(img: &Image, want: &Image, bound: &[f64], t: &Tolerance) -> String {
    let (c, ratio) = measure(img, want, bound);
    format!(
        "worst pixel at {ratio:.2} × its bound, max error {:.4} vs {:.4}, PSNR {:.1} vs {:.1} dB",
        c.max_abs, t.max_abs, c.psnr, t.min_psnr
    )
}

/// The asset's cameras as perspective camera nodes (roots, after the content).
fn add_cameras(doc: &mut splatgl::write::scene::SceneDoc, spec: &AssetSpec) {
    for c in &spec.cameras {
        let cam = doc.add_camera(PerspectiveCamera {
            yfov: c.yfov_deg.to_radians(),
            aspect_ratio: Some(WIDTH as f64 / HEIGHT as f64),
            znear: c.znear,
            zfar: None,
        });
        let r = DQuat::from_mat3(&gltf_axes(c)).normalize();
        let n = doc.add_node(SceneNode {
            name: Some(format!("camera {}", c.name)),
            camera: Some(cam),
            transform: NodeTransform::Trs {
                translation: c.eye,
                rotation: r.to_array(),
                scale: [1.0; 3],
            },
            ..Default::default()
        });
        doc.roots.push(n);
    }
}

fn design_error(spec: &AssetSpec, message: String) -> GenerateError {
    GenerateError::Design {
        asset: spec.name.to_owned(),
        message,
    }
}

/// Writes the asset's file (with its camera nodes), checks `rc_valid` against `splatgl
/// validate`, and loads it back as a renderer would; returns the file's name and the scene.
fn write_asset_file(
    dir: &Path,
    spec: &AssetSpec,
) -> Result<(String, splatgl::load::Scene), GenerateError> {
    let design = |m| design_error(spec, m);
    let mut doc = spec.doc.clone();
    add_cameras(&mut doc, spec);
    let ext = if spec.json { "gltf" } else { "glb" };
    let file = format!("assets/{}.{ext}", spec.name);
    let bytes = if spec.json {
        doc.to_gltf()
    } else {
        doc.to_glb()
    };
    write(&dir.join(&file), &bytes)?;
    let path = dir.join(&file);
    let valid = validate_bytes(&bytes, Some(&path), &LoadOptions::default());
    if (valid.status() == splatgl::load::validate::Status::Valid) != spec.rc_valid {
        let f: Vec<String> = valid.findings.iter().map(|f| f.to_string()).collect();
        return Err(design(format!(
            "rc_valid = {} but splatgl validate says {:?}: {f:?}",
            spec.rc_valid,
            valid.status()
        )));
    }
    let scene = load_bytes(&bytes, Some(&path), &LoadOptions::default())
        .map_err(|e| design(e.to_string()))?;
    if scene.cameras.len() != spec.cameras.len() {
        return Err(design(format!("{} cameras loaded", scene.cameras.len())));
    }
    Ok((file, scene))
}

/// Which errata the camera's tolerance catches (those the asset admits are skipped), and
/// that it detects its variants; an error when a verdict lands within the margin.
fn catches_of(
    spec: &AssetSpec,
    spec_cam: &CameraSpec,
    (cloud, cam): (&splatgl::SplatCloud, &Camera),
    (reference, bound, tolerance): (&Image, &[f64], &Tolerance),
) -> Result<Vec<Erratum>, GenerateError> {
    let admitted = admitted_errata(spec);
    let mut caught = Vec::new();
    for e in Erratum::ALL.into_iter().filter(|e| !admitted.contains(e)) {
        let img = model::render(cloud, cam, &[e]).image;
        match verdict(&img, reference, bound, tolerance) {
            Some(true) => caught.push(e),
            Some(false) => {}
            None => {
                return Err(design_error(
                    spec,
                    format!(
                        "camera {}: erratum {} lands within the margin of the tolerance ({})",
                        spec_cam.name,
                        e.letter(),
                        margin_text(&img, reference, bound, tolerance)
                    ),
                ));
            }
        }
    }
    for &v in spec.detects {
        let img = model::render_with(cloud, cam, &[], &[v]).image;
        if verdict(&img, reference, bound, tolerance) != Some(true) {
            return Err(design_error(
                spec,
                format!(
                    "camera {}: designed to detect {} but its model does not fail clearly ({})",
                    spec_cam.name,
                    v.name(),
                    margin_text(&img, reference, bound, tolerance)
                ),
            ));
        }
    }
    Ok(caught)
}

/// The camera's judged region, refused when two overlapping splats tie in distance (their
/// order would be f32 rounding's) or when less than 5 % of its pixels are judged.
fn judged_of(
    spec: &AssetSpec,
    spec_cam: &CameraSpec,
    cloud: &splatgl::SplatCloud,
    cam: &Camera,
) -> Result<Vec<bool>, GenerateError> {
    if let Some((i, j, d)) = judge::sort_tie(cloud, cam) {
        return Err(design_error(
            spec,
            format!(
                "camera {}: splats {i} and {j} overlap with distances {d:.1e} apart \
                 (a sort tie: their order is f32 rounding's)",
                spec_cam.name
            ),
        ));
    }
    let judged = judge::judged_region(cloud, cam, spec.tested());
    let share = judged.iter().filter(|&&j| j).count() as f64 / judged.len().max(1) as f64;
    if share < 0.05 {
        return Err(design_error(
            spec,
            format!(
                "camera {}: only {:.0} % of its pixels are judged (rims and overlaps whose \
                 order a renderer may choose cover the rest)",
                spec_cam.name,
                100.0 * share
            ),
        ));
    }
    Ok(judged)
}

/// Writes the camera's bound (`.bound.pfm`, in alpha) and judged region (`.judge.png`, white
/// where judged); returns the bound's image (f32, as the runner reads it back).
fn write_bound_and_mask(
    dir: &Path,
    spec: &AssetSpec,
    (bound_pfm, judge_mask): (&str, &str),
    exact: &model::ModelImage,
    judged: &[bool],
) -> Result<Image, GenerateError> {
    let mut bound_img = Image::filled(WIDTH, HEIGHT, [0.0; 4]);
    let mut mask_img = Image::filled(WIDTH, HEIGHT, [0.0, 0.0, 0.0, 1.0]);
    for ((p, m), (b, j)) in bound_img
        .pixels
        .iter_mut()
        .zip(&mut mask_img.pixels)
        .zip(exact.bound.iter().zip(judged))
    {
        p[3] = *b as f32;
        let v = if *j { 1.0 } else { 0.0 };
        *m = [v, v, v, 1.0];
    }
    write(&dir.join(bound_pfm), &bound_img.encode_pfm_alpha())?;
    let mask_png = mask_img.encode_png(PngDepth::Eight, false);
    let mask_png = mask_png.map_err(|e| design_error(spec, e.to_string()))?;
    write(&dir.join(judge_mask), &mask_png)?;
    Ok(bound_img)
}

/// One camera: writes its reference (PNG, PFM) and bound, derives its tolerance and what it
/// catches; returns the manifest entry, its `cameras.json` entry and the errata caught.
fn camera_entry(
    dir: &Path,
    spec: &AssetSpec,
    k: usize,
    spec_cam: &CameraSpec,
    g: &splatgl::camera::GltfPerspective,
    cloud: &splatgl::SplatCloud,
) -> Result<(CameraEntry, serde_json::Value, Vec<Erratum>), GenerateError> {
    let design = |m| design_error(spec, m);
    let cam = Camera::from_gltf(g, WIDTH, HEIGHT).map_err(|e| design(e.to_string()))?;
    let space = cloud.meta.color_space.effective();
    let opts = splatgl::reference::RenderOptions::default();
    let (reference, _) = splatgl::reference::render_display(cloud, &cam, &opts, space);
    let image = format!("{}/{}", spec.name, spec_cam.name);
    let (png, pfm) = (
        format!("reference/{image}.png"),
        format!("reference/{image}.pfm"),
    );
    let png_bytes = reference.encode_png(PngDepth::Eight, false);
    write(
        &dir.join(&png),
        &png_bytes.map_err(|e| design(e.to_string()))?,
    )?;
    write(&dir.join(&pfm), &reference.encode_pfm())?;
    let mut exact = model::render(cloud, &cam, &[]);
    admit(&mut exact, spec, cloud, &cam);
    let judged = judged_of(spec, spec_cam, cloud, &cam)?;
    let bound_pfm = format!("reference/{image}.bound.pfm");
    let judge_mask = format!("reference/{image}.judge.png");
    let bound_img = write_bound_and_mask(dir, spec, (&bound_pfm, &judge_mask), &exact, &judged)?;
    judge::apply(&mut exact.bound, &judged);
    let tolerance = tolerance(&exact);
    // The bound as the runner reads it back (f32), outside the judged region infinite.
    let mut bound: Vec<f64> = bound_img.pixels.iter().map(|p| p[3] as f64).collect();
    judge::apply(&mut bound, &judged);
    let caught = catches_of(
        spec,
        spec_cam,
        (cloud, &cam),
        (&reference, &bound, &tolerance),
    )?;
    let c2w = DMat3::from_mat4(cam.world_to_camera.as_dmat4()).transpose();
    let json_cam = json!({
        "id": k, "img_name": image, "width": WIDTH, "height": HEIGHT,
        "position": cam.eye().as_dvec3().to_array(),
        "rotation": [c2w.row(0).to_array(), c2w.row(1).to_array(), c2w.row(2).to_array()],
        "fx": cam.fx, "fy": cam.fy, "cx": cam.cx, "cy": cam.cy,
    });
    let entry = CameraEntry {
        name: spec_cam.name.to_owned(),
        gltf_camera: k,
        width: WIDTH,
        height: HEIGHT,
        image,
        reference_png: png,
        reference_pfm: pfm,
        bound_pfm,
        judge_mask,
        tolerance,
    };
    Ok((entry, json_cam, caught))
}

fn asset(dir: &Path, spec: &AssetSpec) -> Result<AssetEntry, GenerateError> {
    let (file, scene) = write_asset_file(dir, spec)?;
    let mut cameras = Vec::new();
    let mut json_cams = Vec::new();
    let mut catches = std::collections::BTreeSet::new();
    for (k, (spec_cam, g)) in spec.cameras.iter().zip(&scene.cameras).enumerate() {
        let (entry, json_cam, caught) = camera_entry(dir, spec, k, spec_cam, g, &scene.cloud)?;
        cameras.push(entry);
        json_cams.push(json_cam);
        catches.extend(caught);
    }
    if let Some(e) = spec.designed_for.iter().find(|e| !catches.contains(e)) {
        return Err(design_error(
            spec,
            format!(
                "designed to catch erratum {} but its model passes",
                e.letter()
            ),
        ));
    }
    let cameras_json = format!("assets/{}.cameras.json", spec.name);
    let text = serde_json::to_vec_pretty(&json_cams).unwrap_or_default();
    write(&dir.join(&cameras_json), &text)?;
    Ok(AssetEntry {
        name: spec.name.to_owned(),
        file,
        cameras_json,
        rule: spec.rule.to_owned(),
        rc_section: spec.section.to_owned(),
        failure_means: spec.failure_means.to_owned(),
        checks: spec.checks,
        detects: spec.detects.iter().map(|v| v.name().to_owned()).collect(),
        catches: catches.into_iter().collect(),
        optional: spec.optional,
        rc_valid: spec.rc_valid,
        cameras,
    })
}

/// Writes the suite into `dir` (created if needed): `manifest.json`, `assets/NAME.glb` (or
/// `.gltf`) with camera nodes, `assets/NAME.cameras.json`, `reference/NAME/CAMERA.png|pfm`.
pub fn generate(dir: &Path) -> Result<Manifest, GenerateError> {
    let specs = super::assets::all();
    let mut assets = Vec::new();
    let mut design = Vec::new();
    for spec in &specs {
        match asset(dir, spec) {
            Ok(a) => assets.push(a),
            Err(GenerateError::Design { asset, message }) => {
                design.push(format!("{asset}: {message}"))
            }
            Err(e) => return Err(e),
        }
    }
    if !design.is_empty() {
        return Err(GenerateError::Design {
            asset: format!("{} asset(s)", design.len()),
            message: design.join("; "),
        });
    }
    let m = Manifest {
        generator: format!("splatgl {}", env!("CARGO_PKG_VERSION")),
        rules_version: super::manifest::RULES_VERSION,
        background: [0.0; 3],
        assets,
    };
    let text = serde_json::to_vec_pretty(&m.to_json()).unwrap_or_default();
    write(&dir.join("manifest.json"), &text)?;
    Ok(m)
}
