// Rig model tests: FK, skinning, analytic Jacobians against central
// differences, the TRS parameterisation, validation, cameras, animation.
#include <stdlib.h>
#include <string.h>

#include "fixtures.h"
#include "../../solver/src/model.h" // the LBS model's closed-form regularisers
#include "sp/rig.h"
#include "test.h"

// Central differences of the skinned points with respect to each parameter,
// step 1e-6 of the parameter's range (at least 1e-7).
static void numeric_jacobian(const sp_rig* rig, sp_skinned_points pts, const double* p, double* J)
{
    int P = rig->param_count, n = pts.count;
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* q = malloc(sizeof(double) * P);
    double* xp = malloc(sizeof(double) * 3 * n);
    double* xm = malloc(sizeof(double) * 3 * n);
    for (int k = 0; k < P; ++k) {
        double h = fmax(1e-7, 1e-6 * (rig->params[k].max - rig->params[k].min));
        memcpy(q, p, sizeof(double) * P);
        q[k] = p[k] + h;
        sp_rig_eval_update(ev, q, false);
        sp_rig_eval_points(ev, pts, xp);
        q[k] = p[k] - h;
        sp_rig_eval_update(ev, q, false);
        sp_rig_eval_points(ev, pts, xm);
        for (int i = 0; i < 3 * n; ++i) J[(size_t)i * P + k] = (xp[i] - xm[i]) / (2 * h);
    }
    free(q), free(xp), free(xm);
    sp_rig_eval_destroy(ev);
}

// Every column of the analytic Jacobian equals central differences to 1e-6
// relative (relative to the column's norm, floored at 1e-6 of the whole J).
static void check_jacobian(const sp_rig* rig, sp_skinned_points pts, const double* p)
{
    int P = rig->param_count, n = pts.count;
    double* Ja = malloc(sizeof(double) * 3 * n * P);
    double* Jn = malloc(sizeof(double) * 3 * n * P);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    sp_rig_eval_update(ev, p, true);
    sp_rig_eval_jacobian(ev, pts, NULL, n, Ja);
    numeric_jacobian(rig, pts, p, Jn);
    double total = 0;
    for (int i = 0; i < 3 * n * P; ++i) total += Jn[i] * Jn[i];
    total = sqrt(total);
    int nonzero_cols = 0;
    for (int k = 0; k < P; ++k) {
        double diff = 0, norm = 0;
        for (int i = 0; i < 3 * n; ++i) {
            double a = Ja[(size_t)i * P + k], b = Jn[(size_t)i * P + k];
            diff += (a - b) * (a - b);
            norm += b * b;
        }
        diff = sqrt(diff), norm = sqrt(norm);
        if (norm > 1e-9) ++nonzero_cols;
        if (!(diff <= 1e-6 * fmax(norm, 1e-6 * total))) {
            fprintf(stderr, "  column %d (%s): |analytic - numeric| = %.3g, |numeric| = %.3g\n", k, rig->params[k].name, diff, norm);
            ENSURE(diff <= 1e-6 * fmax(norm, 1e-6 * total));
        }
    }
    ENSURE(nonzero_cols > P / 2);
    // Requested rows give the same rows as the full Jacobian.
    int rows[3] = {n - 1, 0, n / 2};
    double* Jr = malloc(sizeof(double) * 9 * P);
    sp_rig_eval_jacobian(ev, pts, rows, 3, Jr);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < P; ++k) ENSURE(Jr[(size_t)(3 * r + c) * P + k] == Ja[(size_t)(3 * rows[r] + c) * P + k]);
    free(Jr), free(Ja), free(Jn);
    sp_rig_eval_destroy(ev);
}

static void test_jacobian_chain(void)
{
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        sp_rig rig;
        sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 5, .all_channels = true, .seed = seed, .ring_vertices = 6, .rings_per_bone = 3}, &rig);
        ENSURE(rig.param_count >= 5 * 3 + 4);
        sp_test_rng rng = {seed};
        double* p = malloc(sizeof(double) * rig.param_count);
        sp_fixture_random_params(&rig, &rng, 1.2, p);
        check_jacobian(&rig, sp_rig_mesh_points(&rig), p);
        sp_abstraction* a = &rig.abstractions[0];
        check_jacobian(&rig, (sp_skinned_points){a->point_count, a->rest, a->joints, a->weights}, p);
        free(p);
        sp_rig_free(&rig);
    }
}

