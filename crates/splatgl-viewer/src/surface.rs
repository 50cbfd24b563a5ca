//! The window and its GL context: glutin (EGL) on a winit window, GLES 3.0 first, desktop
//! GL 3.3 core as the fallback; vsync through the swap interval.

use std::num::NonZeroU32;

use glutin::config::{Api, Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext,
    Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, SurfaceAttributesBuilder, SwapInterval, WindowSurface};
use glutin_winit::{DisplayBuilder, GlWindow};
use winit::event_loop::ActiveEventLoop;
use winit::raw_window_handle::HasWindowHandle;
use winit::window::{Window, WindowAttributes};

/// A window with a current GL context.
///
/// Fields drop in declaration order: functions, context and surface before the window.
pub struct GlSurfaceWindow {
    /// The context's functions (shared with the interface's painter).
    pub gl: std::sync::Arc<glow::Context>,
    context: PossiblyCurrentContext,
    surface: Surface<WindowSurface>,
    /// The window.
    pub window: Window,
    /// "GLES 3.0" or "GL 3.3 core": what was asked for and got.
    pub api: &'static str,
}

impl std::fmt::Debug for GlSurfaceWindow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GlSurfaceWindow")
            .field("api", &self.api)
            .finish_non_exhaustive()
    }
}

/// The config: 8-bit RGBA, no multisampling (splats are blended per pixel), GLES 3 or GL.
fn pick(configs: Box<dyn Iterator<Item = Config> + '_>) -> Config {
    let mut all: Vec<Config> = configs.collect();
    // Single-sampled first, then GLES 3 capable, then with alpha.
    all.sort_by_key(|c| {
        (
            c.num_samples() != 0,
            !c.api().contains(Api::GLES3),
            c.alpha_size() != 8,
        )
    });
    all.into_iter()
        .next()
        .expect("glutin returns at least one config")
}

impl GlSurfaceWindow {
    /// Creates the window and a context on it: GLES 3.0 (the shaders' GLSL ES 3.00), else
    /// desktop GL 3.3 core. `vsync` sets swap interval 1 (else 0, where the driver allows).
    pub fn new(
        event_loop: &ActiveEventLoop,
        attrs: WindowAttributes,
        vsync: bool,
    ) -> Result<Self, String> {
        let template = ConfigTemplateBuilder::new()
            .with_alpha_size(8)
            .with_api(Api::GLES3 | Api::OPENGL);
        let (window, config) = DisplayBuilder::new()
            .with_window_attributes(Some(attrs))
            .build(event_loop, template, pick)
            .map_err(|e| format!("cannot create a window with a GL config: {e}"))?;
        let window = window.ok_or("no window was created")?;
        let display = config.display();
        let handle = window
            .window_handle()
            .map_err(|e| format!("window handle: {e}"))?
            .as_raw();
        let tries = [
            (
                "GLES 3.0",
                ContextAttributesBuilder::new()
                    .with_context_api(ContextApi::Gles(Some(Version::new(3, 0))))
                    .build(Some(handle)),
            ),
            (
                "GL 3.3 core",
                ContextAttributesBuilder::new()
                    .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 3))))
                    .with_profile(GlProfile::Core)
                    .build(Some(handle)),
            ),
        ];
        let mut errors = Vec::new();
        let mut made = None;
        for (api, attrs) in tries {
            // SAFETY: the raw window handle belongs to `window`, which outlives the context
            // (both are fields of the returned value, the context dropped first).
            match unsafe { display.create_context(&config, &attrs) } {
                Ok(c) => {
                    made = Some((api, c));
                    break;
                }
                Err(e) => errors.push(format!("{api}: {e}")),
            }
        }
        let (api, not_current) =
            made.ok_or_else(|| format!("no GL context: {}", errors.join("; ")))?;
        let surface_attrs = window
            .build_surface_attributes(SurfaceAttributesBuilder::default())
            .map_err(|e| format!("surface attributes: {e}"))?;
        // SAFETY: as above, the window outlives the surface.
        let surface = unsafe { display.create_window_surface(&config, &surface_attrs) }
            .map_err(|e| format!("window surface: {e}"))?;
        let context = not_current
            .make_current(&surface)
            .map_err(|e| format!("make current: {e}"))?;
        let interval = if vsync {
            SwapInterval::Wait(NonZeroU32::MIN)
        } else {
            SwapInterval::DontWait
        };
        if let Err(e) = surface.set_swap_interval(&context, interval) {
            eprintln!("note: cannot set the swap interval ({e}); vsync is the driver's");
        }
        // SAFETY: the loader returns function pointers of the context made current above.
        let gl = unsafe {
            glow::Context::from_loader_function_cstr(|s| display.get_proc_address(s).cast())
        };
        Ok(GlSurfaceWindow {
            gl: std::sync::Arc::new(gl),
            context,
            surface,
            window,
            api,
        })
    }

    /// Resizes the surface to the window's inner size.
    pub fn resize(&self) {
        self.window.resize_surface(&self.surface, &self.context);
    }

    /// Presents the back buffer.
    pub fn swap(&self) -> Result<(), String> {
        self.surface
            .swap_buffers(&self.context)
            .map_err(|e| format!("swap buffers: {e}"))
    }

    /// `GL_RENDERER`, `GL_VERSION` and `GL_VENDOR`, and the context asked for.
    pub fn info(&self) -> String {
        use glow::HasContext;
        // SAFETY: string queries on the current context.
        let (r, v, ve) = unsafe {
            (
                self.gl.get_parameter_string(glow::RENDERER),
                self.gl.get_parameter_string(glow::VERSION),
                self.gl.get_parameter_string(glow::VENDOR),
            )
        };
        format!("{r} | {v} | {ve} ({} context)", self.api)
    }
}
