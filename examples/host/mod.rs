//! The hosts of the embedding examples, shared with `tests/it/gl_embedding.rs` (which renders
//! both headlessly and checks their pixels): `modern` (GLES 3 / core profile, own shader and
//! vertex array), `legacy` (compatibility profile: fixed function, immediate mode, client
//! arrays), `legacy_gl` (the legacy entry points, loaded by hand).
#![allow(dead_code)]

pub mod legacy;
pub mod legacy_gl;
pub mod modern;
