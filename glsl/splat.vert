// Vertex stage of the splat program, direct path: one instance per splat, 4 vertices
// (TRIANGLE_STRIP quad), each corner running the per-splat maths (splat_project.glsl).
// The only attribute is the sorted splat index (divisor 1).

layout(location = 0) in uint a_splat_index;

flat out vec3 v_color;
flat out float v_opacity;
flat out vec3 v_cov2d_inv_upper;   // (S^-1)[0][0], (S^-1)[0][1], (S^-1)[1][1], window pixels
flat out vec2 v_center_px;         // window pixels (gl_FragCoord's frame: y up)

//@include splat_project.glsl

void main() {
    Splat s;
    if (!project_splat(a_splat_index, s)) {
        // Outside the clip volume: the whole quad is clipped away.
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        v_color = vec3(0.0);
        v_opacity = 0.0;
        v_cov2d_inv_upper = vec3(0.0);
        v_center_px = vec2(0.0);
        return;
    }
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    gl_Position = s.clip + vec4(corner.x * s.axes.xy + corner.y * s.axes.zw, 0.0, 0.0);
    v_color = s.color;
    v_opacity = s.opacity;
    v_cov2d_inv_upper = s.conic;
    v_center_px = s.center_px;
}
