//! Accessor component types (glTF 2.0 §3.6.2.2) and their encoding.

/// A stored accessor component type, with normalization (glTF 2.0 §3.6.2.2). The names
/// ([`Comp::name`], parsed by `FromStr`) are the converter's `--quantize` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comp {
    /// float
    F32,
    /// signed byte
    I8,
    /// signed byte normalized
    I8N,
    /// unsigned byte
    U8,
    /// unsigned byte normalized
    U8N,
    /// signed short
    I16,
    /// signed short normalized
    I16N,
    /// unsigned short
    U16,
    /// unsigned short normalized
    U16N,
}

impl std::str::FromStr for Comp {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Comp::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Comp::ALL.iter().map(|c| c.name()).collect();
                format!(
                    "unknown component type {s:?} (expected one of {})",
                    names.join(", ")
                )
            })
    }
}

impl Comp {
    /// Every component type.
    pub const ALL: [Comp; 9] = [
        Comp::F32,
        Comp::I8,
        Comp::I8N,
        Comp::U8,
        Comp::U8N,
        Comp::I16,
        Comp::I16N,
        Comp::U16,
        Comp::U16N,
    ];
    /// Short name: `f32`, `i8`, `i8n`, `u8`, `u8n`, `i16`, `i16n`, `u16`, `u16n` (`n`:
    /// normalized).
    pub fn name(self) -> &'static str {
        match self {
            Comp::F32 => "f32",
            Comp::I8 => "i8",
            Comp::I8N => "i8n",
            Comp::U8 => "u8",
            Comp::U8N => "u8n",
            Comp::I16 => "i16",
            Comp::I16N => "i16n",
            Comp::U16 => "u16",
            Comp::U16N => "u16n",
        }
    }
    /// The decoded values this type can hold, `(lo, hi)` (normalized: glTF's
    /// `max(c / 127, −1)` etc.; not normalized: the integer range). `None` for float.
    pub fn range(self) -> Option<(f64, f64)> {
        match self {
            Comp::F32 => None,
            Comp::I8N | Comp::I16N => Some((-1.0, 1.0)),
            Comp::U8N | Comp::U16N => Some((0.0, 1.0)),
            Comp::I8 => Some((-128.0, 127.0)),
            Comp::U8 => Some((0.0, 255.0)),
            Comp::I16 => Some((-32768.0, 32767.0)),
            Comp::U16 => Some((0.0, 65535.0)),
        }
    }
    /// The quantization step in decoded units (0 for float): one integer for non-normalized
    /// types, `1/127`, `1/255`, `1/32767`, `1/65535` for normalized ones. Rounding to the
    /// nearest stored value errs by at most half of it.
    pub fn step(self) -> f64 {
        match self {
            Comp::F32 => 0.0,
            Comp::I8 | Comp::U8 | Comp::I16 | Comp::U16 => 1.0,
            Comp::I8N => 1.0 / 127.0,
            Comp::U8N => 1.0 / 255.0,
            Comp::I16N => 1.0 / 32767.0,
            Comp::U16N => 1.0 / 65535.0,
        }
    }
    /// Whether the type is stored normalized.
    pub fn is_normalized(self) -> bool {
        self.normalized()
    }
    pub(crate) fn gl(self) -> u32 {
        match self {
            Comp::I8 | Comp::I8N => 5120,
            Comp::U8 | Comp::U8N => 5121,
            Comp::I16 | Comp::I16N => 5122,
            Comp::U16 | Comp::U16N => 5123,
            Comp::F32 => 5126,
        }
    }
    pub(crate) fn size(self) -> usize {
        match self {
            Comp::I8 | Comp::I8N | Comp::U8 | Comp::U8N => 1,
            Comp::I16 | Comp::I16N | Comp::U16 | Comp::U16N => 2,
            Comp::F32 => 4,
        }
    }
    pub(crate) fn normalized(self) -> bool {
        matches!(self, Comp::I8N | Comp::U8N | Comp::I16N | Comp::U16N)
    }
    /// The value as stored: the float, or the quantized integer (what glTF `min`/`max` hold).
    pub(crate) fn stored(self, v: f32) -> f64 {
        let q = |scale: f32, lo: f32, hi: f32| (v * scale).round().clamp(lo, hi) as f64;
        match self {
            Comp::F32 => v as f64,
            Comp::I8 => q(1.0, -128.0, 127.0),
            Comp::I8N => q(127.0, -127.0, 127.0),
            Comp::U8 => q(1.0, 0.0, 255.0),
            Comp::U8N => q(255.0, 0.0, 255.0),
            Comp::I16 => q(1.0, -32768.0, 32767.0),
            Comp::I16N => q(32767.0, -32767.0, 32767.0),
            Comp::U16 => q(1.0, 0.0, 65535.0),
            Comp::U16N => q(65535.0, 0.0, 65535.0),
        }
    }
    /// Encodes `v` (quantizing and clamping integer types).
    pub(crate) fn encode(self, v: f32, out: &mut Vec<u8>) {
        let q = |scale: f32, lo: f32, hi: f32| (v * scale).round().clamp(lo, hi);
        match self {
            Comp::F32 => out.extend_from_slice(&v.to_le_bytes()),
            Comp::I8 => out.push(q(1.0, -128.0, 127.0) as i8 as u8),
            Comp::I8N => out.push(q(127.0, -127.0, 127.0) as i8 as u8),
            Comp::U8 => out.push(q(1.0, 0.0, 255.0) as u8),
            Comp::U8N => out.push(q(255.0, 0.0, 255.0) as u8),
            Comp::I16 => out.extend_from_slice(&(q(1.0, -32768.0, 32767.0) as i16).to_le_bytes()),
            Comp::I16N => {
                out.extend_from_slice(&(q(32767.0, -32767.0, 32767.0) as i16).to_le_bytes())
            }
            Comp::U16 => out.extend_from_slice(&(q(1.0, 0.0, 65535.0) as u16).to_le_bytes()),
            Comp::U16N => out.extend_from_slice(&(q(65535.0, 0.0, 65535.0) as u16).to_le_bytes()),
        }
    }
}
