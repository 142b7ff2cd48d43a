/// render.h: the one OpenGL 3.3 core renderer, for the kiosk window and headless PNGs.
///
/// How to use (a GL 3.3 core context must be current: a GLFW window, or
/// sp_headless_create from headless.h):
///
///     sp_renderer* r; sp_render_target* t; sp_render_mesh* m;
///     if (sp_renderer_create(&(sp_renderer_desc){0}, &r, &err) != SP_OK) ... err.text ...
///     sp_render_target_create(640, 480, 0, &t, &err);  // offscreen, 4x MSAA
///     sp_render_mesh_create(r, &(sp_mesh_desc){
///         .vertex_count = n, .positions = xyz, .colors = ch.colors,
///         .triangle_count = rig.triangle_count, .triangles = rig.triangles}, &m, &err);
///     sp_render_target_bind(t);
///     sp_renderer_begin(r, &camera, 640, 480);
///     sp_renderer_clear(r, SP_COLOR_BACKGROUND_TOP, SP_COLOR_BACKGROUND_BOTTOM);
///     sp_renderer_draw_mesh(r, m, NULL);
///     sp_renderer_draw_polyline(r, stroke, count, false, 4.0f, SP_COLOR_STROKE);
///     sp_renderer_end(r);
///     sp_render_target_read(t, &image, &err);            // RGBA8, top-down rows
///     ... next frame: sp_render_mesh_update(m, new_xyz) ...
///
/// Geometry and pixels: 3D positions are world space (posed, e.g. from
/// sp_rig_eval_points). The view is an sp_camera (rig.h); the GL projection
/// is built from it (sp_render_projection) so that a world point lands in
/// exactly the pixel sp_camera_project gives: pixel (u, v), y down, covers
/// [u, u+1) x [v, v+1) of the camera's width x height canvas. 2D overlays
/// take those same camera pixels. When the viewport is larger than the
/// camera canvas (HiDPI), everything scales together.
///
/// Colours: mesh colours are linear RGBA (glTF base colours); lighting is
/// computed in linear space and written sRGB-encoded. Overlay and background
/// colours are display (sRGB) values, written as given, so a test can look
/// for them in the read-back image.
///
/// Cost: a mesh keeps its triangles on the CPU and recomputes smooth
/// per-vertex normals from the posed triangles on every update (area
/// weighted, welded across UV seams); positions and normals are re-uploaded,
/// colours and indices stay on the GPU. Six 16k-vertex parts per frame is
/// well under a millisecond of CPU time for the normals.
#ifndef SP_RENDER_H
#define SP_RENDER_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/image.h"
#include "sp/result.h"
#include "sp/rig.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Display (sRGB) colours of the house style, as `const float*` for the draw calls.
#define SP_COLOR_STROKE ((const float[4]){0.15f, 0.35f, 0.95f, 1.0f})   ///< the user's strokes
#define SP_COLOR_ABSTRACTION ((const float[4]){1.0f, 0.8f, 0.1f, 1.0f}) ///< fitted abstraction curves
#define SP_COLOR_OUTLINE ((const float[4]){0.08f, 0.08f, 0.1f, 0.85f})  ///< dark halo under light lines
/// A user's strokes are drawn this much wider than the fitted curves over
/// them, so a stroke the fit follows exactly still shows a blue rim.
#define SP_STROKE_UNDER_FIT 1.8f
#define SP_COLOR_INK ((const float[4]){0.1f, 0.07f, 0.07f, 1.0f})       ///< details drawn on the dragon (eyes, spots)
#define SP_COLOR_BACKGROUND_TOP ((const float[4]){0.93f, 0.94f, 0.96f, 1.0f})
#define SP_COLOR_BACKGROUND_BOTTOM ((const float[4]){0.68f, 0.72f, 0.79f, 1.0f})

typedef struct sp_renderer sp_renderer;
typedef struct sp_render_mesh sp_render_mesh;
typedef struct sp_render_target sp_render_target;

/// Zero means defaults.
typedef struct sp_renderer_desc {
    float exposure; ///< multiplies the light; 0: 1.0
    float ambient;  ///< hemisphere ambient strength; 0: 0.35
    bool no_rim;    ///< turn the rim light off
} sp_renderer_desc;

/// Compiles the shaders. Needs a current GL 3.3 core context. On failure
/// *out is NULL and err says why.
sp_result sp_renderer_create(const sp_renderer_desc* desc, sp_renderer** out, sp_error* err);
/// Frees the GL objects (the context must still be current). NULL is fine.
void sp_renderer_destroy(sp_renderer* r);

/// The GL projection (column-major, camera space -> clip) that matches
/// sp_camera_project for cam: NDC x = 2u/width - 1, y = 1 - 2v/height.
/// Depth maps [znear, zfar] (camera units in front of the camera) to [-1, 1];
/// an invalid range (perspective: needs 0 < znear < zfar; orthographic:
/// znear < zfar) falls back to [0.01, 1000].
sp_mat4 sp_render_projection(const sp_camera* cam);

/// Sets cam's znear/zfar to hold the world box [lo, hi] with a small margin
/// (e.g. a posed mesh's bounds, which can leave the rest pose's range).
/// Orthographic ranges may start behind the eye; perspective ones stay in front.
void sp_render_fit_depth(sp_camera* cam, sp_vec3 lo, sp_vec3 hi);