static void test_jacobian_tree(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 14, .branching = true, .all_channels = true, .seed = 9, .ring_vertices = 5, .rings_per_bone = 3}, &rig);
    int depth_max = 0;
    for (int j = 0; j < rig.joint_count; ++j) {
        int d = 0;
        for (int a = j; a >= 0; a = rig.joints[a].parent) ++d;
        if (d > depth_max) depth_max = d;
    }
    ENSURE(depth_max >= 3);
    sp_test_rng rng = {42};
    double* p = malloc(sizeof(double) * rig.param_count);
    sp_fixture_random_params(&rig, &rng, 1.0, p);
    check_jacobian(&rig, sp_rig_mesh_points(&rig), p);
    free(p);
    sp_rig_free(&rig);
}

static void test_defaults_give_rest(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 6, .branching = true, .all_channels = true, .seed = 3}, &rig);
    double* p = malloc(sizeof(double) * rig.param_count);
    double* x = malloc(sizeof(double) * 3 * rig.vertex_count);
    sp_rig_defaults(&rig, p);
    sp_rig_eval* ev;
    sp_rig_eval_create(&rig, &ev, NULL);
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&rig), x);
    for (int i = 0; i < 3 * rig.vertex_count; ++i) ENSURE_NEAR(x[i], rig.rest[i], 1e-7); // weights are float
    sp_rig_eval_destroy(ev);
    free(p), free(x);
    sp_rig_free(&rig);
}

// FK equals a naive recursive product of glTF TRS matrices.
static void naive_world(const sp_rig* rig, const double* p, int j, sp_mat4* out)
{
    sp_vec3 t, s;
    sp_quat r;
    sp_rig_local_trs(rig, j, p, &t, &r, &s);
    sp_mat4 l = sp_mat4_trs(t, r, s);
    if (rig->joints[j].parent < 0) {
        *out = l;
        return;
    }
    sp_mat4 par;
    naive_world(rig, p, rig->joints[j].parent, &par);
    *out = sp_mat4_mul(&par, &l);
}

static void test_fk_naive(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 20, .branching = true, .all_channels = true, .seed = 5}, &rig);
    sp_test_rng rng = {5};
    double* p = malloc(sizeof(double) * rig.param_count);
    sp_fixture_random_params(&rig, &rng, 0.8, p);
    sp_rig_eval* ev;
    sp_rig_eval_create(&rig, &ev, NULL);
    sp_rig_eval_update(ev, p, false);
    for (int j = 0; j < rig.joint_count; ++j) {
        sp_mat4 w;
        naive_world(&rig, p, j, &w);
        for (int k = 0; k < 16; ++k) ENSURE_NEAR(sp_rig_eval_world(ev)[j].m[k], w.m[k], 1e-12);
    }
    sp_rig_eval_destroy(ev);
    free(p);
    sp_rig_free(&rig);
}

static void test_params_from_trs_roundtrip(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 6, .all_channels = true, .seed = 11}, &rig);
    sp_test_rng rng = {11};
    double* p = malloc(sizeof(double) * rig.param_count);
    double* q = malloc(sizeof(double) * rig.param_count);
    for (int it = 0; it < 50; ++it) {
        sp_fixture_random_params(&rig, &rng, 1.3, p); // |ry| < pi/2 keeps the Euler angles unique
        for (int j = 0; j < rig.joint_count; ++j) {
            sp_vec3 t, s;
            sp_quat r;
            sp_rig_local_trs(&rig, j, p, &t, &r, &s);
            sp_rig_params_from_trs(&rig, j, t, r, s, q);
        }
        for (int k = 0; k < rig.param_count; ++k) ENSURE_NEAR(q[k], p[k], 1e-9);
    }
    free(p), free(q);
    sp_rig_free(&rig);
}

