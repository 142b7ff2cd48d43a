// dragon_parts.c: the six dragon parts (assets or stand-ins) and the
// dragon-part evaluation sets; see dragon_parts.h.
#include "dragon_parts.h"

#include "fixtures.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

const char* const k_dragon_part_names[DRAGON_PART_COUNT] = {"front_legs", "head", "hind_legs", "tail", "torso", "wings"};

// Outlines in x right, y up; joints as a chain (x, y).
typedef struct standin_shape {
    int points;
    const double (*xy)[2];
    int joints;
    const double (*jt)[2];
} standin_shape;

static const double k_front_legs_xy[][2] = {{-0.25, 0.1},   {0.25, 0.1},   {0.25, -0.6},  {0.1, -1.25}, {0.45, -1.35},
                                            {0.55, -1.52},  {0.3, -1.45},  {0.35, -1.62}, {0.1, -1.5},  {0.08, -1.65},
                                            {-0.15, -1.45}, {-0.2, -1.25}, {-0.1, -0.7},  {-0.25, -0.6}};
static const double k_front_legs_jt[][2] = {{0, 0}, {0.05, -0.65}, {-0.05, -1.3}, {0.3, -1.45}};
static const double k_head_xy[][2] = {{-0.9, -0.3}, {-0.9, 0.3},  {-0.55, 0.45}, {-0.45, 0.95}, {-0.2, 0.5},
                                      {0.2, 0.45},  {0.6, 0.3},   {1.1, 0.15},   {1.2, 0.0},    {1.1, -0.1},
                                      {0.6, -0.15}, {0.9, -0.35}, {0.3, -0.45},  {-0.3, -0.45}};
static const double k_head_jt[][2] = {{-0.8, 0}, {0, 0}, {0.8, -0.05}};
static const double k_hind_legs_xy[][2] = {{-0.4, 0.15}, {0.3, 0.2},   {0.55, -0.4},  {0.5, -0.7},   {0.0, -1.1},  {0.1, -1.35},
                                           {0.45, -1.4}, {0.5, -1.55}, {0.3, -1.5},   {0.35, -1.66}, {0.1, -1.58}, {0.1, -1.72},
                                           {-0.2, -1.5}, {-0.3, -1.1}, {0.15, -0.65}, {-0.45, -0.3}};
static const double k_hind_legs_jt[][2] = {{0, 0}, {0.35, -0.6}, {-0.1, -1.1}, {0.2, -1.5}};
static const double k_tail_xy[][2] = {{0, 0.25},    {0.6, 0.2},  {1.2, 0.13},   {1.8, 0.08},  {2.1, 0.05},
                                      {2.15, 0.28}, {2.65, 0},   {2.15, -0.28}, {2.1, -0.05}, {1.8, -0.08},
                                      {1.2, -0.13}, {0.6, -0.2}, {0, -0.25}};
static const double k_tail_jt[][2] = {{0, 0}, {0.6, 0}, {1.2, 0}, {1.8, 0}, {2.3, 0}};
static const double k_torso_xy[][2] = {{-1.3, 0.15}, {-0.9, 0.35},  {-0.3, 0.5},  {0.3, 0.5},   {0.8, 0.4},
                                       {1.2, 0.3},   {1.5, 0.25},   {1.5, 0.05},  {1.1, -0.15}, {0.6, -0.45},
                                       {0, -0.55},   {-0.6, -0.45}, {-1.0, -0.2}, {-1.3, -0.05}};
static const double k_torso_jt[][2] = {{-1.0, 0}, {0, 0}, {1.0, 0.1}};
static const double k_wings_xy[][2] = {{0, 0},      {0.4, 0.45},  {0.8, 0.7},  {1.2, 0.95},  {1.7, 1.1},
                                       {1.55, 0.6}, {1.8, 0.2},   {1.3, 0.25}, {1.35, -0.3}, {0.9, -0.05},
                                       {0.7, -0.5}, {0.35, -0.1}, {0.1, -0.3}};
static const double k_wings_jt[][2] = {{0, 0}, {0.8, 0.6}, {1.5, 0.9}};

