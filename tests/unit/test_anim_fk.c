// FK of CesiumMan and RiggedFigure against their own animations: at sampled
// times, the joints' world positions from a plain recursion over the
// animated node transforms equal those of our FK at the parameters that
// sp_rig_params_from_trs gives for the same transforms (full DOFs added),
// so the parameterisation and FK reproduce a real animation.
#include <stdlib.h>
#include <string.h>

#include "fixtures.h"
#include "sp/gltf.h"
#include "test.h"

static void check_model(const char* rel)
{
    sp_character ch;
    sp_fixture_shared_gltf(rel, &ch);
    sp_error err = {0};
    sp_rig* rig = &ch.rig;
    ENSURE(rig->animation_count >= 1);
    // Replace the derived DOFs by full ones: every rotation, translation and scale axis.
    rig->param_count = 0;
    for (int j = 0; j < rig->joint_count; ++j) {
        for (int c = SP_CH_RX; c <= SP_CH_RZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, -3.1416, 3.1416, SP_GROUP_POSE);
        for (int c = SP_CH_TX; c <= SP_CH_TZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, -1e3, 1e3, SP_GROUP_POSE);
        for (int c = SP_CH_SX; c <= SP_CH_SZ; ++c) sp_rig_add_param(rig, j, (sp_channel)c, 1e-3, 1e3, SP_GROUP_SHAPE);
    }
    ENSURE(sp_rig_finalize(rig, rel, NULL, &err) == SP_OK);
    int J = rig->joint_count, P = rig->param_count;
    sp_vec3* t = malloc(sizeof(sp_vec3) * J);
    sp_quat* r = malloc(sizeof(sp_quat) * J);
    sp_vec3* s = malloc(sizeof(sp_vec3) * J);
    sp_mat4* w = malloc(sizeof(sp_mat4) * J);
    double* p = malloc(sizeof(double) * P);
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    const sp_animation* an = &rig->animations[0];
    int checked = 0;
    for (int k = 0; k <= 20; ++k) {
        double time = an->duration_s * k / 20.0;
        for (int j = 0; j < J; ++j) t[j] = rig->joints[j].rest_t, r[j] = rig->joints[j].rest_r, s[j] = rig->joints[j].rest_s;
        sp_animation_sample(an, time, t, r, s);
        sp_rig_defaults(rig, p);
        for (int j = 0; j < J; ++j) {
            sp_rig_params_from_trs(rig, j, t[j], r[j], s[j], p);
            sp_mat4 l = sp_mat4_trs(t[j], r[j], s[j]);
            w[j] = rig->joints[j].parent < 0 ? l : sp_mat4_mul(&w[rig->joints[j].parent], &l);
        }
        sp_rig_eval_update(ev, p, false);
        const sp_mat4* g = sp_rig_eval_world(ev);
        for (int j = 0; j < J; ++j) {
            sp_vec3 a = sp_mat4_translation(&w[j]), b = sp_mat4_translation(&g[j]);
            ENSURE_NEAR(a.x, b.x, 1e-6);
            ENSURE_NEAR(a.y, b.y, 1e-6);
            ENSURE_NEAR(a.z, b.z, 1e-6);
            ++checked;
        }
    }
    // The animation does move the joints (this is not the rest pose 21 times).
    for (int j = 0; j < J; ++j) t[j] = rig->joints[j].rest_t, r[j] = rig->joints[j].rest_r, s[j] = rig->joints[j].rest_s;
    sp_animation_sample(an, 0.5 * an->duration_s, t, r, s);
    double moved = 0;
    for (int j = 0; j < J; ++j) moved += fabs(r[j].x - rig->joints[j].rest_r.x) + fabs(r[j].w - rig->joints[j].rest_r.w);
    ENSURE(moved > 1e-3);
    fprintf(stderr, "  %s: %d joint positions at 21 times match\n", rel, checked);
    sp_rig_eval_destroy(ev);
    free(t), free(r), free(s), free(w), free(p);
    sp_character_free(&ch);
}

static void test_cesiumman(void) { check_model("CesiumMan/CesiumMan.glb"); }
static void test_riggedfigure(void) { check_model("RiggedFigure/RiggedFigure.glb"); }

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv, (sp_test[]){{"cesiumman", test_cesiumman}, {"riggedfigure", test_riggedfigure}, {0}});
}
