// bench/kiosk_sketches.c: a year of visitors' strokes in the part database (issue 16, item 5).
//   kiosk_sketches [--db PATH] [--assets DIR] [--count N] [--approved F] [--json]
// Copies a database built by the default recipe (--db PATH, built there by
// the recipe when missing; default: a temporary one), stores N kiosk sketches
// in it (default 100,000: about a year of a busy museum; strokes of the six
// parts drawn by the hand-drawing model, 400 distinct ones moved about the
// canvas; all but the last 1,000 written in bulk, those by the kiosk's own
// call), approves a share F of them (default 1: the worst case for
// training) and measures: the kiosk's collecting call on that full database
// (sp_db_collect_kiosk_sketch, one commit each), the review's first page
// (counts and the oldest 100 pending, as `db review` lists them), approving
// 100 ids, `sketchpose db review` as a curator runs it (when built), and
// `db train` with the default options (the newest SP_DB_KIOSK_TRAIN_MAX
// approved sketches per category go in; its CPU time too).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench.h"
#include "db_internal.h"
#include "sp/clock.h"
#include "sp/gltf.h"
#include "sp/handdraw.h"
#include "sp/partdb.h"

#define DISTINCT 400

static void copy_file(const char* from, const char* to)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", from, to);
    if (system(cmd) != 0) {
        fprintf(stderr, "kiosk_sketches: cannot copy %s\n", from);
        exit(1);
    }
}

static void fail(const sp_error* err)
{
    fprintf(stderr, "kiosk_sketches: %s\n", err->text);
    exit(1);
}

