//! Frame-time benchmark of the GL backend on the headless context (llvmpipe here): per scene
//! and view, the former draw path against each new step **in the same run**.
//!
//! Scenes (`SPLATGL_BENCH_SCENES`, default `biker,1m,4m`): `biker` = the real 152,746-splat
//! `playcanvas_biker.compressed.ply` (framed as the CLI frames PLY scenes), `1m` = a generated
//! 1M-splat SH-3 cloud, `4m` = a generated 4M-splat SH-0 cloud (`synthetic::random_cloud` in
//! [-1, 1]³, scales × 0.2·(10⁵/n)^(1/3)·`SPLATGL_BENCH_SCALE`, seen from 3.2 units with a
//! 50° vertical field of view). Views: `full` (everything in view) and `half` (the camera
//! turned, by bisection on the CPU cull, until about half the splats are in view).
//!
//! Paths: `former` = every splat sorted and drawn, 3σ quads, each quad corner doing the
//! per-splat maths (the path before issue 15); `cull` = the same draw of only the splats the
//! cull keeps; `extent` = also opacity-aware quads; `new` = also the transform-feedback
//! pre-pass (the default path, `Pipeline::Auto`). All four draw the same image.
//! `SPLATGL_BENCH_PATHS` (default `former,cull,extent,new`) runs some of them only.
//!
//! Columns: splats drawn (instances), fragment-shader invocations
//! (`GL_FRAGMENT_SHADER_INVOCATIONS` of `GL_ARB_pipeline_statistics_query` in a desktop
//! context where the driver has it, else `GL_SAMPLES_PASSED`, else none on ES), sort ms
//! (cull + keys + sort), draw ms (wall, `glFinish`ed) and draw CPU ms (all threads, less
//! disturbed by other jobs), frame ms and frames/s. Medians of `SPLATGL_BENCH_FRAMES`
//! (default 5) frames after one warm-up; the camera orbits a little every frame so every
//! frame sorts anew. `SPLATGL_BENCH_SIZE` (default `1280x720`) sets the framebuffer.
//!
//! Then: the predicted fragment ratio of the opacity-aware quads on the real scenes (pixel
//! centres inside each splat's quad rectangle with k and with 3, counted on the CPU from the
//! reference's projection) against the measured invocation ratio; and the pre-pass crossover
//! (`SPLATGL_BENCH_CROSSOVER`, default `10,100,1000,10000,100000` splats, SH 3, direct vs
//! pre-pass; `none` skips it). `SPLATGL_BENCH_PREDICT=0` skips the prediction table.
//!
//! `cargo bench --features testing --bench gl`; `scripts/bench-gpu.sh` runs it at 1920×1080 with 1M and 4M.

use splatgl_testkit as common;

use std::time::{Duration, Instant};

use common::gl::or_skip;
use glam::Vec3;
use glow::HasContext;
use splatgl::camera::Camera;
use splatgl::cull::{CullBounds, visible_into};
use splatgl::gl::{
    ColorFormat, DrawPath, Errata, Pipeline, ReadbackTarget, SplatRenderer, frustum_for_camera,
};
use splatgl::headless::{GlApi, HeadlessContext};
use splatgl::sort::{SortRequest, Sorter};
use splatgl::{SplatCloud, synthetic};

/// CPU time of the whole process (all threads, so llvmpipe's threads count).
fn cpu_time() -> Duration {
    let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a rusage struct into the valid, writable pointer it is given.
    let u = unsafe {
        libc::getrusage(libc::RUSAGE_SELF, u.as_mut_ptr());
        u.assume_init()
    };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, t.tv_usec as u32 * 1000);
    tv(u.ru_utime) + tv(u.ru_stime)
}

