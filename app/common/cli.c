#include "cli.h"

#include "rig_handle.h"
#include "sp/gltf.h"
#include "sp/part.h"
#include "sp/sketch_io.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void print_help(const char* cmd, const char* positional, const char* summary, const sp_opt* opts, int nopts)
{
    printf("usage: %s%s%s", cmd, positional ? " " : "", positional ? positional : "");
    for (int i = 0; i < nopts; ++i) {
        const char* a = opts[i].kind == SP_OPT_FLAG ? "" : " ";
        printf(opts[i].required ? " %s%s%s" : " [%s%s%s]", opts[i].name, a, opts[i].kind == SP_OPT_FLAG ? "" : opts[i].arg);
    }
    printf("\n\n%s\n\noptions:\n", summary);
    for (int i = 0; i < nopts; ++i) {
        // Name and value padded together, so that a long name ("--representatives K")
        // does not push its help past the column.
        char head[128];
        snprintf(head, sizeof head, "%-12s %s", opts[i].name, opts[i].kind == SP_OPT_FLAG ? "" : opts[i].arg);
        printf("  %-25s %s%s\n", head, opts[i].help, opts[i].required ? " (required)" : "");
    }
    printf("  %-12s %-12s %s\n", "--help", "", "show this help");
}

// One file: one inode when both exist; the same name in one folder when
// neither does (two outputs yet to be written; a dangling link's target
// counts as the name it would make).
static bool same_file(const char* a_given, const char* b_given)
{
    struct stat sa, sb;
    bool ea = stat(a_given, &sa) == 0, eb = stat(b_given, &sb) == 0;
    if (ea || eb) return ea && eb && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char *a = sp_path_follow_links(a_given), *b = sp_path_follow_links(b_given);
    char *da = a ? sp_path_folder(a) : NULL, *db = b ? sp_path_folder(b) : NULL;
    const char *na = a ? strrchr(a, '/') : NULL, *nb = b ? strrchr(b, '/') : NULL;
    bool same = da && db && stat(da, &sa) == 0 && stat(db, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino &&
                !strcmp(na ? na + 1 : a, nb ? nb + 1 : b);
    free(da), free(db), free(a), free(b);
    return same;
}

// The files that an input reads besides itself (a glTF's external buffers
// and images), read from it once a command. Any input but a drawing, a pose
// or a picture by its name, and a plugin, may be a glTF: the loader goes by
// the content (a link named `rig` to a .gltf).
typedef struct in_files {
    bool read;
    char** files;
    int count;
} in_files;

static const in_files* files_of(in_files* f, const char* in)
{
    static const char* const not_gltf[] = {"json", "svg", "png", "ndjson"};
    if (f->read) return f;
    f->read = true;
    bool maybe = !sp_rig_path_is_plugin(in);
    for (size_t e = 0; maybe && e < sizeof not_gltf / sizeof not_gltf[0]; ++e)
        maybe = !sp_path_ext_is(in, not_gltf[e]);
    sp_error err = {0};
    if (maybe && sp_gltf_external_files(in, &f->files, &f->count, &err) != SP_OK) f->count = 0; // the loader will say
    return f;
}

// One line and true when `out` would overwrite the input `in` or a file it
// reads (--report over a .gltf's .bin replaced the rig's vertices).
static bool out_overwrites(const char* cmd, const char* out_name, const char* out, const char* in_name, const char* in,
                           const in_files* f)
{
    for (int k = 0; k < f->count; ++k)
        if (same_file(out, f->files[k])) {
            sp_cli_say("%s: %s %s is a file that %s %s reads (%s): it would be overwritten", cmd, out_name, out, in_name, in,
                       f->files[k]);
            return true;
        }
    if (!same_file(out, in)) return false;
    sp_cli_say("%s: %s %s is the same file as %s: it would be overwritten", cmd, out_name, out, in_name);
    return true;
}

bool sp_cli_out_is_input(const char* cmd, const char* out_name, const char* out, const char* in_name, const char* in)
{
    if (!out || !in || !strcmp(out, "-") || sp_cli_out_is_stream(out)) return false;
    in_files f = {0};
    bool hit = out_overwrites(cmd, out_name, out, in_name, in, files_of(&f, in));
    sp_gltf_files_free(f.files, f.count);
    return hit;
}

// Two outputs on one file keep only the last: said once, from the later.
static bool outs_clash(const char* cmd, const sp_opt* opts, int i, int j, const char* out, const char* other)
{
    if (j > i || !same_file(out, other)) return false;
    sp_cli_say("%s: %s %s is the same file as %s: one would overwrite the other", cmd, opts[i].name, out, opts[j].name);
    return true;
}

// An output that is also an input would be overwritten by the command's
// own result (`pose --strokes s.json --report s.json` replaced the strokes
// with the report), and so would a file a glTF input reads; two outputs on
// one file keep only the last. Streams (/dev/stdout, a pipe) are written as
// they go and left alone.
static int check_files(const char* cmd, const sp_opt* opts, int nopts)
{
    in_files cache[64 * 4] = {{0}}; // an input's files, read once: the first 4 values of the first 64 options
    int rc = -1;
    for (int i = 0; i < nopts && rc < 0; ++i) {
        const char* out = opts[i].kind == SP_OPT_OUT ? *(const char* const*)opts[i].out : NULL;
        if (!out || !strcmp(out, "-") || sp_cli_out_is_stream(out)) continue;
        for (int j = 0; j < nopts && rc < 0; ++j) {
            bool list = opts[j].kind == SP_OPT_IN_LIST;
            if (j == i || !(list || opts[j].kind == SP_OPT_IN || opts[j].kind == SP_OPT_OUT)) continue;
            const char* const* vals = list ? ((const sp_str_list*)opts[j].out)->items : opts[j].out;
            int n = list ? ((const sp_str_list*)opts[j].out)->count : 1;
            for (int k = 0; k < n && rc < 0; ++k) {
                if (!vals[k]) continue;
                in_files once = {0}, *f = j < 64 && k < 4 ? &cache[4 * j + k] : &once;
                bool hit = opts[j].kind == SP_OPT_OUT
                               ? outs_clash(cmd, opts, i, j, out, vals[k])
                               : out_overwrites(cmd, opts[i].name, out, opts[j].name, vals[k], files_of(f, vals[k]));
                if (f == &once) sp_gltf_files_free(once.files, once.count);
                if (hit) rc = 2;
            }
        }
    }
    for (int c = 0; c < 64 * 4; ++c)
        sp_gltf_files_free(cache[c].files, cache[c].count);
    return rc;
}

bool sp_cli_check_out_folders(const char* cmd, const sp_opt* opts, int nopts)
{
    for (int i = 0; i < nopts; ++i)
        if (opts[i].kind == SP_OPT_OUT) {
            const char* out = *(const char* const*)opts[i].out;
            if (out && strcmp(out, "-") && !sp_cli_check_out_folder(cmd, opts[i].name, out)) return false;
        }
    return true;
}

int sp_cli_parse(int argc, char** argv, const char* cmd, const char* summary, const sp_opt* opts, int nopts)
{
    return sp_cli_parse_pos(argc, argv, cmd, NULL, summary, opts, nopts);
}

int sp_cli_parse_pos(int argc, char** argv, const char* cmd, const char* positional, const char* summary, const sp_opt* opts,
                     int nopts)
{
    bool seen[64] = {0};
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            print_help(cmd, positional, summary, opts, nopts);
            return 0;
        }
    }
    for (int i = 1; i < argc; ++i) {
        int k = -1;
        for (int j = 0; j < nopts; ++j)
            if (!strcmp(argv[i], opts[j].name)) k = j;
        if (k < 0) {
            fprintf(stderr, "%s: unknown option '%s' (see --help)\n", cmd, sp_text_printable(argv[i], (char[160]){0}, 160));
            return 2;
        }
        const sp_opt* o = &opts[k];
        // A value given twice is a mistake, not an override: `--out a.glb ...
        // --out b.glb` wrote only b.glb. A flag twice means the same, and a
        // list's values gather.
        bool list = o->kind == SP_OPT_LIST || o->kind == SP_OPT_IN_LIST;
        if (k < 64 && seen[k] && o->kind != SP_OPT_FLAG && !list) {
            fprintf(stderr, "%s: %s given twice (once is enough; see --help)\n", cmd, o->name);
            return 2;
        }
        if (k < 64) seen[k] = true;
        if (o->kind == SP_OPT_FLAG) {
            *(bool*)o->out = true;
            continue;
        }
        if (list) {
            sp_str_list* l = o->out;
            while (i + 1 < argc && strncmp(argv[i + 1], "--", 2) != 0) {
                if (l->count >= 256) {
                    fprintf(stderr, "%s: too many values for %s (256 at most)\n", cmd, o->name);
                    return 2;
                }
                l->items[l->count++] = argv[++i];
                if (o->kind == SP_OPT_IN_LIST && !argv[i][0]) {
                    fprintf(stderr, "%s: %s needs file names, got an empty value\n", cmd, o->name);
                    return 2;
                }
            }
            if (l->count == 0) {
                fprintf(stderr, "%s: %s needs at least one value\n", cmd, o->name);
                return 2;
            }
            continue;
        }
        // An option's value never starts with "--": "--out --no-shadow" lost
        // the value, it does not name a file "--no-shadow" ("-1" stays a value).
        if (i + 1 >= argc || !strncmp(argv[i + 1], "--", 2)) {
            fprintf(stderr, "%s: %s needs a value (%s)\n", cmd, o->name, o->arg);
            return 2;
        }
        const char* v = argv[++i];
        char* end = NULL;
        errno = 0;
        if (o->kind == SP_OPT_STRING || o->kind == SP_OPT_IN || o->kind == SP_OPT_OUT) {
            // An empty file name is a slip (an unset shell variable), not a
            // file that cannot be opened (`--rig ""`: "cannot open", exit 1).
            if (!v[0] && o->kind != SP_OPT_STRING) {
                fprintf(stderr, "%s: %s needs a file name, got an empty value\n", cmd, o->name);
                return 2;
            }
            *(const char**)o->out = v;
        } else if (o->kind == SP_OPT_INT) {
            long x = strtol(v, &end, 10);
            if (end == v || *end) {
                fprintf(stderr, "%s: %s expects an integer, got '%s'\n", cmd, o->name, sp_text_printable(v, (char[160]){0}, 160));
                return 2;
            }
            // An integer all the same: say so, not that it is none.
            if (errno || x < -2147483647L || x > 2147483647L) {
                fprintf(stderr, "%s: %s is out of range (see --help), got '%s'\n", cmd, o->name,
                        sp_text_printable(v, (char[160]){0}, 160));
                return 2;
            }
            *(int*)o->out = (int)x;
        } else if (o->kind == SP_OPT_DOUBLE) {
            double x = sp_cli_strtod(v, &end);
            // ERANGE with a finite x is an underflow (1e-320): a number all the
            // same, and the option's range check says whether it will do.
            if ((errno && !(errno == ERANGE && isfinite(x) && fabs(x) < 1)) || end == v || *end || !isfinite(x)) {
                fprintf(stderr, "%s: %s expects a finite number, got '%s'\n", cmd, o->name,
                        sp_text_printable(v, (char[160]){0}, 160));
                return 2;
            }
            *(double*)o->out = x;
        }
    }
    for (int j = 0; j < nopts && j < 64; ++j)
        if (opts[j].required && !seen[j]) {
            fprintf(stderr, "%s: missing %s %s (see --help)\n", cmd, opts[j].name, opts[j].arg);
            return 2;
        }
    return check_files(cmd, opts, nopts);
}

