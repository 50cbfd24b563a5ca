// Vertex stage of the transform-feedback pre-pass: one POINT per visible splat, in draw
// order, with the rasterizer discarded; writes the per-splat results (splat_project.glsl)
// as one record of RECORD_TEXELS vec4s, captured interleaved in this order
// (`PREPASS_VARYINGS` in src/gl/prepass.rs) and copied into the records texture, which
// splat_quad.vert reads.

layout(location = 0) in uint a_splat_index;

out vec4 t_clip;
out vec4 t_axes;
out vec4 t_color_opacity;
out vec4 t_conic;

//@include splat_project.glsl

void main() {
    Splat s;
    if (project_splat(a_splat_index, s)) {
        t_clip = s.clip;
        t_axes = s.axes;
        t_color_opacity = vec4(s.color, s.opacity);
        t_conic = vec4(s.conic, 0.0);
    } else {
        // Outside the clip volume with no extent: the quad is clipped away.
        t_clip = vec4(2.0, 2.0, 2.0, 1.0);
        t_axes = vec4(0.0);
        t_color_opacity = vec4(0.0);
        t_conic = vec4(0.0);
    }
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
