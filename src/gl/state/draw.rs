//! The state of one draw: set what the draw needs, and in restore mode query the host's values
//! first and put back exactly what was changed (see the tables in [`super`]).

use crate::gl::bound::Bound;
use glow::HasContext;

use super::{ALPHA_TEST, Contexts};
use crate::gl::context::{ContextInfo, Profile};

/// GL calls the state handling of one draw made (`glGet*` / `glIsEnabled` queries, and calls
/// that set state), as counted in the code.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StateCalls {
    /// State queries.
    pub queries: u32,
    /// State-setting calls (binds, enables, funcs, masks).
    pub sets: u32,
}

/// What the draw needs.
pub(crate) struct DrawState {
    pub(crate) program: glow::Program,
    pub(crate) vao: glow::VertexArray,
    /// Bound as `TEXTURE_2D_ARRAY` on units 0 and 1.
    pub(crate) textures: [glow::Texture; 2],
    /// Blend source factor for RGB and alpha (`ONE`, or `SRC_ALPHA` for erratum g).
    pub(crate) blend_src: u32,
    pub(crate) depth_test: bool,
    pub(crate) depth_func: u32,
    /// `GL_FRAMEBUFFER_SRGB` where it can be switched.
    pub(crate) srgb: bool,
}

/// The capabilities a draw sets, and where they exist.
const CAPS: [(u32, Contexts); 10] = [
    (glow::BLEND, Contexts::All),
    (glow::DEPTH_TEST, Contexts::All),
    (glow::CULL_FACE, Contexts::All),
    (glow::RASTERIZER_DISCARD, Contexts::All),
    (glow::POLYGON_OFFSET_FILL, Contexts::All),
    (glow::SAMPLE_ALPHA_TO_COVERAGE, Contexts::All),
    (glow::SAMPLE_COVERAGE, Contexts::All),
    (glow::COLOR_LOGIC_OP, Contexts::Desktop),
    (glow::FRAMEBUFFER_SRGB, Contexts::SrgbSwitch),
    (ALPHA_TEST, Contexts::Compatibility),
];

/// Pixel-unpack parameters a draw needs at 0, and where they exist: the pre-pass copies its
/// records from a buffer into a texture, and each of these would offset or byte-swap that copy
/// (`GL_UNPACK_ALIGNMENT` and `GL_UNPACK_IMAGE_HEIGHT` cannot matter: rows of whole 16-byte
/// texels, one layer per copy).
const UNPACK: [(u32, Contexts); 5] = [
    (glow::UNPACK_ROW_LENGTH, Contexts::All),
    (glow::UNPACK_SKIP_ROWS, Contexts::All),
    (glow::UNPACK_SKIP_PIXELS, Contexts::All),
    (glow::UNPACK_SKIP_IMAGES, Contexts::All),
    (glow::UNPACK_SWAP_BYTES, Contexts::Desktop),
];

/// Whether a piece of state of `contexts` exists in `ctx`.
pub(crate) fn exists(contexts: Contexts, ctx: ContextInfo) -> bool {
    match contexts {
        Contexts::All => true,
        Contexts::Desktop => ctx.desktop(),
        Contexts::Compatibility => ctx.profile == Profile::Compat,
        Contexts::SrgbSwitch => ctx.srgb_switch,
        Contexts::TransformFeedbackObjects => ctx.tf_objects,
    }
}

impl DrawState {
    fn cap(&self, cap: u32) -> bool {
        match cap {
            glow::BLEND => true,
            glow::DEPTH_TEST => self.depth_test,
            glow::FRAMEBUFFER_SRGB => self.srgb,
            _ => false,
        }
    }

    fn blend_func(&self) -> [u32; 4] {
        let (src, dst) = (self.blend_src, glow::ONE_MINUS_SRC_ALPHA);
        [src, dst, src, dst]
    }
}

/// The host's values of what a restoring draw changed (`None`: not changed).
pub(crate) struct Saved {
    program: Option<glow::Program>,
    vao: Option<glow::VertexArray>,
    active_texture: u32,
    units: [(Option<glow::Texture>, Option<glow::Sampler>); 2],
    caps: [Option<bool>; CAPS.len()],
    blend_func: Option<[u32; 4]>,
    blend_equation: Option<[u32; 2]>,
    depth_func: Option<u32>,
    depth_mask: Option<bool>,
    color_mask: Option<[bool; 4]>,
    polygon_mode: Option<[u32; 2]>,
    transform_feedback: Option<glow::TransformFeedback>,
    /// The host's `GL_PIXEL_UNPACK_BUFFER` binding, where one was bound (then unbound).
    unpack_buffer: Option<glow::Buffer>,
    unpack: [Option<i32>; UNPACK.len()],
}

