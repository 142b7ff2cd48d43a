// The headless kiosk pipeline (sp_dragon, app/dragon/include/sp/dragon.h) and `sketchpose dragon`:
// a dragon drawn from synthetic strokes of several parts is classified,
// fitted where it was drawn, attached, animated and exported (one .glb, a skin
// per part, one animation, 0 validator errors); rejected and broken strokes
// change nothing; undo / clear / refit; live update from a second connection
// and a database replaced on disk.
//
// The parts are built in code (tests/support/test_parts.h: chains in the XY
// plane with a tube mesh, a closed outline abstraction, a looping clip,
// sp_part sockets / attach hints), so the test does not depend on assets/;
// `six_real_parts` runs the same checks on the shipped parts once assets/
// holds them (skipped before).
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "dragon_internal.h" // fault injection: sp_dragon.fit_hook
#include "fixtures.h"
#include "sp/clock.h"
#include "sp/curve.h"
#include "sp/dragon.h"
#include "sp/dragon_snapshot.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"
#include "sp/synth.h"
#include "test.h"
#include "test_parts.h"

#define PI 3.14159265358979323846

// ---- test parts: tests/support/test_parts.h (the fixture library) -----------------

// Writes the part (flat: see test_part_rig) and adds it to the database with `sketches` synthetic sketches (-1: none).
static void add_spec_sketches(sp_db* db, const test_part_spec* s, bool flat, uint64_t seed, int sketches)
{
    char file[64];
    snprintf(file, sizeof file, "%s.glb", s->name);
    const char* path = sp_test_tmp_path(file);
    test_part_write(s, flat, path);
    sp_error err = {0};
    sp_result r =
        sp_db_add_part_file(db, path, &(sp_db_part_desc){.name = s->name, .synth_sketches = sketches, .seed = seed}, NULL, &err);
    if (r != SP_OK) fprintf(stderr, "  add-part %s: %s\n", s->name, err.text);
    ENSURE(r == SP_OK);
}

static void add_spec(sp_db* db, const test_part_spec* s, uint64_t seed)
{
    add_spec_sketches(db, s, false, seed, 40);
}

static sp_db_train_desc quick_train(void)
{
    return (sp_db_train_desc){.clf = {.words = 96, .vocab_samples = 8000, .threads = 2}, .folds = -1, .by = "test"};
}

static void train(sp_db* db)
{
    sp_error err = {0};
    sp_db_train_desc td = quick_train();
    sp_result r = sp_db_train(db, &td, NULL, &err);
    if (r != SP_OK) fprintf(stderr, "  train: %s\n", err.text);
    ENSURE(r == SP_OK);
}

// A new database at `path`: the five test parts, `extra` (NULL: none) and a model.
static void make_test_db(const char* path, const test_part_spec* extra)
{
    sp_fixture_remove_db(path);
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_CREATE, &db, &err) == SP_OK);
    for (int i = 0; i < TEST_PART_COUNT; ++i)
        add_spec(db, &k_test_parts[i], (uint64_t)i + 1);
    if (extra) add_spec(db, extra, 9);
    train(db);
    sp_db_close(db);
}

// The test database (built once per run): the five test parts and a model.
static const char* test_db(void)
{
    static char path[1024];
    if (path[0]) return path;
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("dragon_test.db"));
    make_test_db(path, NULL);
    return path;
}

static void copy_file(const char* from, const char* to)
{
    char cmd[2300];
    sp_fixture_remove_db(to);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", from, to);
    ENSURE(system(cmd) == 0);
}

// ---- strokes ----------------------------------------------------------------------

// A synthetic stroke of part `name` (its outline at a random pose, seed),
// scaled to `size` px of diagonal and moved so that `at` (canvas pixels) is
// its box's centre, or (by_root) its attachment end: the root joint's origin
// at the drawn pose. mirror: drawn facing the other way (left-right).
static int part_stroke_ex(sp_db* db, const char* name, uint64_t seed, double amplitude, sp_vec2 at, double size, bool by_root,
                          bool mirror, sp_vec2** out)
{
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_db_load_part(db, name, &ch, &err) == SP_OK);
    sp_db_part_info info;
    ENSURE(sp_db_part(db, name, &info, &err) == SP_OK);
    int a = sp_rig_find_abstraction(&ch.rig, info.abstraction);
    ENSURE(a >= 0);
    double* p = malloc(sizeof(double) * ((size_t)ch.rig.param_count + 1));
    sp_synth_params(&ch.rig, seed, amplitude, p);
    sp_sketch sk = {0};
    ENSURE(sp_synth_sketch(&ch.rig, a, &ch.camera, p, &sk) == SP_OK);
    ENSURE(sk.stroke_count >= 1);
    // Several curves (a real part might have them) are joined into one stroke, in order.
    int n = sp_sketch_point_count(&sk), k = 0;
    sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)n);
    for (int s = 0; s < sk.stroke_count; ++s)
        for (int i = 0; i < sk.strokes[s].count; ++i)
            xy[k++] = sk.strokes[s].points[i];
    sp_vec2 lo, hi;
    ENSURE(sp_sketch_bounds(&sk, &lo, &hi));
    double f = size / sp_v2_len(sp_v2_sub(hi, lo));
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
    if (by_root) {
        sp_rig_eval* ev;
        sp_rig_eval_create(&ch.rig, &ev, NULL);
        sp_rig_eval_update(ev, p, false);
        int root = 0;
        while (ch.rig.joints[root].parent >= 0)
            ++root;
        c = sp_camera_project(&ch.camera, sp_mat4_translation(&sp_rig_eval_world(ev)[root]));
        sp_rig_eval_destroy(ev);
    }
    for (int i = 0; i < n; ++i)
        xy[i] = (sp_vec2){at.x + (mirror ? -f : f) * (xy[i].x - c.x), at.y + f * (xy[i].y - c.y)};
    sp_sketch_free(&sk);
    free(p);
    sp_character_free(&ch);
    *out = xy;
    return n;
}

// A stroke of part `name` centred at (cx, cy), `size` px across.
static int part_stroke(sp_db* db, const char* name, uint64_t seed, double amplitude, double cx, double cy, double size,
                       sp_vec2** out)
{
    return part_stroke_ex(db, name, seed, amplitude, (sp_vec2){cx, cy}, size, false, false, out);
}

// Mean distance (px) from the stroke's points to the part's outline as drawn
// by the world camera at the last pose_at: the part is where it was drawn.
static double stroke_to_outline_px(const sp_dragon* d, int i)
{
    const sp_dragon_part* p = sp_dragon_part_get(d, i);
    const sp_abstraction* ab = &p->character->rig.abstractions[p->abstraction];
    const double* z = sp_dragon_part_outline(d, i);
    sp_camera cam = sp_dragon_camera(d);
    // Dense samples of the projected outline, so the distance is to the curve, not its vertices.
    int n = ab->point_count, m = 2000;
    sp_vec2* zz = malloc(sizeof(sp_vec2) * (size_t)n);
    sp_vec2* dense = malloc(sizeof(sp_vec2) * (size_t)m);
    for (int k = 0; k < n; ++k)
        zz[k] = sp_camera_project(&cam, (sp_vec3){z[3 * k], z[3 * k + 1], z[3 * k + 2]});
    ENSURE(sp_curve_resample(zz, n, ab->curves[0].closed, m, dense) == SP_OK);
    double sum = 0;
    for (int s = 0; s < p->stroke_points; ++s) {
        double best = INFINITY;
        for (int k = 0; k < m; ++k)
            best = fmin(best, sp_v2_len(sp_v2_sub(p->stroke_xy[s], dense[k])));
        sum += best;
    }
    free(zz);
    free(dense);
    return sum / p->stroke_points;
}

// Where each test part goes on a 1280x800 canvas, and how big.
typedef struct layout {
    const char* name;
    double cx, cy, size;
} layout;
static const layout k_layout[] = {
    {"torso_t", 640, 430, 420}, {"tail_t", 330, 470, 330}, {"head_t", 860, 300, 180},
    {"wings_t", 640, 230, 260}, {"legs_t", 610, 600, 200},
};

// The kiosk's fits stop at 250 ms of wall clock: a cap that a loaded
// machine reaches (the sanitizer suite beside other tests: a tail fit
// stopped early and hung free, in CI). These tests pin results, not speed.
static const sp_solve_desc k_uncapped = {.time_cap_ms = 1e9};

static sp_dragon* new_dragon(const char* db_path)
{
    sp_error err = {0};
    sp_dragon* d;
    sp_dragon_create(&(sp_dragon_desc){.db_path = db_path, .canvas_w = 1280, .canvas_h = 800, .solve = k_uncapped}, &d, &err);
    if (!d) fprintf(stderr, "  create: %s\n", err.text);
    ENSURE(d);
    return d;
}

// A pipeline that reads new models in the background (desc.background_model).
static sp_dragon* new_background_dragon(const char* db_path)
{
    sp_error err = {0};
    sp_dragon* d = NULL;
    sp_dragon_create(
        &(sp_dragon_desc){.db_path = db_path, .canvas_w = 1280, .canvas_h = 800, .background_model = true, .solve = k_uncapped},
        &d, &err);
    if (!d) fprintf(stderr, "  create: %s\n", err.text);
    ENSURE(d);
    return d;
}

// A copy of the test database in the scratch folder, its path in `path`.
static void test_db_copy(const char* name, char path[1024])
{
    snprintf(path, 1024, "%s", sp_test_tmp_path(name));
    copy_file(test_db(), path);
}

// A pipeline on the database at `path`, and the database opened read-only
// beside it (for the parts' names and strokes).
static sp_dragon* dragon_and_db(const char* path, sp_db** db)
{
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_READONLY, db, &err) == SP_OK);
    return new_dragon(path);
}

// Draws the test parts in layout order (torso first); returns how many were classified right.
static int draw_layout(sp_dragon* d, sp_db* db, uint64_t seed, bool verbose)
{
    int right = 0;
    for (int i = 0; i < TEST_PART_COUNT; ++i) {
        sp_vec2* xy;
        int n = part_stroke(db, k_layout[i].name, seed + (uint64_t)i, 0.3, k_layout[i].cx, k_layout[i].cy, k_layout[i].size, &xy);
        sp_dragon_result res;
        sp_error err = {0};
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
        free(xy);
        if (verbose)
            fprintf(stderr, "  %-8s -> %s %s (%.2f), %.1f ms (classify %.1f, fit %.1f)\n", k_layout[i].name,
                    res.rejected ? "REJECTED" : "", res.guess_count ? res.guesses[0].category : "-",
                    res.guess_count ? res.guesses[0].confidence : 0, res.ms_total, res.ms_classify, res.ms_fit);
        if (res.rejected) {
            // Drawn again with the category forced (the kiosk's chip): the fit must still work.
            ENSURE(res.reason == SP_DRAGON_UNRECOGNISED);
            ENSURE(part_stroke(db, k_layout[i].name, seed + (uint64_t)i, 0.3, k_layout[i].cx, k_layout[i].cy, k_layout[i].size,
                               &xy) > 0);
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = k_test_parts[i].category}, &res, &err) ==
                   SP_OK);
            free(xy);
            ENSURE(!res.rejected);
        } else {
            right += !strcmp(sp_dragon_part_get(d, res.part)->category, k_test_parts[i].category);
            if (strcmp(sp_dragon_part_get(d, res.part)->category, k_test_parts[i].category)) {
                // A wrong guess: the chip tap re-fits it as what was meant.
                ENSURE(sp_dragon_refit_last(d, k_test_parts[i].category, &res, &err) == SP_OK && !res.rejected);
            }
        }
        ENSURE(res.part == i && sp_dragon_part_count(d) == i + 1);
    }
    return right;
}

// ---- where parts go: any number of heads, wings and legs (issue 15) ----------------------

// Part i's mesh at its fit (its parameters and placement, before attachment),
// on the canvas (malloc'd, rig.vertex_count points).
static sp_vec2* fitted_px(const sp_dragon* d, int i)
{
    const sp_dragon_part* p = sp_dragon_part_get(d, i);
    const sp_rig* rig = &p->character->rig;
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    double* xyz = malloc(sizeof(double) * 3 * (size_t)rig->vertex_count);
    sp_vec2* px = malloc(sizeof(sp_vec2) * (size_t)rig->vertex_count);
    ENSURE(ev && xyz && px);
    sp_rig_eval_update(ev, p->params, false);
    sp_rig_eval_points(ev, sp_rig_mesh_points(rig), xyz);
    sp_camera cam = sp_dragon_camera(d);
    for (int v = 0; v < rig->vertex_count; ++v)
        px[v] = sp_camera_project(&cam, sp_mat4_point(&p->placement, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]}));
    free(xyz);
    sp_rig_eval_destroy(ev);
    return px;
}

// The silhouette of a projected mesh at canvas column x: the topmost (top)
// or bottommost v where its triangles' edges cross the column.
static double edge_at(const sp_rig* rig, const sp_vec2* px, double x, bool top)
{
    double v = top ? INFINITY : -INFINITY;
    for (int f = 0; f < rig->triangle_count; ++f)
        for (int e = 0; e < 3; ++e) {
            sp_vec2 a = px[rig->triangles[3 * f + e]], b = px[rig->triangles[3 * f + (e + 1) % 3]];
            if ((a.x - x) * (b.x - x) > 0 || a.x == b.x) continue;
            double y = a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x);
            v = top ? fmin(v, y) : fmax(v, y);
        }
    ENSURE(isfinite(v));
    return v;
}

// Part i's attachment end in the world at the last pose_at: its root joint's origin.
static sp_vec3 attach_end(const sp_dragon* d, int i)
{
    const sp_dragon_part* p = sp_dragon_part_get(d, i);
    const sp_rig* rig = &p->character->rig;
    sp_rig_eval* ev;
    sp_rig_eval_create(rig, &ev, NULL);
    sp_rig_eval_update(ev, sp_dragon_part_params(d, i), false);
    int root = 0;
    while (rig->joints[root].parent >= 0)
        ++root;
    sp_vec3 a = sp_mat4_point(sp_dragon_part_transform(d, i), sp_mat4_translation(&sp_rig_eval_world(ev)[root]));
    sp_rig_eval_destroy(ev);
    return a;
}

// The point of triangle (a, b, c) nearest p (Ericson, Real-Time Collision Detection 5.1.5).
static sp_vec3 closest_on_triangle3(sp_vec3 p, sp_vec3 a, sp_vec3 b, sp_vec3 c)
{
    sp_vec3 ab = sp_v3_sub(b, a), ac = sp_v3_sub(c, a), ap = sp_v3_sub(p, a);
    double d1 = sp_v3_dot(ab, ap), d2 = sp_v3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    sp_vec3 bp = sp_v3_sub(p, b);
    double d3 = sp_v3_dot(ab, bp), d4 = sp_v3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return sp_v3_add(a, sp_v3_scale(ab, d1 / (d1 - d3)));
    sp_vec3 cp = sp_v3_sub(p, c);
    double d5 = sp_v3_dot(ab, cp), d6 = sp_v3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return sp_v3_add(a, sp_v3_scale(ac, d2 / (d2 - d6)));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return sp_v3_add(b, sp_v3_scale(sp_v3_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    double den = va + vb + vc;
    if (!(fabs(den) > 0)) return a; // a triangle without area
    return sp_v3_add(a, sp_v3_add(sp_v3_scale(ab, vb / den), sp_v3_scale(ac, vc / den)));
}

// Distance from x to the surface of part k (its triangles) at the last pose_at.
static double surface_distance(const sp_dragon* d, int k, sp_vec3 x)
{
    const sp_rig* rig = &sp_dragon_part_get(d, k)->character->rig;
    const double* v = sp_dragon_part_xyz(d, k);
    double best = INFINITY;
    for (int f = 0; f < rig->triangle_count; ++f) {
        const uint32_t* t = rig->triangles + 3 * f;
        sp_vec3 a = {v[3 * t[0]], v[3 * t[0] + 1], v[3 * t[0] + 2]}, b = {v[3 * t[1]], v[3 * t[1] + 1], v[3 * t[1] + 2]},
                c = {v[3 * t[2]], v[3 * t[2] + 1], v[3 * t[2] + 2]};
        best = fmin(best, sp_v3_len(sp_v3_sub(x, closest_on_triangle3(x, a, b, c))));
    }
    return best;
}

static double iou(const double a[4], const double b[4])
{
    double ix = fmin(a[2], b[2]) - fmax(a[0], b[0]), iy = fmin(a[3], b[3]) - fmax(a[1], b[1]);
    if (ix <= 0 || iy <= 0) return 0;
    double in = ix * iy;
    return in / ((a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - in);
}

// The dragon's report (sp_dragon_report_json's text) as a tree.
static cJSON* report_tree(sp_dragon* d)
{
    char* text = NULL;
    sp_error err = {0};
    ENSURE(sp_dragon_report_json(d, &text, &err) == SP_OK);
    cJSON* rep = cJSON_Parse(text);
    free(text);
    ENSURE(rep != NULL);
    return rep;
}

// A report box [x0, y0, x1, y1].
static void json_box(const cJSON* a, double b[4])
{
    ENSURE(cJSON_IsArray(a) && cJSON_GetArraySize(a) == 4);
    for (int k = 0; k < 4; ++k)
        b[k] = cJSON_GetArrayItem(a, k)->valuedouble;
    ENSURE(b[0] <= b[2] && b[1] <= b[3]);
}

// One stroke of a layout: part `name` drawn `size` px across with its
// attachment end at `at` (canvas pixels), facing left when mirror.
typedef struct drawn {
    const char* name;
    const char* category;
    sp_vec2 at;
    double size;
    bool mirror;
    bool touching; // drawn touching the body (else far from it)
} drawn;

enum { MANY = 10 };

// The layout of issue 15 on a torso drawn at (640, 420): a head at the front
// and one at the tail end (facing away), two wings on the back 170 px apart,
// three leg pairs along the belly about 130 px apart, a tail drawn far away,
// and a second wing at the same place as the first (the body's other side).
// Positions are read off the torso's silhouette as fitted.
static void many_layout(sp_db* db, const char* path, sp_vec2** torso_xy, int* torso_n, drawn out[MANY])
{
    *torso_n = part_stroke(db, "torso_t", 700, 0.3, 640, 420, 440, torso_xy);
    sp_dragon* d = new_dragon(path);
    sp_dragon_result res;
    sp_error err = {0};
    ENSURE(sp_dragon_add_points(d, *torso_xy, *torso_n, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK &&
           !res.rejected);
    const sp_rig* rig = &sp_dragon_part_get(d, 0)->character->rig;
    int nv = rig->vertex_count;
    sp_vec2* px = fitted_px(d, 0);
    double x0 = INFINITY, x1 = -INFINITY;
    for (int v = 0; v < nv; ++v)
        x0 = fmin(x0, px[v].x), x1 = fmax(x1, px[v].x);
    double w = x1 - x0;
    // Attachment ends 10-25 px inside the silhouette: drawn touching the body.
#define TOP(x) ((sp_vec2){(x), edge_at(rig, px, (x), true) + 12})
#define BOTTOM(x) ((sp_vec2){(x), edge_at(rig, px, (x), false) - 10})
    out[0] = (drawn){"head_t", "head", {x1 - 14, edge_at(rig, px, x1 - 14, true) + 25}, 170, false, true};
    out[1] = (drawn){"head_t", "head", {x0 + 14, edge_at(rig, px, x0 + 14, true) + 25}, 170, true, true};
    out[2] = (drawn){"wings_t", "wings", TOP(x0 + 0.3 * w), 220, false, true};
    out[3] = (drawn){"wings_t", "wings", TOP(x0 + 0.3 * w + 170), 220, false, true};
    for (int k = 0; k < 3; ++k)
        out[4 + k] = (drawn){"legs_t", "legs", BOTTOM(x0 + (0.2 + 0.3 * k) * w), 170, false, true};
    out[7] = (drawn){"tail_t", "tail", {x0 - 30, 740}, 240, false, false};
    out[8] = (drawn){"legs_t", "legs", BOTTOM(x0 + 0.5 * w + 8), 170, false, true};
    out[9] = (drawn){"wings_t", "wings", TOP(x0 + 0.3 * w + 6), 220, false, true};
#undef TOP
#undef BOTTOM
    free(px);
    sp_dragon_destroy(d);
}

// Draws layout strokes lay[from..to) (forced categories, the visitor's chips), seeds 710 + index.
static void draw_many(sp_dragon* d, sp_db* db, const drawn* lay, int from, int to)
{
    for (int i = from; i < to; ++i) {
        sp_vec2* xy;
        int n = part_stroke_ex(db, lay[i].name, 710 + (uint64_t)i, 0.3, lay[i].at, lay[i].size, true, lay[i].mirror, &xy);
        sp_dragon_result res;
        sp_error err = {0};
        ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = lay[i].category}, &res, &err) == SP_OK);
        free(xy);
        if (res.rejected)
            fprintf(stderr, "  %s at (%.0f, %.0f): %s\n", lay[i].name, lay[i].at.x, lay[i].at.y,
                    sp_dragon_reject_name(res.reason));
        ENSURE(!res.rejected);
    }
}

// The layout drawn body first (torso: part 0, lay[i]: part i + 1).
static sp_dragon* many_body_first(sp_db* db, const char* path, drawn lay[MANY], sp_vec2** torso, int* tn)
{
    many_layout(db, path, torso, tn, lay);
    sp_dragon* d = new_dragon(path);
    sp_dragon_result res;
    sp_error err = {0};
    ENSURE(sp_dragon_add_points(d, *torso, *tn, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK &&
           !res.rejected);
    draw_many(d, db, lay, 0, MANY);
    return d;
}

// Items 1-3 of issue 15 on a drawn layout, from the report: part part_of[i]
// was drawn as lay[i]; the body is part `body`. Prints the figures.
static void check_many(sp_dragon* d, const drawn* lay, const int* part_of, int count, int body)
{
    cJSON* rep = report_tree(d);
    const cJSON* parts = cJSON_GetObjectItem(rep, "parts");
    ENSURE(cJSON_GetArraySize(parts) == sp_dragon_part_count(d));
    double boxes[MANY][4];
    double worst_iou = 1;
    for (int i = 0; i < count; ++i) {
        int k = part_of[i];
        const sp_dragon_part* p = sp_dragon_part_get(d, k);
        const cJSON* pj = cJSON_GetArrayItem(parts, k);
        double ob[4], sb[4];
        json_box(cJSON_GetObjectItem(pj, "outline_bbox_px"), ob);
        json_box(cJSON_GetObjectItem(pj, "stroke_bbox_px"), sb);
        memcpy(boxes[i], ob, sizeof ob);
        const cJSON* at = cJSON_GetObjectItem(pj, "attached_to");
        const cJSON* anchor = cJSON_GetObjectItem(pj, "anchor_px");
        ENSURE(cJSON_IsNumber(at) && at->valueint == p->attached_to);
        double o = iou(ob, sb);
        fprintf(stderr, "  %d %-5s %-6s attached to %2d%s%s, outline/stroke IoU %.2f", k, lay[i].name, lay[i].category,
                p->attached_to, p->far_side ? " (far side)" : "", p->mirrored ? " (mirrored)" : "", o);
        // 1. Where it was drawn: touching the body, attached, at the body's
        // surface nearest its attachment end; far away, free, where drawn.
        ENSURE(p->attached_to == (lay[i].touching ? body : -1));
        if (p->attached_to >= 0) {
            ENSURE(cJSON_IsArray(anchor));
            double ax = cJSON_GetArrayItem(anchor, 0)->valuedouble, ay = cJSON_GetArrayItem(anchor, 1)->valuedouble;
            ENSURE_NEAR(ax, p->anchor.x, 1e-9);
            ENSURE_NEAR(ay, p->anchor.y, 1e-9);
            // The attachment end was drawn inside the silhouette: the anchor is under it.
            double dist = hypot(ax - lay[i].at.x, ay - lay[i].at.y);
            fprintf(stderr, ", anchor %.1f px from where the attachment end was drawn", dist);
            ENSURE(dist < 0.05 * lay[i].size);
        } else {
            ENSURE(cJSON_IsNull(anchor));
        }
        fprintf(stderr, "\n");
        // 2. On its stroke.
        ENSURE(o >= 0.6);
        worst_iou = fmin(worst_iou, o);
        ENSURE(p->mirrored == lay[i].mirror);
    }
    // 2. Parts of one kind drawn apart stay apart (the ones drawn at the
    // same place, as a near and a far one, overlap of course).
    double worst_apart = 0;
    for (int i = 0; i < count; ++i)
        for (int j = i + 1; j < count; ++j) {
            if (strcmp(lay[i].category, lay[j].category)) continue;
            if (hypot(lay[i].at.x - lay[j].at.x, lay[i].at.y - lay[j].at.y) < 20) continue;
            double o = iou(boxes[i], boxes[j]);
            worst_apart = fmax(worst_apart, o);
            ENSURE(o < 0.3);
        }
    fprintf(stderr, "  outline on stroke: IoU >= %.2f; parts of a kind apart: IoU <= %.2f\n", worst_iou, worst_apart);
    cJSON_Delete(rep);
}

// The attachment ends of attached parts stay on the body's surface over
// the loop (no gap, nothing floating), so they move as the body moves there:
// the parts anchored on the moving half of the body (its clip sways the
// joints after the first) move. Returns the largest gap, world units.
static double check_riding(sp_dragon* d, int body, bool sways)
{
    sp_error err = {0};
    int n = sp_dragon_part_count(d);
    double T = sp_dragon_period(d), gap = 0;
    ENSURE(T > 0);
    sp_vec3* a0 = malloc(sizeof(sp_vec3) * (size_t)n);
    double* moved = calloc((size_t)n, sizeof(double));
    for (int k = 0; k <= 8; ++k) {
        ENSURE(sp_dragon_pose_at(d, T * k / 8, &err) == SP_OK);
        for (int i = 0; i < n; ++i) {
            if (sp_dragon_part_get(d, i)->attached_to != body) continue;
            sp_vec3 a = attach_end(d, i);
            gap = fmax(gap, surface_distance(d, body, a));
            if (k == 0) a0[i] = a;
            moved[i] = fmax(moved[i], sp_v3_len(sp_v3_sub(a, a0[i])));
        }
    }
    const sp_dragon_part* b = sp_dragon_part_get(d, body);
    sp_vec2 blo = {INFINITY, 0}, bhi = {-INFINITY, 0};
    sp_vec2* px = fitted_px(d, body);
    for (int v = 0; v < b->character->rig.vertex_count; ++v)
        blo.x = fmin(blo.x, px[v].x), bhi.x = fmax(bhi.x, px[v].x);
    free(px);
    fprintf(stderr, "  attachment ends over the loop: at most %.2g world units off the body's surface; moved:", gap);
    for (int i = 0; i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        if (p->attached_to != body) continue;
        fprintf(stderr, " %d:%.3f", i, moved[i]);
        // The test torso sways from its second joint on: the right 60% of it moves.
        if (sways && p->anchor.x > blo.x + 0.4 * (bhi.x - blo.x)) ENSURE(moved[i] > 1e-2);
    }
    fprintf(stderr, "\n");
    free(a0), free(moved);
    ENSURE(gap < 1e-9);
    return gap;
}

// ---- tests ------------------------------------------------------------------------

static void test_build_and_attach(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    sp_dragon* d = dragon_and_db(path, &db);
    int right = draw_layout(d, db, 100, true);
    fprintf(stderr, "  classified %d of %d right\n", right, TEST_PART_COUNT);
    ENSURE(right >= TEST_PART_COUNT - 1);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    for (int i = 0; i < TEST_PART_COUNT; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        double rel = p->report.mean_error_px / p->report.bbox_diagonal_px;
        double px = stroke_to_outline_px(d, i);
        fprintf(stderr,
                "  %-6s fit %.2f px (%.2f%% of %.0f px), stroke to outline in the world view %.2f px, attached to %d (%s)\n",
                p->category, p->report.mean_error_px, 100 * rel, p->report.bbox_diagonal_px, px, p->attached_to, p->socket);
        ENSURE(rel < 0.03);
        // The part is where it was drawn; attachment may move it onto the body, within the snap distance.
        if (p->attached_to < 0)
            ENSURE(px < 0.03 * p->report.bbox_diagonal_px);
        else
            ENSURE(px < 0.06 * hypot(1280, 800) + 0.03 * p->report.bbox_diagonal_px);
        // The overlay shown right after the fit is over the stroke (before attachment).
        int np = sp_dragon_part_fitted_outline(d, i, NULL);
        ENSURE(np == p->character->rig.abstractions[p->abstraction].point_count);
        sp_vec2* fo = malloc(sizeof(sp_vec2) * (size_t)np);
        ENSURE(sp_dragon_part_fitted_outline(d, i, fo) == np);
        double far = 0;
        for (int k = 0; k < np; ++k) {
            double best = INFINITY;
            for (int s = 0; s < p->stroke_points; ++s)
                best = fmin(best, sp_v2_len(sp_v2_sub(fo[k], p->stroke_xy[s])));
            far = fmax(far, best);
        }
        free(fo);
        ENSURE(far < 0.05 * p->report.bbox_diagonal_px);
    }
    // Every part but the torso hangs on the torso (drawn near it), with the
    // socket meant for its kind as the hint, its attachment end on the
    // torso's surface as the torso moves.
    const char* want[TEST_PART_COUNT] = {"", "tail", "neck", "back", "hips"};
    ENSURE(sp_dragon_part_get(d, 0)->is_torso && sp_dragon_part_get(d, 0)->attached_to == -1);
    for (int i = 1; i < TEST_PART_COUNT; ++i) {
        ENSURE(sp_dragon_part_get(d, i)->attached_to == 0);
        ENSURE(!strcmp(sp_dragon_part_get(d, i)->socket, want[i]));
    }
    check_riding(d, 0, true);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

static void test_animation(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    sp_dragon* d = dragon_and_db(path, &db);
    draw_layout(d, db, 200, false);
    double T = sp_dragon_period(d);
    ENSURE_NEAR(T, 2.0, 1e-6); // the torso's clip is the longest
    int n = sp_dragon_part_count(d);
    // Offsets are relative to rest: with every part fitted at its rest pose
    // the animated parameters at t = 0 would be the clip's first frame;
    // here they must be the fit plus (clip(0) - rest), within bounds.
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    for (int i = 0; i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        const sp_rig* rig = &p->character->rig;
        double* rest = malloc(sizeof(double) * (size_t)rig->param_count);
        double* want = malloc(sizeof(double) * (size_t)rig->param_count);
        ENSURE(rest && want);
        sp_rig_defaults(rig, rest);
        bool has_clip = false;
        for (int a = 0; a < rig->animation_count; ++a) has_clip |= rig->animations[a].channel_count > 0;
        for (int k = 0; k < rig->param_count; ++k) want[k] = p->params[k];
        if (has_clip) {
            // The clip's first frame (its earliest key time), read back as parameters.
            const sp_animation* an = &rig->animations[0];
            double t0 = INFINITY;
            for (int c = 0; c < an->channel_count; ++c)
                if (an->channels[c].key_count > 0) t0 = fmin(t0, an->channels[c].times[0]);
            double* first = malloc(sizeof(double) * (size_t)rig->param_count);
            sp_vec3* tr = malloc(sizeof(sp_vec3) * (size_t)rig->joint_count);
            sp_quat* rq = malloc(sizeof(sp_quat) * (size_t)rig->joint_count);
            sp_vec3* sc = malloc(sizeof(sp_vec3) * (size_t)rig->joint_count);
            ENSURE(first && tr && rq && sc);
            for (int j = 0; j < rig->joint_count; ++j) tr[j] = rig->joints[j].rest_t, rq[j] = rig->joints[j].rest_r, sc[j] = rig->joints[j].rest_s;
            sp_animation_sample(an, t0, tr, rq, sc);
            memcpy(first, rest, sizeof(double) * (size_t)rig->param_count);
            for (int j = 0; j < rig->joint_count; ++j)
                if (rig->joints[j].param_count > 0) sp_rig_params_from_trs(rig, j, tr[j], rq[j], sc[j], first);
            free(tr), free(rq), free(sc);
            for (int k = 0; k < rig->param_count; ++k)
                want[k] = sp_channel_is_scale(rig->params[k].channel) ? p->params[k] * first[k] / rest[k] : p->params[k] + first[k] - rest[k];
            free(first);
        }
        sp_rig_clamp(rig, want);
        for (int k = 0; k < rig->param_count; ++k) ENSURE_NEAR(sp_dragon_part_params(d, i)[k], want[k], 1e-6);
        free(rest), free(want);
    }
    // Two times differ (every animated part moves), and the loop closes at T.
    ENSURE(n == TEST_PART_COUNT);
    double* x0[TEST_PART_COUNT];
    for (int i = 0; i < n; ++i) {
        int nv = sp_dragon_part_get(d, i)->character->rig.vertex_count;
        x0[i] = malloc(sizeof(double) * 3 * (size_t)nv);
        memcpy(x0[i], sp_dragon_part_xyz(d, i), sizeof(double) * 3 * (size_t)nv);
    }
    ENSURE(sp_dragon_pose_at(d, 0.2, &err) == SP_OK);
    for (int i = 0; i < n; ++i) {
        int nv = sp_dragon_part_get(d, i)->character->rig.vertex_count;
        double moved = 0;
        for (int k = 0; k < 3 * nv; ++k)
            moved = fmax(moved, fabs(sp_dragon_part_xyz(d, i)[k] - x0[i][k]));
        fprintf(stderr, "  %-6s moves %.3f world units at t = 0.2 s\n", sp_dragon_part_get(d, i)->category, moved);
        // The legs have no clip but hang on the breathing torso: they move too.
        ENSURE(moved > 1e-3);
    }
    ENSURE(sp_dragon_pose_at(d, T, &err) == SP_OK);
    for (int i = 0; i < n; ++i) {
        int nv = sp_dragon_part_get(d, i)->character->rig.vertex_count;
        for (int k = 0; k < 3 * nv; ++k)
            ENSURE_NEAR(sp_dragon_part_xyz(d, i)[k], x0[i][k], 1e-6);
        free(x0[i]);
    }
    // Parameters stay within bounds at every time.
    for (int k = 0; k < 40; ++k) {
        ENSURE(sp_dragon_pose_at(d, T * k / 40.0, &err) == SP_OK);
        for (int i = 0; i < n; ++i) {
            const sp_rig* rig = &sp_dragon_part_get(d, i)->character->rig;
            for (int q = 0; q < rig->param_count; ++q) {
                double v = sp_dragon_part_params(d, i)[q];
                ENSURE(v >= rig->params[q].min - 1e-12 && v <= rig->params[q].max + 1e-12);
            }
        }
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// glTF Transform (tests/tools/inspect.js) on a file: 1 loads with skins and
// animation intact, 0 not, -1 when it is not installed.
static int gltf_transform_loads(const char* file)
{
    const char* tools = sp_fixture_node_tools("@gltf-transform/core");
    if (!tools) return -1;
    char cmd[3000];
    snprintf(cmd, sizeof cmd, "node '%s/inspect.js' '%s' > '%s'", tools, file, sp_test_tmp_path("dragon_inspect.json"));
    return system(cmd) == 0;
}

// ---- a small glTF evaluator: the exported animation, played back independently ----

typedef struct glb {
    cJSON* j;
    unsigned char* bin;
    size_t bin_size;
} glb;

static void glb_read(const char* path, glb* g)
{
    FILE* f = fopen(path, "rb");
    ENSURE(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char* b = malloc((size_t)n);
    ENSURE(fread(b, 1, (size_t)n, f) == (size_t)n);
    fclose(f);
    uint32_t jl;
    memcpy(&jl, b + 12, 4);
    char* text = malloc(jl + 1);
    memcpy(text, b + 20, jl);
    text[jl] = 0;
    g->j = cJSON_Parse(text);
    free(text);
    ENSURE(g->j);
    uint32_t bl;
    memcpy(&bl, b + 20 + jl, 4);
    g->bin = malloc(bl);
    memcpy(g->bin, b + 28 + jl, bl);
    g->bin_size = bl;
    free(b);
}

static int jint(const cJSON* o, const char* k)
{
    const cJSON* v = cJSON_GetObjectItem(o, k);
    return v ? v->valueint : 0;
}

// Accessor `a` as floats (FLOAT or UNSIGNED_SHORT components); *comps gets the component count.
static float* glb_floats(const glb* g, int a, int* count, int* comps)
{
    const cJSON* acc = cJSON_GetArrayItem(cJSON_GetObjectItem(g->j, "accessors"), a);
    const cJSON* view = cJSON_GetArrayItem(cJSON_GetObjectItem(g->j, "bufferViews"), jint(acc, "bufferView"));
    const char* type = cJSON_GetObjectItem(acc, "type")->valuestring;
    int nc = !strcmp(type, "SCALAR") ? 1 : !strcmp(type, "VEC3") ? 3 : !strcmp(type, "VEC4") ? 4 : 16;
    int n = jint(acc, "count"), ct = jint(acc, "componentType");
    size_t off = (size_t)jint(view, "byteOffset") + (size_t)jint(acc, "byteOffset");
    float* out = malloc(sizeof(float) * (size_t)n * (size_t)nc);
    for (int i = 0; i < n * nc; ++i) {
        if (ct == 5126) {
            memcpy(&out[i], g->bin + off + 4 * (size_t)i, 4);
        } else {
            ENSURE(ct == 5123);
            uint16_t u;
            memcpy(&u, g->bin + off + 2 * (size_t)i, 2);
            out[i] = u;
        }
    }
    *count = n, *comps = nc;
    return out;
}

typedef struct gnode {
    sp_vec3 t, s;
    sp_quat r;
    int parent;
    bool done;
    sp_mat4 world;
} gnode;

static sp_mat4 gworld(gnode* nodes, int i)
{
    gnode* n = &nodes[i];
    if (!n->done) {
        sp_mat4 local = sp_mat4_trs(n->t, n->r, n->s);
        if (n->parent >= 0) {
            sp_mat4 pw = gworld(nodes, n->parent);
            n->world = sp_mat4_mul(&pw, &local);
        } else {
            n->world = local;
        }
        n->done = true;
    }
    return n->world;
}

static double* glb_pose_node(const glb* g, double t, int node_index, int* count);

// Skinned vertices of skin `skin_index`'s mesh (the first node that has it)
// at time t of animation 0 (malloc'd, count by 3).
static double* glb_pose(const glb* g, double t, int skin_index, int* count)
{
    const cJSON* jn = cJSON_GetObjectItem(g->j, "nodes");
    int nn = cJSON_GetArraySize(jn), node = -1;
    for (int i = 0; i < nn && node < 0; ++i) {
        const cJSON* n = cJSON_GetArrayItem(jn, i);
        if (cJSON_GetObjectItem(n, "skin") && jint(n, "skin") == skin_index) node = i;
    }
    ENSURE(node >= 0);
    return glb_pose_node(g, t, node, count);
}

// The skinned points of node node_index's mesh (its first primitive) at
// time t of animation 0 (malloc'd, count by 3).
static double* glb_pose_node(const glb* g, double t, int node_index, int* count)
{
    const cJSON* jn = cJSON_GetObjectItem(g->j, "nodes");
    int nn = cJSON_GetArraySize(jn);
    gnode* nodes = calloc((size_t)nn, sizeof(gnode));
    for (int i = 0; i < nn; ++i) {
        const cJSON* n = cJSON_GetArrayItem(jn, i);
        const cJSON *T = cJSON_GetObjectItem(n, "translation"), *R = cJSON_GetObjectItem(n, "rotation"),
                    *S = cJSON_GetObjectItem(n, "scale");
        nodes[i].t = T ? sp_v3(cJSON_GetArrayItem(T, 0)->valuedouble, cJSON_GetArrayItem(T, 1)->valuedouble,
                               cJSON_GetArrayItem(T, 2)->valuedouble)
                       : sp_v3(0, 0, 0);
        nodes[i].r = R ? (sp_quat){cJSON_GetArrayItem(R, 0)->valuedouble, cJSON_GetArrayItem(R, 1)->valuedouble,
                                   cJSON_GetArrayItem(R, 2)->valuedouble, cJSON_GetArrayItem(R, 3)->valuedouble}
                       : sp_quat_identity();
        nodes[i].s = S ? sp_v3(cJSON_GetArrayItem(S, 0)->valuedouble, cJSON_GetArrayItem(S, 1)->valuedouble,
                               cJSON_GetArrayItem(S, 2)->valuedouble)
                       : sp_v3(1, 1, 1);
        nodes[i].parent = -1;
    }
    for (int i = 0; i < nn; ++i) {
        const cJSON* c;
        cJSON_ArrayForEach(c, cJSON_GetObjectItem(cJSON_GetArrayItem(jn, i), "children")) nodes[c->valueint].parent = i;
    }
    const cJSON* anim = cJSON_GetArrayItem(cJSON_GetObjectItem(g->j, "animations"), 0);
    const cJSON* ch;
    cJSON_ArrayForEach(ch, cJSON_GetObjectItem(anim, "channels"))
    {
        const cJSON* smp = cJSON_GetArrayItem(cJSON_GetObjectItem(anim, "samplers"), jint(ch, "sampler"));
        const cJSON* target = cJSON_GetObjectItem(ch, "target");
        int node = jint(target, "node"), nk, c1, nv, c2;
        const char* path = cJSON_GetObjectItem(target, "path")->valuestring;
        float* times = glb_floats(g, jint(smp, "input"), &nk, &c1);
        float* vals = glb_floats(g, jint(smp, "output"), &nv, &c2);
        int k = 0;
        while (k + 1 < nk && times[k + 1] <= t)
            ++k;
        double u = k + 1 < nk && t > times[k] ? (t - times[k]) / (times[k + 1] - times[k]) : 0;
        int k1 = k + 1 < nk ? k + 1 : k;
        const float *a = vals + c2 * k, *b = vals + c2 * k1;
        if (!strcmp(path, "rotation")) {
            nodes[node].r = sp_quat_slerp((sp_quat){a[0], a[1], a[2], a[3]}, (sp_quat){b[0], b[1], b[2], b[3]}, u);
        } else {
            sp_vec3 v = sp_v3(a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2]));
            if (!strcmp(path, "translation"))
                nodes[node].t = v;
            else
                nodes[node].s = v;
        }
        free(times), free(vals);
    }
    const cJSON* mesh_node = cJSON_GetArrayItem(jn, node_index);
    ENSURE(mesh_node && cJSON_GetObjectItem(mesh_node, "skin"));
    const cJSON* skin = cJSON_GetArrayItem(cJSON_GetObjectItem(g->j, "skins"), jint(mesh_node, "skin"));
    const cJSON* prim = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(g->j, "meshes"), jint(mesh_node, "mesh")), "primitives"), 0);
    const cJSON* attrs = cJSON_GetObjectItem(prim, "attributes");
    int n, c, nj, cj, nw, cw, ni, ci;
    float* pos = glb_floats(g, jint(attrs, "POSITION"), &n, &c);
    float* jo = glb_floats(g, jint(attrs, "JOINTS_0"), &nj, &cj);
    float* we = glb_floats(g, jint(attrs, "WEIGHTS_0"), &nw, &cw);
    float* ibm = glb_floats(g, jint(skin, "inverseBindMatrices"), &ni, &ci);
    int J = cJSON_GetArraySize(cJSON_GetObjectItem(skin, "joints"));
    sp_mat4* M = malloc(sizeof(sp_mat4) * (size_t)J);
    for (int k = 0; k < J; ++k) {
        sp_mat4 w = gworld(nodes, cJSON_GetArrayItem(cJSON_GetObjectItem(skin, "joints"), k)->valueint), ib;
        for (int e = 0; e < 16; ++e)
            ib.m[e] = ibm[16 * k + e];
        M[k] = sp_mat4_mul(&w, &ib);
    }
    double* out = malloc(sizeof(double) * 3 * (size_t)n);
    for (int v = 0; v < n; ++v) {
        sp_vec3 x = sp_v3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]), acc = sp_v3(0, 0, 0);
        for (int k = 0; k < 4; ++k)
            acc = sp_v3_add(acc, sp_v3_scale(sp_mat4_point(&M[(int)jo[4 * v + k]], x), we[4 * v + k]));
        out[3 * v] = acc.x, out[3 * v + 1] = acc.y, out[3 * v + 2] = acc.z;
    }
    free(pos), free(jo), free(we), free(ibm), free(M), free(nodes);
    *count = n;
    return out;
}

