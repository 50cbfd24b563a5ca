//! 3DGS `cameras.json` (written by the INRIA trainer): a list of
//! `{id, img_name, width, height, position[3], rotation[3][3], fx, fy}` with optional `cx`, `cy`.

use super::CameraError;
use crate::files::{Limits, check_json};
use serde_json::Value;

/// One view of a `cameras.json`, values as written (f64).
#[derive(Debug, Clone, PartialEq)]
pub struct CamerasJsonEntry {
    /// `id`.
    pub id: i64,
    /// `img_name` (empty when absent).
    pub img_name: String,
    /// `width` in pixels.
    pub width: u32,
    /// `height` in pixels.
    pub height: u32,
    /// `position`: the camera centre in world space.
    pub position: [f64; 3],
    /// `rotation`: camera → world, `rotation[i]` is row i.
    pub rotation: [[f64; 3]; 3],
    /// `fx` in pixels.
    pub fx: f64,
    /// `fy` in pixels.
    pub fy: f64,
    /// `cx` if present.
    pub cx: Option<f64>,
    /// `cy` if present.
    pub cy: Option<f64>,
}

fn invalid(location: String, message: impl Into<String>) -> CameraError {
    CameraError::Invalid {
        location,
        message: message.into(),
    }
}

fn number(v: Option<&Value>, loc: String) -> Result<f64, CameraError> {
    match v.and_then(Value::as_f64) {
        Some(x) if x.is_finite() => Ok(x),
        Some(_) => Err(invalid(loc, "expected a finite number")),
        None => Err(invalid(loc, "expected a number")),
    }
}

fn size(v: Option<&Value>, loc: String) -> Result<u32, CameraError> {
    match v.and_then(Value::as_u64) {
        Some(x) if (1..=1 << 16).contains(&x) => Ok(x as u32),
        _ => Err(invalid(loc, "expected an integer in 1..=65536")),
    }
}

fn array<'a>(v: Option<&'a Value>, n: usize, loc: &str) -> Result<&'a [Value], CameraError> {
    match v.and_then(Value::as_array) {
        Some(a) if a.len() == n => Ok(a),
        _ => Err(invalid(loc.to_owned(), format!("expected an array of {n}"))),
    }
}

fn entry(i: usize, v: &Value) -> Result<CamerasJsonEntry, CameraError> {
    let at = |k: &str| format!("[{i}].{k}");
    if !v.is_object() {
        return Err(invalid(format!("[{i}]"), "expected an object"));
    }
    let pos = array(v.get("position"), 3, &at("position"))?;
    let mut position = [0.0; 3];
    for (j, p) in pos.iter().enumerate() {
        position[j] = number(Some(p), format!("{}[{j}]", at("position")))?;
    }
    let rows = array(v.get("rotation"), 3, &at("rotation"))?;
    let mut rotation = [[0.0; 3]; 3];
    for (r, row) in rows.iter().enumerate() {
        let row = array(Some(row), 3, &format!("{}[{r}]", at("rotation")))?;
        for (c, x) in row.iter().enumerate() {
            rotation[r][c] = number(Some(x), format!("{}[{r}][{c}]", at("rotation")))?;
        }
    }
    let opt = |k: &str| -> Result<Option<f64>, CameraError> {
        match v.get(k) {
            None | Some(Value::Null) => Ok(None),
            some => number(some, at(k)).map(Some),
        }
    };
    Ok(CamerasJsonEntry {
        id: v.get("id").and_then(Value::as_i64).unwrap_or(i as i64),
        img_name: v
            .get("img_name")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_owned(),
        width: size(v.get("width"), at("width"))?,
        height: size(v.get("height"), at("height"))?,
        position,
        rotation,
        fx: number(v.get("fx"), at("fx"))?,
        fy: number(v.get("fy"), at("fy"))?,
        cx: opt("cx")?,
        cy: opt("cy")?,
    })
}

/// Parses the text of a `cameras.json`. Every entry must be well-formed; errors name the entry
/// and key. Nesting is bounded by the default [`Limits::max_json_depth`].
pub fn parse_cameras_json(text: &str) -> Result<Vec<CamerasJsonEntry>, CameraError> {
    parse_limited(text, &Limits::default())
}

