// db_kiosk.c: visitors' strokes collected by the kiosk, and their review
// (sp/partdb.h, "visitors' strokes").
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "db_internal.h"
#include "sp/part.h"
#include "sp/sketch_io.h"

static const char* const k_status[SP_DB_STATUS_COUNT] = {"pending", "approved", "rejected"};

const char* sp_db_status_name(sp_db_status s)
{
    return s >= 0 && s < SP_DB_STATUS_COUNT ? k_status[s] : "?";
}

static sp_db_status status_of(const char* s)
{
    for (int i = 0; s && i < SP_DB_STATUS_COUNT; ++i)
        if (!strcmp(s, k_status[i])) return (sp_db_status)i;
    return SP_DB_PENDING;
}

void sp_db_set_kiosk_pending_max(sp_db* db, int max)
{
    db->kiosk_pending_max = max > 0 ? max : 0;
}

// SP_ERR_UNSUPPORTED when the pending kiosk sketches are at the handle's cap:
// counted inside the store's transaction (the index on (source, status, id)
// walks them; a few ms at the cap, on the collector's thread).
static sp_result pending_room(sp_db* db, sp_error* err)
{
    int max = db->kiosk_pending_max > 0 ? db->kiosk_pending_max : SP_DB_KIOSK_PENDING_MAX;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'pending'", &st, err);
    if (r != SP_OK) return r;
    int rc = sqlite3_step(st);
    long long pending = rc == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
    sqlite3_finalize(st);
    if (rc != SQLITE_ROW) return db_fail(db, rc, "counting pending kiosk sketches", err);
    if (pending >= max)
        return sp_fail(err, SP_ERR_UNSUPPORTED,
                       "%s: %lld kiosk sketches await review (`sketchpose db review`), the most kept is %d; none more is kept "
                       "until some are reviewed",
                       db->path, pending, max);
    return SP_OK;
}

sp_result sp_db_collect_kiosk_sketch(sp_db* db, const char* category, const sp_stroke* stroke, double canvas_w, double canvas_h,
                                     int64_t* id, sp_error* err)
{
    if (id) *id = 0;
    char shown[128];
    if (!sp_part_name_is_plain(category))
        return sp_fail(err, SP_ERR_INVALID, "%s: kiosk sketch: category '%s' is not a plain name; sketch dropped", db->path,
                       sp_text_printable(category, shown, sizeof shown));
    if (!stroke || stroke->count < 2 || stroke->count > SP_DB_KIOSK_POINTS_MAX)
        return sp_fail(err, SP_ERR_INVALID, "%s: kiosk sketch: %d points (2..%d); sketch dropped", db->path,
                       stroke ? stroke->count : 0, SP_DB_KIOSK_POINTS_MAX);
    sp_sample smp = {.sketch = {.canvas_w = canvas_w, .canvas_h = canvas_h, .stroke_count = 1, .strokes = (sp_stroke*)stroke}};
    sp_error why = {0};
    char what[sizeof why.text];
    snprintf(what, sizeof what, "%s: kiosk sketch", db->path);
    if (db_sample_ok(&smp, what, &why) != SP_OK) return sp_fail(err, SP_ERR_INVALID, "%s; sketch dropped", why.text);
    char* json = sp_sketch_to_json(&smp.sketch, DB_SKETCH_DIGITS);
    if (!json) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: kiosk sketch: out of memory; sketch dropped", db->path);
    // The UI thread must not wait: a short busy timeout, and a commit that
    // does not wait for the disk (WAL with synchronous NORMAL stays consistent
    // after a crash; a power cut may lose the last commits).
    int busy = db->busy_ms;
    sp_db_set_busy_timeout(db, SP_DB_COLLECT_BUSY_MS);
    sqlite3_exec(db->h, "PRAGMA synchronous = NORMAL", NULL, NULL, NULL);
    sqlite3_stmt* st = NULL;
    sp_result r = db_begin(db, err);
    if (r == SP_OK && (r = pending_room(db, err)) != SP_OK) db_rollback(db);
    if (r == SP_OK &&
        (r = db_prepare(db,
                        "INSERT INTO sketches(id, category, source, strokes, added_by, status) VALUES (" DB_SKETCH_ID_HIGH
                        " + 1, ?, 'kiosk', ?, 'kiosk', 'pending')",
                        &st, err)) == SP_OK) {
        sqlite3_bind_text(st, 1, category, -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, json, -1, SQLITE_STATIC);
        int rc = sqlite3_step(st);
        if (rc != SQLITE_DONE)
            r = db_fail(db, rc, "storing a kiosk sketch", err);
        else if (id)
            *id = sqlite3_last_insert_rowid(db->h);
        sqlite3_finalize(st);
        if (r == SP_OK)
            r = db_commit(db, err);
        else
            db_rollback(db);
    }
    if (!db->readonly) sqlite3_exec(db->h, "PRAGMA synchronous = FULL", NULL, NULL, NULL);
    sp_db_set_busy_timeout(db, busy);
    free(json);
    if (r != SP_OK && id) *id = 0;
    if (r != SP_OK && err) {
        char why[sizeof err->text];
        snprintf(why, sizeof why, "%s", err->text);
        sp_fail(err, r, "%s; sketch dropped", why);
    }
    return r;
}

