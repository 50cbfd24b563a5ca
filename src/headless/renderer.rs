//! [`HeadlessRenderer`]: a [`HeadlessContext`] with a [`SplatRenderer`], the uploaded cloud's
//! draw order and cached framebuffers, rendering to [`Image`]s.

use super::{HeadlessContext, HeadlessError};
use crate::camera::Camera;
use crate::cloud::{ColorSpace, SplatCloud};
use crate::gl::frame::{Blend, FrameTargets, Output};
use crate::gl::{DrawSettings, Errata, SplatRenderer};
use crate::image::Image;
use glow::HasContext;

/// Which framebuffer the splats are blended in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TargetKind {
    /// Blend directly in an 8-bit framebuffer: `RGBA8` for `srgb_rec709_display`,
    /// `SRGB8_ALPHA8` for `lin_rec709_display` (GL decodes, blends linear, re-encodes).
    #[default]
    Rgba8,
    /// Blend in an `RGBA16F` [`OffscreenTarget`](crate::gl::OffscreenTarget), then resolve (sRGB-encoding linear clouds)
    /// into an `RGBA8` framebuffer.
    Rgba16fResolve,
}

/// Options of one headless render (the GL counterpart of
/// [`reference::RenderOptions`](crate::reference::RenderOptions)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HeadlessOptions {
    /// Framebuffer to blend in.
    pub target: TargetKind,
    /// Background colour as it appears in the output image (display-referred values). For
    /// `lin_rec709_display` it is sRGB-decoded before blending, so it comes out unchanged.
    pub background: [f32; 3],
    /// SH degree to evaluate; `None` = the cloud's.
    pub sh_degree: Option<u8>,
    /// Colour space override; `None` = the cloud's `meta.color_space` (unknown → default).
    pub color_space: Option<ColorSpace>,
    /// The antialiased kernel ([`DrawSettings::antialiased`]).
    pub antialiased: bool,
}

/// A headless context with a [`SplatRenderer`], an uploaded cloud and cached framebuffers.
///
/// The renderer sorts the cloud given to [`HeadlessRenderer::upload`] (its own copy of the
/// positions and cull radii, as for [`SplatRenderer::draw_frame`]), the
/// only way to upload: the renderer is reachable read-only ([`HeadlessRenderer::renderer`]),
/// so the order can never be computed for another cloud than the one drawn. Each render
/// passes its own [`DrawSettings`]; the renderer's settings are never changed.
///
/// It owns its context, so dropping it deletes every GL object (no `destroy` needed).
#[derive(Debug)]
pub struct HeadlessRenderer {
    renderer: SplatRenderer,
    targets: FrameTargets,
    /// Sort only the splats the camera may see (off for erratum variants, which must draw
    /// exactly as before the cull).
    cull: bool,
    // Declared last: dropped after the GL objects above are deleted in `Drop`.
    ctx: HeadlessContext,
}

impl HeadlessRenderer {
    /// A new GLES 3 context with a renderer (no cloud yet).
    pub fn new() -> Result<Self, HeadlessError> {
        Self::with_context(HeadlessContext::new()?)
    }

    /// A renderer on `ctx` (e.g. `HeadlessContext::with_api(GlApi::DesktopCore33)?`).
    pub fn with_context(ctx: HeadlessContext) -> Result<Self, HeadlessError> {
        Self::with_context_and_errata(ctx, Errata::default())
    }

