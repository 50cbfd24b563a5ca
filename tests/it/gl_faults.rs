//! GL faults come back as errors, never as a panic or a black image reported as success:
//! context creation failure, contexts older than GL 3.3 / GLES 3.0, shader compile and link
//! failures, missing extensions, clouds beyond the texture limits (split over array layers
//! while they fit, a named error when they do not), `GL_OUT_OF_MEMORY` on upload, and a host's
//! pending errors. The faults are injected through `splatgl::gl::fault` (hidden test hooks).

use crate::common;
use common::gl::*;
use glow::HasContext;
use splatgl::gl::fault::{self, Faults};
use splatgl::gl::{ColorFormat, GlError, OffscreenTarget, ReadbackTarget, SplatRenderer};

#[test]
fn failed_context_creation_is_an_error() {
    let r = HeadlessContext::with_api_version(GlApi::DesktopCompat, (9, 0));
    match r {
        Err(HeadlessError::EglUnavailable(m)) => common::skip(&format!("no EGL ({m})")),
        Err(HeadlessError::Egl { call, .. }) => assert_eq!(call, "eglCreateContext"),
        other => panic!("a GL 9.0 context: {other:?}"),
    }
}

#[test]
fn contexts_older_than_gl_3_3_or_gles_3_0_are_refused_naming_both_versions() {
    for (api, fake) in [
        (GlApi::DesktopCompat, "3.0 Mesa 22.3.6"),
        (GlApi::DesktopCompat, "2.1 Mesa 22.3.6"),
        (GlApi::Gles3, "OpenGL ES 2.0 Mesa 22.3.6"),
    ] {
        let Some(ctx) = or_skip(HeadlessContext::with_api(api), "context") else {
            return;
        };
        let gl = ctx.gl();
        let _faults = fault::inject(Faults {
            gl_version: Some(fake.into()),
            ..Faults::default()
        });
        let err = SplatRenderer::new(gl).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, GlError::ContextVersion { .. }), "{msg}");
        assert!(
            msg.contains(fake) && msg.contains("OpenGL ≥ 3.3 or OpenGL ES ≥ 3.0"),
            "{msg}"
        );
        assert!(
            OffscreenTarget::new(gl, 8, 8).is_err(),
            "{fake}: resolve pass too"
        );
    }
    // Asked for compatibility 3.0, Mesa gives its newest compatibility profile, which works.
    let Some(ctx) = or_skip(
        HeadlessContext::with_api_version(GlApi::DesktopCompat, (3, 0)),
        "3.0",
    ) else {
        return;
    };
    eprintln!("compatibility 3.0 asked, got: {}", ctx.describe());
    let mut r = SplatRenderer::new(ctx.gl()).expect("the context Mesa gives is ≥ 3.3");
    r.destroy(ctx.gl());
}

fn append_garbage(stage: &str, source: String) -> String {
    if stage == "fragment" {
        source + "\nthis is not glsl;\n"
    } else {
        source
    }
}

/// A fragment input the vertex stage never writes: compiles, fails to link.
fn unwritten_varying(stage: &str, source: String) -> String {
    if stage == "fragment" {
        source.replace(
            "void main() {",
            "flat in float v_never_written;\nvoid main() {\n    if (v_never_written > 2.0) discard;",
        )
    } else {
        source
    }
}

#[test]
fn bad_shader_source_is_a_compile_or_link_error() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "context") else {
        return;
    };
    let gl = ctx.gl();
    let compile = {
        let _f = fault::inject(Faults {
            edit_shader: Some(append_garbage),
            ..Faults::default()
        });
        SplatRenderer::new(gl).unwrap_err()
    };
    match &compile {
        GlError::Compile {
            stage,
            log,
            numbered_source,
        } => {
            assert_eq!(stage, "fragment (splat)");
            assert!(!log.is_empty());
            assert!(
                numbered_source.contains("| this is not glsl;"),
                "{numbered_source}"
            );
        }
        e => panic!("expected a compile error, got {e}"),
    }
    let link = {
        let _f = fault::inject(Faults {
            edit_shader: Some(unwritten_varying),
            ..Faults::default()
        });
        SplatRenderer::new(gl).unwrap_err()
    };
    assert!(
        matches!(&link, GlError::Link { program, log, .. } if program == "splat" && !log.is_empty()),
        "expected a link error, got {link}"
    );
    // No hook: the same context still builds the renderer.
    SplatRenderer::new(gl).unwrap().destroy(gl);
}

#[test]
fn missing_extension_is_named() {
    let _f = fault::inject(Faults {
        missing_extensions: vec![
            "GL_EXT_color_buffer_float",
            "GL_EXT_color_buffer_half_float",
        ],
        ..Faults::default()
    });
    let Some(ctx) = or_skip(HeadlessContext::new(), "context") else {
        return;
    };
    let err = ReadbackTarget::new(ctx.gl(), 8, 8, ColorFormat::Rgba16f, None).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("GL_EXT_color_buffer_float") && msg.contains("RGBA16F"),
        "{msg}"
    );
    // The headless renderer reports it instead of rendering nothing.
    let Some(mut r) = headless() else { return };
    let cloud = synthetic::random_cloud(50, 0, 0.5, 1);
    r.upload(&cloud).unwrap();
    let cam = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 50.0, 16, 16);
    let opts = HeadlessOptions {
        target: TargetKind::Rgba16fResolve,
        ..HeadlessOptions::default()
    };
    assert!(matches!(
        r.render(&cam, &opts),
        Err(HeadlessError::Gl(GlError::MissingExtension { .. }))
    ));
}

