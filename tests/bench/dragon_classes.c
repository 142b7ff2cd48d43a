// bench/dragon_classes.c: the dragon-part classifier (issue 5, "What it must show").
//   bench_dragon_classes [--json] [--train N] [--test N] [--cal N] [--scribbles N] [--words W] [--sweep] [--db PATH]
// Trains on N hand-drawn sketches per part of seed family 1 (normal style, one
// in four clean: the part database's recipe), tests on --test harsh sketches per
// part of family 2 (600 by default) and on Quick, Draw! drawings of non-dragon
// objects (--scribbles per category, 8 categories: 200), and reports top-1/top-3,
// dragon sketches wrongly rejected and scribbles rejected, for the reject
// threshold of the training set (leave-one-out quantile 0.98) and for thresholds
// calibrated on --cal harsh sketches per part of family 3 at several quantiles.
// --sweep also trains with each classifier option switched the other way
// (calibrated at quantile 0.96). --db evaluates the newest model of a part
// database instead (e.g. the default one of `sketchpose db init`), with its
// own reject threshold, on the same held-out sets. Parts: assets/*.glb when all six are there,
// else the code-built stand-ins (tests/support/dragon_parts.h).
#include <stdlib.h>
#include <string.h>

#include "dragon_parts.h"
#include "sp/classifier.h"
#include "sp/clock.h"
#include "sp/handdraw.h"
#include "sp/partdb.h"
#include "test.h"

typedef struct variant {
    const char* name;
    sp_clf_desc desc;
} variant;

// One classified drawing.
typedef struct answer {
    int label, pred;
    bool top3;
    float distance;
} answer;

static answer* classify_all(const sp_clf* clf, const sp_dataset* ds, double* ms_median, double* ms_p90)
{
    answer* a = calloc((size_t)ds->count + 1, sizeof *a);
    double* ms = malloc(sizeof(double) * ((size_t)ds->count + 1));
    for (int i = 0; i < ds->count; ++i) {
        sp_clf_answer r;
        sp_error err = {0};
        double t = sp_now_ms();
        sp_result rc = sp_clf_classify(clf, &ds->samples[i].sketch, NULL, &r, &err);
        ms[i] = sp_now_ms() - t;
        a[i].label = -1;
        for (int c = 0; ds->samples[i].label >= 0 && c < sp_clf_category_count(clf); ++c)
            if (!strcmp(sp_clf_category(clf, c), ds->categories[ds->samples[i].label])) a[i].label = c;
        a[i].pred = rc == SP_OK && r.count > 0 ? r.ranked[0].category : -1;
        a[i].distance = rc == SP_OK ? r.distance : INFINITY;
        for (int j = 0; rc == SP_OK && j < r.count && j < 3; ++j)
            a[i].top3 |= r.ranked[j].category == a[i].label;
    }
    qsort(ms, (size_t)ds->count, sizeof(double), sp_cmp_double);
    if (ms_median) *ms_median = ds->count ? ms[ds->count / 2] : 0;
    if (ms_p90) *ms_p90 = ds->count ? ms[(int)(0.9 * (ds->count - 1))] : 0;
    free(ms);
    return a;
}

// --db: the database's model with its own threshold, then recalibrated as
// the bench does.
static int report_db_model(const char* db_path, const sp_dataset* test, const sp_dataset* scrib, const sp_dataset* cal)
{
    sp_db* db = NULL;
    sp_clf* clf = NULL;
    sp_error err = {0};
    if (sp_db_open(db_path, SP_DB_READONLY, &db, &err) != SP_OK || sp_db_load_model(db, &clf, NULL, &err) != SP_OK) {
        fprintf(stderr, "bench_dragon_classes: %s\n", err.text);
        sp_db_close(db);
        return 1;
    }
    sp_db_close(db);
    double med, p90;
    answer* at = classify_all(clf, test, &med, &p90);
    answer* as = classify_all(clf, scrib, NULL, NULL);
    float thr = sp_clf_reject_distance(clf);
    int right = 0, top3 = 0, fr = 0, sr = 0;
    for (int i = 0; i < test->count; ++i) {
        right += at[i].pred == at[i].label;
        top3 += at[i].top3;
        fr += !(at[i].distance <= thr);
    }
    for (int i = 0; i < scrib->count; ++i)
        sr += !(as[i].distance <= thr);
    sp_clf_desc d = sp_clf_get_desc(clf);
    printf("%s: %d words; top1 %.1f%%, top3 %.1f%%, dragon rejected %.1f%%, scribbles rejected %.1f%% (reject %.4f); ms "
           "median %.2f, "
           "p90 %.2f\n",
           db_path, d.words, 100.0 * right / test->count, 100.0 * top3 / test->count, 100.0 * fr / test->count,
           scrib->count ? 100.0 * sr / scrib->count : 0.0, thr, med, p90);
    // The same model with the bench's calibration (--cal harsh sketches per part of family 3, quantile 0.96).
    if (sp_clf_calibrate_reject(clf, cal, NULL, 0.96, 1.0, NULL, NULL, &err) == SP_OK) {
        thr = sp_clf_reject_distance(clf);
        fr = sr = 0;
        for (int i = 0; i < test->count; ++i)
            fr += !(at[i].distance <= thr);
        for (int i = 0; i < scrib->count; ++i)
            sr += !(as[i].distance <= thr);
        printf("  recalibrated on %d harsh sketches of family 3 (q0.96): dragon rejected %.1f%%, scribbles rejected %.1f%% "
               "(reject "
               "%.4f)\n",
               cal->count, 100.0 * fr / test->count, scrib->count ? 100.0 * sr / scrib->count : 0.0, thr);
    }
    free(at);
    free(as);
    sp_clf_destroy(clf);
    return 0;
}

