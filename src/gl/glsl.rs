//! GLSL assembly: the sources in `glsl/`, the `#version` line, and the `#define`s.
//!
//! The GLSL files are written in the common subset of GLSL ES 3.00 and GLSL 3.30 and have no
//! `#version` line: [`assemble`] prepends the version for the context ([`GlslVersion`]),
//! precision statements, and the `#define`s from [`defines`] — every number the kernel uses
//! comes from [`crate::profile`] and [`crate::sh`]; the tests below fail if a define disagrees
//! with its Rust constant or a shader spells one of those values as a literal.

use super::context::{ContextInfo, Profile};
use super::data::TextureLayout;
use crate::profile;

/// Vertex stage of the splat program (direct path).
pub(crate) const SPLAT_VERT: &str = include_str!("../../glsl/splat.vert");
/// The per-splat maths, spliced into the vertex stages at `//@include splat_project.glsl`.
pub(crate) const SPLAT_PROJECT_GLSL: &str = include_str!("../../glsl/splat_project.glsl");
/// Vertex stage of the transform-feedback pre-pass.
pub(crate) const SPLAT_PREP_VERT: &str = include_str!("../../glsl/splat_prep.vert");
/// Vertex stage of the splat program after the pre-pass.
pub(crate) const SPLAT_QUAD_VERT: &str = include_str!("../../glsl/splat_quad.vert");
/// Fragment stage of the pre-pass (never runs: the rasterizer is discarded).
pub(crate) const DISCARD_FRAG: &str = include_str!("../../glsl/discard.frag");
/// Texel addressing of the array textures, spliced in at `//@include texel.glsl`.
pub(crate) const TEXEL_GLSL: &str = include_str!("../../glsl/texel.glsl");
/// Spherical-harmonics colour, spliced into the per-splat maths at `//@include sh.glsl`.
pub(crate) const SH_GLSL: &str = include_str!("../../glsl/sh.glsl");
/// Fragment stage of the splat program.
pub(crate) const SPLAT_FRAG: &str = include_str!("../../glsl/splat.frag");
/// Vertex stage of the resolve pass.
pub(crate) const RESOLVE_VERT: &str = include_str!("../../glsl/resolve.vert");
/// Fragment stage of the resolve pass.
pub(crate) const RESOLVE_FRAG: &str = include_str!("../../glsl/resolve.frag");

/// The `#version` line to compile with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum GlslVersion {
    /// `#version 300 es` (OpenGL ES 3.x, WebGL2).
    Es300,
    /// `#version 330 core` (desktop OpenGL 3.3+).
    Core330,
}

impl GlslVersion {
    /// The version for a context: ES contexts get `300 es`, desktop ones (core or
    /// compatibility profile) `330 core`.
    pub(crate) fn for_context(ctx: ContextInfo) -> Self {
        if ctx.profile == Profile::Es {
            GlslVersion::Es300
        } else {
            GlslVersion::Core330
        }
    }

    /// The `#version` line.
    pub(crate) fn line(self) -> &'static str {
        match self {
            GlslVersion::Es300 => "#version 300 es",
            GlslVersion::Core330 => "#version 330 core",
        }
    }
}

/// Switches that put the review draft's Appendix A behaviour back, one erratum each (see
/// `docs/appendix-errata.md`), and the former quads. **For the erratum tests and the
/// benchmarks only** (feature `testing`): every erratum field makes the output wrong on
/// purpose. `Errata::default()` is the correct renderer, and the only one users can build.
#[doc(hidden)]
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
    /// Not an erratum: the quads before the opacity-aware extent (the 3σ ellipse's rectangle
    /// whatever the opacity, [`crate::profile::FORMER_QUAD_MARGIN_PX`] margin). The same image
    /// with more fragments: the benchmarks' baseline. Every erratum variant draws these too.
    pub former_quads: bool,
}

