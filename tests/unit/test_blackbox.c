// test_blackbox.c: black-box rigs (sp/blackbox.h): finite-difference
// Jacobians against the analytic ones of a skinned rig wrapped as a black
// box, bit-identical results for any thread count, the plugin loader's
// errors, recovery of seeded targets on the `face` plugin with bounds
// honoured, and the commands on a plugin (`sketchpose synth/pose/inspect/
// render/export --rig face.so`; drawover and animate refuse one).
#include <elf.h>
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>

#include "fixtures.h"
#include "sp/blackbox.h"
#include "sp/plugin.h"
#include "sp/solver.h"
#include "sp/synth.h"
#include "test.h"

#define PI 3.14159265358979323846

// ---------------------------------------------------------------- an LBS rig as a black box

typedef struct lbs_box {
    sp_blackbox_rig desc;
    const sp_rig* rig;
    sp_blackbox_param params[256];
    sp_blackbox_curve curves[SP_REPORT_CURVES];
    sp_blackbox_abstraction ab;
    double* rest;
    atomic_int out_of_bounds; // evaluations asked for outside the bounds
    atomic_int calls;
    bool short_write; // evaluate() leaves the last abstraction point unwritten
    int sleep_ms;     // each evaluate() takes at least this long
} lbs_box;

static int lbs_evaluate(void* user, const double* p, double* x, double* z)
{
    lbs_box* b = user;
    atomic_fetch_add(&b->calls, 1);
    if (b->sleep_ms > 0) nanosleep(&(struct timespec){0, b->sleep_ms * 1000000L}, NULL);
    for (int k = 0; k < b->rig->param_count; ++k)
        if (p[k] < b->rig->params[k].min || p[k] > b->rig->params[k].max) atomic_fetch_add(&b->out_of_bounds, 1);
    // An evaluator per call: the black-box contract allows concurrent calls.
    sp_rig_eval* ev;
    sp_rig_eval_create(b->rig, &ev, NULL);
    if (!ev) return 1;
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(b->rig), x);
    const sp_abstraction* a = &b->rig->abstractions[0];
    double* all = z && b->short_write ? malloc(sizeof(double) * 3 * (size_t)a->point_count) : NULL;
    if (all) {
        sp_rig_eval_abstraction(ev, a, x, all);
        memcpy(z, all, sizeof(double) * 3 * (size_t)(a->point_count - 1));
        free(all);
    } else if (z) {
        sp_rig_eval_abstraction(ev, a, x, z);
    }
    sp_rig_eval_destroy(ev);
    return 0;
}

// Wraps abstraction 0 of a finalized rig (the box must stay where it is).
static void lbs_box_init(lbs_box* b, const sp_rig* rig)
{
    memset(b, 0, sizeof *b);
    b->rig = rig;
    ENSURE(rig->param_count <= 256);
    for (int k = 0; k < rig->param_count; ++k) {
        const sp_param* q = &rig->params[k];
        int unit = sp_channel_is_rotation(q->channel) ? SP_BB_UNIT_ANGLE
                                                      : (sp_channel_is_scale(q->channel) ? SP_BB_UNIT_FACTOR : SP_BB_UNIT_LENGTH);
        b->params[k] = (sp_blackbox_param){q->name, q->min, q->max, q->def, q->group, unit};
    }
    const sp_abstraction* a = &rig->abstractions[0];
    for (int c = 0; c < a->curve_count; ++c)
        b->curves[c] = (sp_blackbox_curve){a->curves[c].name, a->curves[c].point_count, a->curves[c].closed};
    b->ab = (sp_blackbox_abstraction){a->name, a->correspondence, a->curve_count, b->curves};
    b->rest = malloc(sizeof(double) * 3 * (size_t)rig->vertex_count);
    double* p = malloc(sizeof(double) * (size_t)rig->param_count);
    sp_rig_defaults(rig, p);
    ENSURE(lbs_evaluate(b, p, b->rest, NULL) == 0);
    free(p);
    b->desc = (sp_blackbox_rig){.abi_version = SP_BLACKBOX_ABI_VERSION,
                                .struct_size = sizeof(sp_blackbox_rig),
                                .name = "lbs",
                                .param_count = rig->param_count,
                                .params = b->params,
                                .vertex_count = rig->vertex_count,
                                .rest = b->rest,
                                .triangle_count = rig->triangle_count,
                                .triangles = rig->triangles,
                                .abstraction_count = 1,
                                .abstractions = &b->ab,
                                .user = b,
                                .evaluate = lbs_evaluate};
}

static double max_abs(const double* v, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i)
        m = fmax(m, fabs(v[i]));
    return m;
}

static double max_diff(const double* a, const double* b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

static void test_fd_matches_analytic(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 7, .branching = true, .all_channels = true, .seed = 5}, &rig);
    lbs_box box;
    lbs_box_init(&box, &rig);
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_open(&box.desc, "lbs box", &bb, &err) == SP_OK);
    const int P = rig.param_count, l = rig.abstractions[0].point_count;
    int rows[64], nrows = 0;
    for (int v = 0; v < rig.vertex_count && nrows < 64; v += 37)
        rows[nrows++] = v;
    double* p = malloc(sizeof(double) * P);
    double* Jf = malloc(sizeof(double) * 3 * nrows * P);
    double* Ja = malloc(sizeof(double) * 3 * nrows * P);
    double* Zf = malloc(sizeof(double) * 3 * l * P);
    double* Za = malloc(sizeof(double) * 3 * l * P);
    sp_blackbox_fd* fd;
    sp_blackbox_fd_create(bb, 0, rows, nrows, 1, &fd, NULL);
    ENSURE(fd);
    sp_rig_eval* ev;
    sp_rig_eval_create(&rig, &ev, NULL);
    sp_skinned_points apts = {l, rig.abstractions[0].rest, rig.abstractions[0].joints, rig.abstractions[0].weights};
    sp_test_rng rng = {11};
    double worst = 0;
    for (int trial = 0; trial < 4; ++trial) {
        sp_fixture_random_params(&rig, &rng, 0.8, p);
        ENSURE(sp_blackbox_fd_jacobian(fd, p, Jf, Zf, &err) == SP_OK);
        sp_rig_eval_update(ev, p, true);
        sp_rig_eval_jacobian(ev, sp_rig_mesh_points(&rig), rows, nrows, Ja);
        sp_rig_eval_jacobian(ev, apts, NULL, l, Za);
        double rj = max_diff(Jf, Ja, 3 * nrows * P) / max_abs(Ja, 3 * nrows * P);
        double rz = max_diff(Zf, Za, 3 * l * P) / max_abs(Za, 3 * l * P);
        worst = fmax(worst, fmax(rj, rz));
    }
    printf("  FD vs analytic Jacobian, largest difference relative to the largest entry: %.2e\n", worst);
    ENSURE(worst < 1e-6);
    // At a bound the stencil moves inside (one step of error, O(h)), and the
    // rig is never evaluated outside its bounds.
    sp_rig_defaults(&rig, p);
    for (int k = 0; k < P; ++k)
        if (k % 3 == 0)
            p[k] = rig.params[k].max;
        else if (k % 3 == 1)
            p[k] = rig.params[k].min;
    ENSURE(sp_blackbox_fd_jacobian(fd, p, Jf, Zf, &err) == SP_OK);
    sp_rig_eval_update(ev, p, true);
    sp_rig_eval_jacobian(ev, sp_rig_mesh_points(&rig), rows, nrows, Ja);
    double rb = max_diff(Jf, Ja, 3 * nrows * P) / max_abs(Ja, 3 * nrows * P);
    printf("  at the bounds: %.2e\n", rb);
    ENSURE(rb < 1e-3);
    ENSURE(atomic_load(&box.out_of_bounds) == 0);
    sp_rig_eval_destroy(ev);
    sp_blackbox_fd_destroy(fd);
    sp_blackbox_destroy(bb);
    free(p), free(Jf), free(Ja), free(Zf), free(Za), free(box.rest);
    sp_rig_free(&rig);
}

