/// sp/solver.h: sketch to pose: the regularized nonlinear ICP of the paper.
///
/// How to use:
///
///     sp_solver* s;
///     sp_solve_report rep;
///     sp_error err = {0};
///     if (sp_solver_create(&rig, abstraction_index, &camera, &(sp_solve_desc){0}, &s, &err) != SP_OK) ... err.text ...
///     if (sp_solver_solve(s, &sketch, p_start, p_out, &rep, &err) != SP_OK) ... err.text ...
///     sp_solver_destroy(s);
///
/// The energy (paper eq. 7, coarsened by eq. 12) is
///     W = W_match + l_pose W_pose + l_plane W_plane + l_dist W_dist
/// measured in the units of a fixed reference setup, so that the paper's
/// default weights transfer between characters of any size and canvases of
/// any resolution (a 2-unit character on 640x480 and a 200-unit one on
/// 3840x2160 give the same pose for the same drawing):
///   - 2D: pixels of a view in which the abstraction's bounding-box diagonal
///     (at the start pose) is 500 px, summed as over 200 correspondence
///     pairs: W_match = (200 / N) sum_i |(y_i - z_j) * 500 / L|^2.
///   - 3D: units of a character whose rest mesh diagonal is 200, summed as
///     over 1000 vertices: W_plane = (1000 / k) sum_reps (v . dx * 200 / D)^2
///     and W_dist = (1000 / k) sum_reps d_i / d_max |dx * 200 / D|^2, d_i the
///     3D distance from x_i0 to the nearest point of the matched curves.
///   - W_pose = sum_k ((p_k - p0_k) / u_k)^2: radians for angles, factors for
///     scales, reference units (D / 200) for translations.
/// The reference is the paper's setting (Maya scenes in centimetres, a
/// character a few hundred pixels tall). The fixed counts depart from the
/// paper on purpose: its n/k factor makes the k representatives stand in for
/// all n vertices, so its W_plane and W_dist grow with how finely a mesh is
/// made; here the balance is the same for any vertex or sample count.
///
/// The solve alternates correspondence updates (ICP rounds) with damped
/// Gauss-Newton steps (Levenberg-Marquardt) on the linearised rig. Bounds
/// are honoured exactly by a projected step with an active set: a parameter
/// at a bound whose gradient points outward is held fixed for the step, and
/// every iterate is clamped, so no returned value is ever out of bounds.
#ifndef SP_SOLVER_H
#define SP_SOLVER_H

#include <stdbool.h>

#include "sp/result.h"
#include "sp/rig.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { SP_REPORT_CURVES = 64 };

/// Options; zero means the default.
/// The paper's regulariser weights (eq. 7), for the energies in the
/// reference units above: the match term over the abstraction's own size.
#define SP_LAMBDA_POSE 0.5
#define SP_LAMBDA_PLANE 0.01
#define SP_LAMBDA_DIST 0.001

typedef struct sp_solve_desc {
    double lambda_pose;  ///< 0: SP_LAMBDA_POSE; < 0: term off
    double lambda_plane; ///< 0: SP_LAMBDA_PLANE; < 0: term off
    double lambda_dist;  ///< 0: SP_LAMBDA_DIST; < 0: term off
    int representatives; ///< k for the coarsening (eq. 12); 0: 200
    int samples;         ///< samples per curve after resampling; 0: by length, 16..160
    int max_iterations;  ///< Gauss-Newton iterations of each attempt (a loose fit gets more attempts); 0: 300
    int max_icp_rounds;  ///< correspondence updates; 0: 40
    double time_cap_ms;  ///< wall-clock cap; 0: 3000
    bool no_root_alignment; ///< skip the first stage that moves only the root's parameters
    const bool* active;  ///< param_count flags: which parameters may change; NULL: all
    int threads;         ///< black-box rigs (sp/blackbox.h): finite-difference threads; 0: the online cores (at most 8)
    /// Ordered pairing of an open curve and its stroke runs the way that puts
    /// their ends nearer (the sum of the two ends' distances), not the way of
    /// the least squared distance over all samples: for draw-over, where a
    /// curve is redrawn turned about one end. An arm redrawn raised 40
    /// degrees or more was paired reversed, the cheaper pairing of two lines
    /// meeting at the shoulder, and folded onto itself (an outside review).
    bool ordered_by_ends;
} sp_solve_desc;

