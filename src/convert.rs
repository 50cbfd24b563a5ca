//! The converter's library half (`splatgl convert`): a loaded cloud → an RC-conformant glTF
//! (`.glb`, `.gltf`; a `.glb` with `KHR_gaussian_splatting_compression_spz_2` under
//! `--spz-compress`), an INRIA PLY, Niantic SPZ (v2–v4), antimatter15 `.splat` or PlayCanvas
//! SOG (`.sog`), with
//! optional quantization, SH truncation, a rotation (e.g. a y-down capture to glTF's +Y up)
//! and colour-space relabelling.
//!
//! Output formats are a table keyed by file extension ([`OUTPUTS`]); a new writer is a row.
//! What the glTF output holds: linear scales, only the component types the RC allows per
//! attribute, complete SH degrees, `kernel` and `colorSpace`, `extensionsUsed` (and
//! `KHR_mesh_quantization` in `extensionsRequired` for quantized positions), POSITION
//! `min`/`max`, and a `COLOR_0` fallback computed as the RC's note says (SH0·Y₀₀ + 0.5,
//! clamped, sRGB-decoded for `srgb_rec709_display`, alpha = opacity).

use crate::camera::{Camera, CamerasJsonEntry, UpAxis};
use crate::cloud::{ColorSpace, Known, SplatCloud, sh_coeff_count};
use crate::load::Format;
use crate::write::quantize::dequantize_node;
use crate::write::scene::{CameraNode, PerspectiveCamera, add_camera_nodes};
use crate::write::{self, Comp, GltfWriteOptions};
use glam::{DMat3, DMat4, DQuat, DVec3};

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
    /// PlayCanvas SOG v2 (`.sog`: lossless WebP textures in a zip; see [`write::to_sog_files`]).
    Sog,
}

/// Output formats by file extension (lower case).
pub const OUTPUTS: &[(&str, OutputFormat)] = &[
    ("glb", OutputFormat::Glb),
    ("gltf", OutputFormat::Gltf),
    ("ply", OutputFormat::Ply),
    ("spz", OutputFormat::Spz),
    ("splat", OutputFormat::Splat),
    ("sog", OutputFormat::Sog),
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
    pub fn set(&mut self, spec: &str) -> Result<(), ConvertError> {
        let (attr, ty) = spec.split_once('=').ok_or_else(|| {
            ConvertError::Quantize(format!(
                "--quantize {spec:?}: expected ATTR=TYPE, e.g. scale=u8n"
            ))
        })?;
        let comp: Comp = ty.trim().parse().map_err(ConvertError::Quantize)?;
        let (slot, allowed): (&mut Comp, &[Comp]) = match attr.trim() {
            "position" => (&mut self.position, &write::POSITION_TYPES),
            "rotation" => (&mut self.rotation, &write::ROTATION_TYPES),
            "scale" => (&mut self.scale, &write::SCALE_TYPES),
            "opacity" => (&mut self.opacity, &write::OPACITY_TYPES),
            other => {
                return Err(ConvertError::Quantize(format!(
                    "--quantize: unknown attribute {other:?} (position, rotation, scale, opacity; SH coefficients are float per the RC)"
                )));
            }
        };
        if !allowed.contains(&comp) {
            let names: Vec<&str> = allowed.iter().map(|c| c.name()).collect();
            return Err(ConvertError::Quantize(format!(
                "--quantize {spec}: the RC allows {} for {}",
                names.join(", "),
                attr.trim()
            )));
        }
        *slot = comp;
        Ok(())
    }
    /// Whether any attribute is stored as an integer type.
    pub fn any(&self) -> bool {
        *self != Quantize::default()
    }
}

/// The up axis of an input (`--up`): [`Up::Auto`] follows each format's convention, an
/// explicit axis is turned into glTF's +Y whatever the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Up {
    /// Each format's convention (`--up auto`, the default): the input's up is
    /// [`UpAxis::for_cloud`]'s (glTF +Y; PLY and the packed formats −Y, COLMAP axes, unless the
    /// content stands on z = 0 and is clearly taller along +Z); glTF outputs are +Y up, PLY,
    /// SPZ and `.splat` outputs −Y. Between two formats of the same convention nothing turns;
    /// a PLY-side input written as glTF turns its up to +Y ([`Up::rotation`]: 180° about Z for
    /// −Y, as `@playcanvas/splat-transform` does), a glTF input written as PLY, SPZ or
    /// `.splat` turns by the same 180° about Z back to −Y.
    #[default]
    Auto,
    /// +Y (glTF): nothing to do.
    PosY,
    /// −Y (INRIA / COLMAP captures): 180° about Z, (x, y, z) → (−x, −y, z), the rotation
    /// splat-transform applies (it keeps +Z, the side default views look from, in front).
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
            "auto" => Up::Auto,
            "y" | "+y" => Up::PosY,
            "-y" => Up::NegY,
            "z" | "+z" => Up::PosZ,
            "-z" => Up::NegZ,
            "x" | "+x" => Up::PosX,
            "-x" => Up::NegX,
            _ => return Err(format!("expected auto, y, -y, z, -z, x or -x, found {s:?}")),
        })
    }
}

