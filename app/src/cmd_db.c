// cmd_db.c: sketchpose db init|add-part|add-sketch|list|show|remove|check|train|export|log|review
// The curators' commands over the part database (sp/partdb.h).
#include <cjson/cJSON.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "clf_cli.h"
#include "cli.h"
#include "outputs.h"
#include "sp/headless.h"
#include "sp/math.h"
#include "sp/part_preview.h"
#include "sp/partdb.h"
#include "sp/sketch_sheet.h"

#ifndef SP_SOURCE_DIR
#define SP_SOURCE_DIR "."
#endif

typedef struct db_common {
    const char* db;
    double busy_s;
    const char* by;
} db_common;

#define DB_COMMON_OPTS(c)                                                                                                        \
    {"--db", SP_OPT_IN, &(c).db, "PATH", "the database (default: $SP_DB, else ./sketchpose.db)", false},                         \
        {"--busy-timeout", SP_OPT_DOUBLE, &(c).busy_s, "S", "seconds to wait for another writer, 0..86400 (default 5)", false},  \
    {                                                                                                                            \
        "--by", SP_OPT_STRING, &(c).by, "WHO", "curator's name for the log (default $USER)", false                               \
    }

// Before parsing: --busy-timeout not given (NAN), the library's default.
static db_common db_common_unset(void)
{
    return (db_common){.busy_s = NAN};
}

static const char* db_path(const db_common* c) { return c->db ? c->db : sp_db_default_path(); }

// Splits argv into options (for sp_cli_parse) and positional values; -1
// with *extra the first value past maxpos.
static int split_args(int argc, char** argv, const sp_opt* opts, int nopts, char** kept, const char** pos, int* npos, int maxpos,
                      const char** extra)
{
    int nk = 0;
    *npos = 0;
    kept[nk++] = argv[0];
    for (int i = 1; i < argc; ++i) {
        const sp_opt* o = NULL;
        for (int j = 0; j < nopts; ++j)
            if (!strcmp(argv[i], opts[j].name)) o = &opts[j];
        if (strncmp(argv[i], "--", 2) != 0 && strcmp(argv[i], "-h") != 0) {
            if (*npos >= maxpos) {
                *extra = argv[i];
                return -1;
            }
            pos[(*npos)++] = argv[i];
            continue;
        }
        if (!o && strcmp(argv[i], "--help") != 0 && strcmp(argv[i], "-h") != 0) {
            // An option not known (a typo): the rest goes to the option parser
            // as it is, which names it; its value, taken for a positional,
            // was named instead ("unexpected argument '1'" for --aprove 1).
            while (i < argc)
                kept[nk++] = argv[i++];
            break;
        }
        kept[nk++] = argv[i];
        bool list = o && (o->kind == SP_OPT_LIST || o->kind == SP_OPT_IN_LIST);
        if (o && o->kind != SP_OPT_FLAG && !list && i + 1 < argc)
            kept[nk++] = argv[++i];
        else if (list)
            while (i + 1 < argc && strncmp(argv[i + 1], "--", 2) != 0)
                kept[nk++] = argv[++i];
    }
    return nk;
}

// A curator's name as the log keeps it: newlines and escape codes in --by
// reached `db log` and a terminal, and a 100 KB name every row.
static bool name_ok(const char* by)
{
    size_t n = strlen(by);
    for (size_t i = 0; i < n; ++i)
        if ((unsigned char)by[i] < 0x20 || by[i] == 0x7f) return false;
    return n >= 1 && n <= 128;
}

static int parse(int argc, char** argv, const char* cmd, const db_common* c, const char* summary, const sp_opt* opts, int nopts,
                 const char** pos, int* npos, int minpos, int maxpos, const char* posname)
{
    char* kept[512];
    if (argc > 512) {
        fprintf(stderr, "%s: too many arguments\n", cmd);
        return SP_EXIT_USAGE;
    }
    const char* extra = NULL;
    int nk = split_args(argc, argv, opts, nopts, kept, pos, npos, maxpos, &extra);
    if (nk < 0) {
        if (maxpos == 0)
            fprintf(stderr, "%s: unexpected argument '%s' (it takes none; see --help)\n", cmd,
                    sp_text_printable(extra, (char[160]){0}, 160));
        else
            fprintf(stderr, "%s: unexpected argument '%s' (at most %d %s; see --help)\n", cmd,
                    sp_text_printable(extra, (char[160]){0}, 160), maxpos, posname);
        return SP_EXIT_USAGE;
    }
    int rc = sp_cli_parse_pos(nk, kept, cmd, maxpos ? posname : NULL, summary, opts, nopts);
    if (rc >= 0) return rc;
    // A day at most: beyond, the milliseconds overflow an int. 0 waits not at all.
    if (!isnan(c->busy_s) && !sp_cli_check_double(cmd, "--busy-timeout", c->busy_s, 0, false, 86400)) return SP_EXIT_USAGE;
    if (c->by && !name_ok(c->by)) {
        fprintf(stderr, "%s: --by wants a name of 1 to 128 bytes without control characters (it goes into the log)\n", cmd);
        return SP_EXIT_USAGE;
    }
    if (*npos < minpos) {
        fprintf(stderr, "%s: missing %s (see --help)\n", cmd, posname);
        return SP_EXIT_USAGE;
    }
    for (int i = 0; i < *npos; ++i)
        if (!pos[i][0]) {
            fprintf(stderr, "%s: %s: got an empty file name\n", cmd, posname);
            return SP_EXIT_USAGE;
        }
    return -1;
}

static sp_db* open_db(const char* cmd, const db_common* c, unsigned flags)
{
    sp_db* db = NULL;
    sp_error err = {0};
    // The timeout applies to the open too: a locked database is waited for there first.
    if (sp_db_open_wait(db_path(c), flags, isnan(c->busy_s) ? -1 : (int)lround(c->busy_s * 1000), &db, &err) != SP_OK) {
        fprintf(stderr, "%s: %s\n", cmd, err.text);
        return NULL;
    }
    return db;
}

// Whether the database file is there before a command that may create it.
static bool db_exists(const db_common* c)
{
    struct stat st;
    return stat(db_path(c), &st) == 0 || errno != ENOENT;
}

// A database the failed command created, into which nothing was ever stored
// (its generation is still the schema's first), goes again: a mistyped --db
// must not leave an empty database behind. Any row another process added
// meanwhile would have counted a generation, and keeps the file.
static void drop_if_unused(const db_common* c, bool existed)
{
    if (existed) return;
    sp_db* db = NULL;
    sp_error err = {0};
    if (sp_db_open(db_path(c), SP_DB_READONLY, &db, &err) != SP_OK) return;
    bool unused = sp_db_generation(db) == 1;
    sp_db_close(db);
    if (!unused) return;
    char side[1100];
    remove(db_path(c));
    snprintf(side, sizeof side, "%s-wal", db_path(c));
    remove(side);
    snprintf(side, sizeof side, "%s-shm", db_path(c));
    remove(side);
}

// Said once a command that may create its database has stored something in a
// new one: a mistyped --db or a wrong folder is noticed at once, not when the
// kiosk shows none of it.
static void note_created(const char* cmd, const db_common* c, bool existed)
{
    if (!existed)
        fprintf(stderr,
                "%s: created a new database %s (no file was there; the kiosk's default database is built by `sketchpose db "
                "init`)\n",
                cmd, db_path(c));
}

static int fail(const char* cmd, const sp_error* err)
{
    fprintf(stderr, "%s: %s\n", cmd, err->text);
    return SP_EXIT_INPUT;
}

// The warnings of the part being added (sp_db_part_desc.warn), one line each.
typedef struct part_warnings {
    int count;
    char (*lines)[SP_WARNING_MAX];
    int dropped; // not kept: out of memory
} part_warnings;

