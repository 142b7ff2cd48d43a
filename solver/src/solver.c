// solver.c: setup (coarsening, sparsity), the energy, and the bounded
// Levenberg-Marquardt / ICP loop. Correspondences are built in match.c.
#include <assert.h>
#include <cblas.h>
#include <flann/flann.h>
#include <lapacke.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "solver_internal.h"
#include "sp/curve.h"

// The reference setup the paper's default weights are tuned for, in the
// spirit of its Maya scenes: an abstraction 500 pixels across matched with
// 200 sample pairs, a character 200 units across with 1000 vertices. Every
// solve measures its residuals in these units (see sp/solver.h).
#define SP_REF_PIXELS 500.0
#define SP_REF_PAIRS 200.0
#define SP_REF_SIZE 200.0
#define SP_REF_VERTICES 1000.0

// Built in match.c: resamples the projected curves and the strokes and
// fills s->pairs; writes which stroke each curve got into rep->curves.
sp_result sp__build_pairs(sp_solver* s, const sp_sketch* sk, sp_solve_report* rep, sp_error* err);
// Also in match.c: the best k shifts and directions of the one loop stroke
// against the one closed curve at the current projection
// (sp_corr_ordered_candidates over m samples each), for sp_solver_solve.
int sp__loop_candidates(sp_solver* s, const sp_sketch* sk, sp_ordered_info* out, int k, int* m);

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

const char* sp_stop_reason_name(sp_stop_reason r)
{
    switch (r) {
    case SP_STOP_CONVERGED: return "converged";
    case SP_STOP_MAX_ITERATIONS: return "max_iterations";
    case SP_STOP_TIME_CAP: return "time_cap";
    case SP_STOP_STALLED: return "stalled";
    }
    return "unknown";
}

// ---------------------------------------------------------------- setup

static int cmp_int(const void* a, const void* b) { return *(const int*)a - *(const int*)b; }

// The model's calls (model.h), and bounds as sp_rig_clamp has them.
static inline void model_update(sp_solver* s, const double* p, bool derivatives) { s->model->ops->update(s->model, p, derivatives); }
static inline void model_rows(sp_solver* s, double* xyz) { s->model->ops->rows(s->model, s->reps, s->k, xyz); }
// W_plane and W_dist are computed in closed form by the model (LBS rigs
// where that is cheaper), or from the representatives' rows.
static inline bool closed_form_reg(const sp_solver* s) { return s->model->closed_reg; }
static inline bool has_reg(const sp_solver* s) { return s->k > 0 && (s->d.lambda_plane > 0 || s->d.lambda_dist > 0); }
static void model_defaults(const sp_solver* s, double* p)
{
    for (int i = 0; i < s->P; ++i) p[i] = s->model->params[i].def;
}
static void model_clamp(const sp_solver* s, double* p)
{
    for (int i = 0; i < s->P; ++i) {
        const sp_model_param* q = &s->model->params[i];
        double v = p[i];
        if (!isfinite(v)) v = q->def;
        if (v < q->min) v = q->min;
        if (v > q->max) v = q->max;
        p[i] = v;
    }
}

// The pose a solve starts from: p_start (NULL: the defaults) inside the bounds.
static void start_pose(const sp_solver* s, const double* p_start, double* p)
{
    if (p_start) memcpy(p, p_start, sizeof(double) * (size_t)s->P);
    else model_defaults(s, p);
    model_clamp(s, p);
}

// k-means of the rest vertices (FLANN), centres snapped to the nearest vertex.
static int coarsen(const double* rest_in, int n, int k, int* reps)
{
    double* rest = (double*)rest_in; // FLANN's C API only reads it but is not const-correct
    if (n <= k) {
        for (int i = 0; i < n; ++i) reps[i] = i;
        return n;
    }
    double* centers = malloc(sizeof(double) * 3 * (size_t)k);
    if (!centers) return 0;
    struct FLANNParameters fp = DEFAULT_FLANN_PARAMETERS;
    fp.algorithm = FLANN_INDEX_KMEANS;
    fp.branching = 32;
    fp.iterations = 11;
    fp.centers_init = FLANN_CENTERS_KMEANSPP;
    fp.random_seed = 12345; // deterministic coarsening
    fp.log_level = FLANN_LOG_NONE;
    // FLANN's hierarchical k-means returns (branching-1)*m+1 <= k clusters.
    int got = flann_compute_cluster_centers_double(rest, n, 3, k, centers, &fp);
    if (got <= 0) {
        // Fallback: evenly spaced vertices.
        for (int i = 0; i < k; ++i) reps[i] = (int)((long long)i * n / k);
        free(centers);
        return k;
    }
    struct FLANNParameters ip = DEFAULT_FLANN_PARAMETERS;
    ip.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    ip.checks = -1; // exact search
    ip.log_level = FLANN_LOG_NONE;
    ip.random_seed = 12345;
    float speedup = 0;
    flann_index_t idx = flann_build_index_double(rest, n, 3, &speedup, &ip);
    double* dist = malloc(sizeof(double) * (size_t)got);
    int m = 0;
    if (idx && dist && flann_find_nearest_neighbors_index_double(idx, centers, got, reps, dist, 1, &ip) == 0) {
        // Two centres may snap to one vertex: keep each vertex once.
        qsort(reps, (size_t)got, sizeof(int), cmp_int);
        for (int i = 0; i < got; ++i)
            if (m == 0 || reps[m - 1] != reps[i]) reps[m++] = reps[i];
    } else {
        for (int i = 0; i < got; ++i) reps[i] = (int)((long long)i * n / got);
        m = got;
    }
    if (idx) flann_free_index_double(idx, &ip);
    free(dist);
    free(centers);
    return m;
}

// OpenBLAS threads its small kernels by default and then spends most of a
// solve in sched_yield (perf: 40% on the Table 1 rigs): our systems have at
// most a few hundred unknowns, so one BLAS thread is faster, and the solver's
// own parallel work (finite differences) must not be oversubscribed. Weak, so
// that any other CBLAS/LAPACKE implementation links too.
extern void openblas_set_num_threads(int n) __attribute__((weak));

sp_solver* sp_solver_create(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_solve_desc* desc)
{
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return NULL;
    return sp__solver_create_model(sp__model_lbs_create(rig, abstraction), cam, desc);
}

static int find_group(sp_solver* s, const int* cols, int n)
{
    for (int g = 0; g < s->group_count; ++g)
        if (s->groups[g].n == n && (n == 0 || !memcmp(s->groups[g].cols, cols, sizeof(int) * (size_t)n))) return g;
    s->groups[s->group_count] = (row_group){.cols = cols, .n = n};
    return s->group_count++;
}