// The wrapped skinned rig posed through finite differences reaches the same
// fit as the analytic solver.
static void test_lbs_as_blackbox_solves(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 5, .seed = 3}, &rig);
    lbs_box box;
    lbs_box_init(&box, &rig);
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_open(&box.desc, "lbs box", &bb, &err) == SP_OK);
    sp_camera cam = sp_camera_default_view(rig.rest, rig.vertex_count, 640, 480);
    int P = rig.param_count;
    double *truth = malloc(sizeof(double) * P), *pa = malloc(sizeof(double) * P), *pb = malloc(sizeof(double) * P);
    sp_solver* sa;
    sp_solver_create(&rig, 0, &cam, &(sp_solve_desc){0}, &sa, NULL);
    sp_solver* sb;
    sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){0}, &sb, NULL);
    ENSURE(sa && sb);
    for (int seed = 1; seed <= 3; ++seed) {
        sp_synth_params(&rig, (uint64_t)seed, 0.6, truth);
        sp_sketch sk;
        ENSURE(sp_synth_sketch(&rig, 0, &cam, truth, &sk) == SP_OK);
        sp_solve_report ra, rb;
        ENSURE(sp_solver_solve(sa, &sk, NULL, pa, &ra, &err) == SP_OK);
        ENSURE(sp_solver_solve(sb, &sk, NULL, pb, &rb, &err) == SP_OK);
        printf("  seed %d: analytic %.3f px in %d iterations, finite differences %.3f px in %d (diagonal %.0f px)\n", seed,
               ra.mean_error_px, ra.iterations, rb.mean_error_px, rb.iterations, rb.bbox_diagonal_px);
        ENSURE(rb.mean_error_px < 0.01 * rb.bbox_diagonal_px);
        ENSURE(fabs(rb.after.total - ra.after.total) <= 0.05 * ra.after.total + 1e-9);
        sp_sketch_free(&sk);
    }
    ENSURE(atomic_load(&box.out_of_bounds) == 0);
    sp_solver_destroy(sa);
    sp_solver_destroy(sb);
    sp_blackbox_destroy(bb);
    free(truth), free(pa), free(pb), free(box.rest);
    sp_rig_free(&rig);
}

// The time cap holds inside a finite-difference Jacobian and between the
// damped tries: a rig slow to evaluate stops the solve near the cap, with
// the best pose so far, not 2 P evaluations later.
static void test_time_cap_slow_rig(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 8, .seed = 3}, &rig);
    lbs_box box;
    lbs_box_init(&box, &rig);
    sp_blackbox* bb = NULL;
    ENSURE(sp_blackbox_open(&box.desc, "slow box", &bb, NULL) == SP_OK);
    sp_camera cam = sp_camera_default_view(rig.rest, rig.vertex_count, 640, 480);
    const int P = rig.param_count;
    ENSURE(P >= 20);
    double *truth = malloc(sizeof(double) * P), *p = malloc(sizeof(double) * P);
    sp_synth_params(&rig, 5, 0.6, truth);
    sp_sketch sk;
    ENSURE(sp_synth_sketch(&rig, 0, &cam, truth, &sk) == SP_OK);
    sp_solver* s = NULL;
    ENSURE(sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){.threads = 1, .time_cap_ms = 100}, &s, NULL) == SP_OK);
    // At least 10 ms an evaluation: at most 10 begin before the cap, where
    // one Jacobian alone asks for 2 P.
    box.sleep_ms = 10;
    atomic_store(&box.calls, 0);
    sp_solve_report rep;
    sp_error err = {0};
    ENSURE(sp_solver_solve(s, &sk, NULL, p, &rep, &err) == SP_OK);
    int calls = atomic_load(&box.calls);
    printf("  %d parameters, %d evaluations, %.0f ms, stopped: %s\n", P, calls, rep.ms, sp_stop_reason_name(rep.stopped));
    ENSURE(rep.stopped == SP_STOP_TIME_CAP);
    ENSURE(calls < P);
    for (int k = 0; k < P; ++k)
        ENSURE(isfinite(p[k]) && p[k] >= rig.params[k].min && p[k] <= rig.params[k].max);
    sp_solver_destroy(s);
    sp_sketch_free(&sk);
    sp_blackbox_destroy(bb);
    free(truth), free(p), free(box.rest);
    sp_rig_free(&rig);
}

// ---------------------------------------------------------------- the face plugin

static sp_blackbox* load_face(void)
{
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    if (sp_blackbox_load_plugin(SP_FACE_PLUGIN, &bb, &err) != SP_OK) {
        fprintf(stderr, "  %s\n", err.text);
        ENSURE(!"the face plugin loads");
    }
    return bb;
}

