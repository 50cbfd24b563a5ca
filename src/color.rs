//! Transitional alias: the sRGB transfer function now lives in [`crate::profile`]. Kept only
//! for the loader's call site (`load/gltf/primitive.rs`) until it imports
//! [`crate::profile::srgb_encode`] itself.

pub(crate) use crate::profile::srgb_encode;
