/// sp/rig.h: the rig model: skeleton, parameters, skinning, Jacobians, cameras.
///
/// How to use: an importer (partdb's glTF adapter, a generator, a test) fills
/// an `sp_rig` with malloc'd arrays and calls `sp_rig_finalize`, which checks
/// it and renormalises skin weights. An `sp_rig_eval` then evaluates the rig
/// at a parameter vector p (forward kinematics, linear blend skinning, paper
/// eq. 13) and gives the analytic Jacobians dx/dp for only the rows asked for.
///
///     sp_rig_eval* ev;
///     if (sp_rig_eval_create(&rig, &ev, &err) != SP_OK) ... err.text ...
///     sp_rig_eval_update(ev, p, true);                 // FK + derivative operators
///     sp_rig_eval_points(ev, sp_rig_mesh_points(&rig), xyz);   // n by 3
///     sp_rig_eval_jacobian(ev, pts, rows, nrows, J);   // (3*nrows) by P, row-major
///     sp_rig_eval_destroy(ev);
///
/// Conventions: column-major matrices, glTF quaternions (x, y, z, w), angles
/// in radians, world units as in the source file, pixels y-down.
///
/// The local transform of joint j at parameters p is
///     L_j(p) = T(rest_t + (tx, ty, tz)) * R(rest_r) * Rx(rx) * Ry(ry) * Rz(rz) * S(rest_s * (sx, sy, sz) * s)
/// where channels a joint does not declare hold their default (0 for offsets,
/// 1 for scale factors). Rotations are thus about the joint's own rest axes.
/// World transforms G_j = G_parent(j) * L_j and skin matrices G_j * IBM_j.
#ifndef SP_RIG_H
#define SP_RIG_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/math.h"
#include "sp/result.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { SP_NAME_MAX = 64, SP_INFLUENCES = 4 };

/// A rig parameter's channel on its joint.
typedef enum sp_channel {
    SP_CH_RX, SP_CH_RY, SP_CH_RZ, ///< rotation about the local rest axis, radians, default 0
    SP_CH_TX, SP_CH_TY, SP_CH_TZ, ///< translation offset in parent units, default 0
    SP_CH_SX, SP_CH_SY, SP_CH_SZ, ///< per-axis scale factor, > 0, default 1
    SP_CH_S,                      ///< uniform scale factor, > 0, default 1
    SP_CH_COUNT
} sp_channel;

typedef enum sp_group { SP_GROUP_POSE, SP_GROUP_SHAPE } sp_group;

/// "rx", "ty", "s", ...; NULL for an invalid channel.
const char* sp_channel_name(sp_channel c);
/// Parses "rx".."s"; returns SP_CH_COUNT when unknown.
sp_channel sp_channel_parse(const char* s);
static inline bool sp_channel_is_scale(sp_channel c) { return c >= SP_CH_SX && c <= SP_CH_S; }
static inline bool sp_channel_is_rotation(sp_channel c) { return c <= SP_CH_RZ; }

typedef struct sp_joint {
    char name[SP_NAME_MAX];
    int parent;          ///< index of the parent, -1 for a root; parents come before children
    sp_vec3 rest_t;      ///< rest translation (glTF node TRS)
    sp_quat rest_r;      ///< rest rotation, unit
    sp_vec3 rest_s;      ///< rest scale, each > 0
    sp_mat4 inverse_bind;///< identity for nodes that are ancestors but not skin joints
    int first_param;     ///< this joint's parameters are params[first_param .. +param_count)
    int param_count;
} sp_joint;

typedef struct sp_param {
    char name[2 * SP_NAME_MAX]; ///< "<joint>.<channel>"
    int joint;
    sp_channel channel;
    double min, max;  ///< bounds, min <= def <= max; scales: min > 0
    double def;       ///< default value (the rest pose): 0 for offsets, 1 for scales
    sp_group group;
} sp_param;

typedef enum sp_correspondence { SP_CORR_ORDERED, SP_CORR_CLOSEST } sp_correspondence;

/// One curve of an abstraction: a run of the abstraction's points.
typedef struct sp_curve {
    char name[SP_NAME_MAX];
    int first_point, point_count;
    bool closed; ///< LINE_LOOP
} sp_curve;