/// Why a solve stopped: how the last stage of the attempt kept ended. A
/// stage runs rounds (new correspondences, then a few damped Gauss-Newton
/// iterations with them held; docs/DESIGN.md, "The solver's structure").
/// The reason says how the loop ended, not how good the fit is: read
/// mean_error_px and note for that (a stalled outline often fits well).
typedef enum sp_stop_reason {
    /// W settled: a round lowered it by less than 0.1% at the configured
    /// weights (1% in a stage that only places the root), or by less than
    /// 1e-6 of it at any weights with no failed step.
    SP_STOP_CONVERGED,
    SP_STOP_MAX_ITERATIONS, ///< the iteration or round cap was reached
    SP_STOP_TIME_CAP,       ///< the time cap was reached
    /// W stopped going down without settling, either (a) a round ended on a
    /// failed step, no Levenberg-Marquardt try (12, the damping raised after
    /// each) lowering W although the linearised rig promised a decrease of
    /// more than 1e-9 of W, and the round lowered W by less than 1e-6 of it
    /// (a rig whose Jacobian does not describe it, such as a black box
    /// with a jump); or (b) with correspondences made afresh every round
    /// (closest points) at the configured weights, two rounds in a row
    /// ended no lower than 0.1% below the lowest end of an earlier round,
    /// though each still lowered W against its own pairs by 0.1% or more:
    /// ICP cycling between pairings instead of settling.
    SP_STOP_STALLED,
} sp_stop_reason;

/// "converged", "max_iterations", "time_cap", "stalled" (the report's JSON words).
const char* sp_stop_reason_name(sp_stop_reason r);

typedef struct sp_energy_terms {
    double total, match, pose, plane, dist; ///< weighted terms sum to total
} sp_energy_terms;

typedef struct sp_curve_report {
    int curve;        ///< index in the abstraction
    int stroke;       ///< index of the matched stroke, -1 if none
    bool reversed;    ///< the stroke was drawn against the curve's direction
    double mean_px, max_px; ///< 2D error after the solve, pixels
} sp_curve_report;

typedef struct sp_solve_report {
    int iterations, icp_rounds;
    sp_stop_reason stopped;
    double ms;
    /// W at the start pose, with the attempt's start pairs (closest points
    /// when a placement stage comes first, else the abstraction's own), and
    /// at the result, with the abstraction's own pairs made there: their
    /// totals compare only when the two pairings are the same.
    sp_energy_terms before, after;
    double mean_error_px, max_error_px; ///< over all matched samples, both directions for closest
    double bbox_diagonal_px;            ///< L, the abstraction's 2D diagonal at the start pose
    int curve_count;                    ///< entries used in curves
    sp_curve_report curves[SP_REPORT_CURVES];
    int unused_strokes;                 ///< strokes left without a curve (more strokes than curves)
    char note[512];                     ///< why a best-effort result is only that, or empty (a few lines at most)
} sp_solve_report;

typedef struct sp_solver sp_solver;

/// Prepares a solver for one rig, abstraction and view: the coarsening
/// (k-means of the rest vertices with FLANN, cluster centres snapped to the
/// nearest vertex) and buffers. The rig and camera must outlive the solver.
/// Fails with SP_ERR_INVALID for an abstraction index out of range, with
/// SP_ERR_NO_MEMORY when out of memory; then *out is NULL.
sp_result sp_solver_create(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out,
                           sp_error* err);
/// NULL is fine.
void sp_solver_destroy(sp_solver* s);
/// Representative vertex indices chosen by the coarsening (*count of them).
const int* sp_solver_representatives(const sp_solver* s, int* count);

/// Fits the rig to the strokes from p_start (param_count, NULL: defaults);
/// writes the result into p_out (may alias p_start: then the attempts after
/// the first, when it ends above 1%, start from the best fit so far rather
/// than from p_start, which is what the kiosk and `pose` do). Bad strokes (NaN,
/// empty, one point) are refused with SP_ERR_INVALID; a target that cannot
/// be reached gives SP_OK with a best-effort pose and a note in the report.
sp_result sp_solver_solve(sp_solver* s, const sp_sketch* strokes, const double* p_start, double* p_out, sp_solve_report* rep,
                          sp_error* err);

/// The abstraction's curves projected at parameters p: xy is point_count by 2,
/// pixels (the caller sizes it with the abstraction's point_count).
void sp_solver_project_abstraction(sp_solver* s, const double* p, double* xy);

#ifdef __cplusplus
}
#endif
#endif
