// model_lbs.c: the solver's model of a linear blend skinning rig (paper
// eq. 13): evaluation through sp_rig_eval and analytic Jacobians whose
// sparsity follows the skeleton (a point moves with the parameters of its
// influences and their ancestors).
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "v4d.h"

// The regularisers in closed form (model.h's reg_* calls). A
// representative's displacement is r_i = sum_j w_ij (S_j - S0_j) x_i, with
// S_j joint j's skin matrix (rows 0..2), S0_j the same at the solve's start
// and x_i the homogeneous rest position, and its Jacobian column for a
// parameter q is sum_j w_ij E_qj x_i with E_qj = D_q S_j (eval.c). Any sum
// over representatives of a quadratic in r_i and its Jacobian is therefore a
// quadratic form in the 12 entries of those matrices, with one moment per
// pair of joints that share a representative:
//     W_plane: Kp_jk = sum_i w_ij w_ik (v_i (x) x_i)(v_i (x) x_i)^T  (12 x 12)
//     W_dist:  Ad_jk = sum_i w_ij w_ik d_i x_i x_i^T                  (4 x 4, times I_3)
// (with one viewing direction v, Kp_jk = v v^T (x) Ax_jk, Ax_jk the 4 x 4
// moment without d_i).
// Built once a solve, they make an energy or a Gauss-Newton H cost per pair
// of joints instead of per representative: the representatives' Jacobian
// rows dominated a dragon part's iteration.
typedef struct reg_lbs {
    int nj;                         // rig joints
    int* anc_first;                 // nj + 1: CSR of the parameters at or above each joint
    int* anc;                       //   (sorted): the columns of E_qj
    int* adj_first;                 // nj + 1: CSR of each joint's partners (itself included)
    int* adj_joint;                 //   partner joint
    int* adj_pair;                  //   its pair (moment) index
    int* reach_first;               // nj + 1: CSR of the parameters above any partner: the
    int* reach;                     //   columns joint j's H rows can touch (sorted)
    int pair_count;
    bool ortho;                     // one viewing direction v for all (orthographic cameras):
    double v[3];                    //   Kp_jk = v v^T (x) Ax_jk, 12x less to store and apply
    double* Kp;                     // pair_count * 144 (or Ax: pair_count * 16 when ortho)
    double* Ad;                     // pair_count * 16
    sp_mat4* skin0;                 // nj: skin matrices at reg_prepare
    double* E;                      // 12 per entry of anc: E_qj at the last update
    double* delta;                  // 12 per joint: S_j - S0_j
    double* u;                      // 12 per entry of a joint's reach: sum over partners of K E_rk
    int* pos;                       // P: a parameter's position in the current joint's reach
    int* to;                        // P: positions of a partner's parameters in that reach
} reg_lbs;

typedef struct lbs_model {
    sp_model base;
    const sp_rig* rig;
    sp_rig_eval* ev;
    sp_model_param* params;
    double* mesh;    // vertex_count * 3, for embedded abstractions only
    double* scratch; // 3 * P: a dense 3 x P Jacobian, zero between points (lbs_jacobians)
    reg_lbs reg;
} lbs_model;

// Parameters that move a point skinned to `joints`/`weights`: those of
// every influence joint and its ancestors, sorted, unique. Returns the count.
static int point_columns(const sp_rig* rig, const uint16_t* joints, const float* weights, int ninf, int* out)
{
    int n = 0;
    for (int k = 0; k < ninf; ++k) {
        if (weights[k] == 0.0f) continue;
        for (int a = joints[k]; a >= 0; a = rig->joints[a].parent)
            for (int q = 0; q < rig->joints[a].param_count; ++q)
                out[n++] = rig->joints[a].first_param + q;
    }
    qsort(out, (size_t)n, sizeof(int), sp_cmp_int);
    int u = 0;
    for (int i = 0; i < n; ++i)
        if (u == 0 || out[u - 1] != out[i]) out[u++] = out[i];
    return u;
}

