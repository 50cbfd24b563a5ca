//! 3D Tiles 1.1 tilesets whose tile content is glTF with `KHR_gaussian_splatting` (CesiumJS's
//! format for large splat scenes): [`read`] parses `tileset.json` into a tree of [`Tile`]s with
//! their global transforms and bounding volumes; [`check`] applies the structural rules of
//! 3D Tiles and loads each tile's content through [`crate::load`], for `info` and `validate`;
//! [`select`] chooses the tiles one camera needs within a splat budget, and [`TileCache`]
//! loads their content once, in the tileset's frame, for `render`. [`build`] makes a LOD
//! tree from one cloud (moment-matched merges, `convert … tileset.json`), [`build_streamed`]
//! the same from a [`SplatSource`] read in passes ([`steps`]: its steps for workers of a
//! cluster), and [`tileset_json`] its `tileset.json`.
//! For the viewer, a [`Streamer`] thread selects and loads while the camera moves, and
//! [`pages::PageTable`] keeps each selected tile in GPU pages of its own.
//!
//! What is read: `asset.version` (1.0 or 1.1), `geometricError`, `refine` (`ADD` / `REPLACE`,
//! inherited from the parent), `transform` (column-major, composed parent × child),
//! `boundingVolume` `box` and `sphere` (`region` is reported unsupported: it needs the WGS84
//! ellipsoid), `content.uri` and 1.1's `contents[].uri`. Content URIs are resolved against the
//! tileset's folder (or URL, [`crate::files::http`]) and must stay inside it
//! ([`LoadOptions::allow_outside_paths`]); external tilesets (content that is itself a
//! `tileset.json`) and implicit tiling are not read yet (issue 21).
//!
//! PlayCanvas's streamed SOG (`lod-meta.json`) is read into the same tree ([`TilesetFormat`];
//! the mapping and its derived geometric error are in `lod_meta.rs`, [`level_error`]).

mod build;
mod check;
mod lod_meta;
mod lod_meta_write;
pub mod pages;
mod scratch;
mod select;
mod source;
pub mod steps;
mod stream;
mod units;

pub use build::{
    BuildOptions, BuiltTile, ContentSink, ERROR_QUANTILE, ERROR_SIGMAS, Merged, Reduced, build,
    merge, reduce, tileset_json,
};

pub use check::{LevelSummary, TilesetReport, check};
pub use lod_meta::{MAX_LOD_LEVELS, level_error};
pub use lod_meta_write::{LodMetaLayout, layout as lod_meta_layout};
pub use scratch::{
    MAX_BUCKETS, Plane, SAMPLE, SplatSource, StreamOptions, StreamReport, build_streamed,
};
pub use select::{
    SelectOptions, Selection, TileCache, Y_UP_TO_Z_UP, screen_space_error, select, visible,
};
pub use source::{PlySource, READ_ROWS};
pub use steps::{TILES_DIR, content_extensions};
pub use stream::{
    LOAD_BATCH, StreamFrame, StreamSettings, Streamer, coarse_cover, merged, select_resident,
};

use crate::load::LoadOptions;
use glam::{DMat3, DMat4, DVec3};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Why a tileset could not be read, built, laid out, selected from or streamed.
#[derive(Debug, thiserror::Error)]
pub enum TilesError {
    /// No splats to build a tileset from.
    #[error("no splats to build a tileset from")]
    Empty,
    /// A tile size below [`BuildOptions::MIN_CHUNK_SPLATS`].
    #[error("chunk_splats {chunk} is below the minimum {min}")]
    ChunkTooSmall {
        /// The size asked for.
        chunk: usize,
        /// The minimum.
        min: usize,
    },
    /// The root tile alone holds more splats than the budget.
    #[error("the root tile alone holds {splats} splats, more than the budget of {budget}")]
    OverBudget {
        /// The root's splats.
        splats: u64,
        /// The budget.
        budget: u64,
    },
    /// The tileset could not be read, or is not one (the message names the file and what).
    #[error("{0}")]
    Read(String),
    /// A step of a build failed: the splat source, the content sink, the scratch folder, or a
    /// tile without content (the message names it).
    #[error("{0}")]
    Build(String),
    /// The streaming thread could not start, or nothing at the top of the tree loads.
    #[error("{0}")]
    Stream(String),
}

impl From<TilesError> for String {
    fn from(e: TilesError) -> String {
        e.to_string()
    }
}

/// At most this many tiles are read from one tileset (a hostile file cannot make the tree
/// unbounded).
pub const MAX_TILES: usize = 1 << 20;
/// …and at most this deep.
pub const MAX_DEPTH: usize = 64;

/// How a tile's children refine it (3D Tiles `refine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refine {
    /// The children's content is drawn in addition to the parent's.
    Add,
    /// The children's content replaces the parent's.
    Replace,
}

