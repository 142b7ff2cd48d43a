// sketchpose dragon: the kiosk pipeline without a window. Every stroke of the
// file is one part, in order: classified, instantiated, fitted where it was
// drawn, attached where it touches a body; the dragon is written as one
// animated .glb, a PNG and the report (DESIGN.md "dragon --report").
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cli.h"
#include "commands.h"
#include "outputs.h"
#include "posing.h"
#include "report.h"
#include "sp/dragon.h"
#include "sp/dragon_snapshot.h"

#ifndef SP_SOURCE_DIR
#define SP_SOURCE_DIR "."
#endif

// The stroke file, as the pipeline takes it; false after one line on stderr.
static bool read_strokes(const char* strokes, sp_sketch* sk)
{
    sp_error err = {0};
    // Through the posing commands' reader: an SVG drawing was "malformed JSON near line 1".
    if (sp_read_drawing(strokes, sk, &err) != SP_OK) {
        fprintf(stderr, "sketchpose dragon: %s\n", err.text);
        return false;
    }
    if (sk->stroke_count == 0) {
        fprintf(stderr, "sketchpose dragon: %s: the file has no strokes\n", strokes);
        sp_sketch_free(sk);
        return false;
    }
    // The kiosk's canvas is at most 16384 px a side (a render target's);
    // a larger one was replaced by 1280 x 800 with no word, its strokes off it.
    if (sk->canvas_w > 16384 || sk->canvas_h > 16384) {
        fprintf(stderr, "sketchpose dragon: %s: canvas %g x %g is larger than the kiosk pipeline's 16384 px a side\n", strokes,
                sk->canvas_w, sk->canvas_h);
        sp_sketch_free(sk);
        return false;
    }
    return true;
}

// The per-stroke lines on stderr: the first STROKE_LINES_MAX, then one
// line for the rest (the report keeps every stroke). 500 dots said 500 lines.
enum { STROKE_LINES_MAX = 10 };
typedef struct stroke_lines {
    double canvas_w, canvas_h; // the pipeline's canvas
    int said;
    int unsaid[SP_DRAGON_DETAIL + 1]; // left out past the cap, by reason (SP_DRAGON_DETAIL: kept as details)
} stroke_lines;

// Whether every point of the stroke lies off the canvas (the pipeline calls
// it too_short: what is left of it on the canvas is nothing).
static bool off_canvas(const stroke_lines* l, const sp_stroke* st)
{
    return st->count > 0 && sp_stroke_points_off_canvas(st, l->canvas_w, l->canvas_h) == st->count;
}

static void say_stroke(stroke_lines* l, const sp_dragon* d, const sp_dragon_result* res, const sp_stroke* st, const char* file,
                       int i)
{
    sp_dragon_detail e;
    bool detail = res->detail >= 0 && sp_dragon_detail_get(d, res->detail, &e);
    if (!detail && !res->rejected) return;
    if (l->said >= STROKE_LINES_MAX) {
        int r = detail ? SP_DRAGON_DETAIL : (int)res->reason;
        ++l->unsaid[r >= 0 && r <= SP_DRAGON_DETAIL ? r : SP_DRAGON_UNRECOGNISED]; // a reason added after DETAIL stays counted
        return;
    }
    ++l->said;
    if (detail)
        fprintf(stderr, "sketchpose dragon: %s: stroke %d kept as a detail on part %d\n", file, i, e.part);
    else if (res->reason == SP_DRAGON_NO_PART && sp_dragon_part_error(d)[0])
        fprintf(stderr, "sketchpose dragon: %s: stroke %d left out (no_part: %s)\n", file, i, sp_dragon_part_error(d));
    else if (res->reason == SP_DRAGON_TOO_SHORT && off_canvas(l, st))
        fprintf(stderr, "sketchpose dragon: %s: stroke %d left out (too_short: it lies off the canvas)\n", file, i);
    else
        fprintf(stderr, "sketchpose dragon: %s: stroke %d left out (%s)\n", file, i, sp_dragon_reject_name(res->reason));
}

// "... and 490 more strokes left out (too_short 480, full 10)", one line.
static void say_strokes_unsaid(const stroke_lines* l, const char* file)
{
    int n = 0, details = l->unsaid[SP_DRAGON_DETAIL];
    char why[256] = "";
    for (int r = 0; r < SP_DRAGON_DETAIL; ++r)
        if (l->unsaid[r]) {
            size_t at = strlen(why);
            snprintf(why + at, sizeof why - at, "%s%s %d", n ? ", " : "", sp_dragon_reject_name((sp_dragon_reject)r),
                     l->unsaid[r]);
            n += l->unsaid[r];
        }
    if (n)
        fprintf(stderr, "sketchpose dragon: %s: ... and %d more stroke%s left out (%s)%s\n", file, n, n == 1 ? "" : "s", why,
                details ? ", more kept as details" : "");
    else if (details)
        fprintf(stderr, "sketchpose dragon: %s: ... and %d more stroke%s kept as details\n", file, details,
                details == 1 ? "" : "s");
}