int main(int argc, char** argv)
{
    const char *src = NULL, *assets = SP_SOURCE_DIR "/assets";
    int count = 100000;
    double approved = 1.0;
    bool json = sp_bench_json_flag(argc, argv);
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--db") && i + 1 < argc)
            src = argv[++i];
        else if (!strcmp(argv[i], "--assets") && i + 1 < argc)
            assets = argv[++i];
        else if (!strcmp(argv[i], "--count") && i + 1 < argc)
            count = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--approved") && i + 1 < argc)
            approved = atof(argv[++i]);
        else if (strcmp(argv[i], "--json") != 0) {
            fprintf(stderr, "usage: kiosk_sketches [--db PATH] [--assets DIR] [--count N] [--approved F] [--json]\n");
            return 2;
        }
    }
    if (count < 1 || !(approved >= 0 && approved <= 1)) {
        fprintf(stderr, "kiosk_sketches: --count >= 1, --approved in [0, 1]\n");
        return 2;
    }
    char tmp[] = "/tmp/sp-kiosk-sketches-XXXXXX";
    if (!mkdtemp(tmp)) return 1;
    char base[256], path[256];
    snprintf(base, sizeof base, "%s/default.db", tmp);
    snprintf(path, sizeof path, "%s/year.db", tmp);
    sp_error err = {0};
    if (!src) src = base;
    if (access(src, F_OK) != 0 && sp_db_create_default(src, assets, NULL, &err) != SP_OK) fail(&err);
    copy_file(src, path);
    sp_db* db = NULL;
    if (sp_db_open(path, 0, &db, &err) != SP_OK) fail(&err);
    char** cats;
    int ncat;
    if (sp_db_categories(db, &cats, &ncat, &err) != SP_OK || ncat == 0) fail(&err);
    // Distinct strokes: each part drawn by the hand-drawing model, one stroke a sketch.
    sp_stroke strokes[DISTINCT];
    int labels[DISTINCT], nd = 0;
    for (int c = 0; c < ncat && nd < DISTINCT; ++c) {
        char** names;
        int nn;
        if (sp_db_category_parts(db, cats[c], &names, &nn, &err) != SP_OK || nn == 0) fail(&err);
        sp_character ch = {0};
        if (sp_db_load_part(db, names[0], &ch, &err) != SP_OK) fail(&err);
        for (int k = 0; k < DISTINCT / ncat && nd < DISTINCT; ++k) {
            sp_sketch sk;
            if (sp_handdraw_part(&ch.rig, 0, &ch.camera, &(sp_handdraw_desc){0}, sp_handdraw_seed(77, nd), &sk, NULL, &err) !=
                SP_OK)
                fail(&err);
            strokes[nd] = sk.strokes[0]; // the first stroke, as the kiosk keeps one
            for (int s = 1; s < sk.stroke_count; ++s) {
                free(sk.strokes[s].points);
                free(sk.strokes[s].t);
            }
            free(sk.strokes);
            labels[nd++] = c;
        }
        sp_character_free(&ch);
        sp_db_free_strings(names, nn);
    }
    // A year of them: in bulk (as the kiosk's call stores them: pending, points
    // and times), then the last 1,000 through the kiosk's call, timed.
    struct stat fs0, fs1;
    if (sp_db_checkpoint(db, &err) != SP_OK || stat(path, &fs0) != 0) fail(&err);
    double t0 = sp_now_ms();
    int timed = count < 1000 ? count : 1000;
    char* text[DISTINCT];
    for (int i = 0; i < nd; ++i)
        text[i] = sp_sketch_to_json(&(sp_sketch){.canvas_w = 1280, .canvas_h = 800, .stroke_count = 1, .strokes = &strokes[i]},
                                    DB_SKETCH_DIGITS);
    sqlite3_stmt* st;
    if (db_begin(db, &err) != SP_OK ||
        db_prepare(db,
                   "INSERT INTO sketches(category, source, strokes, added_by, status) VALUES (?, 'kiosk', ?, 'kiosk', 'pending')",
                   &st, &err) != SP_OK)
        fail(&err);
    for (int i = 0; i < count - timed; ++i) {
        sqlite3_bind_text(st, 1, cats[labels[i % nd]], -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, text[i % nd], -1, SQLITE_STATIC);
        if (sqlite3_step(st) != SQLITE_DONE) {
            fprintf(stderr, "kiosk_sketches: bulk insert failed: %s\n", sqlite3_errmsg(db->h));
            return 1;
        }
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    if (db_commit(db, &err) != SP_OK) fail(&err);
    for (int i = 0; i < nd; ++i)
        free(text[i]);
    double fill_s = (sp_now_ms() - t0) / 1000;
    double* ms_collect = malloc(sizeof(double) * (size_t)timed);
    for (int i = count - timed; i < count; ++i) {
        const sp_stroke* s = &strokes[i % nd];
        double t = sp_now_ms();
        if (sp_db_collect_kiosk_sketch(db, cats[labels[i % nd]], s, 1280, 800, NULL, &err) != SP_OK) fail(&err);
        ms_collect[i - (count - timed)] = sp_now_ms() - t;
    }
    // What a year of them takes on the kiosk's disk (the pending ones' cap, SP_DB_KIOSK_PENDING_MAX).
    if (sp_db_checkpoint(db, &err) != SP_OK || stat(path, &fs1) != 0) fail(&err);
    double bytes_each = (double)(fs1.st_size - fs0.st_size) / count;
    // Approve a share (the worst case for training: all of them), in batches of 256 ids.
    int64_t first = 0;
    sp_db_kiosk_sketch* page;
    int n;
    if (sp_db_kiosk_list(db, &(sp_db_kiosk_query){.limit = 1}, &page, &n, &err) != SP_OK || n != 1) fail(&err);
    first = page[0].id;
    sp_db_kiosk_free(page, n);
    int napprove = (int)(approved * count);
    for (int i = 0; i < napprove; i += 256) {
        int64_t ids[256];
        int k = 0;
        for (; k < 256 && i + k < napprove; ++k)
            ids[k] = first + i + k;
        if (sp_db_kiosk_set_status(db, ids, k, SP_DB_APPROVED, "bench", &err) != SP_OK) fail(&err);
    }
    // The review's first page: counts and the oldest 100 pending (or approved when none are pending).
    double ms_page[20], ms_approve[20];
    unsigned mask = napprove < count ? 1u << SP_DB_PENDING : 1u << SP_DB_APPROVED;
    for (int r = 0; r < 20; ++r) {
        double t = sp_now_ms();
        int counts[SP_DB_STATUS_COUNT];
        if (sp_db_kiosk_counts(db, counts, &err) != SP_OK) fail(&err);
        if (sp_db_kiosk_list(db, &(sp_db_kiosk_query){.statuses = mask, .limit = 100}, &page, &n, &err) != SP_OK || n != 100)
            fail(&err);
        ms_page[r] = sp_now_ms() - t;
        int64_t ids[100];
        for (int k = 0; k < 100; ++k)
            ids[k] = page[k].id;
        sp_db_kiosk_free(page, n);
        t = sp_now_ms();
        if (sp_db_kiosk_set_status(db, ids, 100, SP_DB_APPROVED, "bench", &err) != SP_OK) fail(&err);
        ms_approve[r] = sp_now_ms() - t;
    }
    // The command a curator types: `db review` (first page of 100 as JSON), five runs.
    double ms_cli[5];
    int ncli = 0;
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s/app/sketchpose' db review --db '%s' --status all >/dev/null", SP_BINARY_DIR, path);
    for (int r = 0; r < 5 && access(SP_BINARY_DIR "/app/sketchpose", X_OK) == 0; ++r) {
        double t = sp_now_ms();
        if (system(cmd) != 0) break;
        ms_cli[ncli++] = sp_now_ms() - t;
    }
    // Training with the default options (cross-validation and calibration included).
    char* report = NULL;
    struct rusage ru0, ru1;
    getrusage(RUSAGE_SELF, &ru0);
    t0 = sp_now_ms();
    if (sp_db_train(db, &(sp_db_train_desc){.by = "bench"}, &report, &err) != SP_OK) fail(&err);
    double train_ms = sp_now_ms() - t0;
    getrusage(RUSAGE_SELF, &ru1);
    double cpu_s =
        (double)(ru1.ru_utime.tv_sec - ru0.ru_utime.tv_sec) + 1e-6 * (double)(ru1.ru_utime.tv_usec - ru0.ru_utime.tv_usec) +
        (double)(ru1.ru_stime.tv_sec - ru0.ru_stime.tv_sec) + 1e-6 * (double)(ru1.ru_stime.tv_usec - ru0.ru_stime.tv_usec);
    const char* k = strstr(report, "\"kiosk_sketches\": ");
    int in_training = k ? atoi(k + 18) : -1;
    sp_bench_row rows[5] = {0};
    sp_bench_stats(ms_collect, timed, &rows[0].ms_median, &rows[0].ms_p90);
    snprintf(rows[0].name, sizeof rows[0].name, "collect one kiosk sketch (%d stored)", count);
    rows[0].runs = timed;
    rows[0].paper_ms = -1;
    rows[0].target_ms = 16;
    snprintf(rows[0].extra, sizeof rows[0].extra, "\"bytes_per_sketch\": %.0f", bytes_each);

    sp_bench_stats(ms_page, 20, &rows[1].ms_median, &rows[1].ms_p90);
    snprintf(rows[1].name, sizeof rows[1].name, "review: counts and the oldest 100");
    rows[1].runs = 20, rows[1].paper_ms = -1, rows[1].target_ms = -1;
    sp_bench_stats(ms_approve, 20, &rows[2].ms_median, &rows[2].ms_p90);
    snprintf(rows[2].name, sizeof rows[2].name, "review: approve 100 ids");
    rows[2].runs = 20, rows[2].paper_ms = -1, rows[2].target_ms = -1;
    rows[3].ms_median = rows[3].ms_p90 = train_ms;
    snprintf(rows[3].name, sizeof rows[3].name, "db train (%d approved stored)", napprove);
    rows[3].runs = 1, rows[3].paper_ms = -1, rows[3].target_ms = 120000;
    snprintf(rows[3].extra, sizeof rows[3].extra, "\"kiosk_sketches\": %d, \"cpu_s\": %.1f", in_training, cpu_s);
    int nrows = 4;
    if (ncli > 0) {
        sp_bench_stats(ms_cli, ncli, &rows[4].ms_median, &rows[4].ms_p90);
        snprintf(rows[4].name, sizeof rows[4].name, "sketchpose db review (first page, whole process)");
        rows[4].runs = ncli, rows[4].paper_ms = -1, rows[4].target_ms = -1;
        nrows = 5;
    }
    sp_bench_print("Kiosk sketches: a year of visitors' strokes in the part database", rows, nrows, json);
    if (!json)
        printf("stored %d (bulk: %.1f s); %d approved kiosk sketches in the training set; training took %.1f s of CPU\n", count,
               fill_s, in_training, cpu_s);
    free(report);
    free(ms_collect);
    for (int i = 0; i < nd; ++i) {
        free(strokes[i].points);
        free(strokes[i].t);
    }
    sp_db_free_strings(cats, ncat);
    sp_db_close(db);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    return system(cmd) == 0 ? 0 : 1;
}
