// solver_internal.h: the solver's state and the calls its source files make
// to each other. The solve is split by concern:
//   setup.c   the solver's lifetime: coarsening, column lists, row groups, buffers
//   match.c   correspondences: resampling and pairing (ordered, closest points)
//   energy.c  W at p, its Gauss-Newton normal equations, the regularisers' reference
//   step.c    the damped step: the bounded Levenberg-Marquardt step and its tries
//   icp.c     the ICP loop: the plan of an attempt (a table of stages), the
//             stage runner, the attempts of sp_solver_solve
//   report.c  the report's 2D errors
#ifndef SP_SOLVER_INTERNAL_H
#define SP_SOLVER_INTERNAL_H

#include <string.h>

#include "model.h"
#include "sp/curve.h"
#include "sp/solver.h"

// The reference setup the paper's default weights are tuned for, in the
// spirit of its Maya scenes: an abstraction 500 pixels across matched with
// 200 sample pairs, a character 200 units across with 1000 vertices. Every
// solve measures its residuals in these units (see sp/solver.h).
#define SP_REF_PIXELS 500.0
#define SP_REF_PAIRS 200.0
#define SP_REF_SIZE 200.0
#define SP_REF_VERTICES 1000.0

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
    // fully and along it by its curve's tangential weight (see energy.c).
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

// Stroke assignment by topology applies to at most this many strokes and curves (match.c).
enum { SP_TOPO_MAX = 7 };

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
    bool ypoly_valid; // made for this solve's strokes (an attempt clears it)
    int pair_count, pair_cap;
    double L;                  // abstraction 2D diagonal at the start pose, pixels
    int c2s[SP_REPORT_CURVES]; // the last stroke assignment (curve -> stroke), for sp_pairing.keep_assignment
    // With it, when the topology made it: which way each open curve runs
    // along its stroke, where one end of each meets others (the stroke's
    // meeting end pairs with the curve's); -1: not told so.
    signed char topo_rev[SP_REPORT_CURVES];
    // The abstraction's junctions at the default pose (match.c,
    // sp__rest_junctions): bit 2 d + g of rest_meet[c][f] says curve c's end
    // f meets curve d's end g; for abstractions of 2 to 7 curves.
    uint16_t rest_meet[SP_TOPO_MAX][2];
    bool rest_meet_valid;
    bool c2s_valid;
    bool partial_topology; // this attempt assigns fewer strokes than curves by the junctions (icp.c's attempt)
    int one_stroke_curve;  // this attempt's curve for a single stroke (-1: by shape; icp.c's attempt)
    const double* caller_start; // the solve's start as the caller gave it (a copy; NULL: defaults), during sp_solver_solve
    // ordered_by_ends: each curve's direction and the stroke it was decided
    // with, at an attempt's first pairing, held after (an arm folding on its
    // way up had its ends' sums cross and was paired back); -1: not yet.
    int end_stroke[SP_REPORT_CURVES];
    bool end_rev[SP_REPORT_CURVES];
};

// A new solve or attempt pairs afresh: the kept assignment and the
// directions decided by the ends are forgotten together.
static inline void sp__forget_pairing(sp_solver* s)
{
    s->c2s_valid = false;
    for (int c = 0; c < SP_REPORT_CURVES; ++c)
        s->end_stroke[c] = -1;
}

// The energy's weights in one round (the graduated schedule of icp.c):
// W_pose of the parameters from boost_from on times pose_boost (>= 1), the
// parameters before it (a loop's root placement, placed free) at the
// configured weight, W_plane and W_dist times vertex_boost (>= 1).
// {1, 0, 1}: the configured weights.
typedef struct sp_weights {
    double pose_boost;
    int boost_from;
    double vertex_boost;
} sp_weights;

// How sp__build_pairs pairs samples.
typedef struct sp_pairing {
    sp_correspondence mode;
    bool keep_assignment;              // ordered: reuse the last stroke assignment (c2s) when there is one
    const sp_ordered_info* loop_shift; // ordered, one closed curve: hold this shift and direction (NULL: the best each time)
} sp_pairing;

// The model's calls (model.h), and the bounds (sp_param_clamp).
static inline void sp__model_update(sp_solver* s, const double* p, bool derivatives)
{
    s->model->ops->update(s->model, p, derivatives);
}
static inline void sp__model_rows(sp_solver* s, double* xyz)
{
    s->model->ops->rows(s->model, s->reps, s->k, xyz);
}
static inline void sp__model_clamp(const sp_solver* s, double* p)
{
    for (int i = 0; i < s->P; ++i) {
        const sp_model_param* q = &s->model->params[i];
        p[i] = sp_param_clamp(p[i], q->min, q->max, q->def);
    }
}
// The pose a solve starts from: p_start (NULL: the defaults) inside the bounds.
static inline void sp__start_pose(const sp_solver* s, const double* p_start, double* p)
{
    if (p_start)
        memcpy(p, p_start, sizeof(double) * (size_t)s->P);
    else
        for (int i = 0; i < s->P; ++i)
            p[i] = s->model->params[i].def;
    sp__model_clamp(s, p);
}

