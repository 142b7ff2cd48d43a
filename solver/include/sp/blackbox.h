/// sp/blackbox.h: rigs given only as an evaluation function ("black-box"
/// rigs, paper section 3): the C ABI such a rig implements (a plugin shared
/// object is loaded by sp/plugin.h, partdb/), and posing it with the same solver as
/// skinned rigs (energy, regularisers, coarsening, bounds, report), its
/// Jacobians estimated by central finite differences on a thread pool.
///
/// How to use (host side):
///
///     sp_blackbox* bb = NULL;
///     sp_error err = {0};
///     if (sp_blackbox_load_plugin("libsp_face.so", &bb, &err) != SP_OK) ... err.text ...
///     sp_camera cam = sp_blackbox_camera(bb, 640, 480);
///     sp_solver* s;
///     if (sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){0}, &s, &err) != SP_OK) ... err.text ...
///     sp_solver_solve(s, &sketch, NULL, p, &report, &err);
///     sp_solver_destroy(s);
///     sp_blackbox_destroy(bb);              // after every solver made from it
///
/// How to write a rig (plugin side; docs/blackbox.md has a full example):
/// fill an `sp_blackbox_rig` and return it from one exported function
///
///     const sp_blackbox_rig* sp_blackbox_plugin_v1(void);
///
/// (SP_BLACKBOX_ENTRY), which returns NULL on failure. Everything the
/// description points to stays valid and unchanged until the host calls its
/// `release`. A rig linked into the host is opened with sp_blackbox_open.
///
/// Versioning: `abi_version` and `struct_size` come first and are checked
/// before anything else is read, so a host refuses a rig built against
/// another layout with a one-line error instead of misreading it.
///
/// Threads: `evaluate` is called concurrently from several threads (the
/// finite differences of one Jacobian run on every core), always with the
/// same `user`, distinct output buffers and parameters inside the bounds. It
/// must not write to state shared between calls without its own locking.
#ifndef SP_BLACKBOX_H
#define SP_BLACKBOX_H

#include <stdint.h>

#include "sp/result.h"
#include "sp/rig.h"
#include "sp/sketch.h"
#include "sp/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The layout version of sp_blackbox_rig and the structs it points to.
#define SP_BLACKBOX_ABI_VERSION 1u
/// The one symbol a plugin exports (type sp_blackbox_entry_fn).
#define SP_BLACKBOX_ENTRY "sp_blackbox_plugin_v1"

/// How W_pose measures a change of a parameter (its unit u_k, see sp/solver.h).
typedef enum sp_blackbox_unit {
    SP_BB_UNIT_ANGLE = 0,  ///< radians
    SP_BB_UNIT_LENGTH = 1, ///< world units: measured in reference lengths (the mesh diagonal / 200)
    SP_BB_UNIT_FACTOR = 2, ///< a scale factor
    SP_BB_UNIT_WEIGHT = 3, ///< a blend weight, typically 0..1
} sp_blackbox_unit;

/// One rig parameter.
typedef struct sp_blackbox_param {
    const char* name; ///< unique, 1..127 bytes, e.g. "smile_l"
    double min, max;  ///< finite bounds, min <= max (min == max: the parameter is fixed)
    double def;       ///< the rest value, min <= def <= max
    int32_t group;    ///< SP_GROUP_POSE or SP_GROUP_SHAPE (synthetic targets vary them differently)
    int32_t unit;     ///< sp_blackbox_unit
} sp_blackbox_param;

/// One curve of an abstraction: point_count consecutive abstraction points.
typedef struct sp_blackbox_curve {
    const char* name;    ///< 1..63 bytes
    int32_t point_count; ///< >= 2
    int32_t closed;      ///< 1: a loop (the last point joins the first), 0: open
} sp_blackbox_curve;

/// A sketch abstraction: curves whose points the rig computes.
typedef struct sp_blackbox_abstraction {
    const char* name;                ///< 1..63 bytes, unique
    int32_t correspondence;          ///< SP_CORR_ORDERED or SP_CORR_CLOSEST (sp/rig.h)
    int32_t curve_count;             ///< 1..SP_REPORT_CURVES
    const sp_blackbox_curve* curves; ///< curve_count; their points follow each other
} sp_blackbox_abstraction;