double sp_cli_strtod(const char* s, char** end)
{
    // strtod also reads 0x1p3, inf and nan: not the numbers the options
    // document (`--times 0x1,2` was taken as 1, 2; an outside review).
    const char* at = s;
    while (*at == ' ' || *at == '\t')
        ++at;
    if (*at == '+' || *at == '-') ++at;
    bool digits = (*at >= '0' && *at <= '9') || (*at == '.' && at[1] >= '0' && at[1] <= '9');
    if (!digits || (at[0] == '0' && (at[1] == 'x' || at[1] == 'X'))) {
        *end = (char*)s;
        return 0;
    }
    errno = 0;
    return strtod(s, end);
}

bool sp_cli_parse_size(const char* s, int* w, int* h)
{
    char* end = NULL;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X')) return false;
    const char* s2 = end + 1;
    long b = strtol(s2, &end, 10);
    if (end == s2 || *end) return false;
    if (a < 16 || b < 16 || a > 8192 || b > 8192) return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

bool sp_cli_check_int(const char* cmd, const char* name, int v, int lo, int hi)
{
    if (v >= lo && v <= hi) return true;
    fprintf(stderr, "%s: %s must be %d..%d, got %d\n", cmd, name, lo, hi, v);
    return false;
}

bool sp_cli_check_double(const char* cmd, const char* name, double v, double lo, bool lo_open, double hi)
{
    if ((lo_open ? v > lo : v >= lo) && v <= hi) return true;
    fprintf(stderr, "%s: %s must be in %s%.10g, %.10g], got %g\n", cmd, name, lo_open ? "(" : "[", lo, hi, v);
    return false;
}

bool sp_cli_check_name(const char* cmd, const char* name, const char* value)
{
    if (!value || sp_part_name_is_plain(value)) return true;
    char shown[160];
    fprintf(stderr, "%s: %s wants a plain name ([A-Za-z0-9_.-], 1 to %d characters, not starting with '.'), got '%s'\n", cmd,
            name, SP_NAME_MAX - 1, sp_text_printable(value, shown, sizeof shown));
    return false;
}

bool sp_cli_out_is_stream(const char* path)
{
    // /dev/stdout redirected to a file is a regular file by stat, hence its
    // name; a regular file elsewhere under /dev (/dev/shm) is a file.
    struct stat st;
    return sp_path_descriptor(path) >= 0 || (stat(path, &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)));
}

