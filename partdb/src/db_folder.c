// db_folder.c: export to and import from a folder, and the default database
// built from assets/.
#define _XOPEN_SOURCE 700 // nftw
#include <cjson/cJSON.h>
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "db_internal.h"
#include "sp/concept.h"
#include "sp/math.h"
#include "sp/part.h"
#include "sp/sketch_io.h"

// ---- export ----------------------------------------------------------------------
// An export is written into a fresh folder beside DIR (same parent, so that
// rename(2) is atomic) and renamed to DIR only when every file and the
// manifest are written: `db init --from DIR` reads whatever DIR holds as a
// whole export, so a failed one must leave nothing there.

typedef struct export_dir {
    char final[832]; // DIR, a symbolic link resolved, no trailing '/'; at most 800 characters
    char tmp[900];   // the folder being written
    struct stat had; // DIR's own stat when it exists (empty), for its permissions
    bool exists;
} export_dir;

static int sync_entry(const char* path, const struct stat* st, int flag, struct FTW* ftw)
{
    (void)st, (void)ftw;
    int fd = open(path, O_RDONLY | O_CLOEXEC | (flag == FTW_DP ? O_DIRECTORY : 0));
    bool ok = fd >= 0 && (fsync(fd) == 0 || errno == EINVAL);
    int e = errno;
    if (fd >= 0) close(fd);
    errno = e; // what sync_tree's caller reports
    return ok ? 0 : 1;
}

// Every file and folder of the export on disk before it gets its name, so
// that after a power cut DIR is a whole export or absent, never one with
// empty files.
static bool sync_tree(const char* path)
{
    return nftw(path, sync_entry, 16, FTW_DEPTH | FTW_PHYS) == 0;
}

static sp_result not_empty(const char* dir, sp_error* err)
{
    return sp_fail(err, SP_ERR_INVALID,
                   "%s: exists and is not empty (an export goes into a new or empty folder, never over another)", dir);
}

static bool dir_is_empty(const char* dir)
{
    DIR* d = opendir(dir);
    struct dirent* e;
    bool empty = d != NULL;
    while (empty && (e = readdir(d)))
        empty = !strcmp(e->d_name, ".") || !strcmp(e->d_name, "..");
    if (d) closedir(d);
    return empty;
}

// Removes the temporary folders an export to `final` left when its process
// was killed: "<final>.partial-<pid>-<k>" whose pid runs no more on this
// machine. They hold copies only, and a folder of a running export (this
// machine's) is left alone.
static void remove_stopped_exports(const char* final)
{
    char* folder = sp_path_folder(final);
    const char* base = strrchr(final, '/');
    base = base ? base + 1 : final;
    DIR* d = folder ? opendir(folder) : NULL;
    size_t bl = strlen(base);
    struct dirent* e;
    while (d && (e = readdir(d))) {
        const char* tail = e->d_name + bl;
        if (strncmp(e->d_name, base, bl) || strncmp(tail, ".partial-", 9)) continue;
        char* end;
        long pid = strtol(tail + 9, &end, 10);
        if (pid <= 0 || end == tail + 9 || *end != '-' || !end[1] || strspn(end + 1, "0123456789") != strlen(end + 1)) continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
        char path[1200];
        if (snprintf(path, sizeof path, "%s/%s", folder, e->d_name) < (int)sizeof path) sp_dir_remove_tree(path);
    }
    if (d) closedir(d);
    free(folder);
}

// Whether folder `path` (stat st) is a mount point: listed as one in
// /proc/self/mountinfo (a bind mount from the same file system has its
// parent's device), else on another device than its parent ("X/." and
// links resolved first).
static bool is_mount_point(const char* path, const struct stat* st)
{
    char* real = realpath(path, NULL);
    if (!real) return false;
    bool found = false;
    FILE* f = fopen("/proc/self/mountinfo", "re");
    char line[4096], field[4096];
    while (f && !found && fgets(line, sizeof line, f)) {
        // The fifth field is the mount point, with ' ', '\t', '\n' and '\\' as \ooo.
        char* at = line;
        for (int k = 0; k < 4 && at; ++k)
            at = strchr(at, ' '), at = at ? at + 1 : NULL;
        size_t w = 0;
        for (; at && *at && *at != ' ' && w + 1 < sizeof field; ++at)
            if (at[0] == '\\' && isdigit((unsigned char)at[1]) && isdigit((unsigned char)at[2]) &&
                isdigit((unsigned char)at[3])) {
                field[w++] = (char)((at[1] - '0') * 64 + (at[2] - '0') * 8 + (at[3] - '0'));
                at += 3;
            } else {
                field[w++] = *at;
            }
        field[w] = 0;
        found = at && !strcmp(field, real);
    }
    if (f) fclose(f);
    if (!f) {
        char* parent = sp_path_folder(real);
        struct stat up;
        found = parent && stat(parent, &up) == 0 && up.st_dev != st->st_dev;
        free(parent);
    }
    free(real);
    return found;
}

