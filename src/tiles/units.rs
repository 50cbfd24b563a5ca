//! The SOG units of a streamed SOG, decoded once and shared by the leaves that slice them: a
//! unit holds up to splat-transform's chunk size (512 Ki splats by default) for many leaves,
//! and decoding its WebP textures is the expensive part of a load. At most [`KEEP`] units stay
//! decoded (least recently used leaves first); the tile cache holds the slices.

use super::{ContentError, Tileset, lod_meta};
use crate::cloud::SplatCloud;
use crate::load::{LoadOptions, LoadReport, Scene};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Decoded units kept at once.
pub const KEEP: usize = 2;

/// A decoded unit: its content URI (without the fragment), splats and load report.
type Unit = (String, Arc<SplatCloud>, LoadReport);

/// Units that failed, remembered so that the leaves sharing one neither decode nor fetch it
/// again (at most this many).
const FAILED: usize = 4096;

/// The decoded units (most recently used last) and the units that failed, with why.
#[derive(Default)]
struct State {
    kept: Vec<Unit>,
    failed: Vec<(String, String)>,
}

/// What [`Tileset`] keeps of its streamed-SOG units.
#[derive(Clone, Default)]
pub(super) struct Units(Arc<Mutex<State>>);

impl std::fmt::Debug for Units {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.0.lock().map_or(0, |u| u.kept.len());
        write!(f, "Units({n} decoded)")
    }
}

impl Units {
    /// The splats a streamed-SOG content URI (`file#offset=…&count=…`) names.
    pub(super) fn rows(
        &self,
        ts: &Tileset,
        uri: &str,
        opts: &LoadOptions,
    ) -> Result<Scene, ContentError> {
        let bad = |m: String| ContentError::Unreadable(m);
        let (file, offset, count) = lod_meta::rows(uri)
            .ok_or_else(|| bad(format!("{uri:?} is not a reference into a SOG unit")))?;
        let (cloud, report) = self.unit(ts, file, opts)?;
        let end = offset.checked_add(count).filter(|e| *e <= cloud.len());
        let Some(end) = end else {
            return Err(bad(format!(
                "{file:?}: lod-meta.json asks for splats {offset}..{} of a unit that holds {}",
                offset as u128 + count as u128,
                cloud.len()
            )));
        };
        let rows: Vec<u32> = (offset as u32..end as u32).collect();
        Ok(Scene {
            cloud: cloud.select(&rows),
            cameras: Vec::new(),
            report,
        })
    }

    /// Unit `file`, decoded now unless it is among the kept ones.
    fn unit(
        &self,
        ts: &Tileset,
        file: &str,
        opts: &LoadOptions,
    ) -> Result<(Arc<SplatCloud>, LoadReport), ContentError> {
        {
            let mut st = self.0.lock().unwrap_or_else(|p| p.into_inner());
            if let Some(i) = st.kept.iter().position(|u| u.0 == file) {
                let u = st.kept.remove(i);
                let out = (u.1.clone(), u.2.clone());
                st.kept.push(u);
                return Ok(out);
            }
            if let Some((_, why)) = st.failed.iter().find(|f| f.0 == file) {
                return Err(ContentError::Unreadable(why.clone()));
            }
        }
        let scene = self.decode(ts, file, opts).inspect_err(|e| {
            let mut st = self.0.lock().unwrap_or_else(|p| p.into_inner());
            if st.failed.len() < FAILED {
                st.failed.push((file.to_owned(), e.to_string()));
            }
        })?;
        let cloud = Arc::new(scene.cloud);
        let mut st = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if st.kept.len() >= KEEP {
            st.kept.remove(0);
        }
        st.kept
            .push((file.to_owned(), cloud.clone(), scene.report.clone()));
        Ok((cloud, scene.report))
    }

    /// Unit `file` read and decoded.
    fn decode(&self, ts: &Tileset, file: &str, opts: &LoadOptions) -> Result<Scene, ContentError> {
        // Strict: a splat the loader would drop would shift every later leaf's rows.
        let mut o = opts.clone();
        o.strict = true;
        match ts.url() {
            Some(base) => fetch_unit(base, file, &o),
            None => {
                let path = crate::files::contained(ts.folder(), file, o.allow_outside_paths)
                    .map_err(ContentError::Unreadable)?;
                crate::load::load_path(&path, &o)
                    .map_err(|e| ContentError::Unreadable(format!("{file:?} does not load: {e}")))
            }
        }
    }
}

/// A unit's `meta.json` fetched relative to the manifest's URL, its textures through a
/// resolver that fetches them beside it — each URL kept under the manifest's folder and
/// within `max_bytes`.
fn fetch_unit(base: &str, file: &str, o: &LoadOptions) -> Result<Scene, ContentError> {
    use crate::files::http;
    let bad = |e: std::io::Error| ContentError::Unreadable(e.to_string());
    let url = http::resolve(base, file, o.allow_outside_paths).map_err(bad)?;
    let bytes = http::fetch_bounded(&url, o.limits.max_bytes, "the SOG unit").map_err(bad)?;
    let dir = file[..file.rfind('/').map_or(0, |i| i + 1)].to_owned();
    let (base, allow, max) = (base.to_owned(), o.allow_outside_paths, o.limits.max_bytes);
    let mut o = o.clone();
    o.resolver = Some(Arc::new(move |name: &str| {
        let u = http::resolve(&base, &format!("{dir}{name}"), allow).map_err(|e| e.to_string())?;
        http::fetch_bounded(&u, max, "the SOG texture").map_err(|e| e.to_string())
    }));
    crate::load::load_bytes(&bytes, Some(Path::new(file)), &o)
        .map_err(|e| ContentError::Unreadable(format!("{file:?} does not load: {e}")))
}
