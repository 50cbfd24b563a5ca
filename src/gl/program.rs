//! GLSL assembly and program compile/link.
//!
//! The GLSL files in `glsl/` are written in the common subset of GLSL ES 3.00 and GLSL 3.30 and
//! have no `#version` line: [`assemble`] prepends the version for the context
//! ([`GlslVersion`]), precision statements, and the `#define`s from [`defines`] — every number
//! the kernel uses comes from [`super::consts`] and [`crate::sh`].

use glow::HasContext;

use super::GlError;
use super::consts;
use super::data;

/// Vertex stage of the splat program.
pub const SPLAT_VERT: &str = include_str!("../../glsl/splat.vert");
/// Spherical-harmonics colour, spliced into the vertex stage at `//@include sh.glsl`.
pub const SH_GLSL: &str = include_str!("../../glsl/sh.glsl");
/// Fragment stage of the splat program.
pub const SPLAT_FRAG: &str = include_str!("../../glsl/splat.frag");
/// Vertex stage of the resolve pass.
pub const RESOLVE_VERT: &str = include_str!("../../glsl/resolve.vert");
/// Fragment stage of the resolve pass.
pub const RESOLVE_FRAG: &str = include_str!("../../glsl/resolve.frag");

/// The `#version` line to compile with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GlslVersion {
    /// `#version 300 es` (OpenGL ES 3.x, WebGL2).
    Es300,
    /// `#version 330 core` (desktop OpenGL 3.3+).
    Core330,
}

impl GlslVersion {
    /// The version for a context: ES contexts get `300 es`, desktop ones `330 core`.
    pub fn for_context(gl: &glow::Context) -> Self {
        if gl.version().is_embedded {
            GlslVersion::Es300
        } else {
            GlslVersion::Core330
        }
    }

    /// The `#version` line.
    pub fn line(self) -> &'static str {
        match self {
            GlslVersion::Es300 => "#version 300 es",
            GlslVersion::Core330 => "#version 330 core",
        }
    }
}

/// Switches that put the review draft's Appendix A behaviour back, one erratum each (see
/// `docs/appendix-errata.md`). **For tests and demonstrations only**: every `true` field makes
/// the output wrong on purpose. `Errata::default()` is the correct renderer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Errata {
    /// (a) rotation matrix written row-wise into `mat3(...)` → Rᵀ.
    pub a_transposed_rotation: bool,
    /// (b) `W = transpose(mat3(view))`.
    pub b_transposed_view: bool,
    /// (d) quad offset `radius / focal · w` and the appendix's `v_center_px` formula.
    pub d_focal_offset: bool,
    /// (e) SH without Condon–Shortley signs, 2.89 for coefficient 14, sigmoid colour.
    pub e_appendix_sh: bool,
    /// (f) discard at power > 4 (2.83σ) instead of 4.5 (3σ).
    pub f_power_4: bool,
    /// (g) `blendFunc(SRC_ALPHA, ONE_MINUS_SRC_ALPHA)` on premultiplied output. (The
    /// appendix's front-to-back order is the caller's: pass the reversed order.)
    pub g_src_alpha_blend: bool,
    /// (i) no 0.3 px² dilation of Σ'.
    pub i_no_dilation: bool,
    /// (k) no ±1.3·tan(half fov) clamp inside J and no 0.99 cap on α.
    pub k_no_clamp_no_cap: bool,
}

impl Errata {
    fn defines(&self) -> String {
        let mut s = String::new();
        for (on, name) in [
            (self.a_transposed_rotation, "ERRATUM_A"),
            (self.b_transposed_view, "ERRATUM_B"),
            (self.d_focal_offset, "ERRATUM_D"),
            (self.e_appendix_sh, "ERRATUM_E"),
            (self.f_power_4, "ERRATUM_F"),
            (self.i_no_dilation, "ERRATUM_I"),
            (self.k_no_clamp_no_cap, "ERRATUM_K"),
        ] {
            if on {
                s.push_str(&format!("#define {name}\n"));
            }
        }
        s
    }
}

/// A GLSL float literal that round-trips the value (always has an exponent, so it is a float).
fn float_lit(v: f64) -> String {
    format!("{v:e}")
}

/// The `#define`s shared by all stages: kernel constants, SH constants, texture layout
/// (data textures `2^tex_width_log2` texels wide).
pub fn defines(tex_width_log2: u32) -> String {
    use crate::sh::{SH_C0, SH_C1, SH_C2, SH_C3};
    let mut s = String::new();
    let mut def = |name: &str, value: String| s.push_str(&format!("#define {name} {value}\n"));
    def("DILATION", float_lit(consts::DILATION as f64));
    def("CUTOFF_M2", float_lit(consts::CUTOFF_M2 as f64));
    def("ALPHA_MAX", float_lit(consts::ALPHA_MAX as f64));
    def("ALPHA_MIN", float_lit(consts::ALPHA_MIN as f64));
    def("FOV_CLAMP", float_lit(consts::FOV_CLAMP as f64));
    def("SH_DC_BIAS", float_lit(consts::SH_DC_BIAS as f64));
    def("SH_C0", float_lit(SH_C0));
    def("SH_C1", float_lit(SH_C1));
    for (i, c) in SH_C2.iter().enumerate() {
        def(&format!("SH_C2_{i}"), float_lit(*c));
    }
    for (i, c) in SH_C3.iter().enumerate() {
        def(&format!("SH_C3_{i}"), float_lit(*c));
    }
    def("TEX_WIDTH", (1u32 << tex_width_log2).to_string());
    def("TEX_WIDTH_LOG2", tex_width_log2.to_string());
    def("GEOM_TEXELS", data::GEOM_TEXELS.to_string());
    def(
        "MAX_SH_TEXELS",
        data::sh_texels(crate::cloud::MAX_SH_DEGREE).to_string(),
    );
    s
}