// Checks DIR (absent, or an empty folder) and makes the temporary folder beside it.
static sp_result export_begin(const char* dir, export_dir* ex, sp_error* err)
{
    memset(ex, 0, sizeof *ex);
    size_t n = strlen(dir);
    // "out/" and "out/." name out, whose sibling is out.partial-... (with
    // "out/." the temporary folder was made inside out, and the export failed
    // after the work; a second curator review).
    while (n > 1 && (dir[n - 1] == '/' || (n > 2 && dir[n - 1] == '.' && dir[n - 2] == '/')))
        n -= dir[n - 1] == '/' ? 1 : 2;
    // Room for sketches/<category>/<source>-<id>.json below the temporary folder's name.
    if (n == 0 || n > 800)
        return sp_fail(err, SP_ERR_INVALID, "%s: not a usable folder name (empty or over 800 characters)", dir);
    snprintf(ex->final, sizeof ex->final, "%.*s", (int)n, dir);
    struct stat st;
    if (lstat(ex->final, &st) == 0 && S_ISLNK(st.st_mode)) {
        // A link to a folder stays a link: the folder it names is the one replaced.
        char* real = realpath(ex->final, NULL);
        if (!real) return sp_fail(err, SP_ERR_IO, "%s: a symbolic link to nothing usable (%s)", dir, strerror(errno));
        if (strlen(real) > 800) {
            free(real);
            return sp_fail(err, SP_ERR_INVALID, "%s: the folder it names has a name over 800 characters", dir);
        }
        snprintf(ex->final, sizeof ex->final, "%s", real);
        free(real);
    }
    remove_stopped_exports(ex->final);
    if (stat(ex->final, &ex->had) == 0) {
        if (!S_ISDIR(ex->had.st_mode)) return sp_fail(err, SP_ERR_INVALID, "%s: exists and is not a folder", dir);
        if (!dir_is_empty(ex->final)) return not_empty(dir, err);
        // The export is written beside DIR and renamed onto it, which a
        // mount point refuses: said before the work (an empty USB stick's
        // folder failed after the whole export was written on the disk it
        // is mounted on; an outside curator review).
        if (is_mount_point(ex->final, &ex->had))
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: a mount point (a USB stick?), which the finished export cannot be renamed onto: export into a "
                           "new folder on it, e.g. %s/sketchpose-export",
                           dir, ex->final);
        ex->exists = true;
    } else if (errno != ENOENT) {
        return sp_fail(err, SP_ERR_IO, "%s: cannot reach the folder (%s)", dir, strerror(errno));
    }
    for (int k = 0; k < 100; ++k) {
        snprintf(ex->tmp, sizeof ex->tmp, "%s.partial-%ld-%d", ex->final, (long)getpid(), k);
        if (mkdir(ex->tmp, 0777) == 0) return SP_OK;
        if (errno != EEXIST) break;
    }
    return sp_fail(err, SP_ERR_IO, "%s: cannot create a folder beside it to write the export in (%s)", dir, strerror(errno));
}

// Puts the finished export in place, or takes the temporary folder back. A
// message about a file in the temporary folder names it as it would be in DIR.
static sp_result export_end(export_dir* ex, sp_result r, sp_error* err)
{
    if (r == SP_OK) {
        if (ex->exists) chmod(ex->tmp, ex->had.st_mode & 07777); // an empty folder replaced keeps its permissions
        if (!sync_tree(ex->tmp)) {
            r = sp_fail(err, SP_ERR_IO, "%s: cannot write the export to disk (%s); no export was written", ex->final,
                        strerror(errno));
        } else if (rename(ex->tmp, ex->final) == 0) {
            // rename(2) replaces an empty folder and refuses one that is not,
            // so files put into DIR meanwhile are never lost.
            sp_path_sync_folder(ex->final);
            return SP_OK;
        } else {
            r = errno == ENOTEMPTY || errno == EEXIST
                    ? not_empty(ex->final, err)
                    : sp_fail(err, SP_ERR_IO, "%s: cannot put the export in place (%s)", ex->final, strerror(errno));
        }
    } else if (err) {
        size_t n = strlen(ex->tmp);
        char was[sizeof err->text];
        memcpy(was, err->text, sizeof was);
        if (!strncmp(was, ex->tmp, n))
            sp_fail(err, r, "%s%s; no export was written", ex->final, was + n);
        else
            sp_fail(err, r, "%s; %s: no export was written", was, ex->final);
    }
    sp_dir_remove_tree(ex->tmp);
    return r;
}

// A part whose bytes no longer match its checksum would make an export `db
// init --from` refuses: the export fails now, naming the part, not at the
// restore. Row columns: name 0, category 1, gltf 3, sha256 6.
static sp_result export_part_intact(sp_db* db, sqlite3_stmt* st, sp_error* err)
{
    const void* b = sqlite3_column_blob(st, 3);
    size_t n = (size_t)sqlite3_column_bytes(st, 3);
    const char* want = (const char*)sqlite3_column_text(st, 6);
    char got[65];
    if (!sp_sha256_hex(b, n, got)) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (want && !strcmp(got, want)) return SP_OK;
    return sp_fail(err, SP_ERR_PARSE, "%s: part %s (%s): stored bytes do not match the checksum (`db check` lists such parts)",
                   db->path, (const char*)sqlite3_column_text(st, 0), (const char*)sqlite3_column_text(st, 1));
}

