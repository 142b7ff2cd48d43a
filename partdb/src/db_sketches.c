// db_sketches.c: example sketches: stored as sketchpose-strokes JSON (or a
// PNG's grey pixels), read back as a classifier dataset.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "db_internal.h"
#include "sp/part.h"
#include "sp/sketch_io.h"

const char* sp_db_source_name(sp_db_source s)
{
    switch (s) {
    case SP_DB_SOURCE_SYNTHETIC: return "synthetic";
    case SP_DB_SOURCE_CURATED: return "curated";
    case SP_DB_SOURCE_KIOSK: return "kiosk";
    }
    return "curated";
}

sp_result db_sample_ok(const sp_sample* smp, const char* what, sp_error* err)
{
    if (smp->raster.pixels) {
        if (smp->raster.w <= 0 || smp->raster.h <= 0) return sp_fail(err, SP_ERR_INVALID, "%s: empty image", what);
        return SP_OK;
    }
    if (smp->sketch.stroke_count == 0 || sp_sketch_point_count(&smp->sketch) == 0)
        return sp_fail(err, SP_ERR_INVALID, "%s: empty drawing (no strokes)", what);
    const sp_sketch* sk = &smp->sketch;
    if (!sp_sketch_is_valid(sk) || !isfinite(sk->canvas_w) || !isfinite(sk->canvas_h))
        return sp_fail(err, SP_ERR_INVALID, "%s: a coordinate or time is not a finite number", what);
    // Stored, it must read back: one sketch beyond the readers' limits would
    // stop every training run and review page that reaches it.
    if (sk->canvas_w < 0 || sk->canvas_h < 0 || sk->canvas_w > SP_SKETCH_CANVAS_MAX || sk->canvas_h > SP_SKETCH_CANVAS_MAX)
        return sp_fail(err, SP_ERR_INVALID, "%s: canvas %g x %g (0 to %g a side)", what, sk->canvas_w, sk->canvas_h,
                       SP_SKETCH_CANVAS_MAX);
    for (int i = 0; i < sk->stroke_count; ++i) {
        const sp_stroke* k = &sk->strokes[i];
        if (k->count < 1) return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d is empty", what, i);
        for (int j = 0; j < k->count; ++j)
            if (fabs(k->points[j].x) > SP_SKETCH_COORD_MAX || fabs(k->points[j].y) > SP_SKETCH_COORD_MAX)
                return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d point %d is beyond %g", what, i, j, SP_SKETCH_COORD_MAX);
    }
    return SP_OK;
}