static int lbs_columns(const sp_model* m, bool abstraction, int i, int* out)
{
    const lbs_model* L = (const lbs_model*)m;
    const sp_rig* rig = L->rig;
    const sp_abstraction* ab = m->ab;
    if (!abstraction) return point_columns(rig, rig->joints4 + 4 * i, rig->weights4 + 4 * i, 4, out);
    if (ab->rest) return point_columns(rig, ab->joints + 4 * i, ab->weights + 4 * i, 4, out);
    // An embedded point moves with its triangle's three vertices.
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

// A representative's influences with duplicate joints merged and zero
// weights dropped. Returns the count.
static int rep_influences(const sp_rig* rig, int v, int* j, double* w)
{
    int n = 0;
    for (int a = 0; a < 4; ++a) {
        double wa = rig->weights4[4 * v + a];
        if (wa == 0.0) continue;
        int ja = rig->joints4[4 * v + a], b = 0;
        while (b < n && j[b] != ja) ++b;
        if (b == n) j[n] = ja, w[n++] = 0;
        w[b] += wa;
    }
    return n;
}

static int cmp_pair(const void* a, const void* b)
{
    const int* x = a;
    const int* y = b;
    return x[0] != y[0] ? x[0] - y[0] : x[1] - y[1];
}

// The pair index of joints j and k (adjacency of j, binary search).
static int pair_index(const reg_lbs* R, int j, int k)
{
    int lo = R->adj_first[j], hi = R->adj_first[j + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (R->adj_joint[mid] == k) return R->adj_pair[mid];
        if (R->adj_joint[mid] < k) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

// Sorted union of the ancestor parameter lists of `joints` into out. Returns the count.
static int union_columns(const reg_lbs* R, const int* joints, int n, int* out, int P, unsigned char* mark)
{
    memset(mark, 0, (size_t)P);
    for (int a = 0; a < n; ++a)
        for (int t = R->anc_first[joints[a]]; t < R->anc_first[joints[a] + 1]; ++t) mark[R->anc[t]] = 1;
    int c = 0;
    for (int q = 0; q < P; ++q)
        if (mark[q]) out[c++] = q;
    return c;
}

// The pair structure of the representatives (fixed by the coarsening).
static sp_result lbs_prepare(sp_model* m, const int* reps, int k, sp_error* err)
{
    lbs_model* L = (lbs_model*)m;
    const sp_rig* rig = L->rig;
    reg_lbs* R = &L->reg;
    const int nj = rig->joint_count, P = m->P > 0 ? m->P : 1;
    R->nj = nj;
    // Ordered joint pairs of every representative, both orders: the adjacency.
    int* pairs = malloc(sizeof(int) * 2 * (16 * (size_t)k + 1));
    unsigned char* mark = malloc((size_t)P);
    R->anc_first = calloc((size_t)nj + 1, sizeof(int));
    R->adj_first = calloc((size_t)nj + 1, sizeof(int));
    R->reach_first = calloc((size_t)nj + 1, sizeof(int));
    R->anc = malloc(sizeof(int) * ((size_t)nj * (size_t)P + 1));
    R->skin0 = malloc(sizeof(sp_mat4) * ((size_t)nj + 1));
    R->delta = malloc(sizeof(double) * 12 * ((size_t)nj + 1));
    R->u = malloc(sizeof(double) * 12 * (size_t)P);
    R->pos = malloc(sizeof(int) * (size_t)P);
    R->to = malloc(sizeof(int) * (size_t)P);
    bool ok = pairs && mark && R->anc_first && R->adj_first && R->reach_first && R->anc && R->skin0 && R->delta && R->u && R->pos && R->to;
    if (!ok) goto done;
    int na = 0;
    for (int j = 0; j < nj; ++j) {
        R->anc_first[j] = na;
        for (int a = j; a >= 0; a = rig->joints[a].parent)
            for (int q = 0; q < rig->joints[a].param_count; ++q) R->anc[na++] = rig->joints[a].first_param + q;
        qsort(R->anc + R->anc_first[j], (size_t)(na - R->anc_first[j]), sizeof(int), sp_cmp_int);
    }
    R->anc_first[nj] = na;
    R->E = malloc(sizeof(double) * 12 * ((size_t)na + 1));
    int np = 0;
    for (int i = 0; i < k; ++i) {
        int jj[4];
        double ww[4];
        int n = rep_influences(rig, reps[i], jj, ww);
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) pairs[2 * np] = jj[a], pairs[2 * np + 1] = jj[b], ++np;
    }
    qsort(pairs, (size_t)np, 2 * sizeof(int), cmp_pair);
    int nu = 0;
    for (int i = 0; i < np; ++i)
        if (nu == 0 || cmp_pair(pairs + 2 * (nu - 1), pairs + 2 * i) != 0) pairs[2 * nu] = pairs[2 * i], pairs[2 * nu + 1] = pairs[2 * i + 1], ++nu;
    R->adj_joint = malloc(sizeof(int) * ((size_t)nu + 1));
    R->adj_pair = malloc(sizeof(int) * ((size_t)nu + 1));
    ok = R->E && R->adj_joint && R->adj_pair;
    if (!ok) goto done;
    // Unordered pairs (j <= k) get the moment indices; (k, j) shares (j, k)'s.
    R->pair_count = 0;
    for (int i = 0, j = 0; j <= nj; ++j) {
        R->adj_first[j] = i;
        while (j < nj && i < nu && pairs[2 * i] == j) {
            R->adj_joint[i] = pairs[2 * i + 1];
            R->adj_pair[i] = pairs[2 * i + 1] >= j ? R->pair_count++ : -1;
            ++i;
        }
    }
    for (int j = 0; j < nj; ++j)
        for (int i = R->adj_first[j]; i < R->adj_first[j + 1]; ++i)
            if (R->adj_pair[i] < 0) R->adj_pair[i] = pair_index(R, R->adj_joint[i], j);
    R->Kp = malloc(sizeof(double) * 144 * ((size_t)R->pair_count + 1));
    R->Ad = malloc(sizeof(double) * 16 * ((size_t)R->pair_count + 1));
    int* tmp = malloc(sizeof(int) * (size_t)P);
    int total = 0;
    ok = R->Kp && R->Ad && tmp;
    for (int pass = 0; ok && pass < 2; ++pass) {
        total = 0;
        for (int j = 0; j < nj; ++j) {
            int n = union_columns(R, R->adj_joint + R->adj_first[j], R->adj_first[j + 1] - R->adj_first[j], tmp, P, mark);
            R->reach_first[j] = total;
            if (pass) memcpy(R->reach + total, tmp, sizeof(int) * (size_t)n);
            total += n;
        }
        R->reach_first[nj] = total;
        if (!pass) ok = (R->reach = malloc(sizeof(int) * ((size_t)total + 1))) != NULL;
    }
    free(tmp);
    // Closed form or rows, by their multiply-adds per Gauss-Newton H: about
    // 100 per partner-parameter product K E (with one view direction; about
    // 200 with a perspective camera, which this does not know) and 12 per
    // entry of the joints' E u^T blocks, against 4 c (c + 1) + 60 c per
    // representative of c columns (its 4 rows, Jacobian and residuals). The
    // closed form's small products run slower than BLAS, hence the 1.5: the
    // measured break-even lies between the elephant's ratio and the cartoon
    // man's (BENCHMARKS.md, "Measurements behind the solver's constants and
    // stages").
    double closed_ops = 0, rows_ops = 0;
    for (int j = 0; ok && j < nj; ++j) {
        for (int i = R->adj_first[j]; i < R->adj_first[j + 1]; ++i) closed_ops += 100.0 * (R->anc_first[R->adj_joint[i] + 1] - R->anc_first[R->adj_joint[i]] + 1);
        if (R->adj_first[j] < R->adj_first[j + 1])
            closed_ops += 12.0 * (R->anc_first[j + 1] - R->anc_first[j]) * (R->reach_first[j + 1] - R->reach_first[j]);
    }
    int* cols = ok ? malloc(sizeof(int) * (12 * (size_t)P + 16)) : NULL;
    for (int i = 0; cols && i < k; ++i) {
        double c = lbs_columns(m, false, reps[i], cols);
        rows_ops += 4 * c * (c + 1) + 60 * c;
    }
    m->closed_reg = cols && 1.5 * closed_ops < rows_ops;
    free(cols);
done:
    free(pairs), free(mark);
    return ok ? SP_OK : sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making a solver (%d joints, %d representatives)", nj, k);
}

// Fills the moments for a solve starting at the current state.
static void lbs_reg_prepare(sp_model* m, const int* reps, int k, const sp_vec3* view, const double* d)
{
    lbs_model* L = (lbs_model*)m;
    const sp_rig* rig = L->rig;
    reg_lbs* R = &L->reg;
    memcpy(R->skin0, sp_rig_eval_skin(L->ev), sizeof(sp_mat4) * (size_t)R->nj);
    memset(R->Kp, 0, sizeof(double) * 144 * (size_t)R->pair_count);
    R->ortho = true;
    for (int i = 1; i < k && R->ortho; ++i) R->ortho = view[i].x == view[0].x && view[i].y == view[0].y && view[i].z == view[0].z;
    if (k > 0) R->v[0] = view[0].x, R->v[1] = view[0].y, R->v[2] = view[0].z;
    memset(R->Ad, 0, sizeof(double) * 16 * (size_t)R->pair_count);
    for (int i = 0; i < k; ++i) {
        int jj[4];
        double ww[4];
        int n = rep_influences(rig, reps[i], jj, ww);
        const double* x0 = rig->rest + 3 * (size_t)reps[i];
        double x[4] = {x0[0], x0[1], x0[2], 1.0}, v[3] = {view[i].x, view[i].y, view[i].z}, a[12], xx[16];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) a[4 * r + c] = v[r] * x[c];
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) xx[4 * r + c] = x[r] * x[c];
        for (int p = 0; p < n; ++p)
            for (int q = p; q < n; ++q) {
                int pi = pair_index(R, jj[p] < jj[q] ? jj[p] : jj[q], jj[p] < jj[q] ? jj[q] : jj[p]);
                double w = ww[p] * ww[q];
                double* A = R->Ad + 16 * (size_t)pi;
                for (int e = 0; e < 16; ++e) A[e] += w * d[i] * xx[e];
                if (R->ortho) {
                    double* X = R->Kp + 16 * (size_t)pi;
                    for (int e = 0; e < 16; ++e) X[e] += w * xx[e];
                    continue;
                }
                double* K = R->Kp + 144 * (size_t)pi;
                for (int e = 0; e < 12; ++e)
                    for (int f = 0; f < 12; ++f) K[12 * e + f] += w * a[e] * a[f];
            }
    }
}

