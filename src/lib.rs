//! # splatgl
//!
//! A renderer for 3D Gaussian splats and the reference implementation of the glTF extension
//! `KHR_gaussian_splatting` (Release Candidate).
//!
//! Data flow, one module per stage:
//! `load` (glTF / PLY → [`SplatCloud`]) → `sort` → `gl` (draw) with the CPU `reference`
//! rasterizer beside it, and `compare` for image comparison.
#![warn(missing_docs)]

pub mod camera;
pub mod cloud;
pub mod compare;
pub mod conformance;
pub mod convert;
pub mod covariance;
#[cfg(feature = "gl")]
pub mod gl;
#[cfg(feature = "gl")]
pub mod headless;
pub mod image;
pub mod load;
pub mod profile;
pub mod reference;
pub mod scene;
pub mod sh;
pub mod sort;
pub mod write;

pub use cloud::SplatCloud;
