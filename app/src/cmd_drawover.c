// sketchpose drawover: the paper's on-the-fly abstraction. Each stroke of
// --on, drawn over the character in its view, is projected onto the mesh
// (eq. 2); the strokes of --to are their desired shapes.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "posing.h"
#include "solve_cmd.h"
#include "sp/curve.h"
#include "sp/embed.h"

// The shortest stroke drawn over the character, px.
#define DRAWOVER_MIN_PX 3.0

// One abstraction with a curve per stroke of `on`, embedded in the mesh.
static sp_result embed_strokes(const sp_rig* rig, const double* xyz, const sp_camera* cam, const sp_sketch* on, sp_abstraction* out,
                               sp_error* err)
{
    enum { SAMPLES = 48 };
    int n = on->stroke_count;
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "drawover");
    out->correspondence = SP_CORR_ORDERED;
    out->curves = calloc((size_t)n, sizeof(sp_curve));
    out->tri_vertices = malloc(sizeof(uint32_t) * 3 * SAMPLES * (size_t)n);
    out->bary = malloc(sizeof(double) * 3 * SAMPLES * (size_t)n);
    if (!out->curves || !out->tri_vertices || !out->bary) {
        sp_abstraction_free(out);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    for (int i = 0; i < n; ++i) {
        // A tap or a dot says no part of the character: embedded, it swung
        // the arm it touched to its bounds, exit 0 (as --to refuses it).
        double len = sp_curve_length(on->strokes[i].points, on->strokes[i].count, false);
        if (!(len >= DRAWOVER_MIN_PX)) {
            sp_abstraction_free(out);
            return sp_fail(err, SP_ERR_INVALID, "stroke %d is %.1f px long: too short to draw over a part (a tap?)", i, len);
        }
        sp_abstraction one;
        char name[32];
        snprintf(name, sizeof name, "stroke%d", i);
        sp_result r = sp_embed_curve(rig, xyz, cam, on->strokes[i].points, on->strokes[i].count, SAMPLES, name, &one, err);
        if (r != SP_OK) {
            char msg[sizeof err->text];
            snprintf(msg, sizeof msg, "stroke %d: %.480s", i, err->text);
            snprintf(err->text, sizeof err->text, "%s", msg);
            sp_abstraction_free(out);
            return r;
        }
        sp_curve* cv = &out->curves[i];
        *cv = one.curves[0];
        cv->first_point = out->point_count;
        memcpy(out->tri_vertices + 3 * out->point_count, one.tri_vertices, sizeof(uint32_t) * 3 * (size_t)one.point_count);
        memcpy(out->bary + 3 * out->point_count, one.bary, sizeof(double) * 3 * (size_t)one.point_count);
        out->point_count += one.point_count;
        sp_abstraction_free(&one);
    }
    out->curve_count = n;
    return SP_OK;
}

