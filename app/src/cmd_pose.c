// sketchpose pose: redraw posing. Fits the rig (a glTF character or a
// black-box plugin) to strokes drawn in its sketch view and writes the
// posed .glb, a PNG and the solve report.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "commands.h"
#include "posing.h"
#include "solve_cmd.h"

int cmd_pose(int argc, char** argv)
{
    const char *rig_path = NULL, *abs_name = NULL, *strokes = NULL, *out = NULL, *render = NULL, *report = NULL, *start = NULL;
    sp_solve_desc desc = {0};
    // Not given: the solver's defaults; given, a value in range.
    int reps = SP_CLI_UNSET, iters = SP_CLI_UNSET;
    double cap_ms = NAN, lambda_pose = NAN, lambda_plane = NAN, lambda_dist = NAN;
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb), or a black-box rig plugin (.so)", true},
        {"--abstraction", SP_OPT_STRING, &abs_name, "NAME",
         "which abstraction the strokes draw (default: the part's own, else the first)", false},
        {"--strokes", SP_OPT_IN, &strokes, "S.json", "the strokes (sketchpose-strokes JSON, or an SVG drawing: .svg)", true},
        {"--start", SP_OPT_IN, &start, "p.json", "start pose (default: the rig's stored pose)", false},
        {"--out", SP_OPT_OUT, &out, "posed.glb", "write the posed character", false},
        {"--render", SP_OPT_OUT, &render, "out.png", "write a picture: strokes blue, fitted abstraction yellow", false},
        {"--report", SP_OPT_OUT, &report, "report.json", "write the solve report (also printed on stdout)", false},
        {"--lambda-pose", SP_OPT_DOUBLE, &lambda_pose, "L", "weight of W_pose (default 0.5; 0 or negative: off)", false},
        {"--lambda-plane", SP_OPT_DOUBLE, &lambda_plane, "L", "weight of W_plane (default 0.01; 0 or negative: off)", false},
        {"--lambda-dist", SP_OPT_DOUBLE, &lambda_dist, "L", "weight of W_dist (default 0.001; 0 or negative: off)", false},
        {"--representatives", SP_OPT_INT, &reps, "K", "coarsening: representative vertices, 1..100000 (default 200)", false},
        {"--max-iterations", SP_OPT_INT, &iters, "N", "Gauss-Newton iterations at most, each attempt, 1..1000000 (default 300)",
         false},
        {"--max-ms", SP_OPT_DOUBLE, &cap_ms, "MS", "time cap of the solve, " SP_CLI_MAX_MS_RANGE " (default 3000)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose pose", "Redraw posing: fits the rig's abstraction to the strokes.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    const char* cmd = "sketchpose pose";
    if ((reps != SP_CLI_UNSET && !sp_cli_check_int(cmd, "--representatives", reps, 1, 100000)) ||
        (iters != SP_CLI_UNSET && !sp_cli_check_int(cmd, "--max-iterations", iters, 1, 1000000)) ||
        !sp_cli_check_max_ms(cmd, cap_ms) || !sp_cli_check_out(cmd, "--out", out, SP_CLI_OUT_GLTF) ||
        !sp_cli_check_out(cmd, "--render", render, SP_CLI_OUT_PNG))
        return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders(cmd, opts, (int)(sizeof opts / sizeof opts[0]))) return SP_EXIT_INPUT; // before the work
    desc.lambda_pose = sp_solve_cmd_lambda(lambda_pose);
    desc.lambda_plane = sp_solve_cmd_lambda(lambda_plane);
    desc.lambda_dist = sp_solve_cmd_lambda(lambda_dist);
    if (reps != SP_CLI_UNSET) desc.representatives = reps;
    if (iters != SP_CLI_UNSET) desc.max_iterations = iters;
    if (!isnan(cap_ms)) desc.time_cap_ms = cap_ms;
    sp_error err = {0};
    sp_rig_handle* rig = NULL;
    sp_sketch sk = {0};
    sp_solve_cmd run = {.cmd = "sketchpose pose", .desc = desc};
    cJSON* rep_json = NULL;
    double* p = NULL;
    int exit_code = SP_EXIT_INPUT;
    if (sp_rig_handle_load(rig_path, &rig, &err) != SP_OK) goto fail;
    run.rig = rig;
    run.abstraction = sp_rig_handle_pick_abstraction(rig, abs_name, &err);
    if (run.abstraction < 0) goto fail;
    if (sp_read_strokes(strokes, &sk, &err) != SP_OK) goto fail;
    sp_camera cam = sp_rig_handle_camera(rig, sk.canvas_w, sk.canvas_h);
    if (sp_rig_handle_read_pose(rig, start, &p, NULL, &err) != SP_OK) goto fail;
    sp_solve_report rep;
    if (!sp_solve_cmd_solve(&run, &cam, &sk, strokes, p, p, &rep, &rep_json)) goto done;
    sp_solve_outputs o = {.report = report, .out = out, .render = render, .strokes = &sk, .note = rep.note};
    if (sp_solve_cmd_write(&run, rep_json, p, &o)) exit_code = SP_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "sketchpose pose: %s\n", err.text);
done:
    cJSON_Delete(rep_json);
    sp_solve_cmd_end(&run);
    free(p);
    sp_sketch_free(&sk);
    sp_rig_handle_free(rig);
    return exit_code;
}
