//! Default views: which world axis is up ([`UpAxis`]), the extent of a cloud's content
//! ([`Extent`], from each splat's 3σ box) and a camera that frames it ([`Camera::frame_cloud`]),
//! and the way back from a camera to a `--look-at` line ([`LookAt`]).

use glam::{Mat3, Quat, Vec3};

use super::Camera;
use super::up::UpAxis;
use crate::cloud::SplatCloud;

/// [`Camera::frame_extent_along`]: the fraction of the image's width and height left free on
/// each side of the framed box.
pub const FRAME_MARGIN: f32 = 0.04;

/// [`Camera::frame_cloud`]: the width, in standard deviations, of the splat boxes a default
/// view fits to the image (the eye stays outside the 3σ ones).
pub const FIT_SIGMAS: f32 = 2.0;

/// Per axis, the 1st and 99th percentile of the finite ones of `points` (`None` without
/// any): the box framing takes, robust to a few stray points on each side.
pub(crate) fn points_box<'a>(points: impl Iterator<Item = &'a [f32; 3]>) -> Option<(Vec3, Vec3)> {
    let mut axes: [Vec<f32>; 3] = Default::default();
    for p in points.filter(|p| p.iter().all(|v| v.is_finite())) {
        for (a, v) in axes.iter_mut().zip(p) {
            a.push(*v);
        }
    }
    if axes[0].is_empty() {
        return None;
    }
    Some((corner(&mut axes, false), corner(&mut axes, true)))
}

/// Per axis, the [`percentile`] of the non-empty `axes`: a box's lower (`upper = false`) or
/// upper corner.
fn corner(axes: &mut [Vec<f32>; 3], upper: bool) -> Vec3 {
    let [x, y, z] = axes;
    Vec3::new(
        percentile(x, upper),
        percentile(y, upper),
        percentile(z, upper),
    )
}

/// The 1st (`upper = false`) or the 99th percentile (`upper`) of the non-empty `v`, as
/// framing takes them (index `(n − 1) / 100` from either end).
fn percentile(v: &mut [f32], upper: bool) -> f32 {
    let n = v.len();
    let i = if upper {
        n - 1 - (n - 1) / 100
    } else {
        (n - 1) / 100
    };
    *v.select_nth_unstable_by(i, f32::total_cmp).1
}

/// The box a default view frames: per axis, the 1st percentile of the splats' 3σ box minima
/// and the 99th percentile of their maxima, over the splats that can be drawn (finite position
/// and scale, opacity ≥ [`ALPHA_MIN`](crate::profile::ALPHA_MIN)). The 3σ box of a splat is
/// the axis-aligned box of its ellipsoid at three standard deviations (the profile's cut-off),
/// half-extent `3·sqrt(Σ_j (R_kj s_j)²)` on axis k. Percentiles keep a few stray splats (1 %
/// on each side) from shrinking the view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// Lower corner.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
}

impl Extent {
    /// The extent of `cloud`'s content; `None` when no splat can be drawn.
    pub fn of_cloud(cloud: &SplatCloud) -> Option<Self> {
        Self::of_cloud_at(cloud, crate::profile::CUTOFF_M2.sqrt()) // 3σ
    }

    /// The box of points (their 1st..99th percentile per axis, non-finite ones ignored), for
    /// framing points that are not splats; `None` without a finite point.
    pub fn of_points(points: &[[f32; 3]]) -> Option<Self> {
        let (lo, hi) = points_box(points.iter())?;
        Some(Extent { lo, hi })
    }

    /// [`Extent::of_cloud`] with boxes `k` standard deviations wide instead of 3
    /// ([`FIT_SIGMAS`] for the part of the content a default view fits to the image).
    pub fn of_cloud_at(cloud: &SplatCloud, k: f32) -> Option<Self> {
        let mut lo: [Vec<f32>; 3] = Default::default();
        let mut hi: [Vec<f32>; 3] = Default::default();
        for i in 0..cloud.len() {
            let (p, s) = (cloud.positions[i], cloud.scales[i]);
            let q = cloud.rotations[i];
            let drawable = cloud.opacities[i] >= crate::profile::ALPHA_MIN;
            if !drawable || !p.iter().chain(&s).chain(&q).all(|v| v.is_finite()) {
                continue;
            }
            let r = Mat3::from_quat(Quat::from_array(q).normalize());
            let m = Mat3::from_cols(r.x_axis * s[0], r.y_axis * s[1], r.z_axis * s[2]);
            // Half-extent on world axis a: k · |row a of R diag(s)|.
            let rows = m.transpose();
            for (a, row) in [rows.x_axis, rows.y_axis, rows.z_axis].iter().enumerate() {
                let h = k * row.length();
                lo[a].push(p[a] - h);
                hi[a].push(p[a] + h);
            }
        }
        if lo[0].is_empty() {
            return None;
        }
        let (lo, hi) = (corner(&mut lo, false), corner(&mut hi, true));
        // Percentiles taken per side can cross for a near-degenerate axis: keep lo ≤ hi.
        Some(Extent {
            lo: lo.min(hi),
            hi: lo.max(hi),
        })
    }

