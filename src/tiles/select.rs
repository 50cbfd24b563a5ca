//! Choosing the tiles to draw for one camera: by screen-space error, coarse to fine, never more
//! than a splat budget ([`select`]); and the clouds of the chosen tiles, loaded once, in the
//! tileset's frame ([`TileCache`]).

use super::{Refine, Tile, Tileset};
use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::load::LoadOptions;
use glam::{DMat4, DVec3};
use std::collections::HashMap;

/// What [`select`] aims for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelectOptions {
    /// At most this many splats are selected (`--splat-budget`).
    pub splat_budget: u64,
    /// A floor: a tile whose screen-space error is at or below this many pixels is not
    /// refined, budget or not (`--max-screen-error`). Above it, tiles are refined largest
    /// error first until the next refinement would pass the budget: the budget is filled.
    pub max_screen_error: f64,
}

impl SelectOptions {
    /// The default budget: 1,000,000 splats, which software GL (llvmpipe) still draws at
    /// interactive rates; a desktop GPU takes 2.5M and more.
    pub const DEFAULT_SPLAT_BUDGET: u64 = 1_000_000;
    /// The default floor of the screen-space error: 1 px. The budget, not the error, ends
    /// the refinement (CesiumJS's per-tile 16 px stopped a 4M-splat city at 458,752 of a
    /// 1,000,000 budget, 28.4 dB; at 1 px it fills it: docs/lod.md, "Spending the budget").
    pub const DEFAULT_MAX_SCREEN_ERROR: f64 = 1.0;
}

impl Default for SelectOptions {
    fn default() -> Self {
        SelectOptions {
            splat_budget: Self::DEFAULT_SPLAT_BUDGET,
            max_screen_error: Self::DEFAULT_MAX_SCREEN_ERROR,
        }
    }
}

/// The tiles chosen for one camera.
#[derive(Debug, Clone)]
pub struct Selection<'a> {
    /// The tiles to draw (their content together is the view's scene).
    pub tiles: Vec<&'a Tile>,
    /// Their splats.
    pub splats: u64,
    /// Tiles whose screen-space error is still above the target because refining them would
    /// have passed the budget.
    pub held_back: usize,
}

/// The screen-space error of `t` seen by `cam` (pixels): its geometric error over the distance
/// from the eye to its bounding sphere, times the focal length; infinite inside the sphere, 0
/// without a volume.
pub fn screen_space_error(t: &Tile, cam: &Camera) -> f64 {
    let Some(b) = t.bounds else {
        return 0.0;
    };
    let (c, r) = b.sphere();
    let eye = cam.eye();
    let d = (c - DVec3::new(eye.x as f64, eye.y as f64, eye.z as f64)).length() - r;
    if d <= 0.0 {
        return f64::INFINITY;
    }
    t.geometric_error * cam.fy.max(cam.fx) as f64 / d
}

/// Whether `t`'s bounding sphere reaches into `cam`'s view (the four side planes and the
/// plane of the eye; tiles without a volume are taken as visible).
pub fn visible(t: &Tile, cam: &Camera) -> bool {
    let Some(b) = t.bounds else {
        return true;
    };
    let (c, r) = b.sphere();
    let m = cam.world_to_camera.as_dmat4();
    let p = m.transform_point3(c); // OpenCV axes: +z ahead
    let (w, h) = (cam.width as f64, cam.height as f64);
    let (fx, fy, cx, cy) = (cam.fx as f64, cam.fy as f64, cam.cx as f64, cam.cy as f64);
    let side = |n: DVec3| n.normalize().dot(p) <= r;
    p.z >= -r
        && side(DVec3::new(1.0, 0.0, -(w - cx) / fx))
        && side(DVec3::new(-1.0, 0.0, -cx / fx))
        && side(DVec3::new(0.0, 1.0, -(h - cy) / fy))
        && side(DVec3::new(0.0, -1.0, -cy / fy))
}

