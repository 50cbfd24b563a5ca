//! Building a level-of-detail tree from one cloud (`splatgl convert big.ply out/tileset.json`).
//!
//! The tree is a k-d tree of the splats' means: a set of more than
//! [`BuildOptions::chunk_splats`] splats is split at the median of its longest axis, until
//! every leaf holds at most that many original splats. Every inner tile holds a coarse
//! version of its subtree: its children's content together, [reduced](reduce) to at most
//! `chunk_splats` splats by merging neighbours (groups of the same k-d split) into one Gaussian
//! each, [moment-matched](merge). Refinement is `REPLACE`: drawing a tile's children instead
//! of it trades its merged splats for their finer ones.
//!
//! A tile's `geometricError` is how far its merges moved detail: for each merged group, the
//! spread of its members' means around the merged mean (√ of the largest eigenvalue of their
//! weighted scatter, a standard deviation in scene units); the tile's error is its children's
//! largest error plus [`ERROR_SIGMAS`] × the [`ERROR_QUANTILE`] of its groups' spreads, so
//! errors grow towards the root and leaves (original splats) have 0. See `docs/lod.md` for the merge and what the
//! error means for selection.

use crate::cloud::SplatCloud;
use crate::covariance::{c_matrix, scale_rotation_from_covariance, sym_eigen};
use glam::{DMat3, DVec3};
use serde_json::{Value, json};

/// Options of [`build`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuildOptions {
    /// At most this many splats per tile (leaves hold original splats, inner tiles merged
    /// ones).
    pub chunk_splats: usize,
}

impl BuildOptions {
    /// The default tile size: 65,536 splats (about 3.6 MB of degree-0 glTF content).
    pub const DEFAULT_CHUNK_SPLATS: usize = 65_536;
    /// The smallest tile size [`build`] accepts.
    pub const MIN_CHUNK_SPLATS: usize = 16;
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            chunk_splats: Self::DEFAULT_CHUNK_SPLATS,
        }
    }
}

/// The quantile of a tile's group spreads that its `geometricError` adds to its children's
/// (the largest few merges, often of isolated floaters paired with far neighbours, would
/// otherwise decide the error of the whole tile).
pub const ERROR_QUANTILE: f64 = 0.9;

/// A tile's error counts its merges' spread out to this many standard deviations: the
/// 3σ cut-off splats are drawn to, so a merge that moves detail by a spread σ moves what is
/// drawn by up to 3σ.
pub const ERROR_SIGMAS: f64 = 3.0;

/// One tile of a built tree: what `tileset.json` says of it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuiltTile {
    /// Its name in the tree: `r` for the root, then one digit per level (`r01` is the root's
    /// first child's second child); the content file is named after it.
    pub name: String,
    /// Splats in its content.
    pub splats: usize,
    /// Its geometric error (0 for leaves).
    pub geometric_error: f64,
    /// The smallest and largest mean of its subtree's original splats, in the cloud's frame.
    pub min: [f64; 3],
    /// See `min`.
    pub max: [f64; 3],
    /// Its children (none for a leaf).
    pub children: Vec<BuiltTile>,
}

impl BuiltTile {
    /// This tile and every tile below it, parents first.
    pub fn walk(&self) -> Vec<&BuiltTile> {
        let mut out = vec![self];
        for c in &self.children {
            out.extend(c.walk());
        }
        out
    }
}

/// Where [`build`] puts each tile's content as it is made: `(tile name, content)`. It is
/// called from rayon's threads, in no fixed order.
pub type ContentSink<'a> = dyn Fn(&str, &SplatCloud) -> Result<(), String> + Sync + 'a;

/// Builds the tree over `cloud`, handing each tile's content to `sink`. Errors: an empty
/// cloud, a `chunk_splats` below [`BuildOptions::MIN_CHUNK_SPLATS`], or the sink's first
/// error.
pub fn build(
    cloud: &SplatCloud,
    o: &BuildOptions,
    sink: &ContentSink,
) -> Result<BuiltTile, super::TilesError> {
    use super::TilesError;
    if cloud.is_empty() {
        return Err(TilesError::Empty);
    }
    if o.chunk_splats < BuildOptions::MIN_CHUNK_SPLATS {
        return Err(TilesError::ChunkTooSmall {
            chunk: o.chunk_splats,
            min: BuildOptions::MIN_CHUNK_SPLATS,
        });
    }
    let mut idx: Vec<u32> = (0..cloud.len() as u32).collect();
    let (tile, _) =
        node(cloud, &mut idx, "r".into(), o.chunk_splats, sink).map_err(TilesError::Build)?;
    Ok(tile)
}