/// Evaluates the rig at `params` (param_count values, inside the bounds):
/// writes every vertex (vertex_count by 3, world units, y up) and, when
/// `abstraction_xyz` is not NULL, every abstraction point (the points of
/// all abstractions in order, abstraction after abstraction, curve after
/// curve: sp_blackbox_total_points by 3). Returns 0 on success, anything
/// else on failure. Thread-safe as the top of this file says.
typedef int (*sp_blackbox_evaluate_fn)(void* user, const double* params, double* vertices_xyz, double* abstraction_xyz);

/// The description a rig gives the host. All counts are checked on open.
typedef struct sp_blackbox_rig {
    uint32_t abi_version; ///< SP_BLACKBOX_ABI_VERSION
    uint32_t struct_size; ///< sizeof(sp_blackbox_rig) where the rig was compiled
    const char* name;     ///< for messages, e.g. "face"
    int32_t param_count;  ///< >= 1
    const sp_blackbox_param* params;
    int32_t vertex_count;      ///< >= 1
    const double* rest;        ///< vertex_count by 3: evaluate() at the defaults (checked)
    int32_t triangle_count;    ///< >= 0, for rendering
    const uint32_t* triangles; ///< triangle_count by 3 vertex indices
    const float* colors;       ///< vertex_count by 4, linear RGBA base colour, or NULL (clay grey)
    int32_t abstraction_count; ///< >= 1
    const sp_blackbox_abstraction* abstractions;
    double view_forward[3]; ///< the sketch view looks along this world direction (orthographic); all 0: default view
    double view_up[3];      ///< its up direction (not parallel to view_forward); all 0: +Y
    void* user;             ///< passed to evaluate and release
    sp_blackbox_evaluate_fn evaluate;
    void (*release)(void* user); ///< frees the rig; called once by the host when done; may be NULL
} sp_blackbox_rig;

/// The plugin entry point's type.
typedef const sp_blackbox_rig* (*sp_blackbox_entry_fn)(void);

/// A validated black-box rig as the host holds it (opaque).
typedef struct sp_blackbox sp_blackbox;

/// Validates a description and wraps it: versions, counts, names, bounds,
/// indices; evaluate() must succeed at the defaults, give finite values and
/// reproduce `rest`. `what` names the rig in messages (a path). On success
/// the host owns the description (sp_blackbox_destroy calls its release). On
/// failure *out is NULL, and release is called if the version and struct
/// size matched (only then is the layout known), so a bad rig is still freed.
sp_result sp_blackbox_open(const sp_blackbox_rig* rig, const char* what, sp_blackbox** out, sp_error* err);
/// `fn(user)` is called by sp_blackbox_destroy after the rig's own release,
/// last: a plugin's loader unloads the code the rig lives in there.
void sp_blackbox_on_destroy(sp_blackbox* bb, void (*fn)(void* user), void* user);
/// Releases the rig, then calls what sp_blackbox_on_destroy gave. NULL is fine.
void sp_blackbox_destroy(sp_blackbox* bb);

/// The description (read-only; valid until sp_blackbox_destroy).
const sp_blackbox_rig* sp_blackbox_desc(const sp_blackbox* bb);
/// Points of abstraction a.
int sp_blackbox_abstraction_points(const sp_blackbox* bb, int a);
/// Points of all abstractions (the length of evaluate()'s abstraction_xyz / 3).
int sp_blackbox_total_points(const sp_blackbox* bb);
/// Index of abstraction a's first point in evaluate()'s abstraction_xyz.
int sp_blackbox_first_point(const sp_blackbox* bb, int a);
/// The abstraction as the solver's types see it (curves and correspondence;
/// no skinning data, the rig computes its points). All of them are one array:
/// abstraction a is sp_blackbox_abstraction_at(bb, 0) + a.
const sp_abstraction* sp_blackbox_abstraction_at(const sp_blackbox* bb, int a);
/// The parameters in the skinned rig's type (param_count; valid until
/// sp_blackbox_destroy): name, bounds, default and group as the rig declares
/// them, `joint` -1 and `channel` SP_CH_COUNT (a black box has neither).
/// sp_params_clamp clamps into their bounds; units are in sp_blackbox_desc.
const sp_param* sp_blackbox_params(const sp_blackbox* bb);
/// Writes the defaults (param_count values).
void sp_blackbox_defaults(const sp_blackbox* bb, double* p);
/// The sketch view on a width x height canvas: orthographic along
/// view_forward (or sp_camera_default_view), framing the rest mesh.
sp_camera sp_blackbox_camera(const sp_blackbox* bb, int width, int height);
/// Evaluates with checks: p is clamped into the bounds first, and a
/// non-zero return or a non-finite output is an error naming the rig.
/// vertices_xyz and abstraction_xyz as for evaluate (either may be NULL).
sp_result sp_blackbox_evaluate(const sp_blackbox* bb, const double* p, double* vertices_xyz, double* abstraction_xyz,
                               sp_error* err);

