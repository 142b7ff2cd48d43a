/// kiosk_parts.h: a part database and dragon strokes for the kiosk's end-to-end
/// test and benchmark (header-only; needs sp_test_fixtures).
///
/// kp_build_db() fills a new database with the six dragon parts: assets/<part>.glb
/// when all six are there and pass the database's checks (a quickly trained
/// model), else the stand-ins of dragon_parts.h, each given its own colour
/// (kp_hue) and a looping clip. kp_six_strokes() gives one stroke per part,
/// placed like a dragon on a 1280 x 800 canvas: the part's synthetic sketch
/// at a random pose, for the first seed whose category the model ranks in
/// its top three (rank says which chip a visitor would have to tap).
#ifndef SP_TEST_KIOSK_PARTS_H
#define SP_TEST_KIOSK_PARTS_H

#include <sys/stat.h>

#include "dragon_parts.h"
#include "fixtures.h"

#include "sp/partdb.h"
#include "sp/synth.h"

/// Hues (degrees) of the stand-ins, away from the blue stroke (~225) and the yellow outline (~47).
static const double kp_hue[DRAGON_PART_COUNT] = {0, 95, 140, 185, 275, 320};

static inline double kp_srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static inline void kp_hsv_rgb(double h, double s, double v, double rgb[3])
{
    double c = v * s, hp = fmod(h, 360.0) / 60.0, x = c * (1 - fabs(fmod(hp, 2.0) - 1)), m = v - c;
    double r = 0, g = 0, b = 0;
    if (hp < 1)
        r = c, g = x;
    else if (hp < 2)
        r = x, g = c;
    else if (hp < 3)
        g = c, b = x;
    else if (hp < 4)
        g = x, b = c;
    else if (hp < 5)
        r = x, b = c;
    else
        r = c, b = x;
    rgb[0] = r + m, rgb[1] = g + m, rgb[2] = b + m;
}

static inline sp_db_train_desc kp_quick_train(void)
{
    return (sp_db_train_desc){.clf = {.words = 96, .vocab_samples = 8000, .threads = 2}, .folds = -1, .by = "test"};
}

/// Stand-in i with its colour and a looping clip (a sway of its second joint), as a .glb.
static inline bool kp_write_standin(int i, const char* path, sp_error* err)
{
    dragon_part p;
    dragon_standin(i, &p);
    sp_rig* rig = &p.ch.rig;
    double rgb[3];
    kp_hsv_rgb(kp_hue[i], 0.85, 0.8, rgb);
    for (int v = 0; v < rig->vertex_count; ++v)
        for (int c = 0; c < 3; ++c)
            p.ch.colors[4 * v + c] = (float)kp_srgb_to_linear(rgb[c]);
    rig->animations = calloc(1, sizeof(sp_animation));
    sp_animation* an = &rig->animations[0];
    rig->animation_count = 1;
    snprintf(an->name, sizeof an->name, "sway");
    an->duration_s = 0.8 + 0.15 * i;
    an->channel_count = 1;
    an->channels = calloc(1, sizeof(sp_anim_channel));
    sp_anim_channel* ch = &an->channels[0];
    ch->joint = 1;
    ch->path = SP_ANIM_ROTATION;
    ch->interp = SP_INTERP_LINEAR;
    ch->key_count = 3;
    ch->times = malloc(3 * sizeof(float));
    ch->values = malloc(12 * sizeof(float));
    const double ang[3] = {0, 0.3, 0};
    for (int k = 0; k < 3; ++k) {
        ch->times[k] = (float)(an->duration_s * k / 2.0);
        ch->values[4 * k] = 0, ch->values[4 * k + 1] = 0;
        ch->values[4 * k + 2] = (float)sin(0.5 * ang[k]), ch->values[4 * k + 3] = (float)cos(0.5 * ang[k]);
    }
    sp_result r = sp_gltf_save(&p.ch, NULL, path, err);
    sp_character_free(&p.ch);
    return r == SP_OK;
}

