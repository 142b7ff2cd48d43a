// db_models.c: training and storing classifier models, loading the newest,
// and the integrity check.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "db_internal.h"
#include "sp/clock.h"
#include "sp/handdraw.h"

static double now_s(void)
{
    return sp_now_ms() / 1e3;
}

static bool classify_ok(const sp_clf* clf, const sp_sample* s)
{
    sp_clf_answer a;
    sp_error e = {0};
    bool strokes = s->sketch.stroke_count > 0;
    if (sp_clf_classify(clf, strokes ? &s->sketch : NULL, strokes ? NULL : &s->raster, &a, &e) != SP_OK) return false;
    return a.count > 0 && a.ranked[0].category == s->label;
}

static char* desc_json(const sp_clf_desc* d)
{
    db_str b = {0};
    db_str_printf(&b,
                  "{\"words\": %d, \"vocab_samples\": %d, \"kmeans_iterations\": %d, \"soft_neighbours\": %d, \"knn\": %d,"
                  " \"pyramid\": %d, \"tfidf\": %d, \"hellinger\": %d, \"mirror\": %d, \"augment\": %d, \"reject_quantile\": %.6g,"
                  " \"seed\": %u, \"threads\": %d, \"shape_weight\": %.6g, \"picture_weight\": %.6g}",
                  d->words, d->vocab_samples, d->kmeans_iterations, d->soft_neighbours, d->knn, d->pyramid, d->tfidf, d->hellinger,
                  d->mirror, d->augment, d->reject_quantile, (unsigned)d->seed, d->threads, d->shape_weight, d->picture_weight);
    return b.oom ? (free(b.s), NULL) : b.s;
}

static void cats_json(db_str* b, char** cats, int n)
{
    db_str_printf(b, "[");
    for (int i = 0; i < n; ++i) {
        db_str_printf(b, "%s", i ? ", " : "");
        db_str_json(b, cats[i]);
    }
    db_str_printf(b, "]");
}

// Harsh hand-drawn sketches of every current part (labels: the dataset's
// categories), for the reject threshold. Their seed family is their own: the
// stored synthetic sketches never share a pose or a perturbation with them.
static sp_result calibration_set(sp_db* db, const sp_dataset* like, int per_part, sp_dataset* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    for (int c = 0; c < like->category_count; ++c)
        if (sp_dataset_add_category(out, like->categories[c]) < 0) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    sp_db_part_info* parts = NULL;
    int n = 0;
    sp_result r = sp_db_list_parts(db, &parts, &n, err);
    for (int i = 0; r == SP_OK && i < n; ++i) {
        int label = -1;
        for (int c = 0; c < out->category_count; ++c)
            if (!strcmp(out->categories[c], parts[i].category)) label = c;
        if (label < 0) continue;
        sp_character ch = {0};
        if ((r = sp_db_load_part(db, parts[i].name, &ch, err)) != SP_OK) break;
        int a = sp_rig_find_abstraction(&ch.rig, parts[i].abstraction);
        if (a < 0) a = 0;
        sp_handdraw_desc hd = {.style = SP_HANDDRAW_HARSH};
        r = sp_handdraw_dataset(&ch.rig, a, &ch.camera, &hd, sp_handdraw_part_family(0xCA1B4A7Eu, parts[i].name), per_part, label, out->count,
                                out, err);
        sp_character_free(&ch);
    }
    free(parts);
    if (r != SP_OK) sp_dataset_free(out);
    return r;
}

// The training report's first fields: what the set holds.
static void report_head(db_str* rep, const char* cats, int drawings, const db_training_counts* n, int folds)
{
    db_str_printf(
        rep,
        "{\"categories\": %s, \"drawings\": %d, \"kiosk_sketches\": %d, \"curated_sketches\": %d, \"curated_left_out\": %d,"
        " \"unused_drawings\": %d, \"folds\": %d",
        cats ? cats : "[]", drawings, n->kiosk, n->curated, n->curated_left_out, n->unused, folds);
}

