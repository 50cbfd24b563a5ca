//! [`SplatRenderer`]: uploads clouds and draws them into the host's framebuffer. Its
//! [`DrawSettings`] are in `settings.rs`, the draw calls themselves in `draw.rs`, the paged
//! storage of streamed tilesets in `renderer/paged.rs`.

use crate::gl::bound::Bound;
use std::cell::Cell;

use glam::Mat4;
use glow::HasContext;

use super::GlError;
use super::caps::injected;
use super::context::ContextInfo;
use super::data::{CloudSet, PAGE_SPLATS, SplatTextures, TextureLayout};
use super::error::ErrorScope;
use super::glsl::{self, Errata, GlslVersion};
use super::objects::{Creating, Owned};
use super::prepass::{PREPASS_MIN_SPLATS, PrePass, Sources};
use super::program;
use super::settings::{DrawPath, DrawSettings, Pipeline};
use super::state::{Bindings, StateCalls};
use super::uniforms::{Models, Uniforms};
use crate::cloud::{ColorSpace, SplatCloud};

mod paged;
/// The splat renderer. It borrows the host's GL context in every call and never owns it; see
/// [`super::state`] for the GL state each call changes in each mode. All methods must be
/// called with the same context current. One renderer draws one cloud; a [`SplatScene`](super::SplatScene)
/// draws several in one order.
///
/// Per frame only the order is uploaded (`glBufferSubData`, 4 bytes per splat) and nothing is
/// allocated on the host.
///
/// # Colour spaces
///
/// The shader writes the reconstructed colours as they are (premultiplied). For
/// `srgb_rec709_display` clouds that is final: draw into a framebuffer that stores values as
/// written (the draw disables `GL_FRAMEBUFFER_SRGB` where it can be switched; on ES without
/// `GL_EXT_sRGB_write_control` do not draw them into an sRGB framebuffer). For
/// `lin_rec709_display` clouds ([`SplatRenderer::color_space`]) blending must happen on linear
/// values and the result be sRGB-encoded once at the end: draw into an `SRGB8_ALPHA8`
/// framebuffer (the draw enables `GL_FRAMEBUFFER_SRGB` on desktop GL; ES always converts), or
/// into an [`super::OffscreenTarget`] resolved with `encode_srgb = true`.
///
/// # Lifetime
///
/// It owns GL objects but not the context: call [`SplatRenderer::destroy`] with the context
/// current before dropping it (dropping a live renderer leaks its objects and warns once).
/// After `destroy` every method returns [`GlError::Destroyed`].
#[derive(Debug)]
pub struct SplatRenderer {
    pub(super) program: glow::Program,
    pub(super) uniforms: Uniforms,
    pub(super) vao: glow::VertexArray,
    order_buffer: glow::Buffer,
    /// Indices the order buffer holds (grown, never shrunk).
    order_allocated: usize,
    /// Indices `set_order` may write (the uploaded splats).
    order_capacity: usize,
    pub(super) instances: usize,
    pub(super) textures: Option<SplatTextures>,
    pub(super) cloud_degree: u8,
    pub(super) color_space: ColorSpace,
    settings: DrawSettings,
    pub(super) errata: Errata,
    pub(super) ctx: ContextInfo,
    layout: TextureLayout,
    pub(super) models: Models,
    pub(super) state_calls: Cell<StateCalls>,
    pub(super) path: DrawPath,
    pub(super) prepass: Option<PrePass>,
    /// Whether the last draw ran the pre-pass.
    pub(super) used_prepass: Cell<bool>,
    pub(super) owned: Owned,
    /// What [`SplatRenderer::draw_frame`] sorts (from [`SplatRenderer::upload`]).
    pub(super) host_sort: Option<super::host_sort::HostSort>,
    /// Whether the storage is pages ([`SplatRenderer::allocate_pages`]).
    paged: bool,
    /// The timer queries of [`SplatRenderer::set_stage_timing`] (off: `None`).
    pub(super) stages: Option<super::stages::StageQueries>,
}

impl SplatRenderer {
    /// Checks the context (OpenGL ≥ 3.3 or OpenGL ES ≥ 3.0, else
    /// [`GlError::ContextVersion`] naming the version found), compiles the splat program for
    /// its GLSL flavour and creates the (empty) order buffer and vertex array. Leaves every
    /// binding as it found it.
    pub fn new(gl: &glow::Context) -> Result<Self, GlError> {
        Self::with_errata(gl, Errata::default())
    }