/// The context with a count of the calls made through it.
struct Counted<'a> {
    gl: &'a glow::Context,
    calls: StateCalls,
}

impl Counted<'_> {
    fn q(&mut self) -> &glow::Context {
        self.calls.queries += 1;
        self.gl
    }

    fn s(&mut self) -> &glow::Context {
        self.calls.sets += 1;
        self.gl
    }

    fn int(&mut self, pname: u32) -> u32 {
        // SAFETY: a plain integer query of a pname that exists on this context.
        unsafe { self.q().get_parameter_i32(pname) as u32 }
    }

    fn set_cap(&mut self, cap: u32, on: bool) {
        // SAFETY: toggling a capability that exists on this context.
        unsafe {
            if on {
                self.s().enable(cap)
            } else {
                self.s().disable(cap)
            }
        }
    }
}

/// Sets the state of a draw. With `restore`, queries the host's values first, changes only
/// what differs and returns them for [`leave`].
pub(crate) fn enter(
    gl: &glow::Context,
    ctx: ContextInfo,
    want: &DrawState,
    restore: bool,
) -> (Option<Saved>, StateCalls) {
    let mut c = Counted {
        gl,
        calls: StateCalls::default(),
    };
    let saved = if restore {
        Some(enter_restoring(&mut c, ctx, want))
    } else {
        enter_plain(&mut c, ctx, want);
        None
    };
    (saved, c.calls)
}

/// Binds the program, VAO and textures; unbinds the samplers of units 0 and 1 where
/// `unbind_sampler` says (a host sampler object would override the textures' NEAREST
/// filtering, and RGBA32F is not filterable on ES 3.0).
fn bind(c: &mut Counted<'_>, want: &DrawState, unbind_sampler: [bool; 2]) {
    // SAFETY: binds objects the renderer owns (valid on this context) and unbinds samplers.
    unsafe {
        c.s().use_program(Some(want.program));
        c.s().bind_vertex_array(Some(want.vao));
        for (unit, tex) in want.textures.iter().enumerate() {
            c.s().active_texture(glow::TEXTURE0 + unit as u32);
            c.s().bind_texture(glow::TEXTURE_2D_ARRAY, Some(*tex));
            if unbind_sampler[unit] {
                c.s().bind_sampler(unit as u32, None);
            }
        }
    }
}

fn enter_plain(c: &mut Counted<'_>, ctx: ContextInfo, want: &DrawState) {
    bind(c, want, [true; 2]);
    if ctx.tf_objects {
        // SAFETY: binds the default transform-feedback object (exists on this context).
        unsafe {
            c.s()
                .bind_transform_feedback(glow::TRANSFORM_FEEDBACK, None)
        };
    }
    for (cap, contexts) in CAPS {
        if exists(contexts, ctx) {
            c.set_cap(cap, want.cap(cap));
        }
    }
    // SAFETY: unbinds the pixel-unpack buffer and zeroes unpack parameters of this context.
    unsafe {
        c.s().bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        for (pname, contexts) in UNPACK {
            if exists(contexts, ctx) {
                c.s().pixel_store_i32(pname, 0);
            }
        }
    }
    let [sr, dr, sa, da] = want.blend_func();
    // SAFETY: plain state setters with valid enums for this context.
    unsafe {
        c.s().blend_func_separate(sr, dr, sa, da);
        c.s()
            .blend_equation_separate(glow::FUNC_ADD, glow::FUNC_ADD);
        if want.depth_test {
            c.s().depth_func(want.depth_func);
        }
        c.s().depth_mask(false);
        c.s().color_mask(true, true, true, true);
        if ctx.desktop() {
            c.s().polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
        }
    }
}

