/* Column-major 4x4 matrices for the host examples (what glLoadMatrixf, glUniformMatrix4fv and
 * splatgl_renderer_draw take), and the projection of a point to a pixel. */
#ifndef HOST_MATH_H
#define HOST_MATH_H

#include <math.h>

/* World -> GL eye space for an eye looking at `target`, +y up. */
static void look_at(const float eye[3], const float target[3], float m[16]) {
    float f[3], s[3], u[3], n;
    int i;
    for (i = 0; i < 3; i++) f[i] = target[i] - eye[i];
    n = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (i = 0; i < 3; i++) f[i] /= n;
    s[0] = f[1] * 0.0f - f[2] * 1.0f; /* f x (0, 1, 0) */
    s[1] = f[2] * 0.0f - f[0] * 0.0f;
    s[2] = f[0] * 1.0f - f[1] * 0.0f;
    n = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (i = 0; i < 3; i++) s[i] /= n;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    for (i = 0; i < 16; i++) m[i] = 0.0f;
    for (i = 0; i < 3; i++) {
        m[4 * i + 0] = s[i];
        m[4 * i + 1] = u[i];
        m[4 * i + 2] = -f[i];
    }
    m[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    m[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    m[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    m[15] = 1.0f;
}

/* gluPerspective; with `reversed`, reversed-Z with an infinite far plane in GL's [-1, 1]
 * depth range (z_ndc = 2 near / d - 1: +1 at the near plane, -1 at infinity). */
static void perspective(float fovy_deg, float aspect, float near, float far, int reversed,
                        float m[16]) {
    float t = 1.0f / tanf(fovy_deg * 3.14159265f / 360.0f);
    int i;
    for (i = 0; i < 16; i++) m[i] = 0.0f;
    m[0] = t / aspect;
    m[5] = t;
    m[11] = -1.0f;
    if (reversed) {
        m[10] = 1.0f;
        m[14] = 2.0f * near;
    } else {
        m[10] = (far + near) / (near - far);
        m[14] = 2.0f * far * near / (near - far);
    }
}

/* out = a * b. */
static void mat_mul(const float a[16], const float b[16], float out[16]) {
    int r, c, k;
    for (c = 0; c < 4; c++)
        for (r = 0; r < 4; r++) {
            float v = 0.0f;
            for (k = 0; k < 4; k++) v += a[4 * k + r] * b[4 * c + k];
            out[4 * c + r] = v;
        }
}

/* The pixel (x right, y up from the bottom row, as glReadPixels stores it) of world point p. */
static void project(const float view[16], const float proj[16], int w, int h, const float p[3],
                    int px[2]) {
    float vp[16], clip[4];
    int r;
    mat_mul(proj, view, vp);
    for (r = 0; r < 4; r++)
        clip[r] = vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r];
    px[0] = (int)((clip[0] / clip[3] * 0.5f + 0.5f) * (float)w);
    px[1] = (int)((clip[1] / clip[3] * 0.5f + 0.5f) * (float)h);
}

#endif /* HOST_MATH_H */