impl Errata {
    /// Only the former quads ([`Errata::former_quads`]): the correct image by the path the
    /// benchmarks compare against.
    #[cfg(feature = "testing")]
    pub const FORMER_QUADS: Errata = Errata {
        a_transposed_rotation: false,
        b_transposed_view: false,
        d_focal_offset: false,
        e_appendix_sh: false,
        f_power_4: false,
        g_src_alpha_blend: false,
        i_no_dilation: false,
        k_no_clamp_no_cap: false,
        former_quads: true,
    };
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
        if *self != Errata::default() {
            // Erratum variants and the benchmarks' baseline: the former quads, whose margin
            // only they need.
            s.push_str("#define FORMER_QUADS\n");
            let margin = float_lit(profile::FORMER_QUAD_MARGIN_PX as f32 as f64);
            s.push_str(&format!("#define FORMER_QUAD_MARGIN_PX {margin}\n"));
        }
        s
    }
}

/// A GLSL float literal that round-trips the value (always has an exponent, so it is a float).
fn float_lit(v: f64) -> String {
    format!("{v:e}")
}

/// The `#define`s shared by all stages: kernel constants, SH constants, texture layout
/// (data textures `2^width_log2` texels wide, `2^layer_rows_log2` rows per full layer), the
/// scene's cloud limit. Floats are written as the f32 the GPU uses (the profile's f64 values
/// rounded once), except the SH constants, written in full.
pub(crate) fn defines(layout: &TextureLayout) -> String {
    use crate::sh::{SH_C0, SH_C1, SH_C2, SH_C3};
    let mut s = String::new();
    let mut def = |name: &str, value: String| s.push_str(&format!("#define {name} {value}\n"));
    let f32_lit = |v: f64| float_lit(v as f32 as f64);
    def("DILATION", f32_lit(profile::DILATION_PX2));
    def("CUTOFF_M2", f32_lit(profile::CUTOFF_M2 as f64));
    def("ALPHA_MAX", f32_lit(profile::ALPHA_MAX as f64));
    def("ALPHA_MIN", f32_lit(profile::ALPHA_MIN as f64));
    def("OPACITY_M2_MARGIN", f32_lit(profile::OPACITY_M2_MARGIN));
    def("QUAD_AXIS_FACTOR", f32_lit(profile::QUAD_AXIS_FACTOR));
    def("QUAD_MARGIN_PX", f32_lit(profile::QUAD_MARGIN_PX));
    def("FOV_CLAMP", f32_lit(profile::JACOBIAN_CLAMP));
    def("SH_DC_BIAS", f32_lit(profile::SH_DC_BIAS));
    def("SH_C0", float_lit(SH_C0));
    def("SH_C1", float_lit(SH_C1));
    for (i, c) in SH_C2.iter().enumerate() {
        def(&format!("SH_C2_{i}"), float_lit(*c));
    }
    for (i, c) in SH_C3.iter().enumerate() {
        def(&format!("SH_C3_{i}"), float_lit(*c));
    }
    def(
        "SRGB_ENCODE_THRESHOLD",
        f32_lit(profile::SRGB_ENCODE_THRESHOLD),
    );
    def("SRGB_LINEAR_SLOPE", f32_lit(profile::SRGB_LINEAR_SLOPE));
    def("SRGB_SCALE", f32_lit(profile::SRGB_SCALE));
    def("SRGB_OFFSET", f32_lit(profile::SRGB_OFFSET));
    def("SRGB_GAMMA", f32_lit(profile::SRGB_GAMMA));
    def("TEX_WIDTH", (1u32 << layout.width_log2).to_string());
    def("TEX_WIDTH_LOG2", layout.width_log2.to_string());
    def("LAYER_ROWS", (1u32 << layout.layer_rows_log2).to_string());
    def("LAYER_ROWS_LOG2", layout.layer_rows_log2.to_string());
    def("MAX_CLOUDS", super::SplatScene::MAX_CLOUDS.to_string());
    def("GEOM_TEXELS", profile::GEOM_TEXELS.to_string());
    let texel = profile::GEOM_TEXEL_POSITION_OPACITY.to_string();
    def("GEOM_TEXEL_POSITION_OPACITY", texel);
    def(
        "GEOM_TEXEL_ROTATION",
        profile::GEOM_TEXEL_ROTATION.to_string(),
    );
    def("GEOM_TEXEL_SCALE", profile::GEOM_TEXEL_SCALE.to_string());
    let max_sh = profile::sh_texels(crate::cloud::MAX_SH_DEGREE);
    def("MAX_SH_TEXELS", max_sh.to_string());
    def("RECORD_TEXELS", profile::RECORD_TEXELS.to_string());
    def(
        "QUADS_PER_INSTANCE",
        profile::QUADS_PER_INSTANCE.to_string(),
    );
    s
}

