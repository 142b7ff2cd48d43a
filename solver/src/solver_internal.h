// solver_internal.h: the solver's state, shared by its source files.
#ifndef SP_SOLVER_INTERNAL_H
#define SP_SOLVER_INTERNAL_H

#include "model.h"
#include "sp/curve.h"
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
    // Unit normal of the stroke at y for closest-point pairs, (0, 0) for
    // ordered ones: a closest pair weighs the residual across the stroke
    // fully and along it by its curve's tangential weight (see solver.c).
    sp_vec2 n;
    // Closest-point pairs: 0 when y was the stroke sample looking for the
    // curve, 1 when the curve sample looked for the stroke (the final error
    // then measures to the other side's polyline, see fill_errors).
    int dir;
} pair;

// Least-squares rows of the normal equations that share one column list: H
// gets U^T U of the stacked rows with one BLAS call (dsyrk) and one
// scattered add per entry, instead of one per row (segments and
// representatives on the same bones have the same columns; a black-box rig
// has one group of all parameters).
typedef struct row_group {
    const int* cols; // n sorted parameter indices
    int n;
    int cap, rows;   // rows reserved, rows filled since the last flush
    double* U;       // cap by n, row-major: least-squares rows, H += U^T U
} row_group;

struct sp_solver {
    sp_model* model; // the rig: LBS (analytic Jacobians) or black box (finite differences)
    const sp_abstraction* ab;
    const sp_camera* cam;
    sp_solve_desc d;
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
    double* z3;      // point_count * 3
    double* z2;      // point_count * 2
    double* Jz;      // 3D Jacobian blocks of the abstraction points, pool aligned with ab_cols: 3 values per column
    double* G;       // projected Jacobian blocks, pool aligned with ab_cols: 2 values per column
    double* x0;      // k * 3 representatives at the start pose
    double* xr;      // k * 3 representatives now
    double* Jr;      // pool aligned with rep_cols: 3 values per column
    double* dw;      // k: d_i / d_max
    sp_vec3* view;   // k: viewing direction at x0
    double* H;       // P * P
    double* Hl;      // P * P scratch: one block's local normal matrix
    double* g;       // P
    double* p0;      // P: the start pose (W_pose anchor)
    double* unit;    // P: parameter units
    bool* free_;     // P
    // Segments (a, the point after a): the group of the union of both
    // points' columns and where each point's columns sit in it.
    int* seg_grp;       // point_count: -1 for a curve's last point when open
    int* seg_map;       // positions: a's columns, then b's, from seg_first[a]
    int* seg_first;     // point_count
    int* seg_next;      // point_count: b
    int* seg_cols;      // the unions' column lists (groups point into it)
    double* seg_mom;    // point_count by 14: a segment's summed pairs (normal_equations; zero between calls)
    int* seg_pairs;     // point_count: pairs summed into it (zero between calls)
    int* seg_list;      // point_count: the segments touched
    double* rows;       // 4 * P: one segment's or representative's rows (normal_equations)
    double* step_work;  // the bounded step's scratch (sp__bounded_step_work)
    int* step_iwork;    // 3 (P + 1)
    bool* ab_used;      // point_count: a pair's sample lies on the point (jacobian_blocks)
    row_group* groups;
    int group_count;
    int* ab_grp;        // point_count: group of each abstraction point
    int* rep_grp;       // k: group of each representative
    double* group_pool; // U of every group
    // Correspondences.
    pair* pairs;
    // The resampled strokes of the last closest-point matching (polylines,
    // stroke index per sample), for the report's errors.
    sp_vec2* ypoly;
    int* ypoly_stroke;
    int ypoly_count, ypoly_cap;
    int ypoly_total;  // the sample count they were made for
    bool ypoly_valid; // made for this solve's strokes (solve_once clears it)
    int pair_count, pair_cap;
    double L;        // abstraction 2D diagonal at the start pose, pixels
    sp_correspondence mode; // how sp__build_pairs pairs samples now
    double pose_boost;      // >= 1: graduated W_pose weight, 1 in the final rounds
    int boost_from;         // parameters before it (the placement) keep W_pose unboosted
    double vertex_boost;    // >= 1: the same for W_plane and W_dist (draw-over only)
    int c2s[SP_REPORT_CURVES]; // the last stroke assignment (curve -> stroke)
    bool c2s_valid;
    bool used_loop;            // the last attempt matched an outline in order first
    bool placed_free;          // the last attempt placed the root without the boost (boost_from > 0)
    bool loop_forced;          // a loop's ordered pairs use loop_hypothesis instead of the best shift
    sp_ordered_info loop_hypothesis;
    bool keep_assignment;      // reuse c2s instead of assigning again
};

// Test hook: W at p and its Gauss-Newton g (half W's gradient) and H (H may
// be NULL) with the pairs for sk and the regularisers' reference made at
// p_ref, W_pose boosted by pose_boost on the parameters from boost_from on
// (the graduated rounds' weights; 1 and 0: the final ones).
sp_result sp__gauss_newton_at(sp_solver* s, const sp_sketch* sk, const double* p_ref, const double* p, double pose_boost, int boost_from,
                              double* W, double* g, double* H, sp_error* err);

// The bounded Levenberg-Marquardt step of solver.c (exposed for its test):
// (H_ff + mu diag(H_ff)) delta_f = -g_f over the free parameters (H: P x P,
// row-major, symmetric), parameters that would leave [min, max] held on the
// bound they cross and the rest solved again until the step stays inside.
// delta is zero outside the free set. False if the system cannot be solved
// or the step is zero.
// work: sp__bounded_step_work(P) doubles; iwork: 3 (P + 1) ints (the caller's).
bool sp__bounded_step(int P, const double* H, const double* g, const bool* free_, const sp_model_param* params, const double* p, double mu,
                      double* delta, double* work, int* iwork);
size_t sp__bounded_step_work(int P);

#endif