/// Builds the subtree over `idx`; returns it with its content.
pub(super) fn node(
    cloud: &SplatCloud,
    idx: &mut [u32],
    name: String,
    chunk: usize,
    sink: &ContentSink,
) -> Result<(BuiltTile, SplatCloud), String> {
    if idx.len() <= chunk {
        let (min, max) = extent(cloud, idx);
        let content = cloud.select(idx);
        sink(&name, &content)?;
        let tile = BuiltTile {
            name,
            splats: content.len(),
            geometric_error: 0.0,
            min,
            max,
            children: Vec::new(),
        };
        return Ok((tile, content));
    }
    let mid = split(cloud, idx, idx.len() / 2);
    let (left, right) = idx.split_at_mut(mid);
    let (a, b) = rayon::join(
        || node(cloud, left, format!("{name}0"), chunk, sink),
        || node(cloud, right, format!("{name}1"), chunk, sink),
    );
    parent(name, a?, b?, chunk, sink)
}

/// The tile `name` over two built subtrees: their content together, [reduced](reduce) to
/// `chunk` splats; its error grows by the merges' spread, its extent is theirs together.
pub(super) fn parent(
    name: String,
    (ta, ca): (BuiltTile, SplatCloud),
    (tb, cb): (BuiltTile, SplatCloud),
    chunk: usize,
    sink: &ContentSink,
) -> Result<(BuiltTile, SplatCloud), String> {
    let mut both = ca;
    both.append(cb);
    let reduced = reduce(&both, chunk);
    sink(&name, &reduced.cloud)?;
    let tile = BuiltTile {
        name,
        splats: reduced.cloud.len(),
        geometric_error: ta.geometric_error.max(tb.geometric_error) + ERROR_SIGMAS * reduced.error,
        min: std::array::from_fn(|k| ta.min[k].min(tb.min[k])),
        max: std::array::from_fn(|k| ta.max[k].max(tb.max[k])),
        children: vec![ta, tb],
    };
    Ok((tile, reduced.cloud))
}

/// The smallest and largest mean of the splats `idx`.
fn extent(cloud: &SplatCloud, idx: &[u32]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in idx {
        for (k, &v) in cloud.positions[i as usize].iter().enumerate() {
            lo[k] = lo[k].min(v as f64);
            hi[k] = hi[k].max(v as f64);
        }
    }
    (lo, hi)
}

/// Reorders `idx` so that its first `at` splats lie below the rest along the longest axis of
/// their extent; returns `at`.
fn split(cloud: &SplatCloud, idx: &mut [u32], at: usize) -> usize {
    let (lo, hi) = extent(cloud, idx);
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let key = |i: &u32| cloud.positions[*i as usize][axis];
    if at > 0 && at < idx.len() {
        idx.select_nth_unstable_by(at, |a, b| key(a).total_cmp(&key(b)));
    }
    at
}

/// A cloud reduced by [`reduce`].
#[derive(Debug, Clone)]
pub struct Reduced {
    /// The merged splats.
    pub cloud: SplatCloud,
    /// The [`ERROR_QUANTILE`] of the merged groups' spreads (0 when nothing was merged).
    pub error: f64,
}

/// Merges `cloud` down to at most `target` splats: the splats are cut into
/// ⌈len / target⌉-sized groups of neighbours by median splits along the longest axis, and
/// each group is [merged](merge) into one splat.
pub fn reduce(cloud: &SplatCloud, target: usize) -> Reduced {
    let target = target.max(1);
    if cloud.len() <= target {
        return Reduced {
            cloud: cloud.clone(),
            error: 0.0,
        };
    }
    let mut idx: Vec<u32> = (0..cloud.len() as u32).collect();
    let mut groups = Vec::with_capacity(target);
    partition(cloud, &mut idx, 0, target, &mut groups);
    let merged: Vec<(Merged, f64)> = {
        use rayon::prelude::*;
        groups
            .par_iter()
            .map(|r| merge(cloud, &idx[r.clone()]))
            .collect()
    };
    let mut out = SplatCloud::with_capacity(cloud.sh_degree, merged.len());
    out.meta = cloud.meta.clone();
    let mut spreads = Vec::with_capacity(merged.len());
    for (m, spread) in &merged {
        out.push(m.position, m.scale, m.rotation, m.opacity, &m.sh);
        if m.members > 1 {
            spreads.push(*spread);
        }
    }
    Reduced {
        cloud: out,
        error: quantile(&mut spreads, ERROR_QUANTILE),
    }
}

