//! Reading `tileset.json` (3D Tiles 1.0 / 1.1) and streamed SOG `lod-meta.json` into a
//! [`Tileset`]: the structural rules, limits and problems found while reading.

use super::*;

/// Whether `bytes` look like a 3D Tiles `tileset.json` (a JSON object with `asset` and
/// `root`) or a streamed SOG `lod-meta.json` (`lodLevels`, `filenames`, `tree`) — or, when it
/// does not parse (nested too deep, truncated), text with the keys `"root"` and
/// `"geometricError"` (or `"lodLevels"` and `"tree"`), so that [`read`] reports what is wrong
/// with it as a tileset. What `info` and `validate` test before taking a `.json` file as one.
pub fn is_tileset(bytes: &[u8]) -> bool {
    let head = bytes.iter().position(|b| !b.is_ascii_whitespace());
    if head.is_none_or(|i| bytes[i] != b'{') {
        return false;
    }
    // Over the default JSON limits: told by its keys (the reader then names the limit).
    let parsed = crate::files::check_json(bytes, &crate::files::Limits::default())
        .ok()
        .and_then(|_| serde_json::from_slice::<Value>(bytes).ok());
    match parsed {
        Some(v) => {
            (v.get("asset").is_some() && v.get("root").is_some()) || lod_meta::is_lod_meta(&v)
        }
        None => {
            let has = |k: &[u8]| bytes.windows(k.len()).any(|w| w == k);
            (has(b"\"root\"") && has(b"\"geometricError\""))
                || (has(b"\"lodLevels\"") && has(b"\"tree\""))
        }
    }
}

/// Reads `path` as a tileset (3D Tiles, or streamed SOG): within the load limits (`max_bytes`, the JSON nesting depth),
/// at most [`MAX_TILES`] tiles [`MAX_DEPTH`] deep. `Err` when it cannot be read at all (not
/// JSON, no `root`, no usable `asset.version`); rule breaks inside tiles are
/// [`Tileset::problems`].
pub fn read(path: &Path, opts: &LoadOptions) -> Result<Tileset, TilesError> {
    read_tileset(path, opts).map_err(TilesError::Read)
}

fn read_tileset(path: &Path, opts: &LoadOptions) -> Result<Tileset, String> {
    let shown = path.display();
    let bytes = match path.to_str().filter(|s| crate::files::http::is_url(s)) {
        Some(url) => crate::files::http::fetch_bounded(url, opts.limits.max_bytes, "the tileset")
            .map_err(|e| e.to_string())?,
        None => crate::files::read_bounded(path, opts.limits.max_bytes, "the tileset")
            .map_err(|e| format!("{shown}: {e}"))?,
    };
    crate::files::check_json(&bytes, &opts.limits).map_err(|e| format!("{shown}: {e}"))?;
    let v: Value = serde_json::from_slice(&bytes).map_err(|e| format!("{shown}: not JSON: {e}"))?;
    if lod_meta::is_lod_meta(&v) {
        let mut problems = Vec::new();
        let root = lod_meta::read(&v, &mut problems).map_err(|e| format!("{shown}: {e}"))?;
        return Ok(Tileset {
            file: path.to_owned(),
            format: TilesetFormat::StreamedSog,
            version: v.get("version").map_or("1".into(), |x| x.to_string()),
            root,
            problems,
            units: Default::default(),
        });
    }
    let version = v
        .pointer("/asset/version")
        .and_then(Value::as_str)
        .ok_or_else(|| format!("{shown}: asset.version: missing (expected \"1.0\" or \"1.1\")"))?
        .to_owned();
    let mut problems = Vec::new();
    if version != "1.0" && version != "1.1" {
        problems.push(Problem {
            path: "asset.version".into(),
            message: format!("{version:?}: expected \"1.0\" or \"1.1\""),
            unsupported: true,
        });
    }
    extensions_required(&v, &mut problems);
    let root = v
        .get("root")
        .ok_or_else(|| format!("{shown}: root: missing"))?;
    let mut reader = Reader {
        tiles: 0,
        problems: &mut problems,
    };
    let parent = Parent {
        refine: None,
        transform: DMat4::IDENTITY,
        level: 0,
    };
    let root = reader
        .tile(root, "root".into(), parent)
        .ok_or_else(|| format!("{shown}: root: not a tile object"))?;
    if root.refine_missing {
        problems.push(Problem {
            path: "root.refine".into(),
            message: "missing: the root tile must say ADD or REPLACE (read as REPLACE)".into(),
            unsupported: false,
        });
    }
    Ok(Tileset {
        file: path.to_owned(),
        format: TilesetFormat::Tiles3d,
        version,
        root: root.tile,
        problems,
        units: Default::default(),
    })
}

