// The per-splat maths of the splat program, shared by the direct vertex stage (splat.vert:
// every quad corner runs it) and the transform-feedback pre-pass (splat_prep.vert: once per
// splat, the quad then reads the results, splat_quad.vert).
//
// Mirrors the step structure of KHR_gaussian_splatting (review draft) Appendix A with every
// erratum fixed; docs/appendix-errata.md lists each deviation. The `#version` line, precision
// statements and every numeric constant (SH_C*, DILATION, CUTOFF_M2, ALPHA_MAX, ALPHA_MIN,
// OPACITY_M2_MARGIN, QUAD_*, FOV_CLAMP, SH_DC_BIAS, texture layout GEOM_* / MAX_SH_TEXELS /
// TEX_WIDTH / LAYER_ROWS, MAX_CLOUDS) are injected from Rust (splatgl::profile, splatgl::sh)
// as `#define`s; `ERRATUM_*` defines switch in the appendix's literal behaviour for the
// erratum tests only.
//
// Data path (erratum j): the appendix's 21 vertex attributes cannot link on GLES 3.0 (16
// guaranteed); splat data lives in textures read with texelFetch.

// GEOM_TEXELS RGBA32F texels per splat: (position.xyz, opacity), rotation xyzw,
// (scale.xyz, model index) at GEOM_TEXEL_POSITION_OPACITY, GEOM_TEXEL_ROTATION,
// GEOM_TEXEL_SCALE. Array textures: a cloud larger than one layer continues on the next.
uniform highp sampler2DArray u_geometry;
// ceil(3 * coefficients / 4) RGBA16F texels per splat: RGB triples, degree-major, m = -l..l.
uniform highp sampler2DArray u_sh;
uniform int u_sh_texels;      // SH texels per splat in u_sh
uniform int u_sh_degree;      // degree to evaluate, 0..=cloud degree (run-time choice)
uniform int u_sh_fetch_texels; // SH texels holding degrees 0..=u_sh_degree

uniform mat4 u_view_matrix;        // world -> GL eye space (looks down -z)
uniform mat4 u_projection_matrix;  // GL eye -> clip
uniform vec2 u_focal_length;       // fx, fy in pixels
uniform vec2 u_tan_half_fov;       // tan of half the field of view, x and y
uniform vec3 u_camera_position;    // eye in world space
uniform vec4 u_viewport;           // x, y, width, height in window pixels
uniform float u_cull_depth;        // max(NEAR_CULL, camera near): 3DGS in_frustum
uniform int u_splat_count;         // splats uploaded: an order index past them is culled
// Model matrices of a scene's clouds (splat data is in model space); u_model_count = 0 when
// every model is the identity, which skips the transform.
uniform int u_model_count;
uniform vec4 u_model_rows[3 * MAX_CLOUDS]; // rows 0..2 of each model's affine matrix
uniform mat3 u_sh_rotation[MAX_CLOUDS];    // world -> model directions (polar rotation^T)
uniform int u_antialiased;         // 1: opacity compensated for the dilation (antialiased kernel)

// What the quad's corners and the fragments need of one splat.
struct Splat {
    vec4 clip;      // clip-space centre (depth kept inside the clip volume)
    vec4 axes;      // clip-space offsets of the corners (+-1, 0) (xy) and (0, +-1) (zw)
    vec3 color;     // SH colour, negatives clamped
    float opacity;
    vec3 conic;     // (S^-1)[0][0], (S^-1)[0][1], (S^-1)[1][1], window pixels
    vec2 center_px; // window pixels (gl_FragCoord's frame: y up)
};

//@include texel.glsl

//@include sh.glsl

vec4 fetch_geometry(int splat, int k) {
    return texelFetch(u_geometry, texel_coord(splat * GEOM_TEXELS + k), 0);
}