// S_j - S0_j of every joint, as 12 row-major entries (rows 0..2).
static void reg_deltas(lbs_model* L)
{
    reg_lbs* R = &L->reg;
    const sp_mat4* S = sp_rig_eval_skin(L->ev);
    for (int j = 0; j < R->nj; ++j) {
        if (R->adj_first[j] == R->adj_first[j + 1]) continue;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) R->delta[12 * j + 4 * r + c] = S[j].m[4 * c + r] - R->skin0[j].m[4 * c + r];
    }
}

// y += wp Kp e + wd (I_3 (x) Ad) e for moment pair `pair`. With one view
// direction: Kp e = v (x) (Ax (v^T e)), 40 multiply-adds instead of 144.
static inline void apply_ortho(const double* restrict X, const double* restrict A, const double* restrict v, double wp, double wd,
                               const double* restrict e, double* restrict y)
{
    // Four lanes c = 0..3 at a time; X and A are symmetric (their columns
    // are their rows).
    sp_v4d e0, e1, e2, x[4], a[4];
    SP_V4D_LOAD(e0, e), SP_V4D_LOAD(e1, e + 4), SP_V4D_LOAD(e2, e + 8);
    SP_V4D_LOAD_COLS(x, X);
    SP_V4D_LOAD_COLS(a, A);
    sp_v4d sv = v[0] * e0 + v[1] * e1 + v[2] * e2;
    sp_v4d t = wp * (x[0] * sv[0] + x[1] * sv[1] + x[2] * sv[2] + x[3] * sv[3]);
    for (int r = 0; r < 3; ++r) {
        const double* er = e + 4 * r;
        sp_v4d out = v[r] * t + wd * (a[0] * er[0] + a[1] * er[1] + a[2] * er[2] + a[3] * er[3]);
        sp_v4d yr;
        SP_V4D_LOAD(yr, y + 4 * r);
        yr += out;
        memcpy(y + 4 * r, &yr, sizeof yr);
    }
}

