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
    /// OpenGL ES 3 through headless EGL (blending in RGBA16F where the context can render to
    /// it, else RGBA8; 8-bit output).
    Gl,
}

/// GL renderer strings of software rasterizers (lower case).
pub const SOFTWARE_RENDERERS: [&str; 3] = ["llvmpipe", "softpipe", "swiftshader"];

/// Whether a `GL_VERSION / GL_RENDERER` string names a software rasterizer.
pub fn is_software(description: &str) -> bool {
    let d = description.to_ascii_lowercase();
    SOFTWARE_RENDERERS.iter().any(|s| d.contains(s))
}

/// Why an [`Engine`] could not be made, take a cloud or draw.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// GL was asked of a build without the `gl` feature.
    #[error("this splatgl was built without the `gl` feature")]
    NoGlFeature,
    /// GL was asked in the browser, where there is no headless GL.
    #[error("no headless GL in the browser: draw on a WebGL2 canvas")]
    NoHeadlessGl,
    /// The headless context could not be made.
    #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
    #[error("{0}")]
    Context(crate::headless::HeadlessError),
    /// The GL renderer failed to upload or draw.
    #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
    #[error("GL: {0}")]
    Gl(crate::headless::HeadlessError),
    /// The camera's image is larger than any renderer draws.
    #[error(transparent)]
    ImageSize(#[from] crate::camera::ImageSizeError),
}

impl From<EngineError> for String {
    fn from(e: EngineError) -> String {
        e.to_string()
    }
}

/// A renderer made for a batch of images.
pub enum Engine {
    /// The CPU reference rasterizer (nothing to keep between images).
    Reference,
    /// Headless GL: its context and renderer, with the cloud last uploaded, drawing into
    /// `target`.
    #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
    Gl {
        /// The context and renderer.
        renderer: Box<crate::headless::HeadlessRenderer>,
        /// The framebuffer it blends in.
        target: crate::headless::TargetKind,
        /// Why it blends in RGBA8 although RGBA16F was preferred (a one-line warning).
        fallback: Option<String>,
    },
}

impl std::fmt::Debug for Engine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Engine {
    /// The engine of `backend` (GL: a new headless context blending in RGBA16F where it can
    /// render to it, see [`Engine::gl`]).
    pub fn new(backend: Backend) -> Result<Self, EngineError> {
        match backend {
            Backend::Reference => Ok(Engine::Reference),
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
            Backend::Gl => Self::gl(None),
            #[cfg(not(feature = "gl"))]
            Backend::Gl => Err(EngineError::NoGlFeature),
            #[cfg(all(feature = "gl", target_arch = "wasm32"))]
            Backend::Gl => Err(EngineError::NoHeadlessGl),
        }
    }

    /// A GL engine blending in `target`, or with `None` in the framebuffer the RC recommends:
    /// RGBA16F (floating-point blending, resolved to 8 bits) where the context can render to
    /// it (desktop GL; ES with `EXT_color_buffer_half_float` or `_float`), else RGBA8 with a
    /// warning ([`Engine::fallback`]).
    #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
    pub fn gl(target: Option<crate::headless::TargetKind>) -> Result<Self, EngineError> {
        use crate::headless::TargetKind;
        let renderer = crate::headless::HeadlessRenderer::new().map_err(EngineError::Context)?;
        let float = renderer.context().can_render_rgba16f();
        let (target, fallback) = match target {
            Some(t) => (t, None),
            None if float => (TargetKind::Rgba16fResolve, None),
            None => (
                TargetKind::Rgba8,
                Some(format!(
                    "GL blends in RGBA8: the context ({}) cannot render to RGBA16F \
                     (no EXT_color_buffer_half_float), so colours above 1 are clamped per splat",
                    renderer.context().describe()
                )),
            ),
        };
        Ok(Engine::Gl {
            renderer: Box::new(renderer),
            target,
            fallback,
        })
    }

    /// The framebuffer a GL engine blends in (`None` for the reference).
    #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
    pub fn target(&self) -> Option<crate::headless::TargetKind> {
        match self {
            Engine::Reference => None,
            Engine::Gl { target, .. } => Some(*target),
        }
    }

    /// Why a GL engine blends in RGBA8 although RGBA16F was preferred: a one-line warning
    /// for the user (`None` when it blends as asked or preferred, and for the reference).
    pub fn fallback(&self) -> Option<&str> {
        match self {
            Engine::Reference => None,
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
            Engine::Gl { fallback, .. } => fallback.as_deref(),
        }
    }

    /// Which backend this is.
    pub fn backend(&self) -> Backend {
        match self {
            Engine::Reference => Backend::Reference,
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
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
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
            Engine::Gl { renderer, .. } => Some(renderer.context().describe()),
        }
    }

    /// Makes `cloud` the one [`Engine::render`] draws (GL uploads it; the reference keeps
    /// nothing).
    pub fn upload(&mut self, cloud: &SplatCloud) -> Result<(), EngineError> {
        match self {
            Engine::Reference => {
                let _ = cloud;
                Ok(())
            }
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
            Engine::Gl { renderer, .. } => renderer.upload(cloud).map_err(EngineError::Gl),
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
    ) -> Result<(Image, Option<usize>), EngineError> {
        crate::camera::check_image_size(camera.width, camera.height)?;
        match self {
            Engine::Reference => {
                let space = cloud.meta.color_space.effective();
                let (img, stats) = crate::reference::render_display(cloud, camera, opts, space);
                Ok((img, Some(stats.visible)))
            }
            #[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
            Engine::Gl {
                renderer, target, ..
            } => {
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
                    .map_err(EngineError::Gl)
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