static void test_face_asset(void)
{
    sp_blackbox* bb = load_face();
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    printf("  face: %d parameters, %d vertices, %d triangles, %d abstraction coordinates in %d curves\n", r->param_count,
           r->vertex_count, r->triangle_count, 2 * sp_blackbox_total_points(bb), r->abstractions[0].curve_count);
    ENSURE(r->param_count == 44);
    ENSURE(r->vertex_count >= 6000 && r->vertex_count <= 7000);
    ENSURE(r->abstraction_count == 1 && r->abstractions[0].curve_count == 8);
    const char* want[] = {"brow_l", "brow_r", "lid_upper_l", "lid_upper_r", "lid_lower_l", "lid_lower_r", "mouth"};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; ++i) {
        bool found = false;
        for (int c = 0; c < r->abstractions[0].curve_count; ++c)
            found |= !strcmp(r->abstractions[0].curves[c].name, want[i]);
        ENSURE(found);
    }
    // Deterministic: a second instance is the same, bytes and all.
    sp_blackbox* bb2 = load_face();
    const sp_blackbox_rig* r2 = sp_blackbox_desc(bb2);
    ENSURE(r2->vertex_count == r->vertex_count && r2->triangle_count == r->triangle_count);
    ENSURE(!memcmp(r->rest, r2->rest, sizeof(double) * 3 * (size_t)r->vertex_count));
    ENSURE(!memcmp(r->triangles, r2->triangles, sizeof(uint32_t) * 3 * (size_t)r->triangle_count));
    // Not linear in its parameters (not a blendshape-only or skinned rig):
    // x(2p) - x(0) is not 2 (x(p) - x(0)) for the deformers.
    int n = r->vertex_count;
    double* x0 = malloc(sizeof(double) * 3 * n);
    double* x1 = malloc(sizeof(double) * 3 * n);
    double* x2 = malloc(sizeof(double) * 3 * n);
    double p[64];
    sp_error err = {0};
    sp_blackbox_defaults(bb, p);
    ENSURE(sp_blackbox_evaluate(bb, p, x0, NULL, &err) == SP_OK);
    int k = -1;
    for (int i = 0; i < r->param_count; ++i)
        if (!strcmp(r->params[i].name, "head_twist")) k = i;
    ENSURE(k >= 0);
    p[k] = 0.25;
    ENSURE(sp_blackbox_evaluate(bb, p, x1, NULL, &err) == SP_OK);
    p[k] = 0.5;
    ENSURE(sp_blackbox_evaluate(bb, p, x2, NULL, &err) == SP_OK);
    double dev = 0;
    for (int i = 0; i < 3 * n; ++i)
        dev = fmax(dev, fabs((x2[i] - x0[i]) - 2 * (x1[i] - x0[i])));
    ENSURE(dev > 1e-3);
    free(x0), free(x1), free(x2);
    // Its parameters in the skinned rig's type, clamped by the one clamp
    // (sp_params_clamp): out of bounds to a bound, NaN and Inf to the default.
    const sp_param* q = sp_blackbox_params(bb);
    for (int i = 0; i < r->param_count; ++i) {
        ENSURE(!strcmp(q[i].name, r->params[i].name) && q[i].min == r->params[i].min && q[i].max == r->params[i].max);
        ENSURE(q[i].def == r->params[i].def && (int)q[i].group == r->params[i].group && q[i].joint == -1);
    }
    sp_blackbox_defaults(bb, p);
    p[0] = q[0].max + 1, p[1] = q[1].min - 1, p[2] = NAN, p[3] = INFINITY;
    ENSURE(sp_params_clamp(q, r->param_count, p) == 4);
    ENSURE(p[0] == q[0].max && p[1] == q[1].min && p[2] == q[2].def && p[3] == q[3].def);
    ENSURE(sp_params_clamp(q, r->param_count, p) == 0);
    sp_blackbox_destroy(bb2);
    sp_blackbox_destroy(bb);
}

// Random poses anywhere within the bounds keep the surface orientable: at
// most 0.5% of the triangles flip against their rest orientation (the
// assets issue's rule), and no scale factor can reach zero.
static void test_face_no_inversions(void)
{
    sp_blackbox* bb = load_face();
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    for (int k = 0; k < r->param_count; ++k)
        if (r->params[k].unit == SP_BB_UNIT_FACTOR) ENSURE(r->params[k].min > 0);
    int n = r->vertex_count, nt = r->triangle_count;
    double* x = malloc(sizeof(double) * 3 * n);
    double* n0 = malloc(sizeof(double) * 3 * nt);
    bool* live = malloc(sizeof(bool) * nt);
    for (int t = 0; t < nt; ++t) {
        const double* a = r->rest + 3 * r->triangles[3 * t];
        const double* b = r->rest + 3 * r->triangles[3 * t + 1];
        const double* c = r->rest + 3 * r->triangles[3 * t + 2];
        sp_vec3 e = sp_v3_cross(sp_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]), sp_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
        n0[3 * t] = e.x, n0[3 * t + 1] = e.y, n0[3 * t + 2] = e.z;
        live[t] = sp_v3_len(e) > 1e-9; // the lips' corners are degenerate at rest
    }
    int worst = 0;
    sp_error err = {0};
    for (int seed = 1; seed <= 200; ++seed) {
        double p[64];
        sp_blackbox_synth_params(bb, (uint64_t)seed, PI, p);
        ENSURE(sp_blackbox_evaluate(bb, p, x, NULL, &err) == SP_OK);
        int flipped = 0;
        for (int t = 0; t < nt; ++t) {
            if (!live[t]) continue;
            const double* a = x + 3 * r->triangles[3 * t];
            const double* b = x + 3 * r->triangles[3 * t + 1];
            const double* c = x + 3 * r->triangles[3 * t + 2];
            sp_vec3 e = sp_v3_cross(sp_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]), sp_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
            flipped += e.x * n0[3 * t] + e.y * n0[3 * t + 1] + e.z * n0[3 * t + 2] < 0;
        }
        if (flipped > worst) worst = flipped;
    }
    printf("  200 random poses: at most %d of %d triangles flipped (%.2f%%)\n", worst, nt, 100.0 * worst / nt);
    ENSURE(worst <= 0.005 * nt);
    free(x), free(n0), free(live);
    sp_blackbox_destroy(bb);
}

static void test_threads_bit_identical(void)
{
    sp_blackbox* bb = load_face();
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    const int P = r->param_count, l = sp_blackbox_abstraction_points(bb, 0);
    int rows[200];
    for (int i = 0; i < 200; ++i)
        rows[i] = (int)((long long)i * r->vertex_count / 200);
    double p[64];
    sp_blackbox_synth_params(bb, 17, PI, p);
    double* J[3];
    double* Z[3];
    sp_error err = {0};
    for (int t = 0; t < 3; ++t) {
        J[t] = malloc(sizeof(double) * 600 * P);
        Z[t] = malloc(sizeof(double) * 3 * l * P);
        sp_blackbox_fd* fd;
        sp_blackbox_fd_create(bb, 0, rows, 200, t + 1, &fd, NULL);
        ENSURE(fd && sp_blackbox_fd_threads(fd) == t + 1);
        ENSURE(sp_blackbox_fd_jacobian(fd, p, J[t], Z[t], &err) == SP_OK);
        if (t == 2) ENSURE(sp_blackbox_fd_jacobian(fd, p, J[t], Z[t], &err) == SP_OK); // the pool's second round
        sp_blackbox_fd_destroy(fd);
    }
    for (int t = 1; t < 3; ++t) {
        ENSURE(!memcmp(J[0], J[t], sizeof(double) * 600 * P));
        ENSURE(!memcmp(Z[0], Z[t], sizeof(double) * 3 * l * P));
    }
    ENSURE(max_abs(Z[0], 3 * (size_t)l * P) > 0);
    // A whole solve gives the same bits on one thread and on two (no time
    // cap: a slow run under sanitizers must not stop at another iteration).
    sp_camera cam = sp_blackbox_camera(bb, 640, 480);
    sp_sketch sk;
    ENSURE(sp_blackbox_synth_sketch(bb, 0, &cam, p, &sk, &err) == SP_OK);
    double out[2][64];
    for (int t = 0; t < 2; ++t) {
        sp_solver* s;
        sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){.threads = t + 1, .time_cap_ms = 1e9}, &s, NULL);
        sp_solve_report rep;
        ENSURE(s && sp_solver_solve(s, &sk, NULL, out[t], &rep, &err) == SP_OK);
        ENSURE(rep.stopped != SP_STOP_TIME_CAP);
        sp_solver_destroy(s);
    }
    ENSURE(!memcmp(out[0], out[1], sizeof(double) * P));
    sp_sketch_free(&sk);
    for (int t = 0; t < 3; ++t)
        free(J[t]), free(Z[t]);
    sp_blackbox_destroy(bb);
}