static void test_finalize_checks(void)
{
    sp_rig rig;
    sp_error err = {0};
    // Weights that do not sum to one are renormalised and counted.
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 3, .seed = 1}, &rig);
    rig.weights4[0] *= 2.0f;
    rig.weights4[4] *= 0.5f;
    int renorm = -1;
    ENSURE(sp_rig_finalize(&rig, "t.gltf", &renorm, &err) == SP_OK);
    ENSURE(renorm == 2);
    ENSURE_NEAR(rig.weights4[0] + rig.weights4[1] + rig.weights4[2] + rig.weights4[3], 1.0, 1e-6);
    ENSURE(sp_rig_finalize(&rig, "t.gltf", &renorm, &err) == SP_OK && renorm == 0);
    // NaN position.
    double keep = rig.rest[4];
    rig.rest[4] = NAN;
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "t.gltf") && strstr(err.text, "vertex 1"));
    rig.rest[4] = keep;
    // Joint index out of range.
    rig.joints4[8] = 77;
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_ERR_INVALID);
    rig.joints4[8] = 0;
    // Scale parameter with a non-positive lower bound.
    int k = sp_rig_add_param(&rig, 1, SP_CH_S, 0.0, 2.0, SP_GROUP_SHAPE);
    ENSURE(k >= 0);
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "min > 0"));
    rig.params[sp_rig_find_param(&rig, "j1.s")].min = 0.5;
    sp_result fr = sp_rig_finalize(&rig, "t.gltf", NULL, &err);
    if (fr != SP_OK) fprintf(stderr, "  %s\n", err.text);
    ENSURE(fr == SP_OK);
    // Duplicate channel.
    sp_rig_add_param(&rig, 1, SP_CH_S, 0.5, 2.0, SP_GROUP_SHAPE);
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "twice"));
    int dup_at = sp_rig_find_param(&rig, "j1.s"); // sorted: the twin follows it
    memmove(&rig.params[dup_at], &rig.params[dup_at + 1], sizeof(sp_param) * (size_t)(rig.param_count - dup_at - 1));
    rig.param_count--;
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_OK);
    // Parent after child.
    rig.joints[1].parent = 2;
    ENSURE(sp_rig_finalize(&rig, "t.gltf", NULL, &err) == SP_ERR_INVALID);
    rig.joints[1].parent = 0;
    sp_rig_free(&rig);
}

static void test_clamp(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 3, .all_channels = true, .seed = 2}, &rig);
    double* p = malloc(sizeof(double) * rig.param_count);
    sp_rig_defaults(&rig, p);
    int s = sp_rig_find_param(&rig, "j0.s");
    p[0] = 100.0;
    p[1] = NAN;
    p[s] = -3.0;
    ENSURE(sp_rig_clamp(&rig, p) == 3);
    ENSURE(p[0] == rig.params[0].max && p[1] == rig.params[1].def && p[s] == rig.params[s].min && p[s] > 0);
    free(p);
    sp_rig_free(&rig);
}

static void check_camera_jacobian(const sp_camera* cam, sp_vec3 x)
{
    double J[6];
    sp_camera_jacobian(cam, x, J);
    for (int c = 0; c < 3; ++c) {
        double h = 1e-6;
        sp_vec3 a = x, b = x;
        (&a.x)[c] += h, (&b.x)[c] -= h;
        sp_vec2 pa = sp_camera_project(cam, a), pb = sp_camera_project(cam, b);
        ENSURE_NEAR(J[c], (pa.x - pb.x) / (2 * h), 1e-5 * fmax(1.0, fabs(J[c])));
        ENSURE_NEAR(J[3 + c], (pa.y - pb.y) / (2 * h), 1e-5 * fmax(1.0, fabs(J[3 + c])));
    }
}

static void test_cameras(void)
{
    sp_vec3 lo = {-1, 0, -0.5}, hi = {1, 2, 0.5};
    for (int kind = 0; kind < 2; ++kind) {
        sp_camera cam = sp_camera_frame((sp_camera_kind)kind, lo, hi, sp_v3(0, 0, -1), sp_v3(0, 1, 0), 640, 480);
        // The box's corners land inside the canvas, the centre in the middle, y down.
        for (int i = 0; i < 8; ++i) {
            sp_vec3 c = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
            sp_vec2 p = sp_camera_project(&cam, c);
            ENSURE(p.x > 0 && p.x < 640 && p.y > 0 && p.y < 480);
        }
        sp_vec2 top = sp_camera_project(&cam, sp_v3(0, 2, 0)), bottom = sp_camera_project(&cam, sp_v3(0, 0, 0));
        ENSURE(top.y < bottom.y);
        sp_vec2 ctr = sp_camera_project(&cam, sp_v3(0, 1, 0));
        ENSURE_NEAR(ctr.x, 320, 1e-6);
        ENSURE_NEAR(ctr.y, 240, 1e-6);
        check_camera_jacobian(&cam, sp_v3(0.3, 1.7, 0.2));
        check_camera_jacobian(&cam, sp_v3(-0.9, 0.1, -0.4));
        sp_vec3 v = sp_camera_view_dir(&cam, sp_v3(0, 1, 0));
        ENSURE_NEAR(v.z, -1.0, 1e-9);
        ENSURE_NEAR(sp_v3_len(sp_camera_view_dir(&cam, sp_v3(1, 2, 0))), 1.0, 1e-12);
    }
    // A side view along -X.
    sp_camera side = sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, lo, hi, sp_v3(-1, 0, 0), sp_v3(0, 1, 0), 100, 100);
    sp_vec3 v = sp_camera_view_dir(&side, sp_v3(0, 0, 0));
    ENSURE_NEAR(v.x, -1.0, 1e-9);
    check_camera_jacobian(&side, sp_v3(0.3, 1.0, 0.2));
}

