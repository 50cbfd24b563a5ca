// A modern host in C++: an OpenGL 3.3 core context with its own framebuffer, a reversed-Z
// float depth buffer (cleared to 0, GL_GREATER, an infinite far plane) and a shaded mesh (two
// cubes: one in front of the splats, one behind them). The splats come from the host's own
// arrays (splatgl_cloud_from_arrays) and are drawn with the host's matrices and depth
// convention. Checks: where the front cube is, its pixels are untouched (the splats are
// occluded); where the back cube is, the splats cover it; the error paths a host meets.
//
// Build (crates/splatgl-capi/tests/it/capi_hosts.rs does this):
//   cargo build -p splatgl-capi
//   c++ -std=c++17 -Wall -Wextra -Werror -Icrates/splatgl-capi/include -Iexamples/c examples/cpp/core_host.cpp
//       -Ltarget/debug -lsplatgl_capi -lEGL -lm -Wl,-rpath,$PWD/target/debug -o core_host
//   ./core_host
#include <GL/glcorearb.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "egl_headless.h"
#include "host_math.h"
#include "splatgl.h"

namespace {

constexpr int W = 160, H = 120;

// The GL functions this host uses, loaded through EGL (a real host has GLAD, glbinding, …).
struct Gl {
#define GLFN(type, name) type name = reinterpret_cast<type>(eglGetProcAddress("gl" #name));
    GLFN(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)
    GLFN(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)
    GLFN(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)
    GLFN(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)
    GLFN(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)
    GLFN(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)
    GLFN(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)
    GLFN(PFNGLCREATESHADERPROC, CreateShader)
    GLFN(PFNGLSHADERSOURCEPROC, ShaderSource)
    GLFN(PFNGLCOMPILESHADERPROC, CompileShader)
    GLFN(PFNGLGETSHADERIVPROC, GetShaderiv)
    GLFN(PFNGLCREATEPROGRAMPROC, CreateProgram)
    GLFN(PFNGLATTACHSHADERPROC, AttachShader)
    GLFN(PFNGLLINKPROGRAMPROC, LinkProgram)
    GLFN(PFNGLGETPROGRAMIVPROC, GetProgramiv)
    GLFN(PFNGLUSEPROGRAMPROC, UseProgram)
    GLFN(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)
    GLFN(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)
    GLFN(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)
    GLFN(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)
    GLFN(PFNGLGENBUFFERSPROC, GenBuffers)
    GLFN(PFNGLBINDBUFFERPROC, BindBuffer)
    GLFN(PFNGLBUFFERDATAPROC, BufferData)
    GLFN(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)
    GLFN(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)
    GLFN(PFNGLCLEARCOLORPROC, ClearColor)
    GLFN(PFNGLCLEARDEPTHPROC, ClearDepth)
    GLFN(PFNGLCLEARPROC, Clear)
    GLFN(PFNGLENABLEPROC, Enable)
    GLFN(PFNGLDEPTHFUNCPROC, DepthFunc)
    GLFN(PFNGLVIEWPORTPROC, Viewport)
    GLFN(PFNGLDRAWARRAYSPROC, DrawArrays)
    GLFN(PFNGLREADPIXELSPROC, ReadPixels)
    GLFN(PFNGLGETSTRINGPROC, GetString)
#undef GLFN
};

const char *VS = R"(#version 330 core
layout(location = 0) in vec3 pos;
uniform mat4 mvp;
out vec3 p;
void main() { p = pos; gl_Position = mvp * vec4(pos, 1.0); })";
const char *FS = R"(#version 330 core
in vec3 p;
out vec4 color;
void main() { color = vec4(0.3 + 0.4 * abs(p), 1.0); })";

GLuint compile(const Gl &gl, GLenum stage, const char *src) {
    GLuint s = gl.CreateShader(stage);
    gl.ShaderSource(s, 1, &src, nullptr);
    gl.CompileShader(s);
    GLint ok = 0;
    gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    return ok ? s : 0;
}

