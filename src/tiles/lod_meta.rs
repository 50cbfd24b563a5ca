//! PlayCanvas's streamed SOG (`lod-meta.json`, written by `@playcanvas/splat-transform` 3.7 and
//! read by PlayCanvas and Babylon.js) read as a [`super::Tileset`]: a binary tree of nodes with
//! axis-aligned `bound`s; each leaf names, per LOD level (0 the finest), a run of splats
//! `{file, offset, count}` in one of the `filenames` (unbundled SOG `meta.json`s).
//!
//! The mapping onto 3D Tiles' model, so that one selection serves both formats: an inner node is
//! a tile without content whose children refine it; a leaf becomes a chain of `REPLACE` tiles,
//! its coarsest level on top and each finer level the only child of the next coarser one, all
//! with the leaf's bound. The format carries no geometric error unless the writer rendered its
//! optional error tables (`lodErrors`, in units the format does not define); splatgl derives it
//! from the splat counts, as splat-transform's manifest tells consumers to: a level with `n`
//! splats in a leaf of diagonal `D` is `3 D / √n` ([`level_error`]: three times the mean spacing
//! of `n` splats spread over the leaf's cross-section, the scale of splatgl's own merges'
//! error), the finest level 0, and never less than the finer level below it.
//! Content and bounds are in splat-transform's PLY frame (the frame of the SOG units), so the
//! tileset's frame is that frame: no axis turn.
//!
//! What is checked, as splat-transform's reader does (and, for splatgl's `geometricErrors`,
//! one finite non-negative number per level, else a problem and the derived errors): `version` 1 or absent, `lodLevels` a
//! positive integer, `counts` one per level and equal to the tree's sums, `filenames` strings,
//! every LOD reference's level, file index, offset and count in range. A broken node or
//! reference is a [`Problem`] at its JSON path and is left out; the rest is read.

use super::{Bounds, MAX_DEPTH, MAX_TILES, Problem, Refine, Tile};
use glam::{DMat3, DMat4, DVec3};
use serde_json::Value;

/// At most this many LOD levels are read (splat-transform writes a handful).
pub const MAX_LOD_LEVELS: u64 = 32;

/// Whether `v` is a streamed SOG manifest: an object with `lodLevels`, `filenames` and `tree`.
pub(super) fn is_lod_meta(v: &Value) -> bool {
    ["lodLevels", "filenames", "tree"]
        .iter()
        .all(|k| v.get(*k).is_some())
}

/// The content URI of `count` splats from `offset` in `file`: the file's name with a fragment
/// (`0_0/meta.json#offset=0&count=4773`), which [`rows`] reads back.
pub(super) fn content_uri(file: &str, offset: u64, count: u64) -> String {
    format!("{file}#offset={offset}&count={count}")
}

/// The file, offset and count of a content URI made by [`content_uri`].
pub(super) fn rows(uri: &str) -> Option<(&str, usize, usize)> {
    let (file, frag) = uri.split_once('#')?;
    let (o, c) = frag.strip_prefix("offset=")?.split_once("&count=")?;
    Some((file, o.parse().ok()?, c.parse().ok()?))
}