/// Renders `cloud` headlessly with the given faults injected (while the renderer is created,
/// the cloud uploaded and drawn).
fn render_with_faults(
    cloud: &SplatCloud,
    cam: &Camera,
    faults: Faults,
) -> Result<Image, HeadlessError> {
    let _f = fault::inject(faults);
    let mut r = HeadlessRenderer::new()?;
    r.upload(cloud)?;
    r.render(cam, &HeadlessOptions::default())
}

#[test]
fn clouds_beyond_one_texture_are_split_over_array_layers_with_identical_pixels() {
    // 2000 splats of SH degree 3 take 24000 SH texels: with GL_MAX_TEXTURE_SIZE lowered to 64
    // one texture holds 4096, so the cloud needs 6 layers.
    let cloud = synthetic::random_cloud(2000, 3, 0.8, 77);
    let cam = look_at_fov_deg(Vec3::new(0.2, 0.3, 2.8), Vec3::ZERO, 50.0, 64, 48);
    let Some(whole) = or_skip(
        render_with_faults(&cloud, &cam, Faults::default()),
        "render",
    ) else {
        return;
    };
    let lowered = Faults {
        max_texture_size: Some(64),
        ..Faults::default()
    };
    let split = render_with_faults(&cloud, &cam, lowered.clone()).unwrap();
    assert!(whole.pixels.iter().filter(|p| p[3] > 0.1).count() > 1000);
    assert!(split == whole, "the layered upload draws a different image");
    // Two layers of 64 × 64 hold 682 splats of 12 texels: the error names the limits and that.
    let two_layers = Faults {
        max_array_layers: Some(2),
        ..lowered
    };
    let err = render_with_faults(&cloud, &cam, two_layers).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            HeadlessError::Gl(GlError::Capacity {
                splats: 2000,
                fits: 682,
                ..
            })
        ),
        "{msg}"
    );
    assert!(
        msg.contains("GL_MAX_ARRAY_TEXTURE_LAYERS") && msg.contains("GL_MAX_TEXTURE_SIZE 64"),
        "{msg}"
    );
}

#[test]
fn out_of_memory_on_upload_is_an_error_and_the_previous_cloud_stays() {
    let Some(mut r) = headless() else { return };
    let cam = look_at_fov_deg(Vec3::new(0.0, 0.2, 3.0), Vec3::ZERO, 50.0, 48, 48);
    let first = synthetic::random_cloud(300, 1, 0.7, 3);
    r.upload(&first).unwrap();
    let before = r.render(&cam, &HeadlessOptions::default()).unwrap();
    // SAFETY: a plain integer query.
    let layers = unsafe {
        r.context()
            .gl()
            .get_parameter_i32(glow::MAX_ARRAY_TEXTURE_LAYERS)
    };
    let err = {
        // Every data texture asked for with all its layers full: terabytes the driver refuses.
        let _f = fault::inject(Faults {
            oversize_layers: Some(layers),
            ..Faults::default()
        });
        r.upload(&synthetic::random_cloud(10, 0, 0.5, 4))
            .unwrap_err()
    };
    assert!(
        matches!(
            err,
            HeadlessError::Gl(GlError::Gl {
                code: glow::OUT_OF_MEMORY,
                ..
            })
        ),
        "{err}"
    );
    let after = r.render(&cam, &HeadlessOptions::default()).unwrap();
    assert!(
        after == before,
        "the previous cloud no longer draws the same"
    );
}

#[test]
fn host_errors_are_kept_or_reported_never_swallowed() {
    let Some(ctx) = or_skip(HeadlessContext::new(), "context") else {
        return;
    };
    let gl = ctx.gl();
    let cloud = synthetic::random_cloud(20, 0, 0.5, 9);
    let mut r = SplatRenderer::new(gl).unwrap();
    // SAFETY: invalid calls of the "host" that GL rejects without effect, and glGetError.
    unsafe {
        // A re-raisable error survives the upload and a read-back.
        gl.enable(0xDEAD);
        r.upload(gl, &cloud).unwrap();
        let target = ReadbackTarget::new(gl, 4, 4, ColorFormat::Rgba8, None).unwrap();
        target.read_image(gl).unwrap();
        assert_eq!(gl.get_error(), glow::INVALID_ENUM);
        assert_eq!(gl.get_error(), glow::NO_ERROR);
        // GL_OUT_OF_MEMORY cannot be raised again: the upload reports it, untried.
        let t = gl.create_texture().unwrap();
        gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(t));
        gl.tex_storage_3d(glow::TEXTURE_2D_ARRAY, 1, glow::RGBA32F, 8192, 8192, 2048);
        let err = r.upload(gl, &cloud).unwrap_err();
        assert!(
            matches!(
                err,
                GlError::HostError {
                    code: glow::OUT_OF_MEMORY
                }
            ),
            "{err}"
        );
        assert_eq!(gl.get_error(), glow::NO_ERROR);
        gl.delete_texture(t);
        let mut target = target;
        target.destroy(gl);
    }
    r.destroy(gl);
}
