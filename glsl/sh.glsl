// Spherical-harmonics colour (vertex stage), RC basis with the Condon-Shortley phase
// (identical to 3DGS computeColorFromSH). Constants SH_C* come from splatgl::sh, SH_DC_BIAS
// and the texel counts from splatgl::profile.

vec4 sh_texels[MAX_SH_TEXELS];

vec3 sh_coef(int k) {
    int f = 3 * k;
    return vec3(sh_texels[f >> 2][f & 3], sh_texels[(f + 1) >> 2][(f + 1) & 3],
                sh_texels[(f + 2) >> 2][(f + 2) & 3]);
}

vec3 sh_color(int splat, vec3 view_dir) {
    int degree = u_sh_degree;
    for (int i = 0; i < MAX_SH_TEXELS; ++i) {
        if (i >= u_sh_fetch_texels) break;
        int linear_index = splat * u_sh_texels + i;
        sh_texels[i] = texelFetch(u_sh, texel_coord(linear_index), 0);
    }
    float x = view_dir.x, y = view_dir.y, z = view_dir.z;
    vec3 result = SH_C0 * sh_coef(0);
#ifdef ERRATUM_E
    // Appendix literal: no Condon-Shortley signs (the magnitudes of the RC's constants, which
    // the appendix spells to 10 digits), 2.89 (SH_C3_1) for coefficient 14, sigmoid colour.
    if (degree >= 1) {
        result += SH_C1 * y * sh_coef(1) + SH_C1 * z * sh_coef(2) + SH_C1 * x * sh_coef(3);
        if (degree >= 2) {
            float xx = x * x, yy = y * y, zz = z * z;
            result += SH_C2_0 * x * y * sh_coef(4) + abs(SH_C2_1) * y * z * sh_coef(5)
                    + SH_C2_2 * (3.0 * zz - 1.0) * sh_coef(6)
                    + abs(SH_C2_3) * x * z * sh_coef(7) + SH_C2_4 * (xx - yy) * sh_coef(8);
            if (degree >= 3) {
                result += abs(SH_C3_0) * y * (3.0 * xx - yy) * sh_coef(9)
                        + SH_C3_1 * x * y * z * sh_coef(10)
                        + abs(SH_C3_2) * y * (5.0 * zz - 1.0) * sh_coef(11)
                        + SH_C3_3 * z * (5.0 * zz - 3.0) * sh_coef(12)
                        + abs(SH_C3_4) * x * (5.0 * zz - 1.0) * sh_coef(13)
                        + SH_C3_1 * z * (xx - yy) * sh_coef(14)
                        + abs(SH_C3_6) * x * (xx - 3.0 * yy) * sh_coef(15);
            }
        }
    }
    return 1.0 / (1.0 + exp(-result));
#else
    // Erratum e: RC signs and constants; colour = SH + 0.5, negative channels clamped to 0.
    if (degree >= 1) {
        result += -SH_C1 * y * sh_coef(1) + SH_C1 * z * sh_coef(2) - SH_C1 * x * sh_coef(3);
        if (degree >= 2) {
            float xx = x * x, yy = y * y, zz = z * z;
            result += SH_C2_0 * x * y * sh_coef(4) + SH_C2_1 * y * z * sh_coef(5)
                    + SH_C2_2 * (2.0 * zz - xx - yy) * sh_coef(6)
                    + SH_C2_3 * x * z * sh_coef(7) + SH_C2_4 * (xx - yy) * sh_coef(8);
            if (degree >= 3) {
                result += SH_C3_0 * y * (3.0 * xx - yy) * sh_coef(9)
                        + SH_C3_1 * x * y * z * sh_coef(10)
                        + SH_C3_2 * y * (4.0 * zz - xx - yy) * sh_coef(11)
                        + SH_C3_3 * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * sh_coef(12)
                        + SH_C3_4 * x * (4.0 * zz - xx - yy) * sh_coef(13)
                        + SH_C3_5 * z * (xx - yy) * sh_coef(14)
                        + SH_C3_6 * x * (xx - 3.0 * yy) * sh_coef(15);
            }
        }
    }
    return max(result + SH_DC_BIAS, 0.0);
#endif
}