fn median<T: Copy + PartialOrd>(v: &mut [T]) -> T {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// What the fragment query counts here.
#[derive(Clone, Copy, PartialEq)]
enum Counter {
    Invocations,
    SamplesPassed,
    None,
}

impl Counter {
    fn target(self) -> Option<u32> {
        match self {
            Counter::Invocations => Some(0x82F4), // GL_FRAGMENT_SHADER_INVOCATIONS
            Counter::SamplesPassed => Some(glow::SAMPLES_PASSED),
            Counter::None => None,
        }
    }
}

/// The four paths compared.
#[derive(Clone, Copy, PartialEq, Debug)]
enum PathKind {
    Former,
    Cull,
    Extent,
    New,
    /// The pre-pass whatever the count (crossover measurement).
    PrePass,
}

impl PathKind {
    const ALL: [PathKind; 4] = [
        PathKind::Former,
        PathKind::Cull,
        PathKind::Extent,
        PathKind::New,
    ];

    fn name(self) -> &'static str {
        match self {
            PathKind::Former => "former",
            PathKind::Cull => "cull",
            PathKind::Extent => "extent",
            PathKind::New => "new",
            PathKind::PrePass => "pre-pass",
        }
    }

    fn draw_path(self) -> DrawPath {
        let pipeline = match self {
            PathKind::Former | PathKind::Cull | PathKind::Extent => Pipeline::Direct,
            PathKind::New => Pipeline::Auto,
            PathKind::PrePass => Pipeline::PrePass,
        };
        DrawPath { pipeline }
    }

    /// Whether the path draws the former quads (the renderer built with
    /// `Errata::FORMER_QUADS`).
    fn former_quads(self) -> bool {
        matches!(self, PathKind::Former | PathKind::Cull)
    }

    fn culls(self) -> bool {
        self != PathKind::Former
    }
}

/// Medians of one (scene, view, path).
#[derive(Clone, Copy, Default)]
struct Row {
    drawn: usize,
    fragments: Option<u64>,
    sort: f64,
    draw: f64,
    draw_cpu: f64,
    prepass: bool,
    /// GPU time of each stage of one more frame (timer queries; `None` where the context has
    /// none).
    stages: Option<splatgl::gl::StageTimes>,
}

impl Row {
    fn frame(&self) -> f64 {
        self.sort + self.draw
    }
}

struct Bench<'a> {
    gl: &'a glow::Context,
    renderer: SplatRenderer,
    /// The same cloud by the former quads (its own program, `Errata::FORMER_QUADS`).
    former: SplatRenderer,
    sorter: Sorter,
    query: Option<(u32, glow::Query)>,
    frames: usize,
    size: (u32, u32),
}

impl Bench<'_> {
    /// Uploads `cloud` to both renderers (the current quads and the former ones).
    fn upload(&mut self, cloud: &SplatCloud) {
        self.renderer.upload(self.gl, cloud).unwrap();
        self.former.upload(self.gl, cloud).unwrap();
    }

    /// Runs `frames` (+ 1 warm-up) frames of `cloud` from `cam` orbiting by `step` radians per
    /// frame around `target`, by `path`.
    fn run(
        &mut self,
        cloud: &SplatCloud,
        bounds: &CullBounds,
        cam: &Camera,
        target: Vec3,
        path: PathKind,
    ) -> Row {
        let gl = self.gl;
        let renderer = if path.former_quads() {
            &mut self.former
        } else {
            &mut self.renderer
        };
        renderer.set_draw_path(gl, path.draw_path()).unwrap();
        let (w, h) = self.size;
        let mut rows = Vec::new();
        for f in 0..=self.frames {
            let cam = orbit(cam, target, 0.004 * f as f32);
            // SAFETY: clearing the bound framebuffer, then waiting for the GL.
            unsafe {
                gl.clear_color(0.0, 0.0, 0.0, 0.0);
                gl.clear(glow::COLOR_BUFFER_BIT);
                gl.finish();
            }
            let t0 = Instant::now();
            let eye = cam.eye().to_array();
            let order = if path.culls() {
                let frustum = frustum_for_camera(&cam, [0, 0, w as i32, h as i32]);
                let request = SortRequest::distance(eye);
                self.sorter
                    .sort_visible(&cloud.positions, bounds, &frustum, &request)
            } else {
                self.sorter.sort_by_distance(&cloud.positions, eye)
            };
            let drawn = order.len();
            renderer.set_order(gl, order).unwrap();
            // SAFETY: glFinish has no preconditions.
            unsafe { gl.finish() };
            let (t1, c1) = (Instant::now(), cpu_time());
            // SAFETY: a query of this context around one draw.
            unsafe {
                if let Some((target, q)) = self.query {
                    gl.begin_query(target, q);
                }
            }
            renderer.draw_current(gl, &cam).unwrap();
            // SAFETY: ends the query begun above; glFinish.
            let fragments = unsafe {
                let r = self.query.map(|(target, q)| {
                    gl.end_query(target);
                    u64::from(gl.get_query_parameter_u32(q, glow::QUERY_RESULT))
                });
                gl.finish();
                r
            };
            let (t2, c2) = (Instant::now(), cpu_time());
            if f > 0 {
                rows.push(Row {
                    drawn,
                    fragments,
                    sort: ms(t1 - t0),
                    draw: ms(t2 - t1),
                    draw_cpu: ms(c2 - c1),
                    prepass: renderer.last_draw_used_prepass(),
                    stages: None,
                });
            }
        }
        // One more frame, timed per stage on the GPU (not part of the medians).
        let stages = renderer.set_stage_timing(gl, true).ok().and_then(|()| {
            renderer.draw_current(gl, cam).unwrap();
            let t = renderer.stage_times(gl);
            renderer.set_stage_timing(gl, false).unwrap();
            t
        });
        medians(&rows, stages)
    }
}

