// energy.c: the energy W of a pose (paper eq. 7, coarsened by eq. 12, in the
// reference units of sp/solver.h) with the current correspondences, and its
// Gauss-Newton normal equations (eq. 6 and 11) on the linearised rig.
#include <assert.h>
#include <cblas.h>
#include <stdlib.h>
#include <string.h>

#include "solver_internal.h"

// W_plane and W_dist are computed in closed form by the model (LBS rigs
// where that is cheaper), or from the representatives' rows.
static inline bool closed_form_reg(const sp_solver* s)
{
    return s->model->closed_reg;
}
static inline bool has_reg(const sp_solver* s)
{
    return s->k > 0 && (s->d.lambda_plane > 0 || s->d.lambda_dist > 0);
}

// Projects the abstraction at the current rig state into s->z2.
void sp__project_abstraction(sp_solver* s)
{
    s->model->ops->abstraction(s->model, s->z3);
    for (int i = 0; i < s->ab->point_count; ++i) {
        sp_vec2 q = sp_camera_project(s->cam, (sp_vec3){s->z3[3 * i], s->z3[3 * i + 1], s->z3[3 * i + 2]});
        s->z2[2 * i] = q.x, s->z2[2 * i + 1] = q.y;
    }
}

void sp_solver_project_abstraction(sp_solver* s, const double* p, double* xy)
{
    sp__model_update(s, p, false);
    sp__project_abstraction(s);
    memcpy(xy, s->z2, sizeof(double) * 2 * (size_t)s->ab->point_count);
}

// Closest-point pairs measure the residual mostly across the stroke
// (point-to-line, as in Chen and Medioni's ICP): a curve may then slide along
// the stroke within a round instead of being dragged to the sample that was
// closest at the round's start, which is what makes point-to-point ICP crawl.
// The small tangential weight keeps the energy positive definite on straight
// strokes (0 would leave the per-point metric singular there). Closed curves
// may slide more (0.01: fewer iterations, a closer fit); open curves keep
// 0.1, because their ends must not slide off the stroke's ends (BENCHMARKS.md,
// "Measurements behind the solver's constants").
#define SP_TANGENT_WEIGHT_OPEN 0.1
#define SP_TANGENT_WEIGHT_CLOSED 0.01

// The pair's symmetric 2x2 metric (xx, xy, yy): identity for ordered pairs,
// n n^T + w (I - n n^T) for closest ones, w the tangential weight of its curve.
static void pair_metric(const sp_solver* s, const pair* pr, double m[3])
{
    if (pr->n.x == 0.0 && pr->n.y == 0.0) {
        m[0] = 1, m[1] = 0, m[2] = 1;
        return;
    }
    const bool closed = pr->curve >= 0 && pr->curve < s->ab->curve_count && s->ab->curves[pr->curve].closed;
    const double t = closed ? SP_TANGENT_WEIGHT_CLOSED : SP_TANGENT_WEIGHT_OPEN, nx = pr->n.x, ny = pr->n.y;
    m[0] = t + (1 - t) * nx * nx;
    m[1] = (1 - t) * nx * ny;
    m[2] = t + (1 - t) * ny * ny;
}

static double match_weight(const sp_solver* s)
{
    double r = SP_REF_PIXELS / s->L;
    return SP_REF_PAIRS * r * r / (double)(s->pair_count > 0 ? s->pair_count : 1);
}

// Weight of one representative's squared displacement (before lambda):
// reference units, summed as over SP_REF_VERTICES vertices.
static double vertex_weight(const sp_solver* s)
{
    double r = SP_REF_SIZE / s->D;
    return SP_REF_VERTICES * r * r / (double)(s->k > 0 ? s->k : 1);
}

