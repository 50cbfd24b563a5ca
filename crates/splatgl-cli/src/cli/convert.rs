//! `splatgl convert IN OUT`: any readable splat file → `.glb` / `.gltf` (RC-conformant) or
//! `.ply` (INRIA), through [`splatgl::convert`].

use super::convert_lod::TreeOutput;
use splatgl::SplatCloud;
use splatgl::cloud::ColorSpace;
use splatgl::convert::{self, ConvertOptions, OutputFormat, Quantize, Up};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Input file (any format splatgl reads).
    pub input: PathBuf,
    /// Output file: .glb, .gltf (KHR_gaussian_splatting RC), .ply (INRIA 3DGS), .spz (Niantic),
    /// .splat (antimatter15) or .sog (PlayCanvas SOG v2); or a LOD tree: OUT named
    /// lod-meta.json a PlayCanvas streamed SOG (its SOG units in folders beside it), any other
    /// OUT ending in .json a 3D Tiles 1.1 tileset (e.g. out/tileset.json, its tiles' .glb
    /// content in out/tiles/); docs/lod.md.
    pub output: PathBuf,
    /// Store an attribute as an integer type (glTF outputs), ATTR=TYPE, comma-separated or
    /// repeated: position=i8|i8n|u8|u8n|i16|i16n|u16|u16n (KHR_mesh_quantization with a
    /// dequantization node), rotation=i8n|i16n, scale=u8|u8n|u16|u16n, opacity=u8n|u16n.
    #[arg(long, value_name = "ATTR=TYPE", value_delimiter = ',')]
    pub quantize: Vec<String>,
    /// Keep SH degrees up to N (truncate higher ones).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=3))]
    pub sh_degree: Option<u8>,
    /// Rotate about X by DEG degrees (after --up; order X, then Y, then Z).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub rotate_x: f64,
    /// Rotate about Y by DEG degrees.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub rotate_y: f64,
    /// Rotate about Z by DEG degrees.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub rotate_z: f64,
    /// The input's up axis. auto (default): each format's convention, as render frames it —
    /// glTF is +Y up, PLY and the packed formats -Y (COLMAP axes; +Z when the content stands
    /// on z = 0 and is clearly taller along z); a PLY-side input written as glTF is turned to
    /// +Y (180° about Z for -Y, as splat-transform does), a glTF input written as .ply,
    /// .spz or .splat turned back to -Y. An explicit axis is turned into +Y whatever the
    /// output: y (unchanged), -y (180° about Z), z, -z, x, -x.
    #[arg(
        long,
        default_value = "auto",
        value_name = "AXIS",
        allow_hyphen_values = true
    )]
    pub up: Up,
    /// Embed the views of a 3DGS cameras.json (in the input's axes) as glTF perspective
    /// camera nodes named after img_name, turned with the scene (.glb/.gltf outputs), so
    /// `render OUT --gltf-camera all` shows the training views.
    #[arg(long, value_name = "cameras.json")]
    pub camera: Option<PathBuf>,
    /// SPZ version of a .spz output: 2 (gzip; what KHR_gaussian_splatting_compression_spz_2
    /// pins and most readers take), 3 (gzip, smallest-three quaternions) or 4 (zstd).
    #[arg(long, value_name = "2|3|4", value_parser = clap::value_parser!(u32).range(2..=4))]
    pub spz_version: Option<u32>,
    /// .glb output compressed as SPZ v2 in KHR_gaussian_splatting_compression_spz_2 (lossy:
    /// see docs/formats.md) instead of plain accessors.
    #[arg(long)]
    pub spz_compress: bool,
    /// Set colorSpace (a relabel for inputs that carry none, e.g. PLY; colours are unchanged).
    #[arg(long, value_name = "srgb_rec709_display|lin_rec709_display", value_parser = parse_color_space)]
    pub color_space: Option<ColorSpace>,
    /// Write only the splats whose mean lies in this box, in the input's coordinates (as
    /// `render IN --crop` draws them; both ends included; splat-transform's --filter-box order).
    #[arg(long, value_name = "minx,miny,minz,maxx,maxy,maxz", value_parser = splatgl::cull::CropBox::parse, allow_hyphen_values = true)]
    pub crop: Option<splatgl::cull::CropBox>,
    /// Tileset output: at most N splats per tile (leaves hold the original splats, coarser
    /// tiles their moment-matched merges). Default 65536.
    #[arg(long, value_name = "N")]
    pub chunk_splats: Option<usize>,
    /// Tileset output from a binary PLY too large for memory: read it in passes, never whole,
    /// sorting its splats into bucket files in DIR (removed as they are read).
    #[arg(long, value_name = "DIR")]
    pub scratch_dir: Option<PathBuf>,
    /// With --scratch-dir: about N splats per bucket, what is built in memory at once
    /// (default 2097152).
    #[arg(long, value_name = "N")]
    pub bucket_splats: Option<usize>,
    /// Overwrite OUT if it exists.
    #[arg(short, long)]
    pub force: bool,
    /// Print the matrix that takes the input's coordinates to the output's (for a tileset:
    /// to the tileset's z-up frame), so that a camera can be carried over (docs/lod.md).
    #[arg(short, long)]
    pub verbose: bool,
    #[command(flatten)]
    pub load: super::LoadArgs,
}