    /// Like [`HeadlessRenderer::new`] with Appendix A errata switched in. **Erratum tests
    /// only** (feature `testing`; hidden from the documented API).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn with_errata(errata: Errata) -> Result<Self, HeadlessError> {
        Self::with_context_and_errata(HeadlessContext::new()?, errata)
    }

    fn with_context_and_errata(
        ctx: HeadlessContext,
        errata: Errata,
    ) -> Result<Self, HeadlessError> {
        ctx.make_current()?;
        let renderer = SplatRenderer::with_errata(ctx.gl(), errata)?;
        Ok(HeadlessRenderer {
            renderer,
            targets: FrameTargets::default(),
            cull: errata == Errata::default(),
            ctx,
        })
    }

    /// The context.
    pub fn context(&self) -> &HeadlessContext {
        &self.ctx
    }

    /// The renderer (read-only: uploads go through [`HeadlessRenderer::upload`]).
    pub fn renderer(&self) -> &SplatRenderer {
        &self.renderer
    }

    /// Uploads a cloud (replacing the previous one; on failure the previous one stays).
    pub fn upload(&mut self, cloud: &SplatCloud) -> Result<(), HeadlessError> {
        self.ctx.make_current()?;
        self.renderer.upload(self.ctx.gl(), cloud)?;
        Ok(())
    }

    /// Chooses the renderer's draw path and whether `render` culls before sorting. **For the
    /// tests and benchmarks that compare the paths** (feature `testing`; every path draws the
    /// same image).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn set_path(&mut self, path: crate::gl::DrawPath, cull: bool) -> Result<(), HeadlessError> {
        self.ctx.make_current()?;
        self.renderer.set_draw_path(self.ctx.gl(), path)?;
        self.cull = cull;
        Ok(())
    }

    /// Renders the uploaded cloud, sorted back to front for `camera`: only the splats its
    /// frustum may see ([`crate::cull`]; the same image as from all of them).
    pub fn render(
        &mut self,
        camera: &Camera,
        opts: &HeadlessOptions,
    ) -> Result<Image, HeadlessError> {
        self.ctx.make_current()?;
        if camera.width > 0 && camera.height > 0 {
            // The renderer's own sort of the cloud it holds (no copy of it here).
            self.renderer
                .sort_for_camera(self.ctx.gl(), camera, self.cull)?;
        }
        self.draw_uploaded_order(camera, opts)
    }

    /// Renders the uploaded cloud in the given order (first index drawn first).
    pub fn render_with_order(
        &mut self,
        camera: &Camera,
        opts: &HeadlessOptions,
        order: &[u32],
    ) -> Result<Image, HeadlessError> {
        self.ctx.make_current()?;
        if camera.width > 0 && camera.height > 0 {
            self.renderer.set_order(self.ctx.gl(), order)?;
        }
        self.draw_uploaded_order(camera, opts)
    }

    /// Draws the order last uploaded into the cached target and reads it back.
    fn draw_uploaded_order(
        &mut self,
        camera: &Camera,
        opts: &HeadlessOptions,
    ) -> Result<Image, HeadlessError> {
        let (w, h) = (camera.width, camera.height);
        if w == 0 || h == 0 {
            return Ok(Image::filled(w, h, [0.0; 4])); // no pixels (a 0-sized FBO is incomplete)
        }
        let settings = DrawSettings {
            sh_degree: opts.sh_degree,
            depth_test: false,
            color_space: Some(opts.color_space.unwrap_or(self.renderer.color_space())),
            antialiased: opts.antialiased,
            ..DrawSettings::default()
        };
        let blend = match opts.target {
            TargetKind::Rgba8 => Blend::Rgba8,
            TargetKind::Rgba16fResolve => Blend::Rgba16f,
        };
        let gl = self.ctx.gl();
        let image = self.targets.draw(
            gl,
            &self.renderer,
            camera,
            &settings,
            opts.background,
            blend,
            Output::Image,
            "rendering",
        )?;
        Ok(image.expect("Output::Image returns the image"))
    }

    /// Blocks until the GL has finished all commands (for timing).
    pub fn finish(&self) {
        // SAFETY: glFinish has no preconditions.
        unsafe { self.ctx.gl().finish() }
    }
}

impl Drop for HeadlessRenderer {
    fn drop(&mut self) {
        if self.ctx.make_current().is_err() {
            // The objects go with the context (destroyed right after this).
            self.renderer.abandon();
            self.targets.abandon();
            return;
        }
        let gl = self.ctx.gl();
        self.renderer.destroy(gl);
        self.targets.destroy(gl);
    }
}