/// Starts a frame on the bound framebuffer (0 for a window, or a target
/// bound with sp_render_target_bind): sets the viewport to vw x vh pixels
/// (0: the camera's width x height) and resets the GL state the renderer
/// needs. Overlay pixel coordinates are the camera's.
void sp_renderer_begin(sp_renderer* r, const sp_camera* cam, int vw, int vh);
/// Clears colour, depth and stencil: a vertical gradient from `top` to `bottom`
/// (display colours, alpha written as is; bottom NULL = flat `top`).
void sp_renderer_clear(sp_renderer* r, const float top[4], const float bottom[4]);
/// Draws the pending overlays and finishes the frame (does not swap or read).
void sp_renderer_end(sp_renderer* r);

/// A mesh to upload. Positions are required; the rest may be NULL.
typedef struct sp_mesh_desc {
    int vertex_count;
    const double* positions; ///< vertex_count by 3, world
    const float* normals;    ///< vertex_count by 3, or NULL: computed from the triangles
    const float* colors;     ///< vertex_count by 4, linear RGBA, or NULL: base_color
    float base_color[4];     ///< linear RGBA; all zero: a light clay grey
    int triangle_count;
    const uint32_t* triangles; ///< triangle_count by 3, indices < vertex_count
} sp_mesh_desc;

/// A skinned rig's mesh posed at `positions` (its vertices by 3, world, as
/// sp_rig_eval_points gives them), with per-vertex `colors` or NULL.
static inline sp_mesh_desc sp_mesh_desc_of_rig(const sp_rig* rig, const double* positions, const float* colors)
{
    return (sp_mesh_desc){.vertex_count = rig->vertex_count,
                          .positions = positions,
                          .colors = colors,
                          .triangle_count = rig->triangle_count,
                          .triangles = rig->triangles};
}

/// Uploads a mesh (copies everything it needs). On failure (bad index, NaN
/// position, out of memory) *out is NULL and err says why.
sp_result sp_render_mesh_create(sp_renderer* r, const sp_mesh_desc* desc, sp_render_mesh** out, sp_error* err);
/// New positions (vertex_count by 3, world) for the next draws, e.g. a new
/// pose. normals NULL recomputes smooth normals from the triangles.
void sp_render_mesh_update(sp_render_mesh* m, const double* positions, const float* normals);
/// World bounds of the current positions.
void sp_render_mesh_bounds(const sp_render_mesh* m, sp_vec3* lo, sp_vec3* hi);
/// Frees the mesh's GL objects and memory. NULL is fine.
void sp_render_mesh_destroy(sp_render_mesh* m);

/// Draws the mesh smooth-shaded (key, fill and rim light, hemisphere
/// ambient), depth-tested, with an optional model matrix (NULL: identity).
void sp_renderer_draw_mesh(sp_renderer* r, const sp_render_mesh* m, const sp_mat4* model);
/// A soft shadow ellipse on the ground (world +Y up) under the box
/// [lo, hi], drawn flat behind everything drawn later. In side views, where
/// the ground plane is seen edge-on, the ellipse keeps a minimum height so
/// that it still reads as a contact shadow. opacity 0..1 (0: 0.35).
void sp_renderer_draw_ground_shadow(sp_renderer* r, sp_vec3 lo, sp_vec3 hi, float opacity);

/// 2D overlays, in camera pixels (y down), without depth test: they cover
/// whatever was drawn before them. They are batched and drawn in call order
/// before the next mesh, shadow or clear, or at sp_renderer_end. Lines have
/// round joins and caps and are anti-aliased by analytic coverage.
/// A polyline through n points; width in pixels; colour display RGBA. Each
/// pixel is blended once per polyline, so translucent lines stay even at
/// joins and self-crossings (uses the stencil buffer when there is one).
void sp_renderer_draw_polyline(sp_renderer* r, const sp_vec2* px, int n, bool closed, float width, const float rgba[4]);
/// Filled discs of `radius` pixels at the points.
void sp_renderer_draw_dots(sp_renderer* r, const sp_vec2* px, int n, float radius, const float rgba[4]);
/// A 3D polyline (n by 3, world) projected with the frame's camera.
void sp_renderer_draw_curve3d(sp_renderer* r, const double* xyz, int n, bool closed, float width, const float rgba[4]);
/// Ink on a surface: the runs of consecutive points whose normal (n by 3,
/// world) points towards the camera (a zero normal, ink in the air, faces
/// every way), depth-tested against the meshes drawn before it, the points
/// lifted towards the camera by 1.5 widths (at least 4 px) so that the ink
/// does not sink into its own curved surface.
void sp_renderer_draw_curve3d_facing(sp_renderer* r, const double* xyz, const double* normal, int n, float width,
                                     const float rgba[4]);
/// Every curve of an abstraction; xyz are its points in world space
/// (a->point_count by 3, from sp_rig_eval_abstraction).
void sp_renderer_draw_abstraction(sp_renderer* r, const sp_abstraction* a, const double* xyz, float width, const float rgba[4]);

/// An offscreen framebuffer: multisampled colour (RGBA8) and depth, resolved
/// on read. samples 0 means 4; clamped to what the driver offers. On
/// failure *out is NULL and err says why.
sp_result sp_render_target_create(int width, int height, int samples, sp_render_target** out, sp_error* err);
/// NULL is fine.
void sp_render_target_destroy(sp_render_target* t);
/// Binds it for drawing (then call sp_renderer_begin with its size).
void sp_render_target_bind(const sp_render_target* t);
/// Resolves the samples and reads RGBA8 into *img (allocated or reused),
/// top-down rows.
sp_result sp_render_target_read(const sp_render_target* t, sp_image* img, sp_error* err);

/// Compiles and links a GLSL program from a vertex and a fragment shader (a
/// GL context must be current): 0 and a one-line error naming `what` and the
/// compiler's log when it fails. For other GL drawing code (the kiosk's 2D
/// layer) beside the renderer's own programs.
unsigned sp_gl_program(const char* vs_src, const char* fs_src, const char* what, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
