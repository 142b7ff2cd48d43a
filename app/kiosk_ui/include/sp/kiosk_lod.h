/// lod.h: coarser display meshes by vertex clustering, for software renderers.
///
///     sp_lod lod;
///     if (sp_lod_build(xyz, nv, tris, nt, colors, 4000, &lod) == SP_OK) {
///         ... upload lod.tri_count triangles over lod.cluster_count vertices, colours lod.colors ...
///         per frame: sp_lod_positions(&lod, posed_xyz, out);   // cluster means of the posed vertices
///     }
///     sp_lod_free(&lod);
///
/// Why: Mesa's llvmpipe spends CPU on every triangle before shading a single
/// pixel, so six full-detail parts cost more than a frame (BENCHMARKS.md,
/// "The dragon kiosk"). A part
/// drawn a few hundred pixels wide loses little when its vertices are merged
/// on a grid (Rossignac-Borrel clustering) down to a few thousand triangles.
/// The clustering is computed once (on the pose given) and kept: every frame
/// a cluster sits at the mean of its vertices' posed positions, so the coarse
/// mesh follows the skinning without popping.
#ifndef SP_KIOSK_LOD_H
#define SP_KIOSK_LOD_H

#include <stdint.h>

#include "sp/result.h"

typedef struct sp_lod {
    int vertex_count;  ///< of the source mesh
    int cluster_count; ///< vertices of the coarse mesh
    int* cluster;      ///< vertex_count: the cluster of each source vertex
    float* inv_size;   ///< cluster_count: 1 / members
    int tri_count;
    uint32_t* tris; ///< tri_count by 3, cluster indices
    float* colors;  ///< cluster_count by 4 (mean of the members'), or NULL
} sp_lod;

/// Clusters a mesh (xyz: nv by 3; tris: nt by 3; colors: nv by 4 or NULL)
/// on the coarsest-needed cubic grid that keeps at most max_tris triangles
/// (a mesh already within the budget is kept as is, one cluster a vertex).
/// Degenerate and duplicate triangles (either winding) are dropped.
sp_result sp_lod_build(const double* xyz, int nv, const uint32_t* tris, int nt, const float* colors, int max_tris, sp_lod* out);
/// Cluster positions (cluster_count by 3) for posed source positions (vertex_count by 3).
void sp_lod_positions(const sp_lod* lod, const double* xyz, double* out);
void sp_lod_free(sp_lod* lod);

#endif
