// model.h: the rig as the solver sees it. One interface, two
// implementations: linear blend skinning with analytic Jacobians
// (model_lbs.c) and black-box rigs with finite differences (blackbox.c).
// The solver's energy, regularisers, coarsening, bounds and report are the
// same for both; only these calls differ.
#ifndef SP_MODEL_H
#define SP_MODEL_H

#include <stdbool.h>

#include "sp/rig.h"
#include "sp/solver.h"

typedef struct sp_model sp_model;

// Sparse rows: a point's Jacobian touches only some parameters; `first`
// and `count` locate its column list in a pool of parameter indices, and
// its values (3 x count in 3D, 2 x count projected) in pools aligned with it.
typedef struct sparse_block {
    int first, count;
} sparse_block;

// A parameter as the solve needs it.
typedef struct sp_model_param {
    double min, max, def;
    bool length; // measured in reference lengths in W_pose (translations); else in its own unit
} sp_model_param;

typedef struct sp_model_ops {
    // Column list (sorted parameter indices) of the 3D Jacobian of mesh
    // vertex v (abstraction false) or abstraction point v (true): the
    // parameters that can move it. Writes at most 12 * P entries.
    int (*columns)(const sp_model* m, bool abstraction, int v, int* out);
    // Called once after the coarsening with the representatives' vertex
    // indices. On failure err says why (out of memory, a thread that cannot
    // start): the solver's creation fails with that result and text.
    sp_result (*prepare)(sp_model* m, const int* reps, int k, sp_error* err);
    // Sets the state to p (param_count values, inside the bounds). With
    // `derivatives`, the next jacobians() call is at p.
    void (*update)(sp_model* m, const double* p, bool derivatives);
    // World positions of the abstraction's points at the state (point_count by 3).
    void (*abstraction)(sp_model* m, double* z3);
    // World positions of mesh vertices rows[0..n) at the state (n by 3).
    void (*rows)(sp_model* m, const int* rows, int n, double* xyz);
    // 3D Jacobian blocks at the state of the last update with derivatives:
    // per abstraction point (Jz) and per representative (Jr) a 3 x count
    // row-major block over that point's column list, at 3 * first in the
    // pool. ab_used (point_count flags, NULL: all): only these points' blocks
    // are needed (others may be left as they are).
    void (*jacobians)(sp_model* m, const int* reps, int k, const sparse_block* ab_sb, const int* ab_cols, const bool* ab_used,
                      double* Jz, const sparse_block* rep_sb, const int* rep_cols, double* Jr);
    void (*destroy)(sp_model* m);
    // W_plane and W_dist in closed form, used when prepare sets closed_reg
    // (else the solver sums rows of the representatives' Jacobians, and these
    // may be NULL). With r_i the displacement of representative reps[i] from
    // the state at reg_prepare, v_i its viewing direction and d_i its
    // distance weight, reg_energy gives
    // sum_i (v_i . r_i)^2 and sum_i d_i |r_i|^2 at the state, and reg_normal
    // adds the Gauss-Newton H (upper triangle, P x P row-major) and g of
    // wp * W_plane + wd * W_dist at the last update with derivatives.
    void (*reg_prepare)(sp_model* m, const int* reps, int k, const sp_vec3* view, const double* d);
    void (*reg_energy)(sp_model* m, double* plane, double* dist);
    void (*reg_normal)(sp_model* m, double wp, double wd, double* H, double* g);
} sp_model_ops;

struct sp_model {
    const sp_model_ops* ops;
    int P;
    const sp_model_param* params; // P
    int vertex_count;
    const double* rest;       // vertex_count by 3: coarsening and the reference size
    const sp_abstraction* ab; // curves, correspondence, point_count (other fields by implementation)
    bool embedded;            // a draw-over curve embedded in the surface: local edits
    int placement_count;      // the first n parameters place the root (first solve stage); 0: no such stage
    bool closed_reg;          // prepare chose the reg_* calls for W_plane and W_dist (see sp_model_ops)
    bool failed;              // an evaluation failed (black-box rigs); `error` says why
    double deadline_ms;       // sp_now_ms() by which the solve must end (INFINITY: none)
    bool timed_out;           // the deadline passed inside a Jacobian (black-box rigs): no step from it
    sp_error error;
};

// The LBS model of abstraction `abstraction` of a finalized rig (which must
// outlive it). NULL when out of memory.
sp_model* sp__model_lbs_create(const sp_rig* rig, int abstraction);

// The solver on any model (takes it over, destroys it on failure; a NULL
// model is a failed allocation), as sp_solver_create.
sp_result sp__solver_create_model(sp_model* m, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out, sp_error* err);

#endif
