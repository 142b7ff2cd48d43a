// headless.c: EGL on the surfaceless Mesa platform, OpenGL 3.3 core, no surface.
#include "sp/headless.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

struct sp_headless {
    EGLDisplay display;
    EGLContext context;
    char renderer[128];
};

static bool has_extension(const char* list, const char* name)
{
    if (!list) return false;
    size_t n = strlen(name);
    for (const char* p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

static const char* egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS:
        return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
        return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
        return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
        return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
        return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
        return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
        return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
        return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
        return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
        return "EGL_BAD_PARAMETER";
    default:
        return "EGL error";
    }
}

sp_result sp_headless_create(sp_headless** out, sp_error* err)
{
    *out = NULL;
    sp_result res = SP_ERR_UNSUPPORTED;
    // Client extensions are queried on EGL_NO_DISPLAY; NULL means EGL 1.4
    // without EXT_client_extensions, i.e. no platform displays at all.
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_extension(client, "EGL_MESA_platform_surfaceless")) {
        return sp_fail(err, SP_ERR_UNSUPPORTED,
                       "EGL: EGL_MESA_platform_surfaceless is not available (install libegl-mesa0 and libgl1-mesa-dri)");
    }
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display) {
        return sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: eglGetPlatformDisplayEXT is missing");
    }
    EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    EGLint major = 0, minor = 0;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) { // no-op when already initialised
        return sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: cannot initialise the surfaceless display (%s)",
                       egl_error_name(eglGetError()));
    }
    sp_headless* h = calloc(1, sizeof *h);
    if (!h) {
        return sp_fail(err, SP_ERR_NO_MEMORY, "EGL: out of memory");
    }
    h->display = dpy;
    if (!eglBindAPI(EGL_OPENGL_API)) {
        res = sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: desktop OpenGL is not available (%s)", egl_error_name(eglGetError()));
        goto fail;
    }
    // Why no config when possible: we never create a surface, and the
    // surfaceless platform may offer only pbuffer configs.
    EGLConfig config = (EGLConfig)0;
    if (!has_extension(eglQueryString(dpy, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
        const EGLint attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(dpy, attrs, &config, 1, &n) || n < 1) {
            res = sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: no OpenGL config on the surfaceless display");
            goto fail;
        }
    }
    const EGLint ctx_attrs[] = {
        EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    h->context = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attrs);
    if (h->context == EGL_NO_CONTEXT) {
        res =
            sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: cannot create an OpenGL 3.3 core context (%s)", egl_error_name(eglGetError()));
        goto fail;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, h->context)) {
        res = sp_fail(err, SP_ERR_UNSUPPORTED, "EGL: cannot make the context current without a surface (%s)",
                      egl_error_name(eglGetError()));
        goto fail;
    }
    const char* name = (const char*)glGetString(GL_RENDERER);
    snprintf(h->renderer, sizeof h->renderer, "%s", name ? name : "unknown");
    *out = h;
    return SP_OK;
fail:
    sp_headless_destroy(h);
    return res;
}

void sp_headless_destroy(sp_headless* h)
{
    if (!h) return;
    if (h->display != EGL_NO_DISPLAY) {
        eglMakeCurrent(h->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (h->context != EGL_NO_CONTEXT) eglDestroyContext(h->display, h->context);
        // Why no eglTerminate: the surfaceless display is a process-wide
        // singleton (the next sp_headless_create reuses it), and terminating
        // it unloads Mesa's driver, whose static caches (allocated on the
        // first glReadPixels) then show up as leaks under LeakSanitizer.
    }
    // Why: EGL keeps per-thread state (bound API, last error) that leak
    // checkers report otherwise.
    eglReleaseThread();
    free(h);
}

const char* sp_headless_renderer_name(const sp_headless* h)
{
    return h->renderer;
}