/// The tree of `lod-meta.json` (already parsed into `v`) as a root tile; rule breaks that do not
/// stop reading go to `problems`. `Err` when it is not a usable manifest at all.
pub(super) fn read(v: &Value, problems: &mut Vec<Problem>) -> Result<Tile, String> {
    match v.get("version") {
        None => {}
        Some(x) if x.as_u64() == Some(1) => {}
        Some(x) => return Err(format!("version: {x}: expected 1 (or absent)")),
    }
    let levels = v
        .get("lodLevels")
        .and_then(Value::as_u64)
        .filter(|n| (1..=MAX_LOD_LEVELS).contains(n))
        .ok_or_else(|| {
            format!(
                "lodLevels: {}: expected an integer from 1 to {MAX_LOD_LEVELS}",
                v["lodLevels"]
            )
        })? as usize;
    let filenames: Vec<String> = v
        .get("filenames")
        .and_then(Value::as_array)
        .and_then(|a| a.iter().map(|s| s.as_str().map(str::to_owned)).collect())
        .ok_or("filenames: expected an array of strings")?;
    let tree = v
        .get("tree")
        .filter(|t| t.is_object())
        .ok_or("tree: expected a node object")?;
    let mut r = Reader {
        levels,
        filenames: &filenames,
        tiles: 0,
        counts: vec![0; levels],
        problems,
    };
    let root = r
        .node(tree, "tree".into(), 0)
        .ok_or("tree: no usable node (see the problems)")?;
    if let Some(c) = v.get("counts") {
        let want: Option<Vec<u64>> = c
            .as_array()
            .and_then(|a| a.iter().map(Value::as_u64).collect());
        match want {
            Some(w) if w == r.counts => {}
            Some(w) if w.len() == levels => r.problem(
                "counts",
                format!(
                    "{w:?}, but the tree's references sum to {:?} per level",
                    r.counts
                ),
            ),
            _ => r.problem(
                "counts",
                format!("{c}: expected {levels} non-negative integers, one per level"),
            ),
        }
    }
    Ok(root)
}

/// One LOD reference of a leaf: its level, file index, first splat and count.
struct LodRef {
    level: usize,
    file: usize,
    offset: u64,
    count: u64,
}

/// The state of one read.
struct Reader<'a> {
    levels: usize,
    filenames: &'a [String],
    tiles: usize,
    /// Splats referenced per level, to check `counts`.
    counts: Vec<u64>,
    problems: &'a mut Vec<Problem>,
}

