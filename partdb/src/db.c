// db.c: opening the database, the schema and its migrations, transactions,
// the busy message, the generation counter and the curator log.
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "db_internal.h"
#include "sp/sketch_io.h"

void (*sp_db_test_hook)(const char* point) = NULL;

// ---- migrations ----------------------------------------------------------
// Migration i takes the schema from version i to i + 1. Never edit a shipped
// step: add a new one and bump SP_DB_SCHEMA_VERSION.
static const char* const k_migrations[SP_DB_SCHEMA_VERSION] = {
    // 0 -> 1: parts, sketches, models, the append-only log.
    "CREATE TABLE parts("
    " id INTEGER PRIMARY KEY,"
    " name TEXT NOT NULL UNIQUE,"
    " category TEXT NOT NULL,"
    " abstraction TEXT NOT NULL,"
    " gltf BLOB NOT NULL,"
    " bytes INTEGER NOT NULL,"
    " sha256 TEXT NOT NULL,"
    " vertices INTEGER NOT NULL, triangles INTEGER NOT NULL, joints INTEGER NOT NULL,"
    " parameters INTEGER NOT NULL, abstractions INTEGER NOT NULL, animations INTEGER NOT NULL,"
    " selftest_error REAL,"
    " summary TEXT NOT NULL," // JSON: parameters (name, min, max, group) and abstractions (name, curves, points)
    " added_by TEXT NOT NULL,"
    " added_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')));"
    "CREATE INDEX parts_category ON parts(category);"
    "CREATE TABLE sketches("
    " id INTEGER PRIMARY KEY,"
    " category TEXT NOT NULL,"
    " source TEXT NOT NULL CHECK (source IN ('synthetic', 'curated', 'kiosk')),"
    " part_id INTEGER REFERENCES parts(id) ON DELETE CASCADE," // synthetic sketches belong to their part
    " strokes TEXT,"                                           // sketchpose-strokes JSON
    " raster_w INTEGER, raster_h INTEGER, raster BLOB,"        // grey pixels of a PNG sketch
    " png BLOB,"                                               // the PNG as given, for export
    " added_by TEXT NOT NULL,"
    " added_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),"
    " CHECK ((strokes IS NULL) <> (raster IS NULL)));"
    "CREATE INDEX sketches_category ON sketches(category);"
    "CREATE INDEX sketches_part ON sketches(part_id);"
    "CREATE TABLE models("
    " id INTEGER PRIMARY KEY,"
    " model BLOB NOT NULL," // the classifier's model file (sp_clf_save), as is
    " sha256 TEXT NOT NULL,"
    " categories TEXT NOT NULL," // JSON array, the model's categories in order
    " options TEXT NOT NULL,"    // JSON, sp_clf_desc with defaults resolved
    " report TEXT NOT NULL,"     // JSON, training and cross-validation report
    " created_by TEXT NOT NULL,"
    " created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')));"
    "CREATE TABLE log("
    " id INTEGER PRIMARY KEY,"
    " at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),"
    " by TEXT NOT NULL, action TEXT NOT NULL, subject TEXT, details TEXT);"
    "CREATE TRIGGER log_no_update BEFORE UPDATE ON log BEGIN SELECT RAISE(ABORT, 'the curator log is append-only'); END;"
    "CREATE TRIGGER log_no_delete BEFORE DELETE ON log BEGIN SELECT RAISE(ABORT, 'the curator log is append-only'); END;",
    // 1 -> 2: a generation counter that every change of parts, sketches or
    // models bumps in its own transaction, so a reader (the kiosk) can tell
    // "something changed" from one small row.
    "CREATE TABLE meta(key TEXT PRIMARY KEY, value INTEGER NOT NULL);"
    "INSERT INTO meta VALUES ('generation', 1);"
    "CREATE TRIGGER gen_parts_ins AFTER INSERT ON parts BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; END;"
    "CREATE TRIGGER gen_parts_del AFTER DELETE ON parts BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; END;"
    "CREATE TRIGGER gen_sketches_ins AFTER INSERT ON sketches BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; "
    "END;"
    "CREATE TRIGGER gen_sketches_del AFTER DELETE ON sketches BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; "
    "END;"
    "CREATE TRIGGER gen_models_ins AFTER INSERT ON models BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; END;"
    "CREATE TRIGGER gen_models_del AFTER DELETE ON models BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; END;",
    // 2 -> 3: visitors' strokes collected by the kiosk wait for review
    // (status pending, approved or rejected; kiosk sketches added before
    // were a curator's choice: approved). A pending kiosk sketch bumps no
    // generation: it changes no model or part a reader uses, and the kiosk
    // writing one must not make itself reload.
    "ALTER TABLE sketches ADD COLUMN status TEXT CHECK (status IS NULL OR status IN ('pending', 'approved', 'rejected'));"
    "UPDATE sketches SET status = 'approved' WHERE source = 'kiosk';"
    "CREATE INDEX sketches_review ON sketches(source, status, id);"
    "DROP TRIGGER gen_sketches_ins;"
    "CREATE TRIGGER gen_sketches_ins AFTER INSERT ON sketches WHEN NEW.source <> 'kiosk' OR NEW.status = 'approved'"
    " BEGIN UPDATE meta SET value = value + 1 WHERE key = 'generation'; END;",
};