// Rows of `table`; -1 when it cannot be read.
static int count_rows(sp_db* db, const char* table)
{
    char sql[64];
    snprintf(sql, sizeof sql, "SELECT count(*) FROM %s", table);
    sqlite3_stmt* st = NULL;
    int n = -1;
    if (sqlite3_prepare_v2(db->h, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return n;
}

// What sp_db_train stores.
typedef struct stored_model {
    const void* bytes;
    size_t size;
    const char *sha, *categories, *options, *by;
    const sp_dataset* ds; // what it was trained on
    int keep_models;      // sp_db_train_desc's
} stored_model;

// Stores the model with its report (closed here, with "models_removed") in
// one transaction, unless the parts changed while it trained (it would not
// match them), and removes the models past the newest keep_models.
static sp_result store_model(sp_db* db, const stored_model* m, db_str* rep, sp_error* err)
{
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    char** now;
    int nnow;
    if ((r = sp_db_categories(db, &now, &nnow, err)) != SP_OK) goto rollback;
    bool same = nnow == m->ds->category_count;
    for (int c = 0; same && c < nnow; ++c)
        same = !strcmp(now[c], m->ds->categories[c]);
    sp_db_free_strings(now, nnow);
    if (!same) {
        r = sp_fail(err, SP_ERR_BUSY, "%s: the part categories changed while training; train again", db->path);
        goto rollback;
    }
    int keep = m->keep_models ? m->keep_models : SP_DB_KEEP_MODELS;
    int stored = keep > 0 ? count_rows(db, "models") : 0;
    if (stored < 0) {
        r = sp_fail(err, SP_ERR_IO, "%s: the models cannot be counted", db->path);
        goto rollback;
    }
    int removed = keep > 0 && stored + 1 > keep ? stored + 1 - keep : 0;
    db_str_printf(rep, ", \"models_removed\": %d}", removed);
    if (rep->oom) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto rollback;
    }
    sqlite3_stmt* st;
    if ((r = db_prepare(db, "INSERT INTO models(model, sha256, categories, options, report, created_by) VALUES (?,?,?,?,?,?)",
                        &st, err)) != SP_OK)
        goto rollback;
    if ((r = db_bind_blob(db, st, 1, m->bytes, m->size, "the model", err)) != SP_OK) goto rollback;
    sqlite3_bind_text(st, 2, m->sha, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 3, m->categories, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 4, m->options, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 5, rep->s, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 6, db_who(m->by), -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        r = db_fail(db, rc, "storing the model", err);
        goto rollback;
    }
    DB_HOOK("model");
    char subject[32];
    snprintf(subject, sizeof subject, "model %lld", (long long)sqlite3_last_insert_rowid(db->h));
    if (removed > 0) {
        // The newest is never among them, so row ids only grow (a reader compares them: sp_db_model_head).
        char sql[128];
        snprintf(sql, sizeof sql, "DELETE FROM models WHERE id NOT IN (SELECT id FROM models ORDER BY id DESC LIMIT %d)", keep);
        if ((rc = sqlite3_exec(db->h, sql, NULL, NULL, NULL)) != SQLITE_OK) {
            r = db_fail(db, rc, "removing older models", err);
            goto rollback;
        }
    }
    if ((r = db_log_row(db, m->by, "train", subject, rep->s, err)) != SP_OK) goto rollback;
    return db_commit(db, err);
rollback:
    db_rollback(db);
    return r;
}

sp_result sp_db_train(sp_db* db, const sp_db_train_desc* desc, char** report_json, sp_error* err)
{
    if (report_json) *report_json = NULL;
    sp_db_train_desc d = desc ? *desc : (sp_db_train_desc){0};
    if (d.clf.shape_weight == 0.0) d.clf.shape_weight = SP_DB_SHAPE_WEIGHT;
    int folds = d.folds == 0 ? 3 : d.folds < 0 ? 0 : d.folds;
    double t0 = now_s();
    sp_dataset ds;
    db_training_counts n = {0};
    sp_result r =
        db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, d.curated_max ? d.curated_max : SP_DB_CURATED_TRAIN_MAX, &ds, &n, err);
    if (r != SP_OK) return r;
    sp_clf* clf = NULL;
    void* bytes = NULL;
    size_t size = 0;
    char *opts = NULL, *cats_s = NULL;
    db_str rep = {0};
    int* n_cls = calloc((size_t)(ds.category_count > 0 ? ds.category_count : 1), sizeof(int));
    int* ok_cls = calloc((size_t)(ds.category_count > 0 ? ds.category_count : 1), sizeof(int));
    unsigned char* use = malloc((size_t)(ds.count > 0 ? ds.count : 1));
    if (!n_cls || !ok_cls || !use) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    if (ds.category_count == 0) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: no parts, so nothing to train (add parts first)", db->path);
        goto done;
    }
    for (int i = 0; i < ds.count; ++i)
        n_cls[ds.samples[i].label]++;
    for (int c = 0; c < ds.category_count; ++c)
        if (n_cls[c] == 0) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: category '%s' has parts but no sketches (add-sketch --category %s ...)", db->path,
                        ds.categories[c], ds.categories[c]);
            goto done;
        }
    // Cross-validation for the report: fold f holds out the drawings whose
    // index within their category is f modulo the fold count.
    int cv_n = 0, cv_ok = 0;
    double t_cv = now_s();
    for (int f = 0; f < folds; ++f) {
        for (int i = 0; i < ds.count; ++i)
            use[i] = (unsigned char)(ds.samples[i].index % folds != f);
        sp_clf* m = NULL;
        if ((r = sp_clf_train(&ds, use, &d.clf, &m, err)) != SP_OK) goto done;
        for (int i = 0; i < ds.count; ++i) {
            if (use[i]) continue;
            bool ok = classify_ok(m, &ds.samples[i]);
            ok_cls[ds.samples[i].label] += ok;
            cv_ok += ok;
            ++cv_n;
        }
        sp_clf_destroy(m);
    }
    t_cv = now_s() - t_cv;
    double t_train = now_s();
    if ((r = sp_clf_train(&ds, NULL, &d.clf, &clf, err)) != SP_OK) goto done;
    int n_cal = d.calibrate == 0 ? 50 : d.calibrate < 0 ? 0 : d.calibrate;
    double q_cal = d.calibrate_quantile > 0 && d.calibrate_quantile <= 1 ? d.calibrate_quantile : 0.96;
    if (n_cal > 0) {
        sp_dataset cal;
        if ((r = calibration_set(db, &ds, n_cal, &cal, err)) != SP_OK) goto done;
        r = sp_clf_calibrate_reject(clf, &cal, NULL, q_cal, 1.0, NULL, NULL, err);
        n_cal = cal.count;
        sp_dataset_free(&cal);
        if (r != SP_OK) goto done;
    }
    t_train = now_s() - t_train;
    if ((r = sp_clf_to_bytes(clf, &bytes, &size, err)) != SP_OK) goto done;
    sp_clf_desc resolved = sp_clf_get_desc(clf);
    opts = desc_json(&resolved);
    db_str cb = {0};
    cats_json(&cb, ds.categories, ds.category_count);
    cats_s = cb.s;
    report_head(&rep, cats_s, ds.count, &n, folds);
    if (folds > 0) {
        db_str_printf(&rep, ", \"top1\": %.4f, \"per_class\": {", cv_n ? (double)cv_ok / cv_n : 0.0);
        for (int c = 0; c < ds.category_count; ++c) {
            db_str_printf(&rep, "%s", c ? ", " : "");
            db_str_json(&rep, ds.categories[c]);
            db_str_printf(&rep, ": {\"recall\": %.4f, \"n\": %d}", (double)ok_cls[c] / n_cls[c], n_cls[c]);
        }
        db_str_printf(&rep, "}");
    }
    float reject = sp_clf_reject_distance(clf);
    db_str_printf(&rep, ", \"seconds_train\": %.3f, \"seconds_cv\": %.3f, \"reject_distance\": %.4f", t_train, t_cv,
                  isfinite(reject) ? reject : -1.0);
    if (n_cal > 0) db_str_printf(&rep, ", \"calibration\": {\"sketches\": %d, \"quantile\": %.4g}", n_cal, q_cal);
    if (!opts || !cats_s || cb.oom || rep.oom) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    char sha[65];
    if (!sp_sha256_hex(bytes, size, sha)) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    r = store_model(db, &(stored_model){bytes, size, sha, cats_s, opts, d.by, &ds, d.keep_models}, &rep, err);
