// Vertex stage of the splat program after the pre-pass: QUADS_PER_INSTANCE quads per
// instance (indexed TRIANGLES, vertex 4q + corner of quad q), each reading its splat's record
// from the records texture (slot = instance * QUADS_PER_INSTANCE + q, in draw order) and only
// placing its corner. One instance per batch rather than per splat: renderers that pay per
// instance (SwiftShader, llvmpipe) pay once per batch.

uniform highp sampler2DArray u_records;
uniform int u_instances;   // splats drawn: slots past them (the last batch's tail) are dropped
uniform vec4 u_viewport;   // x, y, width, height in window pixels

flat out vec3 v_color;
flat out float v_opacity;
flat out vec3 v_cov2d_inv_upper;
flat out vec2 v_center_px;

//@include texel.glsl

vec4 fetch_record(int slot, int k) {
    return texelFetch(u_records, texel_coord(slot * RECORD_TEXELS + k), 0);
}

void main() {
    int slot = gl_InstanceID * QUADS_PER_INSTANCE + (gl_VertexID >> 2);
    if (slot >= u_instances) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        v_color = vec3(0.0);
        v_opacity = 0.0;
        v_cov2d_inv_upper = vec3(0.0);
        v_center_px = vec2(0.0);
        return;
    }
    vec4 clip = fetch_record(slot, 0);
    vec4 axes = fetch_record(slot, 1);
    vec4 color_opacity = fetch_record(slot, 2);
    int corner_id = gl_VertexID & 3;
    vec2 corner = vec2(float(corner_id & 1), float(corner_id >> 1)) * 2.0 - 1.0;
    gl_Position = clip + vec4(corner.x * axes.xy + corner.y * axes.zw, 0.0, 0.0);
    v_color = color_opacity.rgb;
    v_opacity = color_opacity.a;
    v_cov2d_inv_upper = fetch_record(slot, 3).xyz;
    // The centre in window pixels, as splat_project.glsl computes it (the depth clamp there
    // leaves x, y and w alone).
    v_center_px = (clip.xy / clip.w * 0.5 + 0.5) * u_viewport.zw + u_viewport.xy;
}