// ---- helpers ---------------------------------------------------------------

void db_str_printf(db_str* b, const char* fmt, ...)
{
    if (b->oom) return;
    va_list ap;
    va_start(ap, fmt);
    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
        va_end(ap2);
        b->oom = true;
        return;
    }
    if (b->len + (size_t)n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->len + (size_t)n + 1)
            cap *= 2;
        char* s = realloc(b->s, cap);
        if (!s) {
            va_end(ap2);
            b->oom = true;
            return;
        }
        b->s = s;
        b->cap = cap;
    }
    vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap2);
    va_end(ap2);
    b->len += (size_t)n;
}

void db_str_json(db_str* b, const char* s)
{
    db_str_printf(b, "\"");
    for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p; ++p) {
        if (*p == '"' || *p == '\\') db_str_printf(b, "\\%c", *p);
        else if (*p < 0x20) db_str_printf(b, "\\u%04x", *p);
        else db_str_printf(b, "%c", *p);
    }
    db_str_printf(b, "\"");
}

const char* db_who(const char* by)
{
    if (by && *by) return by;
    const char* u = getenv("USER");
    return u && *u ? u : "unknown";
}

sp_result db_read_json(const char* path, cJSON** root, sp_error* err)
{
    void* text;
    size_t size;
    *root = NULL;
    sp_result r = db_read_file(path, &text, &size, err);
    if (r != SP_OK) return r;
    // One document, each key once, as every user's JSON (a manifest's
    // "sketches" given twice kept the first).
    if ((r = sp_json_document_check(text, size, 0, path, err)) == SP_OK && !(*root = cJSON_ParseWithLength(text, size)))
        r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    free(text);
    return r;
}

sp_result db_read_file(const char* path, void** data, size_t* size, sp_error* err)
{
    return sp_file_read(path, (size_t)1 << 30, data, size, err);
}

// Not sp_file_write: export writes its files into a fresh temporary folder,
// synced as a tree and renamed into place whole (db_folder.c), so a file's
// own temporary copy, fsync and folder sync would only cost a sync a file.
sp_result db_write_file(const char* path, const void* data, size_t size, sp_error* err)
{
    FILE* f = fopen(path, "wb");
    if (!f) return sp_fail(err, SP_ERR_IO, "%s: %s", path, strerror(errno));
    bool ok = fwrite(data, 1, size, f) == size;
    int e = errno; // why: a full disk (ENOSPC) is not a file-size limit (EFBIG)
    if (fclose(f) != 0 && ok) ok = false, e = errno;
    return ok ? SP_OK : sp_fail(err, SP_ERR_IO, "%s: write failed (%s)", path, strerror(e));
}

// The database's -wal (k 0) or -shm (k 1) beside `path` (malloc'd; NULL
// when out of memory).
static char* side_path(const char* path, int k)
{
    size_t n = strlen(path) + 5;
    char* side = malloc(n);
    if (side) snprintf(side, n, "%s-%s", path, k ? "shm" : "wal");
    return side;
}

