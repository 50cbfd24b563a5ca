//! Streaming a tileset while the camera moves (the viewer's tilesets): a [`Streamer`] thread
//! owns the [`TileCache`] and, for the newest camera it was given, selects among the tiles
//! already resident — so the view is never empty and never waits — while it loads the tiles that
//! selection wanted next, a few at a time and in parallel, in the order selection asked for
//! them (largest screen-space error first), then selects again. Each time the selection
//! changes it publishes the selected tiles' content ([`StreamFrame`]), and the counts
//! alone for the first camera and when nothing is left to load, so a caller knows the view is
//! complete. Once nothing is pending for a camera, the selection is the one [`select`] makes
//! loading everything at once (every tile it asked about is then resident): the same image as
//! `render` of that camera, whatever order the tiles arrived in.

use super::select::{SelectOptions, Selection, TileCache, select};
use super::{Tile, Tileset};
use crate::camera::Camera;
use crate::cloud::SplatCloud;
use crate::load::LoadOptions;
use std::sync::{Arc, Condvar, Mutex, mpsc};
use std::thread::JoinHandle;

/// Tiles loaded between two selections (read in parallel).
pub const LOAD_BATCH: usize = 8;

/// What a [`Streamer`] is asked to keep to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamSettings {
    /// The selection's budget and screen-space error.
    pub select: SelectOptions,
    /// Resident tile content is kept within about this many bytes (`--cache-mb`).
    pub cache_bytes: u64,
}

impl Default for StreamSettings {
    /// The default selection, and 2 GB of tile content.
    fn default() -> Self {
        StreamSettings {
            select: SelectOptions::default(),
            cache_bytes: 2048 << 20,
        }
    }
}

/// One published state of the stream.
#[derive(Debug, Clone)]
pub struct StreamFrame {
    /// The selected tiles (path, content in the tileset's frame), when the selection changed
    /// (`None`: only the counts did).
    pub selection: Option<Vec<(String, Arc<SplatCloud>)>>,
    /// Tiles selected.
    pub tiles: usize,
    /// Splats selected.
    pub splats: u64,
    /// The budget they are within.
    pub budget: u64,
    /// Tiles the selection wanted that are not loaded yet (0: the view is complete).
    pub pending: usize,
    /// Tiles resident in the cache.
    pub resident_tiles: usize,
    /// Bytes of resident tile content.
    pub resident_bytes: u64,
    /// Tile loads so far.
    pub loads: u64,
    /// Tiles evicted so far.
    pub evictions: u64,
    /// New warnings (content skipped) since the last frame.
    pub warnings: Vec<String>,
}

impl StreamFrame {
    /// One line of counts, as the viewer prints them.
    pub fn summary(&self) -> String {
        format!(
            "tiles: {} selected, {} splats (budget {}), {} loading; {} resident ({} MB), {} loads, {} evicted",
            self.tiles,
            self.splats,
            self.budget,
            self.pending,
            self.resident_tiles,
            self.resident_bytes.div_ceil(1 << 20),
            self.loads,
            self.evictions
        )
    }
}

/// The camera handed to the thread, and whether to stop.
#[derive(Default)]
struct Wanted {
    camera: Option<Camera>,
    generation: u64,
    stop: bool,
}

type Shared = Arc<(Mutex<Wanted>, Condvar)>;

/// The streaming thread of one tileset; dropping it stops the thread.
pub struct Streamer {
    shared: Shared,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for Streamer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Streamer")
    }
}

impl Streamer {
    /// Starts streaming `ts`: loads the coarsest content on every path (where it does not
    /// load, the tiles below it) and returns it as the first frame; later frames go to
    /// `publish`, from the thread. `Err` when nothing at the top of the tree loads.
    pub fn start(
        ts: Arc<Tileset>,
        opts: LoadOptions,
        settings: StreamSettings,
        publish: Box<dyn Fn(StreamFrame) + Send>,
    ) -> Result<(Streamer, StreamFrame), super::TilesError> {
        use super::TilesError;
        let shared: Shared = Arc::default();
        let (first_tx, first_rx) = mpsc::channel();
        let s = shared.clone();
        let thread = std::thread::Builder::new()
            .name("splatgl-tiles".into())
            .spawn(move || run(&ts, &opts, settings, &s, first_tx, &*publish))
            .map_err(|e| {
                TilesError::Stream(format!("cannot start the tile streaming thread: {e}"))
            })?;
        let first = first_rx
            .recv()
            .map_err(|_| TilesError::Stream("the tile streaming thread ended".to_owned()))?
            .map_err(TilesError::Stream)?;
        let streamer = Streamer {
            shared,
            thread: Some(thread),
        };
        Ok((streamer, first))
    }

    /// The camera to select for from now on (the newest one wins).
    pub fn set_camera(&self, cam: &Camera) {
        let (m, cv) = &*self.shared;
        let mut w = m.lock().unwrap_or_else(|p| p.into_inner());
        w.camera = Some(*cam);
        w.generation += 1;
        cv.notify_one();
    }
}