/// Queries every host value a draw may change, before anything is set: with a threaded GL
/// (Mesa's glthread, vendor "threaded optimisation") queries wait for the command queue, and
/// one batch of them waits once. Only the per-unit queries need `glActiveTexture` between.
fn query_host(c: &mut Counted<'_>, ctx: ContextInfo, depth_test: bool) -> Saved {
    // SAFETY: state queries of pnames that exist on this context; `glActiveTexture` to read
    // the per-unit bindings (put back by `leave`).
    unsafe {
        let mut s = Saved {
            program: c.q().bound_program(glow::CURRENT_PROGRAM),
            vao: c.q().bound_vertex_array(glow::VERTEX_ARRAY_BINDING),
            active_texture: c.int(glow::ACTIVE_TEXTURE),
            units: [(None, None); 2],
            caps: [None; CAPS.len()],
            blend_func: None,
            blend_equation: None,
            depth_func: None,
            depth_mask: None,
            color_mask: None,
            polygon_mode: None,
            transform_feedback: None,
            unpack_buffer: c.q().bound_buffer(glow::PIXEL_UNPACK_BUFFER_BINDING),
            unpack: [None; UNPACK.len()],
        };
        for (k, (pname, contexts)) in UNPACK.into_iter().enumerate() {
            if exists(contexts, ctx) {
                s.unpack[k] = Some(c.int(pname) as i32);
            }
        }
        if ctx.tf_objects {
            s.transform_feedback = c
                .q()
                .bound_transform_feedback(glow::TRANSFORM_FEEDBACK_BINDING);
        }
        for (k, (cap, contexts)) in CAPS.into_iter().enumerate() {
            if exists(contexts, ctx) {
                s.caps[k] = Some(c.q().is_enabled(cap));
            }
        }
        s.blend_func = Some(
            [
                glow::BLEND_SRC_RGB,
                glow::BLEND_DST_RGB,
                glow::BLEND_SRC_ALPHA,
                glow::BLEND_DST_ALPHA,
            ]
            .map(|p| c.int(p)),
        );
        s.blend_equation =
            Some([glow::BLEND_EQUATION_RGB, glow::BLEND_EQUATION_ALPHA].map(|p| c.int(p)));
        if depth_test {
            s.depth_func = Some(c.int(glow::DEPTH_FUNC));
        }
        s.depth_mask = Some(c.q().get_parameter_bool(glow::DEPTH_WRITEMASK));
        s.color_mask = Some(c.q().get_parameter_bool_array::<4>(glow::COLOR_WRITEMASK));
        if ctx.desktop() {
            let mut mode = [0i32; 2];
            c.q().get_parameter_i32_slice(glow::POLYGON_MODE, &mut mode);
            s.polygon_mode = Some(mode.map(|m| m as u32));
        }
        for unit in 0..2 {
            c.s().active_texture(glow::TEXTURE0 + unit as u32);
            let tex = c.q().bound_texture(glow::TEXTURE_BINDING_2D_ARRAY);
            s.units[unit] = (tex, c.q().bound_sampler(glow::SAMPLER_BINDING));
        }
        s
    }
}

/// Restore mode: the host's values first, then only what differs is set; the returned
/// [`Saved`] keeps (as `Some`) just the pieces that were changed.
fn enter_restoring(c: &mut Counted<'_>, ctx: ContextInfo, want: &DrawState) -> Saved {
    let mut s = query_host(c, ctx, want.depth_test);
    bind(c, want, s.units.map(|(_, sampler)| sampler.is_some()));
    if s.transform_feedback.is_some() {
        // SAFETY: binds the default transform-feedback object (the host had another bound).
        unsafe {
            c.s()
                .bind_transform_feedback(glow::TRANSFORM_FEEDBACK, None)
        };
    }
    for (k, (cap, _)) in CAPS.into_iter().enumerate() {
        match s.caps[k] {
            Some(host) if host != want.cap(cap) => c.set_cap(cap, want.cap(cap)),
            _ => s.caps[k] = None,
        }
    }
    // SAFETY: unbinds the host's pixel-unpack buffer and zeroes the unpack parameters it set
    // (kept in `s` to put back).
    unsafe {
        if s.unpack_buffer.is_some() {
            c.s().bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        }
        for (k, (pname, _)) in UNPACK.into_iter().enumerate() {
            match s.unpack[k] {
                Some(host) if host != 0 => c.s().pixel_store_i32(pname, 0),
                _ => s.unpack[k] = None,
            }
        }
    }
    /// Keeps `saved` only if it differs from `want`, calling `set` then.
    fn differs<T: PartialEq + Copy>(saved: &mut Option<T>, want: T, set: impl FnOnce()) {
        match *saved {
            Some(host) if host != want => set(),
            _ => *saved = None,
        }
    }
    let sets = std::cell::Cell::new(0);
    let gl = c.gl;
    // SAFETY: plain state setters with valid enums for this context.
    unsafe {
        let [sr, dr, sa, da] = want.blend_func();
        differs(&mut s.blend_func, want.blend_func(), || {
            gl.blend_func_separate(sr, dr, sa, da);
            sets.set(sets.get() + 1);
        });
        differs(&mut s.blend_equation, [glow::FUNC_ADD; 2], || {
            gl.blend_equation_separate(glow::FUNC_ADD, glow::FUNC_ADD);
            sets.set(sets.get() + 1);
        });
        differs(&mut s.depth_func, want.depth_func, || {
            gl.depth_func(want.depth_func);
            sets.set(sets.get() + 1);
        });
        differs(&mut s.depth_mask, false, || {
            gl.depth_mask(false);
            sets.set(sets.get() + 1);
        });
        differs(&mut s.color_mask, [true; 4], || {
            gl.color_mask(true, true, true, true);
            sets.set(sets.get() + 1);
        });
        differs(&mut s.polygon_mode, [glow::FILL; 2], || {
            gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
            sets.set(sets.get() + 1);
        });
    }
    c.calls.sets += sets.get();
    s
}