static sp_result export_rows(sp_db* db, const char* dir, sp_error* err)
{
    char path[1024];
    sp_result r;
    snprintf(path, sizeof path, "%s/parts", dir);
    if ((r = sp_dir_make(path, err)) != SP_OK) return r;
    snprintf(path, sizeof path, "%s/sketches", dir);
    if ((r = sp_dir_make(path, err)) != SP_OK) return r;
    if ((r = db_exec(db, "BEGIN", err)) != SP_OK) return r; // one snapshot
    db_str m = {0};
    db_str_printf(&m, "{\"format\": \"sketchpose-db-export\", \"version\": 1, \"schema\": %d, \"parts\": [", SP_DB_SCHEMA_VERSION);
    sqlite3_stmt* st;
    if ((r = db_prepare(db,
                        "SELECT name, category, abstraction, gltf, added_by, added_at, sha256,"
                        " json_extract(summary, '$.source_sha256') FROM parts ORDER BY name",
                        &st, err)) != SP_OK)
        goto out;
    int rc, n = 0;
    while (r == SP_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        const char* name = (const char*)sqlite3_column_text(st, 0);
        if ((r = export_part_intact(db, st, err)) != SP_OK) break;
        // Named for what it holds: a part added as a self-contained .gltf is
        // stored as that JSON (a .glb name made tools read it as binary).
        const void* blob = sqlite3_column_blob(st, 3);
        size_t bytes = (size_t)sqlite3_column_bytes(st, 3);
        const char* ext = bytes >= 4 && !memcmp(blob, "glTF", 4) ? "glb" : "gltf";
        snprintf(path, sizeof path, "%s/parts/%s.%s", dir, name, ext);
        r = db_write_file(path, blob, bytes, err);
        db_str_printf(&m, "%s{\"name\": ", n++ ? ", " : "");
        db_str_json(&m, name);
        db_str_printf(&m, ", \"category\": ");
        db_str_json(&m, (const char*)sqlite3_column_text(st, 1));
        db_str_printf(&m, ", \"abstraction\": ");
        db_str_json(&m, (const char*)sqlite3_column_text(st, 2));
        db_str_printf(&m, ", \"file\": \"parts/%s.%s\", \"added_by\": ", name, ext);
        db_str_json(&m, (const char*)sqlite3_column_text(st, 4));
        db_str_printf(&m, ", \"added_at\": ");
        db_str_json(&m, (const char*)sqlite3_column_text(st, 5));
        if (sqlite3_column_type(st, 7) == SQLITE_TEXT) { // the file it was added from, for the same-file warning
            db_str_printf(&m, ", \"source_sha256\": ");
            db_str_json(&m, (const char*)sqlite3_column_text(st, 7));
        }
        db_str_printf(&m, "}");
    }
    // A read error ends the loop as the last row does: an export without the rows after it is no export.
    if (r == SP_OK && rc != SQLITE_DONE) r = db_fail(db, rc, "reading the parts", err);
    sqlite3_finalize(st);
    if (r != SP_OK) goto out;
    db_str_printf(&m, "], \"sketches\": [");
    if ((r = db_prepare(db,
                        "SELECT s.id, s.category, s.source, p.name, s.strokes, s.png, s.raster_w, s.added_by, s.status, "
                        "s.added_at FROM sketches s"
                        " LEFT JOIN parts p ON p.id = s.part_id ORDER BY s.category, s.id",
                        &st, err)) != SP_OK)
        goto out;
    n = 0;
    char last_cat[SP_NAME_MAX] = "";
    while (r == SP_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        long long id = sqlite3_column_int64(st, 0);
        const char* cat = (const char*)sqlite3_column_text(st, 1);
        const char* src = (const char*)sqlite3_column_text(st, 2);
        if (strcmp(cat, last_cat) != 0) {
            snprintf(last_cat, sizeof last_cat, "%s", cat);
            snprintf(path, sizeof path, "%s/sketches/%s", dir, cat);
            if ((r = sp_dir_make(path, err)) != SP_OK) break;
        }
        const char* ext;
        if (sqlite3_column_type(st, 4) != SQLITE_NULL) {
            ext = "json";
            // Strokes that do not parse would make an export `db init --from`
            // refuses: the export fails now, naming the row, not at the restore.
            char what[SP_NAME_MAX + 64];
            snprintf(what, sizeof what, "sketch %lld (%s)", id, cat);
            sp_sketch s = {0};
            sp_error e = {0};
            if (sp_sketch_parse_json((const char*)sqlite3_column_text(st, 4), (size_t)sqlite3_column_bytes(st, 4), what, &s,
                                     &e) != SP_OK) {
                r = sp_fail(err, SP_ERR_PARSE, "%s: %s (`db check` lists such sketches)", db->path, e.text);
                break;
            }
            sp_sketch_free(&s);
            snprintf(path, sizeof path, "%s/sketches/%s/%s-%06lld.json", dir, cat, src, id);
            r = db_write_file(path, sqlite3_column_text(st, 4), (size_t)sqlite3_column_bytes(st, 4), err);
        } else if (sqlite3_column_type(st, 5) != SQLITE_NULL) {
            ext = "png";
            snprintf(path, sizeof path, "%s/sketches/%s/%s-%06lld.png", dir, cat, src, id);
            r = db_write_file(path, sqlite3_column_blob(st, 5), (size_t)sqlite3_column_bytes(st, 5), err);
        } else {
            continue; // a raster without its PNG (none are stored that way today)
        }
        db_str_printf(&m, "%s{\"id\": %lld, \"file\": \"sketches/%s/%s-%06lld.%s\", \"category\": ", n++ ? ", " : "", id, cat,
                      src, id, ext);
        db_str_json(&m, cat);
        db_str_printf(&m, ", \"source\": \"%s\", \"part\": ", src);
        if (sqlite3_column_type(st, 3) != SQLITE_NULL) db_str_json(&m, (const char*)sqlite3_column_text(st, 3));
        else db_str_printf(&m, "null");
        db_str_printf(&m, ", \"added_by\": ");
        db_str_json(&m, (const char*)sqlite3_column_text(st, 7));
        db_str_printf(&m, ", \"added_at\": ");
        db_str_json(&m, (const char*)sqlite3_column_text(st, 9));
        if (sqlite3_column_type(st, 8) != SQLITE_NULL) {
            db_str_printf(&m, ", \"status\": ");
            db_str_json(&m, (const char*)sqlite3_column_text(st, 8));
        }
        db_str_printf(&m, "}");
    }
    if (r == SP_OK && rc != SQLITE_DONE) r = db_fail(db, rc, "reading the sketches", err);
    sqlite3_finalize(st);
    if (r != SP_OK) goto out;
    // The highest id ever given, so that the ids of sketches deleted before
    // the export are not given again after it.
    if ((r = db_prepare(db, "SELECT " DB_SKETCH_ID_HIGH, &st, err)) != SP_OK) goto out;
    db_str_printf(&m, "], \"sketch_id_high\": %lld}\n",
                  sqlite3_step(st) == SQLITE_ROW ? (long long)sqlite3_column_int64(st, 0) : 0);
    sqlite3_finalize(st);
    if (m.oom) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        goto out;
    }
    snprintf(path, sizeof path, "%s/manifest.json", dir);
    r = db_write_file(path, m.s, m.len, err);
out:
    free(m.s);
    db_rollback(db);
    return r;
}

sp_result sp_db_export(sp_db* db, const char* dir, sp_error* err)
{
    export_dir ex;
    sp_result r = export_begin(dir, &ex, err);
    if (r != SP_OK) return r;
    return export_end(&ex, export_rows(db, ex.tmp, err), err);
}

static sp_db_source parse_source(const char* s)
{
    if (s && !strcmp(s, "synthetic")) return SP_DB_SOURCE_SYNTHETIC;
    if (s && !strcmp(s, "kiosk")) return SP_DB_SOURCE_KIOSK;
    return SP_DB_SOURCE_CURATED;
}