// Groups the abstraction points, their segments and the representatives by
// column list. A pair's sample lies on a segment (a, b), so a segment's rows
// span the union of a's and b's columns: the segment's group. Rows reserved:
// 2 per point (a one-point curve's), 4 per segment and 4 per representative
// (W_plane and W_dist): what one normal-equation build pushes at most.
static bool make_groups(sp_solver* s)
{
    const int l = s->ab->point_count;
    size_t total_cols = 0;
    for (int i = 0; i < l; ++i) total_cols += (size_t)s->ab_sb[i].count;
    s->groups = malloc(sizeof(row_group) * (size_t)(2 * l + s->k + 1));
    s->ab_grp = malloc(sizeof(int) * (size_t)(l + 1));
    s->rep_grp = malloc(sizeof(int) * (size_t)(s->k + 1));
    s->seg_grp = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_first = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_next = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_cols = malloc(sizeof(int) * (2 * total_cols + 1)); // a union holds at most a's and b's columns
    s->seg_map = malloc(sizeof(int) * (2 * total_cols + 1));
    if (!s->groups || !s->ab_grp || !s->rep_grp || !s->seg_grp || !s->seg_first || !s->seg_next || !s->seg_cols || !s->seg_map) return false;
    s->group_count = 0;
    for (int i = 0; i < l; ++i) {
        int g = s->ab_grp[i] = find_group(s, s->ab_cols + s->ab_sb[i].first, s->ab_sb[i].count);
        s->groups[g].cap += 2;
    }
    int at = 0, uat = 0;
    for (const sp_curve* cv = s->ab->curves; cv < s->ab->curves + s->ab->curve_count; ++cv)
        for (int k = 0; k < cv->point_count; ++k) {
            const int a = cv->first_point + k;
            const int b = k + 1 < cv->point_count ? a + 1 : (cv->closed ? cv->first_point : -1);
            s->seg_first[a] = at;
            s->seg_grp[a] = -1;
            s->seg_next[a] = b;
            if (b < 0 || b == a) continue; // no segment after an open curve's last point (nor in a one-point curve)
            const int *ca = s->ab_cols + s->ab_sb[a].first, *cb = s->ab_cols + s->ab_sb[b].first;
            const int na = s->ab_sb[a].count, nb = s->ab_sb[b].count;
            int* u = s->seg_cols + uat;
            int nu = 0;
            for (int i = 0, j = 0; i < na || j < nb;) { // sorted union; each side's positions in it
                int c = j >= nb || (i < na && ca[i] <= cb[j]) ? ca[i] : cb[j];
                if (i < na && ca[i] == c) s->seg_map[at + i++] = nu;
                if (j < nb && cb[j] == c) s->seg_map[at + na + j++] = nu;
                u[nu++] = c;
            }
            int g = s->seg_grp[a] = find_group(s, u, nu);
            if (s->groups[g].cols == u) uat += nu; // a new group keeps this copy
            s->groups[g].cap += 4;
            at += na + nb;
        }
    for (int i = 0; i < s->k; ++i) {
        int g = s->rep_grp[i] = find_group(s, s->rep_cols + s->rep_sb[i].first, s->rep_sb[i].count);
        s->groups[g].cap += 4;
    }
    size_t total = 0;
    for (int g = 0; g < s->group_count; ++g) total += (size_t)s->groups[g].cap * (size_t)s->groups[g].n;
    s->group_pool = malloc(sizeof(double) * (total + 1));
    if (!s->group_pool) return false;
    double* pool = s->group_pool;
    for (int g = 0; g < s->group_count; ++g) {
        row_group* gr = &s->groups[g];
        gr->U = pool, pool += (size_t)gr->cap * (size_t)gr->n;
    }
    return true;
}

sp_solver* sp__solver_create_model(sp_model* m, const sp_camera* cam, const sp_solve_desc* desc)
{
    if (openblas_set_num_threads) openblas_set_num_threads(1);
    if (!m) return NULL;
    sp_solver* s = calloc(1, sizeof *s);
    if (!s) {
        m->ops->destroy(m);
        return NULL;
    }
    s->model = m;
    s->ab = m->ab;
    s->cam = cam;
    s->d = desc ? *desc : (sp_solve_desc){0};
    if (s->d.lambda_pose == 0) s->d.lambda_pose = 0.5;
    if (s->d.lambda_plane == 0) s->d.lambda_plane = 0.01;
    if (s->d.lambda_dist == 0) s->d.lambda_dist = 0.001;
    if (s->d.lambda_pose < 0) s->d.lambda_pose = 0;
    if (s->d.lambda_plane < 0) s->d.lambda_plane = 0;
    if (s->d.lambda_dist < 0) s->d.lambda_dist = 0;
    if (s->d.representatives <= 0) s->d.representatives = 200;
    if (s->d.max_iterations <= 0) s->d.max_iterations = 300;
    if (s->d.max_icp_rounds <= 0) s->d.max_icp_rounds = 40;
    if (!(s->d.time_cap_ms > 0)) s->d.time_cap_ms = 3000;
    s->P = m->P;
    int P = s->P > 0 ? s->P : 1, l = s->ab->point_count;
    sp_vec3 lo, hi;
    sp_bounds(m->rest, m->vertex_count, &lo, &hi);
    s->D = sp_v3_len(sp_v3_sub(hi, lo));
    if (!(s->D > 0)) s->D = 1.0;
    s->reps = malloc(sizeof(int) * (size_t)(s->d.representatives + 1));
    s->k = s->reps && m->vertex_count > 0 ? coarsen(m->rest, m->vertex_count, s->d.representatives, s->reps) : 0;
    // Column lists.
    // Before deduplication a point lists every ancestor parameter of up to
    // 12 influences (an embedded point: 3 vertices x 4 joints).
    int* tmp = malloc(sizeof(int) * (size_t)(P * 12 + 16));
    s->ab_sb = malloc(sizeof(sparse_block) * (size_t)(l > 0 ? l : 1));
    s->rep_sb = malloc(sizeof(sparse_block) * (size_t)(s->k > 0 ? s->k : 1));
    size_t ab_total = 0, rep_total = 0;
    if (!tmp || !s->ab_sb || !s->rep_sb || !s->reps || !m->ops->prepare(m, s->reps, s->k)) goto fail;
    for (int pass = 0; pass < 2; ++pass) {
        ab_total = rep_total = 0;
        for (int i = 0; i < l; ++i) {
            int n = m->ops->columns(m, true, i, tmp);
            if (pass) memcpy(s->ab_cols + ab_total, tmp, sizeof(int) * (size_t)n);
            s->ab_sb[i] = (sparse_block){(int)ab_total, n};
            ab_total += (size_t)n;
        }
        for (int i = 0; i < s->k; ++i) {
            int n = m->ops->columns(m, false, s->reps[i], tmp);
            if (pass) memcpy(s->rep_cols + rep_total, tmp, sizeof(int) * (size_t)n);
            s->rep_sb[i] = (sparse_block){(int)rep_total, n};
            rep_total += (size_t)n;
        }
        if (!pass) {
            s->ab_cols = malloc(sizeof(int) * (ab_total + 1));
            s->rep_cols = malloc(sizeof(int) * (rep_total + 1));
            if (!s->ab_cols || !s->rep_cols) goto fail;
        }
    }
    free(tmp);
    tmp = NULL;
    if (!make_groups(s)) goto fail;
    size_t kk = (size_t)(s->k > 0 ? s->k : 1), ll = (size_t)(l > 0 ? l : 1);
    s->z3 = malloc(sizeof(double) * 3 * ll);
    s->z2 = malloc(sizeof(double) * 2 * ll);
    s->Jz = malloc(sizeof(double) * 3 * (ab_total + 1));
    s->G = malloc(sizeof(double) * 2 * (ab_total + 1));
    s->x0 = malloc(sizeof(double) * 3 * kk);
    s->xr = malloc(sizeof(double) * 3 * kk);
    s->Jr = malloc(sizeof(double) * 3 * (rep_total + 1));
    s->dw = malloc(sizeof(double) * kk);
    s->view = malloc(sizeof(sp_vec3) * kk);
    s->H = malloc(sizeof(double) * (size_t)P * (size_t)P);
    s->g = malloc(sizeof(double) * (size_t)P);
    s->p0 = malloc(sizeof(double) * (size_t)P);
    s->unit = malloc(sizeof(double) * (size_t)P);
    s->free_ = malloc(sizeof(bool) * (size_t)P);
    s->Hl = malloc(sizeof(double) * (size_t)P * (size_t)P);
    s->rows = malloc(sizeof(double) * 4 * (size_t)(P + 1));
    s->step_work = malloc(sizeof(double) * sp__bounded_step_work(P));
    s->step_iwork = malloc(sizeof(int) * 3 * (size_t)(P + 1));
    s->seg_mom = calloc(14 * ll, sizeof(double));
    s->seg_pairs = calloc(ll, sizeof(int));
    s->seg_list = malloc(sizeof(int) * ll);
    s->ab_used = malloc(sizeof(bool) * ll);
    if (!s->z3 || !s->z2 || !s->Jz || !s->G || !s->x0 || !s->xr || !s->Jr || !s->dw || !s->view ||
        !s->H || !s->g || !s->p0 || !s->unit || !s->free_ || !s->Hl || !s->rows || !s->step_work || !s->step_iwork || !s->seg_mom || !s->seg_pairs || !s->seg_list || !s->ab_used)
        goto fail;
    for (int i = 0; i < s->P; ++i) s->unit[i] = m->params[i].length ? s->D / SP_REF_SIZE : 1.0;
    return s;
fail:
    free(tmp);
    sp_solver_destroy(s);
    return NULL;
}

