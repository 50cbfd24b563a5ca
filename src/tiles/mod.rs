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
mod read;
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
pub use read::{is_tileset, read};
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