// 36 vertices of a cube of half-size h centred at c.
std::vector<float> cube(const float c[3], float h) {
    static const int faces[6][4][3] = {
        {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},     {{1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}},
        {{-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}}, {{1, -1, 1}, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}},
        {{-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}},     {{-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}}};
    static const int tri[6] = {0, 1, 2, 0, 2, 3};
    std::vector<float> v;
    for (const auto &f : faces)
        for (int k : tri)
            for (int a = 0; a < 3; a++) v.push_back(c[a] + h * static_cast<float>(f[k][a]));
    return v;
}

// A wall of opaque splats at z = 0, x in [-1, 1], y in [-0.6, 0.6], SH degree 0.
struct Wall {
    std::vector<float> pos, scale, rot, opacity, sh;
    size_t n = 0;
    Wall() {
        for (int j = 0; j < 16; j++)
            for (int i = 0; i < 24; i++) {
                const float x = -1.0f + 2.0f * static_cast<float>(i) / 23.0f;
                const float y = -0.6f + 1.2f * static_cast<float>(j) / 15.0f;
                pos.insert(pos.end(), {x, y, 0.0f});
                scale.insert(scale.end(), {0.05f, 0.05f, 0.01f});
                rot.insert(rot.end(), {0.0f, 0.0f, 0.0f, 1.0f});
                opacity.push_back(0.95f);
                sh.insert(sh.end(), {1.2f, -0.4f, 0.8f});  // colour 0.5 + 0.282 · DC
                n++;
            }
    }
};

struct Renderer {
    SplatglRenderer *r;
    ~Renderer() { splatgl_renderer_free(r); }
};
struct Cloud {
    SplatglCloud *c = nullptr;
    ~Cloud() { splatgl_cloud_free(c); }
};

int fail(const char *what) {
    std::fprintf(stderr, "splatgl: %s: %s (code %d)\n", what, splatgl_last_error(),
                 splatgl_last_error_code());
    return 1;
}

int expect(bool ok, const char *what) {
    if (!ok) std::fprintf(stderr, "check failed: %s\n", what);
    return ok ? 0 : 1;
}

}  // namespace