static const char* jstr(const cJSON* o, const char* key)
{
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

// Reads one drawing into a sample (and its PNG bytes for rasters).
static sp_result read_sample(const char* path, sp_sample* smp, void** png, size_t* png_size, sp_error* err)
{
    memset(smp, 0, sizeof *smp);
    *png = NULL;
    *png_size = 0;
    sp_result r = sp_drawing_read(path, &smp->sketch, &smp->raster, err);
    if (r != SP_OK) return r;
    if (smp->raster.pixels) r = db_read_file(path, png, png_size, err);
    if (r == SP_OK) r = db_sample_ok(smp, path, err);
    if (r != SP_OK) {
        sp_sketch_free(&smp->sketch);
        sp_raster_free(&smp->raster);
        free(*png);
        *png = NULL;
    }
    return r;
}

static int64_t part_id(sp_db* db, const char* name)
{
    sqlite3_stmt* st = NULL;
    int64_t id = 0;
    if (name && sqlite3_prepare_v2(db->h, "SELECT id FROM parts WHERE name = ?", -1, &st, NULL) == SQLITE_OK) {
        sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
        if (sqlite3_step(st) == SQLITE_ROW) id = sqlite3_column_int64(st, 0);
    }
    sqlite3_finalize(st);
    return id;
}

// Whether s is one of the n names.
static bool name_in(const char* s, const char* const* names, int n)
{
    for (int k = 0; s && k < n; ++k)
        if (!strcmp(s, names[k])) return true;
    return false;
}

// A time as the database writes one (strftime '%Y-%m-%dT%H:%M:%fZ').
static bool timestamp_ok(const char* t)
{
    static const char form[] = "dddd-dd-ddTdd:dd:dd.dddZ";
    if (!t || strlen(t) != sizeof form - 1) return false;
    for (size_t k = 0; k < sizeof form - 1; ++k)
        if (form[k] == 'd' ? !isdigit((unsigned char)t[k]) : t[k] != form[k]) return false;
    int mo = atoi(t + 5), dd = atoi(t + 8), hh = atoi(t + 11), mi = atoi(t + 14), ss = atoi(t + 17);
    return mo >= 1 && mo <= 12 && dd >= 1 && dd <= 31 && hh <= 23 && mi <= 59 && ss <= 60; // a real time of day
}

static int compare_ids(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

// No sketch id given twice in the manifest: each names one drawing.
static sp_result ids_unique(const cJSON* sketches, const char* path, sp_error* err)
{
    int n = cJSON_GetArraySize(sketches), m = 0;
    double* ids = malloc(sizeof(double) * (size_t)(n + 1));
    if (!ids) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    const cJSON* it;
    cJSON_ArrayForEach(it, sketches)
    {
        const cJSON* id = cJSON_GetObjectItemCaseSensitive(it, "id");
        if (id) ids[m++] = id->valuedouble;
    }
    qsort(ids, (size_t)m, sizeof *ids, compare_ids);
    int k = 1;
    while (k < m && ids[k] != ids[k - 1])
        ++k;
    sp_result r = k < m ? sp_fail(err, SP_ERR_INVALID, "%s: sketch id %.0f given twice", path, ids[k]) : SP_OK;
    free(ids);
    return r;
}

// What a manifest's entries must be before anything is stored: a part's file
// inside the export folder (said as such: "../outside.glb" was "a part entry
// without name or file"), and an added_by without control characters, as
// --by takes it (a newline and an escape code were stored and reached
// `db log` and a terminal). The value is shown escaped.
static sp_result manifest_entries_ok(const cJSON* parts, const cJSON* sketches, const char* path, sp_error* err)
{
    char shown[160];
    int i = 0;
    const cJSON* it;
    cJSON_ArrayForEach(it, parts)
    {
        const char* file = jstr(it, "file");
        if (file && (strstr(file, "..") || file[0] == '/'))
            return sp_fail(err, SP_ERR_INVALID, "%s: part %d: file '%s' must be inside the export folder (no '..', not absolute)",
                           path, i, sp_text_printable(file, shown, sizeof shown));
        if (sp_text_has_control(jstr(it, "added_by")))
            return sp_fail(err, SP_ERR_INVALID, "%s: part %d: added_by '%s' holds control characters", path, i,
                           sp_text_printable(jstr(it, "added_by"), shown, sizeof shown));
        ++i;
    }
    // A source or a review status of no known kind: a typo ("sythetic") was
    // stored as curated, and a status failed the schema's CHECK naming the
    // output database in SQL (an outside review).
    static const char *const sources[] = {"synthetic", "curated", "kiosk"}, *const statuses[] = {"pending", "approved",
                                                                                                 "rejected"};
    i = 0;
    cJSON_ArrayForEach(it, sketches)
    {
        const cJSON* id = cJSON_GetObjectItemCaseSensitive(it, "id");
        const cJSON* at = cJSON_GetObjectItemCaseSensitive(it, "added_at");
        if (id && !(cJSON_IsNumber(id) && id->valuedouble >= 1 && id->valuedouble < 9007199254740992.0 &&
                    id->valuedouble == floor(id->valuedouble)))
            return sp_fail(err, SP_ERR_INVALID, "%s: sketch %d: id is not a whole number from 1 to 2^53 - 1", path, i);
        if (at && !timestamp_ok(cJSON_GetStringValue(at)))
            return sp_fail(err, SP_ERR_INVALID, "%s: sketch %d: added_at '%s' is not a time as YYYY-MM-DDTHH:MM:SS.sssZ", path, i,
                           sp_text_printable(cJSON_IsString(at) ? at->valuestring : "(not text)", shown, sizeof shown));
        if (sp_text_has_control(jstr(it, "added_by")))
            return sp_fail(err, SP_ERR_INVALID, "%s: sketch %d: added_by '%s' holds control characters", path, i,
                           sp_text_printable(jstr(it, "added_by"), shown, sizeof shown));
        const cJSON* src = cJSON_GetObjectItemCaseSensitive(it, "source");
        const cJSON* status = cJSON_GetObjectItemCaseSensitive(it, "status");
        if (src && !name_in(cJSON_GetStringValue(src), sources, 3))
            return sp_fail(err, SP_ERR_INVALID, "%s: sketch %d: source '%s' is not synthetic, curated or kiosk", path, i,
                           sp_text_printable(cJSON_IsString(src) ? src->valuestring : "(not a name)", shown, sizeof shown));
        if (status && !cJSON_IsNull(status) && !name_in(cJSON_GetStringValue(status), statuses, 3))
            return sp_fail(err, SP_ERR_INVALID, "%s: sketch %d: status '%s' is not pending, approved or rejected", path, i,
                           sp_text_printable(cJSON_IsString(status) ? status->valuestring : "(not a name)", shown, sizeof shown));
        ++i;
    }
    return ids_unique(sketches, path, err);
}

// Before an import's sketches are stored: the highest id ever given made at
// least the export's and every id the manifest gives, so that a sketch given
// a new id never takes one the manifest keeps for another.
static sp_result hold_ids_back(sp_db* db, const cJSON* man, const cJSON* sketches, sp_error* err)
{
    double high = 0;
    const cJSON* h = cJSON_GetObjectItemCaseSensitive(man, "sketch_id_high");
    if (cJSON_IsNumber(h) && h->valuedouble >= 1 && h->valuedouble < 9007199254740992.0) high = floor(h->valuedouble);
    const cJSON* it;
    cJSON_ArrayForEach(it, sketches)
    {
        const cJSON* id = cJSON_GetObjectItemCaseSensitive(it, "id");
        if (id) high = fmax(high, id->valuedouble);
    }
    sqlite3_stmt* st;
    sp_result r = db_prepare(
        db, "INSERT OR REPLACE INTO meta(key, value) VALUES ('sketch_id_high', max(?1, " DB_SKETCH_ID_HIGH "))", &st, err);
    if (r != SP_OK) return r;
    sqlite3_bind_int64(st, 1, (sqlite3_int64)high);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? SP_OK : db_fail(db, rc, "importing the sketches' ids", err);
}

// The sketch just stored (the last row) takes the id and the time its
// manifest entry gives, where the id is free: a moved database keeps what
// its review ids and `--after` name (they named other drawings after an
// export and `init --from`, the visits regrouped by category; an outside
// curator review).
static sp_result keep_id_and_time(sp_db* db, const cJSON* entry, sp_error* err)
{
    const cJSON* id = cJSON_GetObjectItemCaseSensitive(entry, "id");
    const char* at = jstr(entry, "added_at");
    if (!id && !at) return SP_OK;
    sqlite3_stmt* st;
    sp_result r = db_prepare(db,
                             "UPDATE sketches SET id = CASE WHEN ?1 IS NULL OR EXISTS (SELECT 1 FROM sketches WHERE id = ?1)"
                             " THEN id ELSE ?1 END, added_at = coalesce(?2, added_at) WHERE id = ?3",
                             &st, err);
    if (r != SP_OK) return r;
    if (id) sqlite3_bind_int64(st, 1, (sqlite3_int64)id->valuedouble);
    if (at) sqlite3_bind_text(st, 2, at, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 3, sqlite3_last_insert_rowid(db->h));
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? SP_OK : db_fail(db, rc, "importing a sketch's id", err);
}

sp_result sp_db_import(sp_db* db, const char* dir, const char* by, sp_error* err)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/manifest.json", dir);
    cJSON* man;
    sp_result r = db_read_json(path, &man, err);
    if (r != SP_OK) return r;
    const cJSON* parts = cJSON_GetObjectItemCaseSensitive(man, "parts");
    const cJSON* sketches = cJSON_GetObjectItemCaseSensitive(man, "sketches");
    if (!man || !cJSON_IsArray(parts) || !cJSON_IsArray(sketches) || !jstr(man, "format") ||
        strcmp(jstr(man, "format"), "sketchpose-db-export") != 0) {
        cJSON_Delete(man);
        return sp_fail(err, SP_ERR_PARSE, "%s: not a sketchpose-db-export manifest", path);
    }
    const cJSON* version = cJSON_GetObjectItemCaseSensitive(man, "version");
    const cJSON* schema = cJSON_GetObjectItemCaseSensitive(man, "schema");
    if ((version && !(cJSON_IsNumber(version) && version->valuedouble == 1)) ||
        (schema && !(cJSON_IsNumber(schema) && schema->valuedouble >= 1 && schema->valuedouble <= SP_DB_SCHEMA_VERSION))) {
        char v[32] = "none", sc[32] = "none";
        const cJSON* said[2] = {version, schema};
        char* text[2] = {v, sc};
        for (int k = 0; k < 2; ++k)
            if (said[k] && cJSON_IsNumber(said[k]))
                snprintf(text[k], sizeof v, "%g", said[k]->valuedouble);
            else if (said[k])
                snprintf(text[k], sizeof v, "not a number");
        cJSON_Delete(man);
        return sp_fail(err, SP_ERR_INVALID,
                       "%s: an export of version %s, schema %s; this sketchpose reads version 1, schemas 1 to %d (a newer "
                       "sketchpose's export?)",
                       path, v, sc, SP_DB_SCHEMA_VERSION);
    }
    if ((r = manifest_entries_ok(parts, sketches, path, err)) != SP_OK) {
        cJSON_Delete(man);
        return r;
    }
    const cJSON* it;
    cJSON_ArrayForEach(it, parts)
    {
        const char *file = jstr(it, "file"), *name = jstr(it, "name");
        if (!file || !name || strstr(file, "..")) {
            r = sp_fail(err, SP_ERR_PARSE, "%s: a part entry without name or file", path);
            break;
        }
        snprintf(path, sizeof path, "%s/%s", dir, file);
        sp_db_part_desc d = {.name = name,
                             .category = jstr(it, "category"),
                             .abstraction = jstr(it, "abstraction"),
                             .added_by = jstr(it, "added_by") ? jstr(it, "added_by") : by,
                             .synth_sketches = -1,
                             .source_sha256 = jstr(it, "source_sha256")};
        if ((r = sp_db_add_part_file(db, path, &d, NULL, err)) != SP_OK) break;
    }
    // Sketches: all of them in one transaction, after reading and checking every file.
    int n = cJSON_GetArraySize(sketches), read = 0;
    sp_sample* smp = r == SP_OK ? calloc((size_t)(n > 0 ? n : 1), sizeof *smp) : NULL;
    sp_db_png* png = r == SP_OK ? calloc((size_t)(n > 0 ? n : 1), sizeof *png) : NULL;
    if (r == SP_OK && (!smp || !png)) r = sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (r == SP_OK) {
        cJSON_ArrayForEach(it, sketches)
        {
            const char *file = jstr(it, "file"), *cat = jstr(it, "category");
            if (!file || !cat || strstr(file, "..") || !sp_part_name_is_plain(cat)) {
                r = sp_fail(err, SP_ERR_PARSE, "%s/manifest.json: a sketch entry without a file or a plain category", dir);
                break;
            }
            snprintf(path, sizeof path, "%s/%s", dir, file);
            void* bytes;
            size_t nb;
            if ((r = read_sample(path, &smp[read], &bytes, &nb, err)) != SP_OK) break;
            png[read].bytes = bytes;
            png[read].size = nb;
            ++read;
        }
    }
    // With no sketches, the highest id ever given is still kept.
    bool high = cJSON_GetObjectItemCaseSensitive(man, "sketch_id_high") != NULL;
    if (r == SP_OK && (read > 0 || high) && (r = db_begin(db, err)) == SP_OK) {
        r = hold_ids_back(db, man, sketches, err);
        int i = 0;
        cJSON_ArrayForEach(it, sketches)
        {
            if (r != SP_OK) break;
            const char* pname = jstr(it, "part");
            const char* src = jstr(it, "source");
            sp_db_source s = parse_source(src);
            if ((r = db_insert_sketch(db, jstr(it, "category"), s, s == SP_DB_SOURCE_SYNTHETIC ? part_id(db, pname) : 0, &smp[i],
                                      &png[i], jstr(it, "added_by") ? jstr(it, "added_by") : by, err)) != SP_OK)
                break;
            // A kiosk sketch keeps its review status (an export without one: approved, as stored before reviews).
            const char* status = jstr(it, "status");
            if (s == SP_DB_SOURCE_KIOSK && status && strcmp(status, "approved") != 0) {
                sqlite3_stmt* up;
                if ((r = db_prepare(db, "UPDATE sketches SET status = ? WHERE id = ?", &up, err)) != SP_OK) break;
                sqlite3_bind_text(up, 1, status, -1, SQLITE_STATIC);
                sqlite3_bind_int64(up, 2, sqlite3_last_insert_rowid(db->h));
                int rc = sqlite3_step(up);
                sqlite3_finalize(up);
                if (rc != SQLITE_DONE) {
                    r = db_fail(db, rc, "importing a kiosk sketch's review status", err);
                    break;
                }
            }
            if ((r = keep_id_and_time(db, it, err)) != SP_OK) break; // last: it may change the row's id
            ++i;
        }
        char details[128];
        snprintf(details, sizeof details, "{\"sketches\": %d}", read);
        if (r == SP_OK) r = db_log_row(db, by, "import", dir, details, err);
        if (r == SP_OK) r = db_commit(db, err);
        else db_rollback(db);
    }
    for (int i = 0; i < read; ++i) {
        sp_sketch_free(&smp[i].sketch);
        sp_raster_free(&smp[i].raster);
        free((void*)png[i].bytes);
    }
    free(smp);
    free(png);
    cJSON_Delete(man);
    return r;
}

// ---- the default database ---------------------------------------------------------

static bool is_part_file(const char* n)
{
    size_t l = strlen(n);
    return n[0] != '.' && ((l > 4 && !strcmp(n + l - 4, ".glb")) || (l > 5 && !strcmp(n + l - 5, ".gltf")));
}

// A message that starts with the temporary name says the name the user gave.
static void say_as_given(sp_error* err, const char* tmp, const char* path)
{
    size_t tl = strlen(tmp);
    if (!err || strncmp(err->text, tmp, tl) != 0) return;
    sp_error why = *err;
    snprintf(err->text, sizeof err->text, "%s%s", path, why.text + tl);
}

// Whether open `fd` is still the file at `path` (not unlinked or replaced).
static bool fd_is_at(int fd, const char* path)
{
    struct stat a, b;
    return fstat(fd, &a) == 0 && stat(path, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

// A build holds `<tmp>-lock` (flock) while it runs, taken before its
// database is made: a lock tells a live build from a killed one also across
// PID namespaces (containers) and NFS clients, where a pid says nothing.
// Returns the held descriptor; -1 with *busy when another build holds that
// name (a container's pid 1 and another's), -1 when the file system has no
// flock (then the build goes on unlocked, its lock file removed).
static int hold_build_lock(const char* tmp, bool* busy)
{
    char lock[1100];
    snprintf(lock, sizeof lock, "%s-lock", tmp);
    *busy = false;
    for (int tries = 0; tries < 8; ++tries) {
        int fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
        if (fd < 0) return -1;
        if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
            *busy = errno == EWOULDBLOCK;
            if (!*busy) unlink(lock);
            close(fd);
            return -1;
        }
        // Still the file at that name: a cleaner may have removed it between
        // the open and the lock (it unlinks only what it holds).
        if (fd_is_at(fd, lock)) return fd;
        close(fd);
    }
    return -1;
}

// Whether the build that owns `lock` is gone: its lock can be taken (then
// the lock file is removed while held, so a build that opened it meanwhile
// sees it gone and makes another), or, with no lock file or no flock on this
// file system (a build of an older sketchpose), no process here has its pid.
static bool build_gone(const char* lock, pid_t pid)
{
    int fd = open(lock, O_RDWR | O_CLOEXEC);
    bool no_lock_file = fd < 0 && errno == ENOENT;
    bool no_pid = pid != getpid() && kill(pid, 0) != 0 && errno == ESRCH;
    if (fd < 0) return no_lock_file && no_pid;
    bool gone;
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
        gone = fd_is_at(fd, lock);
        if (gone) unlink(lock);
    } else {
        gone = errno != EWOULDBLOCK && no_pid; // no flock here: the pid is all there is
    }
    close(fd);
    return gone;
}

// Removes what builds killed before they could clean up left beside `where`
// (`<where>.building-<n>` and its -wal, -shm and -lock), hidden names too:
// each build's fate is asked once, then its files go.
static void remove_stale_builds(const char* where)
{
    char* dir = sp_path_folder(where);
    const char* base = strrchr(where, '/');
    base = base ? base + 1 : where;
    char prefix[300];
    snprintf(prefix, sizeof prefix, "%s.building-", base);
    size_t pl = strlen(prefix);
    enum { BUILDS_MAX = 64 };
    char ids[BUILDS_MAX][16];
    int nid = 0;
    DIR* d = dir ? opendir(dir) : NULL;
    for (struct dirent* e; d && (e = readdir(d)) && nid < BUILDS_MAX;) {
        if (strncmp(e->d_name, prefix, pl) != 0) continue;
        const char* rest = e->d_name + pl;
        size_t digits = strspn(rest, "0123456789");
        const char* side = rest + digits;
        if (digits == 0 || digits > 9 || (side[0] && strcmp(side, "-wal") && strcmp(side, "-shm") && strcmp(side, "-lock")))
            continue;
        char id[16];
        snprintf(id, sizeof id, "%.*s", (int)digits, rest);
        bool seen = false;
        for (int k = 0; k < nid && !seen; ++k)
            seen = !strcmp(ids[k], id);
        if (!seen) snprintf(ids[nid++], sizeof ids[0], "%s", id);
    }
    if (d) closedir(d);
    for (int k = 0; dir && k < nid; ++k) {
        char file[4200];
        snprintf(file, sizeof file, "%s/%s%s-lock", dir, prefix, ids[k]);
        // A name with two more digits than a pid (a build that shared its pid
        // with another) always has a working lock: its number is no pid then.
        if (!build_gone(file, (pid_t)atol(ids[k]))) continue;
        static const char* const sides[] = {"", "-wal", "-shm"};
        for (int s = 0; s < 3; ++s) {
            snprintf(file, sizeof file, "%s/%s%s%s", dir, prefix, ids[k], sides[s]);
            unlink(file);
        }
    }
    free(dir);
}

// Builds a database beside `path` with fill(), then links it into place, so
// that an interrupted build never leaves a half database at `path`. link()
// never replaces: a database someone else completed meanwhile wins. An empty
// file is no database (`mktemp` makes one): it is replaced, if still empty.
static sp_result build_then_link(const char* path, sp_result (*fill)(sp_db*, const void*, sp_error*), const void* ctx, sp_error* err)
{
    struct stat st = {0};
    bool empty = stat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_size == 0;
    if (!empty && stat(path, &st) == 0)
        return sp_fail(err, SP_ERR_INVALID, "%s: exists already (remove it, or use another --db)", path);
    ino_t was = st.st_ino;
    // The empty file itself is replaced: through a link, the file it names
    // (the link stays), and built beside that one, on its file system. A
    // link to no file yet (data/sketchpose.db not made) is followed too, as
    // for every output: the build was linked onto the link's own name,
    // which link() refuses ("File exists"), after a minute's work (an
    // outside review).
    struct stat lst;
    bool dangling = !empty && lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode);
    char* real = empty ? realpath(path, NULL) : dangling ? sp_path_follow_links(path) : NULL;
    const char* where = real ? real : path;
    // `<where>.building-<pid>`, or with two more digits when another build
    // holds that name (the first process of two containers is pid 1 in each).
    char tmp[1024];
    if (strlen(where) + 40 > sizeof tmp) { // cut, the temporary name was the target's own, removed after
        sp_result r =
            sp_fail(err, SP_ERR_INVALID, "%s: path too long (%zu bytes) to build a database beside it", path, strlen(where));
        free(real);
        return r;
    }
    int lock = -1;
    bool busy = true;
    for (int k = 0; busy && k < 100; ++k) {
        if (k == 0)
            snprintf(tmp, sizeof tmp, "%s.building-%ld", where, (long)getpid());
        else
            snprintf(tmp, sizeof tmp, "%s.building-%ld%02d", where, (long)getpid(), k);
        lock = hold_build_lock(tmp, &busy);
    }
    remove_stale_builds(where);
    sp_db* db = NULL;
    sp_result r = sp_db_open(tmp, SP_DB_CREATE, &db, err);
    if (r == SP_OK) r = fill(db, ctx, err);
    sp_db_close(db);
    // The user named `path`; the temporary name beside it would only puzzle
    // them (a full disk while committing named it).
    if (r != SP_OK) say_as_given(err, tmp, path);
    struct stat now;
    bool replace = empty && stat(path, &now) == 0 && now.st_ino == was && now.st_size == 0;
    if (r == SP_OK && empty && !replace)
        r = sp_fail(err, SP_ERR_BUSY, "%s: written by another process meanwhile; nothing replaced", path);
    // It keeps the empty file's permissions (mktemp makes it 0600: a
    // database built into it is as private).
    if (r == SP_OK && replace) chmod(tmp, st.st_mode & 07777);
    if (r == SP_OK && (replace ? rename(tmp, where) : link(tmp, where)) != 0)
        r = sp_fail(err, errno == EEXIST ? SP_ERR_BUSY : SP_ERR_IO, "%s: %s", path, strerror(errno));
    else if (r == SP_OK)
        sp_path_sync_folder(where); // SQLite synced the file; its new name too
    free(real);
    unlink(tmp);
    char side[1100];
    snprintf(side, sizeof side, "%s-wal", tmp);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", tmp);
    unlink(side);
    if (lock >= 0) {
        snprintf(side, sizeof side, "%s-lock", tmp);
        unlink(side);
        close(lock);
    }
    return r;
}

