// sketchpose demo: the kiosk's headless demo (the README's run command when
// there is no display). A visitor's session without a window: the default
// part database (created from assets/ when missing), one hand-drawn stroke
// per dragon part placed like a dragon on the kiosk's canvas, classified,
// fitted and attached by the kiosk pipeline; writes the strokes, a render,
// the animated .glb and the report, and says where: that result on stdout,
// the progress on the way (the database built, each part's tries) on stderr.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "cli.h"
#include "commands.h"
#include "outputs.h"
#include "report.h"
#include "sp/dragon.h"
#include "sp/dragon_snapshot.h"
#include "sp/handdraw.h"
#include "sp/sketch_io.h"

#ifndef SP_SOURCE_DIR
#define SP_SOURCE_DIR "."
#endif

enum { DEMO_W = 1280, DEMO_H = 800, DEMO_TRIES = 12 };

// Where a visitor draws the body: the middle of the canvas.
#define TORSO_X 640
#define TORSO_Y 420
#define TORSO_SIZE 420

// Where the other parts go: touching the body, as a visitor draws them: the
// part's attachment end lands `inside` px (below) within the body's
// silhouette at `along` (0: the tail end, 1: the front end) on its top,
// bottom, front or back end.
typedef enum { ON_TOP, ON_BOTTOM, ON_FRONT, ON_BACK } side;
static const struct {
    const char* category;
    double along;
    side on;
    double size; // the stroke's box diagonal, pixels
} k_layout[] = {
    {"torso", 0, ON_TOP, TORSO_SIZE},     {"head", 1, ON_FRONT, 220},          {"wings", 0.43, ON_TOP, 270},
    {"wings", 0.63, ON_TOP, 220},         {"tail", 0, ON_BACK, 330},           {"front_legs", 0.8, ON_BOTTOM, 190},
    {"front_legs", 0.58, ON_BOTTOM, 180}, {"hind_legs", 0.33, ON_BOTTOM, 200},
};
enum { DEMO_PARTS = sizeof k_layout / sizeof k_layout[0] };

// The body on the canvas at t = 0: its projected vertices.
typedef struct body {
    sp_vec2* px;
    int n;
    double x0, x1;
} body;

static bool body_of(sp_dragon* d, body* b, sp_error* err)
{
    if (sp_dragon_pose_at(d, 0, err) != SP_OK) return false;
    const sp_dragon_part* p = sp_dragon_part_get(d, 0);
    const double* xyz = sp_dragon_part_xyz(d, 0);
    b->n = p->character->rig.vertex_count;
    b->px = malloc(sizeof(sp_vec2) * (size_t)(b->n > 0 ? b->n : 1));
    if (!b->px) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory"), false;
    sp_camera cam = sp_dragon_camera(d);
    b->x0 = INFINITY, b->x1 = -INFINITY;
    for (int v = 0; v < b->n; ++v) {
        b->px[v] = sp_camera_project(&cam, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
        b->x0 = fmin(b->x0, b->px[v].x), b->x1 = fmax(b->x1, b->px[v].x);
    }
    return b->n > 0;
}

// The body's silhouette at column x: its top and bottom.
static void body_span(const body* b, double x, double* top, double* bottom)
{
    *top = INFINITY, *bottom = -INFINITY;
    for (double w = 3; !(*top <= *bottom) && w < 100; w *= 2)
        for (int v = 0; v < b->n; ++v)
            if (fabs(b->px[v].x - x) < w) *top = fmin(*top, b->px[v].y), *bottom = fmax(*bottom, b->px[v].y);
}

// Where part li's attachment end is drawn, on the body.
static sp_vec2 grip_point(const body* b, int li)
{
    const double inside = 12;
    double x = b->x0 + k_layout[li].along * (b->x1 - b->x0), top, bottom;
    switch (k_layout[li].on) {
    case ON_TOP:
        body_span(b, x, &top, &bottom);
        return (sp_vec2){x, top + inside};
    case ON_BOTTOM:
        body_span(b, x, &top, &bottom);
        return (sp_vec2){x, bottom - inside};
    case ON_FRONT:
        x = b->x1 - 2 * inside;
        body_span(b, x, &top, &bottom);
        return (sp_vec2){x, top + 0.3 * (bottom - top)};
    case ON_BACK:
        x = b->x0 + 2 * inside;
        body_span(b, x, &top, &bottom);
        return (sp_vec2){x, 0.5 * (top + bottom)};
    }
    return (sp_vec2){x, 0};
}

// A hand-drawn stroke of the category's first part (seed `seed`), `size` px
// across, its box centred at `at`.
static sp_result part_stroke(sp_db* db, int li, uint64_t seed, sp_vec2 at, sp_vec2** xy, int* n, sp_error* err)
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
    if (r == SP_OK && a < 0)
        r = sp_fail(err, SP_ERR_INVALID, "%s: part %s has no abstraction %s", sp_db_path(db), names[0], info.abstraction);
    if (r == SP_OK)
        r = sp_handdraw_part(&ch.rig, a, &ch.camera, &(sp_handdraw_desc){.style = SP_HANDDRAW_NORMAL}, seed, &sk, NULL, err);
    sp_vec2 lo, hi;
    *n = r == SP_OK ? sp_sketch_point_count(&sk) : 0;
    if (r == SP_OK && (*n < 2 || !sp_sketch_bounds(&sk, &lo, &hi)))
        r = sp_fail(err, SP_ERR_INVALID, "part %s: its hand-drawn sketch is empty", names[0]);
    if (r == SP_OK && !(*xy = malloc(sizeof(sp_vec2) * (size_t)*n))) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (r == SP_OK) {
        // One stroke: the model draws an outline as one (or a few joined) strokes.
        double f = k_layout[li].size / fmax(sp_v2_len(sp_v2_sub(hi, lo)), 1e-9);
        sp_vec2 g = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
        int k = 0;
        for (int s = 0; s < sk.stroke_count; ++s)
            for (int i = 0; i < sk.strokes[s].count; ++i, ++k)
                (*xy)[k] = (sp_vec2){at.x + f * (sk.strokes[s].points[i].x - g.x), at.y + f * (sk.strokes[s].points[i].y - g.y)};
    }
    sp_sketch_free(&sk);
    sp_character_free(&ch);
    sp_db_free_strings(names, count);
    return r;
}