    /// Like [`SplatRenderer::new`], with some of the review draft's Appendix A errata switched
    /// back in. **Erratum tests only** (feature `testing`; hidden from the documented API).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn with_errata(gl: &glow::Context, errata: Errata) -> Result<Self, GlError> {
        Self::build(gl, errata)
    }

    #[cfg(not(feature = "testing"))]
    pub(crate) fn with_errata(gl: &glow::Context, errata: Errata) -> Result<Self, GlError> {
        Self::build(gl, errata)
    }

    fn build(gl: &glow::Context, errata: Errata) -> Result<Self, GlError> {
        let ctx = ContextInfo::check(gl)?;
        let version = GlslVersion::for_context(ctx);
        let layout = TextureLayout::for_context(gl);
        let source = |stage: &str, body: &str| {
            let s = glsl::assemble(version, &errata, &layout, body);
            match injected!(fn(&str, String) -> String, |f| f.edit_shader) {
                Some(edit) => edit(stage, s),
                None => s,
            }
        };
        let vs = source("vertex", glsl::SPLAT_VERT);
        let fs = source("fragment", glsl::SPLAT_FRAG);
        let mut objects = Creating::new(gl);
        let program = program::build_program_in(&mut objects, "splat", &vs, &fs)?;
        // Erratum variants may compile some uniforms away: only the correct program is checked.
        let uniforms = Uniforms::new(gl, program, errata == Errata::default());
        let vao = objects.vertex_array()?;
        let order_buffer = objects.buffer()?;
        {
            let _host = Bindings::for_new(gl);
            // SAFETY: configures the VAO and buffer created just above; `_host` binds the
            // host's VAO and array buffer back.
            unsafe {
                // The only vertex attribute: the sorted splat index, one u32 per instance.
                gl.bind_vertex_array(Some(vao));
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(order_buffer));
                gl.enable_vertex_attrib_array(0);
                gl.vertex_attrib_pointer_i32(0, 1, glow::UNSIGNED_INT, 4, 0);
                gl.vertex_attrib_divisor(0, 1);
            }
        }
        Ok(SplatRenderer {
            program,
            uniforms,
            vao,
            order_buffer,
            order_allocated: 0,
            order_capacity: 0,
            instances: 0,
            textures: None,
            cloud_degree: 0,
            color_space: ColorSpace::default(),
            settings: DrawSettings::default(),
            errata,
            ctx,
            layout,
            models: Models::IDENTITY,
            state_calls: Cell::new(StateCalls::default()),
            path: DrawPath::default(),
            prepass: None,
            used_prepass: Cell::new(false),
            owned: objects.keep("SplatRenderer"),
            host_sort: None,
            paged: false,
            stages: None,
        })
    }

    /// Whether the pre-pass can run here: a context with transform-feedback objects, the
    /// correct shaders (erratum variants draw directly, exactly as before the pre-pass).
    fn prepass_possible(&self) -> bool {
        self.ctx.tf_objects && self.errata == Errata::default()
    }

    /// Whether draws of up to `n` splats may want the pre-pass under the current path.
    fn prepass_wanted(&self, n: usize) -> bool {
        self.prepass_possible()
            && match self.path.pipeline {
                Pipeline::Direct => false,
                Pipeline::PrePass => true,
                Pipeline::Auto => n >= PREPASS_MIN_SPLATS,
            }
    }

    /// Creates (or grows) the pre-pass for `capacity` splats where it is wanted.
    fn ensure_prepass(&mut self, gl: &glow::Context, capacity: usize) -> Result<(), GlError> {
        if !self.prepass_wanted(capacity) {
            return Ok(());
        }
        if let Some(p) = &mut self.prepass {
            return p.reserve(gl, capacity);
        }
        let version = GlslVersion::for_context(self.ctx);
        let asm = |body: &str| glsl::assemble(version, &self.errata, &self.layout, body);
        let src = Sources {
            prep_vert: asm(glsl::SPLAT_PREP_VERT),
            discard_frag: asm(glsl::DISCARD_FRAG),
            quad_vert: asm(glsl::SPLAT_QUAD_VERT),
            splat_frag: asm(glsl::SPLAT_FRAG),
        };
        self.prepass = Some(PrePass::new(
            gl,
            &src,
            self.order_buffer,
            self.layout,
            capacity,
            true,
        )?);
        Ok(())
    }

    /// Chooses the draw path (hidden, see [`Pipeline`]); creates the pre-pass's objects
    /// when the uploaded cloud needs them now.
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn set_draw_path(&mut self, gl: &glow::Context, path: DrawPath) -> Result<(), GlError> {
        self.owned.check()?;
        self.path = path;
        self.ensure_prepass(gl, self.order_capacity)
    }

    /// The draw path (hidden, see [`Pipeline`]).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn draw_path(&self) -> DrawPath {
        self.path
    }

    /// Whether the last draw ran the transform-feedback pre-pass (hidden: tests, benchmarks).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn last_draw_used_prepass(&self) -> bool {
        self.used_prepass.get()
    }

    /// Uploads a cloud's data into textures (once per cloud; replaces any previous cloud) and
    /// sizes the order buffer for `cloud.len()` indices. A cloud larger than one texture is
    /// spread over the layers of array textures; beyond the context's limits it fails with
    /// [`GlError::Capacity`]. GL errors (e.g. `GL_OUT_OF_MEMORY`) are returned as
    /// [`GlError::Gl`]; the host's pending errors are kept ([`super::state`]). On failure the
    /// previous cloud stays uploaded. Leaves every binding and the unpack state as it found
    /// them. Keeps a copy of the positions and the cull radii on the host (16 bytes per
    /// splat) for [`SplatRenderer::draw_frame`]'s sort.
    pub fn upload(&mut self, gl: &glow::Context, cloud: &SplatCloud) -> Result<(), GlError> {
        self.upload_clouds(gl, &[cloud])?;
        self.models = Models::IDENTITY;
        self.host_sort = Some(super::host_sort::HostSort::new(cloud));
        Ok(())
    }

    /// Uploads several clouds as one (cloud `k`'s splats get model index `k`; the colour
    /// space is the first cloud's). For [`SplatScene`].
    pub(super) fn upload_clouds(
        &mut self,
        gl: &glow::Context,
        clouds: &[&SplatCloud],
    ) -> Result<(), GlError> {
        self.owned.check()?;
        let set = CloudSet::new(clouds)?;
        let errors = ErrorScope::begin(gl)?;
        let host = Bindings::for_upload(gl, self.ctx);
        let mut textures = SplatTextures::upload(gl, &set, &self.layout)?;
        drop(host);
        if let Err(e) = errors.end("uploading splat textures") {
            textures.destroy(gl);
            return Err(e);
        }
        let color_space = clouds
            .first()
            .map_or(ColorSpace::default(), |c| c.meta.color_space.effective());
        self.replace_textures(gl, textures, color_space)?;
        self.paged = false;
        Ok(())
    }

    /// Makes `textures` the drawn storage (sizing the order buffer and the pre-pass for it);
    /// on failure they are deleted and the previous storage stays.
    fn replace_textures(
        &mut self,
        gl: &glow::Context,
        mut textures: SplatTextures,
        color_space: ColorSpace,
    ) -> Result<(), GlError> {
        let n = textures.len;
        if n > self.order_allocated
            && let Err(e) = self.grow_order_buffer(gl, n)
        {
            textures.destroy(gl);
            return Err(e);
        }
        if let Err(e) = self.ensure_prepass(gl, n) {
            textures.destroy(gl);
            return Err(e);
        }
        self.cloud_degree = textures.sh_degree;
        if let Some(mut old) = self.textures.replace(textures) {
            old.destroy(gl);
        }
        self.color_space = color_space;
        self.instances = 0;
        self.order_capacity = n;
        self.host_sort = None;
        Ok(())
    }

    /// Reallocates the order buffer for `n` indices. On failure its contents and size are
    /// unknown: the previous order must be set again (and fit).
    fn grow_order_buffer(&mut self, gl: &glow::Context, n: usize) -> Result<(), GlError> {
        let errors = ErrorScope::begin(gl)?;
        {
            let _host = Bindings::for_new(gl);
            // SAFETY: (re)allocates the renderer's own order buffer; `_host` rebinds the
            // host's array buffer.
            unsafe {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.order_buffer));
                let bytes = i32::try_from(n * 4).unwrap_or(i32::MAX);
                gl.buffer_data_size(glow::ARRAY_BUFFER, bytes, glow::DYNAMIC_DRAW);
            }
        }
        let result = errors.end("allocating the order buffer");
        self.instances = 0;
        match &result {
            Ok(()) => self.order_allocated = n,
            Err(_) => {
                self.order_allocated = 0;
                self.order_capacity = 0;
            }
        }
        result
    }

    /// Points model `k`'s uniforms at `models` (see [`SplatScene`]).
    pub(super) fn set_models(&mut self, models: &[Mat4]) {
        self.models.set(models);
    }

    /// The linked splat program (for inspection, e.g. its active attributes; erratum tests).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn program(&self) -> glow::Program {
        self.program
    }

    /// GL calls the state handling of the last draw made (restore mode adds queries and
    /// restoring calls). **For the state-cost measurement** (hidden from the documented API).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub fn last_state_calls(&self) -> StateCalls {
        self.state_calls.get()
    }

    /// Number of splats uploaded.
    pub fn len(&self) -> usize {
        self.textures.as_ref().map_or(0, |t| t.len)
    }

    /// Whether no splats are uploaded.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The uploaded cloud's `colorSpace` (unknown values fall back to the default,
    /// `srgb_rec709_display`).
    pub fn color_space(&self) -> ColorSpace {
        self.color_space
    }

    /// Whether this context can switch `GL_FRAMEBUFFER_SRGB` (desktop GL, or GLES with
    /// `EXT_sRGB_write_control`): then an sRGB framebuffer encodes only with it on.
    pub fn srgb_write_switch(&self) -> bool {
        self.ctx.srgb_switch
    }

    /// SH degree of the uploaded cloud.
    pub fn cloud_sh_degree(&self) -> u8 {
        self.cloud_degree
    }

    /// The current draw settings.
    pub fn settings(&self) -> &DrawSettings {
        &self.settings
    }

    /// Mutable draw settings (take effect at the next draw).
    pub fn settings_mut(&mut self) -> &mut DrawSettings {
        &mut self.settings
    }

    /// Uploads a draw order (`glBufferSubData`, 4 bytes per index): splat indices back to front,
    /// each `< len()`. May be shorter than the cloud (culled or partial draws). Binds the order
    /// buffer as `GL_ARRAY_BUFFER`: put back with [`DrawSettings::restore_state`] (of the
    /// renderer's settings), else left 0.
    pub fn set_order(&mut self, gl: &glow::Context, order: &[u32]) -> Result<(), GlError> {
        self.owned.check()?;
        if self.textures.is_none() {
            return Err(GlError::NotUploaded);
        }
        if order.len() > self.order_capacity {
            return Err(GlError::OrderTooLong {
                got: order.len(),
                capacity: self.order_capacity,
            });
        }
        // SAFETY: writes `order.len() * 4` bytes into the order buffer, which holds
        // `order_allocated * 4 >= order_capacity * 4 >= order.len() * 4` bytes; binds the
        // host's array buffer back (restore mode) or none.
        unsafe {
            let host = if self.settings.restore_state {
                gl.bound_buffer(glow::ARRAY_BUFFER_BINDING)
            } else {
                None
            };
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.order_buffer));
            gl.buffer_sub_data_u8_slice(glow::ARRAY_BUFFER, 0, bytemuck::cast_slice(order));
            gl.bind_buffer(glow::ARRAY_BUFFER, host);
        }
        self.instances = order.len();
        Ok(())
    }

    /// Deletes every GL object the renderer created (once; afterwards every method returns
    /// [`GlError::Destroyed`]). Call it with the renderer's context current. None of them is
    /// bound after any call of the renderer, so no binding changes.
    pub fn destroy(&mut self, gl: &glow::Context) {
        if let Some(mut t) = self.textures.take() {
            t.destroy(gl);
        }
        if let Some(mut p) = self.prepass.take() {
            p.destroy(gl);
        }
        if let Some(mut q) = self.stages.take() {
            q.destroy(gl);
        }
        self.owned.destroy(gl);
        self.host_sort = None;
        self.order_capacity = 0;
        self.instances = 0;
    }

    /// Forgets the objects without GL calls (their context is already gone).
    pub fn abandon(&mut self) {
        if let Some(mut t) = self.textures.take() {
            t.abandon();
        }
        if let Some(mut p) = self.prepass.take() {
            p.abandon();
        }
        if let Some(mut q) = self.stages.take() {
            q.abandon();
        }
        self.owned.abandon();
    }
}