sp_energy_terms sp__energy(sp_solver* s, const double* p, const sp_weights* w)
{
    sp_energy_terms e = {0};
    sp__model_update(s, p, false);
    sp__project_abstraction(s);
    double wm = match_weight(s);
    for (int i = 0; i < s->pair_count; ++i) {
        sp_vec2 d = sp_v2_sub(sp__sample_at(s, s->pairs[i].s), s->pairs[i].y);
        double m[3];
        pair_metric(s, &s->pairs[i], m);
        e.match += wm * (m[0] * d.x * d.x + 2 * m[1] * d.x * d.y + m[2] * d.y * d.y);
    }
    double placement = 0; // W_pose of the parameters the boost leaves alone
    for (int i = 0; i < s->P; ++i) {
        double u = (p[i] - s->p0[i]) / s->unit[i];
        if (i < w->boost_from)
            placement += u * u;
        else
            e.pose += u * u;
    }
    if (has_reg(s) && closed_form_reg(s)) {
        double ep, ed;
        s->model->ops->reg_energy(s->model, &ep, &ed);
        e.plane = vertex_weight(s) * ep;
        e.dist = vertex_weight(s) * ed;
    } else if (has_reg(s)) {
        sp__model_rows(s, s->xr);
        double inv = vertex_weight(s);
        for (int i = 0; i < s->k; ++i) {
            sp_vec3 dx = {s->xr[3 * i] - s->x0[3 * i], s->xr[3 * i + 1] - s->x0[3 * i + 1], s->xr[3 * i + 2] - s->x0[3 * i + 2]};
            double vp = sp_v3_dot(s->view[i], dx);
            e.plane += inv * vp * vp;
            e.dist += inv * s->dw[i] * sp_v3_dot(dx, dx);
        }
    }
    e.pose = e.pose * (s->d.lambda_pose * w->pose_boost) + placement * s->d.lambda_pose;
    e.plane *= s->d.lambda_plane * w->vertex_boost;
    e.dist *= s->d.lambda_dist * w->vertex_boost;
    e.total = e.match + e.pose + e.plane + e.dist;
    // A black-box rig that failed to evaluate here makes this state unusable.
    if (s->model->failed) e.total = INFINITY;
    return e;
}

// ---------------------------------------------------------------- normal equations

// Fills the projected Jacobian blocks of every abstraction point (s->G) and
// the 3D blocks of the representatives (s->Jr) at the current rig state.
// Only points that a pair's sample lies on are needed: an outline of many
// points resampled to fewer samples leaves some untouched (the cartoon man's
// 353 against 160 samples).
static void jacobian_blocks(sp_solver* s)
{
    bool* used = s->ab_used;
    memset(used, 0, sizeof(bool) * (size_t)s->ab->point_count);
    for (int i = 0; i < s->pair_count; ++i)
        used[s->pairs[i].s.a] = used[s->pairs[i].s.b] = true;
    s->model->ops->jacobians(s->model, s->reps, closed_form_reg(s) ? 0 : s->k, s->ab_sb, s->ab_cols, used, s->Jz, s->rep_sb,
                             s->rep_cols, s->Jr);
    for (int i = 0; i < s->ab->point_count; ++i) {
        const sparse_block* sb = &s->ab_sb[i];
        if (!used[i]) continue;
        double C[6];
        sp_camera_jacobian(s->cam, (sp_vec3){s->z3[3 * i], s->z3[3 * i + 1], s->z3[3 * i + 2]}, C);
        const double* Jb = s->Jz + 3 * (size_t)sb->first;
        double* Gb = s->G + 2 * (size_t)sb->first;
        for (int c = 0; c < sb->count; ++c) {
            double jx = Jb[c], jy = Jb[sb->count + c], jz = Jb[2 * sb->count + c];
            Gb[c] = C[0] * jx + C[1] * jy + C[2] * jz;
            Gb[sb->count + c] = C[3] * jx + C[4] * jy + C[5] * jz;
        }
    }
}

// H += U^T U of group g's rows so far, into the upper triangle (columns are
// sorted, so the local upper triangle lands in the global one).
static void flush_group(sp_solver* s, int g)
{
    row_group* gr = &s->groups[g];
    const int n = gr->n, P = s->P;
    if (gr->rows == 0 || n == 0) return;
    cblas_dsyrk(CblasRowMajor, CblasUpper, CblasTrans, n, gr->rows, 1.0, gr->U, n, 0.0, s->Hl, n);
    for (int a = 0; a < n; ++a) {
        double* Hrow = s->H + (size_t)gr->cols[a] * (size_t)P;
        const double* L = s->Hl + (size_t)a * (size_t)n;
        for (int b = a; b < n; ++b)
            Hrow[gr->cols[b]] += L[b];
    }
    gr->rows = 0;
}

static void flush_groups(sp_solver* s)
{
    for (int g = 0; g < s->group_count; ++g)
        flush_group(s, g);
}