// The projected abstraction's box (s->z2): lo x, lo y, hi x, hi y.
static inline void sp__projected_box(const sp_solver* s, double box[4])
{
    box[0] = box[1] = INFINITY, box[2] = box[3] = -INFINITY;
    for (int i = 0; i < s->ab->point_count; ++i) {
        box[0] = fmin(box[0], s->z2[2 * i]), box[2] = fmax(box[2], s->z2[2 * i]);
        box[1] = fmin(box[1], s->z2[2 * i + 1]), box[3] = fmax(box[3], s->z2[2 * i + 1]);
    }
}

// A sample of the projected abstraction (s->z2).
static inline sp_vec2 sp__sample_at(const sp_solver* s, sample_ref r)
{
    const double* a = s->z2 + 2 * r.a;
    const double* b = s->z2 + 2 * r.b;
    return (sp_vec2){a[0] + r.t * (b[0] - a[0]), a[1] + r.t * (b[1] - a[1])};
}

// match.c: the abstraction's junctions at the default pose (rest_meet),
// evaluated with scratch (P doubles); leaves the model at the defaults.
void sp__rest_junctions(sp_solver* s, double* scratch);
// match.c: resamples the projected curves (s->z2) and the strokes and fills
// s->pairs; writes which stroke each curve got into rep->curves.
sp_result sp__build_pairs(sp_solver* s, const sp_sketch* sk, const sp_pairing* how, sp_solve_report* rep, sp_error* err);
// match.c: the best k shifts and directions of the one loop stroke against
// the one closed curve at the current projection
// (sp_corr_ordered_candidates over *m samples each).
int sp__loop_candidates(sp_solver* s, const sp_sketch* sk, sp_ordered_info* out, int k, int* m);

// energy.c: projects the abstraction at the model's state into s->z2.
void sp__project_abstraction(sp_solver* s);
// energy.c: W's terms at p with the current pairs (sets the model's state to p, projects).
sp_energy_terms sp__energy(sp_solver* s, const double* p, const sp_weights* w);
// energy.c: the rig linearised at p and W's normal equations there (s->H,
// s->g); `project` false when the last sp__energy call was at p.
void sp__linearise(sp_solver* s, const double* p, bool project, const sp_weights* w);
// energy.c: what depends on the start pose p: the representatives' start
// positions, viewing directions and distance weights to the matched curves.
void sp__prepare_start(sp_solver* s, const double* p, const sp_solve_report* rep);

// icp.c: bad strokes (none, NaN, one point, no length) refused with a message.
bool sp__sketch_ok(const sp_sketch* sk, sp_error* err);

// report.c: the report's 2D errors of the current pairs (made by `mode`).
void sp__fill_errors(sp_solver* s, sp_correspondence mode, sp_solve_report* rep);

// Test hook: W at p and its Gauss-Newton g (half W's gradient) and H (H may
// be NULL) with the pairs for sk and the regularisers' reference made at
// p_ref, W_pose boosted by pose_boost on the parameters from boost_from on
// (the graduated rounds' weights; 1 and 0: the final ones).
sp_result sp__gauss_newton_at(sp_solver* s, const sp_sketch* sk, const double* p_ref, const double* p, double pose_boost,
                              int boost_from, double* W, double* g, double* H, sp_error* err);

// The bounded Levenberg-Marquardt step of step.c (exposed for its test):
// (H_ff + mu diag(H_ff)) delta_f = -g_f over the free parameters (H: P x P,
// row-major, symmetric), parameters that would leave [min, max] held on the
// bound they cross and the rest solved again until the step stays inside.
// delta is zero outside the free set. False if the system cannot be solved
// or the step is zero.
// work: sp__bounded_step_work(P) doubles; iwork: 3 (P + 1) ints (the caller's).
bool sp__bounded_step(int P, const double* H, const double* g, const bool* free_, const sp_model_param* params, const double* p,
                      double mu, double* delta, double* work, int* iwork);
size_t sp__bounded_step_work(int P);

// step.c: one damped Gauss-Newton iteration (see there).
typedef enum sp_step_result {
    SP_STEP_TAKEN,     // a try lowered W
    SP_STEP_EXHAUSTED, // a try lowered W, by less than 1e-9 of it: this linearisation has no more to give
    SP_STEP_FAILED,    // no try lowered W although the linearisation promised more than 1e-9 of it (a stall)
    SP_STEP_NONE,      // no try lowered W, and the linearisation promised nothing (a stationary point)
} sp_step_result;
// The iterate a stage's rounds move, and the damping carried between iterations.
typedef struct sp_iterate {
    double* p;           // P: the pose, moved by an accepted try
    double* trial;       // P: scratch, a try's pose
    double* delta;       // P: scratch, a try's step
    sp_energy_terms cur; // W at p under the round's weights
    bool z_at_p;         // the abstraction was last projected at p
    double mu;           // the Levenberg-Marquardt damping
} sp_iterate;
sp_step_result sp__gauss_newton_iteration(sp_solver* s, sp_iterate* it, const bool* moves, const sp_weights* w);

#endif
