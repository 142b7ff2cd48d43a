// tests/bench/rig: FK, skinning and Jacobian rows per call, median of runs.
//   build/tests/bench/rig [--json] [--runs N]
// Cases: CesiumMan (../shared/data, if present) and a synthetic 100-joint
// rig with 50k vertices. The Jacobian case asks for 200 representative
// vertices + 400 abstraction points, as the solver does (paper eq. 11-12).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "fixtures.h"
#include "sp/clock.h"
#include "sp/gltf.h"
#include "sp/rig.h"
#include "test.h"

enum { MAX_ROWS = 16 };

typedef struct ctx {
    const sp_rig* rig;
    sp_rig_eval* ev;
    double* p;
    double* x;
    double* J;
    int rows[200];
    sp_skinned_points abst;
} ctx;

static void run_fk(ctx* c) { sp_rig_eval_update(c->ev, c->p, false); }
static void run_fk_deriv(ctx* c) { sp_rig_eval_update(c->ev, c->p, true); }
static void run_skin(ctx* c) { sp_rig_eval_points(c->ev, sp_rig_mesh_points(c->rig), c->x); }
static void run_jac(ctx* c)
{
    int P = c->rig->param_count;
    sp_rig_eval_jacobian(c->ev, sp_rig_mesh_points(c->rig), c->rows, 200, c->J);
    sp_rig_eval_jacobian(c->ev, c->abst, NULL, c->abst.count, c->J + (size_t)600 * P);
}

static sp_bench_row time_it(const char* name, void (*fn)(ctx*), ctx* c, int runs, double target)
{
    double* ms = malloc(sizeof(double) * runs);
    fn(c); // warm-up
    for (int r = 0; r < runs; ++r) {
        // Why the inner repeat: a single call is microseconds, below the clock's useful resolution.
        int reps = 10;
        double t0 = sp_now_ms();
        for (int k = 0; k < reps; ++k) fn(c);
        ms[r] = (sp_now_ms() - t0) / reps;
    }
    sp_bench_row row = {.runs = runs, .paper_ms = -1, .target_ms = target};
    snprintf(row.name, sizeof row.name, "%s", name);
    sp_bench_stats(ms, runs, &row.ms_median, &row.ms_p90);
    snprintf(row.extra, sizeof row.extra, "\"vertices\": %d, \"joints\": %d, \"parameters\": %d", c->rig->vertex_count,
             c->rig->joint_count, c->rig->param_count);
    free(ms);
    return row;
}

static int bench_rig(const char* label, const sp_rig* rig, int runs, sp_bench_row* rows)
{
    ctx c = {.rig = rig};
    sp_rig_eval_create(rig, &c.ev, NULL);
    c.p = malloc(sizeof(double) * rig->param_count);
    c.x = malloc(sizeof(double) * 3 * rig->vertex_count);
    sp_test_rng rng = {1};
    sp_fixture_random_params(rig, &rng, 0.5, c.p);
    for (int i = 0; i < 200; ++i) c.rows[i] = (int)((long long)i * rig->vertex_count / 200);
    // 400 abstraction points: the first abstraction's points, repeated if it has fewer.
    static double rest[400 * 3];
    static uint16_t jn[400 * 4];
    static float wt[400 * 4];
    const sp_abstraction* a = rig->abstraction_count ? &rig->abstractions[0] : NULL;
    for (int i = 0; i < 400; ++i) {
        if (a && a->rest) {
            int s = i % a->point_count;
            memcpy(rest + 3 * i, a->rest + 3 * s, sizeof(double) * 3);
            memcpy(jn + 4 * i, a->joints + 4 * s, sizeof(uint16_t) * 4);
            memcpy(wt + 4 * i, a->weights + 4 * s, sizeof(float) * 4);
        } else {
            int s = c.rows[i % 200];
            memcpy(rest + 3 * i, rig->rest + 3 * s, sizeof(double) * 3);
            memcpy(jn + 4 * i, rig->joints4 + 4 * s, sizeof(uint16_t) * 4);
            memcpy(wt + 4 * i, rig->weights4 + 4 * s, sizeof(float) * 4);
        }
    }
    c.abst = (sp_skinned_points){400, rest, jn, wt};
    c.J = malloc(sizeof(double) * 3 * 600 * (size_t)(rig->param_count ? rig->param_count : 1));
    char name[96];
    int n = 0;
    snprintf(name, sizeof name, "%s fk", label);
    rows[n++] = time_it(name, run_fk, &c, runs, -1);
    snprintf(name, sizeof name, "%s fk+derivatives", label);
    rows[n++] = time_it(name, run_fk_deriv, &c, runs, -1);
    snprintf(name, sizeof name, "%s skinning (all vertices)", label);
    rows[n++] = time_it(name, run_skin, &c, runs, rig->vertex_count >= 50000 ? 2.0 : -1);
    snprintf(name, sizeof name, "%s jacobian 200+400 rows", label);
    rows[n++] = time_it(name, run_jac, &c, runs, 1.0);
    free(c.p), free(c.x), free(c.J);
    sp_rig_eval_destroy(c.ev);
    return n;
}

int main(int argc, char** argv)
{
    int runs = 25;
    for (int i = 1; i + 1 < argc; ++i)
        if (!strcmp(argv[i], "--runs")) runs = atoi(argv[i + 1]);
    if (runs < 3) runs = 3;
    sp_bench_row rows[MAX_ROWS];
    int n = 0;
    const char* data = sp_test_data_dir();
    if (data) {
        char path[1024];
        snprintf(path, sizeof path, "%s/gltf/CesiumMan/CesiumMan.glb", data);
        sp_character ch = {0};
        sp_error err = {0};
        if (sp_gltf_load(path, &ch, &err) == SP_OK) {
            n += bench_rig("CesiumMan", &ch.rig, runs, rows + n);
            sp_character_free(&ch);
        } else {
            fprintf(stderr, "bench rig: %s (skipping CesiumMan)\n", err.text);
        }
    } else {
        fprintf(stderr, "bench rig: ../shared/data absent, skipping CesiumMan\n");
    }
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 100, .branching = true, .rings_per_bone = 21, .ring_vertices = 24, .seed = 1}, &rig);
    n += bench_rig("synthetic 100 joints 50k vertices", &rig, runs, rows + n);
    sp_rig_free(&rig);
    sp_bench_print("tests/bench/rig (one thread)", rows, n, sp_bench_json_flag(argc, argv));
    return 0;
}