// The report's curves name the stroke of the file their part came from:
// the library counts one stroke per part, which a refused stroke or one
// kept as a detail before it puts off by one (an outside review). `list`:
// the "strokes" entries, in file order.
static void curves_name_file_strokes(cJSON* report, const cJSON* list)
{
    const cJSON *s, *cv;
    cJSON_ArrayForEach(cv, cJSON_GetObjectItem(report, "curves"))
    {
        cJSON* stroke = cJSON_GetObjectItem(cv, "stroke");
        const cJSON* part = cJSON_GetObjectItem(cv, "part");
        if (!cJSON_IsNumber(stroke) || !cJSON_IsNumber(part)) continue;
        cJSON_ArrayForEach(s, list)
        {
            const cJSON* sp = cJSON_GetObjectItem(s, "part");
            if (cJSON_IsFalse(cJSON_GetObjectItem(s, "rejected")) && cJSON_IsNumber(sp) && sp->valueint == part->valueint)
                cJSON_SetNumberValue(stroke, cJSON_GetObjectItem(s, "stroke")->valuedouble);
        }
    }
}

int cmd_dragon(int argc, char** argv)
{
    const char *db_path = NULL, *strokes = NULL, *out = NULL, *render = NULL, *report = NULL, *assets = NULL;
    double max_ms = NAN, at = 0; // NAN: not given
    const sp_opt opts[] = {
        {"--db", SP_OPT_IN, &db_path, "DB",
         "the part database (default: $SP_DB, else ./sketchpose.db, as for demo, db and the kiosk; created from --assets when "
         "missing)",
         false},
        {"--strokes", SP_OPT_IN, &strokes, "S.json",
         "the strokes, one per part, in drawing order (sketchpose-strokes JSON, or an SVG drawing as for pose)", true},
        {"--out", SP_OPT_OUT, &out, "dragon.glb", "write the animated dragon (.glb, or .gltf)", false},
        {"--render", SP_OPT_OUT, &render, "out.png", "write a picture: parts, strokes blue, fitted outlines yellow", false},
        {"--report", SP_OPT_OUT, &report, "report.json", "write the report (also printed on stdout)", false},
        {"--assets", SP_OPT_STRING, &assets, "DIR",
         "parts for a database that does not exist yet (default: $SP_ASSETS, else the source tree's assets/)", false},
        {"--max-ms", SP_OPT_DOUBLE, &max_ms, "MS", "time cap of each part's solve, " SP_CLI_MAX_MS_RANGE " (default 250)", false},
        {"--time", SP_OPT_DOUBLE, &at, "S",
         "animation time, s in [0, 3600] (default 0: the loop's start; shipped parts as fitted)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose dragon",
                          "The kiosk pipeline without a window: one part per stroke, one animated dragon.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    // --time: the animation loops every few seconds, so an hour reaches every
    // picture; a negative time was taken as a time counted back from a loop.
    if (!sp_cli_check_max_ms("sketchpose dragon", max_ms) ||
        !sp_cli_check_double("sketchpose dragon", "--time", at, 0, false, 3600) ||
        !sp_cli_check_out("sketchpose dragon", "--out", out, SP_CLI_OUT_GLTF) ||
        !sp_cli_check_out("sketchpose dragon", "--render", render, SP_CLI_OUT_PNG))
        return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose dragon", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    sp_error err = {0};
    sp_sketch sk = {0};
    if (!read_strokes(strokes, &sk)) return SP_EXIT_INPUT;
    int w = sk.canvas_w >= 1 ? (int)sk.canvas_w : 0, h = sk.canvas_h >= 1 ? (int)sk.canvas_h : 0;
    const char* path = db_path ? db_path : sp_db_default_path();
    if (access(path, F_OK) != 0) announce_db_build(path, assets ? assets : sp_dragon_default_assets()); // it waited silently
    sp_dragon* d;
    sp_dragon_create(&(sp_dragon_desc){.db_path = db_path,
                                       .assets_dir = assets,
                                       .canvas_w = w,
                                       .canvas_h = h,
                                       .solve = {.time_cap_ms = isnan(max_ms) ? 0 : max_ms}},
                     &d, &err);
    if (!d) {
        fprintf(stderr, "sketchpose dragon: %s\n", err.text);
        sp_sketch_free(&sk);
        return SP_EXIT_INPUT;
    }
    int exit_code = SP_EXIT_INPUT;
    cJSON* j = NULL;
    if (!sp_dragon_model(d)) { // every stroke would be refused, each blaming the stroke file
        fprintf(stderr, "sketchpose dragon: %s\n", sp_dragon_model_error(d));
        sp_dragon_destroy(d);
        sp_sketch_free(&sk);
        return SP_EXIT_INPUT;
    }
    sp_outputs staged = {0};
    stroke_lines said = {.canvas_w = w ? w : 1280, .canvas_h = h ? h : 800}; // sp_dragon_desc's default canvas
    cJSON* list = cJSON_CreateArray();
    for (int i = 0; i < sk.stroke_count; ++i) {
        sp_dragon_result res;
        cJSON* s = cJSON_CreateObject();
        cJSON_AddItemToArray(list, s);
        cJSON_AddNumberToObject(s, "stroke", i);
        if (sp_dragon_add_stroke(d, &sk.strokes[i], NULL, &res, &err) != SP_OK) {
            fprintf(stderr, "sketchpose dragon: %s: stroke %d: %s\n", strokes, i, err.text);
            goto done;
        }
        cJSON_AddBoolToObject(s, "rejected", res.rejected);
        cJSON_AddStringToObject(s, "reason", sp_dragon_reject_name(res.reason));
        cJSON_AddStringToObject(s, "note", sp_dragon_note_name(res.note));
        if (res.part >= 0)
            cJSON_AddNumberToObject(s, "part", res.part);
        else
            cJSON_AddNullToObject(s, "part");
        if (res.detail >= 0)
            cJSON_AddNumberToObject(s, "detail", res.detail);
        else
            cJSON_AddNullToObject(s, "detail");
        cJSON* g = cJSON_AddArrayToObject(s, "ranked");
        for (int k = 0; k < res.guess_count; ++k) {
            cJSON* o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "category", res.guesses[k].category);
            cJSON_AddNumberToObject(o, "score", res.guesses[k].confidence);
            cJSON_AddItemToArray(g, o);
        }
        // How far from every part (refused over SP_DRAGON_FAR_LIMIT): a curator can see
        // how near a refused drawing of their part came (null: not measured).
        if (isfinite(res.far_score))
            cJSON_AddNumberToObject(s, "far_score", res.far_score);
        else
            cJSON_AddNullToObject(s, "far_score");
        cJSON_AddNumberToObject(s, "ms", res.ms_total);
        say_stroke(&said, d, &res, &sk.strokes[i], strokes, i);
    }
    say_strokes_unsaid(&said, strokes);
    char* text = NULL;
    if (sp_dragon_report_json(d, &text, &err) != SP_OK) goto fail;
    j = cJSON_Parse(text);
    free(text);
    if (!j) {
        sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
        goto fail;
    }
    curves_name_file_strokes(j, list);
    cJSON_AddItemToObject(j, "strokes", list);
    list = NULL;
    if (sp_dragon_part_count(d) == 0) {
        sp_json_print(j);
        fprintf(stderr, "sketchpose dragon: %s: no stroke became a part\n", strokes);
        goto done;
    }
    const char *rep_to, *out_to, *render_to;
    if (sp_outputs_stage(&staged, report, &rep_to, &err) != SP_OK || sp_outputs_stage(&staged, out, &out_to, &err) != SP_OK ||
        sp_outputs_stage(&staged, render, &render_to, &err) != SP_OK)
        goto fail;
    if (rep_to && sp_json_write_file(rep_to, j, &err) != SP_OK) goto fail;
    if (out_to && sp_dragon_export(d, out_to, &err) != SP_OK) goto fail;
    if (render_to) {
        sp_dragon_snapshot_desc sd = {.t = at, .strokes = true, .outlines = true};
        if (sp_dragon_snapshot_png(d, &sd, render_to, &err) != SP_OK) goto fail;
    }
    if (sp_outputs_commit(&staged, &err) != SP_OK) goto fail;
    if (!sp_cli_stdout_taken((const char* const[]){report, out, render}, 3)) sp_json_print(j);
    exit_code = SP_EXIT_OK;
    goto done;
fail:
    sp_outputs_undo(&staged, &err);
    fprintf(stderr, "sketchpose dragon: %s\n", err.text);
done:
    cJSON_Delete(list);
    cJSON_Delete(j);
    sp_dragon_destroy(d);
    sp_sketch_free(&sk);
    return exit_code;
}