/// Assembles one stage: version line, precision, defines (see [`defines`]), then the file (with
/// `//@include sh.glsl` replaced by [`SH_GLSL`]).
pub fn assemble(version: GlslVersion, errata: &Errata, tex_width_log2: u32, body: &str) -> String {
    // Desktop GLSL accepts (and ignores) float/int precision; sampler precision is ES-only.
    let precision = match version {
        GlslVersion::Es300 => {
            "precision highp float;\nprecision highp int;\nprecision highp sampler2D;\n"
        }
        GlslVersion::Core330 => "precision highp float;\nprecision highp int;\n",
    };
    format!(
        "{}\n{precision}{}{}{}",
        version.line(),
        defines(tex_width_log2),
        errata.defines(),
        body.replace("//@include sh.glsl", SH_GLSL)
    )
}

/// The source with each line prefixed by its number (what compile errors refer to).
pub fn numbered(source: &str) -> String {
    source
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{:4} | {l}\n", i + 1))
        .collect()
}

/// Compiles and links a program from two assembled sources.
pub fn build_program(
    gl: &glow::Context,
    name: &str,
    vertex: &str,
    fragment: &str,
) -> Result<glow::Program, GlError> {
    // SAFETY: plain object creation and queries on the current context; every object created
    // here is deleted on every error path, and shaders are detached/deleted after linking.
    unsafe {
        let program = gl.create_program().map_err(|message| GlError::Create {
            what: "program",
            message,
        })?;
        let mut shaders = Vec::with_capacity(2);
        for (stage, kind, src) in [
            ("vertex", glow::VERTEX_SHADER, vertex),
            ("fragment", glow::FRAGMENT_SHADER, fragment),
        ] {
            let shader = match gl.create_shader(kind) {
                Ok(s) => s,
                Err(message) => {
                    for s in shaders {
                        gl.delete_shader(s);
                    }
                    gl.delete_program(program);
                    return Err(GlError::Create {
                        what: "shader",
                        message,
                    });
                }
            };
            gl.shader_source(shader, src);
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                let log = gl.get_shader_info_log(shader);
                gl.delete_shader(shader);
                for s in shaders {
                    gl.delete_shader(s);
                }
                gl.delete_program(program);
                return Err(GlError::Compile {
                    stage: format!("{stage} ({name})"),
                    log,
                    numbered_source: numbered(src),
                });
            }
            gl.attach_shader(program, shader);
            shaders.push(shader);
        }
        gl.link_program(program);
        let ok = gl.get_program_link_status(program);
        for s in shaders {
            gl.detach_shader(program, s);
            gl.delete_shader(s);
        }
        if !ok {
            let log = gl.get_program_info_log(program);
            gl.delete_program(program);
            return Err(GlError::Link {
                program: name.to_owned(),
                log,
                vertex: numbered(vertex),
                fragment: numbered(fragment),
            });
        }
        Ok(program)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_carry_rust_constants() {
        let d = defines(11);
        assert!(d.contains(&format!("#define DILATION {}", float_lit(0.3f32 as f64))));
        assert!(d.contains("#define SH_C3_5 1.445"));
        assert!(d.contains("#define MAX_SH_TEXELS 12"));
        assert!(d.contains("#define TEX_WIDTH 2048\n#define TEX_WIDTH_LOG2 11\n"));
        // Every float literal has an exponent (so GLSL reads it as float).
        for line in d.lines().filter(|l| l.contains("SH_C")) {
            assert!(line.contains('e'), "{line}");
        }
    }

    #[test]
    fn assembled_source_starts_with_version_and_splices_sh() {
        let s = assemble(GlslVersion::Es300, &Errata::default(), 11, SPLAT_VERT);
        assert!(s.starts_with("#version 300 es\n"));
        assert!(s.contains("vec3 sh_color(int splat, vec3 view_dir)"));
        assert!(!s.contains("ERRATUM_A\n#") && !s.contains("#define ERRATUM"));
        let e = Errata {
            a_transposed_rotation: true,
            ..Errata::default()
        };
        assert!(assemble(GlslVersion::Core330, &e, 11, SPLAT_VERT).contains("#define ERRATUM_A"));
    }

    #[test]
    fn numbered_lines() {
        assert_eq!(numbered("a\nb"), "   1 | a\n   2 | b\n");
    }
}