#define STANDIN(a, b)                                                                                                            \
    {                                                                                                                            \
        (int)(sizeof a / sizeof a[0]), a, (int)(sizeof b / sizeof b[0]), b                                                       \
    }
static const standin_shape k_standins[DRAGON_PART_COUNT] = {
    STANDIN(k_front_legs_xy, k_front_legs_jt), STANDIN(k_head_xy, k_head_jt),
    STANDIN(k_hind_legs_xy, k_hind_legs_jt),   STANDIN(k_tail_xy, k_tail_jt),
    STANDIN(k_torso_xy, k_torso_jt),           STANDIN(k_wings_xy, k_wings_jt)};
#undef STANDIN

// The bone (segment jt[b] -> jt[b+1]) nearest to p.
static int standin_bone(const standin_shape* s, double x, double y)
{
    int best = 0;
    double bd = 1e300;
    for (int b = 0; b + 1 < s->joints; ++b) {
        double ax = s->jt[b][0], ay = s->jt[b][1], dx = s->jt[b + 1][0] - ax, dy = s->jt[b + 1][1] - ay;
        double t = ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy);
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double ex = ax + t * dx - x, ey = ay + t * dy - y, d = ex * ex + ey * ey;
        if (d < bd) bd = d, best = b;
    }
    return best;
}

// Stand-in part i (0..5) as a character with an `outline` abstraction (asserts on failure).
void dragon_standin(int i, dragon_part* out)
{
    const standin_shape* s = &k_standins[i];
    const int per = 8; // outline points per polygon edge
    int np = s->points * per;
    sp_rig rig = {0};
    rig.joint_count = s->joints;
    rig.joints = calloc((size_t)s->joints, sizeof(sp_joint));
    for (int j = 0; j < s->joints; ++j) {
        sp_joint* jt = &rig.joints[j];
        snprintf(jt->name, sizeof jt->name, "%s_%d", k_dragon_part_names[i], j);
        jt->parent = j - 1;
        double px = j ? s->jt[j - 1][0] : 0, py = j ? s->jt[j - 1][1] : 0;
        jt->rest_t = sp_v3(s->jt[j][0] - px, s->jt[j][1] - py, 0);
        jt->rest_r = sp_quat_identity();
        jt->rest_s = sp_v3(1, 1, 1);
        sp_mat4 world = sp_mat4_trs(sp_v3(s->jt[j][0], s->jt[j][1], 0), sp_quat_identity(), sp_v3(1, 1, 1));
        sp_mat4_inverse(&world, &jt->inverse_bind);
        sp_rig_add_param(&rig, j, SP_CH_RZ, j ? -0.5 : -0.25, j ? 0.5 : 0.25, SP_GROUP_POSE);
        if (j == 0) {
            sp_rig_add_param(&rig, j, SP_CH_SX, 0.85, 1.2, SP_GROUP_SHAPE);
            sp_rig_add_param(&rig, j, SP_CH_S, 0.8, 1.25, SP_GROUP_SHAPE);
        }
    }
    // Mesh: the outline points and a centre, as a fan; abstraction: the outline, closed.
    rig.vertex_count = np + 1;
    rig.rest = calloc((size_t)(np + 1) * 3, sizeof(double));
    rig.joints4 = calloc((size_t)(np + 1) * 4, sizeof(uint16_t));
    rig.weights4 = calloc((size_t)(np + 1) * 4, sizeof(float));
    rig.triangle_count = np;
    rig.triangles = malloc(sizeof(uint32_t) * 3 * (size_t)np);
    sp_abstraction ab = sp_fixture_outline(np);
    double cx = 0, cy = 0;
    for (int k = 0; k < np; ++k) {
        int e = k / per;
        double f = (double)(k % per) / per;
        const double* a = s->xy[e];
        const double* b = s->xy[(e + 1) % s->points];
        double x = a[0] + f * (b[0] - a[0]), y = a[1] + f * (b[1] - a[1]);
        int bone = standin_bone(s, x, y);
        ab.rest[3 * k] = rig.rest[3 * k] = x;
        ab.rest[3 * k + 1] = rig.rest[3 * k + 1] = y;
        ab.joints[4 * k] = rig.joints4[4 * k] = (uint16_t)bone;
        ab.weights[4 * k] = rig.weights4[4 * k] = 1.0f;
        cx += x / np;
        cy += y / np;
        rig.triangles[3 * k] = (uint32_t)np;
        rig.triangles[3 * k + 1] = (uint32_t)k;
        rig.triangles[3 * k + 2] = (uint32_t)((k + 1) % np);
    }
    rig.rest[3 * np] = cx;
    rig.rest[3 * np + 1] = cy;
    rig.weights4[4 * np] = 1.0f;
    rig.abstraction_count = 1;
    rig.abstractions = malloc(sizeof(sp_abstraction));
    rig.abstractions[0] = ab;
    sp_error err = {0};
    DRAGON_CHECK(sp_rig_finalize(&rig, "stand-in", NULL, &err) == SP_OK);
    memset(out, 0, sizeof *out);
    DRAGON_CHECK(sp_character_from_rig(&rig, &out->ch, &err) == SP_OK);
    out->ch.has_part = true;
    snprintf(out->ch.part.category, sizeof out->ch.part.category, "%s", k_dragon_part_names[i]);
    snprintf(out->ch.part.abstraction, sizeof out->ch.part.abstraction, "outline");
    snprintf(out->name, sizeof out->name, "%s", k_dragon_part_names[i]);
    snprintf(out->category, sizeof out->category, "%s", k_dragon_part_names[i]);
    out->abstraction = 0;
}

