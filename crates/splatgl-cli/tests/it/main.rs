//! The `splatgl` command's integration tests: one binary, a module per subject. They run the
//! built binary (cargo gives its path to this crate's tests alone: `common::cli`), the
//! third-party cross-checks (`common::third_party`) and the viewer under Xvfb
//! (`common::viewer`).

/// The shared test helpers, and the ones that run the `splatgl` binary.
mod common {
    pub use splatgl_testkit::*;

    pub mod cli;
    pub mod third_party;
    #[cfg(feature = "viewer")]
    pub mod viewer;
}

mod cli;
mod cli_backend;
mod cli_batch;
mod cli_framing;
mod cli_kernel_crop;
mod cli_messages;
mod cli_options;
mod conformance;
mod conformance_babylon;
mod conformance_cesium;
mod conformance_playcanvas;
mod conformance_third_party;
mod convert;
mod file_access;
mod hygiene;
mod splat_transform_gltf;
mod tiles;
mod tiles_build;
mod tiles_cesium;
#[cfg(feature = "http")]
mod tiles_http;
#[cfg(feature = "http")]
mod tiles_streamed_sog;
#[cfg(feature = "viewer")]
mod viewer;
#[cfg(feature = "viewer")]
mod viewer_panel;
mod web;
#[cfg(feature = "viewer")]
mod windows;
mod writers;
