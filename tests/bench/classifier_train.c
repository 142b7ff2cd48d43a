// bench/classifier_train.c: classifier training time on 10k drawings (issue 5:
// "training 10k sketches <= 2 minutes on 2 cores").
//   bench_classifier_train [--json] [--threads T] [--copies N] [--no-mirror-row]
// The 10k drawings: the 2500 Quick, Draw! drawings of ../shared/data/quickdraw
// (100 categories x 25) and 3 hand-drawn variants of each (sp_handdraw_apply,
// normal style: rotation, aspect, wobble, gaps, uneven sampling), so 10000
// drawings of 100 categories. Rows: default options (mirrored copies are added,
// so 20000 histograms), and without mirroring (10000). Each row reports the
// stages (descriptor sample, k-means vocabulary, histograms, leave-one-out
// reject calibration) from the progress callback.
#include <stdlib.h>
#include <string.h>

#include "fixtures.h"
#include "sp/classifier.h"
#include "sp/clock.h"
#include "sp/handdraw.h"
#include "sp/sketch_io.h"
#include "test.h"

// Stage boundaries seen through the progress callback.
typedef struct stages {
    double t0, descriptors, vocabulary, histograms;
} stages;

static void on_progress(void* user, const char* stage, int done, int total)
{
    stages* s = user;
    double t = sp_now_ms() - s->t0;
    if (!strcmp(stage, "descriptors") && done == total)
        s->descriptors = t;
    else if (!strcmp(stage, "vocabulary") && done == total)
        s->vocabulary = t;
    else if (!strcmp(stage, "histograms") && done == total)
        s->histograms = t;
}

int main(int argc, char** argv)
{
    bool json = false, no_mirror_row = true;
    int threads = 2, copies = 3;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--json"))
            json = true;
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--copies") && i + 1 < argc)
            copies = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-mirror-row"))
            no_mirror_row = false;
        else {
            fprintf(stderr, "usage: bench_classifier_train [--json] [--threads T] [--copies N] [--no-mirror-row]\n");
            return 2;
        }
    }
    if (threads < 1 || copies < 0 || copies > 100) {
        fprintf(stderr, "bench_classifier_train: --threads >= 1, --copies 0..100\n");
        return 2;
    }
    sp_dataset ds;
    if (!sp_fixture_bench_quickdraw("bench_classifier_train", &ds)) return 1;
    sp_error err = {0};
    // Hand-drawn variants of every drawing.
    int orig = ds.count;
    if (sp_dataset_reserve(&ds, orig * copies) != SP_OK) {
        fprintf(stderr, "bench_classifier_train: out of memory\n");
        return 1;
    }
    sp_handdraw_params hp = sp_handdraw_preset(SP_HANDDRAW_NORMAL);
    for (int k = 0; k < copies; ++k)
        for (int i = 0; i < orig; ++i) {
            sp_sample* s = &ds.samples[ds.count];
            memset(s, 0, sizeof *s);
            if (sp_handdraw_apply(&ds.samples[i].sketch, &hp, sp_handdraw_seed((uint64_t)k + 1, i), &s->sketch, NULL, &err) !=
                SP_OK) {
                fprintf(stderr, "bench_classifier_train: drawing %d: %s\n", i, err.text);
                return 1;
            }
            s->label = ds.samples[i].label;
            s->index = ds.samples[i].index + 25 * (k + 1);
            ++ds.count;
        }
    typedef struct row {
        const char* name;
        sp_clf_desc desc;
        double ms;
        stages st;
    } row;
    row rows[2] = {{"train 10k drawings (x2 mirrored)", {.threads = threads}, 0, {0}},
                   {"train 10k drawings, no mirror", {.threads = threads, .mirror = -1}, 0, {0}}};
    int nr = no_mirror_row ? 2 : 1;
    for (int r = 0; r < nr; ++r) {
        rows[r].desc.progress = on_progress;
        rows[r].desc.progress_user = &rows[r].st;
        rows[r].st.t0 = sp_now_ms();
        sp_clf* clf = NULL;
        if (sp_clf_train(&ds, NULL, &rows[r].desc, &clf, &err) != SP_OK) {
            fprintf(stderr, "bench_classifier_train: %s\n", err.text);
            return 1;
        }
        rows[r].ms = sp_now_ms() - rows[r].st.t0;
        sp_clf_destroy(clf);
    }
    if (json) {
        printf("[");
        for (int r = 0; r < nr; ++r) {
            const stages* s = &rows[r].st;
            printf("%s\n {\"case\": \"%s\", \"ms_median\": %.1f, \"ms_p90\": %.1f, \"runs\": 1, \"target_ms\": 120000, "
                   "\"drawings\": %d, "
                   "\"threads\": %d, \"descriptors_ms\": %.1f, \"vocabulary_ms\": %.1f, \"histograms_ms\": %.1f, "
                   "\"reject_calibration_ms\": %.1f}",
                   r ? "," : "", rows[r].name, rows[r].ms, rows[r].ms, ds.count, threads, s->descriptors,
                   s->vocabulary - s->descriptors, s->histograms - s->vocabulary, rows[r].ms - s->histograms);
        }
        printf("\n]\n");
    } else {
        printf("%d drawings (%d Quick, Draw! + %d hand-drawn variants), %d categories, %d threads\n", ds.count, orig,
               ds.count - orig, ds.category_count, threads);
        printf("%-36s %10s %12s %12s %12s %12s %10s\n", "case", "total ms", "descriptors", "vocabulary", "histograms",
               "leave-1-out", "target ms");
        for (int r = 0; r < nr; ++r) {
            const stages* s = &rows[r].st;
            printf("%-36s %10.0f %12.0f %12.0f %12.0f %12.0f %10d\n", rows[r].name, rows[r].ms, s->descriptors,
                   s->vocabulary - s->descriptors, s->histograms - s->vocabulary, rows[r].ms - s->histograms, 120000);
        }
    }
    sp_dataset_free(&ds);
    return 0;
}