static void collect_warning(void* user, const char* line)
{
    part_warnings* w = user;
    char(*grown)[SP_WARNING_MAX] = realloc(w->lines, sizeof *w->lines * (size_t)(w->count + 1));
    if (!grown) {
        ++w->dropped;
        return;
    }
    w->lines = grown;
    snprintf(w->lines[w->count++], SP_WARNING_MAX, "%s", line);
}

// One part as JSON; `derived` adds what add-part derived, `warns` (may be NULL) its warnings.
static void print_part(const sp_db_part_info* p, bool derived, const part_warnings* warns)
{
    printf("{\"name\": ");
    clf_cli_json_str(stdout, p->name);
    printf(", \"category\": ");
    clf_cli_json_str(stdout, p->category);
    printf(", \"abstraction\": ");
    clf_cli_json_str(stdout, p->abstraction);
    printf(", \"vertices\": %d, \"triangles\": %d, \"joints\": %d, \"parameters\": %d, \"abstractions\": %d, \"animations\": %d, \"bytes\": %zu, "
           "\"sha256\": \"%s\"",
           p->vertices, p->triangles, p->joints, p->parameters, p->abstractions, p->animations, p->bytes, p->sha256);
    if (p->selftest_error >= 0) printf(", \"selftest_error\": %.5f", p->selftest_error);
    if (p->sketches >= 0) printf(", \"category_sketches\": %d", p->sketches);
    printf(", \"added_by\": ");
    clf_cli_json_str(stdout, p->added_by);
    printf(", \"added_at\": ");
    clf_cli_json_str(stdout, p->added_at);
    if (derived) {
        printf(", \"derived\": [");
        for (int b = 0, n = 0; b < SP_DERIVED_COUNT; ++b)
            if (p->derived & (1u << b)) printf("%s\"%s\"", n++ ? ", " : "", sp_derived_name(b));
        printf("]");
    }
    if (warns) {
        printf(", \"warnings\": [");
        for (int i = 0; i < warns->count; ++i) {
            printf("%s", i ? ", " : "");
            clf_cli_json_str(stdout, warns->lines[i]);
        }
        printf("]");
    }
    printf("}");
}

// ---- option values ---------------------------------------------------------------

// A count of sketches to make, where a typed 0 asks for none as -1 does (it
// was the library's default: 60 sketches for a curator who asked for none).
// Not given (SP_CLI_UNSET): the library's 0, its default. Else -1..hi, or one
// line naming the option and the range, false (exit 2).
static bool count_opt(const char* cmd, const char* name, int* v, int hi)
{
    if (*v == SP_CLI_UNSET) {
        *v = 0;
        return true;
    }
    if (*v < -1 || *v > hi) {
        fprintf(stderr, "%s: %s must be -1 or 0 (none) to %d, got %d\n", cmd, name, hi, *v);
        return false;
    }
    if (*v == 0) *v = -1;
    return true;
}

// --folds of the training report: -1 or 0 none (a typed 0 was 3 folds), or
// 2..100 as `eval --folds` (1 fold holds out every drawing). Not given: the
// library's 0, 3 folds. Else one line, false (exit 2).
static bool folds_opt(const char* cmd, int* v)
{
    if (*v == SP_CLI_UNSET || *v == -1 || *v == 0) {
        *v = *v == SP_CLI_UNSET ? 0 : -1;
        return true;
    }
    if (*v >= 2 && *v <= 100) return true;
    fprintf(stderr, "%s: --folds must be -1 or 0 (none), or 2..100, got %d\n", cmd, *v);
    return false;
}

_Static_assert(SP_DB_CURATED_TRAIN_MAX == 400 && SP_DB_KEEP_MODELS == 3, "db train's help gives the defaults");

// A count option that takes -1 for all or 1..1,000,000 (--curated-max,
// --keep-models); not given, 0: the library's default.
static bool all_or_count_opt(const char* cmd, const char* name, int* v)
{
    if (*v == SP_CLI_UNSET) {
        *v = 0;
        return true;
    }
    if (*v == -1 || (*v >= 1 && *v <= 1000000)) return true;
    fprintf(stderr, "%s: %s must be -1 (all) or 1..1000000, got %d\n", cmd, name, *v);
    return false;
}

// ---- subcommands ---------------------------------------------------------------

