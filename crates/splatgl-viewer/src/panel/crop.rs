//! The crop box on screen: its twelve edges (clipped at the near plane) over the splats, and
//! six face handles, one at the centre of each face, that drag their face along its axis.
//!
//! Geometry is in the render image's pixels (the camera's); `px_to_points` converts to the
//! interface's points (÷ `--resolution-scale` ÷ the window's scale factor).

use egui::{Color32, Pos2, Rect, Sense, Stroke, Ui};
use glam::{Vec2, Vec3};

use splatgl::camera::Camera;
use splatgl::cull::CropBox;

/// Corner `i` (bit 0: x, bit 1: y, bit 2: z; 0 = min, 1 = max).
pub fn corner(b: &CropBox, i: usize) -> Vec3 {
    let pick = |a: usize| if i >> a & 1 == 0 { b.min[a] } else { b.max[a] };
    Vec3::new(pick(0), pick(1), pick(2))
}

/// The twelve edges as corner pairs: corners that differ in one bit.
pub fn edges() -> impl Iterator<Item = (usize, usize)> {
    (0..8usize).flat_map(|i| {
        (0..3)
            .map(move |a| (i, i | 1 << a))
            .filter(move |&(i, j)| i != j)
    })
}

/// The segment `a`–`b` (world) in `cam`'s image pixels, clipped to the part in front of the
/// near plane; `None` when all of it is behind.
pub fn project_segment(cam: &Camera, a: Vec3, b: Vec3) -> Option<(Vec2, Vec2)> {
    let near = cam.near.max(1e-6);
    let (mut ca, mut cb) = (cam.to_camera(a), cam.to_camera(b));
    if ca.z < near && cb.z < near {
        return None;
    }
    if ca.z < near {
        ca = ca + (cb - ca) * ((near - ca.z) / (cb.z - ca.z));
    } else if cb.z < near {
        cb = cb + (ca - cb) * ((near - cb.z) / (ca.z - cb.z));
    }
    let px = |c: Vec3| Vec2::new(cam.fx * c.x / c.z + cam.cx, cam.fy * c.y / c.z + cam.cy);
    Some((px(ca), px(cb)))
}

/// The centre of face `f` (axis `f / 2`; `f % 2`: 0 the min face, 1 the max face).
pub fn face_centre(b: &CropBox, f: usize) -> Vec3 {
    let (axis, side) = (f / 2, f % 2);
    let mut c = (Vec3::from_array(b.min) + Vec3::from_array(b.max)) * 0.5;
    c[axis] = if side == 0 { b.min[axis] } else { b.max[axis] };
    c
}

/// How far along world axis `axis` a drag of `delta` image pixels moves a point at `at`: the
/// drag's component along the axis's direction on screen, over the axis's pixels per world
/// unit there. `None` when the axis points (nearly) at the camera or `at` is behind it.
pub fn drag_along_axis(cam: &Camera, at: Vec3, axis: usize, delta: Vec2) -> Option<f32> {
    let depth = cam.to_camera(at).z;
    if depth <= cam.near {
        return None;
    }
    let h = 1e-3 * depth;
    let mut tip = at;
    tip[axis] += h;
    let (p0, p1) = project_segment(cam, at, tip)?;
    let per_unit = (p1 - p0) / h; // pixels per world unit along the axis
    let len2 = per_unit.length_squared();
    (len2 > 1e-6 && len2.is_finite()).then(|| delta.dot(per_unit) / len2)
}

/// Moves face `f` by `d` world units along its axis, never past the opposite face.
pub fn move_face(b: &mut CropBox, f: usize, d: f32) {
    let axis = f / 2;
    if !d.is_finite() {
        return;
    }
    if f.is_multiple_of(2) {
        b.min[axis] = (b.min[axis] + d).min(b.max[axis]);
    } else {
        b.max[axis] = (b.max[axis] + d).max(b.min[axis]);
    }
}

/// What the overlay did this frame.
#[derive(Debug, Clone, Copy, Default)]
pub struct Overlay {
    /// A face was dragged: the box changed.
    pub changed: bool,
    /// Where each face's handle is (points), when in front of the camera.
    pub handles: [Option<Pos2>; 6],
}

const EDGE: Color32 = Color32::from_rgb(255, 196, 40);
const HANDLE: Color32 = Color32::from_rgb(255, 140, 0);
/// Handle radius, points.
const RADIUS: f32 = 6.0;

