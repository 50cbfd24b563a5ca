// Resolve pass: copies the float accumulation target into the bound framebuffer, converting
// linear values to sRGB for `lin_rec709_display` (blending already happened, in linear).
uniform highp sampler2D u_accum;
uniform vec2 u_origin;        // viewport origin in window pixels
uniform int u_encode_srgb;    // 1: linear -> sRGB transfer function on RGB

layout(location = 0) out vec4 o_frag_color;

// The sRGB curve of splatgl::profile (SRGB_* defines).
vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    vec3 lo = c * SRGB_LINEAR_SLOPE;
    vec3 hi = SRGB_SCALE * pow(c, vec3(1.0 / SRGB_GAMMA)) - SRGB_OFFSET;
    return mix(hi, lo, lessThanEqual(c, vec3(SRGB_ENCODE_THRESHOLD)));
}

void main() {
    vec4 c = texelFetch(u_accum, ivec2(gl_FragCoord.xy - u_origin), 0);
    o_frag_color = vec4(u_encode_srgb == 1 ? linear_to_srgb(c.rgb) : c.rgb, c.a);
}
