// The solver issue's recovery protocol: 100 seeded random target poses at
// amplitude up to 45 degrees per joint from the rest pose; synth then pose
// reaches a mean 2D error <= 1% of the abstraction's bounding-box diagonal
// in >= 95% of cases. On the project's chain fixture, and on CesiumMan and
// RiggedFigure with their derived stick figures when ../shared/data exists.
#include <stdlib.h>

#include "fixtures.h"
#include "sp/gltf.h"
#include "sp/solver.h"
#include "sp/synth.h"
#include "test.h"

static int recovered(const sp_rig* rig, const sp_camera* cam, int cases)
{
    int P = rig->param_count, ok = 0;
    double* truth = malloc(sizeof(double) * P);
    double* out = malloc(sizeof(double) * P);
    sp_solver* s;
    sp_solver_create(rig, 0, cam, &(sp_solve_desc){0}, &s, NULL);
    for (int i = 1; i <= cases; ++i) {
        sp_synth_params(rig, (uint64_t)i, 0.7853981633974483, truth);
        sp_sketch sk;
        ENSURE(sp_synth_sketch(rig, 0, cam, truth, &sk) == SP_OK);
        sp_solve_report rep;
        sp_error err = {0};
        ENSURE(sp_solver_solve(s, &sk, NULL, out, &rep, &err) == SP_OK);
        for (int q = 0; q < P; ++q) ENSURE(out[q] >= rig->params[q].min && out[q] <= rig->params[q].max);
        ok += rep.mean_error_px <= 0.01 * rep.bbox_diagonal_px;
        sp_sketch_free(&sk);
    }
    sp_solver_destroy(s);
    free(truth), free(out);
    return ok;
}

static void test_chain(void)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = 6, .seed = 3}, &rig);
    sp_camera cam = sp_camera_default_view(rig.rest, rig.vertex_count, 640, 480);
    int ok = recovered(&rig, &cam, 100);
    fprintf(stderr, "  chain fixture: %d of 100 within 1%%\n", ok);
    ENSURE(ok >= 95);
    sp_rig_free(&rig);
}

static void check_model(const char* rel)
{
    sp_character ch;
    sp_fixture_shared_gltf(rel, &ch);
    int ok = recovered(&ch.rig, &ch.camera, 100);
    fprintf(stderr, "  %s: %d of 100 within 1%%\n", rel, ok);
    ENSURE(ok >= 95);
    sp_character_free(&ch);
}

static void test_cesiumman(void) { check_model("CesiumMan/CesiumMan.glb"); }
static void test_riggedfigure(void) { check_model("RiggedFigure/RiggedFigure.glb"); }

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv, (sp_test[]){{"chain", test_chain}, {"cesiumman", test_cesiumman}, {"riggedfigure", test_riggedfigure}, {0}});
}