// Plays the exported animation back and compares every part's skinned
// vertices with sp_dragon_pose_at at a few times (on the exported keys, and
// between keys, where LINEAR keys at 30 per second approximate the motion).
static void check_playback(sp_dragon* d, const char* file, double tol_between)
{
    glb g;
    glb_read(file, &g);
    // The file is centred: file = world + world_offset (its scene's extras).
    const cJSON* sdj = cJSON_GetObjectItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(g.j, "scenes"), 0), "extras"), "sp_dragon");
    const cJSON* off = cJSON_GetObjectItem(sdj, "world_offset");
    ENSURE(cJSON_GetArraySize(off) == 3);
    double offset[3];
    for (int c = 0; c < 3; ++c)
        offset[c] = cJSON_GetArrayItem(off, c)->valuedouble;
    sp_error err = {0};
    double T = sp_dragon_period(d), worst_on = 0, worst_off = 0;
    int K = (int)ceil(T * 30);
    const double times[] = {0, 7 * T / K, 23 * T / K, 0.37 * T, 0.81 * T};
    for (size_t q = 0; q < sizeof times / sizeof times[0]; ++q) {
        ENSURE(sp_dragon_pose_at(d, times[q], &err) == SP_OK);
        for (int i = 0; i < sp_dragon_part_count(d); ++i) {
            int n;
            double* x = glb_pose(&g, times[q], i, &n);
            ENSURE(n == sp_dragon_part_get(d, i)->character->rig.vertex_count);
            const double* y = sp_dragon_part_xyz(d, i);
            for (int k = 0; k < 3 * n; ++k) {
                double e = fabs(x[k] - (y[k] + offset[k % 3]));
                if (q < 3)
                    worst_on = fmax(worst_on, e);
                else
                    worst_off = fmax(worst_off, e);
            }
            free(x);
        }
    }
    fprintf(stderr, "  playback of the export vs pose_at: %.2g world units on keys, %.2g between keys\n", worst_on, worst_off);
    ENSURE(worst_on < 1e-4); // float32 in the file
    ENSURE(worst_off < tol_between);
    cJSON_Delete(g.j);
    free(g.bin);
}

static void check_export(sp_dragon* d, const char* file, int parts)
{
    sp_error err = {0};
    sp_result r = sp_dragon_export(d, file, &err);
    if (r != SP_OK) fprintf(stderr, "  export: %s\n", err.text);
    ENSURE(r == SP_OK);
    cJSON* j = sp_fixture_glb_json(file);
    const cJSON* skins = cJSON_GetObjectItem(j, "skins");
    const cJSON* anims = cJSON_GetObjectItem(j, "animations");
    ENSURE(cJSON_GetArraySize(skins) == parts);
    ENSURE(cJSON_GetArraySize(anims) == 1);
    int skinned_meshes = 0;
    const cJSON* n;
    cJSON_ArrayForEach(n, cJSON_GetObjectItem(j, "nodes")) skinned_meshes += cJSON_GetObjectItem(n, "skin") != NULL;
    ENSURE(skinned_meshes == parts);
    fprintf(stderr, "  %s: %d skins, %d animation (%d channels)\n", file, cJSON_GetArraySize(skins), cJSON_GetArraySize(anims),
            cJSON_GetArraySize(cJSON_GetObjectItem(cJSON_GetArrayItem(anims, 0), "channels")));
    // A camera that frames the dragon: an orthographic view along -Z whose
    // box holds every vertex at t = 0, which is centred at the origin.
    const cJSON* cams = cJSON_GetObjectItem(j, "cameras");
    ENSURE(cJSON_GetArraySize(cams) == 1);
    const cJSON* ortho = cJSON_GetObjectItem(cJSON_GetArrayItem(cams, 0), "orthographic");
    ENSURE(ortho);
    double xmag = cJSON_GetObjectItem(ortho, "xmag")->valuedouble, ymag = cJSON_GetObjectItem(ortho, "ymag")->valuedouble;
    int camera_nodes = 0;
    cJSON_ArrayForEach(n, cJSON_GetObjectItem(j, "nodes")) camera_nodes += cJSON_GetObjectItem(n, "camera") != NULL;
    ENSURE(camera_nodes == 1);
    cJSON_Delete(j);
    glb g;
    glb_read(file, &g);
    sp_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < parts; ++i) {
        int nv;
        double* x = glb_pose(&g, 0, i, &nv);
        for (int v = 0; v < nv; ++v) {
            lo = (sp_vec3){fmin(lo.x, x[3 * v]), fmin(lo.y, x[3 * v + 1]), fmin(lo.z, x[3 * v + 2])};
            hi = (sp_vec3){fmax(hi.x, x[3 * v]), fmax(hi.y, x[3 * v + 1]), fmax(hi.z, x[3 * v + 2])};
        }
        free(x);
    }
    cJSON_Delete(g.j);
    free(g.bin);
    sp_vec3 c = sp_v3_scale(sp_v3_add(lo, hi), 0.5);
    double size = sp_v3_len(sp_v3_sub(hi, lo));
    fprintf(stderr, "  centre of the exported dragon at t = 0: (%.2g, %.2g, %.2g), %.3g across; camera %.3g x %.3g\n", c.x, c.y,
            c.z, size, 2 * xmag, 2 * ymag);
    ENSURE(sp_v3_len(c) < 1e-4 * size);
    ENSURE(fmax(fabs(lo.x), hi.x) <= xmag && fmax(fabs(lo.y), hi.y) <= ymag);
    int v = sp_fixture_gltf_validate(file);
    if (v < 0)
        fprintf(stderr, "  note: gltf-validator not installed (cd tests/tools && npm ci): not validated\n");
    else
        ENSURE(v == 1);
    v = gltf_transform_loads(file);
    if (v >= 0) ENSURE(v == 1);
}

static void test_export(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    sp_dragon* d = dragon_and_db(path, &db);
    ENSURE(sp_dragon_export(d, sp_test_tmp_path("dragon_empty.glb"), &err) == SP_ERR_INVALID);
    draw_layout(d, db, 300, false);
    check_export(d, sp_test_tmp_path("dragon_test.glb"), TEST_PART_COUNT);
    // The test clips are LINEAR and their keys are among the exported ones: exact between keys too.
    check_playback(d, sp_test_tmp_path("dragon_test.glb"), 1e-4);
    // .gltf with embedded buffers, by extension.
    const char* gltf = sp_test_tmp_path("dragon_test.gltf");
    ENSURE(sp_dragon_export(d, gltf, &err) == SP_OK);
    int v = sp_fixture_gltf_validate(gltf);
    if (v >= 0) ENSURE(v == 1);
    // The export changes nothing: posing afterwards gives the same as before.
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    ENSURE(sp_dragon_part_xyz(d, 0) != NULL);
    // The picture: parts where the strokes are.
    sp_error rerr = {0};
    sp_result r = sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true},
                                         sp_test_tmp_path("dragon_test.png"), &rerr);
    if (r == SP_ERR_UNSUPPORTED)
        fprintf(stderr, "  note: no EGL here, no picture: %s\n", rerr.text);
    else
        ENSURE(r == SP_OK);
    // A stroke shows also where its fitted outline lies right on it (the
    // stroke points within 1.5 px of an outline point, in the canvas).
    sp_image img = {0};
    if (r == SP_OK &&
        sp_dragon_snapshot_render(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true}, &img, &rerr) == SP_OK) {
        int shown = 0, total = 0;
        const sp_camera cam = sp_dragon_camera(d);
        for (int i = 0; i < sp_dragon_part_count(d); ++i) {
            const sp_dragon_part* p = sp_dragon_part_get(d, i);
            const sp_abstraction* ab = &p->character->rig.abstractions[p->abstraction];
            const double* o = sp_dragon_part_outline(d, i);
            for (int k = 0; k < p->stroke_points; ++k) {
                double best = INFINITY;
                for (int j = 0; j < ab->point_count; ++j) {
                    sp_vec2 q = sp_camera_project(&cam, sp_v3(o[3 * j], o[3 * j + 1], o[3 * j + 2]));
                    best = fmin(best, hypot(q.x - p->stroke_xy[k].x, q.y - p->stroke_xy[k].y));
                }
                if (best > 1.5) continue;
                int x = (int)lround(p->stroke_xy[k].x), y = (int)lround(p->stroke_xy[k].y), found = 0;
                for (int dy = -5; dy <= 5; ++dy)
                    for (int dx = -5; dx <= 5; ++dx) {
                        if (x + dx < 0 || y + dy < 0 || x + dx >= img.width || y + dy >= img.height) continue;
                        const uint8_t* px = img.rgba + 4 * ((size_t)(y + dy) * (size_t)img.width + (size_t)(x + dx));
                        found |= px[2] > 180 && px[0] < 90 && px[1] < 140; // the strokes' blue
                    }
                shown += found, ++total;
            }
        }
        fprintf(stderr, "  %d of %d stroke points on their outline blue in the picture\n", shown, total);
        ENSURE(total >= 20 && shown >= total * 95 / 100);
    }
    sp_image_free(&img);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

static int dragon_signature(const sp_dragon* d, char* buf, size_t cap)
{
    size_t len = 0;
    buf[0] = 0;
    for (int i = 0; i < sp_dragon_part_count(d); ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        len += (size_t)snprintf(buf + len, cap - len, "%llu:%s:%d;", (unsigned long long)p->id, p->category, p->attached_to);
    }
    return sp_dragon_part_count(d);
}

// A pipeline whose strokes name their parts (the attract screen's demo)
// loads no model, also after the database changes; its strokes still fit.
static void test_no_model(void)
{
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(test_db(), SP_DB_READONLY, &db, &err) == SP_OK);
    char path[1200], cmd[6000];
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("no_model.db"));
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", test_db(), path);
    ENSURE(system(cmd) == 0);
    sp_dragon* d = NULL;
    ENSURE(sp_dragon_create(
               &(sp_dragon_desc){.db_path = path, .canvas_w = 1280, .canvas_h = 800, .no_model = true, .solve = k_uncapped}, &d,
               &err) == SP_OK);
    ENSURE(sp_dragon_model(d) == NULL && !sp_dragon_model_error(d)[0]); // none asked for: no error
    sp_vec2* xy;
    int n = part_stroke(db, "torso_t", 5, 0.3, 640, 400, 400, &xy);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK && !res.rejected);
    ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_NO_MODEL);
    // The database replaced (a curator's new file): reopened, still no model.
    snprintf(cmd, sizeof cmd, "cp '%s' '%s.new' && mv '%s.new' '%s'", test_db(), path, path, path);
    ENSURE(system(cmd) == 0);
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded && sp_dragon_model(d) == NULL);
    free(xy);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

static void test_rejects_and_bad_strokes(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    sp_dragon* d = dragon_and_db(path, &db);
    sp_vec2* xy;
    int n = part_stroke(db, "torso_t", 5, 0.3, 640, 400, 400, &xy);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    char before[512], after[512];
    dragon_signature(d, before, sizeof before);
    // A scribble: a dense random zigzag the classifier has never seen.
    sp_rng rng = {42};
    int rejected = 0;
    for (int k = 0; k < 20; ++k) {
        sp_vec2 s[400];
        for (int i = 0; i < 400; ++i)
            s[i] = (sp_vec2){500 + sp_rng_range(&rng, 0, 300), 300 + sp_rng_range(&rng, 0, 200)};
        ENSURE(sp_dragon_add_points(d, s, 400, NULL, &res, &err) == SP_OK);
        if (res.rejected) {
            ++rejected;
            ENSURE(res.reason == SP_DRAGON_UNRECOGNISED && res.part == -1);
            dragon_signature(d, after, sizeof after);
            ENSURE(!strcmp(before, after));
        } else {
            const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
            fprintf(stderr, "  scribble %d taken as %s (%.2f): fit error %.1f%% of the diagonal\n", k, p->category, p->confidence,
                    100 * p->report.mean_error_px / p->report.bbox_diagonal_px);
            ENSURE(sp_dragon_undo(d));
        }
    }
    fprintf(stderr, "  %d of 20 scribbles rejected\n", rejected);
    ENSURE(rejected >= 15); // the classifier judges; 17 of 20 with this model
    // Broken strokes: never a crash, never a change.
    sp_vec2 one = {100, 100};
    ENSURE(sp_dragon_add_points(d, &one, 1, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT);
    ENSURE(sp_dragon_add_points(d, NULL, 0, NULL, &res, &err) == SP_OK && res.rejected);
    sp_vec2 tap[3] = {{100, 100}, {101, 100}, {100, 101}};
    ENSURE(sp_dragon_add_points(d, tap, 3, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT);
    sp_vec2 nan[3] = {{100, 100}, {NAN, 100}, {200, 200}};
    ENSURE(sp_dragon_add_points(d, nan, 3, NULL, &res, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  NaN: %s\n", err.text);
    sp_vec2 inf[2] = {{100, 100}, {INFINITY, 100}};
    ENSURE(sp_dragon_add_points(d, inf, 2, NULL, &res, &err) == SP_ERR_INVALID);
    sp_vec2 off[3] = {{-500, -500}, {-900, -20}, {-40, -800}}; // all off the canvas: clamped into a corner
    ENSURE(sp_dragon_add_points(d, off, 3, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT);
    // A part too small to see, away from the body (a review: a 20 px head
    // became a body the size of a pea): "a bit bigger please". Chosen by a
    // chip, it stands.
    double speck = 0.9 * SP_DRAGON_PART_MIN * hypot(1280, 800);
    for (int k = 0; k < 2; ++k) {
        n = part_stroke(db, k ? "head_t" : "tail_t", 9, 0.3, 150, 120, speck, &xy);
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT);
        free(xy);
    }
    dragon_signature(d, after, sizeof after);
    ENSURE(!strcmp(before, after));
    n = part_stroke(db, "tail_t", 9, 0.3, 150, 120, speck, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    ENSURE(sp_dragon_undo(d));
    dragon_signature(d, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // Huge coordinates and a stroke that leaves the window: clamped onto the edges; whatever it becomes, it is valid.
    sp_vec2 huge[4] = {{100, 100}, {1e300, 200}, {-1e300, 1e300}, {600, 400}};
    ENSURE(sp_dragon_add_points(d, huge, 4, NULL, &res, &err) == SP_OK);
    if (!res.rejected) ENSURE(sp_dragon_undo(d));
    // A stroke of 10^5 points (resampled) along the torso outline, forced.
    n = part_stroke(db, "torso_t", 6, 0.3, 640, 400, 400, &xy);
    int big = 100000;
    sp_vec2* many = malloc(sizeof(sp_vec2) * (size_t)big);
    ENSURE(sp_curve_resample(xy, n, false, big, many) == SP_OK);
    free(xy);
    ENSURE(sp_dragon_add_points(d, many, big, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK);
    ENSURE(!res.rejected && sp_dragon_part_get(d, res.part)->stroke_points <= SP_DRAGON_MAX_STROKE_POINTS);
    fprintf(stderr, "  10^5 points: %.1f ms\n", res.ms_total);
    free(many);
    ENSURE(sp_dragon_undo(d));
    // A category with no part, a forced category the model does not know.
    ENSURE(sp_dragon_add_points(d, tap, 3, &(sp_dragon_stroke_opts){.category = "unicorn"}, &res, &err) == SP_OK && res.rejected);
    n = part_stroke(db, "tail_t", 7, 0.3, 300, 400, 300, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "unicorn"}, &res, &err) == SP_OK && res.rejected &&
           res.reason == SP_DRAGON_NO_PART);
    free(xy);
    dragon_signature(d, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // A full dragon takes no more parts (Redraw still works).
    sp_dragon* small = NULL;
    sp_dragon_create(&(sp_dragon_desc){.db_path = path, .canvas_w = 1280, .canvas_h = 800, .max_parts = 2, .solve = k_uncapped},
                     &small, &err);
    ENSURE(small);
    n = part_stroke(db, "tail_t", 8, 0.3, 300, 400, 300, &xy);
    for (int k = 0; k < 3; ++k)
        ENSURE(sp_dragon_add_points(small, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK &&
               res.rejected == (k == 2));
    ENSURE(res.reason == SP_DRAGON_FULL && sp_dragon_part_count(small) == 2);
    ENSURE(sp_dragon_add_points(small, xy, n, &(sp_dragon_stroke_opts){.category = "tail", .replace_last = true}, &res, &err) ==
               SP_OK &&
           !res.rejected);
    free(xy);
    sp_dragon_destroy(small);
    // The pose and export still work after all that.
    ENSURE(sp_dragon_pose_at(d, 0.5, &err) == SP_OK);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Runs a SQL statement on the database at `path` (the test's curator).
static void db_sql(const char* path, const char* sql)
{
    sqlite3* h = NULL;
    ENSURE(sqlite3_open(path, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(h, sql, NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(h);
}

// A part whose stored bytes are broken: a stroke that needs it says which
// part and why (not a bare "no_part"), the part is not parsed again by every
// stroke, the others still serve, and a curator's fix is picked up.
static void test_corrupt_part(void)
{
    const char* good = test_db();
    char path[1024], sql[2400], strokes[1024], log[1024], cmd[4000];
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("dragon_corrupt.db"));
    copy_file(good, path);
    db_sql(path, "UPDATE parts SET gltf = zeroblob(64) WHERE name = 'tail_t'");
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(good, SP_DB_READONLY, &db, &err) == SP_OK);
    sp_vec2 *tail, *torso;
    int nt = part_stroke(db, "tail_t", 31, 0.3, 300, 400, 300, &tail);
    int nb = part_stroke(db, "torso_t", 32, 0.3, 640, 400, 400, &torso);
    sp_db_close(db);
    sp_dragon* d = new_dragon(path);
    sp_dragon_result res;
    for (int k = 0; k < 2; ++k) { // the second time from what the first learnt
        ENSURE(sp_dragon_add_points(d, tail, nt, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK);
        ENSURE(res.rejected && res.reason == SP_DRAGON_NO_PART);
        fprintf(stderr, "  %s\n", sp_dragon_part_error(d));
        ENSURE(strstr(sp_dragon_part_error(d), "tail_t"));
    }
    ENSURE(sp_dragon_add_points(d, torso, nb, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK);
    ENSURE(!res.rejected && !sp_dragon_part_error(d)[0]);
    // Preloading skips it and says why.
    sp_dragon* fresh = new_dragon(path);
    ENSURE(sp_dragon_preload(fresh, &err) == SP_OK && strstr(err.text, "tail_t"));
    ENSURE(sp_dragon_loaded_parts(fresh) == TEST_PART_COUNT - 1);
    sp_dragon_destroy(fresh);
    // The part is put back (and the generation counted, as the curator's
    // commands do): the next stroke finds it.
    snprintf(sql, sizeof sql,
             "ATTACH '%s' AS good; UPDATE parts SET gltf = (SELECT gltf FROM good.parts WHERE name = 'tail_t') WHERE name = "
             "'tail_t'; UPDATE meta SET value = value + 1 WHERE key = 'generation'",
             good);
    db_sql(path, sql);
    ENSURE(sp_dragon_add_points(d, tail, nt, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK);
    ENSURE(!res.rejected && !sp_dragon_part_error(d)[0]);
    sp_dragon_destroy(d);
    // `sketchpose dragon` with every part broken: each stroke left out says why.
    db_sql(path, "UPDATE parts SET gltf = zeroblob(64)");
    sp_sketch sk = {.canvas_w = 1280, .canvas_h = 800};
    ENSURE(sp_sketch_add_stroke(&sk, tail, NULL, nt) == SP_OK);
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("dragon_corrupt.json"));
    ENSURE(sp_sketch_write_json(strokes, &sk, &err) == SP_OK);
    sp_sketch_free(&sk);
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("dragon_corrupt.txt"));
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' > /dev/null 2> '%s'", SP_SKETCHPOSE, path, strokes, log);
    ENSURE(system(cmd) != 0);
    char* text = sp_fixture_file_text(log, NULL);
    fprintf(stderr, "%s", text);
    ENSURE(strstr(text, "stroke 0 left out (no_part: ") && strstr(text, "does not match its checksum") &&
           strstr(text, "no stroke became a part"));
    free(text);
    // The parts table itself unreadable (its root page overwritten): the
    // stroke left out names the database and why, not the stroke file alone.
    {
        char broken[1024];
        snprintf(broken, sizeof broken, "%s", sp_test_tmp_path("dragon_parts_table.db"));
        copy_file(good, broken);
        sqlite3* h = NULL;
        sqlite3_stmt* q = NULL;
        ENSURE(sqlite3_open(broken, &h) == SQLITE_OK &&
               sqlite3_exec(h, "PRAGMA journal_mode = DELETE", NULL, NULL, NULL) == SQLITE_OK);
        ENSURE(sqlite3_prepare_v2(
                   h, "SELECT rootpage, (SELECT page_size FROM pragma_page_size) FROM sqlite_master WHERE name = 'parts'", -1, &q,
                   NULL) == SQLITE_OK &&
               sqlite3_step(q) == SQLITE_ROW);
        long page = sqlite3_column_int64(q, 0), size = sqlite3_column_int64(q, 1);
        sqlite3_finalize(q);
        sqlite3_close(h);
        FILE* f = fopen(broken, "r+b");
        ENSURE(f && page > 1 && fseek(f, (page - 1) * size, SEEK_SET) == 0);
        for (long i = 0; i < size; ++i)
            fputc((int)((i * 131 + 7) & 0xff), f);
        fclose(f);
        char run[4000];
        snprintf(run, sizeof run, "'%s' dragon --db '%s' --strokes '%s' > /dev/null 2> '%s'", SP_SKETCHPOSE, broken, strokes,
                 log);
        ENSURE(system(run) != 0);
        text = sp_fixture_file_text(log, NULL);
        fprintf(stderr, "%s", text);
        char want[1200];
        snprintf(want, sizeof want, "stroke 0 left out (no_part: %s: ", broken);
        ENSURE(strstr(text, want) && strstr(text, "malformed"));
        free(text);
        sp_fixture_remove_db(broken);
    }
    // A model that cannot be used is said once, naming the database, not
    // as every stroke left out "no_model" blaming the stroke file.
    const char* models[] = {"UPDATE models SET model = substr(model, 1, 1000)", "DELETE FROM models"};
    const char* says[] = {": stored bytes do not match the checksum", ": no trained model (run `sketchpose db train`)"};
    for (int i = 0; i < 2; ++i) {
        db_sql(path, models[i]);
        ENSURE(system(cmd) != 0);
        text = sp_fixture_file_text(log, NULL);
        fprintf(stderr, "%s", text);
        char want[1400];
        snprintf(want, sizeof want, "sketchpose dragon: %s: ", path);
        ENSURE(!strncmp(text, want, strlen(want)) && strstr(text, says[i]) && strchr(text, '\n') == text + strlen(text) - 1);
        free(text);
        sp_dragon* m = new_dragon(path);
        ENSURE(!sp_dragon_model(m) && strstr(sp_dragon_model_error(m), says[i]));
        sp_dragon_destroy(m);
    }
    // The demo says it the same way, and takes back the output folder it made.
    char demo_out[1100];
    snprintf(demo_out, sizeof demo_out, "%s", sp_test_tmp_path("corrupt_demo_out"));
    snprintf(cmd, sizeof cmd, "'%s' demo --db '%s' --out '%s' > /dev/null 2> '%s'", SP_SKETCHPOSE, path, demo_out, log);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    text = sp_fixture_file_text(log, NULL);
    ENSURE(strstr(text, "sketchpose demo: ") && strstr(text, says[1]) && strchr(text, '\n') == text + strlen(text) - 1);
    free(text);
    ENSURE(access(demo_out, F_OK) != 0);
    // An output folder that cannot be made: said with the system's reason.
    snprintf(cmd, sizeof cmd, "'%s' demo --db '%s' --out '%s/no/such' > /dev/null 2> '%s'", SP_SKETCHPOSE, path, demo_out, log);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    text = sp_fixture_file_text(log, NULL);
    ENSURE(strstr(text, "sketchpose demo: ") && strstr(text, "/no/such: cannot create the folder (No such file or directory)"));
    free(text);
    free(tail), free(torso);
    sp_fixture_remove_db(path);
}

static void test_undo_clear_refit(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    sp_dragon* d = dragon_and_db(path, &db);
    sp_dragon_result res;
    ENSURE(sp_dragon_refit_last(d, "tail", &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_NOTHING_TO_REFIT);
    ENSURE(!sp_dragon_undo(d));
    // Tail first, then the torso: the tail attaches when the torso comes.
    sp_vec2* xy;
    int n = part_stroke(db, "tail_t", 11, 0.3, 330, 470, 330, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    ENSURE(sp_dragon_part_get(d, 0)->attached_to == -1);
    n = part_stroke(db, "torso_t", 12, 0.3, 640, 430, 420, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    ENSURE(sp_dragon_part_count(d) == 2 && sp_dragon_part_get(d, 0)->attached_to == 1);
    // Three heads are fine, each where it was drawn along the torso's front
    // half, touching it (the socket for heads, "neck", is their hint).
    const sp_rig* trig = &sp_dragon_part_get(d, 1)->character->rig;
    sp_vec2* tpx = fitted_px(d, 1);
    double x1 = -INFINITY;
    for (int v = 0; v < trig->vertex_count; ++v)
        x1 = fmax(x1, tpx[v].x);
    for (int k = 0; k < 3; ++k) {
        double x = x1 - 20 - 70 * k;
        n = part_stroke_ex(db, "head_t", 20 + (uint64_t)k, 0.3, (sp_vec2){x, edge_at(trig, tpx, x, true) + 15}, 160, true, false,
                           &xy);
        ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK &&
               !res.rejected);
        free(xy);
        ENSURE(sp_dragon_part_get(d, res.part)->attached_to == 1);
        ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->socket, "neck"));
    }
    free(tpx);
    ENSURE(sp_dragon_part_count(d) == 5);
    // Refit the last head as wings (a chip tap): same count, new category, same stroke.
    const sp_dragon_part* last = sp_dragon_part_get(d, 4);
    uint64_t old_id = last->id;
    int old_points = last->stroke_points;
    ENSURE(sp_dragon_refit_last(d, "wings", &res, &err) == SP_OK && !res.rejected && res.part == 4);
    last = sp_dragon_part_get(d, 4);
    ENSURE(sp_dragon_part_count(d) == 5 && !strcmp(last->category, "wings") && last->id != old_id &&
           last->stroke_points == old_points);
    ENSURE(!strcmp(last->socket, "back"));
    // Redraw: the next stroke replaces the last part; a rejected one keeps it.
    sp_vec2 tap[2] = {{10, 10}, {11, 10}};
    ENSURE(sp_dragon_add_points(d, tap, 2, &(sp_dragon_stroke_opts){.replace_last = true}, &res, &err) == SP_OK && res.rejected);
    ENSURE(sp_dragon_part_count(d) == 5 && sp_dragon_part_get(d, 4)->id == last->id);
    n = part_stroke(db, "legs_t", 30, 0.3, 610, 600, 200, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs", .replace_last = true}, &res, &err) ==
           SP_OK);
    free(xy);
    ENSURE(!res.rejected && sp_dragon_part_count(d) == 5 && !strcmp(sp_dragon_part_get(d, 4)->category, "legs"));
    // Undo the legs and two heads, then the torso: the tail is free again.
    ENSURE(sp_dragon_undo(d) && sp_dragon_undo(d) && sp_dragon_undo(d));
    ENSURE(sp_dragon_part_count(d) == 2 && sp_dragon_part_get(d, 0)->attached_to == 1);
    ENSURE(sp_dragon_undo(d));
    ENSURE(sp_dragon_part_count(d) == 1 && sp_dragon_part_get(d, 0)->attached_to == -1);
    ENSURE(sp_dragon_pose_at(d, 0.3, &err) == SP_OK);
    sp_dragon_clear(d);
    ENSURE(sp_dragon_part_count(d) == 0);
    ENSURE(sp_dragon_pose_at(d, 0.3, &err) == SP_OK);
    sp_vec3 lo, hi;
    ENSURE(!sp_dragon_bounds(d, &lo, &hi));
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Waits (at most a minute) until the model read in the background is taken.
static bool model_taken(sp_dragon* d)
{
    for (int i = 0; i < 6000; ++i) {
        if (sp_dragon_model_update(d)) return true;
        usleep(10000);
    }
    return false;
}

// desc.background_model: a new model is read on a thread of its own while
// the pipeline goes on with the one it has; a model stored during that read
// is read after it; a pipeline destroyed mid-read waits for the thread.
static void test_background_model(void)
{
    char path[1024];
    test_db_copy("dragon_background.db", path);
    sp_error err = {0};
    sp_dragon* d = new_background_dragon(path);
    const sp_clf* first = sp_dragon_model(d);
    ENSURE(first && !sp_dragon_model_loading(d) && !sp_dragon_model_update(d));
    ENSURE(sp_fixture_store_model_again(path));
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded);
    ENSURE(sp_dragon_model(d) == first && sp_dragon_model_loading(d));
    // A stroke meanwhile has a model (the old one, or the new one if its read has ended).
    sp_dragon_result res = {0};
    sp_vec2 tail[4] = {{300, 300}, {420, 330}, {540, 300}, {660, 340}};
    ENSURE(sp_dragon_add_points(d, tail, 4, NULL, &res, &err) == SP_OK && res.reason != SP_DRAGON_NO_MODEL &&
           res.guess_count > 0);
    ENSURE(sp_dragon_model(d) && (sp_dragon_model(d) == first || !sp_dragon_model_loading(d)));
    if (sp_dragon_model_loading(d)) ENSURE(model_taken(d));
    const sp_clf* second = sp_dragon_model(d);
    ENSURE(second != first && !sp_dragon_model_loading(d));
    // Nothing new stored: nothing read.
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && !sp_dragon_model_loading(d));
    // A model stored during a read is read once that one is taken.
    ENSURE(sp_fixture_store_model_again(path));
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded && sp_dragon_model_loading(d));
    ENSURE(sp_fixture_store_model_again(path));
    ENSURE(model_taken(d) && sp_dragon_model_loading(d));
    ENSURE(model_taken(d) && !sp_dragon_model_loading(d));
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && !sp_dragon_model_loading(d));
    // Destroyed mid-read.
    ENSURE(sp_fixture_store_model_again(path));
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && sp_dragon_model_loading(d));
    sp_dragon_destroy(d);
}

// A curator's sketch or review bumps the database's generation but leaves
// its model: the pipeline keeps the model it has (parsing it again held the
// kiosk's frames for 0.5-1 s). A new model row is read.
static void test_reload_keeps_model(void)
{
    char path[1024];
    test_db_copy("dragon_keep.db", path);
    sp_dragon* d = new_dragon(path);
    const sp_clf* first = sp_dragon_model(d);
    ENSURE(first);
    sp_db* writer = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, 0, &writer, &err) == SP_OK);
    sp_sketch one = {0};
    sp_vec2 line[3] = {{10, 10}, {60, 40}, {120, 30}};
    ENSURE(sp_sketch_add_stroke(&one, line, NULL, 3) == SP_OK);
    sp_dataset ds = {0};
    ds.categories = (char*[]){"tail"};
    ds.category_count = 1;
    ds.samples = &(sp_sample){.sketch = one, .label = 0};
    ds.count = 1;
    ENSURE(sp_db_add_sketches(writer, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_OK);
    sp_sketch_free(&one);
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded);
    ENSURE(sp_dragon_model(d) == first);
    // The same model stored again, as a new row: read.
    ENSURE(sp_fixture_store_model_again(path));
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded);
    ENSURE(sp_dragon_model(d) && sp_dragon_model(d) != first);
    sp_db_close(writer);
    sp_dragon_destroy(d);
}

// The newest model's row id in the database at `path`.
static int64_t newest_model(const char* path)
{
    sp_db* db = NULL;
    sp_error err = {0};
    int64_t head = 0;
    ENSURE(sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK && sp_db_model_head(db, &head, NULL, &err) == SP_OK);
    sp_db_close(db);
    return head;
}

// Polls (at most a minute) until no model is being read in the background.
static void settle(sp_dragon* d)
{
    bool reloaded = false;
    sp_error err = {0};
    for (int i = 0; i < 6000 && sp_dragon_model_loading(d); ++i)
        sp_dragon_model_update(d), usleep(10000);
    ENSURE(!sp_dragon_model_loading(d));
    (void)sp_dragon_reload_if_changed(d, &reloaded, &err);
}

// A background read that fails for a reason that may pass (the file moved
// away while it read) keeps the model in use and is tried again later (here
// "later" is brought forward); a stored model that does not parse keeps the
// one in use without a retry.
static void test_background_read_fails(void)
{
    char path[1024], away[1100];
    test_db_copy("dragon_bg_fail.db", path);
    snprintf(away, sizeof away, "%s.away", path);
    sp_error err = {0};
    sp_dragon* d = new_background_dragon(path);
    const sp_clf* first = sp_dragon_model(d);
    ENSURE(sp_fixture_store_model_again(path));
    ENSURE(rename(path, away) == 0);
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded && sp_dragon_model_loading(d));
    settle(d);
    ENSURE(sp_dragon_model(d) == first && d->model_retry_at > 0);
    ENSURE(rename(away, path) == 0);
    d->model_retry_at = 1; // its time has come
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && sp_dragon_model_loading(d));
    settle(d);
    fprintf(stderr, "  in use: model %lld of %lld\n", (long long)d->model_id, (long long)newest_model(path));
    ENSURE(sp_dragon_model(d) != first && d->model_id == newest_model(path) && d->model_retry_at == 0);
    // A newest model whose stored bytes are damaged: the one in use stays, no retry.
    const sp_clf* second = sp_dragon_model(d);
    ENSURE(sp_fixture_store_model_again(path));
    sqlite3* h = NULL;
    ENSURE(sqlite3_open(path, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(h, "UPDATE models SET sha256 = 'x' WHERE id = (SELECT max(id) FROM models)", NULL, NULL, NULL) ==
           SQLITE_OK);
    sqlite3_close(h);
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && sp_dragon_model_loading(d));
    settle(d);
    ENSURE(sp_dragon_model(d) == second && d->model_retry_at == 0);
    sp_dragon_destroy(d);
}

// The database file replaced (a rename) while a model is read, the new
// file's newest model of the same row id as the one read: the new file's is
// the one used.
static void test_background_replaced(void)
{
    char p[1024], b[1024];
    test_db_copy("dragon_bg_p.db", p);
    test_db_copy("dragon_bg_b.db", b);
    sp_error err = {0};
    sp_db* w = NULL;
    // B: another model of the next id (a copy trained elsewhere, other options).
    sp_db_train_desc td = quick_train();
    td.clf.words = 64;
    ENSURE(sp_db_open(b, 0, &w, &err) == SP_OK && sp_db_train(w, &td, NULL, &err) == SP_OK);
    sp_db_close(w);
    sp_dragon* d = new_background_dragon(p);
    // P's next model, of the same id as B's; large, so that its read lasts.
    td.clf.words = 3000;
    ENSURE(sp_db_open(p, 0, &w, &err) == SP_OK && sp_db_train(w, &td, NULL, &err) == SP_OK);
    sp_db_close(w);
    ENSURE(newest_model(p) == newest_model(b));
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded && sp_dragon_model_loading(d));
    ENSURE(rename(b, p) == 0);
    sp_result polled = sp_dragon_reload_if_changed(d, &reloaded, &err); // a stroke's poll: the file is reopened
    if (polled != SP_OK) fprintf(stderr, "  poll: %s\n", err.text);
    ENSURE(polled == SP_OK);
    for (int i = 0; i < 3; ++i)
        settle(d);
    if (d->model_retry_at > 0) {
        // A read that failed for a reason that may pass (the new file busy
        // for its 100 ms under a loaded machine) is tried again later: now.
        fprintf(stderr, "  a read failed and waits to be tried again\n");
        d->model_retry_at = 1;
        settle(d), settle(d);
    }
    sp_db* r = NULL;
    sp_clf* want = NULL;
    ENSURE(sp_db_open(p, SP_DB_READONLY, &r, &err) == SP_OK && sp_db_load_model(r, &want, NULL, &err) == SP_OK);
    sp_db_close(r);
    fprintf(stderr, "  replaced: words in use %d, the file's model %d\n", sp_clf_get_desc(sp_dragon_model(d)).words,
            sp_clf_get_desc(want).words);
    ENSURE(sp_clf_get_desc(sp_dragon_model(d)).words == 64 && sp_clf_get_desc(want).words == 64);
    sp_clf_destroy(want);
    sp_dragon_destroy(d);
}

// A database file renamed over the path while the pipeline opens it (SQLite
// has the old file, the pipeline has not yet noted which): the next poll
// reopens the new one. Noted after the open, the new file was taken for the
// one the handle had, and the pipeline read the old file for good.
static void test_open_race(void)
{
    char path[1024], other[1024];
    test_db_copy("dragon_race.db", path);
    test_db_copy("dragon_race_new.db", other);
    sp_db* w = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(other, 0, &w, &err) == SP_OK && sp_db_remove_part(w, "tail_t", "test", &err) == SP_OK);
    sp_db_close(w);
    sp_fixture_rename_when_opened(other, path);
    sp_dragon* d = new_dragon(path);
    ENSURE(sp_fixture_rename_done()); // renamed during the pipeline's open
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK);
    sp_vec2 tail[40];
    for (int i = 0; i < 40; ++i)
        tail[i] = (sp_vec2){200 + 8 * i, 500 - 60 * sin(0.1 * i)};
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, tail, 40, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK);
    fprintf(stderr, "  first poll: %s; a tail: %s\n", reloaded ? "reopened" : "nothing new",
            res.rejected ? sp_dragon_reject_name(res.reason) : "a part");
    ENSURE(reloaded && res.rejected && res.reason == SP_DRAGON_NO_PART); // the new file has no tail
    sp_dragon_destroy(d);
}