impl Drop for Streamer {
    fn drop(&mut self) {
        let (m, cv) = &*self.shared;
        m.lock().unwrap_or_else(|p| p.into_inner()).stop = true;
        cv.notify_one();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The coarsest content on every path from the root that loads (where a tile's content does
/// not load, the tiles below it).
pub fn coarse_cover<'t>(ts: &'t Tileset, cache: &mut TileCache<'_>) -> Vec<&'t Tile> {
    let mut open = ts.coarsest();
    open.reverse();
    let mut out = Vec::new();
    while let Some(t) = open.pop() {
        match cache.splats(t) {
            0 => open.extend(t.children.iter().rev()),
            _ => out.push(t),
        }
    }
    out
}

/// [`select`] among the resident tiles alone (it loads nothing): a tile that is not resident
/// counts as too large to add, so what covers it stays drawn, and is returned in `wanted`, in
/// the order selection asked for it (largest screen-space error first). Once `wanted` comes
/// back empty, the selection is the one [`select`] makes loading every tile it asks about.
pub fn select_resident<'t>(
    ts: &'t Tileset,
    cam: &Camera,
    o: &SelectOptions,
    cache: &mut TileCache<'_>,
) -> Result<(Selection<'t>, Vec<&'t Tile>), super::TilesError> {
    let mut wanted: Vec<&Tile> = Vec::new();
    let sel = select(ts, cam, o, &mut |t| {
        if t.content.is_empty() {
            return 0;
        }
        cache.peek(t).unwrap_or_else(|| {
            if !wanted.iter().any(|w| std::ptr::eq(*w, t)) {
                wanted.push(t);
            }
            u64::MAX / 4
        })
    })?;
    Ok((sel, wanted))
}

/// The thread: the cover first, then select / publish / load until stopped.
fn run(
    ts: &Tileset,
    opts: &LoadOptions,
    settings: StreamSettings,
    shared: &Shared,
    first: mpsc::Sender<Result<StreamFrame, String>>,
    publish: &dyn Fn(StreamFrame),
) {
    let mut cache = TileCache::with_max_bytes(ts, opts, settings.cache_bytes);
    let cover = coarse_cover(ts, &mut cache);
    let mut shown: Vec<&str> = cover.iter().map(|t| t.path.as_str()).collect();
    let splats: u64 = cover.iter().map(|t| cache.splats(t)).sum();
    if splats == 0 {
        let why = cache.warnings.join("; ");
        let _ = first.send(Err(format!("no tile at the top of the tree loads: {why}")));
        return;
    }
    let tiles = content_of(&mut cache, &cover);
    let _ = first.send(Ok(frame(
        &mut cache,
        Some(tiles),
        cover.len(),
        splats,
        &settings,
        0,
    )));
    let (mut seen, mut pending, mut first_camera) = (0u64, 0usize, true);
    let root = [&ts.root];
    loop {
        let Some((cam, new_camera)) = next_camera(shared, &mut seen, pending) else {
            return;
        };
        // A new frame (what earlier cameras used may be evicted) only when the camera moved:
        // while one camera's tiles load, none of them is evicted, so loading converges.
        if new_camera {
            cache.next_frame();
        }
        cache.load_all(&root);
        let Ok((sel, mut wanted)) = select_resident(ts, &cam, &settings.select, &mut cache) else {
            // The root alone is over the budget: keep what is shown.
            pending = 0;
            continue;
        };
        let paths: Vec<&str> = sel.tiles.iter().map(|t| t.path.as_str()).collect();
        let changed = paths != shown;
        let was_pending = pending;
        pending = wanted.len();
        if changed {
            shown = paths;
            let tiles = content_of(&mut cache, &sel.tiles);
            publish(frame(
                &mut cache,
                Some(tiles),
                sel.tiles.len(),
                sel.splats,
                &settings,
                pending,
            ));
        } else if (pending == 0 && was_pending > 0) || first_camera {
            publish(frame(
                &mut cache,
                None,
                sel.tiles.len(),
                sel.splats,
                &settings,
                pending,
            ));
        }
        first_camera = false;
        wanted.truncate(LOAD_BATCH);
        cache.load_all(&wanted);
    }
}

/// Waits for a camera to select for: a new one, or the same while tiles are pending. `None`
/// when stopping; else the camera and whether it is new since generation `seen`.
fn next_camera(shared: &Shared, seen: &mut u64, pending: usize) -> Option<(Camera, bool)> {
    let (m, cv) = &**shared;
    let mut w = m.lock().unwrap_or_else(|p| p.into_inner());
    loop {
        while !w.stop && (w.camera.is_none() || (w.generation == *seen && pending == 0)) {
            w = cv.wait(w).unwrap_or_else(|p| p.into_inner());
        }
        if w.stop {
            return None;
        }
        // The wait above ends with a camera unless stopping.
        if let Some(cam) = w.camera {
            let new_camera = w.generation != *seen;
            *seen = w.generation;
            return Some((cam, new_camera));
        }
    }
}

/// A published selection's content as one cloud (the metadata of its first tile with splats).
pub fn merged(selection: &[(String, Arc<SplatCloud>)]) -> SplatCloud {
    let mut out = SplatCloud::new(0);
    for (_, c) in selection {
        super::select::join(&mut out, SplatCloud::clone(c));
    }
    out
}

/// The content of `tiles`, shared with the cache.
fn content_of(cache: &mut TileCache<'_>, tiles: &[&Tile]) -> Vec<(String, Arc<SplatCloud>)> {
    tiles
        .iter()
        .map(|t| (t.path.clone(), cache.shared(t)))
        .collect()
}

fn frame(
    cache: &mut TileCache<'_>,
    selection: Option<Vec<(String, Arc<SplatCloud>)>>,
    tiles: usize,
    splats: u64,
    settings: &StreamSettings,
    pending: usize,
) -> StreamFrame {
    StreamFrame {
        selection,
        tiles,
        splats,
        budget: settings.select.splat_budget,
        pending,
        resident_tiles: cache.resident_tiles(),
        resident_bytes: cache.resident_bytes(),
        loads: cache.loads,
        evictions: cache.evictions,
        warnings: std::mem::take(&mut cache.warnings),
    }
}