static void test_animation_sampling(void)
{
    float times[3] = {0.0f, 1.0f, 2.0f};
    float tv[9] = {0, 0, 0, 2, 0, 0, 2, 4, 0};
    float rt[2] = {0.0f, 1.0f};
    float rv[8] = {0, 0, 0, 1, 0, 0, 1, 0}; // identity -> 180 degrees about z
    sp_anim_channel ch[2] = {{0, SP_ANIM_TRANSLATION, SP_INTERP_LINEAR, 3, times, tv}, {0, SP_ANIM_ROTATION, SP_INTERP_LINEAR, 2, rt, rv}};
    sp_animation an = {"a", 2.0, 2, ch};
    sp_vec3 t[1], s[1] = {{1, 1, 1}};
    sp_quat r[1];
    sp_animation_sample(&an, 0.5, t, r, s);
    ENSURE_NEAR(t[0].x, 1.0, 1e-9);
    ENSURE_NEAR(r[0].z, sin(3.14159265358979 / 4), 1e-6); // 90 degrees
    sp_animation_sample(&an, 1.5, t, r, s);
    ENSURE_NEAR(t[0].x, 2.0, 1e-9);
    ENSURE_NEAR(t[0].y, 2.0, 1e-9);
    sp_animation_sample(&an, 9.0, t, r, s); // clamped past the end
    ENSURE_NEAR(t[0].y, 4.0, 1e-9);
    ch[0].interp = SP_INTERP_STEP;
    sp_animation_sample(&an, 1.9, t, r, s);
    ENSURE_NEAR(t[0].x, 2.0, 1e-9);
    ENSURE_NEAR(t[0].y, 0.0, 1e-9);
}

// The LBS model's closed-form W_plane and W_dist (model_lbs.c: moments per
// pair of joints) against the sums over representatives they replace, built
// from the rig's own rows and Jacobian: energies, H (upper triangle) and g.
// Skin weights are scrambled to four influences with repeated joints and
// zeros, on a branching rig with translations and scales; viewing
// directions per representative (perspective) or one for all (orthographic,
// which the model stores factored).
static void check_regularisers(bool one_view)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 14, .branching = true, .all_channels = true, .seed = 5, .ring_vertices = 5, .rings_per_bone = 3}, &rig);
    sp_test_rng rng = {77};
    for (int v = 0; v < rig.vertex_count; v += 2) {
        for (int a = 0; a < 4; ++a) {
            rig.joints4[4 * v + a] = (uint16_t)(sp_test_uniform(&rng) * rig.joint_count);
            rig.weights4[4 * v + a] = sp_test_uniform(&rng) < 0.2 ? 0.0f : (float)sp_test_range(&rng, 0.1, 1.0);
        }
        if (v % 6 == 0) rig.joints4[4 * v + 1] = rig.joints4[4 * v]; // a joint listed twice
    }
    const int P = rig.param_count, k = rig.vertex_count / 3;
    int* reps = malloc(sizeof(int) * k);
    for (int i = 0; i < k; ++i) reps[i] = 3 * i;
    sp_model* m = sp__model_lbs_create(&rig, 0);
    ENSURE(m && m->ops->reg_normal && m->ops->prepare(m, reps, k, NULL) == SP_OK);
    double* p0 = malloc(sizeof(double) * P);
    double* p1 = malloc(sizeof(double) * P);
    double* d = malloc(sizeof(double) * k);
    sp_vec3* view = malloc(sizeof(sp_vec3) * k);
    sp_fixture_random_params(&rig, &rng, 0.8, p0);
    sp_fixture_random_params(&rig, &rng, 0.8, p1);
    for (int i = 0; i < k; ++i) {
        view[i] = one_view && i > 0 ? view[0] : sp_v3_norm((sp_vec3){sp_test_range(&rng, -1, 1), sp_test_range(&rng, -1, 1), sp_test_range(&rng, 0.5, 1)});
        d[i] = sp_test_uniform(&rng);
    }
    m->ops->update(m, p0, false);
    m->ops->reg_prepare(m, reps, k, view, d);
    m->ops->update(m, p1, true);
    const double wp = 0.7, wd = 1.3;
    double ep, ed;
    m->ops->reg_energy(m, &ep, &ed);
    double* H = calloc((size_t)P * P, sizeof(double));
    double* g = calloc(P, sizeof(double));
    m->ops->reg_normal(m, wp, wd, H, g);

    // The reference: per representative, from rows and the dense Jacobian.
    sp_rig_eval* ev;
    sp_rig_eval_create(&rig, &ev, NULL);
    double* x0 = malloc(sizeof(double) * 3 * k);
    double* x1 = malloc(sizeof(double) * 3 * k);
    double* J = malloc(sizeof(double) * 3 * k * P);
    sp_rig_eval_update(ev, p0, false);
    sp_rig_eval_rows(ev, sp_rig_mesh_points(&rig), reps, k, x0);
    sp_rig_eval_update(ev, p1, true);
    sp_rig_eval_rows(ev, sp_rig_mesh_points(&rig), reps, k, x1);
    sp_rig_eval_jacobian(ev, sp_rig_mesh_points(&rig), reps, k, J);
    double* Hr = calloc((size_t)P * P, sizeof(double));
    double* gr = calloc(P, sizeof(double));
    double epr = 0, edr = 0;
    for (int i = 0; i < k; ++i) {
        double r[3], v[3] = {view[i].x, view[i].y, view[i].z}, vr = 0;
        for (int c = 0; c < 3; ++c) r[c] = x1[3 * i + c] - x0[3 * i + c], vr += v[c] * r[c];
        epr += vr * vr;
        edr += d[i] * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        double W[3][3];
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) W[a][b] = wp * v[a] * v[b] + (a == b ? wd * d[i] : 0);
        const double* Ji = J + (size_t)3 * i * P;
        for (int q = 0; q < P; ++q)
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    gr[q] += Ji[a * P + q] * W[a][b] * r[b];
                    for (int s = q; s < P; ++s) Hr[q * P + s] += Ji[a * P + q] * W[a][b] * Ji[b * P + s];
                }
    }
    ENSURE(epr > 1e-3 && edr > 1e-3); // the poses differ
    ENSURE_NEAR(ep, epr, 1e-9 * epr);
    ENSURE_NEAR(ed, edr, 1e-9 * edr);
    double hmax = 0, gmax = 0;
    for (int q = 0; q < P * P; ++q) hmax = fmax(hmax, fabs(Hr[q]));
    for (int q = 0; q < P; ++q) gmax = fmax(gmax, fabs(gr[q]));
    for (int q = 0; q < P; ++q) {
        ENSURE_NEAR(g[q], gr[q], 1e-9 * gmax);
        for (int s = q; s < P; ++s) ENSURE_NEAR(H[q * P + s], Hr[q * P + s], 1e-9 * hmax);
    }
    free(H), free(g), free(Hr), free(gr), free(x0), free(x1), free(J), free(p0), free(p1), free(d), free(view), free(reps);
    sp_rig_eval_destroy(ev);
    m->ops->destroy(m);
    sp_rig_free(&rig);
}