/// A tile's bounding volume in the tileset's frame (its transform applied).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bounds {
    /// `box`: centre and three half-axis vectors (columns).
    Box {
        /// The centre.
        centre: DVec3,
        /// The half axes as columns.
        half_axes: DMat3,
    },
    /// `sphere`: centre and radius.
    Sphere {
        /// The centre.
        centre: DVec3,
        /// The radius.
        radius: f64,
    },
}

impl Bounds {
    /// The smallest sphere around it (for a box, the one through its corners).
    pub fn sphere(&self) -> (DVec3, f64) {
        match *self {
            Bounds::Sphere { centre, radius } => (centre, radius),
            Bounds::Box { centre, half_axes } => (
                centre,
                (half_axes.x_axis.abs() + half_axes.y_axis.abs() + half_axes.z_axis.abs()).length(),
            ),
        }
    }

    /// Whether `p` lies inside (with a relative tolerance `eps` of the volume's size).
    pub fn contains(&self, p: DVec3, eps: f64) -> bool {
        match *self {
            Bounds::Sphere { centre, radius } => (p - centre).length() <= radius * (1.0 + eps),
            Bounds::Box { centre, half_axes } => {
                let d = p - centre;
                [half_axes.x_axis, half_axes.y_axis, half_axes.z_axis]
                    .iter()
                    .all(|h| {
                        let n2 = h.length_squared();
                        n2 == 0.0 || d.dot(*h).abs() <= n2 * (1.0 + eps)
                    })
            }
        }
    }

    /// Points that span it: a box's eight corners, a sphere's six axis extremes.
    pub fn extremes(&self) -> Vec<DVec3> {
        match *self {
            Bounds::Sphere { centre, radius } => [DVec3::X, DVec3::Y, DVec3::Z]
                .iter()
                .flat_map(|a| [centre + *a * radius, centre - *a * radius])
                .collect(),
            Bounds::Box { centre, half_axes } => (0..8)
                .map(|k| {
                    let s = |bit: i32| if k & bit == 0 { -1.0 } else { 1.0 };
                    centre
                        + half_axes.x_axis * s(1)
                        + half_axes.y_axis * s(2)
                        + half_axes.z_axis * s(4)
                })
                .collect(),
        }
    }
}

/// One tile of the tree.
#[derive(Debug, Clone)]
pub struct Tile {
    /// Where it is in `tileset.json` (`root.children[2].children[0]`).
    pub path: String,
    /// Its depth (the root is 0).
    pub level: usize,
    /// `geometricError` (metres of error if this tile is drawn instead of its children).
    pub geometric_error: f64,
    /// How its children refine it (its own `refine`, else its parent's).
    pub refine: Refine,
    /// The global transform: the product of the `transform`s from the root down to it.
    pub transform: DMat4,
    /// Its bounding volume in the tileset's frame; `None` when it has none splatgl reads
    /// (`region`, or a malformed one: see the report).
    pub bounds: Option<Bounds>,
    /// Its content URIs (`content.uri`, `contents[].uri`), as written.
    pub content: Vec<String>,
    /// Its children.
    pub children: Vec<Tile>,
}

impl Tile {
    /// This tile and every tile below it, depth first.
    pub fn walk(&self) -> Vec<&Tile> {
        let mut out = vec![self];
        for c in &self.children {
            out.extend(c.walk());
        }
        out
    }
}

/// A problem found while reading: its JSON path and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Where (`root.children[1].boundingVolume`).
    pub path: String,
    /// What is wrong, and what was expected.
    pub message: String,
    /// Whether splatgl cannot use it although 3D Tiles allows it (`region`, external
    /// tilesets), rather than the file breaking a rule.
    pub unsupported: bool,
}

/// Which of the two tileset formats a [`Tileset`] was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TilesetFormat {
    /// 3D Tiles 1.1 `tileset.json`, glTF content (y-up, turned to the tileset's z-up).
    Tiles3d,
    /// PlayCanvas streamed SOG `lod-meta.json`, SOG content in its own (PLY) frame.
    StreamedSog,
}

impl TilesetFormat {
    /// Its name in `info` (`"3dtiles"`, `"streamed-sog"`).
    pub fn name(self) -> &'static str {
        match self {
            TilesetFormat::Tiles3d => "3dtiles",
            TilesetFormat::StreamedSog => "streamed-sog",
        }
    }
}

/// A tileset as read.
#[derive(Debug, Clone)]
pub struct Tileset {
    /// The `tileset.json` or `lod-meta.json` read: a path, or an `http://` / `https://` URL as
    /// given (its content is then fetched relative to it, [`crate::files::http`]).
    pub file: PathBuf,
    /// Which format it is.
    pub format: TilesetFormat,
    /// `asset.version` (3D Tiles), or `version` (streamed SOG; `"1"` when absent).
    pub version: String,
    /// The root tile.
    pub root: Tile,
    /// What was wrong in the JSON that did not stop reading (each tile that has it is still
    /// in the tree, with what could be read).
    pub problems: Vec<Problem>,
    /// Decoded streamed-SOG units, shared by the leaves that slice them.
    units: units::Units,
}

