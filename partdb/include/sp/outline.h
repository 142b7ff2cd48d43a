/// sp/outline.h: an outline sketch abstraction traced from a rest mesh.
///
/// How to use (the asset generator and the derivation of sp/derive.h):
///
///     sp_abstraction ab;
///     sp_error err = {0};
///     sp_outline_desc d = {.vertex_count = n, .positions = xyz, .influences = 4, .joints = j, .weights = w,
///                          .triangle_count = t, .triangles = tris, .camera = &side_view};
///     if (sp_outline_trace(&d, &ab, NULL, &err) != SP_OK) { fprintf(stderr, "%s\n", err.text); ... }
///     ... ab.rest are world points at rest: bind space only when the rest skin matrices are the identity ...
///     sp_abstraction_free(&ab);
///
/// The mesh (without the vertices and triangles flagged to skip, e.g. a
/// dragon's spikes and teeth) is projected by the orthographic sketch camera
/// and rasterised (about 1000 cells across), small gaps and diagonal pinches
/// are closed, holes are filled, and the outer boundary of the largest region
/// is traced, smoothed (the raster staircase is far below a sketch's
/// precision) and resampled to `points` equally spaced points. Each point is
/// bound to the nearest vertex (or, with `surface`, the nearest point of a
/// triangle) in the view whose normal faces out of the silhouette (where two
/// legs overlap, the one that makes this stretch of contour; the nearest of
/// all where no normal says so, e.g. a flat sheet seen face on): it takes
/// that depth and skin weights, the weights then smoothed a little along the curve, so that the curve follows
/// the rig like the surface under it and passes evenly from one bone to the
/// next. Open (not watertight) meshes and any triangle winding are fine.
/// Deterministic: plain double arithmetic in a fixed order.
#ifndef SP_OUTLINE_H
#define SP_OUTLINE_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/result.h"
#include "sp/rig.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Skin entries per vertex the tracer keeps while smoothing (more are refused).
enum { SP_OUTLINE_INFLUENCES_MAX = 8 };

/// Skin weights while blending (the tracer's smoothing, the asset generator's
/// meshes): up to 8 (joint, weight) pairs, packed to glTF's 4 at the end.
typedef struct sp_skin8 {
    int n;
    int joint[SP_OUTLINE_INFLUENCES_MAX];
    double w[SP_OUTLINE_INFLUENCES_MAX];
} sp_skin8;
/// Adds w (ignored unless > 0) to joint's weight, merging; when full, replaces
/// the weakest entry if w is stronger.
void sp_skin8_add(sp_skin8* s, int joint, double w);
/// The 4 strongest influences renormalised to sum 1 (ties: lower joint first,
/// for determinism); unused slots are joint 0, weight 0 (all zero: joint 0, 1).
void sp_skin8_pack(const sp_skin8* s, uint16_t joints[4], float weights[4]);

/// What to trace. Zero-initialised fields mean the defaults.
typedef struct sp_outline_desc {
    int vertex_count;
    const double* positions; ///< vertex_count by 3: the mesh at rest, world space
    int influences;          ///< skin entries per vertex, 1..SP_OUTLINE_INFLUENCES_MAX
    const uint16_t* joints;  ///< vertex_count by influences, rig joint indices
    const double* weights;   ///< vertex_count by influences, >= 0 (0: an unused entry)
    int triangle_count;
    const uint32_t* triangles;          ///< triangle_count by 3, indices < vertex_count
    const unsigned char* skip_vertex;   ///< vertex_count flags (non-zero: left out), or NULL
    const unsigned char* skip_triangle; ///< triangle_count flags, or NULL
    const sp_camera* camera;            ///< the sketch view; must be orthographic
    int points;                         ///< points of the curve; 0: 150
    /// Passes of (1/4, 1/2, 1/4) smoothing of the points' world z (the depth
    /// of a view along -Z) along the curve (0: none): where a limb's silhouette runs between the rings of a
    /// coarse tube the nearest vertex alternates between its front and back,
    /// and a limb turning out of the picture would then zigzag the curve.
    int depth_passes;
    /// Bind each point to the nearest point of the nearest outward-facing
    /// triangle (its depth and the three vertices' skins interpolated), for
    /// coarse meshes whose vertices lie far apart along the silhouette;
    /// false: the nearest outward-facing vertex (the generator's dense meshes).
    bool surface;
    /// Keep the largest piece when the silhouette falls apart into several
    /// big ones (the info says how much was left out); false: refuse, which
    /// is what the generator wants of its own parts.
    bool keep_largest;
} sp_outline_desc;

/// What the tracing saw.
typedef struct sp_outline_info {
    int regions;          ///< separate pieces of the closed, hole-filled silhouette
    double dropped_share; ///< cells of the other pieces over all silhouette cells (0: one piece)
    double cell_px;       ///< one raster cell in the camera's pixels
} sp_outline_info;

/// Fills *out (malloc'd arrays, freed with sp_abstraction_free) with one closed
/// curve "outline" in an abstraction "outline", closest-point correspondences;
/// `rest` holds world points at rest (the positions' space), joints and
/// weights the 4 strongest smoothed influences. `info` may be NULL.
/// SP_ERR_INVALID (and *out zeroed) when the mesh has no area in the view,
/// the camera is not orthographic, the arguments are out of range, or (unless
/// keep_largest) the silhouette falls apart; SP_ERR_NO_MEMORY.
sp_result sp_outline_trace(const sp_outline_desc* desc, sp_abstraction* out, sp_outline_info* info, sp_error* err);

/// The tracer's rasteriser, for others that need a mesh's cover: marks
/// (sets to 1) the cells of a w x h grid (row-major, a byte a cell) whose
/// centre (x + 0.5, y + 0.5) lies in triangle a b c, given in cells (either
/// winding, edges included). A triangle of no area, or with a corner that is
/// not finite, marks none; parts beyond the grid are clipped.
void sp_raster_triangle(unsigned char* cells, int w, int h, const double a[2], const double b[2], const double c[2]);

#ifdef __cplusplus
}
#endif
#endif