/// Builds `path` (replacing it); glb_dir holds the stand-ins' files. *real tells whether assets/ was used.
static inline bool kp_build_db(const char* path, const char* assets_dir, const char* glb_dir, bool* real, sp_error* err)
{
    sp_fixture_remove_db(path);
    dragon_part parts[DRAGON_PART_COUNT];
    *real = dragon_parts_load(assets_dir, parts);
    dragon_parts_free(parts);
    sp_db* db = NULL;
    if (*real) {
        // The six part files only (assets/ holds other characters too).
        bool ok = sp_db_open(path, SP_DB_CREATE, &db, err) == SP_OK;
        for (int i = 0; ok && i < DRAGON_PART_COUNT; ++i) {
            char glb[1200];
            snprintf(glb, sizeof glb, "%.1000s/%s.glb", assets_dir, k_dragon_part_names[i]);
            // The assets' solver self-test is their own tests' business: skipped here for speed.
            ok = sp_db_add_part_file(db, glb, &(sp_db_part_desc){.synth_sketches = 40, .selftest_seeds = -1}, NULL, err) == SP_OK;
        }
        sp_db_train_desc td = kp_quick_train();
        ok = ok && sp_db_train(db, &td, NULL, err) == SP_OK;
        sp_db_close(db);
        db = NULL;
        if (ok) return true;
        // The assets are checked by their own tests; the kiosk's go on with the stand-ins.
        fprintf(stderr, "  note: no database from assets/ (%s); using the stand-in parts\n", err->text);
        *real = false;
        sp_fixture_remove_db(path);
    }
    if (sp_db_open(path, SP_DB_CREATE, &db, err) != SP_OK) return false;
    bool ok = true;
    for (int i = 0; ok && i < DRAGON_PART_COUNT; ++i) {
        char glb[1200];
        snprintf(glb, sizeof glb, "%.1000s/kiosk_%s.glb", glb_dir, k_dragon_part_names[i]);
        ok = kp_write_standin(i, glb, err) &&
             // The stand-ins are fixtures of the kiosk, not parts to certify: no solver self-test.
             sp_db_add_part_file(
                 db, glb,
                 &(sp_db_part_desc){
                     .name = k_dragon_part_names[i], .synth_sketches = 40, .seed = (uint64_t)i + 1, .selftest_seeds = -1},
                 NULL, err) == SP_OK;
    }
    sp_db_train_desc td = kp_quick_train();
    ok = ok && sp_db_train(db, &td, NULL, err) == SP_OK;
    sp_db_close(db);
    return ok;
}

/// Where each part goes on the 1280 x 800 canvas: centre and box diagonal (px), in drawing order;
/// the legs touch the body (the parts hang where they are drawn).
static const struct {
    const char* category;
    double cx, cy, size;
} kp_layout[DRAGON_PART_COUNT] = {
    {"torso", 640, 430, 400}, {"head", 910, 290, 200},       {"wings", 610, 220, 270},
    {"tail", 320, 450, 300},  {"front_legs", 770, 580, 190}, {"hind_legs", 510, 580, 200},
};

typedef struct kp_stroke {
    sp_vec2* xy; ///< n points, canvas pixels
    int n;
    int rank; ///< of the right category in the model's ranking (0..2)
    char category[64];
} kp_stroke;

