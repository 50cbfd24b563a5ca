//! What the GL layer sees of the context's extensions and limits: the driver's answers, or,
//! with the cargo feature `testing`, the faults a test injected (`gl::fault`).

/// A value from the faults a test injected on this thread (feature `testing`): `$f` is the
/// `gl::fault::Faults`, `$e` picks an `Option<$t>` from it. Without the feature, `None`: the
/// `fault` module does not exist and nothing thread-local is read.
macro_rules! injected {
    ($t:ty, |$f:ident| $e:expr) => {{
        #[cfg(feature = "testing")]
        let v: Option<$t> = crate::gl::fault::get(|$f| $e);
        #[cfg(not(feature = "testing"))]
        let v: Option<$t> = None;
        v
    }};
}
pub(crate) use injected;

/// Whether the extension is supported, as the GL layer sees it.
pub(crate) fn has_extension(gl: &glow::Context, name: &str) -> bool {
    use glow::HasContext;
    let missing = injected!((), |f| f.missing_extensions.contains(&name).then_some(())).is_some();
    // WebGL names its extensions without the `GL_` prefix (`EXT_color_buffer_float`).
    let set = gl.supported_extensions();
    !missing && (set.contains(name) || name.strip_prefix("GL_").is_some_and(|n| set.contains(n)))
}

/// An integer limit (`GL_MAX_TEXTURE_SIZE`, `GL_MAX_ARRAY_TEXTURE_LAYERS`), as the GL layer
/// sees it: the injected value if one is, else the context's.
pub(crate) fn limit(gl: &glow::Context, pname: u32) -> i32 {
    use glow::HasContext;
    let injected = match pname {
        glow::MAX_TEXTURE_SIZE => injected!(i32, |f| f.max_texture_size),
        glow::MAX_ARRAY_TEXTURE_LAYERS => injected!(i32, |f| f.max_array_layers),
        _ => None,
    };
    // SAFETY: a plain integer query.
    injected.unwrap_or_else(|| unsafe { gl.get_parameter_i32(pname) })
}

/// Whether `gl` can render to and blend in an RGBA32F framebuffer: desktop GL, or ES with
/// `GL_EXT_color_buffer_float` and `GL_EXT_float_blend`.
pub fn can_blend_rgba32f(gl: &glow::Context) -> bool {
    use glow::HasContext;
    !gl.version().is_embedded
        || (has_extension(gl, "GL_EXT_color_buffer_float")
            && has_extension(gl, "GL_EXT_float_blend"))
}

/// Whether `gl` can render to (and blend in) an RGBA16F framebuffer: desktop GL, or ES with
/// `GL_EXT_color_buffer_half_float` or `GL_EXT_color_buffer_float`.
pub fn can_render_rgba16f(gl: &glow::Context) -> bool {
    use glow::HasContext;
    !gl.version().is_embedded
        || has_extension(gl, "GL_EXT_color_buffer_float")
        || has_extension(gl, "GL_EXT_color_buffer_half_float")
}
