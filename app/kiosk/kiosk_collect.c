// kiosk_collect.c: the visitors' strokes the kiosk keeps for review (issue
// 16, item 5), written by a thread of their own so that the frame loop never
// waits for the database (docs/DESIGN.md, "Collecting visitors' strokes").
#include <ctype.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "kiosk_internal.h"
#include "sp/clock.h"
#include "sp/partdb.h"

// Sketches waiting for the writer: more than a whole dragon's (48 parts),
// so only a database that keeps refusing drops what it cannot take.
enum { QUEUE_MAX = 256 };
// Another writer (a curator's `db train` committing its model, an import)
// holds the database longer than a store waits: the sketch is tried again
// this often, for at most this long, in this thread, before it is dropped.
enum { BUSY_RETRY_MS = 200, BUSY_GIVE_UP_MS = 30000 };

typedef struct queued {
    char category[SP_NAME_MAX];
    sp_vec2* xy;
    double* t;
    int n;
    double busy_since; // sp_now_ms of its first try that found the database busy (0: none)
} queued;

struct kiosk_collector {
    sp_db* db; // the writer's own handle; NULL: it could not be opened (tried again for each sketch)
    char last_drop[sizeof(sp_error){0}.text]; // the last reason a sketch was dropped, said ("": none)
    int same_drops;                           // sketches dropped since for that reason, not said yet
    char path[1024];
    double canvas_w, canvas_h;
    double reserve_mb; // free space on the database's disk kept for saves and training (<= 0: none)
    bool threaded;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    queued q[QUEUE_MAX]; // a ring: head, count
    int head, count;
    bool stop;
    int stored, dropped;
};

static void queued_free(queued* s)
{
    free(s->xy);
    free(s->t);
    memset(s, 0, sizeof *s);
}

static void count_result(kiosk_collector* c, bool stored)
{
    pthread_mutex_lock(&c->lock);
    if (stored)
        ++c->stored;
    else
        ++c->dropped;
    pthread_mutex_unlock(&c->lock);
}

// A dropped sketch's reason, said once while it repeats (a visit's twenty
// parts on a damaged database were twenty identical lines): the next
// different reason, a stored sketch or the close (why NULL) says how many
// more went the same way.
bool kiosk_same_reason(const char* a, const char* b)
{
    while (*a && *b) {
        bool na = isdigit((unsigned char)*a), nb = isdigit((unsigned char)*b);
        if (na != nb) return false;
        if (na) {
            while (isdigit((unsigned char)*a) || *a == '.')
                ++a;
            while (isdigit((unsigned char)*b) || *b == '.')
                ++b;
        } else if (*a++ != *b++)
            return false;
    }
    return *a == *b;
}

static void say_dropped(kiosk_collector* c, const char* why)
{
    if (why && kiosk_same_reason(why, c->last_drop)) {
        ++c->same_drops;
        return;
    }
    if (c->same_drops > 0)
        sp_kiosk_log("%s: %d more sketch%s dropped for the same reason", c->path, c->same_drops, c->same_drops == 1 ? "" : "es");
    c->same_drops = 0;
    snprintf(c->last_drop, sizeof c->last_drop, "%s", why ? why : "");
    if (why) sp_kiosk_log("%s", why);
}

// A database that could not be written (read-only, damaged, not there) is
// tried again for each sketch, in this thread: a technician who mends the
// file expects collecting to resume without a restart. Once open, it says
// `said`; otherwise err says why (SP_ERR_BUSY: another writer holds it).
static sp_result open_writer(kiosk_collector* c, const char* said, sp_error* err)
{
    if (c->db) return SP_OK;
    struct stat st;
    if (stat(c->path, &st) != 0) return sp_fail(err, SP_ERR_IO, "%s: no database there; sketch dropped", c->path);
    // Waiting no longer than a store does: closing the kiosk waits for this thread.
    sp_db* db = NULL;
    sp_result r = sp_db_open_wait(c->path, 0, SP_DB_COLLECT_BUSY_MS, &db, err);
    if (r != SP_OK) {
        char why[sizeof err->text];
        snprintf(why, sizeof why, "%s", err->text);
        return sp_fail(err, r, "%s; sketch dropped", why);
    }
    sp_db_set_busy_timeout(db, SP_DB_COLLECT_BUSY_MS);
    c->db = db;
    sp_kiosk_log("%s: %s", c->path, said);
    return SP_OK;
}