/// A sketch abstraction: curves whose points are skinned like the mesh
/// (rest/joints/weights set) or embedded in the mesh surface by barycentric
/// coordinates (tri_vertices/bary set, paper eq. 2), never both.
typedef struct sp_abstraction {
    char name[SP_NAME_MAX];
    sp_correspondence correspondence;
    int curve_count;
    sp_curve* curves;
    int point_count;
    double* rest;       ///< point_count by 3, bind space (like mesh vertices); NULL if embedded
    uint16_t* joints;   ///< point_count by 4, rig joint indices
    float* weights;     ///< point_count by 4, sum 1
    uint32_t* tri_vertices; ///< point_count by 3 mesh vertex indices, if embedded
    double* bary;           ///< point_count by 3 barycentric weights, if embedded
} sp_abstraction;

/// glTF-style keyframe channel on one joint.
typedef enum sp_anim_path { SP_ANIM_TRANSLATION, SP_ANIM_ROTATION, SP_ANIM_SCALE } sp_anim_path;
typedef enum sp_interp { SP_INTERP_LINEAR, SP_INTERP_STEP, SP_INTERP_CUBICSPLINE } sp_interp;
typedef struct sp_anim_channel {
    int joint;
    sp_anim_path path;
    sp_interp interp;
    int key_count;
    float* times;  ///< key_count, seconds, increasing
    float* values; ///< key_count by (3|4), times 3 (in-tangent, value, out-tangent) for CUBICSPLINE
} sp_anim_channel;
typedef struct sp_animation {
    char name[SP_NAME_MAX];
    double duration_s;
    int channel_count;
    sp_anim_channel* channels;
} sp_animation;

/// The rig: everything needed to evaluate x(p) and z(p). All arrays are
/// malloc'd and owned by the rig (sp_rig_free).
typedef struct sp_rig {
    int joint_count;
    sp_joint* joints;
    int param_count;
    sp_param* params;   ///< ordered by joint, contiguous per joint
    int vertex_count;
    double* rest;       ///< vertex_count by 3, bind space
    uint16_t* joints4;  ///< vertex_count by 4, rig joint indices
    float* weights4;    ///< vertex_count by 4
    int triangle_count;
    uint32_t* triangles;///< triangle_count by 3
    int abstraction_count;
    sp_abstraction* abstractions;
    int animation_count;
    sp_animation* animations;
} sp_rig;

/// A set of linearly skinned points (mesh vertices or abstraction points).
typedef struct sp_skinned_points {
    int count;
    const double* rest;     ///< count by 3
    const uint16_t* joints; ///< count by 4
    const float* weights;   ///< count by 4
} sp_skinned_points;

/// Checks the rig (parents before children, indices in range, finite
/// values, bounds ordered, scale bounds > 0, defaults inside bounds, parameter
/// names) and renormalises skin weights that do not sum to 1. Returns the
/// number of renormalised vertices and abstraction points in *renormalised
/// (may be NULL). `what` names the source in messages (a file path).
sp_result sp_rig_finalize(sp_rig* rig, const char* what, int* renormalised, sp_error* err);
/// Frees an abstraction's arrays and zeroes it.
void sp_abstraction_free(sp_abstraction* a);
/// Frees every array of the rig and zeroes it.
void sp_rig_free(sp_rig* rig);
/// Deep copy.
sp_result sp_rig_clone(const sp_rig* src, sp_rig* dst);
/// Appends a parameter to joint `joint`; must be called in joint order (or
/// use it before finalize, which sorts). Returns its index or -1 on error.
int sp_rig_add_param(sp_rig* rig, int joint, sp_channel ch, double min, double max, sp_group group);
/// Index of a joint by name, -1 if none.
int sp_rig_find_joint(const sp_rig* rig, const char* name);
/// Index of a parameter by "<joint>.<channel>", -1 if none.
int sp_rig_find_param(const sp_rig* rig, const char* name);
/// Index of an abstraction by name, -1 if none.
int sp_rig_find_abstraction(const sp_rig* rig, const char* name);
/// Writes every parameter's default into p (param_count).
void sp_rig_defaults(const sp_rig* rig, double* p);
/// Whether parameter k moves the whole character: a translation of the
/// first joint with parameters (the solver's placement joint; for a file
/// without sp_dofs, the placement the loader derives).
static inline bool sp_rig_param_shifts(const sp_rig* rig, int k)
{
    const sp_param* q = &rig->params[k];
    return q->joint == rig->params[0].joint && q->channel >= SP_CH_TX && q->channel <= SP_CH_TZ;
}
/// The one clamp of a parameter value, for every rig kind and the solve: a
/// value that is not finite becomes `def`, then it is put inside [min, max].
static inline double sp_param_clamp(double v, double min, double max, double def)
{
    if (!isfinite(v)) v = def;
    if (v < min) v = min;
    if (v > max) v = max;
    return v;
}
/// Clamps p (count values) into the bounds of `params` (sp_param_clamp);
/// returns how many entries changed. A black-box rig's parameters are
/// sp_param too (sp_blackbox_params).
int sp_params_clamp(const sp_param* params, int count, double* p);
/// sp_params_clamp over the rig's parameters.
int sp_rig_clamp(const sp_rig* rig, double* p);

