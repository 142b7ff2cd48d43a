/// headless.h: an offscreen OpenGL 3.3 core context without a display server.
///
/// How to use (the `sketchpose render` command, tests, the scripted kiosk):
///
///     sp_error err = {0};
///     sp_headless* gl;
///     if (sp_headless_create(&gl, &err) != SP_OK) {   // EGL, surfaceless Mesa platform
///         fprintf(stderr, "%s\n", err.text);
///         return 1;
///     }
///     ... the context is current on this thread: create an sp_render_target
///         (render.h), an sp_renderer, draw, sp_render_target_read ...
///     sp_headless_destroy(gl);
///
/// There is no default framebuffer (EGL_NO_SURFACE): render into an FBO,
/// which is what sp_render_target does. Mesa picks a GPU render node when
/// there is one and otherwise its software rasteriser (llvmpipe), so this
/// works in CI containers without /dev/dri.
#ifndef SP_HEADLESS_H
#define SP_HEADLESS_H

#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_headless sp_headless;

/// Creates an OpenGL 3.3+ core profile context on the EGL surfaceless
/// platform and makes it current on the calling thread. On failure *out is
/// NULL and err has a one-line message (e.g. "EGL:
/// EGL_MESA_platform_surfaceless is not available (install libegl-mesa0 and
/// libgl1-mesa-dri)").
sp_result sp_headless_create(sp_headless** out, sp_error* err);
/// Releases the context (NULL is fine).
void sp_headless_destroy(sp_headless* h);
/// "Mesa llvmpipe (LLVM 15...)": the GL_RENDERER string, for logs.
const char* sp_headless_renderer_name(const sp_headless* h);

#ifdef __cplusplus
}
#endif
#endif
