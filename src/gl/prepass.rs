//! The transform-feedback pre-pass: the per-splat maths (covariance, projection, extent, SH)
//! once per drawn splat instead of once per quad corner.
//!
//! One `GL_POINTS` draw over the order buffer (the sorted visible splats) with the rasterizer
//! discarded runs `glsl/splat_prep.vert` — the same `splat_project.glsl` as the direct path —
//! and captures, interleaved, one [`RECORD_BYTES`]-byte record per splat ([`RECORD_TEXELS`]
//! vec4s: clip-space centre, the clip-space corner offsets, colour and opacity, conic). The
//! records buffer is then copied (`GL_PIXEL_UNPACK_BUFFER` → `glTexSubImage3D`, on the GL's
//! side) into the records texture, laid out like the data textures (record `i`'s texel `k`
//! at linear index `i·RECORD_TEXELS + k`). The quad draw (`glsl/splat_quad.vert`) is one
//! indexed, instanced draw of [`QUADS_PER_INSTANCE`] quads per instance: vertex `4q + c` of
//! instance `j` is corner `c` of the splat in slot `j·QUADS_PER_INSTANCE + q`, which reads
//! its record with `texelFetch` and only places its corner. GLES 3.0 / WebGL2 class:
//! transform feedback, pixel-buffer copies, instancing; no compute, no texture buffers.
//!
//! Why batches: a software GL pays per instance — SwiftShader (Chromium's WebGL2 without a
//! GPU) runs every instance as a draw of its own, llvmpipe sets each one up — so one instance
//! per splat cost more than the splats' maths (`docs/performance.md`). On a GPU a batch is
//! the same work as the instances it replaces.
//!
//! The records buffer and texture hold as many records as splats were uploaded (64 bytes
//! each, twice: 128 bytes per splat), sized at upload; nothing is allocated per frame.

use crate::gl::bound::Bound;
use crate::profile::{QUADS_PER_INSTANCE, RECORD_TEXELS};
use glow::HasContext;

use super::GlError;
use super::data::TextureLayout;
use super::objects::{Creating, Owned};
use super::program;
use super::uniforms::Uniforms;

/// The pre-pass outputs, in capture order (the record layout: one vec4 each).
pub(crate) const PREPASS_VARYINGS: [&str; RECORD_TEXELS] =
    ["t_clip", "t_axes", "t_color_opacity", "t_conic"];
/// Bytes of one RGBA32F texel of the records buffer and texture.
const TEXEL_BYTES: usize = 16;
/// Bytes of one record: [`RECORD_TEXELS`] RGBA32F texels.
pub(crate) const RECORD_BYTES: usize = RECORD_TEXELS * TEXEL_BYTES;

/// Below this many splats drawn, [`Pipeline::Auto`](super::Pipeline::Auto) draws directly.
/// On llvmpipe the pre-pass wins from about 10 splats on (`cargo bench --features testing --bench gl`,
/// `docs/gl-backend.md` "Pre-pass crossover"): its fixed cost there is a few µs. On a GPU a
/// second draw with its program switch costs tens of µs, more than a direct draw of a
/// thousand splats takes, so small clouds keep the direct path (costing at most 0.4 ms on
/// llvmpipe); `scripts/bench-gpu.sh` measures the crossover where a GPU is available.
pub const PREPASS_MIN_SPLATS: usize = 1024;

/// The locations of the quad program's uniforms.
#[derive(Debug)]
struct QuadUniforms {
    u_records: Option<glow::UniformLocation>,
    u_instances: Option<glow::UniformLocation>,
    u_viewport: Option<glow::UniformLocation>,
}

/// The pre-pass's GL objects.
#[derive(Debug)]
pub(super) struct PrePass {
    prep: glow::Program,
    pub(super) prep_uniforms: Uniforms,
    pub(super) quad: glow::Program,
    quad_uniforms: QuadUniforms,
    tf: glow::TransformFeedback,
    records: glow::Buffer,
    /// The records, copied from `records` for the quad draw (`TEXTURE_2D_ARRAY`, RGBA32F).
    records_texture: glow::Texture,
    prep_vao: glow::VertexArray,
    /// The quad draw's vertex array: no attributes, the batch's index buffer.
    pub(super) quad_vao: glow::VertexArray,
    layout: TextureLayout,
    /// Records the buffer and the texture hold.
    capacity: usize,
    owned: Owned,
}