// The database file at c->path is still the one the handle has open; a file
// replaced by a rename (a curator's new database) is opened anew, so that
// no stroke goes into the old, unlinked one: the old handle closes first,
// then the old file's WAL and -shm beside the path go (a connection opened
// by path would apply that WAL to the new file, and a checkpoint write it
// into it). Fails (err says why) when no file is at the path (deleted, or
// moved away: the handle would write into the unlinked file or the one under
// its new name, and the stroke be lost without a word), or the new file
// cannot be written (open_writer tries again at the next sketch).
static sp_result follow_file(kiosk_collector* c, sp_error* err)
{
    sp_db_file_state at = sp_db_file_check(c->db);
    if (at == SP_DB_FILE_GONE)
        return sp_fail(err, SP_ERR_IO, "%s: the database is gone (deleted or moved away); sketch dropped", c->path);
    if (at == SP_DB_FILE_SAME) return SP_OK;
    sp_db_close(c->db);
    c->db = NULL;
    sp_db_drop_stale_sidecars(c->path);
    return open_writer(c, "a new database file there: visitors' strokes go into it", err);
}

// SP_ERR_IO when the database's disk has less than the reserve free: the
// room left is for the visitors' saves and a curator's `db train`.
static sp_result room_left(const kiosk_collector* c, sp_error* err)
{
    double left = c->reserve_mb > 0 ? kiosk_free_mb(c->path) : -1;
    if (left < 0 || left >= c->reserve_mb) return SP_OK;
    return sp_fail(err, SP_ERR_IO,
                   "%s: %.0f MB free on its disk, under the %.0f MB kept for saves and the curators' `db train`; sketch "
                   "dropped (free some room on that disk)",
                   c->path, left, c->reserve_mb);
}

// After a store found the database busy: puts the sketch back at the head of
// the queue and waits BUSY_RETRY_MS (or until woken), returning with the lock
// held; false (nothing done, the lock not held) when it is to be dropped:
// waited long enough, the kiosk closing (*closing), or no room.
static bool wait_busy(kiosk_collector* c, queued* s, bool* closing)
{
    double now = sp_now_ms();
    if (s->busy_since == 0) s->busy_since = now;
    pthread_mutex_lock(&c->lock);
    *closing = c->stop;
    if (c->stop || now - s->busy_since >= BUSY_GIVE_UP_MS || c->count >= QUEUE_MAX) {
        pthread_mutex_unlock(&c->lock);
        return false;
    }
    c->head = (c->head + QUEUE_MAX - 1) % QUEUE_MAX;
    c->q[c->head] = *s, ++c->count;
    struct timespec until; // on the monotonic clock (the condition's): a clock set back does not stretch the wait
    clock_gettime(CLOCK_MONOTONIC, &until);
    until.tv_nsec += (long)BUSY_RETRY_MS * 1000000L;
    until.tv_sec += until.tv_nsec / 1000000000L, until.tv_nsec %= 1000000000L;
    if (!c->stop) pthread_cond_timedwait(&c->wake, &c->lock, &until);
    return true;
}

// The writer: one sketch a transaction, each waiting at most
// SP_DB_COLLECT_BUSY_MS for another writer (partdb.h) and tried again while
// one holds the database (wait_busy); whatever fails is dropped with one
// line (the error says "sketch dropped").
static void* collector_main(void* arg)
{
    kiosk_collector* c = arg;
    pthread_mutex_lock(&c->lock);
    for (;;) {
        while (c->count == 0 && !c->stop)
            pthread_cond_wait(&c->wake, &c->lock);
        if (c->count == 0) break; // stopping, and everything is written
        queued s = c->q[c->head];
        memset(&c->q[c->head], 0, sizeof s);
        c->head = (c->head + 1) % QUEUE_MAX, --c->count;
        pthread_mutex_unlock(&c->lock);
        sp_error err = {0};
        sp_stroke st = {.count = s.n, .points = s.xy, .t = s.t};
        // A database another writer holds is waited for, whether it was
        // found so at the open or at the store.
        sp_result r = open_writer(c, "the database can be written now: visitors' strokes are collected again", &err);
        if (r == SP_OK) r = follow_file(c, &err);
        if (r == SP_OK) r = room_left(c, &err);
        if (r == SP_OK) r = sp_db_collect_kiosk_sketch(c->db, s.category, &st, c->canvas_w, c->canvas_h, NULL, &err);
        bool closing = false;
        if (r == SP_ERR_BUSY && wait_busy(c, &s, &closing)) continue; // the lock is held again
        if (r == SP_ERR_BUSY && s.busy_since > 0)
            sp_kiosk_log("%s: another writer held the database for %.1f s%s; sketch dropped", c->path,
                         (sp_now_ms() - s.busy_since) / 1000.0, closing ? " when the kiosk closed" : "");
        else if (r != SP_OK)
            say_dropped(c, err.text);
        if (r == SP_OK) say_dropped(c, NULL);
        queued_free(&s);
        count_result(c, r == SP_OK);
        pthread_mutex_lock(&c->lock);
        if (r == SP_OK && c->count == 0 && c->db) {
            // Once the queue is empty, the visit's sketches go from the WAL
            // into the file itself: a curator's copy of the file has them,
            // and a file renamed over it (follow_file) never meets this
            // file's WAL. A reader in the way only postpones it.
            pthread_mutex_unlock(&c->lock);
            sp_db_checkpoint(c->db, NULL);
            pthread_mutex_lock(&c->lock);
        }
    }
    pthread_mutex_unlock(&c->lock);
    return NULL;
}