/// The synthetic stroke of layout entry li at seed, if the model ranks its category in the top 3.
static inline bool kp_part_stroke(sp_db* db, const sp_clf* clf, int li, uint64_t seed, kp_stroke* out)
{
    sp_error err = {0};
    char** names = NULL;
    int count = 0;
    // By category: the assets' file names need not be their categories.
    const char* name = kp_layout[li].category;
    if (sp_db_category_parts(db, kp_layout[li].category, &names, &count, &err) == SP_OK && count > 0) name = names[0];
    sp_character ch = {0};
    sp_db_part_info info;
    double* p = NULL;
    sp_sketch sk = {0}, one = {.canvas_w = 1280, .canvas_h = 800};
    sp_vec2* xy = NULL;
    bool ok = false;
    if (sp_db_load_part(db, name, &ch, &err) != SP_OK || sp_db_part(db, name, &info, &err) != SP_OK) goto done;
    int a = sp_rig_find_abstraction(&ch.rig, info.abstraction);
    if (a < 0 || !(p = malloc(sizeof(double) * ((size_t)ch.rig.param_count + 1)))) goto done;
    sp_synth_params(&ch.rig, seed, 0.25, p);
    if (sp_synth_sketch(&ch.rig, a, &ch.camera, p, &sk) != SP_OK) goto done;
    int n = sp_sketch_point_count(&sk), k = 0;
    sp_vec2 lo, hi;
    if (n < 2 || !sp_sketch_bounds(&sk, &lo, &hi) || !(xy = malloc(sizeof(sp_vec2) * (size_t)n))) goto done;
    double f = kp_layout[li].size / sp_v2_len(sp_v2_sub(hi, lo));
    sp_vec2 c = sp_v2_scale(sp_v2_add(lo, hi), 0.5);
    for (int s = 0; s < sk.stroke_count; ++s)
        for (int i = 0; i < sk.strokes[s].count; ++i, ++k)
            xy[k] = (sp_vec2){kp_layout[li].cx + f * (sk.strokes[s].points[i].x - c.x),
                              kp_layout[li].cy + f * (sk.strokes[s].points[i].y - c.y)};
    sp_clf_answer ans;
    if (sp_sketch_add_stroke(&one, xy, NULL, n) != SP_OK || sp_clf_classify(clf, &one, NULL, &ans, &err) != SP_OK) goto done;
    int rank = -1;
    for (int r = 0; r < ans.count && r < 3 && !ans.rejected; ++r)
        if (!strcmp(sp_clf_category(clf, ans.ranked[r].category), info.category)) rank = r;
    if (rank < 0) goto done;
    *out = (kp_stroke){xy, n, rank, {0}};
    snprintf(out->category, sizeof out->category, "%s", info.category);
    xy = NULL;
    ok = true;
done:
    free(xy);
    sp_sketch_free(&one);
    sp_sketch_free(&sk);
    free(p);
    sp_character_free(&ch);
    sp_db_free_strings(names, count);
    return ok;
}

/// One stroke per part (out[DRAGON_PART_COUNT]); false (and err) when a part has no usable seed.
static inline bool kp_six_strokes(const char* db_path, kp_stroke* out, sp_error* err)
{
    sp_db* db = NULL;
    sp_clf* clf = NULL;
    if (sp_db_open(db_path, SP_DB_READONLY, &db, err) != SP_OK) return false;
    bool ok = sp_db_load_model(db, &clf, NULL, err) == SP_OK;
    for (int li = 0; ok && li < DRAGON_PART_COUNT; ++li) {
        bool found = false;
        for (uint64_t seed = 1; seed <= 40 && !found; ++seed)
            found = kp_part_stroke(db, clf, li, 100 * (uint64_t)li + seed, &out[li]);
        if (!found) sp_fail(err, SP_ERR_INVALID, "no seed of %s is ranked in the model's top 3", kp_layout[li].category);
        ok = found;
    }
    sp_clf_destroy(clf);
    sp_db_close(db);
    return ok;
}

/// A benchmark's database and strokes: `db` when given, else `name` built by
/// kp_build_db in dir (SP_BINARY_DIR/tmp; path gets it); the six strokes in
/// out. False with a line on stderr naming `who`.
static inline bool kp_bench_setup(const char* who, const char** db, const char* name, char dir[1024], char path[1100], bool* real,
                                  kp_stroke out[DRAGON_PART_COUNT])
{
    sp_error err = {0};
    snprintf(dir, 1024, "%s/tmp", SP_BINARY_DIR);
    mkdir(dir, 0755);
    if (!*db) {
        snprintf(path, 1100, "%.1024s/%s", dir, name);
        if (!kp_build_db(path, SP_SOURCE_DIR "/assets", dir, real, &err)) {
            fprintf(stderr, "bench %s: %s\n", who, err.text);
            return false;
        }
        *db = path;
    }
    memset(out, 0, sizeof(kp_stroke) * DRAGON_PART_COUNT);
    if (!kp_six_strokes(*db, out, &err)) {
        fprintf(stderr, "bench %s: %s\n", who, err.text);
        return false;
    }
    return true;
}

#endif