    /// Centre of the box.
    pub fn centre(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// Radius of the box's bounding sphere (half its diagonal).
    pub fn radius(&self) -> f32 {
        0.5 * (self.hi - self.lo).length()
    }
}

impl Camera {
    /// The default view of a cloud: looking along [`UpAxis::default_forward`] with `up` up,
    /// at the centre of its [`FIT_SIGMAS`] extent, as close as keeps that box in the image
    /// and the eye outside the 3σ [`Extent`] ([`Camera::frame_boxes_along`]). A splat's
    /// 2σ ellipsoid is where an opaque one is still at alpha e⁻² ≈ 0.14: fitting the 3σ box
    /// instead would leave a lone splat a small blob in a wide dark frame. `None` when no
    /// splat can be drawn.
    pub fn frame_cloud(
        cloud: &SplatCloud,
        up: UpAxis,
        fov_y: f32,
        width: u32,
        height: u32,
    ) -> Option<Self> {
        let outside = Extent::of_cloud(cloud)?;
        let fit = Extent::of_cloud_at(cloud, FIT_SIGMAS)?;
        let (fwd, up) = (up.default_forward(), up.vector());
        Self::frame_boxes_along(&fit, &outside, fwd, up, fov_y, width, height)
    }

    /// A camera looking along `forward` (`up` roughly up) at the centre of `extent`, as close
    /// as keeps every corner of the box inside the image with a [`FRAME_MARGIN`] margin on each
    /// side and every corner in front of the eye (so the eye is outside the box), at least
    /// 1.5 × the near cull ([`NEAR_CULL`](crate::profile::NEAR_CULL)) ahead of the nearest
    /// one, so tiny content is not culled. An extent without size (coincident points of zero
    /// scale) is framed as a unit sphere. `None` when `forward ∥ up`.
    pub fn frame_extent_along(
        extent: &Extent,
        forward: Vec3,
        up: Vec3,
        fov_y: f32,
        width: u32,
        height: u32,
    ) -> Option<Self> {
        Self::frame_boxes_along(extent, extent, forward, up, fov_y, width, height)
    }

    /// [`Camera::frame_extent_along`] fitting `fit` to the image while keeping the eye outside
    /// `outside` (every corner of both in front of the eye).
    pub fn frame_boxes_along(
        fit: &Extent,
        outside: &Extent,
        forward: Vec3,
        up: Vec3,
        fov_y: f32,
        width: u32,
        height: u32,
    ) -> Option<Self> {
        if forward.cross(up).length_squared() <= 1e-12 {
            return None;
        }
        let centre = fit.centre();
        let f = forward.normalize();
        let right = f.cross(up).normalize();
        let image_up = right.cross(f);
        let sized = |e: &Extent| e.radius() > 1e-6;
        let half = if sized(fit) {
            0.5 * (fit.hi - fit.lo)
        } else {
            Vec3::splat(1.0 / 3f32.sqrt()) // a unit sphere's box, as far as framing goes
        };
        let tan_y = (0.5 * fov_y).tan() * (1.0 - 2.0 * FRAME_MARGIN);
        let tan_x = tan_y * width as f32 / height.max(1) as f32;
        let near = 1.5 * crate::profile::NEAR_CULL as f32;
        // A corner at (x, y, z) in the camera's axes, seen from `d` behind the centre, is in
        // the image when |x| ≤ tan_x (d + z) and |y| ≤ tan_y (d + z); in front when d + z > near.
        let mut dist = 0.0f32;
        for i in 0..8 {
            let s = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            let c = s * half;
            let (x, y, z) = (c.dot(right), c.dot(image_up), c.dot(f));
            dist = dist
                .max(x.abs() / tan_x - z)
                .max(y.abs() / tan_y - z)
                .max(near - z);
            if sized(outside) {
                let o = outside.centre() - centre + s * 0.5 * (outside.hi - outside.lo);
                dist = dist.max(near - o.dot(f));
            }
        }
        let eye = centre - f * dist;
        let mut cam = Self::look_at(eye, centre, up, fov_y, width, height);
        let reach = half
            .length()
            .max((outside.centre() - centre).length() + outside.radius());
        cam.far = (dist + 2.0 * reach).max(cam.far);
        Some(cam)
    }