// A reader of a database it could not write (mode 444) leaves its -wal and
// -shm with that mode: SQLite makes them like the database and removes them
// only when a connection that may write closes. Once the owner may write the
// database again, its own leftovers would refuse every write, so they get
// the database's mode. Another user's are left as they are (and said).
static void own_side_files_writable(const char* path, const struct stat* db_st)
{
    if (db_st->st_uid != geteuid() || !(db_st->st_mode & S_IWUSR)) return;
    for (int k = 0; k < 2; ++k) {
        char* side = side_path(path, k);
        struct stat st;
        if (side && lstat(side, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == geteuid() && !(st.st_mode & S_IWUSR))
            chmod(side, db_st->st_mode & 0777);
        free(side);
    }
}

// How a failure leaves the data: a checkpoint runs after the commit, and
// what was committed stays in the WAL.
static const char* db_fail_kept(const char* doing)
{
    return strncmp(doing, "checkpoint", 10) ? "nothing was changed" : "what was committed stays, in the WAL";
}

// SQLite opens a WAL database's -wal or -shm that this user may not write
// (another user's, left by their process) read-only, and every write then
// fails as SQLITE_READONLY, which reads as though the database file were.
// True (err set, naming the file and its owner) when that is the cause.
static bool side_file_unwritable(const char* path, const char* doing, sp_error* err)
{
    for (int k = 0; k < 2; ++k) {
        char* side = side_path(path, k);
        if (!side) return false;
        struct stat st;
        bool theirs =
            stat(side, &st) == 0 && faccessat(AT_FDCWD, side, W_OK, AT_EACCESS) != 0 && (errno == EACCES || errno == EPERM);
        if (theirs)
            sp_fail(
                err, SP_ERR_IO,
                "%s: not writable by this user (owned by uid %ld, mode %03o) while %s; %s (run as its owner, or have them make "
                "it writable)",
                side, (long)st.st_uid, (unsigned)(st.st_mode & 0777), doing, db_fail_kept(doing));
        free(side);
        if (theirs) return true;
    }
    return false;
}

// Whether this process may make files in the folder holding `path` (a
// writable database in a folder it may not write reads as read-only to
// SQLite, and the file's own permissions were blamed).
static bool folder_writable(const char* path)
{
    char dir[4096];
    const char* slash = strrchr(path, '/');
    if (!slash) return access(".", W_OK) == 0;
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1;                // the root folder
    if (n >= sizeof dir) return true; // cannot tell: the general message
    memcpy(dir, path, n);
    dir[n] = 0;
    return access(dir, W_OK) == 0;
}

sp_result db_fail(sp_db* db, int rc, const char* doing, sp_error* err)
{
    int prim = rc & 0xff;
    const char* p = db->path;
    const char* kept = db_fail_kept(doing);
    switch (prim) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
        return sp_fail(err, SP_ERR_BUSY, "%s: database is busy (held by another writer for more than %g s) while %s", p,
                       db->busy_ms / 1000.0, doing);
    case SQLITE_FULL:
        return sp_fail(err, SP_ERR_IO, "%s: disk full while %s; %s", p, doing, kept);
    case SQLITE_READONLY:
        if (!db->readonly && side_file_unwritable(p, doing, err)) return SP_ERR_IO;
        if (!db->readonly && access(p, W_OK) == 0 && !folder_writable(p))
            return sp_fail(
                err, SP_ERR_IO,
                "%s: its folder is not writable (SQLite makes its -wal and -shm files beside the database) while %s; %s", p,
                doing, kept);
        return sp_fail(err, SP_ERR_IO, "%s: the database is read-only (file permissions or opened read-only) while %s; %s", p,
                       doing, kept);
    case SQLITE_NOMEM: return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory while %s", p, doing);
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return sp_fail(err, SP_ERR_PARSE, "%s: not a valid sketchpose database (%s) while %s", p, sqlite3_errstr(rc), doing);
    case SQLITE_IOERR: {
        // The system's reason: a read also fails on a full disk or past a
        // size limit, where SQLite cannot make the -shm beside the database.
        int e = db->h ? sqlite3_system_errno(db->h) : 0;
        if (e == ENOSPC || e == EDQUOT)
            return sp_fail(err, SP_ERR_IO,
                           "%s: disk full while %s (SQLite needs room for the -wal and -shm beside it, also to read it); %s", p,
                           doing, kept);
        if (e == EFBIG)
            return sp_fail(err, SP_ERR_IO, "%s: this process's file size limit (ulimit -f) reached while %s; %s", p, doing, kept);
        if (rc == SQLITE_IOERR_WRITE || rc == SQLITE_IOERR_FSYNC || rc == SQLITE_IOERR_TRUNCATE)
            return sp_fail(err, SP_ERR_IO, "%s: write failed (%s) while %s; %s", p,
                           e ? strerror(e) : "disk full or file too large?", doing, kept);
        return sp_fail(err, SP_ERR_IO, "%s: I/O error (%s%s%s) while %s", p, sqlite3_errmsg(db->h), e ? ": " : "",
                       e ? strerror(e) : "", doing);
    }
    default: return sp_fail(err, SP_ERR_INTERNAL, "%s: %s while %s", p, db->h ? sqlite3_errmsg(db->h) : sqlite3_errstr(rc), doing);
    }
}

sp_result db_exec(sp_db* db, const char* sql, sp_error* err)
{
    int rc = sqlite3_exec(db->h, sql, NULL, NULL, NULL);
    return rc == SQLITE_OK ? SP_OK : db_fail(db, rc, "writing", err);
}

sp_result db_bind_blob(sp_db* db, sqlite3_stmt* st, int i, const void* data, size_t size, const char* what, sp_error* err)
{
    int rc = sqlite3_bind_blob64(st, i, data, (sqlite3_uint64)size, SQLITE_STATIC);
    if (rc == SQLITE_OK) return SP_OK;
    sqlite3_finalize(st);
    // Unchecked, a refused bind left NULL to insert, and the row failed as
    // "NOT NULL constraint failed" after minutes of training.
    if (rc == SQLITE_TOOBIG)
        return sp_fail(err, SP_ERR_UNSUPPORTED,
                       "%s: %s is %zu bytes, more than SQLite stores in one value (%d bytes); nothing was stored", db->path, what,
                       size, sqlite3_limit(db->h, SQLITE_LIMIT_LENGTH, -1));
    return db_fail(db, rc, "storing it", err);
}

