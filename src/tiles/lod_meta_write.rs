//! A built tree ([`super::build`]) laid out as PlayCanvas's streamed SOG (`lod-meta.json`, the
//! layout `@playcanvas/splat-transform` 3.7 writes and [`super::lod_meta`] reads).
//!
//! The format keeps every LOD level at the granularity of the tree's leaves: a leaf node names,
//! per level (0 the finest), a run of splats in one SOG unit. So the tree's leaves are the
//! manifest's leaves, with their original splats as level 0, and each inner tile `j` levels
//! above a leaf gives that leaf the part of its merged content that lies on the leaf's side:
//! each merged splat goes down from its tile to the child whose box (the extent of its
//! subtree's means) is nearest to its mean, until it reaches a leaf. Per level, the leaves'
//! parts are packed in tree order into units of about `unit_splats` (`{level}_{k}/meta.json`,
//! as splat-transform names them); a node's `bound` is the extent of the means of every level
//! it holds. A leaf whose share of a coarse tile is empty has no entry for that level. Where
//! the tree's leaves lie at different depths (a split leaving one half just over the chunk
//! size), level `j` of two leaves may come from tiles at different depths; `geometricErrors`
//! carries each leaf's own. Each
//! leaf also carries its levels' geometric errors (`geometricErrors`: 0, then the errors of
//! the tiles its levels come from, in scene units as in a tileset), a key of splatgl's own
//! that other readers ignore, so splatgl selects from it as from the tileset.

use super::BuiltTile;
use crate::cloud::SplatCloud;
use serde_json::{Map, Value, json};
use std::collections::HashMap;

/// The smallest and largest corner of a set of means.
type Extent = ([f64; 3], [f64; 3]);

/// What [`layout`] makes: the manifest and the SOG units it names, `(file name, splats)`.
pub struct LodMetaLayout {
    /// `lod-meta.json`.
    pub manifest: Value,
    /// Each unit's name (as in `filenames`) and splats, in `filenames` order.
    pub units: Vec<(String, SplatCloud)>,
}

/// One leaf's part of a level: the tile it comes from and which of its splats.
struct Part<'a> {
    tile: &'a str,
    splats: Vec<u32>,
}

/// Each leaf's parts, by level: `parts[leaf][level]`.
type Parts<'a> = HashMap<&'a str, Vec<Option<Part<'a>>>>;

/// Units per level, and each leaf's `(file, offset, count)` per level.
type Units<'a> = (
    Vec<(String, SplatCloud)>,
    HashMap<&'a str, Map<String, Value>>,
    Vec<u64>,
);

/// The content of tile `name`, or the error naming it.
fn content_of<'c>(
    contents: &'c HashMap<String, SplatCloud>,
    name: &str,
) -> Result<&'c SplatCloud, super::TilesError> {
    contents
        .get(name)
        .ok_or_else(|| super::TilesError::Build(format!("tile {name}: no content")))
}

/// Lays out `root`'s tree (each tile's content in `contents`, by name) as a streamed SOG with
/// units of about `unit_splats`. `Err` when a tile's content is missing.
pub fn layout(
    root: &BuiltTile,
    contents: &HashMap<String, SplatCloud>,
    unit_splats: usize,
) -> Result<LodMetaLayout, super::TilesError> {
    let leaves = leaves_below(root);
    let parts = leaf_parts(root, &leaves, contents)?;
    let levels = parts.values().map(Vec::len).max().unwrap_or(1);
    let (units, mut refs, counts) = pack_units(&leaves, &parts, contents, levels, unit_splats)?;
    let bounds = |leaf: &str| -> Extent {
        let mut b = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for part in parts[leaf].iter().flatten() {
            let c = &contents[part.tile];
            for &i in &part.splats {
                for a in 0..3 {
                    let x = c.positions[i as usize][a] as f64;
                    b.0[a] = b.0[a].min(x);
                    b.1[a] = b.1[a].max(x);
                }
            }
        }
        b
    };
    let errors = leaf_errors(root, levels);
    let (tree, _) = node(root, &mut refs, &errors, &bounds);
    let filenames: Vec<&str> = units.iter().map(|(n, _)| n.as_str()).collect();
    let manifest = json!({
        "version": 1,
        "asset": {"generator": concat!("splatgl ", env!("CARGO_PKG_VERSION"))},
        "count": counts.iter().sum::<u64>(),
        "counts": counts,
        "lodLevels": levels,
        "filenames": filenames,
        "tree": tree,
    });
    Ok(LodMetaLayout { manifest, units })
}