/// The area of a handle centred at `centre` (points) that grabs it.
pub fn handle_rect(centre: Pos2) -> Rect {
    Rect::from_center_size(centre, egui::vec2(2.5 * RADIUS, 2.5 * RADIUS))
}

/// Draws `crop` seen by `cam` on `ui`, clipped to `area` (the window outside the panel), and
/// lets its face handles there be dragged.
pub fn show(
    ui: &mut Ui,
    area: Rect,
    cam: &Camera,
    px_to_points: f32,
    crop: &mut CropBox,
) -> Overlay {
    let pt = |p: Vec2| Pos2::new(p.x * px_to_points, p.y * px_to_points);
    let painter = ui.painter().with_clip_rect(area);
    for (i, j) in edges() {
        if let Some((a, b)) = project_segment(cam, corner(crop, i), corner(crop, j)) {
            painter.line_segment([pt(a), pt(b)], Stroke::new(1.5, EDGE));
        }
    }
    let mut out = Overlay::default();
    for f in 0..6 {
        let c = face_centre(crop, f);
        let Some((p, _)) = cam.project(c) else {
            continue;
        };
        let centre = pt(p);
        if !area.contains(centre) {
            continue;
        }
        out.handles[f] = Some(centre);
        let rect = handle_rect(centre);
        let resp = ui.interact(
            rect,
            egui::Id::unique(("splatgl-crop-face", f)),
            Sense::drag(),
        );
        let active = resp.hovered() || resp.dragged();
        let fill = if active { Color32::WHITE } else { HANDLE };
        painter.circle(centre, RADIUS, fill, Stroke::new(1.0, Color32::BLACK));
        let drag = resp.drag_delta();
        if drag != egui::Vec2::ZERO {
            let delta = Vec2::new(drag.x, drag.y) / px_to_points;
            if let Some(d) = drag_along_axis(cam, c, f / 2, delta) {
                move_face(crop, f, d);
                out.changed = true;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> CropBox {
        CropBox {
            min: [-1.0; 3],
            max: [1.0; 3],
        }
    }

    #[test]
    fn a_box_has_twelve_edges_along_one_axis_each() {
        let e: Vec<_> = edges().collect();
        assert_eq!(e.len(), 12);
        for (i, j) in e {
            assert_eq!((i ^ j).count_ones(), 1);
        }
    }

    #[test]
    fn segments_behind_the_camera_are_clipped_at_the_near_plane() {
        let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, -Vec3::Y, 1.0, 100, 100);
        // Wholly behind: nothing.
        assert!(
            project_segment(&cam, Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -2.0)).is_none()
        );
        // Crossing: the behind end moves to the near plane, the front end projects as usual.
        let (a, b) = project_segment(&cam, Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 2.0))
            .expect("in front in part");
        assert!(a.is_finite() && b.is_finite());
        assert_eq!(b, cam.project(Vec3::new(0.0, 0.0, 2.0)).unwrap().0);
    }

    /// Dragging a face handle by the screen length of one world unit along its axis moves the
    /// face by one unit; dragging across the axis moves nothing; a face never passes the
    /// opposite one.
    #[test]
    fn face_drags_follow_the_axis_on_screen() {
        let cam = Camera::look_at(
            Vec3::new(0.0, 0.0, -10.0),
            Vec3::ZERO,
            -Vec3::Y,
            0.8,
            640,
            480,
        );
        let mut b = unit_box();
        let c = face_centre(&b, 1); // +x face
        let (p0, _) = cam.project(c).unwrap();
        let (p1, _) = cam.project(c + Vec3::X).unwrap();
        let along = p1 - p0;
        let d = drag_along_axis(&cam, c, 0, along).unwrap();
        assert!((d - 1.0).abs() < 0.02, "{d}");
        let across = Vec2::new(-along.y, along.x);
        assert!(drag_along_axis(&cam, c, 0, across).unwrap().abs() < 1e-3);
        // The z axis points at this camera: no drag along it.
        assert!(drag_along_axis(&cam, face_centre(&b, 5), 2, along).is_none());
        move_face(&mut b, 1, -5.0);
        assert_eq!(b.max[0], b.min[0]);
        move_face(&mut b, 0, f32::NAN);
        assert_eq!(b.min[0], -1.0);
    }
}