sp_result db_prepare(sp_db* db, const char* sql, sqlite3_stmt** st, sp_error* err)
{
    int rc = sqlite3_prepare_v2(db->h, sql, -1, st, NULL);
    return rc == SQLITE_OK ? SP_OK : db_fail(db, rc, "preparing a query", err);
}

sp_result db_begin(sp_db* db, sp_error* err)
{
    if (db->readonly) return sp_fail(err, SP_ERR_IO, "%s: opened read-only; nothing was changed", db->path);
    // IMMEDIATE takes the write lock now, so a second writer waits here (up to
    // the busy timeout) instead of failing halfway through its statements.
    int rc = sqlite3_exec(db->h, "BEGIN IMMEDIATE", NULL, NULL, NULL);
    return rc == SQLITE_OK ? SP_OK : db_fail(db, rc, "starting a write", err);
}

sp_result db_commit(sp_db* db, sp_error* err)
{
    DB_HOOK("commit");
    int rc = sqlite3_exec(db->h, "COMMIT", NULL, NULL, NULL);
    if (rc != SQLITE_OK) {
        sp_result r = db_fail(db, rc, "committing", err);
        db_rollback(db);
        return r;
    }
    db->gen_valid = false; // our own commits do not change data_version
    return SP_OK;
}

void db_rollback(sp_db* db)
{
    if (!sqlite3_get_autocommit(db->h)) sqlite3_exec(db->h, "ROLLBACK", NULL, NULL, NULL);
}

static int pragma_int(sp_db* db, const char* sql, int* out)
{
    sqlite3_stmt* st = NULL;
    int rc = sqlite3_prepare_v2(db->h, sql, -1, &st, NULL);
    if (rc == SQLITE_OK) {
        rc = sqlite3_step(st);
        if (rc == SQLITE_ROW) {
            *out = sqlite3_column_int(st, 0);
            rc = SQLITE_OK;
        } else if (rc == SQLITE_DONE) {
            rc = SQLITE_ERROR;
        }
    }
    sqlite3_finalize(st);
    return rc;
}