/// Each leaf's parts by level: its own splats at level 0, then at each ancestor's level the
/// ancestor's splats that descend to it.
fn leaf_parts<'a>(
    root: &'a BuiltTile,
    leaves: &[&'a BuiltTile],
    contents: &HashMap<String, SplatCloud>,
) -> Result<Parts<'a>, super::TilesError> {
    let depth = |t: &BuiltTile| t.name.len() - 1;
    let mut parts: Parts = HashMap::new();
    for l in leaves {
        let all = (0..content_of(contents, &l.name)?.len() as u32).collect();
        parts.insert(
            &l.name,
            vec![Some(Part {
                tile: &l.name,
                splats: all,
            })],
        );
    }
    for t in root.walk().into_iter().filter(|t| !t.children.is_empty()) {
        let c = content_of(contents, &t.name)?;
        let mut by_leaf: HashMap<&str, Vec<u32>> = HashMap::new();
        for (i, p) in c.positions.iter().enumerate() {
            let leaf = descend(t, *p);
            by_leaf.entry(&leaf.name).or_default().push(i as u32);
        }
        for (leaf, splats) in by_leaf {
            let level = leaf.len() - 1 - depth(t);
            let slots = parts.get_mut(leaf).expect("every leaf has parts");
            if slots.len() <= level {
                slots.resize_with(level + 1, || None);
            }
            slots[level] = Some(Part {
                tile: &t.name,
                splats,
            });
        }
    }
    Ok(parts)
}

/// Units per level, leaves in tree order, each of about `unit_splats`.
fn pack_units<'a>(
    leaves: &[&'a BuiltTile],
    parts: &Parts<'a>,
    contents: &HashMap<String, SplatCloud>,
    levels: usize,
    unit_splats: usize,
) -> Result<Units<'a>, super::TilesError> {
    let mut units: Vec<(String, SplatCloud)> = Vec::new();
    let mut refs: HashMap<&str, Map<String, Value>> = HashMap::new();
    let mut counts = vec![0u64; levels];
    for (level, count) in counts.iter_mut().enumerate() {
        let mut current: Option<usize> = None;
        let mut k = 0;
        for l in leaves {
            let Some(Some(part)) = parts[l.name.as_str()].get(level) else {
                continue;
            };
            let cloud = content_of(contents, part.tile)?.select(&part.splats);
            let full = current.is_some_and(|u| units[u].1.len() + cloud.len() > unit_splats);
            if current.is_none() || full && !units[current.unwrap()].1.is_empty() {
                units.push((format!("{level}_{k}/meta.json"), SplatCloud::default()));
                current = Some(units.len() - 1);
                k += 1;
            }
            let u = current.unwrap();
            let offset = units[u].1.len();
            *count += cloud.len() as u64;
            refs.entry(&l.name).or_default().insert(
                level.to_string(),
                json!({"file": u, "offset": offset, "count": cloud.len()}),
            );
            if units[u].1.is_empty() {
                units[u].1 = cloud;
            } else {
                units[u].1.append(cloud);
            }
        }
    }
    Ok((units, refs, counts))
}

/// Each leaf's error per level: 0 for its own splats, then each ancestor's geometric error
/// (levels a leaf lacks take its next finer one's).
fn leaf_errors(root: &BuiltTile, levels: usize) -> HashMap<&str, Vec<f64>> {
    let mut errors: HashMap<&str, Vec<f64>> = HashMap::new();
    for t in root.walk() {
        for l in leaves_below(t) {
            let e = errors
                .entry(&l.name)
                .or_insert_with(|| vec![f64::NAN; levels]);
            e[l.name.len() - t.name.len()] = t.geometric_error;
        }
    }
    for e in errors.values_mut() {
        for k in 1..levels {
            if e[k].is_nan() {
                e[k] = e[k - 1];
            }
        }
    }
    errors
}