/// The frames' medians, one row, with the stage times of the extra frame.
fn medians(rows: &[Row], stages: Option<splatgl::gl::StageTimes>) -> Row {
    let pick = |f: fn(&Row) -> f64| median(&mut rows.iter().map(f).collect::<Vec<_>>());
    Row {
        drawn: pick(|r| r.drawn as f64) as usize,
        fragments: rows[0].fragments.map(|_| {
            median(
                &mut rows
                    .iter()
                    .map(|r| r.fragments.unwrap())
                    .collect::<Vec<_>>(),
            )
        }),
        sort: pick(|r| r.sort),
        draw: pick(|r| r.draw),
        draw_cpu: pick(|r| r.draw_cpu),
        prepass: rows[0].prepass,
        stages,
    }
}

/// The GPU stage times as `pre-pass / copy / quads` ms (`-` for a stage that did not run).
fn stage_cells(t: Option<splatgl::gl::StageTimes>) -> String {
    let Some(t) = t else {
        return "no timer queries".into();
    };
    let f = |v: Option<f64>| v.map_or("-".into(), |ms| format!("{ms:.1}"));
    format!("{} / {} / {}", f(t.prepass_ms), f(t.copy_ms), f(t.quads_ms))
}

/// `cam` moved by `angle` radians on a circle about the vertical through `target`, turned
/// with it (so `target` stays where it was in the image).
fn orbit(cam: &Camera, target: Vec3, angle: f32) -> Camera {
    let eye = cam.eye();
    let rot = glam::Quat::from_rotation_y(angle);
    let new_eye = target + rot * (eye - target);
    let forward = cam.world_to_camera.row(2).truncate();
    let up = -cam.world_to_camera.row(1).truncate();
    let fov = 2.0 * (0.5 * cam.height as f32 / cam.fy).atan();
    let mut c = Camera::look_at(
        new_eye,
        new_eye + rot * forward,
        up,
        fov,
        cam.width,
        cam.height,
    );
    c.near = cam.near;
    c.far = cam.far;
    c
}

/// `cam` turned about its own up axis until about half of `cloud` is in view (bisection on
/// the CPU cull's visible count).
fn half_view(cam: &Camera, cloud: &SplatCloud, bounds: &CullBounds) -> Camera {
    let eye = cam.eye();
    let seen = |c: &Camera| {
        let f = frustum_for_camera(c, [0, 0, c.width as i32, c.height as i32]);
        visible_into(&f, &cloud.positions, bounds, &mut Vec::new())
    };
    let turned = |a: f32| orbit(cam, eye, a);
    let (mut lo, mut hi) = (0.0f32, std::f32::consts::PI);
    let target = seen(cam) / 2;
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if seen(&turned(mid)) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    turned(0.5 * (lo + hi))
}

