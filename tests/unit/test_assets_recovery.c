// The solver issue's recovery protocol on the generated dragon parts (issue
// 4): for each part, 100 seeded random targets over shape AND pose
// (sp_synth_params at amplitude pi/4: rotations up to 45 degrees from rest
// within their limits, shape parameters anywhere within their bounds,
// placement translations up to a quarter of their range), drawn as the
// part's outline and solved from the rest pose with `closest`
// correspondences; >= 95 of 100 must end within 1% of the abstraction's
// bounding-box diagonal (mean 2D error). `test_assets_recovery <part>` runs one.
// The same protocol on the paper's characters, per abstraction: the cartoon
// man's stick figure (ordered) and outline (closest), the elephant's stick
// figure (`cartoon_man_stick`, `cartoon_man_outline`, `elephant_stick`).
// Every row asserts the 95 of 100 and a budget on the median
// iterations a solve (its median when set plus a fifth; iterations are
// deterministic where time is not). (The cartoon man's outline, 706
// coordinates, about 2-3 s for its 100 targets, ran 30 with a lower floor
// until the solver tried more than one shift for a loop).
// The sanitizer build (SP_ASSETS_RECOVERY_CASES set) runs the first 10 seeds
// only, for memory and bounds on the same code path, and does not assert the
// rate (10 cases cannot measure 95%; 100 cases of a part take minutes under
// ASan): the accuracy criterion is the optimised build's.
#include <math.h>
#include <stdlib.h>
#include <time.h>

#include "sp/gltf.h"
#include "sp/solver.h"
#include "bench.h"
#include "sp/synth.h"
#include "test.h"

#ifdef SP_ASSETS_RECOVERY_CASES
enum { RATE_ASSERTED = 0 };
#else
#define SP_ASSETS_RECOVERY_CASES 100
enum { RATE_ASSERTED = 1 };
#endif

// Measurements beyond the test: SP_RECOVERY_CASES=N runs seeds 1..N instead
// (the rate is still asserted on them); SP_RECOVERY_SEED=K solves seed K
// alone (to look at one failure; its row then describes that one solve).
static int case_count(int cases, int* first_seed)
{
    const char* one = getenv("SP_RECOVERY_SEED");
    if (one && atoi(one) > 0) {
        *first_seed = atoi(one);
        return 1;
    }
    *first_seed = 1;
    const char* env = getenv("SP_RECOVERY_CASES");
    int n = env ? atoi(env) : 0;
    return n > 0 ? n : cases;
}

