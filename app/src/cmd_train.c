// cmd_train.c: sketchpose train --data DIR --model M
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clf_cli.h"
#include "sp/classifier.h"
#include "sp/clock.h"
#include "sp/sketch_io.h"

// Whether the model would be written where the labelled folder's reader
// looks (DIR/<category>/*.json|svg|png, DIR/*.ndjson): it replaced a
// drawing, and the next train failed on it (an outside review).
static bool model_among_drawings(const char* model, const char* dir)
{
    char* folder = sp_path_folder(model);
    char* up = folder ? sp_path_folder(folder) : NULL;
    char *rd = realpath(dir, NULL), *rf = folder ? realpath(folder, NULL) : NULL, *ru = up ? realpath(up, NULL) : NULL;
    bool drawing = sp_path_ext_is(model, "json") || sp_path_ext_is(model, "svg") || sp_path_ext_is(model, "png");
    bool among = rd && ((rf && !strcmp(rf, rd) && sp_path_ext_is(model, "ndjson")) || (ru && !strcmp(ru, rd) && drawing));
    free(folder), free(up), free(rd), free(rf), free(ru);
    return among;
}

int cmd_train(int argc, char** argv)
{
    const char* data = NULL;
    const char* model = NULL;
    const char* calibrate = NULL;
    double cal_q = NAN; // not given: 0.96
    clf_cli_opts o = clf_cli_opts_unset();
    sp_opt opts[] = {
        {"--data", SP_OPT_STRING, &data, "DIR", "labelled folder: DIR/<category>/*.{json,svg,png}, DIR/<category>.ndjson", true},
        {"--model", SP_OPT_OUT, &model, "M", "model file to write", true},
        {"--calibrate", SP_OPT_STRING, &calibrate, "DIR",
         "held-out labelled folder (e.g. `synth --parts P --style harsh --seed 3`): set the reject threshold from its distances",
         false},
        {"--calibrate-quantile", SP_OPT_DOUBLE, &cal_q, "Q", "with --calibrate: share of its drawings accepted (default 0.96)",
         false},
        CLF_CLI_OPTS(o),
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose train", "train a sketch classifier on a labelled folder", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (!clf_cli_check("sketchpose train", &o)) return SP_EXIT_USAGE;
    // Without --calibrate the quantile was ignored: the training set's threshold, silently.
    if (!isnan(cal_q) && !calibrate) {
        fprintf(stderr, "sketchpose train: --calibrate-quantile applies only with --calibrate DIR\n");
        return SP_EXIT_USAGE;
    }
    for (int i = 0; i < 2; ++i)
        if ((i ? calibrate : data) && model_among_drawings(model, i ? calibrate : data)) {
            sp_cli_say("sketchpose train: --model %s lies among the drawings of %s %s: it would replace or join them; write it "
                       "elsewhere",
                       model, i ? "--calibrate" : "--data", i ? calibrate : data);
            return SP_EXIT_USAGE;
        }
    if (isnan(cal_q)) cal_q = 0.96;
    if (!sp_cli_check_double("sketchpose train", "--calibrate-quantile", cal_q, 0, true, 1)) return SP_EXIT_USAGE;
    if (!sp_cli_check_out_folders("sketchpose train", opts, (int)(sizeof opts / sizeof opts[0])))
        return SP_EXIT_INPUT; // before the work
    double t0 = sp_now_ms();
    sp_error err = {0};
    sp_dataset ds;
    if (sp_dataset_load(data, &ds, &err) != SP_OK || !clf_cli_drop_no_extent("sketchpose train", data, &ds, &err)) {
        fprintf(stderr, "sketchpose train: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    sp_clf_desc desc = clf_cli_desc(&o);
    if (clf_cli_tty()) desc.progress = clf_cli_progress;
    sp_clf* clf = NULL;
    if (sp_clf_train(&ds, NULL, &desc, &clf, &err) != SP_OK) {
        fprintf(stderr, "sketchpose train: %s\n", err.text);
        sp_dataset_free(&ds);
        return SP_EXIT_INPUT;
    }
    if (calibrate) {
        sp_dataset cal;
        sp_result r = sp_dataset_load(calibrate, &cal, &err);
        if (r == SP_OK) {
            r = sp_clf_calibrate_reject(clf, &cal, NULL, cal_q, 1.0, NULL, NULL, &err);
            sp_dataset_free(&cal);
        }
        if (r != SP_OK) {
            fprintf(stderr, "sketchpose train: --calibrate: %s\n", err.text);
            sp_clf_destroy(clf);
            sp_dataset_free(&ds);
            return SP_EXIT_INPUT;
        }
    }
    if (sp_clf_save(clf, model, &err) != SP_OK) {
        fprintf(stderr, "sketchpose train: %s\n", err.text);
        sp_clf_destroy(clf);
        sp_dataset_free(&ds);
        return SP_EXIT_INPUT;
    }
    printf("{\"model\": ");
    clf_cli_json_str(stdout, model);
    float rd = sp_clf_reject_distance(clf);
    printf(", \"categories\": %d, \"drawings\": %d, \"seconds\": %.3f, \"reject_distance\": %.4f}\n", ds.category_count, ds.count,
           (sp_now_ms() - t0) / 1e3, isfinite(rd) ? rd : -1.0);
    sp_clf_destroy(clf);
    sp_dataset_free(&ds);
    return SP_EXIT_OK;
}