fn parse_color_space(s: &str) -> Result<ColorSpace, String> {
    match ColorSpace::parse(s) {
        splatgl::cloud::Known::Known(c) => Ok(c),
        _ => Err(format!(
            "expected srgb_rec709_display or lin_rec709_display, found {s:?}"
        )),
    }
}

/// Splats per progress step of the per-splat work.
const CHUNK: usize = 1 << 16;
/// Inputs at least this large show progress.
const LARGE: usize = 200_000;

/// Progress on stderr: a bar on a terminal, one line per stage otherwise.
pub(super) struct Progress {
    on: bool,
    tty: bool,
}

impl Progress {
    /// Progress that shows (when `on`) as a bar on a terminal, as stage lines otherwise.
    pub(super) fn new(on: bool) -> Self {
        Progress {
            on,
            tty: std::io::stderr().is_terminal(),
        }
    }
    pub(super) fn stage(&self, what: &str) {
        if self.on {
            eprintln!("splatgl convert: {what}");
        }
    }
    pub(super) fn bar(&self, what: &str, done: usize, total: usize) {
        if !(self.on && self.tty) {
            return;
        }
        let w = 30;
        let filled = (done * w).checked_div(total).unwrap_or(w);
        eprint!(
            "\r{what} [{}{}] {:>3}%",
            "#".repeat(filled),
            " ".repeat(w - filled),
            (done * 100).checked_div(total).unwrap_or(100)
        );
        if done == total {
            eprintln!();
        }
        let _ = std::io::stderr().flush();
    }
}

fn options(a: &Args) -> Result<ConvertOptions, String> {
    let mut q = Quantize::default();
    for spec in &a.quantize {
        q.set(spec)?;
    }
    let rotate_deg = [a.rotate_x, a.rotate_y, a.rotate_z];
    if !rotate_deg.iter().all(|d| d.is_finite()) {
        return Err("--rotate-x/-y/-z must be finite".into());
    }
    Ok(ConvertOptions {
        quantize: q,
        sh_degree: a.sh_degree,
        up: a.up,
        rotate_deg,
        color_space: a.color_space,
        spz_version: match a.spz_version {
            Some(v) => splatgl::write::SpzVersion::try_from(v)
                .map_err(|e| format!("--spz-version: {e}"))?,
            None => splatgl::write::SpzVersion::V2,
        },
        spz_compress: a.spz_compress,
    })
}

/// The splats inside `crop` (all without one); an error when none is.
fn crop(cloud: SplatCloud, crop: Option<splatgl::cull::CropBox>) -> Result<SplatCloud, String> {
    let Some(kept) = crop.and_then(|b| b.apply(&cloud)) else {
        return Ok(cloud);
    };
    if kept.is_empty() {
        return Err(format!(
            "--crop: none of the {} splats is inside the box",
            cloud.len()
        ));
    }
    eprintln!("--crop: kept {} of {} splats", kept.len(), cloud.len());
    Ok(kept)
}

/// Rotates by `r` in chunks (progress per chunk).
fn rotate(cloud: SplatCloud, r: glam::DMat3, p: &Progress) -> Result<SplatCloud, String> {
    if r == glam::DMat3::IDENTITY {
        return Ok(cloud);
    }
    let n = cloud.len();
    let mut out = SplatCloud::with_capacity(cloud.sh_degree, n);
    out.meta = cloud.meta.clone();
    for start in (0..n).step_by(CHUNK) {
        let part = convert::slice(&cloud, start..(start + CHUNK).min(n));
        out.append(convert::rotate(&part, r)?);
        p.bar("rotating", (start + CHUNK).min(n), n);
    }
    Ok(out)
}

/// Refuses an output that exists without --force, and one that is the input (same file by
/// any name) even with it.
pub(super) fn check_output(path: &Path, input: &Path, force: bool) -> Result<(), String> {
    splatgl::write::refuse_overwriting_inputs(path, &[input])
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if !force && path.exists() {
        return Err(format!(
            "{} exists; pass -f/--force to overwrite it",
            path.display()
        ));
    }
    Ok(())
}

/// Writes the file: checked again ([`check_output`]), then written atomically (a temporary
/// file in the same folder renamed into place, so a failed or interrupted write leaves the
/// previous file as it was).
pub(super) fn write_output(
    path: &Path,
    input: &Path,
    bytes: &[u8],
    force: bool,
) -> Result<(), String> {
    check_output(path, input, force)?;
    splatgl::write::write_bytes_atomic(path, &[input], bytes)
        .map_err(|e| format!("{}: {e}", path.display()))
}