// Fills parts[6] from assets/ when all six load, else with the stand-ins.
// Returns true when the assets were used. Free with dragon_parts_free.
bool dragon_parts_load(const char* assets_dir, dragon_part parts[DRAGON_PART_COUNT])
{
    memset(parts, 0, sizeof(dragon_part) * DRAGON_PART_COUNT);
    int loaded = 0;
    for (int i = 0; assets_dir && i < DRAGON_PART_COUNT; ++i) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.glb", assets_dir, k_dragon_part_names[i]);
        if (access(path, R_OK) != 0) break;
        sp_error err = {0};
        dragon_part* p = &parts[i];
        if (sp_gltf_load(path, &p->ch, &err) != SP_OK) {
            fprintf(stderr, "  %s\n", err.text);
            break;
        }
        snprintf(p->name, sizeof p->name, "%s", k_dragon_part_names[i]);
        snprintf(p->category, sizeof p->category, "%.63s", p->ch.part.category[0] ? p->ch.part.category : p->name);
        p->abstraction = sp_rig_find_abstraction(&p->ch.rig, "outline");
        if (p->abstraction < 0) p->abstraction = 0;
        ++loaded;
    }
    if (loaded == DRAGON_PART_COUNT) return true;
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        sp_character_free(&parts[i].ch);
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        dragon_standin(i, &parts[i]);
    return false;
}

void dragon_parts_free(dragon_part parts[DRAGON_PART_COUNT])
{
    for (int i = 0; i < DRAGON_PART_COUNT; ++i)
        sp_character_free(&parts[i].ch);
}

// ---- the dragon-part evaluation (issue 5): train on one seed family of
// normal hand-drawn sketches, test on other families drawn harshly, and on
// Quick, Draw! drawings of things that are no dragon part (to be rejected).

// Quick, Draw! categories used as non-dragon scribbles: objects, none of them
// an animal or a body part (chosen before any measurement; 8 x 25 = 200).
const char* const k_scribble_categories[DRAGON_SCRIBBLE_CATEGORIES] = {"house", "guitar", "key",      "stop sign",
                                                                       "chair", "hammer", "sailboat", "suitcase"};

