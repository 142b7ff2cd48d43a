// cmd_eval.c: sketchpose eval --model M --data DIR [--folds K]
#include <stdlib.h>
#include <string.h>

#include "clf_cli.h"
#include "sp/classifier.h"
#include "sp/clock.h"
#include "sp/sketch_io.h"

// Classifies samples with mask[i] set by `clf` (whose categories are looked up by name in ds).
static void run(const sp_clf* clf, const sp_dataset* ds, const unsigned char* mask, int* confusion, int* top1, int* top3, int* n,
                int* rejected, int* failed, double* ms, int* nms)
{
    int nc = ds->category_count;
    int* map = malloc(sizeof(int) * (size_t)sp_clf_category_count(clf));
    for (int k = 0; map && k < sp_clf_category_count(clf); ++k) {
        map[k] = -1;
        for (int c = 0; c < nc; ++c)
            if (!strcmp(sp_clf_category(clf, k), ds->categories[c])) map[k] = c;
    }
    for (int i = 0; map && i < ds->count; ++i) {
        if (mask && !mask[i]) continue;
        const sp_sample* s = &ds->samples[i];
        sp_clf_answer a;
        sp_error err = {0};
        double t0 = sp_now_ms();
        sp_result r = sp_clf_classify(clf, &s->sketch, &s->raster, &a, &err);
        ms[(*nms)++] = sp_now_ms() - t0;
        ++*n;
        if (r != SP_OK) {
            ++*failed;
            continue;
        }
        *rejected += a.rejected;
        int pred = a.count > 0 ? map[a.ranked[0].category] : -1;
        if (pred == s->label) ++*top1;
        for (int j = 0; j < a.count && j < 3; ++j)
            if (map[a.ranked[j].category] == s->label) {
                ++*top3;
                break;
            }
        if (pred >= 0) ++confusion[s->label * nc + pred];
    }
    free(map);
}

