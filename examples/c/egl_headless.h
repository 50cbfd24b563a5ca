/*
 * Headless EGL for the C and C++ host examples: a context of the asked API on Mesa's
 * surfaceless platform, current on this thread, without a default framebuffer (the hosts
 * draw into framebuffer objects of their own). A windowed host gets its context from GLFW,
 * SDL, Qt… instead and passes that library's loader to splatgl_renderer_new.
 */
#ifndef EGL_HEADLESS_H
#define EGL_HEADLESS_H

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

enum headless_api { HEADLESS_GLES3, HEADLESS_CORE33, HEADLESS_COMPAT33 };

/* Creates the context and makes it current; 0 on success, else prints why and returns -1. */
static int headless_context(enum headless_api api) {
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLDisplay display;
    EGLConfig config;
    EGLint count = 0;
    EGLContext context;
    EGLint renderable = api == HEADLESS_GLES3 ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_BIT;
    EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, renderable, EGL_SURFACE_TYPE, EGL_DONT_CARE,
                               EGL_NONE};
    EGLint profile = api == HEADLESS_CORE33 ? EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT
                                            : EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT;
    EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION,
                                api == HEADLESS_GLES3 ? 0 : 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                profile, EGL_NONE};
    if (api == HEADLESS_GLES3) {
        context_attribs[4] = EGL_NONE; /* no profile on ES */
    }
    if (!get_display) {
        fprintf(stderr, "EGL: no eglGetPlatformDisplayEXT\n");
        return -1;
    }
    display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, NULL, NULL)) {
        fprintf(stderr, "EGL: cannot open the surfaceless display (0x%x)\n", eglGetError());
        return -1;
    }
    if (!eglBindAPI(api == HEADLESS_GLES3 ? EGL_OPENGL_ES_API : EGL_OPENGL_API) ||
        !eglChooseConfig(display, config_attribs, &config, 1, &count) || count < 1) {
        fprintf(stderr, "EGL: no config (0x%x)\n", eglGetError());
        return -1;
    }
    context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (context == EGL_NO_CONTEXT ||
        !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
        fprintf(stderr, "EGL: cannot create or bind the context (0x%x)\n", eglGetError());
        return -1;
    }
    return 0;
}

/* The loader splatgl_renderer_new takes: EGL's (which returns core functions on Mesa). */
static void *headless_get_proc(const char *name, void *user) {
    (void)user;
    return (void *)eglGetProcAddress(name);
}

#endif /* EGL_HEADLESS_H */