int main(int argc, char** argv)
{
    bool json = false, sweep = false;
    int ntrain = 300, ntest = 100, ncal = 100, nscrib = 25, words = 1000;
    const char* db_path = NULL;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--json"))
            json = true;
        else if (!strcmp(argv[i], "--sweep"))
            sweep = true;
        else if (!strcmp(argv[i], "--train") && i + 1 < argc)
            ntrain = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--test") && i + 1 < argc)
            ntest = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cal") && i + 1 < argc)
            ncal = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--scribbles") && i + 1 < argc)
            nscrib = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--words") && i + 1 < argc)
            words = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--db") && i + 1 < argc)
            db_path = argv[++i];
        else {
            fprintf(stderr, "usage: bench_dragon_classes [--json] [--train N] [--test N] [--cal N] [--scribbles N] [--words W] "
                            "[--sweep] [--db PATH]\n");
            return 2;
        }
    }
    if (ntrain < 1 || ntest < 1 || ncal < 1 || nscrib < 0 || words < 2) {
        fprintf(stderr, "bench_dragon_classes: counts must be positive\n");
        return 2;
    }
    dragon_part parts[DRAGON_PART_COUNT];
    bool assets = dragon_parts_load(sp_test_src_path("assets"), parts);
    sp_error err = {0};
    sp_dataset train, test, cal, scrib = {0};
    double t0 = sp_now_ms();
    if (dragon_set(parts, ntrain, 1, &(sp_handdraw_desc){.style = SP_HANDDRAW_NORMAL, .clean_share = 0.25}, &train, &err) !=
            SP_OK ||
        dragon_set(parts, ntest, 2, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH}, &test, &err) != SP_OK ||
        dragon_set(parts, ncal, 3, &(sp_handdraw_desc){.style = SP_HANDDRAW_HARSH}, &cal, &err) != SP_OK) {
        fprintf(stderr, "bench_dragon_classes: %s\n", err.text);
        return 1;
    }
    double gen_ms = sp_now_ms() - t0;
    if (nscrib > 0 && dragon_scribbles(sp_test_data_dir(), nscrib, &scrib, &err) != SP_OK)
        fprintf(stderr, "bench_dragon_classes: no scribbles (%s)\n", err.text);
    fprintf(
        stderr,
        "parts: %s; %d training (normal, 1/4 clean, family 1), %d held-out (harsh, family 2), %d calibration (harsh, family 3), "
        "%d scribbles; generated in %.0f ms\n",
        assets ? "assets/*.glb" : "stand-ins (assets/ incomplete)", train.count, test.count, cal.count, scrib.count, gen_ms);

    int rc = 0;
    if (db_path) { // the database's model, its own threshold
        rc = report_db_model(db_path, &test, &scrib, &cal);
        goto done;
    }
    variant vs[32];
    int nv = 0;
    vs[nv++] = (variant){"recipe", {.words = words}};
    if (sweep) {
        vs[nv++] = (variant){"words 500", {.words = 500}};
        vs[nv++] = (variant){"words 2000", {.words = 2000}};
        vs[nv++] = (variant){"no mirror", {.words = words, .mirror = -1}};
        vs[nv++] = (variant){"no pyramid", {.words = words, .pyramid = -1}};
        vs[nv++] = (variant){"pyramid + 4x4", {.words = words, .pyramid = 2}};
        vs[nv++] = (variant){"no tf-idf", {.words = words, .tfidf = -1}};
        vs[nv++] = (variant){"no hellinger", {.words = words, .hellinger = -1}};
        vs[nv++] = (variant){"hard assignment", {.words = words, .soft_neighbours = 1}};
        vs[nv++] = (variant){"knn 4", {.words = words, .knn = 4}};
        vs[nv++] = (variant){"knn 16", {.words = words, .knn = 16}};
        vs[nv++] = (variant){"augment 2", {.words = words, .augment = 2}};
    }
    static const double qs[] = {0, 0.95, 0.96, 0.97, 0.98, 0.99}; // 0: the training set's threshold
    int rows = 0;
    if (json)
        printf("[");
    else
        printf("%-18s %-12s %7s %7s %9s %9s %9s %10s %8s %8s\n", "variant", "threshold", "top1", "top3", "dragon", "scribbles",
               "reject", "train ms", "ms med", "ms p90");
    for (int v = 0; v < nv; ++v) {
        sp_clf* clf = NULL;
        double a0 = sp_now_ms();
        if (sp_clf_train(&train, NULL, &vs[v].desc, &clf, &err) != SP_OK) {
            fprintf(stderr, "bench_dragon_classes: %s: %s\n", vs[v].name, err.text);
            return 1;
        }
        double train_ms = sp_now_ms() - a0;
        double med, p90;
        answer* at = classify_all(clf, &test, &med, &p90);
        answer* as = classify_all(clf, &scrib, NULL, NULL);
        float* cd = malloc(sizeof(float) * (size_t)cal.count);
        int ncd = 0;
        float loo_threshold = sp_clf_reject_distance(clf);
        if (sp_clf_calibrate_reject(clf, &cal, NULL, 1.0, 1.0, cd, &ncd, &err) != SP_OK) {
            fprintf(stderr, "bench_dragon_classes: %s\n", err.text);
            return 1;
        }
        int right = 0, top3 = 0;
        int confusion[DRAGON_PART_COUNT][DRAGON_PART_COUNT] = {{0}};
        for (int i = 0; i < test.count; ++i) {
            right += at[i].pred == at[i].label;
            top3 += at[i].top3;
            if (at[i].label >= 0 && at[i].pred >= 0 && at[i].label < DRAGON_PART_COUNT && at[i].pred < DRAGON_PART_COUNT)
                ++confusion[at[i].label][at[i].pred];
        }
        for (int k = 0; k < (int)(sizeof qs / sizeof qs[0]); ++k) {
            if (k > 0 && v > 0 && qs[k] != 0.96) continue; // the sweep: one operating point
            float thr = loo_threshold;
            if (qs[k] > 0) {
                int qi = (int)ceil(qs[k] * ncd) - 1;
                thr = cd[qi < 0 ? 0 : qi >= ncd ? ncd - 1 : qi];
            }
            int fr = 0, sr = 0;
            for (int i = 0; i < test.count; ++i)
                fr += !(at[i].distance <= thr);
            for (int i = 0; i < scrib.count; ++i)
                sr += !(as[i].distance <= thr);
            char tname[32];
            if (qs[k] > 0)
                snprintf(tname, sizeof tname, "cal q%.2f", qs[k]);
            else
                snprintf(tname, sizeof tname, "train LOO q%.2f", sp_clf_get_desc(clf).reject_quantile);
            double top1 = (double)right / test.count, t3 = (double)top3 / test.count, frr = (double)fr / test.count;
            double srr = scrib.count ? (double)sr / scrib.count : 0.0;
            if (json) {
                printf("%s\n {\"case\": \"dragon parts: %s, %s\", \"ms_median\": %.3f, \"ms_p90\": %.3f, \"runs\": %d, \"top1\": "
                       "%.4f, "
                       "\"top3\": %.4f, \"dragon_rejected\": %.4f, \"scribbles_rejected\": %.4f, \"reject_distance\": %.4f, "
                       "\"train_ms\": %.0f, "
                       "\"train\": %d, \"n\": %d, \"scribbles\": %d, \"assets\": %s, \"target_top1\": 0.97, "
                       "\"target_scribbles_rejected\": 0.8, \"target_dragon_rejected\": 0.03}",
                       rows++ ? "," : "", vs[v].name, tname, med, p90, test.count, top1, t3, frr, srr, thr, train_ms, train.count,
                       test.count, scrib.count, assets ? "true" : "false");
            } else {
                printf("%-18s %-12s %6.1f%% %6.1f%% %8.1f%% %8.1f%% %9.4f %10.0f %8.2f %8.2f\n", vs[v].name, tname, 100 * top1,
                       100 * t3, 100 * frr, 100 * srr, thr, train_ms, med, p90);
            }
        }
        if (v == 0 && !json) {
            fprintf(stderr, "confusion (rows: truth, columns: top-1):\n");
            for (int i = 0; i < train.category_count && i < DRAGON_PART_COUNT; ++i) {
                fprintf(stderr, "  %-12s", train.categories[i]);
                for (int j = 0; j < train.category_count && j < DRAGON_PART_COUNT; ++j)
                    fprintf(stderr, " %4d", confusion[i][j]);
                fprintf(stderr, "\n");
            }
        }
        fflush(stdout);
        free(at);
        free(as);
        free(cd);
        sp_clf_destroy(clf);
    }
    if (json) printf("\n]\n");
done:
    sp_dataset_free(&train);
    sp_dataset_free(&test);
    sp_dataset_free(&cal);
    sp_dataset_free(&scrib);
    dragon_parts_free(parts);
    return rc;
}