bool project_splat(uint index, out Splat s) {
    // An index past the uploaded splats (a host bug) must not fetch undefined texels.
    if (index >= uint(u_splat_count)) {
        return false;
    }
    int splat = int(index);
    vec4 geom0 = fetch_geometry(splat, GEOM_TEXEL_POSITION_OPACITY);
    vec4 a_glob_rotation = fetch_geometry(splat, GEOM_TEXEL_ROTATION);
    vec4 geom2 = fetch_geometry(splat, GEOM_TEXEL_SCALE);
    vec3 a_glob_position = geom0.xyz;
    float a_glob_opacity = geom0.w;
    // A scene's cloud: world position = model * position (the loader's node transform).
    int model = min(int(geom2.w), MAX_CLOUDS - 1);
    mat3 model_linear = mat3(1.0);
    if (u_model_count > 0) {
        vec4 r0 = u_model_rows[3 * model], r1 = u_model_rows[3 * model + 1],
             r2 = u_model_rows[3 * model + 2];
        vec4 p = vec4(a_glob_position, 1.0);
        a_glob_position = vec3(dot(r0, p), dot(r1, p), dot(r2, p));
        model_linear = transpose(mat3(r0.xyz, r1.xyz, r2.xyz));
    }

    // --- STEP 1: view-space position and near cull ---
    vec4 view_space_pos = u_view_matrix * vec4(a_glob_position, 1.0);
    // Erratum c: GL eye space looks down -z; the depth in front of the camera is -z.
    float z_depth = -view_space_pos.z;
    // Written as !(a > b) so a NaN depth (non-finite mean) is culled too; splats whose alpha
    // can never reach ALPHA_MIN (or is NaN) are culled like the reference does.
    if (!(z_depth > u_cull_depth) || !(min(a_glob_opacity, ALPHA_MAX) >= ALPHA_MIN)) {
        return false;
    }

    // --- STEP 2: 3D covariance  Sigma = R S S^T R^T ---
    // Scale is linear in the Release Candidate (the review draft's exp() is gone).
    vec3 scale = geom2.xyz;
    // Normalised like the reference; a zero quaternion means identity there too.
    float q_len = length(a_glob_rotation);
    vec4 q = q_len > 0.0 ? a_glob_rotation / q_len : vec4(0.0, 0.0, 0.0, 1.0);
#ifdef ERRATUM_A
    // Appendix literal: rows written into mat3(...), which fills columns -> R^T.
    mat3 rotation_matrix = mat3(
        1.0 - 2.0 * (q.y * q.y + q.z * q.z), 2.0 * (q.x * q.y - q.z * q.w), 2.0 * (q.x * q.z + q.y * q.w),
        2.0 * (q.x * q.y + q.z * q.w), 1.0 - 2.0 * (q.x * q.x + q.z * q.z), 2.0 * (q.y * q.z - q.x * q.w),
        2.0 * (q.x * q.z - q.y * q.w), 2.0 * (q.y * q.z + q.x * q.w), 1.0 - 2.0 * (q.x * q.x + q.y * q.y));
#else
    // Erratum a: mat3(...) takes columns, so write R column by column.
    mat3 rotation_matrix = mat3(
        1.0 - 2.0 * (q.y * q.y + q.z * q.z), 2.0 * (q.x * q.y + q.z * q.w), 2.0 * (q.x * q.z - q.y * q.w),
        2.0 * (q.x * q.y - q.z * q.w), 1.0 - 2.0 * (q.x * q.x + q.z * q.z), 2.0 * (q.y * q.z + q.x * q.w),
        2.0 * (q.x * q.z + q.y * q.w), 2.0 * (q.y * q.z - q.x * q.w), 1.0 - 2.0 * (q.x * q.x + q.y * q.y));
#endif
    mat3 scale_matrix = mat3(scale.x, 0.0, 0.0, 0.0, scale.y, 0.0, 0.0, 0.0, scale.z);
    mat3 M = rotation_matrix * scale_matrix;
    // A model matrix A: sigma3d = A R S S^T R^T A^T (the loader's M C C^T M^T), i.e. M = A R S.
    if (u_model_count > 0) {
        M = model_linear * M;
    }
    // sigma3d = M * transpose(M); kept factored: Step 3 needs only M.

    // --- STEP 3: projection + Jacobian -> 2D covariance  Sigma' = J W Sigma W^T J^T ---
#ifdef ERRATUM_B
    mat3 W = transpose(mat3(u_view_matrix));
#else
    // Erratum b: the view rotation itself (3DGS computeCov2D), not its transpose.
    mat3 W = mat3(u_view_matrix);
#endif
    // Erratum k: 3DGS clamps x/z and y/z to 1.3 tan(half fov) inside J only.
#ifdef ERRATUM_K
    vec2 t = view_space_pos.xy;
#else
    vec2 lim = FOV_CLAMP * u_tan_half_fov;
    vec2 t = clamp(view_space_pos.xy / z_depth, -lim, lim) * z_depth;
#endif
    float fx = u_focal_length.x, fy = u_focal_length.y;
    // Rows: window x, window y (up); columns: eye x, y, z. mat3(...) fills columns.
    mat3 J = mat3(
        fx / z_depth, 0.0, 0.0,
        0.0, fy / z_depth, 0.0,
        fx * t.x / (z_depth * z_depth), fy * t.y / (z_depth * z_depth), 0.0);
    // Sigma' = J W sigma3d W^T J^T = P P^T with P = J W M (2x3: rows p0, p1). Its
    // determinant is the sum of the squared 2x2 minors of P (Cauchy-Binet), |p0 x p1|^2: no
    // cancellation, where a*c - b*b in f32 loses every digit for long thin splats.
    mat3 P = J * W * M;
    vec3 p0 = vec3(P[0][0], P[1][0], P[2][0]);
    vec3 p1 = vec3(P[0][1], P[1][1], P[2][1]);
    mat2 cov2d = mat2(dot(p0, p0), dot(p0, p1), dot(p0, p1), dot(p1, p1));
    vec3 minors = cross(p0, p1);
    float det = dot(minors, minors);
    float det_undilated = det;
#ifndef ERRATUM_I
    // Erratum i: 3DGS's low-pass dilation of 0.3 px^2: det(S + dI) = det S + d tr S + d^2.
    det += DILATION * (cov2d[0][0] + cov2d[1][1]) + DILATION * DILATION;
    cov2d[0][0] += DILATION;
    cov2d[1][1] += DILATION;
#endif

    // --- STEP 4: extent (radius of the circle around the ellipse, as in 3DGS) ---
    if (!(det > 0.0) || isinf(det)) {
        return false;
    }
    // Antialiased kernel (Mip-Splatting's 2D filter, gsplat's `antialiased`): the dilation
    // keeps the splat's integral, opacity * sqrt(det S / det(S + dI)) (rendering-profile.md).
    float opacity = a_glob_opacity;
    if (u_antialiased != 0) {
        opacity *= sqrt(max(det_undilated / det, 0.0));
        if (!(min(opacity, ALPHA_MAX) >= ALPHA_MIN)) {
            return false;
        }
    }
    // Opacity-aware extent (docs/rendering-profile.md section 3): no pixel beyond Mahalanobis^2
    // k2 = 2 ln(opacity / ALPHA_MIN) can pass the alpha test (ALPHA_MAX >= ALPHA_MIN), so
    // the quad bounds the ellipse of k2 (plus a margin for log/exp rounding), capped at the
    // 3-sigma cut-off. The fragment test is unchanged: the image is the same.
    float k2 = min(CUTOFF_M2, 2.0 * log(opacity / ALPHA_MIN) + OPACITY_M2_MARGIN);
    float quad_margin = QUAD_MARGIN_PX;
#ifdef FORMER_QUADS
    // Erratum variants and the benchmarks' baseline (test builds only) draw exactly the
    // former quads (erratum d's is no bounding box).
    k2 = CUTOFF_M2;
    quad_margin = FORMER_QUAD_MARGIN_PX;
#endif
    float mid = 0.5 * (cov2d[0][0] + cov2d[1][1]);
    float lambda1 = mid + sqrt(max(0.1, mid * mid - det));
    float radius = ceil(sqrt(k2 * lambda1));

    vec4 clip_space_pos = u_projection_matrix * view_space_pos;
    vec2 ndc_pos = clip_space_pos.xy / clip_space_pos.w;
#ifdef ERRATUM_D
    s.axes = vec4(radius / u_focal_length.x * clip_space_pos.w, 0.0,
                  0.0, radius / u_focal_length.y * clip_space_pos.w);
    s.center_px = (ndc_pos * 0.5 + 0.5) * vec2(clip_space_pos.w / u_projection_matrix[0][0] * 2.0,
                                               clip_space_pos.w / u_projection_matrix[1][1] * 2.0);
#else
    // Erratum d: r pixels are 2r/viewport in NDC; the centre in window pixels is
    // (ndc/2 + 1/2) * viewport size + viewport origin (gl_FragCoord's frame).
    s.center_px = (ndc_pos * 0.5 + 0.5) * u_viewport.zw + u_viewport.xy;
    // Splats whose box (half-extents k sqrt(Sigma'_xx), k sqrt(Sigma'_yy)) misses the viewport
    // would be clipped anyway: skip their SH work.
    vec2 extent = min(sqrt(k2 * vec2(cov2d[0][0], cov2d[1][1])) + 0.5, vec2(radius));
    if (any(lessThan(s.center_px + extent, u_viewport.xy)) ||
        any(greaterThan(s.center_px - extent, u_viewport.xy + u_viewport.zw))) {
        return false;
    }
    // The quad is the k-ellipse's bounding rectangle along the eigenvectors of Sigma'
    // rather than the appendix's square of side 2 * radius: far fewer fragments for elongated
    // splats. The fragment shader's exact cut decides which pixels count, so any quad that
    // contains the ellipse gives the same image; the QUAD_AXIS_FACTOR (2%) + QUAD_MARGIN_PX
    // margin covers f32 rounding in the eigen-decomposition and vertex snapping, and the
    // square still bounds it.
    float l1 = mid + sqrt(max(mid * mid - det, 0.0));
    float l2 = det / l1;
    vec2 axis1 = cov2d[0][0] >= cov2d[1][1] ? vec2(l1 - cov2d[1][1], cov2d[0][1])
                                            : vec2(cov2d[0][1], l1 - cov2d[0][0]);
    float axis1_len = length(axis1);
    axis1 = axis1_len > 0.0 ? axis1 / axis1_len : vec2(1.0, 0.0);
    vec2 axis2 = vec2(-axis1.y, axis1.x);
    vec2 half_axes = min(sqrt(k2 * vec2(l1, l2)) * QUAD_AXIS_FACTOR + quad_margin,
                         vec2(radius));
    // The clip-space offsets of the corners (+-1, 0) and (0, +-1): r px are 2r/viewport in NDC.
    vec2 to_clip = (2.0 / u_viewport.zw) * clip_space_pos.w;
    s.axes = vec4(half_axes.x * axis1 * to_clip, half_axes.y * axis2 * to_clip);
#endif
    // No far cull (3DGS has none, nor has the reference): keep the depth inside the clip
    // volume so splats beyond the projection's far plane are not clipped away (at +w for a
    // standard projection, at -w for a reversed-Z one).
    float z_limit = clip_space_pos.w * (1.0 - 1e-6);
    clip_space_pos.z = clamp(clip_space_pos.z, -z_limit, z_limit);
    s.clip = clip_space_pos;

    // --- STEP 5: view-dependent colour from spherical harmonics ---
    vec3 view_dir = normalize(a_glob_position - u_camera_position);
    // In a cloud's model space, as the loader's Wigner-D rotation of the SH by the polar
    // rotation of the model matrix does: colour'(d) = colour(R^T d).
    if (u_model_count > 0) {
        view_dir = u_sh_rotation[model] * view_dir;
    }
    s.color = sh_color(splat, view_dir);
    if (any(isnan(s.color)) || any(isinf(s.color))) {
        return false;
    }

    // --- STEP 6: data for the fragment shader ---
    s.opacity = opacity;
    float inv_det = 1.0 / det;
    s.conic = vec3(cov2d[1][1], -cov2d[0][1], cov2d[0][0]) * inv_det;
    return true;
}
