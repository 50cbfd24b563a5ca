//! The transform-feedback pre-pass: the per-splat maths (covariance, projection, extent, SH)
//! once per drawn splat instead of once per quad corner.
//!
//! One `GL_POINTS` draw over the order buffer (the sorted visible splats) with the rasterizer
//! discarded runs `glsl/splat_prep.vert` — the same `splat_project.glsl` as the direct path —
//! and captures, interleaved, one [`RECORD_BYTES`]-byte record per splat: clip-space centre,
//! the clip-space corner offsets, colour and opacity, conic, centre in pixels. The quad draw
//! (`glsl/splat_quad.vert`) reads record `i` for instance `i` as per-instance attributes
//! (divisor 1) and only places its corner. GLES 3.0 / WebGL2 class: transform feedback and
//! instanced attributes, no compute, no texture buffers.
//!
//! The records buffer holds as many records as splats were uploaded (68 bytes each), sized
//! at upload; nothing is allocated per frame.

use crate::gl::bound::Bound;
use glow::HasContext;

use super::GlError;
use super::objects::{Creating, Owned};
use super::program;
use super::uniforms::Uniforms;

/// The pre-pass outputs, in capture order (the record layout).
pub(crate) const PREPASS_VARYINGS: [&str; 5] = [
    "t_clip",
    "t_axes",
    "t_color_opacity",
    "t_conic",
    "t_center_px",
];
/// Components of each varying of [`PREPASS_VARYINGS`] (= the quad stage's attributes 1..=5).
const COMPONENTS: [i32; 5] = [4, 4, 4, 3, 2];
/// Bytes of one record: 17 floats.
pub(crate) const RECORD_BYTES: usize = 68;

/// Below this many splats drawn, [`Pipeline::Auto`](super::Pipeline::Auto) draws directly.
/// On llvmpipe the pre-pass wins from about 10 splats on (`cargo bench --features testing --bench gl`,
/// `docs/gl-backend.md` "Pre-pass crossover"): its fixed cost there is a few µs. On a GPU a
/// second draw with its program switch costs tens of µs, more than a direct draw of a
/// thousand splats takes, so small clouds keep the direct path (costing at most 0.4 ms on
/// llvmpipe); `scripts/bench-gpu.sh` measures the crossover where a GPU is available.
pub const PREPASS_MIN_SPLATS: usize = 1024;

/// The pre-pass's GL objects.
#[derive(Debug)]
pub(super) struct PrePass {
    prep: glow::Program,
    pub(super) prep_uniforms: Uniforms,
    pub(super) quad: glow::Program,
    tf: glow::TransformFeedback,
    records: glow::Buffer,
    prep_vao: glow::VertexArray,
    pub(super) quad_vao: glow::VertexArray,
    /// Records the buffer holds.
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

impl PrePass {
    /// Builds the programs, the vertex arrays (the prep one reads `order` per vertex, the quad
    /// one the records per instance), the transform-feedback object with the records buffer on
    /// its binding 0, and sizes the records for `capacity` splats. Leaves every binding as it
    /// found it.
    pub(super) fn new(
        gl: &glow::Context,
        src: &Sources,
        order: glow::Buffer,
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
        let (prep_vao, quad_vao) = (objects.vertex_array()?, objects.vertex_array()?);
        let records = objects.buffer()?;
        let tf = objects.transform_feedback()?;
        // SAFETY: configures the objects created just above, then binds the host's vertex
        // array, array buffer, transform-feedback object and generic transform-feedback
        // buffer back (queried first).
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
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(records));
            let mut offset = 0;
            for (k, n) in COMPONENTS.into_iter().enumerate() {
                let index = 1 + k as u32;
                gl.enable_vertex_attrib_array(index);
                let stride = RECORD_BYTES as i32;
                gl.vertex_attrib_pointer_f32(index, n, glow::FLOAT, false, stride, offset);
                gl.vertex_attrib_divisor(index, 1);
                offset += 4 * n;
            }
            debug_assert_eq!(offset as usize, RECORD_BYTES);
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
            tf,
            records,
            prep_vao,
            quad_vao,
            capacity: 0,
            owned: objects.keep("SplatRenderer"),
        };
        p.reserve(gl, capacity)?;
        Ok(p)
    }

    /// Grows the records buffer to hold `capacity` splats (never shrinks). Leaves the
    /// `GL_ARRAY_BUFFER` binding as it found it.
    pub(super) fn reserve(&mut self, gl: &glow::Context, capacity: usize) -> Result<(), GlError> {
        if capacity <= self.capacity {
            return Ok(());
        }
        let bytes = capacity
            .checked_mul(RECORD_BYTES)
            .filter(|&b| b <= i32::MAX as usize);
        let Some(bytes) = bytes else {
            return Err(GlError::Upload(format!(
                "{capacity} splats need {} bytes of pre-pass records, more than one GL buffer \
                 holds",
                capacity as u128 * RECORD_BYTES as u128
            )));
        };
        let errors = super::error::ErrorScope::begin(gl)?;
        // SAFETY: (re)allocates the pre-pass's own buffer; rebinds the host's array buffer.
        unsafe {
            let host = gl.bound_buffer(glow::ARRAY_BUFFER_BINDING);
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.records));
            gl.buffer_data_size(glow::ARRAY_BUFFER, bytes as i32, glow::DYNAMIC_COPY);
            gl.bind_buffer(glow::ARRAY_BUFFER, host);
        }
        // After a failed glBufferData the buffer's size is undefined: claim nothing, so no
        // draw takes the pre-pass path until a reservation succeeds.
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

    /// Captures the records of the first `n` splats of the order (≤ the capacity), then binds
    /// the quad program and vertex array for the instanced draw. Leaves the default
    /// transform-feedback object bound and `GL_RASTERIZER_DISCARD` disabled (as a draw sets
    /// them, see [`super::state`]).
    pub(super) fn capture(&self, gl: &glow::Context, n: usize) {
        let n = n.min(self.capacity);
        // SAFETY: one POINTS draw of `n ≤ capacity` vertices into the records buffer (bound
        // to the transform-feedback object's binding 0 at creation), which holds `capacity`
        // records; then the quad program and vertex array.
        unsafe {
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(self.tf));
            gl.enable(glow::RASTERIZER_DISCARD);
            gl.begin_transform_feedback(glow::POINTS);
            gl.draw_arrays(glow::POINTS, 0, n as i32);
            gl.end_transform_feedback();
            gl.disable(glow::RASTERIZER_DISCARD);
            gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, None);
            gl.use_program(Some(self.quad));
            gl.bind_vertex_array(Some(self.quad_vao));
        }
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
