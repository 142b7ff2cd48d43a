// setup.c: the solver's lifetime: the coarsening (paper eq. 12: k-means of
// the rest vertices), the column lists of the sparse Jacobian blocks, the
// row groups of the normal equations, and the buffers a solve uses.
#include <flann/flann.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "solver_internal.h"

// k-means of the rest vertices (FLANN), centres snapped to the nearest vertex.
// FLANN's hierarchical k-means returns (b - 1) m + 1 <= k clusters for a
// branching b: with b = 32, every k under 32 got one cluster (and the
// regularisers one vertex), 32..62 got 32. From k = 64 up, 32 gives at least
// k - 31 (the default 200: 187, the kiosk's 100: 94); below, the branching
// that comes closest to k, the largest of equals (k itself up to 32).
static int kmeans_branching(int k)
{
    if (k >= 64) return 32;
    int best = 2, best_got = 0;
    for (int b = 2; b <= 32; ++b) {
        int got = (b - 1) * ((k - 1) / (b - 1)) + 1;
        if (got >= best_got) best = b, best_got = got;
    }
    return best;
}

static int coarsen_kmeans(const double* rest_in, int n, int k, int* reps)
{
    double* rest = (double*)rest_in; // FLANN's C API only reads it but is not const-correct
    if (n <= k) {
        for (int i = 0; i < n; ++i)
            reps[i] = i;
        return n;
    }
    double* centers = malloc(sizeof(double) * 3 * (size_t)k);
    if (!centers) return 0;
    struct FLANNParameters fp = DEFAULT_FLANN_PARAMETERS;
    fp.algorithm = FLANN_INDEX_KMEANS;
    fp.branching = kmeans_branching(k);
    fp.iterations = 11;
    fp.centers_init = FLANN_CENTERS_KMEANSPP;
    fp.random_seed = 12345; // deterministic coarsening
    fp.log_level = FLANN_LOG_NONE;
    int got = flann_compute_cluster_centers_double(rest, n, 3, k, centers, &fp);
    if (got <= 0) {
        // Fallback: evenly spaced vertices.
        for (int i = 0; i < k; ++i)
            reps[i] = (int)((long long)i * n / k);
        free(centers);
        return k;
    }
    struct FLANNParameters ip = DEFAULT_FLANN_PARAMETERS;
    ip.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    ip.checks = -1; // exact search
    // One thread: FLANN's default searches with OpenMP on every core, whose
    // idle threads then spin (CPU taken from the kiosk's UI thread;
    // BENCHMARKS.md, "The dragon kiosk") for a search of a few hundred centres.
    ip.cores = 1;
    ip.log_level = FLANN_LOG_NONE;
    ip.random_seed = 12345;
    float speedup = 0;
    flann_index_t idx = flann_build_index_double(rest, n, 3, &speedup, &ip);
    double* dist = malloc(sizeof(double) * (size_t)got);
    int m = 0;
    if (idx && dist && flann_find_nearest_neighbors_index_double(idx, centers, got, reps, dist, 1, &ip) == 0) {
        // Two centres may snap to one vertex: keep each vertex once.
        qsort(reps, (size_t)got, sizeof(int), sp_cmp_int);
        for (int i = 0; i < got; ++i)
            if (m == 0 || reps[m - 1] != reps[i]) reps[m++] = reps[i];
    } else {
        for (int i = 0; i < got; ++i)
            reps[i] = (int)((long long)i * n / got);
        m = got;
    }
    if (idx) flann_free_index_double(idx, &ip);
    free(dist);
    free(centers);
    return m;
}

// The coarsening is a pure function of the mesh and k, and its k-means is
// most of loading a part: the kiosk loads each part twice (its attract
// screen's dragon and the visitor's), a part's line solver shares the mesh
// of its outline solver, and a curator's change reloads every part. So the
// last COARSEN_MEMO answers are remembered for the process, by a hash of
// the vertices (FNV-1a 64 over their bytes, with n and k).
#define COARSEN_MEMO 64
typedef struct coarsen_memo {
    uint64_t hash;
    int n, k, m;
    int* reps;
} coarsen_memo;
static struct {
    pthread_mutex_t lock;
    coarsen_memo e[COARSEN_MEMO];
    int next;
} g_memo = {PTHREAD_MUTEX_INITIALIZER, {{0}}, 0};