// Least-squares rows B (rows x n over group g's columns, residuals r):
// g += B^T r now, H += B^T B when the group is flushed (make_groups reserved
// what one build pushes).
static void push_rows(sp_solver* s, int g, const double* B, int rows, const double* r)
{
    row_group* gr = &s->groups[g];
    const int n = gr->n;
    for (int k = 0; k < rows; ++k) {
        const double* Bk = B + (size_t)k * (size_t)n;
        for (int a = 0; a < n; ++a)
            s->g[gr->cols[a]] += Bk[a] * r[k];
    }
    assert(gr->rows + rows <= gr->cap);
    memcpy(gr->U + (size_t)gr->rows * (size_t)n, B, sizeof(double) * (size_t)rows * (size_t)n);
    gr->rows += rows;
}

// The match term's moments: a pair's sample is (1-t) z_a + t z_b on the
// segment (a, b), its residual d = sample - y weighted by wm m (pair_metric),
// so its Gauss-Newton terms are J^T wm m J and J^T wm m d with
// J = (1-t) G_a + t G_b. Summed over a segment's pairs they are G^T S G and
// G^T beta with G = [G_a; G_b] (4 rows: a's x and y, b's x and y),
// S = sum [(1-t) I; t I] wm m [(1-t) I, t I] (4 x 4) and
// beta = sum [(1-t) I; t I] wm m d. Sums them per segment (s->seg_mom, at a)
// and lists the segments touched (s->seg_list); returns how many.
static int match_moments(sp_solver* s)
{
    const double wm = match_weight(s);
    double* mom = s->seg_mom; // 14 per segment: S's upper triangle (10), beta (4); zero between calls
    int nseg = 0;
    for (int i = 0; i < s->pair_count; ++i) {
        const pair* pr = &s->pairs[i];
        sp_vec2 d = sp_v2_sub(sp__sample_at(s, pr->s), pr->y);
        double m[3];
        pair_metric(s, pr, m);
        const int a = pr->s.a;
        double ta = 1.0 - pr->s.t, tb = pr->s.t;
        if (pr->s.b == a || s->seg_grp[a] < 0) ta += tb, tb = 0;     // on a point: its own columns only
        const double c[4][2] = {{ta, 0}, {0, ta}, {tb, 0}, {0, tb}}; // [(1-t) I; t I]
        const double M[2][2] = {{wm * m[0], wm * m[1]}, {wm * m[1], wm * m[2]}};
        const double Md[2] = {M[0][0] * d.x + M[0][1] * d.y, M[1][0] * d.x + M[1][1] * d.y};
        double* S = mom + 14 * (size_t)a;
        if (s->seg_pairs[a]++ == 0) s->seg_list[nseg++] = a;
        for (int r = 0, e = 0; r < 4; ++r) {
            double cm[2] = {c[r][0] * M[0][0] + c[r][1] * M[1][0], c[r][0] * M[0][1] + c[r][1] * M[1][1]};
            for (int q = r; q < 4; ++q)
                S[e++] += cm[0] * c[q][0] + cm[1] * c[q][1];
            S[10 + r] += c[r][0] * Md[0] + c[r][1] * Md[1];
        }
    }
    return nseg;
}