static void test_live_update(void)
{
    char path[1024], other[1024];
    test_db_copy("dragon_live.db", path);
    snprintf(other, sizeof other, "%s", sp_test_tmp_path("dragon_live_new.db"));
    sp_dragon* d = new_dragon(path);
    sp_db* writer = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, 0, &writer, &err) == SP_OK);
    // Horns: not in the database yet.
    sp_rig rig;
    test_part_rig(&k_test_part_horns, false, &rig);
    sp_character ch = {0};
    ENSURE(sp_character_from_rig(&rig, &ch, &err) == SP_OK);
    sp_sketch sk = {0};
    double* p = malloc(sizeof(double) * ((size_t)ch.rig.param_count + 1));
    sp_synth_params(&ch.rig, 3, 0.3, p);
    ENSURE(sp_synth_sketch(&ch.rig, 0, &ch.camera, p, &sk) == SP_OK);
    free(p);
    sp_character_free(&ch);
    sp_vec2 lo, hi;
    ENSURE(sp_sketch_bounds(&sk, &lo, &hi));
    sp_stroke* s = &sk.strokes[0];
    double f = 200 / sp_v2_len(sp_v2_sub(hi, lo));
    for (int i = 0; i < s->count; ++i)
        s->points[i] = (sp_vec2){900 + f * (s->points[i].x - lo.x), 200 + f * (s->points[i].y - lo.y)};
    sp_dragon_result res;
    ENSURE(sp_dragon_add_stroke(d, s, &(sp_dragon_stroke_opts){.category = "horns"}, &res, &err) == SP_OK && res.rejected &&
           res.reason == SP_DRAGON_NO_PART);
    sp_vec2 tail[40];
    for (int i = 0; i < 40; ++i)
        tail[i] = (sp_vec2){200 + 8 * i, 500 - 60 * sin(0.1 * i)};
    ENSURE(sp_dragon_add_points(d, tail, 40, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK && !res.rejected);
    const sp_character* tail_rig = sp_dragon_part_get(d, res.part)->character;
    // A curator adds the part and retrains, from another connection.
    add_spec(writer, &k_test_part_horns, 9);
    train(writer);
    bool reloaded = false;
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && reloaded);
    ENSURE(sp_dragon_reload_if_changed(d, &reloaded, &err) == SP_OK && !reloaded);
    // The unchanged tail part is not loaded again.
    ENSURE(sp_dragon_add_points(d, tail, 40, &(sp_dragon_stroke_opts){.category = "tail", .replace_last = true}, &res, &err) ==
               SP_OK &&
           !res.rejected);
    ENSURE(sp_dragon_part_get(d, res.part)->character == tail_rig);
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 0);
    ENSURE(sp_dragon_add_stroke(d, s, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  after the update: %s (%.2f)%s\n", res.guess_count ? res.guesses[0].category : "-",
            res.guess_count ? res.guesses[0].confidence : 0, res.rejected ? " rejected" : "");
    ENSURE(!res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, "horns"));
    // Removed again: the part already drawn keeps its rig; the next stroke has no part.
    ENSURE(sp_db_remove_part(writer, "horns_t", "test", &err) == SP_OK);
    ENSURE(sp_dragon_add_stroke(d, s, &(sp_dragon_stroke_opts){.category = "horns"}, &res, &err) == SP_OK && res.rejected &&
           res.reason == SP_DRAGON_NO_PART);
    ENSURE(sp_dragon_part_count(d) == 1 && sp_dragon_part_get(d, 0)->character->rig.vertex_count > 0);
    ENSURE(sp_dragon_pose_at(d, 0.1, &err) == SP_OK);
    sp_db_close(writer);
    // The database replaced on disk (a complete new file renamed over it, as
    // sp_db_create_from_export does): reopened, horns are back.
    copy_file(test_db(), other);
    ENSURE(sp_db_open(other, 0, &writer, &err) == SP_OK);
    add_spec(writer, &k_test_part_horns, 10);
    train(writer);
    sp_db_close(writer);
    ENSURE(rename(other, path) == 0);
    sp_result rr = sp_dragon_reload_if_changed(d, &reloaded, &err);
    if (rr != SP_OK) fprintf(stderr, "  reload: %s\n", err.text);
    ENSURE(rr == SP_OK && reloaded);
    ENSURE(sp_dragon_add_stroke(d, s, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  after the replacement: %s (%.2f) %s\n", res.guess_count ? res.guesses[0].category : "-",
            res.guess_count ? res.guesses[0].confidence : 0, sp_dragon_reject_name(res.reason));
    ENSURE(!res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, "horns"));
    // The database deleted: the kiosk keeps drawing with what it has.
    sp_fixture_remove_db(path);
    ENSURE(sp_dragon_add_stroke(d, s, &(sp_dragon_stroke_opts){.category = "horns"}, &res, &err) == SP_OK);
    ENSURE(sp_dragon_part_count(d) >= 2);
    sp_sketch_free(&sk);
    sp_dragon_destroy(d);
}

// Bad usage of `sketchpose dragon`: exit 2 and one line on stderr holding `want`.
static void dragon_usage_error(const char* args, const char* want)
{
    char cmd[6000], err[2048];
    snprintf(cmd, sizeof cmd, "'%s' dragon %s 2>&1 >/dev/null", SP_SKETCHPOSE, args);
    int rc = sp_fixture_run(cmd, err, sizeof err);
    if (rc != 2 || !strstr(err, want) || strchr(err, '\n') != err + strlen(err) - 1)
        fprintf(stderr, "  dragon %s: exit %d, wanted 2 and one line with '%s': %s\n", args, rc, want, err);
    ENSURE(rc == 2 && strstr(err, want) && strchr(err, '\n') == err + strlen(err) - 1);
}

// `sketchpose dragon`'s lines on stderr: at most 10 per-stroke lines and one
// for the rest (500 dots said 500 lines), a stroke off the canvas said so
// (it was "too_short"), and an SVG drawing read as pose reads it (it was
// "malformed JSON near line 1").
static void test_command_stroke_lines(void)
{
    const char* path = test_db();
    char strokes[1024], svg[1024], cmd[4000], said[16384];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("dragon_dots.json"));
    snprintf(svg, sizeof svg, "%s", sp_test_tmp_path("dragon_line.svg"));
    sp_sketch sk = {.canvas_w = 1280, .canvas_h = 800};
    sp_vec2 off[2] = {{-500, -500}, {-300, -400}};
    ENSURE(sp_sketch_add_stroke(&sk, off, NULL, 2) == SP_OK);
    for (int i = 0; i < 30; ++i) {
        sp_vec2 dot[2] = {{100 + 10.0 * i, 100}, {100 + 10.0 * i, 100}};
        ENSURE(sp_sketch_add_stroke(&sk, dot, NULL, 2) == SP_OK);
    }
    sp_error err = {0};
    ENSURE(sp_sketch_write_json(strokes, &sk, &err) == SP_OK);
    sp_sketch_free(&sk);
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' 2>&1 >/dev/null", SP_SKETCHPOSE, path, strokes);
    ENSURE(sp_fixture_run(cmd, said, sizeof said) == 1);
    fprintf(stderr, "%s", said);
    int lines = 0;
    for (const char* c = said; *c; ++c)
        lines += *c == '\n';
    ENSURE(lines == 12); // 10 strokes, the rest, "no stroke became a part"
    ENSURE(strstr(said, "dragon_dots.json: stroke 0 left out (too_short: it lies off the canvas)\n"));
    ENSURE(strstr(said, "dragon_dots.json: stroke 9 left out (too_short)\n") && !strstr(said, "stroke 10 left out"));
    ENSURE(strstr(said, "dragon_dots.json: ... and 21 more strokes left out (too_short 21)\n"));
    // The report keeps every stroke.
    char rep[1024];
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("dragon_dots_report.json"));
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' > '%s' 2>/dev/null", SP_SKETCHPOSE, path, strokes, rep);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    cJSON* j = sp_fixture_json_file(rep);
    ENSURE(j && cJSON_GetArraySize(cJSON_GetObjectItem(j, "strokes")) == 31);
    ENSURE(
        cJSON_IsNull(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(j, "strokes"), 0), "far_score"))); // not measured
    cJSON_Delete(j);
    FILE* f = fopen(svg, "w");
    ENSURE(f);
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 1280 800\"><path d=\"M 5 5 L 6 5\"/></svg>\n");
    ENSURE(fclose(f) == 0);
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' 2>&1 >/dev/null", SP_SKETCHPOSE, path, svg);
    ENSURE(sp_fixture_run(cmd, said, sizeof said) == 1);
    fprintf(stderr, "%s", said);
    ENSURE(strstr(said, "dragon_line.svg: stroke 0 left out (too_short)") && !strstr(said, "malformed JSON"));
}

// `sketchpose dragon`: a stroke file in, a .glb, a PNG and the report out.
static void test_command(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK);
    sp_sketch sk = {.canvas_w = 1280, .canvas_h = 800};
    // A dot first (refused, too short): the parts' curves name strokes 1, 2, … of the file.
    ENSURE(sp_sketch_add_stroke(&sk, (sp_vec2[]){{100, 100}, {101, 100}}, NULL, 2) == SP_OK);
    for (int i = 0; i < TEST_PART_COUNT; ++i) {
        sp_vec2* xy;
        int n = part_stroke(db, k_layout[i].name, 400 + (uint64_t)i, 0.3, k_layout[i].cx, k_layout[i].cy, k_layout[i].size, &xy);
        ENSURE(sp_sketch_add_stroke(&sk, xy, NULL, n) == SP_OK);
        free(xy);
    }
    sp_db_close(db);
    char strokes[1024], out[1024], png[1024], rep[1024], cmd[6000];
    snprintf(strokes, sizeof strokes, "%s", sp_test_tmp_path("dragon_cmd.json"));
    snprintf(out, sizeof out, "%s", sp_test_tmp_path("dragon_cmd.glb"));
    snprintf(png, sizeof png, "%s", sp_test_tmp_path("dragon_cmd.png"));
    snprintf(rep, sizeof rep, "%s", sp_test_tmp_path("dragon_cmd_report.json"));
    ENSURE(sp_sketch_write_json(strokes, &sk, &err) == SP_OK);
    sp_sketch_free(&sk);
    unlink(out), unlink(png), unlink(rep);
    // The database from $SP_DB, as for demo, db and the kiosk (--db was required).
    snprintf(cmd, sizeof cmd, "SP_DB='%s' '%s' dragon --strokes '%s' --out '%s' --render '%s' --report '%s' > /dev/null", path,
             SP_SKETCHPOSE, strokes, out, png, rep);
    ENSURE(system(cmd) == 0);
    struct stat st;
    ENSURE(stat(png, &st) == 0 && st.st_size > 1000);
    cJSON* j = sp_fixture_json_file(rep);
    const char* keys[] = {"ms",           "iterations",    "icp_rounds",   "stopped",          "energy_before",
                          "energy_after", "mean_error_px", "max_error_px", "bbox_diagonal_px", "curves",
                          "parameters",   "parts"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k)
        ENSURE(cJSON_GetObjectItem(j, keys[k]) != NULL);
    const cJSON* parts = cJSON_GetObjectItem(j, "parts");
    ENSURE(cJSON_GetArraySize(parts) == TEST_PART_COUNT);
    const cJSON* pj;
    cJSON_ArrayForEach(pj, parts)
    {
        ENSURE(cJSON_IsString(cJSON_GetObjectItem(pj, "category")));
        ENSURE(cJSON_IsNumber(cJSON_GetObjectItem(pj, "confidence")));
        const cJSON* r = cJSON_GetObjectItem(pj, "report");
        ENSURE(cJSON_IsNumber(cJSON_GetObjectItem(r, "mean_error_px")) && cJSON_IsObject(cJSON_GetObjectItem(r, "parameters")));
        // Where each part went (issue 15).
        double ob[4], sb[4];
        json_box(cJSON_GetObjectItem(pj, "outline_bbox_px"), ob);
        json_box(cJSON_GetObjectItem(pj, "stroke_bbox_px"), sb);
        const cJSON* at = cJSON_GetObjectItem(pj, "attached_to");
        const cJSON* anchor = cJSON_GetObjectItem(pj, "anchor_px");
        ENSURE(cJSON_IsNumber(at) && at->valueint >= -1 && at->valueint < TEST_PART_COUNT);
        ENSURE(at->valueint >= 0 ? cJSON_GetArraySize(anchor) == 2 : cJSON_IsNull(anchor));
    }
    const cJSON* sj;
    cJSON_ArrayForEach(sj, cJSON_GetObjectItem(j, "strokes"))
    {
        // Each accepted stroke's distance from every part, within the refusal's limit.
        const cJSON* far = cJSON_GetObjectItem(sj, "far_score");
        ENSURE(cJSON_IsString(cJSON_GetObjectItem(sj, "note")));
        ENSURE(cJSON_IsTrue(cJSON_GetObjectItem(sj, "rejected"))
                   ? cJSON_IsNull(far) || cJSON_IsNumber(far)
                   : cJSON_IsNumber(far) && far->valuedouble <= SP_DRAGON_FAR_LIMIT);
    }
    const cJSON* cv;
    int named = 0;
    cJSON_ArrayForEach(cv, cJSON_GetObjectItem(j, "curves"))
    {
        const cJSON* st = cJSON_GetObjectItem(cv, "stroke");
        if (!cJSON_IsNumber(st)) continue;
        const cJSON* from = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "strokes"), st->valueint);
        ENSURE(st->valueint >= 1 && cJSON_GetObjectItem(from, "part")->valueint == cJSON_GetObjectItem(cv, "part")->valueint);
        ++named;
    }
    ENSURE(named >= TEST_PART_COUNT);
    fprintf(stderr, "  sketchpose dragon: mean error %.2f px over %d parts, %.0f ms of solving\n",
            cJSON_GetObjectItem(j, "mean_error_px")->valuedouble, cJSON_GetArraySize(parts),
            cJSON_GetObjectItem(j, "ms")->valuedouble);
    cJSON_Delete(j);
    int v = sp_fixture_gltf_validate(out);
    if (v >= 0) ENSURE(v == 1);
    // Bad input: exit 1 with one line; bad usage: exit 2.
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes /nonexistent.json --out '%s' 2>/dev/null", SP_SKETCHPOSE, path,
             out);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    // A canvas larger than the kiosk's (it became 1280 x 800, the strokes off it).
    char big[1024], line[2048];
    snprintf(big, sizeof big, "%s", sp_test_tmp_path("dragon_big_canvas.json"));
    sp_sketch bigsk = {.canvas_w = 20000, .canvas_h = 12000};
    sp_vec2 two[2] = {{100, 100}, {15000, 9000}};
    ENSURE(sp_sketch_add_stroke(&bigsk, two, NULL, 2) == SP_OK && sp_sketch_write_json(big, &bigsk, &err) == SP_OK);
    sp_sketch_free(&bigsk);
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' 2>&1 >/dev/null", SP_SKETCHPOSE, path, big);
    ENSURE(sp_fixture_run(cmd, line, sizeof line) == 1 &&
           strstr(line, "dragon_big_canvas.json: canvas 20000 x 12000 is larger") &&
           strchr(line, '\n') == line + strlen(line) - 1);
    // No --db and no $SP_DB: ./sketchpose.db, built from --assets when missing
    // (here there are none: exit 1, nothing made).
    char nodb[1100];
    snprintf(nodb, sizeof nodb, "%s", sp_test_tmp_path("dragon_nodb"));
    ENSURE(mkdir(nodb, 0755) == 0 || errno == EEXIST);
    snprintf(cmd, sizeof cmd, "cd '%s' && env -u SP_DB '%s' dragon --strokes '%s' --assets /nonexistent 2>/dev/null", nodb,
             SP_SKETCHPOSE, strokes);
    ENSURE(WEXITSTATUS(system(cmd)) == 1);
    snprintf(cmd, sizeof cmd, "%s/sketchpose.db", nodb);
    ENSURE(access(cmd, F_OK) != 0 && rmdir(nodb) == 0);
    snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' 2>/dev/null", SP_SKETCHPOSE, path);
    ENSURE(WEXITSTATUS(system(cmd)) == 2); // --strokes is required
    // --max-ms out of (0, 3600000] is bad usage, as for pose (it was the default)
    for (int i = 0; i < 2; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' --max-ms %s 2>&1 >/dev/null | grep -q 'max-ms must be'",
                 SP_SKETCHPOSE, path, strokes, i ? "-5" : "0");
        ENSURE(system(cmd) == 0);
        snprintf(cmd, sizeof cmd, "'%s' dragon --db '%s' --strokes '%s' --max-ms %s >/dev/null 2>&1", SP_SKETCHPOSE, path,
                 strokes, i ? "-5" : "0");
        ENSURE(WEXITSTATUS(system(cmd)) == 2);
    }
    // --time: [0, 3600] s (a negative time was taken as one counted back from
    // a loop); what is not a finite number is refused by the parser.
    const char* bad_time[][2] = {{"-1", "--time must be in [0, 3600], got -1"},
                                 {"3601", "--time must be in [0, 3600], got 3601"},
                                 {"nan", "--time expects a finite number, got 'nan'"},
                                 {"-inf", "--time expects a finite number, got '-inf'"},
                                 {"1.5x", "--time expects a finite number, got '1.5x'"}};
    for (int i = 0; i < 5; ++i) {
        char args[4000];
        snprintf(args, sizeof args, "--db '%s' --strokes '%s' --time %s", path, strokes, bad_time[i][0]);
        dragon_usage_error(args, bad_time[i][1]);
    }
    // Outputs by their names: --out other than .glb/.gltf and --render other
    // than .png are bad usage before any work, and nothing is written (the
    // .txt got glTF JSON before, the .jpg a PNG).
    const char* bad_out[2][3] = {{"--out", "dragon_cmd.txt", "--out writes glTF"},
                                 {"--render", "dragon_cmd.jpg", "--render writes a PNG"}};
    for (int i = 0; i < 2; ++i) {
        char bad[1024], args[4000];
        snprintf(bad, sizeof bad, "%s", sp_test_tmp_path(bad_out[i][1]));
        unlink(bad);
        snprintf(args, sizeof args, "--db '%s' --strokes '%s' %s '%s'", path, strokes, bad_out[i][0], bad);
        dragon_usage_error(args, bad_out[i][2]);
        ENSURE(stat(bad, &st) != 0);
    }
}

// The shipped parts (assets/*.glb), once they exist: a default database built
// from them, one stroke per part from its own synthetic sketch, the whole pipeline.
// `sketchpose demo` (the README's run command without a display) on the
// shipped parts' database: six parts placed, the files it names written, the
// .glb valid.
static void check_demo(const char* db_path)
{
    char dir[1024], cmd[4000], glb[1200], png[1200], strokes[1200], log[1200], progress[1200];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("dragon_demo"));
    snprintf(glb, sizeof glb, "%s/dragon.glb", dir);
    snprintf(png, sizeof png, "%s/dragon.png", dir);
    snprintf(strokes, sizeof strokes, "%s/strokes.json", dir);
    snprintf(log, sizeof log, "%s", sp_test_tmp_path("dragon_demo.txt"));
    snprintf(progress, sizeof progress, "%s", sp_test_tmp_path("dragon_demo_progress.txt"));
    unlink(glb), unlink(png), unlink(strokes);
    snprintf(cmd, sizeof cmd, "'%s' demo --db '%s' --out '%s' > '%s' 2> '%s'", SP_SKETCHPOSE, db_path, dir, log, progress);
    ENSURE(system(cmd) == 0);
    // stdout is the result, what was made and where; the parts' progress is on
    // stderr (it was mixed into stdout).
    char* text = sp_fixture_file_text(log, NULL);
    char* prog = sp_fixture_file_text(progress, NULL);
    fprintf(stderr, "%s%s", prog, text);
    ENSURE(strstr(text, "a dragon of 8 parts") && strstr(text, glb) && strstr(text, png));
    ENSURE(!strstr(text, "recognised (") && strstr(prog, "  torso ") && strstr(prog, "recognised ("));
    free(text);
    free(prog);
    struct stat st;
    ENSURE(stat(png, &st) == 0 && st.st_size > 10000);
    sp_sketch sk = {0};
    sp_error err = {0};
    ENSURE(sp_sketch_read_json(strokes, &sk, &err) == SP_OK && sk.stroke_count == 8);
    sp_sketch_free(&sk);
    // Its strokes are on the body: every part but the torso attached, lying on its stroke.
    char rep[1200];
    snprintf(rep, sizeof rep, "%s/report.json", dir);
    cJSON* j = sp_fixture_json_file(rep);
    const cJSON* pj;
    double worst = 1;
    cJSON_ArrayForEach(pj, cJSON_GetObjectItem(j, "parts"))
    {
        double ob[4], sb[4];
        json_box(cJSON_GetObjectItem(pj, "outline_bbox_px"), ob);
        json_box(cJSON_GetObjectItem(pj, "stroke_bbox_px"), sb);
        bool torso = !strcmp(cJSON_GetObjectItem(pj, "category")->valuestring, "torso");
        ENSURE(cJSON_GetObjectItem(pj, "attached_to")->valueint == (torso ? -1 : 0));
        worst = fmin(worst, iou(ob, sb));
    }
    fprintf(stderr, "  demo: every part on the body, outline/stroke IoU >= %.2f\n", worst);
    ENSURE(worst >= 0.6);
    cJSON_Delete(j);
    int v = sp_fixture_gltf_validate(glb);
    if (v >= 0) ENSURE(v == 1);
}

// A default database of the shipped parts (built once per run; quickly
// trained), with the hand-placed designs (`drawn`) or without; skips the
// running test when assets/ has no parts yet.
static const char* real_db_ex(bool drawn)
{
    static char paths[2][1024];
    char* path = paths[drawn];
    if (path[0]) return path;
    char assets[1024];
    snprintf(assets, sizeof assets, "%s/assets", SP_SOURCE_DIR);
    DIR* dir = opendir(assets);
    int glbs = 0;
    if (dir) {
        struct dirent* e;
        while ((e = readdir(dir)))
            glbs += strlen(e->d_name) > 4 && !strcmp(e->d_name + strlen(e->d_name) - 4, ".glb");
        closedir(dir);
    }
    if (glbs == 0) SKIP("assets/ has no parts yet");
    snprintf(path, 1024, "%s", sp_test_tmp_path(drawn ? "dragon_default.db" : "dragon_undrawn.db"));
    sp_fixture_remove_db(path);
    sp_error err = {0};
    sp_db_default_desc dd = {.synth_per_part = 40, .drawn_per_design = drawn ? 0 : -1, .train = quick_train()};
    sp_result r = sp_db_create_default(path, assets, &dd, &err);
    if (r != SP_OK) fprintf(stderr, "  default database: %s\n", err.text);
    if (r != SP_OK) path[0] = 0;
    ENSURE(r == SP_OK);
    return path;
}

static const char* real_db(void)
{
    return real_db_ex(true);
}