// assets/ also holds the paper's characters (cartoon_man, elephant): only
// files whose scene names a part category (`extras.sp_part.category`) are
// kiosk parts. A file that does not load is left to sp_db_add_part_file,
// which refuses it with its reason.
static bool is_kiosk_part(const char* file)
{
    sp_character ch = {0};
    sp_error err = {0};
    if (sp_gltf_load(file, &ch, &err) != SP_OK) return true;
    bool part = ch.part.category[0] != 0;
    sp_character_free(&ch);
    return part;
}

// Concept sketches (sp/concept.h) for every category of the stored parts that
// has a concept, seed family `family_base` (sp_concept_seed): the designs
// visitors draw that the parts' own shapes do not cover.
static sp_result add_concepts(sp_db* db, int per_category, int family_base, sp_error* err)
{
    char** cats = NULL;
    int ncat = 0;
    sp_result r = sp_db_categories(db, &cats, &ncat, err);
    for (int k = 0; r == SP_OK && k < ncat; ++k) {
        sp_concept c = sp_concept_parse(cats[k]);
        if (c == SP_CONCEPT_COUNT) continue;
        sp_dataset ds;
        if ((r = db_dataset_one(&ds, cats[k], per_category, err)) != SP_OK) break;
        for (int i = 0; r == SP_OK && i < per_category; ++i) {
            r = sp_concept_sketch(c, sp_concept_seed(c, (uint64_t)family_base, i), &ds.samples[i].sketch, err);
            ds.samples[i].label = 0, ds.samples[i].index = i;
            ds.count = i + (r == SP_OK);
        }
        if (r == SP_OK) r = sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_SYNTHETIC, SP_DB_BY_CONCEPTS, NULL, err);
        sp_dataset_free(&ds);
    }
    sp_db_free_strings(cats, ncat);
    return r;
}

