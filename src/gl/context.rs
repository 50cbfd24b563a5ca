//! What kind of context the backend runs on: the version check of `SplatRenderer::new` and
//! the profile, which decides the GLSL `#version` and which pieces of state exist.

use glow::HasContext;

use super::GlError;
use super::caps::{self, injected};

/// The versions the backend works on (WebGL2-class: GLSL ES 3.00 or GLSL 3.30).
pub(crate) const NEEDED: &str = "OpenGL ≥ 3.3 or OpenGL ES ≥ 3.0";

/// The kind of context.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Profile {
    /// OpenGL ES 3.x.
    Es,
    /// Desktop core profile.
    Core,
    /// Desktop compatibility profile (the fixed-function pipeline is there too).
    Compat,
}

/// The context facts the backend's state handling depends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ContextInfo {
    pub(crate) profile: Profile,
    /// `GL_FRAMEBUFFER_SRGB` can be switched: desktop GL, or ES with
    /// `GL_EXT_sRGB_write_control`.
    pub(crate) srgb_switch: bool,
    /// Transform-feedback objects exist (`glBindTransformFeedback`): ES 3.x, desktop GL ≥ 4.0
    /// or `GL_ARB_transform_feedback2`. The pre-pass needs them.
    pub(crate) tf_objects: bool,
}

impl ContextInfo {
    /// Desktop GL (core or compatibility).
    pub(crate) fn desktop(self) -> bool {
        self.profile != Profile::Es
    }

    /// Checks the version (`GL_VERSION`, or the one injected by the fault hooks) and finds the
    /// profile.
    pub(crate) fn check(gl: &glow::Context) -> Result<Self, GlError> {
        let version = injected!(String, |f| f.gl_version.clone())
            // SAFETY: a string query.
            .unwrap_or_else(|| unsafe { gl.get_parameter_string(glow::VERSION) });
        let Some((es, major, minor)) = parse_version(&version) else {
            return Err(GlError::ContextVersion {
                found: version,
                needed: NEEDED,
            });
        };
        let ok = if es {
            major >= 3
        } else {
            (major, minor) >= (3, 3)
        };
        if !ok {
            return Err(GlError::ContextVersion {
                found: version,
                needed: NEEDED,
            });
        }
        let profile = if es {
            Profile::Es
        } else {
            // SAFETY: an integer query that exists from GL 3.2 on.
            let mask = unsafe { gl.get_parameter_i32(glow::CONTEXT_PROFILE_MASK) } as u32;
            let compat = mask & glow::CONTEXT_COMPATIBILITY_PROFILE_BIT != 0
                || caps::has_extension(gl, "GL_ARB_compatibility");
            if compat {
                Profile::Compat
            } else {
                Profile::Core
            }
        };
        let srgb_switch = !es || caps::has_extension(gl, "GL_EXT_sRGB_write_control");
        let tf_objects = es || major >= 4 || caps::has_extension(gl, "GL_ARB_transform_feedback2");
        Ok(ContextInfo {
            profile,
            srgb_switch,
            tf_objects,
        })
    }
}

/// `(is ES, major, minor)` of a `GL_VERSION` string: `"OpenGL ES 3.2 Mesa …"`,
/// `"OpenGL ES-CM 1.1"`, `"4.5 (Core Profile) Mesa …"`, `"2.1 Mesa …"`.
fn parse_version(s: &str) -> Option<(bool, u32, u32)> {
    // WebGL N.m is OpenGL ES N+1.m (WebGL 2.0 = ES 3.0), as the WebGL spec defines it.
    if let Some(r) = s.strip_prefix("WebGL ") {
        let (_, major, minor) = parse_version(r)?;
        return Some((true, major + 1, minor));
    }
    let (es, rest) = match s.strip_prefix("OpenGL ES") {
        Some(r) => (true, r.trim_start_matches(|c| c != ' ').trim_start()),
        None => (false, s.trim_start()),
    };
    let number = rest.split(|c: char| c.is_whitespace()).next()?;
    let mut parts = number.split('.');
    let major = parts.next()?.parse().ok()?;
    let minor = parts
        .next()
        .map(|m| m.trim_end_matches(|c: char| !c.is_ascii_digit()))
        .and_then(|m| m.parse().ok())
        .unwrap_or(0);
    Some((es, major, minor))
}

#[cfg(test)]
mod tests {
    use super::parse_version;

    #[test]
    fn version_strings_parse() {
        let p = parse_version;
        assert_eq!(p("OpenGL ES 3.2 Mesa 22.3.6"), Some((true, 3, 2)));
        assert_eq!(p("OpenGL ES 3.0"), Some((true, 3, 0)));
        assert_eq!(p("WebGL 2.0 (OpenGL ES 3.0 Chromium)"), Some((true, 3, 0)));
        assert_eq!(p("WebGL 1.0 (OpenGL ES 2.0 Chromium)"), Some((true, 2, 0)));
        assert_eq!(p("OpenGL ES-CM 1.1 Mesa"), Some((true, 1, 1)));
        assert_eq!(
            p("4.5 (Compatibility Profile) Mesa 22.3.6"),
            Some((false, 4, 5))
        );
        assert_eq!(p("3.3.0 NVIDIA 535.1"), Some((false, 3, 3)));
        assert_eq!(p("2.1 Mesa 22.3.6"), Some((false, 2, 1)));
        assert_eq!(p("garbage"), None);
        assert_eq!(p(""), None);
    }
}
