// solver_internal.h: the solver's state, shared by its source files.
#ifndef SP_SOLVER_INTERNAL_H
#define SP_SOLVER_INTERNAL_H

#include "sp/solver.h"

// A sample on a projected curve: (1 - t) * point a + t * point b.
typedef struct sample_ref {
    int a, b;
    double t;
} sample_ref;

// One correspondence: stroke sample y (pixels) to curve sample s.
typedef struct pair {
    sp_vec2 y;
    sample_ref s;
    int curve; // for the per-curve report
} pair;

// Sparse rows: a point's Jacobian touches only the parameters of its
// influences' ancestors; `cols` lists them (sorted), `block` holds the
// projected 2 x ncols values (row-major).
typedef struct sparse_block {
    int first, count; // into solver->cols / solver->blocks
} sparse_block;

struct sp_solver {
    const sp_rig* rig;
    const sp_abstraction* ab;
    const sp_camera* cam;
    sp_solve_desc d;
    sp_rig_eval* ev;
    int P;
    double D; // rest mesh bounding-box diagonal, world units
    // Coarsening.
    int k;
    int* reps;
    // Column lists: per abstraction point and per representative.
    int* ab_cols;        // pool
    sparse_block* ab_sb; // point_count
    int* rep_cols;       // pool
    sparse_block* rep_sb;// k
    // Buffers.
    double* mesh;    // vertex_count * 3 (only for embedded abstractions)
    double* z3;      // point_count * 3
    double* z2;      // point_count * 2
    double* G;       // projected Jacobian blocks, pool aligned with ab_cols: 2 values per column
    double* x0;      // k * 3 representatives at the start pose
    double* xr;      // k * 3 representatives now
    double* Jr;      // pool aligned with rep_cols: 3 values per column
    double* dw;      // k: d_i / d_max
    sp_vec3* view;   // k: viewing direction at x0
    double* scratch; // 3 * P * 3
    double* H;       // P * P
    double* g;       // P
    double* p0;      // P: the start pose (W_pose anchor)
    double* unit;    // P: parameter units
    bool* free_;     // P
    double* match_aa;   // point_count: summed match weights per point
    double* match_ab;   // point_count: coupling of the segment starting at each point
    double* match_beta; // point_count by 2: weighted residual per point
    // Correspondences.
    pair* pairs;
    int pair_count, pair_cap;
    double L;        // abstraction 2D diagonal at the start pose, pixels
    sp_correspondence mode; // how sp__build_pairs pairs samples now
    double pose_boost;      // >= 1: graduated W_pose weight, 1 in the final rounds
    double vertex_boost;
    int c2s[SP_REPORT_CURVES]; // the last stroke assignment (curve -> stroke)
    bool c2s_valid;
    bool keep_assignment;      // reuse c2s instead of assigning again    // >= 1: the same for W_plane and W_dist (draw-over only)
};

#endif
