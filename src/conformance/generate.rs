//! `splatgl conformance generate DIR`: writes the assets, their cameras, our reference images
//! and `manifest.json`, deriving each camera's tolerance and each asset's `catches`.

use super::assets::{AssetSpec, CameraSpec};
use super::manifest::{AssetEntry, CameraEntry, Manifest, Tolerance};
use super::{Erratum, HEIGHT, WIDTH, model};
use crate::camera::Camera;
use crate::compare::compare;
use crate::image::{Image, PngDepth};
use crate::load::{LoadOptions, load_bytes, validate::validate_bytes};
use crate::write::scene::{NodeTransform, PerspectiveCamera, SceneNode};
use glam::{DMat3, DQuat, DVec3};
use serde_json::json;
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

fn write(path: &Path, bytes: &[u8]) -> Result<(), GenerateError> {
    let io = |source| GenerateError::Io {
        path: path.to_owned(),
        source,
    };
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    std::fs::write(path, bytes).map_err(io)
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

/// Whether the model's image with an erratum fails this camera's tolerance against `want`.
pub(crate) fn fails(img: &Image, want: &Image, t: &Tolerance) -> bool {
    let c = compare(&clamped(img), &clamped(want), 0.0).expect("same size");
    c.max_abs as f64 > t.max_abs || c.psnr < t.min_psnr
}

/// RGB clamped to [0, 1] (what a display and an 8-bit file hold).
pub(crate) fn clamped(img: &Image) -> Image {
    let mut out = img.clone();
    for p in &mut out.pixels {
        for c in &mut p[..3] {
            *c = c.clamp(0.0, 1.0);
        }
    }
    out
}

/// The tolerance from the model's per-pixel bound: `max_abs` is the largest bound, and if
/// every pixel's error is within its bound the MSE is at most the mean squared bound.
fn tolerance(m: &model::ModelImage) -> Tolerance {
    let max_abs = m.bound.iter().copied().fold(0.0, f64::max);
    let mse = m.bound.iter().map(|b| b * b).sum::<f64>() / m.bound.len().max(1) as f64;
    Tolerance {
        max_abs,
        min_psnr: 10.0 * (1.0 / mse).log10(),
        terms: m.worst,
    }
}

fn asset(dir: &Path, spec: &AssetSpec) -> Result<AssetEntry, GenerateError> {
    let design = |message: String| GenerateError::Design {
        asset: spec.name.to_owned(),
        message,
    };
    let mut doc = spec.doc.clone();
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
    if (valid.status() == crate::load::validate::Status::Valid) != spec.rc_valid {
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
    let cloud = &scene.cloud;
    let space = cloud.meta.color_space.effective();
    let mut cameras = Vec::new();
    let mut json_cams = Vec::new();
    let mut catches = std::collections::BTreeSet::new();
    for (k, (spec_cam, g)) in spec.cameras.iter().zip(&scene.cameras).enumerate() {
        let cam = Camera::from_gltf(g, WIDTH, HEIGHT).map_err(|e| design(e.to_string()))?;
        let opts = crate::reference::RenderOptions::default();
        let (reference, _) = crate::reference::render_display(cloud, &cam, &opts, space);
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
        let tolerance = tolerance(&model::render(cloud, &cam, &[]));
        for e in Erratum::ALL {
            if fails(
                &model::render(cloud, &cam, &[e]).image,
                &reference,
                &tolerance,
            ) {
                catches.insert(e);
            }
        }
        let c2w = DMat3::from_mat4(cam.world_to_camera.as_dmat4()).transpose();
        json_cams.push(json!({
            "id": k, "img_name": image, "width": WIDTH, "height": HEIGHT,
            "position": cam.eye().as_dvec3().to_array(),
            "rotation": [c2w.row(0).to_array(), c2w.row(1).to_array(), c2w.row(2).to_array()],
            "fx": cam.fx, "fy": cam.fy, "cx": cam.cx, "cy": cam.cy,
        }));
        cameras.push(CameraEntry {
            name: spec_cam.name.to_owned(),
            gltf_camera: k,
            width: WIDTH,
            height: HEIGHT,
            image,
            reference_png: png,
            reference_pfm: pfm,
            tolerance,
        });
    }
    if let Some(e) = spec.designed_for.iter().find(|e| !catches.contains(e)) {
        return Err(design(format!(
            "designed to catch erratum {} but its model passes",
            e.letter()
        )));
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
    let assets = specs
        .iter()
        .map(|s| asset(dir, s))
        .collect::<Result<Vec<_>, _>>()?;
    let m = Manifest {
        generator: format!("splatgl {}", env!("CARGO_PKG_VERSION")),
        background: [0.0; 3],
        assets,
    };
    let text = serde_json::to_vec_pretty(&m.to_json()).unwrap_or_default();
    write(&dir.join("manifest.json"), &text)?;
    Ok(m)
}