int cmd_drawover(int argc, char** argv)
{
    const char *rig_path = NULL, *on_path = NULL, *to_path = NULL, *out = NULL, *render = NULL, *report = NULL;
    sp_solve_desc desc = {0};
    double cap_ms = NAN, lambda_dist = NAN; // not given: the solver's defaults
    const sp_opt opts[] = {
        {"--rig", SP_OPT_IN, &rig_path, "R.gltf", "the rigged character (.gltf or .glb)", true},
        {"--on", SP_OPT_IN, &on_path, "S1.json", "strokes drawn over the character in its view", true},
        {"--to", SP_OPT_IN, &to_path, "S2.json", "the same strokes redrawn in their desired shape", true},
        {"--out", SP_OPT_OUT, &out, "posed.glb", "write the posed character", false},
        {"--render", SP_OPT_OUT, &render, "out.png", "write a picture: --on grey, --to blue, the fitted curves yellow", false},
        {"--report", SP_OPT_OUT, &report, "report.json", "write the solve report (also printed on stdout)", false},
        {"--lambda-dist", SP_OPT_DOUBLE, &lambda_dist, "L",
         "weight of W_dist, locality, for curves the character's size (default 0.001; scaled like the other weights by "
         "(the character's size / the curves' size)^2, at most 10000; 0 or negative: off)",
         false},
        {"--max-ms", SP_OPT_DOUBLE, &cap_ms, "MS", "time cap of the solve, " SP_CLI_MAX_MS_RANGE " (default 3000)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose drawover", "Draw-over posing: redraw curves drawn over the character.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!sp_cli_check_max_ms("sketchpose drawover", cap_ms) ||
        !sp_cli_check_out("sketchpose drawover", "--out", out, SP_CLI_OUT_GLTF) ||
        !sp_cli_check_out("sketchpose drawover", "--render", render, SP_CLI_OUT_PNG))
        return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose drawover", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    if (!isnan(cap_ms)) desc.time_cap_ms = cap_ms;
    desc.lambda_dist = sp_solve_cmd_lambda(lambda_dist);
    sp_rig_handle* rig = NULL;
    sp_error err = {0};
    sp_sketch on = {0}, to = {0};
    sp_solve_cmd run = {.cmd = "sketchpose drawover", .desc = desc};
    sp_abstraction emb = {0};
    cJSON* rep_json = NULL;
    double *p = NULL, *xyz = NULL;
    bool* active = NULL;
    sp_rig_eval* ev = NULL;
    int exit_code = SP_EXIT_INPUT;
    // Its curves are embedded in the mesh surface, and a black box evaluates
    // only the abstractions it declares.
    if (sp_rig_handle_load_character(rig_path, "draw-over", &rig, &err) != SP_OK) goto fail;
    sp_character* ch = sp_rig_handle_character(rig);
    run.rig = rig;
    if (sp_read_strokes(on_path, &on, &err) != SP_OK || sp_read_strokes(to_path, &to, &err) != SP_OK) goto fail;
    for (int i = 0; i < on.stroke_count; ++i) // each becomes a curve on the character (a tap in --to is left unused)
        if (on.strokes[i].count < 2) {
            sp_fail(&err, SP_ERR_INVALID, "%s: stroke %d is a tap (one point): a curve drawn over the character needs 2", on_path,
                    i);
            goto fail;
        }
    // Both drawings are on one screen: --to's points are read in --on's
    // canvas (its camera), so another canvas gave a wrong fit with exit 0.
    if (to.canvas_w > 0 && on.canvas_w > 0 && (to.canvas_w != on.canvas_w || to.canvas_h != on.canvas_h)) {
        sp_fail(&err, SP_ERR_INVALID, "%s: its canvas %gx%g is not --on's %gx%g (draw both over one view)", to_path, to.canvas_w,
                to.canvas_h, on.canvas_w, on.canvas_h);
        goto fail;
    }
    // A file without a canvas is on the other's (both missing: the rig's view).
    if (on.canvas_w <= 0) on.canvas_w = to.canvas_w, on.canvas_h = to.canvas_h;
    sp_camera cam = sp_rig_handle_camera(rig, on.canvas_w, on.canvas_h);
    if (sp_rig_handle_read_pose(rig, NULL, &p, NULL, &err) != SP_OK) goto fail;
    xyz = malloc(sizeof(double) * 3 * (size_t)(ch->rig.vertex_count + 1));
    sp_rig_eval_create(&ch->rig, &ev, NULL);
    if (!xyz || !ev) goto oom;
    sp_rig_eval_update(ev, p, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(&ch->rig), xyz);
    if (embed_strokes(&ch->rig, xyz, &cam, &on, &emb, &err) != SP_OK) {
        fprintf(stderr, "sketchpose drawover: %s: %s\n", on_path, err.text);
        goto done;
    }
    // The embedded curves join the rig for the solve and the picture; --out
    // writes the file's own abstractions (sp_rig_posed.saved_abstractions).
    run.abstraction = sp_rig_add_abstraction(&ch->rig, &emb);
    if (run.abstraction < 0) goto oom;
    if (!(active = sp_drawover_active(&ch->rig, &emb))) goto oom;
    run.desc.active = active;
    run.desc.ordered_by_ends = true; // a curve redrawn turned about one end keeps its ends
    double scale = sp_drawover_scale_weights(&run.desc, &ch->rig, xyz, &cam, &emb);
    sp_solve_report rep;
    if (!sp_solve_cmd_solve(&run, &cam, &to, to_path, p, p, &rep, &rep_json)) goto done;
    sp_drawover_note_held(&ch->rig, active, rep.note, sizeof rep.note);
    if (rep.note[0]) cJSON_ReplaceItemInObject(rep_json, "note", cJSON_CreateString(rep.note));
    // The weights the solve used (off: 0): they are scaled to the drawn curves.
    cJSON* w = cJSON_AddObjectToObject(rep_json, "weights");
    if (w) {
        cJSON_AddNumberToObject(w, "pose", fmax(run.desc.lambda_pose, 0));
        cJSON_AddNumberToObject(w, "plane", fmax(run.desc.lambda_plane, 0));
        cJSON_AddNumberToObject(w, "dist", fmax(run.desc.lambda_dist, 0));
        cJSON_AddNumberToObject(w, "scaled_by", scale);
    }
    sp_solve_outputs o = {.report = report, .out = out, .render = render, .strokes = &to, .ghost = &on, .note = rep.note};
    if (sp_solve_cmd_write(&run, rep_json, p, &o)) exit_code = SP_EXIT_OK;
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    fprintf(stderr, "sketchpose drawover: %s\n", err.text);
done:
    cJSON_Delete(rep_json);
    sp_solve_cmd_end(&run);
    sp_rig_eval_destroy(ev);
    sp_abstraction_free(&emb);
    free(p), free(xyz), free(active);
    sp_sketch_free(&on), sp_sketch_free(&to);
    sp_rig_handle_free(rig);
    return exit_code;
}
