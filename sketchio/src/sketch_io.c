// sketch_io.c: readers for stroke JSON, Quick, Draw! ndjson and SVG, the
// stroke JSON writer, and labelled sets of drawings as data. PNGs and
// folders (which may hold PNGs) are the classifier's (drawing_io.c).
#define _XOPEN_SOURCE 700 // nftw
#include "sp/sketch_io.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

// ---------------------------------------------------------------------------
// Files

static bool write_all(int fd, const void* data, size_t size)
{
    const char* p = data;
    while (size > 0) {
        ssize_t w = write(fd, p, size);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        p += w, size -= (size_t)w;
    }
    return true;
}

// Straight into what `path` names when it is not a regular file (a FIFO, a device).
static sp_result write_into(const char* path, const void* data, size_t size, sp_error* err)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) return sp_fail(err, SP_ERR_IO, "%s: cannot write (%s)", path, strerror(errno));
    bool ok = write_all(fd, data, size);
    int e = errno;
    if (close(fd) != 0 && ok) ok = false, e = errno;
    return ok ? SP_OK : sp_fail(err, SP_ERR_IO, "%s: write error (%s)", path, strerror(e));
}

char* sp_path_folder(const char* path)
{
    size_t n = strlen(path);
    char* dir = malloc(n + 2);
    if (!dir) return NULL;
    memcpy(dir, path, n + 1);
    while (n > 1 && dir[n - 1] == '/')
        dir[--n] = 0;
    char* slash = strrchr(dir, '/');
    if (!slash)
        strcpy(dir, ".");
    else
        slash[slash == dir] = 0; // "/x" is held by "/"
    return dir;
}

int sp_path_descriptor(const char* given)
{
    // Spelled as the kernel reads it: "//" and "/./" are one "/" ("$dir/stdout" with dir=/dev/).
    char path[64];
    size_t n_out = 0;
    for (const char* c = given; *c; ++c) {
        if (n_out + 1 >= sizeof path) return -1; // longer than any such name
        if (*c == '/' && n_out > 0 && path[n_out - 1] == '/') continue;
        if (*c == '.' && n_out > 0 && path[n_out - 1] == '/' && (c[1] == '/' || !c[1])) continue;
        path[n_out++] = *c;
    }
    path[n_out] = 0;
    if (!strcmp(path, "/dev/stdout")) return 1;
    if (!strcmp(path, "/dev/stderr")) return 2;
    const char* n = !strncmp(path, "/dev/fd/", 8) ? path + 8 : !strncmp(path, "/proc/self/fd/", 14) ? path + 14 : NULL;
    if (!n || !*n || strlen(n) > 6 || strspn(n, "0123456789") != strlen(n)) return -1;
    return atoi(n);
}

char* sp_path_follow_links(const char* path)
{
    char* p = strdup(path);
    for (int hop = 0; p && hop < 40; ++hop) { // 40: the kernel's own limit (ELOOP)
        struct stat st;
        // The kernel's links (/dev/stdout -> /proc/self/fd/1 -> "pipe:[N]")
        // name open files, not paths: followed no further.
        if (sp_path_descriptor(p) >= 0 || !strncmp(p, "/proc/", 6) || lstat(p, &st) != 0 || !S_ISLNK(st.st_mode)) return p;
        char to[4096];
        ssize_t n = readlink(p, to, sizeof to - 1);
        if (n < 0) return p;
        to[n] = 0;
        char* next;
        if (to[0] == '/') {
            next = strdup(to);
        } else {
            char* dir = sp_path_folder(p);
            size_t len = (dir ? strlen(dir) : 0) + strlen(to) + 2;
            next = dir ? malloc(len) : NULL;
            if (next) snprintf(next, len, "%s/%s", dir, to);
            free(dir);
        }
        free(p);
        p = next;
    }
    free(p);
    return NULL;
}

bool sp_path_sync_folder(const char* path)
{
    char* dir = sp_path_folder(path);
    if (!dir) return false;
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    free(dir);
    if (fd < 0) return false;
    bool ok = fsync(fd) == 0 || errno == EINVAL; // EINVAL: a file system that cannot sync folders
    close(fd);
    return ok;
}

char* sp_path_temp_beside(const char* target, const char* ext)
{
    static atomic_uint serial; // unique across threads too
    char* dir = sp_path_folder(target);
    if (!dir) return NULL;
    size_t n = strlen(dir) + strlen(ext) + 48;
    char* s = malloc(n);
    if (s) snprintf(s, n, "%s/.sp-%ld-%u%s", dir, (long)getpid(), atomic_fetch_add(&serial, 1u), ext);
    free(dir);
    return s;
}

sp_result sp_file_write(const char* path, const void* data, size_t size, sp_error* err)
{
    struct stat st;
    // Through a link, the file it names is replaced (a dangling one's is
    // created), so the link stays a link.
    char* real = sp_path_follow_links(path);
    if (!real) return sp_fail(err, SP_ERR_IO, "%s: cannot follow its links (a loop, or out of memory)", path);
    const char* target = real;
    int fd_out = sp_path_descriptor(target);
    if (fd_out >= 0) {
        // Through the descriptor itself, at its offset: reopening the name
        // would start a redirected file at byte 0, or replace it by rename.
        if (fd_out == 1) fflush(stdout);
        if (fd_out == 2) fflush(stderr);
        bool ok = write_all(fd_out, data, size);
        int e = errno;
        free(real);
        return ok ? SP_OK : sp_fail(err, SP_ERR_IO, "%s: write error (%s)", path, strerror(e));
    }
    bool exists = stat(target, &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        free(real);
        return sp_fail(err, SP_ERR_IO, "%s: is a folder, not a file", path);
    }
    if (exists && !S_ISREG(st.st_mode)) {
        sp_result r = write_into(target, data, size, err);
        free(real);
        return r;
    }
    char* tmp = sp_path_temp_beside(target, ".tmp");
    if (!tmp) {
        free(real);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL, 0666);
    int e = errno;
    bool ok = fd >= 0;
    if (ok && exists) fchmod(fd, st.st_mode & 07777); // a file replaced keeps its permissions
    if (ok && !write_all(fd, data, size)) ok = false, e = errno;
    // Synced before the rename: after a power cut the name then holds the
    // old file or the whole new one, never an empty one.
    if (ok && fsync(fd) != 0 && errno != EINVAL) ok = false, e = errno;
    if (fd >= 0 && close(fd) != 0 && ok) ok = false, e = errno;
    if (ok && rename(tmp, target) != 0) ok = false, e = errno;
    if (ok) sp_path_sync_folder(target); // the new name itself survives a power cut (a saved dragon's code)
    if (!ok && fd >= 0) unlink(tmp);
    free(tmp);
    free(real);
    return ok ? SP_OK : sp_fail(err, SP_ERR_IO, "%s: cannot write (%s)", path, strerror(e));
}

sp_result sp_file_write_printed(const char* path, FILE* f, char** text, size_t* len, sp_error* err)
{
    bool bad = ferror(f) != 0;
    bad = fclose(f) != 0 || bad; // fclose sets *text and *len
    sp_result r = bad ? sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path) : sp_file_write(path, *text, *len, err);
    free(*text);
    *text = NULL;
    return r;
}

// `path` opened for reading, *size its bytes: regular files only.
static sp_result open_regular(const char* path, FILE** out, long long* size, sp_error* err)
{
    *out = NULL;
    // O_NONBLOCK: opening a FIFO for reading waits for a writer, so a pipe
    // given as a file would hang before fstat could refuse it.
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return sp_fail(err, SP_ERR_IO, "%s: cannot open (%s)", path, strerror(errno));
    // Regular files only: a device (/dev/zero) or a pipe has no end to size a
    // buffer by, and reading it "whole" would fill the memory.
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return sp_fail(err, SP_ERR_IO, "%s: not a regular file", path);
    }
    int fl = fcntl(fd, F_GETFL);
    FILE* f = fl >= 0 && fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) == 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        int e = errno;
        close(fd);
        return sp_fail(err, SP_ERR_IO, "%s: cannot open (%s)", path, strerror(e));
    }
    *out = f;
    *size = (long long)st.st_size;
    return SP_OK;
}

