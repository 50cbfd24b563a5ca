//! The bindings and pixel-unpack state `new` and `upload` change, captured first and put
//! back when the guard drops (on every return path).

use crate::gl::bound::Bound;
use glow::HasContext;

use crate::gl::context::ContextInfo;

/// `GL_UNPACK_*` integer state and the value an upload needs (tight rows from client memory).
const UNPACK: [(u32, i32); 6] = [
    (glow::UNPACK_ALIGNMENT, 4),
    (glow::UNPACK_ROW_LENGTH, 0),
    (glow::UNPACK_IMAGE_HEIGHT, 0),
    (glow::UNPACK_SKIP_ROWS, 0),
    (glow::UNPACK_SKIP_PIXELS, 0),
    (glow::UNPACK_SKIP_IMAGES, 0),
];

/// Desktop-only `GL_UNPACK_*` booleans (byte order), needed `false`.
const UNPACK_DESKTOP: [u32; 2] = [glow::UNPACK_SWAP_BYTES, glow::UNPACK_LSB_FIRST];

/// Saved bindings and unpack state, restored on drop.
pub(crate) struct Bindings<'gl> {
    gl: &'gl glow::Context,
    vertex_array: Option<Option<glow::VertexArray>>,
    array_buffer: Option<glow::Buffer>,
    texture_2d_array: Option<Option<glow::Texture>>,
    unpack_buffer: Option<Option<glow::Buffer>>,
    unpack: [Option<i32>; UNPACK.len() + UNPACK_DESKTOP.len()],
}

impl<'gl> Bindings<'gl> {
    fn empty(gl: &'gl glow::Context) -> Self {
        // SAFETY: a binding query.
        let array_buffer = unsafe { gl.bound_buffer(glow::ARRAY_BUFFER_BINDING) };
        Bindings {
            gl,
            vertex_array: None,
            array_buffer,
            texture_2d_array: None,
            unpack_buffer: None,
            unpack: [None; UNPACK.len() + UNPACK_DESKTOP.len()],
        }
    }

    /// What `SplatRenderer::new` changes: the VAO and `GL_ARRAY_BUFFER` bindings.
    pub(crate) fn for_new(gl: &'gl glow::Context) -> Self {
        let mut b = Self::empty(gl);
        // SAFETY: a binding query.
        b.vertex_array = Some(unsafe { gl.bound_vertex_array(glow::VERTEX_ARRAY_BINDING) });
        b
    }

    /// What an upload changes: `GL_ARRAY_BUFFER`, the active unit's `TEXTURE_2D_ARRAY` and
    /// the unpack state, which is then set to tight rows read from client memory (whatever
    /// the host left must not offset, swap or redirect the read of the staging buffer).
    pub(crate) fn for_upload(gl: &'gl glow::Context, ctx: ContextInfo) -> Self {
        let mut b = Self::empty(gl);
        // SAFETY: state queries, and unpack state set to valid values.
        unsafe {
            b.texture_2d_array = Some(gl.bound_texture(glow::TEXTURE_BINDING_2D_ARRAY));
            let unpack_buffer = gl.bound_buffer(glow::PIXEL_UNPACK_BUFFER_BINDING);
            if unpack_buffer.is_some() {
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
                b.unpack_buffer = Some(unpack_buffer);
            }
            let desktop = UNPACK_DESKTOP.map(|p| (p, 0));
            let n = if ctx.desktop() {
                b.unpack.len()
            } else {
                UNPACK.len()
            };
            for (k, (pname, need)) in UNPACK.iter().chain(&desktop).take(n).enumerate() {
                let host = gl.get_parameter_i32(*pname);
                if host != *need {
                    gl.pixel_store_i32(*pname, *need);
                    b.unpack[k] = Some(host);
                }
            }
        }
        b
    }
}

impl Drop for Bindings<'_> {
    fn drop(&mut self) {
        let gl = self.gl;
        let desktop = UNPACK_DESKTOP.map(|p| (p, 0));
        // SAFETY: binds back objects the host had bound (or none) and sets state back to the
        // values queried from this context.
        unsafe {
            for ((pname, _), host) in UNPACK.iter().chain(&desktop).zip(self.unpack) {
                if let Some(v) = host {
                    gl.pixel_store_i32(*pname, v);
                }
            }
            if let Some(b) = self.unpack_buffer {
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, b);
            }
            if let Some(t) = self.texture_2d_array {
                gl.bind_texture(glow::TEXTURE_2D_ARRAY, t);
            }
            if let Some(v) = self.vertex_array {
                gl.bind_vertex_array(v);
            }
            gl.bind_buffer(glow::ARRAY_BUFFER, self.array_buffer);
        }
    }
}
