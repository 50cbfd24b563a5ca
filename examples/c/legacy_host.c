/*
 * A legacy OpenGL host in plain C (compatibility profile): fixed-function lighting,
 * immediate-mode geometry, client vertex arrays, its own framebuffer and depth buffer. It
 * draws its scene and a splat cloud loaded from a file with restore_state on, for 3 frames,
 * and checks that
 *   - its own pixels are untouched where its geometry hides the splats, and far from them;
 *   - the splats are drawn (pixels differ from the host-only frame where they are);
 *   - every frame is the same image (no state drifts from frame to frame);
 *   - each of the host's state pieces below reads back unchanged after every splatgl draw.
 *
 * Build (crates/splatgl-capi/tests/it/capi_hosts.rs does this):
 *   cargo build -p splatgl-capi
 *   cc -std=c99 -Wall -Wextra -Werror -Icrates/splatgl-capi/include -Iexamples/c examples/c/legacy_host.c \
 *      -Ltarget/debug -lsplatgl_capi -lEGL -lGL -lm -Wl,-rpath,$PWD/target/debug -o legacy_host
 *   ./legacy_host wall.ply     (crates/splatgl-capi/tests/it/capi_hosts.rs writes the splat wall this expects)
 *
 * On Windows (wgl_headless.h instead of egl_headless.h; scripts/windows/run.sh cross-builds it
 * with mingw-w64 and runs it under Wine):
 *   x86_64-w64-mingw32-gcc -std=c99 -Wall -Wextra -Werror -Icrates/splatgl-capi/include \
 *      -Iexamples/c examples/c/legacy_host.c -L<dir of splatgl.dll> -lsplatgl -lopengl32 -lgdi32 \
 *      -o legacy_host.exe
 *
 * Exit status 0 when every check passes; each failure is printed.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include "wgl_headless.h" /* before GL/gl.h, which needs windows.h there */
#else
#include "egl_headless.h"
#endif
#include <GL/gl.h>
#include <GL/glext.h>
#include "host_math.h"
#include "splatgl.h"

#define W 160
#define H 120
#define FRAMES 3

static PFNGLGENFRAMEBUFFERSPROC p_glGenFramebuffers;
static PFNGLBINDFRAMEBUFFERPROC p_glBindFramebuffer;
static PFNGLFRAMEBUFFERRENDERBUFFERPROC p_glFramebufferRenderbuffer;
static PFNGLCHECKFRAMEBUFFERSTATUSPROC p_glCheckFramebufferStatus;
static PFNGLGENRENDERBUFFERSPROC p_glGenRenderbuffers;
static PFNGLBINDRENDERBUFFERPROC p_glBindRenderbuffer;
static PFNGLRENDERBUFFERSTORAGEPROC p_glRenderbufferStorage;
static PFNGLGENBUFFERSPROC p_glGenBuffers;
static PFNGLBINDBUFFERPROC p_glBindBuffer;
static PFNGLBUFFERDATAPROC p_glBufferData;

#define LOAD(name) (*(void **)&p_##name = headless_get_proc(#name, NULL)) == NULL

static int load_gl(void) {
    if (LOAD(glGenFramebuffers) || LOAD(glBindFramebuffer) || LOAD(glFramebufferRenderbuffer) ||
        LOAD(glCheckFramebufferStatus) || LOAD(glGenRenderbuffers) || LOAD(glBindRenderbuffer) ||
        LOAD(glRenderbufferStorage) || LOAD(glGenBuffers) || LOAD(glBindBuffer) ||
        LOAD(glBufferData)) {
        fprintf(stderr, "a GL 3.0 function is missing\n");
        return -1;
    }
    return 0;
}

/* One piece of host state and how to read it. */
enum kind { READ_ENABLED, READ_INTEGER, READ_FLOAT };
typedef struct {
    const char *name;
    GLenum pname;
    enum kind kind;
    int count;
} piece;