// A labelled set of `per_part` hand-drawn sketches of every part; categories are
// the parts' (sorted, shared when parts share one). Part k uses its own family
// derived from `family` and its name (sp_handdraw_part_family).
sp_result dragon_set(const dragon_part parts[DRAGON_PART_COUNT], int per_part, uint64_t family, const sp_handdraw_desc* hd,
                     sp_dataset* ds, sp_error* err)
{
    memset(ds, 0, sizeof *ds);
    const char* cats[DRAGON_PART_COUNT];
    int nc = 0;
    for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
        int at = 0;
        while (at < nc && strcmp(cats[at], parts[i].category) < 0)
            ++at;
        if (at < nc && !strcmp(cats[at], parts[i].category)) continue;
        memmove(cats + at + 1, cats + at, sizeof *cats * (size_t)(nc - at));
        cats[at] = parts[i].category;
        ++nc;
    }
    for (int c = 0; c < nc; ++c)
        if (sp_dataset_add_category(ds, cats[c]) < 0) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    for (int i = 0; i < DRAGON_PART_COUNT; ++i) {
        int label = 0;
        while (strcmp(ds->categories[label], parts[i].category))
            ++label;
        int index = 0;
        for (int j = 0; j < i; ++j)
            index += !strcmp(parts[j].category, parts[i].category) ? per_part : 0;
        sp_result r = sp_handdraw_dataset(&parts[i].ch.rig, parts[i].abstraction, &parts[i].ch.camera, hd,
                                          sp_handdraw_part_family(family, parts[i].name), per_part, label, index, ds, err);
        if (r != SP_OK) {
            sp_dataset_free(ds);
            return r;
        }
    }
    return SP_OK;
}

// The first `per_category` drawings of each scribble category (labels -1).
// Returns SP_ERR_IO when ../shared/data/quickdraw is absent.
sp_result dragon_scribbles(const char* data_dir, int per_category, sp_dataset* ds, sp_error* err)
{
    memset(ds, 0, sizeof *ds);
    if (!data_dir) return sp_fail(err, SP_ERR_IO, "../shared/data absent");
    for (int c = 0; c < DRAGON_SCRIBBLE_CATEGORIES; ++c) {
        char path[1024];
        snprintf(path, sizeof path, "%s/quickdraw/%s.ndjson", data_dir, k_scribble_categories[c]);
        sp_dataset one = {0};
        sp_result r = sp_dataset_read_ndjson(&one, path, -1, err);
        if (r != SP_OK) {
            sp_dataset_free(ds);
            return r;
        }
        int n = one.count < per_category ? one.count : per_category;
        if (sp_dataset_reserve(ds, n) != SP_OK) {
            sp_dataset_free(&one);
            sp_dataset_free(ds);
            return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        }
        for (int i = 0; i < n; ++i) {
            ds->samples[ds->count++] = one.samples[i];
            memset(&one.samples[i], 0, sizeof one.samples[i]); // moved
        }
        sp_dataset_free(&one);
    }
    return SP_OK;
}

// Classifies `test` (labels = clf categories by name) and `scribbles` (may be NULL).
void dragon_score(const sp_clf* clf, const sp_dataset* test, const sp_dataset* scribbles, dragon_scores* s)
{
    memset(s, 0, sizeof *s);
    s->scribble_dist_min = INFINITY;
    for (int i = 0; i < test->count; ++i) {
        sp_clf_answer a;
        sp_error err = {0};
        ++s->n;
        if (sp_clf_classify(clf, &test->samples[i].sketch, NULL, &a, &err) != SP_OK) {
            ++s->failed;
            continue;
        }
        int want = -1;
        for (int c = 0; c < sp_clf_category_count(clf); ++c)
            if (!strcmp(sp_clf_category(clf, c), test->categories[test->samples[i].label])) want = c;
        s->rejected += a.rejected;
        s->dragon_dist_max = fmaxf(s->dragon_dist_max, a.distance);
        if (a.count > 0 && a.ranked[0].category == want) ++s->right;
        for (int j = 0; j < a.count && j < 3; ++j)
            if (a.ranked[j].category == want) {
                ++s->top3;
                break;
            }
        if (a.count > 0 && want >= 0 && want < DRAGON_PART_COUNT && a.ranked[0].category < DRAGON_PART_COUNT)
            ++s->confusion[want][a.ranked[0].category];
    }
    for (int i = 0; scribbles && i < scribbles->count; ++i) {
        sp_clf_answer a;
        sp_error err = {0};
        ++s->scribbles;
        if (sp_clf_classify(clf, &scribbles->samples[i].sketch, NULL, &a, &err) != SP_OK) {
            ++s->scribbles_rejected; // nothing to place either way
            continue;
        }
        s->scribbles_rejected += a.rejected;
        s->scribble_dist_min = fminf(s->scribble_dist_min, a.distance);
    }
}