sp_result sp_file_read(const char* path, size_t max_bytes, void** data, size_t* size, sp_error* err)
{
    *data = NULL;
    *size = 0;
    FILE* f;
    long long bytes = 0;
    sp_result r = open_regular(path, &f, &bytes, err);
    if (r != SP_OK) return r;
    if ((unsigned long long)bytes > max_bytes) {
        fclose(f);
        return sp_fail(err, SP_ERR_UNSUPPORTED, "%s: file too large (%lld bytes, at most %zu)", path, bytes, max_bytes);
    }
    size_t n = (size_t)bytes;
    char* buf = malloc(n + 1);
    if (!buf) {
        fclose(f);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory reading %zu bytes", path, n);
    }
    size_t got = fread(buf, 1, n, f);
    bool more = got == n && fgetc(f) != EOF; // grown since fstat: not the file that was sized
    bool bad = ferror(f) != 0;
    fclose(f);
    if (got != n || more || bad) {
        free(buf);
        return sp_fail(err, SP_ERR_IO, "%s: read error (%s)", path, bad ? "the system refused" : "the file changed while read");
    }
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return SP_OK;
}

sp_result sp_sketch_file_read(const char* path, char** out, size_t* len, sp_error* err)
{
    return sp_file_read(path, SP_SKETCH_MAX_FILE_BYTES, (void**)out, len, err);
}

static const char* ext_of(const char* path)
{
    const char* slash = strrchr(path, '/');
    const char* dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash)) return "";
    return dot + 1;
}

bool sp_path_ext_is(const char* path, const char* ext)
{
    return strcasecmp(ext_of(path), ext) == 0;
}

sp_result sp_dir_list(const char* dir, char*** names, int* count, sp_error* err)
{
    *names = NULL;
    *count = 0;
    DIR* d = opendir(dir);
    if (!d) return sp_fail(err, SP_ERR_IO, "%s: cannot open the folder (%s)", dir, strerror(errno));
    int n = 0, cap = 0;
    char** v = NULL;
    for (struct dirent* e; (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 32;
            char** g = realloc(v, sizeof *v * (size_t)cap);
            if (!g) goto oom;
            v = g;
        }
        if (!(v[n] = strdup(e->d_name))) goto oom;
        ++n;
    }
    closedir(d);
    if (n) qsort(v, (size_t)n, sizeof *v, sp_cmp_cstr);
    *names = v;
    *count = n;
    return SP_OK;
oom:
    closedir(d);
    sp_dir_list_free(v, n);
    return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory listing the folder", dir);
}

sp_result sp_dir_make(const char* path, sp_error* err)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST) {
        struct stat st;
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return SP_OK;
        errno = ENOTDIR;
    }
    return sp_fail(err, SP_ERR_IO, "%s: cannot create the folder (%s)", path, strerror(errno));
}

static int remove_entry(const char* path, const struct stat* st, int flag, struct FTW* ftw)
{
    (void)st, (void)flag, (void)ftw;
    remove(path);
    return 0; // on past what cannot be removed: the rest still goes
}