static const piece PIECES[] = {
    {"GL_LIGHTING", GL_LIGHTING, READ_ENABLED, 1},
    {"GL_LIGHT0", GL_LIGHT0, READ_ENABLED, 1},
    {"GL_COLOR_MATERIAL", GL_COLOR_MATERIAL, READ_ENABLED, 1},
    {"GL_NORMALIZE", GL_NORMALIZE, READ_ENABLED, 1},
    {"GL_DEPTH_TEST", GL_DEPTH_TEST, READ_ENABLED, 1},
    {"GL_BLEND", GL_BLEND, READ_ENABLED, 1},
    {"GL_CULL_FACE", GL_CULL_FACE, READ_ENABLED, 1},
    {"GL_SCISSOR_TEST", GL_SCISSOR_TEST, READ_ENABLED, 1},
    {"GL_TEXTURE_2D", GL_TEXTURE_2D, READ_ENABLED, 1},
    {"GL_ALPHA_TEST", GL_ALPHA_TEST, READ_ENABLED, 1},
    {"GL_VERTEX_ARRAY", GL_VERTEX_ARRAY, READ_ENABLED, 1},
    {"GL_NORMAL_ARRAY", GL_NORMAL_ARRAY, READ_ENABLED, 1},
    {"GL_DEPTH_FUNC", GL_DEPTH_FUNC, READ_INTEGER, 1},
    {"GL_DEPTH_WRITEMASK", GL_DEPTH_WRITEMASK, READ_INTEGER, 1},
    {"GL_BLEND_SRC_RGB", GL_BLEND_SRC_RGB, READ_INTEGER, 1},
    {"GL_BLEND_DST_RGB", GL_BLEND_DST_RGB, READ_INTEGER, 1},
    {"GL_BLEND_SRC_ALPHA", GL_BLEND_SRC_ALPHA, READ_INTEGER, 1},
    {"GL_BLEND_DST_ALPHA", GL_BLEND_DST_ALPHA, READ_INTEGER, 1},
    {"GL_BLEND_EQUATION_RGB", GL_BLEND_EQUATION_RGB, READ_INTEGER, 1},
    {"GL_CULL_FACE_MODE", GL_CULL_FACE_MODE, READ_INTEGER, 1},
    {"GL_FRONT_FACE", GL_FRONT_FACE, READ_INTEGER, 1},
    {"GL_SHADE_MODEL", GL_SHADE_MODEL, READ_INTEGER, 1},
    {"GL_MATRIX_MODE", GL_MATRIX_MODE, READ_INTEGER, 1},
    {"GL_VIEWPORT", GL_VIEWPORT, READ_INTEGER, 4},
    {"GL_SCISSOR_BOX", GL_SCISSOR_BOX, READ_INTEGER, 4},
    {"GL_COLOR_WRITEMASK", GL_COLOR_WRITEMASK, READ_INTEGER, 4},
    {"GL_POLYGON_MODE", GL_POLYGON_MODE, READ_INTEGER, 2},
    {"GL_CURRENT_PROGRAM", GL_CURRENT_PROGRAM, READ_INTEGER, 1},
    {"GL_ARRAY_BUFFER_BINDING", GL_ARRAY_BUFFER_BINDING, READ_INTEGER, 1},
    {"GL_ELEMENT_ARRAY_BUFFER_BINDING", GL_ELEMENT_ARRAY_BUFFER_BINDING, READ_INTEGER, 1},
    {"GL_VERTEX_ARRAY_BINDING", GL_VERTEX_ARRAY_BINDING, READ_INTEGER, 1},
    {"GL_ACTIVE_TEXTURE", GL_ACTIVE_TEXTURE, READ_INTEGER, 1},
    {"GL_TEXTURE_BINDING_2D", GL_TEXTURE_BINDING_2D, READ_INTEGER, 1},
    {"GL_DRAW_FRAMEBUFFER_BINDING", GL_DRAW_FRAMEBUFFER_BINDING, READ_INTEGER, 1},
    {"GL_RENDERBUFFER_BINDING", GL_RENDERBUFFER_BINDING, READ_INTEGER, 1},
    {"GL_UNPACK_ALIGNMENT", GL_UNPACK_ALIGNMENT, READ_INTEGER, 1},
    {"GL_PACK_ALIGNMENT", GL_PACK_ALIGNMENT, READ_INTEGER, 1},
    {"GL_VERTEX_ARRAY_SIZE", GL_VERTEX_ARRAY_SIZE, READ_INTEGER, 1},
    {"GL_VERTEX_ARRAY_STRIDE", GL_VERTEX_ARRAY_STRIDE, READ_INTEGER, 1},
    {"GL_CURRENT_COLOR", GL_CURRENT_COLOR, READ_FLOAT, 4},
    {"GL_CURRENT_NORMAL", GL_CURRENT_NORMAL, READ_FLOAT, 3},
    {"GL_COLOR_CLEAR_VALUE", GL_COLOR_CLEAR_VALUE, READ_FLOAT, 4},
    {"GL_DEPTH_CLEAR_VALUE", GL_DEPTH_CLEAR_VALUE, READ_FLOAT, 1},
    {"GL_MODELVIEW_MATRIX", GL_MODELVIEW_MATRIX, READ_FLOAT, 16},
    {"GL_PROJECTION_MATRIX", GL_PROJECTION_MATRIX, READ_FLOAT, 16},
    {"GL_LINE_WIDTH", GL_LINE_WIDTH, READ_FLOAT, 1},
};
#define NPIECES (sizeof PIECES / sizeof PIECES[0])