/// Cuts `idx` (starting at `base` of the whole index list) into `groups` ranges of nearly
/// equal size by median splits.
fn partition(
    cloud: &SplatCloud,
    idx: &mut [u32],
    base: usize,
    groups: usize,
    out: &mut Vec<std::ops::Range<usize>>,
) {
    if groups <= 1 || idx.len() <= 1 {
        out.push(base..base + idx.len());
        return;
    }
    let left_groups = groups / 2;
    let at = split(cloud, idx, idx.len() * left_groups / groups);
    let (l, r) = idx.split_at_mut(at);
    partition(cloud, l, base, left_groups, out);
    partition(cloud, r, base + at, groups - left_groups, out);
}

/// The `q` quantile of `v` (0 when empty).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let k = ((v.len() - 1) as f64 * q).round() as usize;
    let (_, x, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    *x
}

/// One splat made by [`merge`].
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// Mean.
    pub position: [f32; 3],
    /// Scales (standard deviations).
    pub scale: [f32; 3],
    /// Rotation `[x, y, z, w]`.
    pub rotation: [f32; 4],
    /// Opacity.
    pub opacity: f32,
    /// SH coefficients, as many as the cloud's degree has.
    pub sh: Vec<[f32; 3]>,
    /// How many splats it stands for.
    pub members: usize,
}

/// A splat's weight in a merge: its opacity × its area (the product of its two largest
/// standard deviations; a splat is mostly a disc), what it contributes to an image.
fn weight_and_area(cloud: &SplatCloud, i: usize) -> (f64, f64) {
    let mut s = cloud.scales[i].map(f64::from);
    s.sort_by(|a, b| b.total_cmp(a));
    let area = s[0] * s[1];
    (cloud.opacities[i] as f64 * area, area)
}

/// Merges the splats `members` of `cloud` into one Gaussian by moment matching, weighted by
/// opacity × area (the product of its two largest standard deviations) `wᵢ`: the mean μ = Σwᵢμᵢ / W, the covariance
/// Σ = Σwᵢ(Σᵢ + (μᵢ−μ)(μᵢ−μ)ᵀ) / W, the SH coefficients the weighted mean of theirs, and
/// the opacity W / area(Σ) — the combined weight over the merged area — but never more than
/// 1 − Π(1 − αᵢ), their opacity stacked on one another (splats that overlap composite, they
/// do not add up). Returns the splat and the spread of the members' means: √ of the largest
/// eigenvalue of Σwᵢ(μᵢ−μ)(μᵢ−μ)ᵀ / W. Zero weights (transparent or flat splats) fall back
/// to opacity, then to equal weights.
pub fn merge(cloud: &SplatCloud, members: &[u32]) -> (Merged, f64) {
    let k = cloud.coeffs_per_splat();
    let wa: Vec<(f64, f64)> = members
        .iter()
        .map(|&i| weight_and_area(cloud, i as usize))
        .collect();
    let sum_w: f64 = wa.iter().map(|x| x.0).sum();
    let sum_a: f64 = members
        .iter()
        .map(|&i| cloud.opacities[i as usize] as f64)
        .sum();
    let weight = |j: usize| -> f64 {
        if sum_w > 0.0 {
            wa[j].0 / sum_w
        } else if sum_a > 0.0 {
            cloud.opacities[members[j] as usize] as f64 / sum_a
        } else {
            1.0 / members.len() as f64
        }
    };
    let mut mean = DVec3::ZERO;
    let mut sh = vec![[0.0f64; 3]; k];
    for (j, &i) in members.iter().enumerate() {
        let w = weight(j);
        mean += w * DVec3::from(cloud.positions[i as usize].map(f64::from));
        for (acc, c) in sh.iter_mut().zip(cloud.sh_of(i as usize)) {
            for ch in 0..3 {
                acc[ch] += w * c[ch] as f64;
            }
        }
    }
    let mut cov = DMat3::ZERO;
    let mut scatter = DMat3::ZERO;
    for (j, &i) in members.iter().enumerate() {
        let i = i as usize;
        let w = weight(j);
        let c = c_matrix(cloud.scales[i], cloud.rotations[i]);
        let d = DVec3::from(cloud.positions[i].map(f64::from)) - mean;
        let dd = outer(d);
        cov += (c * c.transpose() + dd) * w;
        scatter += dd * w;
    }
    let (scale, rotation) = scale_rotation_from_covariance(cov);
    let stacked = 1.0
        - members
            .iter()
            .map(|&i| 1.0 - cloud.opacities[i as usize] as f64)
            .product::<f64>();
    let mut s = scale.map(f64::from);
    s.sort_by(|a, b| b.total_cmp(a));
    let area = s[0] * s[1];
    let opacity = if area > 0.0 && sum_w > 0.0 {
        (sum_w / area).min(stacked)
    } else {
        stacked
    };
    let spread = sym_eigen(scatter).0.max_element().max(0.0).sqrt();
    let merged = Merged {
        position: mean.to_array().map(|v| v as f32),
        scale,
        rotation,
        opacity: opacity.clamp(0.0, 1.0) as f32,
        sh: sh.iter().map(|c| c.map(|v| v as f32)).collect(),
        members: members.len(),
    };
    (merged, spread)
}