// Seeded targets anywhere within the bounds (amplitude pi: every parameter
// uniform in its range), their abstraction projected as strokes, solved
// from the rest pose.
static void test_face_recovery(void)
{
    // As many cases as fit in about 30 s on the 2-core machine; the first
    // 12 of the same seeds under sanitizers, which run 5x slower.
#if defined(__SANITIZE_ADDRESS__)
    enum { CASES = 12 };
#else
    enum { CASES = 40 };
#endif
    sp_blackbox* bb = load_face();
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    const int P = r->param_count;
    sp_camera cam = sp_blackbox_camera(bb, 640, 480);
    sp_solver* s;
    sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){.time_cap_ms = 1e9}, &s, NULL);
    ENSURE(s);
    double rel[CASES], ms[CASES];
    int ok = 0;
    sp_error err = {0};
    for (int i = 0; i < CASES; ++i) {
        double truth[64], p[64];
        sp_blackbox_synth_params(bb, (uint64_t)(1000 + i), PI, truth);
        sp_sketch sk;
        ENSURE(sp_blackbox_synth_sketch(bb, 0, &cam, truth, &sk, &err) == SP_OK);
        sp_solve_report rep;
        ENSURE(sp_solver_solve(s, &sk, NULL, p, &rep, &err) == SP_OK);
        for (int k = 0; k < P; ++k)
            ENSURE(isfinite(p[k]) && p[k] >= r->params[k].min && p[k] <= r->params[k].max);
        rel[i] = rep.mean_error_px / rep.bbox_diagonal_px;
        ms[i] = rep.ms;
        ok += rel[i] <= 0.01;
        sp_sketch_free(&sk);
    }
    qsort(rel, CASES, sizeof(double), sp_cmp_double);
    qsort(ms, CASES, sizeof(double), sp_cmp_double);
    printf("  face recovery: %d/%d within 1%% of the diagonal; error median %.3f%%, p95 %.3f%%, worst %.3f%%; solve median %.0f "
           "ms\n",
           ok, CASES, 100 * rel[CASES / 2], 100 * rel[(int)(0.95 * (CASES - 1) + 0.5)], 100 * rel[CASES - 1], ms[CASES / 2]);
    ENSURE(ok >= (int)ceil(0.95 * CASES));
    sp_solver_destroy(s);
    sp_blackbox_destroy(bb);
}

// A drawing that asks for more than the rig can do: the fit stops exactly
// at bounds and never past them.
static void test_face_bounds(void)
{
    sp_blackbox* bb = load_face();
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    const int P = r->param_count;
    sp_camera cam = sp_blackbox_camera(bb, 640, 480);
    double truth[64], p[64];
    sp_blackbox_defaults(bb, truth);
    for (int k = 0; k < P; ++k)
        if (!strcmp(r->params[k].name, "jaw_open") || !strcmp(r->params[k].name, "brow_raise_l") ||
            !strcmp(r->params[k].name, "brow_raise_r"))
            truth[k] = r->params[k].max;
    sp_sketch sk;
    sp_error err = {0};
    ENSURE(sp_blackbox_synth_sketch(bb, 0, &cam, truth, &sk, &err) == SP_OK);
    // Stretch the whole drawing vertically by 40% about its centre.
    sp_vec2 lo, hi;
    ENSURE(sp_sketch_bounds(&sk, &lo, &hi));
    double cy = 0.5 * (lo.y + hi.y);
    for (int i = 0; i < sk.stroke_count; ++i)
        for (int j = 0; j < sk.strokes[i].count; ++j)
            sk.strokes[i].points[j].y = cy + 1.4 * (sk.strokes[i].points[j].y - cy);
    sp_solver* s;
    sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){0}, &s, NULL);
    sp_solve_report rep;
    ENSURE(s && sp_solver_solve(s, &sk, NULL, p, &rep, &err) == SP_OK);
    int at_bound = 0;
    for (int k = 0; k < P; ++k) {
        ENSURE(p[k] >= r->params[k].min && p[k] <= r->params[k].max);
        at_bound += r->params[k].min < r->params[k].max && (p[k] == r->params[k].min || p[k] == r->params[k].max) &&
                    p[k] != r->params[k].def;
    }
    printf("  stretched drawing: %d parameters end exactly at a bound; mean error %.1f px\n", at_bound, rep.mean_error_px);
    ENSURE(at_bound >= 1);
    sp_solver_destroy(s);
    sp_sketch_free(&sk);
    sp_blackbox_destroy(bb);
}

// ---------------------------------------------------------------- the loader's errors

static const char* plugin(const char* variant)
{
    static char buf[8][1024];
    static int k;
    char* b = buf[k++ % 8];
    snprintf(b, 1024, "%s/libsp_test_bb_%s.so", SP_TEST_PLUGIN_DIR, variant);
    return b;
}

static void expect_load_error(const char* path, sp_result code, const char* a, const char* b)
{
    sp_blackbox* bb = (sp_blackbox*)1;
    sp_error err = {0};
    sp_result r = sp_blackbox_load_plugin(path, &bb, &err);
    printf("  %s\n", err.text);
    ENSURE(r == code);
    ENSURE(bb == NULL);
    ENSURE(strstr(err.text, path) != NULL);
    ENSURE(strchr(err.text, '\n') == NULL);
    ENSURE(strstr(err.text, a) != NULL);
    if (b) ENSURE(strstr(err.text, b) != NULL);
}