sp_result db_log_row(sp_db* db, const char* by, const char* action, const char* subject, const char* details, sp_error* err)
{
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, "INSERT INTO log(by, action, subject, details) VALUES (?, ?, ?, ?)", &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_text(st, 1, db_who(by), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, action, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, subject, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, details, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? SP_OK : db_fail(db, rc, "writing the log", err);
}

// ---- public ------------------------------------------------------------------

const char* sp_db_default_path(void)
{
    const char* e = getenv("SP_DB");
    return e && *e ? e : "sketchpose.db";
}

sp_result db_migrate(sp_db* db, int target, sp_error* err)
{
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    int v = 0;
    int rc = pragma_int(db, "PRAGMA user_version", &v); // re-read under the lock: another process may have migrated
    if (rc != SQLITE_OK) {
        db_rollback(db);
        return db_fail(db, rc, "reading the schema version", err);
    }
    if (v == 0) {
        int tables = 0;
        pragma_int(db, "SELECT count(*) FROM sqlite_master", &tables);
        if (tables > 0) {
            db_rollback(db);
            return sp_fail(err, SP_ERR_INVALID, "%s: an SQLite file but not a sketchpose database (no schema version)", db->path);
        }
    }
    for (; v < target; ++v) {
        if (sqlite3_exec(db->h, k_migrations[v], NULL, NULL, NULL) != SQLITE_OK) {
            char what[64];
            snprintf(what, sizeof what, "migrating the schema from version %d", v);
            r = db_fail(db, sqlite3_errcode(db->h), what, err);
            db_rollback(db);
            return r;
        }
        char sql[64];
        snprintf(sql, sizeof sql, "PRAGMA user_version = %d", v + 1);
        if ((r = db_exec(db, sql, err)) != SP_OK) {
            db_rollback(db);
            return r;
        }
    }
    return db_commit(db, err);
}

// Opens `path` read-only as an SQLite URI with immutable=1 (no locks, no
// -shm): what the URI needs escaped is escaped.
static int open_immutable(const char* path, sqlite3** h)
{
    size_t n = strlen(path);
    char* uri = malloc(3 * n + 32);
    if (!uri) return SQLITE_NOMEM;
    char* o = uri + sprintf(uri, "file:");
    while (path[0] == '/' && path[1] == '/') // "file://" would begin an authority
        ++path;
    for (const char* c = path; *c; ++c)
        o += (*c == '%' || *c == '?' || *c == '#') ? sprintf(o, "%%%02X", (unsigned char)*c) : sprintf(o, "%c", *c);
    sprintf(o, "?immutable=1");
    int rc = sqlite3_open_v2(uri, h, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_FULLMUTEX, NULL);
    free(uri);
    return rc;
}

// True when this user could write the database, its folder and any -wal or
// -shm beside it. A reader then opens the file read-write (SQLite's
// query_only keeps it from changing anything): SQLite removes the -wal and
// -shm only when the last connection to close could write, so a read-only
// reader would leave both behind in the user's folder.
static bool reader_may_write(const char* path)
{
    if (faccessat(AT_FDCWD, path, W_OK, AT_EACCESS) != 0) return false;
    char* dir = sp_path_folder(path);
    bool ok = dir && faccessat(AT_FDCWD, dir, W_OK | X_OK, AT_EACCESS) == 0;
    free(dir);
    for (int k = 0; ok && k < 2; ++k) {
        char* side = side_path(path, k);
        ok = side && (faccessat(AT_FDCWD, side, F_OK, AT_EACCESS) != 0 || faccessat(AT_FDCWD, side, W_OK, AT_EACCESS) == 0);
        free(side);
    }
    return ok;
}

// A database to be created: its folder must be there and take new files.
// Said before SQLite tries, whose retry read-only leaves errno at ENOENT (a
// read-only file system read "cannot open (No such file or directory)").
static sp_result folder_takes_files(const char* path, sp_error* err)
{
    char* dir = sp_path_folder(path);
    if (!dir) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    struct stat ds;
    sp_result r = SP_OK;
    if (stat(dir, &ds) != 0 || !S_ISDIR(ds.st_mode))
        r = sp_fail(err, SP_ERR_IO, "%s: cannot create it: the folder %s is not there", path, dir);
    else if (faccessat(AT_FDCWD, dir, W_OK | X_OK, AT_EACCESS) != 0)
        r = sp_fail(err, SP_ERR_IO, "%s: cannot create it in the folder %s (%s)", path, dir, strerror(errno));
    free(dir);
    return r;
}

// SQLite's open refused (SQLITE_CANTOPEN): why, as far as it can be told.
// Its unix files take a path of at most 512 bytes from /, a relative name
// made absolute first: a short --db in a deep folder fails too.
static sp_result cannot_open(const char* path, int error, sp_error* err)
{
    size_t n = strlen(path);
    char cwd[4096];
    if (path[0] != '/' && getcwd(cwd, sizeof cwd)) n += strlen(cwd) + 1;
    if (n >= 512)
        return sp_fail(err, SP_ERR_IO, "%s: cannot open: its path is %zu bytes from /, longer than SQLite takes (511)", path, n);
    return sp_fail(err, SP_ERR_IO, "%s: cannot open (%s)", path, error ? strerror(error) : "SQLite gave no reason");
}

sp_result sp_db_open(const char* path, unsigned flags, sp_db** out, sp_error* err)
{
    return sp_db_open_wait(path, flags, -1, out, err);
}

// The database files this process has open, with how many handles each:
// sp_db_drop_stale_sidecars must not take another handle's -wal and -shm
// for an old file's, and a process's own fcntl locks do not show to it.
static pthread_mutex_t g_open_lock = PTHREAD_MUTEX_INITIALIZER;
static struct open_file {
    dev_t dev;
    ino_t ino;
    int handles;
} * g_open;
static int g_open_n, g_open_cap, g_open_unlisted;

static void list_open(sp_db* db)
{
    struct stat st;
    pthread_mutex_lock(&g_open_lock);
    if (stat(db->path, &st) != 0) {
        ++g_open_unlisted; // not known: every drop waits until it closes
    } else {
        db->dev = st.st_dev, db->ino = st.st_ino, db->listed = true;
        int i = 0;
        while (i < g_open_n && (g_open[i].dev != db->dev || g_open[i].ino != db->ino))
            ++i;
        if (i == g_open_n && g_open_n == g_open_cap) {
            int cap = g_open_cap ? 2 * g_open_cap : 8;
            struct open_file* grown = realloc(g_open, sizeof *grown * (size_t)cap);
            if (grown) g_open = grown, g_open_cap = cap;
        }
        if (i < g_open_n)
            ++g_open[i].handles;
        else if (g_open_n < g_open_cap)
            g_open[g_open_n++] = (struct open_file){db->dev, db->ino, 1};
        else
            db->listed = false, ++g_open_unlisted;
    }
    pthread_mutex_unlock(&g_open_lock);
}

static void unlist_open(const sp_db* db)
{
    pthread_mutex_lock(&g_open_lock);
    if (!db->listed) {
        --g_open_unlisted;
    } else {
        for (int i = 0; i < g_open_n; ++i)
            if (g_open[i].dev == db->dev && g_open[i].ino == db->ino && --g_open[i].handles == 0) {
                g_open[i] = g_open[--g_open_n];
                break;
            }
    }
    pthread_mutex_unlock(&g_open_lock);
}

// Whether this process has a handle on the file (or one it could not list).
static bool open_here(const struct stat* st)
{
    pthread_mutex_lock(&g_open_lock);
    bool here = g_open_unlisted > 0;
    for (int i = 0; !here && i < g_open_n; ++i)
        here = g_open[i].dev == st->st_dev && g_open[i].ino == st->st_ino;
    pthread_mutex_unlock(&g_open_lock);
    return here;
}

sp_result sp_db_open_wait(const char* path, unsigned flags, int busy_ms, sp_db** out, sp_error* err)
{
    *out = NULL;
    sp_result r;
    bool ro = (flags & SP_DB_READONLY) != 0;
    struct stat st;
    bool exists = stat(path, &st) == 0;
    int why = exists ? 0 : errno;
    // Only a missing file is "no such database": a folder on the way that
    // this user may not enter hides the file without it being absent.
    if (!exists && why == EACCES)
        return sp_fail(err, SP_ERR_IO, "%s: permission denied (this user may not reach the file or a folder above it)", path);
    if (!exists && why != ENOENT) return sp_fail(err, SP_ERR_IO, "%s: cannot reach the database file (%s)", path, strerror(why));
    if (!exists && (ro || !(flags & SP_DB_CREATE)))
        return sp_fail(err, SP_ERR_IO, "%s: no such database (create one with `sketchpose db init`)", path);
    if (exists && !S_ISREG(st.st_mode)) return sp_fail(err, SP_ERR_IO, "%s: not a regular file", path);
    if (!exists && (r = folder_takes_files(path, err)) != SP_OK) return r;
    sp_db* db = calloc(1, sizeof *db);
    if (!db || !(db->path = strdup(path))) {
        free(db);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    db->readonly = ro;
    db->busy_ms = busy_ms >= 0 ? busy_ms : SP_DB_BUSY_MS_DEFAULT;
    if (!ro && exists) own_side_files_writable(path, &st);
    bool ro_file = ro && !reader_may_write(path);
    int oflags =
        ro_file ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | ((flags & SP_DB_CREATE) && !ro ? SQLITE_OPEN_CREATE : 0);
    // The file at the path just before SQLite opens it: one renamed over the
    // path during the open then reads as replaced (noted after the open, the
    // new file could be taken for the one the handle has, and never followed).
    if (exists) db->at_dev = st.st_dev, db->at_ino = st.st_ino, db->at_known = true;
    errno = 0; // SQLite's own refusals set none: a leftover ENOENT said an existing file was missing
    int rc = sqlite3_open_v2(path, &db->h, oflags | SQLITE_OPEN_FULLMUTEX, NULL);
    DB_HOOK("opened");
    r = SP_OK;
    if (rc != SQLITE_OK) {
        r = (rc & 0xff) == SQLITE_CANTOPEN ? cannot_open(path, errno, err) : db_fail(db, rc, "opening", err);
        goto fail;
    }
    sqlite3_extended_result_codes(db->h, 1);
    sqlite3_busy_timeout(db->h, db->busy_ms);
    int v = 0;
    rc = pragma_int(db, "PRAGMA user_version", &v);
    if (ro && ((rc & 0xff) == SQLITE_READONLY || (ro_file && (rc & 0xff) == SQLITE_CANTOPEN))) {
        // A WAL database read where this user may not make its -shm (a folder
        // of someone else's; a read-only file system, where SQLite cannot
        // even open it: an SD card, a squashfs image): read it as a file no
        // one changes meanwhile.
        sqlite3_close(db->h);
        db->h = NULL;
        if ((rc = open_immutable(path, &db->h)) == SQLITE_OK) {
            sqlite3_extended_result_codes(db->h, 1);
            rc = pragma_int(db, "PRAGMA user_version", &v);
        }
    }
    if (rc != SQLITE_OK) {
        // Opened to write, a read-only file fails here: said as what the caller was doing (a kiosk's
        // collector logged "while reading the schema version" for each stroke dropped: an outside review).
        r = db_fail(db, rc, ro ? "reading the schema version" : "opening it to write", err);
        goto fail;
    }
    if (!ro && sqlite3_db_readonly(db->h, "main") == 1) {
        r = sp_fail(err, SP_ERR_IO, "%s: cannot write the database file (read-only file or folder); open it read-only or fix the permissions",
                    path);
        goto fail;
    }
    // Another application's SQLite file is refused before anything here
    // writes to it: the journal mode below stayed WAL on a file `db check`
    // had refused (its schema version may be any number).
    int ours = 0, tables = 0;
    bool counted = pragma_int(db, "SELECT count(*) FROM sqlite_master", &tables) == SQLITE_OK;
    if (counted && tables > 0 &&
        pragma_int(db, "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN ('parts', 'sketches', 'models')",
                   &ours) == SQLITE_OK &&
        (v == 0 || ours < 3)) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: an SQLite file but not a sketchpose database (%s); nothing in it was changed", path,
                    v == 0 ? "no schema version" : "no parts, sketches and models tables");
        goto fail;
    }
    if (v > SP_DB_SCHEMA_VERSION) {
        r = sp_fail(err, SP_ERR_UNSUPPORTED,
                    "%s: database schema version %d is newer than this sketchpose understands (%d); update sketchpose", path, v,
                    SP_DB_SCHEMA_VERSION);
        goto fail;
    }
    // Only SP_DB_CREATE makes a database: an existing empty file (a typo'd
    // path, a truncated copy) opened for writing is refused, not given a schema.
    if (!ro && exists && v == 0 && !(flags & SP_DB_CREATE) && counted && tables == 0) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: not a sketchpose database (an empty file; `sketchpose db init` makes one)", path);
        goto fail;
    }
    if (!ro) {
        // WAL: readers (the kiosk) never block the curator and never see a half-written change.
        sqlite3_stmt* jm = NULL;
        rc = sqlite3_prepare_v2(db->h, "PRAGMA journal_mode = WAL", -1, &jm, NULL);
        if (rc == SQLITE_OK) rc = sqlite3_step(jm);
        bool wal = rc == SQLITE_ROW && !sqlite3_stricmp((const char*)sqlite3_column_text(jm, 0), "wal");
        sqlite3_finalize(jm);
        if (!wal) {
            r = rc == SQLITE_ROW ? sp_fail(err, SP_ERR_IO, "%s: cannot switch to WAL mode", path) : db_fail(db, rc, "switching to WAL mode", err);
            goto fail;
        }
        // FULL: a committed change survives a power cut too, not only a crash.
        if ((r = db_exec(db, "PRAGMA synchronous = FULL", err)) != SP_OK) goto fail;
    }
    if (ro && !ro_file && (r = db_exec(db, "PRAGMA query_only = ON", err)) != SP_OK) goto fail;
    if ((r = db_exec(db, "PRAGMA foreign_keys = ON", err)) != SP_OK) goto fail;
    if (v < SP_DB_SCHEMA_VERSION) {
        if (ro && exists && v > 0) {
            r = sp_fail(err, SP_ERR_UNSUPPORTED,
                        "%s: database schema version %d is older than %d; a user who may write it migrates it by opening it once "
                        "for writing "
                        "(e.g. `sketchpose db check`)",
                        path, v, SP_DB_SCHEMA_VERSION);
            goto fail;
        }
        if (ro) { // an empty file said as a writer says it (the reader's "no schema" said nothing of what to do)
            r = sp_fail(err, SP_ERR_INVALID, "%s: not a sketchpose database (%s)", path,
                        counted && tables == 0 ? "an empty file; `sketchpose db init` makes one" : "no schema");
            goto fail;
        }
        if ((r = db_migrate(db, SP_DB_SCHEMA_VERSION, err)) != SP_OK) goto fail;
    }
    list_open(db);
    if (!db->at_known && db->listed) db->at_dev = db->dev, db->at_ino = db->ino, db->at_known = true; // made by this open
    *out = db;
    return SP_OK;
