//! A modern (GLES 3 / core profile) host for `examples/embed.rs` and its test: it draws an
//! opaque cube with its own shader, vertex array and depth buffer, and lets splatgl draw the
//! splats into the same framebuffer, occluded by the cube, with `restore_state = true`.
//!
//! Like many real hosts it sets its pipeline state **once** (program, vertex array, depth
//! test, depth writes, clear colour) and per frame only clears and draws, so any state splatgl
//! left changed would break its next frame.
#![allow(dead_code)]

use std::error::Error;

use glam::{Mat4, Vec3};
use glow::HasContext;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::gl::{ColorFormat, DepthFormat, ReadbackTarget, SplatRenderer};
use splatgl::headless::HeadlessContext;
use splatgl::image::Image;

/// The host's clear colour (opaque dark blue-grey).
pub const CLEAR: [f32; 4] = [0.1, 0.1, 0.12, 1.0];

const VERT: &str = "
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_color;
uniform mat4 u_mvp;
out vec3 v_color;
void main() {
    v_color = a_color;
    gl_Position = u_mvp * vec4(a_position, 1.0);
}
";

const FRAG: &str = "
precision highp float;
in vec3 v_color;
out vec4 o_color;
void main() {
    o_color = vec4(v_color, 1.0);
}
";

/// A unit cube (±0.5), one flat colour per face: 24 vertices (position, colour), 36 indices.
pub fn cube() -> (Vec<f32>, Vec<u16>) {
    let faces: [(Vec3, Vec3, Vec3, [f32; 3]); 6] = [
        (Vec3::X, Vec3::Y, Vec3::Z, [0.9, 0.4, 0.1]),
        (-Vec3::X, Vec3::Y, -Vec3::Z, [0.7, 0.3, 0.1]),
        (Vec3::Y, Vec3::Z, Vec3::X, [0.95, 0.6, 0.2]),
        (-Vec3::Y, Vec3::X, Vec3::Z, [0.4, 0.2, 0.05]),
        (Vec3::Z, Vec3::X, Vec3::Y, [0.85, 0.5, 0.15]),
        (-Vec3::Z, Vec3::Y, Vec3::X, [0.6, 0.25, 0.1]),
    ];
    let (mut vertices, mut indices) = (Vec::new(), Vec::new());
    for (k, (n, u, v, rgb)) in faces.iter().enumerate() {
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let p = 0.5 * (*n + a * *u + b * *v);
            vertices.extend_from_slice(&[p.x, p.y, p.z, rgb[0], rgb[1], rgb[2]]);
        }
        let base = 4 * k as u16;
        indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (vertices, indices)
}

/// The host's GL objects.
pub struct ModernHost {
    program: glow::Program,
    vao: glow::VertexArray,
    buffers: [glow::Buffer; 2],
    u_mvp: Option<glow::UniformLocation>,
    index_count: i32,
}