/// The tiles to draw for `cam`: the root, then — largest screen-space error first — each
/// visible tile above `o.max_screen_error` is refined (its visible children added; with
/// `REPLACE` the tile itself leaves) when the selection stays within `o.splat_budget`
/// splats. A tile without splats (no content, or content that did not load) is refined
/// first and whatever its error (as CesiumJS does with empty tiles): it draws nothing, so the
/// coarsest content below it covers the view before any finer tile takes budget. `splats(tile)` counts a tile's content (loading it). `Err` when the root alone
/// holds more than the budget.
pub fn select<'a>(
    ts: &'a Tileset,
    cam: &Camera,
    o: &SelectOptions,
    splats: &mut dyn FnMut(&'a Tile) -> u64,
) -> Result<Selection<'a>, super::TilesError> {
    let root = &ts.root;
    let mut used = splats(root);
    if used > o.splat_budget {
        return Err(super::TilesError::OverBudget {
            splats: used,
            budget: o.splat_budget,
        });
    }
    let mut chosen: Vec<&Tile> = vec![root];
    let mut open: Vec<(f64, &Tile)> = vec![(priority(root, used, cam), root)];
    // Refinements that did not fit: tried again when a later one frees splats (a tile whose
    // visible children hold fewer splats than itself).
    let mut waiting: Vec<(f64, &Tile)> = Vec::new();
    while let Some(i) = largest(&open) {
        let (sse, t) = open.swap_remove(i);
        let fine_enough = sse <= o.max_screen_error && splats(t) > 0;
        if fine_enough || t.children.is_empty() || !visible(t, cam) {
            continue;
        }
        let kids: Vec<&Tile> = t.children.iter().filter(|c| visible(c, cam)).collect();
        let cost: u64 = kids.iter().map(|c| splats(c)).sum();
        let freed = match t.refine {
            Refine::Replace => splats(t),
            Refine::Add => 0,
        };
        if used - freed + cost > o.splat_budget {
            waiting.push((sse, t));
            continue;
        }
        if cost < freed {
            open.append(&mut waiting);
        }
        used = used - freed + cost;
        if t.refine == Refine::Replace {
            chosen.retain(|c| !std::ptr::eq(*c, t));
        }
        for c in kids {
            chosen.push(c);
            open.push((priority(c, splats(c), cam), c));
        }
    }
    Ok(Selection {
        tiles: chosen,
        splats: used,
        held_back: waiting.len(),
    })
}

/// The order in which open tiles are refined: tiles without splats first, then by
/// screen-space error.
fn priority(t: &Tile, splats: u64, cam: &Camera) -> f64 {
    match splats {
        0 => f64::INFINITY,
        _ => screen_space_error(t, cam),
    }
}

/// The index of the largest error in `open`.
fn largest(open: &[(f64, &Tile)]) -> Option<usize> {
    (0..open.len()).max_by(|&a, &b| open[a].0.total_cmp(&open[b].0))
}

/// glTF content is y-up; 3D Tiles turns it to z-up before the tile's transform.
pub const Y_UP_TO_Z_UP: DMat4 = DMat4::from_cols_array(&[
    1.0, 0.0, 0.0, 0.0, //
    0.0, 0.0, 1.0, 0.0, //
    0.0, -1.0, 0.0, 0.0, //
    0.0, 0.0, 0.0, 1.0,
]);

/// Each tile's content, loaded once, in the tileset's frame ([`Tileset::content_frame`], then
/// the tile's transform). A content file that is missing, outside the tileset's folder or does not load
/// is skipped with a warning, so the rest still draws.
///
/// With a memory cap ([`TileCache::with_max_bytes`]) the least recently used tiles are
/// evicted when a frame starts or a load takes it over the cap — except tiles used since the last
/// [`TileCache::next_frame`], which the frame being assembled needs (so the cache can hold
/// more than the cap while one frame's selection alone is larger).
pub struct TileCache<'a> {
    ts: &'a Tileset,
    opts: LoadOptions,
    clouds: HashMap<String, Entry>,
    max_bytes: u64,
    bytes: u64,
    frame: u64,
    tick: u64,
    /// Tiles evicted so far.
    pub evictions: u64,
    /// Tile loads so far (a tile evicted and needed again counts again).
    pub loads: u64,
    /// What was skipped: one line per content file, except that content failing with the
    /// same error as an earlier one (the leaves of one broken streamed-SOG unit) only counts
    /// in [`TileCache::skipped_alike`].
    pub warnings: Vec<String>,
    /// Content files skipped with an error already in `warnings`.
    pub skipped_alike: u64,
    errors_seen: std::collections::HashSet<String>,
}

/// A resident tile: its content and when it was last used.
struct Entry {
    cloud: std::sync::Arc<SplatCloud>,
    bytes: u64,
    frame: u64,
    tick: u64,
}

/// Bytes a cloud holds in memory (its arrays).
fn cloud_bytes(c: &SplatCloud) -> u64 {
    (c.len() * (12 + 12 + 16 + 4) + c.sh.len() * 12) as u64
}

impl<'a> TileCache<'a> {
    /// A cache for `ts`, loading with `opts` (limits, containment), without a memory cap.
    pub fn new(ts: &'a Tileset, opts: &LoadOptions) -> Self {
        TileCache {
            ts,
            opts: opts.clone(),
            clouds: HashMap::new(),
            max_bytes: u64::MAX,
            bytes: 0,
            frame: 0,
            tick: 0,
            evictions: 0,
            loads: 0,
            warnings: Vec::new(),
            skipped_alike: 0,
            errors_seen: Default::default(),
        }
    }

    /// The same, keeping at most about `max_bytes` of tile content resident.
    pub fn with_max_bytes(ts: &'a Tileset, opts: &LoadOptions, max_bytes: u64) -> Self {
        TileCache {
            max_bytes,
            ..Self::new(ts, opts)
        }
    }

    /// Starts a new frame: tiles used before it may be evicted again, and are, least
    /// recently used first, while the cache is over its cap.
    pub fn next_frame(&mut self) {
        self.frame += 1;
        self.evict();
    }

    /// Bytes of tile content resident now.
    pub fn resident_bytes(&self) -> u64 {
        self.bytes
    }

