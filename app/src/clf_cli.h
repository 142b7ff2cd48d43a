/// clf_cli.h: what the classifier commands (train, eval, classify) share:
/// training options on the command line, a terminal progress bar, JSON strings.
/// Header-only so that it needs no build changes; included by the commands that train, evaluate or print JSON by hand.
#ifndef SP_CLF_CLI_H
#define SP_CLF_CLI_H

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "sp/classifier.h"
#include "sp/handdraw.h"

/// Training options as flags; zero values mean the library defaults, except
/// the range-checked ones, which start "not given" (clf_cli_opts_unset).
typedef struct clf_cli_opts {
    int words, knn, augment, soft, threads, seed, pyramid;
    bool no_pyramid, no_tfidf, no_hellinger, no_mirror, handdraw;
    double reject_quantile, shape_weight, picture_weight;
} clf_cli_opts;

/// The options before parsing: a range-checked number not given is SP_CLI_UNSET
/// (NaN for the quantile), so that a typed 0 is out of its range, not the default.
static inline clf_cli_opts clf_cli_opts_unset(void)
{
    return (clf_cli_opts){.words = SP_CLI_UNSET,
                          .knn = SP_CLI_UNSET,
                          .soft = SP_CLI_UNSET,
                          .threads = SP_CLI_UNSET,
                          .pyramid = SP_CLI_UNSET,
                          .reject_quantile = NAN};
}

/// An int option as the library takes it: not given is 0, its default.
static inline int clf_cli_int(int v)
{
    return v == SP_CLI_UNSET ? 0 : v;
}

#define CLF_CLI_OPTS(o)                                                                                                          \
    {"--words", SP_OPT_INT, &(o).words, "N", "vocabulary size, 1..20000 (default 500)", false},                                  \
        {"--knn", SP_OPT_INT, &(o).knn, "K", "neighbours voting, 1..64 (default 8)", false},                                     \
        {"--soft", SP_OPT_INT, &(o).soft, "N", "words per descriptor, soft assignment, 1..16 (default 4)", false},               \
        {"--augment", SP_OPT_INT, &(o).augment, "N", "jittered copies per training drawing, 0..16 (default 0)", false},          \
        {"--handdraw", SP_OPT_FLAG, &(o).handdraw, "", "--augment copies from the hand-drawing model instead of affine jitter",  \
         false},                                                                                                                 \
        {"--no-pyramid", SP_OPT_FLAG, &(o).no_pyramid, "", "no 2x2 spatial pyramid", false},                                     \
        {"--pyramid",                                                                                                            \
         SP_OPT_INT,                                                                                                             \
         &(o).pyramid,                                                                                                           \
         "L",                                                                                                                    \
         "pyramid levels past the whole drawing: 1 = 2x2 (default), 2 = also 4x4 (none: --no-pyramid)",                          \
         false},                                                                                                                 \
        {"--no-tfidf", SP_OPT_FLAG, &(o).no_tfidf, "", "no tf-idf word weights", false},                                         \
        {"--no-hellinger", SP_OPT_FLAG, &(o).no_hellinger, "", "plain L2 between histograms", false},                            \
        {"--no-mirror", SP_OPT_FLAG, &(o).no_mirror, "", "do not add mirrored training drawings", false},                        \
        {"--reject-quantile",                                                                                                    \
         SP_OPT_DOUBLE,                                                                                                          \
         &(o).reject_quantile,                                                                                                   \
         "Q",                                                                                                                    \
         "reject threshold quantile, in (0, 1] (default 0.98)",                                                                  \
         false},                                                                                                                 \
        {"--shape-weight",                                                                                                       \
         SP_OPT_DOUBLE,                                                                                                          \
         &(o).shape_weight,                                                                                                      \
         "W",                                                                                                                    \
         "global shape evidence weight (0: none; part databases 0.75; < 0: none)",                                               \
         false},                                                                                                                 \
        {"--picture-weight",                                                                                                     \
         SP_OPT_DOUBLE,                                                                                                          \
         &(o).picture_weight,                                                                                                    \
         "W",                                                                                                                    \
         "whole-drawing picture evidence weight (0: the default, 0.3; < 0: none)",                                               \
         false},                                                                                                                 \
        {"--seed", SP_OPT_INT, &(o).seed, "S", "random seed, not negative (default 1)", false},                                  \
    {                                                                                                                            \
        "--threads", SP_OPT_INT, &(o).threads, "T", "worker threads, 1..256 (default 2)", false                                  \
    }