// Each touched segment's moments as least-squares rows: with S = L L^T the
// segment is at most four rows L^T G over the union of a's and b's columns
// with residuals L^-1 beta (a pivot that is zero, as when all of a
// segment's pairs share one t, drops its row: S is positive semidefinite,
// beta in its range), pushed to the segment's group. So a segment costs at
// most four rows however many pairs it has, and two with one pair. Zeroes
// the moments it read.
static void segment_rows(sp_solver* s, int nseg)
{
    double* rows = s->rows;
    for (int k = 0; k < nseg; ++k) {
        const int a = s->seg_list[k];
        double* S = s->seg_mom + 14 * (size_t)a;
        const bool seg = s->seg_grp[a] >= 0;
        double L[4][4] = {{0}}, r[4];
        bool live[4];
        for (int j = 0, e = 0; j < 4; ++j) // unpack the upper triangle into L's lower one
            for (int q = j; q < 4; ++q)
                L[q][j] = S[e++];
        for (int j = 0; j < 4; ++j) {
            double piv = L[j][j];
            for (int i = 0; i < j; ++i)
                if (live[i]) piv -= L[j][i] * L[j][i];
            live[j] = piv > 1e-12 * L[j][j] && piv > 0;
            if (!live[j]) continue;
            double ljj = sqrt(piv);
            for (int q = j + 1; q < 4; ++q) {
                double v = L[q][j];
                for (int i = 0; i < j; ++i)
                    if (live[i]) v -= L[q][i] * L[j][i];
                L[q][j] = v / ljj;
            }
            L[j][j] = ljj;
            double v = S[10 + j];
            for (int i = 0; i < j; ++i)
                if (live[i]) v -= L[j][i] * r[i];
            r[j] = v / ljj;
        }
        const int g = seg ? s->seg_grp[a] : s->ab_grp[a], n = s->groups[g].n;
        const sparse_block* A = &s->ab_sb[a];
        const double* Ga = s->G + 2 * (size_t)A->first;
        const int* map = seg ? s->seg_map + s->seg_first[a] : NULL; // a's columns, then b's; NULL: a's own
        int nr = 0;
        double rr[4];
        for (int j = 0; j < 4; ++j) {
            if (!live[j]) continue;
            double* row = rows + (size_t)nr * (size_t)n;
            memset(row, 0, sizeof(double) * (size_t)n);
            // Row j = column j of L against G's four rows (L's entries above
            // its diagonal are the zeros it was made with).
            const double ax = L[0][j], ay = L[1][j], bx = L[2][j], by = L[3][j];
            for (int c = 0; c < A->count; ++c)
                row[map ? map[c] : c] += ax * Ga[c] + ay * Ga[A->count + c];
            if (seg && (bx != 0 || by != 0)) {
                const int bpt = s->seg_next[a];
                const sparse_block* Bb = &s->ab_sb[bpt];
                const double* Gb = s->G + 2 * (size_t)Bb->first;
                const int* mb = map + A->count;
                for (int c = 0; c < Bb->count; ++c)
                    row[mb[c]] += bx * Gb[c] + by * Gb[Bb->count + c];
            }
            rr[nr++] = r[j];
        }
        if (nr) push_rows(s, g, rows, nr, rr);
        memset(S, 0, sizeof(double) * 14);
        s->seg_pairs[a] = 0;
    }
}

// W_plane and W_dist's Gauss-Newton terms: from the model in closed form,
// or as rows of the representatives' Jacobians.
static void regulariser_rows(sp_solver* s, const sp_weights* w)
{
    const double inv = vertex_weight(s) * w->vertex_boost;
    if (closed_form_reg(s)) {
        s->model->ops->reg_normal(s->model, s->d.lambda_plane * inv, s->d.lambda_dist * inv, s->H, s->g);
        return;
    }
    double* B = s->rows;
    for (int i = 0; i < s->k; ++i) {
        const sparse_block* sb = &s->rep_sb[i];
        const double* Jb = s->Jr + 3 * (size_t)sb->first;
        double dx[3] = {s->xr[3 * i] - s->x0[3 * i], s->xr[3 * i + 1] - s->x0[3 * i + 1], s->xr[3 * i + 2] - s->x0[3 * i + 2]};
        // W_plane and W_dist of this representative as four rows of one
        // least-squares block, each scaled by the square root of its weight.
        int n = sb->count, rows = 0;
        double r4[4];
        double wp = s->d.lambda_plane * inv, wd = s->d.lambda_dist * inv * s->dw[i];
        if (wp > 0) {
            sp_vec3 v = s->view[i];
            double sw = sqrt(wp);
            for (int c = 0; c < n; ++c)
                B[c] = sw * (v.x * Jb[c] + v.y * Jb[n + c] + v.z * Jb[2 * n + c]);
            r4[rows++] = sw * (v.x * dx[0] + v.y * dx[1] + v.z * dx[2]);
        }
        if (wd > 0) {
            double sw = sqrt(wd);
            for (int d = 0; d < 3; ++d) {
                for (int c = 0; c < n; ++c)
                    B[rows * n + c] = sw * Jb[d * n + c];
                r4[rows++] = sw * dx[d];
            }
        }
        if (rows) push_rows(s, s->rep_grp[i], B, rows, r4);
    }
}