static void test_six_real_parts(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_result r;
    sp_db* db = NULL;
    ENSURE(sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK);
    sp_db_part_info* infos = NULL;
    int np = 0;
    ENSURE(sp_db_list_parts(db, &infos, &np, &err) == SP_OK);
    // Torso first (the others attach to it), the rest spread around it.
    sp_dragon* d = new_dragon(path);
    int order[64], k = 0;
    for (int i = 0; i < np && k < 64; ++i)
        if (!strcmp(infos[i].category, "torso")) order[k++] = i;
    for (int i = 0; i < np && k < 64; ++i)
        if (strcmp(infos[i].category, "torso")) order[k++] = i;
    // Where a visitor would draw each part of a dragon facing right (others: around the torso).
    static const layout where[] = {{"torso", 640, 420, 420}, {"head", 900, 300, 200},       {"tail", 330, 430, 320},
                                   {"wings", 600, 240, 320}, {"front_legs", 740, 570, 190}, {"hind_legs", 500, 570, 190}};
    int right = 0;
    for (int m = 0; m < k; ++m) {
        const sp_db_part_info* info = &infos[order[m]];
        double ang = 2 * PI * m / (k > 1 ? k - 1 : 1);
        double cx = 640 + 330 * cos(ang), cy = 400 - 230 * sin(ang), size = 250;
        for (size_t w = 0; w < sizeof where / sizeof where[0]; ++w)
            if (!strcmp(where[w].name, info->category)) cx = where[w].cx, cy = where[w].cy, size = where[w].size;
        sp_vec2* xy;
        int n = part_stroke(db, info->name, 500 + (uint64_t)m, 0.3, cx, cy, size, &xy);
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
        if (res.rejected || strcmp(sp_dragon_part_get(d, res.part)->category, info->category)) {
            if (!res.rejected) ENSURE(sp_dragon_undo(d));
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = info->category}, &res, &err) == SP_OK);
        } else {
            ++right;
        }
        free(xy);
        ENSURE(!res.rejected);
        const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
        fprintf(stderr, "  %-12s %-10s fit %.2f%% of %.0f px in %.1f ms (total %.1f ms, first of its kind), attached to %d %s\n",
                info->name, p->category, 100 * p->report.mean_error_px / p->report.bbox_diagonal_px, p->report.bbox_diagonal_px,
                res.ms_fit, res.ms_total, p->attached_to, p->socket);
        ENSURE(p->report.mean_error_px / p->report.bbox_diagonal_px < 0.05);
    }
    fprintf(stderr, "  classified %d of %d right\n", right, k);
    ENSURE(right >= k - 1);
    // Pen-up to fitted part once the parts are loaded (what a visitor waits for).
    sp_dragon* d2 = new_dragon(path);
    double tp = sp_now_ms();
    ENSURE(sp_dragon_preload(d2, &err) == SP_OK);
    fprintf(stderr, "  preloading %d parts: %.0f ms\n", np, sp_now_ms() - tp);
    double ms[256];
    int nm = 0;
    for (int rep = 0; rep < 3; ++rep)
        for (int m = 0; m < k && nm < 256; ++m) {
            sp_vec2* xy;
            int n = part_stroke(db, infos[order[m]].name, 900 + (uint64_t)(rep * k + m), 0.3, 640, 400, 300, &xy);
            sp_dragon_result res;
            ENSURE(sp_dragon_add_points(d2, xy, n, &(sp_dragon_stroke_opts){.category = infos[order[m]].category}, &res, &err) ==
                   SP_OK);
            free(xy);
            ENSURE(!res.rejected);
            ms[nm++] = res.ms_total;
        }
    for (int a = 0; a < nm; ++a)
        for (int b = a + 1; b < nm; ++b)
            if (ms[b] < ms[a]) {
                double x = ms[a];
                ms[a] = ms[b];
                ms[b] = x;
            }
    fprintf(stderr, "  stroke to fitted part, parts loaded: median %.1f ms, max %.1f ms over %d strokes\n", ms[nm / 2],
            ms[nm - 1], nm);
    sp_dragon_destroy(d2);
    bool torso = false;
    for (int m = 0; m < k; ++m)
        torso |= sp_dragon_part_get(d, m)->is_torso;
    if (torso) {
        for (int m = 0; m < k; ++m)
            ENSURE(sp_dragon_part_get(d, m)->is_torso || sp_dragon_part_get(d, m)->attached_to >= 0);
        // The shipped parts' attachment ends (their root joints' pivots) ride the breathing torso.
        check_riding(d, 0, false);
    }
    ENSURE(sp_dragon_period(d) > 0);
    check_export(d, sp_test_tmp_path("dragon_real.glb"), k);
    // Any interpolation in the shipped clips: within 0.5% of the canvas height between keys.
    check_playback(d, sp_test_tmp_path("dragon_real.glb"), 1e-2);
    sp_error rerr = {0};
    r = sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true},
                               sp_test_tmp_path("dragon_real.png"), &rerr);
    ENSURE(r == SP_OK || r == SP_ERR_UNSUPPORTED);
    free(infos);
    sp_dragon_destroy(d);
    sp_db_close(db);
    if (r == SP_OK) check_demo(path);
}

static void test_many_parts(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK);
    drawn lay[MANY];
    sp_vec2* torso;
    int tn;
    // Eight parts and one more each of wings and legs at the same place as another.
    sp_dragon* d = many_body_first(db, path, lay, &torso, &tn);
    int part_of[MANY];
    for (int i = 0; i < MANY; ++i)
        part_of[i] = i + 1;
    check_many(d, lay, part_of, MANY, 0);
    // Two of a kind at the same place: one on the near side, one on the far
    // side, apart in depth (no z-fighting).
    const sp_dragon_part *w1 = sp_dragon_part_get(d, 3), *w2 = sp_dragon_part_get(d, 10);
    const sp_dragon_part *l1 = sp_dragon_part_get(d, 6), *l2 = sp_dragon_part_get(d, 9);
    ENSURE(!w1->far_side && w2->far_side && !l1->far_side && l2->far_side);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    sp_vec3 aw1 = attach_end(d, 3), aw2 = attach_end(d, 10), al1 = attach_end(d, 6), al2 = attach_end(d, 9);
    // The canvas is 2 world units high: 0.1 is 40 px of depth, surfaces well apart.
    fprintf(stderr, "  same place, near and far: wings %.3f world units apart in depth, legs %.3f\n", aw1.z - aw2.z,
            al1.z - al2.z);
    ENSURE(aw1.z - aw2.z > 0.1 && al1.z - al2.z > 0.1);
    check_riding(d, 0, true);
    check_export(d, sp_test_tmp_path("dragon_many.glb"), MANY + 1);
    check_playback(d, sp_test_tmp_path("dragon_many.glb"), 1e-4);
    sp_error rerr = {0};
    sp_result r = sp_dragon_snapshot_png(d, &(sp_dragon_snapshot_desc){.strokes = true, .outlines = true},
                                         sp_test_tmp_path("dragon_many.png"), &rerr);
    ENSURE(r == SP_OK || r == SP_ERR_UNSUPPORTED);
    // With eleven parts, the last one's chip (refit as legs), Redraw (a leg
    // pair along the belly instead) and Undo touch only the last part.
    sp_vec2 anchors[MANY + 1];
    for (int i = 0; i < MANY; ++i)
        anchors[i] = sp_dragon_part_get(d, i)->anchor;
    sp_dragon_result res;
    ENSURE(sp_dragon_refit_last(d, "legs", &res, &err) == SP_OK && !res.rejected && res.part == MANY);
    ENSURE(!strcmp(sp_dragon_part_get(d, MANY)->category, "legs") && sp_dragon_part_count(d) == MANY + 1);
    sp_vec2* xy;
    sp_vec2 between = sp_v2_scale(sp_v2_add(lay[4].at, lay[5].at), 0.5);
    int n = part_stroke_ex(db, "legs_t", 790, 0.3, between, 150, true, false, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs", .replace_last = true}, &res, &err) ==
               SP_OK &&
           !res.rejected && res.part == MANY);
    free(xy);
    ENSURE(sp_dragon_part_count(d) == MANY + 1 && sp_dragon_part_get(d, MANY)->attached_to == 0);
    for (int i = 0; i < MANY; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        ENSURE(p->attached_to < 0 ? isnan(p->anchor.x) : p->anchor.x == anchors[i].x && p->anchor.y == anchors[i].y);
    }
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == MANY);
    ENSURE(sp_dragon_pose_at(d, 0.5, &err) == SP_OK);
    free(torso);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The same strokes with the body drawn last: it collects every part drawn
// before it at the same places; undoing it frees them where they were drawn.
static void test_body_last_and_undo(void)
{
    const char* path = test_db();
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_READONLY, &db, &err) == SP_OK);
    drawn lay[MANY];
    sp_vec2* torso;
    int tn;
    sp_dragon* first = many_body_first(db, path, lay, &torso, &tn); // the reference
    sp_dragon* d = new_dragon(path);
    sp_dragon_result res;
    draw_many(d, db, lay, 0, MANY);
    for (int i = 0; i < MANY; ++i)
        ENSURE(sp_dragon_part_get(d, i)->attached_to == -1);
    ENSURE(sp_dragon_add_points(d, torso, tn, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK &&
           !res.rejected && res.part == MANY);
    int part_of[MANY];
    for (int i = 0; i < MANY; ++i)
        part_of[i] = i;
    check_many(d, lay, part_of, MANY, MANY);
    double worst = 0;
    for (int i = 0; i < MANY; ++i) {
        const sp_dragon_part *a = sp_dragon_part_get(d, i), *b = sp_dragon_part_get(first, i + 1);
        if (a->attached_to < 0) continue;
        ENSURE(a->far_side == b->far_side);
        worst = fmax(worst, hypot(a->anchor.x - b->anchor.x, a->anchor.y - b->anchor.y));
    }
    fprintf(stderr, "  body drawn last: the anchors are those of the body drawn first within %.2g px\n", worst);
    ENSURE(worst < 1e-6);
    check_riding(d, MANY, true);
    // Undo the body: every part free, on its stroke again.
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == MANY);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    cJSON* rep = report_tree(d);
    for (int i = 0; i < MANY; ++i) {
        const cJSON* pj = cJSON_GetArrayItem(cJSON_GetObjectItem(rep, "parts"), i);
        double ob[4], sb[4];
        json_box(cJSON_GetObjectItem(pj, "outline_bbox_px"), ob);
        json_box(cJSON_GetObjectItem(pj, "stroke_bbox_px"), sb);
        ENSURE(sp_dragon_part_get(d, i)->attached_to == -1 && cJSON_GetObjectItem(pj, "attached_to")->valueint == -1);
        ENSURE(cJSON_IsNull(cJSON_GetObjectItem(pj, "anchor_px")));
        ENSURE(iou(ob, sb) >= 0.6);
    }
    cJSON_Delete(rep);
    check_export(d, sp_test_tmp_path("dragon_headless.glb"), MANY);
    free(torso);
    sp_dragon_destroy(first);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

static void put_nan(double* p, int n)
{
    if (n > 0) p[n / 2] = NAN;
}

// What could break the kiosk on a visitor's stroke: a part drawn at a body
// whose triangles have no area, a fit that comes back with NaN, 48 parts
// already placed. The pipeline keeps going and says why (the kiosk shows
// it: tests/unit/test_kiosk_ui.c, test_kiosk_e2e.c).
static void test_robustness(void)
{
    // A body of zero-area triangles (its outline is fine: it can be drawn and fitted).
    char path[1024];
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("dragon_flat.db"));
    sp_fixture_remove_db(path);
    sp_db* db = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, SP_DB_CREATE, &db, &err) == SP_OK);
    test_part_spec flat = k_test_parts[0];
    flat.name = "flat_t";
    add_spec_sketches(db, &flat, true, 1, -1);
    add_spec_sketches(db, &k_test_parts[4], false, 2, -1);
    sp_dragon* d = new_dragon(path);
    sp_vec2* xy;
    int n = part_stroke(db, "flat_t", 5, 0.3, 640, 420, 440, &xy);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    const sp_rig* frig = &sp_dragon_part_get(d, 0)->character->rig;
    sp_vec2* fpx = fitted_px(d, 0);
    n = part_stroke_ex(db, "legs_t", 6, 0.3, (sp_vec2){640, edge_at(frig, fpx, 640, false)}, 170, true, false, &xy);
    free(fpx);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs"}, &res, &err) == SP_OK);
    free(xy);
    fprintf(stderr, "  legs drawn at a body without area: %s, note %s, attached to %d\n", sp_dragon_reject_name(res.reason),
            sp_dragon_note_name(res.note), sp_dragon_part_get(d, 1)->attached_to);
    ENSURE(!res.rejected && res.note == SP_DRAGON_NOTE_NO_SURFACE && sp_dragon_part_get(d, 1)->attached_to == -1);
    ENSURE(sp_dragon_pose_at(d, 0.4, &err) == SP_OK);
    cJSON* rep = report_tree(d);
    ENSURE(!strcmp(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(rep, "parts"), 1), "note")->valuestring,
                   "no_surface"));
    cJSON_Delete(rep);
    ENSURE(sp_dragon_export(d, sp_test_tmp_path("dragon_flat.glb"), &err) == SP_OK);
    sp_dragon_destroy(d);
    sp_db_close(db);

    // NaN in the fitted pose (injected after the solve): refused, nothing changed, and why.
    const char* tpath = test_db();
    ENSURE(sp_db_open(tpath, SP_DB_READONLY, &db, &err) == SP_OK);
    d = new_dragon(tpath);
    d->fit_hook = put_nan;
    n = part_stroke(db, "legs_t", 7, 0.3, 640, 400, 170, &xy);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs"}, &res, &err) == SP_OK);
    fprintf(stderr, "  NaN in the fit: %s, note %s\n", sp_dragon_reject_name(res.reason), sp_dragon_note_name(res.note));
    ENSURE(res.rejected && res.reason == SP_DRAGON_FIT_FAILED && res.note == SP_DRAGON_NOTE_NOT_FINITE);
    ENSURE(sp_dragon_part_count(d) == 0);
    d->fit_hook = NULL;
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs"}, &res, &err) == SP_OK && !res.rejected);
    ENSURE(sp_dragon_undo(d));

    // 48 parts placed (the default limit): the next is refused as full; the
    // dragon poses, reports and exports.
    int torso_n;
    sp_vec2* torso;
    torso_n = part_stroke(db, "torso_t", 8, 0.3, 640, 400, 460, &torso);
    ENSURE(sp_dragon_add_points(d, torso, torso_n, &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK &&
           !res.rejected);
    free(torso);
    double worst_ms = 0;
    for (int k = 1; k < 48; ++k) {
        // Legs all over the canvas: along the body (attached), above and below it (free).
        sp_vec2* lxy;
        int ln = part_stroke(db, "legs_t", 100 + (uint64_t)k, 0.3, 120 + 1040.0 * (k % 16) / 15, 150 + 250.0 * (k / 16), 120, &lxy);
        ENSURE(sp_dragon_add_points(d, lxy, ln, &(sp_dragon_stroke_opts){.category = "legs"}, &res, &err) == SP_OK &&
               !res.rejected);
        free(lxy);
        worst_ms = fmax(worst_ms, res.ms_total);
    }
    int attached = 0;
    for (int k = 1; k < 48; ++k)
        attached += sp_dragon_part_get(d, k)->attached_to == 0;
    fprintf(stderr, "  48 parts: %d legs attached to the body, %d free\n", attached, 47 - attached);
    ENSURE(attached > 0 && attached < 47);
    ENSURE(sp_dragon_part_count(d) == 48);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "legs"}, &res, &err) == SP_OK);
    fprintf(stderr, "  stroke 49: %s (the slowest of the 47 before: %.0f ms)\n", sp_dragon_reject_name(res.reason), worst_ms);
    ENSURE(res.rejected && res.reason == SP_DRAGON_FULL && sp_dragon_part_count(d) == 48);
    ENSURE(sp_dragon_pose_at(d, 0.7, &err) == SP_OK);
    rep = report_tree(d);
    ENSURE(cJSON_GetArraySize(cJSON_GetObjectItem(rep, "parts")) == 48);
    cJSON_Delete(rep);
    ENSURE(sp_dragon_export(d, sp_test_tmp_path("dragon_48.glb"), &err) == SP_OK);
    free(xy);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// An accepted stroke (res, the dragon holding it alone) became, of the
// classifier's guesses, the category whose score over its fit's error (mean
// error over the stroke's diagonal) is highest, and that category leads the
// guesses: each guess is fitted again on the emptied canvas, forced, and
// compared. Returns whether it differs from the classifier's own first guess.
static bool check_rerank(sp_dragon* d, const sp_stroke* stroke, const sp_dragon_result* res)
{
    const sp_dragon_part* kept = sp_dragon_part_get(d, res->part);
    ENSURE(sp_dragon_part_count(d) == 1 && res->guess_count > 0 && !strcmp(kept->category, res->guesses[0].category));
    ENSURE(kept->confidence == res->guesses[0].confidence);
    // The classifier's own ranking of the stroke as the pipeline cleaned it.
    sp_sketch one = {.canvas_w = 1280, .canvas_h = 800, .stroke_count = 1,
                     .strokes = &(sp_stroke){.count = kept->stroke_points, .points = (sp_vec2*)kept->stroke_xy}};
    sp_clf_answer a;
    sp_error err = {0};
    ENSURE(sp_clf_classify(sp_dragon_model(d), &one, NULL, &a, &err) == SP_OK && a.count > 0);
    bool other = strcmp(sp_clf_category(sp_dragon_model(d), a.ranked[0].category), kept->category) != 0;
    sp_dragon_clear(d);
    float first = 0.0f; // the classifier's first guess's score: guesses under a fifth of it are not fitted
    for (int g = 0; g < res->guess_count; ++g)
        first = fmaxf(first, res->guesses[g].confidence);
    int best = -1;
    double best_rank = 0.0;
    for (int g = 0; g < res->guess_count; ++g) {
        if (res->guesses[g].confidence < 0.2f * first) continue;
        sp_dragon_result f;
        ENSURE(sp_dragon_add_stroke(d, stroke, &(sp_dragon_stroke_opts){.category = res->guesses[g].category}, &f, &err) == SP_OK);
        if (f.rejected) continue;
        const sp_solve_report* r = &sp_dragon_part_get(d, f.part)->report;
        double rank = res->guesses[g].confidence / fmax(r->mean_error_px / fmax(r->bbox_diagonal_px, 1.0), 1e-4);
        if (best < 0 || rank > best_rank) best = g, best_rank = rank;
        sp_dragon_clear(d);
    }
    ENSURE(best == 0);
    return other;
}

// True when the default database's recipe finds the people's strokes (the
// Quick, Draw! data under ../shared/data, as assets/sketches/picks.json names it).
static bool people_strokes_present(void)
{
    int picks = 0;
    bool missing = true;
    sp_error err = {0};
    ENSURE(sp_db_people_source(SP_SOURCE_DIR "/assets", NULL, &picks, &missing, &err) == SP_OK);
    return picks > 0 && !missing;
}

// Skips the running test when <build>/tests/data/visitors was built with
// the Quick, Draw! data and it is gone, or without it and it has come since
// (the build's `built` file says which, tests/tools/visitors_build.cmake):
// the next build remakes the set.
static void need_visitors_as_data(void)
{
    static char why[1400];
    char qd[1100], built[1200];
    snprintf(qd, sizeof qd, "%s/quickdraw", SP_SHARED_DATA);
    snprintf(built, sizeof built, "%s/tests/data/visitors/built", SP_BINARY_DIR);
    bool now = access(qd, F_OK) == 0;
    char* text = sp_fixture_file_text(built, NULL);
    bool with = !strncmp(text, "with ", 5), without = !strncmp(text, "without ", 8);
    free(text);
    if (now ? with : without) return;
    snprintf(why, sizeof why, "%s/tests/data/visitors was built %s %s, which is %s now: run `cmake --build %s` to remake it",
             SP_BINARY_DIR, with ? "with" : "without", qd, now ? "there" : "absent", SP_BINARY_DIR);
    SKIP(why);
}

// The kiosk's refusal policy on visitors' drawings (the tune half of
// tests/data/visitors, never trained on): a stroke that looks anything like a
// part becomes a part, clear non-parts are refused. Floors under what this
// quickly trained model reaches (71% right, 9% refused, 97% in the top 3, 52%
// of the non-parts refused, 40% before the mirror evidence; before the
// picture evidence and the fit's re-ranking 65%, 11%, 97%, 40%; before the
// recipe's concept sketches 53%, 3%, 74%, 44%); the classifier's own reject
// threshold refused half of the parts. Every accepted stroke's part is
// checked against the fit's ranking.
static void test_visitors_policy(void)
{
    need_visitors_as_data();
    const char* path = real_db();
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/data/visitors/tune", SP_BINARY_DIR); // built from designs.json (tests/bench/visitors.cmake)
    sp_dataset ds;
    sp_error err = {0};
    ENSURE(sp_dataset_load(dir, &ds, &err) == SP_OK);
    sp_dragon* d = new_dragon(path);
    int parts = 0, right = 0, refused = 0, top3 = 0, non = 0, non_refused = 0, reranked = 0, kin_added = 0, scored = 0, far = 0;
    for (int i = 0; i < ds.count; ++i) {
        const char* label = ds.categories[ds.samples[i].label];
        const sp_stroke* stroke = &ds.samples[i].sketch.strokes[0];
        sp_dragon_result res;
        ENSURE(sp_dragon_add_stroke(d, stroke, NULL, &res, &err) == SP_OK);
        // The far score, where measured, is what refused the stroke or let it through (what `visitors --limits` sweeps).
        if (isfinite(res.far_score)) {
            ++scored;
            ENSURE(res.rejected == (res.far_score > SP_DRAGON_FAR_LIMIT));
            ENSURE(!res.rejected || res.reason == SP_DRAGON_UNRECOGNISED);
            far += res.rejected;
        }
        if (!strcmp(label, "not_a_part")) {
            ++non;
            non_refused += res.rejected;
        } else {
            ++parts;
            refused += res.rejected;
            right += !res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, label);
            for (int k = 0; k < res.guess_count; ++k)
                top3 += !strcmp(res.guesses[k].category, label);
        }
        if (!res.rejected) reranked += check_rerank(d, stroke, &res);
        // A stroke taken for legs (its chips' first guess) offers both kinds,
        // also where the classifier's three best guesses lack the other.
        if (res.guess_count > 0 && strstr(res.guesses[0].category, "legs")) {
            const char* kin = strcmp(res.guesses[0].category, "front_legs") ? "front_legs" : "hind_legs";
            bool offered = false, ranked = false;
            for (int k = 0; k < res.guess_count; ++k)
                offered |= !strcmp(res.guesses[k].category, kin);
            ENSURE(offered);
            sp_clf_answer a;
            ENSURE(sp_clf_classify(sp_dragon_model(d), &ds.samples[i].sketch, NULL, &a, &err) == SP_OK);
            for (int k = 0; k < a.count && k < SP_DRAGON_GUESSES; ++k)
                ranked |= !strcmp(sp_clf_category(sp_dragon_model(d), a.ranked[k].category), kin);
            kin_added += !ranked;
        }
        sp_dragon_clear(d);
    }
    fprintf(stderr,
            "  %d parts: %d right, %d refused, %d in the top 3; %d of %d non-parts refused; %d accepted as another than the "
            "classifier's first guess; %d taken for legs offered the other kind beyond the classifier's three\n",
            parts, right, refused, top3, non_refused, non, reranked, kin_added);
    ENSURE(reranked > 0);  // the fit's evidence decides some strokes
    ENSURE(kin_added > 0); // and the legs' kin some chips
    fprintf(stderr, "  far score measured for %d of %d strokes, %d refused by it\n", scored, ds.count, far);
    ENSURE(scored >= ds.count / 2 && far > 0 && far < scored);
    // Without ../shared/data the set (and the model's training) lacks the Quick, Draw! strokes: the hand-placed drawings remain.
    bool people = people_strokes_present();
    if (!people)
        fprintf(stderr, "  %s/quickdraw is absent: the hand-placed drawings only, a model without people's strokes\n",
                SP_SHARED_DATA);
    ENSURE(people ? parts >= 60 && non >= 20 : parts >= 40 && non >= 14);
    ENSURE(refused <= parts / 6);
    ENSURE(right >= parts / 2);
    ENSURE(top3 >= 9 * parts / 10);
    ENSURE(non_refused >= non / 4);
    // With the default recipe's people's strokes, the policy holds near
    // where the tune half put it (53 right, 3 refused, 65 in the top 3, 14 of
    // 25 non-parts refused): a refusal limit moved from 1.23 to 1.33 refused
    // 10 non-parts and passed the looser checks above.
    if (people) ENSURE(right >= 3 * parts / 4 && refused <= parts / 10 && top3 >= 95 * parts / 100 && 2 * non_refused >= non);
    // A tap, a tiny stroke and a dense scribble are refused whatever the model.
    sp_vec2 tap[2] = {{640, 400}, {641, 400}}, tiny[3] = {{640, 400}, {646, 404}, {650, 406}}, scribble[200];
    for (int i = 0; i < 200; ++i)
        scribble[i] = (sp_vec2){600 + (i % 2 ? 120 : 0) + 5 * sin(i * 0.7), 380 + i * 0.4};
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, tap, 2, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT &&
           isnan(res.far_score));
    ENSURE(sp_dragon_add_points(d, tiny, 3, NULL, &res, &err) == SP_OK && res.rejected && res.reason == SP_DRAGON_TOO_SHORT);
    ENSURE(sp_dragon_add_points(d, scribble, 200, NULL, &res, &err) == SP_OK && res.rejected &&
           res.reason == SP_DRAGON_UNRECOGNISED && isnan(res.far_score)); // refused before its fit
    // Forced categories (a chip tap) are never refused, nor measured.
    ENSURE(sp_dragon_add_points(d, scribble, 200, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK &&
           !res.rejected && isnan(res.far_score));
    sp_dragon_destroy(d);
    sp_dataset_free(&ds);
}

// Draws the shipped part of `category` (a synthetic stroke of its own) in
// the box centred at (cx, cy), optionally mirrored, classified or forced;
// returns the result (ENSURE'd accepted).
// The synthetic stroke of the shipped part of `category` in the box centred
// at (cx, cy), optionally mirrored: *xy malloc'd, returns the point count.
static int category_stroke(sp_db* db, const char* category, double cx, double cy, double size, bool mirror, sp_vec2** xy)
{
    char** names = NULL;
    int n = 0;
    sp_error err = {0};
    ENSURE(sp_db_category_parts(db, category, &names, &n, &err) == SP_OK && n > 0);
    int k = part_stroke_ex(db, names[0], 500, 0.3, (sp_vec2){cx, cy}, size, false, mirror, xy);
    sp_db_free_strings(names, n);
    return k;
}

static sp_dragon_result draw_part(sp_dragon* d, sp_db* db, const char* category, double cx, double cy, double size, bool mirror,
                                  bool forced)
{
    sp_error err = {0};
    sp_vec2* xy;
    int k = category_stroke(db, category, cx, cy, size, mirror, &xy);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, k, forced ? &(sp_dragon_stroke_opts){.category = category} : NULL, &res, &err) == SP_OK);
    free(xy);
    ENSURE(!res.rejected);
    return res;
}

static bool guessed(const sp_dragon_result* res, const char* category)
{
    for (int g = 0; g < res->guess_count; ++g)
        if (!strcmp(res->guesses[g].category, category)) return true;
    return false;
}

// Front and hind legs are one family (sp_part.family "legs"): legs drawn at
// a body whose facing its head tells become the legs of that end, whichever
// the drawing looks like (a tail tells the facing too); the chips still
// offer what it looks like; a chip's choice, a free part, a body without a
// head or tail, and a head and a tail that disagree keep the classifier's
// answer.
static void test_family_by_place(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    // A dragon facing right as modelled, then mirrored (its head drawn on the left).
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        double front = mirrored ? 520 : 760, rear = mirrored ? 760 : 520, head = mirrored ? 380 : 900;
        sp_dragon_clear(d);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        // No head yet: the facing is unknown and the classifier's answer stays.
        sp_dragon_result res = draw_part(d, db, "front_legs", rear, 570, 190, mirrored, false);
        ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, "front_legs"));
        ENSURE(sp_dragon_part_get(d, res.part)->attached_to == 0);
        ENSURE(sp_dragon_undo(d));
        draw_part(d, db, "head", head, 300, 200, mirrored, true);
        ENSURE(sp_dragon_part_get(d, 1)->attached_to == 0);
        static const char* const kinds[2] = {"front_legs", "hind_legs"};
        for (int drawn = 0; drawn < 2; ++drawn)
            for (int at_rear = 0; at_rear < 2; ++at_rear) {
                res = draw_part(d, db, kinds[drawn], at_rear ? rear : front, 570, 190, mirrored, false);
                const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
                fprintf(stderr, "  facing %s, %s drawn at the %s: %s, fit %.1f%% (chips %s, %s)\n", mirrored ? "left" : "right",
                        kinds[drawn], at_rear ? "rear" : "front", p->category,
                        100 * p->report.mean_error_px / p->report.bbox_diagonal_px, res.guesses[0].category,
                        res.guess_count > 1 ? res.guesses[1].category : "-");
                ENSURE(p->attached_to == 0);
                ENSURE(!strcmp(p->category, kinds[at_rear]));
                ENSURE(!strcmp(res.guesses[0].category, p->category));
                ENSURE(guessed(&res, kinds[drawn])); // a part made the other kind keeps what it looks like in the chips
                ENSURE(p->report.mean_error_px / p->report.bbox_diagonal_px < 0.05); // the kind it became takes the stroke
                // The chip's choice stands wherever the legs are.
                ENSURE(sp_dragon_refit_last(d, kinds[!at_rear], &res, &err) == SP_OK && !res.rejected);
                ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, kinds[!at_rear]));
                ENSURE(sp_dragon_undo(d));
            }
        // Far from the body the legs stay what they look like.
        res = draw_part(d, db, "front_legs", rear, 770, 60, mirrored, false);
        ENSURE(sp_dragon_part_get(d, res.part)->attached_to < 0);
        ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, "front_legs"));
        ENSURE(sp_dragon_undo(d));
        // A tail at the head's end contradicts the head: no facing, no change.
        // (Tails drawn high: a tail's root lies low in its box.)
        draw_part(d, db, "tail", mirrored ? 330 : 950, 370, 320, !mirrored, true);
        ENSURE(sp_dragon_part_get(d, 2)->attached_to == 0);
        for (int at_rear = 0; at_rear < 2; ++at_rear) { // neither the head's facing nor the tail's wins
            res = draw_part(d, db, "front_legs", at_rear ? rear : front, 570, 190, mirrored, false);
            ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, "front_legs"));
            ENSURE(sp_dragon_undo(d));
        }
        // A tail alone tells the facing as a head does.
        sp_dragon_clear(d);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        draw_part(d, db, "tail", mirrored ? 950 : 330, 370, 320, mirrored, true);
        ENSURE(sp_dragon_part_get(d, 1)->attached_to == 0);
        res = draw_part(d, db, "front_legs", rear, 570, 190, mirrored, false);
        ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, "hind_legs"));
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The box of n points (sp_sketch_bounds of them as one stroke).
static void points_box(const sp_vec2* xy, int n, sp_vec2* lo, sp_vec2* hi)
{
    sp_sketch one = {.stroke_count = 1, .strokes = &(sp_stroke){.count = n, .points = (sp_vec2*)xy}};
    ENSURE(sp_sketch_bounds(&one, lo, hi));
}

// A drawing of the visitors' set (built from designs.json; `rel` under its
// tune half, one stroke) moved and scaled so that its box has diagonal
// `diag` and centre `at`, mirrored left-right on request. malloc'd; *n points.
static sp_vec2* visitor_stroke(const char* rel, double diag, sp_vec2 at, bool mirror, int* n)
{
    char file[1200];
    snprintf(file, sizeof file, "%s/tests/data/visitors/tune/%s", SP_BINARY_DIR, rel);
    sp_sketch sk;
    sp_error err = {0};
    sp_vec2 lo, hi;
    ENSURE(sp_sketch_read_json(file, &sk, &err) == SP_OK && sk.stroke_count == 1 && sp_sketch_bounds(&sk, &lo, &hi));
    const sp_stroke* s = &sk.strokes[0];
    sp_vec2* xy = malloc(sizeof(sp_vec2) * (size_t)s->count);
    ENSURE(xy);
    double f = diag / hypot(hi.x - lo.x, hi.y - lo.y);
    for (int i = 0; i < s->count; ++i)
        xy[i] = (sp_vec2){at.x + (mirror ? -f : f) * (s->points[i].x - 0.5 * (lo.x + hi.x)),
                          at.y + f * (s->points[i].y - 0.5 * (lo.y + hi.y))};
    *n = s->count;
    sp_sketch_free(&sk);
    return xy;
}

// The box of part i's mesh at its fit on the canvas (fitted_px).
static void fitted_box(const sp_dragon* d, int i, sp_vec2* lo, sp_vec2* hi)
{
    sp_vec2* px = fitted_px(d, i);
    points_box(px, sp_dragon_part_get(d, i)->character->rig.vertex_count, lo, hi);
    free(px);
}

// A visitor's drawing (visitor_stroke: diagonal `diag`, its centre at height
// y, mirrored on request) at the right or left end of the box [blo, bhi]:
// its own box `inset` px into it (negative: that far beyond). malloc'd; *n points.
static sp_vec2* at_box_end(const char* rel, double diag, double y, bool mirror, sp_vec2 blo, sp_vec2 bhi, bool right,
                           double inset, int* n)
{
    sp_vec2 lo, hi, *xy = visitor_stroke(rel, diag, (sp_vec2){0, y}, mirror, n);
    points_box(xy, *n, &lo, &hi);
    double dx = right ? (bhi.x - inset) - lo.x : (blo.x + inset) - hi.x;
    for (int k = 0; k < *n; ++k)
        xy[k].x += dx;
    return xy;
}

// The strokes of the README's kiosk session (docs/img/kiosk_on_body.json: a
// body, then a round head, a club-ended tail and drooping wings drawn on it).
static int readme_session(sp_vec2** xy, int* n, int cap)
{
    char file[1200];
    snprintf(file, sizeof file, "%s/docs/img/kiosk_on_body.json", SP_SOURCE_DIR);
    return sp_fixture_session_strokes(file, xy, n, cap);
}