    /// The distance to focus on `point`: its depth along the view axis, or (when it is not in
    /// front of the camera) its distance, at least 1. The viewer's pivot distance and the
    /// target distance of a printed `--look-at`.
    pub fn focus_distance_to(&self, point: Vec3) -> f32 {
        let z = self.to_camera(point).z;
        if z > 1e-3 {
            z
        } else {
            (point - self.eye()).length().max(1.0)
        }
    }

    /// This camera as `--look-at` values: its eye, the point `distance` in front of it on the
    /// optical axis as target, its image "up" (−y of the OpenCV axes) and its vertical field of
    /// view. See [`LookAt`] for when this is exact.
    pub fn as_look_at(&self, distance: f32) -> LookAt {
        let inv = self.world_to_camera.inverse();
        let eye = inv.w_axis.truncate();
        let forward = inv.z_axis.truncate().normalize();
        let up = -inv.y_axis.truncate().normalize();
        let fov_y_deg = (2.0 * (0.5 * self.height as f32 / self.fy).atan()).to_degrees();
        let rel = |a: f32, b: f32| (a - b).abs() <= 1e-4 * b.abs().max(1.0);
        LookAt {
            eye,
            target: eye + forward * distance.max(1e-3),
            up,
            fov_y_deg,
            width: self.width,
            height: self.height,
            exact: rel(self.fx, self.fy)
                && rel(self.cx, 0.5 * self.width as f32)
                && rel(self.cy, 0.5 * self.height as f32),
        }
    }
}

/// A camera written as the `--look-at … --fov … --width … --height …` options of
/// `splatgl render` / `splatgl view` (its `Display`). `exact` is false when the camera has
/// `fx ≠ fy` or an off-centre principal point, which a look-at cannot express: the line then
/// gives the same pose and vertical field of view only (a `cameras.json` entry is exact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LookAt {
    /// Eye.
    pub eye: Vec3,
    /// Target.
    pub target: Vec3,
    /// Up (perpendicular to the view direction).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Whether `Camera::look_at` of these values gives back the same intrinsics.
    pub exact: bool,
}

impl std::fmt::Display for LookAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |v: Vec3| format!("{},{},{}", v.x, v.y, v.z);
        write!(
            f,
            "--look-at {},{},{} --fov {} --width {} --height {}",
            v(self.eye),
            v(self.target),
            v(self.up),
            self.fov_y_deg,
            self.width,
            self.height
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_line_rebuilds_the_camera() {
        let cam = Camera::look_at(
            Vec3::new(1.0, -2.0, 3.5),
            Vec3::new(0.1, 0.2, -0.3),
            Vec3::new(0.0, -1.0, 0.2),
            0.8,
            320,
            200,
        );
        let l = cam.as_look_at(2.0);
        assert!(l.exact);
        let back = Camera::look_at(
            l.eye,
            l.target,
            l.up,
            l.fov_y_deg.to_radians(),
            l.width,
            l.height,
        );
        let d = (back.world_to_camera - cam.world_to_camera)
            .abs()
            .to_cols_array();
        assert!(d.iter().all(|e| *e < 1e-5), "{d:?}");
        assert!((back.fy - cam.fy).abs() < 1e-3 * cam.fy);
    }

    #[test]
    fn default_forward_is_the_historical_one_for_y_and_minus_y() {
        let y = UpAxis::Y.default_forward();
        let ny = UpAxis::NegY.default_forward();
        assert!((y - Vec3::new(0.0, -0.35, -1.0).normalize()).length() < 1e-6);
        assert!((ny - Vec3::new(0.0, 0.35, -1.0).normalize()).length() < 1e-6);
        assert!(UpAxis::Z.default_forward().dot(Vec3::Z) < 0.0);
    }
}