bool sp_cli_out_is_stdout(const char* path)
{
    if (!path) return false;
    if (!strcmp(path, "-") || sp_path_descriptor(path) == 1) return true;
    struct stat sp, so;
    return stat(path, &sp) == 0 && fstat(1, &so) == 0 && sp.st_dev == so.st_dev && sp.st_ino == so.st_ino;
}

bool sp_cli_stdout_taken(const char* const* outs, int n)
{
    for (int i = 0; i < n; ++i)
        if (sp_cli_out_is_stdout(outs[i])) return true;
    return false;
}

// Why the existing folder dir takes no new file, or NULL. A folder that
// lets root write but takes no new file (/proc) failed only after the work,
// with ENOENT from the temporary file (an outside review): a file is made
// there and removed.
static const char* folder_takes_no_file(const char* dir)
{
    struct stat st;
    if (stat(dir, &st) != 0) return strerror(errno);
    if (!S_ISDIR(st.st_mode)) return "not a folder";
    if (access(dir, W_OK | X_OK) != 0) return "this user may not write there";
    size_t dn = strlen(dir) + 3;
    char* in_dir = malloc(dn); // a name in the folder written (links followed)
    if (in_dir) snprintf(in_dir, dn, "%s/x", dir);
    char* probe = in_dir ? sp_path_temp_beside(in_dir, ".probe") : NULL;
    free(in_dir);
    int pfd = probe ? open(probe, O_WRONLY | O_CREAT | O_EXCL, 0600) : 0;
    // ENOENT from an existing folder (/proc) named the probe, not the folder.
    const char* why = pfd >= 0 ? NULL : errno == ENOENT ? "it takes no new file" : strerror(errno);
    if (probe && pfd >= 0) close(pfd), unlink(probe);
    free(probe);
    return why;
}