static inline void apply_full(const double* restrict K, const double* restrict A, double wp, double wd, const double* restrict e,
                              double* restrict y)
{
    double out[12];
    for (int a = 0; a < 12; ++a) {
        const double* Ka = K + 12 * a;
        double sk = 0;
        for (int b = 0; b < 12; ++b) sk += Ka[b] * e[b];
        const double* Aa = A + 4 * (a & 3);
        const double* er = e + (a & ~3);
        out[a] = wp * sk + wd * (Aa[0] * er[0] + Aa[1] * er[1] + Aa[2] * er[2] + Aa[3] * er[3]);
    }
    for (int a = 0; a < 12; ++a) y[a] += out[a];
}

// y_i += (wp Kp + wd I_3 (x) Ad) e_i for n vectors e_i (12 apart) into
// y + 12 * to[i] (to NULL: y itself for every i).
static void reg_apply(const reg_lbs* R, int pair, double wp, double wd, const double* e, int n, const int* to, double* y)
{
    const double* A = R->Ad + 16 * (size_t)pair;
    if (R->ortho) {
        const double* X = R->Kp + 16 * (size_t)pair;
        for (int i = 0; i < n; ++i) apply_ortho(X, A, R->v, wp, wd, e + 12 * i, to ? y + 12 * to[i] : y);
    } else {
        const double* K = R->Kp + 144 * (size_t)pair;
        for (int i = 0; i < n; ++i) apply_full(K, A, wp, wd, e + 12 * i, to ? y + 12 * to[i] : y);
    }
}