sp_result sp_db_kiosk_counts(sp_db* db, int counts[SP_DB_STATUS_COUNT], sp_error* err)
{
    for (int i = 0; i < SP_DB_STATUS_COUNT; ++i)
        counts[i] = 0;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "SELECT status, count(*) FROM sketches WHERE source = 'kiosk' GROUP BY status", &st, err);
    if (r != SP_OK) return r;
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW)
        counts[status_of((const char*)sqlite3_column_text(st, 0))] += sqlite3_column_int(st, 1);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? SP_OK : db_fail(db, rc, "counting kiosk sketches", err);
}

void sp_db_kiosk_free(sp_db_kiosk_sketch* s, int count)
{
    for (int i = 0; s && i < count; ++i)
        sp_sketch_free(&s[i].sketch);
    free(s);
}

sp_result sp_db_kiosk_list(sp_db* db, const sp_db_kiosk_query* q, sp_db_kiosk_sketch** out, int* count, sp_error* err)
{
    *out = NULL;
    *count = 0;
    sp_db_kiosk_query d = q ? *q : (sp_db_kiosk_query){0};
    unsigned mask = d.statuses ? d.statuses : 1u << SP_DB_PENDING;
    // The statuses are our own constants: written into the query, one index range each.
    db_str sql = {0};
    db_str_printf(&sql, "SELECT id, category, status, added_at, strokes FROM sketches WHERE source = 'kiosk' AND status IN (");
    for (int i = 0, n = 0; i < SP_DB_STATUS_COUNT; ++i)
        if (mask & (1u << i)) db_str_printf(&sql, "%s'%s'", n++ ? ", " : "", k_status[i]);
    db_str_printf(&sql, ") AND id > ?1 ORDER BY id LIMIT ?2");
    if (sql.oom) {
        free(sql.s);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, sql.s, &st, err);
    free(sql.s);
    if (r != SP_OK) return r;
    sqlite3_bind_int64(st, 1, d.after);
    sqlite3_bind_int64(st, 2, d.limit > 0 ? d.limit : -1);
    sp_db_kiosk_sketch* v = NULL;
    int n = 0, cap = 0, rc;
    while (r == SP_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            sp_db_kiosk_sketch* g = realloc(v, sizeof *g * (size_t)cap);
            if (!g) {
                r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
                break;
            }
            v = g;
        }
        sp_db_kiosk_sketch* k = &v[n];
        memset(k, 0, sizeof *k);
        k->id = sqlite3_column_int64(st, 0);
        snprintf(k->category, sizeof k->category, "%s", (const char*)sqlite3_column_text(st, 1));
        k->status = status_of((const char*)sqlite3_column_text(st, 2));
        snprintf(k->created_at, sizeof k->created_at, "%s", (const char*)sqlite3_column_text(st, 3));
        char what[96];
        snprintf(what, sizeof what, "%s: kiosk sketch %lld", db->path, (long long)k->id);
        const char* text = (const char*)sqlite3_column_text(st, 4);
        if (!text)
            r = sp_fail(err, SP_ERR_PARSE, "%s: no strokes", what);
        else
            r = sp_sketch_parse_json(text, (size_t)sqlite3_column_bytes(st, 4), what, &k->sketch, err);
        if (r == SP_OK) ++n;
    }
    if (r == SP_OK && rc != SQLITE_DONE) r = db_fail(db, rc, "reading kiosk sketches", err);
    sqlite3_finalize(st);
    if (r != SP_OK) {
        sp_db_kiosk_free(v, n);
        return r;
    }
    *out = v;
    *count = n;
    return SP_OK;
}

