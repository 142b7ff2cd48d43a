// The solver issue's recovery protocol: 100 seeded random target poses at
// amplitude up to 45 degrees per joint from the rest pose; synth then pose
// reaches a mean 2D error <= 1% of the abstraction's bounding-box diagonal
// in >= 95% of cases. On the project's chain fixture, and on CesiumMan and
// RiggedFigure with their derived stick figures when ../shared/data exists.
// Those two also move as a whole (the translation the loader derives for a
// file without sp_dofs): held at rest for the protocol's poses, and used by
// the same poses drawn a tenth of their size away from where the view puts
// them, as people draw.
#include <math.h>
#include <stdlib.h>

#include "fixtures.h"
#include "sp/gltf.h"
#include "sp/solver.h"
#include "sp/synth.h"
#include "test.h"

// Of `cases` seeded poses, how many are fitted within 1%; with `shift` > 0
// the strokes are moved by that share of their size (in a direction that
// turns by the golden angle from case to case) and the rig's own placement
// translation is held at rest in the target.
static int recovered(const sp_rig* rig, const sp_camera* cam, int cases, double shift)
{
    int P = rig->param_count, ok = 0;
    double* truth = malloc(sizeof(double) * P);
    double* out = malloc(sizeof(double) * P);
    sp_solver* s;
    sp_solver_create(rig, 0, cam, &(sp_solve_desc){0}, &s, NULL);
    for (int i = 1; i <= cases; ++i) {
        sp_synth_params(rig, (uint64_t)i, 0.7853981633974483, truth);
        for (int q = 0; shift >= 0 && q < P; ++q)
            if (sp_rig_param_shifts(rig, q)) truth[q] = rig->params[q].def;
        sp_sketch sk;
        ENSURE(sp_synth_sketch(rig, 0, cam, truth, &sk) == SP_OK);
        sp_vec2 lo, hi;
        ENSURE(sp_sketch_bounds(&sk, &lo, &hi));
        double by = fmax(shift, 0) * sp_v2_len(sp_v2_sub(hi, lo)), turn = 2.399963229728653 * i;
        for (int a = 0; a < sk.stroke_count; ++a)
            for (int b = 0; b < sk.strokes[a].count; ++b)
                sk.strokes[a].points[b] = sp_v2_add(sk.strokes[a].points[b], (sp_vec2){by * cos(turn), by * sin(turn)});
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
    int ok = recovered(&rig, &cam, 100, -1);
    fprintf(stderr, "  chain fixture: %d of 100 within 1%%\n", ok);
    ENSURE(ok >= 95);
    sp_rig_free(&rig);
}

static void check_model(const char* rel, double shift, int want)
{
    sp_character ch;
    sp_fixture_shared_gltf(rel, &ch);
    int ok = recovered(&ch.rig, &ch.camera, 100, shift);
    fprintf(stderr, "  %s, drawn %.0f%% of its size away: %d of 100 within 1%%\n", rel, 100 * shift, ok);
    ENSURE(ok >= want);
    sp_character_free(&ch);
}

static void test_cesiumman(void)
{
    check_model("CesiumMan/CesiumMan.glb", 0, 95);
}
static void test_riggedfigure(void)
{
    check_model("RiggedFigure/RiggedFigure.glb", 0, 95);
}
// 92 and 89 of 100 when measured; without the derived translation none.
static void test_cesiumman_shifted(void)
{
    check_model("CesiumMan/CesiumMan.glb", 0.1, 80);
}
static void test_riggedfigure_shifted(void)
{
    check_model("RiggedFigure/RiggedFigure.glb", 0.1, 80);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"chain", test_chain},
                                   {"cesiumman", test_cesiumman},
                                   {"riggedfigure", test_riggedfigure},
                                   {"cesiumman_shifted", test_cesiumman_shifted},
                                   {"riggedfigure_shifted", test_riggedfigure_shifted},
                                   {0}});
}
