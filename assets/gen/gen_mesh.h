/// gen_mesh.h: geometry building blocks of the asset generator.
///
/// How to use: a part builder grows one `sp_gen_mesh` (positions in the
/// part's rest space, sRGB vertex colours, skin weights) from smooth pieces:
///
///     sp_gen_path spine;                                  // a smooth centreline
///     sp_gen_path_catmull(&spine, ctrl, 5, 32);
///     sp_gen_chain ch = {0};                              // skin along it
///     sp_gen_chain_add(&ch, j_hips, 0.0, 0.0);
///     sp_gen_chain_add(&ch, j_chest, 1.1, 0.45);          // joint, station, blend half-width
///     sp_gen_tube(&mesh, &(sp_gen_tube_desc){.path = &spine, .rings = 120, .segments = 48,
///                                             .profile = my_profile, .color = my_colour, .chain = &ch, ...});
///     sp_gen_cone(&mesh, &(sp_gen_cone_desc){...});       // horns, spikes, claws
///
/// Everything is plain double arithmetic in a fixed order (no threads, no
/// clock, no unseeded randomness), so a generator run is reproducible bit
/// for bit. Allocation failure ends the generator with a message (it is a
/// build tool; there is nothing sensible to fall back to).
///
/// Conventions: a part faces +X with +Y up; the sketch view looks along -Z,
/// so the side silhouette lives in the XY plane. A tube's cross-section
/// angle a is 0 on its "up" side (the section's N axis), pi/2 on its +side
/// (B axis, +Z by default), pi underneath.
#ifndef SP_GEN_MESH_H
#define SP_GEN_MESH_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/math.h"
#include "sp/outline.h"

enum { SP_GEN_SKIN_MAX = SP_OUTLINE_INFLUENCES_MAX };

/// A colour, sRGB-encoded components in [0, 1] (converted to linear on save).
typedef struct sp_gen_rgb {
    double r, g, b;
} sp_gen_rgb;

/// Skin weights while building: up to 8 (joint, weight) pairs; packing
/// keeps the 4 strongest and renormalises (partdb's sp_skin8, which the
/// outline tracer smooths with).
typedef sp_skin8 sp_gen_skin;

/// A growing triangle mesh with per-vertex colour and skin.
typedef struct sp_gen_mesh {
    int vertex_count, vertex_cap;
    double* pos;       ///< vertex_count by 3, rest space
    sp_gen_rgb* color; ///< vertex_count
    sp_gen_skin* skin; ///< vertex_count
    int tri_count, tri_cap;
    uint32_t* tris; ///< tri_count by 3, counter-clockwise seen from outside
    /// While set, new vertices and triangles are decorations (spikes, teeth,
    /// claws): rendered and skinned like the rest but left out of the
    /// outline, which is what a person would draw (and what a closest-point
    /// fit can follow without snagging on every spike).
    bool decorating;
    unsigned char* deco_vertex; ///< vertex_count flags
    unsigned char* deco_tri;    ///< tri_count flags
} sp_gen_mesh;

/// Ends the program with a message when p is NULL (allocation failure).
void* sp_gen_check_alloc(void* p);
void sp_gen_mesh_free(sp_gen_mesh* m);
/// Appends a vertex; returns its index.
int sp_gen_mesh_vertex(sp_gen_mesh* m, sp_vec3 p, sp_gen_rgb c, const sp_gen_skin* s);
void sp_gen_mesh_tri(sp_gen_mesh* m, int a, int b, int c);
/// Appends a mirrored copy (z -> -z, winding flipped) of vertices
/// [first_vertex, end) and triangles [first_tri, end): the far wing or leg.
void sp_gen_mesh_mirror_z(sp_gen_mesh* m, int first_vertex, int first_tri);

// ---- skin weights --------------------------------------------------------

static inline sp_gen_skin sp_gen_skin_one(int joint)
{
    return (sp_gen_skin){1, {joint}, {1.0}};
}
/// Adds w to joint's weight (merging), dropping the weakest entry when full.
static inline void sp_gen_skin_add(sp_gen_skin* s, int joint, double w)
{
    sp_skin8_add(s, joint, w);
}
/// (1 - t) a + t b.
sp_gen_skin sp_gen_skin_lerp(const sp_gen_skin* a, const sp_gen_skin* b, double t);
/// The 4 strongest influences, renormalised to sum 1 (ties: lower joint
/// first, for determinism); unused slots are joint 0, weight 0.
static inline void sp_gen_skin_pack(const sp_gen_skin* s, uint16_t joints[4], float weights[4])
{
    sp_skin8_pack(s, joints, weights);
}