// x^T M y for a symmetric 4 x 4 M.
static inline double form4(const double* x, const double* M, const double* y)
{
    double r = 0;
    for (int a = 0; a < 4; ++a) r += x[a] * (M[4 * a] * y[0] + M[4 * a + 1] * y[1] + M[4 * a + 2] * y[2] + M[4 * a + 3] * y[3]);
    return r;
}

static void lbs_reg_energy(sp_model* m, double* plane, double* dist)
{
    lbs_model* L = (lbs_model*)m;
    reg_lbs* R = &L->reg;
    reg_deltas(L);
    double ep = 0, ed = 0;
    for (int j = 0; j < R->nj; ++j)
        for (int i = R->adj_first[j]; i < R->adj_first[j + 1]; ++i) {
            const int k = R->adj_joint[i], pair = R->adj_pair[i];
            if (k < j) continue; // each unordered pair once, off-diagonal ones twice
            const double f = k == j ? 1.0 : 2.0;
            const double* dj = R->delta + 12 * j;
            const double* dk = R->delta + 12 * k;
            if (R->ortho) {
                // v^T Delta: the plane term's 4-vectors; the distance term row by row.
                double sj[4], sk[4];
                for (int c = 0; c < 4; ++c) {
                    sj[c] = R->v[0] * dj[c] + R->v[1] * dj[4 + c] + R->v[2] * dj[8 + c];
                    sk[c] = R->v[0] * dk[c] + R->v[1] * dk[4 + c] + R->v[2] * dk[8 + c];
                }
                const double* A = R->Ad + 16 * (size_t)pair;
                ep += f * form4(sj, R->Kp + 16 * (size_t)pair, sk);
                ed += f * (form4(dj, A, dk) + form4(dj + 4, A, dk + 4) + form4(dj + 8, A, dk + 8));
                continue;
            }
            double yp[12] = {0}, yd[12] = {0};
            reg_apply(R, pair, 1.0, 0.0, dk, 1, NULL, yp);
            reg_apply(R, pair, 0.0, 1.0, dk, 1, NULL, yd);
            for (int a = 0; a < 12; ++a) ep += f * dj[a] * yp[a], ed += f * dj[a] * yd[a];
        }
    *plane = ep, *dist = ed;
}