/// d dᵀ.
fn outer(d: DVec3) -> DMat3 {
    DMat3::from_cols(d * d.x, d * d.y, d * d.z)
}

/// The `tileset.json` of a built tree (3D Tiles 1.1): each tile's content at `uri(name)`, a
/// `box` around its splats' means, its `geometricError`, `refine: REPLACE` at the root. The
/// content is glTF (y-up), which 3D Tiles turns z-up, so the boxes are turned the same way
/// (glTF (x, y, z) is (x, −z, y) in the tileset). `content_extensions` are the glTF
/// extensions every content uses and requires, listed in `3DTILES_content_gltf` (CesiumJS
/// reads the content as splats only when they are). Every box grows by `margin` on each side:
/// the content's position rounding (SPZ's fixed point), so encoded centres stay inside.
pub fn tileset_json(
    root: &BuiltTile,
    uri: &dyn Fn(&str) -> String,
    content_extensions: &[&str],
    margin: f64,
) -> Value {
    json!({
        "asset": { "version": "1.1", "generator": concat!("splatgl ", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": ["3DTILES_content_gltf"],
        "extensions": { "3DTILES_content_gltf": {
            "extensionsUsed": content_extensions,
            "extensionsRequired": content_extensions,
        } },
        "geometricError": tileset_error(root),
        "root": tile_json(root, uri, margin, true),
    })
}

/// The tileset's own geometric error (the error of drawing nothing): twice the root's, or the
/// root's extent when the root is a leaf.
fn tileset_error(root: &BuiltTile) -> f64 {
    if root.geometric_error > 0.0 {
        2.0 * root.geometric_error
    } else {
        (0..3)
            .map(|k| root.max[k] - root.min[k])
            .fold(0.0, f64::max)
    }
}

fn tile_json(t: &BuiltTile, uri: &dyn Fn(&str) -> String, margin: f64, root: bool) -> Value {
    let c = |k: usize| (t.min[k] + t.max[k]) / 2.0;
    let h = |k: usize| (t.max[k] - t.min[k]) / 2.0 + margin.max(0.0);
    // glTF (x, y, z) → tileset (x, −z, y): the half axes along x, along −z (length h_z, as y),
    // along y (length h_y, as z).
    let bx = [
        c(0),
        -c(2),
        c(1),
        h(0),
        0.0,
        0.0,
        0.0,
        h(2),
        0.0,
        0.0,
        0.0,
        h(1),
    ];
    let mut v = json!({
        "boundingVolume": { "box": bx },
        "geometricError": t.geometric_error,
        "content": { "uri": uri(&t.name) },
    });
    if root {
        v["refine"] = json!("REPLACE");
    }
    if !t.children.is_empty() {
        v["children"] = Value::Array(
            t.children
                .iter()
                .map(|c| tile_json(c, uri, margin, false))
                .collect(),
        );
    }
    v
}

#[cfg(test)]
mod tests;
