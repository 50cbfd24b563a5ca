//! What the panel shows and what it asks the viewer to do: the scene's facts (fixed while a
//! scene is shown), the frame statistics (each frame), the settings it edits in place, and
//! the [`Action`]s that need the viewer (a camera, a reload, a file dialog).

use splatgl::camera::UpAxis;
use splatgl::cull::CropBox;

/// Facts about the scene on screen, made once when it is installed.
#[derive(Debug, Clone, Default)]
pub struct Facts {
    /// File name (or "default scene").
    pub name: String,
    /// The path as given, if any.
    pub path: Option<String>,
    /// Format name (`Format::name`), "built in" for the default scene.
    pub format: String,
    /// Container, version and compression of quantized formats (`spz 3, gzip`).
    pub container: Option<String>,
    /// Splats resident (after `--max-splats`).
    pub splats: usize,
    /// Splats in the file.
    pub file_splats: usize,
    /// The file's SH degree.
    pub sh_degree: u8,
    /// `lin_rec709_display`, `srgb_rec709_display`, or what the file said.
    pub colour_space: String,
    /// Whether the antialiased kernel is used, and why.
    pub kernel: String,
    /// Axis-aligned bounds of the splat means.
    pub bounds: Option<([f32; 3], [f32; 3])>,
    /// The loader's warnings, summarised.
    pub warnings: Vec<String>,
    /// The camera list: the file's glTF camera nodes, then the `--camera` views.
    pub cameras: Vec<String>,
}

/// Frame statistics over the last second.
#[derive(Debug, Clone, Default)]
pub struct Live {
    /// Frames per second.
    pub fps: f32,
    /// Mean and 99th percentile frame time, ms.
    pub frame_ms: (f32, f32),
    /// Mean sort time of the orders drawn, ms.
    pub sort_ms: f32,
    /// Time of the last order upload (`set_order`), ms; 0 when the order did not change.
    pub upload_ms: f32,
    /// How the frame's order was obtained (`exact`, `stale (0.002 moved)`, `waited`).
    pub order: String,
    /// Splats in the order drawn (after the crop).
    pub drawn: usize,
    /// CPU time of the interface in the last frame, ms: layout (egui's pass and
    /// tessellation; 0 when the previous layout was reused) and painting (GL calls).
    pub ui_ms: (f32, f32),
    /// A streamed tileset's counts (`None` for other scenes).
    pub tiles: Option<TileCounts>,
}

/// A streamed tileset's counts, as the last stream frame and page placement left them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TileCounts {
    /// Tiles selected, and their splats.
    pub selected: usize,
    pub splats: u64,
    /// The splat budget (`--splat-budget`).
    pub budget: u64,
    /// Tiles the selection wants that are still loading.
    pub loading: usize,
    /// Tiles resident in the cache, and their megabytes (`--cache-mb`).
    pub resident: usize,
    pub resident_mb: u64,
    /// GPU pages holding tiles, and allocated.
    pub pages_used: usize,
    pub pages: usize,
}

/// The settings the panel edits in place; the viewer applies what changed.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// SH degree evaluated (the file's caps it).
    pub sh_degree: u8,
    /// Background, display values.
    pub background: [f32; 3],
    /// Render at this fraction of the window's pixels.
    pub resolution_scale: f32,
    /// The crop box, when on.
    pub crop: Option<CropBox>,
    /// Draw the crop box's wireframe and handles.
    pub show_crop: bool,
    /// The `--max-splats` budget being edited (applied by [`Action::Budget`]).
    pub budget: Option<usize>,
}

/// What the panel asks of the viewer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// Go to camera `i` of [`Facts::cameras`].
    Camera(usize),
    /// Switch to this up axis (and frame from its default direction).
    Up(UpAxis),
    /// Reload the scene with this `--max-splats` budget.
    Budget(Option<usize>),
    /// Back to the initial view (`Home`).
    Reset,
    /// Frame the cloud along the view (`F`).
    Frame,
    /// Screenshot without the panel (`P`).
    Screenshot,
    /// Open a file (`O`).
    Open,
}