void sp_solver_destroy(sp_solver* s)
{
    if (!s) return;
    if (s->model) s->model->ops->destroy(s->model);
    free(s->reps), free(s->ab_cols), free(s->ab_sb), free(s->rep_cols), free(s->rep_sb);
    free(s->Jz), free(s->z3), free(s->z2), free(s->G), free(s->x0), free(s->xr), free(s->Jr), free(s->dw), free(s->view);
    free(s->H), free(s->g), free(s->p0), free(s->unit), free(s->free_), free(s->pairs);
    free(s->ypoly), free(s->ypoly_stroke);
    free(s->Hl), free(s->rows), free(s->step_work), free(s->step_iwork), free(s->ab_used);
    free(s->groups), free(s->ab_grp), free(s->rep_grp), free(s->group_pool);
    free(s->seg_grp), free(s->seg_first), free(s->seg_cols), free(s->seg_map), free(s->seg_next);
    free(s->seg_mom), free(s->seg_pairs), free(s->seg_list);
    free(s);
}

const int* sp_solver_representatives(const sp_solver* s, int* count)
{
    *count = s->k;
    return s->reps;
}

// ---------------------------------------------------------------- evaluation

// Projects the abstraction at the current rig state into s->z2.
static void project_abstraction(sp_solver* s)
{
    s->model->ops->abstraction(s->model, s->z3);
    for (int i = 0; i < s->ab->point_count; ++i) {
        sp_vec2 q = sp_camera_project(s->cam, (sp_vec3){s->z3[3 * i], s->z3[3 * i + 1], s->z3[3 * i + 2]});
        s->z2[2 * i] = q.x, s->z2[2 * i + 1] = q.y;
    }
}

void sp_solver_project_abstraction(sp_solver* s, const double* p, double* xy)
{
    model_update(s, p, false);
    project_abstraction(s);
    memcpy(xy, s->z2, sizeof(double) * 2 * (size_t)s->ab->point_count);
}

static sp_vec2 sample_at(const sp_solver* s, sample_ref r)
{
    const double* a = s->z2 + 2 * r.a;
    const double* b = s->z2 + 2 * r.b;
    return (sp_vec2){a[0] + r.t * (b[0] - a[0]), a[1] + r.t * (b[1] - a[1])};
}

// Closest-point pairs measure the residual mostly across the stroke
// (point-to-line, as in Chen and Medioni's ICP): a curve may then slide along
// the stroke within a round instead of being dragged to the sample that was
// closest at the round's start, which is what makes point-to-point ICP crawl
// (the Table 1 benchmark rigs needed 3x the iterations). The small tangential
// weight keeps the energy positive definite on straight strokes (0 would
// leave the per-point metric singular there). Closed curves get 0.01: the
// dragon parts' closest-point refinement then takes 20-40% fewer iterations
// and ends at half the mean error, recovery unchanged (200 targets a part).
// Open curves keep 0.1: their ends must not slide off the stroke's ends
// (0.01 there: the dragon-sized synthetic rig of per-bone curves recovered
// 8 of 20 instead of 17).
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

// Energy terms at p with the current correspondences (updates the rig state).
static sp_energy_terms energy(sp_solver* s, const double* p)
{
    sp_energy_terms e = {0};
    model_update(s, p, false);
    project_abstraction(s);
    double wm = match_weight(s);
    for (int i = 0; i < s->pair_count; ++i) {
        sp_vec2 d = sp_v2_sub(sample_at(s, s->pairs[i].s), s->pairs[i].y);
        double m[3];
        pair_metric(s, &s->pairs[i], m);
        e.match += wm * (m[0] * d.x * d.x + 2 * m[1] * d.x * d.y + m[2] * d.y * d.y);
    }
    double placement = 0; // W_pose of the parameters the boost leaves alone
    for (int i = 0; i < s->P; ++i) {
        double u = (p[i] - s->p0[i]) / s->unit[i];
        if (i < s->boost_from)
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
        model_rows(s, s->xr);
        double inv = vertex_weight(s);
        for (int i = 0; i < s->k; ++i) {
            sp_vec3 dx = {s->xr[3 * i] - s->x0[3 * i], s->xr[3 * i + 1] - s->x0[3 * i + 1], s->xr[3 * i + 2] - s->x0[3 * i + 2]};
            double vp = sp_v3_dot(s->view[i], dx);
            e.plane += inv * vp * vp;
            e.dist += inv * s->dw[i] * sp_v3_dot(dx, dx);
        }
    }
    e.pose = e.pose * (s->d.lambda_pose * s->pose_boost) + placement * s->d.lambda_pose;
    e.plane *= s->d.lambda_plane * s->vertex_boost;
    e.dist *= s->d.lambda_dist * s->vertex_boost;
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
    for (int i = 0; i < s->pair_count; ++i) used[s->pairs[i].s.a] = used[s->pairs[i].s.b] = true;
    s->model->ops->jacobians(s->model, s->reps, closed_form_reg(s) ? 0 : s->k, s->ab_sb, s->ab_cols, used, s->Jz, s->rep_sb, s->rep_cols,
                             s->Jr);
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
        for (int b = a; b < n; ++b) Hrow[gr->cols[b]] += L[b];
    }
    gr->rows = 0;
}

static void flush_groups(sp_solver* s)
{
    for (int g = 0; g < s->group_count; ++g) flush_group(s, g);
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
        for (int a = 0; a < n; ++a) s->g[gr->cols[a]] += Bk[a] * r[k];
    }
    assert(gr->rows + rows <= gr->cap);
    memcpy(gr->U + (size_t)gr->rows * (size_t)n, B, sizeof(double) * (size_t)rows * (size_t)n);
    gr->rows += rows;
}

