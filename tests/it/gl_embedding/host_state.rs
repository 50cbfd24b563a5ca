//! A hostile host for the state tests: over 60 pieces of GL state set to distinctive
//! non-default values (bindings on several texture units, buffers, blend separate, depth,
//! stencil, scissor, colour mask, pixel store, polygon state; on desktop GL logic op, polygon
//! mode, sRGB; in the compatibility profile matrices, texture enables, client arrays, current
//! colour and more), each with the query that reads it back.

use std::num::NonZeroU32;

use glam::Mat4;
use glow::HasContext;
use splatgl::headless::{GlApi, HeadlessContext};

use super::host::legacy_gl::{self as lg, LegacyGl};

/// How a piece is read back (every value as `f64`s; booleans 0/1).
#[derive(Clone, Copy)]
pub enum Q {
    /// `glGetIntegerv` of n values.
    Int(u32, usize),
    /// `glGetFloatv` of n values.
    Float(u32, usize),
    /// `glIsEnabled`.
    Enabled(u32),
    /// `glGetVertexAttribfv(index, pname)`, 4 values.
    Attrib(u32, u32),
    /// `glGetTexEnviv(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE)`.
    EnvMode,
}

type Setter = Box<dyn Fn(&Host)>;

/// One piece of state.
pub struct Piece {
    pub name: String,
    /// The query enum (matches `splatgl::gl::state::Left::pname`).
    pub pname: u32,
    /// Texture unit for per-unit state (made active for the query).
    pub unit: Option<u32>,
    pub q: Q,
    /// Whether the host's value differs from a fresh context's (a few pieces keep the
    /// default on purpose, e.g. `GL_DEPTH_WRITEMASK` true, the value splatgl must put back).
    pub distinct: bool,
    /// State of the bound vertex array object (read through the host's VAO).
    pub vao_state: bool,
    set: Option<Setter>,
}

/// The host's objects: the values its bindings point at.
pub struct Host<'a> {
    pub _ctx: &'a HeadlessContext,
    pub gl: &'a glow::Context,
    pub lgl: LegacyGl,
    pub api: GlApi,
    pub srgb_switch: bool,
    program: glow::Program,
    vao: Option<glow::VertexArray>,
    /// array, element, unpack, pack, uniform, copy read, copy write, transform feedback.
    buffers: Vec<glow::Buffer>,
    tex2d: Vec<glow::Texture>,
    tex_array: Vec<glow::Texture>,
    tex3d: glow::Texture,
    cube: glow::Texture,
    tex1d: Option<glow::Texture>,
    rect: Option<glow::Texture>,
    samplers: Vec<glow::Sampler>,
    rb: glow::Renderbuffer,
    draw_fbo: glow::Framebuffer,
    read_fbo: glow::Framebuffer,
    tf: glow::TransformFeedback,
}

const ARRAY: usize = 0;
const ELEMENT: usize = 1;
const UNPACK: usize = 2;
const PACK: usize = 3;
const UNIFORM: usize = 4;
const COPY_READ: usize = 5;
const COPY_WRITE: usize = 6;
const TF_BUFFER: usize = 7;

/// A distinctive matrix.
pub fn matrix(k: f32) -> Mat4 {
    Mat4::from_cols_array(&std::array::from_fn(|i| k + i as f32 * 0.25))
}

impl<'a> Host<'a> {
    /// Creates the host's objects on the current context of `api`.
    pub fn new(ctx: &'a HeadlessContext, api: GlApi) -> Self {
        let gl = ctx.gl();
        let lgl = LegacyGl::load(|n| ctx.get_proc_address(n)).expect("entry points");
        let desktop = api != GlApi::Gles3;
        let srgb_switch = desktop
            || gl
                .supported_extensions()
                .contains("GL_EXT_sRGB_write_control");
        // SAFETY: creates objects on the current context and gives each its target.
        unsafe {
            let program = host_program(gl, desktop);
            let vao = (api != GlApi::DesktopCompat).then(|| gl.create_vertex_array().unwrap());
            let buffers: Vec<_> = (0..8).map(|_| gl.create_buffer().unwrap()).collect();
            let tex = |target: u32| {
                let t = gl.create_texture().unwrap();
                gl.bind_texture(target, Some(t));
                gl.bind_texture(target, None);
                t
            };
            let tex2d = (0..4).map(|_| tex(glow::TEXTURE_2D)).collect();
            let tex_array = (0..3).map(|_| tex(glow::TEXTURE_2D_ARRAY)).collect();
            let (tex3d, cube) = (tex(glow::TEXTURE_3D), tex(glow::TEXTURE_CUBE_MAP));
            let tex1d = desktop.then(|| tex(glow::TEXTURE_1D));
            let rect = desktop.then(|| tex(glow::TEXTURE_RECTANGLE));
            let samplers = (0..3).map(|_| gl.create_sampler().unwrap()).collect();
            let rb = gl.create_renderbuffer().unwrap();
            let (draw_fbo, read_fbo) = (framebuffer(gl, 64, 64), framebuffer(gl, 8, 8));
            let tf = gl.create_transform_feedback().unwrap();
            Host {
                _ctx: ctx,
                gl,
                lgl,
                api,
                srgb_switch,
                program,
                vao,
                buffers,
                tex2d,
                tex_array,
                tex3d,
                cube,
                tex1d,
                rect,
                samplers,
                rb,
                draw_fbo,
                read_fbo,
                tf,
            }
        }
    }