/// Refuses out-of-range training options with one line naming the option
/// (not given: the library's default; a typed 0 is out of range). False: exit 2.
static inline bool clf_cli_check(const char* cmd, const clf_cli_opts* o)
{
    // 20000 words: a vocabulary 40 times the default; k-means on more runs for hours.
    return (o->words == SP_CLI_UNSET || sp_cli_check_int(cmd, "--words", o->words, 1, 20000)) &&
           (o->knn == SP_CLI_UNSET || sp_cli_check_int(cmd, "--knn", o->knn, 1, 64)) &&
           (o->soft == SP_CLI_UNSET || sp_cli_check_int(cmd, "--soft", o->soft, 1, 16)) &&
           (o->pyramid == SP_CLI_UNSET || sp_cli_check_int(cmd, "--pyramid", o->pyramid, 1, 2)) &&
           // 16: the classifier's own cap (classifier.c), which cut more, and negatives, silently.
           sp_cli_check_int(cmd, "--augment", o->augment, 0, 16) &&
           (isnan(o->reject_quantile) || sp_cli_check_double(cmd, "--reject-quantile", o->reject_quantile, 0, true, 1)) &&
           (o->threads == SP_CLI_UNSET || sp_cli_check_int(cmd, "--threads", o->threads, 1, 256)) &&
           sp_cli_check_int(cmd, "--seed", o->seed, 0, INT_MAX);
}

/// Augmented copy k of a training drawing drawn again through the hand-drawing
/// model (normal style), seeded by the copy and the sample: reproducible.
static inline sp_result clf_cli_handdraw(void* user, const sp_sketch* in, int sample, int k, sp_sketch* out)
{
    (void)user;
    sp_handdraw_params hp = sp_handdraw_preset(SP_HANDDRAW_NORMAL);
    return sp_handdraw_apply(in, &hp, sp_handdraw_seed((uint64_t)k + 1, sample), out, NULL, NULL);
}

static inline sp_clf_desc clf_cli_desc(const clf_cli_opts* o)
{
    sp_clf_desc d = {0};
    d.words = clf_cli_int(o->words);
    d.knn = clf_cli_int(o->knn);
    d.soft_neighbours = clf_cli_int(o->soft);
    d.augment = o->augment;
    d.pyramid = o->no_pyramid ? -1 : clf_cli_int(o->pyramid);
    d.tfidf = o->no_tfidf ? -1 : 0;
    d.hellinger = o->no_hellinger ? -1 : 0;
    d.mirror = o->no_mirror ? -1 : 0;
    d.reject_quantile = isnan(o->reject_quantile) ? 0 : o->reject_quantile;
    d.shape_weight = o->shape_weight;
    d.picture_weight = o->picture_weight;
    d.seed = (uint32_t)o->seed;
    d.threads = clf_cli_int(o->threads);
    if (o->handdraw) d.augment_fn = clf_cli_handdraw;
    return d;
}

/// Progress bar on stderr, drawn only when stderr is a terminal (user = const char* prefix).
static inline void clf_cli_progress(void* user, const char* stage, int done, int total)
{
    if (total <= 0) return;
    int step = total / 50 > 0 ? total / 50 : 1;
    if (done != total && done % step != 0) return;
    int fill = (int)(30.0 * done / total);
    fprintf(stderr, "\r%s%-12s [%.*s%*s] %d/%d", user ? (const char*)user : "", stage, fill,
            "##############################", 30 - fill, "", done, total);
    if (done == total) fputc('\n', stderr);
    fflush(stderr);
}

/// A labelled folder's drawings with no extent (a dot, all points at one
/// place, an ndjson "drawing": []) are left out of training and evaluation
/// with one warning line counting them, where they were trained on as
/// blank pictures; false (err filled) when none is left.
static inline bool clf_cli_drop_no_extent(const char* cmd, const char* dir, sp_dataset* ds, sp_error* err)
{
    int n = sp_dataset_drop_no_extent(ds);
    if (n > 0)
        fprintf(stderr,
                "%s: warning: %s: %d drawing%s left out: no extent (no points, or all at one place; a picture with no dark "
                "lines)\n",
                cmd, dir, n, n == 1 ? "" : "s");
    if (ds->count == 0) {
        sp_dataset_free(ds);
        sp_fail(err, SP_ERR_INVALID, "%s: no drawing with an extent (all points at one place, or none; pictures all blank)", dir);
        return false;
    }
    // A category with no drawing left (its folder empty, or only blank
    // pictures) would be in the model with nothing to learn it from: every
    // drawing of it taken for another (a second review).
    for (int c = 0; c < ds->category_count; ++c) {
        int k = 0;
        while (k < ds->count && ds->samples[k].label != c)
            ++k;
        if (k < ds->count) continue;
        sp_fail(err, SP_ERR_INVALID, "%s: category '%s' has no drawing%s (nothing to learn it from)", dir, ds->categories[c],
                n > 0 ? " left" : "");
        sp_dataset_free(ds);
        return false;
    }
    return true;
}

static inline bool clf_cli_tty(void) { return isatty(fileno(stderr)) != 0; }

/// Writes s as a JSON string.
static inline void clf_cli_json_str(FILE* f, const char* s)
{
    fputc('"', f);
    for (const unsigned char* p = (const unsigned char*)s; *p; ++p) {
        if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
        else if (*p < 0x20) fprintf(f, "\\u%04x", *p);
        else fputc(*p, f);
    }
    fputc('"', f);
}

#endif