// Gauss-Newton normal equations of W at the current state (upper triangle
// of H filled, then mirrored). Requires an update with derivatives.
static void normal_equations(sp_solver* s, const double* p)
{
    const int P = s->P;
    memset(s->H, 0, sizeof(double) * (size_t)P * (size_t)P);
    memset(s->g, 0, sizeof(double) * (size_t)P);
    jacobian_blocks(s);
    // The match term: a pair's sample is (1-t) z_a + t z_b on the segment
    // (a, b), its residual d = sample - y weighted by wm m (pair_metric), so
    // its Gauss-Newton terms are J^T wm m J and J^T wm m d with
    // J = (1-t) G_a + t G_b. Summed over a segment's pairs they are
    // G^T S G and G^T beta with G = [G_a; G_b] (4 rows: a's x and y, b's x
    // and y), S = sum [(1-t) I; t I] wm m [(1-t) I, t I] (4 x 4) and
    // beta = sum [(1-t) I; t I] wm m d. With S = L L^T the segment becomes at
    // most four least-squares rows L^T G over the union of a's and b's
    // columns with residuals L^-1 beta (a pivot that is zero, as when all of
    // a segment's pairs share one t, drops its row: S is positive
    // semidefinite, beta in its range), and H += rows^T rows is one
    // symmetric rank-k update per group. So a segment costs at most 4 rows
    // however many pairs it has (the dragon-sized rig: 8 a segment), and 2
    // with one pair (the cartoon man's outline: 320 pairs on 353 segments).
    // (Per-point sums with a cross term per segment, as before, took
    // syr2k at twice the flops and loops into H across groups.)
    const double wm = match_weight(s);
    double* mom = s->seg_mom; // 14 per segment: S's upper triangle (10), beta (4); zero between calls
    int nseg = 0;
    for (int i = 0; i < s->pair_count; ++i) {
        const pair* pr = &s->pairs[i];
        sp_vec2 d = sp_v2_sub(sample_at(s, pr->s), pr->y);
        double m[3];
        pair_metric(s, pr, m);
        const int a = pr->s.a;
        double ta = 1.0 - pr->s.t, tb = pr->s.t;
        if (pr->s.b == a || s->seg_grp[a] < 0) ta += tb, tb = 0; // on a point: its own columns only
        const double c[4][2] = {{ta, 0}, {0, ta}, {tb, 0}, {0, tb}}; // [(1-t) I; t I]
        const double M[2][2] = {{wm * m[0], wm * m[1]}, {wm * m[1], wm * m[2]}};
        const double Md[2] = {M[0][0] * d.x + M[0][1] * d.y, M[1][0] * d.x + M[1][1] * d.y};
        double* S = mom + 14 * (size_t)a;
        if (s->seg_pairs[a]++ == 0) s->seg_list[nseg++] = a;
        for (int r = 0, e = 0; r < 4; ++r) {
            double cm[2] = {c[r][0] * M[0][0] + c[r][1] * M[1][0], c[r][0] * M[0][1] + c[r][1] * M[1][1]};
            for (int q = r; q < 4; ++q) S[e++] += cm[0] * c[q][0] + cm[1] * c[q][1];
            S[10 + r] += c[r][0] * Md[0] + c[r][1] * Md[1];
        }
    }
    double* rows = s->rows;
    for (int k = 0; k < nseg; ++k) {
        const int a = s->seg_list[k];
        double* S = mom + 14 * (size_t)a;
        const bool seg = s->seg_grp[a] >= 0;
        double L[4][4] = {{0}}, r[4];
        bool live[4];
        for (int j = 0, e = 0; j < 4; ++j) // unpack the upper triangle into L's lower one
            for (int q = j; q < 4; ++q) L[q][j] = S[e++];
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
            for (int c = 0; c < A->count; ++c) row[map ? map[c] : c] += ax * Ga[c] + ay * Ga[A->count + c];
            if (seg && (bx != 0 || by != 0)) {
                const int bpt = s->seg_next[a];
                const sparse_block* Bb = &s->ab_sb[bpt];
                const double* Gb = s->G + 2 * (size_t)Bb->first;
                const int* mb = map + A->count;
                for (int c = 0; c < Bb->count; ++c) row[mb[c]] += bx * Gb[c] + by * Gb[Bb->count + c];
            }
            rr[nr++] = r[j];
        }
        if (nr) push_rows(s, g, rows, nr, rr);
        memset(S, 0, sizeof(double) * 14);
        s->seg_pairs[a] = 0;
    }
    if (has_reg(s) && closed_form_reg(s)) {
        double inv = vertex_weight(s) * s->vertex_boost;
        s->model->ops->reg_normal(s->model, s->d.lambda_plane * inv, s->d.lambda_dist * inv, s->H, s->g);
    } else if (has_reg(s)) {
        double inv = vertex_weight(s) * s->vertex_boost;
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
                for (int c = 0; c < n; ++c) B[c] = sw * (v.x * Jb[c] + v.y * Jb[n + c] + v.z * Jb[2 * n + c]);
                r4[rows++] = sw * (v.x * dx[0] + v.y * dx[1] + v.z * dx[2]);
            }
            if (wd > 0) {
                double sw = sqrt(wd);
                for (int d = 0; d < 3; ++d) {
                    for (int c = 0; c < n; ++c) B[rows * n + c] = sw * Jb[d * n + c];
                    r4[rows++] = sw * dx[d];
                }
            }
            if (rows) push_rows(s, s->rep_grp[i], B, rows, r4);
        }
    }
    flush_groups(s);
    for (int q = 0; q < P; ++q) {
        double w = s->d.lambda_pose * (q < s->boost_from ? 1.0 : s->pose_boost) / (s->unit[q] * s->unit[q]);
        s->H[q * P + q] += w;
        s->g[q] += w * (p[q] - s->p0[q]);
    }
    for (int a = 0; a < P; ++a)
        for (int b = a + 1; b < P; ++b) s->H[b * P + a] = s->H[a * P + b];
}

// The rig linearised at p: state with derivatives, projection (unless the
// caller's last energy left it at p), representatives' rows when the
// regularisers use them, then the normal equations.
static void linearise(sp_solver* s, const double* p, bool project)
{
    model_update(s, p, true);
    if (project) project_abstraction(s);
    if (s->k > 0 && !closed_form_reg(s)) model_rows(s, s->xr);
    normal_equations(s, p);
}

// Solves (H_ff + mu diag) delta_f = -g_f over the free parameters, within
// the bounds: a parameter whose step would leave its box is put on the bound
// it crosses (its step fixed to reach it) and the rest is solved again, until
// the step stays inside. Clamping the unconstrained step instead changes its
// direction behind the quadratic model's back: near joint limits such steps
// raised W where the model promised a drop, the damping grew and convergence
// crawled (the elephant's stick: 107 iterations, 88 of them after the
// weights were final).
// The passes share one Cholesky factor A = U'U of the free system: holding
// the set R at steps d_R is the equality-constrained problem
// min 1/2 x'Ax - b'x with x_R = d_R, solved by x = x0 - A^-1 E_R l with
// x0 = A^-1 b and (E_R' A^-1 E_R) l = x0_R - d_R (the Schur complement of
// its KKT system; the same x as solving the reduced system, to rounding).
// With V = U'^-1 E_R that matrix is V'V, so a pass costs one triangular
// solve for the newly held columns and one back substitution instead of a
// factorisation (the cartoon man: 2.9 factorisations of 92 x 92 a try -> 1;
// 8-14% fewer instructions a solve, the same recovery over 200 targets).
// (Tried once before, when the representatives' rows dominated, and dropped
// for no gain.)
// Returns false if the system could not be solved.
size_t sp__bounded_step_work(int P)
{
    return 3 * (size_t)P * (size_t)P + 5 * (size_t)P + 5;
}