impl ModernHost {
    /// Compiles the host's shader, uploads the cube and sets the host's state once.
    pub fn new(gl: &glow::Context) -> Result<Self, Box<dyn Error>> {
        let version = if gl.version().is_embedded {
            "#version 300 es\n"
        } else {
            "#version 330 core\n"
        };
        let (vertices, indices) = cube();
        // SAFETY: creates and configures the host's own objects on the current context.
        unsafe {
            let program = gl.create_program()?;
            for (kind, src) in [(glow::VERTEX_SHADER, VERT), (glow::FRAGMENT_SHADER, FRAG)] {
                let s = gl.create_shader(kind)?;
                gl.shader_source(s, &format!("{version}{src}"));
                gl.compile_shader(s);
                if !gl.get_shader_compile_status(s) {
                    return Err(gl.get_shader_info_log(s).into());
                }
                gl.attach_shader(program, s);
                gl.delete_shader(s);
            }
            gl.link_program(program);
            if !gl.get_program_link_status(program) {
                return Err(gl.get_program_info_log(program).into());
            }
            let vao = gl.create_vertex_array()?;
            let (vbo, ebo) = (gl.create_buffer()?, gl.create_buffer()?);
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            let bytes: &[u8] = bytemuck::cast_slice(&vertices);
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytes, glow::STATIC_DRAW);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ebo));
            let bytes: &[u8] = bytemuck::cast_slice(&indices);
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, bytes, glow::STATIC_DRAW);
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 24, 0);
            gl.enable_vertex_attrib_array(1);
            gl.vertex_attrib_pointer_f32(1, 3, glow::FLOAT, false, 24, 12);
            // The state this host relies on from now on (never set again).
            gl.use_program(Some(program));
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            gl.disable(glow::BLEND);
            gl.clear_color(CLEAR[0], CLEAR[1], CLEAR[2], CLEAR[3]);
            let u_mvp = gl.get_uniform_location(program, "u_mvp");
            Ok(ModernHost {
                program,
                vao,
                buffers: [vbo, ebo],
                u_mvp,
                index_count: indices.len() as i32,
            })
        }
    }

    /// One host frame: clear colour and depth, draw the cube with `mvp`.
    pub fn draw(&self, gl: &glow::Context, mvp: Mat4) {
        // SAFETY: a clear of the bound framebuffer.
        unsafe { gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT) };
        self.draw_cube(gl, mvp);
    }

    /// Draws the cube with `mvp` (no clear).
    pub fn draw_cube(&self, gl: &glow::Context, mvp: Mat4) {
        // SAFETY: draws the host's cube with the state set in `new`.
        unsafe {
            gl.uniform_matrix_4_f32_slice(self.u_mvp.as_ref(), false, &mvp.to_cols_array());
            gl.draw_elements(glow::TRIANGLES, self.index_count, glow::UNSIGNED_SHORT, 0);
        }
    }

    /// Deletes the host's objects.
    pub fn destroy(&self, gl: &glow::Context) {
        // SAFETY: deletes the host's own objects.
        unsafe {
            gl.delete_program(self.program);
            gl.delete_vertex_array(self.vao);
            self.buffers.iter().for_each(|b| gl.delete_buffer(*b));
        }
    }
}

/// The scene's camera: at (0.3, 0.4, 4) looking at the origin, 50° vertical fov.
pub fn camera(width: u32, height: u32) -> Camera {
    let eye = Vec3::new(0.3, 0.4, 4.0);
    Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 50f32.to_radians(), width, height)
}

/// The cube's model matrix: 0.8 wide, between the camera and the cloud (at z ≈ 0).
pub fn cube_model() -> Mat4 {
    Mat4::from_translation(Vec3::new(0.35, 0.1, 1.6)) * Mat4::from_scale(Vec3::splat(0.8))
}

/// The frames of one run.
pub struct Frames {
    /// A host frame drawn before splatgl was ever called.
    pub host_only_before: Image,
    /// Host frames with splats.
    pub with_splats: Vec<Image>,
    /// A host frame (no splats) drawn after the splat frames.
    pub host_only_after: Image,
}

/// The example: the host's frame alone, then `frames` frames with splats (the host's own
/// view and projection passed with `draw_with_matrices`, restore mode), then the host's frame
/// alone again. Renders into a `width × height` RGBA8 + depth framebuffer (the stand-in for a
/// window).
pub fn run(
    ctx: &HeadlessContext,
    cloud: &SplatCloud,
    frames: usize,
    width: u32,
    height: u32,
) -> Result<Frames, Box<dyn Error>> {
    let gl = ctx.gl();
    let mut window = ReadbackTarget::new(
        gl,
        width,
        height,
        ColorFormat::Rgba8,
        Some(DepthFormat::Depth24),
    )?;
    window.bind(gl)?; // the host's framebuffer and viewport, bound once
    let host = ModernHost::new(gl)?;
    let cam = camera(width, height);
    let (view, projection) = (cam.gl_view(), cam.gl_projection());
    let mvp = projection * view * cube_model();
    host.draw(gl, mvp);
    let host_only_before = window.read_image(gl)?;

    let mut renderer = SplatRenderer::new(gl)?;
    renderer.settings_mut().restore_state = true;
    renderer.settings_mut().depth_test = true; // the host's depth buffer occludes splats
    renderer.upload(gl, cloud)?;
    let viewport = [0, 0, width as i32, height as i32];
    let mut with_splats = Vec::new();
    for _ in 0..frames {
        host.draw(gl, mvp);
        renderer.draw_frame(gl, view, projection, viewport)?; // culls, sorts, draws
        with_splats.push(window.read_image(gl)?);
    }
    host.draw(gl, mvp);
    let host_only_after = window.read_image(gl)?;
    renderer.destroy(gl);
    host.destroy(gl);
    window.destroy(gl);
    Ok(Frames {
        host_only_before,
        with_splats,
        host_only_after,
    })
}
