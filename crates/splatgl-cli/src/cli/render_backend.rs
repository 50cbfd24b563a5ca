//! `render --backend`: which renderer draws, and why (printed with `-v`).
//!
//! `auto` takes the CPU reference when the output needs more than the GL readback's 8 bits
//! (`.pfm`, `--depth16`) or a view-depth sort, when no GL context can be made, or when the GL
//! context is a software rasterizer (llvmpipe, softpipe, SwiftShader: the reference is faster
//! there and needs far less memory); GL otherwise (a hardware driver). `--target` asks for GL.

use splatgl::SplatCloud;
use splatgl::engine::{Engine, is_software};
use splatgl::reference::RenderOptions;

/// What the flags ask of the backend.
#[derive(Debug, Clone, Copy)]
pub struct Wanted {
    /// `--backend`.
    pub backend: super::render::Backend,
    /// `--target` given (GL only).
    pub target: Option<super::render::TargetArg>,
    /// Output needs float precision (`.pfm`, `--depth16`).
    pub float_output: bool,
    /// `--sort view-depth` (reference only).
    pub view_depth: bool,
}

impl Wanted {
    /// The combinations no backend can honour, found before loading: float outputs or a
    /// view-depth sort from GL (its readback is 8-bit; it sorts by distance), `--target`
    /// with the reference.
    pub fn check(&self) -> Result<(), String> {
        use super::render::Backend;
        let gl = self.backend == Backend::Gl || self.target.is_some();
        if gl && self.float_output {
            return Err(format!(
                "{} reads back 8 bits per channel, so a .pfm or --depth16 output would be \
                 quantized to k/255; use --backend reference (or auto) for float output",
                self.gl_flag()
            ));
        }
        if gl && self.view_depth {
            return Err(format!(
                "{}: --sort view-depth is only implemented by --backend reference",
                self.gl_flag()
            ));
        }
        if self.target.is_some() && self.backend == Backend::Reference {
            return Err(
                "--target chooses the GL framebuffer; it does not apply to --backend reference"
                    .into(),
            );
        }
        Ok(())
    }

    fn gl_flag(&self) -> &'static str {
        if self.target.is_some() && self.backend != super::render::Backend::Gl {
            "--target (GL)"
        } else {
            "--backend gl"
        }
    }

    /// Chooses the engine for `cloud` (uploading it for GL); returns it and why it was
    /// chosen.
    pub fn engine(
        &self,
        cloud: &SplatCloud,
        opts: &RenderOptions,
    ) -> Result<(Engine, String), String> {
        use super::render::Backend;
        match self.backend {
            Backend::Reference => return Ok((Engine::Reference, "--backend reference".into())),
            Backend::Auto if self.target.is_none() && self.float_output => {
                return Ok((
                    Engine::Reference,
                    "auto: float output (.pfm / --depth16) needs the reference".into(),
                ));
            }
            Backend::Auto if self.view_depth => {
                return Ok((
                    Engine::Reference,
                    "auto: --sort view-depth needs the reference".into(),
                ));
            }
            _ => {}
        }
        match self.gl(cloud, opts) {
            Ok((engine, driver)) => {
                if self.backend == Backend::Auto && self.target.is_none() && is_software(&driver) {
                    return Ok((
                        Engine::Reference,
                        format!(
                            "auto: GL is a software rasterizer ({driver}), where the CPU reference is faster"
                        ),
                    ));
                }
                let blend = match engine.target() {
                    Some(splatgl::headless::TargetKind::Rgba16fResolve) => "RGBA16F",
                    _ => "RGBA8",
                };
                let why = match self.backend {
                    Backend::Gl => format!("--backend gl ({driver}), blending in {blend}"),
                    _ if self.target.is_some() => {
                        format!("auto: --target asks for GL ({driver}), blending in {blend}")
                    }
                    _ => format!("auto: hardware GL driver ({driver}), blending in {blend}"),
                };
                Ok((engine, why))
            }
            Err(e) if self.backend == Backend::Gl || self.target.is_some() => {
                Err(format!("{}: {e}", self.gl_flag()))
            }
            Err(e) => Ok((Engine::Reference, format!("auto: GL unavailable ({e})"))),
        }
    }

    fn gl(&self, cloud: &SplatCloud, _: &RenderOptions) -> Result<(Engine, String), String> {
        use super::render::TargetArg;
        use splatgl::headless::TargetKind;
        // No --target: the RC's recommendation, float blending where the context can.
        let target = self.target.map(|t| match t {
            TargetArg::Rgba8 => TargetKind::Rgba8,
            TargetArg::Rgba16f => TargetKind::Rgba16fResolve,
        });
        let mut engine = Engine::gl(target)?;
        let driver = engine.describe().unwrap_or_default();
        // Software GL under auto falls back to the reference: no upload needed then.
        let auto_software = self.backend == super::render::Backend::Auto
            && self.target.is_none()
            && is_software(&driver);
        if !auto_software {
            engine.upload(cloud)?;
        }
        Ok((engine, driver))
    }
}