// One UPDATE of one kiosk sketch inside the caller's transaction; SP_ERR_INVALID when id is not one.
static sp_result update_one(sp_db* db, const char* sql, const char* value, int64_t id, sp_error* err)
{
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, sql, &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, value, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, id);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) return db_fail(db, rc, "reviewing kiosk sketches", err);
    if (sqlite3_changes(db->h) == 0)
        return sp_fail(err, SP_ERR_INVALID, "%s: no kiosk sketch %lld; nothing was changed", db->path, (long long)id);
    return SP_OK;
}

typedef struct id_list {
    int64_t* v;
    int n, cap;
} id_list;

static bool id_push(id_list* l, int64_t id)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 64;
        int64_t* g = realloc(l->v, sizeof(int64_t) * (size_t)cap);
        if (!g) return false;
        l->v = g, l->cap = cap;
    }
    l->v[l->n++] = id;
    return true;
}

static int cmp_id(const void* a, const void* b)
{
    int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
    return (x > y) - (x < y);
}

// The pending kiosk sketches of one range to `status`, inside the caller's
// transaction, their ids appended to `set`; SP_ERR_INVALID when it has none.
static sp_result update_range(sp_db* db, const sp_db_kiosk_range* g, const char* status, id_list* set, sp_error* err)
{
    sqlite3_stmt* st;
    sp_result r =
        db_prepare(db,
                   "UPDATE sketches SET status = ?1 WHERE source = 'kiosk' AND status = 'pending' AND id BETWEEN ?2 AND ?3"
                   " RETURNING id",
                   &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, status, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, g->first);
    sqlite3_bind_int64(st, 3, g->last);
    int rc, found = 0;
    while (r == SP_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        ++found;
        if (!id_push(set, sqlite3_column_int64(st, 0))) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    if (r == SP_OK && rc != SQLITE_DONE) r = db_fail(db, rc, "reviewing kiosk sketches", err);
    sqlite3_finalize(st);
    if (r == SP_OK && found == 0)
        r = sp_fail(err, SP_ERR_INVALID, "%s: no pending kiosk sketch in %lld-%lld; nothing was changed", db->path,
                    (long long)g->first, (long long)g->last);
    return r;
}

sp_result sp_db_kiosk_set_status(sp_db* db, const int64_t* ids, int n, sp_db_status status, const char* by, sp_error* err)
{
    if (n <= 0) return sp_fail(err, SP_ERR_INVALID, "%s: no kiosk sketch ids given", db->path);
    return sp_db_kiosk_review(db, ids, n, NULL, 0, status, by, NULL, NULL, err);
}

sp_result sp_db_kiosk_review(sp_db* db, const int64_t* ids, int n, const sp_db_kiosk_range* ranges, int nr, sp_db_status status,
                             const char* by, int64_t** changed, int* n_changed, sp_error* err)
{
    if (changed) *changed = NULL;
    if (n_changed) *n_changed = 0;
    if (status < 0 || status >= SP_DB_STATUS_COUNT) return sp_fail(err, SP_ERR_INVALID, "unknown review status");
    if (n <= 0 && nr <= 0) return sp_fail(err, SP_ERR_INVALID, "%s: no kiosk sketch ids given", db->path);
    for (int i = 0; i < nr; ++i)
        if (ranges[i].first > ranges[i].last)
            return sp_fail(err, SP_ERR_INVALID, "%s: the range %lld-%lld is empty", db->path, (long long)ranges[i].first,
                           (long long)ranges[i].last);
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    id_list set = {0};
    // Ranges first: an id also named alone is then set again, not missed
    // by its range as no longer pending.
    for (int i = 0; r == SP_OK && i < nr; ++i)
        r = update_range(db, &ranges[i], k_status[status], &set, err);
    for (int i = 0; r == SP_OK && i < n; ++i) {
        r = update_one(db, "UPDATE sketches SET status = ?1 WHERE id = ?2 AND source = 'kiosk'", k_status[status], ids[i], err);
        if (r == SP_OK && !id_push(&set, ids[i])) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    int m = 0;
    if (r == SP_OK && set.n > 0) {
        qsort(set.v, (size_t)set.n, sizeof(int64_t), cmp_id);
        for (int i = 0; i < set.n; ++i)
            if (i == 0 || set.v[i] != set.v[m - 1]) set.v[m++] = set.v[i];
    }
    db_str b = {0};
    db_str_printf(&b, "{\"status\": \"%s\", \"ids\": [", k_status[status]);
    for (int i = 0; r == SP_OK && i < m; ++i)
        db_str_printf(&b, "%s%lld", i ? ", " : "", (long long)set.v[i]);
    db_str_printf(&b, "]}");
    if (r == SP_OK)
        r = b.oom ? sp_fail(err, SP_ERR_NO_MEMORY, "out of memory") : db_log_row(db, by, "review", "kiosk sketches", b.s, err);
    free(b.s);
    if (r == SP_OK)
        r = db_commit(db, err);
    else
        db_rollback(db);
    if (r == SP_OK && changed) {
        *changed = set.v;
        set.v = NULL;
    }
    if (r == SP_OK && n_changed) *n_changed = m;
    free(set.v);
    return r;
}

sp_result sp_db_kiosk_relabel(sp_db* db, int64_t id, const char* category, const char* by, sp_error* err)
{
    char** cats;
    int ncat;
    sp_result r = sp_db_categories(db, &cats, &ncat, err);
    if (r != SP_OK) return r;
    bool known = false;
    for (int i = 0; category && i < ncat; ++i)
        known |= !strcmp(cats[i], category);
    sp_db_free_strings(cats, ncat);
    char shown[128];
    if (!known)
        return sp_fail(err, SP_ERR_INVALID, "%s: '%s' is not a part category (see `sketchpose db list`); nothing was changed",
                       db->path, sp_text_printable(category, shown, sizeof shown));
    if ((r = db_begin(db, err)) != SP_OK) return r;
    r = update_one(db, "UPDATE sketches SET category = ?1 WHERE id = ?2 AND source = 'kiosk'", category, id, err);
    if (r == SP_OK) {
        char details[160], subject[48];
        snprintf(details, sizeof details, "{\"category\": \"%s\"}", category);
        snprintf(subject, sizeof subject, "kiosk sketch %lld", (long long)id);
        r = db_log_row(db, by, "relabel", subject, details, err);
    }
    if (r != SP_OK) {
        db_rollback(db);
        return r;
    }
    return db_commit(db, err);
}

sp_result sp_db_kiosk_delete_rejected(sp_db* db, const char* by, int* deleted, sp_error* err)
{
    if (deleted) *deleted = 0;
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    // The highest id so far is kept (meta 'sketch_id_high', DB_SKETCH_ID_HIGH):
    // SQLite gives a new row the highest id left plus one, so the newest ones
    // deleted would be given again, and the log's rejected ids and a review's
    // --after would name other visitors' strokes (an operations review).
    int rc = sqlite3_exec(db->h, "INSERT OR REPLACE INTO meta(key, value) VALUES ('sketch_id_high', " DB_SKETCH_ID_HIGH ")", NULL,
                          NULL, NULL);
    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db->h, "DELETE FROM sketches WHERE source = 'kiosk' AND status = 'rejected'", NULL, NULL, NULL);
    int n = rc == SQLITE_OK ? sqlite3_changes(db->h) : 0;
    if (rc != SQLITE_OK) r = db_fail(db, rc, "deleting rejected kiosk sketches", err);
    char details[64];
    snprintf(details, sizeof details, "{\"deleted\": %d}", n);
    if (r == SP_OK) r = db_log_row(db, by, "delete", "rejected kiosk sketches", details, err);
    if (r != SP_OK) {
        db_rollback(db);
        return r;
    }
    if ((r = db_commit(db, err)) == SP_OK && deleted) *deleted = n;
    return r;
}
