//! A legacy host for `examples/embed_legacy.rs` and its test: a desktop compatibility-profile
//! application drawing with the fixed-function pipeline — a textured ground quad in immediate
//! mode, then (after splatgl's splats) a cube from client arrays in a vertex buffer — with
//! splatgl drawing between its two passes, `restore_state = true`.
//!
//! It relies on state it set once, as legacy code does: the checker texture bound on unit 0
//! with `GL_TEXTURE_2D` enabled and `GL_MODULATE`, the cube's VBO bound as `GL_ARRAY_BUFFER`
//! (every frame it calls `glVertexPointer(offset)` expecting it still bound), the client
//! arrays enabled, depth test and writes on, `GL_MODELVIEW` the matrix mode.
#![allow(dead_code)]

use std::error::Error;
use std::ffi::c_void;

use glam::Mat4;
use glow::HasContext;
use splatgl::SplatCloud;
use splatgl::gl::{ColorFormat, DepthFormat, ReadbackTarget, SplatRenderer};
use splatgl::headless::HeadlessContext;
use splatgl::image::Image;

use super::legacy_gl::{self as lg, LegacyGl};
use super::modern::{CLEAR, camera, cube, cube_model};

/// The checker texture's two colours (RGBA8).
pub const CHECKER: [[u8; 4]; 2] = [[40, 150, 60, 255], [230, 225, 200, 255]];
/// Height of the ground plane.
pub const GROUND_Y: f32 = -0.7;

/// The host's GL objects and entry points.
pub struct LegacyHost {
    lgl: LegacyGl,
    texture: glow::Texture,
    vbo: glow::Buffer,
    vertex_count: i32,
}

impl LegacyHost {
    /// Loads the legacy entry points, creates the texture and the cube's VBO and sets the
    /// state the host relies on, once.
    pub fn new(ctx: &HeadlessContext) -> Result<Self, Box<dyn Error>> {
        let lgl = LegacyGl::load(|name| ctx.get_proc_address(name))?;
        let gl = ctx.gl();
        let (vertices, indices) = cube();
        // Unindexed triangles (position, colour) for glDrawArrays from client arrays.
        let flat: Vec<f32> = indices
            .iter()
            .flat_map(|&i| vertices[6 * i as usize..6 * i as usize + 6].to_vec())
            .collect();
        let texels: Vec<u8> = (0..64)
            .flat_map(|i| CHECKER[((i % 8) / 2 + (i / 8) / 2) % 2])
            .collect();
        // SAFETY: creates the host's objects and sets fixed-function state on a current
        // compatibility-profile context; the legacy pointers are that context's.
        unsafe {
            let texture = gl.create_texture()?;
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            gl.tex_image_2d(
                glow::TEXTURE_2D,
                0,
                glow::RGBA8 as i32,
                8,
                8,
                0,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelUnpackData::Slice(Some(&texels)),
            );
            for p in [glow::TEXTURE_MIN_FILTER, glow::TEXTURE_MAG_FILTER] {
                gl.tex_parameter_i32(glow::TEXTURE_2D, p, glow::NEAREST as i32);
            }
            gl.enable(glow::TEXTURE_2D);
            (lgl.tex_envi)(lg::TEXTURE_ENV, lg::TEXTURE_ENV_MODE, lg::MODULATE as i32);
            let vbo = gl.create_buffer()?;
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            let bytes: &[u8] = bytemuck::cast_slice(&flat);
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytes, glow::STATIC_DRAW);
            (lgl.enable_client_state)(lg::VERTEX_ARRAY);
            (lgl.enable_client_state)(lg::COLOR_ARRAY);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            (lgl.shade_model)(lg::FLAT);
            gl.clear_color(CLEAR[0], CLEAR[1], CLEAR[2], CLEAR[3]);
            (lgl.matrix_mode)(lg::MODELVIEW);
            Ok(LegacyHost {
                lgl,
                texture,
                vbo,
                vertex_count: (flat.len() / 6) as i32,
            })
        }
    }

    /// Clears and draws the textured ground quad (immediate mode) with `projection` and `view`.
    pub fn ground_pass(&self, gl: &glow::Context, projection: Mat4, view: Mat4) {
        let l = &self.lgl;
        // SAFETY: fixed-function calls on the current compatibility context.
        unsafe {
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            (l.matrix_mode)(lg::PROJECTION);
            (l.load_matrix)(projection.to_cols_array().as_ptr());
            (l.matrix_mode)(lg::MODELVIEW);
            (l.load_matrix)(view.to_cols_array().as_ptr());
            (l.color4)(1.0, 1.0, 1.0, 1.0);
            (l.begin)(lg::QUADS);
            let s = 3.0;
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                (l.tex_coord2)(u * 6.0, v * 6.0);
                (l.vertex3)(s * (2.0 * u - 1.0), GROUND_Y, s * (1.0 - 2.0 * v));
            }
            (l.end)();
        }
    }

    /// Draws the cube from client arrays in the (still bound) VBO, untextured.
    pub fn cube_pass(&self, gl: &glow::Context, view: Mat4) {
        let l = &self.lgl;
        // SAFETY: the pointers are byte offsets into the VBO the host bound in `new` and
        // expects still bound; 36 vertices of 24 bytes are there.
        unsafe {
            gl.disable(glow::TEXTURE_2D);
            (l.load_matrix)((view * cube_model()).to_cols_array().as_ptr());
            (l.vertex_pointer)(3, glow::FLOAT, 24, std::ptr::null::<c_void>());
            (l.color_pointer)(3, glow::FLOAT, 24, 12usize as *const c_void);
            (l.draw_arrays)(glow::TRIANGLES, 0, self.vertex_count);
            gl.enable(glow::TEXTURE_2D);
        }
    }

    /// Deletes the host's objects.
    pub fn destroy(&self, gl: &glow::Context) {
        // SAFETY: deletes the host's own objects.
        unsafe {
            gl.delete_texture(self.texture);
            gl.delete_buffer(self.vbo);
        }
    }
}

/// The example: `frames` frames of ground pass, splats, cube pass, in a `width × height`
/// RGBA8 + depth framebuffer (the stand-in for the window), with the host's fixed-function
/// matrices passed to `draw_with_matrices`. Also returns a frame drawn before splatgl was
/// created, with the same passes and no splats.
pub fn run(
    ctx: &HeadlessContext,
    cloud: &SplatCloud,
    frames: usize,
    width: u32,
    height: u32,
) -> Result<(Image, Vec<Image>), Box<dyn Error>> {
    let gl = ctx.gl();
    let mut window = ReadbackTarget::new(
        gl,
        width,
        height,
        ColorFormat::Rgba8,
        Some(DepthFormat::Depth24),
    )?;
    window.bind(gl)?;
    let host = LegacyHost::new(ctx)?;
    let cam = camera(width, height);
    let (view, projection) = (cam.gl_view(), cam.gl_projection());
    host.ground_pass(gl, projection, view);
    host.cube_pass(gl, view);
    let without_splats = window.read_image(gl)?;

    let mut renderer = SplatRenderer::new(gl)?;
    renderer.settings_mut().restore_state = true;
    renderer.upload(gl, cloud)?;
    let viewport = [0, 0, width as i32, height as i32];
    let mut images = Vec::new();
    for _ in 0..frames {
        host.ground_pass(gl, projection, view);
        renderer.draw_frame(gl, view, projection, viewport)?; // culls, sorts, draws
        host.cube_pass(gl, view);
        images.push(window.read_image(gl)?);
    }
    renderer.destroy(gl);
    host.destroy(gl);
    window.destroy(gl);
    Ok((without_splats, images))
}