/// The bench scenes: name, cloud, camera, orbit target.
fn scene(name: &str, w: u32, h: u32, scale: f32) -> Option<(SplatCloud, Camera, Vec3)> {
    let fov = 50f32.to_radians();
    let generated = |n: usize, degree: u8| {
        let mut cloud = synthetic::random_cloud(n, degree, 1.0, 1234);
        let k = scale * 0.2 * (1e5 / n as f32).cbrt();
        for s in &mut cloud.scales {
            *s = s.map(|v| v * k);
        }
        let cam = Camera::look_at(Vec3::new(0.0, 0.4, 3.2), Vec3::ZERO, Vec3::Y, fov, w, h);
        (cloud, cam, Vec3::ZERO)
    };
    Some(match name {
        "biker" | "guitar" | "fox" | "tower" | "fruit" => {
            let file = match name {
                "biker" => "playcanvas_biker.compressed.ply",
                "guitar" => "playcanvas_guitar.compressed.ply",
                "fox" => "mujoco_warp_fox_sh0.ply",
                "tower" => "sharpgltf_tower_legacy_spz_v2.glb",
                _ => "supersplat_fruit_drops_minimal_sh3.ply",
            };
            let cloud = splatgl::load::load_path(&common::real(file)?, &Default::default())
                .ok()?
                .cloud;
            let (fwd, up) = if name == "tower" {
                (Vec3::new(0.0, -0.35, -1.0), Vec3::Y)
            } else {
                (Vec3::new(0.0, 0.35, -1.0), -Vec3::Y)
            };
            let cam = common::frame_points_along(&cloud.positions, fwd, up, fov, w, h)?;
            let target = cam.eye() + cam.world_to_camera.inverse().z_axis.truncate();
            (cloud, cam, target)
        }
        "1m" => generated(1_000_000, 3),
        "4m" => generated(4_000_000, 0),
        other => {
            let n: usize = other.trim_end_matches(['k', 'K']).parse().ok()?;
            generated(n * if other.ends_with(['k', 'K']) { 1000 } else { 1 }, 3)
        }
    })
}

#[path = "gl/predict.rs"]
mod predict;

fn main() {
    // `cargo test --all-targets` runs bench binaries without `--bench`: then only smoke-test
    // the code paths on a small cloud.
    let smoke = !std::env::args().any(|a| a == "--bench");
    let frames = if smoke {
        1
    } else {
        env("SPLATGL_BENCH_FRAMES", 5usize).max(1)
    };
    let (w, h) = bench_size();
    let scale: f32 = env("SPLATGL_BENCH_SCALE", 1.0);
    let paths: String = env("SPLATGL_BENCH_PATHS", "former,cull,extent,new".to_owned());
    let scenes: String = if smoke {
        "5000".into()
    } else {
        env("SPLATGL_BENCH_SCENES", "biker,1m,4m".to_owned())
    };
    let crossover: String = if smoke {
        "none".into()
    } else {
        env(
            "SPLATGL_BENCH_CROSSOVER",
            "10,100,1000,10000,100000".to_owned(),
        )
    };
    let Some((ctx, counter)) = counting_context() else {
        return;
    };
    let gl = ctx.gl();
    println!("framebuffer {w}×{h} RGBA8, {frames} frames (median) after a warm-up\n");
    let mut frame = ReadbackTarget::new(gl, w, h, ColorFormat::Rgba8, None).unwrap();
    frame.bind(gl).unwrap();
    // SAFETY: creating a query object on the current context.
    let query = counter
        .target()
        .map(|t| (t, unsafe { gl.create_query().unwrap() }));
    let mut b = Bench {
        gl,
        renderer: SplatRenderer::new(gl).unwrap(),
        former: SplatRenderer::with_errata(gl, Errata::FORMER_QUADS).unwrap(),
        sorter: Sorter::new(),
        query,
        frames,
        size: (w, h),
    };
    print_header();
    let mut summary = Vec::new();
    for name in scenes.split(',').map(str::trim) {
        let Some((cloud, cam, target)) = scene(name, w, h, scale) else {
            println!("{name}: not available (skipped)");
            continue;
        };
        b.upload(&cloud);
        let bounds = CullBounds::new(&cloud);
        let half = half_view(&cam, &cloud, &bounds);
        for (view, c) in [("full", cam), ("half", half)] {
            let mut rows = Vec::new();
            for path in PathKind::ALL {
                if !paths.split(',').any(|p| p.trim() == path.name()) {
                    rows.push(Row::default());
                    continue;
                }
                let r = b.run(&cloud, &bounds, &c, target, path);
                print_row(name, view, path, &r);
                rows.push(r);
            }
            summary.push((name.to_owned(), view, cloud.len(), rows));
        }
    }
    print_summary(&summary);
    if env("SPLATGL_BENCH_PREDICT", 1u8) != 0 && !smoke {
        predict::fragment_table(&mut b, &summary, scale);
    }
    predict::crossover(&mut b, &crossover, scale);
    b.renderer.destroy(gl);
    b.former.destroy(gl);
    frame.destroy(gl);
}