    /// Sets every piece to the host's value (in list order).
    pub fn apply(&self, pieces: &[Piece]) {
        for p in pieces {
            if let Some(set) = &p.set {
                set(self);
                // SAFETY: glGetError.
                let e = unsafe { self.gl.get_error() };
                assert_eq!(e, glow::NO_ERROR, "{:?}: setting {}", self.api, p.name);
            }
        }
    }

    /// Binds the host's vertex array again (as the host would after a draw that leaves 0).
    pub fn bind_vao(&self) {
        // SAFETY: binds the host's own VAO (or 0, its default one, in the compatibility test).
        unsafe { self.gl.bind_vertex_array(self.vao) };
    }
}

/// A complete RGBA8 + depth/stencil framebuffer of `w × h`.
unsafe fn framebuffer(gl: &glow::Context, w: i32, h: i32) -> glow::Framebuffer {
    // SAFETY: the caller's contract (a current context); objects made here, bound and unbound.
    unsafe {
        let fbo = gl.create_framebuffer().unwrap();
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        for (format, attach) in [
            (glow::RGBA8, glow::COLOR_ATTACHMENT0),
            (glow::DEPTH24_STENCIL8, glow::DEPTH_STENCIL_ATTACHMENT),
        ] {
            let rb = gl.create_renderbuffer().unwrap();
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
            gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attach, glow::RENDERBUFFER, Some(rb));
        }
        assert_eq!(
            gl.check_framebuffer_status(glow::FRAMEBUFFER),
            glow::FRAMEBUFFER_COMPLETE
        );
        gl.bind_renderbuffer(glow::RENDERBUFFER, None);
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        fbo
    }
}

/// A linked program of the host.
unsafe fn host_program(gl: &glow::Context, desktop: bool) -> glow::Program {
    let v = if desktop {
        "#version 330 core\n"
    } else {
        "#version 300 es\nprecision highp float;\n"
    };
    // SAFETY: the caller's contract (a current context); shaders and a program made here.
    unsafe {
        let p = gl.create_program().unwrap();
        for (kind, body) in [
            (
                glow::VERTEX_SHADER,
                "void main() { gl_Position = vec4(0.0); }",
            ),
            (
                glow::FRAGMENT_SHADER,
                "out vec4 o; void main() { o = vec4(1.0); }",
            ),
        ] {
            let s = gl.create_shader(kind).unwrap();
            gl.shader_source(s, &format!("{v}{body}"));
            gl.compile_shader(s);
            assert!(
                gl.get_shader_compile_status(s),
                "{}",
                gl.get_shader_info_log(s)
            );
            gl.attach_shader(p, s);
            gl.delete_shader(s);
        }
        gl.link_program(p);
        assert!(gl.get_program_link_status(p));
        p
    }
}

/// Reads a piece back (making its unit active first; the caller restores the active unit).
pub fn query(gl: &glow::Context, lgl: &LegacyGl, p: &Piece) -> Vec<f64> {
    // SAFETY: state queries with output buffers of the size asked for.
    unsafe {
        if let Some(u) = p.unit {
            gl.active_texture(glow::TEXTURE0 + u);
        }
        match p.q {
            Q::Int(pname, n) => {
                let mut v = vec![0i32; n];
                gl.get_parameter_i32_slice(pname, &mut v);
                v.into_iter().map(f64::from).collect()
            }
            Q::Float(pname, n) => {
                let mut v = vec![0f32; n];
                gl.get_parameter_f32_slice(pname, &mut v);
                v.into_iter().map(f64::from).collect()
            }
            Q::Enabled(cap) => vec![f64::from(u8::from(gl.is_enabled(cap)))],
            Q::Attrib(index, pname) => {
                let mut v = [0f32; 4];
                gl.get_vertex_attrib_parameter_f32_slice(index, pname, &mut v);
                v.into_iter().map(f64::from).collect()
            }
            Q::EnvMode => {
                let mut v = 0i32;
                (lgl.get_tex_enviv)(lg::TEXTURE_ENV, lg::TEXTURE_ENV_MODE, &mut v);
                vec![f64::from(v)]
            }
        }
    }
}

/// Reads every piece; leaves the active texture unit as it found it.
pub fn query_all(gl: &glow::Context, lgl: &LegacyGl, pieces: &[Piece]) -> Vec<Vec<f64>> {
    // SAFETY: a state query, and restoring the value read after each per-unit query.
    let active = unsafe { gl.get_parameter_i32(glow::ACTIVE_TEXTURE) } as u32;
    // SAFETY: restores a value read from this context.
    let restore = || unsafe { gl.active_texture(active) };
    pieces
        .iter()
        .map(|p| {
            let v = query(gl, lgl, p);
            restore();
            v
        })
        .collect()
}