impl Tileset {
    /// The folder its content URIs are resolved against (`.` for a bare file name).
    pub fn folder(&self) -> &Path {
        self.file
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
    }

    /// The frame change from a tile's content to the tile (before its transform): glTF's
    /// y-up to 3D Tiles' z-up, or none for streamed SOG.
    pub fn content_frame(&self) -> DMat4 {
        match self.format {
            TilesetFormat::Tiles3d => select::Y_UP_TO_Z_UP,
            TilesetFormat::StreamedSog => DMat4::IDENTITY,
        }
    }

    /// The up axis its frame implies for automatic framing. 3D Tiles are z-up (glTF content
    /// is rotated into that frame by [`Tileset::content_frame`]): the root's +Z as its
    /// transform places it, as the nearest of +Y, −Y (a root transform that turns the tileset
    /// y-up) or else +Z. `None` for streamed SOG, whose content's own rule applies.
    pub fn up(&self) -> Option<crate::camera::UpAxis> {
        use crate::camera::UpAxis;
        match self.format {
            TilesetFormat::Tiles3d => {
                let u = self.root.transform.transform_vector3(glam::DVec3::Z);
                let y = u.y / u.length().max(f64::MIN_POSITIVE);
                Some(match y {
                    y if y > 0.9 => UpAxis::Y,
                    y if y < -0.9 => UpAxis::NegY,
                    _ => UpAxis::Z,
                })
            }
            TilesetFormat::StreamedSog => None,
        }
    }

    /// The tiles whose content is drawn when nothing is refined: on every path from the root,
    /// the first tile with content (for framing a view before selecting).
    pub fn coarsest(&self) -> Vec<&Tile> {
        let mut out = Vec::new();
        let mut stack = vec![&self.root];
        while let Some(t) = stack.pop() {
            match t.content.is_empty() {
                false => out.push(t),
                true => stack.extend(t.children.iter().rev()),
            }
        }
        out
    }

    /// The scene a tile's content URI names, loaded with `opts` inside [`Tileset::folder`]
    /// (the one way `check` and the tile cache read content). For a streamed SOG, the run of
    /// splats the URI names in its SOG unit (decoded once for the leaves that share it).
    pub fn load_content(
        &self,
        uri: &str,
        opts: &LoadOptions,
    ) -> Result<crate::load::Scene, ContentError> {
        if self.format == TilesetFormat::StreamedSog {
            return self.units.rows(self, uri, opts);
        }
        if uri.ends_with(".json") {
            return Err(ContentError::Unsupported(format!(
                "{uri:?}: external tilesets are not read by splatgl yet"
            )));
        }
        if let Some(base) = self.url() {
            return load_url_content(base, uri, opts);
        }
        let file = crate::files::contained(self.folder(), uri, opts.allow_outside_paths)
            .map_err(ContentError::Unreadable)?;
        crate::load::load_path(&file, opts)
            .map_err(|e| ContentError::Unreadable(format!("{uri:?} does not load: {e}")))
    }

    /// The URL it was fetched from, if it was.
    pub fn url(&self) -> Option<&str> {
        self.file.to_str().filter(|s| crate::files::http::is_url(s))
    }
}

/// A tile's content fetched relative to the tileset's URL (kept under its folder).
fn load_url_content(
    base: &str,
    uri: &str,
    opts: &LoadOptions,
) -> Result<crate::load::Scene, ContentError> {
    use crate::files::http;
    let url = http::resolve(base, uri, opts.allow_outside_paths)
        .map_err(|e| ContentError::Unreadable(e.to_string()))?;
    let bytes = http::fetch_bounded(&url, opts.limits.max_bytes, "the tile content")
        .map_err(|e| ContentError::Unreadable(e.to_string()))?;
    // No path: the format is told by the bytes, and nothing the content names is read from
    // disk (external glTF buffers of fetched content are not fetched: use .glb or data URIs).
    let mut o = opts.clone();
    o.resolver = None;
    crate::load::load_bytes(&bytes, None, &o)
        .map_err(|e| ContentError::Unreadable(format!("{uri:?} does not load: {e}")))
}

/// Why [`Tileset::load_content`] gave no scene.
#[derive(Debug, Clone, PartialEq)]
pub enum ContentError {
    /// 3D Tiles allows it, splatgl does not read it yet (an external tileset).
    Unsupported(String),
    /// Outside the tileset's folder, missing, or not loadable.
    Unreadable(String),
}

impl std::fmt::Display for ContentError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ContentError::Unsupported(m) | ContentError::Unreadable(m) => f.write_str(m),
        }
    }
}

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