/// What the pre-pass's programs are built from: (prep vertex, discard fragment, quad vertex,
/// splat fragment), assembled by the renderer.
pub(super) struct Sources {
    pub(super) prep_vert: String,
    pub(super) discard_frag: String,
    pub(super) quad_vert: String,
    pub(super) splat_frag: String,
}

/// The indices of one batch: quad `q` is the triangles (4q, 4q+1, 4q+2) and (4q+2, 4q+1, 4q+3)
/// — corners (−1,−1), (+1,−1), (−1,+1), (+1,+1).
fn batch_indices() -> Vec<u16> {
    const _: () = assert!(4 * QUADS_PER_INSTANCE <= u16::MAX as usize + 1);
    (0..QUADS_PER_INSTANCE as u16)
        .flat_map(|q| [0, 1, 2, 2, 1, 3].map(|c| 4 * q + c))
        .collect()
}

impl PrePass {
    /// Builds the programs, the vertex arrays (the prep one reads `order` per vertex, the quad
    /// one has the batch's index buffer), the transform-feedback object with the records
    /// buffer on its binding 0, the records texture, and sizes both for `capacity` splats.
    /// Leaves every binding as it found it.
    pub(super) fn new(
        gl: &glow::Context,
        src: &Sources,
        order: glow::Buffer,
        layout: TextureLayout,
        capacity: usize,
        check_uniforms: bool,
    ) -> Result<Self, GlError> {
        let mut objects = Creating::new(gl);
        let prep = program::build_program_with_feedback(
            &mut objects,
            "splat pre-pass",
            &src.prep_vert,
            &src.discard_frag,
            &PREPASS_VARYINGS,
        )?;
        let quad =
            program::build_program_in(&mut objects, "splat quad", &src.quad_vert, &src.splat_frag)?;
        let prep_uniforms = Uniforms::new(gl, prep, check_uniforms);
        let [u_records, u_instances, u_viewport] = program::uniform_locations(
            gl,
            quad,
            "splat quad",
            ["u_records", "u_instances", "u_viewport"],
            check_uniforms,
        );
        let (prep_vao, quad_vao) = (objects.vertex_array()?, objects.vertex_array()?);
        let (records, indices) = (objects.buffer()?, objects.buffer()?);
        let records_texture = objects.texture()?;
        let tf = objects.transform_feedback()?;
        // SAFETY: configures the objects created just above, then binds the host's vertex
        // array, array buffer, transform-feedback object and generic transform-feedback
        // buffer back (queried first). The element-array binding is the quad VAO's own.
        unsafe {
            let host_vao = gl.bound_vertex_array(glow::VERTEX_ARRAY_BINDING);
            let host_array = gl.bound_buffer(glow::ARRAY_BUFFER_BINDING);
            let host_tf = gl.bound_transform_feedback(glow::TRANSFORM_FEEDBACK_BINDING);
            let host_tf_buffer = gl.bound_buffer(glow::TRANSFORM_FEEDBACK_BUFFER_BINDING);
            gl.bind_vertex_array(Some(prep_vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(order));
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_i32(0, 1, glow::UNSIGNED_INT, 4, 0);
            gl.bind_vertex_array(Some(quad_vao));
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(indices));
            let data = batch_indices();
            gl.buffer_data_u8_slice(
                glow::ELEMENT_ARRAY_BUFFER,
                bytemuck::cast_slice(&data),
                glow::STATIC_DRAW,
            );
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(tf));
            gl.bind_buffer_base(glow::TRANSFORM_FEEDBACK_BUFFER, 0, Some(records));
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, host_tf);
            gl.bind_buffer(glow::TRANSFORM_FEEDBACK_BUFFER, host_tf_buffer);
            gl.bind_vertex_array(host_vao);
            gl.bind_buffer(glow::ARRAY_BUFFER, host_array);
        }
        let mut p = PrePass {
            prep,
            prep_uniforms,
            quad,
            quad_uniforms: QuadUniforms {
                u_records,
                u_instances,
                u_viewport,
            },
            tf,
            records,
            records_texture,
            prep_vao,
            quad_vao,
            layout,
            capacity: 0,
            owned: objects.keep("SplatRenderer"),
        };
        p.reserve(gl, capacity)?;
        Ok(p)
    }

    /// Grows the records buffer and texture to hold `capacity` splats (never shrinks): whole
    /// rows of the texture, so the copy reads whole rows of the buffer. Leaves the
    /// `GL_ARRAY_BUFFER`, `GL_PIXEL_UNPACK_BUFFER` and the active unit's `TEXTURE_2D_ARRAY`
    /// bindings as it found them (a host's unpack buffer is unbound meanwhile: with one bound,
    /// the texture's allocation would read from it; without, the unpack parameters do not
    /// matter to an allocation without data).
    pub(super) fn reserve(&mut self, gl: &glow::Context, capacity: usize) -> Result<(), GlError> {
        if capacity <= self.capacity {
            return Ok(());
        }
        self.layout.check(capacity, RECORD_TEXELS)?;
        let (rows, layers) = self.layout.shape(capacity, RECORD_TEXELS);
        let width = self.layout.width();
        let bytes = (width * rows * layers)
            .checked_mul(TEXEL_BYTES)
            .filter(|&b| b <= i32::MAX as usize);
        let Some(bytes) = bytes else {
            return Err(GlError::Upload(format!(
                "{capacity} splats need {} bytes of pre-pass records, more than one GL buffer \
                 holds",
                capacity as u128 * RECORD_BYTES as u128
            )));
        };
        let errors = super::error::ErrorScope::begin(gl)?;
        // SAFETY: (re)allocates the pre-pass's own buffer and texture (mutable storage:
        // respecified at the new size); rebinds the host's array buffer and texture.
        unsafe {
            let host = gl.bound_buffer(glow::ARRAY_BUFFER_BINDING);
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.records));
            gl.buffer_data_size(glow::ARRAY_BUFFER, bytes as i32, glow::DYNAMIC_COPY);
            gl.bind_buffer(glow::ARRAY_BUFFER, host);
            let host_tex = gl.bound_texture(glow::TEXTURE_BINDING_2D_ARRAY);
            let host_unpack = gl.bound_buffer(glow::PIXEL_UNPACK_BUFFER_BINDING);
            if host_unpack.is_some() {
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
            }
            gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(self.records_texture));
            let (w, h, d) = (width as i32, rows as i32, layers as i32);
            gl.tex_image_3d(
                glow::TEXTURE_2D_ARRAY,
                0,
                glow::RGBA32F as i32,
                w,
                h,
                d,
                0,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelUnpackData::Slice(None),
            );
            super::data::nearest_texel_reads(gl);
            gl.bind_texture(glow::TEXTURE_2D_ARRAY, host_tex);
            if host_unpack.is_some() {
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, host_unpack);
            }
        }
        // After a failed allocation the sizes are undefined: claim nothing, so no draw takes
        // the pre-pass path until a reservation succeeds.
        self.capacity = 0;
        errors.end("allocating the pre-pass records")?;
        self.capacity = capacity;
        Ok(())
    }

    /// Binds the pre-pass program and vertex array (then set its uniforms).
    pub(super) fn bind(&self, gl: &glow::Context) {
        // SAFETY: binds the pre-pass's own program and vertex array.
        unsafe {
            gl.use_program(Some(self.prep));
            gl.bind_vertex_array(Some(self.prep_vao));
        }
    }

    /// Captures the records of the first `n` splats of the order (≤ the capacity). Leaves the
    /// default transform-feedback object bound and `GL_RASTERIZER_DISCARD` disabled (as a
    /// draw sets them, see [`super::state`]).
    pub(super) fn capture(&self, gl: &glow::Context, n: usize) {
        let n = n.min(self.capacity);
        // SAFETY: one POINTS draw of `n ≤ capacity` vertices into the records buffer (bound
        // to the transform-feedback object's binding 0 at creation), which holds `capacity`
        // records.
        unsafe {
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(self.tf));
            gl.enable(glow::RASTERIZER_DISCARD);
            gl.begin_transform_feedback(glow::POINTS);
            gl.draw_arrays(glow::POINTS, 0, n as i32);
            gl.end_transform_feedback();
            gl.disable(glow::RASTERIZER_DISCARD);
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, None);
        }
    }

    /// Copies the first `n` captured records into the records texture and binds it on unit 0;
    /// leaves no pixel-unpack buffer bound and unit 1 active (the draw set the unpack
    /// parameters the copy needs, see [`super::state`]).
    pub(super) fn copy_records(&self, gl: &glow::Context, n: usize) {
        let n = n.min(self.capacity);
        let width = self.layout.width();
        let layer_rows = self.layout.layer_rows();
        // SAFETY: copies of whole rows of the records buffer, inside both the buffer and the
        // texture (sized for `capacity` records in whole rows).
        unsafe {
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(self.records_texture));
            gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, Some(self.records));
            let mut rows = (n * RECORD_TEXELS).div_ceil(width);
            let mut layer = 0;
            while rows > 0 {
                let here = rows.min(layer_rows);
                let offset = layer * layer_rows * width * TEXEL_BYTES;
                gl.tex_sub_image_3d(
                    glow::TEXTURE_2D_ARRAY,
                    0,
                    0,
                    0,
                    layer as i32,
                    width as i32,
                    here as i32,
                    1,
                    glow::RGBA,
                    glow::FLOAT,
                    glow::PixelUnpackData::BufferOffset(offset as u32),
                );
                rows -= here;
                layer += 1;
            }
            gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
            gl.active_texture(glow::TEXTURE1);
        }
    }

    /// Binds the quad program (its uniforms set for `n` splats in `viewport`) and its vertex
    /// array.
    pub(super) fn bind_quads(&self, gl: &glow::Context, n: usize, viewport: [i32; 4]) {
        let n = n.min(self.capacity);
        // SAFETY: binds the pre-pass's own quad program and vertex array and sets its
        // uniforms with values of the declared types.
        unsafe {
            gl.use_program(Some(self.quad));
            gl.bind_vertex_array(Some(self.quad_vao));
            let u = &self.quad_uniforms;
            gl.uniform_1_i32(u.u_records.as_ref(), 0);
            gl.uniform_1_i32(u.u_instances.as_ref(), n as i32);
            let [vx, vy, vw, vh] = viewport.map(|v| v as f32);
            gl.uniform_4_f32(u.u_viewport.as_ref(), vx, vy, vw, vh);
        }
    }

    /// Draws the quads of the first `n` records captured: `⌈n / QUADS_PER_INSTANCE⌉`
    /// instances of one batch (bound by [`PrePass::bind_quads`]).
    pub(super) fn draw_quads(&self, gl: &glow::Context, n: usize) {
        let n = n.min(self.capacity);
        let instances = n.div_ceil(QUADS_PER_INSTANCE) as i32;
        // SAFETY: the quad VAO's element buffer holds 6·QUADS_PER_INSTANCE u16 indices; the
        // shader drops the slots past `n` and reads records only below it.
        unsafe {
            gl.draw_elements_instanced(
                glow::TRIANGLES,
                6 * QUADS_PER_INSTANCE as i32,
                glow::UNSIGNED_SHORT,
                0,
                instances,
            )
        };
    }

    /// Records the buffer holds.
    pub(super) fn capacity(&self) -> usize {
        self.capacity
    }

    /// Deletes the objects.
    pub(super) fn destroy(&mut self, gl: &glow::Context) {
        self.owned.destroy(gl);
    }

    /// Forgets the objects (their context is gone).
    pub(super) fn abandon(&mut self) {
        self.owned.abandon();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_batch_quad_is_two_triangles_over_its_own_four_corners() {
        let idx = batch_indices();
        assert_eq!(idx.len(), 6 * QUADS_PER_INSTANCE);
        for (q, tri) in idx.chunks(6).enumerate() {
            let base = 4 * q as u16;
            let mut corners = tri.to_vec();
            corners.sort();
            corners.dedup();
            assert_eq!(corners, [base, base + 1, base + 2, base + 3]);
            // The shared edge is the diagonal (1, 2): both triangles hold it.
            assert!(tri[..3].contains(&(base + 1)) && tri[..3].contains(&(base + 2)));
            assert!(tri[3..].contains(&(base + 1)) && tri[3..].contains(&(base + 2)));
        }
    }
}