typedef struct {
    float v[NPIECES][16];
} snapshot;

static void read_state(snapshot *s) {
    size_t i;
    memset(s, 0, sizeof *s);
    for (i = 0; i < NPIECES; i++) {
        const piece *p = &PIECES[i];
        GLint ints[16] = {0};
        int k;
        switch (p->kind) {
        case READ_ENABLED:
            s->v[i][0] = (float)glIsEnabled(p->pname);
            break;
        case READ_INTEGER:
            glGetIntegerv(p->pname, ints);
            for (k = 0; k < p->count; k++) s->v[i][k] = (float)ints[k];
            break;
        case READ_FLOAT:
            glGetFloatv(p->pname, s->v[i]);
            break;
        }
    }
}

/* Prints every piece that differs; returns how many. */
static int compare_state(const snapshot *before, const snapshot *after, int frame) {
    size_t i;
    int bad = 0;
    for (i = 0; i < NPIECES; i++) {
        if (memcmp(before->v[i], after->v[i], sizeof before->v[i]) != 0) {
            fprintf(stderr, "frame %d: %s changed by splatgl (%g -> %g)\n", frame, PIECES[i].name,
                    (double)before->v[i][0], (double)after->v[i][0]);
            bad++;
        }
    }
    return bad;
}

typedef struct {
    float view[16], proj[16];
    GLuint vbo, texture;
} host;

static const float GROUND[] = {-4, -1, 2, 4, -1, 2, 4, -1, -6, -4, -1, -6};
static const float GROUND_N[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
/* The occluder: a lit quad in front of the left part of the splat wall (z = 0). */
static const float OCCLUDER[] = {-1.6f, -0.5f, 0.8f, -0.3f, -0.5f, 0.8f,
                                 -0.3f, 0.5f,  0.8f, -1.6f, 0.5f,  0.8f};

/* The host's frame: clear, fixed-function lighting, a ground from client arrays, an
 * immediate-mode quad; leaves the state a legacy application typically leaves. */
static void host_frame(const host *h) {
    static const float light[] = {1.0f, 2.0f, 3.0f, 0.0f};
    int i;
    glClearColor(0.1f, 0.12f, 0.18f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixf(h->proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(h->view);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glShadeModel(GL_SMOOTH);
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLightfv(GL_LIGHT0, GL_POSITION, light);
    glEnable(GL_COLOR_MATERIAL);
    glEnable(GL_NORMALIZE);
    p_glBindBuffer(GL_ARRAY_BUFFER, 0); /* client arrays read host memory */
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, GROUND);
    glNormalPointer(GL_FLOAT, 0, GROUND_N);
    glColor3f(0.35f, 0.5f, 0.3f);
    glDrawArrays(GL_QUADS, 0, 4);
    glBegin(GL_QUADS);
    glNormal3f(0.0f, 0.0f, 1.0f);
    glColor3f(0.8f, 0.3f, 0.2f);
    for (i = 0; i < 4; i++) glVertex3fv(&OCCLUDER[3 * i]);
    glEnd();
    /* What such applications leave behind when they call a library. */
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, W, H);
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, h->texture);
    glEnable(GL_ALPHA_TEST);
    glColor4f(0.2f, 0.4f, 0.6f, 0.5f);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    p_glBindBuffer(GL_ARRAY_BUFFER, h->vbo);
}

/* Undoes what host_frame leaves, so that the next frame starts from its own state. */
static void host_end_frame(void) {
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_ALPHA_TEST);
}

static void read_pixels(unsigned char *rgba) {
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
}

static int same_pixel(const unsigned char *a, const unsigned char *b, const int px[2]) {
    size_t k = 4 * ((size_t)px[1] * W + (size_t)px[0]);
    return memcmp(a + k, b + k, 4) == 0;
}

static int fail(const char *what) {
    fprintf(stderr, "splatgl: %s: %s (code %d)\n", what, splatgl_last_error(),
            splatgl_last_error_code());
    return 1;
}