static void test_plugin_errors(void)
{
    expect_load_error("/nonexistent/dir/libnothing.so", SP_ERR_IO, "No such file", NULL);
    const char* bogus = sp_test_tmp_path("bogus_plugin.so");
    FILE* f = fopen(bogus, "w");
    ENSURE(f);
    fputs("this is not an ELF file\n", f);
    fclose(f);
    expect_load_error(bogus, SP_ERR_PARSE, "cannot load it as a shared object", NULL);
    expect_load_error(plugin("nosym"), SP_ERR_INVALID, "no symbol sp_blackbox_plugin_v1", "extern \"C\"");
    // Another processor's object: dlopen alone says "No such file or directory".
    // Checked where this host is little-endian x86-64 or AArch64 (the loader
    // names the processors it knows; elsewhere dlopen speaks).
    size_t n = 0;
    unsigned char* so = (unsigned char*)sp_fixture_file_text(plugin("good"), &n);
    ENSURE(n > 64);
    bool x86 = so[18] == 62 && so[19] == 0, arm64 = so[18] == 183 && so[19] == 0;
    if (so[5] == 1 && (x86 || arm64)) {
        so[18] = x86 ? 183 : 62; // e_machine: the other one
        const char* arch = sp_test_tmp_path("other_arch.so");
        f = fopen(arch, "wb");
        ENSURE(f && fwrite(so, 1, n, f) == n && fclose(f) == 0);
        expect_load_error(arch, SP_ERR_PARSE,
                          x86 ? "built for another processor (AArch64), this is x86-64"
                              : "built for another processor (x86-64), this is AArch64",
                          NULL);
        so[18] = 7, so[19] = 7; // e_machine 0x0707: no name here
        f = fopen(arch, "wb");
        ENSURE(f && fwrite(so, 1, n, f) == n && fclose(f) == 0);
        expect_load_error(arch, SP_ERR_PARSE, "built for another processor (ELF machine 1799)", NULL);
    } else {
        printf("  the other-processor check is not run on this processor\n");
    }
    free(so);
    expect_load_error(plugin("null"), SP_ERR_INVALID, "returned no rig", NULL);
    expect_load_error(plugin("badversion"), SP_ERR_UNSUPPORTED, "ABI version 99", "reads version 1");
    expect_load_error(plugin("badsize"), SP_ERR_UNSUPPORTED, "inconsistent sizes", "sp_blackbox_rig");
    expect_load_error(plugin("badtri"), SP_ERR_INVALID, "inconsistent sizes", "triangle");
    expect_load_error(plugin("badrest"), SP_ERR_INVALID, "does not reproduce the rest mesh", NULL);
    expect_load_error(plugin("nan"), SP_ERR_INVALID, "NaN", "vertex 2");
    // The good one loads, and unloads cleanly.
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_load_plugin(plugin("good"), &bb, &err) == SP_OK);
    ENSURE(sp_blackbox_desc(bb)->param_count == 4 && sp_blackbox_total_points(bb) == 8);
    sp_blackbox_destroy(bb);
}

// A plugin cut short: dlopen would map segments past the end of the file and
// die of SIGBUS touching them, so the loader refuses it first.
static void test_plugin_truncated(void)
{
    FILE* in = fopen(SP_FACE_PLUGIN, "rb");
    ENSURE(in);
    static unsigned char so[1 << 20];
    size_t n = fread(so, 1, sizeof so, in);
    fclose(in);
    ENSURE(n > 20000 && n < sizeof so);
    const size_t cuts[] = {10, 64, 500, 1000, 4096, 20000, n / 2, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        char path[64];
        snprintf(path, sizeof path, "face_cut_%zu.so", cuts[i]);
        const char* cut = sp_test_tmp_path(path);
        FILE* f = fopen(cut, "wb");
        ENSURE(f && fwrite(so, 1, cuts[i], f) == cuts[i]);
        fclose(f);
        expect_load_error(cut, SP_ERR_PARSE, "not a complete shared object (truncated?)", NULL);
    }
    // An ELF of no known class is refused by name, not handed to dlopen.
    so[EI_CLASS] = 7;
    const char* odd = sp_test_tmp_path("face_class7.so");
    FILE* f = fopen(odd, "wb");
    ENSURE(f && fwrite(so, 1, n, f) == n);
    fclose(f);
    expect_load_error(odd, SP_ERR_PARSE, "ELF class 7", NULL);
}

// A rig whose evaluation breaks during a solve: a one-line error, no NaN pose.
static void test_nan_during_solve(void)
{
    sp_blackbox *good = NULL, *bad = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_load_plugin(plugin("good"), &good, &err) == SP_OK);
    ENSURE(sp_blackbox_load_plugin(plugin("nanlater"), &bad, &err) == SP_OK);
    // Seen from above, where the bend shows fully.
    sp_camera cam = sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, sp_v3(-1.5, -1.5, -1.5), sp_v3(1.5, 1.5, 1.5), sp_v3(0, -1, 0),
                                    sp_v3(0, 0, -1), 640, 480);
    double truth[4] = {0.1, -0.1, 0.2, 0.8}, p[4] = {0, 0, 0, 0};
    sp_sketch sk;
    ENSURE(sp_blackbox_synth_sketch(good, 0, &cam, truth, &sk, &err) == SP_OK);
    sp_solver* s;
    sp_solver_create_blackbox(good, 0, &cam, &(sp_solve_desc){0}, &s, NULL);
    sp_solve_report rep;
    ENSURE(s && sp_solver_solve(s, &sk, NULL, p, &rep, &err) == SP_OK);
    ENSURE(rep.mean_error_px < 0.01 * rep.bbox_diagonal_px);
    sp_solver_destroy(s);
    sp_solver_create_blackbox(bad, 0, &cam, &(sp_solve_desc){0}, &s, NULL);
    memset(&err, 0, sizeof err);
    sp_result res = sp_solver_solve(s, &sk, NULL, p, &rep, &err);
    printf("  %s\n", err.text);
    ENSURE(res == SP_ERR_INVALID && strstr(err.text, "NaN") && strchr(err.text, '\n') == NULL);
    sp_solver_destroy(s);
    sp_sketch_free(&sk);
    sp_blackbox_destroy(good);
    sp_blackbox_destroy(bad);
}

// ---------------------------------------------------------------- the command line

static const char* sketchpose(void)
{
    static char b[1024];
    snprintf(b, sizeof b, "%s/app/sketchpose", SP_BINARY_DIR);
    struct stat st;
    return stat(b, &st) == 0 ? b : NULL;
}

static char* slurp(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    return buf;
}