/// Leaves the draw: puts back what [`enter`] saved, or (plain mode) unbinds the renderer's
/// objects as documented.
pub(crate) fn leave(gl: &glow::Context, ctx: ContextInfo, saved: Option<Saved>) -> StateCalls {
    let mut c = Counted {
        gl,
        calls: StateCalls::default(),
    };
    // SAFETY: (re)binds objects the host had bound (still valid: the host's) or none, and sets
    // state back to values queried from this context.
    unsafe {
        let Some(s) = saved else {
            c.s().bind_vertex_array(None);
            c.s().bind_texture(glow::TEXTURE_2D_ARRAY, None); // unit 1, still active
            c.s().active_texture(glow::TEXTURE0);
            c.s().bind_texture(glow::TEXTURE_2D_ARRAY, None);
            c.s().use_program(None);
            return c.calls;
        };
        c.s().bind_vertex_array(s.vao);
        c.s().use_program(s.program);
        if let Some(tf) = s.transform_feedback {
            c.s()
                .bind_transform_feedback(glow::TRANSFORM_FEEDBACK, Some(tf));
        }
        for unit in (0..2).rev() {
            if unit == 0 {
                c.s().active_texture(glow::TEXTURE0);
            }
            let (tex, sampler) = s.units[unit];
            c.s().bind_texture(glow::TEXTURE_2D_ARRAY, tex);
            if sampler.is_some() {
                c.s().bind_sampler(unit as u32, sampler);
            }
        }
        if s.active_texture != glow::TEXTURE0 {
            c.s().active_texture(s.active_texture);
        }
        for (k, (cap, _)) in CAPS.into_iter().enumerate() {
            if let Some(on) = s.caps[k] {
                c.set_cap(cap, on);
            }
        }
        if s.unpack_buffer.is_some() {
            c.s()
                .bind_buffer(glow::PIXEL_UNPACK_BUFFER, s.unpack_buffer);
        }
        for (k, (pname, _)) in UNPACK.into_iter().enumerate() {
            if let Some(v) = s.unpack[k] {
                c.s().pixel_store_i32(pname, v);
            }
        }
        if let Some([sr, dr, sa, da]) = s.blend_func {
            c.s().blend_func_separate(sr, dr, sa, da);
        }
        if let Some([rgb, alpha]) = s.blend_equation {
            c.s().blend_equation_separate(rgb, alpha);
        }
        if let Some(f) = s.depth_func {
            c.s().depth_func(f);
        }
        if let Some(m) = s.depth_mask {
            c.s().depth_mask(m);
        }
        if let Some([r, g, b, a]) = s.color_mask {
            c.s().color_mask(r, g, b, a);
        }
        if let Some([front, back]) = s.polygon_mode {
            if front == back || ctx.profile != Profile::Compat {
                c.s().polygon_mode(glow::FRONT_AND_BACK, front);
            } else {
                c.s().polygon_mode(glow::FRONT, front);
                c.s().polygon_mode(glow::BACK, back);
            }
        }
    }
    c.calls
}