bool sp_cli_check_out_folder(const char* cmd, const char* name, const char* path)
{
    if (!path) return true;
    // Through a link, the file is written in the folder of the one it names.
    char* real = sp_path_follow_links(path);
    int fd = sp_path_descriptor(real ? real : path);
    if (fd >= 0) {
        // Written through that descriptor: one this process did not get
        // (`>&-`) would be whatever it opens next, a database, say.
        free(real);
        if (fcntl(fd, F_GETFD) != -1) return true;
        sp_cli_say("%s: %s %s: descriptor %d is not open (nothing to write into)", cmd, name, path, fd);
        return false;
    }
    if (sp_cli_out_is_stream(path)) {
        free(real);
        return true;
    }
    char* dir = real ? sp_path_folder(real) : NULL;
    free(real);
    if (!dir) return true; // out of memory or a loop of links: the writer will say so
    const char* why = folder_takes_no_file(dir);
    if (why) sp_cli_say("%s: %s %s: cannot write into folder '%s' (%s)", cmd, name, path, dir, why);
    free(dir);
    struct stat st;
    if (!why && stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        sp_cli_say("%s: %s %s: is a folder, not a file", cmd, name, path);
        return false;
    }
    return why == NULL;
}

bool sp_cli_check_folder_to_make(const char* cmd, const char* name, const char* dir, const char* purpose)
{
    // Through a link, the folder it names (one not made yet: the writer makes it).
    char* real = sp_path_follow_links(dir);
    char* at = real ? strdup(real) : NULL;
    // No folder at the end of its links (a loop): every write would fail.
    const char* why = real ? NULL : "its links go round in a loop";
    while (at && !why) {
        struct stat st;
        if (stat(at, &st) == 0) {
            why = folder_takes_no_file(at);
            break;
        }
        if (errno != ENOENT && errno != ENOTDIR) {
            why = strerror(errno);
            break;
        }
        char* up = sp_path_folder(at); // missing (or under a file): its folder tells
        bool top = up && !strcmp(up, at);
        free(at);
        at = top ? NULL : up;
    }
    if (why && (!at || !strcmp(at, real)))
        sp_cli_say("%s: %s %s: %s (%s there)", cmd, name, dir, why, purpose);
    else if (why)
        sp_cli_say("%s: %s %s: '%s' on its way: %s (the folder is made and %s there)", cmd, name, dir, at, why, purpose);
    free(at), free(real);
    return why == NULL;
}