static uint64_t rest_hash(const double* rest, int n)
{
    uint64_t h = 1469598103934665603ull;
    const unsigned char* b = (const unsigned char*)rest;
    for (size_t i = 0; i < sizeof(double) * 3 * (size_t)n; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

// How much larger the mesh is in the world, at the default pose, than in
// its rest (bind-space) coordinates: the median, over the representatives,
// of the distance to the nearest other one there over here, which a bone's
// rotation leaves alone (a spread about the centroid would not). The
// reference size D must be in world units, where the strokes and the camera
// are; an armature scaled 10x or 100x (a unit conversion in an FBX export)
// keeps the vertices 10x or 100x smaller, and the regularisers, weighted by
// 1/D^2, then held a fit 100x or 10^4x too hard. A default pose that is the
// bind pose gives 1 up to a glTF's float rounding; within 5% is taken for 1,
// so that only a change of units is corrected and other rigs solve exactly
// as before.
static double bind_to_world_scale(sp_solver* s, sp_model* m)
{
    int k = s->k;
    if (k < 2) return 1.0;
    double* x = malloc(sizeof(double) * 3 * (size_t)k);
    double* p = malloc(sizeof(double) * (size_t)(m->P + 1));
    double* ratio = malloc(sizeof(double) * (size_t)k);
    if (!x || !p || !ratio) {
        free(x), free(p), free(ratio);
        return 1.0;
    }
    for (int i = 0; i < m->P; ++i)
        p[i] = m->params[i].def;
    m->ops->update(m, p, false);
    m->ops->rows(m, s->reps, k, x);
    int n = 0;
    for (int i = 0; i < k; ++i) {
        const double* ri = m->rest + 3 * s->reps[i];
        double best = INFINITY;
        int nearest = -1;
        for (int j = 0; j < k; ++j) {
            const double* rj = m->rest + 3 * s->reps[j];
            double d = (ri[0] - rj[0]) * (ri[0] - rj[0]) + (ri[1] - rj[1]) * (ri[1] - rj[1]) + (ri[2] - rj[2]) * (ri[2] - rj[2]);
            if (j != i && d > 0 && d < best) best = d, nearest = j;
        }
        if (nearest < 0) continue;
        const double *xi = x + 3 * i, *xj = x + 3 * nearest;
        double w = (xi[0] - xj[0]) * (xi[0] - xj[0]) + (xi[1] - xj[1]) * (xi[1] - xj[1]) + (xi[2] - xj[2]) * (xi[2] - xj[2]);
        ratio[n++] = sqrt(w / best);
    }
    double f = 1.0;
    if (n > 0) {
        qsort(ratio, (size_t)n, sizeof *ratio, sp_cmp_double);
        f = ratio[n / 2];
    }
    free(x), free(p), free(ratio);
    if (m->failed || !(isfinite(f) && f > 0)) return 1.0; // a black box that failed: the solve says why
    return fabs(f - 1) < 0.05 ? 1.0 : f;
}

static int coarsen(const double* rest, int n, int k, int* reps)
{
    uint64_t h = rest_hash(rest, n);
    int m = -1;
    pthread_mutex_lock(&g_memo.lock);
    for (int i = 0; i < COARSEN_MEMO && m < 0; ++i) {
        const coarsen_memo* e = &g_memo.e[i];
        if (e->reps && e->hash == h && e->n == n && e->k == k) memcpy(reps, e->reps, sizeof(int) * (size_t)(m = e->m));
    }
    pthread_mutex_unlock(&g_memo.lock);
    if (m >= 0) return m;
    m = coarsen_kmeans(rest, n, k, reps);
    int* keep = m > 0 ? malloc(sizeof(int) * (size_t)m) : NULL;
    if (!keep) return m; // not remembered: only the next load pays
    memcpy(keep, reps, sizeof(int) * (size_t)m);
    pthread_mutex_lock(&g_memo.lock);
    coarsen_memo* e = &g_memo.e[g_memo.next];
    g_memo.next = (g_memo.next + 1) % COARSEN_MEMO;
    free(e->reps);
    *e = (coarsen_memo){h, n, k, m, keep};
    pthread_mutex_unlock(&g_memo.lock);
    return m;
}

// OpenBLAS threads its small kernels by default and then spends most of a
// solve in sched_yield: our systems have at
// most a few hundred unknowns, so one BLAS thread is faster, and the solver's
// own parallel work (finite differences) must not be oversubscribed. Weak, so
// that any other CBLAS/LAPACKE implementation links too.
extern void openblas_set_num_threads(int n) __attribute__((weak));

sp_result sp_solver_create(const sp_rig* rig, int abstraction, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out,
                           sp_error* err)
{
    *out = NULL;
    if (abstraction < 0 || abstraction >= rig->abstraction_count)
        return sp_fail(err, SP_ERR_INVALID, "abstraction %d does not exist (the rig has %d)", abstraction,
                       rig->abstraction_count);
    return sp__solver_create_model(sp__model_lbs_create(rig, abstraction), cam, desc, out, err);
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
    for (int i = 0; i < l; ++i)
        total_cols += (size_t)s->ab_sb[i].count;
    s->groups = malloc(sizeof(row_group) * (size_t)(2 * l + s->k + 1));
    s->ab_grp = malloc(sizeof(int) * (size_t)(l + 1));
    s->rep_grp = malloc(sizeof(int) * (size_t)(s->k + 1));
    s->seg_grp = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_first = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_next = malloc(sizeof(int) * (size_t)(l + 1));
    s->seg_cols = malloc(sizeof(int) * (2 * total_cols + 1)); // a union holds at most a's and b's columns
    s->seg_map = malloc(sizeof(int) * (2 * total_cols + 1));
    if (!s->groups || !s->ab_grp || !s->rep_grp || !s->seg_grp || !s->seg_first || !s->seg_next || !s->seg_cols || !s->seg_map)
        return false;
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
    for (int g = 0; g < s->group_count; ++g)
        total += (size_t)s->groups[g].cap * (size_t)s->groups[g].n;
    s->group_pool = malloc(sizeof(double) * (total + 1));
    if (!s->group_pool) return false;
    double* pool = s->group_pool;
    for (int g = 0; g < s->group_count; ++g) {
        row_group* gr = &s->groups[g];
        gr->U = pool, pool += (size_t)gr->cap * (size_t)gr->n;
    }
    return true;
}

sp_result sp__solver_create_model(sp_model* m, const sp_camera* cam, const sp_solve_desc* desc, sp_solver** out, sp_error* err)
{
    if (openblas_set_num_threads) openblas_set_num_threads(1);
    *out = NULL;
    sp_solver* s = m ? calloc(1, sizeof *s) : NULL;
    if (!s) {
        if (m) m->ops->destroy(m);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making a solver");
    }
    s->model = m;
    s->one_stroke_curve = -1; // by shape (icp.c's attempts say otherwise)
    m->deadline_ms = INFINITY;
    s->ab = m->ab;
    s->cam = cam;
    s->d = desc ? *desc : (sp_solve_desc){0};
    if (s->d.lambda_pose == 0) s->d.lambda_pose = SP_LAMBDA_POSE;
    if (s->d.lambda_plane == 0) s->d.lambda_plane = SP_LAMBDA_PLANE;
    if (s->d.lambda_dist == 0) s->d.lambda_dist = SP_LAMBDA_DIST;
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
    if (!tmp || !s->ab_sb || !s->rep_sb || !s->reps) goto fail;
    sp_result prepared = m->ops->prepare(m, s->reps, s->k, err);
    if (prepared != SP_OK) {
        free(tmp);
        sp_solver_destroy(s);
        return prepared;
    }
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
    if (!s->z3 || !s->z2 || !s->Jz || !s->G || !s->x0 || !s->xr || !s->Jr || !s->dw || !s->view || !s->H || !s->g || !s->p0 ||
        !s->unit || !s->free_ || !s->Hl || !s->rows || !s->step_work || !s->step_iwork || !s->seg_mom || !s->seg_pairs ||
        !s->seg_list || !s->ab_used)
        goto fail;
    s->D *= bind_to_world_scale(s, m);
    for (int i = 0; i < s->P; ++i)
        s->unit[i] = m->params[i].length ? s->D / SP_REF_SIZE : 1.0;
    *out = s;
    return SP_OK;
fail:
    free(tmp);
    sp_solver_destroy(s);
    return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making a solver (%d parameters, %d abstraction points)", P, l);
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
