// bench/classifier.c: classifier speed (and, on ../shared/data/quickdraw, accuracy of one fold).
//   bench_classifier [--json] [--runs N]
// Cases: rasterise+describe one drawing, classify one drawing (rasterise ->
// descriptors -> histogram -> FLANN k-NN), training on 2000 drawings.
#include <stdlib.h>
#include <string.h>

#include "../../classifier/src/feat.h"
#include "fixtures.h"
#include "sp/classifier.h"
#include "sp/clock.h"
#include "sp/sketch_io.h"
#include "test.h"

typedef struct row {
    const char* name;
    double median, p90, target;
    int runs;
    char extra[128];
} row;

static row summarise(const char* name, double* ms, int n, double target)
{
    qsort(ms, (size_t)n, sizeof(double), sp_cmp_double);
    row r = {name, ms[n / 2], ms[(int)(0.9 * (n - 1))], target, n, ""};
    return r;
}

int main(int argc, char** argv)
{
    bool json = false;
    int runs = 500;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--json"))
            json = true;
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_classifier [--json] [--runs N]\n");
            return 2;
        }
    }
    sp_dataset ds;
    if (!sp_fixture_bench_quickdraw("bench_classifier", &ds)) return 1;
    sp_error err = {0};
    row rows[4];
    int nr = 0;
    // Fold 0 of the 5-fold protocol (index mod 5): train on 2000, test on 500.
    unsigned char* use = malloc((size_t)ds.count);
    for (int i = 0; i < ds.count; ++i)
        use[i] = ds.samples[i].index % 5 != 0;
    double t0 = sp_now_ms();
    sp_clf* clf = NULL;
    if (sp_clf_train(&ds, use, &(sp_clf_desc){0}, &clf, &err) != SP_OK) {
        fprintf(stderr, "bench_classifier: %s\n", err.text);
        return 1;
    }
    double train_ms = sp_now_ms() - t0;
    rows[nr++] = (row){"train 2000 quickdraw (x2 mirrored)", train_ms, train_ms, 0, 1, ""};

    double* ms = malloc(sizeof(double) * (size_t)(runs > ds.count ? runs : ds.count));
    sp_features* f = malloc(sizeof *f);
    sp_feat_scratch* scratch = malloc(sizeof *scratch); // kept, as the classifier keeps its
    int n = 0;
    for (int k = 0; k < runs; ++k) {
        const sp_sample* s = &ds.samples[(k * 5) % ds.count];
        double a = sp_now_ms();
        sp_feat_extract(&s->sketch, NULL, scratch, f, &err);
        ms[n++] = sp_now_ms() - a;
    }
    rows[nr++] = summarise("rasterise + descriptors", ms, n, 0);

    n = 0;
    int right = 0, tested = 0;
    for (int k = 0; k < runs; ++k) {
        const sp_sample* s = &ds.samples[(k * 5) % ds.count];
        sp_clf_answer a;
        double t = sp_now_ms();
        sp_clf_classify(clf, &s->sketch, NULL, &a, &err);
        ms[n++] = sp_now_ms() - t;
        if (s->index % 5 == 0) {
            ++tested;
            right += a.count > 0 && a.ranked[0].category == s->label;
        }
    }
    rows[nr] = summarise("classify one drawing (100 classes)", ms, n, 10.0);
    snprintf(rows[nr].extra, sizeof rows[nr].extra, "\"top1_fold0\": %.4f", tested ? (double)right / tested : 0.0);
    ++nr;

    if (json) {
        printf("[");
        for (int i = 0; i < nr; ++i) {
            printf("%s\n {\"case\": \"%s\", \"ms_median\": %.3f, \"ms_p90\": %.3f, \"runs\": %d", i ? "," : "", rows[i].name,
                   rows[i].median, rows[i].p90, rows[i].runs);
            if (rows[i].target > 0) printf(", \"target_ms\": %.1f", rows[i].target);
            if (rows[i].extra[0]) printf(", %s", rows[i].extra);
            printf("}");
        }
        printf("\n]\n");
    } else {
        printf("%-40s %10s %10s %6s %10s\n", "case", "median ms", "p90 ms", "runs", "target ms");
        for (int i = 0; i < nr; ++i)
            printf("%-40s %10.3f %10.3f %6d %10s %s\n", rows[i].name, rows[i].median, rows[i].p90, rows[i].runs,
                   rows[i].target > 0 ? "10" : "-", rows[i].extra);
    }
    free(ms);
    free(f);
    free(scratch);
    free(use);
    sp_clf_destroy(clf);
    sp_dataset_free(&ds);
    return 0;
}