bool sp__bounded_step(int P, const double* H, const double* g, const bool* free_, const sp_model_param* params, const double* p, double mu,
                      double* delta, double* work, int* iwork)
{
    const size_t PP = (size_t)P * (size_t)P;
    int* idx = iwork;           // the free parameters
    int* rpos = idx + P + 1;    // positions in idx of the held parameters, in the order they were held
    int* held = rpos + P + 1;   // by position in idx
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
        for (int j = 0; j < nf; ++j) A[i * nf + j] = Hi[idx[j]];
        // Marquardt scaling plus a floor so that flat directions stay solvable.
        A[i * nf + i] += mu * (Hi[idx[i]] + 1e-9);
        x0[i] = -g[idx[i]];
        held[i] = 0;
    }
    // A is symmetric: column-major saves LAPACKE's transposed copy. The _work
    // forms skip LAPACKE's NaN scans (the result is checked below).
    bool ok = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', nf, A, nf) == 0 && LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'U', nf, 1, A, nf, x0, nf) == 0;
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
        for (int j = nr0; j < nr; ++j) V[(size_t)j * (size_t)nf + (size_t)rpos[j]] = 1.0;
        cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, nf, nr - nr0, 1.0, A, nf, Vn, nf);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, nr, nf, 1.0, V, nf, 0.0, S, nr);
        for (int a = 0; a < nr; ++a) l[a] = x0[rpos[a]] - dR[a];
        ok = LAPACKE_dposv_work(LAPACK_COL_MAJOR, 'U', nr, 1, S, nr, l, nr) == 0;
        if (!ok) break;
        // x = x0 - A^-1 E_R l = x0 - U^-1 (V l)
        cblas_dgemv(CblasColMajor, CblasNoTrans, nf, nr, 1.0, V, nf, l, 1, 0.0, l + nr, 1);
        cblas_dtrsv(CblasColMajor, CblasUpper, CblasNoTrans, CblasNonUnit, nf, A, nf, l + nr, 1);
        for (int i = 0; i < nf; ++i) x[i] = x0[i] - l[nr + i];
        for (int j = 0; j < nr; ++j) x[rpos[j]] = dR[j]; // exactly on the bound, not to rounding
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
// is held for this step.
static void choose_free(sp_solver* s, const double* p, const bool* stage_active)
{
    for (int q = 0; q < s->P; ++q) {
        const sp_model_param* pr = &s->model->params[q];
        bool f = stage_active[q];
        double eps = 1e-12 * (1.0 + fabs(pr->max - pr->min));
        if (p[q] <= pr->min + eps && s->g[q] > 0) f = false;
        if (p[q] >= pr->max - eps && s->g[q] < 0) f = false;
        if (pr->min == pr->max) f = false;
        s->free_[q] = f;
    }
}

// Precomputes what depends on the start pose: x0 and viewing directions of
// the representatives, and d_i / d_max from the curves that got a stroke.
static void prepare_start(sp_solver* s, const double* p, const sp_solve_report* rep)
{
    model_update(s, p, false);
    model_rows(s, s->x0);
    project_abstraction(s);
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
    for (int i = 0; i < s->k; ++i) s->dw[i] = dmax > 0 ? s->dw[i] / dmax : 0;
    memcpy(s->xr, s->x0, sizeof(double) * 3 * (size_t)s->k);
    if (closed_form_reg(s)) s->model->ops->reg_prepare(s->model, s->reps, s->k, s->view, s->dw); // the state is p
}

// The polyline distances of closest pairs (see fill_errors): queries of
// direction `dir` (and curve `curve` for dir 0) against polylines p/next.
// Leaves d[] alone for other pairs or when out of memory (d is then the
// sample-to-sample distance, an upper bound).
static void polyline_errors(const sp_solver* s, int dir, int curve, const sp_vec2* p, const int* next, int n, double* d)
{
    sp_vec2* q = malloc(sizeof(sp_vec2) * (size_t)(s->pair_count + 1));
    int* which = malloc(sizeof(int) * (size_t)(s->pair_count + 1));
    double* out = malloc(sizeof(double) * (size_t)(s->pair_count + 1));
    int nq = 0;
    for (int i = 0; q && which && out && i < s->pair_count; ++i) {
        const pair* pr = &s->pairs[i];
        if (pr->dir != dir || (dir == 0 && pr->curve != curve)) continue;
        which[nq] = i;
        q[nq++] = dir == 0 ? pr->y : sample_at(s, pr->s);
    }
    if (nq > 0 && sp_polyline_distances(p, next, n, q, nq, out) == SP_OK)
        for (int k = 0; k < nq; ++k) d[which[k]] = fmin(d[which[k]], out[k]);
    free(q), free(which), free(out);
}

// The report's 2D errors. Ordered pairs: the distance between corresponding
// samples. Closest pairs: the distance of each sample to the other side's
// polyline, not to its nearest sample: two samplings of the same curve are
// up to half a spacing apart, which would put a floor of about 0.7% of the
// diagonal under every closest-point fit (seen on the dragon outlines).
static void fill_errors(sp_solver* s, sp_solve_report* rep)
{
    double sum = 0, mx = 0;
    double csum[SP_REPORT_CURVES] = {0}, cmax[SP_REPORT_CURVES] = {0};
    int cn[SP_REPORT_CURVES] = {0};
    // Out of memory, d stays NULL and every pair keeps its sample distance.
    double* d = malloc(sizeof(double) * (size_t)(s->pair_count + 1));
    for (int i = 0; d && i < s->pair_count; ++i) d[i] = sp_v2_len(sp_v2_sub(sample_at(s, s->pairs[i].s), s->pairs[i].y));
    const int l = s->ab->point_count, ny = s->ypoly_count;
    int* next = d && s->mode == SP_CORR_CLOSEST ? malloc(sizeof(int) * (size_t)(l > ny ? l + 1 : ny + 1)) : NULL;
    sp_vec2* z = next ? malloc(sizeof(sp_vec2) * (size_t)(l + 1)) : NULL;
    if (next && z) {
        // Stroke samples to their curve's projected polyline.
        for (int c = 0; c < s->ab->curve_count; ++c) {
            const sp_curve* cv = &s->ab->curves[c];
            for (int k = 0; k < cv->point_count; ++k) {
                next[k] = k + 1 < cv->point_count ? k + 1 : (cv->closed && k > 0 ? 0 : -1);
                z[k] = (sp_vec2){s->z2[2 * (cv->first_point + k)], s->z2[2 * (cv->first_point + k) + 1]};
            }
            polyline_errors(s, 0, c, z, next, cv->point_count, d);
        }
        // Curve samples to the resampled strokes (consecutive samples of one stroke are joined).
        for (int k = 0; k < ny; ++k) next[k] = k + 1 < ny && s->ypoly_stroke[k + 1] == s->ypoly_stroke[k] ? k + 1 : -1;
        if (ny > 0) polyline_errors(s, 1, -1, s->ypoly, next, ny, d);
    }
    free(next), free(z);
    for (int i = 0; i < s->pair_count; ++i) {
        double di = d ? d[i] : sp_v2_len(sp_v2_sub(sample_at(s, s->pairs[i].s), s->pairs[i].y));
        sum += di;
        if (di > mx) mx = di;
        int c = s->pairs[i].curve;
        if (c >= 0 && c < SP_REPORT_CURVES) {
            csum[c] += di, cn[c]++;
            if (di > cmax[c]) cmax[c] = di;
        }
    }
    free(d);
    rep->mean_error_px = s->pair_count ? sum / s->pair_count : 0;
    rep->max_error_px = mx;
    for (int c = 0; c < rep->curve_count; ++c) {
        rep->curves[c].mean_px = cn[c] ? csum[c] / cn[c] : 0;
        rep->curves[c].max_px = cmax[c];
    }
}