/// The 3D Tiles extensions splatgl reads: glTF content declared by `3DTILES_content_gltf`.
const TILES_EXTENSIONS: &[&str] = &["3DTILES_content_gltf"];

/// `extensionsRequired` of the tileset (3D Tiles extensions) and of `3DTILES_content_gltf`
/// (glTF extensions every content may require): each one splatgl cannot honour is an
/// `unsupported` problem at its path.
fn extensions_required(v: &Value, problems: &mut Vec<Problem>) {
    let lists = [
        (
            "extensionsRequired",
            "/extensionsRequired",
            TILES_EXTENSIONS,
        ),
        (
            "extensions.3DTILES_content_gltf.extensionsRequired",
            "/extensions/3DTILES_content_gltf/extensionsRequired",
            crate::load::gltf::SUPPORTED_REQUIRED,
        ),
    ];
    for (path, pointer, known) in lists {
        let Some(list) = v.pointer(pointer).and_then(Value::as_array) else {
            continue;
        };
        for (i, e) in list.iter().enumerate() {
            let name = e.as_str().unwrap_or("");
            if !known.contains(&name) {
                problems.push(Problem {
                    path: format!("{path}[{i}]"),
                    message: format!("{e} is required but splatgl does not implement it"),
                    unsupported: true,
                });
            }
        }
    }
}

/// What a tile inherits from its parent.
#[derive(Clone, Copy)]
struct Parent {
    refine: Option<Refine>,
    transform: DMat4,
    level: usize,
}

/// A tile as read, and whether it had its own `refine`.
struct ReadTile {
    tile: Tile,
    refine_missing: bool,
}

/// The state of one read: tiles so far and the problems found.
struct Reader<'a> {
    tiles: usize,
    problems: &'a mut Vec<Problem>,
}