// Runs cmd with stdout and stderr to files; returns the exit status. *out
// and *err are the files' text (static buffers of slurp's: copy to keep).
static int run_cli(const char* cmd, char** out, char** err)
{
    char full[8192], o[1024], e[1024];
    snprintf(o, sizeof o, "%s", sp_test_tmp_path("cli_out.txt"));
    snprintf(e, sizeof e, "%s", sp_test_tmp_path("cli_err.txt"));
    snprintf(full, sizeof full, "%s > '%s' 2> '%s'", cmd, o, e);
    int rc = system(full);
    static char ob[1 << 16];
    char* t = slurp(o);
    snprintf(ob, sizeof ob, "%s", t ? t : "");
    *out = ob;
    *err = slurp(e);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// One line on stderr that names `a` (and `b` when not NULL).
static bool one_line_naming(const char* e, const char* a, const char* b)
{
    return e && strchr(e, '\n') == e + strlen(e) - 1 && strstr(e, a) && (!b || strstr(e, b));
}

// A plugin's pose files (pose --start, synth --pose, render --pose, export
// --pose) are read like a glTF rig's, by the plugin's parameter names: an
// unknown name or a non-number is one line naming the file and the name,
// exit 1; a value out of bounds is clamped with a warning.
static void cli_plugin_pose_files(const char* bin, const char* strokes, const char* truth)
{
    char cmd[8192], bad[1024], far[1024];
    char *out, *err;
    snprintf(bad, sizeof bad, "%s", sp_test_tmp_path("face_bad_pose.json"));
    snprintf(far, sizeof far, "%s", sp_test_tmp_path("face_far_pose.json"));
    FILE* f = fopen(bad, "wb");
    ENSURE(f && fputs("{\"parameters\": {\"jaw_opn\": 0.5}}", f) >= 0 && fclose(f) == 0);
    f = fopen(far, "wb");
    ENSURE(f && fputs("{\"parameters\": {\"jaw_open\": 7}}", f) >= 0 && fclose(f) == 0);
    snprintf(cmd, sizeof cmd, "'%s' pose --rig '%s' --strokes '%s' --start '%s'", bin, SP_FACE_PLUGIN, strokes, bad);
    ENSURE(run_cli(cmd, &out, &err) == 1 && one_line_naming(err, bad, "'jaw_opn'"));
    snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s' --pose '%s' --out '%s'", bin, SP_FACE_PLUGIN, bad,
             sp_test_tmp_path("x.json"));
    ENSURE(run_cli(cmd, &out, &err) == 1 && one_line_naming(err, bad, "'jaw_opn'"));
    snprintf(cmd, sizeof cmd, "'%s' export --rig '%s' --pose '%s' --out '%s'", bin, SP_FACE_PLUGIN, far,
             sp_test_tmp_path("x.glb"));
    ENSURE(run_cli(cmd, &out, &err) == 0 && strstr(err, "clamped to 1") && strstr(out, "\"clamped\":1"));
    // The truth pose file synth wrote starts a solve where it ends.
    snprintf(cmd, sizeof cmd, "'%s' pose --rig '%s' --strokes '%s' --start '%s'", bin, SP_FACE_PLUGIN, strokes, truth);
    ENSURE(run_cli(cmd, &out, &err) == 0 && strstr(out, "\"iterations\":\t"));
}

// export writes a plugin's posed mesh as a static glTF (as pose --out);
// drawover and animate refuse a plugin in one line saying why; synth
// --style is bad usage for a plugin; inspect lists no joints for one.
static void cli_plugin_other_commands(const char* bin, const char* strokes, const char* truth)
{
    char cmd[8192], glb[1024];
    char *out, *err;
    snprintf(glb, sizeof glb, "%s", sp_test_tmp_path("face_export.glb"));
    remove(glb);
    snprintf(cmd, sizeof cmd, "'%s' export --rig '%s' --pose '%s' --out '%s'", bin, SP_FACE_PLUGIN, truth, glb);
    ENSURE(run_cli(cmd, &out, &err) == 0 && strstr(out, "\"parameters\":44") && strstr(out, "\"clamped\":0"));
    snprintf(cmd, sizeof cmd, "'%s' inspect --rig '%s'", bin, glb);
    ENSURE(run_cli(cmd, &out, &err) == 0 && strstr(out, "\"vertices\":\t6537,") && strstr(out, "\"parameters\":\t[],"));
    ENSURE(strstr(out, "\"name\":\t\"root\"") && strstr(out, "\"name\":\t\"face\"") && !strstr(out, "black_box"));
    snprintf(cmd, sizeof cmd, "'%s' drawover --rig '%s' --on '%s' --to '%s'", bin, SP_FACE_PLUGIN, strokes, strokes);
    ENSURE(run_cli(cmd, &out, &err) == 1 && one_line_naming(err, SP_FACE_PLUGIN, "needs a glTF character"));
    snprintf(cmd, sizeof cmd, "'%s' animate --rig '%s' --strokes '%s' --out '%s'", bin, SP_FACE_PLUGIN, strokes, glb);
    ENSURE(run_cli(cmd, &out, &err) == 1 && one_line_naming(err, SP_FACE_PLUGIN, "needs a glTF character"));
    snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s' --seed 1 --style normal --out '%s'", bin, SP_FACE_PLUGIN,
             sp_test_tmp_path("x.json"));
    ENSURE(run_cli(cmd, &out, &err) == 2 && one_line_naming(err, "--style", NULL));
    snprintf(cmd, sizeof cmd, "'%s' inspect --rig '%s'", bin, SP_FACE_PLUGIN);
    ENSURE(run_cli(cmd, &out, &err) == 0 && !strncmp(out, "{\n\t\"black_box\":\ttrue,", 19) && strstr(out, "\"joints\":\t[]"));
    ENSURE(!strstr(out, "derived_dofs"));
}

