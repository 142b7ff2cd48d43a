// eval.c: forward kinematics, linear blend skinning (paper eq. 13) and its
// analytic Jacobian.
//
// The Jacobian rests on one identity. For a parameter k on joint a, every
// descendant world transform changes as dG_j/dp_k = D_k * G_j with
//     D_k = G_parent(a) * (dL_a/dp_k * L_a^-1) * G_parent(a)^-1,
// so for a skinned point x = sum_j w_j * G_j * IBM_j * x0 = sum_j w_j * y_j,
//     dx/dp_k = D_k applied to sum_{j below a} w_j * (y_j, 1).
// D_k is affine with a zero bottom row; its local factor E = dL * L^-1 has a
// closed form per channel (below), which needs no matrix inverse of L.
#include <stdlib.h>
#include <string.h>

#include "sp/rig.h"
#include "v4d.h"

struct sp_rig_eval {
    const sp_rig* rig;
    sp_mat4* local;  // joint_count
    sp_mat4* world;  // joint_count
    sp_mat4* skin;   // joint_count
    sp_mat4* deriv;  // param_count: D_k (rows 0..2 used)
    bool has_deriv;
};

sp_result sp_rig_eval_create(const sp_rig* rig, sp_rig_eval** out, sp_error* err)
{
    *out = NULL;
    sp_rig_eval* ev = calloc(1, sizeof *ev);
    if (!ev) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making a rig evaluator");
    size_t nj = (size_t)rig->joint_count, np = (size_t)(rig->param_count > 0 ? rig->param_count : 1);
    ev->rig = rig;
    ev->local = malloc(sizeof(sp_mat4) * nj);
    ev->world = malloc(sizeof(sp_mat4) * nj);
    ev->skin = malloc(sizeof(sp_mat4) * nj);
    ev->deriv = malloc(sizeof(sp_mat4) * np);
    double* p = malloc(sizeof(double) * np);
    if (!ev->local || !ev->world || !ev->skin || !ev->deriv || !p) {
        free(p);
        sp_rig_eval_destroy(ev);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory making a rig evaluator (%d joints)", rig->joint_count);
    }
    sp_rig_defaults(rig, p);
    sp_rig_eval_update(ev, p, false);
    free(p);
    *out = ev;
    return SP_OK;
}

void sp_rig_eval_destroy(sp_rig_eval* ev)
{
    if (!ev) return;
    free(ev->local);
    free(ev->world);
    free(ev->skin);
    free(ev->deriv);
    free(ev);
}

const sp_mat4* sp_rig_eval_world(const sp_rig_eval* ev) { return ev->world; }
const sp_mat4* sp_rig_eval_skin(const sp_rig_eval* ev) { return ev->skin; }
const sp_mat4* sp_rig_eval_derivatives(const sp_rig_eval* ev) { return ev->deriv; }

// Skew matrix [a]x with translation c, as an affine 4x4 with zero bottom row.
static sp_mat4 affine_skew(sp_vec3 a, sp_vec3 c)
{
    sp_mat4 e = {{0}};
    e.m[1] = a.z, e.m[2] = -a.y;  // column 0
    e.m[4] = -a.z, e.m[6] = a.x;  // column 1
    e.m[8] = a.y, e.m[9] = -a.x;  // column 2
    e.m[12] = c.x, e.m[13] = c.y, e.m[14] = c.z;
    return e;
}

