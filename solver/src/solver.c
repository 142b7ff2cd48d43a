// solver.c: setup (coarsening, sparsity), the energy, and the bounded
// Levenberg-Marquardt / ICP loop. Correspondences are built in match.c.
#include <flann/flann.h>
#include <lapacke.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "solver_internal.h"

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

// Parameters that move a point skinned to `joints`/`weights`: those of
// every influence joint and its ancestors, sorted, unique. Returns the count.
static int point_columns(const sp_rig* rig, const uint16_t* joints, const float* weights, int ninf, int* out)
{
    int n = 0;
    for (int k = 0; k < ninf; ++k) {
        if (weights[k] == 0.0f) continue;
        for (int a = joints[k]; a >= 0; a = rig->joints[a].parent)
            for (int q = 0; q < rig->joints[a].param_count; ++q) out[n++] = rig->joints[a].first_param + q;
    }
    qsort(out, (size_t)n, sizeof(int), cmp_int);
    int u = 0;
    for (int i = 0; i < n; ++i)
        if (u == 0 || out[u - 1] != out[i]) out[u++] = out[i];
    return u;
}

// Column list of an abstraction point (skinned, or embedded in 3 vertices).
static int abstraction_point_columns(const sp_rig* rig, const sp_abstraction* ab, int i, int* out)
{
    if (ab->rest) return point_columns(rig, ab->joints + 4 * i, ab->weights + 4 * i, 4, out);
    uint16_t j[12];
    float w[12];
    for (int v = 0; v < 3; ++v) {
        uint32_t vi = ab->tri_vertices[3 * i + v];
        for (int k = 0; k < 4; ++k) {
            j[4 * v + k] = rig->joints4[4 * vi + k];
            w[4 * v + k] = ab->bary[3 * i + v] != 0.0 ? rig->weights4[4 * vi + k] : 0.0f;
        }
    }
    return point_columns(rig, j, w, 12, out);
}