// Gauss-Newton normal equations of W at the current state (upper triangle
// of H filled, then mirrored). Requires an update with derivatives. Rows
// are collected per column set and added to H by one symmetric rank-k
// update per set (flush_groups).
static void normal_equations(sp_solver* s, const double* p, const sp_weights* w)
{
    const int P = s->P;
    memset(s->H, 0, sizeof(double) * (size_t)P * (size_t)P);
    memset(s->g, 0, sizeof(double) * (size_t)P);
    jacobian_blocks(s);
    segment_rows(s, match_moments(s));
    if (has_reg(s)) regulariser_rows(s, w);
    flush_groups(s);
    const double lambda = s->d.lambda_pose, boost = w->pose_boost;
    const int from = w->boost_from;
    double *H = s->H, *g = s->g;
    for (int q = 0; q < P; ++q) {
        double wq = lambda * (q < from ? 1.0 : boost) / (s->unit[q] * s->unit[q]);
        H[q * P + q] += wq;
        g[q] += wq * (p[q] - s->p0[q]);
    }
    for (int a = 0; a < P; ++a)
        for (int b = a + 1; b < P; ++b)
            s->H[b * P + a] = s->H[a * P + b];
}

void sp__linearise(sp_solver* s, const double* p, bool project, const sp_weights* w)
{
    sp__model_update(s, p, true);
    if (project) sp__project_abstraction(s);
    if (s->k > 0 && !closed_form_reg(s)) sp__model_rows(s, s->xr);
    normal_equations(s, p, w);
}

// Precomputes what depends on the start pose: x0 and viewing directions of
// the representatives, and d_i / d_max from the curves that got a stroke.
void sp__prepare_start(sp_solver* s, const double* p, const sp_solve_report* rep)
{
    sp__model_update(s, p, false);
    sp__model_rows(s, s->x0);
    sp__project_abstraction(s);
    double dmax = 0;
    for (int i = 0; i < s->k; ++i) {
        sp_vec3 x = {s->x0[3 * i], s->x0[3 * i + 1], s->x0[3 * i + 2]};
        s->view[i] = sp_camera_view_dir(s->cam, x);
        double best = INFINITY;
        for (int c = 0; c < s->ab->curve_count; ++c) {
            bool matched = rep == NULL || c >= rep->curve_count || rep->curves[c].stroke >= 0;
            if (!matched) continue;
            const sp_curve* cv = &s->ab->curves[c];
            for (int j = cv->first_point; j < cv->first_point + cv->point_count; ++j) {
                sp_vec3 z = {s->z3[3 * j], s->z3[3 * j + 1], s->z3[3 * j + 2]};
                double d = sp_v3_len(sp_v3_sub(x, z));
                if (d < best) best = d;
            }
        }
        s->dw[i] = isfinite(best) ? best : 0;
        if (s->dw[i] > dmax) dmax = s->dw[i];
    }
    for (int i = 0; i < s->k; ++i)
        s->dw[i] = dmax > 0 ? s->dw[i] / dmax : 0;
    memcpy(s->xr, s->x0, sizeof(double) * 3 * (size_t)s->k);
    if (closed_form_reg(s)) s->model->ops->reg_prepare(s->model, s->reps, s->k, s->view, s->dw); // the state is p
}

// Test hook (solver_internal.h): W and its Gauss-Newton g and H at p with
// the pairs and the regularisers' reference made at p_ref.
sp_result sp__gauss_newton_at(sp_solver* s, const sp_sketch* sk, const double* p_ref, const double* p, double pose_boost,
                              int boost_from, double* W, double* g, double* H, sp_error* err)
{
    if (!sp__sketch_ok(sk, err)) return SP_ERR_INVALID;
    sp_solve_report rep;
    memset(&rep, 0, sizeof rep);
    memcpy(s->p0, p_ref, sizeof(double) * (size_t)s->P);
    sp__forget_pairing(s);
    s->ypoly_valid = false;
    s->model->failed = false;
    sp__model_update(s, p_ref, false);
    sp__project_abstraction(s);
    s->L = 1.0; // the weights' pixel scale: any fixed value will do here
    sp_result res = sp__build_pairs(s, sk, &(sp_pairing){.mode = s->ab->correspondence}, &rep, err);
    if (res != SP_OK) return res;
    sp__prepare_start(s, p_ref, &rep);
    const sp_weights w = {.pose_boost = pose_boost, .boost_from = boost_from, .vertex_boost = 1.0};
    *W = sp__energy(s, p, &w).total;
    sp__linearise(s, p, false, &w); // the energy projected at p
    memcpy(g, s->g, sizeof(double) * (size_t)s->P);
    if (H) memcpy(H, s->H, sizeof(double) * (size_t)s->P * (size_t)s->P);
    return SP_OK;
}