done:
    (void)t0;
    if (r == SP_OK && report_json) {
        *report_json = rep.s;
        rep.s = NULL;
    }
    free(rep.s);
    free(opts);
    free(cats_s);
    free(bytes);
    free(use);
    free(n_cls);
    free(ok_cls);
    sp_clf_destroy(clf);
    sp_dataset_free(&ds);
    return r;
}

sp_result sp_db_load_model(sp_db* db, sp_clf** out, int64_t* id, sp_error* err)
{
    *out = NULL;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT id, model, sha256 FROM models ORDER BY id DESC LIMIT 1", &st, err);
    if (r != SP_OK) return r;
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        const void* b = sqlite3_column_blob(st, 1);
        size_t n = (size_t)sqlite3_column_bytes(st, 1);
        char sha[65], what[600];
        snprintf(what, sizeof what, "%s: model %lld", db->path, (long long)sqlite3_column_int64(st, 0));
        if (!sp_sha256_hex(b, n, sha))
            r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
        else if (strcmp(sha, (const char*)sqlite3_column_text(st, 2)) != 0)
            r = sp_fail(err, SP_ERR_PARSE, "%s: stored bytes do not match the checksum", what);
        else
            r = sp_clf_from_bytes(b, n, what, out, err);
        if (r == SP_OK && id) *id = sqlite3_column_int64(st, 0);
    } else if (rc == SQLITE_DONE) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: no trained model (run `sketchpose db train`)", db->path);
    } else {
        r = db_fail(db, rc, "reading the model", err);
    }
    sqlite3_finalize(st);
    return r;
}

