//! Loading scenes on a background thread: the file is read in 1 MiB chunks (progress in
//! bytes), then decoded by [`load_bytes`] (reported as "decoding"), then cut to the
//! `--max-splats` budget. (The crop box is not applied here: it is a cull, editable while the
//! scene is shown.) The window keeps drawing the previous scene meanwhile.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use splatgl::camera::GltfPerspective;
use splatgl::cloud::SplatCloud;
use splatgl::load::{Format, LoadOptions, load_bytes};

/// Which splats of a file the viewer keeps: at most `max_splats` of them.
#[derive(Debug, Clone, Copy, Default)]
pub struct Keep {
    /// `--max-splats`.
    pub max_splats: Option<usize>,
    /// A tileset's selection and cache (`--splat-budget`, `--max-screen-error`, `--cache-mb`).
    pub tiles: splatgl::tiles::StreamSettings,
}

/// A scene ready to show.
#[derive(Debug)]
pub struct Loaded {
    /// The file (`None`: the bundled default scene).
    pub path: Option<PathBuf>,
    /// The splats (after the budget).
    pub cloud: SplatCloud,
    /// Splats in the file.
    pub file_len: usize,
    /// The file's format (`None`: the default scene).
    pub format: Option<Format>,
    /// The file's glTF camera nodes.
    pub cameras: Vec<GltfPerspective>,
    /// The loader's warnings, summarised.
    pub warnings: Vec<String>,
    /// The file says it was trained with antialiasing (`--antialiased auto`).
    pub trained_antialiased: bool,
    /// Container, version and compression of a quantized format (`spz 3, gzip`).
    pub container: Option<String>,
    /// For a tileset: its streaming thread (`cloud` is then its first selection, the coarsest
    /// content; later ones arrive as [`LoadEvent::Tiles`]).
    pub streamer: Option<splatgl::tiles::Streamer>,
    /// For a tileset: the tiles of its first selection (`cloud` is them merged, for framing).
    pub tiles: Vec<(String, Arc<SplatCloud>)>,
    /// The up axis the scene's frame implies (a 3D Tiles tileset's +Z), before the format's
    /// rule.
    pub up: Option<splatgl::camera::UpAxis>,
}

impl Loaded {
    /// The name shown in the title: the file name, or "default scene".
    pub fn name(&self) -> String {
        display_name(self.path.as_deref())
    }
}

/// The file name of `path` (or "default scene").
pub fn display_name(path: Option<&Path>) -> String {
    match path {
        Some(p) => p
            .file_name()
            .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into()),
        None => "default scene".into(),
    }
}

/// What the loading thread reports.
#[derive(Debug)]
pub enum LoadEvent {
    /// `done` of `total` bytes read.
    Progress {
        /// The load's id.
        id: u64,
        /// Bytes read.
        done: u64,
        /// File size.
        total: u64,
    },
    /// Reading finished; decoding.
    Decoding {
        /// The load's id.
        id: u64,
    },
    /// A tileset's streaming thread selected other tiles (or finished loading them).
    Tiles {
        /// The load's id.
        id: u64,
        /// The new selection and the counts.
        frame: Box<splatgl::tiles::StreamFrame>,
    },
    /// Finished.
    Done {
        /// The load's id.
        id: u64,
        /// The scene, or the error message (naming the file).
        result: Result<Box<Loaded>, String>,
    },
}

/// Starts loading `path` (`None`: the bundled default scene) on a new thread; `send` delivers
/// its events (throttled progress, then exactly one `Done`; for a tileset, `Tiles` from its
/// streaming thread after that).
pub fn spawn(
    id: u64,
    path: Option<PathBuf>,
    opts: Arc<LoadOptions>,
    keep: Keep,
    send: impl Fn(LoadEvent) + Send + Sync + Clone + 'static,
) {
    let body = move || {
        let result = match path.as_deref().filter(|p| is_tileset(p, &opts)) {
            Some(p) => load_tileset(id, p, &opts, keep, send.clone()),
            None => load(id, path, &opts, keep, &send),
        };
        send(LoadEvent::Done { id, result });
    };
    if let Err(e) = std::thread::Builder::new()
        .name("splatgl-load".into())
        .spawn(body)
    {
        eprintln!("error: cannot start the loading thread: {e}");
    }
}

fn load(
    id: u64,
    path: Option<PathBuf>,
    opts: &LoadOptions,
    keep: Keep,
    send: &impl Fn(LoadEvent),
) -> Result<Box<Loaded>, String> {
    let (cloud, format, cameras, warnings, trained_antialiased, container) = match &path {
        None => (
            splatgl::synthetic::default_scene(),
            None,
            Vec::new(),
            Vec::new(),
            false,
            None,
        ),
        Some(p) => {
            let bytes = read_with_progress(id, p, opts.limits.max_bytes, send)?;
            send(LoadEvent::Decoding { id });
            let scene = load_bytes(&bytes, Some(p), opts).map_err(|e| e.to_string())?;
            let warnings = scene.report.summarized_warnings();
            let container = scene.report.details.as_ref().map(|d| {
                let mut c = d.container.to_owned();
                if !d.version.is_empty() {
                    c += &format!(" {}", d.version);
                }
                c + &format!(", {}", d.compression)
            });
            (
                scene.cloud,
                Some(scene.report.format),
                scene.cameras,
                warnings,
                scene.report.trained_antialiased(),
                container,
            )
        }
    };
    if cloud.is_empty() {
        return Err(format!(
            "{}: no splats to show",
            display_name(path.as_deref())
        ));
    }
    let file_len = cloud.len();
    let cloud = match keep
        .max_splats
        .and_then(|n| super::budget::subset(&cloud, n))
    {
        Some(s) => s,
        None => cloud,
    };
    Ok(Box::new(Loaded {
        path,
        cloud,
        file_len,
        format,
        cameras,
        warnings,
        trained_antialiased,
        container,
        streamer: None,
        tiles: Vec::new(),
        up: None,
    }))
}

