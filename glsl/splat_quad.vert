// Vertex stage of the splat program after the pre-pass: one instance per visible splat, 4
// vertices (TRIANGLE_STRIP quad) that only place the corner; the per-splat results come from
// the pre-pass's transform-feedback buffer as per-instance attributes (divisor 1).

layout(location = 1) in vec4 a_clip;
layout(location = 2) in vec4 a_axes;
layout(location = 3) in vec4 a_color_opacity;
layout(location = 4) in vec3 a_conic;
layout(location = 5) in vec2 a_center_px;

flat out vec3 v_color;
flat out float v_opacity;
flat out vec3 v_cov2d_inv_upper;
flat out vec2 v_center_px;

void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    gl_Position = a_clip + vec4(corner.x * a_axes.xy + corner.y * a_axes.zw, 0.0, 0.0);
    v_color = a_color_opacity.rgb;
    v_opacity = a_color_opacity.a;
    v_cov2d_inv_upper = a_conic;
    v_center_px = a_center_px;
}