impl Reader<'_> {
    fn problem(&mut self, path: &str, message: impl Into<String>) {
        self.problems.push(Problem {
            path: path.to_owned(),
            message: message.into(),
            unsupported: false,
        });
    }

    /// The node `v` at `path`, `depth` below the root, as a tile (a leaf: its chain of levels);
    /// `None` when it is unusable or the tree is over its limits.
    fn node(&mut self, v: &Value, path: String, depth: usize) -> Option<Tile> {
        let Some(obj) = v.as_object() else {
            self.problem(&path, "expected a node object");
            return None;
        };
        if self.tiles >= MAX_TILES || depth > MAX_DEPTH {
            self.problems.push(Problem {
                path: path.clone(),
                message: format!(
                    "more than {MAX_TILES} tiles or deeper than {MAX_DEPTH}: not read"
                ),
                unsupported: true,
            });
            return None;
        }
        self.tiles += 1;
        let bounds = self.bound(obj.get("bound"), &path);
        if let Some(list) = obj.get("children") {
            let Some(list) = list.as_array() else {
                self.problem(&format!("{path}.children"), "expected an array");
                return None;
            };
            if obj.contains_key("lods") {
                self.problem(
                    &format!("{path}.lods"),
                    "a node with children holds no LOD references (ignored)",
                );
            }
            let children: Vec<Tile> = list
                .iter()
                .enumerate()
                .filter_map(|(i, c)| self.node(c, format!("{path}.children[{i}]"), depth + 1))
                .collect();
            let geometric_error = children
                .iter()
                .map(|c| c.geometric_error)
                .fold(0.0, f64::max);
            return Some(tile(
                path,
                depth,
                geometric_error,
                bounds,
                Vec::new(),
                children,
            ));
        }
        let refs = self.lods(obj.get("lods"), &path);
        let errors = self.errors(obj.get("geometricErrors"), &path);
        Some(self.chain(&path, depth, bounds, refs, errors))
    }

    /// A leaf's levels as a chain of tiles, the coarsest on top.
    fn chain(
        &mut self,
        path: &str,
        depth: usize,
        bounds: Option<Bounds>,
        refs: Vec<LodRef>,
        errors: Option<Vec<f64>>,
    ) -> Tile {
        let diagonal = bounds.map_or(0.0, |b| 2.0 * b.sphere().1);
        let mut below: Option<Tile> = None;
        let n = refs.len();
        // Finest first (refs are sorted by level), each wrapped by the next coarser one.
        for (k, r) in refs.into_iter().enumerate() {
            let finer = below.take();
            let error = match &finer {
                None => 0.0,
                Some(f) => errors
                    .as_ref()
                    .map_or_else(|| level_error(diagonal, r.count), |e| e[r.level])
                    .max(f.geometric_error),
            };
            let uri = content_uri(&self.filenames[r.file], r.offset, r.count);
            let t = tile(
                format!("{path}.lods[\"{}\"]", r.level),
                depth + (n - 1 - k),
                error,
                bounds,
                vec![uri],
                finer.into_iter().collect(),
            );
            below = Some(t);
        }
        below.unwrap_or_else(|| tile(path.to_owned(), depth, 0.0, bounds, Vec::new(), Vec::new()))
    }

    /// A leaf's LOD references, finest level first; broken ones are problems and left out.
    fn lods(&mut self, v: Option<&Value>, path: &str) -> Vec<LodRef> {
        let at = format!("{path}.lods");
        let Some(map) = v.and_then(Value::as_object) else {
            self.problem(&at, "a leaf needs an object of LOD references");
            return Vec::new();
        };
        let mut out = Vec::new();
        for (key, r) in map {
            let here = format!("{at}[\"{key}\"]");
            let int = |k: &str| r.get(k).and_then(Value::as_u64);
            let level = key.parse::<usize>().ok().filter(|l| *l < self.levels);
            let (Some(level), Some(file), Some(offset), Some(count)) =
                (level, int("file"), int("offset"), int("count"))
            else {
                self.problem(
                    &here,
                    format!(
                        "{r}: expected a level below lodLevels ({}) and integer file, offset and count",
                        self.levels
                    ),
                );
                continue;
            };
            if file as usize >= self.filenames.len() {
                self.problem(
                    &format!("{here}.file"),
                    format!("{file}: only {} filenames", self.filenames.len()),
                );
                continue;
            }
            self.counts[level] += count;
            out.push(LodRef {
                level,
                file: file as usize,
                offset,
                count,
            });
        }
        out.sort_by_key(|r| r.level);
        out
    }

    /// A leaf's `geometricErrors` (splatgl's own key, which other readers ignore): one finite,
    /// non-negative error per level, in scene units as 3D Tiles' `geometricError`. `None` when
    /// absent; a problem, and `None`, when malformed.
    fn errors(&mut self, v: Option<&Value>, path: &str) -> Option<Vec<f64>> {
        let v = v?;
        let e: Option<Vec<f64>> = v
            .as_array()
            .filter(|a| a.len() == self.levels)
            .and_then(|a| a.iter().map(Value::as_f64).collect())
            .filter(|e: &Vec<f64>| e.iter().all(|x| x.is_finite() && *x >= 0.0));
        if e.is_none() {
            self.problem(
                &format!("{path}.geometricErrors"),
                format!(
                    "{v}: expected {} finite non-negative numbers, one per level (errors derived from the counts instead)",
                    self.levels
                ),
            );
        }
        e
    }

    /// A node's `bound` (`min`, `max`: three finite numbers each, min ≤ max) as a box.
    fn bound(&mut self, v: Option<&Value>, path: &str) -> Option<Bounds> {
        let corner = |k: &str| -> Option<DVec3> {
            let a = v?.get(k)?.as_array()?;
            let n: Vec<f64> = a.iter().filter_map(Value::as_f64).collect();
            (n.len() == 3 && a.len() == 3 && n.iter().all(|x| x.is_finite()))
                .then(|| DVec3::new(n[0], n[1], n[2]))
        };
        match (corner("min"), corner("max")) {
            (Some(lo), Some(hi)) if lo.cmple(hi).all() => {
                let h = (hi - lo) / 2.0;
                Some(Bounds::Box {
                    centre: (lo + hi) / 2.0,
                    half_axes: DMat3::from_diagonal(h),
                })
            }
            _ => {
                self.problem(
                    &format!("{path}.bound"),
                    "expected min and max, three finite numbers each, min ≤ max",
                );
                None
            }
        }
    }
}

