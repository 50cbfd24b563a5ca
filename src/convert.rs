//! The converter's library half (`splatgl convert`): a loaded cloud → an RC-conformant glTF
//! (`.glb`, `.gltf`; a `.glb` with `KHR_gaussian_splatting_compression_spz_2` under
//! `--spz-compress`), an INRIA PLY, Niantic SPZ (v2–v4) or antimatter15 `.splat`, with
//! optional quantization, SH truncation, a rotation (e.g. a y-down capture to glTF's +Y up)
//! and colour-space relabelling.
//!
//! Output formats are a table keyed by file extension ([`OUTPUTS`]); a new writer is a row.
//! What the glTF output holds: linear scales, only the component types the RC allows per
//! attribute, complete SH degrees, `kernel` and `colorSpace`, `extensionsUsed` (and
//! `KHR_mesh_quantization` in `extensionsRequired` for quantized positions), POSITION
//! `min`/`max`, and a `COLOR_0` fallback computed as the RC's note says (SH0·Y₀₀ + 0.5,
//! clamped, sRGB-decoded for `srgb_rec709_display`, alpha = opacity).

use crate::cloud::{ColorSpace, Known, SplatCloud, sh_coeff_count};
use crate::write::quantize::dequantize_node;
use crate::write::{self, Comp, GltfWriteOptions};
use glam::{DMat3, DMat4};

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// Binary glTF.
    Glb,
    /// glTF JSON with an embedded (data-URI) buffer.
    Gltf,
    /// INRIA 3DGS binary PLY.
    Ply,
    /// Niantic SPZ ([`ConvertOptions::spz_version`]; v2 by default).
    Spz,
    /// antimatter15 `.splat` (32 bytes per splat, SH degree 0).
    Splat,
}

/// Output formats by file extension (lower case).
pub const OUTPUTS: &[(&str, OutputFormat)] = &[
    ("glb", OutputFormat::Glb),
    ("gltf", OutputFormat::Gltf),
    ("ply", OutputFormat::Ply),
    ("spz", OutputFormat::Spz),
    ("splat", OutputFormat::Splat),
];

impl OutputFormat {
    /// The format for a file name's extension.
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        OUTPUTS.iter().find(|(e, _)| *e == ext).map(|(_, f)| *f)
    }
    /// Whether the format stores component types (glTF).
    pub fn is_gltf(self) -> bool {
        matches!(self, OutputFormat::Glb | OutputFormat::Gltf)
    }
}

/// Per-attribute component types (`--quantize`), each within the RC's table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quantize {
    /// POSITION (non-float: `KHR_mesh_quantization` with a dequantization node).
    pub position: Comp,
    /// ROTATION.
    pub rotation: Comp,
    /// SCALE.
    pub scale: Comp,
    /// OPACITY.
    pub opacity: Comp,
}

impl Default for Quantize {
    fn default() -> Self {
        Quantize {
            position: Comp::F32,
            rotation: Comp::F32,
            scale: Comp::F32,
            opacity: Comp::F32,
        }
    }
}

impl Quantize {
    /// Sets one attribute from `ATTR=TYPE` (attributes `position`, `rotation`, `scale`,
    /// `opacity`; types [`Comp::name`]s), checking the RC's table.
    pub fn set(&mut self, spec: &str) -> Result<(), String> {
        let (attr, ty) = spec
            .split_once('=')
            .ok_or_else(|| format!("--quantize {spec:?}: expected ATTR=TYPE, e.g. scale=u8n"))?;
        let comp: Comp = ty.trim().parse()?;
        let (slot, allowed): (&mut Comp, &[Comp]) = match attr.trim() {
            "position" => (&mut self.position, &write::POSITION_TYPES),
            "rotation" => (&mut self.rotation, &write::ROTATION_TYPES),
            "scale" => (&mut self.scale, &write::SCALE_TYPES),
            "opacity" => (&mut self.opacity, &write::OPACITY_TYPES),
            other => {
                return Err(format!(
                    "--quantize: unknown attribute {other:?} (position, rotation, scale, opacity; SH coefficients are float per the RC)"
                ));
            }
        };
        if !allowed.contains(&comp) {
            let names: Vec<&str> = allowed.iter().map(|c| c.name()).collect();
            return Err(format!(
                "--quantize {spec}: the RC allows {} for {}",
                names.join(", "),
                attr.trim()
            ));
        }
        *slot = comp;
        Ok(())
    }
    /// Whether any attribute is stored as an integer type.
    pub fn any(&self) -> bool {
        *self != Quantize::default()
    }
}

/// The up axis of an input, converted to glTF's +Y (`--up`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Up {
    /// +Y (glTF): nothing to do.
    #[default]
    PosY,
    /// −Y (INRIA / COLMAP captures): 180° about X.
    NegY,
    /// +Z: −90° about X.
    PosZ,
    /// −Z: +90° about X.
    NegZ,
    /// +X: +90° about Z.
    PosX,
    /// −X: −90° about Z.
    NegX,
}

impl std::str::FromStr for Up {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "y" | "+y" => Up::PosY,
            "-y" => Up::NegY,
            "z" | "+z" => Up::PosZ,
            "-z" => Up::NegZ,
            "x" | "+x" => Up::PosX,
            "-x" => Up::NegX,
            _ => return Err(format!("expected y, -y, z, -z, x or -x, found {s:?}")),
        })
    }
}