// A stroke drawn on a body (overlapping it or within the snap distance, clearly smaller) is a part of
// that dragon, never a second body: the classifier's "body" stays among the
// chips and a chip's choice stands; a body drawn apart, or about as large,
// is a second dragon; a Redraw of the body is a body.
static void test_drawn_on_body(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    // A visitor's closed head (the visitors' set, tune half), which alone the classifier takes for a body.
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        sp_dragon_clear(d);
        sp_dragon_result res, body = draw_part(d, db, "torso", 640, 420, 420, false, true);
        ENSURE(sp_dragon_part_get(d, body.part)->is_torso);
        // The head drawn apart from the body, then over the body's front top corner (diagonal 180).
        for (int on = 0; on < 2; ++on) {
            int n;
            sp_vec2 at = {on ? (mirrored ? 470 : 810) : (mirrored ? 1130 : 150), on ? 300 : 120};
            sp_vec2* xy = visitor_stroke("head/head-blunt-round-ear.json", 180, at, mirrored, &n);
            ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
            free(xy);
            const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
            fprintf(stderr, "  head drawn %s, facing %s: %s (chips %s, %s, %s)\n", on ? "on the body" : "apart",
                    mirrored ? "left" : "right", p->category, res.guesses[0].category, res.guesses[1].category,
                    res.guesses[2].category);
            if (!on) { // the premise: alone it looks like a body, and apart it is a second dragon
                ENSURE(p->is_torso);
                ENSURE(sp_dragon_undo(d));
                continue;
            }
            ENSURE(!strcmp(p->category, "head"));
            ENSURE(p->attached_to == body.part);
            ENSURE(!strcmp(res.guesses[0].category, "head"));
            ENSURE(guessed(&res, "torso")); // what it looked like is one tap away
            // The chip's choice stands: a body on a body is a second body.
            ENSURE(sp_dragon_refit_last(d, "torso", &res, &err) == SP_OK && !res.rejected);
            ENSURE(sp_dragon_part_get(d, res.part)->is_torso);
            ENSURE(sp_dragon_undo(d));
        }
        // Drawn near the body's front end, 30 px beyond the fitted body's box
        // (the snap distance is 6% of the canvas diagonal, 91 px): near counts as on.
        {
            sp_vec2 blo, bhi;
            int n;
            fitted_box(d, body.part, &blo, &bhi);
            sp_vec2* xy = at_box_end("head/head-blunt-round-ear.json", 180, blo.y + 40, mirrored, blo, bhi, !mirrored, -30, &n);
            ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
            free(xy);
            const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
            fprintf(stderr, "  head drawn near the body, facing %s: %s (chips %s, %s, %s)\n", mirrored ? "left" : "right",
                    p->category, res.guesses[0].category, res.guesses[1].category, res.guesses[2].category);
            ENSURE(!p->is_torso && guessed(&res, "torso"));
            ENSURE(sp_dragon_undo(d));
        }
        // The body's own stroke, small on the body: not a body; about as large: a second dragon.
        res = draw_part(d, db, "torso", mirrored ? 500 : 780, 330, 150, false, false);
        ENSURE(!sp_dragon_part_get(d, res.part)->is_torso && guessed(&res, "torso"));
        ENSURE(sp_dragon_undo(d));
        res = draw_part(d, db, "torso", 700, 460, 400, false, false);
        ENSURE(sp_dragon_part_get(d, res.part)->is_torso);
        ENSURE(sp_dragon_undo(d));
        // Redraw of the body with a smaller one: the body it replaces does not count.
        sp_vec2* xy;
        int k = category_stroke(db, "torso", 640, 420, 250, false, &xy);
        ENSURE(sp_dragon_add_points(d, xy, k, &(sp_dragon_stroke_opts){.replace_last = true}, &res, &err) == SP_OK);
        free(xy);
        ENSURE(!res.rejected && sp_dragon_part_count(d) == 1 && sp_dragon_part_get(d, res.part)->is_torso);
    }
    // The README's session (docs/img/kiosk_on_body.json): a body, then a round
    // head, a club-ended tail and drooping wings drawn on it, all classified
    // (alone, the default database's model takes each of the three for a body).
    sp_dragon_clear(d);
    sp_vec2* xy[8];
    int n[8], strokes = readme_session(xy, n, 8);
    for (int k = 0; k < strokes; ++k) {
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, xy[k], n[k], NULL, &res, &err) == SP_OK);
        if (res.rejected) fprintf(stderr, "  stroke %d refused: reason %d (%s)\n", k, (int)res.reason, err.text);
        ENSURE(!res.rejected);
        free(xy[k]);
    }
    // One dragon: the body, and three parts attached to it (which parts is
    // the model's call: the README's picture is the default database's, this
    // test's model is trained quickly).
    ENSURE(strokes == 4 && sp_dragon_part_count(d) == 4);
    for (int i = 0; i < 4; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        fprintf(stderr, "  README session, stroke %d: %s, attached to %d\n", i + 1, p->category, p->attached_to);
        ENSURE(p->is_torso == (i == 0) && p->attached_to == (i == 0 ? -1 : 0));
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// On a cleared canvas, the `count` strokes of tests/e2e/data/NAME.json, each
// classified as a visitor's; from stroke `may_refuse` on (0: none) one may
// be refused.
static void draw_data_strokes(sp_dragon* d, const char* name, int count, int may_refuse)
{
    char file[1200];
    snprintf(file, sizeof file, "%s/tests/e2e/data/%s.json", SP_SOURCE_DIR, name);
    sp_sketch sk = {0};
    sp_error err = {0};
    ENSURE(sp_sketch_read_json(file, &sk, &err) == SP_OK && sk.stroke_count == count);
    sp_dragon_clear(d);
    for (int k = 0; k < count; ++k) {
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, sk.strokes[k].points, sk.strokes[k].count, NULL, &res, &err) == SP_OK);
        if (res.rejected) fprintf(stderr, "  %s, stroke %d refused: %s\n", name, k + 1, sp_dragon_reject_name(res.reason));
        ENSURE(!res.rejected || (may_refuse > 0 && k >= may_refuse));
    }
    sp_sketch_free(&sk);
}

// A dragon's body that carries its head stays a body when a second body is
// drawn on it (an outside review's strokes, tests/e2e/data): a body drawn
// again round the first made that one a head as large as the body; an arch
// over the back, which the default database's model took for a body far
// less surely (0.49, against 1.00), made the dragon's body a pair of legs
// and dropped the head.
static void test_body_with_a_part_stays(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    const char* files[2] = {"kiosk_body_again", "kiosk_arch_over_back"};
    for (int f = 0; f < 2; ++f) {
        draw_data_strokes(d, files[f], 3, 2); // the arch: this test's quickly trained model refuses it
        const sp_dragon_part *body = sp_dragon_part_get(d, 0), *head = sp_dragon_part_get(d, 1);
        fprintf(stderr, "  %s: stroke 1 %s (%.2f), stroke 2 %s attached to %d\n", files[f], body->category, body->confidence,
                head->category, head->attached_to);
        ENSURE(body->is_torso && !strcmp(head->category, "head") && head->attached_to == 0);
    }
    // A tail drawn first and taken for a body, legs on it, then the body:
    // the tail is decided again, one body (a rule by the classifier's
    // confidence kept the tail a body; a second review).
    draw_data_strokes(d, "kiosk_tail_first_legs_body", 3, 0);
    int bodies = 0;
    for (int i = 0; i < sp_dragon_part_count(d); ++i)
        bodies += sp_dragon_part_get(d, i)->is_torso;
    fprintf(stderr, "  tail first, legs, body: %d part(s), %d body\n", sp_dragon_part_count(d), bodies);
    ENSURE(bodies == 1);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Parts a child goes over twice without lifting the finger (an outside
// review's strokes, tests/e2e/data): a head drawn back along its line,
// wings round their outline twice, a tail out and back, a body round twice.
// Each was refused with the right part first at 0.97-1.00 (no drawing the
// classifier knows goes over itself); each is now taken as drawn once.
static void test_gone_over_twice(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    draw_data_strokes(d, "kiosk_gone_over_twice", 4, 0);
    const char* want[4] = {"torso", "head", "wings", "tail"};
    ENSURE(sp_dragon_part_count(d) == 4);
    for (int i = 0; i < 4; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        fprintf(stderr, "  stroke %d: %s (%.2f), attached to %d\n", i + 1, p->category, p->confidence, p->attached_to);
        ENSURE(!strcmp(p->category, want[i]) && p->attached_to == (i == 0 ? -1 : 0));
    }
    draw_data_strokes(d, "kiosk_body_twice_round", 1, 0);
    ENSURE(sp_dragon_part_count(d) == 1 && sp_dragon_part_get(d, 0)->is_torso);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The canvas box of detail i's points as posed (after sp_dragon_pose_at);
// false when it is not shown.
static bool detail_box(const sp_dragon* d, int i, sp_vec2* lo, sp_vec2* hi)
{
    sp_dragon_detail e;
    if (!sp_dragon_detail_get(d, i, &e) || !e.xyz) return false;
    *lo = (sp_vec2){INFINITY, INFINITY}, *hi = (sp_vec2){-INFINITY, -INFINITY};
    const sp_camera cam = sp_dragon_camera(d);
    for (int j = 0; j < e.point_count; ++j) {
        sp_vec2 p = sp_camera_project(&cam, (sp_vec3){e.xyz[3 * j], e.xyz[3 * j + 1], e.xyz[3 * j + 2]});
        lo->x = fmin(lo->x, p.x), lo->y = fmin(lo->y, p.y), hi->x = fmax(hi->x, p.x), hi->y = fmax(hi->y, p.y);
    }
    return true;
}

// An eye drawn in a head drawn first, which the classifier took for a
// body, then the body: the head is decided again and its eye goes with it
// (it was hidden for good: bound to the body fit the head no longer had).
// Undo of the body gives the first fit back, and the eye as it was bound.
static void test_ink_follows_its_part(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    sp_error err = {0};
    draw_data_strokes(d, "kiosk_head_first_eye", 3, 1);
    ENSURE(sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == 1);
    const sp_dragon_part *head = sp_dragon_part_get(d, 0), *body = sp_dragon_part_get(d, 1);
    fprintf(stderr, "  first stroke: %s, then %s\n", head->category, body->category);
    ENSURE(!strcmp(head->category, "head") && body->is_torso && head->attached_to == 1);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    sp_vec2 lo, hi;
    ENSURE(detail_box(d, 0, &lo, &hi));
    fprintf(stderr, "  the eye shown at [%.0f %.0f %.0f %.0f] (drawn at about [768 309 782 321])\n", lo.x, lo.y, hi.x, hi.y);
    ENSURE(fabs(0.5 * (lo.x + hi.x) - 775) < 12 && fabs(0.5 * (lo.y + hi.y) - 315) < 12 && hi.x - lo.x > 8 && hi.x - lo.x < 30);
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 1 && sp_dragon_part_get(d, 0)->is_torso);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK && detail_box(d, 0, &lo, &hi));
    ENSURE(fabs(0.5 * (lo.x + hi.x) - 775) < 12 && fabs(0.5 * (lo.y + hi.y) - 315) < 12);
    // Spots on legs that the head drawn next makes the other kind (a second
    // review): they stay on the legs, where they hung 50 px beside them in
    // the air, bound where the old fit had the leg.
    draw_data_strokes(d, "kiosk_ink_legs_change_kind", 5, 2);
    ENSURE(sp_dragon_detail_count(d) == 2 && sp_dragon_pose_at(d, 0, &err) == SP_OK);
    const sp_camera cam = sp_dragon_camera(d);
    for (int i = 0; i < 2; ++i) {
        sp_dragon_detail e;
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.xyz && detail_box(d, i, &lo, &hi));
        sp_vec2 mid = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y)};
        const double* v = sp_dragon_part_xyz(d, e.part);
        double nearest = INFINITY;
        for (int k = 0; k < sp_dragon_part_get(d, e.part)->character->rig.vertex_count; ++k)
            nearest = fmin(nearest,
                           sp_v2_len(sp_v2_sub(sp_camera_project(&cam, (sp_vec3){v[3 * k], v[3 * k + 1], v[3 * k + 2]}), mid)));
        fprintf(stderr, "  spot %d on %s: %.1f px from its nearest vertex\n", i, sp_dragon_part_get(d, e.part)->category,
                nearest);
        ENSURE(nearest < 8);
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The visitors' tails these tests draw out of a body's end.
static const char* const k_end_tails[4] = {"tail/tail-outline-spade.json", "tail/tail-outline-flame.json",
                                           "tail/tail-line-curl.json", "tail/tail-wavy-line.json"};

// On a cleared canvas, the test body (forced, at the canvas's middle; its
// result to *body) and a visitor's tail stroke (diagonal 260, mirrored when
// right) placed out of the body's left end, or its right: its box `inset` px
// into the body's (30: the visitors bench's --on-body scene; negative: that
// far apart), centred on the body's height. The stroke is malloc'd, *n
// points; not drawn.
static sp_vec2* tail_out_of_body(sp_dragon* d, sp_db* db, const char* tail, bool right, double inset, sp_dragon_result* body,
                                 int* n)
{
    sp_dragon_clear(d);
    *body = draw_part(d, db, "torso", 640, 420, 420, false, true);
    sp_vec2 blo, bhi;
    fitted_box(d, body->part, &blo, &bhi);
    return at_box_end(tail, 260, 0.5 * (blo.y + bhi.y), right, blo, bhi, right, inset, n);
}

// A head or tail drawn out of a body's end has its root at the body, also
// when the other facing fits the stroke better (visitors' tails ending in a
// spade, a flame or a curl fit best reversed): it attaches there, facing
// away from the body, whichever end of the body it comes out of.
static void test_root_at_the_body(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    int reversed_alone = 0, near_attached = 0;
    for (int k = 0; k < 8; ++k)
        for (int right = 0; right < 2; ++right) { // the tail out of the body's left end (as modelled), then its right
            sp_dragon_result res, body;
            int n;
            // Into the body's box, then 30 px beyond its end: near enough to attach, so the same.
            double inset = k < 4 ? 30 : -30;
            sp_vec2* xy = tail_out_of_body(d, db, k_end_tails[k % 4], right, inset, &body, &n);
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK &&
                   !res.rejected);
            const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
            fprintf(stderr, "  %s %s the body's %s end: attached to %d, mirrored %d, fit %.2f%%\n", k_end_tails[k % 4],
                    inset > 0 ? "out of" : "30 px beyond", right ? "right" : "left", p->attached_to, p->mirrored,
                    100 * p->report.mean_error_px / p->report.bbox_diagonal_px);
            // Its root towards the body, and at the body also beyond its end:
            // the wavy line's fit, with its line, reaches the stroke's end.
            ENSURE(p->mirrored == (right != 0));
            ENSURE(p->attached_to == body.part);
            near_attached += inset < 0 && p->attached_to == body.part;
            // The premise: drawn alone, its shape fits the other facing better.
            sp_dragon_clear(d);
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK &&
                   !res.rejected);
            reversed_alone += sp_dragon_part_get(d, res.part)->mirrored != (right != 0);
            free(xy);
        }
    fprintf(stderr, "  drawn alone, %d of 16 fit reversed; beyond the end, %d of 8 attached\n", reversed_alone, near_attached);
    ENSURE(reversed_alone >= 8 && near_attached == 8);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Adds a stroke as `category` (as a chip would: this test's quick database
// must not decide what it is); returns the new part's index.
static int add_as(sp_dragon* d, const sp_vec2* xy, int n, const char* category)
{
    sp_error err = {0};
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = category}, &res, &err) == SP_OK && !res.rejected);
    return res.part;
}

// The name of the abstraction part i was fitted with ("outline", "line").
static const char* fitted_curve(const sp_dragon* d, int i)
{
    const sp_dragon_part* p = sp_dragon_part_get(d, i);
    return p->character->rig.abstractions[p->abstraction].name;
}

// How far the fitted curve of part i reaches along the stroke xy: the
// share of the stroke's points within `near` px of the curve.
static double fitted_reach(const sp_dragon* d, int i, const sp_vec2* xy, int n, double near)
{
    int m = sp_dragon_part_fitted_outline(d, i, NULL);
    sp_vec2* c = malloc(sizeof(sp_vec2) * (size_t)m);
    ENSURE(c && sp_dragon_part_fitted_outline(d, i, c) == m);
    int reached = 0;
    for (int k = 0; k < n; ++k) {
        double best = INFINITY;
        for (int j = 0; j < m; ++j)
            best = fmin(best, sp_v2_len(sp_v2_sub(xy[k], c[j])));
        reached += best <= near;
    }
    free(c);
    return (double)reached / n;
}

// A tail drawn as one open line (the visitors' wavy lines, tune half) is
// fitted with the tail's line (sp_rig_add_line): along the whole stroke,
// where its outline covered only part of it. A closed tail keeps the
// outline, and so does a line taken for a part without a line (a head).
static void test_line_drawn(void)
{
    const char* path = real_db();
    sp_dragon* d = new_dragon(path);
    const char* lines[] = {"tail/tail-wavy-line.json", "tail/tail-wavy-line-rising.json"};
    int as_line = 0, total = 0;
    double reach_sum = 0;
    for (int k = 0; k < 2; ++k)
        for (int mirror = 0; mirror < 2; ++mirror)
            for (int size = 0; size < 2; ++size) {
                int n;
                sp_vec2* xy = visitor_stroke(lines[k], size ? 420 : 300, (sp_vec2){640, 400}, mirror, &n);
                int i = add_as(d, xy, n, "tail");
                const char* curve = fitted_curve(d, i);
                double reach = fitted_reach(d, i, xy, n, 0.06 * (size ? 420 : 300));
                fprintf(stderr, "  %s%s, %.0f px: fitted with its %s, %.0f%% of the stroke within 6%% of its size\n", lines[k],
                        mirror ? " mirrored" : "", size ? 420.0 : 300.0, curve, 100 * reach);
                as_line += !strcmp(curve, "line");
                reach_sum += reach;
                ++total;
                sp_dragon_clear(d);
                free(xy);
            }
    // Fitted with their outlines, these reach 74% (the wavy line) and 90-93%.
    fprintf(stderr, "  %d of %d fitted with the line, reaching %.0f%% of their strokes\n", as_line, total, 100 * reach_sum / total);
    ENSURE(as_line >= total - 2 && reach_sum / total >= 0.85);
    const char* closed[][2] = {{"tail/tail-outline-spade.json", "tail"}, {"tail/tail-wavy-line.json", "head"}};
    for (int k = 0; k < 2; ++k) {
        int n;
        sp_vec2* xy = visitor_stroke(closed[k][0], 320, (sp_vec2){640, 400}, false, &n);
        ENSURE(!strcmp(fitted_curve(d, add_as(d, xy, n, closed[k][1])), "outline"));
        sp_dragon_clear(d);
        free(xy);
    }
    sp_dragon_destroy(d);
}

// The canvas distance between part i's two feet (its skeleton's two leaves)
// as fitted, in the part's own view; NAN when it has not two leaves.
static double feet_apart(const sp_dragon* d, int i)
{
    const sp_dragon_part* p = sp_dragon_part_get(d, i);
    const sp_rig* rig = &p->character->rig;
    int leaf[2], n = 0;
    for (int j = 0; j < rig->joint_count; ++j) {
        bool parent = false;
        for (int c = 0; c < rig->joint_count; ++c)
            parent = parent || rig->joints[c].parent == j;
        if (!parent && n < 2)
            leaf[n++] = j;
        else if (!parent)
            return NAN;
    }
    sp_rig_eval* ev = NULL;
    ENSURE(n == 2 && sp_rig_eval_create(rig, &ev, NULL) == SP_OK);
    sp_rig_eval_update(ev, p->params, false);
    const sp_mat4* w = sp_rig_eval_world(ev);
    double apart = sp_v2_len(sp_v2_sub(sp_camera_project(&p->view, sp_mat4_translation(&w[leaf[0]])),
                                       sp_camera_project(&p->view, sp_mat4_translation(&w[leaf[1]]))));
    sp_rig_eval_destroy(ev);
    return apart;
}

// A pair of legs drawn as one straight line (a young child's leg) is
// fitted with one leg's line (sp_rig_add_limb), the other leg standing
// beside it as drawn (dragon_limb_follow; it swung across: an X, an outside
// review): along the whole stroke, where the outline and the pair's
// peaked line both shrank to under half of it (an outside review: 40-45%
// of the line's length, every straight leg). The visitors' legs drawn as a
// peaked line (both feet on the ground) keep the pair's curves.
static void test_leg_drawn_as_one_line(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    int as_limb = 0, total = 0;
    double worst = 1, widest[2] = {0, 0}; // hind, front
    for (int k = 0; k < 8; ++k) {
        sp_dragon_clear(d);
        sp_dragon_result body = draw_part(d, db, "torso", 640, 380, 420, false, true);
        sp_vec2 blo, bhi;
        fitted_box(d, body.part, &blo, &bhi);
        bool front = k & 1;
        double len = k & 2 ? 240 : 120, slant = k & 4 ? 0.35 : 0.0; // radians from upright
        // From the belly down, with a little of a hand's wobble.
        sp_vec2 top = {blo.x + (front ? 0.7 : 0.3) * (bhi.x - blo.x), bhi.y - 0.08 * (bhi.y - blo.y)}, xy[40];
        for (int i = 0; i < 40; ++i) {
            double u = i / 39.0, w = 2.0 * sin(9.0 * u + k);
            xy[i] = (sp_vec2){top.x + u * len * sin(slant) + w, top.y + u * len * cos(slant)};
        }
        int i = add_as(d, xy, 40, front ? "front_legs" : "hind_legs");
        const char* curve = fitted_curve(d, i);
        double reach = fitted_reach(d, i, xy, 40, fmax(6.0, 0.06 * len));
        // The leg not drawn stands beside the drawn one, not across it (an X).
        double apart = feet_apart(d, i) / len;
        fprintf(stderr,
                "  %s legs, a line of %.0f px %s: fitted with its %s, %.0f%% of the line within 6%% of its length; feet %.2f of "
                "it apart\n",
                front ? "front" : "hind", len, slant > 0 ? "slanted" : "upright", curve, 100 * reach, apart);
        as_limb += !strcmp(curve, "limb");
        worst = fmin(worst, reach);
        widest[front] = fmax(widest[front], apart);
        ++total;
    }
    // The hind legs' thighs reach their bounds (the other's feet were
    // 0.44-0.52 of the line apart, now 0.43-0.44); the front legs stand as one (0.31-0.45, now 0.01-0.07).
    // Drawn before the head that says the dragon faces left, the legs are
    // fitted again, turned: they still stand side by side (the second fit
    // crossed them again: an outside review).
    sp_dragon_clear(d);
    sp_dragon_result body = draw_part(d, db, "torso", 640, 380, 420, true, true);
    sp_vec2 blo, bhi, turned[40];
    fitted_box(d, body.part, &blo, &bhi);
    for (int i = 0; i < 40; ++i)
        turned[i] = (sp_vec2){blo.x + 0.3 * (bhi.x - blo.x), bhi.y - 0.08 * (bhi.y - blo.y) + 200.0 * i / 39};
    int legs = add_as(d, turned, 40, "front_legs");
    draw_part(d, db, "head", blo.x - 40, blo.y + 10, 220, true, true);
    const sp_dragon_part* lp = sp_dragon_part_get(d, legs);
    double turned_apart = feet_apart(d, legs) / 200;
    fprintf(stderr, "  front legs drawn before a head facing left: %s, %s, feet %.2f of the line apart\n",
            lp->mirrored ? "turned" : "not turned", fitted_curve(d, legs), turned_apart);
    widest[1] = fmax(widest[1], lp->mirrored ? turned_apart : INFINITY);
    fprintf(stderr, "  feet at most %.2f (hind legs), %.2f (front legs) of the line apart\n", widest[0], widest[1]);
    ENSURE(as_limb == total && worst >= 0.8 && widest[0] <= 0.47 && widest[1] <= 0.15);
    const char* peaked[] = {"front_legs/front-legs-open-line.json", "hind_legs/hind-legs-zigzag-line.json"};
    for (int k = 0; k < 2; ++k) {
        int n;
        sp_dragon_clear(d);
        sp_vec2* xy = visitor_stroke(peaked[k], 260, (sp_vec2){640, 400}, false, &n);
        const char* curve = fitted_curve(d, add_as(d, xy, n, k ? "hind_legs" : "front_legs"));
        fprintf(stderr, "  %s: fitted with its %s\n", peaked[k], curve);
        ENSURE(strcmp(curve, "limb"));
        free(xy);
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A shape drawn on a body is measured against the body as drawn, not only
// as fitted: a child's body with a fin the fit left out (an outside
// review's dolphin, its fit 0.56 of the drawing) made a wing drawn on its
// back "about as large" as the body, and a second body. Here the body's
// drawing is made 1.6 times its fit (the stroke box, as such a drawing
// leaves it), and a smaller body drawing goes on its back: 0.85 of the
// fit's size, 0.53 of the drawing's.
static void test_on_body_as_drawn(void)
{
    const char* path = real_db();
    sp_dragon* d = new_dragon(path);
    int n, m;
    sp_vec2* body = visitor_stroke("torso/torso-pear.json", 360, (sp_vec2){560, 420}, false, &n);
    int b = add_as(d, body, n, "torso");
    sp_vec2 flo, fhi;
    fitted_box(d, b, &flo, &fhi);
    double fit_diag = sp_v2_len(sp_v2_sub(fhi, flo));
    sp_vec2* small =
        visitor_stroke("torso/torso-humped.json", 0.85 * fit_diag, (sp_vec2){0.5 * (flo.x + fhi.x), flo.y + 10}, false, &m);
    sp_error err = {0};
    sp_dragon_result res;
    char became[2][SP_NAME_MAX];
    for (int drawn = 0; drawn < 2; ++drawn) {
        double* box = d->parts[b]->stroke_box;
        double cx = 0.5 * (flo.x + fhi.x), cy = 0.5 * (flo.y + fhi.y), k = drawn ? 0.8 : 0.5;
        box[0] = cx - k * (fhi.x - flo.x), box[1] = cy - k * (fhi.y - flo.y);
        box[2] = cx + k * (fhi.x - flo.x), box[3] = cy + k * (fhi.y - flo.y);
        ENSURE(sp_dragon_add_points(d, small, m, NULL, &res, &err) == SP_OK);
        snprintf(became[drawn], sizeof became[drawn], "%s", res.rejected ? "refused" : sp_dragon_part_get(d, res.part)->category);
        fprintf(stderr, "  a body drawing %.0f px on the back of a body fitted %.0f px, drawn %.0f: %s\n", 0.85 * fit_diag,
                fit_diag, 2 * k * fit_diag, became[drawn]);
        if (!res.rejected) ENSURE(sp_dragon_undo(d));
    }
    ENSURE(!strcmp(became[0], "torso") && strcmp(became[1], "torso") != 0);
    free(body), free(small);
    sp_dragon_destroy(d);
}

// Legs and wings face the way their dragon does (docs/DESIGN.md, "The kiosk
// pipeline"): a dragon of visitors' drawings (tune half) drawn facing left
// (mirrored, its head at the left end of the body) gets its legs and wings
// fitted mirrored too; drawn before the head, they turn when it comes, and
// Undo of the head gives their former fits back. Facing right, nothing is
// mirrored. The README's picture of it holds.
static void test_facing_follows_dragon(void)
{
    const char* path = real_db();
    sp_dragon* d = new_dragon(path);
    const char* rel[] = {"torso/torso-humped.json", "head/head-open-jaw-teeth.json", "front_legs/front-legs-boots.json",
                         "hind_legs/hind-legs-boots.json", "wings/wing-2-scallops-drooping.json"};
    const char* category[] = {"torso", "head", "front_legs", "hind_legs", "wings"};
    const double cx[] = {640, 900, 740, 520, 620}, cy[] = {400, 280, 590, 590, 240}, diag[] = {420, 200, 190, 190, 240};
    for (int left = 0; left < 2; ++left)
        for (int head_last = 0; head_last < 2; ++head_last) {
            sp_dragon_clear(d);
            const int order[2][5] = {{0, 1, 2, 3, 4}, {0, 2, 3, 4, 1}};
            for (int j = 0; j < 5; ++j) {
                int k = order[head_last][j], n;
                sp_vec2* xy = visitor_stroke(rel[k], diag[k], (sp_vec2){left ? 1280 - cx[k] : cx[k], cy[k]}, left, &n);
                add_as(d, xy, n, category[k]);
                free(xy);
            }
            for (int i = 1; i < 5; ++i) {
                const sp_dragon_part* p = sp_dragon_part_get(d, i);
                fprintf(stderr, "  facing %s, head %s: %s attached to %d, mirrored %d\n", left ? "left" : "right",
                        head_last ? "last" : "second", p->category, p->attached_to, p->mirrored);
                ENSURE(p->attached_to == 0 && p->mirrored == (left != 0));
            }
            if (head_last) {
                ENSURE(sp_dragon_undo(d));
                for (int i = 1; i < 4; ++i)
                    ENSURE(!sp_dragon_part_get(d, i)->mirrored);
            }
        }
    // The README's picture (docs/img/kiosk_facing_left.json), each stroke
    // the part the kiosk makes it on the default database (this test's
    // quick database classifies otherwise): every part faces left and joins
    // the body, and the wavy-line tail is fitted with its line.
    sp_dragon_clear(d);
    char file[1200];
    snprintf(file, sizeof file, "%s/docs/img/kiosk_facing_left.json", SP_SOURCE_DIR);
    sp_vec2* xy[8];
    int n[8], count = sp_fixture_session_strokes(file, xy, n, 8);
    const char* want[] = {"torso", "front_legs", "hind_legs", "wings", "head", "tail"};
    ENSURE(count == 6);
    for (int k = 0; k < count; ++k) {
        add_as(d, xy[k], n[k], want[k]);
        free(xy[k]);
    }
    for (int i = 0; i < 6; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        fprintf(stderr, "  README picture: %s, attached to %d, mirrored %d, fitted with its %s\n", p->category, p->attached_to,
                p->mirrored, fitted_curve(d, i));
        ENSURE(!strcmp(p->category, want[i]) && (i == 0 || (p->attached_to == 0 && p->mirrored)));
    }
    ENSURE(!strcmp(fitted_curve(d, 5), "line"));
    sp_dragon_destroy(d);
}

// A head drawn before the body faces as it would drawn after it: each of
// the visitors' heads (tune half) at the body's front top corner, the
// dragon facing right and left, drawn after the body, then before it.
static void test_head_first_faces_as_after(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    char dir[1200];
    snprintf(dir, sizeof dir, "%s/tests/data/visitors/tune/head", SP_BINARY_DIR);
    struct dirent** names = NULL;
    int nn = scandir(dir, &names, NULL, alphasort), compared = 0;
    for (int f = 0; f < nn; ++f) {
        const char* name = names[f]->d_name;
        size_t len = strlen(name);
        if (len > 5 && !strcmp(name + len - 5, ".json"))
            for (int left = 0; left < 2; ++left) {
                char rel[300];
                snprintf(rel, sizeof rel, "head/%s", name);
                bool facing[2];
                for (int first = 0; first < 2; ++first) {
                    sp_dragon_clear(d);
                    sp_dragon_result body = draw_part(d, db, "torso", 640, 420, 420, left, true);
                    sp_vec2 blo, bhi;
                    fitted_box(d, body.part, &blo, &bhi);
                    int n;
                    sp_vec2* xy = visitor_stroke(rel, 200, (sp_vec2){left ? blo.x + 20 : bhi.x - 20, blo.y + 20}, left, &n);
                    if (first) sp_dragon_clear(d);
                    add_as(d, xy, n, "head");
                    if (first) draw_part(d, db, "torso", 640, 420, 420, left, true);
                    free(xy);
                    const sp_dragon_part* h = sp_dragon_part_get(d, first ? 0 : 1);
                    ENSURE(!strcmp(h->category, "head"));
                    facing[first] = h->mirrored;
                }
                fprintf(stderr, "  %s, dragon facing %s: mirrored %d drawn after the body, %d before\n", name,
                        left ? "left" : "right", facing[0], facing[1]);
                ENSURE(facing[0] == facing[1]);
                ++compared;
            }
        free(names[f]);
    }
    free(names);
    ENSURE(compared >= 14);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A visitor's doodle (tune half) drawn at the canvas's centre: refused as
// unrecognised, with guesses for the chips. Returns its points, which the
// caller frees, for the caller's further checks.
static sp_vec2* refused_doodle(sp_dragon* d, const char* rel, sp_dragon_result* res, int* n)
{
    sp_error err = {0};
    sp_vec2* xy = visitor_stroke(rel, 320, (sp_vec2){640, 400}, false, n);
    ENSURE(sp_dragon_add_points(d, xy, *n, NULL, res, &err) == SP_OK);
    fprintf(stderr, "  %s: %s, first guess %s\n", rel, res->rejected ? "refused" : "accepted",
            res->guess_count ? res->guesses[0].category : "-");
    ENSURE(res->rejected && res->reason == SP_DRAGON_UNRECOGNISED && res->guess_count > 0);
    return xy;
}

// The refusal's mirror evidence (docs/DESIGN.md, "Refusal policy"): a
// visitor's tree (tune half), its own mirror image about an upright line and
// taken for a part drawn in profile, is refused, and turned a quarter is not;
// the sun, as symmetric, is refused; a neat pair of legs and a humped body,
// as symmetric, stay parts.
static void test_mirror_refusal(void)
{
    // The tree is taken for a head by the recipe without the hand-placed
    // designs; with them, for legs (the mirror then has nothing to say).
    // Without the people's strokes too it is taken for a part and accepted:
    // no database the recipe makes without the data pins the case.
    if (!people_strokes_present()) SKIP("../shared/data/quickdraw absent: the tree's refusal needs the people's strokes");
    const char* path = real_db_ex(false);
    sp_dragon* d = new_dragon(path);
    sp_error err = {0};
    const char* doodles[] = {"not_a_part/tree.json", "not_a_part/sun.json"};
    for (int k = 0; k < 2; ++k) {
        int n;
        sp_dragon_result res;
        sp_vec2* xy = refused_doodle(d, doodles[k], &res, &n);
        if (k == 0) {
            // Taken for a part drawn in profile (the mirror weighs only
            // there); the sun's first guess moves with the recipe's draw,
            // and its rays' turn symmetry refuses it whatever it is taken for.
            ENSURE(strcmp(res.guesses[0].category, "torso") != 0 && !strstr(res.guesses[0].category, "legs"));
            // The tree turned a quarter about its centre is no longer
            // symmetric about an upright line, and the rest of the evidence
            // takes it for a part: the mirror is what refuses it.
            for (int i = 0; i < n; ++i)
                xy[i] = (sp_vec2){640 - (xy[i].y - 400), 400 + (xy[i].x - 640)};
            ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
        }
        free(xy);
        sp_dragon_clear(d);
    }
    // As symmetric, and parts: a pair of legs as one outline, a body with two humps.
    sp_vec2 legs[] = {{540, 300}, {540, 520}, {580, 520}, {580, 380}, {700, 380}, {700, 520}, {740, 520}, {740, 300}, {540, 300}};
    sp_vec2 xy[81];
    ENSURE(sp_curve_resample(legs, 9, false, 81, xy) == SP_OK);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, 81, NULL, &res, &err) == SP_OK && !res.rejected);
    ENSURE(strstr(sp_dragon_part_get(d, res.part)->category, "legs"));
    sp_vec2 body[81];
    for (int i = 0; i <= 80; ++i) {
        double t = 2 * M_PI * i / 80, x = cos(t), y = 0.5 * sin(t);
        if (y < 0) y -= 0.3 * (exp(-pow((x - 0.4) / 0.25, 2)) + exp(-pow((x + 0.4) / 0.25, 2)));
        body[i] = (sp_vec2){640 + 200 * x, 400 + 200 * y};
    }
    ENSURE(sp_dragon_add_points(d, body, 81, NULL, &res, &err) == SP_OK && !res.rejected);
    ENSURE(!strcmp(sp_dragon_part_get(d, res.part)->category, "torso"));
    sp_dragon_destroy(d);
}

// A drawing with the symmetry of a regular polygon or a star is refused
// whatever it is taken for (a triangle, a square, a house, a star), and only
// that symmetry refuses it: the same triangle stretched sideways, a round
// body with a wobble that repeats five times round and an oval body (each
// lands near itself at any turn) are parts.
static void test_polygon_refusal(void)
{
    const char* path = real_db();
    sp_dragon* d = new_dragon(path);
    sp_error err = {0};
    sp_dragon_result res;
    const char* doodles[] = {"not_a_part/triangle.json", "not_a_part/house.json"};
    for (int k = 0; k < 2; ++k) {
        int n;
        sp_vec2* xy = refused_doodle(d, doodles[k], &res, &n);
        if (k == 0) {
            for (int i = 0; i < n; ++i)
                xy[i].x = 640 + 1.6 * (xy[i].x - 640);
            ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
        }
        free(xy);
        sp_dragon_clear(d);
    }
    // Drawn here: a square and a five-pointed star, their outlines
    // resampled to 101 points.
    sp_vec2 square[] = {{500, 260}, {780, 260}, {780, 540}, {500, 540}, {500, 260}};
    sp_vec2 star[11];
    for (int i = 0; i <= 10; ++i) {
        double a = M_PI / 2 + M_PI * i / 5, r = i % 2 ? 0.4 * 150 : 150;
        star[i] = (sp_vec2){640 + r * cos(a), 400 - r * sin(a)};
    }
    const sp_vec2* polygons[] = {square, star};
    const int corners[] = {5, 11};
    for (int k = 0; k < 2; ++k) {
        sp_vec2 xy[101];
        ENSURE(sp_curve_resample(polygons[k], corners[k], false, 101, xy) == SP_OK);
        ENSURE(sp_dragon_add_points(d, xy, 101, NULL, &res, &err) == SP_OK);
        ENSURE(res.rejected && res.reason == SP_DRAGON_UNRECOGNISED);
        sp_dragon_clear(d);
    }
    for (int k = 0; k < 2; ++k) {
        sp_vec2 body[81];
        for (int i = 0; i <= 80; ++i) {
            double t = 2 * M_PI * i / 80, r = k == 0 ? 1 + 0.04 * sin(5 * t) : 1;
            body[i] = (sp_vec2){640 + 200 * r * cos(t), 400 + 200 * r * (k == 0 ? 1 : 0.82) * sin(t)};
        }
        ENSURE(sp_dragon_add_points(d, body, 81, NULL, &res, &err) == SP_OK && !res.rejected);
        fprintf(stderr, "  %s body: %s\n", k == 0 ? "round" : "oval", sp_dragon_part_get(d, res.part)->category);
        sp_dragon_clear(d);
    }
    sp_dragon_destroy(d);
}

// A part removed until the next db train: the model still ranks its
// category first for drawings of it. The stroke becomes the best guess
// that has a part, as if the removed one had not been guessed; it was
// refused for having no part, which the kiosk showed as "not ready".
static void test_guess_without_part(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("dragon_no_head.db"));
    copy_file(real_db(), path);
    sp_db* w = NULL;
    sp_error err = {0};
    ENSURE(sp_db_open(path, 0, &w, &err) == SP_OK && sp_db_remove_part(w, "head", "test", &err) == SP_OK);
    sp_db_close(w);
    sp_dragon* d = new_dragon(path);
    ENSURE(!sp_dragon_has_part(d, "head") && sp_dragon_has_part(d, "wings"));
    int n;
    sp_vec2* xy = visitor_stroke("head/head-open-jaw-teeth.json", 230, (sp_vec2){640, 400}, false, &n);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  a head with no head part: %s %s, guesses", res.rejected ? "refused" : "accepted",
            res.rejected ? sp_dragon_reject_name(res.reason) : sp_dragon_part_get(d, res.part)->category);
    for (int g = 0; g < res.guess_count; ++g)
        fprintf(stderr, " %s %.2f", res.guesses[g].category, res.guesses[g].confidence);
    fprintf(stderr, "\n");
    bool head_first = false; // the model, not trained again, still takes it for a head
    for (int g = 0; g < res.guess_count; ++g)
        head_first = head_first || (!strcmp(res.guesses[g].category, "head") && res.guesses[g].confidence > 0.5f);
    ENSURE(head_first);
    ENSURE(res.reason != SP_DRAGON_NO_PART && !res.rejected && strcmp(sp_dragon_part_get(d, res.part)->category, "head"));
    free(xy);
    sp_dragon_destroy(d);
}