/// A setter closure from an unsafe GL block.
macro_rules! s {
    (|$h:ident| $body:expr) => {
        Some(Box::new(move |$h: &Host| {
            // SAFETY: a state setter on the host's own current context and objects.
            unsafe {
                $body;
            }
        }) as Setter)
    };
}

/// The list being built.
struct Pieces(Vec<Piece>);

impl Pieces {
    fn add(&mut self, name: &str, pname: u32, unit: Option<u32>, q: Q, set: Option<Setter>) {
        self.0.push(Piece {
            name: name.to_owned(),
            pname,
            unit,
            q,
            distinct: true,
            vao_state: false,
            set,
        })
    }
}

fn int(pname: u32) -> Q {
    Q::Int(pname, 1)
}

/// The host's pieces for `api` (only those that exist there), one per line.
#[rustfmt::skip]
pub fn pieces(host: &Host) -> Vec<Piece> {
    let compat = host.api == GlApi::DesktopCompat;
    let mut p = Pieces(Vec::new());
    bindings(&mut p, host.api != GlApi::Gles3);
    fixed_state(&mut p, host.api);
    if host.api != GlApi::Gles3 {
        desktop_state(&mut p);
    }
    if host.srgb_switch {
        // Desktop default: off (the host turns it on); ES default: on (the host turns it off).
        p.add("GL_FRAMEBUFFER_SRGB", glow::FRAMEBUFFER_SRGB, None, Q::Enabled(glow::FRAMEBUFFER_SRGB), s!(|h| {
            if h.api == GlApi::Gles3 { h.gl.disable(glow::FRAMEBUFFER_SRGB) } else { h.gl.enable(glow::FRAMEBUFFER_SRGB) }
        }));
    }
    if compat {
        compatibility_state(&mut p);
    }
    // Last: the active unit (the per-unit setters above change it).
    p.add("GL_ACTIVE_TEXTURE", glow::ACTIVE_TEXTURE, None, int(glow::ACTIVE_TEXTURE), s!(|h| h.gl.active_texture(glow::TEXTURE3)));
    let mut v = p.0;
    for p in &mut v {
        // The default, which splatgl changes for its draw and must put back.
        p.distinct &= p.pname != glow::DEPTH_WRITEMASK;
        p.distinct &= !(compat && p.pname == glow::VERTEX_ARRAY_BINDING);
        p.vao_state = p.pname == glow::ELEMENT_ARRAY_BUFFER_BINDING || matches!(p.q, Q::Attrib(2, _));
    }
    v
}