/// Assembles one stage: version line, precision, defines (see [`defines`]), then the file (with
/// `//@include splat_project.glsl`, `//@include texel.glsl` and `//@include sh.glsl` replaced by
/// those files).
pub(crate) fn assemble(
    version: GlslVersion,
    errata: &Errata,
    layout: &TextureLayout,
    body: &str,
) -> String {
    // Desktop GLSL accepts (and ignores) float/int precision; sampler precision is ES-only.
    let precision = match version {
        GlslVersion::Es300 => {
            "precision highp float;\nprecision highp int;\nprecision highp sampler2D;\n\
             precision highp sampler2DArray;\n"
        }
        GlslVersion::Core330 => "precision highp float;\nprecision highp int;\n",
    };
    format!(
        "{}\n{precision}{}{}{}",
        version.line(),
        defines(layout),
        errata.defines(),
        body.replace("//@include splat_project.glsl", SPLAT_PROJECT_GLSL)
            .replace("//@include texel.glsl", TEXEL_GLSL)
            .replace("//@include sh.glsl", SH_GLSL)
    )
}

/// The source with each line prefixed by its number (what compile errors refer to).
pub(crate) fn numbered(source: &str) -> String {
    source
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{:4} | {l}\n", i + 1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sh::{SH_C0, SH_C1, SH_C2, SH_C3};
    use std::collections::BTreeMap;

    /// The GLSL sources, by file name.
    const SOURCES: [(&str, &str); 10] = [
        ("splat.vert", SPLAT_VERT),
        ("texel.glsl", TEXEL_GLSL),
        ("splat_project.glsl", SPLAT_PROJECT_GLSL),
        ("splat_prep.vert", SPLAT_PREP_VERT),
        ("splat_quad.vert", SPLAT_QUAD_VERT),
        ("discard.frag", DISCARD_FRAG),
        ("sh.glsl", SH_GLSL),
        ("splat.frag", SPLAT_FRAG),
        ("resolve.vert", RESOLVE_VERT),
        ("resolve.frag", RESOLVE_FRAG),
    ];

    /// The layout the tests use: 2048 × 2048 layers.
    fn layout() -> TextureLayout {
        TextureLayout::for_limits(2048, 256)
    }

    /// `#define NAME VALUE` lines of `defines(&layout())`, parsed.
    fn parsed_defines() -> BTreeMap<String, f64> {
        defines(&layout())
            .lines()
            .map(|l| {
                let mut it = l.strip_prefix("#define ").expect(l).split(' ');
                let (name, value) = (it.next().unwrap(), it.next().expect(l));
                (name.to_owned(), value.parse::<f64>().expect(l))
            })
            .collect()
    }

    /// Every define with the Rust value it must carry (written out here, independently of
    /// `defines`): the profile's constants and the SH basis.
    fn rust_twins() -> Vec<(String, f64)> {
        let mut v: Vec<(String, f64)> = vec![
            ("DILATION".into(), profile::DILATION_PX2),
            ("CUTOFF_M2".into(), profile::CUTOFF_M2 as f64),
            ("ALPHA_MAX".into(), profile::ALPHA_MAX as f64),
            ("ALPHA_MIN".into(), profile::ALPHA_MIN as f64),
            ("OPACITY_M2_MARGIN".into(), profile::OPACITY_M2_MARGIN),
            ("QUAD_AXIS_FACTOR".into(), profile::QUAD_AXIS_FACTOR),
            ("QUAD_MARGIN_PX".into(), profile::QUAD_MARGIN_PX),
            ("FOV_CLAMP".into(), profile::JACOBIAN_CLAMP),
            ("SH_DC_BIAS".into(), profile::SH_DC_BIAS),
            ("SH_C0".into(), SH_C0),
            ("SH_C1".into(), SH_C1),
            (
                "SRGB_ENCODE_THRESHOLD".into(),
                profile::SRGB_ENCODE_THRESHOLD,
            ),
            ("SRGB_LINEAR_SLOPE".into(), profile::SRGB_LINEAR_SLOPE),
            ("SRGB_SCALE".into(), profile::SRGB_SCALE),
            ("SRGB_OFFSET".into(), profile::SRGB_OFFSET),
            ("SRGB_GAMMA".into(), profile::SRGB_GAMMA),
            ("GEOM_TEXELS".into(), profile::GEOM_TEXELS as f64),
            (
                "GEOM_TEXEL_POSITION_OPACITY".into(),
                profile::GEOM_TEXEL_POSITION_OPACITY as f64,
            ),
            (
                "GEOM_TEXEL_ROTATION".into(),
                profile::GEOM_TEXEL_ROTATION as f64,
            ),
            ("GEOM_TEXEL_SCALE".into(), profile::GEOM_TEXEL_SCALE as f64),
            ("MAX_SH_TEXELS".into(), profile::sh_texels(3) as f64),
            ("RECORD_TEXELS".into(), profile::RECORD_TEXELS as f64),
            (
                "QUADS_PER_INSTANCE".into(),
                profile::QUADS_PER_INSTANCE as f64,
            ),
            ("TEX_WIDTH".into(), 2048.0),
            ("TEX_WIDTH_LOG2".into(), 11.0),
            ("LAYER_ROWS".into(), 2048.0),
            ("LAYER_ROWS_LOG2".into(), 11.0),
            (
                "MAX_CLOUDS".into(),
                crate::gl::SplatScene::MAX_CLOUDS as f64,
            ),
        ];
        v.extend(
            SH_C2
                .iter()
                .enumerate()
                .map(|(i, c)| (format!("SH_C2_{i}"), *c)),
        );
        v.extend(
            SH_C3
                .iter()
                .enumerate()
                .map(|(i, c)| (format!("SH_C3_{i}"), *c)),
        );
        v
    }

    #[test]
    fn defines_carry_rust_constants() {
        let d = defines(&layout());
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
    fn every_define_equals_its_rust_constant_as_the_gpu_reads_it() {
        let defs = parsed_defines();
        let twins = rust_twins();
        for (name, want) in &twins {
            let got = defs
                .get(name)
                .unwrap_or_else(|| panic!("no #define {name}"));
            assert_eq!(*got as f32, *want as f32, "#define {name}");
        }
        let known: Vec<&String> = twins.iter().map(|(n, _)| n).collect();
        for name in defs.keys() {
            assert!(
                known.contains(&name),
                "#define {name} has no Rust twin in this test"
            );
        }
    }

    #[test]
    fn only_switched_programs_carry_the_former_quads() {
        assert_eq!(Errata::default().defines(), "");
        let former = Errata {
            former_quads: true,
            ..Errata::default()
        };
        let d = former.defines();
        let margin = d
            .lines()
            .find_map(|l| l.strip_prefix("#define FORMER_QUAD_MARGIN_PX "))
            .expect("the former quads' margin");
        let margin: f64 = margin.parse().unwrap();
        assert_eq!(margin as f32, profile::FORMER_QUAD_MARGIN_PX as f32);
        assert!(d.starts_with("#define FORMER_QUADS\n"), "{d}");
    }

    #[test]
    fn every_define_is_used_by_a_shader() {
        let words = |src: &'static str| {
            src.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .collect::<Vec<_>>()
        };
        let used: Vec<&str> = SOURCES.iter().flat_map(|(_, s)| words(s)).collect();
        for name in parsed_defines().keys() {
            assert!(
                used.contains(&name.as_str()),
                "#define {name} unused in glsl/"
            );
        }
    }

    /// Float literals (with a `.` or an exponent) in GLSL source, comments removed, with
    /// their line numbers.
    fn float_literals(src: &str) -> Vec<(usize, f64, String)> {
        let mut out = Vec::new();
        for (n, line) in src.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let b = code.as_bytes();
            let mut i = 0;
            while i < b.len() {
                let starts = b[i].is_ascii_digit()
                    || (b[i] == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
                let in_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
                if !starts || in_word {
                    i += 1;
                    continue;
                }
                let mut j = i;
                while j < b.len()
                    && (b[j].is_ascii_digit()
                        || b[j] == b'.'
                        || matches!(b[j], b'e' | b'E')
                        || (matches!(b[j], b'+' | b'-') && matches!(b[j - 1], b'e' | b'E')))
                {
                    j += 1;
                }
                let tok = &code[i..j];
                if tok.contains(['.', 'e', 'E']) {
                    out.push((n + 1, tok.parse::<f64>().expect(tok), tok.to_owned()));
                }
                i = j;
            }
        }
        out
    }

    #[test]
    fn shaders_spell_no_profile_value_as_a_literal() {
        // Values so common in plain arithmetic (halves, small integers: `0.5 * x`, `2.0 * zz`)
        // that a literal proves nothing; their defines are covered by
        // `every_define_is_used_by_a_shader`.
        let ordinary = [0.0, 0.5, 1.0, 2.0, 3.0, 4.0];
        let values: Vec<(String, f64)> = rust_twins()
            .into_iter()
            .filter(|(_, v)| !ordinary.contains(&v.abs()))
            .collect();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs();
        let mut found = Vec::new();
        for (file, src) in SOURCES {
            for (line, lit, tok) in float_literals(src) {
                for (name, v) in &values {
                    if close(lit, v.abs()) || close(1.0 / lit, v.abs()) {
                        found.push(format!("glsl/{file}:{line}: `{tok}` is {name}"));
                    }
                }
            }
        }
        assert!(found.is_empty(), "use the #defines:\n{}", found.join("\n"));
        // The scanner itself finds what it should.
        let probe = float_literals("x = 0.99 * y + 1.0/255.0; // 1.3\nz = 12.92e0 + a2.5;");
        let toks: Vec<&str> = probe.iter().map(|(_, _, t)| t.as_str()).collect();
        assert_eq!(toks, ["0.99", "1.0", "255.0", "12.92e0"]);
    }

    #[test]
    fn assembled_source_starts_with_version_and_splices_sh() {
        let s = assemble(
            GlslVersion::Es300,
            &Errata::default(),
            &layout(),
            SPLAT_VERT,
        );
        assert!(s.starts_with("#version 300 es\n"));
        assert!(s.contains("vec3 sh_color(int splat, vec3 view_dir)"));
        assert!(!s.contains("ERRATUM_A\n#") && !s.contains("#define ERRATUM"));
        let e = Errata {
            a_transposed_rotation: true,
            ..Errata::default()
        };
        assert!(
            assemble(GlslVersion::Core330, &e, &layout(), SPLAT_VERT).contains("#define ERRATUM_A")
        );
    }

    #[test]
    fn numbered_lines() {
        assert_eq!(numbered("a\nb"), "   1 | a\n   2 | b\n");
    }
}