fail:
    sqlite3_close(db->h);
    free(db->path);
    free(db);
    return r;
}

void sp_db_close(sp_db* db)
{
    if (!db) return;
    db_rollback(db);
    sqlite3_close(db->h);
    unlist_open(db);
    free(db->path);
    free(db);
}

void sp_db_set_busy_timeout(sp_db* db, int ms)
{
    db->busy_ms = ms < 0 ? 0 : ms;
    sqlite3_busy_timeout(db->h, db->busy_ms);
}

sp_db_file_state sp_db_file_check(const sp_db* db)
{
    struct stat st;
    if (stat(db->path, &st) != 0) return errno == ENOENT || errno == ENOTDIR ? SP_DB_FILE_GONE : SP_DB_FILE_SAME;
    return db->at_known && (st.st_dev != db->at_dev || st.st_ino != db->at_ino) ? SP_DB_FILE_REPLACED : SP_DB_FILE_SAME;
}

bool sp_db_file_id(const sp_db* db, uint64_t* dev, uint64_t* ino)
{
    *dev = db->at_known ? (uint64_t)db->at_dev : 0;
    *ino = db->at_known ? (uint64_t)db->at_ino : 0;
    return db->at_known;
}

// Whether the WAL w was made or written after the database file db arrived
// (its mtime against the file's ctime, which rename sets; to the nanosecond:
// a connection opened in the second of a rename makes its WAL within it. Not
// the WAL's ctime: SQLite running as root gives the WAL its owner at every open).
static bool written_after(const struct stat* w, const struct stat* db)
{
    return w->st_mtim.tv_sec != db->st_ctim.tv_sec ? w->st_mtim.tv_sec > db->st_ctim.tv_sec
                                                   : w->st_mtim.tv_nsec > db->st_ctim.tv_nsec;
}

