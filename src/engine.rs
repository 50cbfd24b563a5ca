//! Offline images from either renderer: [`Backend`] names one (the CPU reference or headless
//! GL) and [`Engine`] is one made, holding what it keeps across the images of a batch (the GL
//! context and the uploaded cloud). The one backend choice behind `render --backend` (whose
//! `auto` policy lives in the command line) and `conformance run --backend`.

use crate::SplatCloud;
use crate::camera::Camera;
use crate::image::Image;
use crate::reference::RenderOptions;

/// splatgl's renderers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// The CPU reference rasterizer (float output).
    Reference,
    /// OpenGL ES 3 through headless EGL (8-bit output, or RGBA16F resolved to 8 bits).
    Gl,
}

/// GL renderer strings of software rasterizers (lower case).
pub const SOFTWARE_RENDERERS: [&str; 3] = ["llvmpipe", "softpipe", "swiftshader"];

/// Whether a `GL_VERSION / GL_RENDERER` string names a software rasterizer.
pub fn is_software(description: &str) -> bool {
    let d = description.to_ascii_lowercase();
    SOFTWARE_RENDERERS.iter().any(|s| d.contains(s))
}

/// A renderer made for a batch of images.
pub enum Engine {
    /// The CPU reference rasterizer (nothing to keep between images).
    Reference,
    /// Headless GL: its context and renderer, with the cloud last uploaded, drawing into
    /// `target`.
    #[cfg(feature = "gl")]
    Gl {
        /// The context and renderer.
        renderer: Box<crate::headless::HeadlessRenderer>,
        /// The framebuffer it blends in.
        target: crate::headless::TargetKind,
    },
}

impl std::fmt::Debug for Engine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Engine {
    /// The engine of `backend` (GL: a new headless context, RGBA8 target).
    pub fn new(backend: Backend) -> Result<Self, String> {
        match backend {
            Backend::Reference => Ok(Engine::Reference),
            #[cfg(feature = "gl")]
            Backend::Gl => Self::gl(crate::headless::TargetKind::Rgba8),
            #[cfg(not(feature = "gl"))]
            Backend::Gl => Err("this splatgl was built without the `gl` feature".into()),
        }
    }

    /// A GL engine blending in `target`.
    #[cfg(feature = "gl")]
    pub fn gl(target: crate::headless::TargetKind) -> Result<Self, String> {
        let renderer = crate::headless::HeadlessRenderer::new().map_err(|e| e.to_string())?;
        Ok(Engine::Gl {
            renderer: Box::new(renderer),
            target,
        })
    }

    /// Which backend this is.
    pub fn backend(&self) -> Backend {
        match self {
            Engine::Reference => Backend::Reference,
            #[cfg(feature = "gl")]
            Engine::Gl { .. } => Backend::Gl,
        }
    }

    /// The backend's name (`reference`, `gl`).
    pub fn name(&self) -> &'static str {
        match self.backend() {
            Backend::Reference => "reference",
            Backend::Gl => "gl",
        }
    }

    /// The GL context's `GL_VERSION / GL_RENDERER` (`None` for the reference).
    pub fn describe(&self) -> Option<String> {
        match self {
            Engine::Reference => None,
            #[cfg(feature = "gl")]
            Engine::Gl { renderer, .. } => Some(renderer.context().describe()),
        }
    }

    /// Makes `cloud` the one [`Engine::render`] draws (GL uploads it; the reference keeps
    /// nothing).
    pub fn upload(&mut self, cloud: &SplatCloud) -> Result<(), String> {
        match self {
            Engine::Reference => {
                let _ = cloud;
                Ok(())
            }
            #[cfg(feature = "gl")]
            Engine::Gl { renderer, .. } => renderer.upload(cloud).map_err(|e| format!("GL: {e}")),
        }
    }

    /// Renders `cloud` (the one uploaded, for GL) from `camera` as displayed (sRGB-encoded for
    /// `lin_rec709_display`, which is what GL gives), with `opts`' background and SH degree;
    /// the reference also says how many splats it drew.
    pub fn render(
        &mut self,
        cloud: &SplatCloud,
        camera: &Camera,
        opts: &RenderOptions,
    ) -> Result<(Image, Option<usize>), String> {
        match self {
            Engine::Reference => {
                let space = cloud.meta.color_space.effective();
                let (img, stats) = crate::reference::render_display(cloud, camera, opts, space);
                Ok((img, Some(stats.visible)))
            }
            #[cfg(feature = "gl")]
            Engine::Gl { renderer, target } => {
                let o = crate::headless::HeadlessOptions {
                    target: *target,
                    background: opts.background,
                    sh_degree: Some(opts.sh_degree),
                    color_space: None,
                    antialiased: opts.antialiased,
                };
                renderer
                    .render(camera, &o)
                    .map(|img| (img, None))
                    .map_err(|e| format!("GL: {e}"))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn software_rasterizers_are_recognised_by_their_renderer_string() {
        use super::is_software;
        assert!(is_software(
            "OpenGL ES 3.2 Mesa 24.2.8 / llvmpipe (LLVM 19.1.7, 256 bits)"
        ));
        assert!(is_software("OpenGL ES 3.0 / Google SwiftShader"));
        assert!(is_software("3.3 (Core Profile) Mesa 23 / softpipe"));
        assert!(!is_software(
            "OpenGL ES 3.2 NVIDIA 550.54 / NVIDIA GeForce RTX 4090/PCIe/SSE2"
        ));
        assert!(!is_software(
            "OpenGL ES 3.2 Mesa 24.2 / AMD Radeon RX 7900 (radeonsi)"
        ));
    }
}
