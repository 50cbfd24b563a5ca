//! [`Details`]: what a quantized container says about itself, beyond the splats — which
//! container and version, its entropy coding, how many bits each attribute keeps, flags such as
//! SPZ's antialiasing bit, and every lossy step between the trainer's floats and the file.
//! `splatgl info` prints it (text, and the `--json` keys `container`, `container_version`,
//! `compression`, `gltf_extension`, `quantization`, `lossy`, `antialiased`).

/// How one attribute is stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AttributeBits {
    /// `"position"`, `"scale"`, `"rotation"`, `"color"`, `"opacity"` or `"sh"`.
    pub attribute: &'static str,
    /// Bits per component as stored (before any entropy coding); 32 for f32.
    pub bits: u8,
    /// How the stored value maps to ours, e.g. `"24-bit fixed point, 12 fractional bits"`.
    pub encoding: String,
}

/// Container facts of a loaded file.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Details {
    /// The container the splats were packed in: `"spz"`, `"splat"`, `"ksplat"`, `"sog"` or
    /// `"compressed_ply"` (also for a payload inside glTF, see [`Details::gltf_extension`]).
    pub container: &'static str,
    /// Its version as the file states it (`"2"`, `"4"`, `"0.1"`), empty when the container has
    /// none (`.splat`, compressed PLY).
    pub version: String,
    /// Entropy coding / wrapping: `"gzip"`, `"zstd"`, `"zip"`, `"none"`, …
    pub compression: String,
    /// The glTF extension that carries the payload (`KHR_gaussian_splatting_compression_spz_2`
    /// or the legacy `KHR_spz_gaussian_splats_compression`); `None` for a file of its own.
    pub gltf_extension: Option<&'static str>,
    /// One entry per attribute.
    pub quantization: Vec<AttributeBits>,
    /// SPZ flag 0x1: the splats were trained with antialiasing (Mip-Splatting style) and are
    /// meant to be rendered with the matching 2D filter compensation. `false` for containers
    /// without the flag.
    pub antialiased: bool,
    /// What the format cannot keep (each a sentence, for `info`).
    pub lossy: Vec<String>,
}

impl Details {
    pub(crate) fn new(container: &'static str, compression: impl Into<String>) -> Self {
        Details {
            container,
            compression: compression.into(),
            ..Default::default()
        }
    }
    pub(crate) fn bits(&mut self, attribute: &'static str, bits: u8, encoding: impl Into<String>) {
        self.quantization.push(AttributeBits {
            attribute,
            bits,
            encoding: encoding.into(),
        });
    }
    pub(crate) fn lossy(&mut self, what: impl Into<String>) {
        self.lossy.push(what.into());
    }

    /// One line for people: `SPZ v2, gzip, in KHR_gaussian_splatting_compression_spz_2`.
    pub fn summary(&self) -> String {
        let mut s = self.container.to_string();
        if !self.version.is_empty() {
            s += &format!(" v{}", self.version);
        }
        if !self.compression.is_empty() {
            s += &format!(", {}", self.compression);
        }
        if let Some(e) = self.gltf_extension {
            s += &format!(", in {e}");
        }
        s
    }

    /// The `info --json` keys this adds (`container`, `container_version`, `compression`,
    /// `gltf_extension`, `quantization`, `lossy`, `antialiased`); all `null` without details.
    pub fn json_keys(d: Option<&Details>) -> serde_json::Map<String, serde_json::Value> {
        use serde_json::{Value, json};
        let mut m = serde_json::Map::new();
        let get = |f: &dyn Fn(&Details) -> Value| d.map_or(Value::Null, f);
        m.insert("container".into(), get(&|d| json!(d.container)));
        m.insert("container_version".into(), get(&|d| json!(d.version)));
        m.insert("compression".into(), get(&|d| json!(d.compression)));
        m.insert("gltf_extension".into(), get(&|d| json!(d.gltf_extension)));
        let q = |d: &Details| {
            let q = d.quantization.iter();
            json!(
                q.map(
                    |b| json!({"attribute": b.attribute, "bits": b.bits, "encoding": b.encoding})
                )
                .collect::<Vec<_>>()
            )
        };
        m.insert("quantization".into(), get(&q));
        m.insert("lossy".into(), get(&|d| json!(d.lossy)));
        m.insert("antialiased".into(), get(&|d| json!(d.antialiased)));
        m
    }
}