static inline sp_skinned_points sp_rig_mesh_points(const sp_rig* rig)
{
    return (sp_skinned_points){rig->vertex_count, rig->rest, rig->joints4, rig->weights4};
}

/// Local TRS of one joint at parameters p (see the formula at the top).
void sp_rig_local_trs(const sp_rig* rig, int joint, const double* p, sp_vec3* t, sp_quat* r, sp_vec3* s);
/// Inverse of the parameterisation: the parameters of `joint` that best
/// reproduce a local TRS (rotation offset as XYZ Euler over the declared
/// rotation channels, translation offset, scale factors). Writes only that
/// joint's entries of p, clamped to bounds.
void sp_rig_params_from_trs(const sp_rig* rig, int joint, sp_vec3 t, sp_quat r, sp_vec3 s, double* p);

/// Samples an animation at time t (seconds, clamped to its range) into
/// per-joint local TRS arrays, which the caller pre-fills (e.g. with rest).
void sp_animation_sample(const sp_animation* anim, double t, sp_vec3* trans, sp_quat* rot, sp_vec3* scale);
/// The rig's first animation whose keys span more than a millisecond (a
/// clip that moves), its first and last key times in *start and *end; NULL
/// (start and end untouched) when it has none.
const sp_animation* sp_rig_first_clip(const sp_rig* rig, double* start, double* end);
/// Whether n key times can be an animation's: finite, at most FLT_MAX in
/// magnitude and increasing in single precision (glTF stores float times).
/// SP_ERR_INVALID (one line naming the key) when not.
sp_result sp_animation_check_times(const double* times, int n, sp_error* err);
/// A glTF-style animation that passes through key poses: keys is nkeys by
/// rig->param_count, times nkeys seconds (finite, increasing as floats, as the
/// channels store them). Every joint with
/// parameters gets LINEAR channels for the paths its parameters touch
/// (rotation, translation, scale), sampled from sp_rig_local_trs at each key.
sp_result sp_animation_from_keys(const sp_rig* rig, const double* keys, const double* times, int nkeys, const char* name,
                                 sp_animation* out, sp_error* err);

