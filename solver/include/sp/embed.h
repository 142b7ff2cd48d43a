/// sp/embed.h: on-the-fly abstractions for draw-over posing (paper eq. 2).
///
/// A curve drawn over the character in the view is projected onto the mesh:
/// each sample's pixel ray hits the front-most triangle, and the point is
/// stored as barycentric coordinates of that triangle's three vertices, so
/// it is carried along as the rig deforms:
///
///     sp_abstraction a;
///     sp_embed_curve(&rig, posed_xyz, &cam, px, n, 64, "drawover", &a, &err);
///     ... append to a copy of the rig (sp_rig_add_abstraction) and solve ...
///     sp_abstraction_free(&a);
#ifndef SP_EMBED_H
#define SP_EMBED_H

#include "sp/rig.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The camera ray through pixel (u, v): origin on the near plane, unit direction.
void sp_camera_ray(const sp_camera* cam, sp_vec2 px, sp_vec3* origin, sp_vec3* dir);

/// Embeds the polyline px (n points, pixels) resampled to `samples` points
/// into the mesh posed at mesh_xyz (vertex_count by 3) as an open, ordered
/// one-curve abstraction called `name`. A sample whose ray misses the mesh
/// takes the nearest vertex in the image if it is within 4% of the canvas
/// diagonal. Fails with SP_ERR_INVALID when fewer than half the samples
/// land on the character (the curve was not drawn over it).
sp_result sp_embed_curve(const sp_rig* rig, const double* mesh_xyz, const sp_camera* cam, const sp_vec2* px, int n, int samples,
                         const char* name, sp_abstraction* out, sp_error* err);
/// Appends a copy of `a` to the rig's abstractions; returns its index or -1.
int sp_rig_add_abstraction(sp_rig* rig, const sp_abstraction* a);

#ifdef __cplusplus
}
#endif
#endif