/// Bindings: program, VAO and its attribute state, buffers, framebuffers, textures and
/// samplers on several units.
#[rustfmt::skip]
fn bindings(p: &mut Pieces, desktop: bool) {
    use Q::*;
    // --- bindings ---
    p.add("GL_CURRENT_PROGRAM", glow::CURRENT_PROGRAM, None, int(glow::CURRENT_PROGRAM), s!(|h| h.gl.use_program(Some(h.program))));
    // The compatibility host draws from client arrays on the default VAO 0 (not distinctive).
    p.add("GL_VERTEX_ARRAY_BINDING", glow::VERTEX_ARRAY_BINDING, None, int(glow::VERTEX_ARRAY_BINDING), s!(|h| h.gl.bind_vertex_array(h.vao)));
    for (name, target, binding, k) in [
        ("GL_ARRAY_BUFFER_BINDING", glow::ARRAY_BUFFER, glow::ARRAY_BUFFER_BINDING, ARRAY),
        ("GL_ELEMENT_ARRAY_BUFFER_BINDING", glow::ELEMENT_ARRAY_BUFFER, glow::ELEMENT_ARRAY_BUFFER_BINDING, ELEMENT),
        ("GL_PIXEL_UNPACK_BUFFER_BINDING", glow::PIXEL_UNPACK_BUFFER, glow::PIXEL_UNPACK_BUFFER_BINDING, UNPACK),
        ("GL_PIXEL_PACK_BUFFER_BINDING", glow::PIXEL_PACK_BUFFER, glow::PIXEL_PACK_BUFFER_BINDING, PACK),
        ("GL_UNIFORM_BUFFER_BINDING", glow::UNIFORM_BUFFER, glow::UNIFORM_BUFFER_BINDING, UNIFORM),
        ("GL_COPY_READ_BUFFER_BINDING", glow::COPY_READ_BUFFER, glow::COPY_READ_BUFFER_BINDING, COPY_READ),
        ("GL_COPY_WRITE_BUFFER_BINDING", glow::COPY_WRITE_BUFFER, glow::COPY_WRITE_BUFFER_BINDING, COPY_WRITE),
        ("GL_TRANSFORM_FEEDBACK_BUFFER_BINDING", glow::TRANSFORM_FEEDBACK_BUFFER, glow::TRANSFORM_FEEDBACK_BUFFER_BINDING, TF_BUFFER),
    ] {
        p.add(name, binding, None, int(binding), s!(|h| h.gl.bind_buffer(target, Some(h.buffers[k]))));
    }
    // The host's vertex array (VAO 0 in the compatibility profile) keeps an attribute
    // pointer of its own, and a generic current value.
    p.add("GL_VERTEX_ATTRIB_ARRAY_ENABLED[2]", glow::VERTEX_ATTRIB_ARRAY_ENABLED, None, Attrib(2, glow::VERTEX_ATTRIB_ARRAY_ENABLED), s!(|h| {
        h.gl.bind_buffer(glow::ARRAY_BUFFER, Some(h.buffers[ARRAY]));
        h.gl.vertex_attrib_pointer_f32(2, 3, glow::FLOAT, false, 20, 8);
        h.gl.vertex_attrib_divisor(2, 2);
        h.gl.enable_vertex_attrib_array(2)
    }));
    p.add("GL_VERTEX_ATTRIB_ARRAY_STRIDE[2]", glow::VERTEX_ATTRIB_ARRAY_STRIDE, None, Attrib(2, glow::VERTEX_ATTRIB_ARRAY_STRIDE), None);
    p.add("GL_VERTEX_ATTRIB_ARRAY_DIVISOR[2]", glow::VERTEX_ATTRIB_ARRAY_DIVISOR, None, Attrib(2, glow::VERTEX_ATTRIB_ARRAY_DIVISOR), None);
    p.add("GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING[2]", glow::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING, None, Attrib(2, glow::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING), None);
    p.add("GL_CURRENT_VERTEX_ATTRIB[3]", glow::CURRENT_VERTEX_ATTRIB, None, Attrib(3, glow::CURRENT_VERTEX_ATTRIB), s!(|h| h.gl.vertex_attrib_4_f32(3, 0.1, 0.2, 0.3, 0.4)));
    p.add("GL_TRANSFORM_FEEDBACK_BINDING", glow::TRANSFORM_FEEDBACK_BINDING, None, int(glow::TRANSFORM_FEEDBACK_BINDING), s!(|h| h.gl.bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(h.tf))));
    p.add("GL_RENDERBUFFER_BINDING", glow::RENDERBUFFER_BINDING, None, int(glow::RENDERBUFFER_BINDING), s!(|h| h.gl.bind_renderbuffer(glow::RENDERBUFFER, Some(h.rb))));
    p.add("GL_DRAW_FRAMEBUFFER_BINDING", glow::DRAW_FRAMEBUFFER_BINDING, None, int(glow::DRAW_FRAMEBUFFER_BINDING), s!(|h| h.gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(h.draw_fbo))));
    p.add("GL_READ_FRAMEBUFFER_BINDING", glow::READ_FRAMEBUFFER_BINDING, None, int(glow::READ_FRAMEBUFFER_BINDING), s!(|h| h.gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(h.read_fbo))));
    // --- textures and samplers on several units ---
    let unit_bind = |target: u32, pick: fn(&Host, usize) -> glow::Texture, unit: u32| -> Setter {
        Box::new(move |h: &Host| {
            // SAFETY: binds the host's own texture on its current context.
            unsafe {
                h.gl.active_texture(glow::TEXTURE0 + unit);
                h.gl.bind_texture(target, Some(pick(h, unit as usize)));
            }
        })
    };
    for u in 0..4 {
        p.add("GL_TEXTURE_BINDING_2D", glow::TEXTURE_BINDING_2D, Some(u), int(glow::TEXTURE_BINDING_2D), Some(unit_bind(glow::TEXTURE_2D, |h, u| h.tex2d[u], u)));
    }
    for u in 0..3 {
        p.add("GL_TEXTURE_BINDING_2D_ARRAY", glow::TEXTURE_BINDING_2D_ARRAY, Some(u), int(glow::TEXTURE_BINDING_2D_ARRAY), Some(unit_bind(glow::TEXTURE_2D_ARRAY, |h, u| h.tex_array[u], u)));
        p.add("GL_SAMPLER_BINDING", glow::SAMPLER_BINDING, Some(u), int(glow::SAMPLER_BINDING), Some(Box::new(move |h: &Host| {
            // SAFETY: binds the host's own sampler on its current context.
            unsafe { h.gl.bind_sampler(u, Some(h.samplers[u as usize])) }
        })));
    }
    p.add("GL_TEXTURE_BINDING_3D", glow::TEXTURE_BINDING_3D, Some(0), int(glow::TEXTURE_BINDING_3D), Some(unit_bind(glow::TEXTURE_3D, |h, _| h.tex3d, 0)));
    p.add("GL_TEXTURE_BINDING_CUBE_MAP", glow::TEXTURE_BINDING_CUBE_MAP, Some(1), int(glow::TEXTURE_BINDING_CUBE_MAP), Some(unit_bind(glow::TEXTURE_CUBE_MAP, |h, _| h.cube, 1)));
    if desktop {
        p.add("GL_TEXTURE_BINDING_1D", glow::TEXTURE_BINDING_1D, Some(2), int(glow::TEXTURE_BINDING_1D), Some(unit_bind(glow::TEXTURE_1D, |h, _| h.tex1d.unwrap(), 2)));
        p.add("GL_TEXTURE_BINDING_RECTANGLE", glow::TEXTURE_BINDING_RECTANGLE, Some(3), int(glow::TEXTURE_BINDING_RECTANGLE), Some(unit_bind(glow::TEXTURE_RECTANGLE, |h, _| h.rect.unwrap(), 3)));
    }
}