/// The leaf below `t` that a splat at `p` goes to: at each tile, the child whose box is
/// nearest (0 inside it; the first on a tie).
fn descend(t: &BuiltTile, p: [f32; 3]) -> &BuiltTile {
    let mut at = t;
    while !at.children.is_empty() {
        at = at
            .children
            .iter()
            .min_by(|a, b| box_distance(a, p).total_cmp(&box_distance(b, p)))
            .expect("not empty");
    }
    at
}

fn box_distance(t: &BuiltTile, p: [f32; 3]) -> f64 {
    (0..3)
        .map(|a| {
            let x = p[a] as f64;
            let d = (t.min[a] - x).max(x - t.max[a]).max(0.0);
            d * d
        })
        .sum()
}

/// The leaves of `t`'s subtree (`t` itself for a leaf).
fn leaves_below(t: &BuiltTile) -> Vec<&BuiltTile> {
    t.walk()
        .into_iter()
        .filter(|x| x.children.is_empty())
        .collect()
}

/// The manifest node of `t` and its bound.
fn node(
    t: &BuiltTile,
    refs: &mut HashMap<&str, Map<String, Value>>,
    errors: &HashMap<&str, Vec<f64>>,
    bounds: &dyn Fn(&str) -> Extent,
) -> (Value, Extent) {
    if t.children.is_empty() {
        let b = bounds(&t.name);
        let lods = refs.remove(t.name.as_str()).unwrap_or_default();
        let e = &errors[t.name.as_str()];
        return (
            json!({"bound": {"min": b.0, "max": b.1}, "lods": lods, "geometricErrors": e}),
            b,
        );
    }
    let (kids, boxes): (Vec<Value>, Vec<_>) = t
        .children
        .iter()
        .map(|c| node(c, refs, errors, bounds))
        .unzip();
    let b = boxes.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), (l, h)| {
            (
                std::array::from_fn(|a| lo[a].min(l[a])),
                std::array::from_fn(|a| hi[a].max(h[a])),
            )
        },
    );
    (
        json!({"bound": {"min": b.0, "max": b.1}, "children": kids}),
        b,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tiles::{BuildOptions, build};
    use std::sync::Mutex;

    #[test]
    fn every_tiles_splats_land_once_at_their_level_and_the_manifest_reads_back_clean() {
        let cloud = crate::synthetic::random_cloud(2000, 1, 1.0, 5);
        let contents = Mutex::new(HashMap::new());
        let root = build(&cloud, &BuildOptions { chunk_splats: 200 }, &|n, c| {
            contents.lock().unwrap().insert(n.to_owned(), c.clone());
            Ok(())
        })
        .unwrap();
        let contents = contents.into_inner().unwrap();
        let out = layout(&root, &contents, 300).unwrap();
        let m = &out.manifest;
        // Level j holds the content of the tiles j levels above the leaves, once each (this
        // tree is balanced: 2000 splats halve evenly to 16 leaves of 125).
        let levels = m["lodLevels"].as_u64().unwrap() as usize;
        for (j, count) in m["counts"].as_array().unwrap().iter().enumerate() {
            let want: usize = root
                .walk()
                .iter()
                .filter(|t| {
                    t.name.len() + j == root.walk().iter().map(|l| l.name.len()).max().unwrap()
                })
                .map(|t| t.splats)
                .sum();
            assert_eq!(count.as_u64().unwrap() as usize, want, "level {j}");
        }
        assert_eq!(m["counts"][0], cloud.len());
        // Units of at most 300 splats (every part here is ≤ 200), none empty.
        for (name, unit) in &out.units {
            assert!((1..=300).contains(&unit.len()), "{name}: {}", unit.len());
        }
        let mut problems = Vec::new();
        let tree = crate::tiles::lod_meta::read(m, &mut problems).unwrap();
        assert!(problems.is_empty(), "{problems:?}");
        // Each leaf's chain has every level, its errors the tree's (0 at the leaf).
        let chains = tree
            .walk()
            .into_iter()
            .filter(|t| !t.content.is_empty())
            .count();
        assert_eq!(
            chains,
            levels * root.walk().iter().filter(|t| t.children.is_empty()).count()
        );
        assert_eq!(tree.geometric_error, root.geometric_error);
    }
}