sp_result db_insert_sketch(sp_db* db, const char* category, sp_db_source source, int64_t part_id, const sp_sample* smp,
                           const sp_db_png* png, const char* by, sp_error* err)
{
    sqlite3_stmt* st;
    // A kiosk sketch a curator adds is reviewed by that act: approved.
    sp_result r = db_prepare(
        db,
        "INSERT INTO sketches(id, category, source, part_id, strokes, raster_w, raster_h, raster, png, added_by, status)"
        " VALUES (" DB_SKETCH_ID_HIGH " + 1, ?1,?2,?3,?4,?5,?6,?7,?8,?9, CASE WHEN ?2 = 'kiosk' THEN 'approved' END)",
        &st, err);
    if (r != SP_OK) return r;
    char* json = NULL;
    sqlite3_bind_text(st, 1, category, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, sp_db_source_name(source), -1, SQLITE_STATIC);
    if (part_id > 0) sqlite3_bind_int64(st, 3, part_id);
    if (smp->raster.pixels) {
        sqlite3_bind_int(st, 5, smp->raster.w);
        sqlite3_bind_int(st, 6, smp->raster.h);
        size_t n = (size_t)smp->raster.w * (size_t)smp->raster.h;
        if ((r = db_bind_blob(db, st, 7, smp->raster.pixels, n, "the drawing's picture", err)) != SP_OK) return r;
        if (png && png->bytes && (r = db_bind_blob(db, st, 8, png->bytes, png->size, "the drawing's PNG", err)) != SP_OK)
            return r;
    } else {
        if (!(json = sp_sketch_to_json(&smp->sketch, DB_SKETCH_DIGITS))) {
            sqlite3_finalize(st);
            return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        }
        sqlite3_bind_text(st, 4, json, -1, SQLITE_STATIC);
    }
    sqlite3_bind_text(st, 9, db_who(by), -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    free(json);
    return rc == SQLITE_DONE ? SP_OK : db_fail(db, rc, "storing a sketch", err);
}

const char* sp_db_kiosk_sketch_problem(const sp_sample* smp)
{
    const sp_sketch* k = &smp->sketch;
    if (smp->raster.pixels) return "a picture";
    if (k->stroke_count != 1) return "several strokes";
    if (k->strokes[0].count > SP_DB_KIOSK_POINTS_MAX) return "one stroke of too many points";
    if (k->strokes[0].count < 2) return "one stroke of fewer than 2 points";
    return NULL;
}

sp_result sp_db_add_sketches(sp_db* db, const sp_dataset* data, const sp_db_png* png, sp_db_source source, const char* by, int* added,
                             sp_error* err)
{
    if (added) *added = 0;
    // Validate everything first: a bad drawing refuses the whole set.
    for (int i = 0; i < data->count; ++i) {
        const sp_sample* s = &data->samples[i];
        char what[96];
        snprintf(what, sizeof what, "drawing %d", i);
        if (s->label < 0 || s->label >= data->category_count) return sp_fail(err, SP_ERR_INVALID, "%s: no category", what);
        char shown[128];
        if (!sp_part_name_is_plain(data->categories[s->label]))
            return sp_fail(err, SP_ERR_INVALID, "category '%s' is not a plain name ([A-Za-z0-9_.-], < 64)",
                           sp_text_printable(data->categories[s->label], shown, sizeof shown));
        sp_result r = db_sample_ok(s, what, err);
        if (r != SP_OK) return r;
        // Review shows and trains on a kiosk sketch's one stroke: 200,000
        // strokes were listed as one, and a million points stalled a sheet.
        const char* why = source == SP_DB_SOURCE_KIOSK ? sp_db_kiosk_sketch_problem(s) : NULL;
        if (why)
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: a kiosk sketch is one stroke of 2..%d points; this is %s (add it as curated)", what,
                           SP_DB_KIOSK_POINTS_MAX, why);
    }
    if (data->count == 0) return sp_fail(err, SP_ERR_INVALID, "no drawings to add");
    // Categories differing only in case (a folder `Head` beside the parts'
    // `head`) were stored apart and never trained on, with a warning that
    // asked for a part of that category (an outside review).
    for (int a = 0; a < data->category_count; ++a)
        for (int b = a + 1; b < data->category_count; ++b)
            if (!strcasecmp(data->categories[a], data->categories[b]))
                return sp_fail(err, SP_ERR_INVALID, "categories '%s' and '%s' differ only in case (use one)", data->categories[a],
                               data->categories[b]);
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    for (int c = 0; c < data->category_count; ++c)
        if ((r = db_category_case_clash(db, data->categories[c], err)) != SP_OK) {
            db_rollback(db);
            return r;
        }
    for (int i = 0; i < data->count; ++i) {
        const sp_sample* s = &data->samples[i];
        if ((r = db_insert_sketch(db, data->categories[s->label], source, 0, s, png ? &png[i] : NULL, by, err)) != SP_OK) {
            db_rollback(db);
            return r;
        }
        if (i == data->count / 2) DB_HOOK("sketches");
    }
    db_str b = {0};
    db_str_printf(&b, "{\"source\": \"%s\", \"count\": %d, \"categories\": [", sp_db_source_name(source), data->count);
    for (int c = 0; c < data->category_count; ++c) {
        db_str_printf(&b, "%s", c ? ", " : "");
        db_str_json(&b, data->categories[c]);
    }
    db_str_printf(&b, "]}");
    r = b.oom ? sp_fail(err, SP_ERR_NO_MEMORY, "out of memory")
              : db_log_row(db, by, "add-sketches", data->category_count == 1 ? data->categories[0] : NULL, b.s, err);
    free(b.s);
    if (r != SP_OK) {
        db_rollback(db);
        return r;
    }
    if ((r = db_commit(db, err)) == SP_OK && added) *added = data->count;
    return r;
}