int main(int argc, char **argv) {
    static unsigned char host_only[W * H * 4], frames[FRAMES][W * H * 4];
    const float eye[3] = {0.0f, 0.3f, 3.0f}, target[3] = {0.0f, 0.0f, 0.0f};
    const int viewport[4] = {0, 0, W, H};
    host h;
    GLuint fbo, color, depth;
    SplatglCloud *cloud = NULL;
    SplatglRenderer *renderer;
    snapshot before, after;
    int bad = 0, f, i, changed = 0, px_occluder[2], px_splats[2], px_corner[2] = {2, H - 3};
    const float occluder_mid[3] = {-0.95f, 0.0f, 0.8f}, splat_mid[3] = {0.6f, 0.0f, 0.0f};

    if (argc < 2) {
        fprintf(stderr, "usage: %s SPLAT_FILE\n", argv[0]);
        return 2;
    }
    if (headless_context(HEADLESS_COMPAT33) != 0 || load_gl() != 0) return 1;
    printf("GL_VERSION %s; splatgl %s\n", (const char *)glGetString(GL_VERSION),
           splatgl_version());

    /* The host's own framebuffer: colour and depth renderbuffers. */
    p_glGenFramebuffers(1, &fbo);
    p_glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    p_glGenRenderbuffers(1, &color);
    p_glBindRenderbuffer(GL_RENDERBUFFER, color);
    p_glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    p_glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    p_glGenRenderbuffers(1, &depth);
    p_glBindRenderbuffer(GL_RENDERBUFFER, depth);
    p_glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, W, H);
    p_glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (p_glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "host framebuffer incomplete\n");
        return 1;
    }
    glViewport(0, 0, W, H);
    glGenTextures(1, &h.texture);
    glBindTexture(GL_TEXTURE_2D, h.texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, "\xff\xff\xff\xff");
    p_glGenBuffers(1, &h.vbo);
    p_glBindBuffer(GL_ARRAY_BUFFER, h.vbo);
    p_glBufferData(GL_ARRAY_BUFFER, sizeof GROUND, GROUND, GL_STATIC_DRAW);
    look_at(eye, target, h.view);
    perspective(50.0f, (float)W / (float)H, 0.1f, 50.0f, 0, h.proj);

    host_frame(&h);
    read_pixels(host_only);
    host_end_frame();

    renderer = splatgl_renderer_new(headless_get_proc, NULL);
    if (!renderer) return fail("splatgl_renderer_new");
    if (splatgl_renderer_set_restore_state(renderer, 1) != SPLATGL_OK)
        return fail("set_restore_state");
    if (splatgl_renderer_set_depth_func(renderer, GL_LEQUAL) != SPLATGL_OK)
        return fail("set_depth_func");
    if (splatgl_cloud_load(argv[1], &cloud) != SPLATGL_OK) return fail("splatgl_cloud_load");
    printf("loaded %zu splats, SH degree %d\n", splatgl_cloud_len(cloud),
           splatgl_cloud_sh_degree(cloud));
    if (splatgl_renderer_upload(renderer, cloud) != SPLATGL_OK) return fail("upload");
    splatgl_cloud_free(cloud); /* the renderer keeps what it needs */

    for (f = 0; f < FRAMES; f++) {
        host_frame(&h);
        read_state(&before);
        if (splatgl_renderer_draw(renderer, h.view, h.proj, viewport) != SPLATGL_OK)
            return fail("splatgl_renderer_draw");
        read_state(&after);
        bad += compare_state(&before, &after, f);
        read_pixels(frames[f]);
        host_end_frame();
        if (f > 0 && memcmp(frames[f], frames[0], sizeof frames[0]) != 0) {
            fprintf(stderr, "frame %d differs from frame 0\n", f);
            bad++;
        }
    }

    project(h.view, h.proj, W, H, occluder_mid, px_occluder);
    project(h.view, h.proj, W, H, splat_mid, px_splats);
    if (same_pixel(host_only, frames[0], px_splats)) {
        fprintf(stderr, "no splat at pixel (%d, %d)\n", px_splats[0], px_splats[1]);
        bad++;
    }
    if (!same_pixel(host_only, frames[0], px_occluder)) {
        fprintf(stderr, "the occluder's pixel (%d, %d) changed: splats not hidden by the host's "
                        "depth buffer\n", px_occluder[0], px_occluder[1]);
        bad++;
    }
    if (!same_pixel(host_only, frames[0], px_corner)) {
        fprintf(stderr, "a host pixel far from the splats changed\n");
        bad++;
    }
    for (i = 0; i < W * H; i++) changed += memcmp(host_only + 4 * i, frames[0] + 4 * i, 4) != 0;
    printf("%zu state pieces checked after each of %d draws; %d of %d pixels show splats\n",
           NPIECES, FRAMES, changed, W * H);
    if (changed < W * H / 20) {
        fprintf(stderr, "only %d pixels show splats\n", changed);
        bad++;
    }
    splatgl_renderer_free(renderer);
    if (splatgl_last_error_code() != SPLATGL_OK) return fail("splatgl_renderer_free");
    printf(bad ? "FAILED: %d checks\n" : "ok\n", bad);
    return bad ? 1 : 0;
}