// ---------------------------------------------------------------- the solve

static bool sketch_ok(const sp_sketch* sk, sp_error* err)
{
    if (!sk || sk->stroke_count <= 0) {
        sp_fail(err, SP_ERR_INVALID, "the sketch has no strokes");
        return false;
    }
    if (!sp_sketch_is_valid(sk)) {
        sp_fail(err, SP_ERR_INVALID, "the sketch has a non-finite coordinate");
        return false;
    }
    for (int i = 0; i < sk->stroke_count; ++i) {
        const sp_stroke* st = &sk->strokes[i];
        double len = 0;
        for (int j = 1; j < st->count; ++j) len += sp_v2_len(sp_v2_sub(st->points[j], st->points[j - 1]));
        if (st->count < 2 || !(len > 0)) {
            sp_fail(err, SP_ERR_INVALID, "stroke %d has %s", i, st->count < 2 ? "fewer than 2 points" : "no length");
            return false;
        }
    }
    return true;
}

// A stroke whose ends meet within a fifth of its bounding-box diagonal: a
// person drawing a closed outline (gaps at closure are common, see the
// hand-drawing model of the classifier's training data).
static bool stroke_is_loop(const sp_stroke* st)
{
    if (st->count < 8) return false;
    double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
    for (int i = 0; i < st->count; ++i) {
        lx = fmin(lx, st->points[i].x), hx = fmax(hx, st->points[i].x);
        ly = fmin(ly, st->points[i].y), hy = fmax(hy, st->points[i].y);
    }
    double diag = hypot(hx - lx, hy - ly);
    sp_vec2 gap = sp_v2_sub(st->points[st->count - 1], st->points[0]);
    return diag > 0 && sp_v2_len(gap) <= 0.2 * diag;
}

