// drawn.c: the parts as other hands designed them (sp_db_drawn_sketches in
// sp/partdb.h): hand-placed control points in assets/sketches/drawings.json,
// each design drawn (once in the default recipe) by the project's hand-drawing
// model.
//
// The concept grammar (concept.c) is one author's idea of each part, however
// many seeds it takes; these are many people's ideas, one design each. They
// are made by makers who never saw the visitors' evaluation set
// (tests/data/visitors), and the file is drawn by sp/handdraw.h, not by the
// evaluation's own pen model.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "db_internal.h"
#include "sp/concept.h"
#include "sp/handdraw.h"
#include "sp/synth.h"

#define DRAWN_MAX_POINTS 256 // control points of one design
#define DRAWN_PATH_CAP 4096  // its sampled path
#define DRAWN_SAMPLES_SEG 8  // path points per control-point span

typedef struct drawn_path {
    sp_vec2 p[DRAWN_PATH_CAP];
    int n;
} drawn_path;

static void path_put(drawn_path* P, sp_vec2 v)
{
    if (P->n < DRAWN_PATH_CAP) P->p[P->n++] = v;
}

// Centripetal Catmull-Rom through c[0..n-1] (a run between corners), c[0]
// excluded, so that runs join at their shared corner point.
static void run_spline(drawn_path* P, const sp_vec2* c, int n)
{
    for (int i = 0; i + 1 < n; ++i) {
        sp_vec2 p1 = c[i], p2 = c[i + 1];
        // Phantom ends mirror the neighbour, so a run's ends leave along their chord.
        sp_vec2 p0 = i > 0 ? c[i - 1] : (sp_vec2){2 * p1.x - p2.x, 2 * p1.y - p2.y};
        sp_vec2 p3 = i + 2 < n ? c[i + 2] : (sp_vec2){2 * p2.x - p1.x, 2 * p2.y - p1.y};
        double t0 = 0, t1 = t0 + sqrt(fmax(hypot(p1.x - p0.x, p1.y - p0.y), 1e-6));
        double t2 = t1 + sqrt(fmax(hypot(p2.x - p1.x, p2.y - p1.y), 1e-6));
        double t3 = t2 + sqrt(fmax(hypot(p3.x - p2.x, p3.y - p2.y), 1e-6));
        for (int k = 1; k <= DRAWN_SAMPLES_SEG; ++k) {
            double t = t1 + (t2 - t1) * k / DRAWN_SAMPLES_SEG;
            sp_vec2 q[7];
            const sp_vec2* pts[4] = {&p0, &p1, &p2, &p3};
            const double ts[4] = {t0, t1, t2, t3};
            // Barry-Goldman pyramid.
            for (int j = 0; j < 3; ++j) {
                double w = (t - ts[j]) / (ts[j + 1] - ts[j]);
                q[j] = (sp_vec2){pts[j]->x + (pts[j + 1]->x - pts[j]->x) * w, pts[j]->y + (pts[j + 1]->y - pts[j]->y) * w};
            }
            for (int j = 0; j < 2; ++j) {
                double w = (t - ts[j]) / (ts[j + 2] - ts[j]);
                q[3 + j] = (sp_vec2){q[j].x + (q[j + 1].x - q[j].x) * w, q[j].y + (q[j + 1].y - q[j].y) * w};
            }
            double w = (t - t1) / (t2 - t1);
            q[5] = (sp_vec2){q[3].x + (q[4].x - q[3].x) * w, q[3].y + (q[4].y - q[3].y) * w};
            path_put(P, q[5]);
        }
    }
}

// The design's clean stroke, varied by `rng`: every control point moved a
// little (no two hands place them alike), stretched, mirrored, tilted, and
// scaled and centred as a concept sketch is.
static sp_result drawn_clean(const sp_vec2* ctrl, int n, bool closed, sp_rng* rng, sp_sketch* out)
{
    sp_vec2 c[DRAWN_MAX_POINTS + 1];
    double sx = sp_rng_range(rng, 0.85, 1.18), jitter = 1.2;
    for (int i = 0; i < n; ++i) {
        // A corner (a point written twice) moves as one point.
        bool twin = i > 0 && ctrl[i].x == ctrl[i - 1].x && ctrl[i].y == ctrl[i - 1].y;
        c[i] =
            twin ? c[i - 1] : (sp_vec2){(ctrl[i].x + jitter * sp_rng_normal(rng)) * sx, ctrl[i].y + jitter * sp_rng_normal(rng)};
    }
    // A closed design ends on its first point exactly: the hand-drawing model closes only such curves.
    if (closed) c[n++] = c[0];
    drawn_path P = {.n = 0};
    path_put(&P, c[0]);
    int b = 0;
    for (int i = 1; i <= n; ++i) {
        bool corner = i < n && c[i].x == c[i - 1].x && c[i].y == c[i - 1].y;
        if (i == n || corner) {
            run_spline(&P, c + b, i - b);
            b = i;
        }
    }
    double mirror = sp_rng_uniform(rng) < 0.5 ? -1 : 1, turn = sp_rng_range(rng, -0.3, 0.3);
    return sp_concept_place(P.p, P.n, mirror, turn, out, NULL);
}

