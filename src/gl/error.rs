//! [`GlError`], and the error scope around the backend's own GL calls: a host's pending
//! `glGetError` codes are drained before the backend checks its own and raised again after,
//! so the host still sees them ([`ErrorScope`]).

use glow::HasContext;

/// Errors of the GL layer.
#[derive(Debug, thiserror::Error)]
pub enum GlError {
    /// A shader stage failed to compile. `source` is the assembled source with line numbers.
    #[error("{stage} shader failed to compile:\n{log}\n--- source ---\n{numbered_source}")]
    Compile {
        /// `"vertex"` or `"fragment"`, with the program's name.
        stage: String,
        /// The driver's info log.
        log: String,
        /// The assembled source, one numbered line per source line.
        numbered_source: String,
    },
    /// The program failed to link.
    #[error(
        "program `{program}` failed to link:\n{log}\n--- vertex ---\n{vertex}\n--- fragment ---\n{fragment}"
    )]
    Link {
        /// Which program.
        program: String,
        /// The driver's info log.
        log: String,
        /// Numbered vertex source.
        vertex: String,
        /// Numbered fragment source.
        fragment: String,
    },
    /// A GL object could not be created (the driver's message).
    #[error("could not create GL {what}: {message}")]
    Create {
        /// What kind of object.
        what: &'static str,
        /// The driver's message.
        message: String,
    },
    /// The context lacks something the backend needs.
    #[error("unsupported GL context: {0}")]
    Unsupported(String),
    /// The context's version is older than the backend needs.
    #[error("GL context version `{found}` found; splatgl needs {needed}")]
    ContextVersion {
        /// The context's `GL_VERSION` string.
        found: String,
        /// The versions that work.
        needed: &'static str,
    },
    /// An extension the operation needs is missing.
    #[error("{needed_for} needs the GL extension {extension}, which this context lacks")]
    MissingExtension {
        /// The extension (or the alternatives, e.g. `A or B`).
        extension: &'static str,
        /// What needs it.
        needed_for: &'static str,
    },
    /// The cloud is larger than the data textures can hold on this context.
    #[error("{splats} splats do not fit the data textures: {limits} hold at most {fits} splats")]
    Capacity {
        /// Splats asked for.
        splats: usize,
        /// The most that fit (for this SH degree).
        fits: usize,
        /// The limits that bind, with their values.
        limits: String,
    },
    /// The host had a GL error pending that the backend cannot raise again after checking its
    /// own calls (`GL_OUT_OF_MEMORY`, `GL_INVALID_FRAMEBUFFER_OPERATION`, stack or context-loss
    /// errors): it is reported here instead of being swallowed. The operation was not done.
    #[error("the host left GL error 0x{code:04X} pending before splatgl's call; not attempted")]
    HostError {
        /// The host's error code.
        code: u32,
    },
    /// A host projection matrix that is not a perspective projection the splat maths can
    /// use, or a model matrix that is not a finite affine transform.
    #[error("unsupported matrix: {0}")]
    Matrix(String),
    /// The cloud (or scene) is inconsistent or cannot be uploaded as given.
    #[error("cannot upload cloud: {0}")]
    Upload(String),
    /// `draw` was given more indices than the uploaded cloud has splats.
    #[error("order has {got} indices but the uploaded cloud has {capacity} splats")]
    OrderTooLong {
        /// Length of the order passed.
        got: usize,
        /// Splats uploaded.
        capacity: usize,
    },
    /// A viewport without pixels (`x, y, width, height` with a width or height ≤ 0).
    #[error("viewport {0:?} has no pixels (x, y, width, height)")]
    Viewport([i32; 4]),
    /// `draw` was called before `upload`.
    #[error("draw called before upload")]
    NotUploaded,
    /// A framebuffer was incomplete.
    #[error("framebuffer incomplete: status 0x{0:04X}")]
    Framebuffer(u32),
    /// A method was called after `destroy` (the name of the type).
    #[error("{0} used after destroy()")]
    Destroyed(&'static str),
    /// `glGetError` reported an error after an operation.
    #[error("GL error 0x{code:04X} after {during}")]
    Gl {
        /// The error code.
        code: u32,
        /// What the backend was doing.
        during: &'static str,
    },
}

/// At most this many pending error flags are drained (GL keeps one per kind of error at most;
/// Mesa keeps one in all).
const MAX_PENDING: usize = 8;