/// Finite-difference step of parameter k, the rule every Jacobian uses:
/// h_k = 1e-5 * (max_k - min_k) (0 for a fixed parameter). The derivative
/// at p is (f(b) - f(a)) / (b - a) over the stencil [a, b] = [p - h, p + h],
/// shifted to stay inside the bounds when p is within h of one (b - a = 2h
/// always), so the rig is never evaluated outside its bounds. Scaling by the
/// range makes the step meaningful for angles, lengths and weights alike;
/// 1e-5 of the range is near the optimum for central differences in double
/// precision (truncation ~h^2, rounding ~eps/h) for ranges of order 1.
double sp_blackbox_fd_step(const sp_blackbox* bb, int k);

/// A finite-difference Jacobian engine for fixed rows (mesh vertices) and
/// one abstraction, with its own pool of worker threads.
typedef struct sp_blackbox_fd sp_blackbox_fd;
/// threads: how many threads evaluate (the caller's included); 0: the
/// online cores, at most 8. rows (nrows vertex indices) are copied.
/// Fails (naming the rig) with SP_ERR_INVALID for an index out of range,
/// SP_ERR_NO_MEMORY when out of memory, SP_ERR_INTERNAL when a thread
/// cannot start; then *out is NULL.
sp_result sp_blackbox_fd_create(const sp_blackbox* bb, int abstraction, const int* rows, int nrows, int threads,
                                sp_blackbox_fd** out, sp_error* err);
/// NULL is fine.
void sp_blackbox_fd_destroy(sp_blackbox_fd* fd);
/// Threads the engine uses.
int sp_blackbox_fd_threads(const sp_blackbox_fd* fd);
/// Wall-clock time (sp_now_ms) after which sp_blackbox_fd_jacobian begins
/// no more columns and returns SP_ERR_TIMEOUT; INFINITY (the default): none.
/// A column already begun runs to its end.
void sp_blackbox_fd_set_deadline(sp_blackbox_fd* fd, double deadline_ms);
/// dx/dp at p for the rows (J_rows: (3 * nrows) by param_count, row-major)
/// and dz/dp for the abstraction's points (J_abs: (3 * points) by
/// param_count); either may be NULL. Each column is computed by one thread
/// from its own evaluations, so the result is bit-identical for any thread
/// count and timing. Fails (naming the parameter) if an evaluation fails, and
/// with SP_ERR_TIMEOUT when the deadline passes first.
sp_result sp_blackbox_fd_jacobian(sp_blackbox_fd* fd, const double* p, double* J_rows, double* J_abs, sp_error* err);

/// A solver for a black-box rig: the same energy, regularisers, coarsening,
/// bounds and report as sp_solver_create, with finite-difference Jacobians
/// on `desc->threads` threads (0: the online cores). bb and cam must
/// outlive the solver. There is no root-placement stage (the rig's
/// parameters have no skeleton). Fails as sp_solver_create (also when a
/// finite-difference thread cannot start); then *out is NULL.
/// A failing or NaN evaluation during a solve makes sp_solver_solve return
/// SP_ERR_INVALID with a message naming the rig.
sp_result sp_solver_create_blackbox(const sp_blackbox* bb, int abstraction, const sp_camera* cam, const sp_solve_desc* desc,
                                    sp_solver** out, sp_error* err);

/// A random parameter vector within bounds, the amplitude rule of
/// sp/synth.h: angles move at most `amplitude` radians from their default,
/// other pose parameters at most amplitude/pi of their half range, shape
/// parameters anywhere in their bounds. Deterministic for a seed.
void sp_blackbox_synth_params(const sp_blackbox* bb, uint64_t seed, double amplitude, double* p);
/// Abstraction a at p projected by cam, one stroke per curve (closed curves
/// repeat their first point), on the camera's canvas.
sp_result sp_blackbox_synth_sketch(const sp_blackbox* bb, int a, const sp_camera* cam, const double* p, sp_sketch* out,
                                   sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
