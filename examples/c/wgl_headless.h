/*
 * Headless WGL for the C and C++ host examples on Windows: the counterpart of
 * egl_headless.h. WGL has no surfaceless contexts, so this makes a window that is never shown,
 * gives its device context a pixel format and creates a context of the asked API on it with
 * wglCreateContextAttribsARB, current on this thread. The hosts draw into framebuffer objects
 * of their own. A windowed host gets its context from GLFW, SDL, Qt… instead and passes that
 * library's loader to splatgl_renderer_new.
 *
 * Link with -lopengl32 -lgdi32.
 */
#ifndef WGL_HEADLESS_H
#define WGL_HEADLESS_H

#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <stdio.h>
/* windows.h's 16-bit leftovers: `near` and `far` are empty macros there. */
#undef near
#undef far
#include <string.h>

enum headless_api { HEADLESS_GLES3, HEADLESS_CORE33, HEADLESS_COMPAT33 };

typedef HGLRC(WINAPI *headless_create_context_attribs)(HDC, HGLRC, const int *);

/* Creates the context and makes it current; 0 on success, else prints why and returns -1. */
static int headless_context(enum headless_api api) {
    static const int profile_bits[] = {0x0004 /* ES2_PROFILE_BIT_EXT */,
                                       0x0001 /* CORE_PROFILE_BIT_ARB */,
                                       0x0002 /* COMPATIBILITY_PROFILE_BIT_ARB */};
    int attribs[] = {0x2091 /* MAJOR_VERSION */, 3, 0x2092 /* MINOR_VERSION */, 3,
                     0x9126 /* PROFILE_MASK */, 0, 0};
    PIXELFORMATDESCRIPTOR pfd;
    WNDCLASSA wc;
    HWND window;
    HDC dc;
    HGLRC bootstrap, context;
    headless_create_context_attribs create;
    int format;

    memset(&wc, 0, sizeof wc);
    wc.style = CS_OWNDC;
    wc.lpfnWndProc = DefWindowProcA;
    wc.hInstance = GetModuleHandleA(NULL);
    wc.lpszClassName = "splatgl-host";
    RegisterClassA(&wc);
    window = CreateWindowExA(0, "splatgl-host", "splatgl-host", WS_OVERLAPPEDWINDOW, 0, 0, 16,
                             16, NULL, NULL, wc.hInstance, NULL);
    dc = window ? GetDC(window) : NULL;
    if (!dc) {
        fprintf(stderr, "WGL: cannot create the hidden window (%lu)\n", GetLastError());
        return -1;
    }
    memset(&pfd, 0, sizeof pfd);
    pfd.nSize = sizeof pfd;
    pfd.nVersion = 1;
    pfd.dwFlags = PFD_DRAW_TO_WINDOW | PFD_SUPPORT_OPENGL | PFD_DOUBLEBUFFER;
    pfd.iPixelType = PFD_TYPE_RGBA;
    pfd.cColorBits = 32;
    pfd.cAlphaBits = 8;
    pfd.cDepthBits = 24;
    pfd.cStencilBits = 8;
    format = ChoosePixelFormat(dc, &pfd);
    if (!format || !SetPixelFormat(dc, format, &pfd)) {
        fprintf(stderr, "WGL: no pixel format (%lu)\n", GetLastError());
        return -1;
    }
    bootstrap = wglCreateContext(dc);
    if (!bootstrap || !wglMakeCurrent(dc, bootstrap)) {
        fprintf(stderr, "WGL: cannot create the bootstrap context (%lu)\n", GetLastError());
        return -1;
    }
    create = (headless_create_context_attribs)(void (*)(void))wglGetProcAddress(
        "wglCreateContextAttribsARB");
    if (api == HEADLESS_GLES3) attribs[3] = 0;
    attribs[5] = profile_bits[api];
    context = create ? create(dc, NULL, attribs) : NULL;
    wglMakeCurrent(NULL, NULL);
    wglDeleteContext(bootstrap);
    if (!context || !wglMakeCurrent(dc, context)) {
        fprintf(stderr, "WGL: cannot create or bind the context (%lu)\n", GetLastError());
        return -1;
    }
    return 0;
}

/* The loader splatgl_renderer_new takes: wglGetProcAddress, and opengl32.dll for the
 * OpenGL 1.1 functions it does not return (it gives NULL or a small sentinel for those). */
static void *headless_get_proc(const char *name, void *user) {
    static HMODULE opengl32;
    void *p = (void *)(void (*)(void))wglGetProcAddress(name);
    (void)user;
    if (p == NULL || p == (void *)1 || p == (void *)2 || p == (void *)3 || p == (void *)-1) {
        if (!opengl32) opengl32 = LoadLibraryA("opengl32.dll");
        p = opengl32 ? (void *)(void (*)(void))GetProcAddress(opengl32, name) : NULL;
    }
    return p;
}

#endif /* WGL_HEADLESS_H */
