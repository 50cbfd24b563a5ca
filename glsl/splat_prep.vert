// Vertex stage of the transform-feedback pre-pass: one POINT per visible splat, in draw
// order, with the rasterizer discarded; writes the per-splat results (splat_project.glsl)
// for splat_quad.vert, which reads them as per-instance attributes. The varyings are
// captured interleaved in this order (`PREPASS_VARYINGS` in src/gl/prepass.rs).

layout(location = 0) in uint a_splat_index;

out vec4 t_clip;
out vec4 t_axes;
out vec4 t_color_opacity;
out vec3 t_conic;
out vec2 t_center_px;

//@include splat_project.glsl

void main() {
    Splat s;
    if (project_splat(a_splat_index, s)) {
        t_clip = s.clip;
        t_axes = s.axes;
        t_color_opacity = vec4(s.color, s.opacity);
        t_conic = s.conic;
        t_center_px = s.center_px;
    } else {
        // Outside the clip volume with no extent: the quad is clipped away.
        t_clip = vec4(2.0, 2.0, 2.0, 1.0);
        t_axes = vec4(0.0);
        t_color_opacity = vec4(0.0);
        t_conic = vec3(0.0);
        t_center_px = vec2(0.0);
    }
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