static sp_result solve_once(sp_solver* s, const sp_sketch* sk, const double* p_start, double* p_out, sp_solve_report* rep, bool allow_loop,
                            bool place_free, double time_cap_ms, sp_error* err)
{
    double t0 = now_ms();
    s->used_loop = s->placed_free = false;
    s->boost_from = 0;
    s->ypoly_valid = false; // the strokes may be new
    memset(rep, 0, sizeof *rep);
    if (!sketch_ok(sk, err)) return SP_ERR_INVALID;
    const int P = s->P;
    double* p = malloc(sizeof(double) * (size_t)(P + 1));
    double* pn = malloc(sizeof(double) * (size_t)(P + 1));
    double* delta = malloc(sizeof(double) * (size_t)(P + 1));
    bool* stage_active = malloc(sizeof(bool) * (size_t)(P + 1));
    if (!p || !pn || !delta || !stage_active) {
        free(p), free(pn), free(delta), free(stage_active);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory in the solver");
    }
    start_pose(s, p_start, p);
    memcpy(s->p0, p, sizeof(double) * (size_t)P);
    s->model->failed = false;

    // L: the abstraction's diagonal in pixels at the start pose.
    model_update(s, p, false);
    project_abstraction(s);
    double start_iou;
    {
        double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
        for (int i = 0; i < s->ab->point_count; ++i) {
            lx = fmin(lx, s->z2[2 * i]), hx = fmax(hx, s->z2[2 * i]);
            ly = fmin(ly, s->z2[2 * i + 1]), hy = fmax(hy, s->z2[2 * i + 1]);
        }
        s->L = sqrt((hx - lx) * (hx - lx) + (hy - ly) * (hy - ly));
        if (!(s->L > 1e-6)) s->L = 1.0;
        // How well the strokes' box already covers the abstraction's (IoU).
        sp_vec2 slo, shi;
        start_iou = 0;
        if (sp_sketch_bounds(sk, &slo, &shi)) {
            double ix = fmin(hx, shi.x) - fmax(lx, slo.x), iy = fmin(hy, shi.y) - fmax(ly, slo.y);
            double inter = ix > 0 && iy > 0 ? ix * iy : 0;
            double uni = (hx - lx) * (hy - ly) + (shi.x - slo.x) * (shi.y - slo.y) - inter;
            start_iou = uni > 0 ? inter / uni : 0;
        }
    }
    rep->bbox_diagonal_px = s->L;

    // Stages: (0) only the root's placement moves, when it has translation
    // or scale parameters, so that a part drawn anywhere on the canvas is
    // first brought to the stroke; (1) everything moves; (2) for an outline
    // drawn as a loop, closest-point refinement after stage 1 in order. (A closest-point
    // stage before ordered matching was tried and lost: it folds stick
    // figures into local minima, 17% vs 97% recovery on the test chain.)
    // The placement stage is skipped when the strokes already sit on the
    // abstraction (their boxes overlap with IoU > 0.5): a character redrawn
    // where it stands. Closest points then only misplace a posed figure
    // (cartoon_man's stick: 94 -> 99 of 100 recovered; dragon parts drawn
    // elsewhere on the canvas keep the stage).
    const bool placing = !s->d.no_root_alignment && s->model->placement_count > 0 && start_iou <= 0.5;
    int first_stage = placing ? 0 : 1;
    int last_stage = 1;
    // An outline (one closed curve, closest points) drawn as one closed
    // stroke is matched in order first (arc length, best cyclic shift and
    // direction), then refined with closest points: closest-point ICP from
    // the rest pose snags in local minima where limbs cross (dragon parts:
    // 16-79% of random targets recovered; in order first: 95-100%).
    bool loop_first = s->ab->correspondence == SP_CORR_CLOSEST && s->ab->curve_count == 1 && s->ab->curves[0].closed &&
                      sk->stroke_count == 1 && stroke_is_loop(&sk->strokes[0]) && allow_loop;
    s->used_loop = loop_first;
    if (loop_first) last_stage = 2;
    // The graduated rounds below anchor W_pose strongly at the start pose,
    // and a placement found in stage 0 is part of that pose: the first
    // round pulled the root most of the way back to where the part stood
    // (the tail: W 1e5 at the end of stage 0, 5e9 at the start of stage 1)
    // and the rounds after it placed it again while they relaxed, so stage
    // 0's iterations were lost and the closest-point stage started from a
    // poorer ordered fit. With place_free a loop skips stage 0 and the
    // boost leaves its placement alone: the ordered rounds place the root
    // while the joints are still stiff. Dragon parts (400 targets a part):
    // tail 31 -> 18 iterations a solve, the other parts 22-25 -> 16-18,
    // 2392 -> 2395 of 2400 within 1% with the second attempt that
    // sp_solver_solve gives a failed fit (place_free false, as before).
    // Other rigs keep stage 0 and the boosted placement: freeing it there
    // cost the synthetic Table 1 rigs iterations (dragon-sized 46 -> 64).
    s->placed_free = placing && place_free && loop_first;
    s->boost_from = s->placed_free ? s->model->placement_count : 0;
    if (s->placed_free) first_stage = 1;

    s->mode = first_stage == 0 ? SP_CORR_CLOSEST : s->ab->correspondence;
    s->c2s_valid = s->keep_assignment = false;
    sp_result res = s->model->failed ? sp_fail(err, SP_ERR_INVALID, "%s", s->model->error.text) : sp__build_pairs(s, sk, rep, err);
    if (res != SP_OK) goto done;
    prepare_start(s, p, rep);
    s->pose_boost = s->vertex_boost = 1.0;
    rep->before = energy(s, p);
    sp_energy_terms cur = rep->before;
    rep->stopped = SP_STOP_MAX_ITERATIONS;
    double mu = 1e-3;
    bool time_up = false, converged = false;
    for (int stage = first_stage; stage <= last_stage && !time_up; ++stage) {
        for (int q = 0; q < P; ++q) {
            bool a = s->d.active ? s->d.active[q] : true;
            if (stage == 0) a = a && q < s->model->placement_count;
            stage_active[q] = a;
        }
        // Placement is found with closest points (no assignment needed);
        // the full solve uses the abstraction's own procedure.
        s->mode = stage == 0 ? SP_CORR_CLOSEST : s->ab->correspondence;
        // The loop's placement is found in order too: the best cyclic shift
        // and direction of a closed curve do not depend on where the stroke
        // is or how big (both only add a term common to every shift), and
        // fixed pairs place the root in a few iterations where closest
        // points crawled (dragon parts: 15 iterations -> 4-6).
        if (loop_first) s->mode = stage <= 1 ? SP_CORR_ORDERED : SP_CORR_CLOSEST;
        s->c2s_valid = s->keep_assignment = false;
        converged = false;
        double best_end = INFINITY; // lowest W at the end of a round at final weights
        int stall_rounds = 0;
        for (int round = 0; round < s->d.max_icp_rounds && !time_up && !s->model->failed; ++round) {
            // Ordered correspondences are kept once the weights are final:
            // re-resampling a curve that barely moves only slides its samples
            // along it, which costs many rounds and gains nothing.
            bool frozen = s->mode == SP_CORR_ORDERED && s->pose_boost == 1.0 && round > 0;
            // A loop's ordered stage only has to bring the outline near the
            // stroke: once the graduated rounds are over, closest points take
            // it from there. Converging the ordered fit first cost 2-25
            // iterations (the cartoon man's outline: 70 -> 45 a solve) and
            // changed no recovery (200 targets a part: the same counts).
            if (loop_first && stage == 1 && frozen) break;
            if ((round > 0 || stage > first_stage) && !frozen) {
                model_update(s, p, false);
                project_abstraction(s);
                res = sp__build_pairs(s, sk, rep, err);
                if (res != SP_OK) goto done;
            }
            ++rep->icp_rounds;
            // The assignment settles in the first rounds; keeping it then
            // saves the search and stops late flips between look-alikes.
            s->keep_assignment = round >= 3;
            // Graduated regularisation: strongly damped early rounds follow
            // the correspondences in small steps instead of jumping into a
            // folded local minimum; from the thirteenth round on (the tenth
            // for loops, below) the weights are the configured ones, so the
            // result minimises the real W.
            // One Gauss-Newton iteration per graduated round and a factor 4
            // between rounds recover as well as two and a factor 8 in fewer
            // iterations (200 targets a row: dragon parts within 2 either
            // way, cartoon_man's stick 193 -> 199).
            // Draw-over curves (embedded in the surface) are local edits, so
            // there W_plane and W_dist are graduated too: the early steps
            // then move what is near the curve, not the whole figure.
            // A loop placed in order relaxes faster (by 6 a round): its
            // pairs follow the outline's arc length, which does not fold
            // (dragon parts 3 fewer iterations, the same recovery over 200
            // targets a part; by 8, wings lost 2 of 200).
            s->pose_boost = stage != 1 ? 1.0 : fmax(1.0, 1e7 / pow(loop_first ? 6.0 : 4.0, round));
            s->vertex_boost = s->model->embedded ? s->pose_boost : 1.0;
            cur = energy(s, p);
            bool z_at_p = true; // the abstraction was last projected at p (by energy)
            double round_start = cur.total;
            // Few Gauss-Newton iterations per round: correspondences from
            // the previous pose go stale quickly, and while the weights are
            // graduated a round only has to follow them part of the way.
            // Frozen ordered pairs do not go stale: their rounds are only the
            // window the 0.1% test below is taken over, and two iterations
            // make it a test of 0.05% an iteration. Rounds of eight spent a
            // third of a stick solve creeping the last 0.2% of W down at
            // Gauss-Newton's linear rate without moving the fit (200 targets
            // a row: the same counts, error medians and p95 within 0.003%;
            // the cartoon man's stick 39 -> 25 iterations, the elephant's
            // 31 -> 25). A loop's closest-point refinement starts near the
            // stroke, where fresh pairs after every iteration beat more
            // iterations on old ones (dragon parts: 36-52 -> 26-35
            // iterations a solve, the same recovery over 200 targets a part);
            // its ordered stage, which only has to bring the outline near
            // the stroke, ends after one iteration at the final weights too
            // (three: the cartoon man's outline 23% more instructions, the
            // same recovery over 400 targets: 398 each, dragon parts within
            // one either way).
            int max_it = s->pose_boost > 1.0 ? 1 : (frozen ? 2 : (loop_first && stage >= 1 ? 1 : 3));
            for (int it = 0; it < max_it; ++it) {
                if (rep->iterations >= s->d.max_iterations) break;
                if (now_ms() - t0 > time_cap_ms) {
                    time_up = true;
                    break;
                }
                ++rep->iterations;
                linearise(s, p, !z_at_p); // else the accepted step's energy projected at p (same values)
                choose_free(s, p, stage_active);
                bool accepted = false;
                for (int tries = 0; tries < 12 && !accepted; ++tries) {
                    if (!lm_step(s, p, mu, delta)) {
                        mu *= 10;
                        continue;
                    }
                    for (int q = 0; q < P; ++q) pn[q] = p[q] + delta[q];
                    model_clamp(s, pn);
                    sp_energy_terms e = energy(s, pn);
                    if (e.total < cur.total) {
                        accepted = true;
                        double gain = (cur.total - e.total) / fmax(cur.total, 1e-300);
                        memcpy(p, pn, sizeof(double) * (size_t)P);
                        cur = e;
                        z_at_p = true;
                        mu = fmax(mu / 3, 1e-7);
                        if (gain < 1e-9) it = max_it; // this linearisation is exhausted
                    } else {
                        mu *= 4;
                        z_at_p = false;
                    }
                }
                if (!accepted) break;
            }
            double drop = (round_start - cur.total) / fmax(round_start, 1e-300);
            // Converged when a round no longer lowers W by more than 0.1% once
            // the weights are the real ones (1% while only placing the root).
            // The regularisers keep a large residual at the optimum, where
            // Gauss-Newton converges only linearly; the recovery benchmark
            // gives the same errors with this tolerance as with 0.01% in a
            // third of the iterations.
            double tol = stage == 0 ? 1e-2 : 1e-3;
            // With correspondences rebuilt every round (closest points), W
            // measured against fresh pairs can creep up while each round
            // still lowers it a little: ICP has stalled when two rounds in a
            // row end no lower than the best end so far. (One such round is
            // not enough: a many-limbed outline still improves by 1-3% a
            // round after a bad one.)
            if (!frozen && s->pose_boost == 1.0) {
                stall_rounds = cur.total > best_end * (1.0 - tol) ? stall_rounds + 1 : 0;
                best_end = fmin(best_end, cur.total);
            }
            bool stalled = stall_rounds >= 2;
            if (drop < 1e-6 || (s->pose_boost == 1.0 && drop < tol) || stalled) {
                converged = true;
                break;
            }
            if (rep->iterations >= s->d.max_iterations) break;
        }
    }
    if (s->model->failed) {
        // A black-box rig that cannot evaluate inside its bounds is broken:
        // say so instead of returning a pose fitted around the hole.
        res = sp_fail(err, SP_ERR_INVALID, "%s", s->model->error.text);
        goto done;
    }
    rep->stopped = time_up ? SP_STOP_TIME_CAP : (converged ? SP_STOP_CONVERGED : SP_STOP_MAX_ITERATIONS);
    // Final errors with fresh correspondences at the result.
    s->mode = s->ab->correspondence;
    s->pose_boost = s->vertex_boost = 1.0;
    model_update(s, p, false);
    project_abstraction(s);
    res = sp__build_pairs(s, sk, rep, err);
    if (res != SP_OK) goto done;
    rep->after = energy(s, p);
    fill_errors(s, rep);
    if (rep->mean_error_px > 0.05 * s->L && !rep->note[0])
        snprintf(rep->note, sizeof rep->note, "best effort: the abstraction cannot reach the strokes (mean error %.1f px, %.1f%% of its size)",
                 rep->mean_error_px, 100.0 * rep->mean_error_px / s->L);
    memcpy(p_out, p, sizeof(double) * (size_t)P);
done:
    rep->ms = now_ms() - t0;
    free(p), free(pn), free(delta), free(stage_active);
    return res;
}