/// A stretch of the backend's own GL calls whose errors are checked without swallowing the
/// host's: [`ErrorScope::begin`] drains the codes the host left pending, [`ErrorScope::end`]
/// reads the backend's own, and on drop the host's codes are raised again, in order, with a
/// side-effect-free invalid call each (a `glGetIntegerv(0)`, a vertex-attribute query past
/// the last attribute, a result query on a query name never begun). A host with
/// `KHR_debug` output sees those calls as messages.
pub(crate) struct ErrorScope<'gl> {
    gl: &'gl glow::Context,
    host: [u32; MAX_PENDING],
    pending: usize,
}

impl<'gl> ErrorScope<'gl> {
    /// Drains the host's pending errors. Fails with [`GlError::HostError`] (the host's code
    /// reported, the others raised again) when one cannot be raised again.
    pub(crate) fn begin(gl: &'gl glow::Context) -> Result<Self, GlError> {
        let mut scope = ErrorScope {
            gl,
            host: [glow::NO_ERROR; MAX_PENDING],
            pending: 0,
        };
        let mut unraisable = None;
        for _ in 0..MAX_PENDING {
            // SAFETY: glGetError has no preconditions beyond a current context, which every
            // caller of this crate's GL functions must provide.
            let code = unsafe { gl.get_error() };
            if code == glow::NO_ERROR {
                break;
            }
            if reraisable(code) {
                scope.host[scope.pending] = code;
                scope.pending += 1;
            } else {
                unraisable.get_or_insert(code);
            }
        }
        match unraisable {
            Some(code) => Err(GlError::HostError { code }), // `scope` drops: the rest re-raised
            None => Ok(scope),
        }
    }

    /// Reads the errors the backend's calls since [`ErrorScope::begin`] caused (the first is
    /// reported), then raises the host's again.
    pub(crate) fn end(self, during: &'static str) -> Result<(), GlError> {
        match drain(self.gl) {
            glow::NO_ERROR => Ok(()),
            code => Err(GlError::Gl { code, during }),
        }
    }
}

impl Drop for ErrorScope<'_> {
    fn drop(&mut self) {
        // Errors of ours left by an early return were reported by that return: drop them, so
        // that the host's codes come first again.
        drain(self.gl);
        for &code in &self.host[..self.pending] {
            raise(self.gl, code);
        }
    }
}

/// Reads and clears every pending error flag, returning the first (or `NO_ERROR`).
fn drain(gl: &glow::Context) -> u32 {
    let mut first = glow::NO_ERROR;
    for _ in 0..MAX_PENDING {
        // SAFETY: as in `ErrorScope::begin`.
        let code = unsafe { gl.get_error() };
        if code == glow::NO_ERROR {
            break;
        }
        if first == glow::NO_ERROR {
            first = code;
        }
    }
    first
}

/// Whether [`raise`] can produce `code`.
fn reraisable(code: u32) -> bool {
    matches!(
        code,
        glow::INVALID_ENUM | glow::INVALID_VALUE | glow::INVALID_OPERATION
    )
}

/// Raises `code` (one of [`reraisable`]'s) with a call that has no other effect.
fn raise(gl: &glow::Context, code: u32) {
    // SAFETY: each call is an invalid query: GL records the error and writes nothing (the
    // output buffers are valid anyway).
    unsafe {
        match code {
            glow::INVALID_ENUM => {
                gl.get_parameter_i32(0);
            }
            glow::INVALID_VALUE => {
                let mut out = [0.0f32; 4];
                gl.get_vertex_attrib_parameter_f32_slice(
                    u32::MAX,
                    glow::CURRENT_VERTEX_ATTRIB,
                    &mut out,
                );
            }
            glow::INVALID_OPERATION => {
                // A query name never begun is not a query object yet: asking for its result
                // is invalid. The name is the backend's own and deleted at once.
                if let Ok(q) = gl.create_query() {
                    gl.get_query_parameter_u32(q, glow::QUERY_RESULT_AVAILABLE);
                    gl.delete_query(q);
                }
            }
            _ => {}
        }
    }
}

/// Checks `glGetError` where no host error can be pending (the headless renderer's own
/// context).
pub(crate) fn check_error(gl: &glow::Context, during: &'static str) -> Result<(), GlError> {
    match drain(gl) {
        glow::NO_ERROR => Ok(()),
        code => Err(GlError::Gl { code, during }),
    }
}