// ---- scalar helpers ------------------------------------------------------

static inline double sp_gen_clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}
/// Hermite smoothstep of x over [e0, e1] (0 below, 1 above).
static inline double sp_gen_smoothstep(double e0, double e1, double x)
{
    double t = sp_gen_clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}
static inline double sp_gen_lerp(double a, double b, double t)
{
    return a + (b - a) * t;
}
static inline sp_gen_rgb sp_gen_mix(sp_gen_rgb a, sp_gen_rgb b, double t)
{
    return (sp_gen_rgb){a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}
static inline sp_gen_rgb sp_gen_shade(sp_gen_rgb a, double f)
{
    return (sp_gen_rgb){a.r * f, a.g * f, a.b * f};
}
/// Smooth 1D interpolation through keys (u_i, v_i), u increasing (n >= 2):
/// cubic Hermite with Catmull-Rom slopes, constant beyond the ends.
double sp_gen_interp(const double (*keys)[2], int n, double u);
/// Deterministic hash of two integers to [0, 1) (scale speckle).
double sp_gen_hash2(uint32_t a, uint32_t b);
/// Smooth value noise in [0, 1) on a lattice of unit spacing (2D).
double sp_gen_noise2(double x, double y, uint32_t seed);

// ---- smooth curves -------------------------------------------------------

/// A densely sampled polyline with cumulative arc length, for centrelines.
typedef struct sp_gen_path {
    int n;
    sp_vec3* p;
    double* s; ///< cumulative arc length, s[0] = 0
    double length;
} sp_gen_path;

/// Centripetal Catmull-Rom through ctrl[0..n) (n >= 2), `per_span` samples
/// per span; the ends are extrapolated so the curve starts and ends at the
/// first and last control points.
void sp_gen_path_catmull(sp_gen_path* out, const sp_vec3* ctrl, int n, int per_span);
/// A path from explicit points (copied).
void sp_gen_path_points(sp_gen_path* out, const sp_vec3* pts, int n);
void sp_gen_path_free(sp_gen_path* p);
/// Point at arc length s (clamped to [0, length]); *tangent (may be NULL) is unit.
sp_vec3 sp_gen_path_at(const sp_gen_path* p, double s, sp_vec3* tangent);
/// Arc length of the path point nearest to q.
double sp_gen_path_project(const sp_gen_path* p, sp_vec3 q);
/// Quadratic Bezier point.
sp_vec3 sp_gen_bezier2(sp_vec3 a, sp_vec3 c, sp_vec3 b, double t);

// ---- skin along a bone chain ---------------------------------------------

enum { SP_GEN_CHAIN_MAX = 24 };
/// A bone chain along a path: joint k owns arc lengths [station_k,
/// station_k+1); across each interior station the weight passes to the next
/// joint by a smoothstep of half-width blend_k (clamped to half of either
/// neighbouring segment, so at most two joints blend at any point and the
/// weights are a partition of unity). A wide blend spreads a bend over the
/// tube, which is what keeps a 60-degree bend from collapsing.
typedef struct sp_gen_chain {
    int count;
    int joint[SP_GEN_CHAIN_MAX];
    double station[SP_GEN_CHAIN_MAX];
    double blend[SP_GEN_CHAIN_MAX];
} sp_gen_chain;

void sp_gen_chain_add(sp_gen_chain* c, int joint, double station, double blend);
/// Skin at arc length s.
sp_gen_skin sp_gen_chain_skin(const sp_gen_chain* c, double s);

// ---- swept tubes ---------------------------------------------------------

/// Half extents of a cross-section: above (along N), below, and sideways (along B).
typedef struct sp_gen_section {
    double up, down, side;
} sp_gen_section;

typedef sp_gen_section (*sp_gen_profile_fn)(double u, void* user);
/// Colour at tube parameter u in [0, 1] (caps: 0 or 1), section angle a, rest position p.
typedef sp_gen_rgb (*sp_gen_color_fn)(double u, double a, sp_vec3 p, void* user);
/// Optional radial factor (ridges, bulges) at (u, a).
typedef double (*sp_gen_bump_fn)(double u, double a, void* user);

typedef struct sp_gen_tube_desc {
    const sp_gen_path* path; ///< centreline
    double s0, s1;           ///< arc-length range (s1 == 0: the whole path)
    int rings;               ///< rings along [s0, s1], >= 2
    int segments;            ///< vertices per ring, >= 3
    sp_vec3 side;            ///< reference for the section's B axis (zero: +Z)
    sp_gen_profile_fn profile;
    sp_gen_color_fn color;
    sp_gen_bump_fn bump; ///< may be NULL
    void* user;
    const sp_gen_chain* chain; ///< skin by arc length; NULL: `skin` for every vertex
    sp_gen_skin skin;
    /// Optional skin at arc length s from the chain's (or the fixed) skin,
    /// e.g. to fade a parent in partially.
    sp_gen_skin (*skin_at)(double s, const sp_gen_skin* base, void* user);
    int cap0_rings, cap1_rings; ///< rounded caps (0: open end)
    double cap0_len, cap1_len;  ///< cap lengths as a factor of the end section's mean radius (1: a hemisphere)
    double z_offset;            ///< added to every z (after the sweep)
} sp_gen_tube_desc;

/// Sweeps a tube: rings of `segments` vertices with blended cross-sections,
/// rounded caps ending in a pole. Returns the index of its first vertex.
int sp_gen_tube(sp_gen_mesh* m, const sp_gen_tube_desc* d);

/// A cone along a quadratic Bezier from the base centre through `bend` to
/// the tip (horns curve, spikes do not: bend = midpoint), radius shrinking
/// from `base_radius` with exponent `taper` to a rounded tip of `tip_radius`,
/// flattened sideways by `flat` (1: round). Rigid to `skin`.
typedef struct sp_gen_cone_desc {
    sp_vec3 base, bend, tip;
    double base_radius, tip_radius, taper, flat;
    sp_vec3 side; ///< reference for flattening (zero: +Z)
    int rings, segments;
    sp_gen_rgb base_color, tip_color;
    sp_gen_skin skin;
} sp_gen_cone_desc;
int sp_gen_cone(sp_gen_mesh* m, const sp_gen_cone_desc* d);

/// An ellipsoid with semi-axes ax, ay, az (orthogonal, right-handed: ax x ay
/// along az, else it is inside out), tessellated with its poles at center
/// -+ ax, coloured by `color` (u from 0 at the -ax pole to 1 at the +ax pole,
/// a around the ax axis from ay towards az), rigid to `skin` (eyes, knobs).
typedef struct sp_gen_ellipsoid_desc {
    sp_vec3 center, ax, ay, az;
    int rings, segments;
    sp_gen_color_fn color;
    void* user;
    sp_gen_skin skin;
} sp_gen_ellipsoid_desc;
int sp_gen_ellipsoid(sp_gen_mesh* m, const sp_gen_ellipsoid_desc* d);

// ---- membranes -----------------------------------------------------------

/// A boundary curve for a membrane: a polyline with a skin per point,
/// parameterised by normalised arc length.
typedef struct sp_gen_curve {
    int n;
    sp_vec3* p;
    sp_gen_skin* skin;
    double* s; ///< normalised arc length, filled by sp_gen_curve_finish
} sp_gen_curve;

void sp_gen_curve_push(sp_gen_curve* c, sp_vec3 p, const sp_gen_skin* skin);
void sp_gen_curve_finish(sp_gen_curve* c);
void sp_gen_curve_free(sp_gen_curve* c);
/// Position and skin at normalised arc length t.
sp_vec3 sp_gen_curve_at(const sp_gen_curve* c, double t, sp_gen_skin* skin);

/// A thin two-sided membrane (bat/dragon wing skin): the Coons patch of
/// four boundary curves, inner (s = 0) and outer (s = 1) running in t, the
/// sides t = 0 and t = 1 running in s; corners must meet. Skin: the side
/// curves' skins blended across t. Two layers `thickness` apart along +-Z
/// joined along the rim.
typedef struct sp_gen_membrane_desc {
    const sp_gen_curve *inner, *outer, *side0, *side1;
    int ns, nt; ///< grid resolution (vertices per direction)
    double thickness;
    sp_gen_color_fn color; ///< u = s, a = t
    void* user;
    /// Optional skin at rest position p, given the default (`blend`: the
    /// side curves' skins blended across t); NULL keeps the default. A blend
    /// whose gradient runs across the bones (e.g. by the angle about a common
    /// pivot) cannot fold the membrane over.
    sp_gen_skin (*skin)(sp_vec3 p, const sp_gen_skin* blend, void* user);
} sp_gen_membrane_desc;
int sp_gen_membrane(sp_gen_mesh* m, const sp_gen_membrane_desc* d);

/// Applies z += y * k to vertices [first, end) (leans a flat wing outwards
/// without changing its side view).
void sp_gen_mesh_shear_z(sp_gen_mesh* m, int first_vertex, double k, double z_offset);

#endif