// E = dL/dp * L^-1 for one channel, in the parent's frame.
static sp_mat4 local_derivative(const sp_joint* jt, const double* ch, sp_channel c, sp_vec3 t, sp_quat r)
{
    sp_mat4 e = {{0}};
    switch (c) {
    case SP_CH_TX: case SP_CH_TY: case SP_CH_TZ:
        e.m[12] = c == SP_CH_TX, e.m[13] = c == SP_CH_TY, e.m[14] = c == SP_CH_TZ;
        return e;
    case SP_CH_RX: case SP_CH_RY: case SP_CH_RZ: {
        // dR * R^-1 = [axis]x with the axis rotated by every factor before it.
        sp_quat q = jt->rest_r;
        if (c >= SP_CH_RY) q = sp_quat_mul(q, sp_quat_axis_angle((sp_vec3){1, 0, 0}, ch[SP_CH_RX]));
        if (c >= SP_CH_RZ) q = sp_quat_mul(q, sp_quat_axis_angle((sp_vec3){0, 1, 0}, ch[SP_CH_RY]));
        sp_vec3 axis = sp_quat_rotate(q, (sp_vec3){c == SP_CH_RX, c == SP_CH_RY, c == SP_CH_RZ});
        // T [a]x T^-1: translation -a x t.
        return affine_skew(axis, sp_v3_scale(sp_v3_cross(axis, t), -1.0));
    }
    default: {
        // T R diag(g) R^-1 T^-1 with g = dS * S^-1 (1/factor on the scaled axes).
        double f = ch[c];
        sp_vec3 g = {0, 0, 0};
        if (c == SP_CH_SX) g.x = 1.0 / f;
        else if (c == SP_CH_SY) g.y = 1.0 / f;
        else if (c == SP_CH_SZ) g.z = 1.0 / f;
        else g = (sp_vec3){1.0 / f, 1.0 / f, 1.0 / f};
        sp_mat4 rot = sp_mat4_trs((sp_vec3){0, 0, 0}, r, (sp_vec3){1, 1, 1});
        double gk[3] = {g.x, g.y, g.z};
        // (R diag(g) R^T)[row][col] = sum_k R[row][k] g_k R[col][k], R[row][k] = rot.m[k*4 + row].
        for (int col = 0; col < 3; ++col)
            for (int row = 0; row < 3; ++row)
                for (int k = 0; k < 3; ++k) e.m[col * 4 + row] += rot.m[k * 4 + row] * gk[k] * rot.m[k * 4 + col];
        sp_vec3 mt = sp_mat4_dir(&e, t);
        e.m[12] = -mt.x, e.m[13] = -mt.y, e.m[14] = -mt.z;
        return e;
    }
    }
}

void sp_rig_eval_update(sp_rig_eval* ev, const double* p, bool derivatives)
{
    const sp_rig* rig = ev->rig;
    for (int j = 0; j < rig->joint_count; ++j) {
        const sp_joint* jt = &rig->joints[j];
        sp_vec3 t, s;
        sp_quat r;
        sp_rig_local_trs(rig, j, p, &t, &r, &s);
        ev->local[j] = sp_mat4_trs(t, r, s);
        ev->world[j] = jt->parent < 0 ? ev->local[j] : sp_mat4_mul(&ev->world[jt->parent], &ev->local[j]);
        ev->skin[j] = sp_mat4_mul(&ev->world[j], &jt->inverse_bind);
        if (!derivatives || jt->param_count == 0) continue;
        double ch[SP_CH_COUNT] = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1};
        for (int i = 0; i < jt->param_count; ++i) ch[rig->params[jt->first_param + i].channel] = p[jt->first_param + i];
        sp_mat4 par = sp_mat4_identity(), par_inv = sp_mat4_identity();
        if (jt->parent >= 0) {
            par = ev->world[jt->parent];
            sp_mat4_inverse(&par, &par_inv);
        }
        for (int i = 0; i < jt->param_count; ++i) {
            int k = jt->first_param + i;
            sp_mat4 e = local_derivative(jt, ch, rig->params[k].channel, t, r);
            sp_mat4 pe = sp_mat4_mul(&par, &e);
            ev->deriv[k] = sp_mat4_mul(&pe, &par_inv);
        }
    }
    ev->has_deriv = derivatives;
}

static inline void skin_one(const sp_rig_eval* ev, sp_skinned_points pts, int i, double* out)
{
    const double* x0 = pts.rest + 3 * (size_t)i;
    sp_v4d acc = SP_V4D_SPLAT(0.0);
    for (int k = 0; k < SP_INFLUENCES; ++k) {
        float w = pts.weights[4 * i + k];
        if (w == 0.0f) continue;
        sp_v4d y;
        SP_V4D_MAT4_POINT(y, ev->skin[pts.joints[4 * i + k]].m, x0);
        acc += (double)w * y;
    }
    out[0] = acc[0], out[1] = acc[1], out[2] = acc[2];
}

void sp_rig_eval_points(const sp_rig_eval* ev, sp_skinned_points pts, double* out)
{
    for (int i = 0; i < pts.count; ++i) skin_one(ev, pts, i, out + 3 * i);
}