// Colouring in: a zigzag scribble over most of the body (an outside
// review's child) is kept as ink on it, offered as a detail; it was
// refused as a scribble and faded. The same scribble beside the dragon is
// still refused.
static void test_colouring_in(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    sp_dragon_result body = draw_part(d, db, "torso", 640, 440, 420, false, true), res;
    sp_vec2 blo, bhi;
    fitted_box(d, body.part, &blo, &bhi);
    for (int k = 0; k < 2; ++k) {
        // 12 strokes up and down across the body's middle, within its outline.
        sp_vec2 zig[25], xy[400];
        double x0 = blo.x + 0.2 * (bhi.x - blo.x), w = 0.6 * (bhi.x - blo.x), ym = 0.5 * (blo.y + bhi.y);
        double dy = k ? 700 - ym : 0; // k = 1: far below the dragon
        for (int i = 0; i < 25; ++i)
            zig[i] = (sp_vec2){x0 + w * i / 24, ym + dy + (i % 2 ? 0.18 : -0.18) * (bhi.y - blo.y)};
        ENSURE(sp_curve_resample(zig, 25, false, 400, xy) == SP_OK);
        int before = sp_dragon_detail_count(d);
        ENSURE(sp_dragon_add_points(d, xy, 400, NULL, &res, &err) == SP_OK && res.rejected);
        fprintf(stderr, "  a zigzag %s: %s, %d details\n", k ? "below the dragon" : "over the body",
                sp_dragon_reject_name(res.reason), sp_dragon_detail_count(d));
        if (k == 0)
            ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail >= 0 && sp_dragon_detail_count(d) == before + 1 &&
                   res.guess_count > 0);
        else
            ENSURE(res.reason == SP_DRAGON_UNRECOGNISED && sp_dragon_detail_count(d) == before);
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The refusal's symmetry rules are for shapes no dragon part has. A part
// that has them itself (a curator's star; a person seen from the front, an
// outline that is its own mirror image: an outside review's derived
// CesiumMan was refused when drawn as it is) is not held to them; the
// shipped parts are, as before: none has a polygon's symmetry, and the
// head, tail and wings are not their own mirror images.
static void test_own_symmetry(void)
{
    sp_dragon* d = new_dragon(real_db());
    const char* cats[6] = {"torso", "head", "wings", "tail", "front_legs", "hind_legs"};
    for (int k = 0; k < 6; ++k) {
        const tpl* t = dragon_category_first(d, cats[k]);
        ENSURE(t);
        fprintf(stderr, "  %s: its own mirror gap %.3f, polygonal %d\n", cats[k], t->own_mirror_gap, t->own_polygonal);
        ENSURE(!t->own_polygonal && (k < 1 || k > 3 || t->own_mirror_gap >= 0.08));
    }
    sp_dragon_destroy(d);
    // A post, upright and straight, among the test parts: its own mirror
    // image. Drawn as it is, it is a post, not refused.
    const test_part_spec post = {"post_t", "post", 3,   0.6, M_PI / 2,           0.0,
                                 0.16,     0.16,   1.0, 0.2, {0.6f, 0.5f, 0.3f}, "{\"category\": \"post\"}"};
    char path[1024];
    snprintf(path, sizeof path, "%s", sp_test_tmp_path("dragon_post.db"));
    make_test_db(path, &post);
    sp_db* db = NULL;
    sp_error err = {0};
    d = dragon_and_db(path, &db);
    const tpl* t = dragon_category_first(d, "post");
    ENSURE(t && t->own_mirror_gap < 0.08 && !t->own_polygonal);
    sp_vec2* xy;
    int n = part_stroke(db, "post_t", 3, 0.0, 640, 400, 360, &xy);
    sp_dragon_result res;
    ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  the post drawn as it is (mirror gap %.3f): %s, first guess %s, far score %.2f\n", dragon_mirror_gap(xy, n),
            res.rejected ? sp_dragon_reject_name(res.reason) : "accepted", res.guess_count ? res.guesses[0].category : "-",
            res.far_score);
    // Its far score without the mirror term (which added 7 x (0.08 - its gap), 0.36, to 0.32).
    ENSURE(!res.rejected && !strcmp(sp_dragon_part_get(d, res.part)->category, "post") && res.far_score < 0.5);
    free(xy);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A slow, shaky hand: the visitors' drawings with a point every pixel and
// 1 px of touch noise (an outside review's child) become the part the
// steady drawing does. The noise doubled the stroke's length, which the
// scribble test refused, its first guess right.
static void test_shaky_hand(void)
{
    const char* path = real_db();
    sp_dragon* d = new_dragon(path);
    sp_error err = {0};
    const char* drawings[] = {"head/head-open-jaw-teeth.json", "front_legs/front-legs-boots.json",
                              "hind_legs/hind-legs-boots.json"};
    sp_rng rng = {11};
    for (int k = 0; k < 3; ++k) {
        int n;
        sp_vec2* xy = visitor_stroke(drawings[k], k == 0 ? 230 : 175, (sp_vec2){640, 400}, false, &n);
        sp_dragon_result steady, shaky;
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &steady, &err) == SP_OK && !steady.rejected);
        char category[64];
        snprintf(category, sizeof category, "%s", sp_dragon_part_get(d, steady.part)->category);
        sp_dragon_clear(d);
        int m = (int)sp_curve_length(xy, n, false);
        sp_vec2* slow = malloc(sizeof(sp_vec2) * (size_t)m);
        ENSURE(slow && sp_curve_resample(xy, n, false, m, slow) == SP_OK);
        for (int i = 0; i < m; ++i)
            slow[i].x += sp_rng_normal(&rng), slow[i].y += sp_rng_normal(&rng);
        ENSURE(sp_dragon_add_points(d, slow, m, NULL, &shaky, &err) == SP_OK);
        fprintf(stderr, "  %s: steady %s, shaky (%d points) %s\n", drawings[k], category, m,
                shaky.rejected ? sp_dragon_reject_name(shaky.reason) : sp_dragon_part_get(d, shaky.part)->category);
        ENSURE(!shaky.rejected && !strcmp(sp_dragon_part_get(d, shaky.part)->category, category));
        sp_dragon_clear(d);
        free(slow);
        free(xy);
    }
    sp_dragon_destroy(d);
}

// The distance from canvas point p to the nearest of part i's mesh vertices at its fit.
static double to_fitted_mesh(const sp_dragon* d, int i, sp_vec2 p)
{
    sp_vec2* px = fitted_px(d, i);
    double best = INFINITY;
    for (int v = 0; v < sp_dragon_part_get(d, i)->character->rig.vertex_count; ++v)
        best = fmin(best, sp_v2_len(sp_v2_sub(px[v], p)));
    free(px);
    return best;
}

// The distance from p to the polyline xy (n points, open).
static double to_polyline(const sp_vec2* xy, int n, sp_vec2 p)
{
    double best = n > 0 ? sp_v2_len(sp_v2_sub(xy[0], p)) : INFINITY;
    for (int k = 1; k < n; ++k) {
        sp_vec2 ab = sp_v2_sub(xy[k], xy[k - 1]);
        double l2 = sp_v2_dot(ab, ab), s = l2 > 0 ? fmin(1, fmax(0, sp_v2_dot(sp_v2_sub(p, xy[k - 1]), ab) / l2)) : 0;
        best = fmin(best, sp_v2_len(sp_v2_sub(p, sp_v2_add(xy[k - 1], sp_v2_scale(ab, s)))));
    }
    return best;
}

// Wings drawn a little above the back, beyond the tips of its spikes (an
// outside review's child): they go on the back, where the body's outline
// is, not on a spike's tip, hovering above it. Drawn on either side of the
// middle, facing either way; a head drawn above the front the same.
static void test_on_the_back_not_a_spike(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    for (int k = 0; k < 4; ++k) {
        bool mirrored = k & 1, head = k >= 2;
        sp_dragon_clear(d);
        sp_vec2* body_xy;
        int bn = category_stroke(db, "torso", 640, 440, 420, mirrored, &body_xy), n;
        sp_dragon_result body, res;
        ENSURE(sp_dragon_add_points(d, body_xy, bn, &(sp_dragon_stroke_opts){.category = "torso"}, &body, &err) == SP_OK &&
               !body.rejected);
        sp_vec2 blo, bhi, slo, shi;
        fitted_box(d, body.part, &blo, &bhi); // its mesh, the spikes' tips at the top
        double x = head ? (mirrored ? blo.x + 40 : bhi.x - 40) : 640 + (mirrored ? 30 : -30);
        sp_vec2* xy = visitor_stroke(head ? "head/head-blunt-round-ear.json" : "wings/wing-3-scallops-raised.json", 200,
                                     (sp_vec2){x, 0}, mirrored, &n);
        points_box(xy, n, &slo, &shi);
        for (int i = 0; i < n; ++i) // its lowest point 12 px above the spikes' tips
            xy[i].y += blo.y - 12 - shi.y;
        ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = head ? "head" : "wings"}, &res, &err) ==
                   SP_OK &&
               !res.rejected);
        const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
        double off = p->attached_to == body.part ? to_polyline(body_xy, bn, p->anchor) : INFINITY;
        fprintf(stderr, "  %s above the %s (facing %s): attached to %d, the anchor %.1f px from the body's stroke\n",
                head ? "a head" : "wings", head ? "front" : "back", mirrored ? "left" : "right", p->attached_to, off);
        // The spikes stand about 25 px above the back at this size; the
        // fitted outline lies within a few px of the stroke.
        ENSURE(p->attached_to == body.part && off < 8);
        free(xy);
        free(body_xy);
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A part drawn a little apart from a body (its stroke within the snap
// distance of the body's surface), whose fit puts its attachment end
// farther (a round head's neck fitted inside the drawing, on the side away
// from the body), is fitted again with that end where the stroke comes
// nearest the body: it attaches, its neck meeting the body's surface, its
// head still where it was drawn. Drawn farther apart it stays free, and a
// chip's choice reaches too (the README's tree taken for a head). A head
// drawn first reaches when the body comes; Undo of the body frees it again.
static void test_reaches_the_body(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    double snap = 0.06 * hypot(1280, 800);
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        for (int apart = 0; apart < 3; ++apart) {
            sp_dragon_clear(d);
            sp_dragon_result body = draw_part(d, db, "torso", 640, 440, 420, false, true), res;
            sp_vec2 blo, bhi, slo, shi;
            int n;
            fitted_box(d, body.part, &blo, &bhi);
            // 20 or 45 px beyond the body's front top corner (the visitors
            // bench's --gap), or 200 px: apart.
            double gap = apart == 0 ? 20 : apart == 1 ? 45 : 200;
            sp_vec2* xy = at_box_end("head/head-blunt-round-ear.json", 230, blo.y - 40, mirrored, blo, bhi, !mirrored, -gap, &n);
            points_box(xy, n, &slo, &shi);
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK &&
                   !res.rejected);
            const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
            double near = INFINITY; // how near the stroke comes to the body's mesh
            for (int k = 0; k < n; ++k)
                near = fmin(near, to_fitted_mesh(d, body.part, xy[k]));
            free(xy);
            sp_vec2 olo, ohi;
            fitted_box(d, res.part, &olo, &ohi);
            double diag = hypot(shi.x - slo.x, shi.y - slo.y),
                   off = sp_v2_len(sp_v2_sub(sp_v2_scale(sp_v2_add(olo, ohi), 0.5), sp_v2_scale(sp_v2_add(slo, shi), 0.5)));
            fprintf(stderr,
                    "  round head %.0f px beyond the body (facing %s): stroke %.0f px from the body, attached to %d, "
                    "its end %.0f px from the anchor, its fit's centre %.0f px from the stroke's, error %.1f px, pen-up to part "
                    "%.1f ms\n",
                    gap, mirrored ? "left" : "right", near, p->attached_to, sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)), off,
                    p->report.mean_error_px, res.ms_total);
            if (near > snap) { // drawn apart: free where drawn
                ENSURE(p->attached_to < 0);
                continue;
            }
            ENSURE(p->attached_to == body.part);
            ENSURE(sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)) < 0.25 * snap); // its end fitted at the body
            ENSURE(off < 0.25 * diag);                                            // the part fits its stroke where it was drawn
        }
        ENSURE(sp_dragon_undo(d));
    }
    // The head first, 20 or 45 px beyond where the body comes: the body
    // makes it reach, and Undo of the body gives its own fit back, free.
    for (int mirrored = 0; mirrored < 2; ++mirrored) { // 20 px facing right, 45 facing left
        double gap = mirrored ? 45 : 20;
        sp_dragon_clear(d);
        sp_dragon_result body = draw_part(d, db, "torso", 640, 440, 420, false, true), res;
        sp_vec2 blo, bhi;
        int n;
        fitted_box(d, body.part, &blo, &bhi);
        sp_dragon_clear(d);
        sp_vec2* xy = at_box_end("head/head-blunt-round-ear.json", 230, blo.y - 40, mirrored, blo, bhi, !mirrored, -gap, &n);
        ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK &&
               !res.rejected && res.part == 0);
        free(xy);
        const sp_dragon_part* p = sp_dragon_part_get(d, 0);
        int np = p->character->rig.param_count;
        double own[256];
        bool was_mirrored = p->mirrored;
        ENSURE(np <= 256 && p->attached_to < 0);
        memcpy(own, p->params, sizeof(double) * (size_t)np);
        body = draw_part(d, db, "torso", 640, 440, 420, false, true);
        p = sp_dragon_part_get(d, 0);
        fprintf(stderr,
                "  round head %.0f px beyond, then the body (facing %s): attached to %d, its end %.0f px from the anchor\n", gap,
                mirrored ? "left" : "right", p->attached_to, sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)));
        ENSURE(body.part == 1 && p->attached_to == 1);
        ENSURE(sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)) < 0.25 * snap);
        ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 1);
        p = sp_dragon_part_get(d, 0);
        ENSURE(p->attached_to < 0 && p->mirrored == was_mirrored && !memcmp(p->params, own, sizeof(double) * (size_t)np));
    }
    // The README's refused stroke (docs/img/kiosk_refused.json): a tree
    // drawn over the body's front, made a head with a chip (the kiosk adds
    // the refused stroke again with the chip's category).
    sp_dragon_clear(d);
    sp_dragon_result body = draw_part(d, db, "torso", 640, 440, 420, false, true), res;
    sp_vec2 blo, bhi;
    int n;
    fitted_box(d, body.part, &blo, &bhi);
    sp_vec2* xy = visitor_stroke("not_a_part/tree.json", 260, (sp_vec2){bhi.x - 60, blo.y - 110}, false, &n);
    ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK && !res.rejected);
    free(xy);
    const sp_dragon_part* p = sp_dragon_part_get(d, res.part);
    fprintf(stderr, "  the README's tree as a head: attached to %d, its end %.0f px from the anchor\n", p->attached_to,
            sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)));
    ENSURE(p->attached_to == body.part && sp_v2_len(sp_v2_sub(p->attach_end, p->anchor)) < 0.25 * snap);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Wings face the way their dragon does unless the other facing fits them
// twice as well: a child's wing leaning forward, drawn at the shoulders
// (an outside review), fitted leaning back shrank across the neck and was
// kept as ink on the head. Here the wings' own outline, mirrored, drawn on
// the back of a dragon facing right: fitted as drawn, and attached. The
// visitors' tune-half wings at a dragon keep their dragon's facing
// (visitors --on-body, line for line).
static void test_wing_leaning_forward(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    sp_dragon_result body = draw_part(d, db, "torso", 640, 440, 420, false, true);
    draw_part(d, db, "head", 900, 300, 200, false, true); // the dragon faces right
    for (int mirror = 0; mirror < 2; ++mirror) {
        sp_vec2* xy;
        int n = category_stroke(db, "wings", 620, 250, 200, mirror, &xy);
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "wings"}, &res, &err) == SP_OK &&
               !res.rejected);
        free(xy);
        const sp_dragon_part* w = sp_dragon_part_get(d, res.part);
        fprintf(stderr, "  wings drawn %s: fitted %s, attached to %d, error %.1f px\n",
                mirror ? "leaning forward" : "as modelled", w->mirrored ? "mirrored" : "as modelled", w->attached_to,
                w->report.mean_error_px);
        ENSURE(w->mirrored == (mirror != 0) && w->attached_to == body.part);
        ENSURE(sp_dragon_undo(d));
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A dragon of visitors' drawings (tune half), drawn facing right or left:
// `body` at (640, cy) at diagonal body_diag, then `head` at diagonal
// head_diag at the top corner of the body's box at its facing end, moved out
// by dx and down by dy; both forced.
typedef struct drawn_dragon {
    sp_dragon_result body, head;
    sp_vec2 lo, hi; // the body stroke's box
} drawn_dragon;

static drawn_dragon draw_body_and_head(sp_dragon* d, const char* body, double body_diag, double cy, const char* head,
                                       double head_diag, double dx, double dy, bool left)
{
    drawn_dragon g;
    sp_error err = {0};
    int bn, hn;
    sp_vec2* body_xy = visitor_stroke(body, body_diag, (sp_vec2){640, cy}, left, &bn);
    points_box(body_xy, bn, &g.lo, &g.hi);
    sp_vec2 at = {640 + (left ? -1 : 1) * (0.5 * (g.hi.x - g.lo.x) + dx), g.lo.y + dy};
    sp_vec2* head_xy = visitor_stroke(head, head_diag, at, left, &hn);
    ENSURE(sp_dragon_add_points(d, body_xy, bn, &(sp_dragon_stroke_opts){.category = "torso"}, &g.body, &err) == SP_OK &&
           !g.body.rejected);
    ENSURE(sp_dragon_add_points(d, head_xy, hn, &(sp_dragon_stroke_opts){.category = "head"}, &g.head, &err) == SP_OK &&
           !g.head.rejected);
    free(body_xy);
    free(head_xy);
    return g;
}

// A body drawn rising to one end (the visitors' "long rising" body) with a
// big head drawn at the top corner of its box over the low end, as the
// visitors bench places heads: its neck hangs on the back 45 px from the
// body's middle, so the dragon's facing is read from where the head is
// drawn, not from where it hangs (read from there, nothing was told, and
// the tune half's legs at such a dragon faced the wrong way).
static void test_facing_of_a_rising_body(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    for (int left = 0; left < 2; ++left) {
        sp_dragon_clear(d);
        drawn_dragon g =
            draw_body_and_head(d, "torso/torso-long-rising.json", 500, 400, "head/head-brow-ridge.json", 320, -20, -20, left);
        const sp_dragon_part* h = sp_dragon_part_get(d, g.head.part);
        int facing = dragon_facing_at(d, g.lo, g.hi);
        fprintf(stderr, "  facing %s: the head hangs on %d at x %.0f (the body %.0f-%.0f); the dragon reads facing %d\n",
                left ? "left" : "right", h->attached_to, h->anchor.x, g.lo.x, g.hi.x, facing);
        ENSURE(h->attached_to == g.body.part && facing == (left ? -1 : 1));
    }
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// The longest stroke of drawing `index` of Quick, Draw!'s `category`
// (../shared/data/quickdraw, read by sketchio's ndjson reader), fitted into
// the box [lo, hi] keeping its aspect, centred, mirrored left-right when
// asked, a point every 4 px at most; NULL when the file or drawing is not there.
static sp_vec2* quickdraw_stroke(const char* category, int index, sp_vec2 lo, sp_vec2 hi, bool mirror, int* n)
{
    char file[1200];
    snprintf(file, sizeof file, "%s/quickdraw/%s.ndjson", SP_SHARED_DATA, category);
    FILE* f = fopen(file, "r");
    if (!f) return NULL;
    static char line[1 << 16];
    bool got = false;
    for (int k = 0; k <= index && fgets(line, sizeof line, f); ++k)
        got = k == index;
    fclose(f);
    sp_dataset ds = {0};
    sp_error err = {0};
    if (!got || sp_dataset_parse_ndjson(&ds, line, strlen(line), file, -1, &err) != SP_OK || ds.count != 1) {
        sp_dataset_free(&ds);
        return NULL;
    }
    const sp_sketch* sk = &ds.samples[0].sketch;
    const sp_stroke* st = NULL;
    double best_len = -1;
    for (int i = 0; i < sk->stroke_count; ++i) {
        double len = sp_curve_length(sk->strokes[i].points, sk->strokes[i].count, false);
        if (len > best_len) best_len = len, st = &sk->strokes[i];
    }
    sp_vec2 p0, p1;
    points_box(st->points, st->count, &p0, &p1);
    double s = fmin((hi.x - lo.x) / fmax(p1.x - p0.x, 1), (hi.y - lo.y) / fmax(p1.y - p0.y, 1));
    sp_vec2 c = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y)};
    int cap = (int)(best_len * s / 4) + st->count + 1, k = 0;
    sp_vec2* out = malloc(sizeof(sp_vec2) * (size_t)cap);
    ENSURE(out);
    for (int i = 0; i < st->count; ++i) {
        sp_vec2 p = {c.x + (mirror ? -1 : 1) * (st->points[i].x - 0.5 * (p0.x + p1.x)) * s,
                     c.y + (st->points[i].y - 0.5 * (p0.y + p1.y)) * s};
        if (k > 0) { // a point every 4 px at most, as a finger gives them
            sp_vec2 q = out[k - 1];
            for (int t = 1, steps = (int)(sp_v2_len(sp_v2_sub(p, q)) / 4); t < steps && k < cap; ++t)
                out[k++] = sp_v2_add(q, sp_v2_scale(sp_v2_sub(p, q), (double)t / steps));
        }
        if (k < cap) out[k++] = p;
    }
    sp_dataset_free(&ds);
    *n = k;
    return out;
}

// An L-shaped leg (a child's: a line down, a foot at its end) is a leg
// whichever way its foot points: legs are fitted in their dragon's facing,
// and a foot pointing back fitted it at twice the error and was refused as
// far from every part (an outside review: Quick, Draw! feet 10 and 17,
// far_score 1.26 and 1.31, their mirror images accepted). Each drawn at
// the hind end of a dragon facing right and one facing left, as drawn and
// mirrored: the old code refused half of them. A Quick, Draw! hammer drawn
// there stays refused (a guard: in the review's own scene it was kept as
// legs until the rescue asked the classifier to be sure; here it is refused
// either way).
static void test_foot_either_way(void)
{
    if (!people_strokes_present()) SKIP("../shared/data/quickdraw absent");
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    int accepted = 0, total = 0, hammers_refused = 0;
    for (int left = 0; left < 2; ++left) {
        sp_dragon_clear(d);
        drawn_dragon g =
            draw_body_and_head(d, "torso/torso-humped.json", 420, 360, "head/head-brow-ridge.json", 220, 60, 0, left);
        sp_vec2 blo = g.lo, bhi = g.hi;
        sp_dragon_result res;
        double xc = left ? bhi.x - 0.3 * (bhi.x - blo.x) : blo.x + 0.3 * (bhi.x - blo.x);
        const int drawing[3] = {10, 17, 5};
        for (int k = 0; k < 6; ++k) {
            int n;
            const char* what = k < 4 ? "foot" : "hammer"; // a hammer, taken for legs at 0.67: not sure enough
            sp_vec2* xy = quickdraw_stroke(what, drawing[k / 2], (sp_vec2){xc - 50, bhi.y - 20}, (sp_vec2){xc + 50, bhi.y + 160},
                                           k % 2, &n);
            ENSURE(xy);
            ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
            const char* cat = res.rejected ? "refused" : sp_dragon_part_get(d, res.part)->category;
            fprintf(stderr, "  dragon facing %s, %s %d%s: %s (far %.2f)\n", left ? "left" : "right", what, drawing[k / 2],
                    k % 2 ? " mirrored" : "", cat, res.far_score);
            hammers_refused += k >= 4 && res.rejected;
            accepted += k < 4 && !res.rejected && strstr(cat, "legs");
            total += k < 4;
            if (!res.rejected) sp_dragon_undo(d);
            free(xy);
        }
    }
    fprintf(stderr, "  hammers refused: %d of 4\n", hammers_refused);
    ENSURE(accepted == total && hammers_refused == 4);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A bigger body drawn round a small dragon (an outside review's "my dragon
// is too small"): the small body carries a head and legs, so it is not
// decided again as a part lying on the new body (it became a head smeared
// over the big body's flank); drawn alone, a body on the new one still is.
static void test_body_round_a_dragon(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    sp_dragon_result small = draw_part(d, db, "torso", 640, 440, 300, false, false);
    ENSURE(small.part == 0 && sp_dragon_part_get(d, 0)->is_torso);
    draw_part(d, db, "head", 820, 340, 160, false, true);
    draw_part(d, db, "front_legs", 700, 520, 130, false, true);
    int carried = 0;
    for (int i = 1; i < sp_dragon_part_count(d); ++i)
        carried += sp_dragon_part_get(d, i)->attached_to == 0;
    ENSURE(carried == 2);
    sp_dragon_result big = draw_part(d, db, "torso", 640, 440, 620, false, false);
    fprintf(stderr, "  a small dragon, then a body twice its size round it: the small body is a %s, the new one a %s\n",
            sp_dragon_part_get(d, 0)->category, sp_dragon_part_get(d, big.part)->category);
    ENSURE(sp_dragon_part_get(d, 0)->is_torso && sp_dragon_part_get(d, big.part)->is_torso);
    // The small body alone (nothing on it), then the big one: decided again as before.
    sp_dragon_clear(d);
    draw_part(d, db, "torso", 640, 440, 300, false, false);
    draw_part(d, db, "torso", 640, 440, 620, false, false);
    fprintf(stderr, "  the small body alone, then the big one: the small one is a %s\n", sp_dragon_part_get(d, 0)->category);
    ENSURE(!sp_dragon_part_get(d, 0)->is_torso);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Parts drawn before the body end as if drawn after it, keeping their ids:
// the same tails turn to face away from the body and attach; a round head
// that alone is a body becomes the head; legs become the legs of their end
// (also when the head comes after them). Undo of the body (or the head), or
// a chip that makes the body another part, gives the former fits back.
static void test_parts_before_body(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    int turned = 0, near_attached = 0;
    for (int k = 0; k < 8; ++k)
        for (int right = 0; right < 2; ++right) {
            sp_dragon_result res, body;
            int n;
            // Out of the body's end, then 30 px beyond it (near enough to attach).
            sp_vec2* xy = tail_out_of_body(d, db, k_end_tails[k % 4], right, k < 4 ? 30 : -30, &body, &n);
            sp_dragon_clear(d); // the tail first, the body after it
            ENSURE(sp_dragon_add_points(d, xy, n, &(sp_dragon_stroke_opts){.category = "tail"}, &res, &err) == SP_OK &&
                   !res.rejected && res.part == 0);
            free(xy);
            const sp_dragon_part* t = sp_dragon_part_get(d, 0);
            uint64_t id = t->id;
            bool was_mirrored = t->mirrored;
            int np = t->character->rig.param_count;
            double before[256];
            ENSURE(np <= 256);
            memcpy(before, t->params, sizeof(double) * (size_t)np);
            body = draw_part(d, db, "torso", 640, 420, 420, false, true);
            t = sp_dragon_part_get(d, 0);
            fprintf(stderr, "  %s, then the body, %s its %s end: mirrored %d -> %d, attached to %d\n", k_end_tails[k % 4],
                    k < 4 ? "out of" : "30 px beyond", right ? "right" : "left", was_mirrored, t->mirrored, t->attached_to);
            ENSURE(body.part == 1 && t->id == id && !strcmp(t->category, "tail"));
            ENSURE(t->mirrored == (right != 0)); // facing away from the body
            ENSURE(t->attached_to == 1); // also beyond the end (test_root_at_the_body)
            near_attached += k >= 4 && t->attached_to == 1;
            turned += was_mirrored != t->mirrored;
            // Undo of the body: the tail's own fit again, free.
            ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 1);
            t = sp_dragon_part_get(d, 0);
            ENSURE(t->id == id && t->mirrored == was_mirrored && t->attached_to == -1);
            ENSURE(!memcmp(t->params, before, sizeof(double) * (size_t)np));
            // The body again, then a chip makes it a head: the tail's own fit again.
            body = draw_part(d, db, "torso", 640, 420, 420, false, true);
            ENSURE(sp_dragon_part_get(d, 0)->mirrored == (right != 0));
            ENSURE(sp_dragon_refit_last(d, "head", &res, &err) == SP_OK && !res.rejected && res.part == 1);
            t = sp_dragon_part_get(d, 0);
            ENSURE(t->mirrored == was_mirrored && !memcmp(t->params, before, sizeof(double) * (size_t)np));
            ENSURE(sp_dragon_pose_at(d, 0.25, &err) == SP_OK);
        }
    // The premise: drawn alone, most of these tails face the other way.
    fprintf(stderr, "  turned by the body drawn after them: %d of 16; beyond the end, %d of 8 attached\n", turned, near_attached);
    ENSURE(turned >= 8 && near_attached == 8);
    // A visitor's closed head, which alone is a body (test_drawn_on_body),
    // drawn first over where the body's front top corner will be: when the
    // body comes it is the head it is when drawn after the body.
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        sp_dragon_result res, after;
        int n;
        sp_vec2* xy = visitor_stroke("head/head-blunt-round-ear.json", 180, (sp_vec2){mirrored ? 470 : 810, 300}, mirrored, &n);
        sp_dragon_clear(d);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &after, &err) == SP_OK && !after.rejected);
        const sp_dragon_part* want = sp_dragon_part_get(d, 1);
        ENSURE(!strcmp(want->category, "head") && want->attached_to == 0);
        int np = want->character->rig.param_count;
        double want_p[256];
        ENSURE(np <= 256);
        memcpy(want_p, want->params, sizeof(double) * (size_t)np);
        bool want_mirrored = want->mirrored;
        sp_dragon_clear(d);
        ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK && !res.rejected);
        ENSURE(sp_dragon_part_get(d, 0)->is_torso); // the premise
        uint64_t id = sp_dragon_part_get(d, 0)->id;
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        const sp_dragon_part* h = sp_dragon_part_get(d, 0);
        fprintf(stderr, "  round head, then the body (facing %s): %s, attached to %d\n", mirrored ? "left" : "right", h->category,
                h->attached_to);
        ENSURE(h->id == id && !strcmp(h->category, "head") && h->attached_to == 1 && h->mirrored == want_mirrored);
        ENSURE(!memcmp(h->params, want_p, sizeof(double) * (size_t)np));
        // Undo of the body: a body again.
        ENSURE(sp_dragon_undo(d) && sp_dragon_part_get(d, 0)->is_torso && sp_dragon_part_get(d, 0)->id == id);
        // A body chosen with a chip stays one: a second dragon.
        ENSURE(sp_dragon_refit_last(d, "torso", &res, &err) == SP_OK && !res.rejected);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        ENSURE(sp_dragon_part_get(d, 0)->is_torso);
        free(xy);
    }
    // Legs drawn before the body (after the head): the legs of their end,
    // as when drawn after it; legs chosen with a chip stay what they are.
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        double rear = mirrored ? 760 : 520, head = mirrored ? 380 : 900;
        sp_dragon_clear(d);
        draw_part(d, db, "head", head, 300, 200, mirrored, true);
        sp_dragon_result res = draw_part(d, db, "front_legs", rear, 570, 190, mirrored, false);
        ENSURE(res.part == 1 && !strcmp(sp_dragon_part_get(d, 1)->category, "front_legs")); // no body: what they look like
        uint64_t id = sp_dragon_part_get(d, 1)->id;
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        const sp_dragon_part* legs = sp_dragon_part_get(d, 1);
        fprintf(stderr, "  front legs drawn at the rear, then the body (facing %s): %s, attached to %d\n",
                mirrored ? "left" : "right", legs->category, legs->attached_to);
        ENSURE(!strcmp(legs->category, "hind_legs") && legs->attached_to == 2 && legs->id == id);
        ENSURE(sp_dragon_part_get(d, 0)->attached_to == 2); // the head, which tells the facing
        ENSURE(sp_dragon_undo(d) && !strcmp(sp_dragon_part_get(d, 1)->category, "front_legs"));
        ENSURE(sp_dragon_undo(d)); // the legs, drawn again and chosen with a chip
        res = draw_part(d, db, "front_legs", rear, 570, 190, mirrored, false);
        ENSURE(sp_dragon_refit_last(d, "front_legs", &res, &err) == SP_OK && !res.rejected);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        ENSURE(!strcmp(sp_dragon_part_get(d, 1)->category, "front_legs"));
    }
    // Legs drawn on the body before its head: when the head comes and tells
    // the facing, they are the legs of their end; Undo of the head gives
    // them back.
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        double rear = mirrored ? 760 : 520, head = mirrored ? 380 : 900;
        sp_dragon_clear(d);
        draw_part(d, db, "torso", 640, 420, 420, false, true);
        draw_part(d, db, "front_legs", rear, 570, 190, mirrored, false);
        uint64_t id = sp_dragon_part_get(d, 1)->id;
        ENSURE(!strcmp(sp_dragon_part_get(d, 1)->category, "front_legs")); // no facing yet
        draw_part(d, db, "head", head, 300, 200, mirrored, true);
        ENSURE(sp_dragon_part_get(d, 2)->attached_to == 0);
        const sp_dragon_part* legs = sp_dragon_part_get(d, 1);
        fprintf(stderr, "  front legs drawn at the rear, then the head (facing %s): %s\n", mirrored ? "left" : "right",
                legs->category);
        ENSURE(!strcmp(legs->category, "hind_legs") && legs->attached_to == 0 && legs->id == id);
        ENSURE(sp_dragon_undo(d) && !strcmp(sp_dragon_part_get(d, 1)->category, "front_legs"));
    }
    // The README's session with the tail drawn first: the same dragon.
    sp_vec2* xy[8];
    int n[8], strokes = readme_session(xy, n, 8);
    ENSURE(strokes == 4);
    static const int orders[2][4] = {{0, 1, 2, 3}, {2, 0, 1, 3}};
    sp_dragon* same[2] = {d, new_dragon(path)};
    for (int o = 0; o < 2; ++o) {
        sp_dragon_clear(same[o]);
        for (int k = 0; k < 4; ++k) {
            sp_dragon_result res;
            ENSURE(sp_dragon_add_points(same[o], xy[orders[o][k]], n[orders[o][k]], NULL, &res, &err) == SP_OK && !res.rejected);
        }
    }
    for (int k = 0; k < 4; ++k) { // stroke k of the session is part k, then part orders[1]^-1(k)
        int j = k == 2 ? 0 : k < 2 ? k + 1 : 3;
        const sp_dragon_part *a = sp_dragon_part_get(same[0], k), *b = sp_dragon_part_get(same[1], j);
        int aa = a->attached_to, ba = b->attached_to < 0 ? -1 : orders[1][b->attached_to];
        fprintf(stderr, "  README session, stroke %d: %s (attached to stroke %d); tail first: %s (%d)\n", k + 1, a->category,
                aa + 1, b->category, ba + 1);
        ENSURE(!strcmp(a->category, b->category) && aa == ba && a->mirrored == b->mirrored);
        ENSURE(!memcmp(a->params, b->params, sizeof(double) * (size_t)a->character->rig.param_count));
    }
    for (int k = 0; k < 4; ++k)
        free(xy[k]);
    sp_dragon_destroy(same[1]);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// Whether every point of a circle of radius r about c (and c) lies in part