impl Reader<'_> {
    fn problem(&mut self, path: &str, message: impl Into<String>, unsupported: bool) {
        self.problems.push(Problem {
            path: path.to_owned(),
            message: message.into(),
            unsupported,
        });
    }

    /// The tile `v` at `path` below `parent`; `None` when `v` is not an object or the tree is
    /// over its limits.
    fn tile(&mut self, v: &Value, path: String, parent: Parent) -> Option<ReadTile> {
        let obj = v.as_object()?;
        self.tiles += 1;
        if self.tiles > MAX_TILES || parent.level > MAX_DEPTH {
            self.problem(
                &path,
                format!("more than {MAX_TILES} tiles or deeper than {MAX_DEPTH}: not read"),
                true,
            );
            return None;
        }
        let geometric_error = match obj.get("geometricError").and_then(Value::as_f64) {
            Some(g) if g.is_finite() && g >= 0.0 => g,
            other => {
                let found = other.map_or("missing".to_owned(), |g| g.to_string());
                self.problem(
                    &format!("{path}.geometricError"),
                    format!("{found}: expected a number ≥ 0 (read as 0)"),
                    false,
                );
                0.0
            }
        };
        let own_refine = match obj.get("refine").map(|r| r.as_str()) {
            None => None,
            Some(Some("ADD")) => Some(Refine::Add),
            Some(Some("REPLACE")) => Some(Refine::Replace),
            Some(other) => {
                self.problem(
                    &format!("{path}.refine"),
                    format!("{other:?}: expected \"ADD\" or \"REPLACE\" (inherited instead)"),
                    false,
                );
                None
            }
        };
        let refine = own_refine.or(parent.refine).unwrap_or(Refine::Replace);
        let transform = parent.transform * self.transform(obj.get("transform"), &path);
        let bounds = self.bounds(obj.get("boundingVolume"), &path, transform);
        let content = self.content(obj, &path);
        let mut children = Vec::new();
        if let Some(list) = obj.get("children") {
            let Some(list) = list.as_array() else {
                self.problem(&format!("{path}.children"), "expected an array", false);
                return None;
            };
            let below = Parent {
                refine: Some(refine),
                transform,
                level: parent.level + 1,
            };
            for (i, c) in list.iter().enumerate() {
                let cp = format!("{path}.children[{i}]");
                match self.tile(c, cp.clone(), below) {
                    Some(t) => children.push(t.tile),
                    None if c.is_object() => {}
                    None => self.problem(&cp, "expected a tile object", false),
                }
            }
        }
        Some(ReadTile {
            tile: Tile {
                path,
                level: parent.level,
                geometric_error,
                refine,
                transform,
                bounds,
                content,
                children,
            },
            refine_missing: own_refine.is_none(),
        })
    }

    /// A tile's own `transform` (identity when absent or malformed).
    fn transform(&mut self, v: Option<&Value>, path: &str) -> DMat4 {
        let Some(v) = v else {
            return DMat4::IDENTITY;
        };
        let m: Option<Vec<f64>> = v
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_f64).collect());
        match m {
            Some(m) if m.len() == 16 && m.iter().all(|x| x.is_finite()) => {
                DMat4::from_cols_slice(&m)
            }
            _ => {
                self.problem(
                    &format!("{path}.transform"),
                    "expected 16 finite numbers, column-major (identity used)",
                    false,
                );
                DMat4::IDENTITY
            }
        }
    }

    /// A tile's bounding volume in the tileset's frame.
    fn bounds(&mut self, v: Option<&Value>, path: &str, m: DMat4) -> Option<Bounds> {
        let at = format!("{path}.boundingVolume");
        let Some(v) = v else {
            self.problem(&at, "missing (every tile needs one)", false);
            return None;
        };
        let nums = |k: &str| -> Option<Vec<f64>> {
            let a = v.get(k)?.as_array()?;
            let n: Vec<f64> = a.iter().filter_map(Value::as_f64).collect();
            (n.len() == a.len() && n.iter().all(|x| x.is_finite())).then_some(n)
        };
        if let Some(b) = nums("box") {
            if b.len() == 12 {
                let m3 = DMat3::from_mat4(m);
                let col = |i: usize| m3 * DVec3::new(b[i], b[i + 1], b[i + 2]);
                return Some(Bounds::Box {
                    centre: m.transform_point3(DVec3::new(b[0], b[1], b[2])),
                    half_axes: DMat3::from_cols(col(3), col(6), col(9)),
                });
            }
        } else if let Some(s) = nums("sphere") {
            if s.len() == 4 && s[3] >= 0.0 {
                // The largest column length of the transform scales the radius.
                let m3 = DMat3::from_mat4(m);
                let k = [m3.x_axis, m3.y_axis, m3.z_axis]
                    .iter()
                    .map(|c| c.length())
                    .fold(0.0, f64::max);
                return Some(Bounds::Sphere {
                    centre: m.transform_point3(DVec3::new(s[0], s[1], s[2])),
                    radius: s[3] * k,
                });
            }
        } else if v.get("region").is_some() {
            self.problem(
                &at,
                "region (longitude/latitude on the WGS84 ellipsoid) is not read by splatgl: use box or sphere",
                true,
            );
            return None;
        }
        self.problem(
            &at,
            "expected box (12 finite numbers), sphere (4, radius ≥ 0) or region",
            false,
        );
        None
    }

    /// A tile's content URIs (`content.uri`, `contents[].uri`).
    fn content(&mut self, obj: &serde_json::Map<String, Value>, path: &str) -> Vec<String> {
        let mut out = Vec::new();
        let mut one = |c: &Value, at: String, out: &mut Vec<String>| match c
            .get("uri")
            .and_then(Value::as_str)
        {
            Some(u) => out.push(u.to_owned()),
            None => self.problem(&at, "content without a uri string", false),
        };
        if let Some(c) = obj.get("content") {
            one(c, format!("{path}.content"), &mut out);
        }
        if let Some(list) = obj.get("contents").and_then(Value::as_array) {
            for (i, c) in list.iter().enumerate() {
                one(c, format!("{path}.contents[{i}]"), &mut out);
            }
        }
        out
    }
}
