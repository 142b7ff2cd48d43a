/// gen_outline.h: an outline sketch abstraction from a rest mesh.
///
/// How to use:
///
///     sp_abstraction ab;
///     char why[256];
///     if (!sp_gen_outline(&mesh, &camera, 150, &ab, why, sizeof why)) { fprintf(stderr, "%s\n", why); ... }
///
/// The rest mesh (without its decorations) is projected by the sketch camera and rasterised (about
/// 1000 cells across), small gaps and diagonal pinches are closed, holes
/// are filled, and the outer boundary of the largest region is traced,
/// smoothed (the raster staircase is far below a sketch's precision) and
/// resampled to `points` equally spaced points. Each point is bound to the
/// nearest vertex in the view whose normal faces out of the silhouette
/// (where two legs overlap, the one that makes this stretch of contour): it
/// takes that vertex's depth and skin weights, the weights then smoothed a
/// little along the curve, so the curve follows the rig like the surface
/// under it and passes evenly from one bone to the next.
#ifndef SP_GEN_OUTLINE_H
#define SP_GEN_OUTLINE_H

#include <stdbool.h>
#include <stddef.h>

#include "gen_mesh.h"
#include "sp/rig.h"

/// Fills *out (malloc'd arrays, owned by the caller, freed with
/// sp_abstraction_free) with one closed curve named "outline" in an
/// abstraction named "outline", closest-point correspondences. Returns
/// false with a message in `why` if the mesh has no area in the view or
/// the silhouette falls apart into several large pieces.
bool sp_gen_outline(const sp_gen_mesh* mesh, const sp_camera* cam, int points, sp_abstraction* out, char* why, size_t why_size);

#endif
