//! GL object lifetimes, shaped like `egui_glow`'s painter: every GL-owning type has
//! `destroy(&mut self, gl)`, checks a destroyed flag on entry ([`Owned::check`]) and warns
//! once per process when it is dropped without `destroy` (its GL objects then leak: the type
//! does not own the context, so it cannot delete them in `Drop`).
//!
//! [`Creating`] is the one cleanup path for partially created objects: everything created
//! through it is deleted again unless [`Creating::keep`] is reached.

use std::sync::Mutex;

use glow::HasContext;

use super::GlError;

/// The GL objects a value owns, and whether it was destroyed. Dropped while live (objects
/// not deleted), it warns once per type name and process.
#[derive(Debug)]
pub(crate) struct Owned {
    what: &'static str,
    objects: Vec<GlObject>,
    destroyed: bool,
}

/// The type names already warned about (each warns once per process).
static WARNED: Mutex<Vec<&'static str>> = Mutex::new(Vec::new());

impl Owned {
    /// `Err(GlError::Destroyed)` once the owner was destroyed (checked on entry of every method
    /// that touches GL).
    pub(crate) fn check(&self) -> Result<(), GlError> {
        if self.destroyed {
            Err(GlError::Destroyed(self.what))
        } else {
            Ok(())
        }
    }

    /// Deletes the objects (once; later calls do nothing).
    pub(crate) fn destroy(&mut self, gl: &glow::Context) {
        if !std::mem::replace(&mut self.destroyed, true) {
            delete_all(gl, &self.objects);
        }
    }

    /// Marks the objects gone without GL calls: their context was destroyed with them.
    pub(crate) fn abandon(&mut self) {
        self.destroyed = true;
    }
}

impl Drop for Owned {
    fn drop(&mut self) {
        if self.destroyed || self.objects.is_empty() {
            return;
        }
        let mut warned = WARNED.lock().unwrap_or_else(|e| e.into_inner());
        if !warned.contains(&self.what) {
            warned.push(self.what);
            eprintln!(
                "splatgl: a {} was dropped without destroy(&gl): its GL objects leak",
                self.what
            );
        }
    }
}

/// One GL object of any kind.
#[derive(Debug, Clone, Copy)]
pub(crate) enum GlObject {
    Program(glow::Program),
    Shader(glow::Shader),
    Texture(glow::Texture),
    Framebuffer(glow::Framebuffer),
    Renderbuffer(glow::Renderbuffer),
    Buffer(glow::Buffer),
    VertexArray(glow::VertexArray),
    TransformFeedback(glow::TransformFeedback),
    Query(glow::Query),
}

impl GlObject {
    /// Deletes the object.
    pub(crate) fn delete(self, gl: &glow::Context) {
        // SAFETY: deleting a name this crate created; deleting is valid for any name of the
        // right kind (a name already deleted is silently ignored by GL).
        unsafe {
            match self {
                GlObject::Program(o) => gl.delete_program(o),
                GlObject::Shader(o) => gl.delete_shader(o),
                GlObject::Texture(o) => gl.delete_texture(o),
                GlObject::Framebuffer(o) => gl.delete_framebuffer(o),
                GlObject::Renderbuffer(o) => gl.delete_renderbuffer(o),
                GlObject::Buffer(o) => gl.delete_buffer(o),
                GlObject::VertexArray(o) => gl.delete_vertex_array(o),
                GlObject::TransformFeedback(o) => gl.delete_transform_feedback(o),
                GlObject::Query(o) => gl.delete_query(o),
            }
        }
    }
}

/// Deletes every object in `objects` (last created first).
pub(crate) fn delete_all(gl: &glow::Context, objects: &[GlObject]) {
    for o in objects.iter().rev() {
        o.delete(gl);
    }
}

/// Objects being created together: dropped before [`Creating::keep`], it deletes them all.
pub(crate) struct Creating<'gl> {
    gl: &'gl glow::Context,
    objects: Vec<GlObject>,
}

