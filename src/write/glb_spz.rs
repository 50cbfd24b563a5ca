//! `.glb` with `KHR_gaussian_splatting_compression_spz_2`: the splats as one SPZ v2 (gzip)
//! blob in a bufferView, packed from glTF's LUF axes to SPZ's RUB (the extension's text;
//! CesiumJS instead reads the payload as stored, see docs/formats.md § glTF with SPZ
//! compression), and placeholder accessors without bufferViews whose `count` is the SPZ point
//! count. POSITION's `min`/`max` (a glTF MUST) hold the positions as they decode, quantization
//! included, so a reader can tell which axes the payload is in.

use super::spz::{SpzWriteError, SpzWriteOptions, encode};
use super::{extension_object, glb_bytes};
use crate::cloud::SplatCloud;
use crate::load::spz::Frame;
use serde_json::{Value, json};

const SPZ_2: &str = "KHR_gaussian_splatting_compression_spz_2";
const PREFIX: &str = "KHR_gaussian_splatting:";

/// Encodes `cloud` (in glTF axes, like [`super::to_glb`]) as a `.glb` whose one splat
/// primitive is compressed by `KHR_gaussian_splatting_compression_spz_2`, with Niantic's
/// defaults (SPZ v2, 12 fractional bits, SH 5/4 bits). See [`to_glb_spz_with`].
pub fn to_glb_spz(cloud: &SplatCloud) -> Result<Vec<u8>, SpzWriteError> {
    to_glb_spz_with(cloud, &SpzWriteOptions::default())
}

/// [`to_glb_spz`] with `o`'s fractional bits, SH bits and antialiasing flag. `o.version` must
/// be [`super::SpzVersion::V2`], the one the extension pins; `o.axes` raw skips the LUF → RUB
/// conversion (glTF-axis numbers in the payload, as CesiumJS reads it).
pub fn to_glb_spz_with(cloud: &SplatCloud, o: &SpzWriteOptions) -> Result<Vec<u8>, SpzWriteError> {
    let (doc, spz) = build_glb_spz(cloud, o)?;
    Ok(glb_bytes(&doc, &spz))
}

/// The document and the BIN chunk (the SPZ payload) of [`to_glb_spz_with`], for writers that
/// add to the document (camera nodes) before framing it with [`glb_bytes`].
pub(crate) fn build_glb_spz(
    cloud: &SplatCloud,
    o: &SpzWriteOptions,
) -> Result<(Value, Vec<u8>), SpzWriteError> {
    if o.version != super::SpzVersion::V2 {
        return Err(SpzWriteError::Options(format!(
            "{SPZ_2} pins SPZ version 2, not {}",
            o.version.number()
        )));
    }
    let spz = encode(cloud, o, Frame::Gltf)?;
    let n = cloud.len();
    let mut accessors = Vec::new();
    let mut attrs = serde_json::Map::new();
    let mut placeholder = |name: String, ty: &str| {
        accessors.push(json!({"componentType": 5126, "count": n, "type": ty}));
        attrs.insert(name, json!(accessors.len() - 1));
    };
    placeholder("POSITION".into(), "VEC3");
    placeholder(format!("{PREFIX}ROTATION"), "VEC4");
    placeholder(format!("{PREFIX}SCALE"), "VEC3");
    placeholder(format!("{PREFIX}OPACITY"), "SCALAR");
    for l in 0..=cloud.sh_degree as usize {
        for c in 0..2 * l + 1 {
            placeholder(format!("{PREFIX}SH_DEGREE_{l}_COEF_{c}"), "VEC3");
        }
    }
    if let Some((lo, hi)) = decoded_bounds(cloud, o.fractional_bits) {
        accessors[0]["min"] = json!(lo);
        accessors[0]["max"] = json!(hi);
    }
    let mut ext = extension_object(&cloud.meta);
    ext["extensions"] = json!({ SPZ_2: {"bufferView": 0} });
    let used = ["KHR_gaussian_splatting", SPZ_2];
    let doc: Value = json!({
        "asset": {"version": "2.0", "generator": "splatgl"},
        "extensionsUsed": used,
        // The placeholders have no data to fall back on.
        "extensionsRequired": used,
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": attrs,
            "mode": 0,
            "extensions": {"KHR_gaussian_splatting": ext},
        }]}],
        "buffers": [{"byteLength": spz.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": spz.len()}],
        "accessors": accessors,
    });
    Ok((doc, spz))
}

/// Bounds of the positions as a reader decodes them: rounded to steps of 2^-bits (the axis
/// flips of the round trip cancel exactly).
fn decoded_bounds(cloud: &SplatCloud, bits: u8) -> Option<([f64; 3], [f64; 3])> {
    if cloud.is_empty() {
        return None;
    }
    let step = (1u64 << bits) as f64;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &cloud.positions {
        for k in 0..3 {
            let v = (p[k] as f64 * step).round() / step;
            lo[k] = lo[k].min(v);
            hi[k] = hi[k].max(v);
        }
    }
    Some((lo, hi))
}