static void lbs_reg_normal(sp_model* m, double wp, double wd, double* H, double* g)
{
    lbs_model* L = (lbs_model*)m;
    reg_lbs* R = &L->reg;
    const int P = m->P;
    const sp_mat4* S = sp_rig_eval_skin(L->ev);
    const sp_mat4* D = sp_rig_eval_derivatives(L->ev);
    reg_deltas(L);
    // E_qj = D_q S_j (rows 0..2; S's bottom row is 0 0 0 1, D's is zero).
    for (int j = 0; j < R->nj; ++j) {
        if (R->adj_first[j] == R->adj_first[j + 1]) continue;
        const double* Sj = S[j].m;
        for (int t = R->anc_first[j]; t < R->anc_first[j + 1]; ++t) {
            const double* Dq = D[R->anc[t]].m;
            double* E = R->E + 12 * (size_t)t;
            // Column c of D_q S_j from D_q's columns (rows 0..3 at once, the
            // same sums in the same order), stored row-major.
            sp_v4d d[4];
            SP_V4D_LOAD_COLS(d, Dq);
            for (int c = 0; c < 4; ++c) {
                sp_v4d col = d[0] * Sj[4 * c] + d[1] * Sj[4 * c + 1] + d[2] * Sj[4 * c + 2] + d[3] * Sj[4 * c + 3];
                E[c] = col[0], E[4 + c] = col[1], E[8 + c] = col[2];
            }
        }
    }
    for (int j = 0; j < R->nj; ++j) {
        if (R->adj_first[j] == R->adj_first[j + 1]) continue;
        const int* reach = R->reach + R->reach_first[j];
        const int nr = R->reach_first[j + 1] - R->reach_first[j], na = R->anc_first[j + 1] - R->anc_first[j];
        int* to = R->to;
        for (int t = 0; t < nr; ++t) R->pos[reach[t]] = t;
        memset(R->u, 0, sizeof(double) * 12 * (size_t)nr);
        double h[12] = {0};
        for (int i = R->adj_first[j]; i < R->adj_first[j + 1]; ++i) {
            const int k = R->adj_joint[i], pair = R->adj_pair[i];
            reg_apply(R, pair, wp, wd, R->delta + 12 * k, 1, NULL, h);
            const int a0 = R->anc_first[k], nk = R->anc_first[k + 1] - a0;
            for (int t = 0; t < nk; ++t) to[t] = R->pos[R->anc[a0 + t]];
            reg_apply(R, pair, wp, wd, R->E + 12 * (size_t)a0, nk, to, R->u);
        }
        // This joint's rows: g_q += E_qj . h and H_qr += E_qj . u_r (r >= q).
        // Only the upper triangle is needed, 12 products a dot: written out
        // as three four-lane products. (One dgemm E_j u^T for the whole block
        // computed both triangles, and its per-call setup and zeroing were
        // most of its cost at these sizes; BENCHMARKS.md, "Solver: the
        // paper's Table 1".)
        const double* Ej = R->E + 12 * (size_t)R->anc_first[j];
        int s0 = 0;
        for (int t = 0; t < na; ++t) {
            const int q = R->anc[R->anc_first[j] + t];
            const double* E = Ej + 12 * t;
            double gq = 0;
            for (int a = 0; a < 12; ++a) gq += E[a] * h[a];
            g[q] += gq;
            while (s0 < nr && reach[s0] < q) ++s0; // anc is sorted too
            double* Hq = H + (size_t)q * (size_t)P;
            sp_v4d e0, e1, e2;
            SP_V4D_LOAD(e0, E), SP_V4D_LOAD(e1, E + 4), SP_V4D_LOAD(e2, E + 8);
            for (int s = s0; s < nr; ++s) {
                const double* us = R->u + 12 * (size_t)s;
                sp_v4d u0, u1, u2;
                SP_V4D_LOAD(u0, us), SP_V4D_LOAD(u1, us + 4), SP_V4D_LOAD(u2, us + 8);
                sp_v4d m = e0 * u0 + e1 * u1 + e2 * u2;
                Hq[reach[s]] += (m[0] + m[1]) + (m[2] + m[3]);
            }
        }
    }
}

static void lbs_update(sp_model* m, const double* p, bool derivatives)
{
    lbs_model* L = (lbs_model*)m;
    sp_rig_eval_update(L->ev, p, derivatives);
}

static void lbs_abstraction(sp_model* m, double* z3)
{
    lbs_model* L = (lbs_model*)m;
    if (!m->ab->rest) sp_rig_eval_points(L->ev, sp_rig_mesh_points(L->rig), L->mesh);
    sp_rig_eval_abstraction(L->ev, m->ab, L->mesh, z3);
}

static void lbs_rows(sp_model* m, const int* rows, int n, double* xyz)
{
    lbs_model* L = (lbs_model*)m;
    sp_rig_eval_rows(L->ev, sp_rig_mesh_points(L->rig), rows, n, xyz);
}

// Gathers point columns `cols` of the dense 3 x P scratch J into the block
// Jb and clears them, leaving J all zero again (it starts zeroed): the
// scratch is never cleared whole, which cost more than the Jacobian itself
// on the 92-parameter cartoon man.
static void gather_clear(double* J, int P, const int* cols, int n, double* Jb)
{
    for (int c = 0; c < n; ++c) {
        int q = cols[c];
        Jb[c] = J[q], Jb[n + c] = J[P + q], Jb[2 * n + c] = J[2 * P + q];
        J[q] = J[P + q] = J[2 * P + q] = 0.0;
    }
}