static sp_result design_wants(const char* path, int index, sp_error* err)
{
    return sp_fail(
        err, SP_ERR_PARSE,
        "%s: drawing %d: wants \"name\", \"label\", \"points\" (2 to %d [x, y] in a 100 x 100 box) and \"closed\" true or false",
        path, index + 1, DRAWN_MAX_POINTS);
}

// Design `d`'s control points, checked (its label was, with the others', by
// db_dataset_labels); the error names the file and the design.
static sp_result read_design(const char* path, int index, const cJSON* d, sp_vec2* ctrl, int* n, bool* closed, const char** label,
                             sp_error* err)
{
    const cJSON* pts = cJSON_GetObjectItemCaseSensitive(d, "points");
    const cJSON* cl = cJSON_GetObjectItemCaseSensitive(d, "closed");
    *label = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(d, "label"));
    const char* name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(d, "name"));
    int m = cJSON_GetArraySize(pts);
    if (!name || !cJSON_IsArray(pts) || m < 2 || m > DRAWN_MAX_POINTS || (cl && !cJSON_IsBool(cl)))
        return design_wants(path, index, err);
    *closed = cJSON_IsTrue(cl);
    *n = 0;
    const cJSON* p;
    cJSON_ArrayForEach(p, pts)
    {
        const cJSON* x = cJSON_GetArrayItem(p, 0);
        const cJSON* y = cJSON_GetArrayItem(p, 1);
        if (cJSON_GetArraySize(p) != 2 || !cJSON_IsNumber(x) || !cJSON_IsNumber(y) || !(fabs(x->valuedouble) <= 1000) ||
            !(fabs(y->valuedouble) <= 1000))
            return sp_fail(err, SP_ERR_PARSE, "%s: drawing \"%s\": point %d is not [x, y] within +-1000", path, name, *n + 1);
        ctrl[(*n)++] = (sp_vec2){x->valuedouble, y->valuedouble};
    }
    return SP_OK;
}

sp_result sp_db_drawn_sketches(const char* assets_dir, int per_design, uint64_t family, sp_dataset* out, int* designs,
                               sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (designs) *designs = 0;
    char path[2048];
    snprintf(path, sizeof path, "%s/sketches/drawings.json", assets_dir);
    struct stat st;
    if (per_design <= 0 || stat(path, &st) != 0) return SP_OK; // an assets folder without designs
    cJSON* root;
    sp_result r = db_read_json(path, &root, err);
    if (r != SP_OK) return r;
    const cJSON* list = cJSON_GetObjectItemCaseSensitive(root, "drawings");
    if (!cJSON_IsArray(list)) {
        cJSON_Delete(root);
        return sp_fail(err, SP_ERR_PARSE, "%s: not a drawings file (want {\"drawings\": [...]})", path);
    }
    // Categories sorted, as a labelled folder would give them; designs in the file's order.
    sp_dataset ds;
    int bad = 0;
    r = db_dataset_labels(list, "label", &ds, &bad, err);
    if (r == SP_ERR_PARSE) design_wants(path, bad, err);
    sp_vec2* ctrl = malloc(DRAWN_MAX_POINTS * sizeof *ctrl);
    if (!ctrl && r == SP_OK) r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    const cJSON* d;
    int index = 0, *per_cat = calloc((size_t)(ds.category_count ? ds.category_count : 1), sizeof *per_cat);
    if (!per_cat && r == SP_OK) r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    cJSON_ArrayForEach(d, list)
    {
        if (r != SP_OK) break;
        int n = 0;
        bool closed = false;
        const char* label = NULL;
        if ((r = read_design(path, index, d, ctrl, &n, &closed, &label, err)) != SP_OK) break;
        int k = 0;
        while (strcmp(ds.categories[k], label) != 0)
            ++k;
        // Each design's draws come from its own seed: adding a design leaves the others' sketches as they were.
        const char* name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(d, "name"));
        uint64_t base = sp_handdraw_part_family(family, name);
        for (int j = 0; r == SP_OK && j < per_design; ++j) {
            uint64_t seed = sp_handdraw_seed(base, j);
            sp_rng rng = {seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull};
            sp_sketch clean;
            if ((r = drawn_clean(ctrl, n, closed, &rng, &clean)) != SP_OK) {
                if (r == SP_ERR_NO_MEMORY)
                    sp_fail(err, r, "%s: out of memory", path);
                else
                    sp_fail(err, r, "%s: drawing \"%s\": its points have no extent", path, name);
                break;
            }
            sp_sample smp = {.label = k, .index = per_cat[k]++};
            sp_error why = {0};
            if ((r = sp_concept_draw(&clean, seed, &smp.sketch, &why)) != SP_OK)
                sp_fail(err, r, "%s: drawing \"%s\": %s", path, name, why.text);
            sp_sketch_free(&clean);
            if (r == SP_OK && sp_dataset_add_sample(&ds, &smp) != SP_OK) {
                sp_sketch_free(&smp.sketch);
                r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
            }
        }
        ++index;
    }
    free(per_cat);
    free(ctrl);
    cJSON_Delete(root);
    if (r != SP_OK)
        sp_dataset_free(&ds);
    else {
        *out = ds;
        if (designs) *designs = index;
    }
    return r;
}