static int db_init(int argc, char** argv)
{
    const char* cmd = "sketchpose db init";
    db_common c = db_common_unset();
    const char* from = NULL;
    const char *assets = NULL, *quickdraw = NULL;
    // Not given: the library's defaults (count_opt, folds_opt).
    int synth = SP_CLI_UNSET, concepts = SP_CLI_UNSET, concept_family = SP_CLI_UNSET, drawings = SP_CLI_UNSET,
        folds = SP_CLI_UNSET;
    bool no_train = false;
    clf_cli_opts o = clf_cli_opts_unset();
    sp_opt opts[] = {
        DB_COMMON_OPTS(c),
        {"--from", SP_OPT_STRING, &from, "DIR", "rebuild from a folder written by `db export`", false},
        {"--assets", SP_OPT_STRING, &assets, "DIR",
         "parts to build the default database from (default: the source tree's assets/)", false},
        {"--synth", SP_OPT_INT, &synth, "N", "synthetic sketches per part, -1 or 0 (none) to 10000 (default 60)", false},
        {"--concepts", SP_OPT_INT, &concepts, "N",
         "concept sketches per dragon-part category, -1 or 0 (none) to 10000 (default 60)", false},
        {"--concept-family", SP_OPT_INT, &concept_family, "F",
         "seed family of the concept sketches (default 1; another family is another draw of the same designs, as `synth "
         "--concepts --seed F`)",
         false},
        {"--drawings", SP_OPT_INT, &drawings, "N",
         "draws of each hand-placed design of assets/sketches/drawings.json, -1 or 0 (none) to 100 (default 1; seed family "
         "--concept-family)",
         false},
        {"--quickdraw", SP_OPT_STRING, &quickdraw, "DIR",
         "the Quick, Draw! data that the people's strokes (assets/sketches/picks.json) are read from (default: the folder "
         "picks.json names, ../shared/data/quickdraw beside the clone)",
         false},
        {"--folds", SP_OPT_INT, &folds, "K", "cross-validation folds of the training report, 2..100 (default 3; -1 or 0: none)",
         false},
        {"--no-train", SP_OPT_FLAG, &no_train, "", "(with --from) do not train a model", false},
        CLF_CLI_OPTS(o)};
    const char* pos[1];
    int npos;
    int rc = parse(
        argc, argv, cmd, &c,
        "create a database: the default one from assets/ (parts, synthetic sketches, a trained model), or one rebuilt from an "
        "export folder",
        opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 0, "");
    if (rc >= 0) return rc;
    // The options of the other way to make a database were ignored.
    const char* other = !from                            ? (no_train ? "--no-train" : NULL)
                        : synth != SP_CLI_UNSET          ? "--synth"
                        : concepts != SP_CLI_UNSET       ? "--concepts"
                        : drawings != SP_CLI_UNSET       ? "--drawings"
                        : concept_family != SP_CLI_UNSET ? "--concept-family"
                        : assets                         ? "--assets"
                        : quickdraw                      ? "--quickdraw"
                                                         : NULL;
    if (other) {
        fprintf(stderr, "%s: %s does not apply %s --from DIR\n", cmd, other, from ? "with" : "without");
        return SP_EXIT_USAGE;
    }
    if (!clf_cli_check(cmd, &o)) return SP_EXIT_USAGE;
    if (!count_opt(cmd, "--synth", &synth, 10000) || !count_opt(cmd, "--concepts", &concepts, 10000) ||
        !count_opt(cmd, "--drawings", &drawings, 100) || !folds_opt(cmd, &folds))
        return SP_EXIT_USAGE;
    if (concept_family == SP_CLI_UNSET) concept_family = 1;
    if (concept_family < 1 || concept_family > 1000000) {
        fprintf(stderr, "%s: --concept-family must be 1 to 1000000\n", cmd);
        return SP_EXIT_USAGE;
    }
    sp_error err = {0};
    sp_db_train_desc td = {.clf = clf_cli_desc(&o), .folds = folds, .by = c.by};
    if (clf_cli_tty()) td.clf.progress = clf_cli_progress;
    sp_result r;
    if (from) r = sp_db_create_from_export(db_path(&c), from, no_train ? NULL : &td, c.by, &err);
    else {
        char def[1024];
        snprintf(def, sizeof def, "%s/assets", SP_SOURCE_DIR);
        if (!assets) assets = def;
        // Whether the people's strokes can join.
        bool missing = false;
        int picks = 0;
        if ((r = sp_db_people_source(assets, quickdraw, &picks, &missing, &err)) != SP_OK) return fail(cmd, &err);
        if (missing)
            fprintf(stderr, "%s: %s/sketches/picks.json: the Quick, Draw! data is not where it says; building without the people's strokes "
                            "(--quickdraw DIR names it)\n", cmd, assets);
        r = sp_db_create_default(db_path(&c), assets,
                                 &(sp_db_default_desc){.synth_per_part = synth,
                                                       .concepts_per_category = concepts,
                                                       .concept_family = concept_family,
                                                       .drawn_per_design = drawings,
                                                       .quickdraw_dir = quickdraw,
                                                       .train = td},
                                 &err);
    }
    if (r != SP_OK) return fail(cmd, &err);
    sp_cli_done("%s is built", db_path(&c));
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_db_part_info* parts = NULL;
    int n = 0;
    char* models = NULL;
    // What the default recipe stored, by maker.
    int nparts = 0, nconcepts = 0, ndesigns = 0, npeople = 0;
    if (sp_db_list_parts(db, &parts, &n, &err) != SP_OK || sp_db_models_json(db, &models, &err) != SP_OK ||
        (!from && (sp_db_sketch_count_by(db, SP_DB_SOURCE_SYNTHETIC, SP_DB_BY_ASSETS, &nparts, &err) != SP_OK ||
                   sp_db_sketch_count_by(db, SP_DB_SOURCE_SYNTHETIC, SP_DB_BY_CONCEPTS, &nconcepts, &err) != SP_OK ||
                   sp_db_sketch_count_by(db, SP_DB_SOURCE_SYNTHETIC, SP_DB_BY_DRAWINGS, &ndesigns, &err) != SP_OK ||
                   sp_db_sketch_count_by(db, SP_DB_SOURCE_CURATED, SP_DB_BY_ASSETS, &npeople, &err) != SP_OK))) {
        free(parts);
        free(models);
        sp_db_close(db);
        return fail(cmd, &err);
    }
    printf("{\"db\": ");
    clf_cli_json_str(stdout, db_path(&c));
    printf(", \"parts\": %d", n);
    if (!from)
        printf(", \"part_sketches\": %d, \"concept_sketches\": %d, \"design_sketches\": %d, \"people_strokes\": %d", nparts,
               nconcepts, ndesigns, npeople);
    printf(", \"models\": %s}\n", models);
    free(parts);
    free(models);
    sp_db_close(db);
    return SP_EXIT_OK;
}

// --attach-joint and --view choose how a plain rigged glTF is derived; a part
// with sketchpose extras of its own is stored as it is, so either is bad usage
// there (it was ignored, even a joint the part does not have). A file that does
// not load is left to the add, which says so.
static bool derive_options_apply(const char* cmd, const char* file, const char* attach_joint, const char* view)
{
    if (!attach_joint && !view) return true;
    sp_character ch = {0};
    sp_error err = {0};
    bool plain = sp_gltf_load(file, &ch, &err) != SP_OK || sp_part_needs_derivation(&ch);
    sp_character_free(&ch);
    if (!plain)
        fprintf(stderr, "%s: %s applies to a part derived from a plain rigged glTF; %s already has sketchpose extras\n", cmd,
                attach_joint ? "--attach-joint" : "--view", file);
    return plain;
}

// add-part's --preview, drawn from the part as it will be stored (sp_db_part_desc.before_store).
static sp_result store_preview(void* user, const sp_character* part, int abstraction, sp_error* err)
{
    sp_result r = sp_part_preview_png(part, abstraction, (const char*)user, err);
    if (r != SP_OK) {
        char why[sizeof err->text];
        snprintf(why, sizeof why, "%s", err->text);
        sp_fail(err, r, "%s; the part was not stored", why);
    }
    return r;
}