static void test_cli(void)
{
    const char* bin = sketchpose();
    if (!bin) SKIP("sketchpose not built");
    char cmd[8192];
    // Own copies: sp_test_tmp_path's buffers rotate.
    char s[1024], t[1024], rep[1024], png[1024], glb[1024], log[1024], vr[1024], ins[1024], rpng[1024];
    snprintf(s, sizeof s, "%s", sp_test_tmp_path("face_s.json"));
    snprintf(t, sizeof t, "%s", sp_test_tmp_path("face_t.json"));
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("face_r.json"));
    snprintf(png, sizeof png, "%s", sp_test_tmp_path("face_posed.png"));
    snprintf(glb, sizeof glb, "%s", sp_test_tmp_path("face_posed.glb"));
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("face_err.txt"));
    snprintf(vr, sizeof vr, "%s", sp_test_tmp_path("face_validate.json"));
    snprintf(ins, sizeof ins, "%s", sp_test_tmp_path("face_inspect.json"));
    snprintf(rpng, sizeof rpng, "%s", sp_test_tmp_path("face_render.png"));
    remove(png), remove(rep), remove(glb);
    snprintf(cmd, sizeof cmd, "'%s' synth --rig '%s' --seed 7 --amplitude 3.1416 --out '%s' --truth '%s'", bin, SP_FACE_PLUGIN, s,
             t);
    ENSURE(system(cmd) == 0);
    snprintf(cmd, sizeof cmd, "'%s' pose --rig '%s' --strokes '%s' --render '%s' --report '%s' --out '%s' > /dev/null", bin,
             SP_FACE_PLUGIN, s, png, rep, glb);
    ENSURE(system(cmd) == 0);
    char* j = slurp(rep);
    ENSURE(j && strstr(j, "\"parameters\"") && strstr(j, "\"jaw_open\"") && strstr(j, "\"mouth\""));
    const char* m = strstr(j, "\"mean_error_px\":");
    const char* d = strstr(j, "\"bbox_diagonal_px\":");
    ENSURE(m && d);
    double mean = atof(m + 16), diag = atof(d + 19);
    printf("  sketchpose pose --rig face: mean error %.2f px of %.0f px\n", mean, diag);
    ENSURE(mean < 0.01 * diag);
    struct stat st;
    ENSURE(stat(png, &st) == 0 && st.st_size > 10000);
    ENSURE(stat(glb, &st) == 0 && st.st_size > 100000);
    // The posed result is a valid glTF (Khronos validator, when node and the
    // test tools are installed).
    const char* tools = sp_fixture_node_tools("gltf-validator");
    if (tools) {
        snprintf(cmd, sizeof cmd, "node '%s/validate.js' '%s' > '%s'", tools, glb, vr);
        ENSURE(system(cmd) == 0);
        char* v = slurp(vr);
        ENSURE(v && strstr(v, "\"numErrors\": 0"));
    }
    // inspect reports the plugin's counts.
    snprintf(cmd, sizeof cmd, "'%s' inspect --rig '%s' > '%s'", bin, SP_FACE_PLUGIN, ins);
    ENSURE(system(cmd) == 0);
    char* ij = slurp(ins);
    int units = 0;
    for (const char* q = ij; q && (q = strstr(q, "\"unit\"")); ++q)
        ++units;
    ENSURE(ij && strstr(ij, "\"black_box\":\ttrue") && units == 44);
    // render shows the plugin at a pose file's pose.
    remove(rpng);
    snprintf(cmd, sizeof cmd, "'%s' render --rig '%s' --pose '%s' --out '%s' --size 320x320", bin, SP_FACE_PLUGIN, t, rpng);
    ENSURE(system(cmd) == 0);
    ENSURE(stat(rpng, &st) == 0 && st.st_size > 5000);
    // Starting from the truth converges at once.
    snprintf(cmd, sizeof cmd, "'%s' pose --rig '%s' --strokes '%s' --start '%s' > /dev/null", bin, SP_FACE_PLUGIN, s, t);
    ENSURE(system(cmd) == 0);
    // A missing plugin: exit 1, one line naming it.
    snprintf(cmd, sizeof cmd, "'%s' pose --rig /nonexistent/face.so --strokes '%s' 2> '%s'", bin, s, log);
    int rc = system(cmd);
    ENSURE(WIFEXITED(rc) && WEXITSTATUS(rc) == 1);
    char* e = slurp(log);
    ENSURE(e && strstr(e, "/nonexistent/face.so") && strchr(e, '\n') == e + strlen(e) - 1);
    snprintf(cmd, sizeof cmd, "'%s' pose --rig '%s' --strokes '%s' 2> '%s'", bin, plugin("badversion"), s, log);
    rc = system(cmd);
    ENSURE(WIFEXITED(rc) && WEXITSTATUS(rc) == 1);
    e = slurp(log);
    ENSURE(e && strstr(e, "ABI version 99"));
    cli_plugin_pose_files(bin, s, t);
    cli_plugin_other_commands(bin, s, t);
}

// blackbox.cmake links with --wrap=pthread_create: while refuse_threads is
// set, no thread starts, as when a process has reached its thread limit.
static atomic_bool refuse_threads;
int __real_pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*fn)(void*), void* arg);
int __wrap_pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*fn)(void*), void* arg);
int __wrap_pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*fn)(void*), void* arg)
{
    return refuse_threads ? EAGAIN : __real_pthread_create(t, a, fn, arg);
}

// The creators say why they refuse (docs/DESIGN.md, "API conventions"):
// *out NULL, SP_ERR_INVALID and a line naming the rig (SP_ERR_INTERNAL for
// threads that cannot start); err may be NULL.
static void test_creation_says_why(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 3, .seed = 1}, &rig);
    lbs_box box;
    lbs_box_init(&box, &rig);
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_open(&box.desc, "lbs box", &bb, &err) == SP_OK);
    sp_camera cam = sp_blackbox_camera(bb, 640, 480);
    const int a = rig.abstraction_count, row = rig.vertex_count;
    sp_solver* s = (sp_solver*)&err; // a creator writes NULL on failure
    ENSURE(sp_solver_create_blackbox(bb, a, &cam, NULL, &s, &err) == SP_ERR_INVALID && !s);
    fprintf(stderr, "  %s\n", err.text);
    char want[128];
    snprintf(want, sizeof want, "lbs box: abstraction %d does not exist", a);
    ENSURE(strstr(err.text, want));
    sp_blackbox_fd* fd = (sp_blackbox_fd*)&err;
    ENSURE(sp_blackbox_fd_create(bb, 0, &row, 1, 1, &fd, &err) == SP_ERR_INVALID && !fd);
    fprintf(stderr, "  %s\n", err.text);
    snprintf(want, sizeof want, "lbs box: row 0 is vertex %d, out of range", row);
    ENSURE(strstr(err.text, want));
    ENSURE(sp_blackbox_fd_create(bb, -1, NULL, 0, 1, &fd, NULL) == SP_ERR_INVALID && !fd);
    // Threads that cannot start: said so, not that memory ran out.
    refuse_threads = true;
    sp_result r = sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){.threads = 2}, &s, &err);
    refuse_threads = false;
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(r == SP_ERR_INTERNAL && !s);
    ENSURE(strstr(err.text, "lbs box: cannot start finite-difference thread 1"));
    ENSURE(sp_solver_create_blackbox(bb, 0, &cam, NULL, &s, NULL) == SP_OK && s);
    sp_solver_destroy(s);
    sp_blackbox_destroy(bb);
    free(box.rest);
    sp_rig_free(&rig);
}