impl From<UpAxis> for Up {
    fn from(a: UpAxis) -> Self {
        match a {
            UpAxis::Y => Up::PosY,
            UpAxis::NegY => Up::NegY,
            UpAxis::Z => Up::PosZ,
        }
    }
}

impl Up {
    /// The rotation taking this axis to +Y, exact (a signed permutation: every entry 0 or ±1,
    /// so positions, quaternions and the SH of a 180° turn move without rounding).
    /// [`Up::Auto`] has none of its own: see [`ConvertOptions::rotation_for`].
    pub fn rotation(self) -> DMat3 {
        let m = |cols: [[f64; 3]; 3]| DMat3::from_cols_array_2d(&cols);
        match self {
            Up::Auto | Up::PosY => DMat3::IDENTITY,
            Up::NegY => m([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]),
            // Columns are the images of x, y, z.
            Up::PosZ => m([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
            Up::NegZ => m([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
            Up::PosX => m([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            Up::NegX => m([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        }
    }

    /// The rotation of `--up auto` from an input of `input` format (with up `input_up`, from
    /// [`UpAxis::for_cloud`]) to an output in `output` format. See [`Up::Auto`].
    pub fn auto_rotation(input: Format, input_up: UpAxis, output: OutputFormat) -> DMat3 {
        let input_gltf = matches!(input, Format::Gltf | Format::Glb);
        match (input_gltf, output.is_gltf()) {
            (true, true) | (false, false) => DMat3::IDENTITY,
            (false, true) => Up::from(input_up).rotation(),
            // glTF's +Y to the PLY side's −Y: 180° about Z is its own inverse.
            (true, false) => Up::NegY.rotation().transpose(),
        }
    }
}

/// Why a conversion step failed.
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    /// A `--quantize ATTR=TYPE` spec that names no attribute or type, or a type the RC does not
    /// allow for that attribute (the message lists what it allows).
    #[error("{0}")]
    Quantize(String),
    /// A rotation that leaves values that are not finite (the loader's findings).
    #[error("{0}")]
    NotFinite(String),
    /// Camera nodes asked of a format other than glTF.
    #[error("camera nodes need a .glb or .gltf output")]
    CamerasNeedGltf,
    /// SPZ cannot hold the cloud (its 24-bit fixed-point positions).
    #[error("cannot write SPZ: {0}")]
    Spz(#[from] write::SpzWriteError),
    /// The SOG writer failed.
    #[error(transparent)]
    Sog(#[from] write::SogWriteError),
    /// A `cameras.json` view that makes no camera or no finite glTF camera.
    #[error("view {index}{}: {message}", name.as_ref().map(|n| format!(" ({n})")).unwrap_or_default())]
    View {
        /// Its index in the file.
        index: usize,
        /// Its name, once known.
        name: Option<String>,
        /// What is wrong with it.
        message: String,
    },
}

impl From<ConvertError> for String {
    fn from(e: ConvertError) -> String {
        e.to_string()
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
    /// The rotation applied to the cloud with `up` taken as given: `Rz · Ry · Rx · R_up`
    /// ([`Up::Auto`] counts as no rotation here; [`ConvertOptions::rotation_for`] resolves it).
    pub fn rotation(&self) -> DMat3 {
        self.extra_rotation() * self.up.rotation()
    }

    /// The rotation applied to `cloud`, read as `input`, when written as `output`:
    /// `Rz · Ry · Rx · R_up`, with [`Up::Auto`] resolved by [`Up::auto_rotation`].
    pub fn rotation_for(&self, input: Format, cloud: &SplatCloud, output: OutputFormat) -> DMat3 {
        let up = match self.up {
            Up::Auto => Up::auto_rotation(input, UpAxis::for_cloud(Some(input), cloud), output),
            explicit => explicit.rotation(),
        };
        self.extra_rotation() * up
    }

    /// `--rotate-x/-y/-z`: `Rz · Ry · Rx` (the identity, exactly, when all are 0).
    fn extra_rotation(&self) -> DMat3 {
        let [x, y, z] = self.rotate_deg.map(f64::to_radians);
        let turn = |d: f64, f: fn(f64) -> DMat3| if d == 0.0 { DMat3::IDENTITY } else { f(d) };
        turn(z, DMat3::from_rotation_z)
            * turn(y, DMat3::from_rotation_y)
            * turn(x, DMat3::from_rotation_x)
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
pub fn rotate(cloud: &SplatCloud, r: DMat3) -> Result<SplatCloud, ConvertError> {
    let mut findings = Vec::new();
    crate::load::gltf::apply_node_transform(cloud, DMat4::from_mat3(r), 0, &mut findings)
        .ok_or_else(|| {
            let all: Vec<String> = findings.iter().map(|f| f.to_string()).collect();
            ConvertError::NotFinite(all.join("; "))
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
) -> Result<(Vec<u8>, Vec<String>), ConvertError> {
    encode_with_cameras(cloud, format, o, &[])
}

/// [`encode`], with `cameras` as perspective camera nodes of a glTF output (see
/// [`camera_node`]). Cameras need a glTF output: other formats are an error.
pub fn encode_with_cameras(
    cloud: &SplatCloud,
    format: OutputFormat,
    o: &ConvertOptions,
    cameras: &[CameraNode],
) -> Result<(Vec<u8>, Vec<String>), ConvertError> {
    if !cameras.is_empty() && !format.is_gltf() {
        return Err(ConvertError::CamerasNeedGltf);
    }
    let mut notes = Vec::new();
    match format {
        OutputFormat::Ply => return Ok((write::to_inria_ply(cloud), notes)),
        OutputFormat::Sog => return Ok((write::to_sog_bundle(cloud)?, notes)),
        OutputFormat::Spz => {
            return Ok((write::to_spz(cloud, o.spz_version)?, notes));
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
            let (mut doc, spz) = write::build_glb_spz(cloud, &write::SpzWriteOptions::default())?;
            add_camera_nodes(&mut doc, cameras);
            return Ok((write::glb_bytes(&doc, &spz), notes));
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
    let (mut doc, bin) = write::build(&d.cloud, &w);
    add_camera_nodes(&mut doc, cameras);
    let bytes = match format {
        OutputFormat::Glb => write::glb_bytes(&doc, &bin),
        _ => write::gltf_bytes(doc, &bin),
    };
    Ok((bytes, notes))
}

/// The glTF camera node of one `cameras.json` view of a cloud that is written turned by `r`
/// ([`ConvertOptions::rotation_for`]), so that `render OUT --gltf-camera N` shows what
/// `render IN --camera cameras.json --view N` shows: the node sits at `r ·` the view's centre
/// with `r ·` its camera → world rotation, OpenCV axes turned to glTF's (Y and Z negated);
/// `yfov = 2·atan(height / (2·fy))`, `aspectRatio = width·fy / (height·fx)` (so `fx ≠ fy`
/// survives when the image keeps the view's aspect ratio), near 0.01 and far 100 as the 3DGS
/// trainer's. Named after `img_name` (`view N` without one). The note says what glTF cannot
/// hold: a principal point off the image centre.
pub fn camera_node(
    e: &CamerasJsonEntry,
    index: usize,
    r: DMat3,
) -> Result<(CameraNode, Option<String>), ConvertError> {
    let cam = Camera::from_3dgs(e).map_err(|err| ConvertError::View {
        index,
        name: None,
        message: err.to_string(),
    })?;
    // The rotation as the renderer uses it (Camera::from_3dgs orthonormalises it), so that the
    // node shows what `render --camera` shows; the centre as written (f64).
    let c2w = DMat3::from_mat4(cam.world_to_camera.as_dmat4()).transpose();
    let axes = r * c2w * DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0));
    let q = DQuat::from_mat3(&axes).normalize();
    let eye = r * DVec3::from_array(e.position);
    // Near and far as the decimal numbers the trainer's 0.01 / 100 are, not their f32 values.
    let decimal = |v: f32| v.to_string().parse::<f64>().unwrap_or(v as f64);
    let (w, h) = (e.width as f64, e.height as f64);
    let camera = PerspectiveCamera {
        yfov: 2.0 * (0.5 * h / e.fy).atan(),
        aspect_ratio: Some(w * e.fy / (h * e.fx)),
        znear: decimal(cam.near),
        zfar: Some(decimal(cam.far)),
    };
    let name = match e.img_name.as_str() {
        "" => format!("view {index}"),
        n => n.to_owned(),
    };
    let off = |c: Option<f64>, size: f64| c.is_some_and(|c| (c - 0.5 * size).abs() > 1e-4 * size);
    let note = (off(e.cx, w) || off(e.cy, h)).then(|| {
        format!(
            "view {index} ({name}): principal point ({}, {}) is off the image centre; a glTF camera keeps it centred",
            e.cx.unwrap_or(0.5 * w),
            e.cy.unwrap_or(0.5 * h)
        )
    });
    let finite = [
        camera.yfov,
        camera.aspect_ratio.unwrap_or(1.0),
        q.x,
        q.y,
        q.z,
        q.w,
    ]
    .iter()
    .chain(&eye.to_array())
    .all(|v| v.is_finite());
    if !finite || camera.aspect_ratio.is_some_and(|a| a <= 0.0) {
        return Err(ConvertError::View {
            index,
            message: format!(
                "its numbers give no finite glTF camera (yfov {}, aspectRatio {:?})",
                camera.yfov, camera.aspect_ratio
            ),
            name: Some(name),
        });
    }
    let node = CameraNode {
        name,
        camera,
        translation: eye.to_array(),
        rotation: [q.x, q.y, q.z, q.w],
    };
    Ok((node, note))
}
