// sketchpose pose: redraw posing. Fits the rig to strokes drawn in its
// sketch view and writes the posed .glb, a PNG and the solve report.
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "plugin_rig.h"
#include "pose_io.h"
#include "posing.h"
#include "report.h"
#include "sp/gltf.h"
#include "sp/snapshot.h"
#include "sp/solver.h"

int cmd_pose(int argc, char** argv)
{
    const char *rig_path = NULL, *abs_name = NULL, *strokes = NULL, *out = NULL, *render = NULL, *report = NULL, *start = NULL;
    sp_solve_desc desc = {0};
    const sp_opt opts[] = {
        {"--rig", SP_OPT_STRING, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME", "which abstraction the strokes draw (default: the first)", false},
        {"--strokes", SP_OPT_STRING, &strokes, "S.json", "the strokes (sketchpose-strokes JSON)", true},
        {"--start", SP_OPT_STRING, &start, "p.json", "start pose (default: the rig's stored pose)", false},
        {"--out", SP_OPT_STRING, &out, "posed.glb", "write the posed character", false},
        {"--render", SP_OPT_STRING, &render, "out.png", "write a picture: strokes blue, fitted abstraction yellow", false},
        {"--report", SP_OPT_STRING, &report, "report.json", "write the solve report (also printed on stdout)", false},
        {"--lambda-pose", SP_OPT_DOUBLE, &desc.lambda_pose, "L", "weight of W_pose (default 0.5; negative: off)", false},
        {"--lambda-plane", SP_OPT_DOUBLE, &desc.lambda_plane, "L", "weight of W_plane (default 0.01; negative: off)", false},
        {"--lambda-dist", SP_OPT_DOUBLE, &desc.lambda_dist, "L", "weight of W_dist (default 0.001; negative: off)", false},
        {"--representatives", SP_OPT_INT, &desc.representatives, "K", "coarsening: representative vertices (default 200)", false},
        {"--max-iterations", SP_OPT_INT, &desc.max_iterations, "N", "Gauss-Newton iterations at most (default 300)", false},
        {"--max-ms", SP_OPT_DOUBLE, &desc.time_cap_ms, "MS", "time cap of the solve (default 3000)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose pose", "Redraw posing: fits the rig's abstraction to the strokes.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (sp_is_plugin_path(rig_path)) return sp_plugin_pose(rig_path, abs_name, strokes, start, out, render, report, &desc);
    sp_character ch = {0};
    sp_error err = {0};
    sp_sketch sk = {0};
    sp_solver* solver = NULL;
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_gltf_load(rig_path, &ch, &err) != SP_OK) goto fail;
    int a = sp_pick_abstraction(&ch, rig_path, abs_name, &err);
    if (a < 0) goto fail;
    if (sp_read_strokes(strokes, &sk, &err) != SP_OK) goto fail;
    sp_camera cam = sp_canvas_camera(&ch, &sk);
    p = malloc(sizeof(double) * (size_t)(ch.rig.param_count + 1));
    if (!p) goto oom;
    for (int i = 0; i < ch.rig.param_count; ++i) p[i] = ch.pose[i];
    if (start && sp_pose_read(start, &ch.rig, p, NULL, &err) != SP_OK) goto fail;
    solver = sp_solver_create(&ch.rig, a, &cam, &desc);
    if (!solver) goto oom;
    sp_solve_report rep;
    if (sp_solver_solve(solver, &sk, p, p, &rep, &err) != SP_OK) {
        fprintf(stderr, "sketchpose pose: %s: %s\n", strokes, err.text);
        goto done;
    }
    cJSON* j = sp_report_to_json(&rep, &ch.rig, &ch.rig.abstractions[a], p);
    sp_result wr = report ? sp_json_write_file(report, j, &err) : SP_OK;
    sp_json_print(j);
    cJSON_Delete(j);
    if (wr != SP_OK) goto fail;
    if (out && sp_gltf_save(&ch, p, out, &err) != SP_OK) goto fail;
    if (render) {
        sp_snapshot_desc d = {.character = &ch, .params = p, .camera = &cam, .abstraction = a, .strokes = &sk};
        if (sp_snapshot_png(&d, render, &err) != SP_OK) goto fail;
    }
    if (rep.note[0]) fprintf(stderr, "sketchpose pose: %s\n", rep.note);
    exit_code = SP_EXIT_OK;
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    fprintf(stderr, "sketchpose pose: %s\n", err.text);
done:
    sp_solver_destroy(solver);
    free(p);
    sp_sketch_free(&sk);
    sp_character_free(&ch);
    return exit_code;
}