fn go(a: &Args) -> Result<(), String> {
    let t0 = Instant::now();
    let tree = super::convert_lod::tree_output(&a.output);
    let tileset = tree.is_some();
    let (format, o) = output_and_options(a, tree)?;
    check_output(&a.output, &a.input, a.force)?;
    if let (true, Some(dir)) = (tileset, &a.scratch_dir) {
        return super::convert_lod::write_tileset_streamed(a, &o, dir, t0);
    }
    let limits = a.load.options().limits;
    let views = match &a.camera {
        Some(path) => splatgl::camera::load_cameras_json_limited(path, &limits)
            .map_err(|e| format!("--camera: {e}"))?,
        None => Vec::new(),
    };
    let scene = splatgl::load::load_path(&a.input, &a.load.options()).map_err(|e| e.to_string())?;
    a.load
        .common
        .check_applies(&a.input.display().to_string(), Some(scene.report.format))?;
    for w in scene.report.summarized_warnings() {
        eprintln!("warning: {w}");
    }
    let mut cloud = scene.cloud;
    let p = Progress {
        on: cloud.len() >= LARGE,
        tty: std::io::stderr().is_terminal(),
    };
    p.stage(&format!(
        "read {} splats in {:.1} s",
        cloud.len(),
        t0.elapsed().as_secs_f64()
    ));
    cloud = crop(cloud, a.crop)?;
    convert::relabel(&mut cloud, &o);
    let r = o.rotation_for(scene.report.format, &cloud, format);
    let mut cameras = Vec::with_capacity(views.len());
    for (i, e) in views.iter().enumerate() {
        let (node, note) = convert::camera_node(e, i, r)?;
        if let Some(n) = note {
            eprintln!("note: {n}");
        }
        cameras.push(node);
    }
    if a.verbose {
        eprintln!("{}", transform_note(r, tree));
    }
    let cloud = rotate(cloud, r, &p)?;
    if let Some(kind) = tree {
        return super::convert_lod::write_tree(a, kind, &cloud, &o, &p, t0);
    }
    p.stage("encoding");
    let (bytes, notes) = convert::encode_with_cameras(&cloud, format, &o, &cameras)?;
    for n in notes {
        eprintln!("note: {n}");
    }
    write_output(&a.output, &a.input, &bytes, a.force)?;
    eprintln!(
        "splatgl convert: {} splats, SH degree {} -> {} ({} bytes) in {:.1} s",
        cloud.len(),
        cloud.sh_degree,
        a.output.display(),
        bytes.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The output format OUT asks for and the conversion options, checked against each other
/// (an option that does not apply to that output is an error naming it).
fn output_and_options(
    a: &Args,
    tree: Option<TreeOutput>,
) -> Result<(OutputFormat, ConvertOptions), String> {
    let tileset = tree.is_some();
    let format = if let Some(kind) = tree {
        super::convert_lod::check_args(a)?;
        match kind {
            TreeOutput::Tiles3d => OutputFormat::Glb,
            TreeOutput::LodMeta if a.scratch_dir.is_some() => {
                return Err(format!(
                    "{}: a streamed SOG is built in memory; --scratch-dir builds 3D Tiles \
                     tilesets (e.g. out/tileset.json) only",
                    a.output.display()
                ));
            }
            TreeOutput::LodMeta => OutputFormat::Sog,
        }
    } else {
        OutputFormat::from_path(&a.output).ok_or_else(|| {
            let exts: Vec<&str> = convert::OUTPUTS.iter().map(|(e, _)| *e).collect();
            format!(
                "{}: output must end in .{}",
                a.output.display(),
                exts.join(", .")
            )
        })?
    };
    let o = options(a)?;
    if o.quantize.any() && (!format.is_gltf() || o.spz_compress) {
        return Err("--quantize applies to uncompressed .glb/.gltf outputs only".into());
    }
    if o.spz_compress && format != OutputFormat::Glb {
        return Err("--spz-compress applies to .glb outputs only".into());
    }
    if (a.chunk_splats.is_some() || a.scratch_dir.is_some()) && !tileset {
        return Err(
            "--chunk-splats and --scratch-dir apply to tileset outputs (OUT ending in .json) only"
                .into(),
        );
    }
    if a.spz_version.is_some() && format != OutputFormat::Spz {
        return Err("--spz-version applies to .spz outputs only".into());
    }
    if a.camera.is_some() && !format.is_gltf() {
        return Err("--camera applies to .glb/.gltf outputs only (camera nodes)".into());
    }
    Ok((format, o))
}

/// `-v`'s line: the matrix from the input's coordinates to the output's — the up-axis and
/// `--rotate-*` rotation `r`, and for a 3D Tiles tileset glTF's +Y turned to +Z after it.
pub(super) fn transform_note(r: glam::DMat3, tree: Option<TreeOutput>) -> String {
    let m = glam::DMat4::from_mat3(r);
    match tree {
        Some(TreeOutput::Tiles3d) => format!(
            "transform: input → tileset (z-up) {} (a camera at eye e in the input is at M·e in the tileset; its look and up vectors turn by M too)",
            super::tileset::matrix_text(splatgl::tiles::Y_UP_TO_Z_UP * m)
        ),
        _ => format!(
            "transform: input → output {} (a camera at eye e in the input is at M·e in the output)",
            super::tileset::matrix_text(m)
        ),
    }
}

/// Runs it. Exit status 0 on success, 2 on any error.
pub fn run(a: Args) -> ExitCode {
    super::exit_status(go(&a))
}
