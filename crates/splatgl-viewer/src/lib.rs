//! The desktop viewer of splatgl: `splatgl view [FILE]` and `examples/viewer.rs`.
//!
//! A winit window with a glutin (EGL) context — GLES 3.0, else desktop GL 3.3 core — hosting a
//! [`SplatRenderer`](splatgl::gl::SplatRenderer) through the same public API an embedding
//! application uses. Per frame: the controls move the camera, the newest finished order of an
//! [`AsyncSorter`](splatgl::sort::AsyncSorter) is drawn unless the camera moved beyond the
//! staleness bound ([`StaleBound`]; the frame then waits for the sort of its own eye), only a
//! changed order is uploaded, and the image is blended in `RGBA16F` and resolved (8 bits where
//! the context cannot render to float). Files load on a background thread (drag and drop,
//! `O`, the command line); a failed load keeps the previous scene.
//!
//! Controls, the staleness bound and the `--max-splats` rule are documented in
//! `docs/viewer.md` and printed by `H` / `F1` ([`HELP`]).
//!
//! ```no_run
//! let opts = splatgl_viewer::ViewerOptions {
//!     file: Some("scene.ply".into()),
//!     ..Default::default()
//! };
//! splatgl_viewer::run(opts).unwrap();
//! ```

#![warn(missing_docs)]

mod app;
mod budget;
mod controls;
mod draw;
mod loading;
mod panel;
mod rig;
mod stats;
mod surface;

pub use splatgl::sort::StaleBound;

use std::path::PathBuf;

use splatgl::camera::ViewOptions;
use splatgl::load::LoadOptions;

/// The controls, as `H` / `F1` print them (docs/guide.md's and docs/viewer.md's tables say the same).
pub const HELP: &str = "\
splatgl view controls
  orbit mode (default)           fly mode (Tab)
  left drag    orbit             left drag    look around
  right/middle drag  pan         W A S D      move
  wheel        zoom to cursor    R / F        up / down (along the up axis)
  Q / E        roll              Shift        4x faster
                                 wheel        move forward/back
  Tab          orbit <-> fly     I            inertia on/off
  F            frame the cloud (orbit mode)   Home / 0   initial view
  1 2 3 4      SH degree 0..3    U            up axis +Y -> -Y -> +Z
  C            next camera (glTF camera nodes, then --camera cameras.json)
  V            print the camera as a splatgl render line (+ cameras.json with --print-camera-json)
  P            screenshot (PNG of the framebuffer, timestamped, in the current directory)
  O            open a file (zenity / kdialog, else type a path on stdin); or drop a file
  G            show / hide the panel (scene, statistics, settings, cameras, crop box)
  F11          fullscreen        H / F1       this help        Esc  quit";

/// The framebuffer the viewer blends in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TargetChoice {
    /// `RGBA16F` and a resolve pass when the context can render to it, else 8 bits.
    #[default]
    Float,
    /// Always 8 bits (`RGBA8`, `SRGB8_ALPHA8` for linear clouds).
    Rgba8,
}

/// `--bench-frames N [--orbit]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bench {
    /// Frames measured (after two warm-up frames).
    pub frames: usize,
    /// Move along one full orbit around the initial pivot (else a still camera).
    pub orbit: bool,
    /// Draw the interface in the measured frames too (`--bench-panel`) and report its CPU
    /// time; without it benchmark frames never draw it.
    pub panel: bool,
}

/// Everything `splatgl view` takes.
#[derive(Debug)]
pub struct ViewerOptions {
    /// The scene; `None`: the bundled default scene.
    pub file: Option<PathBuf>,
    /// The initial view: the camera options of `splatgl render`.
    pub view: ViewOptions,
    /// Loader options.
    pub load: LoadOptions,
    /// Start in fullscreen.
    pub fullscreen: bool,
    /// Swap interval 1.
    pub vsync: bool,
    /// Render at this fraction of the window's pixels (stretched to the window).
    pub resolution_scale: f32,
    /// Keep at most this many of the file's splats (the opacity × area ranking of
    /// `budget.rs`); the crop box then hides those outside it.
    pub max_splats: Option<usize>,
    /// Draw only the splats whose mean is inside this box (`--crop`): a cull, not a cut at
    /// load time, so the panel can move the box's faces over the whole file.
    pub crop: Option<splatgl::cull::CropBox>,
    /// Every frame waits for the sort of its own camera.
    pub sort_sync: bool,
    /// The staleness bound.
    pub stale: StaleBound,
    /// Float or 8-bit blending.
    pub target: TargetChoice,
    /// SH degree to evaluate at start (the file's caps it).
    pub sh_degree: u8,
    /// Background, display values.
    pub background: [f32; 3],
    /// The kernel: antialiased when the file says so (`Auto`), always, or never.
    pub antialiased: splatgl::load::AntialiasMode,
    /// Measure frames and exit.
    pub bench: Option<Bench>,
    /// `V` also prints a cameras.json entry.
    pub print_camera_json: bool,
    /// Start with the interface hidden (`--no-ui`; `G` shows it).
    pub no_ui: bool,
    /// For a tileset: the splat budget, screen-space error and cache size its streaming keeps
    /// to (`--splat-budget`, `--max-screen-error`, `--cache-mb`).
    pub tiles: splatgl::tiles::StreamSettings,
    /// Test hook (feature `testing`): after the first scene has been shown for a few frames,
    /// deliver this path as a `DroppedFile` window event (the drag-and-drop code path).
    #[cfg(feature = "testing")]
    #[doc(hidden)]
    pub test_drop: Option<PathBuf>,
}

impl Default for ViewerOptions {
    fn default() -> Self {
        ViewerOptions {
            file: None,
            view: ViewOptions::default(),
            load: LoadOptions::default(),
            fullscreen: false,
            vsync: true,
            resolution_scale: 1.0,
            max_splats: None,
            crop: None,
            sort_sync: false,
            stale: StaleBound::Auto,
            target: TargetChoice::Float,
            sh_degree: 3,
            background: [0.0; 3],
            antialiased: splatgl::load::AntialiasMode::Auto,
            bench: None,
            print_camera_json: false,
            no_ui: false,
            tiles: Default::default(),
            #[cfg(feature = "testing")]
            test_drop: None,
        }
    }
}

/// Why the viewer stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No window or GL context (no display, no EGL, no GLES 3 / GL 3.3).
    #[error("cannot open the viewer window: {0}")]
    Window(String),
    /// The GL layer failed.
    #[error(transparent)]
    Gl(#[from] splatgl::gl::GlError),
    /// The file given on the command line could not be shown.
    #[error("{0}")]
    Load(String),
    /// The camera options ask for a view the scene cannot give.
    #[error(transparent)]
    Camera(#[from] splatgl::camera::CameraError),
}

/// Opens the viewer window and runs until it is closed (or the benchmark ends).
pub fn run(opts: ViewerOptions) -> Result<(), ViewerError> {
    app::run(opts)
}