// Test hook (solver_internal.h): W and its Gauss-Newton g and H at p with
// the pairs and the regularisers' reference made at p_ref.
sp_result sp__gauss_newton_at(sp_solver* s, const sp_sketch* sk, const double* p_ref, const double* p, double pose_boost, int boost_from,
                              double* W, double* g, double* H, sp_error* err)
{
    if (!sketch_ok(sk, err)) return SP_ERR_INVALID;
    sp_solve_report rep;
    memset(&rep, 0, sizeof rep);
    memcpy(s->p0, p_ref, sizeof(double) * (size_t)s->P);
    s->pose_boost = s->vertex_boost = 1.0;
    s->mode = s->ab->correspondence;
    s->c2s_valid = s->keep_assignment = false;
    s->ypoly_valid = false;
    s->model->failed = false;
    model_update(s, p_ref, false);
    project_abstraction(s);
    s->L = 1.0; // the weights' pixel scale: any fixed value will do here
    sp_result res = sp__build_pairs(s, sk, &rep, err);
    if (res != SP_OK) return res;
    prepare_start(s, p_ref, &rep);
    s->pose_boost = pose_boost;
    s->boost_from = boost_from;
    *W = energy(s, p).total;
    linearise(s, p, false); // energy projected at p
    memcpy(g, s->g, sizeof(double) * (size_t)s->P);
    if (H) memcpy(H, s->H, sizeof(double) * (size_t)s->P * (size_t)s->P);
    return SP_OK;
}

// Keeps attempt r2 (parameters p2) when it fits better than rep; the work of
// both counts in the report either way.
static void keep_better(const sp_solver* s, sp_solve_report* rep, double* p_out, sp_solve_report* r2, const double* p2)
{
    if (r2->mean_error_px < rep->mean_error_px) {
        r2->iterations += rep->iterations, r2->icp_rounds += rep->icp_rounds, r2->ms += rep->ms;
        *rep = *r2;
        memcpy(p_out, p2, sizeof(double) * (size_t)s->P);
    } else {
        rep->iterations += r2->iterations, rep->icp_rounds += r2->icp_rounds, rep->ms += r2->ms;
    }
}

static bool fit_ok(const sp_solve_report* rep) { return rep->mean_error_px <= 0.01 * rep->bbox_diagonal_px; }

// One more attempt at a loop that a first fit left above 1% (sp_solver_solve).
typedef struct attempt {
    bool allow_loop, place_free;
    bool forced; // hold hyp's shift and direction through the ordered stage
    sp_ordered_info hyp;
} attempt;

sp_result sp_solver_solve(sp_solver* s, const sp_sketch* sk, const double* p_start, double* p_out, sp_solve_report* rep,
                          sp_error* err)
{
    s->loop_forced = false;
    sp_result res = solve_once(s, sk, p_start, p_out, rep, true, true, s->d.time_cap_ms, err);
    if (res != SP_OK || fit_ok(rep) || !s->used_loop) return res;
    // The attempts that follow a loop's failed fit, in order, until one ends
    // within 1% or the time cap is reached; the best fit is kept and every
    // attempt counts in the report's work and time (a fit that succeeds the
    // first time pays nothing).
    // - A root placed without the boost (solve_once) can settle where the
    //   joints cannot finish the fit (the wings' wide span, now and then):
    //   the placement held back with the joints, as the graduated rounds did
    //   before (dragon parts 2381 -> 2395 of 2400 within 1%; the wings 394 ->
    //   399 of 400).
    // - An outline matched in order can lock onto the wrong cyclic shift or
    //   direction when the drawing is far from the start pose: the best
    //   shift against the rest outline is not the drawing's, and the fit
    //   then bends the outline round to agree with it (the cartoon man's
    //   posed outlines: that shift is often a sixth of the way round;
    //   forcing the drawing's own start recovered 98 of 100 instead of 89).
    //   So other shifts get a turn, each held through the ordered stage: the
    //   best shift moved a sixth of the way round either way (an eighth or a
    //   tenth: 96 and 94 of 100), then the runner-up shift (the cost's next
    //   local minimum, either direction; alone: 93-94 of 100).
    // - Last the plain closest-point solve (a thin tail's two edges look
    //   alike).
    // Cartoon man's outline 89 -> 100 of 100 (398 of 400), wings 194 -> 200
    // and tail 198 -> 200 of 200.
    attempt at[5];
    int na = 0;
    if (s->placed_free) at[na++] = (attempt){.allow_loop = true};
    double* p2 = malloc(sizeof(double) * (size_t)(s->P + 1));
    sp_solve_report* r2 = malloc(sizeof *r2);
    if (!p2 || !r2) {
        free(p2), free(r2);
        return res;
    }
    sp_ordered_info cand[2];
    int m = 0;
    start_pose(s, p_start, p2);
    model_update(s, p2, false);
    project_abstraction(s);
    int nc = s->model->failed ? 0 : sp__loop_candidates(s, sk, cand, 2, &m);
    if (nc > 0 && m >= 6) {
        at[na] = (attempt){.allow_loop = true, .forced = true, .hyp = cand[0]}, at[na++].hyp.shift = (cand[0].shift + m / 6) % m;
        at[na] = (attempt){.allow_loop = true, .forced = true, .hyp = cand[0]}, at[na++].hyp.shift = (cand[0].shift + m - m / 6) % m;
    }
    if (nc > 1) at[na++] = (attempt){.allow_loop = true, .forced = true, .hyp = cand[1]};
    at[na++] = (attempt){.allow_loop = false};
    sp_error e2 = {0};
    for (int i = 0; i < na && !fit_ok(rep) && s->d.time_cap_ms - rep->ms > 0; ++i) {
        s->loop_forced = at[i].forced, s->loop_hypothesis = at[i].hyp;
        if (solve_once(s, sk, p_start, p2, r2, at[i].allow_loop, at[i].place_free, s->d.time_cap_ms - rep->ms, &e2) == SP_OK)
            keep_better(s, rep, p_out, r2, p2);
    }
    s->loop_forced = false;
    free(p2), free(r2);
    return res;
}