typedef struct default_ctx {
    const char* assets;
    char** names;
    int n;
    sp_db_default_desc d;
} default_ctx;

static sp_result fill_default(sp_db* db, const void* vctx, sp_error* err)
{
    const default_ctx* c = vctx;
    sp_result r = SP_OK;
    for (int i = 0; r == SP_OK && i < c->n; ++i) {
        char file[1024];
        snprintf(file, sizeof file, "%s/%s", c->assets, c->names[i]);
        if (!is_kiosk_part(file)) continue;
        sp_db_part_desc pd = {.synth_sketches = c->d.synth_per_part, .seed = (uint64_t)i + 1, .added_by = SP_DB_BY_ASSETS};
        r = sp_db_add_part_file(db, file, &pd, NULL, err);
    }
    int nconcepts = c->d.concepts_per_category == 0 ? SP_DB_CONCEPTS_DEFAULT : c->d.concepts_per_category < 0 ? 0 : c->d.concepts_per_category;
    // The concepts' seed family also seeds the designs' draws, so that one family is one draw of the whole recipe.
    int family = c->d.concept_family > 0 ? c->d.concept_family : 1;
    if (r == SP_OK && nconcepts > 0) r = add_concepts(db, nconcepts, family, err);
    if (r == SP_OK) {
        sp_dataset human;
        if ((r = sp_db_people_strokes(c->assets, c->d.quickdraw_dir, &human, NULL, err)) == SP_OK && human.count > 0)
            r = sp_db_add_sketches(db, &human, NULL, SP_DB_SOURCE_CURATED, SP_DB_BY_ASSETS, NULL, err);
        sp_dataset_free(&human);
    }
    int ndrawn = c->d.drawn_per_design == 0 ? SP_DB_DRAWN_DEFAULT : c->d.drawn_per_design;
    if (r == SP_OK && ndrawn > 0) {
        sp_dataset drawn;
        if ((r = sp_db_drawn_sketches(c->assets, ndrawn, (uint64_t)family, &drawn, NULL, err)) == SP_OK && drawn.count > 0)
            r = sp_db_add_sketches(db, &drawn, NULL, SP_DB_SOURCE_SYNTHETIC, SP_DB_BY_DRAWINGS, NULL, err);
        sp_dataset_free(&drawn);
    }
    if (r == SP_OK) {
        sp_db_train_desc td = c->d.train;
        if (!td.by) td.by = SP_DB_BY_ASSETS;
        r = sp_db_train(db, &td, NULL, err);
    }
    return r;
}