sp_result sp_db_model_head(sp_db* db, int64_t* id, char sha256[65], sp_error* err)
{
    *id = 0;
    if (sha256) sha256[0] = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, sha256 ? "SELECT id, sha256 FROM models ORDER BY id DESC LIMIT 1" : "SELECT max(id) FROM models",
                             &st, err);
    if (r != SP_OK) return r;
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        *id = sqlite3_column_int64(st, 0); // max() of no rows is NULL: 0
        const char* s = sha256 ? (const char*)sqlite3_column_text(st, 1) : NULL;
        if (sha256) snprintf(sha256, 65, "%s", s ? s : "");
    } else if (rc != SQLITE_DONE) {
        r = db_fail(db, rc, "reading the model", err);
    }
    sqlite3_finalize(st);
    return r;
}

// ---- check -------------------------------------------------------------------

static void problem(db_str* b, int* n, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void problem(db_str* b, int* n, const char* fmt, ...)
{
    char line[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    db_str_printf(b, "%s", (*n)++ ? ", " : "");
    db_str_json(b, line);
}

sp_result sp_db_check(sp_db* db, bool* ok, char** json, sp_error* err)
{
    *ok = false;
    if (json) *json = NULL;
    db_str pb = {0};
    int np = 0;
    sp_result r = db_exec(db, "BEGIN", err); // one snapshot for every check
    if (r != SP_OK) return r;
    char integrity[256] = "";
    sqlite3_stmt* st;
    if ((r = db_prepare(db, "PRAGMA integrity_check", &st, err)) != SP_OK) goto out;
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        const char* line = (const char*)sqlite3_column_text(st, 0);
        if (!integrity[0]) snprintf(integrity, sizeof integrity, "%s", line);
        if (strcmp(line, "ok") != 0) problem(&pb, &np, "integrity: %s", line);
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) problem(&pb, &np, "integrity check failed: %s", sqlite3_errstr(rc));
    if ((r = db_prepare(db, "PRAGMA foreign_key_check", &st, err)) != SP_OK) goto out;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW)
        problem(&pb, &np, "foreign key: %s row %lld refers to a missing %s", sqlite3_column_text(st, 0),
                (long long)sqlite3_column_int64(st, 1), sqlite3_column_text(st, 2));
    sqlite3_finalize(st);
    // Every part loads from its bytes and matches its checksum and size.
    if ((r = db_prepare(db, "SELECT name, gltf, sha256, bytes FROM parts ORDER BY name", &st, err)) != SP_OK) goto out;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        const char* name = (const char*)sqlite3_column_text(st, 0);
        const void* b = sqlite3_column_blob(st, 1);
        size_t n = (size_t)sqlite3_column_bytes(st, 1);
        char sha[65];
        if (!sp_sha256_hex(b, n, sha))
            problem(&pb, &np, "part %s: checksum not computed (out of memory)", name);
        else if (strcmp(sha, (const char*)sqlite3_column_text(st, 2)) != 0)
            problem(&pb, &np, "part %s: checksum mismatch", name);
        if ((sqlite3_int64)n != sqlite3_column_int64(st, 3)) problem(&pb, &np, "part %s: size mismatch", name);
        sp_character ch = {0};
        sp_error e = {0};
        if (sp_gltf_load_memory(b, n, name, &ch, &e) != SP_OK) problem(&pb, &np, "part %s does not load: %s", name, e.text);
        sp_character_free(&ch);
    }
    sqlite3_finalize(st);
    // Every sketch parses.
    if ((r = db_prepare(db, "SELECT id, strokes, raster_w, raster_h, length(raster) FROM sketches", &st, err)) != SP_OK) goto out;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        long long id = sqlite3_column_int64(st, 0);
        if (sqlite3_column_type(st, 1) != SQLITE_NULL) {
            sp_sketch s = {0};
            sp_error e = {0};
            if (sp_sketch_parse_json((const char*)sqlite3_column_text(st, 1), (size_t)sqlite3_column_bytes(st, 1), "sketch", &s, &e) != SP_OK)
                problem(&pb, &np, "sketch %lld does not parse: %s", id, e.text);
            sp_sketch_free(&s);
        } else if ((long long)sqlite3_column_int(st, 2) * sqlite3_column_int(st, 3) != sqlite3_column_int64(st, 4)) {
            problem(&pb, &np, "sketch %lld: raster size does not match its pixels", id);
        }
    }
    sqlite3_finalize(st);
    // The newest model loads and knows exactly the current part categories.
    int models = count_rows(db, "models");
    if (models > 0) {
        sp_clf* clf = NULL;
        sp_error e = {0};
        if (sp_db_load_model(db, &clf, NULL, &e) != SP_OK) problem(&pb, &np, "newest model: %s", e.text);
        else {
            char** cats;
            int n;
            if ((r = sp_db_categories(db, &cats, &n, err)) != SP_OK) {
                sp_clf_destroy(clf);
                goto out;
            }
            bool same = n == sp_clf_category_count(clf);
            for (int i = 0; same && i < n; ++i)
                same = !strcmp(cats[i], sp_clf_category(clf, i));
            if (!same) {
                db_str a = {0}, b = {0};
                cats_json(&a, cats, n);
                db_str_printf(&b, "[");
                for (int i = 0; i < sp_clf_category_count(clf); ++i) {
                    db_str_printf(&b, "%s", i ? ", " : "");
                    db_str_json(&b, sp_clf_category(clf, i));
                }
                db_str_printf(&b, "]");
                problem(&pb, &np, "newest model's categories %s differ from the parts' %s: run `sketchpose db train`", b.s ? b.s : "",
                        a.s ? a.s : "");
                free(a.s);
                free(b.s);
            }
            sp_db_free_strings(cats, n);
            sp_clf_destroy(clf);
        }
    } else if (count_rows(db, "parts") > 0) {
        problem(&pb, &np, "no trained model: run `sketchpose db train`");
    }
    *ok = np == 0;
    if (json) {
        db_str b = {0};
        db_str_printf(&b, "{\"ok\": %s, \"integrity\": ", *ok ? "true" : "false");
        db_str_json(&b, integrity);
        db_str_printf(&b, ", \"schema\": %d, \"generation\": %llu, \"parts\": %d, \"sketches\": %d, \"models\": %d, \"problems\": [%s]}",
                      sp_db_schema_version(db), (unsigned long long)sp_db_generation(db), count_rows(db, "parts"),
                      count_rows(db, "sketches"), models, pb.s ? pb.s : "");
        if (b.oom || pb.oom) {
            free(b.s);
            r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        } else {
            *json = b.s;
        }
    }
