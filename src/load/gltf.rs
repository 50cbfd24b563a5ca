//! glTF loader (in progress).
use super::{Format, LoadOptions, Loaded};
use std::path::Path;

/// What is wrong with a glTF file.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// Placeholder.
    #[error("glTF loading is not implemented yet")]
    NotYet,
}

/// Loads a glTF or GLB file from memory.
pub fn load(
    _bytes: &[u8],
    _format: Format,
    _path: Option<&Path>,
    _opts: &LoadOptions,
) -> Result<Loaded, GltfError> {
    Err(GltfError::NotYet)
}