// The demo's last line: the database, and the command that makes the same
// dragon again, to paste: this very program, every path quoted for the shell.
static void print_again(const char* db_path, const char* strokes)
{
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    self[n > 0 ? n : 0] = 0;
    printf("database: %s; again from these strokes: ", db_path);
    const char* words[] = {n > 0 ? self : "sketchpose",
                           "dragon",
                           "--db",
                           db_path,
                           "--strokes",
                           strokes,
                           "--out",
                           "dragon.glb",
                           "--render",
                           "dragon.png"};
    for (size_t i = 0; i < sizeof words / sizeof words[0]; ++i) {
        if (i) putchar(' ');
        sp_cli_print_shell_word(stdout, words[i]);
    }
    putchar('\n');
}

void announce_db_build(const char* path, const char* assets)
{
    fprintf(stderr, "creating the part database %s from %s (parts, hand-drawn sketches, a trained model)...\n", path, assets);
    char note[1200];
    if (sp_db_people_note(assets, note, sizeof note)) fprintf(stderr, "note: %s\n", note);
}

int cmd_demo(int argc, char** argv)
{
    const char *out_dir = "demo-out", *db_path = NULL, *assets = NULL;
    int seed = 1;
    const sp_opt opts[] = {
        {"--out", SP_OPT_STRING, &out_dir, "DIR", "where to write the strokes, render, .glb and report (default demo-out)",
         false},
        {"--db", SP_OPT_STRING, &db_path, "DB",
         "part database (default: $SP_DB or sketchpose.db; created from --assets when missing)", false},
        {"--assets", SP_OPT_STRING, &assets, "DIR",
         "parts for a database that does not exist yet (default: $SP_ASSETS, else the source tree's assets/)", false},
        {"--seed", SP_OPT_INT, &seed, "N", "first seed of the hand-drawn strokes (default 1)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose demo",
                          "The kiosk without a window: eight hand-drawn dragon parts in, an animated dragon out.", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (seed < 0) {
        fprintf(stderr, "sketchpose demo: --seed must not be negative\n");
        return SP_EXIT_USAGE;
    }
    // Made first, so that a folder that cannot be made is said before the
    // database is built; a demo that fails removes it again when it is
    // still empty (rmdir removes nothing else).
    bool made_out = mkdir(out_dir, 0755) == 0;
    sp_error err = {0};
    if (!made_out && sp_dir_make(out_dir, &err) != SP_OK) { // one there already is fine; else it says why
        fprintf(stderr, "sketchpose demo: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    sp_db* db = NULL;
    if (!assets) assets = sp_dragon_default_assets();
    const char* path = db_path ? db_path : sp_db_default_path();
    struct stat st;
    bool created = stat(path, &st) != 0;
    if (created) announce_db_build(path, assets);
    if (sp_db_open_or_create_default(path, assets, SP_DB_READONLY, &db, &err) != SP_OK) {
        fprintf(stderr, "sketchpose demo: %s\n", err.text);
        if (made_out) rmdir(out_dir);
        return SP_EXIT_INPUT;
    }
    sp_dragon* d;
    sp_dragon_create(&(sp_dragon_desc){.db = db, .canvas_w = DEMO_W, .canvas_h = DEMO_H}, &d, &err);
    if (!d || !sp_dragon_model(d)) { // without a model no drawing becomes a part
        fprintf(stderr, "sketchpose demo: %s\n", d ? sp_dragon_model_error(d) : err.text);
        sp_dragon_destroy(d);
        sp_db_close(db);
        if (made_out) rmdir(out_dir);
        return SP_EXIT_INPUT;
    }
    int exit_code = SP_EXIT_INPUT;
    sp_outputs staged = {0};
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
    body b = {0};
    for (int li = 0; li < DEMO_PARTS; ++li) {
        bool placed = false;
        // The torso first, in the middle; then every other part touching it.
        if (li > 0 && !b.px && sp_dragon_part_count(d) > 0 && !body_of(d, &b, &err)) goto fail;
        sp_vec2 at = b.px ? grip_point(&b, li) : (sp_vec2){TORSO_X, TORSO_Y};
        for (int t = 0; t < DEMO_TRIES && !placed; ++t) {
            sp_vec2* xy;
            int n;
            uint64_t s = sp_handdraw_seed((uint64_t)seed, 100 * li + t);
            if (part_stroke(db, li, s, at, &xy, &n, &err) != SP_OK) goto fail;
            sp_stroke stroke = {.count = n, .points = xy};
            sp_dragon_result res;
            sp_result r = sp_dragon_add_stroke(d, &stroke, NULL, &res, &err);
            bool right = r == SP_OK && !res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, k_layout[li].category);
            if (r == SP_OK && !res.rejected && !right) sp_dragon_undo(d);
            if (right && li > 0 && b.px) {
                // Drawn with its attachment end on the body: the same stroke,
                // moved so that the end the fit found lands on the grip point.
                sp_vec2 off = sp_v2_sub(at, sp_dragon_part_get(d, res.part)->attach_end);
                for (int i = 0; i < n; ++i)
                    xy[i] = sp_v2_add(xy[i], off);
                float conf = res.guesses[0].confidence;
                sp_dragon_undo(d);
                r = sp_dragon_add_stroke(d, &stroke, &(sp_dragon_stroke_opts){.category = k_layout[li].category}, &res, &err);
                right = r == SP_OK && !res.rejected;
                res.guesses[0].confidence = conf;
            }
            if (right) {
                placed = true;
                fprintf(stderr, "  %-10s drawn %d time%s, recognised (%.0f%%), fitted in %.0f ms%s\n", k_layout[li].category,
                        t + 1, t ? "s" : "", 100.0 * res.guesses[0].confidence, res.ms_fit,
                        sp_dragon_part_get(d, res.part)->attached_to >= 0 ? ", on the body" : "");
                if (sp_sketch_add_stroke(&drawn, xy, NULL, n) != SP_OK) {
                    free(xy);
                    goto oom;
                }
            }
            free(xy);
            if (r != SP_OK) goto fail;
        }
        if (!placed) fprintf(stderr, "  %-10s not recognised in %d tries: left out\n", k_layout[li].category, DEMO_TRIES);
    }
    if (sp_dragon_part_count(d) == 0) {
        fprintf(stderr, "sketchpose demo: no part was recognised by the model in %s\n", path);
        goto done;
    }
    char* text = NULL;
    if (sp_dragon_report_json(d, &text, &err) != SP_OK) goto fail;
    j = cJSON_Parse(text);
    free(text);
    if (!j) goto oom;
    // The four files together or none, over a folder of an earlier demo.
    const char *strokes_to, *report_to, *glb_to, *png_to;
    if (sp_outputs_stage(&staged, strokes, &strokes_to, &err) != SP_OK ||
        sp_outputs_stage(&staged, report, &report_to, &err) != SP_OK || sp_outputs_stage(&staged, glb, &glb_to, &err) != SP_OK ||
        sp_outputs_stage(&staged, png, &png_to, &err) != SP_OK || sp_sketch_write_json(strokes_to, &drawn, &err) != SP_OK ||
        sp_json_write_file(report_to, j, &err) != SP_OK || sp_dragon_export(d, glb_to, &err) != SP_OK ||
        sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true}, png_to, &err) != SP_OK ||
        sp_outputs_commit(&staged, &err) != SP_OK)
        goto fail;
    printf("a dragon of %d parts (animation %.1f s, looped)\n", sp_dragon_part_count(d), sp_dragon_period(d));
    printf("wrote %s (parts, strokes blue, fitted outlines yellow), %s (animated), %s, %s\n", png, glb, strokes, report);
    print_again(path, strokes);
    exit_code = SP_EXIT_OK;
    goto done;
oom:
    sp_fail(&err, SP_ERR_NO_MEMORY, "out of memory");
fail:
    sp_outputs_undo(&staged, &err);
    fprintf(stderr, "sketchpose demo: %s\n", err.text);
done:
    if (exit_code != SP_EXIT_OK && made_out) rmdir(out_dir);
    free(b.px);
    cJSON_Delete(j);
    sp_sketch_free(&drawn);
    sp_dragon_destroy(d);
    sp_db_close(db);
    return exit_code;
}