fn parse_limited(text: &str, limits: &Limits) -> Result<Vec<CamerasJsonEntry>, CameraError> {
    check_json(text.as_bytes(), limits).map_err(|m| invalid(String::new(), m))?;
    let v: Value = serde_json::from_str(text)?;
    let list = v
        .as_array()
        .ok_or_else(|| invalid(String::new(), "expected a JSON array of cameras"))?;
    list.iter().enumerate().map(|(i, e)| entry(i, e)).collect()
}

/// Reads and parses a `cameras.json` file with the default [`Limits`].
pub fn load_cameras_json(
    path: impl AsRef<std::path::Path>,
) -> Result<Vec<CamerasJsonEntry>, CameraError> {
    load_cameras_json_limited(path, &Limits::default())
}

/// Reads and parses a `cameras.json` file: a regular file of at most `limits.max_bytes`, nested
/// at most `limits.max_json_depth` deep.
pub fn load_cameras_json_limited(
    path: impl AsRef<std::path::Path>,
    limits: &Limits,
) -> Result<Vec<CamerasJsonEntry>, CameraError> {
    let path = path.as_ref();
    let io = |source| CameraError::Io {
        path: path.to_owned(),
        source,
    };
    let bytes = crate::files::read_bounded(path, limits.max_bytes, "cameras.json").map_err(io)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("cameras.json is not UTF-8 ({e})"),
        ))
    })?;
    parse_limited(&text, limits).map_err(|e| match e {
        CameraError::Json(_) | CameraError::Invalid { .. } => CameraError::File {
            path: path.to_owned(),
            source: Box::new(e),
        },
        other => other,
    })
}

impl super::Camera {
    /// This camera as one `cameras.json` entry of the INRIA 3DGS trainer (`id`, `img_name`,
    /// `width`, `height`, `position`, `rotation` camera → world by rows, `fx`, `fy`; `cx`/`cy`
    /// only when the principal point is off the image centre). [`super::Camera::from_3dgs`]
    /// reads it back (its near/far are the trainer's 0.01 / 100).
    pub fn to_3dgs_json(&self, id: i64, img_name: &str) -> Value {
        let inv = self.world_to_camera.as_dmat4().inverse();
        let c2w = glam::DMat3::from_mat4(inv);
        // Row i of camera → world: element i of each camera axis.
        let rows: Vec<Vec<f64>> = (0..3)
            .map(|i| vec![c2w.x_axis[i], c2w.y_axis[i], c2w.z_axis[i]])
            .map(|r| r.into_iter().map(|v| v as f32 as f64).collect())
            .collect();
        let centre = inv.w_axis.truncate().as_vec3();
        let mut e = serde_json::json!({
            "id": id,
            "img_name": img_name,
            "width": self.width,
            "height": self.height,
            "position": centre.to_array(),
            "rotation": rows,
            "fx": self.fx,
            "fy": self.fy,
        });
        let off = |c: f32, size: u32| (c - 0.5 * size as f32).abs() > 1e-4 * size as f32;
        if off(self.cx, self.width) || off(self.cy, self.height) {
            e["cx"] = self.cx.into();
            e["cy"] = self.cy.into();
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    #[test]
    fn cameras_json_entry_reads_back_as_the_same_camera() {
        let mut cam = super::super::Camera::look_at(
            Vec3::new(0.5, -1.0, 4.0),
            Vec3::new(0.0, 0.3, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            0.7,
            400,
            300,
        );
        cam.cx = 190.0;
        let text = serde_json::to_string(&vec![cam.to_3dgs_json(3, "v")]).unwrap();
        let e = &super::parse_cameras_json(&text).unwrap()[0];
        let back = super::super::Camera::from_3dgs(e).unwrap();
        assert_eq!((back.width, back.height, back.cx), (400, 300, 190.0));
        assert!((back.fx - cam.fx).abs() < 1e-4 && (back.cy - 150.0).abs() < 1e-6);
        let d = (back.world_to_camera - cam.world_to_camera)
            .abs()
            .to_cols_array();
        assert!(d.iter().all(|v| *v < 1e-5), "{d:?}");
    }
}