/// Blend, depth, stencil, scissor, colour, viewport, polygon, rasterisation, hints, pixel store.
#[rustfmt::skip]
fn fixed_state(p: &mut Pieces, api: GlApi) {
    use Q::*;
    // --- blending ---
    p.add("GL_BLEND", glow::BLEND, None, Enabled(glow::BLEND), s!(|h| h.gl.enable(glow::BLEND)));
    p.add("GL_BLEND_SRC_RGB", glow::BLEND_SRC_RGB, None, int(glow::BLEND_SRC_RGB), s!(|h| h.gl.blend_func_separate(glow::DST_COLOR, glow::SRC_COLOR, glow::ONE_MINUS_DST_ALPHA, glow::CONSTANT_ALPHA)));
    p.add("GL_BLEND_DST_RGB", glow::BLEND_DST_RGB, None, int(glow::BLEND_DST_RGB), None);
    p.add("GL_BLEND_SRC_ALPHA", glow::BLEND_SRC_ALPHA, None, int(glow::BLEND_SRC_ALPHA), None);
    p.add("GL_BLEND_DST_ALPHA", glow::BLEND_DST_ALPHA, None, int(glow::BLEND_DST_ALPHA), None);
    p.add("GL_BLEND_EQUATION_RGB", glow::BLEND_EQUATION_RGB, None, int(glow::BLEND_EQUATION_RGB), s!(|h| h.gl.blend_equation_separate(glow::FUNC_SUBTRACT, glow::MAX)));
    p.add("GL_BLEND_EQUATION_ALPHA", glow::BLEND_EQUATION_ALPHA, None, int(glow::BLEND_EQUATION_ALPHA), None);
    p.add("GL_BLEND_COLOR", glow::BLEND_COLOR, None, Float(glow::BLEND_COLOR, 4), s!(|h| h.gl.blend_color(0.1, 0.2, 0.3, 0.4)));
    // --- depth ---
    p.add("GL_DEPTH_TEST", glow::DEPTH_TEST, None, Enabled(glow::DEPTH_TEST), s!(|h| h.gl.enable(glow::DEPTH_TEST)));
    p.add("GL_DEPTH_FUNC", glow::DEPTH_FUNC, None, int(glow::DEPTH_FUNC), s!(|h| h.gl.depth_func(glow::GEQUAL)));
    p.add("GL_DEPTH_WRITEMASK", glow::DEPTH_WRITEMASK, None, int(glow::DEPTH_WRITEMASK), s!(|h| h.gl.depth_mask(true)));
    p.add("GL_DEPTH_CLEAR_VALUE", glow::DEPTH_CLEAR_VALUE, None, Float(glow::DEPTH_CLEAR_VALUE, 1), s!(|h| h.gl.clear_depth_f32(0.25)));
    p.add("GL_DEPTH_RANGE", glow::DEPTH_RANGE, None, Float(glow::DEPTH_RANGE, 2), s!(|h| h.gl.depth_range_f32(0.125, 0.875)));
    // --- stencil ---
    p.add("GL_STENCIL_TEST", glow::STENCIL_TEST, None, Enabled(glow::STENCIL_TEST), s!(|h| {
        h.gl.enable(glow::STENCIL_TEST);
        h.gl.stencil_func_separate(glow::FRONT, glow::GREATER, 5, 0x3C);
        h.gl.stencil_func_separate(glow::BACK, glow::LEQUAL, 7, 0x0F);
        h.gl.stencil_op_separate(glow::FRONT, glow::INCR, glow::DECR, glow::INVERT);
        h.gl.stencil_op_separate(glow::BACK, glow::DECR_WRAP, glow::INCR_WRAP, glow::ZERO);
        h.gl.stencil_mask_separate(glow::FRONT, 0xA5);
        h.gl.stencil_mask_separate(glow::BACK, 0x5A);
        h.gl.clear_stencil(3)
    }));
    for (name, pname) in [
        ("GL_STENCIL_FUNC", glow::STENCIL_FUNC),
        ("GL_STENCIL_REF", glow::STENCIL_REF),
        ("GL_STENCIL_VALUE_MASK", glow::STENCIL_VALUE_MASK),
        ("GL_STENCIL_FAIL", glow::STENCIL_FAIL),
        ("GL_STENCIL_PASS_DEPTH_FAIL", glow::STENCIL_PASS_DEPTH_FAIL),
        ("GL_STENCIL_PASS_DEPTH_PASS", glow::STENCIL_PASS_DEPTH_PASS),
        ("GL_STENCIL_WRITEMASK", glow::STENCIL_WRITEMASK),
        ("GL_STENCIL_BACK_FUNC", glow::STENCIL_BACK_FUNC),
        ("GL_STENCIL_BACK_REF", glow::STENCIL_BACK_REF),
        ("GL_STENCIL_BACK_VALUE_MASK", glow::STENCIL_BACK_VALUE_MASK),
        ("GL_STENCIL_BACK_FAIL", glow::STENCIL_BACK_FAIL),
        ("GL_STENCIL_BACK_WRITEMASK", glow::STENCIL_BACK_WRITEMASK),
        ("GL_STENCIL_CLEAR_VALUE", glow::STENCIL_CLEAR_VALUE),
    ] {
        p.add(name, pname, None, int(pname), None);
    }
    // --- scissor, colour, viewport ---
    p.add("GL_SCISSOR_TEST", glow::SCISSOR_TEST, None, Enabled(glow::SCISSOR_TEST), s!(|h| h.gl.enable(glow::SCISSOR_TEST)));
    p.add("GL_SCISSOR_BOX", glow::SCISSOR_BOX, None, Int(glow::SCISSOR_BOX, 4), s!(|h| h.gl.scissor(1, 2, 30, 40)));
    p.add("GL_COLOR_WRITEMASK", glow::COLOR_WRITEMASK, None, Int(glow::COLOR_WRITEMASK, 4), s!(|h| h.gl.color_mask(true, false, true, false)));
    p.add("GL_COLOR_CLEAR_VALUE", glow::COLOR_CLEAR_VALUE, None, Float(glow::COLOR_CLEAR_VALUE, 4), s!(|h| h.gl.clear_color(0.5, 0.25, 0.125, 0.75)));
    p.add("GL_VIEWPORT", glow::VIEWPORT, None, Int(glow::VIEWPORT, 4), s!(|h| h.gl.viewport(3, 4, 50, 60)));
    p.add("GL_DITHER", glow::DITHER, None, Enabled(glow::DITHER), s!(|h| h.gl.disable(glow::DITHER)));
    // --- polygon state and rasterisation ---
    p.add("GL_CULL_FACE", glow::CULL_FACE, None, Enabled(glow::CULL_FACE), s!(|h| h.gl.enable(glow::CULL_FACE)));
    p.add("GL_CULL_FACE_MODE", glow::CULL_FACE_MODE, None, int(glow::CULL_FACE_MODE), s!(|h| h.gl.cull_face(glow::FRONT_AND_BACK)));
    p.add("GL_FRONT_FACE", glow::FRONT_FACE, None, int(glow::FRONT_FACE), s!(|h| h.gl.front_face(glow::CW)));
    p.add("GL_POLYGON_OFFSET_FILL", glow::POLYGON_OFFSET_FILL, None, Enabled(glow::POLYGON_OFFSET_FILL), s!(|h| h.gl.enable(glow::POLYGON_OFFSET_FILL)));
    p.add("GL_POLYGON_OFFSET_FACTOR", glow::POLYGON_OFFSET_FACTOR, None, Float(glow::POLYGON_OFFSET_FACTOR, 1), s!(|h| h.gl.polygon_offset(2.5, -1.5)));
    p.add("GL_POLYGON_OFFSET_UNITS", glow::POLYGON_OFFSET_UNITS, None, Float(glow::POLYGON_OFFSET_UNITS, 1), None);
    p.add("GL_RASTERIZER_DISCARD", glow::RASTERIZER_DISCARD, None, Enabled(glow::RASTERIZER_DISCARD), s!(|h| h.gl.enable(glow::RASTERIZER_DISCARD)));
    p.add("GL_SAMPLE_ALPHA_TO_COVERAGE", glow::SAMPLE_ALPHA_TO_COVERAGE, None, Enabled(glow::SAMPLE_ALPHA_TO_COVERAGE), s!(|h| h.gl.enable(glow::SAMPLE_ALPHA_TO_COVERAGE)));
    p.add("GL_SAMPLE_COVERAGE", glow::SAMPLE_COVERAGE, None, Enabled(glow::SAMPLE_COVERAGE), s!(|h| {
        h.gl.enable(glow::SAMPLE_COVERAGE);
        h.gl.sample_coverage(0.5, true)
    }));
    p.add("GL_SAMPLE_COVERAGE_VALUE", glow::SAMPLE_COVERAGE_VALUE, None, Float(glow::SAMPLE_COVERAGE_VALUE, 1), None);
    p.add("GL_SAMPLE_COVERAGE_INVERT", glow::SAMPLE_COVERAGE_INVERT, None, int(glow::SAMPLE_COVERAGE_INVERT), None);
    p.add("GL_PRIMITIVE_RESTART_FIXED_INDEX", glow::PRIMITIVE_RESTART_FIXED_INDEX, None, Enabled(glow::PRIMITIVE_RESTART_FIXED_INDEX), s!(|h| h.gl.enable(glow::PRIMITIVE_RESTART_FIXED_INDEX)));
    if api != GlApi::DesktopCore33 {
        p.add("GL_GENERATE_MIPMAP_HINT", glow::GENERATE_MIPMAP_HINT, None, int(glow::GENERATE_MIPMAP_HINT), s!(|h| h.gl.hint(glow::GENERATE_MIPMAP_HINT, glow::NICEST)));
    }
    p.add("GL_FRAGMENT_SHADER_DERIVATIVE_HINT", glow::FRAGMENT_SHADER_DERIVATIVE_HINT, None, int(glow::FRAGMENT_SHADER_DERIVATIVE_HINT), s!(|h| h.gl.hint(glow::FRAGMENT_SHADER_DERIVATIVE_HINT, glow::FASTEST)));
    // --- pixel store ---
    for (name, pname, value) in [
        ("GL_UNPACK_ALIGNMENT", glow::UNPACK_ALIGNMENT, 1),
        ("GL_UNPACK_ROW_LENGTH", glow::UNPACK_ROW_LENGTH, 7),
        ("GL_UNPACK_IMAGE_HEIGHT", glow::UNPACK_IMAGE_HEIGHT, 5),
        ("GL_UNPACK_SKIP_ROWS", glow::UNPACK_SKIP_ROWS, 2),
        ("GL_UNPACK_SKIP_PIXELS", glow::UNPACK_SKIP_PIXELS, 3),
        ("GL_UNPACK_SKIP_IMAGES", glow::UNPACK_SKIP_IMAGES, 1),
        ("GL_PACK_ALIGNMENT", glow::PACK_ALIGNMENT, 2),
        ("GL_PACK_ROW_LENGTH", glow::PACK_ROW_LENGTH, 9),
        ("GL_PACK_SKIP_ROWS", glow::PACK_SKIP_ROWS, 1),
        ("GL_PACK_SKIP_PIXELS", glow::PACK_SKIP_PIXELS, 4),
    ] {
        p.add(name, pname, None, int(pname), s!(|h| h.gl.pixel_store_i32(pname, value)));
    }
}