// The -shm's times say nothing (readers write it), so only the WAL's are compared.
void sp_db_drop_stale_sidecars(const char* path)
{
    struct stat db, w;
    if (stat(path, &db) != 0) return;
    // Another handle of ours on the new file made those, or uses them (the
    // kiosk's collector follows a replaced file before its pipeline does).
    if (open_here(&db)) return;
    // Whole names or none: a name cut short could be the database's own.
    char *wal = side_path(path, 0), *shm = side_path(path, 1);
    bool drop = wal && shm && !(stat(wal, &w) == 0 && written_after(&w, &db));
    int fd = drop ? open(shm, O_RDWR) : -1;
    if (fd >= 0) {
        // SQLite's unix VFS locks bytes 120..128 of the -shm (the lock slots and the dead man switch).
        struct flock fl = {.l_type = F_WRLCK, .l_whence = SEEK_SET, .l_start = 120, .l_len = 9};
        drop = fcntl(fd, F_GETLK, &fl) == 0 && fl.l_type == F_UNLCK;
        close(fd);
    }
    if (drop) unlink(wal), unlink(shm);
    free(wal), free(shm);
}

sp_result sp_db_checkpoint(sp_db* db, sp_error* err)
{
    int log = 0, done = 0;
    int rc = sqlite3_wal_checkpoint_v2(db->h, NULL, SQLITE_CHECKPOINT_TRUNCATE, &log, &done);
    if (rc == SQLITE_BUSY || (rc == SQLITE_OK && done < log))
        return sp_fail(err, SP_ERR_BUSY, "%s: checkpoint: the database is in use; its WAL is kept", db->path);
    return rc == SQLITE_OK ? SP_OK : db_fail(db, rc, "checkpointing", err);
}

