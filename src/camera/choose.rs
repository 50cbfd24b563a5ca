//! [`ViewOptions`]: the camera options `splatgl render` and `splatgl view` share, and the one
//! function that turns them into a [`Camera`] for a scene.

use glam::Vec3;
use std::path::PathBuf;

use super::up::UpAxis;
use super::{Camera, CameraError, CamerasJsonEntry, GltfPerspective, load_cameras_json_limited};
use crate::cloud::SplatCloud;
use crate::files::{Format, Limits};

/// What a view is chosen for: the cloud, the format it was read from (`None`: the bundled
/// default scene) and the glTF camera nodes of its file.
#[derive(Debug, Clone, Copy)]
pub struct SceneView<'a> {
    /// The splats.
    pub cloud: &'a SplatCloud,
    /// The file's format; `None` for the bundled default scene.
    pub format: Option<Format>,
    /// The file's perspective camera nodes.
    pub cameras: &'a [GltfPerspective],
}

/// An explicit look-at: eye, target, and up (`None`: the scene's [`UpAxis`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LookAtSpec {
    /// Eye.
    pub eye: Vec3,
    /// Target.
    pub target: Vec3,
    /// Up; `None` = the scene's up axis (`--up`, or its per-format default).
    pub up: Option<Vec3>,
}

/// The camera options of `splatgl render` / `splatgl view`. At most one of `cameras_json`,
/// `gltf_camera` and `look_at` is used, in that priority; with none, the bundled default
/// scene has its own camera and every file is framed ([`Camera::frame_cloud`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ViewOptions {
    /// A 3DGS `cameras.json` to take the view from (`--camera`).
    pub cameras_json: Option<PathBuf>,
    /// Which entry of it (`--view`, 0-based).
    pub view: usize,
    /// The N-th glTF camera node of the scene (`--gltf-camera`).
    pub gltf_camera: Option<usize>,
    /// A look-at (`--look-at`).
    pub look_at: Option<LookAtSpec>,
    /// Vertical field of view in degrees for look-at and framing (`--fov`).
    pub fov_deg: f32,
    /// Up axis (`--up`); `None` = auto ([`UpAxis::for_cloud`]).
    pub up: Option<UpAxis>,
    /// Image width (`--width`).
    pub width: Option<u32>,
    /// Image height (`--height`).
    pub height: Option<u32>,
    /// What `cameras_json` is read under (`max_bytes`, `max_json_depth`; the scene's limits).
    pub limits: Limits,
}

impl Default for ViewOptions {
    fn default() -> Self {
        ViewOptions {
            cameras_json: None,
            view: 0,
            gltf_camera: None,
            look_at: None,
            fov_deg: 50.0,
            up: None,
            width: None,
            height: None,
            limits: Limits::default(),
        }
    }
}

fn unavailable(message: String) -> CameraError {
    CameraError::Unavailable(message)
}

impl ViewOptions {
    /// The up axis for a scene of `format`: `up`, or the per-format rule.
    pub fn up_for(&self, format: Option<Format>) -> UpAxis {
        self.up.unwrap_or_else(|| UpAxis::for_format(format))
    }

    /// The up axis for `scene`: `up`, or the per-cloud rule ([`UpAxis::for_cloud`]).
    pub fn up_for_scene(&self, scene: SceneView<'_>) -> UpAxis {
        self.up
            .unwrap_or_else(|| UpAxis::for_cloud(scene.format, scene.cloud))
    }

    /// The image size: `width`/`height`, a missing one derived from `(w, h)`'s aspect ratio.
    pub fn size_or(&self, w: u32, h: u32) -> (u32, u32) {
        let derive = |a: u32, b: u32, c: u32| (a as u64 * b as u64 + c as u64 / 2) / c as u64;
        match (self.width, self.height) {
            (Some(x), Some(y)) => (x, y),
            (Some(x), None) => (x, derive(x, h, w).clamp(1, 16384) as u32),
            (None, Some(y)) => (derive(y, w, h).clamp(1, 16384) as u32, y),
            (None, None) => (w, h),
        }
    }

    /// The entries of `cameras_json` (empty without one).
    pub fn cameras_json_entries(&self) -> Result<Vec<CamerasJsonEntry>, CameraError> {
        match &self.cameras_json {
            Some(path) => load_cameras_json_limited(path, &self.limits),
            None => Ok(Vec::new()),
        }
    }