void sp_rig_eval_rows(const sp_rig_eval* ev, sp_skinned_points pts, const int* rows, int nrows, double* out)
{
    for (int r = 0; r < nrows; ++r) skin_one(ev, pts, rows ? rows[r] : r, out + 3 * r);
}

void sp_rig_eval_jacobian_add(const sp_rig_eval* ev, sp_skinned_points pts, int i, double scale, double* J)
{
    const sp_rig* rig = ev->rig;
    const int P = rig->param_count;
    if (P == 0 || !ev->has_deriv) return;
    const double* x0 = pts.rest + 3 * (size_t)i;
    double* jx = J;
    double* jy = jx + P;
    double* jz = jy + P;
    // dx/dp_q = D_q (sum of w_j (y_j, 1) over the influences j at or below
    // q's joint): the influences' sums are carried up the skeleton together,
    // deepest joint first (parents precede children), so that an ancestor
    // shared by several influences is applied once, not once per influence.
    int joint[SP_INFLUENCES], n = 0;
    double acc[SP_INFLUENCES][4];
    for (int k = 0; k < SP_INFLUENCES; ++k) {
        double w = scale * pts.weights[4 * i + k];
        if (w == 0.0) continue;
        sp_v4d y; // as skin_one
        SP_V4D_MAT4_POINT(y, ev->skin[pts.joints[4 * i + k]].m, x0);
        joint[n] = pts.joints[4 * i + k];
        acc[n][0] = w * y[0], acc[n][1] = w * y[1], acc[n][2] = w * y[2], acc[n][3] = w;
        ++n;
    }
    while (n > 0) {
        int a = joint[0];
        for (int k = 1; k < n; ++k)
            if (joint[k] > a) a = joint[k];
        double Y[4] = {0, 0, 0, 0};
        for (int k = 0; k < n;) {
            if (joint[k] != a) {
                ++k;
                continue;
            }
            for (int c = 0; c < 4; ++c) Y[c] += acc[k][c];
            --n;
            joint[k] = joint[n];
            memcpy(acc[k], acc[n], sizeof acc[k]);
        }
        const sp_joint* ja = &rig->joints[a];
        const sp_v4d y0 = SP_V4D_SPLAT(Y[0]), y1 = SP_V4D_SPLAT(Y[1]), y2 = SP_V4D_SPLAT(Y[2]), y3 = SP_V4D_SPLAT(Y[3]);
        for (int q = ja->first_param; q < ja->first_param + ja->param_count; ++q) {
            // D_q Y as D_q's four columns (column-major) times Y's entries:
            // the same sums in the same order as row by row, all rows at
            // once (the fourth is zero).
            sp_v4d c[4];
            SP_V4D_LOAD_COLS(c, ev->deriv[q].m);
            sp_v4d v = c[0] * y0 + c[1] * y1 + c[2] * y2 + c[3] * y3;
            jx[q] += v[0], jy[q] += v[1], jz[q] += v[2];
        }
        if (ja->parent >= 0) {
            joint[n] = ja->parent;
            memcpy(acc[n], Y, sizeof Y);
            ++n;
        }
    }
}

void sp_rig_eval_jacobian(const sp_rig_eval* ev, sp_skinned_points pts, const int* rows, int nrows, double* J)
{
    const int P = ev->rig->param_count;
    memset(J, 0, sizeof(double) * 3 * (size_t)nrows * (size_t)P);
    for (int r = 0; r < nrows; ++r) sp_rig_eval_jacobian_add(ev, pts, rows ? rows[r] : r, 1.0, J + (size_t)(3 * r) * P);
}

void sp_rig_eval_abstraction(const sp_rig_eval* ev, const sp_abstraction* a, const double* mesh_xyz, double* out)
{
    if (a->rest) {
        sp_skinned_points pts = {a->point_count, a->rest, a->joints, a->weights};
        sp_rig_eval_points(ev, pts, out);
        return;
    }
    for (int i = 0; i < a->point_count; ++i) {
        double x = 0, y = 0, z = 0;
        for (int k = 0; k < 3; ++k) {
            const double* v = mesh_xyz + 3 * (size_t)a->tri_vertices[3 * i + k];
            double b = a->bary[3 * i + k];
            x += b * v[0], y += b * v[1], z += b * v[2];
        }
        out[3 * i] = x, out[3 * i + 1] = y, out[3 * i + 2] = z;
    }
}
