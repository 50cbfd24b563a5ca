//! Program compile/link with numbered-source error reports, and uniform lookup.

use glow::HasContext;

use super::GlError;
use super::glsl::numbered;
use super::objects::Creating;

/// Compiles and links a program from two assembled sources; the caller owns (and deletes) the
/// program. Compile and link errors carry the driver's log and the numbered sources.
/// For the GL tests' host programs only (feature `testing`).
#[cfg(feature = "testing")]
pub fn build_program(
    gl: &glow::Context,
    name: &str,
    vertex: &str,
    fragment: &str,
) -> Result<glow::Program, GlError> {
    let mut objects = Creating::new(gl);
    let program = build_program_in(&mut objects, name, vertex, fragment)?;
    objects.release();
    Ok(program)
}

/// `build_program` with the program created in `objects` (deleted with them on a later
/// failure). The shaders are always deleted before returning.
pub(crate) fn build_program_in(
    objects: &mut Creating<'_>,
    name: &str,
    vertex: &str,
    fragment: &str,
) -> Result<glow::Program, GlError> {
    build_program_with_feedback(objects, name, vertex, fragment, &[])
}

/// [`build_program_in`], capturing the vertex outputs `varyings` (interleaved, in that order)
/// by transform feedback when not empty.
pub(crate) fn build_program_with_feedback(
    objects: &mut Creating<'_>,
    name: &str,
    vertex: &str,
    fragment: &str,
    varyings: &[&str],
) -> Result<glow::Program, GlError> {
    let gl = objects.gl();
    let program = objects.program()?;
    // Dropped (so deleted) on every path out of this function, after being detached.
    let mut shaders = Creating::new(gl);
    let mut attached = Vec::with_capacity(2);
    // SAFETY: compiles, attaches, links and detaches objects created just above on the current
    // context; `shaders` deletes the shaders on return, `objects` the program on failure.
    unsafe {
        for (stage, kind, src) in [
            ("vertex", glow::VERTEX_SHADER, vertex),
            ("fragment", glow::FRAGMENT_SHADER, fragment),
        ] {
            let shader = shaders.shader(kind)?;
            gl.shader_source(shader, src);
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                for &s in &attached {
                    gl.detach_shader(program, s);
                }
                return Err(GlError::Compile {
                    stage: format!("{stage} ({name})"),
                    log: gl.get_shader_info_log(shader),
                    numbered_source: numbered(src),
                });
            }
            gl.attach_shader(program, shader);
            attached.push(shader);
        }
        if !varyings.is_empty() {
            gl.transform_feedback_varyings(program, varyings, glow::INTERLEAVED_ATTRIBS);
        }
        gl.link_program(program);
        for &s in &attached {
            gl.detach_shader(program, s);
        }
        if !gl.get_program_link_status(program) {
            return Err(GlError::Link {
                program: name.to_owned(),
                log: gl.get_program_info_log(program),
                vertex: numbered(vertex),
                fragment: numbered(fragment),
            });
        }
    }
    Ok(program)
}

/// The locations of the uniforms the Rust side sets, in the order of `names`. With `check`
/// (the correct program, not an erratum variant, whose `#ifdef`s may leave some unused), a
/// debug build asserts that every one exists: a uniform renamed in GLSL but not in Rust fails
/// loudly instead of leaving its value unset.
pub(crate) fn uniform_locations<const N: usize>(
    gl: &glow::Context,
    program: glow::Program,
    program_name: &str,
    names: [&str; N],
    check: bool,
) -> [Option<glow::UniformLocation>; N] {
    // SAFETY: uniform queries on a linked program.
    let locations = names.map(|n| unsafe { gl.get_uniform_location(program, n) });
    if check {
        let missing: Vec<&str> = (names.iter().zip(&locations))
            .filter(|(_, l)| l.is_none())
            .map(|(n, _)| *n)
            .collect();
        debug_assert!(
            missing.is_empty(),
            "program `{program_name}`: uniform(s) {missing:?} set from Rust are not active in \
             the linked program (renamed or unused in the GLSL?)"
        );
    }
    locations
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::glsl::{Errata, GlslVersion, RESOLVE_FRAG, RESOLVE_VERT, assemble};

    #[cfg(debug_assertions)]
    #[test]
    fn a_uniform_missing_from_the_program_fails_loudly() {
        let ctx = match crate::headless::HeadlessContext::new() {
            Ok(c) => c,
            Err(crate::headless::HeadlessError::EglUnavailable(m)) => {
                // tests/common::skip's rule, for this unit test.
                assert!(
                    std::env::var("SPLATGL_REQUIRE").map_or(true, |v| v != "all"),
                    "SPLATGL_REQUIRE=all, but EGL cannot be opened here ({m})"
                );
                eprintln!("SKIPPED: EGL cannot be opened here ({m})");
                return;
            }
            Err(e) => panic!("{e}"),
        };
        let gl = ctx.gl();
        let v = assemble(
            GlslVersion::Es300,
            &Errata::default(),
            &crate::gl::data::TextureLayout::for_limits(2048, 1),
            RESOLVE_VERT,
        );
        let f = assemble(
            GlslVersion::Es300,
            &Errata::default(),
            &crate::gl::data::TextureLayout::for_limits(2048, 1),
            RESOLVE_FRAG,
        );
        // build_program_in, not build_program: the latter exists only with feature `testing`.
        let mut objects = Creating::new(gl);
        let program = build_program_in(&mut objects, "resolve", &v, &f).unwrap();
        objects.release();
        let all = uniform_locations(gl, program, "resolve", ["u_accum", "u_origin"], true);
        assert!(all.iter().all(Option::is_some));
        let renamed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            uniform_locations(gl, program, "resolve", ["u_accum", "u_renamed"], true)
        }));
        let msg = *renamed.unwrap_err().downcast::<String>().unwrap();
        assert!(msg.contains("[\"u_renamed\"]"), "{msg}");
        // SAFETY: deleting the program created above.
        unsafe { gl.delete_program(program) };
    }
}
