//! Fault injection for the GL tests (**hidden from the documented API**): lets a test make the
//! GL layer see an older context, lower limits, bad shader source, a missing extension or an
//! allocation the driver refuses, so every error path can be exercised on one healthy driver.
//!
//! The faults are per thread (a GL context is current on one thread, and the test harness runs
//! each test on its own thread) and last while the `FaultGuard` returned by `inject` lives.
//! The module exists only with the cargo feature `testing` (the tests enable it): without it
//! the GL layer's lookups (`gl::caps`, `injected!`) are the healthy driver's answers, with
//! nothing thread-local read and no symbol of this module in the binary.

use std::cell::RefCell;

/// The faults to inject. `Default` injects none.
#[derive(Debug, Clone, Default)]
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

thread_local! {
    static FAULTS: RefCell<Option<Faults>> = const { RefCell::new(None) };
}

/// Injects `faults` on this thread until the returned guard is dropped.
pub fn inject(faults: Faults) -> FaultGuard {
    let previous = FAULTS.with(|f| f.replace(Some(faults)));
    FaultGuard { previous }
}

/// Removes the injected faults when dropped (restoring any injected before).
#[derive(Debug)]
pub struct FaultGuard {
    previous: Option<Faults>,
}

impl Drop for FaultGuard {
    fn drop(&mut self) {
        let previous = self.previous.take();
        FAULTS.with(|f| *f.borrow_mut() = previous);
    }
}

/// A value from the injected faults, if any are injected.
pub(crate) fn get<T>(pick: impl FnOnce(&Faults) -> Option<T>) -> Option<T> {
    FAULTS.with(|f| f.borrow().as_ref().and_then(pick))
}