// i's projected mesh as posed at t = 0 (attached, as the visitor sees it).
static bool disc_on_part(const sp_dragon* d, int i, sp_vec2 c, double r)
{
    const sp_rig* rig = &sp_dragon_part_get(d, i)->character->rig;
    const double* xyz = sp_dragon_part_xyz(d, i);
    sp_camera cam = sp_dragon_camera(d);
    for (int k = 0; k <= 12; ++k) {
        sp_vec2 x = k == 12 ? c : (sp_vec2){c.x + r * cos(k * M_PI / 6), c.y + r * sin(k * M_PI / 6)};
        bool in = false;
        for (int f = 0; f < rig->triangle_count && !in; ++f) {
            sp_vec2 v[3];
            for (int e = 0; e < 3; ++e) {
                const double* w = xyz + 3 * rig->triangles[3 * f + e];
                v[e] = sp_camera_project(&cam, (sp_vec3){w[0], w[1], w[2]});
            }
            double d1 = (v[1].x - v[0].x) * (x.y - v[0].y) - (v[1].y - v[0].y) * (x.x - v[0].x);
            double d2 = (v[2].x - v[1].x) * (x.y - v[1].y) - (v[2].y - v[1].y) * (x.x - v[1].x);
            double d3 = (v[0].x - v[2].x) * (x.y - v[2].y) - (v[0].y - v[2].y) * (x.x - v[2].x);
            in = (d1 >= 0 && d2 >= 0 && d3 >= 0) || (d1 <= 0 && d2 <= 0 && d3 <= 0);
        }
        if (!in) return false;
    }
    return true;
}

// A point of part i where a disc of radius 2r lies on it and one of radius
// 3r + 10 not on part `not_on` (-1: none), searched on a grid over its box
// from the middle out (false: none found).
static bool spot_on_part(sp_dragon* d, int i, double r, int not_on, sp_vec2* out)
{
    sp_error err = {0};
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    sp_vec2 lo, hi;
    const sp_rig* rig = &sp_dragon_part_get(d, i)->character->rig;
    const double* xyz = sp_dragon_part_xyz(d, i);
    sp_camera cam = sp_dragon_camera(d);
    lo = hi = sp_camera_project(&cam, (sp_vec3){xyz[0], xyz[1], xyz[2]});
    for (int v = 1; v < rig->vertex_count; ++v) {
        sp_vec2 x = sp_camera_project(&cam, (sp_vec3){xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]});
        lo.x = fmin(lo.x, x.x), lo.y = fmin(lo.y, x.y), hi.x = fmax(hi.x, x.x), hi.y = fmax(hi.y, x.y);
    }
    for (int ring = 0; ring <= 8; ++ring)
        for (int gx = -ring; gx <= ring; ++gx)
            for (int gy = -ring; gy <= ring; ++gy) {
                if (abs(gx) != ring && abs(gy) != ring) continue;
                sp_vec2 c = {0.5 * (lo.x + hi.x) + gx * (hi.x - lo.x) / 18, 0.5 * (lo.y + hi.y) + gy * (hi.y - lo.y) / 18};
                if (disc_on_part(d, i, c, 2 * r) && (not_on < 0 || !disc_on_part(d, not_on, c, 3 * r + 10))) {
                    *out = c;
                    return true;
                }
            }
    return false;
}

// A small wobbly loop (an eye, a spot) of radius r about c; 40 points.
static void small_loop(sp_vec2 c, double r, sp_vec2 xy[40])
{
    for (int k = 0; k < 40; ++k) {
        double a = 2 * M_PI * k / 37.0; // a little overshoot, as drawn
        xy[k] = (sp_vec2){c.x + r * (1 + 0.08 * sin(3 * a)) * cos(a), c.y + 0.9 * r * sin(a)};
    }
}

// Whether a dark pixel (every channel low, as ink, not a part's colour) lies
// within r px of p (canvas pixels) in the picture.
static bool dark_near(const sp_image* img, sp_vec2 p, int r)
{
    int x = (int)lround(p.x), y = (int)lround(p.y);
    bool found = false;
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            if (x + dx < 0 || y + dy < 0 || x + dx >= img->width || y + dy >= img->height) continue;
            const uint8_t* px = img->rgba + 4 * ((size_t)(y + dy) * (size_t)img->width + (size_t)(x + dx));
            found |= px[0] < 70 && px[1] < 70 && px[2] < 70;
        }
    return found;
}

// Ink point k of detail i on the canvas at the last pose_at.
static sp_vec2 ink_px(const sp_dragon* d, int i, int k)
{
    sp_dragon_detail e;
    sp_camera cam = sp_dragon_camera(d);
    ENSURE(sp_dragon_detail_get(d, i, &e) && e.xyz);
    return sp_camera_project(&cam, (sp_vec3){e.xyz[3 * k], e.xyz[3 * k + 1], e.xyz[3 * k + 2]});
}

// The vertex of part p nearest world point x at the last pose_at.
static int nearest_vertex(const sp_dragon* d, int p, const double* x)
{
    const double* v = sp_dragon_part_xyz(d, p);
    int nv = sp_dragon_part_get(d, p)->character->rig.vertex_count, best = -1;
    double bd = INFINITY;
    for (int k = 0; k < nv; ++k) {
        double dd = 0;
        for (int c = 0; c < 3; ++c)
            dd += (v[3 * k + c] - x[c]) * (v[3 * k + c] - x[c]);
        if (dd < bd) bd = dd, best = k;
    }
    return best;
}

// Exports the dragon to `name` and plays its ink back from the file: the
// largest distance (world units) from pose_at's ink, at three times of the
// loop, over its `count` ink nodes (each named for the part of the detail
// in order: `parts`[i], two digits); the validator must take the file.
static double ink_played_back(sp_dragon* d, const char* name, int count, const int* parts)
{
    sp_error err = {0};
    const char* glbf = sp_test_tmp_path(name);
    ENSURE(sp_dragon_export(d, glbf, &err) == SP_OK);
    glb g;
    glb_read(glbf, &g);
    const cJSON* off = cJSON_GetObjectItem(
        cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(g.j, "scenes"), 0), "extras"),
                            "sp_dragon"),
        "world_offset");
    int ink_nodes[8], found = 0;
    ENSURE(count <= 8);
    const cJSON* jn = cJSON_GetObjectItem(g.j, "nodes");
    for (int i = 0; i < cJSON_GetArraySize(jn); ++i) {
        const char* nm = cJSON_GetObjectItem(cJSON_GetArrayItem(jn, i), "name")->valuestring;
        if (strstr(nm, "/ink")) {
            char want[8];
            ENSURE(found < count);
            snprintf(want, sizeof want, "%02d_", parts[found]);
            ENSURE(!strncmp(nm, want, 3));
            ink_nodes[found++] = i;
        }
    }
    ENSURE(found == count);
    double worst = 0, period = sp_dragon_period(d);
    sp_dragon_detail e;
    for (int step = 0; step < 3; ++step) {
        double t = step * 0.37 * period;
        ENSURE(sp_dragon_pose_at(d, t, &err) == SP_OK);
        for (int i = 0; i < count; ++i) {
            int np;
            double* x = glb_pose_node(&g, t, ink_nodes[i], &np);
            ENSURE(sp_dragon_detail_get(d, i, &e) && e.xyz && np == e.point_count);
            for (int k = 0; k < 3 * np; ++k)
                worst = fmax(worst, fabs(x[k] - (e.xyz[k] + cJSON_GetArrayItem(off, k % 3)->valuedouble)));
            free(x);
        }
    }
    cJSON_Delete(g.j);
    free(g.bin);
    int v = sp_fixture_gltf_validate(glbf);
    if (v >= 0) ENSURE(v == 1);
    return worst;
}

// Details are kept as ink that rides their part. The README's picture
// (docs/img/kiosk_detail.json): the body and the head as the kiosk makes
// them on the default database (this test's quick database classifies
// otherwise), then three spots on the body and an eye on the head.
static void details_ride_their_part(sp_dragon* d)
{
    sp_error err = {0};
    sp_dragon_result res;
    sp_dragon_clear(d);
    char file[1200];
    snprintf(file, sizeof file, "%s/docs/img/kiosk_detail.json", SP_SOURCE_DIR);
    sp_vec2* s6[8];
    int n6[8], count = sp_fixture_session_strokes(file, s6, n6, 8);
    ENSURE(count == 6);
    for (int k = 0; k < count; ++k) {
        if (k < 2) {
            add_as(d, s6[k], n6[k], k == 0 ? "torso" : "head");
            continue;
        }
        ENSURE(sp_dragon_add_points(d, s6[k], n6[k], NULL, &res, &err) == SP_OK);
        ENSURE(res.rejected && res.reason == SP_DRAGON_DETAIL && res.detail == k - 2 && sp_dragon_detail_count(d) == k - 1);
        fprintf(stderr, "  detail %d kept in %.1f ms (pen-up to ink)\n", k - 2, res.ms_total);
    }
    ENSURE(sp_dragon_part_count(d) == 2 && sp_dragon_part_get(d, 1)->attached_to == 0);
    sp_dragon_detail e;
    for (int i = 0; i < 4; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.part == (i < 3 ? 0 : 1) && e.point_count >= 20 && !e.xyz);
        ENSURE(e.id > sp_dragon_part_get(d, 1)->id);
    }
    ENSURE(!sp_dragon_detail_get(d, 4, &e) && !sp_dragon_detail_get(d, -1, &e));
    // The report lists them with their parts.
    char* text = NULL;
    ENSURE(sp_dragon_report_json(d, &text, &err) == SP_OK);
    cJSON* rj = cJSON_Parse(text);
    free(text);
    const cJSON* rd = cJSON_GetObjectItem(rj, "details");
    ENSURE(cJSON_GetArraySize(rd) == 4);
    for (int i = 0; i < 4; ++i)
        ENSURE(jint(cJSON_GetArrayItem(rd, i), "part") == (i < 3 ? 0 : 1) && jint(cJSON_GetArrayItem(rd, i), "points") >= 20);
    cJSON_Delete(rj);
    // Posed: each ink is where it was drawn, about as large (its box's centre
    // near the stroke's: at t = 0 the head is off its fit by its clip's first offsets).
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    for (int i = 0; i < 4; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.xyz && e.normal);
        sp_vec2 lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY}, slo = lo, shi = hi;
        for (int k = 0; k < e.point_count; ++k) {
            sp_vec2 q = ink_px(d, i, k);
            lo.x = fmin(lo.x, q.x), lo.y = fmin(lo.y, q.y), hi.x = fmax(hi.x, q.x), hi.y = fmax(hi.y, q.y);
            ENSURE(e.normal[3 * k + 2] > 0); // drawn on the side that faces the canvas
        }
        for (int k = 0; k < n6[i + 2]; ++k)
            slo.x = fmin(slo.x, s6[i + 2][k].x), slo.y = fmin(slo.y, s6[i + 2][k].y), shi.x = fmax(shi.x, s6[i + 2][k].x),
            shi.y = fmax(shi.y, s6[i + 2][k].y);
        double off = hypot(0.5 * (lo.x + hi.x - slo.x - shi.x), 0.5 * (lo.y + hi.y - slo.y - shi.y));
        double size = hypot(hi.x - lo.x, hi.y - lo.y) / hypot(shi.x - slo.x, shi.y - slo.y);
        fprintf(stderr, "  detail %d on part %d: %d points, %.1f px from its stroke, %.2f its size\n", i, e.part, e.point_count,
                off, size);
        ENSURE(off < 12 && size > 0.8 && size < 1.25);
    }
    // It rides its part: over the loop each ink point moves as the part's
    // vertex nearest it does (the eye with the head, not the body).
    double period = sp_dragon_period(d);
    ENSURE(period > 0);
    int near_v[4][SP_DRAGON_DETAIL_POINTS];
    sp_vec2 ink0[4][SP_DRAGON_DETAIL_POINTS], vtx0[4][SP_DRAGON_DETAIL_POINTS];
    sp_camera cam = sp_dragon_camera(d);
    for (int i = 0; i < 4; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e));
        for (int k = 0; k < e.point_count; ++k) {
            near_v[i][k] = nearest_vertex(d, e.part, e.xyz + 3 * k);
            const double* v = sp_dragon_part_xyz(d, e.part) + 3 * near_v[i][k];
            ink0[i][k] = ink_px(d, i, k), vtx0[i][k] = sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]});
        }
    }
    double moved = 0;
    for (int step = 1; step <= 4; ++step) {
        ENSURE(sp_dragon_pose_at(d, step * period / 5, &err) == SP_OK);
        for (int i = 0; i < 4; ++i) {
            ENSURE(sp_dragon_detail_get(d, i, &e) && e.xyz);
            for (int k = 0; k < e.point_count; ++k) {
                const double* v = sp_dragon_part_xyz(d, e.part) + 3 * near_v[i][k];
                sp_vec2 dv = sp_v2_sub(sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]}), vtx0[i][k]);
                sp_vec2 di = sp_v2_sub(ink_px(d, i, k), ink0[i][k]);
                moved = fmax(moved, sp_v2_len(di));
                ENSURE(sp_v2_len(sp_v2_sub(di, dv)) < 2.5);
            }
        }
    }
    fprintf(stderr, "  the ink moves up to %.1f px over the loop, as its part\n", moved);
    ENSURE(moved > 3);
    // The export holds the ink: a line on each part's skin that the file's
    // animation moves as pose_at does (within half a canvas pixel: a point
    // skinned by its corners' blended influences is not exactly the blend of
    // its skinned corners), and the validator takes it.
    double worst = ink_played_back(d, "dragon_ink.glb", 4, (const int[]){0, 0, 0, 1});
    fprintf(stderr, "  the exported ink played back vs pose_at: %.2g world units (a canvas pixel is %.2g)\n", worst, 2.0 / 800);
    ENSURE(worst < 0.5 * 2.0 / 800);
    // Undo takes back the last change: the eye, then a spot, then the head.
    ENSURE(sp_dragon_undo(d) && sp_dragon_detail_count(d) == 3 && sp_dragon_part_count(d) == 2);
    // A chip for the eye (kept again) makes it a head in its place.
    ENSURE(sp_dragon_add_points(d, s6[5], n6[5], NULL, &res, &err) == SP_OK && res.detail == 3);
    ENSURE(sp_dragon_add_points(d, s6[5], n6[5], &(sp_dragon_stroke_opts){.category = "head", .replace_detail = true}, &res,
                                &err) == SP_OK);
    ENSURE(!res.rejected && sp_dragon_part_count(d) == 3 && sp_dragon_detail_count(d) == 3);
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == 3);
    // Only when the detail is the last change: after a part, the chip's part is added and the ink stays.
    ENSURE(sp_dragon_add_points(d, s6[5], n6[5], NULL, &res, &err) == SP_OK && res.detail == 3);
    ENSURE(sp_dragon_add_points(d, s6[0], n6[0], &(sp_dragon_stroke_opts){.category = "torso"}, &res, &err) == SP_OK);
    ENSURE(sp_dragon_add_points(d, s6[5], n6[5], &(sp_dragon_stroke_opts){.category = "head", .replace_detail = true}, &res,
                                &err) == SP_OK);
    ENSURE(!res.rejected && sp_dragon_part_count(d) == 4 && sp_dragon_detail_count(d) == 4);
    ENSURE(sp_dragon_undo(d) && sp_dragon_undo(d) && sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == 4);
    // A Redraw of the head drops its ink; the body's stays.
    ENSURE(sp_dragon_add_points(d, s6[1], n6[1], &(sp_dragon_stroke_opts){.category = "head", .replace_last = true}, &res,
                                &err) == SP_OK);
    ENSURE(!res.rejected && sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == 3);
    for (int i = 0; i < 3; ++i)
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.part == 0);
    // The picture shows the ink (dark pixels where the spots were drawn, on a green body).
    sp_image img = {0};
    sp_error rerr = {0};
    sp_result r = sp_dragon_snapshot_render(d, &(sp_dragon_snapshot_desc){0}, &img, &rerr);
    if (r == SP_ERR_UNSUPPORTED) {
        fprintf(stderr, "  note: no EGL here, no picture: %s\n", rerr.text);
    } else {
        ENSURE(r == SP_OK);
        int dark = 0, total = 0;
        for (int k = 0; k < n6[2]; ++k) { // ink (every channel low: not the green body) within 4 px
            dark += dark_near(&img, s6[2][k], 4), ++total;
        }
        fprintf(stderr, "  %d of %d points of the first spot dark in the picture\n", dark, total);
        ENSURE(total > 0 && dark >= total / 2);
        sp_image_free(&img);
    }
    // Redraw armed, a small stroke on the body is a detail of the body; its
    // chip makes it the head in the last part's place and takes its ink back.
    ENSURE(sp_dragon_add_points(d, s6[2], n6[2], &(sp_dragon_stroke_opts){.replace_last = true}, &res, &err) == SP_OK);
    ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail == 3 && sp_dragon_part_count(d) == 2);
    ENSURE(sp_dragon_add_points(d, s6[2], n6[2],
                                &(sp_dragon_stroke_opts){.category = "head", .replace_last = true, .replace_detail = true}, &res,
                                &err) == SP_OK);
    ENSURE(!res.rejected && sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == 3);
    ENSURE(sp_dragon_part_get(d, 1)->stroke_points > 0 && !strcmp(sp_dragon_part_get(d, 1)->category, "head"));
    // At most SP_DRAGON_MAX_DETAILS (a kiosk runs all day): then a detail is refused and not kept.
    sp_vec2 slo = s6[2][0], shi = s6[2][0];
    for (int k = 1; k < n6[2]; ++k)
        slo.x = fmin(slo.x, s6[2][k].x), slo.y = fmin(slo.y, s6[2][k].y), shi.x = fmax(shi.x, s6[2][k].x),
        shi.y = fmax(shi.y, s6[2][k].y);
    detail_hit hit = {0};
    ENSURE(dragon_detail_of(d, s6[2], n6[2], slo, shi, -1, &hit) == 0);
    while (dragon_detail_keep(d, &hit, s6[2], n6[2]) >= 0)
        ;
    dragon_detail_hit_free(&hit);
    ENSURE(sp_dragon_detail_count(d) == SP_DRAGON_MAX_DETAILS);
    ENSURE(sp_dragon_add_points(d, s6[2], n6[2], NULL, &res, &err) == SP_OK && res.reason == SP_DRAGON_DETAIL &&
           res.detail == -1);
    ENSURE(sp_dragon_pose_at(d, 0.3, &err) == SP_OK &&
           sp_dragon_export(d, sp_test_tmp_path("dragon_ink_full.glb"), &err) == SP_OK);
    sp_dragon_clear(d);
    ENSURE(sp_dragon_detail_count(d) == 0 && !sp_dragon_undo(d));
    for (int k = 0; k < count; ++k)
        free(s6[k]);
}