/// The geometric error of a coarser level with `count` splats in a leaf of diagonal `diagonal`:
/// [`super::ERROR_SIGMAS`] × the splats' mean spacing `diagonal / √count` — the scale of
/// splatgl's own merges' error (3 × the spread of the splats one merged splat stands for).
pub fn level_error(diagonal: f64, count: u64) -> f64 {
    super::ERROR_SIGMAS * diagonal / (count.max(1) as f64).sqrt()
}

fn tile(
    path: String,
    level: usize,
    geometric_error: f64,
    bounds: Option<Bounds>,
    content: Vec<String>,
    children: Vec<Tile>,
) -> Tile {
    Tile {
        path,
        level,
        geometric_error,
        refine: Refine::Replace,
        transform: DMat4::IDENTITY,
        bounds,
        content,
        children,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leaf(file: u64, counts: &[u64]) -> Value {
        let lods: serde_json::Map<String, Value> = counts
            .iter()
            .enumerate()
            .map(|(l, c)| {
                (
                    l.to_string(),
                    serde_json::json!({"file": file, "offset": 0, "count": c}),
                )
            })
            .collect();
        serde_json::json!({"bound": {"min": [0, 0, 0], "max": [1, 1, 1]}, "lods": lods})
    }

    #[test]
    fn a_leaf_becomes_a_chain_coarsest_on_top_with_errors_from_counts() {
        let v = serde_json::json!({"version": 1, "lodLevels": 2, "counts": [400, 100],
            "filenames": ["0_0/meta.json", "1_0/meta.json"],
            "tree": {"bound": {"min": [0, 0, 0], "max": [1, 1, 1]},
                     "children": [leaf(0, &[200, 50]), leaf(0, &[200, 50])]}});
        let mut problems = Vec::new();
        let root = read(&v, &mut problems).unwrap();
        assert!(problems.is_empty(), "{problems:?}");
        assert!(root.content.is_empty());
        let top = &root.children[0];
        assert_eq!(top.content, ["0_0/meta.json#offset=0&count=50"]);
        assert_eq!(top.geometric_error, level_error(3f64.sqrt(), 50));
        assert!((top.geometric_error - 3.0 * 3f64.sqrt() / 50f64.sqrt()).abs() < 1e-12);
        assert_eq!(root.geometric_error, top.geometric_error);
        let fine = &top.children[0];
        assert_eq!(fine.content, ["0_0/meta.json#offset=0&count=200"]);
        assert_eq!(fine.geometric_error, 0.0);
        assert!(fine.children.is_empty());
        assert_eq!((top.level, fine.level), (1, 2));
        assert_eq!(rows(&fine.content[0]), Some(("0_0/meta.json", 0, 200)));
    }

    #[test]
    fn broken_references_and_wrong_counts_are_problems_at_their_paths() {
        let v = serde_json::json!({"lodLevels": 1, "counts": [9], "filenames": ["a/meta.json"],
            "tree": {"bound": {"min": [0, 0, 0], "max": [1, 1, 1]},
                     "lods": {"0": {"file": 3, "offset": 0, "count": 5}, "7": {"file": 0}}}});
        let mut problems = Vec::new();
        read(&v, &mut problems).unwrap();
        let paths: Vec<&str> = problems.iter().map(|p| p.path.as_str()).collect();
        assert_eq!(
            paths,
            ["tree.lods[\"0\"].file", "tree.lods[\"7\"]", "counts"]
        );
    }

    #[test]
    fn unusable_manifests_are_errors() {
        for (v, want) in [
            (
                serde_json::json!({"version": 2, "lodLevels": 1, "filenames": [], "tree": {}}),
                "version",
            ),
            (
                serde_json::json!({"lodLevels": 0, "filenames": [], "tree": {}}),
                "lodLevels",
            ),
            (
                serde_json::json!({"lodLevels": 1, "filenames": [1], "tree": {}}),
                "filenames",
            ),
            (
                serde_json::json!({"lodLevels": 1, "filenames": [], "tree": 3}),
                "tree",
            ),
        ] {
            let e = read(&v, &mut Vec::new()).unwrap_err();
            assert!(e.starts_with(want), "{e}");
        }
    }
}
