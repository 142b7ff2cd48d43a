// model_lbs.c: the solver's model of a linear blend skinning rig (paper
// eq. 13): evaluation through sp_rig_eval and analytic Jacobians whose
// sparsity follows the skeleton (a point moves with the parameters of its
// influences and their ancestors).
#include <stdlib.h>
#include <string.h>

#include "model.h"

typedef struct lbs_model {
    sp_model base;
    const sp_rig* rig;
    sp_rig_eval* ev;
    sp_model_param* params;
    double* mesh;    // vertex_count * 3, for embedded abstractions only
    double* scratch; // 6 * P: a dense 3 x P Jacobian and one more for embedded points
} lbs_model;

static int cmp_int(const void* a, const void* b)
{
    return *(const int*)a - *(const int*)b;
}

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
    qsort(out, (size_t)n, sizeof(int), cmp_int);
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

static bool lbs_prepare(sp_model* m, const int* reps, int k)
{
    (void)m, (void)reps, (void)k;
    return true;
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

static void lbs_jacobians(sp_model* m, const int* reps, int k, const sparse_block* ab_sb, const int* ab_cols, double* Jz,
                          const sparse_block* rep_sb, const int* rep_cols, double* Jr)
{
    lbs_model* L = (lbs_model*)m;
    const sp_rig* rig = L->rig;
    const sp_abstraction* ab = m->ab;
    const int P = m->P;
    double* J = L->scratch; // 3 x P
    double* Jv = L->scratch + 3 * P;
    for (int i = 0; i < ab->point_count; ++i) {
        const sparse_block* sb = &ab_sb[i];
        if (ab->rest) {
            sp_skinned_points pts = {ab->point_count, ab->rest, ab->joints, ab->weights};
            sp_rig_eval_jacobian(L->ev, pts, &i, 1, J);
        } else {
            memset(J, 0, sizeof(double) * 3 * (size_t)P);
            for (int v = 0; v < 3; ++v) {
                int vi = (int)ab->tri_vertices[3 * i + v];
                double b = ab->bary[3 * i + v];
                if (b == 0.0) continue;
                sp_rig_eval_jacobian(L->ev, sp_rig_mesh_points(rig), &vi, 1, Jv);
                for (int c = 0; c < sb->count; ++c) {
                    int q = ab_cols[sb->first + c];
                    for (int r = 0; r < 3; ++r)
                        J[r * P + q] += b * Jv[r * P + q];
                }
            }
        }
        double* Jb = Jz + 3 * (size_t)sb->first;
        for (int c = 0; c < sb->count; ++c) {
            int q = ab_cols[sb->first + c];
            Jb[c] = J[q], Jb[sb->count + c] = J[P + q], Jb[2 * sb->count + c] = J[2 * P + q];
        }
    }
    for (int i = 0; i < k; ++i) {
        const sparse_block* sb = &rep_sb[i];
        sp_rig_eval_jacobian(L->ev, sp_rig_mesh_points(rig), &reps[i], 1, J);
        double* Jb = Jr + 3 * (size_t)sb->first;
        for (int c = 0; c < sb->count; ++c) {
            int q = rep_cols[sb->first + c];
            Jb[c] = J[q], Jb[sb->count + c] = J[P + q], Jb[2 * sb->count + c] = J[2 * P + q];
        }
    }
}

static void lbs_destroy(sp_model* m)
{
    lbs_model* L = (lbs_model*)m;
    if (!L) return;
    sp_rig_eval_destroy(L->ev);
    free(L->params), free(L->mesh), free(L->scratch);
    free(L);
}

static const sp_model_ops lbs_ops = {lbs_columns, lbs_prepare, lbs_update, lbs_abstraction, lbs_rows, lbs_jacobians, lbs_destroy};

sp_model* sp__model_lbs_create(const sp_rig* rig, int abstraction)
{
    if (abstraction < 0 || abstraction >= rig->abstraction_count) return NULL;
    lbs_model* L = calloc(1, sizeof *L);
    if (!L) return NULL;
    const sp_abstraction* ab = &rig->abstractions[abstraction];
    int P = rig->param_count > 0 ? rig->param_count : 1;
    L->rig = rig;
    L->ev = sp_rig_eval_create(rig);
    L->params = malloc(sizeof(sp_model_param) * (size_t)P);
    L->scratch = malloc(sizeof(double) * 6 * (size_t)P);
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