// k-means of the rest vertices (FLANN), centres snapped to the nearest vertex.
static int coarsen(const sp_rig* rig, int k, int* reps)
{
    int n = rig->vertex_count;
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
    int got = flann_compute_cluster_centers_double(rig->rest, n, 3, k, centers, &fp);
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
    flann_index_t idx = flann_build_index_double(rig->rest, n, 3, &speedup, &ip);
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

sp_solver* sp_solver_create(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_solve_desc* desc)
{
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return NULL;
    sp_solver* s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->rig = rig;
    s->ab = &rig->abstractions[abstraction];
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
    s->P = rig->param_count;
    int P = s->P > 0 ? s->P : 1, l = s->ab->point_count;
    s->ev = sp_rig_eval_create(rig);
    sp_vec3 lo, hi;
    sp_bounds(rig->rest, rig->vertex_count, &lo, &hi);
    s->D = sp_v3_len(sp_v3_sub(hi, lo));
    if (!(s->D > 0)) s->D = 1.0;
    s->reps = malloc(sizeof(int) * (size_t)(s->d.representatives + 1));
    s->k = s->reps && rig->vertex_count > 0 ? coarsen(rig, s->d.representatives, s->reps) : 0;
    // Column lists.
    // Before deduplication a point lists every ancestor parameter of up to
    // 12 influences (an embedded point: 3 vertices x 4 joints).
    int* tmp = malloc(sizeof(int) * (size_t)(P * 12 + 16));
    s->ab_sb = malloc(sizeof(sparse_block) * (size_t)(l > 0 ? l : 1));
    s->rep_sb = malloc(sizeof(sparse_block) * (size_t)(s->k > 0 ? s->k : 1));
    size_t ab_total = 0, rep_total = 0;
    if (!s->ev || !tmp || !s->ab_sb || !s->rep_sb || !s->reps) goto fail;
    for (int pass = 0; pass < 2; ++pass) {
        ab_total = rep_total = 0;
        for (int i = 0; i < l; ++i) {
            int n = abstraction_point_columns(rig, s->ab, i, tmp);
            if (pass) memcpy(s->ab_cols + ab_total, tmp, sizeof(int) * (size_t)n);
            s->ab_sb[i] = (sparse_block){(int)ab_total, n};
            ab_total += (size_t)n;
        }
        for (int i = 0; i < s->k; ++i) {
            int v = s->reps[i];
            int n = point_columns(rig, rig->joints4 + 4 * v, rig->weights4 + 4 * v, 4, tmp);
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
    size_t kk = (size_t)(s->k > 0 ? s->k : 1), ll = (size_t)(l > 0 ? l : 1);
    s->mesh = s->ab->rest ? NULL : malloc(sizeof(double) * 3 * (size_t)rig->vertex_count);
    s->z3 = malloc(sizeof(double) * 3 * ll);
    s->z2 = malloc(sizeof(double) * 2 * ll);
    s->G = malloc(sizeof(double) * 2 * (ab_total + 1));
    s->x0 = malloc(sizeof(double) * 3 * kk);
    s->xr = malloc(sizeof(double) * 3 * kk);
    s->Jr = malloc(sizeof(double) * 3 * (rep_total + 1));
    s->dw = malloc(sizeof(double) * kk);
    s->view = malloc(sizeof(sp_vec3) * kk);
    s->scratch = malloc(sizeof(double) * 9 * (size_t)P);
    s->H = malloc(sizeof(double) * (size_t)P * (size_t)P);
    s->g = malloc(sizeof(double) * (size_t)P);
    s->p0 = malloc(sizeof(double) * (size_t)P);
    s->unit = malloc(sizeof(double) * (size_t)P);
    s->free_ = malloc(sizeof(bool) * (size_t)P);
    s->match_aa = malloc(sizeof(double) * ll);
    s->match_ab = malloc(sizeof(double) * ll);
    s->match_beta = malloc(sizeof(double) * 2 * ll);
    if ((!s->ab->rest && !s->mesh) || !s->z3 || !s->z2 || !s->G || !s->x0 || !s->xr || !s->Jr || !s->dw || !s->view ||
        !s->scratch || !s->H || !s->g || !s->p0 || !s->unit || !s->free_ || !s->match_aa || !s->match_ab || !s->match_beta)
        goto fail;
    for (int i = 0; i < s->P; ++i) {
        sp_channel c = rig->params[i].channel;
        s->unit[i] = (c >= SP_CH_TX && c <= SP_CH_TZ) ? s->D / SP_REF_SIZE : 1.0;
    }
    return s;
fail:
    free(tmp);
    sp_solver_destroy(s);
    return NULL;
}

void sp_solver_destroy(sp_solver* s)
{
    if (!s) return;
    sp_rig_eval_destroy(s->ev);
    free(s->reps), free(s->ab_cols), free(s->ab_sb), free(s->rep_cols), free(s->rep_sb);
    free(s->mesh), free(s->z3), free(s->z2), free(s->G), free(s->x0), free(s->xr), free(s->Jr), free(s->dw), free(s->view);
    free(s->scratch), free(s->H), free(s->g), free(s->p0), free(s->unit), free(s->free_), free(s->pairs);
    free(s->match_aa), free(s->match_ab), free(s->match_beta);
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
    if (!s->ab->rest) sp_rig_eval_points(s->ev, sp_rig_mesh_points(s->rig), s->mesh);
    sp_rig_eval_abstraction(s->ev, s->ab, s->mesh, s->z3);
    for (int i = 0; i < s->ab->point_count; ++i) {
        sp_vec2 q = sp_camera_project(s->cam, (sp_vec3){s->z3[3 * i], s->z3[3 * i + 1], s->z3[3 * i + 2]});
        s->z2[2 * i] = q.x, s->z2[2 * i + 1] = q.y;
    }
}

void sp_solver_project_abstraction(sp_solver* s, const double* p, double* xy)
{
    sp_rig_eval_update(s->ev, p, false);
    project_abstraction(s);
    memcpy(xy, s->z2, sizeof(double) * 2 * (size_t)s->ab->point_count);
}

static sp_vec2 sample_at(const sp_solver* s, sample_ref r)
{
    const double* a = s->z2 + 2 * r.a;
    const double* b = s->z2 + 2 * r.b;
    return (sp_vec2){a[0] + r.t * (b[0] - a[0]), a[1] + r.t * (b[1] - a[1])};
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
    sp_rig_eval_update(s->ev, p, false);
    project_abstraction(s);
    double wm = match_weight(s);
    for (int i = 0; i < s->pair_count; ++i) {
        sp_vec2 d = sp_v2_sub(sample_at(s, s->pairs[i].s), s->pairs[i].y);
        e.match += wm * sp_v2_dot(d, d);
    }
    for (int i = 0; i < s->P; ++i) {
        double u = (p[i] - s->p0[i]) / s->unit[i];
        e.pose += u * u;
    }
    if (s->k > 0 && (s->d.lambda_plane > 0 || s->d.lambda_dist > 0)) {
        sp_rig_eval_rows(s->ev, sp_rig_mesh_points(s->rig), s->reps, s->k, s->xr);
        double inv = vertex_weight(s);
        for (int i = 0; i < s->k; ++i) {
            sp_vec3 dx = {s->xr[3 * i] - s->x0[3 * i], s->xr[3 * i + 1] - s->x0[3 * i + 1], s->xr[3 * i + 2] - s->x0[3 * i + 2]};
            double vp = sp_v3_dot(s->view[i], dx);
            e.plane += inv * vp * vp;
            e.dist += inv * s->dw[i] * sp_v3_dot(dx, dx);
        }
    }
    e.pose *= s->d.lambda_pose * s->pose_boost;
    e.plane *= s->d.lambda_plane * s->vertex_boost;
    e.dist *= s->d.lambda_dist * s->vertex_boost;
    e.total = e.match + e.pose + e.plane + e.dist;
    return e;
}

// ---------------------------------------------------------------- normal equations

// Fills the projected Jacobian blocks of every abstraction point (s->G) and
// the 3D blocks of the representatives (s->Jr) at the current rig state.
static void jacobian_blocks(sp_solver* s)
{
    const sp_rig* rig = s->rig;
    const int P = s->P;
    double* J = s->scratch; // 3 x P
    double* Jv = s->scratch + 3 * P;
    for (int i = 0; i < s->ab->point_count; ++i) {
        const sparse_block* sb = &s->ab_sb[i];
        if (s->ab->rest) {
            sp_skinned_points pts = {s->ab->point_count, s->ab->rest, s->ab->joints, s->ab->weights};
            sp_rig_eval_jacobian(s->ev, pts, &i, 1, J);
        } else {
            memset(J, 0, sizeof(double) * 3 * (size_t)P);
            for (int v = 0; v < 3; ++v) {
                int vi = (int)s->ab->tri_vertices[3 * i + v];
                double b = s->ab->bary[3 * i + v];
                if (b == 0.0) continue;
                sp_rig_eval_jacobian(s->ev, sp_rig_mesh_points(rig), &vi, 1, Jv);
                for (int c = 0; c < sb->count; ++c) {
                    int q = s->ab_cols[sb->first + c];
                    for (int r = 0; r < 3; ++r) J[r * P + q] += b * Jv[r * P + q];
                }
            }
        }
        double C[6];
        sp_camera_jacobian(s->cam, (sp_vec3){s->z3[3 * i], s->z3[3 * i + 1], s->z3[3 * i + 2]}, C);
        double* Gb = s->G + 2 * (size_t)sb->first;
        for (int c = 0; c < sb->count; ++c) {
            int q = s->ab_cols[sb->first + c];
            double jx = J[q], jy = J[P + q], jz = J[2 * P + q];
            Gb[c] = C[0] * jx + C[1] * jy + C[2] * jz;
            Gb[sb->count + c] = C[3] * jx + C[4] * jy + C[5] * jz;
        }
    }
    for (int i = 0; i < s->k; ++i) {
        const sparse_block* sb = &s->rep_sb[i];
        sp_rig_eval_jacobian(s->ev, sp_rig_mesh_points(rig), &s->reps[i], 1, J);
        double* Jb = s->Jr + 3 * (size_t)sb->first;
        for (int c = 0; c < sb->count; ++c) {
            int q = s->rep_cols[sb->first + c];
            Jb[c] = J[q], Jb[sb->count + c] = J[P + q], Jb[2 * sb->count + c] = J[2 * P + q];
        }
    }
}

// H += wh * B^T B, g += wg * B^T r over the listed (sorted) columns; B is
// rows x n, row-major. Fills the upper triangle of H.
static void accumulate(sp_solver* s, const int* cols, int n, const double* B, int rows, const double* r, double wg, double wh)
{
    const int P = s->P;
    for (int a = 0; a < n; ++a) {
        int qa = cols[a];
        double ga = 0;
        for (int k = 0; k < rows; ++k) ga += B[k * n + a] * r[k];
        s->g[qa] += wg * ga;
        if (wh == 0.0) continue;
        for (int b = a; b < n; ++b) {
            double h = 0;
            for (int k = 0; k < rows; ++k) h += B[k * n + a] * B[k * n + b];
            s->H[qa * P + cols[b]] += wh * h;
        }
    }
}

// Gauss-Newton normal equations of W at the current state (upper triangle
// of H filled, then mirrored). Requires an update with derivatives.
static void normal_equations(sp_solver* s, const double* p)
{
    const int P = s->P;
    memset(s->H, 0, sizeof(double) * (size_t)P * (size_t)P);
    memset(s->g, 0, sizeof(double) * (size_t)P);
    jacobian_blocks(s);
    int* cols = malloc(sizeof(int) * (size_t)(2 * P + 1));
    double* B = malloc(sizeof(double) * (size_t)(6 * P + 3));
    if (!cols || !B) {
        free(cols), free(B);
        return;
    }
    // The match term is quadratic in the projected points z: a sample is
    // (1-t) z_a + t z_b, so summing over pairs first leaves per point a
    // weight aa and a gradient vector beta, and per segment (a, b) a
    // coupling ab. H and g then need one product per point and one per
    // segment instead of one per pair, whatever the sample count.
    const int l = s->ab->point_count;
    double* aa = s->match_aa;
    double* ab = s->match_ab;
    double* beta = s->match_beta;
    memset(aa, 0, sizeof(double) * (size_t)l);
    memset(ab, 0, sizeof(double) * (size_t)l);
    memset(beta, 0, sizeof(double) * 2 * (size_t)l);
    double wm = match_weight(s);
    for (int i = 0; i < s->pair_count; ++i) {
        const pair* pr = &s->pairs[i];
        sp_vec2 d = sp_v2_sub(sample_at(s, pr->s), pr->y);
        double ca = 1.0 - pr->s.t, cb = pr->s.t;
        int a = pr->s.a, b = pr->s.b;
        if (a == b) ca += cb, cb = 0;
        aa[a] += wm * ca * ca;
        aa[b] += wm * cb * cb;
        ab[a] += wm * ca * cb; // segment a -> b: b is the point after a
        beta[2 * a] += wm * ca * d.x, beta[2 * a + 1] += wm * ca * d.y;
        beta[2 * b] += wm * cb * d.x, beta[2 * b + 1] += wm * cb * d.y;
    }
    for (const sp_curve* cv = s->ab->curves; cv < s->ab->curves + s->ab->curve_count; ++cv) {
        for (int k = 0; k < cv->point_count; ++k) {
            int a = cv->first_point + k;
            const sparse_block* A = &s->ab_sb[a];
            const double* Ga = s->G + 2 * (size_t)A->first;
            const int* ca = s->ab_cols + A->first;
            if (aa[a] != 0.0 || beta[2 * a] != 0.0 || beta[2 * a + 1] != 0.0)
                accumulate(s, ca, A->count, Ga, 2, beta + 2 * a, 1.0, aa[a]);
            if (ab[a] == 0.0) continue;
            int b = k + 1 < cv->point_count ? a + 1 : cv->first_point; // closing segment of a loop
            const sparse_block* Bk = &s->ab_sb[b];
            const double* Gb = s->G + 2 * (size_t)Bk->first;
            const int* cb = s->ab_cols + Bk->first;
            // Cross term ab * (Ga^T Gb + Gb^T Ga), into the upper triangle.
            for (int i = 0; i < A->count; ++i)
                for (int j = 0; j < Bk->count; ++j) {
                    double x = ab[a] * (Ga[i] * Gb[j] + Ga[A->count + i] * Gb[Bk->count + j]);
                    int qi = ca[i], qj = cb[j];
                    if (qi == qj) s->H[qi * P + qi] += 2.0 * x;
                    else if (qi < qj) s->H[qi * P + qj] += x;
                    else s->H[qj * P + qi] += x;
                }
        }
    }
    if (s->k > 0 && (s->d.lambda_plane > 0 || s->d.lambda_dist > 0)) {
        double inv = vertex_weight(s) * s->vertex_boost;
        for (int i = 0; i < s->k; ++i) {
            const sparse_block* sb = &s->rep_sb[i];
            const double* Jb = s->Jr + 3 * (size_t)sb->first;
            const int* cl = s->rep_cols + sb->first;
            double dx[3] = {s->xr[3 * i] - s->x0[3 * i], s->xr[3 * i + 1] - s->x0[3 * i + 1], s->xr[3 * i + 2] - s->x0[3 * i + 2]};
            if (s->d.lambda_plane > 0) {
                sp_vec3 v = s->view[i];
                for (int c = 0; c < sb->count; ++c) B[c] = v.x * Jb[c] + v.y * Jb[sb->count + c] + v.z * Jb[2 * sb->count + c];
                double r = v.x * dx[0] + v.y * dx[1] + v.z * dx[2];
                accumulate(s, cl, sb->count, B, 1, &r, s->d.lambda_plane * inv, s->d.lambda_plane * inv);
            }
            if (s->d.lambda_dist > 0 && s->dw[i] > 0) accumulate(s, cl, sb->count, Jb, 3, dx, s->d.lambda_dist * inv * s->dw[i], s->d.lambda_dist * inv * s->dw[i]);
        }
    }
    for (int q = 0; q < P; ++q) {
        double w = s->d.lambda_pose * s->pose_boost / (s->unit[q] * s->unit[q]);
        s->H[q * P + q] += w;
        s->g[q] += w * (p[q] - s->p0[q]);
    }
    for (int a = 0; a < P; ++a)
        for (int b = a + 1; b < P; ++b) s->H[b * P + a] = s->H[a * P + b];
    free(cols), free(B);
}

// Solves (H_ff + mu diag) delta_f = -g_f over the free parameters. Returns
// false if the system could not be solved.
static bool lm_step(sp_solver* s, double mu, double* delta)
{
    const int P = s->P;
    int* idx = malloc(sizeof(int) * (size_t)(P + 1));
    int nf = 0;
    for (int q = 0; q < P; ++q)
        if (s->free_[q]) idx[nf++] = q;
    memset(delta, 0, sizeof(double) * (size_t)P);
    if (nf == 0) {
        free(idx);
        return false;
    }
    double* A = malloc(sizeof(double) * (size_t)nf * (size_t)nf);
    double* b = malloc(sizeof(double) * (size_t)nf);
    bool ok = A && b;
    if (ok) {
        for (int i = 0; i < nf; ++i) {
            for (int j = 0; j < nf; ++j) A[i * nf + j] = s->H[idx[i] * P + idx[j]];
            // Marquardt scaling plus a floor so that flat directions stay solvable.
            A[i * nf + i] += mu * (s->H[idx[i] * P + idx[i]] + 1e-9);
            b[i] = -s->g[idx[i]];
        }
        ok = LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', nf, 1, A, nf, b, 1) == 0;
        for (int i = 0; ok && i < nf; ++i) {
            if (!isfinite(b[i])) ok = false;
            else delta[idx[i]] = b[i];
        }
    }
    free(A), free(b), free(idx);
    return ok;
}

// Active set: a parameter at a bound whose descent direction leaves the box
// is held for this step.
static void choose_free(sp_solver* s, const double* p, const bool* stage_active)
{
    for (int q = 0; q < s->P; ++q) {
        const sp_param* pr = &s->rig->params[q];
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
    sp_rig_eval_update(s->ev, p, false);
    sp_rig_eval_rows(s->ev, sp_rig_mesh_points(s->rig), s->reps, s->k, s->x0);
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
}

// Per-curve and overall 2D errors from the current pairs at the current state.
static void fill_errors(sp_solver* s, sp_solve_report* rep)
{
    double sum = 0, mx = 0;
    double csum[SP_REPORT_CURVES] = {0}, cmax[SP_REPORT_CURVES] = {0};
    int cn[SP_REPORT_CURVES] = {0};
    for (int i = 0; i < s->pair_count; ++i) {
        double d = sp_v2_len(sp_v2_sub(sample_at(s, s->pairs[i].s), s->pairs[i].y));
        sum += d;
        if (d > mx) mx = d;
        int c = s->pairs[i].curve;
        if (c >= 0 && c < SP_REPORT_CURVES) {
            csum[c] += d, cn[c]++;
            if (d > cmax[c]) cmax[c] = d;
        }
    }
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

sp_result sp_solver_solve(sp_solver* s, const sp_sketch* sk, const double* p_start, double* p_out, sp_solve_report* rep,
                          sp_error* err)
{
    double t0 = now_ms();
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
    if (p_start) memcpy(p, p_start, sizeof(double) * (size_t)P);
    else sp_rig_defaults(s->rig, p);
    sp_rig_clamp(s->rig, p);
    memcpy(s->p0, p, sizeof(double) * (size_t)P);

    // L: the abstraction's diagonal in pixels at the start pose.
    sp_rig_eval_update(s->ev, p, false);
    project_abstraction(s);
    {
        double lx = INFINITY, ly = INFINITY, hx = -INFINITY, hy = -INFINITY;
        for (int i = 0; i < s->ab->point_count; ++i) {
            lx = fmin(lx, s->z2[2 * i]), hx = fmax(hx, s->z2[2 * i]);
            ly = fmin(ly, s->z2[2 * i + 1]), hy = fmax(hy, s->z2[2 * i + 1]);
        }
        s->L = sqrt((hx - lx) * (hx - lx) + (hy - ly) * (hy - ly));
        if (!(s->L > 1e-6)) s->L = 1.0;
    }
    rep->bbox_diagonal_px = s->L;

    // Stages: (0) only the root's placement moves, when it has translation
    // or scale parameters, so that a part drawn anywhere on the canvas is
    // first brought to the stroke; (1) everything moves. (A closest-point
    // stage before ordered matching was tried and lost: it folds stick
    // figures into local minima, 17% vs 97% recovery on the test chain.)
    int root_joint = P > 0 ? s->rig->params[0].joint : -1;
    bool has_placement = false;
    for (int q = 0; q < P && s->rig->params[q].joint == root_joint; ++q)
        has_placement |= !sp_channel_is_rotation(s->rig->params[q].channel);
    int first_stage = (!s->d.no_root_alignment && has_placement) ? 0 : 1;
    int last_stage = 1;

    s->mode = first_stage == 0 ? SP_CORR_CLOSEST : s->ab->correspondence;
    s->c2s_valid = s->keep_assignment = false;
    sp_result res = sp__build_pairs(s, sk, rep, err);
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
            if (stage == 0) a = a && s->rig->params[q].joint == root_joint;
            stage_active[q] = a;
        }
        // Placement is found with closest points (no assignment needed);
        // the full solve uses the abstraction's own procedure.
        s->mode = stage == 0 ? SP_CORR_CLOSEST : s->ab->correspondence;
        converged = false;
        for (int round = 0; round < s->d.max_icp_rounds && !time_up; ++round) {
            // Ordered correspondences are kept once the weights are final:
            // re-resampling a curve that barely moves only slides its samples
            // along it, which costs many rounds and gains nothing.
            bool frozen = s->mode == SP_CORR_ORDERED && s->pose_boost == 1.0 && round > 0;
            if ((round > 0 || stage > first_stage) && !frozen) {
                sp_rig_eval_update(s->ev, p, false);
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
            // folded local minimum; from the ninth round on the weights are
            // the configured ones, so the result minimises the real W.
            // Draw-over curves (embedded in the surface) are local edits, so
            // there W_plane and W_dist are graduated too: the early steps
            // then move what is near the curve, not the whole figure.
            s->pose_boost = fmax(1.0, 1e7 / pow(8.0, round));
            s->vertex_boost = s->ab->rest ? 1.0 : s->pose_boost;
            cur = energy(s, p);
            double round_start = cur.total;
            // Gauss-Newton iterations with these correspondences.
            for (int it = 0; it < 8; ++it) {
                if (rep->iterations >= s->d.max_iterations) break;
                if (now_ms() - t0 > s->d.time_cap_ms) {
                    time_up = true;
                    break;
                }
                ++rep->iterations;
                sp_rig_eval_update(s->ev, p, true);
                project_abstraction(s);
                if (s->k > 0) sp_rig_eval_rows(s->ev, sp_rig_mesh_points(s->rig), s->reps, s->k, s->xr);
                normal_equations(s, p);
                choose_free(s, p, stage_active);
                bool accepted = false;
                for (int tries = 0; tries < 12 && !accepted; ++tries) {
                    if (!lm_step(s, mu, delta)) {
                        mu *= 10;
                        continue;
                    }
                    for (int q = 0; q < P; ++q) pn[q] = p[q] + delta[q];
                    sp_rig_clamp(s->rig, pn);
                    sp_energy_terms e = energy(s, pn);
                    if (e.total < cur.total) {
                        accepted = true;
                        double gain = (cur.total - e.total) / fmax(cur.total, 1e-300);
                        memcpy(p, pn, sizeof(double) * (size_t)P);
                        cur = e;
                        mu = fmax(mu / 3, 1e-7);
                        if (gain < 1e-9) it = 8; // this linearisation is exhausted
                    } else {
                        mu *= 4;
                    }
                }
                if (!accepted) break;
            }
            double drop = (round_start - cur.total) / fmax(round_start, 1e-300);
            // Converged when a round with fresh correspondences no longer
            // lowers W by more than 0.01% once the weights are the real ones.
            if (drop < 1e-6 || (s->pose_boost == 1.0 && drop < 1e-4)) {
                converged = true;
                break;
            }
            if (rep->iterations >= s->d.max_iterations) break;
        }
    }
    rep->stopped = time_up ? SP_STOP_TIME_CAP : (converged ? SP_STOP_CONVERGED : SP_STOP_MAX_ITERATIONS);
    // Final errors with fresh correspondences at the result.
    s->mode = s->ab->correspondence;
    s->pose_boost = s->vertex_boost = 1.0;
    sp_rig_eval_update(s->ev, p, false);
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
