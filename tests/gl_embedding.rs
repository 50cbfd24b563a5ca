//! The renderer embedded in a host's GL context: drawing into a host-owned framebuffer with
//! its depth buffer and viewport, the GL state left as documented in `splatgl::gl::state`,
//! `destroy`, and the errors an embedder sees (shader compile logs).

mod common;
use common::gl::*;

#[test]
fn host_depth_buffer_viewport_and_gl_state_are_respected() {
    use glow::HasContext;
    use splatgl::gl::{
        ColorFormat, DepthFormat, ReadbackTarget, SplatRenderer, sort_back_to_front,
    };
    let Some(ctx) = or_skip(HeadlessContext::new(), "headless context") else {
        return;
    };
    let gl = ctx.gl();
    let (w, h) = (32u32, 32u32);
    // The "host": an RGBA8 + DEPTH24 framebuffer with a viewport offset inside a larger one.
    let mut host =
        ReadbackTarget::new(gl, 2 * w, h, ColorFormat::Rgba8, Some(DepthFormat::Depth24)).unwrap();
    host.bind(gl).unwrap();
    let fbo = host.framebuffer();
    let mut cloud = SplatCloud::new(0);
    cloud.push(
        [0.0; 3],
        [0.3; 3],
        [0.0, 0.0, 0.0, 1.0],
        0.95,
        &sh_for([1.0, 1.0, 1.0], 0),
    );
    let c = look_at_fov_deg(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 50.0, w, h);
    let mut renderer = SplatRenderer::new(gl).unwrap();
    renderer.upload(gl, &cloud).unwrap();
    let mut order = Vec::new();
    sort_back_to_front(&cloud.positions, c.eye(), &mut order);
    // Right half of the framebuffer is the host's viewport for the splats.
    let mut centre_red = |depth_clear: f32, depth_test: bool| -> u8 {
        // SAFETY: clears and reads one pixel of the bound framebuffer.
        unsafe {
            gl.viewport(0, 0, 2 * w as i32, h as i32);
            gl.depth_mask(true);
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.clear_depth_f32(depth_clear);
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            gl.viewport(w as i32, 0, w as i32, h as i32);
        }
        renderer.settings_mut().depth_test = depth_test;
        renderer.draw(gl, &c, &order).unwrap();
        // GL pixel (w + w/2, h/2), counted from the bottom row.
        let px = host.read_image(gl).unwrap().get(w + w / 2, h - 1 - h / 2);
        (px[0] * 255.0).round() as u8
    };
    assert!(centre_red(0.0, false) > 200, "drawn without depth test");
    assert!(centre_red(1.0, true) > 200, "host depth far: splat passes");
    assert_eq!(
        centre_red(0.0, true),
        0,
        "host geometry in front: splat hidden"
    );
    // The left half (outside the viewport) stays untouched.
    let px = host.read_image(gl).unwrap().get(w / 2, h - 1 - h / 2);
    // SAFETY: state queries.
    unsafe {
        assert_eq!(px, [0.0; 4]);
        // State left as documented in splatgl::gl::state.
        assert_eq!(gl.get_parameter_i32(glow::CURRENT_PROGRAM), 0);
        assert_eq!(gl.get_parameter_i32(glow::VERTEX_ARRAY_BINDING), 0);
        assert_eq!(gl.get_parameter_i32(glow::ARRAY_BUFFER_BINDING), 0);
        assert_eq!(
            gl.get_parameter_i32(glow::ACTIVE_TEXTURE),
            glow::TEXTURE0 as i32
        );
        assert_eq!(gl.get_parameter_i32(glow::TEXTURE_BINDING_2D), 0);
        assert!(gl.is_enabled(glow::BLEND));
        assert_eq!(gl.get_parameter_i32(glow::BLEND_SRC_RGB), glow::ONE as i32);
        assert_eq!(
            gl.get_parameter_i32(glow::BLEND_DST_ALPHA),
            glow::ONE_MINUS_SRC_ALPHA as i32
        );
        assert_eq!(gl.get_parameter_i32(glow::DEPTH_WRITEMASK), 0);
        assert_eq!(
            gl.get_parameter_i32(glow::DRAW_FRAMEBUFFER_BINDING),
            fbo.0.get() as i32
        );
        let mut vp = [0i32; 4];
        gl.get_parameter_i32_slice(glow::VIEWPORT, &mut vp);
        assert_eq!(vp, [w as i32, 0, w as i32, h as i32]);
    }
    renderer.destroy(gl);
    host.destroy(gl);
    // A destroyed renderer refuses to draw instead of touching deleted objects.
    assert!(matches!(
        renderer.draw(gl, &c, &order),
        Err(splatgl::gl::GlError::Destroyed("SplatRenderer"))
    ));
}

#[test]
fn shader_errors_carry_log_and_numbered_source() {
    let Some(r) = headless() else { return };
    let gl = r.context().gl();
    let vs = "#version 300 es\nvoid main() {\n  gl_Position = vec4(0.0);\n}\n";
    let fs = "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() {\n  o = undefined_thing;\n}\n";
    let err = splatgl::gl::build_program(gl, "broken", vs, fs).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, splatgl::gl::GlError::Compile { .. }), "{msg}");
    assert!(msg.contains("undefined_thing"), "{msg}");
    assert!(msg.contains("   5 |   o = undefined_thing;"), "{msg}");
}
