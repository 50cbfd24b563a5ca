//! [`UpAxis`]: which world axis is up in a scene, and the rule `--up auto` follows.

use glam::Vec3;

use super::frame::points_box;
use crate::cloud::SplatCloud;
use crate::files::Format;

/// The world axis that is up in a scene: the orbit axis of the viewer, the default `up` of
/// `--look-at` and the up of automatic framing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UpAxis {
    /// +Y (glTF).
    Y,
    /// −Y (COLMAP / INRIA 3DGS training output, and the packed formats derived from it).
    NegY,
    /// +Z (CAD, robotics, many scanners).
    Z,
}

impl UpAxis {
    /// The rule for `--up auto`: glTF (`.gltf`, `.glb`) is +Y up by the glTF spec; every other
    /// format splatgl reads (INRIA and compressed PLY, and the packed formats) stores 3DGS
    /// training output in COLMAP axes, −Y up. The bundled default scene (`None`) is +Y up.
    pub fn for_format(format: Option<Format>) -> Self {
        match format {
            None | Some(Format::Gltf | Format::Glb) => UpAxis::Y,
            #[allow(unreachable_patterns)] // formats added later are COLMAP-axis packings
            Some(_) => UpAxis::NegY,
        }
    }

    /// The rule for `--up auto` with the cloud at hand: [`UpAxis::for_format`], except that
    /// a cloud of a non-glTF format that stands on the z = 0 plane and is clearly taller along
    /// +Z than wide is +Z up (robotics / photogrammetry exports such as the MuJoCo fox): over
    /// the drawable splats' centres (1st..99th percentile per axis), the z extent is at least
    /// [`Z_UP_TALLER`] × the x and the y extent, and at most [`Z_UP_BELOW`] of it lies below
    /// z = 0. COLMAP-axis training output (−Y up) is wide in x and z and spans both sides of
    /// z = 0, so it keeps −Y.
    pub fn for_cloud(format: Option<Format>, cloud: &SplatCloud) -> Self {
        let by_format = Self::for_format(format);
        if by_format != UpAxis::NegY {
            return by_format;
        }
        match centre_box(cloud) {
            Some((lo, hi)) => {
                let e = hi - lo;
                let tall = e.z > 0.0 && e.z >= Z_UP_TALLER * e.x.max(e.y);
                if tall && -lo.z <= Z_UP_BELOW * e.z {
                    UpAxis::Z
                } else {
                    by_format
                }
            }
            None => by_format,
        }
    }

    /// [`UpAxis::for_cloud`] and the rule that chose it, in words (what `info` prints).
    pub fn for_cloud_explained(format: Option<Format>, cloud: &SplatCloud) -> (Self, &'static str) {
        let up = Self::for_cloud(format, cloud);
        let why = match up {
            UpAxis::Y => "glTF: +Y up by the glTF specification",
            UpAxis::Z => "stands on z = 0 and is clearly taller along +Z than wide",
            UpAxis::NegY => "PLY and the packed formats: 3DGS training output in COLMAP axes",
        };
        (up, why)
    }

    /// The unit vector.
    pub fn vector(self) -> Vec3 {
        match self {
            UpAxis::Y => Vec3::Y,
            UpAxis::NegY => -Vec3::Y,
            UpAxis::Z => Vec3::Z,
        }
    }

    /// The command-line spelling: `y`, `-y` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            UpAxis::Y => "y",
            UpAxis::NegY => "-y",
            UpAxis::Z => "z",
        }
    }

    /// The next axis in the viewer's `U` cycle: +Y → −Y → +Z → +Y.
    pub fn next(self) -> Self {
        match self {
            UpAxis::Y => UpAxis::NegY,
            UpAxis::NegY => UpAxis::Z,
            UpAxis::Z => UpAxis::Y,
        }
    }

    /// The direction of the default view: from the "front" (+Z for ±Y up, −Y for +Z up),
    /// looking slightly down (a slope of 0.35 against the up axis). For +Y this is the
    /// historical `(0, −0.35, −1)`, for −Y `(0, 0.35, −1)`.
    pub fn default_forward(self) -> Vec3 {
        let front = match self {
            UpAxis::Y | UpAxis::NegY => Vec3::Z,
            UpAxis::Z => -Vec3::Y,
        };
        (-front - 0.35 * self.vector()).normalize()
    }
}

/// [`UpAxis::for_cloud`]: how much taller along z than along x and y a cloud must be to be
/// taken as +Z up.
pub const Z_UP_TALLER: f32 = 1.1;
/// [`UpAxis::for_cloud`]: the most of a +Z-up cloud's z extent that may lie below z = 0.
pub const Z_UP_BELOW: f32 = 0.05;

/// Per axis, the 1st and 99th percentile of the drawable splats' centres.
fn centre_box(cloud: &SplatCloud) -> Option<(Vec3, Vec3)> {
    let drawable = |(_, o): &(&[f32; 3], &f32)| **o >= crate::profile::ALPHA_MIN;
    points_box(
        cloud
            .positions
            .iter()
            .zip(&cloud.opacities)
            .filter(drawable)
            .map(|(p, _)| p),
    )
}
