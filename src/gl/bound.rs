//! Which object is bound (`glGet*` of a `*_BINDING`): [`Bound`], the one way the GL layer asks.
//!
//! glow's WebGL backend cannot answer these when the binding is none or an object the page
//! created without glow (it panics), so on the web (`wasm32`) every answer is `None`: there
//! splatgl does not read the page's bindings, and what a call would put back is "none bound".
//! Everywhere else the answer is GL's.

/// Queries of the bound buffer, framebuffer, program, sampler, texture, transform feedback
/// and vertex array objects.
pub(crate) trait Bound {
    /// `glGetIntegerv(pname)` of a buffer binding.
    unsafe fn bound_buffer(&self, pname: u32) -> Option<glow::Buffer>;
    /// Of a framebuffer binding.
    unsafe fn bound_framebuffer(&self, pname: u32) -> Option<glow::Framebuffer>;
    /// Of `GL_CURRENT_PROGRAM`.
    unsafe fn bound_program(&self, pname: u32) -> Option<glow::Program>;
    /// Of `GL_SAMPLER_BINDING`.
    unsafe fn bound_sampler(&self, pname: u32) -> Option<glow::Sampler>;
    /// Of a texture binding.
    unsafe fn bound_texture(&self, pname: u32) -> Option<glow::Texture>;
    /// Of `GL_TRANSFORM_FEEDBACK_BINDING`.
    unsafe fn bound_transform_feedback(&self, pname: u32) -> Option<glow::TransformFeedback>;
    /// Of `GL_VERTEX_ARRAY_BINDING`.
    unsafe fn bound_vertex_array(&self, pname: u32) -> Option<glow::VertexArray>;
}

macro_rules! bound {
    ($($name:ident => $glow:ident -> $ty:ty;)*) => {
        impl Bound for glow::Context {
            $(
                #[cfg(not(target_arch = "wasm32"))]
                unsafe fn $name(&self, pname: u32) -> Option<$ty> {
                    use glow::HasContext;
                    // SAFETY: the caller's (a binding pname that exists on this context).
                    unsafe { self.$glow(pname) }
                }
                #[cfg(target_arch = "wasm32")]
                unsafe fn $name(&self, _pname: u32) -> Option<$ty> {
                    None
                }
            )*
        }
    };
}

bound! {
    bound_buffer => get_parameter_buffer -> glow::Buffer;
    bound_framebuffer => get_parameter_framebuffer -> glow::Framebuffer;
    bound_program => get_parameter_program -> glow::Program;
    bound_sampler => get_parameter_sampler -> glow::Sampler;
    bound_texture => get_parameter_texture -> glow::Texture;
    bound_transform_feedback => get_parameter_transform_feedback -> glow::TransformFeedback;
    bound_vertex_array => get_parameter_vertex_array -> glow::VertexArray;
}