int main() {
    if (headless_context(HEADLESS_CORE33) != 0) return 1;
    Gl gl;
    std::printf("GL_VERSION %s\n", reinterpret_cast<const char *>(gl.GetString(GL_VERSION)));
    GLuint fbo, color, depth;
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.GenRenderbuffers(1, &color);
    gl.BindRenderbuffer(GL_RENDERBUFFER, color);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    gl.GenRenderbuffers(1, &depth);
    gl.BindRenderbuffer(GL_RENDERBUFFER, depth);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, W, H);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return 1;
    gl.Viewport(0, 0, W, H);

    GLuint vs = compile(gl, GL_VERTEX_SHADER, VS), fs = compile(gl, GL_FRAGMENT_SHADER, FS);
    GLuint prog = gl.CreateProgram();
    gl.AttachShader(prog, vs);
    gl.AttachShader(prog, fs);
    gl.LinkProgram(prog);
    GLint linked = 0;
    gl.GetProgramiv(prog, GL_LINK_STATUS, &linked);
    if (!vs || !fs || !linked) return expect(false, "host shaders");
    const float front_c[3] = {-0.6f, 0.0f, 0.6f}, back_c[3] = {0.6f, 0.0f, -0.8f};
    std::vector<float> verts = cube(front_c, 0.3f), back = cube(back_c, 0.35f);
    verts.insert(verts.end(), back.begin(), back.end());
    GLuint vao, vbo;
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.GenBuffers(1, &vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(verts.size() * sizeof(float)),
                  verts.data(), GL_STATIC_DRAW);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.EnableVertexAttribArray(0);

    const float eye[3] = {0.0f, 0.2f, 3.0f}, target[3] = {0.0f, 0.0f, 0.0f};
    float view[16], proj[16], mvp[16];
    look_at(eye, target, view);
    perspective(50.0f, static_cast<float>(W) / H, 0.1f, 0.0f, 1, proj);  // reversed, infinite
    mat_mul(proj, view, mvp);
    const int viewport[4] = {0, 0, W, H};

    Renderer r{splatgl_renderer_new(headless_get_proc, nullptr)};
    if (!r.r) return fail("splatgl_renderer_new");
    int bad = 0;
    // Error paths a host meets: each a code and a message, never a crash.
    bad += expect(splatgl_renderer_draw(r.r, view, proj, viewport) == SPLATGL_ERROR_NOT_UPLOADED,
                  "draw before upload");
    bad += expect(std::strlen(splatgl_last_error()) > 0, "a message for the failed draw");
    bad += expect(splatgl_renderer_set_depth_func(r.r, 0x1234) == SPLATGL_ERROR_INVALID_ARGUMENT,
                  "a depth function that is not one");
    bad += expect(splatgl_renderer_draw(nullptr, view, proj, viewport) == SPLATGL_ERROR_NULL_POINTER,
                  "a NULL renderer");

    Wall wall;
    Cloud cloud;
    if (splatgl_cloud_from_arrays(wall.n, wall.pos.data(), wall.scale.data(), wall.rot.data(),
                                  wall.opacity.data(), 0, wall.sh.data(), &cloud.c) != SPLATGL_OK)
        return fail("splatgl_cloud_from_arrays");
    if (splatgl_renderer_upload(r.r, cloud.c) != SPLATGL_OK) return fail("upload");
    if (splatgl_renderer_set_depth_func(r.r, GL_GREATER) != SPLATGL_OK) return fail("depth func");
    const int bad_viewport[4] = {0, 0, 0, H};
    bad += expect(splatgl_renderer_draw(r.r, view, proj, bad_viewport) == SPLATGL_ERROR_VIEWPORT,
                  "a viewport without pixels");
    float nan_view[16];
    std::memcpy(nan_view, view, sizeof view);
    nan_view[12] = std::nanf("");
    bad += expect(splatgl_renderer_draw(r.r, nan_view, proj, viewport) == SPLATGL_ERROR_MATRIX,
                  "a non-finite view matrix");

    std::vector<unsigned char> cubes_only(W * H * 4), with_splats(W * H * 4);
    for (int splats = 0; splats < 2; splats++) {
        gl.ClearColor(0.05f, 0.05f, 0.08f, 1.0f);
        gl.ClearDepth(0.0);  // reversed-Z: far is 0
        gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        gl.Enable(GL_DEPTH_TEST);
        gl.DepthFunc(GL_GREATER);
        gl.UseProgram(prog);
        gl.BindVertexArray(vao);
        gl.UniformMatrix4fv(gl.GetUniformLocation(prog, "mvp"), 1, GL_FALSE, mvp);
        gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(verts.size() / 3));
        if (splats && splatgl_renderer_draw(r.r, view, proj, viewport) != SPLATGL_OK)
            return fail("splatgl_renderer_draw");
        gl.ReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE,
                      (splats ? with_splats : cubes_only).data());
    }
    auto at = [&](const std::vector<unsigned char> &img, const float p[3]) {
        int px[2];
        project(view, proj, W, H, p, px);
        return std::vector<unsigned char>(img.begin() + 4 * (px[1] * W + px[0]),
                                          img.begin() + 4 * (px[1] * W + px[0]) + 4);
    };
    const float front_face[3] = {-0.6f, 0.0f, 0.9f};  // the front cube's face, before the wall
    const float back_seen[3] = {0.6f, 0.0f, 0.0f};     // the wall, in front of the back cube
    bad += expect(at(with_splats, front_face) == at(cubes_only, front_face),
                  "the front cube hides the splats (reversed-Z depth test)");
    bad += expect(at(with_splats, back_seen) != at(cubes_only, back_seen),
                  "the splats cover the cube behind them");
    int changed = 0;
    for (int i = 0; i < W * H; i++)
        changed += std::memcmp(&with_splats[4 * i], &cubes_only[4 * i], 4) != 0;
    std::printf("%d of %d pixels show splats\n", changed, W * H);
    bad += expect(changed > W * H / 10, "the splats are drawn");
    std::printf(bad ? "FAILED: %d checks\n" : "ok\n", bad);
    return bad ? 1 : 0;
}