sp_result sp_db_sketch_counts(sp_db* db, char*** categories, int** counts, int* count, sp_error* err)
{
    *categories = NULL;
    *counts = NULL;
    *count = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db,
                             "SELECT category, count(*) FROM sketches WHERE source <> 'kiosk' OR status = 'approved'"
                             " GROUP BY category ORDER BY category",
                             &st, err);
    if (r != SP_OK) return r;
    int rc, n = 0, cap = 0;
    char** names = NULL;
    int* cnt = NULL;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (n == cap) {
            cap = cap ? 2 * cap : 8;
            char** g = realloc(names, sizeof *names * (size_t)cap);
            if (g) names = g;
            int* h = realloc(cnt, sizeof *cnt * (size_t)cap);
            if (h) cnt = h;
            if (!g || !h) break;
        }
        if (!(names[n] = strdup((const char*)sqlite3_column_text(st, 0)))) break;
        cnt[n++] = sqlite3_column_int(st, 1);
    }
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        sp_db_free_strings(names, n);
        free(cnt);
        return rc == SQLITE_ROW ? sp_fail(err, SP_ERR_NO_MEMORY, "out of memory") : db_fail(db, rc, "counting sketches", err);
    }
    *categories = names;
    *counts = cnt;
    *count = n;
    return SP_OK;
}

sp_result sp_db_sketch_count_by(sp_db* db, sp_db_source source, const char* by, int* count, sp_error* err)
{
    *count = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT count(*) FROM sketches WHERE source = ?1 AND added_by = ?2", &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, sp_db_source_name(source), -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, by, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) *count = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return rc == SQLITE_ROW ? SP_OK : db_fail(db, rc, "counting sketches", err);
}

static int find_cat(char** cats, int n, const char* c)
{
    int lo = 0, hi = n - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2, k = strcmp(cats[mid], c);
        if (k == 0) return mid;
        if (k < 0) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

sp_result sp_db_load_dataset(sp_db* db, sp_dataset* out, int* unused, sp_error* err)
{
    db_training_counts n = {0};
    sp_result r = db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, SP_DB_CURATED_TRAIN_MAX, out, &n, err);
    if (unused) *unused = n.unused;
    return r;
}

// Curated sketches past the cap: of the set's categories (cats, sorted) in
// n->curated_left_out, of others in n->unused (the rows never read).
static sp_result curated_past_cap(sp_db* db, char** cats, int ncat, int cap, db_training_counts* n, sp_error* err)
{
    if (cap < 0) return SP_OK;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT category, count(*) FROM sketches WHERE source = 'curated' GROUP BY category", &st, err);
    if (r != SP_OK) return r;
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        int past = sqlite3_column_int(st, 1) - cap;
        if (past <= 0) continue;
        if (find_cat(cats, ncat, (const char*)sqlite3_column_text(st, 0)) >= 0)
            n->curated_left_out += past;
        else
            n->unused += past;
    }
    if (rc != SQLITE_DONE) r = db_fail(db, rc, "counting curated sketches", err);
    sqlite3_finalize(st);
    return r;
}

