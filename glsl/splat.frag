// Fragment stage of the splat program: evaluates the projected Gaussian at the pixel centre
// and writes premultiplied colour for blendFunc(ONE, ONE_MINUS_SRC_ALPHA) (erratum g).

flat in vec3 v_color;
flat in float v_opacity;
flat in vec3 v_cov2d_inv_upper;
flat in vec2 v_center_px;

layout(location = 0) out vec4 o_frag_color;

void main() {
    // --- STEP 1: G(x), the Gaussian at this pixel centre (window pixels, y up) ---
    vec2 d = gl_FragCoord.xy - v_center_px;
    float power = 0.5 * (d.x * d.x * v_cov2d_inv_upper.x + d.y * d.y * v_cov2d_inv_upper.z)
                + d.x * d.y * v_cov2d_inv_upper.y;
    // Erratum f: the 3-sigma cut is Mahalanobis^2 <= 9, i.e. power <= 4.5 (not 4).
#ifdef ERRATUM_F
    if (power > 4.0) {
#else
    if (power > 0.5 * CUTOFF_M2) {
#endif
        discard;
    }
    float G_x = exp(-power);

    // --- STEP 2: alpha, capped at 0.99 (erratum k), skipped below 1/255 ---
#ifdef ERRATUM_K
    float final_alpha = v_opacity * G_x;
#else
    float final_alpha = min(ALPHA_MAX, v_opacity * G_x);
#endif
    if (final_alpha < ALPHA_MIN) {
        discard;
    }

    // --- STEP 3: premultiplied output ---
    o_frag_color = vec4(v_color * final_alpha, final_alpha);
}