    /// The distance from `cam`'s eye to its focus (the viewer's orbit pivot, and the target of
    /// a printed `--look-at`): the --look-at target's distance, else the depth of the content's
    /// centre (of its [`FIT_SIGMAS`](super::FIT_SIGMAS) [`Extent`](super::Extent), which default
    /// views look at; [`Camera::focus_distance_to`]), else 1.
    pub fn focus_distance(&self, cam: &Camera, cloud: &SplatCloud) -> f32 {
        self.focus_distance_in(cam, self.focus_extent(cloud).as_ref())
    }

    /// The content's extent [`ViewOptions::focus_distance_in`] measures against (`None` with
    /// a --look-at, which gives its own target, or without drawable splats): computed once
    /// for a batch of views.
    pub fn focus_extent(&self, cloud: &SplatCloud) -> Option<super::Extent> {
        match self.look_at {
            Some(_) => None,
            None => super::Extent::of_cloud_at(cloud, super::FIT_SIGMAS),
        }
    }

    /// [`ViewOptions::focus_distance`] with the extent given (from
    /// [`ViewOptions::focus_extent`]).
    pub fn focus_distance_in(&self, cam: &Camera, extent: Option<&super::Extent>) -> f32 {
        if let Some(l) = &self.look_at {
            return (l.target - l.eye).length();
        }
        extent.map_or(1.0, |e| cam.focus_distance_to(e.centre()))
    }

    /// The camera of one cameras.json entry, resized by the options' --width / --height.
    pub fn camera_for_entry(&self, e: &CamerasJsonEntry) -> Result<Camera, CameraError> {
        let cam = Camera::from_3dgs(e)?;
        let (w, h) = self.size_or(cam.width, cam.height);
        cam.resized(w, h).validated()
    }

    /// The view for `scene`. `default_size` is the image size when neither the options nor
    /// the view's source (a cameras.json entry, a glTF camera's aspect ratio) give one.
    pub fn camera(
        &self,
        scene: SceneView<'_>,
        default_size: (u32, u32),
    ) -> Result<Camera, CameraError> {
        let fov = self.fov_deg.to_radians();
        if !(fov > 0.0 && fov < std::f32::consts::PI) {
            return Err(unavailable(format!(
                "--fov {} must be in (0, 180)",
                self.fov_deg
            )));
        }
        if let Some(path) = &self.cameras_json {
            let list = load_cameras_json_limited(path, &self.limits)?;
            let e = list.get(self.view).ok_or_else(|| {
                unavailable(format!(
                    "--view {}: {} has {} views",
                    self.view,
                    path.display(),
                    list.len()
                ))
            })?;
            return self.camera_for_entry(e);
        }
        if let Some(n) = self.gltf_camera {
            if !matches!(scene.format, Some(Format::Gltf | Format::Glb)) {
                return Err(unavailable(
                    "--gltf-camera needs a .gltf or .glb scene".into(),
                ));
            }
            let g = scene.cameras.get(n).ok_or_else(|| {
                unavailable(format!(
                    "--gltf-camera {n}: the scene has {} perspective camera node(s)",
                    scene.cameras.len()
                ))
            })?;
            // Keep the camera's aspect ratio when no size is given.
            let h = self.height.unwrap_or(default_size.1);
            let w = self.width.unwrap_or_else(|| {
                g.aspect_ratio.map_or(default_size.0, |r| {
                    ((h as f32 * r).round() as u32).clamp(1, 16384)
                })
            });
            return Camera::from_gltf(g, w, h);
        }
        let (w, h) = self.size_or(default_size.0, default_size.1);
        let up = self.up_for_scene(scene);
        if let Some(l) = &self.look_at {
            let up = l.up.unwrap_or(up.vector());
            let fwd = l.target - l.eye;
            // `!(… > …)` also refuses NaN: finite points far apart overflow `fwd` to inf.
            let side = fwd.cross(up).length();
            if !(fwd.is_finite() && fwd.length() > 0.0 && side > 1e-6 * fwd.length() * up.length())
            {
                return Err(unavailable(
                    "--look-at: eye = target, up parallel to the view direction, or points too far apart for f32".into(),
                ));
            }
            return Camera::look_at(l.eye, l.target, up, fov, w, h).validated();
        }
        if scene.format.is_none() && self.up.is_none() {
            return Ok(Camera::default_scene_view(w, h));
        }
        Camera::frame_cloud(scene.cloud, up, fov, w, h)
            .ok_or_else(|| {
                unavailable(
                    "the scene has no splat that can be drawn to frame; give --look-at".into(),
                )
            })?
            .validated()
            .map_err(|_| {
                unavailable(
                    "the scene's extent is too large to frame in f32 (positions near ±3.4e38); give --look-at".into(),
                )
            })
    }
}