/// Desktop GL only: polygon mode, logic op, desktop capabilities and pixel store.
#[rustfmt::skip]
fn desktop_state(p: &mut Pieces) {
    use Q::*;
    {
        p.add("GL_POLYGON_MODE", glow::POLYGON_MODE, None, Int(glow::POLYGON_MODE, 2), s!(|h| h.gl.polygon_mode(glow::FRONT_AND_BACK, glow::LINE)));
        p.add("GL_COLOR_LOGIC_OP", glow::COLOR_LOGIC_OP, None, Enabled(glow::COLOR_LOGIC_OP), s!(|h| {
            h.gl.enable(glow::COLOR_LOGIC_OP);
            (h.lgl.logic_op)(lg::XOR)
        }));
        p.add("GL_LOGIC_OP_MODE", lg::LOGIC_OP_MODE, None, int(lg::LOGIC_OP_MODE), None);
        for cap in [glow::PROGRAM_POINT_SIZE, glow::DEPTH_CLAMP, glow::TEXTURE_CUBE_MAP_SEAMLESS, glow::LINE_SMOOTH, glow::PRIMITIVE_RESTART] {
            p.add(&format!("capability 0x{cap:04X}"), cap, None, Enabled(cap), s!(|h| h.gl.enable(cap)));
        }
        p.add("GL_MULTISAMPLE", glow::MULTISAMPLE, None, Enabled(glow::MULTISAMPLE), s!(|h| h.gl.disable(glow::MULTISAMPLE)));
        p.add("GL_POINT_SIZE", lg::POINT_SIZE, None, Float(lg::POINT_SIZE, 1), s!(|h| (h.lgl.point_size)(3.0)));
        for pname in [glow::UNPACK_SWAP_BYTES, glow::UNPACK_LSB_FIRST, glow::PACK_SWAP_BYTES] {
            p.add(&format!("pixel store 0x{pname:04X}"), pname, None, int(pname), s!(|h| h.gl.pixel_store_bool(pname, true)));
        }
    }
}

