// sketchpose demo: the kiosk's headless demo (the README's run command when
// there is no display). A visitor's session without a window: the default
// part database (created from assets/ when missing), one hand-drawn stroke
// per dragon part placed like a dragon on the kiosk's canvas, classified,
// fitted and attached by the kiosk pipeline; writes the strokes, a render,
// the animated .glb and the report, and says where.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "cli.h"
#include "report.h"
#include "sp/dragon.h"
#include "sp/dragon_snapshot.h"
#include "sp/handdraw.h"
#include "sp/sketch_io.h"

#ifndef SP_SOURCE_DIR
#define SP_SOURCE_DIR "."
#endif

enum { DEMO_W = 1280, DEMO_H = 800, DEMO_PARTS = 6, DEMO_TRIES = 12 };

// Where a visitor would draw each part (canvas centre and box diagonal, px), in drawing order.
static const struct {
    const char* category;
    double cx, cy, size;
} k_layout[DEMO_PARTS] = {
    {"torso", 640, 430, 400}, {"head", 910, 290, 200},       {"wings", 610, 220, 270},
    {"tail", 320, 450, 300},  {"front_legs", 770, 610, 190}, {"hind_legs", 500, 620, 200},
};

// A hand-drawn stroke of the category's first part (seed `seed`), moved into its layout box.
static sp_result part_stroke(sp_db* db, int li, uint64_t seed, sp_vec2** xy, int* n, sp_error* err)
{
    char** names = NULL;
    int count = 0;
    sp_character ch = {0};
    sp_sketch sk = {0};
    *xy = NULL;
    sp_result r = sp_db_category_parts(db, k_layout[li].category, &names, &count, err);
    if (r == SP_OK && count == 0) r = sp_fail(err, SP_ERR_INVALID, "%s: no %s part", sp_db_path(db), k_layout[li].category);
    sp_db_part_info info;
    if (r == SP_OK) r = sp_db_part(db, names[0], &info, err);
    if (r == SP_OK) r = sp_db_load_part(db, names[0], &ch, err);
    int a = r == SP_OK ? sp_rig_find_abstraction(&ch.rig, info.abstraction) : -1;
    if (r == SP_OK && a < 0) r = sp_fail(err, SP_ERR_INVALID, "%s: part %s has no abstraction %s", sp_db_path(db), names[0], info.abstraction);
    if (r == SP_OK) r = sp_handdraw_part(&ch.rig, a, &ch.camera, &(sp_handdraw_desc){.style = SP_HANDDRAW_NORMAL}, seed, &sk, NULL, err);
    sp_vec2 lo, hi;
    *n = r == SP_OK ? sp_sketch_point_count(&sk) : 0;
    if (r == SP_OK && (*n < 2 || !sp_sketch_bounds(&sk, &lo, &hi)))
        r = sp_fail(err, SP_ERR_INVALID, "part %s: its hand-drawn sketch is empty", names[0]);
    if (r == SP_OK && !(*xy = malloc(sizeof(sp_vec2) * (size_t)*n))) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (r == SP_OK) {
        // One stroke: the model draws an outline as one (or a few joined) strokes.
        double f = k_layout[li].size / fmax(sp_v2_len(sp_v2_sub(hi, lo)), 1e-9);
        sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
        int k = 0;
        for (int s = 0; s < sk.stroke_count; ++s)
            for (int i = 0; i < sk.strokes[s].count; ++i, ++k)
                (*xy)[k] = (sp_vec2){k_layout[li].cx + f * (sk.strokes[s].points[i].x - c.x),
                                     k_layout[li].cy + f * (sk.strokes[s].points[i].y - c.y)};
    }
    sp_sketch_free(&sk);
    sp_character_free(&ch);
    sp_db_free_strings(names, count);
    return r;
}