static int db_add_part(int argc, char** argv)
{
    const char* cmd = "sketchpose db add-part";
    db_common c = db_common_unset();
    sp_db_part_desc d = {0};
    bool no_selftest = false;
    const char *view = NULL, *preview = NULL;
    int synth = SP_CLI_UNSET;
    sp_opt opts[] = {
        DB_COMMON_OPTS(c),
        {"--category", SP_OPT_STRING, &d.category, "C", "category (default: the part's extras.sp_part.category)", false},
        {"--name", SP_OPT_STRING, &d.name, "NAME", "part name (default: the file name without extension)", false},
        {"--abstraction", SP_OPT_STRING, &d.abstraction, "A",
         "abstraction its sketches show (default: sp_part.abstraction, else the first; a derived part: outline, or stick)",
         false},
        {"--attach-joint", SP_OPT_STRING, &d.attach_joint, "NAME",
         "a derived part attaches by this joint (default: its root's end)", false},
        {"--view", SP_OPT_STRING, &view, "V",
         "a derived part's sketch view: auto (default), -z, +z, -x, +x (see `sketchpose derive --help`)", false},
        {"--preview", SP_OPT_OUT, &preview, "out.png",
         "render the stored part at rest and in three random poses, its abstraction overlaid", false},
        {"--synth", SP_OPT_INT, &synth, "N", "synthetic sketches stored with it, -1 or 0 (none) to 10000 (default 60)", false},
        {"--no-selftest", SP_OPT_FLAG, &no_selftest, "", "skip the solver self-test", false}};
    const char* pos[1];
    int npos;
    int rc = parse(
        argc, argv, cmd, &c,
        "validate a rigged part (loads, skin, abstraction, bounded parameters, solver self-test) and store it with synthetic "
        "sketches; a rigged glTF without sketchpose extras first gets them derived (as `sketchpose derive`); a refused part "
        "writes nothing",
        opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 1, 1, "PART.glb");
    if (rc >= 0) return rc;
    if (!sp_cli_check_out(cmd, "--preview", preview, SP_CLI_OUT_PNG) || !count_opt(cmd, "--synth", &synth, 10000) ||
        sp_cli_out_is_input(cmd, "--preview", preview, "the part", pos[0]))
        return SP_EXIT_USAGE;
    d.synth_sketches = synth;
    if (!sp_cli_check_name(cmd, "--category", d.category) || !sp_cli_check_name(cmd, "--name", d.name)) return SP_EXIT_USAGE;
    if (view && !sp_derive_view_parse(view, &d.view)) {
        fprintf(stderr, "%s: --view wants auto, -z, +z, -x or +x, got '%s'\n", cmd, sp_text_printable(view, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    // --view auto is the default, which every part takes (sp_db_add_part agrees).
    if (!derive_options_apply(cmd, pos[0], d.attach_joint, view && strcmp(view, "auto") != 0 ? view : NULL)) return SP_EXIT_USAGE;
    part_warnings warns = {0};
    d.warn = collect_warning;
    d.warn_user = &warns;
    d.added_by = c.by;
    if (no_selftest) d.selftest_seeds = -1;
    sp_error err = {0};
    if (preview) {
        // A renderer and a place for the picture first: without them nothing is stored.
        if (!sp_cli_check_out_folders(cmd, opts, (int)(sizeof opts / sizeof opts[0]))) return SP_EXIT_INPUT;
        sp_headless* gl;
        sp_headless_create(&gl, &err);
        if (!gl) return fail(cmd, &err);
        sp_headless_destroy(gl);
    }
    bool existed = db_exists(&c);
    sp_db* db = open_db(cmd, &c, SP_DB_CREATE);
    if (!db) return SP_EXIT_INPUT;
    // The picture is made (staged) before the part is stored: a picture that
    // fails (a full disk) leaves the database as it was, where the part was
    // stored, then removed, the log showing both (an outside review).
    sp_outputs staged = {0};
    const char* preview_to = NULL;
    sp_result r = sp_outputs_stage(&staged, preview, &preview_to, &err);
    d.before_store = preview_to ? store_preview : NULL;
    d.before_store_user = (void*)preview_to;
    sp_db_part_info info;
    if (r == SP_OK) r = sp_db_add_part_file(db, pos[0], &d, &info, &err);
    if (r == SP_OK && (r = sp_outputs_commit(&staged, &err)) != SP_OK) {
        // Put in place it could not be (rare: its folder went): the part goes again.
        sp_error rm = {0};
        if (sp_db_remove_part(db, info.name, c.by, &rm) == SP_OK) {
            char why[sizeof err.text];
            snprintf(why, sizeof why, "%s", err.text);
            sp_fail(&err, r, "%s; part %s not kept", why, info.name);
        }
    }
    if (r != SP_OK) sp_outputs_undo(&staged, &err);
    sp_db_close(db);
    if (r != SP_OK) {
        free(warns.lines);
        drop_if_unused(&c, existed);
        return fail(cmd, &err);
    }
    note_created(cmd, &c, existed);
    sp_cli_done("part %s is stored in %s", info.name, db_path(&c));
    // As `sketchpose derive` prints them for the same file: stderr for the curator, JSON for a script.
    char shown[300]; // the path as typed, on one line (warnings are one line each)
    sp_text_printable(pos[0], shown, sizeof shown);
    for (int i = 0; i < warns.count; ++i)
        fprintf(stderr, "%s: %s: warning: %s\n", cmd, shown, warns.lines[i]);
    if (warns.dropped) fprintf(stderr, "%s: %s: warning: %d more warnings (out of memory)\n", cmd, shown, warns.dropped);
    if (!sp_cli_out_is_stdout(preview)) { // a preview on stdout has it to itself
        print_part(&info, true, &warns);
        printf("\n");
    }
    free(warns.lines);
    return SP_EXIT_OK;
}

// ---- add-sketch: reading files ------------------------------------------------------

typedef struct sketch_set {
    sp_dataset ds;
    sp_db_png* png; // parallel to ds.samples
    int cap;
    bool kiosk; // added as kiosk sketches: each one stroke (sp_db_add_sketches)
} sketch_set;

static bool has_ext(const char* p, const char* ext)
{
    size_t n = strlen(p), e = strlen(ext);
    return n > e && !strcasecmp(p + n - e, ext);
}

// Adds a drawing read from `what` (a file, or a drawing of one).
static sp_result push(sketch_set* s, sp_sample* smp, void* png, size_t png_size, const char* what, sp_error* err)
{
    const char* why = s->kiosk ? sp_db_kiosk_sketch_problem(smp) : NULL;
    if (why)
        return sp_fail(err, SP_ERR_INVALID, "%s: a kiosk sketch is one stroke of 2..%d points; this is %s (add it as curated)",
                       what, SP_DB_KIOSK_POINTS_MAX, why);
    if (sp_dataset_reserve(&s->ds, 1) != SP_OK) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (s->ds.capacity > s->cap) { // the drawings' PNGs, one a sample
        sp_db_png* h = realloc(s->png, sizeof *h * (size_t)s->ds.capacity);
        if (!h) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
        s->png = h;
        s->cap = s->ds.capacity;
    }
    s->png[s->ds.count] = (sp_db_png){png, png_size};
    s->ds.samples[s->ds.count++] = *smp;
    return SP_OK;
}

// A drawing of strokes with no extent (a dot; an ndjson "drawing": []) is
// nothing to train on or show: refused, as classify and pose refuse it.
static sp_result extent_ok(const sp_sample* smp, const char* what, sp_error* err)
{
    const char* why = smp->raster.pixels ? sp_raster_ink_problem(&smp->raster) : sp_sketch_extent_problem(&smp->sketch);
    return why ? sp_fail(err, SP_ERR_INVALID, "%s: %s", what, why) : SP_OK;
}

static sp_result add_file(sketch_set* s, const char* path, const char* category, sp_error* err)
{
    int label = sp_dataset_add_category(&s->ds, category);
    if (label < 0) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    if (has_ext(path, ".ndjson")) {
        sp_dataset tmp = {0};
        sp_result r = sp_dataset_read_ndjson(&tmp, path, -1, err);
        if (r == SP_OK && tmp.count == 0) r = sp_fail(err, SP_ERR_INVALID, "%s: no drawings", path);
        for (int i = 0; r == SP_OK && i < tmp.count; ++i) {
            sp_sample smp = tmp.samples[i];
            smp.label = label;
            char what[2100];
            snprintf(what, sizeof what, "%s: drawing %d", path, i + 1);
            if ((r = extent_ok(&smp, what, err)) == SP_OK && (r = push(s, &smp, NULL, 0, what, err)) == SP_OK)
                memset(&tmp.samples[i], 0, sizeof tmp.samples[i]);
        }
        sp_dataset_free(&tmp);
        return r;
    }
    sp_sample smp = {.label = label};
    sp_result r = sp_drawing_read(path, &smp.sketch, &smp.raster, err);
    if (r != SP_OK) return r;
    if (!smp.raster.pixels && sp_sketch_point_count(&smp.sketch) == 0) {
        sp_sketch_free(&smp.sketch);
        return sp_fail(err, SP_ERR_INVALID, "%s: empty drawing (no strokes)", path);
    }
    if ((r = extent_ok(&smp, path, err)) != SP_OK) {
        sp_sketch_free(&smp.sketch);
        return r;
    }
    void* png = NULL;
    size_t n = 0;
    if (smp.raster.pixels && (r = sp_file_read(path, (size_t)1 << 30, &png, &n, err)) != SP_OK) {
        sp_raster_free(&smp.raster);
        return r;
    }
    if ((r = push(s, &smp, png, n, path, err)) != SP_OK) {
        sp_sketch_free(&smp.sketch);
        sp_raster_free(&smp.raster);
        free(png);
    }
    return r;
}

static bool is_dir(const char* p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

// A labelled folder: DIR/<category>/*.{json,svg,png} and DIR/<category>.ndjson
// (`only`: just that category).
static sp_result add_folder(sketch_set* s, const char* dir, const char* only, sp_error* err)
{
    char** names;
    int n;
    sp_result r = sp_dir_list(dir, &names, &n, err);
    if (r != SP_OK) return r;
    int before = s->ds.count;
    char path[2048];
    for (int i = 0; r == SP_OK && i < n; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        if (is_dir(path)) {
            if (only && strcmp(only, names[i]) != 0) continue;
            char** files;
            int m;
            r = sp_dir_list(path, &files, &m, err);
            for (int j = 0; r == SP_OK && j < m; ++j) {
                char fp[4096];
                snprintf(fp, sizeof fp, "%s/%s", path, files[j]);
                if (has_ext(fp, ".json") || has_ext(fp, ".svg") || has_ext(fp, ".png")) r = add_file(s, fp, names[i], err);
            }
            sp_dir_list_free(files, m);
        } else if (has_ext(names[i], ".ndjson")) {
            char cat[256];
            snprintf(cat, sizeof cat, "%.*s", (int)(strlen(names[i]) - 7), names[i]);
            if (!only || !strcmp(only, cat)) r = add_file(s, path, cat, err);
        }
    }
    sp_dir_list_free(names, n);
    if (r == SP_OK && s->ds.count == before) r = sp_fail(err, SP_ERR_INVALID, "%s: no drawings found%s%s", dir, only ? " for category " : "", only ? only : "");
    return r;
}

// One warning line per stored category that no part of the database has:
// training uses such sketches only once a part of it is added (it reported
// them as unused drawings, and nothing said why). Stored all the same: a
// curator may add the sketches before the part.
static void warn_partless(const char* cmd, sp_db* db, const sp_dataset* ds, const int* per)
{
    char** cats = NULL;
    int n = 0;
    sp_error err = {0};
    if (sp_db_categories(db, &cats, &n, &err) != SP_OK) {
        fprintf(stderr, "%s: warning: %s\n", cmd, err.text);
        return;
    }
    char have[1024] = "";
    for (int i = 0; i < n; ++i) {
        size_t len = strlen(have);
        snprintf(have + len, sizeof have - len, "%s%s", i ? ", " : "", cats[i]);
    }
    for (int k = 0; k < ds->category_count; ++k) {
        bool known = false;
        for (int i = 0; i < n && !known; ++i)
            known = !strcmp(cats[i], ds->categories[k]);
        if (per[k] > 0 && !known)
            fprintf(stderr,
                    "%s: warning: no part of category '%s' in %s (%s%s); its %d sketch%s stored, unused by training until one is "
                    "added\n",
                    cmd, ds->categories[k], sp_db_path(db), n ? "its part categories: " : "it has no parts", have, per[k],
                    per[k] == 1 ? " is" : "es are");
    }
    sp_db_free_strings(cats, n);
}

static int db_add_sketch(int argc, char** argv)
{
    const char* cmd = "sketchpose db add-sketch";
    db_common c = db_common_unset();
    const char* category = NULL;
    const char* source = NULL;
    sp_opt opts[] = {DB_COMMON_OPTS(c),
                     {"--category", SP_OPT_STRING, &category, "C", "category of the drawings (labelled folders name their own)", false},
                     {"--source", SP_OPT_STRING, &source, "S", "curated (default) or kiosk", false}};
    const char* pos[256];
    int npos;
    int rc = parse(
        argc, argv, cmd, &c,
        "add example sketches: JSON strokes, Quick, Draw! .ndjson, SVG, PNG, or labelled folders DIR/<category>/...; all or "
        "nothing",
        opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 1, 256, "FILES...");
    if (rc >= 0) return rc;
    sp_db_source src = SP_DB_SOURCE_CURATED;
    if (source && !strcmp(source, "kiosk")) src = SP_DB_SOURCE_KIOSK;
    else if (source && strcmp(source, "curated") != 0) {
        fprintf(stderr, "%s: --source must be curated or kiosk, got '%s'\n", cmd, sp_text_printable(source, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    if (!sp_cli_check_name(cmd, "--category", category)) return SP_EXIT_USAGE;
    for (int i = 0; i < npos; ++i)
        if (!category && !is_dir(pos[i])) {
            fprintf(stderr, "%s: %s: give --category for drawings outside a labelled folder\n", cmd, pos[i]);
            return SP_EXIT_USAGE;
        }
    sketch_set s = {.kiosk = src == SP_DB_SOURCE_KIOSK};
    sp_error err = {0};
    sp_result r = SP_OK;
    for (int i = 0; r == SP_OK && i < npos; ++i)
        r = is_dir(pos[i]) ? add_folder(&s, pos[i], category, &err) : add_file(&s, pos[i], category, &err);
    int added = 0;
    sp_db* db = NULL;
    bool existed = db_exists(&c);
    if (r == SP_OK) {
        db = open_db(cmd, &c, SP_DB_CREATE);
        if (!db) r = SP_ERR_IO;
        else r = sp_db_add_sketches(db, &s.ds, s.png, src, c.by, &added, &err);
    }
    int exit_code = SP_EXIT_OK;
    if (r != SP_OK) exit_code = db || err.text[0] ? fail(cmd, &err) : SP_EXIT_INPUT;
    else {
        note_created(cmd, &c, existed);
        sp_cli_done("%d sketch%s stored in %s", added, added == 1 ? " is" : "es are", db_path(&c));
        int* per = calloc((size_t)(s.ds.category_count + 1), sizeof(int));
        for (int i = 0; per && i < s.ds.count; ++i)
            per[s.ds.samples[i].label]++;
        if (per) warn_partless(cmd, db, &s.ds, per);
        printf("{\"added\": %d, \"categories\": {", added);
        for (int k = 0; per && k < s.ds.category_count; ++k) {
            printf("%s", k ? ", " : "");
            clf_cli_json_str(stdout, s.ds.categories[k]);
            printf(": %d", per[k]);
        }
        free(per);
        printf("}}\n");
    }
    sp_db_close(db);
    if (exit_code != SP_EXIT_OK) drop_if_unused(&c, existed);
    for (int i = 0; i < s.ds.count; ++i)
        free((void*)s.png[i].bytes);
    free(s.png);
    sp_dataset_free(&s.ds);
    return exit_code;
}

static int db_list(int argc, char** argv)
{
    const char* cmd = "sketchpose db list";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c,
                   "parts (category, vertex and parameter counts), sketch counts per category and models, as JSON", opts,
                   (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 0, "");
    if (rc >= 0) return rc;
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    sp_db_part_info* parts = NULL;
    int n = 0, ncat = 0;
    char** cats = NULL;
    int* counts = NULL;
    char* models = NULL;
    if (sp_db_list_parts(db, &parts, &n, &err) != SP_OK || sp_db_sketch_counts(db, &cats, &counts, &ncat, &err) != SP_OK ||
        sp_db_models_json(db, &models, &err) != SP_OK) {
        free(parts);
        sp_db_free_strings(cats, ncat);
        free(counts);
        sp_db_close(db);
        return fail(cmd, &err);
    }
    printf("{\"db\": ");
    clf_cli_json_str(stdout, sp_db_path(db));
    printf(", \"schema\": %d, \"generation\": %llu, \"parts\": [", sp_db_schema_version(db), (unsigned long long)sp_db_generation(db));
    for (int i = 0; i < n; ++i) {
        printf("%s", i ? ", " : "");
        print_part(&parts[i], false, NULL);
    }
    printf("], \"sketches\": {");
    for (int i = 0; i < ncat; ++i) {
        printf("%s", i ? ", " : "");
        clf_cli_json_str(stdout, cats[i]);
        printf(": %d", counts[i]);
    }
    printf("}, \"models\": %s}\n", models);
    free(parts);
    sp_db_free_strings(cats, ncat);
    free(counts);
    free(models);
    sp_db_close(db);
    return SP_EXIT_OK;
}

static int db_show(int argc, char** argv)
{
    const char* cmd = "sketchpose db show";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c, "one part: summary, parameters, abstractions and its log, as JSON", opts,
                   (int)(sizeof opts / sizeof opts[0]), pos, &npos, 1, 1, "NAME");
    if (rc >= 0) return rc;
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    sp_db_part_info info;
    char *summary = NULL, *log = NULL;
    if (sp_db_part(db, pos[0], &info, &err) != SP_OK || sp_db_part_summary_json(db, pos[0], &summary, &err) != SP_OK ||
        sp_db_log_json(db, pos[0], &log, &err) != SP_OK) {
        free(summary);
        sp_db_close(db);
        return fail(cmd, &err);
    }
    printf("{\"part\": ");
    print_part(&info, false, NULL);
    printf(", \"summary\": %s, \"log\": %s}\n", summary, log);
    free(summary);
    free(log);
    sp_db_close(db);
    return SP_EXIT_OK;
}

// What a removal leaves the kiosk, said on stderr: a category no part has
// now that the newest model still knows (its strokes became another part,
// with nothing offered, until a retrain), and a dragon without a body to
// hang its parts on (an outside curator review).
static void note_after_remove(const char* cmd, sp_db* db, const char* category)
{
    char** cats = NULL;
    int n = 0;
    char* models = NULL;
    sp_error e = {0};
    if (sp_db_categories(db, &cats, &n, &e) != SP_OK) return;
    bool left = false;
    for (int i = 0; i < n; ++i)
        left = left || !strcmp(cats[i], category);
    sp_db_free_strings(cats, n);
    if (left) return;
    if (sp_db_models_json(db, &models, &e) == SP_OK) {
        cJSON* m = cJSON_Parse(models);
        const cJSON* known = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(m, 0), "categories");
        const cJSON* it;
        bool knows = false;
        cJSON_ArrayForEach(it, known) knows = knows || (cJSON_IsString(it) && !strcmp(it->valuestring, category));
        if (knows)
            fprintf(stderr,
                    "%s: no part of category %s is left, and the newest model still knows it: run `sketchpose db train`\n", cmd,
                    category);
        cJSON_Delete(m);
        free(models);
    }
    if (!strcmp(category, "torso"))
        fprintf(stderr,
                "%s: no body (category torso) is left: the kiosk's parts will hang free, and no stroke can make the body it asks "
                "for\n",
                cmd);
}

static int db_remove(int argc, char** argv)
{
    const char* cmd = "sketchpose db remove";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c, "remove a part and its synthetic sketches (curated sketches stay)", opts,
                   (int)(sizeof opts / sizeof opts[0]), pos, &npos, 1, 1, "NAME");
    if (rc >= 0) return rc;
    sp_db* db = open_db(cmd, &c, 0);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    sp_db_part_info gone;
    sp_result r = sp_db_part(db, pos[0], &gone, &err);
    if (r == SP_OK) r = sp_db_remove_part(db, pos[0], c.by, &err);
    if (r == SP_OK) note_after_remove(cmd, db, gone.category);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    sp_cli_done("part %s is removed from %s", pos[0], db_path(&c));
    printf("{\"removed\": ");
    clf_cli_json_str(stdout, pos[0]);
    printf("}\n");
    return SP_EXIT_OK;
}

static int db_check(int argc, char** argv)
{
    const char* cmd = "sketchpose db check";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(
        argc, argv, cmd, &c,
        "SQLite integrity and foreign keys, every part loads and matches its checksum, every sketch parses, the newest model "
        "matches the part categories; JSON; exit 1 on any problem",
        opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 0, "");
    if (rc >= 0) return rc;
    // Writable, so that an older schema gets migrated; read-only where this
    // user may not write it (another user's file, read-only media): a check
    // only reads, and was refused there as "the database is read-only".
    char* dir = sp_path_folder(db_path(&c));
    bool ro = access(db_path(&c), W_OK) != 0 || (dir && access(dir, W_OK) != 0);
    free(dir);
    sp_db* db = open_db(cmd, &c, ro ? SP_DB_READONLY : 0);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    bool ok = false;
    char* json = NULL;
    sp_result r = sp_db_check(db, &ok, &json, &err);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    printf("%s\n", json);
    free(json);
    if (!ok) fprintf(stderr, "%s: problems found (see \"problems\")\n", cmd);
    return ok ? SP_EXIT_OK : SP_EXIT_INPUT;
}

static int db_train(int argc, char** argv)
{
    const char* cmd = "sketchpose db train";
    db_common c = db_common_unset();
    int folds = SP_CLI_UNSET; // not given: the library's 3 (folds_opt)
    int curated_max = SP_CLI_UNSET, keep_models = SP_CLI_UNSET;
    clf_cli_opts o = clf_cli_opts_unset();
    sp_opt opts[] = {
        DB_COMMON_OPTS(c),
        {"--folds", SP_OPT_INT, &folds, "K", "cross-validation folds for the report, 2..100 (default 3; -1 or 0: none)", false},
        {"--curated-max", SP_OPT_INT, &curated_max, "N",
         "curated sketches per category to train on, spread over those stored, 1..1000000 (default 400; -1: all)", false},
        {"--keep-models", SP_OPT_INT, &keep_models, "N",
         "models kept, the new one and the newest before it; older ones are removed, 1..1000000 (default 3; -1: all)", false},
        CLF_CLI_OPTS(o)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c,
                   "rebuild the classifier from the stored sketches of the current part categories; store it with its report",
                   opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 0, "");
    if (rc >= 0) return rc;
    if (!clf_cli_check(cmd, &o) || !folds_opt(cmd, &folds) || !all_or_count_opt(cmd, "--curated-max", &curated_max) ||
        !all_or_count_opt(cmd, "--keep-models", &keep_models))
        return SP_EXIT_USAGE;
    sp_db* db = open_db(cmd, &c, 0);
    if (!db) return SP_EXIT_INPUT;
    sp_db_train_desc td = {
        .clf = clf_cli_desc(&o), .folds = folds, .by = c.by, .curated_max = curated_max, .keep_models = keep_models};
    if (clf_cli_tty()) td.clf.progress = clf_cli_progress;
    sp_error err = {0};
    char* report = NULL;
    sp_result r = sp_db_train(db, &td, &report, &err);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    sp_cli_done("the new model is stored in %s", db_path(&c));
    cJSON* rj = cJSON_Parse(report);
    const cJSON* left = cJSON_GetObjectItemCaseSensitive(rj, "curated_left_out");
    long n_left = cJSON_IsNumber(left) ? (long)left->valuedouble : 0;
    cJSON_Delete(rj);
    if (n_left > 0)
        fprintf(
            stderr,
            "%s: %ld curated sketches left out of training: at most %d a category, spread over those stored (--curated-max)\n",
            cmd, n_left, curated_max > 0 ? curated_max : SP_DB_CURATED_TRAIN_MAX);
    printf("%s\n", report);
    free(report);
    return SP_EXIT_OK;
}

static int db_export(int argc, char** argv)
{
    const char* cmd = "sketchpose db export";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c,
                   "write DIR/parts/*.glb, DIR/sketches/<category>/* and DIR/manifest.json (what `db init --from DIR` reads); "
                   "DIR new or empty, written whole or not at all",
                   opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 1, 1, "DIR");
    if (rc >= 0) return rc;
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    sp_result r = sp_db_export(db, pos[0], &err);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    printf("{\"exported\": ");
    clf_cli_json_str(stdout, pos[0]);
    printf("}\n");
    return SP_EXIT_OK;
}

static int db_log(int argc, char** argv)
{
    const char* cmd = "sketchpose db log";
    db_common c = db_common_unset();
    sp_opt opts[] = {DB_COMMON_OPTS(c)};
    const char* pos[1];
    int npos;
    int rc = parse(argc, argv, cmd, &c, "the curator log (append-only), oldest first, as JSON; NAME: only entries about it", opts,
                   (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 1, "[NAME]");
    if (rc >= 0) return rc;
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_error err = {0};
    char* json = NULL;
    sp_result r = sp_db_log_json(db, npos ? pos[0] : NULL, &json, &err);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    printf("%s\n", json);
    free(json);
    return SP_EXIT_OK;
}

// ---- review: visitors' strokes collected by the kiosk -----------------------------------

static void print_kiosk_sketch(const sp_db_kiosk_sketch* k)
{
    printf("{\"id\": %lld, \"category\": ", (long long)k->id);
    clf_cli_json_str(stdout, k->category);
    printf(", \"status\": \"%s\", \"created_at\": ", sp_db_status_name(k->status));
    clf_cli_json_str(stdout, k->created_at);
    printf(", \"points\": [");
    const sp_stroke* st = k->sketch.stroke_count > 0 ? &k->sketch.strokes[0] : NULL;
    for (int i = 0; st && i < st->count; ++i)
        printf("%s[%.6g, %.6g]", i ? ", " : "", st->points[i].x, st->points[i].y);
    printf("]");
    if (st && st->t) {
        printf(", \"t\": [");
        for (int i = 0; i < st->count; ++i)
            printf("%s%.6g", i ? ", " : "", st->t[i]);
        printf("]");
    }
    printf("}");
}

// One positive id at *s, up to `stop` ('\0' or '-'); *s moves past it.
static bool parse_id(const char** s, char stop, int64_t* id)
{
    char* end = NULL;
    errno = 0;
    long long x = isdigit((unsigned char)**s) ? strtoll(*s, &end, 10) : 0;
    if (!end || *end != stop || x <= 0 || errno == ERANGE) return false;
    *id = x;
    *s = end + (stop != 0);
    return true;
}

// Reads the values of --approve/--reject/--relabel: ids (positive integers)
// and, unless ranges is NULL, FIRST-LAST ranges; else one line and false.
static bool parse_ids(const char* cmd, const sp_str_list* l, int count, int64_t* ids, int* n, sp_db_kiosk_range* ranges, int* nr)
{
    *n = 0;
    if (nr) *nr = 0;
    for (int i = 0; i < count; ++i) {
        const char* v = l->items[i];
        const char* s = v;
        sp_db_kiosk_range g;
        if (parse_id(&s, 0, &ids[*n])) {
            ++*n;
        } else if (ranges && parse_id(&s, '-', &g.first) && parse_id(&s, 0, &g.last) && g.first <= g.last) {
            ranges[(*nr)++] = g;
        } else {
            char shown[128];
            fprintf(stderr, "%s: '%s' is not a kiosk sketch id (a positive number)%s; nothing was changed\n", cmd,
                    sp_text_printable(v, shown, sizeof shown), ranges ? " or a range of them (FIRST-LAST, FIRST <= LAST)" : "");
            return false;
        }
    }
    return true;
}

// db review's actions: --approve, --reject (ids and ranges), --relabel ID
// CATEGORY, --delete-rejected; all or nothing, the result as JSON.
static int review_act(const char* cmd, const db_common* c, const sp_str_list* approve, const sp_str_list* reject,
                      const sp_str_list* relabel, bool delete_rejected)
{
    sp_error err = {0};
    const sp_str_list* l = approve->count ? approve : reject->count ? reject : relabel;
    int64_t ids[256], *changed = NULL;
    sp_db_kiosk_range ranges[256];
    int n = 0, nr = 0, m = 0;
    // A malformed id is a malformed option value: bad usage, as a number out of its range (an unknown id is bad input).
    if (!delete_rejected && !parse_ids(cmd, l, relabel->count ? 1 : l->count, ids, &n, relabel->count ? NULL : ranges, &nr))
        return SP_EXIT_USAGE;
    sp_db* db = open_db(cmd, c, 0);
    if (!db) return SP_EXIT_INPUT;
    sp_result r = delete_rejected  ? sp_db_kiosk_delete_rejected(db, c->by, &m, &err)
                  : relabel->count ? sp_db_kiosk_relabel(db, ids[0], relabel->items[1], c->by, &err)
                                   : sp_db_kiosk_review(db, ids, n, ranges, nr, approve->count ? SP_DB_APPROVED : SP_DB_REJECTED,
                                                        c->by, &changed, &m, &err);
    sp_db_close(db);
    if (r != SP_OK) return fail(cmd, &err);
    sp_cli_done("the review is stored in %s", db_path(c));
    if (delete_rejected) {
        printf("{\"deleted\": %d}\n", m);
    } else if (relabel->count) {
        printf("{\"relabelled\": %lld, \"category\": ", (long long)ids[0]);
        clf_cli_json_str(stdout, relabel->items[1]);
        printf("}\n");
    } else {
        printf("{\"%s\": [", approve->count ? "approved" : "rejected");
        for (int i = 0; i < m; ++i)
            printf("%s%lld", i ? ", " : "", (long long)changed[i]);
        printf("]}\n");
    }
    free(changed);
    return SP_EXIT_OK;
}

static int db_review(int argc, char** argv)
{
    const char* cmd = "sketchpose db review";
    db_common c = db_common_unset();
    const char *status = NULL, *sheet = NULL;       // status NULL: pending
    int limit = SP_CLI_UNSET, after = SP_CLI_UNSET; // not given: 100, 0
    sp_str_list approve = {0}, reject = {0}, relabel = {0};
    bool delete_rejected = false;
    sp_opt opts[] = {
        DB_COMMON_OPTS(c),
        {"--status", SP_OPT_STRING, &status, "S", "which to list: pending (default), approved, rejected or all", false},
        {"--limit", SP_OPT_INT, &limit, "N", "list at most N, oldest first (default 100; 0: all)", false},
        {"--after", SP_OPT_INT, &after, "ID", "list only ids above ID (the next page: the last id shown)", false},
        {"--sheet", SP_OPT_OUT, &sheet, "out.png", "also draw the listed sketches as a labelled contact sheet", false},
        {"--approve", SP_OPT_LIST, &approve, "ID...",
         "approve these kiosk sketches (`db train` uses approved ones); FIRST-LAST: the pending ones from FIRST to LAST", false},
        {"--reject", SP_OPT_LIST, &reject, "ID...",
         "reject these kiosk sketches (kept, never trained on); FIRST-LAST: the pending ones from FIRST to LAST", false},
        {"--relabel", SP_OPT_LIST, &relabel, "ID CATEGORY", "give a kiosk sketch another part category", false},
        {"--delete-rejected", SP_OPT_FLAG, &delete_rejected, NULL,
         "delete every rejected kiosk sketch (later strokes reuse their room in the file, which does not shrink)", false}};
    const char* pos[1];
    int npos;
    int rc =
        parse(argc, argv, cmd, &c,
              "the visitors' strokes the kiosk collected: list them as JSON (pending ones by default, oldest first), draw them, "
              "approve, reject, relabel or delete them; an unknown id changes nothing",
              opts, (int)(sizeof opts / sizeof opts[0]), pos, &npos, 0, 0, "");
    if (rc >= 0) return rc;
    if (!sp_cli_check_out(cmd, "--sheet", sheet, SP_CLI_OUT_PNG)) return SP_EXIT_USAGE;
    int actions = (approve.count > 0) + (reject.count > 0) + (relabel.count > 0) + delete_rejected;
    // The listing's options were ignored by an action.
    const char* listing = status ? "--status" : limit != SP_CLI_UNSET ? "--limit" : after != SP_CLI_UNSET ? "--after" : NULL;
    if (actions && listing) {
        fprintf(stderr,
                "%s: %s chooses what is listed; it does not apply to --approve, --reject, --relabel or --delete-rejected\n", cmd,
                listing);
        return SP_EXIT_USAGE;
    }
    if (!status) status = "pending";
    if (limit == SP_CLI_UNSET) limit = 100;
    if (after == SP_CLI_UNSET) after = 0;
    if (limit < 0 || after < 0) {
        fprintf(stderr, "%s: %s must not be negative, got %d\n", cmd, limit < 0 ? "--limit" : "--after",
                limit < 0 ? limit : after);
        return SP_EXIT_USAGE;
    }
    // Said for what was given (one message for all three read as if no
    // action had been given; an outside review).
    if (relabel.count && relabel.count != 2) {
        fprintf(stderr, "%s: --relabel takes one id and its new category (--relabel ID CATEGORY), got %d value%s\n", cmd,
                relabel.count, relabel.count == 1 ? "" : "s");
        return SP_EXIT_USAGE;
    }
    if (actions > 1 || (actions && sheet)) {
        fprintf(stderr,
                "%s: %s: one action at a time, --approve ID..., --reject ID..., --relabel ID CATEGORY or --delete-rejected, "
                "and not with --sheet (which draws the listing)\n",
                cmd, actions > 1 ? "more than one action given" : "an action with --sheet");
        return SP_EXIT_USAGE;
    }
    unsigned mask = 0;
    for (int i = 0; i < SP_DB_STATUS_COUNT; ++i)
        if (!strcmp(status, sp_db_status_name((sp_db_status)i))) mask = 1u << i;
    if (!strcmp(status, "all")) mask = (1u << SP_DB_STATUS_COUNT) - 1;
    if (!mask) {
        fprintf(stderr, "%s: --status must be pending, approved, rejected or all, got '%s'\n", cmd,
                sp_text_printable(status, (char[160]){0}, 160));
        return SP_EXIT_USAGE;
    }
    if (relabel.count == 2 && !sp_cli_check_name(cmd, "--relabel's CATEGORY", relabel.items[1])) return SP_EXIT_USAGE;
    if (actions) return review_act(cmd, &c, &approve, &reject, &relabel, delete_rejected);
    sp_error err = {0};
    if (!sp_cli_check_out_folders(cmd, opts, (int)(sizeof opts / sizeof opts[0]))) return SP_EXIT_INPUT;
    sp_db* db = open_db(cmd, &c, SP_DB_READONLY);
    if (!db) return SP_EXIT_INPUT;
    sp_db_kiosk_sketch* ks = NULL;
    int listed = 0, counts[SP_DB_STATUS_COUNT];
    // One more than a page, to know whether this page is the last (next_after null).
    int ask = limit > 0 && limit < INT_MAX ? limit + 1 : limit;
    if (sp_db_kiosk_counts(db, counts, &err) != SP_OK ||
        sp_db_kiosk_list(db, &(sp_db_kiosk_query){.statuses = mask, .limit = ask, .after = after}, &ks, &listed, &err) != SP_OK) {
        sp_db_close(db);
        return fail(cmd, &err);
    }
    sp_db_close(db);
    if (counts[SP_DB_PENDING] >= SP_DB_KIOSK_PENDING_MAX)
        fprintf(stderr,
                "%s: note: %d kiosk sketches await review, the most a kiosk keeps: it keeps no new strokes until some are "
                "approved or rejected\n",
                cmd, counts[SP_DB_PENDING]);
    bool more = limit > 0 && listed > limit;
    int n = more ? limit : listed;
    int code = SP_EXIT_OK;
    if (sheet) {
        sp_sheet_item* items = calloc((size_t)(n > 0 ? n : 1), sizeof *items);
        char(*labels)[96] = calloc((size_t)(n > 0 ? n : 1), sizeof *labels);
        char(*notes)[96] = calloc((size_t)(n > 0 ? n : 1), sizeof *notes);
        for (int i = 0; items && labels && notes && i < n; ++i) {
            snprintf(labels[i], sizeof labels[i], "%lld %s", (long long)ks[i].id, ks[i].category);
            // "pending 12-02 04:44": month, day and time of the UTC created_at, to fit the cell.
            const char* at = strlen(ks[i].created_at) >= 16 ? ks[i].created_at : "0000-00-00T00:00";
            snprintf(notes[i], sizeof notes[i], "%s %.5s %.5s", sp_db_status_name(ks[i].status), at + 5, at + 11);
            items[i] = (sp_sheet_item){.sketch = &ks[i].sketch, .label = labels[i], .note = notes[i]};
        }
        char title[160];
        snprintf(title, sizeof title, "%s kiosk sketches, oldest first (%d shown)", status, n);
        if (!items || !labels || !notes)
            code = fail(cmd, &(sp_error){.text = "out of memory"});
        else if (n == 0)
            fprintf(stderr, "%s: no kiosk sketches listed (--status %s): no sheet written\n", cmd, status);
        else if (sp_sheet_write_png(items, n, &(sp_sheet_desc){.title = title}, sheet, &err) != SP_OK)
            code = fail(cmd, &err);
        free(items);
        free(labels);
        free(notes);
    }
    if (code == SP_EXIT_OK) {
        printf("{\"sketches\": [");
        for (int i = 0; i < n; ++i) {
            printf("%s", i ? ", " : "");
            print_kiosk_sketch(&ks[i]);
        }
        printf("], \"counts\": {\"pending\": %d, \"approved\": %d, \"rejected\": %d}, \"next_after\": ", counts[SP_DB_PENDING],
               counts[SP_DB_APPROVED], counts[SP_DB_REJECTED]);
        if (more)
            printf("%lld}\n", (long long)ks[n - 1].id);
        else
            printf("null}\n");
    }
    sp_db_kiosk_free(ks, listed);
    return code;
}

typedef struct db_sub {
    const char* name;
    int (*run)(int, char**);
    const char* help;
} db_sub;

static const db_sub k_subs[] = {
    {"init", db_init, "create the default database from assets/, or rebuild one with --from DIR"},
    {"add-part", db_add_part, "validate and store a rigged part (PART.glb) with synthetic sketches"},
    {"add-sketch", db_add_sketch, "store example sketches (JSON, ndjson, SVG, PNG, labelled folders)"},
    {"list", db_list, "parts, sketch counts and models (JSON)"},
    {"show", db_show, "one part with its parameters, abstractions and log (JSON)"},
    {"remove", db_remove, "remove a part"},
    {"check", db_check, "integrity and consistency checks (JSON; exit 1 on problems)"},
    {"train", db_train, "retrain the classifier from the stored sketches"},
    {"export", db_export, "write the parts and sketches to a folder"},
    {"log", db_log, "the curator log (JSON)"},
    {"review", db_review, "the visitors' strokes the kiosk collected: list, draw, approve, reject, relabel"},
};

static void db_usage(FILE* f)
{
    fprintf(f, "usage: sketchpose db <subcommand> [--db PATH] [options]   (sketchpose db <subcommand> --help for details)\n\n"
               "The curators' part database. PATH defaults to $SP_DB, else ./sketchpose.db.\n\nsubcommands:\n");
    for (size_t i = 0; i < sizeof k_subs / sizeof k_subs[0]; ++i)
        fprintf(f, "  %-11s %s\n", k_subs[i].name, k_subs[i].help);
}

int cmd_db(int argc, char** argv)
{
    if (argc < 2) {
        db_usage(stderr);
        return SP_EXIT_USAGE;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        db_usage(stdout);
        return SP_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof k_subs / sizeof k_subs[0]; ++i)
        if (!strcmp(argv[1], k_subs[i].name)) return k_subs[i].run(argc - 1, argv + 1);
    fprintf(stderr, "sketchpose db: unknown subcommand '%s' (try sketchpose db --help)\n", argv[1]);
    return SP_EXIT_USAGE;
}
