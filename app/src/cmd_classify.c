// cmd_classify.c: sketchpose classify --model M|--db DB --strokes S.json
#include <math.h>

#include "clf_cli.h"
#include "sp/classifier.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"

int cmd_classify(int argc, char** argv)
{
    const char* model = NULL;
    const char* db_path = NULL;
    const char* strokes = NULL;
    int top = 5;
    sp_opt opts[] = {
        {"--model", SP_OPT_IN, &model, "M", "trained model (sketchpose train)", false},
        {"--db", SP_OPT_IN, &db_path, "DB", "use the part database's current model instead (sketchpose db train)", false},
        {"--strokes", SP_OPT_IN, &strokes, "S.json", "the drawing: stroke JSON, SVG, PNG or ndjson (first drawing)", true},
        {"--top", SP_OPT_INT, &top, "N", "ranked categories to print (default 5, at most 10)", false},
    };
    int rc = sp_cli_parse(argc, argv, "sketchpose classify", "classify one drawing; prints ranked categories as JSON", opts,
                          (int)(sizeof opts / sizeof opts[0]));
    if (rc >= 0) return rc;
    if (top < 1 || top > SP_CLF_MAX_RANKED) {
        fprintf(stderr, "sketchpose classify: --top must be 1..%d\n", SP_CLF_MAX_RANKED);
        return SP_EXIT_USAGE;
    }
    if (!model == !db_path) {
        fprintf(stderr, "sketchpose classify: give --model M or --db DB (one of them)\n");
        return SP_EXIT_USAGE;
    }
    sp_error err = {0};
    sp_clf* clf = NULL;
    sp_result lr;
    if (db_path) {
        sp_db* db = NULL;
        lr = sp_db_open(db_path, SP_DB_READONLY, &db, &err);
        if (lr == SP_OK) lr = sp_db_load_model(db, &clf, NULL, &err);
        sp_db_close(db);
    } else {
        lr = sp_clf_load(model, &clf, &err);
    }
    if (lr != SP_OK) {
        fprintf(stderr, "sketchpose classify: %s\n", err.text);
        return SP_EXIT_INPUT;
    }
    sp_sketch s;
    sp_raster r;
    if (sp_drawing_read(strokes, &s, &r, &err) != SP_OK) {
        fprintf(stderr, "sketchpose classify: %s\n", err.text);
        sp_clf_destroy(clf);
        return SP_EXIT_INPUT;
    }
    // A dot has nothing to classify (pose refuses it too): it was ranked,
    // exit 0. A blank picture is said as db add-sketch says it.
    const char* why = r.pixels ? sp_raster_ink_problem(&r) : sp_sketch_extent_problem(&s);
    if (why) {
        fprintf(stderr, "sketchpose classify: %s: %s\n", strokes, why);
        sp_sketch_free(&s);
        sp_raster_free(&r);
        sp_clf_destroy(clf);
        return SP_EXIT_INPUT;
    }
    sp_clf_answer a;
    sp_result res = sp_clf_classify(clf, &s, &r, &a, &err);
    sp_sketch_free(&s);
    sp_raster_free(&r);
    if (res != SP_OK) {
        fprintf(stderr, "sketchpose classify: %s: %s\n", strokes, err.text);
        sp_clf_destroy(clf);
        return SP_EXIT_INPUT;
    }
    printf("{\"ranked\": [");
    for (int i = 0; i < a.count && i < top; ++i) {
        printf("%s{\"category\": ", i ? ", " : "");
        clf_cli_json_str(stdout, sp_clf_category(clf, a.ranked[i].category));
        printf(", \"score\": %.4f}", a.ranked[i].score);
    }
    printf("], \"rejected\": %s, \"distance\": %.4f, \"reject_distance\": %.4f}\n", a.rejected ? "true" : "false", a.distance,
           isfinite(a.reject_distance) ? a.reject_distance : -1.0);
    sp_clf_destroy(clf);
    return SP_EXIT_OK;
}