impl<'gl> Creating<'gl> {
    /// Nothing created yet.
    pub(crate) fn new(gl: &'gl glow::Context) -> Self {
        Creating {
            gl,
            objects: Vec::new(),
        }
    }

    /// The context the objects are created on.
    pub(crate) fn gl(&self) -> &'gl glow::Context {
        self.gl
    }

    /// Creation succeeded and the caller takes the objects over itself (nothing is deleted).
    #[cfg_attr(not(feature = "testing"), allow(dead_code))] // build_program (tests)
    pub(crate) fn release(mut self) {
        self.objects.clear();
    }

    /// Creation succeeded: the objects belong to a value of type `what` now.
    pub(crate) fn keep(mut self, what: &'static str) -> Owned {
        Owned {
            what,
            objects: std::mem::take(&mut self.objects),
            destroyed: false,
        }
    }

    /// Records a freshly created object (or maps glow's error to [`GlError::Create`]).
    fn push<T: Copy>(
        &mut self,
        r: Result<T, String>,
        what: &'static str,
        wrap: fn(T) -> GlObject,
    ) -> Result<T, GlError> {
        let o = r.map_err(|message| GlError::Create { what, message })?;
        self.objects.push(wrap(o));
        Ok(o)
    }

    /// A new shader of `kind` (`VERTEX_SHADER`, `FRAGMENT_SHADER`).
    pub(crate) fn shader(&mut self, kind: u32) -> Result<glow::Shader, GlError> {
        // SAFETY: plain object creation on the current context.
        let r = unsafe { self.gl.create_shader(kind) };
        self.push(r, "shader", GlObject::Shader)
    }
}

/// `Creating::$fn()`: a new object of one kind, from glow's `$create`.
macro_rules! creators {
    ($($(#[$doc:meta])* $fn:ident: $ty:ident = $create:ident, $what:literal;)*) => {
        impl Creating<'_> {
            $(
                $(#[$doc])*
                pub(crate) fn $fn(&mut self) -> Result<glow::$ty, GlError> {
                    // SAFETY: plain object creation on the current context.
                    let r = unsafe { self.gl.$create() };
                    self.push(r, $what, GlObject::$ty)
                }
            )*
        }
    };
}

creators! {
    /// A new program.
    program: Program = create_program, "program";
    /// A new texture.
    texture: Texture = create_texture, "texture";
    /// A new framebuffer.
    framebuffer: Framebuffer = create_framebuffer, "framebuffer";
    /// A new renderbuffer.
    renderbuffer: Renderbuffer = create_renderbuffer, "renderbuffer";
    /// A new buffer.
    buffer: Buffer = create_buffer, "buffer";
    /// A new vertex array.
    vertex_array: VertexArray = create_vertex_array, "vertex array";
    /// A new transform-feedback object.
    transform_feedback: TransformFeedback = create_transform_feedback, "transform feedback";
    /// A new query object.
    query: Query = create_query, "query";
}

impl Drop for Creating<'_> {
    fn drop(&mut self) {
        delete_all(self.gl, &self.objects);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn owned(what: &'static str) -> Owned {
        let name = std::num::NonZeroU32::new(7).unwrap();
        Owned {
            what,
            objects: vec![GlObject::Texture(glow::NativeTexture(name))],
            destroyed: false,
        }
    }

    #[test]
    fn a_live_owner_dropped_warns_and_a_gone_one_refuses_use() {
        let warned = || WARNED.lock().unwrap().contains(&"LeakTestOwner");
        drop(owned("LeakTestOwner"));
        assert!(warned());
        let mut gone = owned("GoneTestOwner");
        assert!(gone.check().is_ok());
        gone.abandon();
        assert!(matches!(
            gone.check(),
            Err(GlError::Destroyed("GoneTestOwner"))
        ));
        drop(gone);
        assert!(!WARNED.lock().unwrap().contains(&"GoneTestOwner"));
    }
}