kiosk_collector* kiosk_collector_open(const char* db_path, double canvas_w, double canvas_h, double reserve_mb)
{
    kiosk_collector* c = calloc(1, sizeof *c);
    if (!c) {
        sp_kiosk_log("out of memory: visitors' strokes are not collected");
        return NULL;
    }
    c->canvas_w = canvas_w, c->canvas_h = canvas_h, c->reserve_mb = reserve_mb;
    snprintf(c->path, sizeof c->path, "%s", db_path);
    pthread_mutex_init(&c->lock, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&c->wake, &ca);
    pthread_condattr_destroy(&ca);
    // A writable handle of its own (the pipeline reads through a read-only
    // one); opening migrates an older schema. It runs at start, before the
    // first frame. A database that cannot be written keeps the kiosk running:
    // each sketch is then dropped with one line, until the writer's handle
    // opens (open_writer).
    sp_error err = {0};
    if (sp_db_open(db_path, 0, &c->db, &err) != SP_OK) {
        sp_kiosk_log("visitors' strokes cannot be collected for now (tried again for each): %s", err.text);
        c->db = NULL;
    }
    // Every wait of the writer's (a store, a checkpoint) is short: closing the
    // kiosk waits for the writer.
    if (c->db) sp_db_set_busy_timeout(c->db, SP_DB_COLLECT_BUSY_MS);
    c->threaded = pthread_create(&c->thread, NULL, collector_main, c) == 0;
    if (!c->threaded) {
        sp_kiosk_log("%s: visitors' strokes cannot be collected: no thread to write them", db_path);
        sp_db_close(c->db);
        c->db = NULL;
    }
    return c;
}

void kiosk_collector_push(kiosk_collector* c, const char* category, const sp_vec2* xy, const double* t, int n)
{
    if (!c) return;
    if (!c->threaded) {
        sp_kiosk_log("a %s stroke not collected (no thread to write it); sketch dropped", category);
        count_result(c, false);
        return;
    }
    queued s = {.n = n, .xy = malloc(sizeof *s.xy * (size_t)n), .t = t ? malloc(sizeof *s.t * (size_t)n) : NULL};
    snprintf(s.category, sizeof s.category, "%s", category);
    pthread_mutex_lock(&c->lock);
    const char* why = n <= 0                  ? "no points"
                      : !s.xy || (t && !s.t)  ? "out of memory"
                      : c->count >= QUEUE_MAX ? "too many waiting for the database"
                                              : NULL;
    bool ok = !why;
    if (ok) {
        memcpy(s.xy, xy, sizeof *s.xy * (size_t)n);
        if (t) memcpy(s.t, t, sizeof *s.t * (size_t)n);
        c->q[(c->head + c->count++) % QUEUE_MAX] = s;
        pthread_cond_signal(&c->wake);
    } else {
        ++c->dropped;
    }
    pthread_mutex_unlock(&c->lock);
    if (!ok) {
        sp_kiosk_log("a %s stroke not collected (%s); sketch dropped", category, why);
        queued_free(&s);
    }
}

void kiosk_collector_counts(kiosk_collector* c, int* stored, int* dropped)
{
    *stored = *dropped = 0;
    if (!c) return;
    pthread_mutex_lock(&c->lock);
    *stored = c->stored, *dropped = c->dropped;
    pthread_mutex_unlock(&c->lock);
}

void kiosk_collector_close(kiosk_collector* c, int* stored, int* dropped)
{
    *stored = *dropped = 0;
    if (!c) return;
    if (c->threaded) {
        // The writer empties the queue first (each sketch waits at most
        // SP_DB_COLLECT_BUSY_MS), so closing the kiosk keeps what was left.
        pthread_mutex_lock(&c->lock);
        c->stop = true;
        pthread_cond_signal(&c->wake);
        pthread_mutex_unlock(&c->lock);
        pthread_join(c->thread, NULL);
    }
    kiosk_collector_counts(c, stored, dropped);
    say_dropped(c, NULL);
    sp_db_close(c->db);
    pthread_cond_destroy(&c->wake);
    pthread_mutex_destroy(&c->lock);
    free(c);
}
