//! Rendering the suite with splatgl's own backends (`conformance run --backend`), and with the
//! GL backend's erratum switches (the erratum proof).

use super::KitError;
use super::manifest::Manifest;
use splatgl::camera::Camera;
use splatgl::engine::Engine;
use splatgl::image::Image;
use splatgl::load::{LoadOptions, Scene, load_path};
use std::path::Path;

pub use splatgl::engine::Backend;

/// One asset loaded with its cameras at the manifest's image sizes.
pub fn load_asset(
    dir: &Path,
    m: &Manifest,
    asset: usize,
) -> Result<(Scene, Vec<Camera>), KitError> {
    let a = &m.assets[asset];
    let file = super::manifest::suite_path(dir, &a.file)?;
    let scene =
        load_path(file, &LoadOptions::default()).map_err(|e| KitError::Asset(e.to_string()))?;
    let cams = a
        .cameras
        .iter()
        .map(|c| {
            let g = scene
                .cameras
                .get(c.gltf_camera)
                .ok_or_else(|| format!("{}: no camera {}", a.file, c.gltf_camera))?;
            Camera::from_gltf(g, c.width, c.height).map_err(|e| e.to_string())
        })
        .collect::<Result<Vec<_>, String>>()
        .map_err(KitError::Asset)?;
    Ok((scene, cams))
}

/// Every camera's image, `(image path, image)` in manifest order.
pub type Images = Vec<(String, Image)>;

/// Renders the suite with `backend` (errata off): one [`Engine`] for every asset.
pub fn render_suite(dir: &Path, m: &Manifest, backend: Backend) -> Result<Images, KitError> {
    let mut engine = Engine::new(backend)?;
    let opts = splatgl::reference::RenderOptions {
        background: m.background.map(|v| v as f32),
        ..Default::default()
    };
    let mut out = Vec::new();
    for (i, a) in m.assets.iter().enumerate() {
        let (scene, cams) = load_asset(dir, m, i)?;
        engine.upload(&scene.cloud)?;
        for (c, cam) in a.cameras.iter().zip(&cams) {
            let (img, _) = engine.render(&scene.cloud, cam, &opts)?;
            out.push((c.image.clone(), img));
        }
    }
    Ok(out)
}

/// Renders the suite with the GL backend and `errata` switched in; `front_to_back` draws in
/// the reversed (appendix, erratum g) order. The erratum proof's (feature `testing`).
#[cfg(all(feature = "gl", feature = "testing"))]
pub fn render_suite_gl(
    dir: &Path,
    m: &Manifest,
    errata: splatgl::gl::Errata,
    front_to_back: bool,
) -> Result<Images, KitError> {
    let gl = |e: splatgl::headless::HeadlessError| KitError::Gl(e.to_string());
    let r = splatgl::headless::HeadlessRenderer::with_errata(errata).map_err(gl)?;
    render_suite_with(dir, m, r, front_to_back)
}

/// Renders the suite with `r`, in the reversed order when `front_to_back`.
#[cfg(all(feature = "gl", feature = "testing"))]
fn render_suite_with(
    dir: &Path,
    m: &Manifest,
    mut r: splatgl::headless::HeadlessRenderer,
    front_to_back: bool,
) -> Result<Images, KitError> {
    let gl = |e: splatgl::headless::HeadlessError| KitError::Gl(e.to_string());
    use splatgl::headless::{HeadlessOptions, TargetKind};
    // Blended as `conformance run --backend gl` blends (Engine::gl): in RGBA16F where the
    // context can render to it.
    let target = if r.context().can_render_rgba16f() {
        TargetKind::Rgba16fResolve
    } else {
        TargetKind::Rgba8
    };
    let opts = HeadlessOptions {
        target,
        background: m.background.map(|v| v as f32),
        ..Default::default()
    };
    let mut out = Vec::new();
    for (i, a) in m.assets.iter().enumerate() {
        let (scene, cams) = load_asset(dir, m, i)?;
        r.upload(&scene.cloud).map_err(gl)?;
        for (c, cam) in a.cameras.iter().zip(&cams) {
            let img = if front_to_back {
                let mut order = splatgl::sort::Sorter::new()
                    .sort_by_distance(&scene.cloud.positions, cam.eye().to_array())
                    .to_vec();
                order.reverse();
                r.render_with_order(cam, &opts, &order)
            } else {
                r.render(cam, &opts)
            };
            out.push((c.image.clone(), img.map_err(gl)?));
        }
    }
    Ok(out)
}