/// Whether `p` names a tileset: an http(s) URL, or a `.json` that reads as one.
fn is_tileset(p: &Path, opts: &LoadOptions) -> bool {
    #[cfg(feature = "http")]
    if p.to_str().is_some_and(splatgl::files::http::is_url) {
        return true;
    }
    p.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        && splatgl::files::read_bounded(p, opts.limits.max_bytes, "the file")
            .is_ok_and(|b| splatgl::tiles::is_tileset(&b))
}

/// A tileset: read, and streamed from its coarsest content on (`keep.tiles`).
fn load_tileset(
    id: u64,
    p: &Path,
    opts: &LoadOptions,
    keep: Keep,
    send: impl Fn(LoadEvent) + Send + Sync + 'static,
) -> Result<Box<Loaded>, String> {
    send(LoadEvent::Decoding { id });
    let ts = splatgl::tiles::read(p, opts)?;
    let mut warnings: Vec<String> = ts
        .problems
        .iter()
        .map(|pr| format!("{}: {}", pr.path, pr.message))
        .collect();
    let format = match ts.format {
        splatgl::tiles::TilesetFormat::Tiles3d => Format::Glb,
        splatgl::tiles::TilesetFormat::StreamedSog => Format::Sog,
    };
    let publish = Box::new(move |f: splatgl::tiles::StreamFrame| {
        send(LoadEvent::Tiles {
            id,
            frame: Box::new(f),
        })
    });
    let ts_up = ts.up();
    let (streamer, first) =
        splatgl::tiles::Streamer::start(Arc::new(ts), opts.clone(), keep.tiles, publish)
            .map_err(|e| format!("{}: {e}", p.display()))?;
    warnings.extend(first.warnings.iter().cloned());
    let up = ts_up;
    let tiles = first.selection.unwrap_or_default();
    let cloud = splatgl::tiles::merged(&tiles);
    Ok(Box::new(Loaded {
        tiles,
        up,
        path: Some(p.to_owned()),
        file_len: cloud.len(),
        cloud,
        format: Some(format),
        cameras: Vec::new(),
        warnings,
        trained_antialiased: false,
        container: Some(format!("{} tileset", ts_name(format))),
        streamer: Some(streamer),
    }))
}

fn ts_name(f: Format) -> &'static str {
    match f {
        Format::Sog => "streamed SOG",
        _ => "3D Tiles",
    }
}

/// Reads a file in 1 MiB chunks, reporting progress at most every 100 ms: a regular file of at
/// most `max_bytes` (`files::open_regular`: FIFOs, devices and directories fail at once; the
/// size is checked before reading, and again while reading).
fn read_with_progress(
    id: u64,
    p: &Path,
    max_bytes: u64,
    send: &impl Fn(LoadEvent),
) -> Result<Vec<u8>, String> {
    let err = |e: std::io::Error| format!("{}: {e}", p.display());
    let (f, total) = splatgl::files::open_regular(p, "the scene file").map_err(err)?;
    let too_large = |size: u64| {
        format!(
            "{}: the scene file is {size} bytes, more than the limit of {max_bytes} bytes (limits.max_bytes, --max-bytes)",
            p.display()
        )
    };
    if total > max_bytes {
        return Err(too_large(total));
    }
    let mut f = f.take(max_bytes.saturating_add(1));
    let mut bytes = Vec::with_capacity(total as usize);
    let mut chunk = vec![0u8; 1 << 20];
    let mut last = Instant::now();
    loop {
        let n = match f.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(err(e)),
        };
        bytes.extend_from_slice(&chunk[..n]);
        if bytes.len() as u64 > max_bytes {
            return Err(too_large(bytes.len() as u64));
        }
        if last.elapsed() >= Duration::from_millis(100) {
            last = Instant::now();
            let done = bytes.len() as u64;
            send(LoadEvent::Progress {
                id,
                done,
                total: total.max(done),
            });
        }
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_and_oversized_files_fail_at_once() {
        let quiet = |_: LoadEvent| {};
        let t0 = Instant::now();
        let e = read_with_progress(0, Path::new("/dev/zero"), 1 << 30, &quiet).unwrap_err();
        assert!(e.contains("character device"), "{e}");
        let d = std::env::temp_dir().join(format!("splatgl-viewer-load-{}", std::process::id()));
        // Empty first: a folder left by an earlier run with the same pid holds the FIFO.
        std::fs::remove_dir_all(&d).ok();
        std::fs::create_dir_all(&d).unwrap();
        let e = read_with_progress(0, &d, 1 << 30, &quiet).unwrap_err();
        assert!(e.contains("directory"), "{e}");
        let fifo = d.join("fifo.ply");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path that lives through the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_with_progress(0, &fifo, 1 << 30, &quiet).unwrap_err();
        assert!(e.contains("FIFO"), "{e}");
        assert!(t0.elapsed() < Duration::from_secs(1));
        let f = d.join("s.ply");
        std::fs::write(&f, [0u8; 100]).unwrap();
        assert_eq!(read_with_progress(0, &f, 100, &quiet).unwrap().len(), 100);
        let e = read_with_progress(0, &f, 99, &quiet).unwrap_err();
        assert!(e.contains("more than the limit of 99 bytes"), "{e}");
        std::fs::remove_dir_all(&d).ok();
    }
}
