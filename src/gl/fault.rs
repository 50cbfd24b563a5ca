//! Fault injection for the GL tests (**hidden from the documented API**): lets a test make the
//! GL layer see an older context, lower limits, bad shader source, a missing extension or an
//! allocation the driver refuses, so every error path can be exercised on one healthy driver.
//!
//! The faults are per thread (a GL context is current on one thread, and the test harness runs
//! each test on its own thread) and last while the `FaultGuard` returned by `inject` lives.
//! Only with the cargo feature `testing` (the tests enable it): without it `inject` does not
//! exist and every lookup below is the healthy driver's answer, with nothing thread-local read.

#[cfg(feature = "testing")]
use std::cell::RefCell;

/// The faults to inject. `Default` injects none.
#[derive(Debug, Clone, Default)]
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub struct Faults {
    /// Read instead of `GL_VERSION` by the context check of `SplatRenderer::new`, e.g.
    /// `"2.1 Mesa 22.3.6"` or `"OpenGL ES 2.0 Mesa"`.
    pub gl_version: Option<String>,
    /// The effective `GL_MAX_TEXTURE_SIZE` (lowered to force clouds across array layers). Read
    /// by `SplatRenderer::new` (texture width, baked into the shader) and `upload`.
    pub max_texture_size: Option<i32>,
    /// The effective `GL_MAX_ARRAY_TEXTURE_LAYERS`.
    pub max_array_layers: Option<i32>,
    /// Rewrites the assembled source of each stage of the splat program before it is compiled:
    /// called with `"vertex"` or `"fragment"` and the source.
    pub edit_shader: Option<fn(&str, String) -> String>,
    /// Extensions treated as absent (e.g. `"GL_EXT_color_buffer_float"`).
    pub missing_extensions: Vec<&'static str>,
    /// Allocate every data texture of an upload with this many full layers, whatever the cloud
    /// needs (a request the driver refuses with `GL_OUT_OF_MEMORY`, without allocating).
    pub oversize_layers: Option<i32>,
}

#[cfg(feature = "testing")]
thread_local! {
    static FAULTS: RefCell<Option<Faults>> = const { RefCell::new(None) };
}

/// Injects `faults` on this thread until the returned guard is dropped.
#[cfg(feature = "testing")]
pub fn inject(faults: Faults) -> FaultGuard {
    let previous = FAULTS.with(|f| f.replace(Some(faults)));
    FaultGuard { previous }
}

/// Removes the injected faults when dropped (restoring any injected before).
#[cfg(feature = "testing")]
#[derive(Debug)]
pub struct FaultGuard {
    previous: Option<Faults>,
}

#[cfg(feature = "testing")]
impl Drop for FaultGuard {
    fn drop(&mut self) {
        let previous = self.previous.take();
        FAULTS.with(|f| *f.borrow_mut() = previous);
    }
}

/// A value from the injected faults, if any are injected.
#[cfg(feature = "testing")]
pub(crate) fn get<T>(pick: impl FnOnce(&Faults) -> Option<T>) -> Option<T> {
    FAULTS.with(|f| f.borrow().as_ref().and_then(pick))
}

/// Without the `testing` feature nothing is ever injected.
#[cfg(not(feature = "testing"))]
#[inline(always)]
pub(crate) fn get<T>(_pick: impl FnOnce(&Faults) -> Option<T>) -> Option<T> {
    None
}

/// Whether the extension is supported, as the GL layer sees it.
pub(crate) fn has_extension(gl: &glow::Context, name: &str) -> bool {
    use glow::HasContext;
    let missing = get(|f| f.missing_extensions.contains(&name).then_some(())).is_some();
    !missing && gl.supported_extensions().contains(name)
}

/// An integer limit (`GL_MAX_TEXTURE_SIZE`, `GL_MAX_ARRAY_TEXTURE_LAYERS`), as the GL layer
/// sees it: the injected value if one is, else the context's.
pub(crate) fn limit(gl: &glow::Context, pname: u32) -> i32 {
    use glow::HasContext;
    let injected = match pname {
        glow::MAX_TEXTURE_SIZE => get(|f| f.max_texture_size),
        glow::MAX_ARRAY_TEXTURE_LAYERS => get(|f| f.max_array_layers),
        _ => None,
    };
    // SAFETY: a plain integer query.
    injected.unwrap_or_else(|| unsafe { gl.get_parameter_i32(pname) })
}
