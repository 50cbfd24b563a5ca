// Fragment stage of the pre-pass program (GLSL ES 3.00 needs one to link; the rasterizer is
// discarded, so it never runs).

layout(location = 0) out vec4 o_frag_color;

void main() {
    o_frag_color = vec4(0.0);
}