    /// Tiles resident now.
    pub fn resident_tiles(&self) -> usize {
        self.clouds.len()
    }

    /// Tile `t`'s content (all its content files), loaded when it is not resident.
    pub fn cloud(&mut self, t: &Tile) -> &SplatCloud {
        if self.peek(t).is_none() {
            let (cloud, failed) = self.read(t);
            self.note(t, failed);
            self.insert(t, cloud);
        }
        &self.clouds[&t.path].cloud
    }

    /// Tile `t`'s content as [`TileCache::cloud`], shared (no copy).
    pub fn shared(&mut self, t: &Tile) -> std::sync::Arc<SplatCloud> {
        self.cloud(t);
        self.clouds[&t.path].cloud.clone()
    }

    /// The splats of `t` if it is resident (and marks it used), without loading it.
    pub fn peek(&mut self, t: &Tile) -> Option<u64> {
        self.tick += 1;
        let (frame, tick) = (self.frame, self.tick);
        let e = self.clouds.get_mut(&t.path)?;
        (e.frame, e.tick) = (frame, tick);
        Some(e.cloud.len() as u64)
    }

    /// Loads those of `tiles` that are not resident, reading their content in parallel (the
    /// loading pool: rayon's threads), in the order given for what does not fit the cap.
    pub fn load_all(&mut self, tiles: &[&Tile]) {
        use rayon::prelude::*;
        let todo: Vec<&Tile> = tiles
            .iter()
            .copied()
            .filter(|t| !self.clouds.contains_key(&t.path))
            .collect();
        let read: Vec<_> = todo.par_iter().map(|t| self.read(t)).collect();
        for (t, (cloud, failed)) in todo.into_iter().zip(read) {
            self.note(t, failed);
            self.insert(t, cloud);
        }
    }

    /// Makes `cloud` tile `t`'s resident content, used now.
    fn insert(&mut self, t: &Tile, cloud: SplatCloud) {
        self.tick += 1;
        self.loads += 1;
        let bytes = cloud_bytes(&cloud);
        self.bytes += bytes;
        self.evict();
        let e = Entry {
            cloud: cloud.into(),
            bytes,
            frame: self.frame,
            tick: self.tick,
        };
        self.clouds.insert(t.path.clone(), e);
    }

    /// Evicts least recently used tiles of earlier frames while the cache is over its cap.
    fn evict(&mut self) {
        while self.bytes > self.max_bytes {
            let oldest = self
                .clouds
                .iter()
                .filter(|(_, e)| e.frame < self.frame)
                .min_by_key(|(_, e)| e.tick)
                .map(|(k, _)| k.clone());
            let Some(k) = oldest else { break };
            if let Some(e) = self.clouds.remove(&k) {
                self.bytes -= e.bytes;
                self.evictions += 1;
            }
        }
    }

    /// The splats of tile `t`'s content.
    pub fn splats(&mut self, t: &Tile) -> u64 {
        self.cloud(t).len() as u64
    }

    /// The content of `tiles` as one cloud (SH degrees unified by zero-padding; the metadata —
    /// colour space, kernel — of the first tile with splats).
    pub fn merged(&mut self, tiles: &[&Tile]) -> SplatCloud {
        let mut out = SplatCloud::new(0);
        for t in tiles {
            join(&mut out, SplatCloud::clone(self.cloud(t)));
        }
        out
    }

    /// Tile `t`'s content files joined, and the ones that failed (URI, why).
    fn read(&self, t: &Tile) -> (SplatCloud, Vec<(String, String)>) {
        let mut out = SplatCloud::new(0);
        let mut failed = Vec::new();
        for uri in &t.content {
            match self.load_one(t, uri) {
                Ok(c) => join(&mut out, c),
                Err(e) => failed.push((uri.clone(), e)),
            }
        }
        (out, failed)
    }

    /// Warns of `t`'s failed content, once per distinct error.
    fn note(&mut self, t: &Tile, failed: Vec<(String, String)>) {
        for (uri, e) in failed {
            if self.errors_seen.contains(&e) {
                self.skipped_alike += 1;
            } else {
                self.warnings
                    .push(format!("{}: {uri:?} skipped: {e}", t.path));
                self.errors_seen.insert(e);
            }
        }
    }

    fn load_one(&self, t: &Tile, uri: &str) -> Result<SplatCloud, String> {
        let scene = self
            .ts
            .load_content(uri, &self.opts)
            .map_err(|e| e.to_string())?;
        let mut findings = Vec::new();
        crate::load::gltf::apply_node_transform(
            &scene.cloud,
            t.transform * self.ts.content_frame(),
            0,
            &mut findings,
        )
        .ok_or_else(|| {
            let why: Vec<String> = findings.iter().map(|f| f.message.clone()).collect();
            format!("the tile transform breaks its splats: {}", why.join("; "))
        })
    }
}

/// Appends `c` to `out`, taking `c`'s metadata when `out` has no splats yet.
pub(super) fn join(out: &mut SplatCloud, c: SplatCloud) {
    if out.is_empty() {
        out.meta = c.meta.clone();
    }
    out.append(c);
}
