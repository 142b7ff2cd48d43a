// step.c: the damped step. One Gauss-Newton iteration linearises the rig at
// p and tries Levenberg-Marquardt steps, each inside the parameter bounds,
// until one lowers W; the damping is carried from iteration to iteration.
#include <cblas.h>
#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

#include "solver_internal.h"
#include "sp/clock.h"

// Solves (H_ff + mu diag) delta_f = -g_f over the free parameters, within
// the bounds: a parameter whose step would leave its box is put on the bound
// it crosses (its step fixed to reach it) and the rest is solved again, until
// the step stays inside. Clamping the unconstrained step instead changes its
// direction behind the quadratic model's back: near joint limits such steps
// raised W where the model promised a drop, the damping grew and convergence
// crawled.
// The passes share one Cholesky factor A = U'U of the free system: holding
// the set R at steps d_R is the equality-constrained problem
// min 1/2 x'Ax - b'x with x_R = d_R, solved by x = x0 - A^-1 E_R l with
// x0 = A^-1 b and (E_R' A^-1 E_R) l = x0_R - d_R (the Schur complement of
// its KKT system; the same x as solving the reduced system, to rounding).
// With V = U'^-1 E_R that matrix is V'V, so a pass costs one triangular
// solve for the newly held columns and one back substitution instead of a
// factorisation (BENCHMARKS.md has the figures).
// Returns false if the system could not be solved.
size_t sp__bounded_step_work(int P)
{
    return 3 * (size_t)P * (size_t)P + 5 * (size_t)P + 5;
}

bool sp__bounded_step(int P, const double* H, const double* g, const bool* free_, const sp_model_param* params, const double* p,
                      double mu, double* delta, double* work, int* iwork)
{
    const size_t PP = (size_t)P * (size_t)P;
    int* idx = iwork;         // the free parameters
    int* rpos = idx + P + 1;  // positions in idx of the held parameters, in the order they were held
    int* held = rpos + P + 1; // by position in idx
    double* A = work;
    memset(delta, 0, sizeof(double) * (size_t)P);
    int nf = 0;
    for (int q = 0; q < P; ++q)
        if (free_[q]) idx[nf++] = q;
    if (nf == 0) return false;
    double* V = A + PP;     // nf x nr, column-major: column j = U^-T e_rpos[j] (A = U'U)
    double* S = V + PP;     // nr x nr: V'V = E_R' A^-1 E_R, factored in place
    double* x0 = S + PP;    // A^-1 b
    double* x = x0 + P + 1; // the current pass's step
    double* dR = x + P + 1; // the held parameters' steps
    double* l = dR + P + 1; // multipliers, then V l
    for (int i = 0; i < nf; ++i) {
        const double* Hi = H + (size_t)idx[i] * (size_t)P;
        for (int j = 0; j < nf; ++j)
            A[i * nf + j] = Hi[idx[j]];
        // Marquardt scaling plus a floor so that flat directions stay solvable.
        A[i * nf + i] += mu * (Hi[idx[i]] + 1e-9);
        x0[i] = -g[idx[i]];
        held[i] = 0;
    }
    // A is symmetric: column-major saves LAPACKE's transposed copy. The _work
    // forms skip LAPACKE's NaN scans (the result is checked below).
    bool ok = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', nf, A, nf) == 0 &&
              LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'U', nf, 1, A, nf, x0, nf) == 0;
    memcpy(x, x0, sizeof(double) * (size_t)nf);
    int nr = 0;
    for (int pass = 0; ok && pass <= nf; ++pass) {
        const int nr0 = nr;
        for (int i = 0; i < nf; ++i) {
            if (!isfinite(x[i])) {
                ok = false;
                break;
            }
            if (held[i]) continue;
            const sp_model_param* pr = &params[idx[i]];
            double v = p[idx[i]] + x[i];
            if (v < pr->min || v > pr->max) {
                held[i] = 1;
                dR[nr] = (v < pr->min ? pr->min : pr->max) - p[idx[i]];
                rpos[nr++] = i;
            }
        }
        if (!ok || nr == nr0) break; // inside the box
        // The newly held columns, all in one triangular solve.
        double* Vn = V + (size_t)nr0 * (size_t)nf;
        memset(Vn, 0, sizeof(double) * (size_t)(nr - nr0) * (size_t)nf);
        for (int j = nr0; j < nr; ++j)
            V[(size_t)j * (size_t)nf + (size_t)rpos[j]] = 1.0;
        cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, nf, nr - nr0, 1.0, A, nf, Vn, nf);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, nr, nf, 1.0, V, nf, 0.0, S, nr);
        for (int a = 0; a < nr; ++a)
            l[a] = x0[rpos[a]] - dR[a];
        ok = LAPACKE_dposv_work(LAPACK_COL_MAJOR, 'U', nr, 1, S, nr, l, nr) == 0;
        if (!ok) break;
        // x = x0 - A^-1 E_R l = x0 - U^-1 (V l)
        cblas_dgemv(CblasColMajor, CblasNoTrans, nf, nr, 1.0, V, nf, l, 1, 0.0, l + nr, 1);
        cblas_dtrsv(CblasColMajor, CblasUpper, CblasNoTrans, CblasNonUnit, nf, A, nf, l + nr, 1);
        for (int i = 0; i < nf; ++i)
            x[i] = x0[i] - l[nr + i];
        for (int j = 0; j < nr; ++j)
            x[rpos[j]] = dR[j]; // exactly on the bound, not to rounding
    }
    bool any = false;
    for (int i = 0; ok && i < nf; ++i) {
        delta[idx[i]] = x[i];
        any |= x[i] != 0.0;
    }
    if (!ok) memset(delta, 0, sizeof(double) * (size_t)P);
    return ok && any;
}