sp_result sp_db_create_default(const char* path, const char* assets_dir, const sp_db_default_desc* desc, sp_error* err)
{
    default_ctx c = {.assets = assets_dir, .d = desc ? *desc : (sp_db_default_desc){0}};
    int n = 0;
    sp_result r = sp_dir_list(assets_dir, &c.names, &n, err);
    if (r != SP_OK) return r;
    for (int i = 0; i < n; ++i) { // the parts only, in the listing's sorted order
        if (is_part_file(c.names[i])) c.names[c.n++] = c.names[i];
        else free(c.names[i]);
    }
    if (c.n == 0) {
        free(c.names);
        return sp_fail(err, SP_ERR_INVALID, "%s: no parts (*.glb, *.gltf) to build the default database from", assets_dir);
    }
    r = build_then_link(path, fill_default, &c, err);
    sp_db_free_strings(c.names, c.n);
    return r;
}

typedef struct export_ctx {
    const char* dir;
    const char* by;
    const sp_db_train_desc* train;
} export_ctx;

static sp_result fill_export(sp_db* db, const void* vctx, sp_error* err)
{
    const export_ctx* c = vctx;
    sp_result r = sp_db_import(db, c->dir, c->by, err);
    if (r == SP_OK && c->train) r = sp_db_train(db, c->train, NULL, err);
    return r;
}

sp_result sp_db_create_from_export(const char* path, const char* dir, const sp_db_train_desc* train, const char* by, sp_error* err)
{
    export_ctx c = {dir, by, train};
    return build_then_link(path, fill_export, &c, err);
}

sp_result sp_db_open_or_create_default(const char* path, const char* assets_dir, unsigned flags, sp_db** out, sp_error* err)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        sp_result r = sp_db_create_default(path, assets_dir, NULL, err);
        if (r != SP_OK && !(r == SP_ERR_BUSY && stat(path, &st) == 0)) return r;
    }
    return sp_db_open(path, flags & ~(unsigned)SP_DB_CREATE, out, err);
}