bool sp_cli_check_out(const char* cmd, const char* name, const char* path, sp_cli_out_kind kind)
{
    if (!path) return true;
    // A pipe or a device has no file name to say a format, and the writers
    // write into one (`render --out /dev/stdout | ...`).
    if (sp_cli_out_is_stream(path)) return true;
    if (kind == SP_CLI_OUT_GLTF) {
        if (sp_path_ext_is(path, "glb") || sp_path_ext_is(path, "gltf")) return true;
        sp_cli_say("%s: %s writes glTF: the file name must end in .glb or .gltf, got '%s'", cmd, name, path);
    } else if (kind == SP_CLI_OUT_PNG) {
        if (sp_path_ext_is(path, "png")) return true;
        sp_cli_say("%s: %s writes a PNG: the file name must end in .png, got '%s'", cmd, name, path);
    } else {
        // The drawing readers (classify, db add-sketch, labelled folders) tell
        // a stroke file from SVG, PNG and ndjson by this name.
        if (sp_path_ext_is(path, "json")) return true;
        sp_cli_say("%s: %s writes a stroke file (JSON): the file name must end in .json, got '%s'", cmd, name, path);
    }
    return false;
}

bool sp_cli_check_max_ms(const char* cmd, double ms)
{
    return isnan(ms) || sp_cli_check_double(cmd, "--max-ms", ms, 0, true, SP_CLI_MAX_MS);
}

void sp_cli_print_shell_word(FILE* f, const char* s)
{
    bool plain = s[0] != 0;
    for (const char* c = s; plain && *c; ++c)
        plain = isalnum((unsigned char)*c) || strchr("_./=:,+-", *c);
    if (plain) {
        fputs(s, f);
        return;
    }
    fputc('\'', f);
    for (const char* c = s; *c; ++c) {
        if (*c == '\'')
            fputs("'\\''", f);
        else
            fputc(*c, f);
    }
    fputc('\'', f);
}

void sp_cli_say(const char* fmt, ...)
{
    char line[SP_TEXT_LINE_MAX];
    va_list ap;
    va_start(ap, fmt);
    sp_text_vline(line, sizeof line, fmt, ap);
    va_end(ap);
    fprintf(stderr, "%s\n", line);
}

static char g_done[512];

void sp_cli_done(const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g_done, sizeof g_done, fmt, ap);
    va_end(ap);
}

const char* sp_cli_done_text(void)
{
    return g_done;
}