// A small stroke drawn on a part is a detail of it (an eye on the head,
// spots on the body): refused as a part, with its guesses for the chips,
// and kept as ink on the part (details_ride_their_part). Before, each
// became a tiny part: a head on the body, a body or a head floating at the
// head. The same loop drawn apart from every part, as large as a part, or
// chosen with a chip is a part; so is a visitor's pair of legs drawn small
// on the body.
static void test_details_on_parts(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_dragon_result res;
    sp_dragon* d = new_dragon(path);
    int n;
    sp_vec2* xy = visitor_stroke("torso/torso-pear.json", 500, (sp_vec2){600, 450}, false, &n);
    int body = add_as(d, xy, n, "torso");
    free(xy);
    sp_vec2 blo, bhi; // the head centred 20 px inside the body's front top corner, as visitors draw it
    fitted_box(d, body, &blo, &bhi);
    sp_vec2 head_at = {bhi.x - 20, blo.y + 20};
    xy = visitor_stroke("head/head-frill.json", 220, head_at, false, &n);
    int head = add_as(d, xy, n, "head");
    free(xy);
    ENSURE(sp_dragon_part_get(d, head)->attached_to == body);
    sp_vec2 spot, eye, loop[40];
    ENSURE(spot_on_part(d, body, 16, -1, &spot) && spot_on_part(d, head, 8, body, &eye));
    fprintf(stderr, "  body at (600, 450), head at (%.0f, %.0f)\n", head_at.x, head_at.y);
    // Three spots on the body, an eye on the head: details.
    for (int k = 0; k < 4; ++k) {
        sp_vec2 c = k == 3 ? eye : (sp_vec2){spot.x + (k - 1) * 40, spot.y + (k == 1 ? 0 : 20)};
        if (k < 3 && !disc_on_part(d, body, c, 18)) c = spot; // stays on the body whatever its shape
        small_loop(c, k == 3 ? 8 : 16, loop);
        ENSURE(sp_dragon_add_points(d, loop, 40, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  %s at (%.0f, %.0f): %s, guesses %d (%s)\n", k == 3 ? "eye" : "spot", c.x, c.y,
                sp_dragon_reject_name(res.reason), res.guess_count, res.guess_count ? res.guesses[0].category : "");
        ENSURE(res.rejected && res.reason == SP_DRAGON_DETAIL && res.part == -1 && res.guess_count > 0);
        ENSURE(sp_dragon_part_count(d) == 2);
    }
    // A chip makes the eye a part: a chosen category is never a detail.
    ENSURE(sp_dragon_add_points(d, loop, 40, &(sp_dragon_stroke_opts){.category = "head"}, &res, &err) == SP_OK && !res.rejected);
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 2);
    // A Redraw of the head: the head it replaces holds no details.
    ENSURE(sp_dragon_add_points(d, loop, 40, &(sp_dragon_stroke_opts){.replace_last = true}, &res, &err) == SP_OK);
    fprintf(stderr, "  the eye as a Redraw of the head: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL);
    if (!res.rejected) {
        ENSURE(sp_dragon_undo(d)); // the redrawn "head" is gone; put the head back
        xy = visitor_stroke("head/head-frill.json", 220, head_at, false, &n);
        head = add_as(d, xy, n, "head");
        free(xy);
    }
    // The spot drawn apart from every part, or as large as a part: not a detail.
    small_loop((sp_vec2){150, 700}, 16, loop);
    ENSURE(sp_dragon_add_points(d, loop, 40, NULL, &res, &err) == SP_OK && res.reason != SP_DRAGON_DETAIL);
    if (!res.rejected) ENSURE(sp_dragon_undo(d));
    small_loop(spot, 70, loop);
    ENSURE(sp_dragon_add_points(d, loop, 40, NULL, &res, &err) == SP_OK && res.reason != SP_DRAGON_DETAIL);
    if (!res.rejected) ENSURE(sp_dragon_undo(d));
    // A visitor's legs drawn small, their top inside the body: a part.
    xy = visitor_stroke("front_legs/front-legs-boots.json", 110, (sp_vec2){spot.x, spot.y + 30}, false, &n);
    ENSURE(sp_dragon_add_points(d, xy, n, NULL, &res, &err) == SP_OK);
    free(xy);
    fprintf(stderr, "  small legs on the body: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL);
    // A dense scribble on the body (shading) is a detail too, not "what is that?".
    sp_vec2 shade[200];
    for (int k = 0; k < 200; ++k)
        shade[k] = (sp_vec2){spot.x - 15 + 30 * fabs(fmod(k * 0.37, 2.0) - 1), spot.y - 12 + 0.12 * k};
    ENSURE(sp_dragon_add_points(d, shade, 200, NULL, &res, &err) == SP_OK && res.reason == SP_DRAGON_DETAIL);
    sp_dragon_detail e; // kept, resampled along its length to at most SP_DRAGON_DETAIL_POINTS
    ENSURE(res.detail >= 0 && sp_dragon_detail_get(d, res.detail, &e) && e.point_count == SP_DRAGON_DETAIL_POINTS);
    // A spot drawn half over a thin tail's edge (a review: "A bit bigger
    // please" took it away): too small for a part, half on the tail, ink on
    // it, whole. Drawn 40 px above the tail it is still too small.
    xy = at_box_end("tail/tail-wavy-line.json", 260, 0.5 * (blo.y + bhi.y), false, blo, bhi, false, 30, &n);
    int tail = add_as(d, xy, n, "tail");
    free(xy);
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    sp_vec2 tlo, thi, edge = {0, INFINITY};
    fitted_box(d, tail, &tlo, &thi);
    sp_camera cam = sp_dragon_camera(d);
    const double* txyz = sp_dragon_part_xyz(d, tail);
    for (int v = 0; v < sp_dragon_part_get(d, tail)->character->rig.vertex_count; ++v) { // the top edge at the tail's middle
        sp_vec2 x = sp_camera_project(&cam, (sp_vec3){txyz[3 * v], txyz[3 * v + 1], txyz[3 * v + 2]});
        if (fabs(x.x - 0.5 * (tlo.x + thi.x)) < 8 && x.y < edge.y) edge = x;
    }
    ENSURE(isfinite(edge.y));
    for (int above = 0; above < 2; ++above) {
        small_loop((sp_vec2){edge.x, edge.y - (above ? 40 : 3)}, 8, loop); // over the edge, more off the tail than on
        ENSURE(sp_dragon_add_points(d, loop, 40, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  a spot %s the tail's edge: %s\n", above ? "40 px above" : "over", sp_dragon_reject_name(res.reason));
        if (above) {
            ENSURE(res.reason == SP_DRAGON_TOO_SHORT);
            continue;
        }
        ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail >= 0 && sp_dragon_detail_get(d, res.detail, &e) && e.part == tail);
        ENSURE(e.point_count >= 36); // its points off the tail are kept too
        // Posed at t = 0 (the tail off its fit by its clip's first offsets): the spot, whole, where it was drawn.
        ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
        sp_vec2 ilo = {INFINITY, INFINITY}, ihi = {-INFINITY, -INFINITY}, slo, shi;
        for (int k = 0; k < e.point_count; ++k) {
            sp_vec2 q = ink_px(d, res.detail, k);
            ilo.x = fmin(ilo.x, q.x), ilo.y = fmin(ilo.y, q.y), ihi.x = fmax(ihi.x, q.x), ihi.y = fmax(ihi.y, q.y);
        }
        points_box(loop, 40, &slo, &shi);
        double size = hypot(ihi.x - ilo.x, ihi.y - ilo.y) / hypot(shi.x - slo.x, shi.y - slo.y),
               moved = sp_v2_len(sp_v2_sub(sp_v2_add(ilo, ihi), sp_v2_add(slo, shi))) / 2;
        fprintf(stderr, "  its ink %.2f its size, its centre %.1f px from the spot's\n", size, moved);
        ENSURE(size > 0.85 && size < 1.2 && moved < 12);
    }
    details_ride_their_part(d);
    sp_dragon_destroy(d);
}

// The README's dragon (docs/img/kiosk_detail.json): its six strokes (s6,
// n6: freed by the caller) and a new dragon with its body and head made so
// by a chip, as the kiosk makes them on the default database (this test's
// quick database classifies otherwise). *body, *head: their indices.
static sp_dragon* readme_dragon(const char* path, sp_vec2* s6[8], int n6[8], int* body, int* head)
{
    char file[1200];
    snprintf(file, sizeof file, "%s/docs/img/kiosk_detail.json", SP_SOURCE_DIR);
    ENSURE(sp_fixture_session_strokes(file, s6, n6, 8) == 6);
    sp_dragon* d = new_dragon(path);
    *body = add_as(d, s6[0], n6[0], "torso");
    *head = add_as(d, s6[1], n6[1], "head");
    return d;
}

// A wavy line of 40 points from `from` along the unit direction dir, turned by `turn` radians.
static void wavy_line(sp_vec2 from, sp_vec2 dir, double turn, double length, sp_vec2 out[40])
{
    sp_vec2 u = {cos(turn) * dir.x - sin(turn) * dir.y, sin(turn) * dir.x + cos(turn) * dir.y}, v = {-u.y, u.x};
    for (int i = 0; i < 40; ++i) {
        double t = i / 39.0, off = 10 * sin(t * 4 * M_PI) * (0.3 + t);
        out[i] = sp_v2_add(from, sp_v2_add(sp_v2_scale(u, t * length), sp_v2_scale(v, off)));
    }
}

// A stroke drawn out of a part, away from the body (fire from the mouth),
// is a flourish: kept as ink on that part, its points off the mesh carried
// in the air by the part's skin where the stroke leaves it. Before, each
// line of fire became a tiny tail floating beside the head, a flame
// outline a second head or wings. The README's dragon (docs/img/kiosk_detail.json:
// its body and head), then fire from the head's snout, as a visitor draws it.
static void test_flourishes_off_parts(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_dragon_result res;
    sp_vec2* s6[8];
    int n6[8], count = 6, body, head;
    sp_dragon* d = readme_dragon(path, s6, n6, &body, &head);
    ENSURE(sp_dragon_part_get(d, head)->attached_to == body);
    // The snout as drawn: the head's stroke point farthest from the body's middle.
    sp_vec2 bc = {0, 0}, tip = s6[1][0];
    for (int k = 0; k < n6[0]; ++k)
        bc = sp_v2_add(bc, sp_v2_scale(s6[0][k], 1.0 / n6[0]));
    for (int k = 0; k < n6[1]; ++k)
        if (sp_v2_len(sp_v2_sub(s6[1][k], bc)) > sp_v2_len(sp_v2_sub(tip, bc))) tip = s6[1][k];
    sp_vec2 dir = sp_v2_scale(sp_v2_sub(tip, bc), 1 / sp_v2_len(sp_v2_sub(tip, bc)));
    sp_vec2 fire[3][40];
    for (int k = 0; k < 3; ++k) {
        wavy_line(sp_v2_add(tip, sp_v2_scale(dir, 6)), dir, 0.25 * (k - 1), 150, fire[k]);
        ENSURE(sp_dragon_add_points(d, fire[k], 40, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  fire %d: %s, %.1f ms (pen-up to ink)\n", k, sp_dragon_reject_name(res.reason), res.ms_total);
        ENSURE(res.rejected && res.reason == SP_DRAGON_DETAIL && res.detail == k && res.guess_count > 0);
        ENSURE(sp_dragon_part_count(d) == 2 && sp_dragon_detail_count(d) == k + 1);
    }
    // At t = 0 each line is where it was drawn, at its size, mostly in the air.
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    sp_dragon_detail e;
    for (int i = 0; i < 3; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.part == head && e.xyz && e.point_count == 40);
        sp_vec2 lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY}, slo = lo, shi = hi;
        int air = 0;
        for (int k = 0; k < e.point_count; ++k) {
            sp_vec2 q = ink_px(d, i, k), s = fire[i][k];
            lo.x = fmin(lo.x, q.x), lo.y = fmin(lo.y, q.y), hi.x = fmax(hi.x, q.x), hi.y = fmax(hi.y, q.y);
            slo.x = fmin(slo.x, s.x), slo.y = fmin(slo.y, s.y), shi.x = fmax(shi.x, s.x), shi.y = fmax(shi.y, s.y);
            air += e.normal[3 * k] == 0 && e.normal[3 * k + 1] == 0 && e.normal[3 * k + 2] == 0;
        }
        double off = hypot(0.5 * (lo.x + hi.x - slo.x - shi.x), 0.5 * (lo.y + hi.y - slo.y - shi.y));
        double size = hypot(hi.x - lo.x, hi.y - lo.y) / hypot(shi.x - slo.x, shi.y - slo.y);
        fprintf(stderr, "  fire %d on part %d: %d of %d points in the air, %.1f px from its stroke, %.2f its size\n", i, e.part,
                air, e.point_count, off, size);
        ENSURE(air >= 30 && off < 12 && size > 0.9 && size < 1.1);
    }
    // It rides the head: over the loop each line's first point moves as the
    // head's vertex nearest it, and the line keeps its length (carried, not bent).
    double period = sp_dragon_period(d), moved = 0, stretch = 0;
    ENSURE(period > 0);
    sp_camera cam = sp_dragon_camera(d);
    int near_v[3];
    sp_vec2 ink0[3], vtx0[3];
    double len0[3];
    for (int i = 0; i < 3; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e));
        near_v[i] = nearest_vertex(d, head, e.xyz);
        const double* v = sp_dragon_part_xyz(d, head) + 3 * near_v[i];
        ink0[i] = ink_px(d, i, 0), vtx0[i] = sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]});
        len0[i] = sp_v2_len(sp_v2_sub(ink_px(d, i, 39), ink0[i]));
    }
    for (int step = 1; step <= 4; ++step) {
        ENSURE(sp_dragon_pose_at(d, step * period / 5, &err) == SP_OK);
        for (int i = 0; i < 3; ++i) {
            const double* v = sp_dragon_part_xyz(d, head) + 3 * near_v[i];
            sp_vec2 dv = sp_v2_sub(sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]}), vtx0[i]);
            sp_vec2 di = sp_v2_sub(ink_px(d, i, 0), ink0[i]);
            moved = fmax(moved, sp_v2_len(di));
            ENSURE(sp_v2_len(sp_v2_sub(di, dv)) < 2.5);
            stretch = fmax(stretch, fabs(sp_v2_len(sp_v2_sub(ink_px(d, i, 39), ink_px(d, i, 0))) / len0[i] - 1));
        }
    }
    fprintf(stderr, "  the fire moves up to %.1f px over the loop, its lines' lengths within %.1f%%\n", moved, 100 * stretch);
    ENSURE(moved > 3 && stretch < 0.1);
    // The export: the points in the air skinned by their carrier play back as pose_at.
    double worst = ink_played_back(d, "dragon_fire.glb", 3, (const int[]){1, 1, 1});
    fprintf(stderr, "  the exported fire played back vs pose_at: %.2g world units (a canvas pixel is %.2g)\n", worst, 2.0 / 800);
    ENSURE(worst < 0.5 * 2.0 / 800);
    // The picture shows it in the air (dark pixels along the middle line as posed).
    sp_image img = {0};
    sp_error rerr = {0};
    sp_result r = sp_dragon_snapshot_render(d, &(sp_dragon_snapshot_desc){0}, &img, &rerr);
    if (r == SP_ERR_UNSUPPORTED) {
        fprintf(stderr, "  note: no EGL here, no picture: %s\n", rerr.text);
    } else {
        ENSURE(r == SP_OK);
        int dark = 0;
        for (int k = 0; k < 40; ++k) {
            dark += dark_near(&img, ink_px(d, 1, k), 3);
        }
        fprintf(stderr, "  %d of 40 points of the middle line dark in the picture\n", dark);
        ENSURE(dark >= 36);
        sp_image_free(&img);
    }
    // The flourish test's "near the ink drawn out of it" measures to the ink
    // where it is shown, also once its part has been laid out again and
    // moved (attached elsewhere, or freed): here the head's layout shifted
    // by 40 px. Before, it measured to where the ink had been drawn.
    part* hp = d->parts[head];
    sp_mat4 laid = hp->world_fit, shift = sp_mat4_translate((sp_vec3){40 * 2.0 / 800, 0, 0});
    double near_ink[2] = {0, 0};
    for (int pass = 0; pass < 2; ++pass) {
        if (pass) hp->world_fit = sp_mat4_mul(&shift, &laid);
        ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
        for (int k = 0; k < 40; ++k)
            near_ink[pass] = fmax(near_ink[pass], dragon_ink_distance(d, hp->pub.id, ink_px(d, 1, k)));
        fprintf(stderr, "  the middle line as shown at t = 0%s: within %.1f px of the ink the flourish test sees\n",
                pass ? ", its head laid out 40 px away" : "", near_ink[pass]);
    }
    ENSURE(near_ink[0] < 10 && near_ink[1] < near_ink[0] + 2);
    hp->world_fit = laid;
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    // A puff drawn at the middle line's end, off the head's mesh but on its ink, rides the head too.
    sp_vec2 puff[40], end = fire[1][39];
    for (int k = 0; k < 40; ++k)
        puff[k] = (sp_vec2){end.x + 25 * dir.x + 22 * cos(2 * M_PI * k / 39 + M_PI) * 1.2,
                            end.y + 25 * dir.y + 18 * sin(2 * M_PI * k / 39)};
    ENSURE(sp_dragon_add_points(d, puff, 40, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  a puff at the fire's end: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail == 3 && sp_dragon_detail_get(d, 3, &e) && e.part == head);
    // Undo takes back the puff and the fire, one at a time.
    for (int k = 4; k > 0; --k)
        ENSURE(sp_dragon_undo(d) && sp_dragon_detail_count(d) == k - 1 && sp_dragon_part_count(d) == 2);
    // Not flourishes: the line drawn apart from the head, or out of the
    // body (a tail), is a part or refused, never ink; so is fire from a
    // head that has no body yet (parts drawn before their body are parts).
    wavy_line(sp_v2_add(tip, sp_v2_scale(dir, 80)), dir, 0, 150, fire[0]);
    ENSURE(sp_dragon_add_points(d, fire[0], 40, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  the line 80 px from the snout: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 0);
    if (!res.rejected) ENSURE(sp_dragon_undo(d));
    sp_vec2 rear = s6[0][0];
    for (int k = 0; k < n6[0]; ++k)
        if (s6[0][k].x < rear.x) rear = s6[0][k];
    wavy_line(sp_v2_add(rear, (sp_vec2){-4, 0}), (sp_vec2){-1, 0}, 0.2, 150, fire[0]);
    ENSURE(sp_dragon_add_points(d, fire[0], 40, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  the line out of the body's rear: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 0);
    if (!res.rejected) ENSURE(sp_dragon_undo(d));
    // A head drawn out of the body's front end while the dragon has none is
    // its head, never a flourish of a part it touches (dragon_claims_socket);
    // with its head there, that place is for fire.
    const tpl* ht = d->parts[head]->t;
    sp_vec2 flo = {tip.x, tip.y - 60}, fhi = {tip.x + 200, tip.y + 60};
    ENSURE(!dragon_claims_socket(d, ht, flo, fhi));
    ENSURE(sp_dragon_undo(d) && sp_dragon_part_count(d) == 1);
    ENSURE(dragon_claims_socket(d, ht, flo, fhi));
    ENSURE(
        !dragon_claims_socket(d, ht, (sp_vec2){flo.x + 150, flo.y}, (sp_vec2){fhi.x + 150, fhi.y})); // beyond the snap distance
    sp_dragon_clear(d);
    head = add_as(d, s6[1], n6[1], "head");
    ENSURE(sp_dragon_add_points(d, fire[1], 40, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  fire from a head with no body: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 0);
    for (int k = 0; k < count; ++k)
        free(s6[k]);
    // A crown drawn on the head as the visitor drew it, where the fit does
    // not reach (an outside review's session: the fitted head sits 40-60 px
    // under the drawn outline's top): ink on the head, not a tiny tail.
    sp_dragon_clear(d);
    char file[1200];
    snprintf(file, sizeof file, "%s/tests/e2e/data/kiosk_crown_gap.json", SP_SOURCE_DIR);
    sp_vec2* cg[8];
    int ncg[8];
    ENSURE(sp_fixture_session_strokes(file, cg, ncg, 8) == 4);
    const char* kinds[3] = {"torso", "head", "tail"};
    for (int k = 0; k < 3; ++k)
        add_as(d, cg[k], ncg[k], kinds[k]);
    ENSURE(sp_dragon_add_points(d, cg[3], ncg[3], NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  a crown on the head as drawn: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail >= 0 && sp_dragon_detail_get(d, res.detail, &e) && e.part == 1);
    for (int k = 0; k < 4; ++k)
        free(cg[k]);
    sp_dragon_destroy(d);
}

// Decorations drawn inside a body (an outside review's: stripes, a spiral,
// a zigzag, a wavy line along the belly) are ink on it, whatever the
// classifier took them for: they became legs and a tail stuck to the flank,
// and the wavy line, refused after its fit, faded.
static void test_decorations_on_the_body(void)
{
    const char* path = real_db();
    sp_db* db = NULL;
    sp_dragon* d = dragon_and_db(path, &db);
    char file[1200];
    snprintf(file, sizeof file, "%s/tests/e2e/data/kiosk_decorations.json", SP_SOURCE_DIR);
    sp_sketch sk = {0};
    sp_error err = {0};
    ENSURE(sp_sketch_read_json(file, &sk, &err) == SP_OK && sk.stroke_count == 9);
    const char* kinds[5] = {"torso", "head", "front_legs", "hind_legs", "tail"};
    for (int k = 0; k < 5; ++k)
        add_as(d, sk.strokes[k].points, sk.strokes[k].count, kinds[k]);
    const char* names[4] = {"stripes", "a spiral", "a zigzag", "a wavy line along the belly"};
    int inked = 0;
    for (int k = 5; k < 9; ++k) {
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, sk.strokes[k].points, sk.strokes[k].count, NULL, &res, &err) == SP_OK);
        sp_dragon_detail e;
        bool on_body = res.reason == SP_DRAGON_DETAIL && sp_dragon_detail_get(d, res.detail, &e) && e.part == 0;
        float sure = 0; // the classifier's best score (the guesses are ranked by their fits)
        for (int g = 0; g < res.guess_count; ++g)
            sure = fmaxf(sure, res.guesses[g].confidence);
        fprintf(stderr, "  %s on the body: %s%s (%s %.2f)\n", names[k - 5], sp_dragon_reject_name(res.reason),
                on_body ? ", ink on it" : "", res.guess_count ? res.guesses[0].category : "-", sure);
        // Unsure, it is ink; a part the classifier is sure of stays one
        // unless its fit refuses it (a wing drawn on the flank; this test's
        // quickly trained model is sure of some of these).
        ENSURE(sure >= 0.85f || (on_body && sp_dragon_part_count(d) == 5));
        inked += sure < 0.85f;
        if (!res.rejected || res.reason == SP_DRAGON_DETAIL) ENSURE(sp_dragon_undo(d));
    }
    ENSURE(inked >= 2); // the premise: most are not surely parts
    // Wings drawn flat on the flank stay wings where the classifier is sure
    // (a third review: 10 of 30 visitors' wings there became ink).
    const char* wings[3] = {"wings/wing-feathered.json", "wings/wing-3-scallops-raised.json", "wings/wing-fan-4-ribs.json"};
    int sure_wings = 0;
    for (int w = 0; w < 3; ++w) {
        int m;
        sp_vec2* xy = visitor_stroke(wings[w], 200, (sp_vec2){650, 412}, false, &m);
        sp_dragon_result res;
        ENSURE(sp_dragon_add_points(d, xy, m, NULL, &res, &err) == SP_OK);
        free(xy);
        float sure = 0;
        for (int g = 0; g < res.guess_count; ++g)
            if (!strcmp(res.guesses[g].category, "wings")) sure = res.guesses[g].confidence;
        fprintf(stderr, "  %s on the flank: %s (wings %.2f)\n", wings[w], sp_dragon_reject_name(res.reason), sure);
        if (sure >= 0.85f) ENSURE(res.reason == SP_DRAGON_ACCEPTED && ++sure_wings);
        if (!res.rejected || res.reason == SP_DRAGON_DETAIL) ENSURE(sp_dragon_undo(d));
    }
    ENSURE(sure_wings >= 1);
    sp_sketch_free(&sk);
    sp_dragon_destroy(d);
    sp_db_close(db);
}

// A flame drawn out of the tip of a tail drawn as one line (fitted with its
// `line`) is ink on the tail, and at t = 0 it lies where it was drawn: the
// tail is taken as shown, posed at the dragon's clock, whether the flame
// starts at the tip as shown or at the tail's stroke. Before, the tail was
// taken at its fit, which its sway (off rest at t = 0) moves: the flame at
// the stroke's tip showed well above where it was drawn, and the one at
// the tip as shown was too far from the fit to be ink and became a part.
static void test_flourish_on_line_tail(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_dragon_result res;
    sp_vec2* s6[8];
    int n6[8], body, head, n;
    sp_dragon* d = readme_dragon(path, s6, n6, &body, &head);
    sp_vec2 blo, bhi, hlo, hhi;
    points_box(s6[0], n6[0], &blo, &bhi);
    points_box(s6[1], n6[1], &hlo, &hhi);
    bool right = hlo.x + hhi.x < blo.x + bhi.x; // the tail at the end away from the head
    double out = right ? 1 : -1;
    sp_vec2* xy = at_box_end("tail/tail-wavy-line.json", 300, 0.5 * (blo.y + bhi.y), !right, blo, bhi, right, 20, &n);
    int tail = add_as(d, xy, n, "tail");
    fprintf(stderr, "  the tail: fitted with its %s, attached to %d\n", fitted_curve(d, tail),
            sp_dragon_part_get(d, tail)->attached_to);
    ENSURE(!strcmp(fitted_curve(d, tail), "line") && sp_dragon_part_get(d, tail)->attached_to == body);
    // The tips: the stroke's point and the shown mesh's vertex farthest out.
    sp_vec2 tips[2] = {xy[0], {0, 0}};
    for (int k = 0; k < n; ++k)
        if (out * (xy[k].x - tips[0].x) > 0) tips[0] = xy[k];
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK);
    const double* x = sp_dragon_part_xyz(d, tail);
    sp_camera cam = sp_dragon_camera(d);
    for (int v = 0; v < sp_dragon_part_get(d, tail)->character->rig.vertex_count; ++v) {
        sp_vec2 q = sp_camera_project(&cam, (sp_vec3){x[3 * v], x[3 * v + 1], x[3 * v + 2]});
        if (v == 0 || out * (q.x - tips[1].x) > 0) tips[1] = q;
    }
    fprintf(stderr, "  the tip: drawn at (%.0f, %.0f), shown at (%.0f, %.0f)\n", tips[0].x, tips[0].y, tips[1].x, tips[1].y);
    for (int i = 0; i < 2; ++i) {
        // A zigzag outline out of the tip.
        sp_vec2 flame[60];
        for (int k = 0; k < 60; ++k) {
            double u = k < 30 ? k / 29.0 : (59 - k) / 29.0, zig = 12 * fabs(fmod(4 * u, 1.0) - 0.5);
            flame[k] = (sp_vec2){tips[i].x + out * (4 + 110 * u), tips[i].y + (k < 30 ? -1 : 1) * (8 + 22 * sin(M_PI * u) + zig)};
        }
        ENSURE(sp_dragon_add_points(d, flame, 60, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  the flame at the tip %s: %s\n", i ? "as shown" : "as drawn", sp_dragon_reject_name(res.reason));
        ENSURE(res.reason == SP_DRAGON_DETAIL && res.detail == 0);
        sp_dragon_detail e;
        ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK && sp_dragon_detail_get(d, 0, &e) && e.part == tail && e.point_count == 60);
        double worst = 0;
        for (int k = 0; k < e.point_count; ++k)
            worst = fmax(worst, sp_v2_len(sp_v2_sub(ink_px(d, 0, k), flame[k])));
        fprintf(stderr, "  at t = 0 its ink lies within %.2f px of its stroke\n", worst);
        ENSURE(worst < 0.5);
        ENSURE(sp_dragon_undo(d) && sp_dragon_detail_count(d) == 0);
    }
    free(xy);
    for (int k = 0; k < 6; ++k)
        free(s6[k]);
    sp_dragon_destroy(d);
}

// A zigzag of spikes (n points) over the top (or, below, under the bottom)
// of a body's stroke (body: nb points) from x0 to x1, its teeth `tall` px.
static int spikes_along(const sp_vec2* body, int nb, double x0, double x1, double tall, bool below, sp_vec2* out, int cap)
{
    int n = 0;
    for (double x = x0; x <= x1 && n < cap; x += 4) {
        double edge = below ? -INFINITY : INFINITY;
        for (int k = 0; k < nb; ++k)
            if (fabs(body[k].x - x) < 6) edge = below ? fmax(edge, body[k].y) : fmin(edge, body[k].y);
        if (!isfinite(edge)) continue;
        double ph = fmod(x - x0, 28) / 28, h = 2 + tall * (1 - fabs(2 * ph - 1));
        out[n++] = (sp_vec2){x, below ? edge + h : edge - h};
    }
    return n;
}

// Spikes drawn along a body's back are a detail of the body, kept as ink
// whose points off the mesh are each carried by the vertex nearest them.
// Before, the zigzag became a thin tail lying on the back, and low teeth
// a pair of legs standing on it. The README's
// dragon (docs/img/kiosk_detail.json: its body and head). The same zigzag
// under the belly, far above the back, only a few teeth long or closed
// into a loop is not.
static void test_spikes_on_the_back(void)
{
    const char* path = real_db();
    sp_error err = {0};
    sp_dragon_result res;
    sp_vec2* s6[8];
    int n6[8], count = 6, body, head;
    sp_dragon* d = readme_dragon(path, s6, n6, &body, &head);
    (void)head;
    sp_vec2 sp[128];
    int n = spikes_along(s6[0], n6[0], 430, 720, 22, false, sp, 128);
    ENSURE(n > 60);
    ENSURE(sp_dragon_add_points(d, sp, n, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  spikes along the back: %s, %.1f ms (pen-up to ink)\n", sp_dragon_reject_name(res.reason), res.ms_total);
    ENSURE(res.rejected && res.reason == SP_DRAGON_DETAIL && res.detail == 0 && res.guess_count > 0);
    sp_dragon_detail e;
    ENSURE(sp_dragon_pose_at(d, 0, &err) == SP_OK && sp_dragon_detail_get(d, 0, &e) && e.part == body && e.xyz);
    int air = 0;
    double off = 0;
    for (int k = 0; k < e.point_count; ++k) {
        air += e.normal[3 * k] == 0 && e.normal[3 * k + 1] == 0 && e.normal[3 * k + 2] == 0;
        off = fmax(off, sp_v2_len(sp_v2_sub(ink_px(d, 0, k), sp[k])));
    }
    fprintf(stderr, "  %d of %d points in the air, at t = 0 each within %.1f px of where it was drawn\n", air, e.point_count,
            off);
    ENSURE(e.point_count == n && air >= n / 3 && off < 6);
    // Over the loop each point in the air moves as the body's vertex nearest it.
    double period = sp_dragon_period(d), worst = 0;
    sp_camera cam = sp_dragon_camera(d);
    int near_v[128];
    sp_vec2 ink0[128], vtx0[128];
    for (int k = 0; k < n; ++k) {
        near_v[k] = nearest_vertex(d, body, e.xyz + 3 * k);
        const double* v = sp_dragon_part_xyz(d, body) + 3 * near_v[k];
        ink0[k] = ink_px(d, 0, k), vtx0[k] = sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]});
    }
    for (int step = 1; step <= 4; ++step) {
        ENSURE(sp_dragon_pose_at(d, step * period / 5, &err) == SP_OK);
        for (int k = 0; k < n; ++k) {
            const double* v = sp_dragon_part_xyz(d, body) + 3 * near_v[k];
            sp_vec2 dv = sp_v2_sub(sp_camera_project(&cam, (sp_vec3){v[0], v[1], v[2]}), vtx0[k]);
            worst = fmax(worst, sp_v2_len(sp_v2_sub(sp_v2_sub(ink_px(d, 0, k), ink0[k]), dv)));
        }
    }
    fprintf(stderr, "  over the loop each point within %.2f px of its nearest vertex's motion\n", worst);
    ENSURE(worst < 2.5);
    worst = ink_played_back(d, "dragon_spikes.glb", 1, (const int[]){0});
    fprintf(stderr, "  the exported spikes played back vs pose_at: %.2g world units\n", worst);
    ENSURE(worst < 0.5 * 2.0 / 800);
    ENSURE(sp_dragon_undo(d) && sp_dragon_detail_count(d) == 0);
    // Low teeth (a review: 15-20 px high) lie on the body's own spikes in
    // its mesh, few of their points off it: still ink along the back.
    for (double tall = 12; tall <= 16; tall += 4) {
        n = spikes_along(s6[0], n6[0], 430, 720, tall, false, sp, 128);
        ENSURE(sp_dragon_add_points(d, sp, n, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  spikes %.0f px high along the back: %s\n", tall, sp_dragon_reject_name(res.reason));
        ENSURE(res.reason == SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 1);
        ENSURE(sp_dragon_undo(d) && sp_dragon_detail_count(d) == 0);
    }
    // Not along the back: under the belly (legs drawn short reach down there), 60 px above it, three teeth.
    const struct {
        const char* what;
        double x1, lift;
        bool below;
    } no[3] = {{"under the belly", 720, 0, true}, {"60 px above the back", 720, 60, false}, {"three teeth", 514, 0, false}};
    for (int c = 0; c < 3; ++c) {
        n = spikes_along(s6[0], n6[0], 430, no[c].x1, 22, no[c].below, sp, 128);
        for (int k = 0; k < n; ++k)
            sp[k].y -= no[c].lift;
        ENSURE(sp_dragon_add_points(d, sp, n, NULL, &res, &err) == SP_OK);
        fprintf(stderr, "  spikes %s: %s\n", no[c].what, sp_dragon_reject_name(res.reason));
        ENSURE(res.reason != SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 0);
        if (!res.rejected) ENSURE(sp_dragon_undo(d));
    }
    // Nor a closed shape on the back's edge (a part drawn there): the spikes
    // closed by a line back through them to where they began.
    sp_vec2 closed[256];
    n = spikes_along(s6[0], n6[0], 430, 720, 22, false, closed, 128);
    int back = spikes_along(s6[0], n6[0], 430, 720, 0, false, closed + n, 128);
    for (int k = 0; k < back / 2; ++k) { // reversed: from the last tooth back to the first
        sp_vec2 t = closed[n + k];
        closed[n + k] = closed[n + back - 1 - k], closed[n + back - 1 - k] = t;
    }
    for (int k = 0; k < back; ++k) // through the teeth, off the back (or it would lie on the mesh)
        closed[n + k].y -= 12;
    ENSURE(sp_dragon_add_points(d, closed, n + back, NULL, &res, &err) == SP_OK);
    fprintf(stderr, "  the spikes closed into a loop: %s\n", sp_dragon_reject_name(res.reason));
    ENSURE(res.reason != SP_DRAGON_DETAIL && sp_dragon_detail_count(d) == 0);
    for (int k = 0; k < count; ++k)
        free(s6[k]);
    sp_dragon_destroy(d);
}

// ------------------------------------------------------------ a day at the kiosk, at random

// One of the shapes visitors draw (a blob, a body, a line, spikes, a leg
// pair, an eye, wings, a scribble, a circle), or a stroke no finger makes (a tap,
// NaN, a point far off, a point repeated), at centre c, size `size` px,
// turned by `turn`; returns the point count. *nan: it holds a NaN.
static int storm_shape(sp_test_rng* r, sp_vec2 c, double size, double turn, sp_vec2* out, int cap, bool* nan)
{
    *nan = false;
    int kind = (int)(sp_test_uniform(r) * 10), n = 0;
    double ct = cos(turn), st = sin(turn), h = 0.5 * size;
    for (int i = 0; i < cap; ++i) {
        double u = (double)i / (cap - 1), a = 2 * PI * u, x, y;
        switch (kind) {
        case 0: // a blob
            x = h * cos(a) * (1 + 0.15 * sin(5 * a)), y = 0.6 * h * sin(a);
            break;
        case 1: // a humped body
            x = h * cos(a), y = 0.4 * h * sin(a) - (sin(a) > 0 ? 0.3 * h * sin(a) : 0);
            break;
        case 2: // a wavy line
            x = h * (2 * u - 1), y = 0.15 * h * sin(3 * a);
            break;
        case 3: // spikes
            x = h * (2 * u - 1), y = (i % 6 < 3 ? 0.2 : -0.2) * h;
            break;
        case 4: // a leg pair
            x = h * (2 * u - 1), y = h * fabs(sin(2 * a)) - 0.5 * h;
            break;
        case 5: // an eye
            x = 0.08 * h * cos(a), y = 0.08 * h * sin(a);
            break;
        case 6: // wings
            x = h * cos(0.5 * a), y = -h * sin(0.5 * a) * (1 + 0.2 * fabs(sin(4 * a)));
            break;
        case 7: // a scribble
            x = h * sp_test_range(r, -1, 1), y = h * sp_test_range(r, -1, 1);
            break;
        default: // a circle
            x = h * cos(a), y = h * sin(a);
            break;
        }
        out[n++] = (sp_vec2){c.x + ct * x - st * y, c.y + st * x + ct * y};
    }
    double bad = sp_test_uniform(r);
    if (bad < 0.03) return 2; // a tap
    if (bad < 0.05)
        out[n / 2] = (sp_vec2){NAN, out[n / 2].y}, *nan = true; // NaN
    else if (bad < 0.07)
        out[n / 3] = (sp_vec2){1e12, -1e12}; // far off
    else if (bad < 0.09)
        for (int i = 0; i < n; ++i)
            out[i] = out[0]; // one point, repeated
    return n;
}

// Every part and its ink posed finite, attachments only to bodies.
static void storm_check(sp_dragon* d, double t)
{
    sp_error err = {0};
    int n = sp_dragon_part_count(d), nd = sp_dragon_detail_count(d);
    ENSURE(n >= 0 && n <= 48 && nd >= 0 && nd <= SP_DRAGON_MAX_DETAILS);
    for (int i = 0; i < n; ++i) {
        const sp_dragon_part* p = sp_dragon_part_get(d, i);
        ENSURE(p && p->attached_to >= -1 && p->attached_to < n && p->attached_to != i);
        if (p->attached_to >= 0) ENSURE(sp_dragon_part_get(d, p->attached_to)->is_torso && !p->is_torso);
        for (int k = 0; k < p->character->rig.param_count; ++k)
            ENSURE(isfinite(p->params[k]));
    }
    ENSURE(sp_dragon_pose_at(d, t, &err) == SP_OK);
    for (int i = 0; i < n; ++i) {
        const double* x = sp_dragon_part_xyz(d, i);
        int nv = sp_dragon_part_get(d, i)->character->rig.vertex_count;
        for (int k = 0; k < 3 * nv; ++k)
            ENSURE(isfinite(x[k]));
    }
    sp_dragon_detail e;
    for (int i = 0; i < nd; ++i) {
        ENSURE(sp_dragon_detail_get(d, i, &e) && e.part >= 0 && e.part < n);
        for (int k = 0; e.xyz && k < 3 * e.point_count; ++k)
            ENSURE(isfinite(e.xyz[k]));
    }
}

// A kiosk's day in fast motion: strokes of every kind drawn anywhere, on
// parts and beside them, chips (a forced category, a Redraw, a detail made a
// part), Undo, Start over, the animation posed at random times, a report
// and an export. The pipeline never fails, never poses a NaN, and hangs
// parts only on bodies. SP_STORM_OPS and SP_STORM_SEED run it longer by hand.
static void test_scene_storm(void)
{
    const char* path = real_db();
    const char* env_ops = getenv("SP_STORM_OPS");
    const char* env_seed = getenv("SP_STORM_SEED");
    int ops = env_ops ? atoi(env_ops) : 240;
    sp_test_rng r = {env_seed ? strtoull(env_seed, NULL, 10) : 7};
    sp_error err = {0};
    sp_dragon* d = NULL;
    ENSURE(sp_dragon_create(&(sp_dragon_desc){.db_path = path, .canvas_w = 1280, .canvas_h = 800, .solve = k_uncapped}, &d,
                            &err) == SP_OK);
    static const char* const cats[] = {"torso", "head", "wings", "tail", "front_legs", "hind_legs", "no_such_part"};
    enum { CAP = 96 };
    sp_vec2 pts[CAP];
    int added = 0, details = 0, refused = 0, attached = 0, undos = 0, refits = 0;
    for (int op = 0; op < ops; ++op) {
        double u = sp_test_uniform(&r);
        sp_dragon_result res;
        int n = sp_dragon_part_count(d);
        if (u < 0.72) { // a stroke: anywhere, or at a part already there
            sp_vec2 c = {sp_test_range(&r, 0, 1280), sp_test_range(&r, 0, 800)};
            if (n > 0 && sp_test_uniform(&r) < 0.6) {
                const sp_dragon_part* p = sp_dragon_part_get(d, (int)(sp_test_uniform(&r) * n));
                if (p->stroke_points > 0) c = p->stroke_xy[(int)(sp_test_uniform(&r) * p->stroke_points)];
            }
            bool nan;
            int m = storm_shape(&r, c, sp_test_range(&r, 15, 700), sp_test_range(&r, -PI, PI), pts, CAP, &nan);
            double w = sp_test_uniform(&r);
            sp_dragon_stroke_opts o = {.category = w < 0.12 ? cats[(int)(sp_test_uniform(&r) * 7)] : NULL,
                                       .replace_last = w > 0.9,
                                       .replace_detail = w < 0.04};
            sp_result rc = sp_dragon_add_points(d, pts, m, &o, &res, &err);
            ENSURE(rc == (nan ? SP_ERR_INVALID : SP_OK)); // a NaN is refused as bad input, nothing changes
            if (rc != SP_OK) continue;
            added += !res.rejected, refused += res.rejected && res.reason != SP_DRAGON_DETAIL;
            details += res.reason == SP_DRAGON_DETAIL;
            if (!res.rejected) attached += sp_dragon_part_get(d, res.part)->attached_to >= 0;
        } else if (u < 0.82) {
            undos += sp_dragon_undo(d);
        } else if (u < 0.92) { // a chip: the last part as another
            sp_result rc = sp_dragon_refit_last(d, cats[(int)(sp_test_uniform(&r) * 7)], &res, &err);
            ENSURE(rc == SP_OK || n == 0);
            refits += rc == SP_OK && !res.rejected;
        } else if (u < 0.94) {
            sp_dragon_clear(d);
        } else if (u < 0.97) {
            char* json = NULL;
            ENSURE(sp_dragon_report_json(d, &json, &err) == SP_OK && json);
            cJSON* doc = cJSON_Parse(json);
            ENSURE(doc);
            cJSON_Delete(doc);
            free(json);
        }
        storm_check(d, sp_test_range(&r, 0, 2 * fmax(1, sp_dragon_period(d))));
    }
    if (sp_dragon_part_count(d) > 0) ENSURE(sp_dragon_export(d, sp_test_tmp_path("storm.glb"), &err) == SP_OK);
    fprintf(
        stderr,
        "  %d operations: %d parts added (%d attached), %d details, %d refused, %d undos, %d chips; %d parts, %d details left\n",
        ops, added, attached, details, refused, undos, refits, sp_dragon_part_count(d), sp_dragon_detail_count(d));
    // The storm went everywhere a visit goes.
    if (!env_ops) ENSURE(added > 40 && attached > 5 && details > 3 && refused > 5 && undos > 5 && refits > 5);
    sp_dragon_destroy(d);
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"build_and_attach", test_build_and_attach},
                                   {"animation", test_animation},
                                   {"export", test_export},
                                   {"rejects_and_bad_strokes", test_rejects_and_bad_strokes},
                                   {"corrupt_part", test_corrupt_part},
                                   {"no_model", test_no_model},
                                   {"undo_clear_refit", test_undo_clear_refit},
                                   {"live_update", test_live_update},
                                   {"reload_keeps_model", test_reload_keeps_model},
                                   {"background_model", test_background_model},
                                   {"background_read_fails", test_background_read_fails},
                                   {"background_replaced", test_background_replaced},
                                   {"open_race", test_open_race},
                                   {"command", test_command},
                                   {"command_stroke_lines", test_command_stroke_lines},
                                   {"six_real_parts", test_six_real_parts},
                                   {"many_parts", test_many_parts},
                                   {"body_last_and_undo", test_body_last_and_undo},
                                   {"robustness", test_robustness},
                                   {"visitors_policy", test_visitors_policy},
                                   {"line_drawn", test_line_drawn},
                                   {"leg_drawn_as_one_line", test_leg_drawn_as_one_line},
                                   {"on_body_as_drawn", test_on_body_as_drawn},
                                   {"facing_follows_dragon", test_facing_follows_dragon},
                                   {"head_first_faces_as_after", test_head_first_faces_as_after},
                                   {"mirror_refusal", test_mirror_refusal},
                                   {"polygon_refusal", test_polygon_refusal},
                                   {"shaky_hand", test_shaky_hand},
                                   {"own_symmetry", test_own_symmetry},
                                   {"colouring_in", test_colouring_in},
                                   {"guess_without_part", test_guess_without_part},
                                   {"family_by_place", test_family_by_place},
                                   {"drawn_on_body", test_drawn_on_body},
                                   {"body_with_a_part_stays", test_body_with_a_part_stays},
                                   {"decorations_on_the_body", test_decorations_on_the_body},
                                   {"gone_over_twice", test_gone_over_twice},
                                   {"ink_follows_its_part", test_ink_follows_its_part},
                                   {"root_at_the_body", test_root_at_the_body},
                                   {"reaches_the_body", test_reaches_the_body},
                                   {"on_the_back_not_a_spike", test_on_the_back_not_a_spike},
                                   {"body_round_a_dragon", test_body_round_a_dragon},
                                   {"wing_leaning_forward", test_wing_leaning_forward},
                                   {"facing_of_a_rising_body", test_facing_of_a_rising_body},
                                   {"foot_either_way", test_foot_either_way},
                                   {"parts_before_body", test_parts_before_body},
                                   {"details_on_parts", test_details_on_parts},
                                   {"flourishes_off_parts", test_flourishes_off_parts},
                                   {"flourish_on_line_tail", test_flourish_on_line_tail},
                                   {"scene_storm", test_scene_storm},
                                   {"spikes_on_the_back", test_spikes_on_the_back},
                                   {0}});
}