/// Evaluator: FK state and derivative operators for one rig.
typedef struct sp_rig_eval sp_rig_eval;
/// An evaluator at the rig's defaults (the rig must outlive it). Fails only
/// when out of memory; then *out is NULL.
sp_result sp_rig_eval_create(const sp_rig* rig, sp_rig_eval** out, sp_error* err);
void sp_rig_eval_destroy(sp_rig_eval* ev);
/// Forward kinematics at p (param_count values). With `derivatives`, also
/// the per-parameter operators D_k = dG_a/dp_k * G_a^-1 used by the Jacobians.
void sp_rig_eval_update(sp_rig_eval* ev, const double* p, bool derivatives);
/// World transforms G_j after the last update (joint_count).
const sp_mat4* sp_rig_eval_world(const sp_rig_eval* ev);
/// Skin matrices G_j * IBM_j after the last update (joint_count).
const sp_mat4* sp_rig_eval_skin(const sp_rig_eval* ev);
/// Derivative operators D_k after the last update with derivatives (param_count;
/// affine, rows 0..2 used): dG_j/dp_k = D_k * G_j for every joint j at or below
/// parameter k's joint.
const sp_mat4* sp_rig_eval_derivatives(const sp_rig_eval* ev);
/// Skins every point: out is pts.count by 3.
void sp_rig_eval_points(const sp_rig_eval* ev, sp_skinned_points pts, double* out);
/// Skins only rows[0..nrows): out is nrows by 3.
void sp_rig_eval_rows(const sp_rig_eval* ev, sp_skinned_points pts, const int* rows, int nrows, double* out);
/// Analytic Jacobian d x_row / d p for the requested rows (rows NULL means
/// 0..nrows-1): J is (3*nrows) by param_count, row-major, overwritten.
/// Requires an update with derivatives.
void sp_rig_eval_jacobian(const sp_rig_eval* ev, sp_skinned_points pts, const int* rows, int nrows, double* J);
/// Adds point i's Jacobian times `scale` into J (3 by param_count,
/// row-major) without clearing it: a caller that gathers a few columns per
/// point clears just those instead of all 3 * param_count entries.
void sp_rig_eval_jacobian_add(const sp_rig_eval* ev, sp_skinned_points pts, int i, double scale, double* J);
/// Abstraction points in world space (a->point_count by 3), skinned or
/// embedded. `mesh_xyz` (vertex_count by 3, current pose) is needed only for
/// embedded abstractions and may be NULL otherwise.
void sp_rig_eval_abstraction(const sp_rig_eval* ev, const sp_abstraction* a, const double* mesh_xyz, double* out);

/// Camera. The view matrix maps world to camera space, where the camera
/// looks down -Z with +Y up (glTF). Pixels: origin top-left, y down.
typedef enum sp_camera_kind { SP_CAMERA_ORTHOGRAPHIC, SP_CAMERA_PERSPECTIVE } sp_camera_kind;
typedef struct sp_camera {
    sp_camera_kind kind;
    sp_mat4 view;     ///< world -> camera
    double scale;     ///< orthographic: pixels per world unit; perspective: focal length in pixels
    double cx, cy;    ///< principal point, pixels
    int width, height;///< canvas, pixels
    double znear, zfar; ///< clip range for rendering, camera units, > 0
} sp_camera;

/// Projects a world point to pixels.
sp_vec2 sp_camera_project(const sp_camera* cam, sp_vec3 world);
/// 2x3 projection Jacobian at a world point, row-major (the paper's C for
/// orthographic cameras, where it does not depend on the point).
void sp_camera_jacobian(const sp_camera* cam, sp_vec3 world, double J[6]);
/// Unit viewing direction (camera towards the point) in world space.
sp_vec3 sp_camera_view_dir(const sp_camera* cam, sp_vec3 world);
/// A camera of the given kind looking along `forward` (world, e.g. -Z for a
/// front view) with `up`, framing the box [lo, hi] with a margin of 10%.
sp_camera sp_camera_frame(sp_camera_kind kind, sp_vec3 lo, sp_vec3 hi, sp_vec3 forward, sp_vec3 up, int width, int height);
/// The default sketch view of a character without a camera: orthographic,
/// y up, looking along -Z or -X, whichever sees the wider spread of the
/// points (xyz, n by 3, e.g. the rest-pose vertices), so that a figure
/// modelled facing +X is still seen from the front with its limbs apart.
sp_camera sp_camera_default_view(const double* xyz, int n, int width, int height);
/// The same view on a canvas of another size: the picture is scaled to fit
/// (aspect kept) and stays centred, so a figure framed on 640x480 keeps its
/// place on 1280x800.
sp_camera sp_camera_resize(const sp_camera* cam, int width, int height);
/// Axis-aligned bounds of n points (n by 3).
void sp_bounds(const double* xyz, int n, sp_vec3* lo, sp_vec3* hi);

#ifdef __cplusplus
}
#endif
#endif
