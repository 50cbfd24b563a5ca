//! GPU time of each stage of a draw, by timer queries (`GL_TIME_ELAPSED`: desktop GL ≥ 3.3,
//! `EXT_disjoint_timer_query` on ES, `EXT_disjoint_timer_query_webgl2` in browsers): the
//! pre-pass (transform feedback), the copy of its records into the records texture, and the
//! quads (or the direct draw). Off unless asked for ([`SplatRenderer::set_stage_timing`]):
//! a query per stage per draw, read after the frame ([`SplatRenderer::stage_times`]).
//! `docs/performance.md` has the tables it gives.

use glow::HasContext;

use super::GlError;
use super::caps::has_extension;
use super::objects::{Creating, Owned};
use super::renderer::SplatRenderer;

/// `GL_TIME_ELAPSED` (`TIME_ELAPSED_EXT`).
const TIME_ELAPSED: u32 = 0x88BF;
/// `GL_GPU_DISJOINT_EXT`: the timer was disturbed, results are unreliable.
const GPU_DISJOINT: u32 = 0x8FBB;

/// The stages timed, in draw order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stage {
    PrePass = 0,
    Copy = 1,
    Quads = 2,
}

/// GPU milliseconds of each stage of the last draw (`None`: the stage did not run, e.g. the
/// direct path has no pre-pass and no copy).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// The transform-feedback pre-pass (per-splat maths).
    pub prepass_ms: Option<f64>,
    /// The copy of the records into the records texture.
    pub copy_ms: Option<f64>,
    /// The quads: vertices, rasterisation, fragments, blending.
    pub quads_ms: Option<f64>,
}

/// The query objects, and which ran in the last draw.
#[derive(Debug)]
pub(crate) struct StageQueries {
    queries: [glow::Query; 3],
    ran: std::cell::Cell<[bool; 3]>,
    owned: Owned,
}

/// Whether the context has `GL_TIME_ELAPSED` queries.
pub(crate) fn available(gl: &glow::Context) -> bool {
    !gl.version().is_embedded
        || has_extension(gl, "GL_EXT_disjoint_timer_query")
        || has_extension(gl, "GL_EXT_disjoint_timer_query_webgl2")
}

impl StageQueries {
    pub(crate) fn new(gl: &glow::Context) -> Result<Self, GlError> {
        if !available(gl) {
            return Err(GlError::Unsupported(
                "this context has no GL_TIME_ELAPSED timer queries".into(),
            ));
        }
        let mut objects = Creating::new(gl);
        let queries = [objects.query()?, objects.query()?, objects.query()?];
        Ok(StageQueries {
            queries,
            ran: std::cell::Cell::new([false; 3]),
            owned: objects.keep("SplatRenderer"),
        })
    }

    /// Forgets which stages ran (at the start of a draw).
    pub(crate) fn reset(&self) {
        self.ran.set([false; 3]);
    }

    /// Runs `f` inside the query of `stage`.
    pub(crate) fn time<T>(&self, gl: &glow::Context, stage: Stage, f: impl FnOnce() -> T) -> T {
        let k = stage as usize;
        // SAFETY: one TIME_ELAPSED query of our own, begun and ended around `f` (no other
        // TIME_ELAPSED query of ours is active: the stages run one after the other).
        unsafe { gl.begin_query(TIME_ELAPSED, self.queries[k]) };
        let r = f();
        // SAFETY: ends the query begun above.
        unsafe { gl.end_query(TIME_ELAPSED) };
        let mut ran = self.ran.get();
        ran[k] = true;
        self.ran.set(ran);
        r
    }

    /// The results of the last draw: natively waits for them; in a browser (where WebGL
    /// makes results available only once the page has returned to its event loop) a result
    /// not yet available is `None`.
    pub(crate) fn read(&self, gl: &glow::Context) -> StageTimes {
        let ran = self.ran.get();
        // SAFETY: result queries of our own query objects, for the stages that ran.
        let ms = |k: usize| unsafe {
            let q = self.queries[k];
            let ready = !cfg!(target_arch = "wasm32")
                || gl.get_query_parameter_u32(q, glow::QUERY_RESULT_AVAILABLE) != 0;
            (ran[k] && ready)
                .then(|| gl.get_query_parameter_u64(q, glow::QUERY_RESULT) as f64 * 1e-6)
        };
        let times = StageTimes {
            prepass_ms: ms(Stage::PrePass as usize),
            copy_ms: ms(Stage::Copy as usize),
            quads_ms: ms(Stage::Quads as usize),
        };
        // A disjoint timer (a frequency change, a context switch) makes the results unreliable:
        // report none rather than wrong ones (ES and WebGL only say so).
        let disjoint = gl.version().is_embedded
            // SAFETY: a plain integer query of a pname the extension defines.
            && unsafe { gl.get_parameter_i32(GPU_DISJOINT) } != 0;
        if disjoint {
            StageTimes::default()
        } else {
            times
        }
    }

    pub(crate) fn destroy(&mut self, gl: &glow::Context) {
        self.owned.destroy(gl);
    }

    pub(crate) fn abandon(&mut self) {
        self.owned.abandon();
    }
}

impl SplatRenderer {
    /// Times each stage of every draw on the GPU from now on (`true`), or stops (`false`),
    /// for [`SplatRenderer::stage_times`]. Errors where the context has no `GL_TIME_ELAPSED`
    /// queries. Costs a query per stage per draw; nothing when off (the default). While it is
    /// on, the host must not have a `GL_TIME_ELAPSED` query of its own active during a draw
    /// (GL allows one at a time).
    pub fn set_stage_timing(&mut self, gl: &glow::Context, on: bool) -> Result<(), GlError> {
        self.owned.check()?;
        match (on, self.stages.take()) {
            (true, Some(q)) => self.stages = Some(q),
            (true, None) => self.stages = Some(StageQueries::new(gl)?),
            (false, Some(mut q)) => q.destroy(gl),
            (false, None) => {}
        }
        Ok(())
    }

    /// The GPU time of each stage of the last draw (waits for the GPU to finish it); `None`
    /// unless [`SplatRenderer::set_stage_timing`] is on.
    pub fn stage_times(&self, gl: &glow::Context) -> Option<StageTimes> {
        self.stages.as_ref().map(|q| q.read(gl))
    }
}
