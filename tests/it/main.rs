//! The `splatgl` library's integration tests: one binary, a module per subject. Modules that
//! need the GL backend or its test hooks are compiled with those features (`cargo test
//! --all-features` compiles them all). The tests that count allocations with a global
//! allocator are binaries of their own (`tests/sort.rs`, `tests/format_memory.rs`,
//! `tests/gl_frame_alloc.rs`).

/// The shared test helpers, and the GL one that needs the renderer's test hooks.
mod common {
    pub use splatgl_testkit::*;

    /// The GL helpers.
    #[cfg(feature = "gl")]
    pub mod gl {
        #[cfg(feature = "testing")]
        pub use splatgl::gl::Errata;
        pub use splatgl_testkit::gl::*;

        /// A headless renderer with review-draft errata switched in, or `None` (test skipped,
        /// with a message) when EGL cannot be opened.
        #[cfg(feature = "testing")]
        pub fn headless_with(errata: Errata) -> Option<HeadlessRenderer> {
            or_skip(HeadlessRenderer::with_errata(errata), "headless GL failed")
        }
    }
}

#[cfg(feature = "gl")]
mod antialiased;
mod camera;
mod docs_paths;
mod docs_snippets;
mod format_roundtrip;
mod formats;
#[cfg(feature = "gl")]
mod gl_draw_frame;
#[cfg(feature = "testing")]
mod gl_embedding;
#[cfg(feature = "testing")]
mod gl_errata;
#[cfg(feature = "testing")]
mod gl_faults;
#[cfg(feature = "gl")]
mod gl_pages;
#[cfg(feature = "testing")]
mod gl_vs_reference;
mod gltf_roundtrip;
mod layering;
mod malformed_input;
mod node_transforms;
mod ply;
mod real_files;
mod reference;
mod splat_transform;