sp_result db_load_training_set(sp_db* db, int kiosk_cap, int curated_max, sp_dataset* out, db_training_counts* counts,
                               sp_error* err)
{
    memset(out, 0, sizeof *out);
    db_training_counts n = {0};
    if (counts) *counts = n; // also when it fails early
    // One read transaction: categories and sketches are one consistent snapshot.
    sp_result r = db_exec(db, "BEGIN", err);
    if (r != SP_OK) return r;
    char** cats;
    int ncat;
    if ((r = sp_db_categories(db, &cats, &ncat, err)) != SP_OK) {
        db_rollback(db);
        return r;
    }
    out->categories = cats;
    out->category_count = ncat;
    sqlite3_stmt* st = NULL;
    // Every synthetic sketch; of the approved kiosk sketches the newest
    // `kiosk_cap` per category (a year of visitors would otherwise
    // swamp the parts' own sketches and the training time); of the curated
    // ones `curated_max` per category, ordered by a fixed hash of the id so
    // that they spread over all that were added, early and late (without a
    // cap a curator's tens of thousands made training slow and the kiosk
    // huge: BENCHMARKS.md, "Curated sketches in training").
    if ((r = curated_past_cap(db, cats, ncat, curated_max, &n, err)) != SP_OK ||
        (r = db_prepare(
             db,
             "SELECT id, category, strokes, raster_w, raster_h, raster, source FROM sketches"
             " WHERE source = 'synthetic' OR id IN (SELECT id FROM (SELECT id, row_number() OVER"
             " (PARTITION BY category ORDER BY id DESC) AS k FROM sketches WHERE source = 'kiosk' AND status = 'approved')"
             " WHERE k <= ?1) OR id IN (SELECT id FROM (SELECT id, row_number() OVER"
             " (PARTITION BY category ORDER BY (id * 2654435761) % 4294967311, id) AS k FROM sketches WHERE source = 'curated')"
             " WHERE ?2 < 0 OR k <= ?2) ORDER BY category, id",
             &st, err)) != SP_OK) {
        db_rollback(db);
        sp_dataset_free(out);
        return r;
    }
    sqlite3_bind_int(st, 1, kiosk_cap);
    sqlite3_bind_int(st, 2, curated_max);
    int rc;
    int* per_cat = calloc((size_t)(ncat > 0 ? ncat : 1), sizeof(int));
    if (!per_cat) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    while (r == SP_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        int label = find_cat(cats, ncat, (const char*)sqlite3_column_text(st, 1));
        if (label < 0) {
            ++n.unused;
            continue;
        }
        if (sp_dataset_reserve(out, 1) != SP_OK) {
            r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            break;
        }
        sp_sample* s = &out->samples[out->count];
        memset(s, 0, sizeof *s);
        s->label = label;
        s->index = per_cat[label]++;
        char what[96];
        snprintf(what, sizeof what, "%s: sketch %lld", db->path, (long long)sqlite3_column_int64(st, 0));
        if (sqlite3_column_type(st, 2) != SQLITE_NULL) {
            r = sp_sketch_parse_json((const char*)sqlite3_column_text(st, 2), (size_t)sqlite3_column_bytes(st, 2), what, &s->sketch, err);
        } else {
            int w = sqlite3_column_int(st, 3), h = sqlite3_column_int(st, 4);
            const void* px = sqlite3_column_blob(st, 5);
            if (w <= 0 || h <= 0 || !px || (size_t)sqlite3_column_bytes(st, 5) != (size_t)w * (size_t)h)
                r = sp_fail(err, SP_ERR_PARSE, "%s: raster size does not match its pixels", what);
            else if (!(s->raster.pixels = malloc((size_t)w * (size_t)h)))
                r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
            else {
                memcpy(s->raster.pixels, px, (size_t)w * (size_t)h);
                s->raster.w = w;
                s->raster.h = h;
            }
        }
        if (r == SP_OK) {
            ++out->count;
            const char* source = (const char*)sqlite3_column_text(st, 6);
            n.kiosk += source && !strcmp(source, "kiosk");
            n.curated += source && !strcmp(source, "curated");
        } else {
            sp_sketch_free(&s->sketch);
            sp_raster_free(&s->raster);
        }
    }
    if (r == SP_OK && rc != SQLITE_DONE) r = db_fail(db, rc, "reading sketches", err);
    sqlite3_finalize(st);
    db_rollback(db);
    free(per_cat);
    if (r != SP_OK) sp_dataset_free(out);
    if (counts) *counts = n;
    return r;
}