out:
    free(pb.s);
    db_rollback(db);
    return r;
}

sp_result sp_db_models_json(sp_db* db, char** json, sp_error* err)
{
    *json = NULL;
    sqlite3_stmt* st;
    sp_result r =
        db_prepare(db, "SELECT id, created_at, created_by, length(model), categories, options, report FROM models ORDER BY id DESC", &st, err);
    if (r != SP_OK) return r;
    db_str b = {0};
    db_str_printf(&b, "[");
    int rc, n = 0;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        db_str_printf(&b, "%s{\"id\": %lld, \"created_at\": ", n++ ? ", " : "", (long long)sqlite3_column_int64(st, 0));
        db_str_json(&b, (const char*)sqlite3_column_text(st, 1));
        db_str_printf(&b, ", \"created_by\": ");
        db_str_json(&b, (const char*)sqlite3_column_text(st, 2));
        db_str_printf(&b, ", \"bytes\": %lld, \"categories\": %s, \"options\": %s, \"report\": %s}", (long long)sqlite3_column_int64(st, 3),
                      sqlite3_column_text(st, 4), sqlite3_column_text(st, 5), sqlite3_column_text(st, 6));
    }
    sqlite3_finalize(st);
    db_str_printf(&b, "]");
    if (rc != SQLITE_DONE || b.oom) {
        free(b.s);
        return rc != SQLITE_DONE ? db_fail(db, rc, "listing models", err) : sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    *json = b.s;
    return SP_OK;
}