// docs/blackbox.md's example plugin, as a reader copies it out of the page
// (blackbox.cmake builds it from there): it loads, and its seeded poses are
// found again from their strokes, bend included.
static void test_doc_example(void)
{
    sp_blackbox* bb = NULL;
    sp_error err = {0};
    ENSURE(sp_blackbox_load_plugin(plugin("doc"), &bb, &err) == SP_OK);
    const sp_blackbox_rig* r = sp_blackbox_desc(bb);
    ENSURE(r->param_count == 4 && !strcmp(r->params[3].name, "bend"));
    sp_camera cam = sp_blackbox_camera(bb, 640, 480);
    sp_solver* s = NULL;
    ENSURE(sp_solver_create_blackbox(bb, 0, &cam, &(sp_solve_desc){.time_cap_ms = 1e9}, &s, &err) == SP_OK);
    double worst = 0;
    for (int seed = 1; seed <= 6; ++seed) {
        double truth[4], p[4];
        sp_blackbox_synth_params(bb, (uint64_t)seed, 1.0, truth);
        sp_sketch sk;
        ENSURE(sp_blackbox_synth_sketch(bb, 0, &cam, truth, &sk, &err) == SP_OK);
        sp_solve_report rep;
        ENSURE(sp_solver_solve(s, &sk, NULL, p, &rep, &err) == SP_OK);
        for (int k = 0; k < 4; ++k)
            worst = fmax(worst, fabs(p[k] - truth[k]));
        sp_sketch_free(&sk);
    }
    printf("  doc example: worst parameter error %.3f over 6 seeds\n", worst);
    ENSURE(worst < 0.1);
    sp_solver_destroy(s);
    sp_blackbox_destroy(bb);
}

// Opens the box's description as it is now: NULL when it opened, else the message.
static const char* open_error(lbs_box* box)
{
    static sp_error err;
    sp_blackbox* bb = NULL;
    memset(&err, 0, sizeof err);
    if (sp_blackbox_open(&box->desc, "lbs box", &bb, &err) == SP_OK) {
        sp_blackbox_destroy(bb);
        return NULL;
    }
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(!bb && strstr(err.text, "lbs box: ") == err.text && !strchr(err.text, '\n'));
    return err.text;
}

// What a plugin author gets wrong is refused on open with what is wrong:
// names that would break the JSON they go into, a range whose step is not a
// number, two curves of one name, colours glTF cannot hold, too many
// parameters to solve, points evaluate() leaves out.
static void test_description_checks(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 3, .seed = 1}, &rig);
    lbs_box box;
    lbs_box_init(&box, &rig);
    ENSURE(box.ab.curve_count >= 2);
    ENSURE(open_error(&box) == NULL);
    const char* name = box.params[0].name;
    const char* bad_names[] = {"mov\xff\xfe_y", "a\xc0\xaf", "a\xed\xa0\x80", "a\xf4\x90\x80\x80", "a\xe2\x82"};
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; ++i) {
        box.params[0].name = bad_names[i];
        const char* e = open_error(&box);
        ENSURE(e && strstr(e, "parameter 0 has a name that is not UTF-8"));
    }
    box.params[0].name = "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x90\x89"; // café € and a dragon
    ENSURE(open_error(&box) == NULL);
    box.params[0].name = name;
    double lo = box.params[1].min, hi = box.params[1].max, def = box.params[1].def;
    box.params[1].min = -1.7e308, box.params[1].max = 1.7e308, box.params[1].def = 0;
    const char* e = open_error(&box);
    ENSURE(e && strstr(e, box.params[1].name) && strstr(e, "too large to be a number"));
    box.params[1].min = lo, box.params[1].max = hi, box.params[1].def = def;
    const char* curve = box.curves[1].name;
    box.curves[1].name = box.curves[0].name;
    e = open_error(&box);
    ENSURE(e && strstr(e, "two curves of") && strstr(e, box.curves[0].name));
    box.curves[1].name = curve;
    float* colors = malloc(sizeof(float) * 4 * (size_t)rig.vertex_count);
    for (int i = 0; i < 4 * rig.vertex_count; ++i)
        colors[i] = 0.5f;
    box.desc.colors = colors;
    ENSURE(open_error(&box) == NULL);
    colors[4 * 7 + 1] = 255.0f; // 0..255 by mistake
    e = open_error(&box);
    ENSURE(e && strstr(e, "colour of vertex 7") && strstr(e, "not in 0..1"));
    colors[4 * 7 + 1] = NAN;
    ENSURE(open_error(&box) != NULL);
    box.desc.colors = NULL;
    free(colors);
    int P = box.desc.param_count;
    static sp_blackbox_param many[5000];
    static char names[5000][16];
    for (int i = 0; i < 5000; ++i) {
        snprintf(names[i], sizeof names[i], "p%d", i);
        many[i] = (sp_blackbox_param){names[i], 0, 1, 0, SP_GROUP_POSE, SP_BB_UNIT_WEIGHT};
    }
    box.desc.params = many, box.desc.param_count = 5000;
    e = open_error(&box);
    ENSURE(e && strstr(e, "5000 parameters (1..4096)"));
    box.desc.params = box.params, box.desc.param_count = P;
    box.short_write = true;
    e = open_error(&box);
    char want[96];
    snprintf(want, sizeof want, "or none (abstraction point %d) at the defaults", rig.abstractions[0].point_count - 1);
    ENSURE(e && strstr(e, want));
    box.short_write = false;
    // The description is the host's copy: a rig that changes its own after
    // open (counts, functions) is not read past its arrays.
    sp_blackbox* bb = NULL;
    ENSURE(sp_blackbox_open(&box.desc, "lbs box", &bb, NULL) == SP_OK);
    box.desc.param_count = 1000000, box.desc.params = NULL, box.desc.evaluate = NULL;
    ENSURE(sp_blackbox_desc(bb)->param_count == P && !strcmp(sp_blackbox_desc(bb)->params[0].name, name));
    double* p = malloc(sizeof(double) * (size_t)P);
    double* x = malloc(sizeof(double) * 3 * (size_t)rig.vertex_count);
    sp_blackbox_defaults(bb, p);
    ENSURE(sp_blackbox_evaluate(bb, p, x, NULL, NULL) == SP_OK);
    free(p), free(x);
    sp_blackbox_destroy(bb);
    free(box.rest);
    sp_rig_free(&rig);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"fd_matches_analytic", test_fd_matches_analytic},
                                   {"lbs_as_blackbox_solves", test_lbs_as_blackbox_solves},
                                   {"time_cap_slow_rig", test_time_cap_slow_rig},
                                   {"face_asset", test_face_asset},
                                   {"face_no_inversions", test_face_no_inversions},
                                   {"threads_bit_identical", test_threads_bit_identical},
                                   {"plugin_errors", test_plugin_errors},
                                   {"plugin_truncated", test_plugin_truncated},
                                   {"nan_during_solve", test_nan_during_solve},
                                   {"face_bounds", test_face_bounds},
                                   {"face_recovery", test_face_recovery},
                                   {"cli", test_cli},
                                   {"creation_says_why", test_creation_says_why},
                                   {"description_checks", test_description_checks},
                                   {"doc_example", test_doc_example},
                                   {0}});
}