static void test_regularisers_closed_form(void)
{
    check_regularisers(false);
    check_regularisers(true);
}

// Bounds of points: the box, a NaN coordinate passed over (as fmin and fmax
// do), a coordinate with no number NaN, no points the zero box.
static void test_bounds(void)
{
    sp_vec3 lo, hi;
    const double xyz[] = {1, -2, 3, -4, 5, NAN, 0.5, NAN, -6, 2, 0, 9};
    sp_bounds(xyz, 4, &lo, &hi);
    ENSURE(lo.x == -4 && lo.y == -2 && lo.z == -6 && hi.x == 2 && hi.y == 5 && hi.z == 9);
    sp_bounds(xyz + 3, 1, &lo, &hi);
    ENSURE(lo.x == -4 && hi.y == 5 && isnan(lo.z) && isnan(hi.z));
    const double first_nan[] = {NAN, 1, 1, 3, 2, 2};
    sp_bounds(first_nan, 2, &lo, &hi);
    ENSURE(lo.x == 3 && hi.x == 3 && lo.y == 1 && hi.y == 2);
    sp_bounds(xyz, 0, &lo, &hi);
    ENSURE(lo.x == 0 && lo.y == 0 && lo.z == 0 && hi.x == 0 && hi.y == 0 && hi.z == 0);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"jacobian_chain", test_jacobian_chain},
                                   {"jacobian_tree", test_jacobian_tree},
                                   {"defaults_give_rest", test_defaults_give_rest},
                                   {"fk_naive", test_fk_naive},
                                   {"params_from_trs_roundtrip", test_params_from_trs_roundtrip},
                                   {"finalize_checks", test_finalize_checks},
                                   {"clamp", test_clamp},
                                   {"cameras", test_cameras},
                                   {"animation_sampling", test_animation_sampling},
                                   {"regularisers_closed_form", test_regularisers_closed_form},
                                   {"bounds", test_bounds},
                                   {0}});
}