static void recover_abstraction(const char* name, const char* abstraction, int cases, int iteration_budget)
{
    int first_seed;
    cases = case_count(cases, &first_seed);
    char rel[256];
    snprintf(rel, sizeof rel, "assets/%s.glb", name);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(sp_test_src_path(rel), &ch, &err) == SP_OK);
    const sp_rig* rig = &ch.rig;
    int P = rig->param_count, ab = sp_rig_find_abstraction(rig, abstraction);
    ENSURE(ab >= 0);
    double* truth = malloc(sizeof(double) * (size_t)P);
    double* out = malloc(sizeof(double) * (size_t)P);
    double* errs = malloc(sizeof(double) * (size_t)cases); // relative errors, for the median and p95
    double* its = malloc(sizeof(double) * (size_t)cases);  // iterations (every attempt of a solve)
    // No wall-clock cap: the protocol measures what the solver reaches, and
    // a time cap would make the slow sanitizer build stop elsewhere.
    sp_solver* s;
    sp_solver_create(rig, ab, &ch.camera, &(sp_solve_desc){.time_cap_ms = 1e9}, &s, NULL);
    ENSURE(truth && out && errs && its && s);
    int ok = 0;
    double worst = 0, ms = 0, err_sum = 0;
    int worst_seed = 0;
    for (int seed = first_seed; seed < first_seed + cases; ++seed) {
        sp_synth_params(rig, (uint64_t)seed, 0.7853981633974483, truth);
        sp_sketch sk;
        ENSURE(sp_synth_sketch(rig, ab, &ch.camera, truth, &sk) == SP_OK);
        sp_solve_report rep;
        ENSURE(sp_solver_solve(s, &sk, NULL, out, &rep, &err) == SP_OK);
        for (int q = 0; q < P; ++q)
            ENSURE(out[q] >= rig->params[q].min && out[q] <= rig->params[q].max);
        double rel_err = rep.mean_error_px / rep.bbox_diagonal_px;
        ok += rel_err <= 0.01;
        if (rel_err > 0.01) fprintf(stderr, "    %s %s seed %d: %.2f%% (%d iterations)\n", name, abstraction, seed, 100 * rel_err, rep.iterations);
        err_sum += rel_err;
        errs[seed - first_seed] = rel_err;
        its[seed - first_seed] = rep.iterations;
        ms += rep.ms;
        if (rel_err > worst) worst = rel_err, worst_seed = seed;
        sp_sketch_free(&sk);
    }
    double med, p90, it_med, it_p90;
    sp_bench_stats(errs, cases, &med, &p90); // sorts errs
    sp_bench_stats(its, cases, &it_med, &it_p90);
    double p95 = errs[(int)(0.95 * (cases - 1) + 0.5)];
    fprintf(stderr,
            "  %-10s %s: %d of %d within 1%% (error mean %.3f%%, median %.3f%%, p95 %.3f%%, worst %.2f%% at seed %d), %.0f ms per "
            "solve, iterations median %.0f (budget %d) p90 %.0f, dim p %d x %d z %d\n",
            name, abstraction, ok, cases, 100.0 * err_sum / cases, 100 * med, 100 * p95, 100 * worst, worst_seed, ms / cases, it_med,
            iteration_budget, it_p90, P, 3 * rig->vertex_count, 2 * rig->abstractions[ab].point_count);
    sp_solver_destroy(s);
    free(truth), free(out), free(errs), free(its);
    sp_character_free(&ch);
    if (RATE_ASSERTED) {
        ENSURE(ok >= (int)ceil(0.95 * cases));
        // Iterations are deterministic, so their median is a fair guard on
        // the solver's convergence where time is not: each row's budget is
        // its median when set, plus a fifth (solver/src/icp.c's round lengths).
        ENSURE(it_med <= iteration_budget);
    }
    else
        fprintf(stderr, "  (sanitizer build: %d cases for memory and bounds, rate not asserted)\n", cases);
}

static void recover(const char* name, int iteration_budget)
{
    recover_abstraction(name, "outline", SP_ASSETS_RECOVERY_CASES, iteration_budget);
}

static void test_torso(void)
{
    recover("torso", 19);
}
static void test_tail(void)
{
    recover("tail", 22);
}
static void test_head(void)
{
    recover("head", 19);
}
static void test_wings(void)
{
    recover("wings", 22);
}
static void test_front_legs(void)
{
    recover("front_legs", 19);
}
static void test_hind_legs(void)
{
    recover("hind_legs", 20);
}
static void test_cartoon_man_stick(void)
{
    recover_abstraction("cartoon_man", "stick", SP_ASSETS_RECOVERY_CASES, 30);
}
static void test_cartoon_man_outline(void)
{
    // The bar like every row since the runner-up shifts of a loop
    // get a turn (solver/src/icp.c, further_attempts): 100 of 100, 200 of 200 and
    // 398 of 400 with SP_RECOVERY_CASES (89 of 100 before).
    recover_abstraction("cartoon_man", "outline", SP_ASSETS_RECOVERY_CASES, 29);
}
static void test_elephant_stick(void)
{
    recover_abstraction("elephant", "stick", SP_ASSETS_RECOVERY_CASES, 28);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"torso", test_torso},
                                   {"tail", test_tail},
                                   {"head", test_head},
                                   {"wings", test_wings},
                                   {"front_legs", test_front_legs},
                                   {"hind_legs", test_hind_legs},
                                   {"cartoon_man_stick", test_cartoon_man_stick},
                                   {"cartoon_man_outline", test_cartoon_man_outline},
                                   {"elephant_stick", test_elephant_stick},
                                   {0}});
}
