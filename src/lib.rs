//! # splatgl
//!
//! A renderer for 3D Gaussian splats and the reference implementation of the glTF extension
//! `KHR_gaussian_splatting` (Release Candidate).
//!
//! Data flow, one module per stage: [`load`] (glTF / PLY / SPZ / .splat / .ksplat / SOG →
//! [`SplatCloud`], with its [`cloud`] metadata) → [`cull`] → [`sort`] → `gl` (draw; `headless` drives it without a window) with
//! the CPU [`reference`](mod@reference) rasterizer beside it, [`compare`] for image comparison, [`image`] for
//! PNG / PFM files and [`write`](mod@write) for glTF / PLY output. [`camera`] holds the camera model,
//! [`profile`] every number of the rendering profile and [`sh`] the spherical harmonics.
//! The crates and modules are mapped in `ARCHITECTURE.md`; the applications (command line,
//! viewer, conformance kit, C API) are crates of their own in `crates/`.
//!
//! ## Embedding in a GL host (feature `gl`)
//!
//! The host keeps its context, framebuffer, depth buffer and camera; the renderer culls, sorts
//! and draws into whatever is bound (`docs/embedding.md`; C and C++ hosts: the `splatgl-capi`
//! crate):
//!
#![cfg_attr(feature = "gl", doc = "```no_run")]
#![cfg_attr(feature = "gl", doc = include_str!("../docs/snippets/embed.rs"))]
#![cfg_attr(feature = "gl", doc = "```")]
#![warn(missing_docs)]

pub mod camera;
pub mod cloud;
pub mod compare;
pub mod convert;
pub mod covariance;
pub mod cull;
pub mod engine;
pub mod files;
#[cfg(feature = "gl")]
pub mod gl;
#[cfg(all(feature = "gl", not(target_arch = "wasm32")))]
pub mod headless;
pub mod image;
pub mod load;
pub mod profile;
pub mod reference;
pub mod sh;
pub mod sort;
pub mod synthetic;
pub mod tiles;
pub mod write;

pub use cloud::SplatCloud;