int cmd_demo(int argc, char** argv)
{
    const char *out_dir = "demo-out", *db_path = NULL, *assets = SP_SOURCE_DIR "/assets";
    int seed = 1;
    const sp_opt opts[] = {
        {"--out", SP_OPT_STRING, &out_dir, "DIR", "where to write the strokes, render, .glb and report (default demo-out)", false},
        {"--db", SP_OPT_STRING, &db_path, "DB", "part database (default: $SP_DB or sketchpose.db; created from --assets when missing)",
         false},
        {"--assets", SP_OPT_STRING, &assets, "DIR", "parts for a database that does not exist yet (default: the source tree's assets/)",
         false},
        {"--seed", SP_OPT_INT, &seed, "N", "first seed of the hand-drawn strokes (default 1)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose demo",
                          "The kiosk without a window: six hand-drawn dragon parts in, an animated dragon out.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (seed < 0) {
        fprintf(stderr, "sketchpose demo: --seed must not be negative\n");
        return SP_EXIT_USAGE;
    }
    if (mkdir(out_dir, 0755) != 0) {
        struct stat st;
        if (stat(out_dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
            fprintf(stderr, "sketchpose demo: %s: cannot create the folder\n", out_dir);
            return SP_EXIT_INPUT;
        }
    }
    sp_error err = {0};
    sp_db* db = NULL;
    const char* path = db_path ? db_path : sp_db_default_path();
    struct stat st;
    bool created = stat(path, &st) != 0;
    if (created) printf("creating the part database %s from %s (parts, hand-drawn sketches, a trained model)...\n", path, assets);
    fflush(stdout);
    if (sp_db_open_or_create_default(path, assets, SP_DB_READONLY, &db, &err) != SP_OK) {
        fprintf(stderr, "sketchpose demo: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    sp_dragon* d = sp_dragon_create(&(sp_dragon_desc){.db = db, .canvas_w = DEMO_W, .canvas_h = DEMO_H}, &err);
    if (!d) {
        fprintf(stderr, "sketchpose demo: %s\n", err.text);
        sp_db_close(db);
        return SP_EXIT_INPUT;
    }
    int exit_code = SP_EXIT_INPUT;
    sp_sketch drawn = {.canvas_w = DEMO_W, .canvas_h = DEMO_H};
    cJSON* j = NULL;
    char strokes[1200], png[1200], glb[1200], report[1200];
    snprintf(strokes, sizeof strokes, "%s/strokes.json", out_dir);
    snprintf(png, sizeof png, "%s/dragon.png", out_dir);
    snprintf(glb, sizeof glb, "%s/dragon.glb", out_dir);
    snprintf(report, sizeof report, "%s/report.json", out_dir);
    // A visitor whose drawing is not recognised draws again: each part gets
    // the first of a few hand-drawn strokes that becomes that part, and the
    // demo says how many tries it took.
    for (int li = 0; li < DEMO_PARTS; ++li) {
        bool placed = false;
        for (int t = 0; t < DEMO_TRIES && !placed; ++t) {
            sp_vec2* xy;
            int n;
            uint64_t s = sp_handdraw_seed((uint64_t)seed, 100 * li + t);
            if (part_stroke(db, li, s, &xy, &n, &err) != SP_OK) goto fail;
            sp_stroke stroke = {.count = n, .points = xy};
            sp_dragon_result res;
            sp_result r = sp_dragon_add_stroke(d, &stroke, NULL, &res, &err);
            bool right = r == SP_OK && !res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, k_layout[li].category);
            if (r == SP_OK && !res.rejected && !right) sp_dragon_undo(d);
            if (right) {
                placed = true;
                printf("  %-10s drawn %d time%s, recognised (%.0f%%), fitted in %.0f ms\n", k_layout[li].category, t + 1, t ? "s" : "",
                       100.0 * res.guesses[0].confidence, res.ms_fit);
                if (sp_sketch_add_stroke(&drawn, xy, NULL, n) != SP_OK) {
                    free(xy);
                    goto oom;
                }
            }
            free(xy);
            if (r != SP_OK) goto fail;
        }
        if (!placed) printf("  %-10s not recognised in %d tries: left out\n", k_layout[li].category, DEMO_TRIES);
    }
    if (sp_dragon_part_count(d) == 0) {
        fprintf(stderr, "sketchpose demo: no part was recognised; is the model in %s trained?\n", path);
        goto done;
    }
    j = sp_dragon_report_json(d);
    if (!j) goto oom;
    if (sp_sketch_write_json(strokes, &drawn, &err) != SP_OK || sp_json_write_file(report, j, &err) != SP_OK ||
        sp_dragon_export(d, glb, &err) != SP_OK ||
        sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true}, png, &err) != SP_OK)
        goto fail;
    printf("a dragon of %d parts (animation %.1f s, looped)\n", sp_dragon_part_count(d), sp_dragon_period(d));
    printf("wrote %s (parts, strokes blue, fitted outlines yellow), %s (animated), %s, %s\n", png, glb, strokes, report);
    printf("database: %s; again from these strokes: sketchpose dragon --db %s --strokes %s --out dragon.glb --render dragon.png\n", path,
           path, strokes);
    exit_code = SP_EXIT_OK;
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    fprintf(stderr, "sketchpose demo: %s\n", err.text);
done:
    cJSON_Delete(j);
    sp_sketch_free(&drawn);
    sp_dragon_destroy(d);
    sp_db_close(db);
    return exit_code;
}