impl Up {
    /// The rotation taking this axis to +Y.
    pub fn rotation(self) -> DMat3 {
        use std::f64::consts::{FRAC_PI_2, PI};
        match self {
            Up::PosY => DMat3::IDENTITY,
            Up::NegY => DMat3::from_rotation_x(PI),
            Up::PosZ => DMat3::from_rotation_x(-FRAC_PI_2),
            Up::NegZ => DMat3::from_rotation_x(FRAC_PI_2),
            Up::PosX => DMat3::from_rotation_z(FRAC_PI_2),
            Up::NegX => DMat3::from_rotation_z(-FRAC_PI_2),
        }
    }
}

/// What to do to the cloud before writing.
#[derive(Debug, Clone, Default)]
pub struct ConvertOptions {
    /// Component types (glTF outputs).
    pub quantize: Quantize,
    /// Keep SH degrees up to this one (`None`: all).
    pub sh_degree: Option<u8>,
    /// Input up axis.
    pub up: Up,
    /// Rotations in degrees about X, then Y, then Z, applied after `up`.
    pub rotate_deg: [f64; 3],
    /// Relabel the colour space (no colour values change).
    pub color_space: Option<ColorSpace>,
    /// SPZ version of `.spz` outputs.
    pub spz_version: write::SpzVersion,
    /// `.glb` output: SPZ v2 in `KHR_gaussian_splatting_compression_spz_2` instead of
    /// accessors (then `quantize` does not apply).
    pub spz_compress: bool,
}

impl ConvertOptions {
    /// The rotation applied to the cloud: `Rz · Ry · Rx · R_up`.
    pub fn rotation(&self) -> DMat3 {
        let [x, y, z] = self.rotate_deg.map(f64::to_radians);
        DMat3::from_rotation_z(z)
            * DMat3::from_rotation_y(y)
            * DMat3::from_rotation_x(x)
            * self.up.rotation()
    }
}

/// A copy of splats `range` of `cloud`.
pub fn slice(cloud: &SplatCloud, range: std::ops::Range<usize>) -> SplatCloud {
    let k = cloud.coeffs_per_splat();
    SplatCloud {
        positions: cloud.positions[range.clone()].to_vec(),
        scales: cloud.scales[range.clone()].to_vec(),
        rotations: cloud.rotations[range.clone()].to_vec(),
        opacities: cloud.opacities[range.clone()].to_vec(),
        sh_degree: cloud.sh_degree,
        sh: cloud.sh[range.start * k..range.end * k].to_vec(),
        meta: cloud.meta.clone(),
    }
}

/// Keeps SH degrees `0..=degree` (no-op when the cloud has no more).
pub fn truncate_sh(cloud: &mut SplatCloud, degree: u8) {
    if degree >= cloud.sh_degree {
        return;
    }
    let (old, new) = (cloud.coeffs_per_splat(), sh_coeff_count(degree));
    let sh = cloud
        .sh
        .chunks_exact(old)
        .flat_map(|c| c[..new].iter().copied())
        .collect();
    cloud.sh = sh;
    cloud.sh_degree = degree;
}

/// Rotates a cloud (positions, covariances, SH by Wigner-D) exactly as the glTF loader
/// applies a node rotation. `Err` if the result is not finite.
pub fn rotate(cloud: &SplatCloud, r: DMat3) -> Result<SplatCloud, String> {
    let mut findings = Vec::new();
    crate::load::gltf::apply_node_transform(cloud, DMat4::from_mat3(r), 0, &mut findings)
        .ok_or_else(|| {
            findings
                .iter()
                .map(|f| f.to_string())
                .collect::<Vec<_>>()
                .join("; ")
        })
}

/// Relabels and truncates (the cheap, whole-cloud steps of [`ConvertOptions`]).
pub fn relabel(cloud: &mut SplatCloud, o: &ConvertOptions) {
    if let Some(d) = o.sh_degree {
        truncate_sh(cloud, d);
    }
    if let Some(cs) = o.color_space {
        cloud.meta.color_space = Known::Known(cs);
    }
}

/// The file bytes of `cloud` in `format`, and notes for the user (e.g. clamped values).
/// Fails only where the format cannot hold the cloud (SPZ's 24-bit fixed-point positions).
pub fn encode(
    cloud: &SplatCloud,
    format: OutputFormat,
    o: &ConvertOptions,
) -> Result<(Vec<u8>, Vec<String>), String> {
    let mut notes = Vec::new();
    let spz_err = |e: write::SpzWriteError| format!("cannot write SPZ: {e}");
    match format {
        OutputFormat::Ply => return Ok((write::to_inria_ply(cloud), notes)),
        OutputFormat::Spz => {
            return Ok((write::to_spz(cloud, o.spz_version).map_err(spz_err)?, notes));
        }
        OutputFormat::Splat => {
            if cloud.sh_degree > 0 {
                notes.push(format!(
                    ".splat holds colour only: SH degrees 1..={} dropped",
                    cloud.sh_degree
                ));
            }
            return Ok((write::to_splat(cloud), notes));
        }
        OutputFormat::Glb if o.spz_compress => {
            return Ok((write::to_glb_spz(cloud).map_err(spz_err)?, notes));
        }
        OutputFormat::Glb | OutputFormat::Gltf => {}
    }
    let q = &o.quantize;
    let d = dequantize_node(cloud, q.position, q.scale);
    if d.clamped_scales > 0 {
        notes.push(format!(
            "{} scale values exceeded the range of {} and were clamped",
            d.clamped_scales,
            q.scale.name()
        ));
    }
    let w = GltfWriteOptions {
        position: q.position,
        rotation: q.rotation,
        scale: q.scale,
        opacity: q.opacity,
        node_matrix: d.matrix,
        color0: true,
        ..Default::default()
    };
    let bytes = match format {
        OutputFormat::Glb => write::to_glb(&d.cloud, &w),
        _ => write::to_gltf(&d.cloud, &w),
    };
    Ok((bytes, notes))
}