static void lbs_jacobians(sp_model* m, const int* reps, int k, const sparse_block* ab_sb, const int* ab_cols, const bool* ab_used,
                          double* Jz, const sparse_block* rep_sb, const int* rep_cols, double* Jr)
{
    lbs_model* L = (lbs_model*)m;
    const sp_rig* rig = L->rig;
    const sp_abstraction* ab = m->ab;
    const int P = m->P;
    double* J = L->scratch; // 3 x P, all zero between points
    for (int i = 0; i < ab->point_count; ++i) {
        const sparse_block* sb = &ab_sb[i];
        if (ab_used && !ab_used[i]) continue;
        if (ab->rest) {
            sp_skinned_points pts = {ab->point_count, ab->rest, ab->joints, ab->weights};
            sp_rig_eval_jacobian_add(L->ev, pts, i, 1.0, J);
        } else {
            // An embedded point: its triangle's vertices by barycentric weight.
            for (int v = 0; v < 3; ++v) {
                double b = ab->bary[3 * i + v];
                if (b != 0.0) sp_rig_eval_jacobian_add(L->ev, sp_rig_mesh_points(rig), (int)ab->tri_vertices[3 * i + v], b, J);
            }
        }
        gather_clear(J, P, ab_cols + sb->first, sb->count, Jz + 3 * (size_t)sb->first);
    }
    for (int i = 0; i < k; ++i) {
        const sparse_block* sb = &rep_sb[i];
        sp_rig_eval_jacobian_add(L->ev, sp_rig_mesh_points(rig), reps[i], 1.0, J);
        gather_clear(J, P, rep_cols + sb->first, sb->count, Jr + 3 * (size_t)sb->first);
    }
}

static void lbs_destroy(sp_model* m)
{
    lbs_model* L = (lbs_model*)m;
    if (!L) return;
    sp_rig_eval_destroy(L->ev);
    free(L->params), free(L->mesh), free(L->scratch);
    reg_lbs* R = &L->reg;
    free(R->anc_first), free(R->anc), free(R->adj_first), free(R->adj_joint), free(R->adj_pair), free(R->reach_first), free(R->reach);
    free(R->Kp), free(R->Ad), free(R->skin0), free(R->E), free(R->delta), free(R->u), free(R->pos), free(R->to);
    free(L);
}

static const sp_model_ops lbs_ops = {lbs_columns,   lbs_prepare, lbs_update,      lbs_abstraction, lbs_rows,
                                     lbs_jacobians, lbs_destroy, lbs_reg_prepare, lbs_reg_energy,  lbs_reg_normal};

sp_model* sp__model_lbs_create(const sp_rig* rig, int abstraction)
{
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return NULL;
    lbs_model* L = calloc(1, sizeof *L);
    if (!L) return NULL;
    const sp_abstraction* ab = &rig->abstractions[abstraction];
    int P = rig->param_count > 0 ? rig->param_count : 1;
    L->rig = rig;
    sp_rig_eval_create(rig, &L->ev, NULL);
    L->params = malloc(sizeof(sp_model_param) * (size_t)P);
    L->scratch = calloc(3 * (size_t)P, sizeof(double));
    L->mesh = ab->rest ? NULL : malloc(sizeof(double) * 3 * (size_t)(rig->vertex_count + 1));
    if (!L->ev || !L->params || !L->scratch || (!ab->rest && !L->mesh)) {
        lbs_destroy(&L->base);
        return NULL;
    }
    for (int i = 0; i < rig->param_count; ++i) {
        const sp_param* q = &rig->params[i];
        L->params[i] = (sp_model_param){q->min, q->max, q->def, q->channel >= SP_CH_TX && q->channel <= SP_CH_TZ};
    }
    // The root's parameters come first (parameters are ordered by joint);
    // they form the placement stage when they translate or scale it.
    int root_joint = rig->param_count > 0 ? rig->params[0].joint : -1, n = 0;
    bool has_placement = false;
    for (; n < rig->param_count && rig->params[n].joint == root_joint; ++n)
        has_placement |= !sp_channel_is_rotation(rig->params[n].channel);
    L->base = (sp_model){.ops = &lbs_ops,
                         .P = rig->param_count,
                         .params = L->params,
                         .vertex_count = rig->vertex_count,
                         .rest = rig->rest,
                         .ab = ab,
                         .embedded = ab->rest == NULL,
                         .placement_count = has_placement ? n : 0};
    return &L->base;
}
