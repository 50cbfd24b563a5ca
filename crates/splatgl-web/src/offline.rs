//! What the page renders besides its frames: the default view of what is loaded, and one
//! image of it as a PNG (`scripts/web.sh render`, the conformance adapter).

use super::*;

#[wasm_bindgen]
impl Renderer {
    /// The default view of what is loaded at `width` × `height` (what `splatgl render` picks
    /// without camera options: the default scene's own view, else the cloud framed), as 10
    /// numbers: eye (3), target (3), up (3), vertical field of view in degrees.
    pub fn default_view(&self, width: u32, height: u32) -> Result<Vec<f32>, JsError> {
        let cam = self.default_camera(width, height)?;
        let eye = cam.eye();
        let inv = cam.world_to_camera.inverse();
        // OpenCV axes: +z forward, −y up.
        let forward = inv.transform_vector3(Vec3::Z);
        let up = -inv.transform_vector3(Vec3::Y);
        let fov = 2.0 * (0.5 * cam.height as f32 / cam.fy).atan();
        let target = eye + forward;
        Ok([eye, target, up]
            .iter()
            .flat_map(|v| v.to_array())
            .chain([fov.to_degrees()])
            .collect())
    }

    fn default_camera(&self, width: u32, height: u32) -> Result<Camera, JsError> {
        let l = self
            .loaded
            .as_ref()
            .ok_or_else(|| JsError::new("nothing is loaded"))?;
        let opts = ViewOptions {
            width: Some(width),
            height: Some(height),
            ..ViewOptions::default()
        };
        let scene = SceneView {
            cloud: &l.cloud,
            format: l.format,
            cameras: &l.cameras,
        };
        opts.camera(scene, (width, height)).map_err(js_error)
    }

    /// Renders what is loaded as `splatgl render --backend gl` does (blending in RGBA16F, the
    /// framebuffer the RC recommends) and returns an 8-bit RGB PNG: seen by glTF camera node
    /// `gltf_camera` of the file, or with `gltf_camera` < 0 by the default view
    /// ([`Renderer::default_view`]), at `width` × `height`, over `background` (RGB, 0–1).
    /// The canvas is left as it was (the image is drawn off screen).
    pub fn render_png(
        &mut self,
        gltf_camera: i32,
        width: u32,
        height: u32,
        r: f32,
        g: f32,
        b: f32,
    ) -> Result<Vec<u8>, JsError> {
        self.live()?;
        if width == 0 || height == 0 || width > 8192 || height > 8192 {
            return Err(JsError::new(&format!(
                "image size {width}×{height}: each side must be 1–8192"
            )));
        }
        let camera = if gltf_camera < 0 {
            self.default_camera(width, height)?
        } else {
            let l = self
                .loaded
                .as_ref()
                .ok_or_else(|| JsError::new("nothing is loaded"))?;
            let g = l.cameras.get(gltf_camera as usize).ok_or_else(|| {
                JsError::new(&format!(
                    "{}: no glTF camera {gltf_camera} (it has {})",
                    l.name,
                    l.cameras.len()
                ))
            })?;
            Camera::from_gltf(g, width, height).map_err(js_error)?
        };
        self.renderer
            .sort_for_camera(&self.gl, &camera, true)
            .map_err(js_error)?;
        let settings = DrawSettings {
            sh_degree: self.sh_degree,
            depth_test: false,
            color_space: Some(self.renderer.color_space()),
            ..DrawSettings::default()
        };
        let image = self
            .targets
            .draw(
                &self.gl,
                &self.renderer,
                &camera,
                &settings,
                [r, g, b],
                Blend::Rgba16f,
                Output::Image,
                "rendering",
            )
            .map_err(js_error)?
            .ok_or_else(|| JsError::new("no image came back"))?;
        image.encode_png(PngDepth::Eight, false).map_err(js_error)
    }
}