void sp_dir_remove_tree(const char* path)
{
    nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

void sp_dir_list_free(char** names, int count)
{
    for (int i = 0; i < count; ++i)
        free(names[i]);
    free(names);
}

// Line number of byte `at` in text (1-based), for parse messages.
static int line_of(const char* text, size_t len, const char* at)
{
    if (!at || at < text || at > text + len) return 0;
    int line = 1;
    for (const char* p = text; p < at; ++p)
        if (*p == '\n') ++line;
    return line;
}

// ---------------------------------------------------------------------------
// Stroke JSON

static bool json_number(const cJSON* j, double* v)
{
    if (!cJSON_IsNumber(j)) return false;
    *v = j->valuedouble;
    return isfinite(*v);
}

// Scratch for the stroke being read: its values are checked here first, and
// sp_sketch_add_stroke copies them, so a bad value midway leaves no half a stroke.
typedef struct stroke_scratch {
    sp_vec2* pts;
    double* ts; // NULL when the stroke has no times
} stroke_scratch;

// Room for n points, and n times when with_t; false when out of memory.
static bool scratch_resize(stroke_scratch* b, int n, bool with_t)
{
    free(b->pts);
    free(b->ts);
    b->pts = malloc(sizeof *b->pts * (size_t)(n ? n : 1));
    b->ts = with_t ? malloc(sizeof *b->ts * (size_t)(n ? n : 1)) : NULL;
    return b->pts && (!with_t || b->ts);
}

// The end of a read: the scratch is freed, and the sketch is handed over only when all of it was read.
static sp_result scratch_finish(stroke_scratch* b, sp_result rc, sp_sketch* s, sp_sketch* out)
{
    free(b->pts);
    free(b->ts);
    if (rc != SP_OK)
        sp_sketch_free(s);
    else
        *out = *s;
    return rc;
}

// One stroke into s, with every reader's message for the one way it can fail.
static sp_result add_stroke(sp_sketch* s, const sp_vec2* pts, const double* ts, int n, const char* name, sp_error* err)
{
    if (sp_sketch_add_stroke(s, pts, ts, n) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
    return SP_OK;
}

// The first byte at or after p that is not JSON white space (nor a NUL, when
// nul counts as space: some editors pad the end of a file with them).
static const char* skip_space(const char* p, const char* stop, bool nul)
{
    while (p < stop && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' || (nul && *p == 0)))
        ++p;
    return p;
}

// Where a JSON file does not parse, said so that a one-line file (a stroke
// file written by a script) can be mended: the line, the column and up to
// 16 bytes from there, anything but printable ASCII as \xNN (a UTF-8
// character cut at the 16th byte, or a UTF-16 file, printed raw bytes), and
// why when the cause is common: a NaN or infinity as Python's json writes
// them, a file that is empty or ends before the document does.
static sp_result json_error_at(const char* text, size_t len, const char* end, const char* name, sp_error* err)
{
    const char* stop = text + len;
    if (skip_space(text, stop, false) == stop)
        return sp_fail(err, SP_ERR_PARSE, "%s: the file is empty (no JSON document)", name);
    if (!end || end < text || end > stop) return sp_fail(err, SP_ERR_PARSE, "%s: malformed JSON", name);
    const char* bol = end;
    while (bol > text && bol[-1] != '\n')
        --bol;
    char near[16 * 4 + 1];
    size_t n = 0, taken = 0;
    for (const char* q = end; q < stop && taken < 16 && *q != '\n' && *q != '\r'; ++q, ++taken) {
        unsigned char c = (unsigned char)*q;
        n += (size_t)(c >= 0x20 && c < 0x7f ? snprintf(near + n, sizeof near - n, "%c", c)
                                            : snprintf(near + n, sizeof near - n, "\\x%02X", c));
    }
    size_t word = 0; // the bare word there: nan, inf, infinity (any case, a sign before)
    while (end + word < stop && (isalpha((unsigned char)end[word]) || (word == 0 && (end[0] == '-' || end[0] == '+'))))
        ++word;
    const char* w = end + (word && (end[0] == '-' || end[0] == '+'));
    size_t wl = word - (size_t)(w - end);
    bool not_number =
        (wl == 3 && (!strncasecmp(w, "nan", 3) || !strncasecmp(w, "inf", 3))) || (wl == 8 && !strncasecmp(w, "infinity", 8));
    bool cut = skip_space(end, stop, false) >= stop || end + 1 >= stop;
    return sp_fail(err, SP_ERR_PARSE, "%s: malformed JSON near line %d, column %d%s%s%s%s", name, line_of(text, len, end),
                   (int)(end - bol) + 1, n ? ", at '" : "", n ? near : "", n ? "'" : "",
                   not_number ? " (NaN and infinity are not JSON numbers)"
                   : cut      ? " (the file ends before the document does: cut short?)"
                              : "");
}

sp_result sp_json_document_end(const char* text, size_t len, bool parsed, const char* end, const char* name, sp_error* err)
{
    if (!parsed) return json_error_at(text, len, end, name, err);
    // Anything but white space after the document means the file is not what it seems (two files joined, a bad edit).
    if (end) end = skip_space(end, text + len, true);
    if (end && end < text + len)
        return sp_fail(err, SP_ERR_PARSE, "%s: text after the JSON document, line %d", name, line_of(text, len, end));
    return SP_OK;
}

sp_json_shape sp_json_measure(const char* text, size_t len)
{
    sp_json_shape m = {0, 1};
    size_t depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < len; ++i) {
        char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == ',') {
            ++m.values;
        } else if (c == '[' || c == '{') {
            ++m.values;
            if (++depth > m.depth) m.depth = depth;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return m;
}

sp_result sp_json_values_within(const char* text, size_t len, size_t max_values, const char* name, sp_error* err)
{
    if (sp_json_measure(text, len).values > max_values)
        return sp_fail(err, SP_ERR_INVALID, "%s: more than %zu JSON values (a stroke file holds at most %d points)", name,
                       max_values, SP_SKETCH_MAX_POINTS);
    return SP_OK;
}

bool sp_text_has_control(const char* s)
{
    for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p; ++p)
        if (*p < 0x20 || *p == 0x7f) return true;
    return false;
}

const char* sp_text_printable(const char* s, char* buf, size_t cap)
{
    size_t at = 0;
    const unsigned char* p = (const unsigned char*)(s ? s : "");
    for (; *p; ++p) {
        char one[8];
        int n = *p == '\n'                  ? snprintf(one, sizeof one, "\\n")
                : *p == '\r'                ? snprintf(one, sizeof one, "\\r")
                : *p == '\t'                ? snprintf(one, sizeof one, "\\t")
                : *p == '\\'                ? snprintf(one, sizeof one, "\\\\")
                : (*p < 0x20 || *p == 0x7f) ? snprintf(one, sizeof one, "\\x%02x", *p)
                                            : snprintf(one, sizeof one, "%c", *p);
        if (at + (size_t)n + 4 > cap) break; // room for "..." and the NUL
        memcpy(buf + at, one, (size_t)n);
        at += (size_t)n;
    }
    if (*p && cap >= 4) {
        memcpy(buf + at, "...", 3);
        at += 3;
    }
    buf[at < cap ? at : cap - 1] = 0;
    return buf;
}

static int key_order(const void* a, const void* b)
{
    return strcmp(*(const char* const*)a, *(const char* const*)b);
}

// The first key that obj holds twice, else NULL (also for anything but an
// object); *no_memory tells a failed allocation from no key twice.
static const char* json_key_twice(const cJSON* obj, bool* no_memory)
{
    if (no_memory) *no_memory = false;
    if (!cJSON_IsObject(obj)) return NULL;
    int n = cJSON_GetArraySize(obj);
    if (n < 2) return NULL;
    // Sorted, so that an object of a million keys is checked in n log n, not n^2.
    const char** keys = malloc(sizeof *keys * (size_t)n);
    if (!keys) {
        if (no_memory) *no_memory = true;
        return NULL;
    }
    int k = 0;
    for (const cJSON* it = obj->child; it && k < n; it = it->next)
        keys[k++] = it->string ? it->string : "";
    qsort(keys, (size_t)k, sizeof *keys, key_order);
    const char* twice = NULL;
    for (int i = 1; i < k && !twice; ++i)
        if (!strcmp(keys[i - 1], keys[i])) twice = keys[i];
    free(keys);
    return twice;
}

// A key given twice in the stroke file's object or in one of its strokes: one
// line naming it (cJSON keeps both and lookups find the first, so the second
// was silently dropped: `"strokes": [], "strokes": [...]` read as no strokes).
static sp_result keys_once(const cJSON* root, const char* name, sp_error* err)
{
    bool oom = false;
    const char* twice = json_key_twice(root, &oom);
    char shown[96]; // a key is the file's text: \n in it is a newline by now
    if (twice)
        return sp_fail(err, SP_ERR_INVALID, "%s: key \"%s\" given twice", name, sp_text_printable(twice, shown, sizeof shown));
    const cJSON* strokes = cJSON_GetObjectItemCaseSensitive(root, "strokes");
    int si = 0;
    const cJSON* st;
    if (cJSON_IsArray(strokes)) cJSON_ArrayForEach(st, strokes)
        {
            if (!oom && (twice = json_key_twice(st, &oom)) != NULL)
                return sp_fail(err, SP_ERR_INVALID, "%s: stroke %d: key \"%s\" given twice", name, si,
                               sp_text_printable(twice, shown, sizeof shown));
            ++si;
        }
    if (oom) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
    return SP_OK;
}

// The first key held twice by obj or any object within it (depth-first), else NULL.
static const char* json_key_twice_within(const cJSON* obj, bool* no_memory)
{
    const char* twice = json_key_twice(obj, no_memory);
    for (const cJSON* it = obj ? obj->child : NULL; it && !twice && !*no_memory; it = it->next)
        if (cJSON_IsObject(it) || cJSON_IsArray(it)) twice = json_key_twice_within(it, no_memory);
    return twice;
}

// One JSON document parsed from text: nothing but white space after it,
// and no NUL byte in it (inside a key, "ca\0nvas", cJSON cut the key short
// and a stroke file's canvas was dropped silently). *doc: NULL on failure.
static sp_result parse_document(const char* text, size_t len, const char* name, cJSON** doc, sp_error* err)
{
    const char* end = NULL;
    *doc = cJSON_ParseWithLengthOpts(text, len, &end, false);
    sp_result r = sp_json_document_end(text, len, *doc != NULL, end, name, err);
    const char* nul = r == SP_OK ? memchr(text, 0, (size_t)(end - text)) : NULL;
    if (nul)
        r = sp_fail(err, SP_ERR_PARSE, "%s: a NUL byte in the JSON document, line %d (not a text file?)", name,
                    line_of(text, len, nul));
    if (r != SP_OK) {
        cJSON_Delete(*doc);
        *doc = NULL;
    }
    return r;
}

// parse_document, and no object anywhere holding a key twice. *doc: NULL on failure.
static sp_result parse_keys_once(const char* text, size_t len, const char* name, cJSON** doc, sp_error* err)
{
    sp_result r = parse_document(text, len, name, doc, err);
    bool oom = false;
    const char* twice = r == SP_OK ? json_key_twice_within(*doc, &oom) : NULL;
    char shown[96];
    if (twice)
        r = sp_fail(err, SP_ERR_INVALID, "%s: key \"%s\" given twice", name, sp_text_printable(twice, shown, sizeof shown));
    else if (oom)
        r = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
    if (r != SP_OK) {
        cJSON_Delete(*doc);
        *doc = NULL;
    }
    return r;
}

sp_result sp_json_document_check(const char* text, size_t len, size_t max_values, const char* name, sp_error* err)
{
    if (max_values > 0 && sp_json_measure(text, len).values > max_values)
        return sp_fail(err, SP_ERR_INVALID, "%s: more than %zu JSON values", name, max_values);
    cJSON* doc;
    sp_result r = parse_keys_once(text, len, name, &doc, err);
    cJSON_Delete(doc);
    return r;
}

sp_result sp_sketch_parse_json(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_result vr = sp_json_values_within(text, len, SP_SKETCH_MAX_JSON_VALUES, name, err);
    if (vr != SP_OK) return vr;
    cJSON* root;
    sp_result rc = parse_document(text, len, name, &root, err);
    if (rc != SP_OK) return rc;
    sp_sketch s = {0};
    stroke_scratch b = {0};
    const cJSON* fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
    const cJSON* ver = cJSON_GetObjectItemCaseSensitive(root, "version");
    const cJSON* canvas = cJSON_GetObjectItemCaseSensitive(root, "canvas");
    const cJSON* strokes = cJSON_GetObjectItemCaseSensitive(root, "strokes");
    if (!cJSON_IsObject(root)) {
        rc = sp_fail(err, SP_ERR_PARSE, "%s: a stroke file is a JSON object", name);
        goto done;
    }
    if ((rc = keys_once(root, name, err)) != SP_OK) goto done;
    if (!cJSON_IsString(fmt) || strcmp(fmt->valuestring, "sketchpose-strokes") != 0) {
        rc = sp_fail(err, SP_ERR_PARSE, "%s: \"format\" must be \"sketchpose-strokes\"", name);
        goto done;
    }
    double vd = 0.0;
    if (!json_number(ver, &vd)) {
        rc = sp_fail(err, SP_ERR_PARSE, "%s: \"version\" missing or not a number", name);
        goto done;
    }
    if (vd != 1.0) {
        rc = sp_fail(err, SP_ERR_UNSUPPORTED, "%s: stroke file version %g, this build reads version 1", name, vd);
        goto done;
    }
    if (canvas) {
        double w = 0, h = 0;
        if (!cJSON_IsArray(canvas) || cJSON_GetArraySize(canvas) != 2 || !json_number(cJSON_GetArrayItem(canvas, 0), &w) ||
            !json_number(cJSON_GetArrayItem(canvas, 1), &h) || w < 0 || h < 0 || w > SP_SKETCH_CANVAS_MAX ||
            h > SP_SKETCH_CANVAS_MAX) {
            rc = sp_fail(err, SP_ERR_INVALID, "%s: \"canvas\" must be [width, height] with 0 <= sizes <= 1e6", name);
            goto done;
        }
        // [0, 0] is the writer's "no canvas" (as a file without one); a side
        // under a pixel otherwise is no canvas either, and the commands put
        // their default 640 x 480 in its place without a word.
        if (!(w == 0 && h == 0) && (w < 1 || h < 1)) {
            rc = sp_fail(err, SP_ERR_INVALID,
                         "%s: \"canvas\" [%g, %g] has a side under 1 px (give [width, height] of 1 to 1e6 px, or no canvas)",
                         name, w, h);
            goto done;
        }
        s.canvas_w = w;
        s.canvas_h = h;
    }
    if (!cJSON_IsArray(strokes)) {
        rc = sp_fail(err, SP_ERR_PARSE, "%s: \"strokes\" missing or not an array", name);
        goto done;
    }
    int total = 0, si = 0;
    const cJSON* st;
    cJSON_ArrayForEach(st, strokes)
    {
        const cJSON* p = cJSON_GetObjectItemCaseSensitive(st, "points");
        const cJSON* t = cJSON_GetObjectItemCaseSensitive(st, "t");
        if (!cJSON_IsObject(st) || !cJSON_IsArray(p)) {
            rc = sp_fail(err, SP_ERR_PARSE, "%s: stroke %d has no \"points\" array", name, si);
            goto done;
        }
        int n = cJSON_GetArraySize(p);
        if (n > SP_SKETCH_MAX_POINTS - total) {
            rc = sp_fail(err, SP_ERR_UNSUPPORTED, "%s: more than %d points", name, SP_SKETCH_MAX_POINTS);
            goto done;
        }
        total += n;
        if (t && !cJSON_IsNull(t) && (!cJSON_IsArray(t) || cJSON_GetArraySize(t) != n)) {
            rc = sp_fail(err, SP_ERR_INVALID, "%s: stroke %d: \"t\" must be an array as long as \"points\"", name, si);
            goto done;
        }
        bool has_t = t && cJSON_IsArray(t);
        if (!scratch_resize(&b, n, has_t)) {
            rc = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
            goto done;
        }
        int k = 0;
        const cJSON* q;
        cJSON_ArrayForEach(q, p)
        {
            double x, y;
            if (!cJSON_IsArray(q) || cJSON_GetArraySize(q) != 2 || !cJSON_IsNumber(cJSON_GetArrayItem(q, 0)) ||
                !cJSON_IsNumber(cJSON_GetArrayItem(q, 1))) {
                rc = sp_fail(err, SP_ERR_PARSE, "%s: stroke %d point %d is not [x, y]", name, si, k);
                goto done;
            }
            if (!json_number(cJSON_GetArrayItem(q, 0), &x) || !json_number(cJSON_GetArrayItem(q, 1), &y) ||
                fabs(x) > SP_SKETCH_COORD_MAX || fabs(y) > SP_SKETCH_COORD_MAX) {
                rc = sp_fail(err, SP_ERR_INVALID, "%s: stroke %d point %d is not finite (or beyond 1e9)", name, si, k);
                goto done;
            }
            b.pts[k++] = (sp_vec2){x, y};
        }
        if (has_t) {
            k = 0;
            cJSON_ArrayForEach(q, t)
            {
                if (!json_number(q, &b.ts[k])) {
                    rc = sp_fail(err, SP_ERR_INVALID, "%s: stroke %d time %d is not a finite number", name, si, k);
                    goto done;
                }
                ++k;
            }
        }
        if ((rc = add_stroke(&s, b.pts, b.ts, n, name, err)) != SP_OK) goto done;
        ++si;
    }
done:
    cJSON_Delete(root);
    return scratch_finish(&b, rc, &s, out);
}

sp_result sp_sketch_read_json(const char* path, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    char* text;
    size_t len;
    sp_result rc = sp_sketch_file_read(path, &text, &len, err);
    if (rc != SP_OK) return rc;
    rc = sp_sketch_parse_json(text, len, path, out, err);
    free(text);
    return rc;
}

char* sp_sketch_to_json(const sp_sketch* s, int digits)
{
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f) return NULL;
    bool all_t = s->stroke_count > 0;
    for (int i = 0; i < s->stroke_count; ++i)
        if (!s->strokes[i].t) all_t = false;
    const int d = digits;
    fprintf(f, "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [%.*g, %.*g], \"strokes\": [", d, s->canvas_w, d,
            s->canvas_h);
    for (int i = 0; i < s->stroke_count; ++i) {
        const sp_stroke* st = &s->strokes[i];
        fprintf(f, "%s\n  {\"points\": [", i ? "," : "");
        for (int j = 0; j < st->count; ++j)
            fprintf(f, "%s[%.*g, %.*g]", j ? ", " : "", d, st->points[j].x, d, st->points[j].y);
        fprintf(f, "]");
        if (all_t) {
            fprintf(f, ", \"t\": [");
            for (int j = 0; j < st->count; ++j)
                fprintf(f, "%s%.*g", j ? ", " : "", d, st->t[j]);
            fprintf(f, "]");
        }
        fprintf(f, "}");
    }
    fprintf(f, "%s]}\n", s->stroke_count ? "\n" : "");
    bool bad = ferror(f) != 0;
    bad = fclose(f) != 0 || bad; // fclose sets text and len
    if (bad) {
        free(text);
        return NULL;
    }
    return text;
}

sp_result sp_sketch_write_json(const char* path, const sp_sketch* s, sp_error* err)
{
    if (!sp_sketch_is_valid(s)) return sp_fail(err, SP_ERR_INVALID, "%s: sketch has non-finite values", path);
    // Made in memory and written whole (sp_file_write): a failed write leaves no half a file.
    char* text = sp_sketch_to_json(s, SP_SKETCH_JSON_EXACT);
    if (!text) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    sp_result r = sp_file_write(path, text, strlen(text), err);
    free(text);
    return r;
}

// ---------------------------------------------------------------------------
// Dataset

int sp_dataset_add_category(sp_dataset* ds, const char* name)
{
    for (int i = 0; i < ds->category_count; ++i)
        if (!strcmp(ds->categories[i], name)) return i;
    char** grown = realloc(ds->categories, sizeof(char*) * (size_t)(ds->category_count + 1));
    if (!grown) return -1;
    ds->categories = grown;
    char* copy = strdup(name);
    if (!copy) return -1;
    ds->categories[ds->category_count] = copy;
    return ds->category_count++;
}

sp_result sp_dataset_reserve(sp_dataset* ds, int n)
{
    if (n < 0 || ds->count < 0 || n > INT_MAX - ds->count) return SP_ERR_NO_MEMORY;
    // A set built before `capacity` was kept (0) holds exactly `count`.
    if (ds->count + n <= ds->capacity) return SP_OK;
    long long cap = ds->capacity > 0 ? ds->capacity : 8;
    while (cap < (long long)ds->count + n)
        cap *= 2;
    if (cap > INT_MAX) cap = (long long)ds->count + n;
    sp_sample* grown = realloc(ds->samples, sizeof(sp_sample) * (size_t)cap);
    if (!grown) return SP_ERR_NO_MEMORY;
    ds->samples = grown;
    ds->capacity = (int)cap;
    return SP_OK;
}

sp_result sp_dataset_add_sample(sp_dataset* ds, sp_sample* smp)
{
    if (sp_dataset_reserve(ds, 1) != SP_OK) return SP_ERR_NO_MEMORY;
    int n = ds->count;
    int idx = 0;
    for (int i = 0; i < n; ++i)
        if (ds->samples[i].label == smp->label) ++idx;
    smp->index = idx;
    ds->samples[ds->count++] = *smp;
    return SP_OK;
}

void sp_raster_free(sp_raster* r)
{
    if (!r) return;
    free(r->pixels);
    memset(r, 0, sizeof *r);
}

const char* sp_sketch_extent_problem(const sp_sketch* s)
{
    bool any = false;
    sp_vec2 first = {0, 0};
    for (int i = 0; i < s->stroke_count; ++i)
        for (int k = 0; k < s->strokes[i].count; ++k) {
            sp_vec2 p = s->strokes[i].points[k];
            if (!any) first = p, any = true;
            if (p.x != first.x || p.y != first.y) return NULL;
        }
    return any ? "the drawing has no extent: all its points are at one place" : "the drawing has no points";
}

const char* sp_raster_ink_problem(const sp_raster* r)
{
    size_t n = r->pixels && r->w > 0 && r->h > 0 ? (size_t)r->w * (size_t)r->h : 0;
    for (size_t i = 0; i < n; ++i)
        if (r->pixels[i] < SP_RASTER_INK_BELOW) return NULL;
    return "the picture has no dark lines (a blank page?)";
}

int sp_dataset_drop_no_extent(sp_dataset* ds)
{
    int kept = 0, dropped = 0;
    for (int i = 0; i < ds->count; ++i) {
        sp_sample* smp = &ds->samples[i];
        if (smp->raster.pixels ? sp_raster_ink_problem(&smp->raster) != NULL : sp_sketch_extent_problem(&smp->sketch) != NULL) {
            sp_sketch_free(&smp->sketch);
            sp_raster_free(&smp->raster);
            ++dropped;
            continue;
        }
        ds->samples[kept++] = *smp;
    }
    ds->count = kept;
    // Folds take a drawing's index within its category: renumbered, as the set was read.
    int* next = dropped ? calloc((size_t)ds->category_count + 1, sizeof *next) : NULL;
    for (int i = 0; next && i < kept; ++i) {
        int l = ds->samples[i].label;
        if (l >= 0 && l < ds->category_count) ds->samples[i].index = next[l]++;
    }
    free(next); // out of memory: the indices keep their gaps, which folds take as they come
    return dropped;
}

void sp_dataset_free(sp_dataset* ds)
{
    if (!ds) return;
    for (int i = 0; i < ds->count; ++i) {
        sp_sketch_free(&ds->samples[i].sketch);
        sp_raster_free(&ds->samples[i].raster);
    }
    for (int i = 0; i < ds->category_count; ++i)
        free(ds->categories[i]);
    free(ds->samples);
    free(ds->categories);
    memset(ds, 0, sizeof *ds);
}

// ---------------------------------------------------------------------------
// Quick, Draw! ndjson

// Parses one drawing: [[[x...],[y...](,[t...])], ...].
static sp_result ndjson_drawing(const cJSON* drawing, const char* name, int line, sp_sketch* out, sp_error* err)
{
    sp_sketch s = {0};
    stroke_scratch b = {0};
    sp_result rc = SP_OK;
    int total = 0, si = 0;
    const cJSON* st;
    cJSON_ArrayForEach(st, drawing)
    {
        const cJSON* xs = cJSON_GetArrayItem(st, 0);
        const cJSON* ys = cJSON_GetArrayItem(st, 1);
        const cJSON* tt = cJSON_GetArrayItem(st, 2);
        int n = cJSON_GetArraySize(xs);
        if (!cJSON_IsArray(st) || !cJSON_IsArray(xs) || !cJSON_IsArray(ys) || cJSON_GetArraySize(ys) != n ||
            (tt && (!cJSON_IsArray(tt) || cJSON_GetArraySize(tt) != n))) {
            rc = sp_fail(err, SP_ERR_PARSE, "%s:%d: stroke %d is not [[x...], [y...]] of equal lengths", name, line, si);
            goto done;
        }
        if (n > SP_SKETCH_MAX_POINTS - total) {
            rc = sp_fail(err, SP_ERR_UNSUPPORTED, "%s:%d: more than %d points in one drawing", name, line, SP_SKETCH_MAX_POINTS);
            goto done;
        }
        total += n;
        if (!scratch_resize(&b, n, tt != NULL)) {
            rc = sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
            goto done;
        }
        const cJSON* x = xs->child;
        const cJSON* y = ys->child;
        const cJSON* t = tt ? tt->child : NULL;
        for (int k = 0; k < n; ++k, x = x->next, y = y->next) {
            double vx, vy;
            if (!json_number(x, &vx) || !json_number(y, &vy) || fabs(vx) > SP_SKETCH_COORD_MAX ||
                fabs(vy) > SP_SKETCH_COORD_MAX) {
                rc = sp_fail(err, SP_ERR_INVALID, "%s:%d: stroke %d point %d is not a finite number pair", name, line, si, k);
                goto done;
            }
            b.pts[k] = (sp_vec2){vx, vy};
            if (t) {
                if (!json_number(t, &b.ts[k])) {
                    rc = sp_fail(err, SP_ERR_INVALID, "%s:%d: stroke %d time %d is not finite", name, line, si, k);
                    goto done;
                }
                t = t->next;
            }
        }
        if ((rc = add_stroke(&s, b.pts, b.ts, n, name, err)) != SP_OK) goto done;
        ++si;
    }
done:
    return scratch_finish(&b, rc, &s, out);
}

sp_result sp_dataset_parse_ndjson(sp_dataset* ds, const char* text, size_t len, const char* name, int label, sp_error* err)
{
    size_t at = 0;
    int line = 0;
    while (at < len) {
        size_t e = at;
        while (e < len && text[e] != '\n')
            ++e;
        ++line;
        size_t b = at;
        at = e + 1;
        while (b < e && isspace((unsigned char)text[b]))
            ++b;
        if (b == e) continue; // blank line
        // Each line is a JSON document as the stroke file is: its values
        // counted before it is parsed (a 60 MB line of small values took
        // 2.4 GB), one document, no NUL, each key once (an outside review).
        char lname[1100];
        snprintf(lname, sizeof lname, "%s:%d", name, line);
        cJSON* root = NULL;
        sp_result vr = sp_json_values_within(text + b, e - b, SP_SKETCH_MAX_JSON_VALUES, lname, err);
        if (vr != SP_OK || (vr = parse_keys_once(text + b, e - b, lname, &root, err)) != SP_OK) return vr;
        const cJSON* drawing = cJSON_GetObjectItemCaseSensitive(root, "drawing");
        if (!cJSON_IsObject(root) || !cJSON_IsArray(drawing)) {
            cJSON_Delete(root);
            return sp_fail(err, SP_ERR_PARSE, "%s:%d: no \"drawing\" array", name, line);
        }
        sp_sample smp = {.label = label};
        sp_result rc = ndjson_drawing(drawing, name, line, &smp.sketch, err);
        cJSON_Delete(root);
        if (rc != SP_OK) return rc;
        smp.sketch.canvas_w = smp.sketch.canvas_h = 256.0; // Quick, Draw! simplified drawings are 0..255
        if (sp_dataset_add_sample(ds, &smp) != SP_OK) {
            sp_sketch_free(&smp.sketch);
            return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
        }
    }
    return SP_OK;
}

sp_result sp_dataset_read_ndjson(sp_dataset* ds, const char* path, int label, sp_error* err)
{
    char* text;
    size_t len;
    sp_result rc = sp_sketch_file_read(path, &text, &len, err);
    if (rc != SP_OK) return rc;
    rc = sp_dataset_parse_ndjson(ds, text, len, path, label, err);
    free(text);
    return rc;
}

// ---------------------------------------------------------------------------
// SVG

typedef struct affine {
    double a, b, c, d, e, f; // x' = a x + c y + e, y' = b x + d y + f (SVG matrix order)
} affine;

static const affine k_identity = {1, 0, 0, 1, 0, 0};

static affine affine_mul(affine m, affine n) // m * n (apply n first)
{
    return (affine){m.a * n.a + m.c * n.b, m.b * n.a + m.d * n.b,       m.a * n.c + m.c * n.d,
                    m.b * n.c + m.d * n.d, m.a * n.e + m.c * n.f + m.e, m.b * n.e + m.d * n.f + m.f};
}

static sp_vec2 affine_apply(affine m, double x, double y)
{
    return (sp_vec2){m.a * x + m.c * y + m.e, m.b * x + m.d * y + m.f};
}

typedef struct svg_ctx {
    const char* name;
    sp_error* err;
    sp_sketch* out;
    sp_vec2* pts; // current stroke, in document coordinates (transformed)
    int n, cap, total;
    affine m;
} svg_ctx;

static sp_result svg_point(svg_ctx* c, double x, double y)
{
    if (!isfinite(x) || !isfinite(y) || fabs(x) > SP_SKETCH_COORD_MAX || fabs(y) > SP_SKETCH_COORD_MAX)
        return sp_fail(c->err, SP_ERR_INVALID, "%s: coordinate out of range", c->name);
    if (c->total >= SP_SKETCH_MAX_POINTS)
        return sp_fail(c->err, SP_ERR_UNSUPPORTED, "%s: more than %d points after flattening", c->name, SP_SKETCH_MAX_POINTS);
    if (c->n == c->cap) {
        int cap = c->cap ? c->cap * 2 : 64;
        sp_vec2* g = realloc(c->pts, sizeof *g * (size_t)cap);
        if (!g) return sp_fail(c->err, SP_ERR_NO_MEMORY, "%s: out of memory", c->name);
        c->pts = g;
        c->cap = cap;
    }
    sp_vec2 p = affine_apply(c->m, x, y);
    if (!sp_v2_is_valid(p) || fabs(p.x) > SP_SKETCH_COORD_MAX || fabs(p.y) > SP_SKETCH_COORD_MAX)
        return sp_fail(c->err, SP_ERR_INVALID, "%s: transformed coordinate out of range", c->name);
    c->pts[c->n++] = p;
    ++c->total;
    return SP_OK;
}

static sp_result svg_flush(svg_ctx* c)
{
    sp_result rc = c->n > 0 ? add_stroke(c->out, c->pts, NULL, c->n, c->name, c->err) : SP_OK;
    c->n = 0;
    return rc;
}

// Reads one number at *p (skipping separators). Refuses inf/nan/hex, which strtod would take.
static bool svg_number(const char** p, const char* end, double* v)
{
    const char* s = *p;
    while (s < end && (isspace((unsigned char)*s) || *s == ','))
        ++s;
    if (s >= end) return false;
    char buf[64];
    size_t k = 0;
    const char* q = s;
    if (q < end && (*q == '+' || *q == '-')) buf[k++] = *q++;
    bool digits = false, dot = false;
    while (q < end) {
        if (isdigit((unsigned char)*q))
            digits = true;
        else if (*q == '.' && !dot)
            dot = true;
        else
            break;
        // A number longer than the buffer: digits past the point only lose
        // precision and are read over; any other is refused (it was cut in
        // two, and the rest read as the next number).
        if (k < sizeof buf - 8)
            buf[k++] = *q;
        else if (!dot || *q == '.')
            return false;
        ++q;
    }
    if (!digits) return false;
    if (q < end && (*q == 'e' || *q == 'E')) {
        const char* r = q + 1;
        char eb[8];
        size_t ek = 0;
        eb[ek++] = 'e';
        if (r < end && (*r == '+' || *r == '-')) eb[ek++] = *r++;
        bool ed = false;
        while (r < end && isdigit((unsigned char)*r) && ek < sizeof eb - 1) {
            eb[ek++] = *r++;
            ed = true;
        }
        if (ed && r < end && isdigit((unsigned char)*r)) return false; // an exponent of more digits than it holds
        if (ed) {
            memcpy(buf + k, eb, ek);
            k += ek;
            q = r;
        }
    }
    buf[k] = '\0';
    *v = strtod(buf, NULL);
    if (!isfinite(*v)) return false;
    *p = q;
    return true;
}

static bool svg_numbers(const char** p, const char* end, double* v, int n)
{
    for (int i = 0; i < n; ++i)
        if (!svg_number(p, end, &v[i])) return false;
    return true;
}

// Flattening: fixed segments per curve, enough for sketches drawn at <= 1000 px.
enum { SVG_CURVE_SEGMENTS = 12 };

// An arc flag is one character, '0' or '1' (SVG 1.1 path grammar): "011 1" is two flags and a number.
static bool svg_flag(const char** p, const char* end, bool* f)
{
    const char* s = *p;
    while (s < end && (isspace((unsigned char)*s) || *s == ','))
        ++s;
    if (s >= end || (*s != '0' && *s != '1')) return false;
    *f = *s == '1';
    *p = s + 1;
    return true;
}

// Elliptical arc from (x1,y1); a = rx, ry, x-axis rotation (degrees), x2, y2. SVG 1.1
// implementation notes F.6.5-F.6.6, worked in units of the radii so that a huge radius
// cannot overflow the squares. Sampled at the curves' density: a circle drawn as arcs
// gets as many points as one drawn as four Béziers.
static sp_result svg_arc(svg_ctx* c, double x1, double y1, const double a[5], bool large, bool sweep)
{
    double rx = fabs(a[0]), ry = fabs(a[1]), x2 = a[3], y2 = a[4];
    if (x1 == x2 && y1 == y2) return SP_OK;              // F.6.2: no arc at all
    if (rx == 0 || ry == 0) return svg_point(c, x2, y2); // F.6.2: a straight line
    double phi = a[2] * M_PI / 180.0, cs = cos(phi), sn = sin(phi);
    double hx = (x1 - x2) / 2, hy = (y1 - y2) / 2;
    double X = (cs * hx + sn * hy) / rx, Y = (-sn * hx + cs * hy) / ry; // x1', y1' over the radii
    double l = X * X + Y * Y, k = 0;
    if (!(l > 0) || !isfinite(l)) return svg_point(c, x2, y2);
    if (l > 1) { // radii too small for the endpoints: scaled up until they just fit (F.6.6)
        double s = sqrt(l);
        rx *= s, ry *= s, X /= s, Y /= s;
    } else
        k = (large != sweep ? 1 : -1) * sqrt((1 - l) / l);
    // Centre (k Y, -k X) in radius units; u and v run from it to the two endpoints.
    double ux = X - k * Y, uy = Y + k * X, vx = -X - k * Y, vy = -Y + k * X;
    double t0 = atan2(uy, ux), dt = atan2(ux * vy - uy * vx, ux * vx + uy * vy);
    if (!sweep && dt > 0)
        dt -= 2 * M_PI;
    else if (sweep && dt < 0)
        dt += 2 * M_PI;
    if (!isfinite(k) || !isfinite(dt)) return svg_point(c, x2, y2);
    double ccx = cs * k * rx * Y + sn * k * ry * X + (x1 + x2) / 2;
    double ccy = sn * k * rx * Y - cs * k * ry * X + (y1 + y2) / 2;
    int n = (int)ceil(fabs(dt) / (M_PI / 2) * SVG_CURVE_SEGMENTS);
    if (n < 1) n = 1;
    for (int i = 1; i < n; ++i) {
        double t = t0 + dt * i / n, ex = rx * cos(t), ey = ry * sin(t);
        sp_result rc = svg_point(c, cs * ex - sn * ey + ccx, sn * ex + cs * ey + ccy);
        if (rc != SP_OK) return rc;
    }
    return svg_point(c, x2, y2); // exactly the endpoint, which the next command starts from
}

// The end of a path's subpath: a stroke, unless it is a lone moveto ("M 5 5
// M 100 100 L ..."), which SVG does not draw (it was a stroke of 1 point,
// and the file was refused as one).
static sp_result svg_subpath_end(svg_ctx* c)
{
    if (c->n == 1) {
        c->n = 0;
        --c->total;
    }
    return svg_flush(c);
}

static sp_result svg_path(svg_ctx* c, const char* d, const char* end)
{
    const char* p = d;
    double cx = 0, cy = 0, sx = 0, sy = 0, lcx = 0, lcy = 0; // current, subpath start, last control
    char cmd = 0, prev = 0;
    sp_result rc;
    for (;;) {
        while (p < end && (isspace((unsigned char)*p) || *p == ','))
            ++p;
        if (p >= end) break;
        if (isalpha((unsigned char)*p))
            cmd = *p++;
        else if (!cmd)
            return sp_fail(c->err, SP_ERR_PARSE, "%s: path data must start with a command", c->name);
        else if (cmd == 'M')
            cmd = 'L'; // implicit lineto after moveto
        else if (cmd == 'm')
            cmd = 'l';
        bool rel = islower((unsigned char)cmd) != 0;
        double ox = rel ? cx : 0, oy = rel ? cy : 0, v[7];
        switch (toupper((unsigned char)cmd)) {
        case 'M':
            if (!svg_numbers(&p, end, v, 2)) goto bad;
            if ((rc = svg_subpath_end(c)) != SP_OK) return rc;
            cx = sx = ox + v[0];
            cy = sy = oy + v[1];
            if ((rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            break;
        case 'L':
            if (!svg_numbers(&p, end, v, 2)) goto bad;
            cx = ox + v[0];
            cy = oy + v[1];
            if ((rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            break;
        case 'H':
            if (!svg_numbers(&p, end, v, 1)) goto bad;
            cx = ox + v[0];
            if ((rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            break;
        case 'V':
            if (!svg_numbers(&p, end, v, 1)) goto bad;
            cy = oy + v[0];
            if ((rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            break;
        case 'C':
        case 'S': {
            double x1, y1, x2, y2, x, y;
            if (toupper((unsigned char)cmd) == 'C') {
                if (!svg_numbers(&p, end, v, 6)) goto bad;
                x1 = ox + v[0], y1 = oy + v[1], x2 = ox + v[2], y2 = oy + v[3], x = ox + v[4], y = oy + v[5];
            } else {
                if (!svg_numbers(&p, end, v, 4)) goto bad;
                bool refl = strchr("CcSs", prev) != NULL;
                x1 = refl ? 2 * cx - lcx : cx, y1 = refl ? 2 * cy - lcy : cy;
                x2 = ox + v[0], y2 = oy + v[1], x = ox + v[2], y = oy + v[3];
            }
            if (c->n == 0 && (rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            for (int i = 1; i <= SVG_CURVE_SEGMENTS; ++i) {
                double t = (double)i / SVG_CURVE_SEGMENTS, u = 1 - t;
                double bx = u * u * u * cx + 3 * u * u * t * x1 + 3 * u * t * t * x2 + t * t * t * x;
                double by = u * u * u * cy + 3 * u * u * t * y1 + 3 * u * t * t * y2 + t * t * t * y;
                if ((rc = svg_point(c, bx, by)) != SP_OK) return rc;
            }
            lcx = x2, lcy = y2, cx = x, cy = y;
            break;
        }
        case 'Q':
        case 'T': {
            double x1, y1, x, y;
            if (toupper((unsigned char)cmd) == 'Q') {
                if (!svg_numbers(&p, end, v, 4)) goto bad;
                x1 = ox + v[0], y1 = oy + v[1], x = ox + v[2], y = oy + v[3];
            } else {
                if (!svg_numbers(&p, end, v, 2)) goto bad;
                bool refl = strchr("QqTt", prev) != NULL;
                x1 = refl ? 2 * cx - lcx : cx, y1 = refl ? 2 * cy - lcy : cy;
                x = ox + v[0], y = oy + v[1];
            }
            if (c->n == 0 && (rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            for (int i = 1; i <= SVG_CURVE_SEGMENTS; ++i) {
                double t = (double)i / SVG_CURVE_SEGMENTS, u = 1 - t;
                if ((rc = svg_point(c, u * u * cx + 2 * u * t * x1 + t * t * x, u * u * cy + 2 * u * t * y1 + t * t * y)) !=
                    SP_OK)
                    return rc;
            }
            lcx = x1, lcy = y1, cx = x, cy = y;
            break;
        }
        case 'A': {
            bool large, sweep;
            if (!svg_numbers(&p, end, v, 3) || !svg_flag(&p, end, &large) || !svg_flag(&p, end, &sweep) ||
                !svg_numbers(&p, end, v + 3, 2))
                goto bad;
            v[3] += ox, v[4] += oy;
            if (c->n == 0 && (rc = svg_point(c, cx, cy)) != SP_OK) return rc;
            if ((rc = svg_arc(c, cx, cy, v, large, sweep)) != SP_OK) return rc;
            cx = v[3], cy = v[4];
            break;
        }
        case 'Z':
            if (c->n > 0 && (rc = svg_point(c, sx, sy)) != SP_OK) return rc;
            cx = sx, cy = sy;
            if ((rc = svg_flush(c)) != SP_OK) return rc;
            cmd = 0; // a number right after Z is an error
            prev = 'Z';
            continue;
        default:
            return sp_fail(c->err, SP_ERR_PARSE, "%s: unknown path command '%c'", c->name, cmd);
        }
        prev = cmd;
    }
    return svg_subpath_end(c);
bad:
    return sp_fail(c->err, SP_ERR_PARSE, "%s: bad numbers after path command '%c'", c->name, cmd);
}

// Parses a transform list into an affine (SVG order: left to right, each applied to what follows).
static bool svg_transform(const char* s, const char* end, affine* out)
{
    affine m = k_identity;
    const char* p = s;
    for (;;) {
        while (p < end && (isspace((unsigned char)*p) || *p == ','))
            ++p;
        if (p >= end) break;
        const char* nm = p;
        while (p < end && isalpha((unsigned char)*p))
            ++p;
        size_t nl = (size_t)(p - nm);
        while (p < end && isspace((unsigned char)*p))
            ++p;
        if (p >= end || *p != '(' || nl == 0) return false;
        ++p;
        double v[6];
        int n = 0;
        for (;;) {
            while (p < end && (isspace((unsigned char)*p) || *p == ','))
                ++p;
            if (p < end && *p == ')') {
                ++p;
                break;
            }
            if (n == 6 || !svg_number(&p, end, &v[n])) return false;
            ++n;
        }
        affine t = k_identity;
        if (nl == 9 && !strncmp(nm, "translate", 9) && (n == 1 || n == 2))
            t.e = v[0], t.f = n == 2 ? v[1] : 0;
        else if (nl == 5 && !strncmp(nm, "scale", 5) && (n == 1 || n == 2))
            t.a = v[0], t.d = n == 2 ? v[1] : v[0];
        else if (nl == 6 && !strncmp(nm, "matrix", 6) && n == 6)
            t = (affine){v[0], v[1], v[2], v[3], v[4], v[5]};
        else if (nl == 6 && !strncmp(nm, "rotate", 6) && (n == 1 || n == 3)) {
            double r = v[0] * M_PI / 180.0, cs = cos(r), sn = sin(r);
            t = (affine){cs, sn, -sn, cs, 0, 0};
            if (n == 3) {
                affine a = {1, 0, 0, 1, v[1], v[2]}, b = {1, 0, 0, 1, -v[1], -v[2]};
                t = affine_mul(affine_mul(a, t), b);
            }
        } else if (nl == 5 && !strncmp(nm, "skewX", 5) && n == 1)
            t.c = tan(v[0] * M_PI / 180.0);
        else if (nl == 5 && !strncmp(nm, "skewY", 5) && n == 1)
            t.b = tan(v[0] * M_PI / 180.0);
        else
            return false;
        m = affine_mul(m, t);
    }
    *out = m;
    return true;
}

// Finds attribute `key` in the tag text [s, e); returns value bounds.
static bool svg_attr(const char* s, const char* e, const char* key, const char** vb, const char** ve)
{
    size_t kl = strlen(key);
    for (const char* p = s; p + kl < e; ++p) {
        if (strncmp(p, key, kl) != 0) continue;
        if (p > s && !isspace((unsigned char)p[-1])) continue;
        const char* q = p + kl;
        while (q < e && isspace((unsigned char)*q))
            ++q;
        if (q >= e || *q != '=') continue;
        ++q;
        while (q < e && isspace((unsigned char)*q))
            ++q;
        if (q >= e || (*q != '"' && *q != '\'')) continue;
        char quote = *q++;
        const char* r = memchr(q, quote, (size_t)(e - q));
        if (!r) return false;
        *vb = q;
        *ve = r;
        return true;
    }
    return false;
}

static bool tag_is(const char* s, const char* e, const char* nm)
{
    size_t n = strlen(nm);
    return (size_t)(e - s) >= n && !strncmp(s, nm, n) && (s + n == e || isspace((unsigned char)s[n]) || s[n] == '/');
}

// The element name after '<' or '</', without an "svg:" prefix: some exporters write
// the SVG namespace as a prefix (<svg:svg>, <svg:path>), which means no prefix here.
static const char* svg_name(const char* s, const char* e)
{
    return e - s > 4 && !strncmp(s, "svg:", 4) ? s + 4 : s;
}

static size_t svg_name_len(const char* s, const char* e)
{
    const char* q = s;
    while (q < e && !isspace((unsigned char)*q) && *q != '/')
        ++q;
    return (size_t)(q - s);
}

// True when [b, e), leading spaces aside, starts with CSS keyword kw (any case) and nothing
// but "!important" or spaces follows.
static bool svg_keyword(const char* b, const char* e, const char* kw)
{
    while (b < e && isspace((unsigned char)*b))
        ++b;
    size_t n = strlen(kw);
    if ((size_t)(e - b) < n) return false;
    for (size_t i = 0; i < n; ++i)
        if (tolower((unsigned char)b[i]) != kw[i]) return false;
    return b + n == e || isspace((unsigned char)b[n]) || b[n] == '!';
}

// Whether property [prop, prop + pl) (CSS names are in any case) with value [vb, ve) hides.
static bool svg_hides(const char* prop, size_t pl, const char* vb, const char* ve)
{
    if (pl == 7 && svg_keyword(prop, prop + pl, "display")) return svg_keyword(vb, ve, "none");
    if (pl == 10 && svg_keyword(prop, prop + pl, "visibility"))
        return svg_keyword(vb, ve, "hidden") || svg_keyword(vb, ve, "collapse");
    return false;
}

// An element that draws nothing, nor lets its content draw: display none or visibility
// hidden, as attributes or in its style. (A child's visibility="visible" inside a hidden
// group, which SVG would draw, is not looked for: editors hide whole layers.)
static bool svg_hidden(const char* s, const char* e)
{
    const char *vb, *ve;
    if (svg_attr(s, e, "display", &vb, &ve) && svg_hides("display", 7, vb, ve)) return true;
    if (svg_attr(s, e, "visibility", &vb, &ve) && svg_hides("visibility", 10, vb, ve)) return true;
    if (!svg_attr(s, e, "style", &vb, &ve)) return false;
    for (const char* d = vb; d < ve;) { // "name: value; ..."
        const char* semi = memchr(d, ';', (size_t)(ve - d));
        if (!semi) semi = ve;
        const char* colon = memchr(d, ':', (size_t)(semi - d));
        while (d < semi && isspace((unsigned char)*d))
            ++d;
        if (colon) {
            const char* pe = colon;
            while (pe > d && isspace((unsigned char)pe[-1]))
                --pe;
            if (svg_hides(d, (size_t)(pe - d), colon + 1, semi)) return true;
        }
        d = semi < ve ? semi + 1 : ve;
    }
    return false;
}

// Containers whose content is drawn only where something else refers to it, if at all.
static bool svg_unrendered(const char* s, const char* e)
{
    static const char* const names[] = {"defs", "symbol", "marker", "clipPath", "mask", "pattern"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (tag_is(s, e, names[i])) return true;
    return false;
}

// One drawing element (its tag at lt in text, name at nm, ending at gt): its strokes, through c->m.
static sp_result svg_shape(svg_ctx* c, const char* text, size_t len, const char* lt, const char* nm, const char* gt)
{
    const char* s = lt + 1;
    const char *vb, *ve;
    sp_result rc = SP_OK;
    if (tag_is(nm, gt, "path")) {
        if (svg_attr(s, gt, "d", &vb, &ve)) rc = svg_path(c, vb, ve);
    } else if (tag_is(nm, gt, "line")) {
        double v[4];
        const char* keys[4] = {"x1", "y1", "x2", "y2"};
        for (int i = 0; i < 4; ++i) {
            const char* q;
            v[i] = 0;
            if (svg_attr(s, gt, keys[i], &vb, &ve) && (q = vb, !svg_number(&q, ve, &v[i])))
                return sp_fail(c->err, SP_ERR_PARSE, "%s: bad <line> near line %d", c->name, line_of(text, len, lt));
        }
        if ((rc = svg_point(c, v[0], v[1])) == SP_OK && (rc = svg_point(c, v[2], v[3])) == SP_OK) rc = svg_flush(c);
    } else if (tag_is(nm, gt, "polyline") || tag_is(nm, gt, "polygon")) {
        if (svg_attr(s, gt, "points", &vb, &ve)) {
            const char* q = vb;
            double xy[2], x0 = 0, y0 = 0;
            int k = 0;
            for (const char* r = q; rc == SP_OK && svg_numbers(&r, ve, xy, 2); q = r) { // q: after the last whole pair
                if (k++ == 0) x0 = xy[0], y0 = xy[1];
                rc = svg_point(c, xy[0], xy[1]);
            }
            // What is left is no number pair ("3 nan 5 6", an odd count): named, where the points so far were read.
            while (rc == SP_OK && q < ve && (isspace((unsigned char)*q) || *q == ','))
                ++q;
            if (rc == SP_OK && q < ve) {
                char bad[40], shown[128];
                snprintf(bad, sizeof bad, "%.*s", (int)(ve - q < 24 ? ve - q : 24), q);
                return sp_fail(c->err, SP_ERR_PARSE, "%s: bad <%s> points near line %d: '%s%s' is not a number pair", c->name,
                               tag_is(nm, gt, "polygon") ? "polygon" : "polyline", line_of(text, len, lt),
                               sp_text_printable(bad, shown, sizeof shown), ve - q > 24 ? "..." : "");
            }
            if (rc == SP_OK && k > 0 && tag_is(nm, gt, "polygon")) rc = svg_point(c, x0, y0);
            if (rc == SP_OK) rc = svg_flush(c);
        }
    }
    return rc;
}

// The translation that puts the first <svg>'s viewBox corner at the canvas origin, and its
// size as the canvas: a drawing an editor padded or cropped keeps its place on it.
static affine svg_viewbox(const char* s, const char* gt, sp_sketch* out)
{
    const char *vb, *ve;
    double v[4];
    const char* q;
    if (out->canvas_w != 0 || !svg_attr(s, gt, "viewBox", &vb, &ve)) return k_identity;
    q = vb;
    if (!svg_numbers(&q, ve, v, 4) || fabs(v[0]) >= 1e9 || fabs(v[1]) >= 1e9 || !(v[2] > 0 && v[3] > 0) || v[2] >= 1e6 ||
        v[3] >= 1e6)
        return k_identity;
    out->canvas_w = v[2];
    out->canvas_h = v[3];
    return (affine){1, 0, 0, 1, -v[0], -v[1]};
}

enum { SVG_MAX_DEPTH = 64 };

sp_result sp_sketch_parse_svg(const char* text, size_t len, const char* name, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    svg_ctx c = {.name = name, .err = err, .out = out, .m = k_identity};
    affine stack[SVG_MAX_DEPTH];
    const char* open[SVG_MAX_DEPTH]; // the group names, for a file cut short
    int depth = 0;
    // Inside a hidden or unrendered element: its name, and how many of that name are open.
    const char* skip = NULL;
    size_t skip_len = 0;
    int skip_depth = 0;
    bool saw_svg = false;
    sp_result rc = SP_OK;
    const char* p = text;
    const char* end = text + len;
    while (p < end) {
        const char* lt = memchr(p, '<', (size_t)(end - p));
        if (!lt) break;
        const char* s = lt + 1;
        if (end - s >= 3 && !strncmp(s, "!--", 3)) { // comment
            const char* q = s + 3;
            while (q + 2 < end && strncmp(q, "-->", 3))
                ++q;
            p = q + 2 < end ? q + 3 : end;
            continue;
        }
        const char* gt = memchr(s, '>', (size_t)(end - s));
        if (!gt) {
            rc = sp_fail(err, SP_ERR_PARSE, "%s: unterminated tag near line %d", name, line_of(text, len, lt));
            goto fail;
        }
        p = gt + 1;
        if (*s == '?' || *s == '!') continue;
        bool closing = *s == '/';
        bool self_closing = gt[-1] == '/';
        const char* nm = svg_name(closing ? s + 1 : s, gt);
        size_t nl = svg_name_len(nm, gt);
        if (skip) {
            if (nl == skip_len && !strncmp(nm, skip, nl) && !self_closing && (closing ? --skip_depth : ++skip_depth) == 0)
                skip = NULL;
            continue;
        }
        if (closing) {
            if (tag_is(nm, gt, "g") || tag_is(nm, gt, "svg") || tag_is(nm, gt, "a")) {
                if (depth == 0) {
                    rc = sp_fail(err, SP_ERR_PARSE, "%s: unbalanced </g> near line %d", name, line_of(text, len, lt));
                    goto fail;
                }
                c.m = stack[--depth];
            }
            continue;
        }
        bool is_svg = tag_is(nm, gt, "svg");
        saw_svg = saw_svg || is_svg;
        if (svg_unrendered(nm, gt) || svg_hidden(s, gt)) {
            if (!self_closing && nl > 0) skip = nm, skip_len = nl, skip_depth = 1;
            continue;
        }
        const char *vb, *ve;
        affine local = k_identity;
        if (svg_attr(s, gt, "transform", &vb, &ve) && !svg_transform(vb, ve, &local)) {
            rc = sp_fail(err, SP_ERR_PARSE, "%s: bad transform near line %d", name, line_of(text, len, lt));
            goto fail;
        }
        if (is_svg) local = affine_mul(svg_viewbox(s, gt, out), local);
        if (is_svg || tag_is(nm, gt, "g") || tag_is(nm, gt, "a")) {
            if (self_closing) continue;
            if (depth == SVG_MAX_DEPTH) {
                rc = sp_fail(err, SP_ERR_UNSUPPORTED, "%s: groups nested deeper than %d", name, SVG_MAX_DEPTH);
                goto fail;
            }
            open[depth] = is_svg ? "svg" : tag_is(nm, gt, "g") ? "g" : "a";
            stack[depth++] = c.m;
            c.m = affine_mul(c.m, local);
            continue;
        }
        affine saved = c.m;
        c.m = affine_mul(c.m, local);
        rc = svg_shape(&c, text, len, lt, nm, gt);
        c.m = saved;
        if (rc != SP_OK) goto fail;
    }
    if (skip || depth > 0) { // a file cut between two elements would otherwise pass for a whole drawing
        rc = sp_fail(err, SP_ERR_PARSE, "%s: the file ends inside <%.*s> (cut short?)", name,
                     skip ? (int)(skip_len < 40 ? skip_len : 40) : (int)strlen(open[depth - 1]), skip ? skip : open[depth - 1]);
        goto fail;
    }
    if (!saw_svg) {
        rc = sp_fail(err, SP_ERR_PARSE, "%s: no <svg> element", name);
        goto fail;
    }
    free(c.pts);
    return SP_OK;
fail:
    free(c.pts);
    sp_sketch_free(out);
    return rc;
}

sp_result sp_sketch_read_svg(const char* path, sp_sketch* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    char* text;
    size_t len;
    sp_result rc = sp_sketch_file_read(path, &text, &len, err);
    if (rc != SP_OK) return rc;
    rc = sp_sketch_parse_svg(text, len, path, out, err);
    free(text);
    return rc;
}