static bool lm_step(sp_solver* s, const double* p, double mu, double* delta)
{
    return sp__bounded_step(s->P, s->H, s->g, s->free_, s->model->params, p, mu, delta, s->step_work, s->step_iwork);
}

// Active set: a parameter at a bound whose descent direction leaves the box
// is held for this step; `moves` (the stage's) holds the others that may not move.
static void choose_free(sp_solver* s, const double* p, const bool* moves)
{
    for (int q = 0; q < s->P; ++q) {
        const sp_model_param* pr = &s->model->params[q];
        bool f = moves[q];
        double eps = 1e-12 * (1.0 + fabs(pr->max - pr->min));
        if (p[q] <= pr->min + eps && s->g[q] > 0) f = false;
        if (p[q] >= pr->max - eps && s->g[q] < 0) f = false;
        if (pr->min == pr->max) f = false;
        s->free_[q] = f;
    }
}

// Whether the linearisation at p promises a decrease worth taking: the
// bounded step at the least damping the iteration uses lowers the
// Gauss-Newton model W + 2 g'd + d'Hd by more than 1e-9 of W (the gain below
// which an accepted step ends a linearisation). No step (a zero gradient on
// the free parameters) promises nothing.
static bool promises_decrease(sp_solver* s, const double* p, double W, double* delta)
{
    if (!lm_step(s, p, 1e-7, delta)) return false;
    const int P = s->P;
    double gd = 0, dHd = 0;
    for (int a = 0; a < P; ++a) {
        if (delta[a] == 0.0) continue;
        gd += s->g[a] * delta[a];
        const double* Ha = s->H + (size_t)a * (size_t)P;
        double row = 0;
        for (int b = 0; b < P; ++b)
            row += Ha[b] * delta[b];
        dHd += delta[a] * row;
    }
    return -(2 * gd + dHd) > 1e-9 * W;
}

// One Gauss-Newton iteration at it->p under the round's weights w, moving
// only the parameters `moves` allows: up to 12 Levenberg-Marquardt tries,
// the damping divided by 3 after a try that lowers W (at least 1e-7) and
// multiplied by 4 after one that does not (by 10 when the system cannot be
// solved), so that the next iteration starts from what worked.
sp_step_result sp__gauss_newton_iteration(sp_solver* s, sp_iterate* it, const bool* moves, const sp_weights* w)
{
    const int P = s->P;
    sp__linearise(s, it->p, !it->z_at_p, w);
    if (s->model->timed_out) return SP_STEP_NONE; // no Jacobian to step by
    choose_free(s, it->p, moves);
    for (int tries = 0; tries < 12; ++tries) {
        // Each try evaluates the rig: a slow black box would overrun the cap.
        if (tries > 0 && sp_now_ms() > s->model->deadline_ms) {
            s->model->timed_out = true;
            return SP_STEP_NONE;
        }
        if (!lm_step(s, it->p, it->mu, it->delta)) {
            it->mu *= 10;
            continue;
        }
        for (int q = 0; q < P; ++q)
            it->trial[q] = it->p[q] + it->delta[q];
        sp__model_clamp(s, it->trial);
        sp_energy_terms e = sp__energy(s, it->trial, w);
        if (e.total < it->cur.total) {
            double gain = (it->cur.total - e.total) / fmax(it->cur.total, 1e-300);
            memcpy(it->p, it->trial, sizeof(double) * (size_t)P);
            it->cur = e;
            it->z_at_p = true;
            it->mu = fmax(it->mu / 3, 1e-7);
            return gain < 1e-9 ? SP_STEP_EXHAUSTED : SP_STEP_TAKEN;
        }
        it->mu *= 4;
        it->z_at_p = false;
    }
    return promises_decrease(s, it->p, it->cur.total, it->delta) ? SP_STEP_FAILED : SP_STEP_NONE;
}