const char* sp_db_path(const sp_db* db) { return db->path; }

int sp_db_schema_version(sp_db* db)
{
    int v = -1;
    pragma_int(db, "PRAGMA user_version", &v);
    return v;
}

uint64_t sp_db_generation(sp_db* db)
{
    int dv = 0;
    if (pragma_int(db, "PRAGMA data_version", &dv) != SQLITE_OK) return 0;
    if (db->gen_valid && dv == db->dv) return db->gen;
    sqlite3_stmt* st = NULL;
    uint64_t g = 0;
    if (sqlite3_prepare_v2(db->h, "SELECT value FROM meta WHERE key = 'generation'", -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        g = (uint64_t)sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    if (g) {
        db->gen = g;
        db->dv = dv;
        db->gen_valid = true;
    }
    return g;
}

sp_result sp_db_log(sp_db* db, const char* by, const char* action, const char* subject, const char* details, sp_error* err)
{
    sp_result r = db_begin(db, err);
    if (r != SP_OK) return r;
    if ((r = db_log_row(db, by, action, subject, details, err)) != SP_OK) {
        db_rollback(db);
        return r;
    }
    return db_commit(db, err);
}

sp_result sp_db_log_json(sp_db* db, const char* subject, char** json, sp_error* err)
{
    *json = NULL;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db, subject ? "SELECT id, at, by, action, subject, details FROM log WHERE subject = ? ORDER BY id"
                                         : "SELECT id, at, by, action, subject, details FROM log ORDER BY id",
                             &st, err);
    if (r != SP_OK) return r;
    if (subject) sqlite3_bind_text(st, 1, subject, -1, SQLITE_TRANSIENT);
    db_str b = {0};
    db_str_printf(&b, "[");
    int rc, n = 0;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        db_str_printf(&b, "%s{\"id\": %lld, \"at\": ", n++ ? ", " : "", (long long)sqlite3_column_int64(st, 0));
        db_str_json(&b, (const char*)sqlite3_column_text(st, 1));
        db_str_printf(&b, ", \"by\": ");
        db_str_json(&b, (const char*)sqlite3_column_text(st, 2));
        db_str_printf(&b, ", \"action\": ");
        db_str_json(&b, (const char*)sqlite3_column_text(st, 3));
        db_str_printf(&b, ", \"subject\": ");
        db_str_json(&b, (const char*)sqlite3_column_text(st, 4));
        const char* d = (const char*)sqlite3_column_text(st, 5);
        db_str_printf(&b, ", \"details\": %s}", d && *d ? d : "null");
    }
    sqlite3_finalize(st);
    db_str_printf(&b, "]");
    if (rc != SQLITE_DONE) {
        free(b.s);
        return db_fail(db, rc, "reading the log", err);
    }
    if (b.oom) {
        free(b.s);
        return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    }
    *json = b.s;
    return SP_OK;
}

void sp_db_free_strings(char** names, int count)
{
    if (!names) return;
    for (int i = 0; i < count; ++i)
        free(names[i]);
    free(names);
}
