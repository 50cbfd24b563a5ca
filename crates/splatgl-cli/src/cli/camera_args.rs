//! The camera options of `render` and `view` (one clap group, flattened into both) and the way
//! the chosen camera is printed.

use glam::Vec3;
use splatgl::camera::{Camera, LookAtSpec, UpAxis, ViewOptions};

/// `--up`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpArg {
    /// +Y up (glTF).
    Y,
    /// −Y up (COLMAP / INRIA training output).
    #[value(name = "-y")]
    NegY,
    /// +Z up.
    Z,
    /// From the format: glTF +Y; PLY and the packed formats (COLMAP axes) −Y, but +Z for a
    /// cloud standing on z = 0 that is clearly taller along +Z than wide; the bundled default
    /// scene +Y.
    Auto,
}

/// `--view` / `--gltf-camera`: one index, or `all` (render only: one image each).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pick {
    /// The N-th (0-based).
    Index(usize),
    /// Every one, in list order.
    All,
}

impl Pick {
    /// The index, `0` for `all` (the first view).
    pub fn first(self) -> usize {
        match self {
            Pick::Index(i) => i,
            Pick::All => 0,
        }
    }
}

fn parse_pick(s: &str) -> Result<Pick, String> {
    if s == "all" {
        return Ok(Pick::All);
    }
    s.parse()
        .map(Pick::Index)
        .map_err(|_| format!("expected a 0-based index or `all`, found {s:?}"))
}

/// `--fov`: degrees in (0, 180).
fn parse_fov(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v < 180.0 => Ok(v),
        Ok(v) => Err(format!("{v} is outside (0, 180) degrees")),
        Err(_) => Err(format!("expected degrees in (0, 180), found {s:?}")),
    }
}

/// Camera options.
#[derive(clap::Args, Debug, Clone)]
pub struct CameraArgs {
    /// 3DGS cameras.json to take the view from (see --view).
    #[arg(long, value_name = "cameras.json", conflicts_with_all = ["look_at", "gltf_camera"])]
    pub camera: Option<std::path::PathBuf>,
    /// Index (0-based, list order) of the view in --camera (default 0); `all` (render):
    /// one image per view.
    #[arg(long, value_name = "N|all", requires = "camera", value_parser = parse_pick)]
    pub view: Option<Pick>,
    /// Look-at camera: eye, target and optionally up (default: the --up axis).
    #[arg(
        long,
        value_name = "ex,ey,ez,tx,ty,tz[,ux,uy,uz]",
        allow_hyphen_values = true
    )]
    #[arg(conflicts_with = "gltf_camera")]
    pub look_at: Option<String>,
    /// Use the N-th glTF camera node of the scene; `all` (render): one image per camera node.
    ///
    /// Without any camera option the view frames the scene's content (the splats' 3σ boxes)
    /// from the front, slightly from above, with the --up axis up; the default scene has its
    /// own camera.
    #[arg(long, value_name = "N|all", value_parser = parse_pick)]
    pub gltf_camera: Option<Pick>,
    /// Which world axis is up, for framing and --look-at's default up.
    #[arg(long, value_enum, default_value_t = UpArg::Auto, allow_hyphen_values = true)]
    pub up: UpArg,
    /// Image width (default 640 for render, 1280 for view; or the cameras.json view's, scaled).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: Option<u32>,
    /// Image height (default 480 for render, 720 for view; or the cameras.json view's, scaled).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: Option<u32>,
    /// Vertical field of view in degrees, in (0, 180) (look-at and automatic framing;
    /// default 50).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true, value_parser = parse_fov)]
    pub fov: Option<f32>,
    /// Also print the camera as a 3DGS cameras.json (one entry) on stdout; for a render batch,
    /// one cameras.json with an entry per image (id = index, img_name = the file's stem).
    #[arg(long)]
    pub print_camera_json: bool,
}

/// `--background r,g,b`: three display values in [0, 1].
pub fn background(s: &str) -> Result<[f32; 3], String> {
    let v = floats(s, "--background", &[3])?;
    if let Some(x) = v.iter().find(|x| !(0.0..=1.0).contains(*x)) {
        return Err(format!(
            "--background {s}: {x} is outside [0, 1] (display values)"
        ));
    }
    Ok([v[0], v[1], v[2]])
}

/// Comma-separated finite floats, `counts` of them.
pub fn floats(s: &str, what: &str, counts: &[usize]) -> Result<Vec<f32>, String> {
    let v: Result<Vec<f32>, _> = s.split(',').map(|t| t.trim().parse::<f32>()).collect();
    match v {
        Ok(v) if counts.contains(&v.len()) && v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(format!(
            "{what}: expected {} comma-separated finite numbers, got {s:?}",
            counts
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(" or ")
        )),
    }
}

impl CameraArgs {
    /// The library's options (parses --look-at).
    pub fn options(&self) -> Result<ViewOptions, String> {
        let look_at = match &self.look_at {
            Some(s) => {
                let v = floats(s, "--look-at", &[6, 9])?;
                Some(LookAtSpec {
                    eye: Vec3::new(v[0], v[1], v[2]),
                    target: Vec3::new(v[3], v[4], v[5]),
                    up: (v.len() == 9).then(|| Vec3::new(v[6], v[7], v[8])),
                })
            }
            None => None,
        };
        Ok(ViewOptions {
            cameras_json: self.camera.clone(),
            view: self.view.map_or(0, Pick::first),
            gltf_camera: self.gltf_camera.map(Pick::first),
            look_at,
            fov_deg: self.fov.unwrap_or(50.0),
            up: match self.up {
                UpArg::Y => Some(UpAxis::Y),
                UpArg::NegY => Some(UpAxis::NegY),
                UpArg::Z => Some(UpAxis::Z),
                UpArg::Auto => None,
            },
            width: self.width,
            height: self.height,
            limits: Default::default(),
        })
    }
}

/// The camera as a paste-able option line (`--look-at … --fov … --width … --height …`), with
/// the target at `distance` in front of the eye; notes when a look-at cannot express it.
pub fn look_at_line(cam: &Camera, distance: f32) -> String {
    let l = cam.as_look_at(distance);
    if l.exact {
        l.to_string()
    } else {
        format!(
            "{l}  (approximate: fx ≠ fy or off-centre principal point; --print-camera-json is exact)"
        )
    }
}

/// The camera as a one-entry 3DGS cameras.json (one line).
pub fn camera_json_line(cam: &Camera) -> String {
    serde_json::Value::Array(vec![cam.to_3dgs_json(0, "splatgl")]).to_string()
}