/// Compatibility profile: fixed-function matrices, texture enables and environment, lighting,
/// fog, alpha test, current values, client arrays.
#[rustfmt::skip]
fn compatibility_state(p: &mut Pieces) {
    use Q::*;
    {
        let load = |mode: u32, m: Mat4, unit: u32| -> Setter {
            // SAFETY: a state setter on the host's own current context and objects.
            Box::new(move |h: &Host| unsafe {
                h.gl.active_texture(glow::TEXTURE0 + unit);
                (h.lgl.matrix_mode)(mode);
                (h.lgl.load_matrix)(m.to_cols_array().as_ptr());
            })
        };
        p.add("GL_MODELVIEW_MATRIX", lg::MODELVIEW_MATRIX, None, Float(lg::MODELVIEW_MATRIX, 16), Some(load(lg::MODELVIEW, matrix(1.0), 0)));
        p.add("GL_PROJECTION_MATRIX", lg::PROJECTION_MATRIX, None, Float(lg::PROJECTION_MATRIX, 16), Some(load(lg::PROJECTION, matrix(2.0), 0)));
        p.add("GL_TEXTURE_MATRIX", lg::TEXTURE_MATRIX, Some(0), Float(lg::TEXTURE_MATRIX, 16), Some(load(lg::TEXTURE, matrix(3.0), 0)));
        for u in 0..2 {
            // SAFETY: a state setter on the host's own current context and objects.
            p.add("GL_TEXTURE_2D (enable)", glow::TEXTURE_2D, Some(u), Enabled(glow::TEXTURE_2D), Some(Box::new(move |h: &Host| unsafe {
                h.gl.active_texture(glow::TEXTURE0 + u);
                h.gl.enable(glow::TEXTURE_2D)
            })));
        }
        // SAFETY: a state setter on the host's own current context and objects.
        p.add("GL_TEXTURE_ENV_MODE", lg::TEXTURE_ENV_MODE, Some(0), EnvMode, Some(Box::new(|h: &Host| unsafe {
            h.gl.active_texture(glow::TEXTURE0);
            (h.lgl.tex_envi)(lg::TEXTURE_ENV, lg::TEXTURE_ENV_MODE, lg::DECAL as i32)
        })));
        p.add("GL_CURRENT_TEXTURE_COORDS", lg::CURRENT_TEXTURE_COORDS, Some(0), Float(lg::CURRENT_TEXTURE_COORDS, 4), s!(|h| (h.lgl.tex_coord2)(0.5, 0.25)));
        for cap in [lg::LIGHTING, lg::FOG, lg::NORMALIZE, lg::COLOR_MATERIAL, lg::LINE_STIPPLE] {
            p.add(&format!("fixed-function capability 0x{cap:04X}"), cap, None, Enabled(cap), s!(|h| h.gl.enable(cap)));
        }
        p.add("GL_ALPHA_TEST", lg::ALPHA_TEST, None, Enabled(lg::ALPHA_TEST), s!(|h| {
            h.gl.enable(lg::ALPHA_TEST);
            (h.lgl.alpha_func)(glow::GREATER, 0.5)
        }));
        p.add("GL_ALPHA_TEST_FUNC", lg::ALPHA_TEST_FUNC, None, int(lg::ALPHA_TEST_FUNC), None);
        p.add("GL_ALPHA_TEST_REF", lg::ALPHA_TEST_REF, None, Float(lg::ALPHA_TEST_REF, 1), None);
        p.add("GL_SHADE_MODEL", lg::SHADE_MODEL, None, int(lg::SHADE_MODEL), s!(|h| (h.lgl.shade_model)(lg::FLAT)));
        p.add("GL_CURRENT_COLOR", lg::CURRENT_COLOR, None, Float(lg::CURRENT_COLOR, 4), s!(|h| (h.lgl.color4)(0.2, 0.4, 0.6, 0.8)));
        p.add("GL_CURRENT_NORMAL", lg::CURRENT_NORMAL, None, Float(lg::CURRENT_NORMAL, 3), s!(|h| (h.lgl.normal3)(1.0, 0.0, 0.0)));
        p.add("GL_VERTEX_ARRAY", lg::VERTEX_ARRAY, None, Enabled(lg::VERTEX_ARRAY), s!(|h| {
            h.gl.bind_buffer(glow::ARRAY_BUFFER, Some(h.buffers[ARRAY]));
            (h.lgl.vertex_pointer)(2, glow::FLOAT, 16, 4usize as *const std::ffi::c_void);
            (h.lgl.enable_client_state)(lg::VERTEX_ARRAY)
        }));
        p.add("GL_VERTEX_ARRAY_BUFFER_BINDING", lg::VERTEX_ARRAY_BUFFER_BINDING, None, int(lg::VERTEX_ARRAY_BUFFER_BINDING), None);
        p.add("GL_VERTEX_ARRAY_SIZE", lg::VERTEX_ARRAY_SIZE, None, int(lg::VERTEX_ARRAY_SIZE), None);
        p.add("GL_VERTEX_ARRAY_STRIDE", lg::VERTEX_ARRAY_STRIDE, None, int(lg::VERTEX_ARRAY_STRIDE), None);
        p.add("GL_COLOR_ARRAY", lg::COLOR_ARRAY, None, Enabled(lg::COLOR_ARRAY), s!(|h| (h.lgl.enable_client_state)(lg::COLOR_ARRAY)));
        p.add("GL_TEXTURE_COORD_ARRAY (client unit 1)", lg::TEXTURE_COORD_ARRAY, None, Enabled(lg::TEXTURE_COORD_ARRAY), s!(|h| {
            (h.lgl.client_active_texture)(glow::TEXTURE1);
            (h.lgl.enable_client_state)(lg::TEXTURE_COORD_ARRAY)
        }));
        p.add("GL_CLIENT_ACTIVE_TEXTURE", lg::CLIENT_ACTIVE_TEXTURE, None, int(lg::CLIENT_ACTIVE_TEXTURE), None);
        p.add("GL_MATRIX_MODE", lg::MATRIX_MODE, None, int(lg::MATRIX_MODE), s!(|h| (h.lgl.matrix_mode)(lg::TEXTURE)));
    }
}

/// A name GL never generated (an invalid-operation probe).
pub fn ungenerated_vertex_array() -> glow::VertexArray {
    glow::NativeVertexArray(NonZeroU32::new(0x7FFF_FFF0).unwrap())
}