/// `SPLATGL_BENCH_SIZE` (`WxH`, default 1280x720).
fn bench_size() -> (u32, u32) {
    let size: String = env("SPLATGL_BENCH_SIZE", "1280x720".to_owned());
    size.split_once('x')
        .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        .unwrap_or((1280, 720))
}

/// A desktop context where it counts fragment-shader invocations (else samples passed); else
/// ES, counting nothing. `None` (a skip, said) without headless GL. Prints what it got.
fn counting_context() -> Option<(HeadlessContext, Counter)> {
    let desktop = HeadlessContext::with_api(GlApi::DesktopCore33).ok();
    let stats = desktop.as_ref().is_some_and(|c| {
        c.gl()
            .supported_extensions()
            .contains("GL_ARB_pipeline_statistics_query")
    });
    let (ctx, counter) = match desktop {
        Some(c) if stats => (c, Counter::Invocations),
        Some(c) => (c, Counter::SamplesPassed),
        None => (
            or_skip(HeadlessContext::new(), "headless context")?,
            Counter::None,
        ),
    };
    println!("context: {}", ctx.describe());
    println!(
        "fragments counted by: {}",
        match counter {
            Counter::Invocations =>
                "GL_FRAGMENT_SHADER_INVOCATIONS (ARB_pipeline_statistics_query)",
            Counter::SamplesPassed => "GL_SAMPLES_PASSED (no pipeline statistics here)",
            Counter::None => "nothing (ES context)",
        }
    );
    Some((ctx, counter))
}

/// The table's header.
fn print_header() {
    println!(
        "{:>7} | {:>4} | {:>6} | {:>9} | {:>13} | {:>8} | {:>9} | {:>11} | {:>9} | {:>7} | pre-pass | GPU ms: pre-pass / copy / quads",
        "scene",
        "view",
        "path",
        "drawn",
        "fragments",
        "sort ms",
        "draw ms",
        "draw CPU ms",
        "frame ms",
        "frame/s",
    );
}

/// One row of the table.
fn print_row(name: &str, view: &str, path: PathKind, r: &Row) {
    println!(
        "{:>7} | {:>4} | {:>6} | {:>9} | {:>13} | {:>8.2} | {:>9.1} | {:>11.1} | {:>9.1} | {:>7.2} | {:>8} | {}",
        name,
        view,
        path.name(),
        r.drawn,
        r.fragments.map_or("-".into(), |f| f.to_string()),
        r.sort,
        r.draw,
        r.draw_cpu,
        r.frame(),
        1e3 / r.frame(),
        if r.prepass { "yes" } else { "no" },
        stage_cells(r.stages)
    );
}

/// Speed-ups of the new path over the former one, split into its steps.
fn print_summary(summary: &[(String, &str, usize, Vec<Row>)]) {
    println!(
        "\n{:>7} | {:>4} | {:>9} | {:>7} | {:>14} | {:>14} | {:>16} | {:>13}",
        "scene",
        "view",
        "splats",
        "in view",
        "draw: cull ×",
        "extent ×",
        "pre-pass ×",
        "new/former"
    );
    for (name, view, n, rows) in summary {
        let [former, cull, extent, new] = [rows[0], rows[1], rows[2], rows[3]];
        println!(
            "{:>7} | {:>4} | {:>9} | {:>6.1}% | {:>14.2} | {:>14.2} | {:>16.2} | {:>6.2}× ({:.2}× frame)",
            name,
            view,
            n,
            100.0 * new.drawn as f64 / *n as f64,
            former.draw / cull.draw,
            cull.draw / extent.draw,
            extent.draw / new.draw,
            former.draw / new.draw,
            former.frame() / new.frame(),
        );
    }
}