int cmd_eval(int argc, char** argv)
{
    const char* data = NULL;
    const char* model = NULL;
    int folds = 0;
    clf_cli_opts o = clf_cli_opts_unset();
    sp_opt opts[] = {
        {"--model", SP_OPT_IN, &model, "M",
         "trained model (required unless --folds; with --folds, the folds train with its options)", false},
        {"--data", SP_OPT_STRING, &data, "DIR", "labelled folder to evaluate on", true},
        {"--folds", SP_OPT_INT, &folds, "K",
         "K-fold cross-validation on DIR (fold = drawing index mod K), 2..100 (-1 or 0: none, the default)", false},
        CLF_CLI_OPTS(o),
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose eval",
                          "accuracy of a classifier: top-1/top-3, per-class recall, confusion matrix, ms per drawing", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (folds == -1) folds = 0; // none, as for db init and db train
    if (!model && folds == 0) {
        fprintf(stderr, "sketchpose eval: give --model M, or --folds K to cross-validate (see --help)\n");
        return SP_EXIT_USAGE;
    }
    if (!clf_cli_check("sketchpose eval", &o)) return SP_EXIT_USAGE;
    if (folds != 0 && (folds < 2 || folds > 100)) {
        fprintf(stderr, "sketchpose eval: --folds must be 2..100 (-1 or 0: none), got %d\n", folds);
        return SP_EXIT_USAGE;
    }
    // A model keeps its training options, so with --model the training options
    // (opts[3..], CLF_CLI_OPTS) were ignored; all but --handdraw with --folds,
    // which a model does not keep.
    for (int j = 3; model && j < (int)(sizeof opts / sizeof opts[0]); ++j)
        for (int i = 1; i < argc; ++i)
            if (!strcmp(argv[i], opts[j].name) && (strcmp(argv[i], "--handdraw") != 0 || folds == 0)) {
                fprintf(stderr, "sketchpose eval: %s does not apply with --model M%s\n", argv[i],
                        strcmp(argv[i], "--handdraw") ? " (the model keeps its own training options)" : " without --folds");
                return SP_EXIT_USAGE;
            }
    sp_error err = {0};
    sp_dataset ds;
    if (sp_dataset_load(data, &ds, &err) != SP_OK || !clf_cli_drop_no_extent("sketchpose eval", data, &ds, &err)) {
        fprintf(stderr, "sketchpose eval: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    int nc = ds.category_count;
    int* confusion = calloc((size_t)nc * nc, sizeof(int));
    double* ms = malloc(sizeof(double) * (size_t)ds.count);
    unsigned char* mask = malloc((size_t)ds.count);
    if (!confusion || !ms || !mask) {
        fprintf(stderr, "sketchpose eval: out of memory\n");
        return SP_EXIT_INPUT;
    }
    int top1 = 0, top3 = 0, n = 0, rejected = 0, failed = 0, nms = 0;
    int fold_n[100] = {0}, fold_top1[100] = {0}, fold_top3[100] = {0};
    sp_clf_desc desc = clf_cli_desc(&o);
    sp_clf* clf = NULL;
    if (model) {
        if (sp_clf_load(model, &clf, &err) != SP_OK) {
            fprintf(stderr, "sketchpose eval: %s\n", err.text);
            sp_dataset_free(&ds);
            return SP_EXIT_INPUT;
        }
        desc = sp_clf_get_desc(clf);                            // cross-validation reuses the model's options
        desc.augment_fn = o.handdraw ? clf_cli_handdraw : NULL; // not stored in the model
    }
    if (folds == 0) {
        run(clf, &ds, NULL, confusion, &top1, &top3, &n, &rejected, &failed, ms, &nms);
    } else {
        if (clf_cli_tty()) desc.progress = clf_cli_progress;
        for (int f = 0; f < folds; ++f) {
            for (int i = 0; i < ds.count; ++i)
                mask[i] = ds.samples[i].index % folds != f;
            sp_clf* fc = NULL;
            char prefix[32];
            snprintf(prefix, sizeof prefix, "fold %d/%d ", f + 1, folds);
            desc.progress_user = prefix;
            if (sp_clf_train(&ds, mask, &desc, &fc, &err) != SP_OK) {
                fprintf(stderr, "sketchpose eval: fold %d: %s\n", f, err.text);
                sp_clf_destroy(clf);
                sp_dataset_free(&ds);
                return SP_EXIT_INPUT;
            }
            for (int i = 0; i < ds.count; ++i)
                mask[i] = !mask[i];
            int n0 = n, top10 = top1, top30 = top3;
            run(fc, &ds, mask, confusion, &top1, &top3, &n, &rejected, &failed, ms, &nms);
            sp_clf_destroy(fc);
            fold_n[f] = n - n0;
            fold_top1[f] = top1 - top10;
            fold_top3[f] = top3 - top30;
        }
    }
    qsort(ms, (size_t)nms, sizeof(double), sp_cmp_double);
    printf("{\"top1\": %.4f, \"top3\": %.4f, \"n\": %d, \"ms_median\": %.3f, \"ms_p90\": %.3f, \"rejected\": %d, "
           "\"failed\": %d, \"folds\": %d,\n",
           n ? (double)top1 / n : 0.0, n ? (double)top3 / n : 0.0, n, sp_sorted_quantile(ms, nms, 0.5),
           sp_sorted_quantile(ms, nms, 0.9), rejected, failed, folds);
    if (folds > 0) {
        printf(" \"per_fold\": [");
        for (int f = 0; f < folds; ++f)
            printf("%s{\"top1\": %.4f, \"top3\": %.4f, \"n\": %d}", f ? ", " : "",
                   fold_n[f] ? (double)fold_top1[f] / fold_n[f] : 0.0, fold_n[f] ? (double)fold_top3[f] / fold_n[f] : 0.0,
                   fold_n[f]);
        printf("],\n");
    }
    printf(" \"per_class\": {");
    for (int c = 0; c < nc; ++c) {
        int row = 0, total = 0;
        for (int i = 0; i < ds.count; ++i)
            total += ds.samples[i].label == c;
        row = confusion[c * nc + c];
        printf("%s\n  ", c ? "," : "");
        clf_cli_json_str(stdout, ds.categories[c]);
        printf(": {\"recall\": %.4f, \"n\": %d}", total ? (double)row / total : 0.0, total);
    }
    printf("},\n \"confusion\": {\"categories\": [");
    for (int c = 0; c < nc; ++c) {
        if (c) printf(", ");
        clf_cli_json_str(stdout, ds.categories[c]);
    }
    printf("], \"matrix\": [");
    for (int c = 0; c < nc; ++c) {
        printf("%s\n  [", c ? "," : "");
        for (int k = 0; k < nc; ++k)
            printf("%s%d", k ? ", " : "", confusion[c * nc + k]);
        printf("]");
    }
    printf("]}}\n");
    free(confusion);
    free(ms);
    free(mask);
    sp_clf_destroy(clf);
    sp_dataset_free(&ds);
    return SP_EXIT_OK;
}
