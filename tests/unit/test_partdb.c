// Part database tests: round trips (add, list, remove, retrain, export and
// rebuild), a curator-added category recognised after training, crash safety
// (SIGKILL during add-part and train, many times), two writers, read-only
// files and a full disk, schema migrations, malformed input that must leave
// the file untouched, and the generation counter a kiosk polls.
//
// The parts are fixture rigs (tests/support/fixtures.h) saved as GLB with an
// sp_part category, so the test does not depend on assets/.
// `test_partdb --write-parts DIR` writes them for trying the CLI by hand.
#define _XOPEN_SOURCE 700 // nftw
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "db_internal.h"
#include "fixtures.h"
#include "mini_gltf.h"
#include "sp/clock.h"
#include "sp/concept.h"
#include "sp/handdraw.h"
#include "sp/partdb.h"
#include "sp/sketch_io.h"
#include "sp/synth.h"
#include "test.h"

// ---- helpers -----------------------------------------------------------------

typedef struct fixture_part {
    const char* name;
    const char* category;
    int joints;
    bool branching;
    uint64_t seed;
} fixture_part;

static const fixture_part k_parts[] = {
    {"tail_a", "tail", 5, false, 1},
    {"wings_a", "wings", 6, true, 2},
    {"horns_a", "horns", 8, true, 5},
    {"tail_b", "tail", 5, false, 7},
};

static void write_part(const fixture_part* fp, const char* path)
{
    sp_rig rig;
    sp_fixture_tree_rig(&(sp_fixture_desc){.joint_count = fp->joints, .branching = fp->branching, .seed = fp->seed, .rings_per_bone = 4,
                                           .ring_vertices = 8},
                        &rig);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_character_from_rig(&rig, &ch, &err) == SP_OK);
    ch.has_part = true;
    snprintf(ch.part.category, sizeof ch.part.category, "%s", fp->category);
    sp_result r = sp_gltf_save(&ch, NULL, path, &err);
    if (r != SP_OK) fprintf(stderr, "  %s\n", err.text);
    ENSURE(r == SP_OK);
    sp_character_free(&ch);
}

// Fixture part i as a file in the build's tmp folder (written once).
static const char* part_file(int i)
{
    static char paths[4][1024];
    if (!paths[i][0]) {
        char name[64];
        snprintf(name, sizeof name, "%s.glb", k_parts[i].name);
        snprintf(paths[i], sizeof paths[i], "%s", sp_test_tmp_path(name));
        write_part(&k_parts[i], paths[i]);
    }
    return paths[i];
}

// n synthetic sketches of stored part `part` (seed 77), labelled `category`.
static sp_dataset synth_as(sp_db* db, const char* part, int n, const char* category)
{
    sp_dataset ds = {0};
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_db_load_part(db, part, &ch, &err) == SP_OK);
    ENSURE(db_synth_sketches(&ch, 0, n, 77, 0, &ds, &err) == SP_OK);
    sp_character_free(&ch);
    free(ds.categories[0]);
    ds.categories[0] = strdup(category);
    return ds;
}

static sp_db* open_ok(const char* path, unsigned flags)
{
    sp_db* db = NULL;
    sp_error err = {0};
    sp_result r = sp_db_open(path, flags, &db, &err);
    if (r != SP_OK) fprintf(stderr, "  open: %s\n", err.text);
    ENSURE(r == SP_OK);
    return db;
}

static void add_ok(sp_db* db, int i, int synth)
{
    sp_error err = {0};
    sp_db_part_info info;
    sp_result r = sp_db_add_part_file(db, part_file(i), &(sp_db_part_desc){.name = k_parts[i].name, .synth_sketches = synth, .seed = (uint64_t)i + 1}, &info, &err);
    if (r != SP_OK) fprintf(stderr, "  add-part: %s\n", err.text);
    ENSURE(r == SP_OK);
    ENSURE(!strcmp(info.category, k_parts[i].category));
}

// Small vocabulary: training in well under a second on the test's few hundred drawings.
static sp_db_train_desc quick_train(int folds)
{
    return (sp_db_train_desc){.clf = {.words = 64, .vocab_samples = 6000, .threads = 2}, .folds = folds, .by = "test"};
}

static void train_ok(sp_db* db, int folds, char** report)
{
    sp_error err = {0};
    sp_db_train_desc td = quick_train(folds);
    sp_result r = sp_db_train(db, &td, report, &err);
    if (r != SP_OK) fprintf(stderr, "  train: %s\n", err.text);
    ENSURE(r == SP_OK);
}

static void check_ok(sp_db* db)
{
    bool ok = false;
    char* json = NULL;
    sp_error err = {0};
    ENSURE(sp_db_check(db, &ok, &json, &err) == SP_OK);
    if (!ok) fprintf(stderr, "  check: %s\n", json);
    free(json);
    ENSURE(ok);
}

static int scalar(const char* path, const char* sql)
{
    sqlite3* h;
    ENSURE(sqlite3_open_v2(path, &h, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK);
    sqlite3_stmt* st;
    ENSURE(sqlite3_prepare_v2(h, sql, -1, &st, NULL) == SQLITE_OK);
    ENSURE(sqlite3_step(st) == SQLITE_ROW);
    int v = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(h);
    return v;
}

static void file_sha(const char* path, char hex[65])
{
    void* b;
    size_t n;
    sp_error err = {0};
    ENSURE(db_read_file(path, &b, &n, &err) == SP_OK);
    ENSURE(sp_sha256_hex(b, n, hex));
    free(b);
}

static void copy_file(const char* from, const char* to)
{
    FILE* a = fopen(from, "rb");
    FILE* b = fopen(to, "wb");
    ENSURE(a && b);
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, a)) > 0)
        ENSURE(fwrite(buf, 1, n, b) == n);
    fclose(a);
    ENSURE(fclose(b) == 0);
}

// A database with tail_a and wings_a (30 synthetic sketches each), trained,
// as a fresh file `name`. Built once a run and copied: every case starts
// from the same file, and the build is the slow part under the sanitizers.
static const char* base_db(const char* name)
{
    static char built[1024];
    if (!built[0]) {
        const char* b = sp_test_tmp_path("base_built.db");
        sp_fixture_remove_db(b);
        sp_db* db = open_ok(b, SP_DB_CREATE);
        add_ok(db, 0, 30);
        add_ok(db, 1, 30);
        train_ok(db, -1, NULL);
        sp_db_close(db);
        char wal[1100];
        snprintf(wal, sizeof wal, "%s-wal", b);
        ENSURE(access(wal, F_OK) != 0); // closed whole: the one file holds it all
        snprintf(built, sizeof built, "%s", b);
    }
    const char* path = sp_test_tmp_path(name);
    sp_fixture_remove_db(path);
    copy_file(built, path);
    return path;
}

static const char* sketchpose_bin(void)
{
    static char b[1024];
    snprintf(b, sizeof b, "%s/app/sketchpose", SP_BINARY_DIR);
    return access(b, X_OK) == 0 ? b : NULL;
}

// `sketchpose db train` on the database at p, quickly (no folds, 64 words),
// with `more` (options, redirections) appended; its exit status, what it
// printed in out. Skips the test when the command is not built.
static int quick_train_cli(const char* p, const char* more, char* out, size_t size)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' db train --db '%s' --folds -1 --words 64 %s", bin, p, more);
    return sp_fixture_run(cmd, out, size);
}

// ---- tests ---------------------------------------------------------------------------

static void test_sha256(void)
{
    char h[65];
    ENSURE(sp_sha256_hex("", 0, h));
    ENSURE(!strcmp(h, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"));
    ENSURE(sp_sha256_hex("abc", 3, h));
    ENSURE(!strcmp(h, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));
    const char* m = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"; // 56 bytes: two padding blocks
    ENSURE(sp_sha256_hex(m, strlen(m), h));
    ENSURE(!strcmp(h, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"));
}

// Scratch paths for an export test named `stem`: its database, the one
// rebuilt from the export, and the export's folder; none of them there.
static void fresh_export(const char* stem, char p[1024], char p2[1024], char dir[1024])
{
    char name[128], cmd[1100];
    snprintf(name, sizeof name, "%s.db", stem);
    snprintf(p, 1024, "%s", sp_test_tmp_path(name));
    snprintf(name, sizeof name, "%s_rebuilt.db", stem);
    snprintf(p2, 1024, "%s", sp_test_tmp_path(name));
    snprintf(name, sizeof name, "%s_export", stem);
    snprintf(dir, 1024, "%s", sp_test_tmp_path(name));
    sp_fixture_remove_db(p);
    sp_fixture_remove_db(p2);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ENSURE(system(cmd) == 0);
}

// An export killed midway leaves "<DIR>.partial-<pid>-<k>" beside DIR (a
// full copy of the database, seen by an outside curator review): the next
// export to DIR removes those of a process that runs no more, and leaves a
// running one's (this process's) and anything else named like it.
static void test_export_clears_stopped(void)
{
    char p[1024], p2[1024], dir[1024], left[1200], live[1200], other[1200], file[1300];
    fresh_export("exstop", p, p2, dir);
    pid_t child = fork();
    if (child == 0) _exit(0);
    ENSURE(child > 0 && waitpid(child, NULL, 0) == child); // a pid that runs no more
    snprintf(left, sizeof left, "%s.partial-%ld-0", dir, (long)child);
    snprintf(live, sizeof live, "%s.partial-%ld-7", dir, (long)getpid());
    snprintf(other, sizeof other, "%s.partial-%ld-0x", dir, (long)child);
    const char* made[] = {left, live, other};
    for (int i = 0; i < 3; ++i) {
        ENSURE(mkdir(made[i], 0777) == 0);
        snprintf(file, sizeof file, "%s/manifest.json", made[i]);
        FILE* f = fopen(file, "wb");
        ENSURE(f && fputs("{}", f) >= 0 && fclose(f) == 0);
    }
    sp_db* db = open_ok(p, SP_DB_CREATE);
    add_ok(db, 1, 5);
    sp_error err = {0};
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    ENSURE(access(left, F_OK) != 0);
    ENSURE(access(live, F_OK) == 0 && access(other, F_OK) == 0);
    for (int i = 1; i < 3; ++i)
        sp_dir_remove_tree(made[i]);
    sp_dir_remove_tree(dir);
    sp_fixture_remove_db(p);
}

// A part stored as the self-contained .gltf it was added from is exported
// under a .gltf name (an outside curator review: parts/NAME.glb held JSON,
// which tools that go by the name read as binary), and the export rebuilds.
static void test_export_gltf_named(void)
{
    char p[1024], dir[1024], gltf[1024], file[1200], p2[1024];
    fresh_export("exgltf", p, p2, dir);
    snprintf(gltf, sizeof gltf, "%s", sp_test_tmp_path("text_part.gltf"));
    write_part(&k_parts[0], gltf);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    sp_error err = {0};
    ENSURE(sp_db_add_part_file(db, gltf, &(sp_db_part_desc){.name = "text_part", .synth_sketches = 5}, NULL, &err) == SP_OK);
    add_ok(db, 1, 5);
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    snprintf(file, sizeof file, "%s/parts/text_part.gltf", dir);
    FILE* f = fopen(file, "rb");
    ENSURE(f && fgetc(f) == '{');
    fclose(f);
    snprintf(file, sizeof file, "%s/parts/text_part.glb", dir);
    ENSURE(access(file, F_OK) != 0);
    snprintf(file, sizeof file, "%s/parts/%s.glb", dir, k_parts[1].name); // a GLB stays one
    f = fopen(file, "rb");
    char magic[4] = {0};
    ENSURE(f && fread(magic, 1, 4, f) == 4 && !memcmp(magic, "glTF", 4));
    fclose(f);
    snprintf(file, sizeof file, "%s/manifest.json", dir);
    static char manifest[1 << 20];
    f = fopen(file, "rb");
    ENSURE(f);
    manifest[fread(manifest, 1, sizeof manifest - 1, f)] = 0;
    fclose(f);
    ENSURE(strstr(manifest, "\"parts/text_part.gltf\""));
    // A manifest whose "sketches" is given twice (an edit by hand) is refused
    // naming the key: cJSON kept the first, the second list silently lost.
    char* open_brace = strchr(manifest, '{');
    ENSURE(open_brace);
    f = fopen(file, "wb");
    ENSURE(f && fprintf(f, "{\"sketches\": [], %s", open_brace + 1) > 0 && fclose(f) == 0);
    sp_db_train_desc td = quick_train(-1);
    err = (sp_error){0};
    ENSURE(sp_db_create_from_export(p2, dir, &td, "test", &err) != SP_OK && strstr(err.text, "key \"sketches\" given twice"));
    fprintf(stderr, "  %s\n", err.text);
    // A sketch's source or review status of no known kind is refused naming
    // the entry (a typo was stored as curated; a bad status failed in SQL).
    const char* kinds[2][2] = {{"\"source\": \"", "sythetic"}, {"\"source\": \"", "kiosk\", \"status\": \"bogus"}};
    for (int k = 0; k < 2; ++k) {
        char* at = strstr(manifest, kinds[k][0]);
        ENSURE(at);
        char* value_end = strchr(at + strlen(kinds[k][0]), '"');
        f = fopen(file, "wb");
        ENSURE(f && fprintf(f, "%.*s%s%s", (int)(at - manifest + strlen(kinds[k][0])), manifest, kinds[k][1], value_end) > 0 &&
               fclose(f) == 0);
        err = (sp_error){0};
        ENSURE(sp_db_create_from_export(p2, dir, &td, "test", &err) != SP_OK &&
               strstr(err.text, k ? "status 'bogus' is not pending" : "source 'sythetic' is not synthetic"));
        fprintf(stderr, "  %s\n", err.text);
    }
    f = fopen(file, "wb");
    ENSURE(f && fputs(manifest, f) >= 0 && fclose(f) == 0);
    ENSURE(sp_db_create_from_export(p2, dir, &td, "test", &err) == SP_OK);
    ENSURE(scalar(p2, "SELECT count(*) FROM parts") == 2);
}

// A database on a read-only file system (an SD card, a squashfs image, a
// read-only mount) is read as an immutable file, as one in a folder the user
// may not write (SQLite cannot open it there at all: every reader, the
// kiosk too, failed with "unable to open database file"); one to be
// created there, or in a folder that is not there, says so (it said "cannot
// open (No such file or directory)": SQLite's retry had set errno). The
// read-only mount is made in a mount namespace of its own (unshare); where
// this user may not make one, that part is skipped.
static void test_read_only_file_system(void)
{
    char dir[1024], ro[1100], p[1200], cmd[8192], out[4096];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("rofs_src"));
    snprintf(ro, sizeof ro, "%s", sp_test_tmp_path("rofs"));
    mkdir(dir, 0755), mkdir(ro, 0755);
    snprintf(p, sizeof p, "%s/parts.db", dir);
    sp_fixture_remove_db(p);
    sp_db_close(open_ok(p, SP_DB_CREATE));
    sp_db* db = NULL;
    sp_error err = {0};
    snprintf(p, sizeof p, "%s/nowhere/parts.db", dir);
    ENSURE(sp_db_open(p, SP_DB_CREATE, &db, &err) == SP_ERR_IO && strstr(err.text, "nowhere is not there"));
    fprintf(stderr, "  %s\n", err.text);
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    snprintf(cmd, sizeof cmd, "unshare -m sh -c \"mount --bind '%s' '%s' && mount -o remount,ro,bind '%s'\" 2>/dev/null", dir, ro,
             ro);
    if (system(cmd) != 0) SKIP("no mount namespace for this user (unshare -m)");
    snprintf(cmd, sizeof cmd,
             "unshare -m sh -c \"mount --bind '%s' '%s' && mount -o remount,ro,bind '%s' && '%s' db list --db '%s/parts.db' && "
             "'%s' db init --db '%s/new.db' --folds 0\" 2>&1",
             dir, ro, ro, bin, ro, bin, ro);
    int rc = sp_fixture_run(cmd, out, sizeof out);
    fprintf(stderr, "  exit %d: %s", rc, out);
    ENSURE(rc == 1 && strstr(out, "\"schema\": 3") && strstr(out, "new.db: cannot create it in the folder") &&
           strstr(out, "Read-only file system"));
}

// An export onto an empty mount point (a freshly mounted USB stick) is
// refused before the work, saying to export into a folder on it: it was
// written beside the mount point, on the disk that holds it, and then could
// not be renamed onto it (an outside curator review). Where this user may
// not mount, skipped.
static void test_export_onto_mount_point(void)
{
    char p[1024], usb[1024], other[1024], cmd[16384], out[4096];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("usb_src.db"));
    snprintf(usb, sizeof usb, "%s", sp_test_tmp_path("usb"));
    snprintf(other, sizeof other, "%s", sp_test_tmp_path("usb_bound"));
    mkdir(other, 0755);
    sp_fixture_remove_db(p);
    mkdir(usb, 0755);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    add_ok(db, 1, 5);
    sp_db_close(db);
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    snprintf(cmd, sizeof cmd, "unshare -m sh -c \"mount -t tmpfs tmpfs '%s'\" 2>/dev/null", usb);
    if (system(cmd) != 0) SKIP("no mount namespace for this user (unshare -m)");
    // The folder itself, named "usb/." too, and a bind mount over it of a
    // folder on the same file system: each refused, nothing written beside it.
    snprintf(
        cmd, sizeof cmd,
        "unshare -m sh -c \"mount -t tmpfs tmpfs '%s' && '%s' db export '%s' --db '%s'; echo exit \\$?; '%s' db export '%s/.' "
        "--db '%s'; echo exit \\$?; mount --bind '%s' '%s' && '%s' db export '%s' --db '%s'; echo exit \\$?\" 2>&1; "
        "echo partials $(ls -d '%s'.partial-* 2>/dev/null | wc -l)",
        usb, bin, usb, p, bin, usb, p, other, usb, bin, usb, p, usb);
    int rc = sp_fixture_run(cmd, out, sizeof out);
    fprintf(stderr, "  %s", out);
    int said = 0;
    for (const char* at = out; (at = strstr(at, "a mount point (a USB stick?)")); ++at)
        ++said;
    ENSURE(rc == 0 && said == 3 && strstr(out, "export into a new folder on it") && !strstr(out, "exit 0") &&
           strstr(out, "partials 0"));
    rmdir(other);
    rmdir(usb);
    sp_fixture_remove_db(p);
}

// A part whose only curve the loader left out (saved as LINES, as Blender
// does) is refused with the loader's reason, where it said only "no sketch
// abstraction" (an outside curator review).
static void test_refusal_says_why(void)
{
    char* text = mini_gltf(&(mini_desc){.extras = true});
    char* mode = strstr(text, "\"mode\": 2}]}");
    ENSURE(mode);
    mode[8] = '1';
    sp_error err = {0};
    ENSURE(sp_db_validate_part(
               text, strlen(text), "curve_lines",
               &(sp_db_part_desc){.name = "curve_lines", .abstraction = "outline", .selftest_seeds = -1, .synth_sketches = -1},
               NULL, &err) != SP_OK);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "no sketch abstraction named outline (ignored mesh") &&
           strstr(err.text, "this one is mode 1 (LINES)"));
    free(text);
}

// The same file stored twice, under another name and category, is said
// (an outside curator review: the classifier learnt two categories from
// the same shapes without a word); a different file says nothing.
static void collect_line(void* user, const char* line)
{
    char* buf = user;
    if (strlen(buf) + strlen(line) + 2 < 2048) strcat(strcat(buf, line), "\n");
}

static void test_same_file_twice(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("twice.db"));
    sp_fixture_remove_db(p);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    sp_error err = {0};
    char said[2048] = "";
    const sp_db_part_desc base = {.synth_sketches = -1, .selftest_seeds = -1, .warn = collect_line, .warn_user = said};
    sp_db_part_desc d = base;
    d.name = "first";
    ENSURE(sp_db_add_part_file(db, part_file(0), &d, NULL, &err) == SP_OK && !strstr(said, "the same file"));
    d.name = "other";
    ENSURE(sp_db_add_part_file(db, part_file(1), &d, NULL, &err) == SP_OK && !strstr(said, "the same file"));
    d.name = "again", d.category = "fin";
    ENSURE(sp_db_add_part_file(db, part_file(0), &d, NULL, &err) == SP_OK);
    fprintf(stderr, "  %s", said);
    ENSURE(strstr(said, "the same file as part 'first' (category "));
    // A plain glTF (derived as it is added) under two categories: stored as
    // two files (the category is in them), it was not said (a second
    // curator review).
    char plain[1100];
    snprintf(plain, sizeof plain, "%s", sp_test_tmp_path("plain_twice.gltf"));
    char* text = mini_gltf(&(mini_desc){0});
    FILE* f = fopen(plain, "wb");
    ENSURE(text && f && fputs(text, f) >= 0 && fclose(f) == 0);
    free(text);
    said[0] = 0;
    d.name = "plain_fin", d.category = "fin";
    sp_result r = sp_db_add_part_file(db, plain, &d, NULL, &err);
    if (r != SP_OK) fprintf(stderr, "  plain: %s\n", err.text);
    ENSURE(r == SP_OK && !strstr(said, "the same file"));
    d.name = "plain_rider", d.category = "rider";
    ENSURE(sp_db_add_part_file(db, plain, &d, NULL, &err) == SP_OK);
    fprintf(stderr, "  %s", said);
    ENSURE(strstr(said, "the same file as part 'plain_fin' (category fin)"));
    // And after a move (export, init --from): the exported part file is the
    // derived one, so the original's hash goes with it in the manifest.
    char dir[1100], moved[1100];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("twice_export"));
    snprintf(moved, sizeof moved, "%s", sp_test_tmp_path("twice_moved.db"));
    sp_dir_remove_tree(dir);
    sp_fixture_remove_db(moved);
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    ENSURE(sp_db_create_from_export(moved, dir, NULL, "test", &err) == SP_OK);
    db = open_ok(moved, 0);
    said[0] = 0;
    d.name = "plain_wing", d.category = "wing";
    ENSURE(sp_db_add_part_file(db, plain, &d, NULL, &err) == SP_OK);
    fprintf(stderr, "  after a move: %s", said);
    ENSURE(strstr(said, "the same file as part 'plain_"));
    sp_db_close(db);
    sp_dir_remove_tree(dir);
}

static void test_round_trip(void)
{
    const char* path = sp_test_tmp_path("rt.db");
    char p[1024];
    snprintf(p, sizeof p, "%s", path);
    sp_fixture_remove_db(p);
    sp_error err = {0};
    sp_db* db = NULL;
    ENSURE(sp_db_open(p, 0, &db, &err) == SP_ERR_IO && strstr(err.text, "no such database")); // no CREATE
    db = open_ok(p, SP_DB_CREATE);
    ENSURE(sp_db_schema_version(db) == SP_DB_SCHEMA_VERSION);
    add_ok(db, 0, 20);
    add_ok(db, 1, 20);
    // A name that exists is refused.
    err = (sp_error){0};
    ENSURE(sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "tail_a", .synth_sketches = -1}, NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "exists"));
    // A name taken from a file name that is no plain name says where it came
    // from and what to do (it said only "part name 'my part' is not a plain name").
    char spaced[1100], cp[2400];
    snprintf(spaced, sizeof spaced, "%s", sp_test_tmp_path("my part.glb"));
    snprintf(cp, sizeof cp, "cp '%s' '%s'", part_file(0), spaced);
    ENSURE(system(cp) == 0);
    ENSURE(sp_db_add_part_file(db, spaced, &(sp_db_part_desc){.synth_sketches = -1}, NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "my part.glb: the part would be named '") && strstr(err.text, "my part' after the file") &&
           strstr(err.text, "rename the file, or give the part a name"));
    unlink(spaced);
    sp_db_part_info* parts;
    int n;
    ENSURE(sp_db_list_parts(db, &parts, &n, &err) == SP_OK && n == 2);
    fprintf(stderr, "  %s %s %d sketches, %d vertices, self-test %.4f\n", parts[0].name, parts[0].category, parts[0].sketches, parts[0].vertices, parts[0].selftest_error);
    ENSURE(!strcmp(parts[0].name, "tail_a") && !strcmp(parts[0].category, "tail") && parts[0].sketches == 20);
    ENSURE(parts[0].vertices > 0 && parts[0].parameters > 0 && parts[0].selftest_error >= 0 && parts[0].selftest_error <= 0.02);
    free(parts);
    // Curated sketches: strokes of a wings pose, stored and read back.
    sp_dataset ds = synth_as(db, "wings_a", 5, "wings");
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", &n, &err) == SP_OK && n == 5);
    sp_dataset_free(&ds);
    ENSURE(sp_db_load_dataset(db, &ds, NULL, &err) == SP_OK);
    ENSURE(ds.count == 45 && ds.category_count == 2 && !strcmp(ds.categories[1], "wings"));
    sp_dataset_free(&ds);
    // No model yet: check says so.
    bool ok = true;
    ENSURE(sp_db_check(db, &ok, NULL, &err) == SP_OK && !ok);
    char* report = NULL;
    train_ok(db, 2, &report);
    ENSURE(strstr(report, "\"per_class\"") && strstr(report, "\"top1\""));
    free(report);
    check_ok(db);
    // Remove: its synthetic sketches go, the model no longer matches, retrain fixes it.
    ENSURE(sp_db_remove_part(db, "tail_a", "test", &err) == SP_OK);
    ENSURE(sp_db_remove_part(db, "tail_a", "test", &err) == SP_ERR_INVALID && strstr(err.text, "no part named"));
    ENSURE(scalar(p, "SELECT count(*) FROM sketches") == 25);
    ENSURE(sp_db_check(db, &ok, NULL, &err) == SP_OK && !ok);
    train_ok(db, -1, NULL);
    check_ok(db);
    sp_clf* clf;
    ENSURE(sp_db_load_model(db, &clf, NULL, &err) == SP_OK);
    ENSURE(sp_clf_category_count(clf) == 1 && !strcmp(sp_clf_category(clf, 0), "wings"));
    // A part database's model weighs the strokes' shape and picture unless told otherwise.
    ENSURE(sp_clf_get_desc(clf).shape_weight == SP_DB_SHAPE_WEIGHT);
    ENSURE(sp_clf_get_desc(clf).picture_weight == SP_CLF_PICTURE_WEIGHT);
    sp_clf_destroy(clf);
    add_ok(db, 0, 20);
    train_ok(db, -1, NULL);
    check_ok(db);
    // The log is append-only.
    ENSURE(sqlite3_exec(((struct sp_db*)db)->h, "DELETE FROM log", NULL, NULL, NULL) != SQLITE_OK);
    char* log;
    ENSURE(sp_db_log_json(db, NULL, &log, &err) == SP_OK);
    ENSURE(strstr(log, "remove-part") && strstr(log, "add-part") && strstr(log, "train") && strstr(log, "add-sketches"));
    free(log);
    // Export and rebuild: the same parts, sketches and a model that matches.
    char dir[1024], p2[1024];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("export"));
    snprintf(p2, sizeof p2, "%s", sp_test_tmp_path("rebuilt.db"));
    ENSURE(system("true") == 0);
    char cmd[2200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ENSURE(system(cmd) == 0);
    sp_fixture_remove_db(p2);
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    sp_db_train_desc td = quick_train(-1);
    sp_result r = sp_db_create_from_export(p2, dir, &td, "test", &err);
    if (r != SP_OK) fprintf(stderr, "  rebuild: %s\n", err.text);
    ENSURE(r == SP_OK);
    ENSURE(scalar(p2, "SELECT count(*) FROM parts") == 2);
    ENSURE(scalar(p2, "SELECT count(*) FROM sketches") == scalar(p, "SELECT count(*) FROM sketches"));
    ENSURE(scalar(p2, "SELECT count(*) FROM sketches WHERE source = 'curated'") == 5);
    ENSURE(scalar(p2, "SELECT count(*) FROM sketches WHERE part_id IS NOT NULL") == 40);
    ENSURE(scalar(p2, "SELECT count(*) FROM parts a WHERE sha256 = 'x'") == 0);
    db = open_ok(p2, 0);
    check_ok(db);
    sp_db_close(db);
    // Existing targets are never overwritten.
    ENSURE(sp_db_create_from_export(p2, dir, NULL, "test", &err) == SP_ERR_INVALID && strstr(err.text, "exists"));
    // An empty file is no database (`mktemp` makes one): it takes the build
    // (it was refused as existing, though the database opener treats it as new).
    char empty[1100];
    snprintf(empty, sizeof empty, "%s", sp_test_tmp_path("empty_target.db"));
    sp_fixture_remove_db(empty);
    FILE* f = fopen(empty, "wb");
    ENSURE(f && fclose(f) == 0);
    r = sp_db_create_from_export(empty, dir, NULL, "test", &err);
    if (r != SP_OK) fprintf(stderr, "  into an empty file: %s\n", err.text);
    ENSURE(r == SP_OK && scalar(empty, "SELECT count(*) FROM parts") == 2);
    sp_fixture_remove_db(empty);
    // It keeps the empty file's permissions (a 0600 file became a 0644
    // database), and through a link the file it names takes the build (the
    // link became a database and its target stayed empty).
    char link[1100];
    snprintf(link, sizeof link, "%s", sp_test_tmp_path("empty_link.db"));
    unlink(link);
    f = fopen(empty, "wb");
    ENSURE(f && fclose(f) == 0 && chmod(empty, 0600) == 0 && symlink(empty, link) == 0);
    r = sp_db_create_from_export(link, dir, NULL, "test", &err);
    if (r != SP_OK) fprintf(stderr, "  into a link to an empty file: %s\n", err.text);
    struct stat st;
    ENSURE(r == SP_OK && lstat(link, &st) == 0 && S_ISLNK(st.st_mode));
    ENSURE(stat(empty, &st) == 0 && (st.st_mode & 0777) == 0600 && scalar(empty, "SELECT count(*) FROM parts") == 2);
    unlink(link);
    sp_fixture_remove_db(empty);
    // A link to no file yet (data/sketchpose.db not made): the file it names
    // takes the build, the link stays (the build was linked onto the link's
    // own name: "File exists", after the work; an outside review).
    ENSURE(symlink(empty, link) == 0);
    r = sp_db_create_from_export(link, dir, NULL, "test", &err);
    if (r != SP_OK) fprintf(stderr, "  into a dangling link: %s\n", err.text);
    ENSURE(r == SP_OK && lstat(link, &st) == 0 && S_ISLNK(st.st_mode) && scalar(empty, "SELECT count(*) FROM parts") == 2);
    unlink(link);
    sp_fixture_remove_db(empty);
}

// A stored sketch's doubles survive export and rebuild exactly, and the
// stroke text's writer at SP_SKETCH_JSON_EXACT digits loses none (the
// database stores DB_SKETCH_DIGITS: db_internal.h says why).
static void same_bits(const sp_sketch* a, const sp_sketch* b)
{
    ENSURE(a->stroke_count == 1 && b->stroke_count == 1 && a->strokes[0].count == b->strokes[0].count);
    ENSURE(!memcmp(&a->canvas_w, &b->canvas_w, sizeof a->canvas_w) && !memcmp(&a->canvas_h, &b->canvas_h, sizeof a->canvas_h));
    ENSURE(!memcmp(a->strokes[0].points, b->strokes[0].points, sizeof(sp_vec2) * (size_t)a->strokes[0].count));
    ENSURE(b->strokes[0].t && !memcmp(a->strokes[0].t, b->strokes[0].t, sizeof(double) * (size_t)a->strokes[0].count));
}

// The stored sketch of 7 timed points in the database at `path` (ds keeps it).
static const sp_sketch* stored_sketch_of(const char* path, sp_dataset* ds)
{
    sp_db* db = open_ok(path, 0);
    sp_error err = {0};
    ENSURE(sp_db_load_dataset(db, ds, NULL, &err) == SP_OK);
    sp_db_close(db);
    const sp_sketch* found = NULL;
    for (int i = 0; i < ds->count; ++i) {
        const sp_sketch* k = &ds->samples[i].sketch;
        if (k->stroke_count == 1 && k->strokes[0].count == 7 && k->strokes[0].t) {
            ENSURE(!found);
            found = k;
        }
    }
    ENSURE(found);
    return found;
}

static void test_sketch_doubles_exact(void)
{
    sp_vec2 pts[7] = {{0.1 + 0.2, 1.0 / 3.0},
                      {100.0 / 7.0, 2.0 / 3.0},
                      {1e-17, 123.456789012345678},
                      {640.0000000000001, 1.1},
                      {3.14159265358979, 2.718281828459045},
                      {0.7, 0.1 * 3},
                      {799.99999999999989, 5e-324}};
    double t[7] = {0, 16.666666666666668, 33.333333333333336, 50.00000000000001, 66.7, 83.3, 1.0 / 7.0 + 100};
    sp_stroke k = {.points = pts, .t = t, .count = 7};
    sp_sketch sk = {.canvas_w = 1280.0000000000002, .canvas_h = 800.0 / 3.0, .stroke_count = 1, .strokes = &k};
    sp_error err = {0};
    char* text = sp_sketch_to_json(&sk, SP_SKETCH_JSON_EXACT);
    sp_sketch back = {0};
    ENSURE(text && sp_sketch_parse_json(text, strlen(text), "exact", &back, &err) == SP_OK);
    same_bits(&sk, &back);
    sp_sketch_free(&back);
    free(text);
    char p[1024], p2[1024], dir[1024];
    fresh_export("exact", p, p2, dir);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    add_ok(db, 0, 0);
    char* cat = strdup(k_parts[0].category);
    sp_sample smp = {.sketch = sk, .label = 0};
    sp_dataset in = {.categories = &cat, .category_count = 1, .samples = &smp, .count = 1};
    int n = 0;
    ENSURE(sp_db_add_sketches(db, &in, NULL, SP_DB_SOURCE_CURATED, "test", &n, &err) == SP_OK && n == 1);
    free(cat);
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    ENSURE(sp_db_create_from_export(p2, dir, NULL, "test", &err) == SP_OK);
    sp_dataset d1 = {0}, d2 = {0};
    const sp_sketch* s1 = stored_sketch_of(p, &d1);
    same_bits(s1, stored_sketch_of(p2, &d2));
    ENSURE(fabs(s1->strokes[0].points[0].x - pts[0].x) < 1e-12);
    sp_dataset_free(&d1);
    sp_dataset_free(&d2);
}

static void test_curator_category(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("cur.db"));
    sp_db* db = open_ok(p, 0);
    sp_error err = {0};
    add_ok(db, 2, 60); // horns: a category the model has never seen
    bool ok = true;
    ENSURE(sp_db_check(db, &ok, NULL, &err) == SP_OK && !ok);
    train_ok(db, -1, NULL);
    check_ok(db);
    sp_clf* clf;
    ENSURE(sp_db_load_model(db, &clf, NULL, &err) == SP_OK);
    sp_character ch = {0};
    ENSURE(sp_db_load_part(db, "horns_a", &ch, &err) == SP_OK);
    int right = 0, n = 30;
    for (int i = 0; i < n; ++i) { // fresh poses, never stored
        double* q = malloc(sizeof(double) * (size_t)ch.rig.param_count);
        sp_synth_params(&ch.rig, 900 + (uint64_t)i, 0.4, q);
        sp_sketch sk = {0};
        ENSURE(sp_synth_sketch(&ch.rig, 0, &ch.camera, q, &sk) == SP_OK);
        sp_clf_answer a;
        ENSURE(sp_clf_classify(clf, &sk, NULL, &a, &err) == SP_OK);
        right += a.count > 0 && !strcmp(sp_clf_category(clf, a.ranked[0].category), "horns");
        if (getenv("SP_VERBOSE")) fprintf(stderr, "  -> %s %.2f rejected %d\n", a.count ? sp_clf_category(clf, a.ranked[0].category) : "-", a.count ? a.ranked[0].score : 0, a.rejected);
        sp_sketch_free(&sk);
        free(q);
    }
    fprintf(stderr, "  horns recognised %d/%d after train\n", right, n);
    ENSURE(right >= 21); // 70%; chance is 33%
    sp_character_free(&ch);
    sp_clf_destroy(clf);
    sp_db_close(db);
}

// ---- crash safety ------------------------------------------------------------------------

static int g_hook_ms = 0;
static void sleep_hook(const char* point)
{
    (void)point;
    usleep((useconds_t)g_hook_ms * 1000);
}

typedef enum { OP_ADD_PART, OP_TRAIN } crash_op;

static void run_op(const char* path, crash_op op)
{
    sp_db* db = NULL;
    sp_error err = {0};
    if (sp_db_open(path, 0, &db, &err) != SP_OK) _exit(3);
    sp_result r;
    if (op == OP_ADD_PART) {
        r = sp_db_add_part_file(db, part_file(3), &(sp_db_part_desc){.name = "tail_b", .synth_sketches = 30, .selftest_seeds = 1}, NULL, &err);
    } else {
        sp_db_train_desc td = quick_train(-1);
        r = sp_db_train(db, &td, NULL, &err);
    }
    sp_db_close(db);
    if (r != SP_OK) fprintf(stderr, "  child: %s\n", err.text);
    _exit(r == SP_OK ? 0 : 4);
}

static void crash_loop(crash_op op, int runs, uint64_t seed)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db(op == OP_ADD_PART ? "crash_add.db" : "crash_train.db"));
    part_file(3);
    // One uninterrupted run measures how long the operation takes (hook included).
    g_hook_ms = 15;
    int parts0 = scalar(p, "SELECT count(*) FROM parts"), sk0 = scalar(p, "SELECT count(*) FROM sketches");
    double t0 = sp_now_ms();
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) {
        sp_db_test_hook = sleep_hook;
        run_op(p, op);
    }
    int status;
    ENSURE(waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0);
    double span = sp_now_ms() - t0;
    sp_error err = {0};
    if (op == OP_ADD_PART) {
        sp_db* db = open_ok(p, 0);
        ENSURE(sp_db_remove_part(db, "tail_b", "test", &err) == SP_OK);
        sp_db_close(db);
    }
    sp_test_rng rng = {seed};
    int olds = 0, news = 0;
    for (int k = 0; k < runs; ++k) {
        int newest = scalar(p, "SELECT max(id) FROM models");
        double at = sp_test_range(&rng, 0.0, 1.1 * span);
        pid = fork();
        ENSURE(pid >= 0);
        if (pid == 0) {
            sp_db_test_hook = sleep_hook;
            run_op(p, op);
        }
        usleep((useconds_t)(at * 1000));
        kill(pid, SIGKILL);
        ENSURE(waitpid(pid, &status, 0) == pid);
        // After the kill: integrity holds and the state is the old or the new one.
        sp_db* db = open_ok(p, 0);
        check_ok(db);
        sp_db_close(db);
        int parts = scalar(p, "SELECT count(*) FROM parts"), sk = scalar(p, "SELECT count(*) FROM sketches");
        if (op == OP_ADD_PART) {
            bool old = parts == parts0 && sk == sk0, nu = parts == parts0 + 1 && sk == sk0 + 30;
            if (!old && !nu) fprintf(stderr, "  mixed state: %d parts, %d sketches\n", parts, sk);
            ENSURE(old || nu);
            olds += old;
            news += nu;
            if (nu) {
                db = open_ok(p, 0);
                ENSURE(sp_db_remove_part(db, "tail_b", "test", &err) == SP_OK);
                sp_db_close(db);
            }
        } else {
            int m = scalar(p, "SELECT max(id) FROM models");
            ENSURE(m == newest || m == newest + 1);
            // Each model stored has its log row, and only those (ids from 1; older models removed by train).
            ENSURE(scalar(p, "SELECT count(*) FROM log WHERE action = 'train'") == m);
            ENSURE(scalar(p, "SELECT count(*) FROM models") == (m < SP_DB_KEEP_MODELS ? m : SP_DB_KEEP_MODELS));
            olds += m == newest;
            news += m == newest + 1;
        }
    }
    fprintf(stderr, "  %s: %d kills over %.0f ms: %d old, %d new, never mixed\n", op == OP_ADD_PART ? "add-part" : "train", runs, span,
            olds, news);
}

// Kill points per crash test: each run adds a part (solver self-test) or
// trains; under ASan+UBSan that is several times slower, and the sanitizers
// look at the same code paths with fewer kills.
#if defined(__SANITIZE_ADDRESS__)
enum { CRASH_RUNS = 8 };
#else
enum { CRASH_RUNS = 30 };
#endif
static void test_crash_add_part(void) { crash_loop(OP_ADD_PART, CRASH_RUNS, 12345); }
static void test_crash_train(void) { crash_loop(OP_TRAIN, CRASH_RUNS, 777); }

// ---- concurrency, permissions, full disk ----------------------------------------------------

static sp_dataset one_sketch(const char* cat)
{
    sp_dataset ds = {0};
    sp_dataset_add_category(&ds, cat);
    ds.samples = calloc(1, sizeof(sp_sample));
    sp_vec2 pts[3] = {{10, 10}, {50, 80}, {90, 20}};
    sp_sketch_add_stroke(&ds.samples[0].sketch, pts, NULL, 3);
    ds.samples[0].sketch.canvas_w = ds.samples[0].sketch.canvas_h = 100;
    ds.count = 1;
    return ds;
}

static void test_two_writers(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("busy.db"));
    sp_fixture_remove_db(p);
    sp_db_close(open_ok(p, SP_DB_CREATE));
    // Another writer holds the lock: we wait our timeout, then fail with the message.
    sqlite3* other;
    ENSURE(sqlite3_open(p, &other) == SQLITE_OK);
    ENSURE(sqlite3_exec(other, "BEGIN IMMEDIATE; INSERT INTO log(by, action) VALUES ('other', 'hold')", NULL, NULL, NULL) == SQLITE_OK);
    sp_db* db = open_ok(p, 0);
    sp_db_set_busy_timeout(db, 300);
    sp_dataset ds = one_sketch("tail");
    sp_error err = {0};
    double t0 = sp_now_ms();
    sp_result r = sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err);
    double waited = sp_now_ms() - t0;
    fprintf(stderr, "  busy after %.0f ms: %s\n", waited, err.text);
    ENSURE(r == SP_ERR_BUSY);
    ENSURE(strstr(err.text, "database is busy (held by another writer for more than 0.3 s)"));
    ENSURE(waited >= 250 && waited < 2000);
    sqlite3_exec(other, "COMMIT", NULL, NULL, NULL);
    sqlite3_close(other);
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_OK);
    sp_db_close(db);
    // Two processes writing at once are serialised: every write lands.
    pid_t kids[2];
    for (int k = 0; k < 2; ++k) {
        kids[k] = fork();
        ENSURE(kids[k] >= 0);
        if (kids[k] == 0) {
            sp_db* d = NULL;
            sp_error e = {0};
            if (sp_db_open(p, 0, &d, &e) != SP_OK) _exit(3);
            for (int i = 0; i < 25; ++i)
                if (sp_db_add_sketches(d, &ds, NULL, SP_DB_SOURCE_CURATED, k ? "b" : "a", NULL, &e) != SP_OK) _exit(4);
            sp_db_close(d);
            _exit(0);
        }
    }
    for (int k = 0; k < 2; ++k) {
        int st;
        ENSURE(waitpid(kids[k], &st, 0) == kids[k] && WIFEXITED(st) && WEXITSTATUS(st) == 0);
    }
    ENSURE(scalar(p, "SELECT count(*) FROM sketches") == 51);
    sp_dataset_free(&ds);
}

// Runs write(db) in a child whose files may not grow past `limit` bytes (a
// full disk), the database opened with `flags`; true when it failed there
// with SP_ERR_IO and a one-line message that starts with `starts` (NULL: any).
static bool past_limit(const char* path, unsigned flags, off_t limit, sp_result (*write)(sp_db*, sp_error*), const char* starts)
{
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_IGN);
        sp_db* d = NULL;
        sp_error e = {0};
        if (sp_db_open(path, flags, &d, &e) != SP_OK) _exit(3);
        struct rlimit rl = {(rlim_t)limit, (rlim_t)limit};
        setrlimit(RLIMIT_FSIZE, &rl);
        sp_result r = write(d, &e);
        fprintf(stderr, "  disk full: %s\n", e.text);
        sp_db_close(d);
        bool said = e.text[0] && !strchr(e.text, '\n') && (!starts || strstr(e.text, starts) == e.text);
        _exit(r == SP_ERR_IO && said ? 0 : 6);
    }
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid);
    return WIFEXITED(st) && WEXITSTATUS(st) == 0;
}

// past_limit at the database file's size now: it may not grow.
static bool on_full_disk(const char* path, sp_result (*write)(sp_db*, sp_error*))
{
    struct stat fs;
    ENSURE(stat(path, &fs) == 0);
    return past_limit(path, 0, fs.st_size, write, NULL);
}

static sp_result add_big_part(sp_db* db, sp_error* err)
{
    return sp_db_add_part_file(db, part_file(2), &(sp_db_part_desc){.synth_sketches = 200, .selftest_seeds = -1}, NULL, err);
}

static void test_read_only_and_full(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("ro.db"));
    char before[65], after[65];
    file_sha(p, before);
    // Opened read-only: reads work, writes are refused clearly.
    sp_db* db = open_ok(p, SP_DB_READONLY);
    sp_error err = {0};
    sp_dataset ds = one_sketch("tail");
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_ERR_IO);
    ENSURE(strstr(err.text, "read-only"));
    check_ok(db);
    sp_db_close(db);
    // A file the user may not write (a non-root child, as root ignores
    // permissions), in a folder that child can reach wherever the clone lives.
    const char* dir = sp_test_reachable_dir("sp_partdb");
    ENSURE(dir);
    char ro[1024];
    snprintf(ro, sizeof ro, "%s/ro.db", dir);
    copy_file(p, ro);
    ENSURE(chmod(ro, 0444) == 0);
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) {
        if (geteuid() == 0 && setuid(65534) != 0) _exit(5);
        sp_db* d = NULL;
        sp_error e = {0};
        sp_result r = sp_db_open(ro, 0, &d, &e);
        fprintf(stderr, "  read-only file: %s\n", e.text);
        _exit(r == SP_ERR_IO && strstr(e.text, "read-only") ? 0 : 6);
    }
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st));
    ENSURE(WEXITSTATUS(st) == 0);
    file_sha(ro, after);
    ENSURE(!strcmp(before, after));
    sp_fixture_remove_db(ro);
    ENSURE(rmdir(dir) == 0);
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    ENSURE(on_full_disk(p, add_big_part));
    db = open_ok(p, 0);
    check_ok(db);
    sp_db_close(db);
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 2);
    sp_dataset_free(&ds);
}

// A copy of the base database (as `copy_of`) named `name` in a fresh folder
// that other users may reach; its path in p, the folder returned.
static const char* base_db_in_folder(const char* tag, const char* name, const char* copy_of, char p[1024])
{
    const char* dir = sp_test_reachable_dir(tag);
    ENSURE(dir);
    snprintf(p, 1024, "%s/%s", dir, name);
    copy_file(base_db(copy_of), p);
    return dir;
}

// fork(); the child runs as nobody when the test runs as root (root ignores
// permissions), exiting 5 if it cannot drop them.
static pid_t fork_unprivileged(void)
{
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0 && geteuid() == 0 && setuid(65534) != 0) _exit(5);
    return pid;
}

// A database behind a folder the user may not enter: "permission denied",
// not "no such database" (root ignores permissions: its child drops them).
static void test_unreachable(void)
{
    char p[1024];
    const char* dir = base_db_in_folder("sp_partdb", "x.db", "unreachable.db", p);
    ENSURE(chmod(dir, geteuid() == 0 ? 0700 : 0) == 0);
    pid_t pid = fork_unprivileged();
    if (pid == 0) {
        int code = 0;
        for (int k = 0; k < 2; ++k) {
            sp_db* d = NULL;
            sp_error e = {0};
            sp_result r = sp_db_open(p, k ? SP_DB_READONLY : SP_DB_CREATE, &d, &e);
            fprintf(stderr, "  unreachable (%s): %s\n", k ? "read-only" : "create", e.text);
            if (r != SP_ERR_IO || !strstr(e.text, "permission denied") || strstr(e.text, "no such")) code = 6;
        }
        _exit(code);
    }
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st));
    ENSURE(chmod(dir, 0755) == 0);
    ENSURE(WEXITSTATUS(st) == 0);
    sp_fixture_remove_db(p);
    ENSURE(rmdir(dir) == 0);
    // A file that is really missing still says so.
    sp_db* d = NULL;
    sp_error e = {0};
    ENSURE(sp_db_open(p, SP_DB_READONLY, &d, &e) == SP_ERR_IO && strstr(e.text, "no such database"));
}

// A database in a folder this user may read but not write (someone else's):
// read-only commands still read it, though SQLite cannot make its -shm there;
// a writer is refused with one line (root's child drops its rights).
static void test_read_only_folder(void)
{
    char p[1024];
    const char* dir = base_db_in_folder("sp_partdb_ro", "shared.db", "ro_folder.db", p);
    ENSURE(chmod(p, 0644) == 0 && chmod(dir, geteuid() == 0 ? 0755 : 0555) == 0);
    // `db check` only reads: it checks such a database (it was refused as
    // read-only). The command runs from the folder: a clone under a folder
    // others may not enter keeps its build out of the child's reach.
    const char* bin = sketchpose_bin();
    char exe[1100] = "", check[2400] = "";
    if (bin) {
        snprintf(exe, sizeof exe, "%s/sketchpose", dir);
        snprintf(check, sizeof check, "cp '%s' '%s' && chmod 0755 '%s'", bin, exe, exe);
        ENSURE(chmod(dir, 0755) == 0 && system(check) == 0 && chmod(dir, geteuid() == 0 ? 0755 : 0555) == 0);
        snprintf(check, sizeof check, "'%s' db check --db '%s' | grep -q '\"ok\": true'", exe, p);
    }
    pid_t pid = fork_unprivileged();
    if (pid == 0) {
        if (check[0] && system(check) != 0) _exit(8);
        sp_db* d = NULL;
        sp_error e = {0};
        char** cats = NULL;
        int n = 0;
        sp_result r = sp_db_open(p, SP_DB_READONLY, &d, &e);
        if (r == SP_OK) r = sp_db_categories(d, &cats, &n, &e);
        fprintf(stderr, "  read-only folder, reader: %s, %d categories\n", r == SP_OK ? "ok" : e.text, n);
        sp_db_free_strings(cats, n);
        sp_db_close(d);
        if (r != SP_OK || n != 2) _exit(6);
        r = sp_db_open(p, 0, &d, &e);
        fprintf(stderr, "  read-only folder, writer: %s\n", e.text);
        _exit(r == SP_ERR_IO && strstr(e.text, "shared.db") ? 0 : 7);
    }
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st));
    ENSURE(WEXITSTATUS(st) == 0);
    // The file writable, its folder not: the folder is blamed (an outside
    // curator review was told of the file's permissions, which were 0666).
    ENSURE(chmod(p, 0666) == 0);
    pid = fork_unprivileged();
    if (pid == 0) {
        sp_db* d = NULL;
        sp_error e = {0};
        sp_result r = sp_db_open(p, 0, &d, &e);
        if (r == SP_OK) r = sp_db_remove_part(d, "tail_a", "test", &e);
        fprintf(stderr, "  writable file, read-only folder, writer: %s\n", e.text);
        sp_db_close(d);
        _exit(r == SP_ERR_IO && strstr(e.text, "its folder is not writable") ? 0 : 9);
    }
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st));
    ENSURE(chmod(dir, 0755) == 0);
    ENSURE(WEXITSTATUS(st) == 0);
    struct stat sb;
    char side[1100];
    snprintf(side, sizeof side, "%s-shm", p);
    ENSURE(stat(side, &sb) != 0); // the reader left nothing beside it
    sp_fixture_remove_db(p);
    if (exe[0]) ENSURE(unlink(exe) == 0);
    ENSURE(rmdir(dir) == 0);
}

static bool beside(const char* db, const char* suffix)
{
    char side[1100];
    snprintf(side, sizeof side, "%s-%s", db, suffix);
    return access(side, F_OK) == 0;
}

// Readers leave no -wal or -shm beside a database they could write (SQLite
// removes them only when the last connection to close may write): the demo's
// and the kiosk's folder keeps the one file. A reader that closes while a
// writer is open leaves the writer's WAL alone, and a reader still changes
// nothing.
static void test_readers_leave_one_file(void)
{
    const char* p = base_db("one_file.db");
    for (int pass = 0; pass < 2; ++pass) {
        sp_db* r1 = open_ok(p, SP_DB_READONLY);
        sp_db* r2 = open_ok(p, SP_DB_READONLY);
        char** cats = NULL;
        int n = 0;
        sp_error e = {0};
        ENSURE(sp_db_categories(r2, &cats, &n, &e) == SP_OK && n == 2);
        sp_db_free_strings(cats, n);
        ENSURE(beside(p, "wal") && beside(p, "shm")); // open readers share them
        sp_db_close(r1);
        ENSURE(beside(p, "wal"));
        sp_db_close(r2);
        ENSURE(!beside(p, "wal") && !beside(p, "shm"));
    }
    sp_db* w = open_ok(p, 0);
    sp_error e = {0};
    ENSURE(sp_db_log(w, "writer", "note", "one_file", NULL, &e) == SP_OK);
    sp_db* r = open_ok(p, SP_DB_READONLY);
    sp_db_close(r);
    ENSURE(beside(p, "wal")); // the writer's, still open
    sp_dataset ds = one_sketch("tail");
    r = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_db_add_sketches(r, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &e) == SP_ERR_IO && strstr(e.text, "read-only"));
    sp_db_close(r);
    sp_db_close(w);
    sp_dataset_free(&ds);
    ENSURE(!beside(p, "wal") && !beside(p, "shm"));
    ENSURE(scalar(p, "SELECT count(*) FROM log WHERE by = 'writer'") == 1);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'curated'") == 0);
    sp_fixture_remove_db(p);
}

// A reader of a database it owns but could not write (mode 444) leaves the
// -wal and -shm at 444 (SQLite removes them only when a connection that may
// write closes); once the owner may write the database again, those
// leftovers of its own no longer refuse every write ("not writable by this
// user ... run as its owner", to the owner). Needs root to be another user.
static void test_own_readonly_leftovers(void)
{
    if (geteuid() != 0) SKIP("needs root (to run as a user that owns the database)");
    char p[1024], side[1100];
    const char* dir = base_db_in_folder("sp_partdb_ro", "mine.db", "own_ro.db", p);
    ENSURE(chown(dir, 65534, 65534) == 0 && chown(p, 65534, 65534) == 0 && chmod(p, 0444) == 0);
    for (int step = 0; step < 2; ++step) {
        if (step == 1) ENSURE(chmod(p, 0644) == 0); // the owner may write it again
        pid_t pid = fork_unprivileged();
        if (pid == 0) {
            sp_db* d = NULL;
            sp_error e = {0};
            sp_result r;
            if (step == 0) { // read, leaving -wal and -shm behind
                char* log = NULL;
                r = sp_db_open(p, SP_DB_READONLY, &d, &e);
                if (r == SP_OK) r = sp_db_log_json(d, "own_ro", &log, &e);
                free(log);
            } else {
                sp_dataset ds = one_sketch("tail");
                if ((r = sp_db_open(p, 0, &d, &e)) == SP_OK)
                    r = sp_db_add_sketches(d, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &e);
                sp_dataset_free(&ds);
            }
            fprintf(stderr, "  own read-only leftovers, step %d: %s\n", step, r == SP_OK ? "ok" : e.text);
            sp_db_close(d);
            _exit(r == SP_OK ? 0 : 6);
        }
        int st;
        ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st) && WEXITSTATUS(st) == 0);
        if (step == 0) {
            snprintf(side, sizeof side, "%s-shm", p);
            struct stat ss;
            ENSURE(stat(side, &ss) == 0 && (ss.st_mode & 0777) == 0444); // the case this is about
        }
    }
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'curated'") == 1);
    sp_fixture_remove_db(p);
    ENSURE(rmdir(dir) == 0);
}

// path: a file name `len` bytes long under tmp/<name>, in folders of 150
// bytes made on the way, ending in `suffix`.
static void long_path(const char* name, size_t len, const char* suffix, char path[2048])
{
    char dir[2048];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path(name));
    mkdir(dir, 0777);
    while (strlen(dir) < len - 200) {
        size_t n = strlen(dir);
        dir[n] = '/';
        memset(dir + n + 1, 'd', 150);
        dir[n + 151] = 0;
        ENSURE(mkdir(dir, 0777) == 0 || errno == EEXIST);
    }
    size_t n = strlen(dir), k = strlen(suffix);
    memcpy(path, dir, n);
    path[n] = '/';
    memset(path + n + 1, 'f', len - n - 1 - k);
    memcpy(path + len - k, suffix, k + 1);
    ENSURE(strlen(path) == len);
}

// A database whose path fills the 1,100 bytes the -wal and -shm names were
// built in: the cut name was the database's own, and it was removed as a
// stale sidecar.
static void test_drop_sidecars_long_path(void)
{
    char path[2048];
    long_path("long", 1099, "", path);
    FILE* f = fopen(path, "wb");
    ENSURE(f && fputs("a database", f) >= 0 && fclose(f) == 0);
    sp_db_drop_stale_sidecars(path);
    struct stat st;
    ENSURE(stat(path, &st) == 0);
    unlink(path);
}

// Paths too long for SQLite (512 bytes from /) or for the build's
// temporary name: one line saying so, and nothing removed (an outside
// review: "cannot open (No such file or directory)" of a file that was
// there; on a 1023-byte path the temporary name, cut, was the target's own,
// and the user's empty file was removed after the failed build).
static void test_long_paths(void)
{
    char path[2048];
    if (strlen(sp_test_tmp_path("longdb")) > 500) SKIP("the build folder's own path is longer than 500 bytes");
    long_path("longdb", 1023, ".db", path);
    FILE* f = fopen(path, "wb"); // empty, as mktemp makes it
    ENSURE(f && fclose(f) == 0);
    sp_error err = {0};
    sp_db_default_desc dd = {.synth_per_part = 2, .train = quick_train(-1)};
    ENSURE(sp_db_create_default(path, SP_SOURCE_DIR "/assets", &dd, &err) != SP_OK);
    fprintf(stderr, "  %s\n", err.text);
    struct stat st;
    ENSURE(stat(path, &st) == 0 && st.st_size == 0 && strstr(err.text, "path too long"));
    unlink(path);
    // A database 600 bytes from /: said, the reason at the line's end.
    path[600 - 3] = 0;
    strcat(path, ".db");
    sp_db* db = NULL;
    ENSURE(sp_db_open(path, SP_DB_CREATE, &db, &err) == SP_ERR_IO && !db);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "its path is 600 bytes from /, longer than SQLite takes"));
}

// A WAL database whose -wal and -shm a writer that crashed left behind, owned
// by another user (root) and not writable by this one, in a folder and beside
// a database file everyone may write: readers still read it (the WAL's rows
// too); a writer is refused with one line naming the -wal file and its owner,
// not "the database is read-only". Needs root to own files as another user.
static void test_foreign_wal(void)
{
    if (geteuid() != 0) SKIP("needs root (to leave -wal and -shm owned by another user)");
    char p[1024], side[1100];
    const char* dir = base_db_in_folder("sp_partdb_wal", "shared.db", "foreign_wal.db", p);
    ENSURE(chmod(p, 0666) == 0 && chmod(dir, 0777) == 0);
    pid_t pid = fork();
    ENSURE(pid >= 0);
    if (pid == 0) { // the writer that crashed: one change in the WAL, no close to fold it in
        sp_db* d = NULL;
        sp_error e = {0};
        if (sp_db_open(p, 0, &d, &e) != SP_OK || sp_db_log(d, "crashed", "note", "foreign_wal", NULL, &e) != SP_OK) _exit(6);
        raise(SIGKILL);
    }
    int st;
    ENSURE(waitpid(pid, &st, 0) == pid && WIFSIGNALED(st));
    for (int k = 0; k < 2; ++k) {
        snprintf(side, sizeof side, "%s-%s", p, k ? "shm" : "wal");
        ENSURE(chmod(side, 0644) == 0);
    }
    pid = fork_unprivileged();
    if (pid == 0) {
        sp_db* d = NULL;
        sp_error e = {0};
        char* log = NULL;
        sp_result r = sp_db_open(p, SP_DB_READONLY, &d, &e);
        if (r == SP_OK) r = sp_db_log_json(d, "foreign_wal", &log, &e);
        fprintf(stderr, "  foreign -wal, reader: %s\n", r == SP_OK ? log : e.text);
        bool read = r == SP_OK && strstr(log, "crashed");
        free(log);
        sp_db_close(d);
        if (!read) _exit(6);
        sp_dataset ds = one_sketch("tail");
        if ((r = sp_db_open(p, 0, &d, &e)) == SP_OK) r = sp_db_add_sketches(d, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &e);
        fprintf(stderr, "  foreign -wal, writer: %s\n", e.text);
        sp_db_close(d);
        sp_dataset_free(&ds);
        char want[1100];
        snprintf(want, sizeof want, "%s-wal: not writable by this user (owned by uid 0", p);
        _exit(r == SP_ERR_IO && strstr(e.text, want) == e.text && !strchr(e.text, '\n') ? 0 : 7);
    }
    ENSURE(waitpid(pid, &st, 0) == pid && WIFEXITED(st));
    ENSURE(WEXITSTATUS(st) == 0);
    ENSURE(scalar(p, "SELECT count(*) FROM log WHERE by = 'crashed'") == 1);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'curated'") == 0);
    sp_fixture_remove_db(p);
    ENSURE(rmdir(dir) == 0);
}

static void test_schema_versions(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("schema.db"));
    sp_error err = {0};
    // Newer: refused, untouched.
    sqlite3* h;
    ENSURE(sqlite3_open(p, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(h, "PRAGMA user_version = 99", NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(h);
    char before[65], after[65];
    file_sha(p, before);
    sp_db* db = NULL;
    ENSURE(sp_db_open(p, 0, &db, &err) == SP_ERR_UNSUPPORTED);
    fprintf(stderr, "  newer: %s\n", err.text);
    ENSURE(strstr(err.text, "newer") && strstr(err.text, "99"));
    ENSURE(sp_db_open(p, SP_DB_READONLY, &db, &err) == SP_ERR_UNSUPPORTED);
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // Older (version 1: no generation counter, no review status): read-only refuses, writable migrates and keeps the data.
    ENSURE(sp_fixture_db_downgrade(p, 1));
    ENSURE(sp_db_open(p, SP_DB_READONLY, &db, &err) == SP_ERR_UNSUPPORTED && strstr(err.text, "older") &&
           strstr(err.text, "a user who may write it")); // `db check` alone reads it for one who may not
    db = open_ok(p, 0);
    ENSURE(sp_db_schema_version(db) == SP_DB_SCHEMA_VERSION);
    uint64_t g = sp_db_generation(db);
    ENSURE(g >= 1);
    check_ok(db);
    add_ok(db, 3, 5);
    ENSURE(sp_db_generation(db) > g);
    sp_db_close(db);
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 3);
    // Not a database / someone else's database.
    char q[1024];
    snprintf(q, sizeof q, "%s", sp_test_tmp_path("notdb.db"));
    ENSURE(db_write_file(q, "hello, this is not sqlite at all..............................................................", 90, &err) ==
           SP_OK);
    ENSURE(sp_db_open(q, 0, &db, &err) != SP_OK);
    fprintf(stderr, "  not a database: %s\n", err.text);
    sp_fixture_remove_db(q);
    ENSURE(sqlite3_open(q, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(h, "CREATE TABLE foo(x)", NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(h);
    ENSURE(sp_db_open(q, 0, &db, &err) == SP_ERR_INVALID && strstr(err.text, "not a sketchpose database"));
    // With a schema version of its own (any application may set one): said
    // so, not "no such table" or "newer than this sketchpose", and its
    // journal mode is left as it was (it stayed WAL after the refusal).
    for (int v = 1; v <= SP_DB_SCHEMA_VERSION + 1; v += SP_DB_SCHEMA_VERSION) {
        sp_fixture_remove_db(q);
        ENSURE(sqlite3_open(q, &h) == SQLITE_OK);
        char sql[96];
        snprintf(sql, sizeof sql, "CREATE TABLE foo(x); PRAGMA user_version = %d;", v);
        ENSURE(sqlite3_exec(h, sql, NULL, NULL, NULL) == SQLITE_OK);
        sqlite3_close(h);
        for (int ro = 0; ro < 2; ++ro) {
            sp_result r = sp_db_open(q, ro ? SP_DB_READONLY : 0, &db, &err);
            fprintf(stderr, "  another application's (version %d): %s\n", v, err.text);
            ENSURE(r == SP_ERR_INVALID && strstr(err.text, "not a sketchpose database"));
        }
        ENSURE(sqlite3_open(q, &h) == SQLITE_OK);
        sqlite3_stmt* jm = NULL;
        ENSURE(sqlite3_prepare_v2(h, "PRAGMA journal_mode", -1, &jm, NULL) == SQLITE_OK && sqlite3_step(jm) == SQLITE_ROW);
        ENSURE(!strcmp((const char*)sqlite3_column_text(jm, 0), "delete"));
        sqlite3_finalize(jm);
        sqlite3_close(h);
    }
    // An empty file (a typo'd path, a truncated copy) opened for writing is
    // refused and stays empty; only SP_DB_CREATE makes a database of it.
    sp_fixture_remove_db(q);
    ENSURE(db_write_file(q, "", 0, &err) == SP_OK);
    ENSURE(sp_db_open(q, 0, &db, &err) == SP_ERR_INVALID && strstr(err.text, "empty file"));
    // Read, it is said the same way (it was "no schema": nothing said what to do; an outside review).
    ENSURE(sp_db_open(q, SP_DB_READONLY, &db, &err) == SP_ERR_INVALID && strstr(err.text, "an empty file; `sketchpose db init`"));
    struct stat st;
    ENSURE(stat(q, &st) == 0 && st.st_size == 0);
    ENSURE(sp_db_open(q, SP_DB_CREATE, &db, &err) == SP_OK);
    sp_db_close(db);
    sp_fixture_remove_db(q);
}

// Names from files and from users reach one-line messages escaped, and an
// export's entries are checked before anything is stored: a part file
// outside the folder is said as such ("a part entry without name or file"
// before), an added_by with a newline and an escape code is refused (it was
// stored and reached `db log`).
static void test_names_escaped(void)
{
    char dir[1024], target[1100], cmd[4400];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("esc_export"));
    snprintf(target, sizeof target, "%s", sp_test_tmp_path("esc.db"));
    const char* manifests[][2] = {
        {"\"parts\": [{\"name\": \"tail_a\", \"file\": \"../outside.glb\"}], \"sketches\": []",
         "part 0: file '../outside.glb' must be inside the export folder"},
        {"\"parts\": [{\"name\": \"tail_a\", \"file\": \"parts/tail_a.glb\", \"added_by\": \"a\\nb\\u001b[31m\"}], "
         "\"sketches\": []",
         "part 0: added_by 'a\\nb\\x1b[31m' holds control characters"},
        {"\"parts\": [], \"sketches\": [{\"file\": \"s.json\", \"category\": \"tail\", \"added_by\": \"x\\ry\"}]",
         "sketch 0: added_by 'x\\ry' holds control characters"},
        // A sketch's id and time, kept by a move, are checked as its other fields.
        {"\"parts\": [], \"sketches\": [{\"id\": 7, \"file\": \"s.json\", \"category\": \"tail\"}, {\"id\": 7, \"file\": "
         "\"s.json\", \"category\": \"tail\"}]",
         "sketch id 7 given twice"},
        {"\"parts\": [], \"sketches\": [{\"id\": 2.5, \"file\": \"s.json\", \"category\": \"tail\"}]",
         "sketch 0: id is not a whole number from 1 to 2^53 - 1"},
        {"\"parts\": [], \"sketches\": [{\"file\": \"s.json\", \"category\": \"tail\", \"added_at\": \"yesterday\"}]",
         "sketch 0: added_at 'yesterday' is not a time as YYYY-MM-DDTHH:MM:SS.sssZ"},
        {"\"parts\": [], \"sketches\": [{\"file\": \"s.json\", \"category\": \"tail\", \"added_at\": "
         "\"2026-99-99T99:99:99.999Z\"}]",
         "sketch 0: added_at '2026-99-99T99:99:99.999Z' is not a time"},
        // A newer release's export is not read as this one's.
        {"\"version\": 2, \"parts\": [], \"sketches\": []", "an export of version 2, schema 3; this sketchpose reads version 1"},
        {"\"schema\": 9, \"parts\": [], \"sketches\": []", "an export of version 1, schema 9;"},
    };
    for (size_t i = 0; i < sizeof manifests / sizeof manifests[0]; ++i) {
        snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s/parts' && cp '%s' '%s/parts/tail_a.glb'", dir, dir, part_file(0),
                 dir);
        ENSURE(system(cmd) == 0);
        char man[1200];
        snprintf(man, sizeof man, "%s/manifest.json", dir);
        FILE* f = fopen(man, "w");
        ENSURE(f);
        const char* m = manifests[i][0];
        fprintf(f, "{\"format\": \"sketchpose-db-export\", %s%s%s}", strstr(m, "\"version\"") ? "" : "\"version\": 1, ",
                strstr(m, "\"schema\"") ? "" : "\"schema\": 3, ", m);
        ENSURE(fclose(f) == 0);
        sp_fixture_remove_db(target);
        sp_error err = {0};
        sp_result r = sp_db_create_from_export(target, dir, NULL, "test", &err);
        fprintf(stderr, "  %s\n", err.text);
        ENSURE(r == SP_ERR_INVALID && strstr(err.text, manifests[i][1]) && !strchr(err.text, '\n') && !strchr(err.text, 27));
        ENSURE(access(target, F_OK) != 0);
    }
    // A category with a newline and an escape code, given or from the file: shown escaped.
    snprintf(target, sizeof target, "%s", sp_test_tmp_path("esc2.db"));
    sp_fixture_remove_db(target);
    sp_db* db = open_ok(target, SP_DB_CREATE);
    sp_error err = {0};
    sp_result r =
        sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "t", .category = "to\nrso\x1b[31m"}, NULL, &err);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(r != SP_OK && strstr(err.text, "'to\\nrso\\x1b[31m'") && !strchr(err.text, '\n') && !strchr(err.text, 27));
    r = sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "t\nx"}, NULL, &err);
    ENSURE(r != SP_OK && strstr(err.text, "part name 't\\nx'") && !strchr(err.text, '\n'));
    sp_db_close(db);
}

static void test_bad_input(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("bad.db"));
    char before[65], after[65];
    file_sha(p, before);
    sp_db* db = open_ok(p, 0);
    struct {
        const char* name;
        mini_desc d;
    } cases[] = {
        {"b_accessor.gltf", {.pos_accessor = 42}}, {"b_past_end.gltf", {.pos_count = 100}}, {"b_missing_bin.gltf", {.uri = "missing.bin"}},
        {"b_empty_skin.gltf", {.empty_skin = true}}, {"b_cycle.gltf", {.cycle = true}},       {"b_nan.gltf", {.nan_position = true}},
        {"b_zero_weights.gltf", {.zero_weights = true}}, {"b_bad_joint.gltf", {.bad_joint = 5}}, {"b_bad_dofs.gltf", {.bad_dofs = true}},
        {"b_no_category.gltf", {0}}, // loads, but has no category
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const char* f = sp_test_tmp_path(cases[i].name);
        char* text = mini_gltf(&cases[i].d);
        ENSURE(mini_write(f, text, strlen(text)));
        free(text);
        sp_error err = {0};
        sp_result r = sp_db_add_part_file(db, f, NULL, NULL, &err);
        fprintf(stderr, "  %-22s -> %s\n", cases[i].name, err.text);
        ENSURE(r != SP_OK && err.text[0]);
    }
    // Garbage and truncated GLBs straight into sp_db_add_part.
    void* glb;
    size_t n;
    sp_error err = {0};
    ENSURE(db_read_file(part_file(0), &glb, &n, &err) == SP_OK);
    size_t cuts[] = {0, 11, 20, n / 2, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; ++i) {
        err = (sp_error){0};
        ENSURE(sp_db_add_part(db, glb, cuts[i], &(sp_db_part_desc){.name = "cut"}, NULL, &err) != SP_OK && err.text[0]);
    }
    // A glTF over SQLite's value limit (lowered here to 10 kB; 1 GB by
    // default, which a 45,000-sketch model passed) is refused in words, not
    // as a NOT NULL constraint.
    int limit = sqlite3_limit(db->h, SQLITE_LIMIT_LENGTH, 10000);
    ENSURE(n > 10000);
    err = (sp_error){0};
    ENSURE(sp_db_add_part(db, glb, n, &(sp_db_part_desc){.name = "big"}, NULL, &err) == SP_ERR_UNSUPPORTED);
    printf("  %s\n", err.text);
    ENSURE(strstr(err.text, "the part's glTF is") && strstr(err.text, "more than SQLite stores in one value"));
    // So is a drawing's picture; the set is stored whole or not at all.
    sp_dataset big = {0};
    ENSURE(sp_dataset_add_category(&big, "tail") == 0);
    sp_sample smp = {.label = 0, .raster = {200, 200, calloc(200 * 200, 1)}};
    ENSURE(smp.raster.pixels && sp_dataset_add_sample(&big, &smp) == SP_OK);
    int had = -1, has = -2, added = -1;
    ENSURE(sp_db_sketch_count_by(db, SP_DB_SOURCE_CURATED, "test", &had, &err) == SP_OK);
    ENSURE(sp_db_add_sketches(db, &big, NULL, SP_DB_SOURCE_CURATED, "test", &added, &err) == SP_ERR_UNSUPPORTED);
    printf("  %s\n", err.text);
    ENSURE(strstr(err.text, "the drawing's picture is 40000 bytes") && added == 0);
    ENSURE(sp_db_sketch_count_by(db, SP_DB_SOURCE_CURATED, "test", &has, &err) == SP_OK && has == had);
    sp_dataset_free(&big);
    sqlite3_limit(db->h, SQLITE_LIMIT_LENGTH, limit);
    memset((char*)glb + 20, 'x', 40);
    ENSURE(sp_db_add_part(db, glb, n, &(sp_db_part_desc){.name = "garbled"}, NULL, &err) != SP_OK);
    free(glb);
    // An unfittable or badly named part.
    ENSURE(sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "../evil"}, NULL, &err) == SP_ERR_INVALID);
    ENSURE(sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "x", .category = "a b"}, NULL, &err) == SP_ERR_INVALID);
    ENSURE(sp_db_add_part_file(db, part_file(0), &(sp_db_part_desc){.name = "x", .abstraction = "nope"}, NULL, &err) == SP_ERR_INVALID);
    ENSURE(strstr(err.text, "no sketch abstraction named nope"));
    // Bad drawings refuse the whole set.
    sp_dataset ds = one_sketch("tail");
    ds.samples[0].sketch.strokes[0].points[1].x = NAN;
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "t", NULL, &err) == SP_ERR_INVALID);
    ds.samples[0].sketch.strokes[0].points[1].x = -3e9; // finite, but no reader would take it back
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "t", NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "beyond"));
    sp_dataset_free(&ds);
    ds = one_sketch("no/slash");
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "t", NULL, &err) == SP_ERR_INVALID);
    sp_dataset_free(&ds);
    sp_db_close(db);
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // The same through the command line, sketches included.
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    struct {
        const char* name;
        const char* text;
    } sk[] = {
        {"s_empty.json", "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [100, 100], \"strokes\": []}"},
        {"s_trunc.json", "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"strokes\": [{\"points\": [[1, 2], [3"},
        {"s_nan.json", "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [9, 9], \"strokes\": [{\"points\": [[1, "
                       "2], [NaN, 3]]}]}"},
        {"s_version.json", "{\"format\": \"sketchpose-strokes\", \"version\": 7, \"canvas\": [9, 9], \"strokes\": [{\"points\": "
                           "[[1, 2], [2, 3]]}]}"},
        {"s_trailing.json",
         "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"strokes\": [{\"points\": [[1, 2], [2, 3]]}]}\n}{ oops"},
        {"s_bad.svg", "<svg><path d=\"M 10 10 L zz\"/></svg>"},
        {"s_notpng.png", "this is not a png"},
        {"s_bad.ndjson", "{\"word\": \"cat\", \"drawing\": [[[1, 2], [3]]]}\n"},
        {"s_unknown.txt", "hello"},
    };
    for (size_t i = 0; i < sizeof sk / sizeof sk[0]; ++i) {
        const char* f = sp_test_tmp_path(sk[i].name);
        ENSURE(db_write_file(f, sk[i].text, strlen(sk[i].text), &err) == SP_OK);
        char cmd[4096];
        snprintf(cmd, sizeof cmd, "'%s' db add-sketch --db '%s' --category tail '%s' 2>&1 >/dev/null", bin, p, f);
        FILE* pp = popen(cmd, "r");
        char line[600] = "";
        if (!fgets(line, sizeof line, pp)) line[0] = 0;
        int st = pclose(pp);
        fprintf(stderr, "  %-15s -> exit %d: %s", sk[i].name, WEXITSTATUS(st), line);
        ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == 1 && strstr(line, "sketchpose db add-sketch: "));
        ENSURE(!strstr(sk[i].name, "trailing") || strstr(line, "text after the JSON document, line 2"));
    }
    // As kiosk sketches, one stroke of at most SP_DB_KIOSK_POINTS_MAX points
    // (a review listed 200,000 strokes as one, and a million points took a
    // minute a sheet): refused naming the file, the database unchanged.
    {
        size_t cap = 64 + 24 * (size_t)(SP_DB_KIOSK_POINTS_MAX + 1);
        char* big = malloc(cap);
        ENSURE(big);
        int k = sprintf(big, "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"strokes\": [{\"points\": [");
        for (int i = 0; i <= SP_DB_KIOSK_POINTS_MAX; ++i)
            k += sprintf(big + k, "%s[%d, %d]", i ? ", " : "", i % 300, i / 300);
        sprintf(big + k, "]}]}");
        const char* kinds[2][3] = {
            {"k_two.json",
             "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"strokes\": [{\"points\": [[1, 2], [30, 40]]}, "
             "{\"points\": [[5, 5], [50, 9]]}]}",
             "this is several strokes"},
            {"k_many.json", big, "this is one stroke of too many points"}};
        for (int i = 0; i < 2; ++i) {
            const char* f = sp_test_tmp_path(kinds[i][0]);
            ENSURE(db_write_file(f, kinds[i][1], strlen(kinds[i][1]), &err) == SP_OK);
            char cmd[4096], line[600] = "";
            snprintf(cmd, sizeof cmd, "'%s' db add-sketch --db '%s' --category tail --source kiosk '%s' 2>&1 >/dev/null", bin, p,
                     f);
            FILE* pp = popen(cmd, "r");
            if (!fgets(line, sizeof line, pp)) line[0] = 0;
            int st = pclose(pp);
            fprintf(stderr, "  %-15s -> exit %d: %s", kinds[i][0], WEXITSTATUS(st), line);
            ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == 1 && strstr(line, f) && strstr(line, "a kiosk sketch is one stroke") &&
                   strstr(line, kinds[i][2]));
        }
        // The library refuses them too, whoever calls it.
        sp_db* kdb;
        ENSURE(sp_db_open(p, 0, &kdb, &err) == SP_OK);
        sp_stroke two[2] = {{.count = 2, .points = (sp_vec2[]){{1, 2}, {30, 40}}},
                            {.count = 2, .points = (sp_vec2[]){{5, 5}, {50, 9}}}};
        sp_sample smp = {.sketch = {.canvas_w = 100, .canvas_h = 100, .stroke_count = 2, .strokes = two}};
        char* cats[1] = {"tail"};
        sp_dataset ds = {.count = 1, .samples = &smp, .category_count = 1, .categories = cats};
        int added = -1;
        ENSURE(sp_db_add_sketches(kdb, &ds, NULL, SP_DB_SOURCE_KIOSK, "t", &added, &err) == SP_ERR_INVALID && added == 0 &&
               strstr(err.text, "a kiosk sketch is one stroke"));
        sp_db_close(kdb);
        free(big);
    }
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' db add-part --db '%s' '%s' 2>/dev/null >/dev/null", bin, p, sp_test_tmp_path("b_cycle.gltf"));
    int st = system(cmd);
    ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == 1);
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // A failed add into a database the command would create leaves none behind
    // (a part that does not load, exit 1; a sketch whose category is no plain
    // name, bad usage since names are checked as options, exit 2).
    char fresh[1100];
    snprintf(fresh, sizeof fresh, "%s", sp_test_tmp_path("never_made.db"));
    unlink(fresh);
    const char* one = sp_test_tmp_path("s_one.json");
    const char* one_text = "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [9, 9], \"strokes\": [{\"points\": "
                           "[[1, 2], [2, 3]]}]}";
    ENSURE(db_write_file(one, one_text, strlen(one_text), &err) == SP_OK);
    const char* tries[2][2] = {{"add-part", sp_test_tmp_path("b_cycle.gltf")}, {"add-sketch --category 'not plain'", one}};
    for (int i = 0; i < 2; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' db %s --db '%s' '%s' 2>/dev/null >/dev/null", bin, tries[i][0], fresh, tries[i][1]);
        st = system(cmd);
        struct stat fs;
        ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == (i == 0 ? 1 : 2) && stat(fresh, &fs) != 0 && errno == ENOENT);
    }
    // A value a subcommand does not take is bad usage naming it (it printed "too many  (at most 0)").
    const char* sub[2] = {"list", "show head"};
    for (int i = 0; i < 2; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' db %s extra --db '%s' 2>&1 >/dev/null", bin, sub[i], p);
        FILE* pp = popen(cmd, "r");
        char line[600] = "";
        if (!fgets(line, sizeof line, pp)) line[0] = 0;
        st = pclose(pp);
        ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == 2 && strstr(line, "unexpected argument 'extra'"));
    }
    // A misspelt option with its value names the option, not the value (an
    // outside review: "--aprove 1" said "unexpected argument '1'").
    const char* typos[3][2] = {{"review --aprove 1", "--aprove"}, {"list --limt 3", "--limt"}, {"show head --jsn x", "--jsn"}};
    for (int i = 0; i < 3; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' db %s --db '%s' 2>&1 >/dev/null", bin, typos[i][0], p);
        FILE* pp = popen(cmd, "r");
        char line[600] = "", want[80];
        if (!fgets(line, sizeof line, pp)) line[0] = 0;
        st = pclose(pp);
        snprintf(want, sizeof want, "unknown option '%s'", typos[i][1]);
        ENSURE(WIFEXITED(st) && WEXITSTATUS(st) == 2 && strstr(line, want));
    }
}

static void test_generation(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("gen.db"));
    sp_db* reader = open_ok(p, SP_DB_READONLY);
    sp_db* writer = open_ok(p, 0);
    uint64_t g0 = sp_db_generation(reader);
    ENSURE(g0 > 0 && sp_db_generation(reader) == g0);
    // A cheap poll: a thousand calls with nothing changed.
    double t0 = sp_now_ms();
    for (int i = 0; i < 1000; ++i)
        ENSURE(sp_db_generation(reader) == g0);
    double per = (sp_now_ms() - t0) / 1000;
    fprintf(stderr, "  sp_db_generation: %.2f us per unchanged poll\n", per * 1000);
    int64_t id0 = 0, id1 = 0;
    sp_clf* clf;
    sp_error err = {0};
    ENSURE(sp_db_load_model(reader, &clf, &id0, &err) == SP_OK);
    sp_clf_destroy(clf);
    train_ok(writer, -1, NULL);
    uint64_t g1 = sp_db_generation(reader);
    ENSURE(g1 > g0);
    ENSURE(sp_db_generation(writer) == g1);
    ENSURE(sp_db_load_model(reader, &clf, &id1, &err) == SP_OK && id1 > id0);
    sp_clf_destroy(clf);
    // The newest model's head, with its checksum and without (the id alone).
    int64_t head = 0, bare = 0;
    char sha[65] = "";
    ENSURE(sp_db_model_head(reader, &head, sha, &err) == SP_OK && head == id1 && strlen(sha) == 64);
    ENSURE(sp_db_model_head(reader, &bare, NULL, &err) == SP_OK && bare == id1);
    ENSURE(sp_db_remove_part(writer, "wings_a", "t", &err) == SP_OK);
    ENSURE(sp_db_generation(reader) > g1);
    sp_db_close(writer);
    sp_db_close(reader);
}

// Trains with keep_models `keep`; the report's "models_removed".
static int train_keeping(sp_db* db, int keep)
{
    sp_db_train_desc td = quick_train(-1);
    td.keep_models = keep;
    char* report = NULL;
    sp_error err = {0};
    sp_result r = sp_db_train(db, &td, &report, &err);
    if (r != SP_OK) fprintf(stderr, "  train: %s\n", err.text);
    ENSURE(r == SP_OK);
    cJSON* j = cJSON_Parse(report);
    free(report);
    const cJSON* removed = cJSON_GetObjectItemCaseSensitive(j, "models_removed");
    ENSURE(cJSON_IsNumber(removed));
    int n = (int)removed->valuedouble;
    cJSON_Delete(j);
    return n;
}

// db train keeps the newest models (SP_DB_KEEP_MODELS by default) and
// removes the older ones in its transaction; the newest is the one read.
static void test_keep_models(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("keep_models.db"));
    sp_db* db = open_ok(p, 0);
    ENSURE(scalar(p, "SELECT count(*) FROM models") == 1);
    ENSURE(train_keeping(db, -1) == 0 && train_keeping(db, -1) == 0 && train_keeping(db, -1) == 0);
    ENSURE(scalar(p, "SELECT count(*) FROM models") == 4);
    int newest = scalar(p, "SELECT max(id) FROM models");
    ENSURE(train_keeping(db, 0) == 2); // the default keeps 3
    ENSURE(scalar(p, "SELECT count(*) FROM models") == SP_DB_KEEP_MODELS);
    ENSURE(scalar(p, "SELECT min(id) FROM models") == newest - 1 && scalar(p, "SELECT max(id) FROM models") == newest + 1);
    ENSURE(train_keeping(db, 1) == 3);
    ENSURE(scalar(p, "SELECT count(*) FROM models") == 1 && scalar(p, "SELECT max(id) FROM models") == newest + 2);
    int64_t id = 0;
    sp_clf* clf = NULL;
    sp_error err = {0};
    ENSURE(sp_db_load_model(db, &clf, &id, &err) == SP_OK && id == newest + 2);
    sp_clf_destroy(clf);
    check_ok(db);
    sp_db_close(db);
    // The command: --keep-models, and the count in its report.
    char out[65536];
    ENSURE(quick_train_cli(p, "--keep-models 1 2>/dev/null", out, sizeof out) == 0 && strstr(out, "\"models_removed\": 1"));
    ENSURE(scalar(p, "SELECT count(*) FROM models") == 1 && scalar(p, "SELECT max(id) FROM models") == newest + 3);
}

static void put_text(const char* path, const char* text)
{
    FILE* f = fopen(path, "wb");
    ENSURE(f && fputs(text, f) >= 0 && fclose(f) == 0);
}

// A project-made stand-in for the Quick, Draw! data beside an assets folder:
// <root>/qd/fix.ndjson (two drawings) and <root>/assets/sketches/picks.json
// naming three of their strokes (`picks`: the JSON array's items).
static void people_fixture(const char* root, const char* picks)
{
    char cmd[2200], f[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s/qd' '%s/assets/sketches' && mkdir -p '%s/qd' '%s/assets/sketches'", root, root, root, root);
    ENSURE(system(cmd) == 0);
    snprintf(f, sizeof f, "%s/qd/fix.ndjson", root);
    put_text(f, "{\"word\":\"x\",\"key_id\":\"111\",\"drawing\":[[[0,10,20],[0,5,0]],[[30,40],[30,41]]]}\n"
                "{\"word\":\"y\",\"key_id\":\"222\",\"drawing\":[[[5,6,7,8],[1,2,3,4]]]}\n");
    snprintf(f, sizeof f, "%s/assets/sketches/picks.json", root);
    char text[2048];
    snprintf(text, sizeof text, "{\"quickdraw\": \"../../qd\", \"picks\": [%s]}", picks);
    put_text(f, text);
}

#define PEOPLE_PICKS                                                                                                             \
    "{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":2,\"stroke\":0,\"key_id\":\"222\"},"                             \
    "{\"category\":\"horns\",\"file\":\"fix.ndjson\",\"line\":1,\"stroke\":1,\"key_id\":\"111\"},"                            \
    "{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":1,\"stroke\":0,\"key_id\":\"111\"}"

// The people's strokes of the default recipe are named in picks.json and read
// from the data, never copied: order, checks, and a data folder that is absent.
static void test_people_strokes(void)
{
    char root[1024], assets[1100];
    snprintf(root, sizeof root, "%s", sp_test_tmp_path("people"));
    snprintf(assets, sizeof assets, "%s/assets", root);
    people_fixture(root, PEOPLE_PICKS);
    sp_dataset ds;
    sp_error err = {0};
    bool missing = true;
    ENSURE(sp_db_people_strokes(assets, NULL, &ds, &missing, &err) == SP_OK && !missing);
    int picks = 0;
    ENSURE(sp_db_people_source(assets, NULL, &picks, &missing, &err) == SP_OK && picks == 3 && !missing);
    // Categories sorted; within one, the file's order; each a one-stroke sketch on Quick, Draw!'s canvas.
    ENSURE(ds.count == 3 && ds.category_count == 2 && !strcmp(ds.categories[0], "horns") && !strcmp(ds.categories[1], "tail"));
    ENSURE(ds.samples[0].label == 0 && ds.samples[1].label == 1 && ds.samples[2].label == 1);
    for (int i = 0; i < 3; ++i)
        ENSURE(ds.samples[i].sketch.stroke_count == 1 && ds.samples[i].sketch.canvas_w == 256);
    ENSURE(ds.samples[0].sketch.strokes[0].count == 2 && ds.samples[0].sketch.strokes[0].points[1].y == 41);
    ENSURE(ds.samples[1].sketch.strokes[0].count == 4 && ds.samples[1].sketch.strokes[0].points[3].x == 8);
    ENSURE(ds.samples[2].sketch.strokes[0].count == 3 && ds.samples[2].sketch.strokes[0].points[1].y == 5);
    sp_dataset_free(&ds);
    // The data's folder given explicitly.
    char qd[1100];
    snprintf(qd, sizeof qd, "%s/qd", root);
    ENSURE(sp_db_people_strokes(assets, qd, &ds, NULL, &err) == SP_OK && ds.count == 3);
    sp_dataset_free(&ds);
    // Not there: built without (empty, *missing), unless the caller named the folder.
    char cmd[2400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", qd);
    ENSURE(system(cmd) == 0);
    ENSURE(sp_db_people_strokes(assets, NULL, &ds, &missing, &err) == SP_OK && missing && ds.count == 0);
    ENSURE(sp_db_people_strokes(assets, qd, &ds, &missing, &err) == SP_ERR_IO && strstr(err.text, qd));
    ENSURE(sp_db_people_source(assets, NULL, &picks, &missing, &err) == SP_OK && picks == 3 && missing);
    ENSURE(sp_db_people_source(assets, qd, &picks, &missing, &err) == SP_ERR_IO && strstr(err.text, qd));
    char note[1200]; // what a first start says, the kiosk's and the demo's
    ENSURE(sp_db_people_note(assets, note, sizeof note) && strstr(note, "/sketches/picks.json: the Quick, Draw! data it names"));
    // Picks the data does not have: one line naming the file and line.
    struct {
        const char* pick;
        sp_result want;
        const char* says;
    } bad[] = {
        {"{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":1,\"stroke\":0,\"key_id\":\"999\"}", SP_ERR_INVALID, "fix.ndjson:1: key_id 111"},
        {"{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":9,\"stroke\":0,\"key_id\":\"111\"}", SP_ERR_INVALID, "no line 9"},
        {"{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":2,\"stroke\":1,\"key_id\":\"222\"}", SP_ERR_INVALID, "fix.ndjson:2: no stroke 1"},
        {"{\"category\":\"tail\",\"file\":\"none.ndjson\",\"line\":1,\"stroke\":0,\"key_id\":\"1\"}", SP_ERR_IO, "none.ndjson"},
        {"{\"category\":\"tail\",\"file\":\"../fix.ndjson\",\"line\":1,\"stroke\":0,\"key_id\":\"111\"}", SP_ERR_PARSE, "picks.json"},
        {"{\"file\":\"fix.ndjson\",\"line\":1,\"stroke\":0,\"key_id\":\"111\"}", SP_ERR_PARSE, "picks.json"},
        {"{\"category\":\"tail\",\"file\":\"fix.ndjson\",\"line\":0,\"stroke\":0,\"key_id\":\"111\"}", SP_ERR_PARSE, "picks.json"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        people_fixture(root, bad[i].pick);
        sp_result r = sp_db_people_strokes(assets, NULL, &ds, NULL, &err);
        if (r != bad[i].want || !strstr(err.text, bad[i].says)) fprintf(stderr, "  pick %zu: %d %s\n", i, r, err.text);
        ENSURE(r == bad[i].want && strstr(err.text, bad[i].says) && ds.count == 0);
    }
    char f[1200];
    snprintf(f, sizeof f, "%s/sketches/picks.json", assets);
    put_text(f, "{\"picks\": 3}");
    ENSURE(sp_db_people_strokes(assets, NULL, &ds, NULL, &err) == SP_ERR_PARSE && strstr(err.text, "picks.json: not a picks file"));
    // No picks.json: nothing to add.
    remove(f);
    ENSURE(sp_db_people_strokes(assets, NULL, &ds, &missing, &err) == SP_OK && ds.count == 0 && !missing);
    ENSURE(sp_db_people_source(assets, NULL, &picks, &missing, &err) == SP_OK && picks == 0 && !missing);
    ENSURE(!sp_db_people_note(assets, note, sizeof note));

    // The project's own picks, read from ../shared/data.
    char qdreal[1100];
    snprintf(qdreal, sizeof qdreal, "%s/quickdraw", SP_SHARED_DATA);
    struct stat st;
    if (stat(qdreal, &st) != 0) SKIP("../shared/data/quickdraw is absent (the fixture above covers the code)");
    ENSURE(sp_db_people_strokes(sp_test_src_path("assets"), NULL, &ds, &missing, &err) == SP_OK && !missing);
    fprintf(stderr, "  assets/sketches/picks.json: %d people's strokes in %d categories\n", ds.count, ds.category_count);
    ENSURE(ds.count >= 60 && ds.category_count == 6);
    for (int i = 0; i < ds.count; ++i)
        ENSURE(ds.samples[i].sketch.stroke_count == 1 && ds.samples[i].sketch.strokes[0].count >= 2);
    sp_dataset_free(&ds);
}

// Whether two sketches have the same points, to within `tol` (0: exactly).
static bool same_sketch(const sp_sketch* a, const sp_sketch* b, double tol)
{
    if (a->stroke_count != b->stroke_count) return false;
    for (int k = 0; k < a->stroke_count; ++k) {
        if (a->strokes[k].count != b->strokes[k].count) return false;
        for (int j = 0; j < a->strokes[k].count; ++j)
            if (fabs(a->strokes[k].points[j].x - b->strokes[k].points[j].x) > tol ||
                fabs(a->strokes[k].points[j].y - b->strokes[k].points[j].y) > tol)
                return false;
    }
    return true;
}

#define DRAWN_FIXTURE                                                                                                            \
    "{\"name\": \"t-wave\", \"label\": \"tail\", \"closed\": false, \"points\": [[0, 50], [20, 40], [40, 60], [60, 40], [80, "   \
    "60], "                                                                                                                      \
    "[95, 45], [95, 45], [100, 55]]}, "                                                                                          \
    "{\"name\": \"h-box\", \"label\": \"head\", \"closed\": true, \"points\": [[10, 90], [15, 40], [40, 20], [70, 25], [95, "    \
    "40], "                                                                                                                      \
    "[95, 40], [90, 55], [60, 60], [40, 70], [35, 90]]}, "                                                                       \
    "{\"name\": \"t-hook\", \"label\": \"tail\", \"points\": [[0, 10], [50, 20], [90, 60], [70, 90], [60, 70]]}"

// The hand-placed designs of the default recipe (assets/sketches/drawings.json):
// order, seeds by name, checks, and the project's own file kept apart from
// the visitors' evaluation set.
static void test_drawn_sketches(void)
{
    char root[1024], assets[1100], f[1200];
    snprintf(root, sizeof root, "%s", sp_test_tmp_path("drawn"));
    snprintf(assets, sizeof assets, "%s/assets", root);
    char cmd[2400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s/sketches'", root, assets);
    ENSURE(system(cmd) == 0);
    snprintf(f, sizeof f, "%s/sketches/drawings.json", assets);
    sp_dataset ds, again, other;
    sp_error err = {0};
    int designs = -1;
    // No file: nothing to add.
    ENSURE(sp_db_drawn_sketches(assets, 3, 1, &ds, &designs, &err) == SP_OK && ds.count == 0 && designs == 0);
    put_text(f, "{\"drawings\": [" DRAWN_FIXTURE "]}");
    ENSURE(sp_db_drawn_sketches(assets, 0, 1, &ds, &designs, &err) == SP_OK && ds.count == 0);
    ENSURE(sp_db_drawn_sketches(assets, 4, 1, &ds, &designs, &err) == SP_OK && designs == 3);
    // Categories sorted; the file's order within each; every draw a stroke of concept-sketch size on the kiosk's canvas.
    ENSURE(ds.count == 12 && ds.category_count == 2 && !strcmp(ds.categories[0], "head") && !strcmp(ds.categories[1], "tail"));
    for (int i = 0; i < 12; ++i) {
        const sp_sketch* s = &ds.samples[i].sketch;
        ENSURE(ds.samples[i].label == (i >= 4 && i < 8 ? 0 : 1));
        ENSURE(s->stroke_count >= 1 && s->canvas_w == SP_CONCEPT_CANVAS_W && s->canvas_h == SP_CONCEPT_CANVAS_H);
        double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
        for (int k = 0; k < s->stroke_count; ++k)
            for (int j = 0; j < s->strokes[k].count; ++j) {
                sp_vec2 p = s->strokes[k].points[j];
                ENSURE(isfinite(p.x) && isfinite(p.y));
                lo[0] = fmin(lo[0], p.x), lo[1] = fmin(lo[1], p.y), hi[0] = fmax(hi[0], p.x), hi[1] = fmax(hi[1], p.y);
            }
        double diag = hypot(hi[0] - lo[0], hi[1] - lo[1]);
        ENSURE(diag > 220 && diag < 480 && fabs((lo[0] + hi[0]) / 2 - 640) < 150 && fabs((lo[1] + hi[1]) / 2 - 400) < 150);
    }
    // Draws of one design differ; the same family draws the same bits; another family others.
    ENSURE(!same_sketch(&ds.samples[0].sketch, &ds.samples[1].sketch, 0));
    ENSURE(sp_db_drawn_sketches(assets, 4, 1, &again, NULL, &err) == SP_OK && again.count == 12);
    ENSURE(sp_db_drawn_sketches(assets, 4, 2, &other, NULL, &err) == SP_OK && other.count == 12);
    for (int i = 0; i < 12; ++i) {
        ENSURE(same_sketch(&ds.samples[i].sketch, &again.samples[i].sketch, 0));
        ENSURE(!same_sketch(&ds.samples[i].sketch, &other.samples[i].sketch, 0));
    }
    sp_dataset_free(&again);
    sp_dataset_free(&other);
    // A design's draws depend on its name, not its place: one added first leaves the others' as they were.
    put_text(f,
             "{\"drawings\": [{\"name\": \"new\", \"label\": \"tail\", \"points\": [[0, 0], [100, 100]]}, " DRAWN_FIXTURE "]}");
    ENSURE(sp_db_drawn_sketches(assets, 4, 1, &again, &designs, &err) == SP_OK && again.count == 16 && designs == 4);
    for (int i = 0; i < 8; ++i)
        ENSURE(same_sketch(&ds.samples[i].sketch, &again.samples[4 + i].sketch, 0));
    sp_dataset_free(&again);
    sp_dataset_free(&ds);
    // Malformed: one line naming the file (and the design), nothing returned.
    struct {
        const char* text;
        const char* says;
    } bad[] = {
        {"{\"drawings\": 3}", "drawings.json: not a drawings file"},
        {"[1, 2]", "drawings.json: not a drawings file"},
        {"{\"drawings\": [{\"label\": \"tail\", \"points\": [[0, 0], [1, 1]]}]}", "drawings.json: drawing 1: wants"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [[0, 0]]}]}", "drawing 1: wants"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"closed\": 1, \"points\": [[0, 0], [1, 1]]}]}",
         "drawing 1: wants"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"\", \"points\": [[0, 0], [1, 1]]}]}", "drawing 1: wants"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [[0, 0], [1, \"y\"]]}]}", "drawing \"a\": point 2"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [[0, 0], [1, 1, 1]]}]}", "drawing \"a\": point 2"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [[0, 0], [1e9, 1]]}]}", "drawing \"a\": point 2"},
        {"{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [[5, 5], [5, 5], [5, 5]]}]}",
         "drawing \"a\": its points have no extent"},
        {"{\"drawings\": [", "drawings.json"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        put_text(f, bad[i].text);
        memset(&err, 0, sizeof err);
        sp_result r = sp_db_drawn_sketches(assets, 2, 1, &ds, NULL, &err);
        if (r == SP_OK || !strstr(err.text, bad[i].says)) fprintf(stderr, "  case %zu: %d %s\n", i, r, err.text);
        ENSURE(r != SP_OK && strstr(err.text, bad[i].says) && ds.count == 0);
    }
    char many[12000];
    int at = snprintf(many, sizeof many, "{\"drawings\": [{\"name\": \"a\", \"label\": \"tail\", \"points\": [");
    for (int i = 0; i < 300; ++i)
        at += snprintf(many + at, sizeof many - (size_t)at, "%s[%d, %d]", i ? ", " : "", i % 100, i / 3);
    snprintf(many + at, sizeof many - (size_t)at, "]}]}");
    put_text(f, many);
    ENSURE(sp_db_drawn_sketches(assets, 2, 1, &ds, NULL, &err) == SP_ERR_PARSE && strstr(err.text, "drawing 1: wants"));

    // The project's own designs: the six parts, names unique, none of them a drawing of the visitors' evaluation set.
    ENSURE(sp_db_drawn_sketches(sp_test_src_path("assets"), 1, 1, &ds, &designs, &err) == SP_OK);
    fprintf(stderr, "  assets/sketches/drawings.json: %d designs in %d categories\n", designs, ds.category_count);
    ENSURE(ds.category_count == SP_CONCEPT_COUNT && designs >= 20 * SP_CONCEPT_COUNT);
    for (int k = 0; k < ds.category_count; ++k)
        ENSURE(sp_concept_parse(ds.categories[k]) != SP_CONCEPT_COUNT);
    sp_dataset_free(&ds);
    cJSON *mine = NULL, *theirs = NULL;
    char path[1200];
    snprintf(path, sizeof path, "%s", sp_test_src_path("assets/sketches/drawings.json"));
    ENSURE(db_read_json(path, &mine, &err) == SP_OK);
    snprintf(path, sizeof path, "%s", sp_test_src_path("tests/data/visitors/designs.json"));
    ENSURE(db_read_json(path, &theirs, &err) == SP_OK);
    const cJSON *a, *b;
    cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(mine, "drawings"))
    {
        const char* name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(a, "name"));
        char* pa = cJSON_PrintUnformatted(cJSON_GetObjectItemCaseSensitive(a, "points"));
        ENSURE(name && pa);
        for (const cJSON* c = a->next; c; c = c->next)
            ENSURE(strcmp(name, cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(c, "name"))) != 0);
        cJSON_ArrayForEach(b, cJSON_GetObjectItemCaseSensitive(theirs, "drawings"))
        {
            char* pb = cJSON_PrintUnformatted(cJSON_GetObjectItemCaseSensitive(b, "points"));
            if (pb && !strcmp(pa, pb)) fprintf(stderr, "  %s is an evaluation drawing\n", name);
            ENSURE(!pb || strcmp(pa, pb) != 0);
            cJSON_free(pb);
        }
        cJSON_free(pa);
    }
    cJSON_Delete(mine);
    cJSON_Delete(theirs);
}

// An assets folder of three fixture parts (tail, wings, horns) and the
// people's strokes that its picks.json names (two tails and a horn), in the
// temporary folder `name`; returns that folder.
static const char* default_assets(const char* name, char* assets, size_t cap)
{
    static char root[1024];
    snprintf(root, sizeof root, "%s", sp_test_tmp_path(name));
    snprintf(assets, cap, "%s/assets", root);
    people_fixture(root, PEOPLE_PICKS);
    for (int i = 0; i < 3; ++i) {
        char f[1200];
        snprintf(f, sizeof f, "%s/%s.glb", assets, k_parts[i].name);
        write_part(&k_parts[i], f);
    }
    return root;
}

// Curated sketches past the cap stay stored but out of the training set,
// spread over those stored; counted in the report (a curator's 30,000 made
// an 18-minute training and a 2.3 GB kiosk).
static void test_curated_cap(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("curated_cap.db"));
    sp_fixture_remove_db(p);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    add_ok(db, 1, 20); // wings, 20 synthetic sketches
    sp_error err = {0};
    sp_character ch = {0};
    ENSURE(sp_db_load_part(db, "wings_a", &ch, &err) == SP_OK);
    const char* cats[] = {"wings", "tail"};
    const int counts[] = {30, 7};    // tail: no part, so unused
    double first_x[30], first_y[30]; // of each curated wings sketch, in the order added
    for (int c = 0; c < 2; ++c) {
        sp_dataset ds = {0};
        ENSURE(db_synth_sketches(&ch, 0, counts[c], 91 + (uint64_t)c, 0, &ds, &err) == SP_OK);
        for (int i = 0; c == 0 && i < 30; ++i)
            first_x[i] = ds.samples[i].sketch.strokes[0].points[0].x, first_y[i] = ds.samples[i].sketch.strokes[0].points[0].y;
        free(ds.categories[0]);
        ds.categories[0] = strdup(cats[c]);
        ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_OK);
        sp_dataset_free(&ds);
    }
    sp_character_free(&ch);
    db_training_counts tc;
    sp_dataset ds;
    ENSURE(db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, 5, &ds, &tc, &err) == SP_OK);
    ENSURE(ds.count == 25 && tc.curated == 5 && tc.curated_left_out == 25 && tc.unused == 7);
    sp_dataset_free(&ds);
    ENSURE(db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, -1, &ds, &tc, &err) == SP_OK);
    ENSURE(ds.count == 50 && tc.curated == 30 && tc.curated_left_out == 0 && tc.unused == 7);
    sp_dataset_free(&ds);
    // Spread: of 30 added in one go, the 10 kept are not the first or last 10.
    ENSURE(db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, 10, &ds, &tc, &err) == SP_OK && tc.curated == 10);
    int early = 0, middle = 0, late = 0;
    for (int s = 0; s < ds.count; ++s)
        for (int i = 0; i < 30; ++i)
            if (fabs(ds.samples[s].sketch.strokes[0].points[0].x - first_x[i]) < 1e-6 &&
                fabs(ds.samples[s].sketch.strokes[0].points[0].y - first_y[i]) < 1e-6)
                early += i < 10, middle += i >= 10 && i < 20, late += i >= 20;
    fprintf(stderr, "  kept of 30: %d of the first 10, %d of the middle, %d of the last\n", early, middle, late);
    ENSURE(early + middle + late == 10 && early >= 1 && early <= 6 && late >= 1 && late <= 6);
    sp_dataset_free(&ds);
    // The default cap holds 30, and the report counts both.
    char* report = NULL;
    train_ok(db, -1, &report);
    ENSURE(strstr(report, "\"curated_sketches\": 30, \"curated_left_out\": 0,"));
    free(report);
    sp_db_train_desc td = quick_train(-1);
    td.curated_max = 12;
    ENSURE(sp_db_train(db, &td, &report, &err) == SP_OK);
    ENSURE(strstr(report, "\"drawings\": 32,") && strstr(report, "\"curated_sketches\": 12, \"curated_left_out\": 18,") &&
           strstr(report, "\"unused_drawings\": 7,"));
    free(report);
    sp_db_close(db);
    // The command says what it left out, in one line.
    char out[65536];
    ENSURE(quick_train_cli(p, "--curated-max 25 2>&1 >/dev/null", out, sizeof out) == 0);
    fprintf(stderr, "  %s", out);
    ENSURE(strstr(out, "5 curated sketches left out of training: at most 25 a category") &&
           strchr(out, '\n') == out + strlen(out) - 1);
}

static void test_default_db(void)
{
    // The default database from an assets folder of fixture parts.
    char dir[1100], p[1024];
    default_assets("default", dir, sizeof dir);
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("default.db"));
    sp_fixture_remove_db(p);
    sp_db* db = NULL;
    sp_error err = {0};
    // Two hand-placed designs, a tail and a horn, drawn twice each (family 2, as the concepts).
    char f[1200];
    snprintf(f, sizeof f, "%s/sketches/drawings.json", dir);
    put_text(f,
             "{\"drawings\": [{\"name\": \"t\", \"label\": \"tail\", \"points\": [[0, 50], [50, 30], [100, 60]]}, "
             "{\"name\": \"h\", \"label\": \"horns\", \"closed\": true, \"points\": [[0, 100], [50, 0], [50, 0], [100, 100]]}]}");
    sp_db_default_desc dd = {
        .synth_per_part = 20, .concepts_per_category = 5, .concept_family = 2, .drawn_per_design = 2, .train = quick_train(-1)};
    double t0 = sp_now_ms();
    sp_result r = sp_db_create_default(p, dir, &dd, &err);
    if (r != SP_OK) fprintf(stderr, "  default: %s\n", err.text);
    ENSURE(r == SP_OK);
    fprintf(stderr, "  default database of 3 parts x 20 sketches in %.0f ms\n", sp_now_ms() - t0);
    ENSURE(sp_db_open_or_create_default(p, dir, SP_DB_READONLY, &db, &err) == SP_OK);
    check_ok(db);
    char** cats;
    int n;
    ENSURE(sp_db_categories(db, &cats, &n, &err) == SP_OK && n == 3);
    sp_db_free_strings(cats, n);
    // Concept sketches join the categories that have a concept (tail, wings), not a curator's own (horns);
    // the people's strokes and the designs' draws join theirs.
    int* counts;
    ENSURE(sp_db_sketch_counts(db, &cats, &counts, &n, &err) == SP_OK && n == 3);
    for (int i = 0; i < n; ++i)
        ENSURE(counts[i] == (!strcmp(cats[i], "horns") ? 23 : !strcmp(cats[i], "tail") ? 29 : 25));
    sp_db_free_strings(cats, n);
    free(counts);
    // They are the draw of the family asked for (another draw of the same designs), not the default family's.
    sp_dataset ds;
    ENSURE(sp_db_load_dataset(db, &ds, NULL, &err) == SP_OK);
    for (uint64_t family = 1; family <= 2; ++family) {
        sp_sketch want;
        ENSURE(sp_concept_sketch(SP_CONCEPT_TAIL, sp_handdraw_seed(sp_handdraw_part_family(family, "tail"), 0), &want, &err) ==
               SP_OK);
        bool found = false;
        for (int i = 0; i < ds.count && !found; ++i) {
            const sp_sketch* s = &ds.samples[i].sketch;
            if (strcmp(ds.categories[ds.samples[i].label], "tail") || s->stroke_count != 1 ||
                s->strokes[0].count != want.strokes[0].count)
                continue;
            found = true;
            for (int k = 0; k < want.strokes[0].count && found; ++k)
                found = fabs(s->strokes[0].points[k].x - want.strokes[0].points[k].x) < 0.01 &&
                        fabs(s->strokes[0].points[k].y - want.strokes[0].points[k].y) < 0.01;
        }
        ENSURE(found == (family == 2));
        sp_sketch_free(&want);
    }
    // The designs' draws are sp_db_drawn_sketches' of that family.
    sp_dataset drawn;
    ENSURE(sp_db_drawn_sketches(dir, 2, 2, &drawn, NULL, &err) == SP_OK && drawn.count == 4);
    for (int j = 0; j < drawn.count; ++j) {
        int hits = 0;
        for (int i = 0; i < ds.count; ++i)
            hits += !strcmp(ds.categories[ds.samples[i].label], drawn.categories[drawn.samples[j].label]) &&
                    same_sketch(&ds.samples[i].sketch, &drawn.samples[j].sketch, 0.01);
        ENSURE(hits == 1);
    }
    sp_dataset_free(&drawn);
    sp_dataset_free(&ds);
    sp_db_close(db);
    ENSURE(sp_db_create_default(p, dir, &dd, &err) == SP_ERR_INVALID);
}

// ---- visitors' strokes: collection and review ----------------------------------------

// A visitor's stroke: a bent line on a 1280 x 800 canvas, with times; `k` moves it.
static sp_stroke visitor_stroke(int k, sp_vec2* pts, double* t)
{
    for (int i = 0; i < 40; ++i) {
        pts[i] = (sp_vec2){300 + 10 * i + k, 400 + 60 * sin(i * 0.2) + k};
        t[i] = 16.7 * i;
    }
    return (sp_stroke){.count = 40, .points = pts, .t = t};
}

static int64_t collect_ok(sp_db* db, const char* category, int k)
{
    sp_vec2 pts[40];
    double t[40];
    sp_stroke st = visitor_stroke(k, pts, t);
    int64_t id = 0;
    sp_error err = {0};
    sp_result r = sp_db_collect_kiosk_sketch(db, category, &st, 1280, 800, &id, &err);
    if (r != SP_OK) fprintf(stderr, "  collect: %s\n", err.text);
    ENSURE(r == SP_OK && id > 0);
    return id;
}

// Collects until the database refuses (the WAL's slack fills first).
static sp_result collect_many(sp_db* db, sp_error* err)
{
    sp_result r = SP_OK;
    for (int i = 0; i < 2000 && r == SP_OK; ++i) {
        sp_vec2 q[40];
        double tq[40];
        sp_stroke s = visitor_stroke(i, q, tq);
        r = sp_db_collect_kiosk_sketch(db, "tail", &s, 1280, 800, NULL, err);
    }
    return r == SP_OK || strstr(err->text, "dropped") ? r : SP_ERR_INTERNAL;
}

// The sketches of database b that a has with the same id, category, source,
// status, strokes and time.
static int same_sketches(const char* a, const char* b)
{
    sqlite3* h;
    ENSURE(sqlite3_open_v2(b, &h, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK);
    char* sql = sqlite3_mprintf("ATTACH %Q AS a", a);
    ENSURE(sqlite3_exec(h, sql, NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_free(sql);
    sqlite3_stmt* st;
    ENSURE(
        sqlite3_prepare_v2(h,
                           "SELECT count(*) FROM sketches s JOIN a.sketches t ON s.id = t.id AND s.category = t.category AND"
                           " s.source = t.source AND s.status IS t.status AND s.strokes IS t.strokes AND s.added_at = t.added_at",
                           -1, &st, NULL) == SQLITE_OK);
    ENSURE(sqlite3_step(st) == SQLITE_ROW);
    int n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(h);
    return n;
}

// A follower (the kiosk's pipeline and collector) asks partdb whether the
// path still names the file its handle opened: the same, another renamed
// over it, or none. A file renamed over the path while the handle was being
// opened (after SQLite opened the old one) reads as replaced: noted after
// the open, the new file was taken for the handle's and never followed.
static void test_file_check(void)
{
    char p[1024], q[1024];
    snprintf(p, sizeof p, "%s", base_db("check_p.db"));
    snprintf(q, sizeof q, "%s", base_db("check_q.db"));
    struct stat st;
    ENSURE(stat(p, &st) == 0);
    sp_db* db = open_ok(p, SP_DB_READONLY);
    uint64_t dev = 0, ino = 0;
    ENSURE(sp_db_file_id(db, &dev, &ino) && dev == (uint64_t)st.st_dev && ino == (uint64_t)st.st_ino);
    ENSURE(sp_db_file_check(db) == SP_DB_FILE_SAME);
    ENSURE(rename(q, p) == 0);
    ENSURE(sp_db_file_check(db) == SP_DB_FILE_REPLACED);
    sp_db_close(db);
    sp_fixture_remove_db(p);
    db = open_ok(base_db("check_p.db"), SP_DB_READONLY);
    ENSURE(unlink(p) == 0 && sp_db_file_check(db) == SP_DB_FILE_GONE);
    sp_db_close(db);
    // Renamed over it during the open.
    snprintf(p, sizeof p, "%s", base_db("check_p.db"));
    snprintf(q, sizeof q, "%s", base_db("check_q.db"));
    sp_fixture_rename_when_opened(q, p);
    db = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_fixture_rename_done());
    ENSURE(sp_db_file_check(db) == SP_DB_FILE_REPLACED);
    sp_db_close(db);
    // A database this open makes: its own file.
    sp_fixture_remove_db(q);
    db = open_ok(q, SP_DB_CREATE);
    ENSURE(sp_db_file_check(db) == SP_DB_FILE_SAME && sp_db_file_id(db, &dev, &ino) && ino != 0);
    sp_db_close(db);
}

static void test_kiosk_collect(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("kiosk.db"));
    sp_db* reader = open_ok(p, SP_DB_READONLY);
    sp_db* kiosk = open_ok(p, 0);
    uint64_t g0 = sp_db_generation(reader);
    int64_t a = collect_ok(kiosk, "tail", 0), b = collect_ok(kiosk, "tail", 5), c = collect_ok(kiosk, "wings", 9);
    // Pending sketches change no model or part: a kiosk that collects does not make itself (or others) reload.
    ENSURE(sp_db_generation(reader) == g0);
    sp_error err = {0};
    int counts[SP_DB_STATUS_COUNT];
    ENSURE(sp_db_kiosk_counts(reader, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 3 && counts[SP_DB_APPROVED] == 0);
    // Points and times only, oldest first.
    sp_db_kiosk_sketch* ks;
    int n;
    ENSURE(sp_db_kiosk_list(reader, NULL, &ks, &n, &err) == SP_OK && n == 3);
    ENSURE(ks[0].id == a && ks[1].id == b && ks[2].id == c && !strcmp(ks[2].category, "wings") && ks[0].status == SP_DB_PENDING);
    ENSURE(ks[0].sketch.stroke_count == 1 && ks[0].sketch.strokes[0].count == 40 && ks[0].sketch.strokes[0].t);
    ENSURE_NEAR(ks[1].sketch.strokes[0].points[3].x, 300 + 30 + 5, 1e-9);
    ENSURE(strlen(ks[0].created_at) >= 20);
    sp_db_kiosk_free(ks, n);
    // Paging.
    ENSURE(sp_db_kiosk_list(reader, &(sp_db_kiosk_query){.limit = 2}, &ks, &n, &err) == SP_OK && n == 2);
    sp_db_kiosk_free(ks, n);
    ENSURE(sp_db_kiosk_list(reader, &(sp_db_kiosk_query){.after = b}, &ks, &n, &err) == SP_OK && n == 1 && ks[0].id == c);
    sp_db_kiosk_free(ks, n);
    // Bad strokes and labels are refused with one line, nothing stored.
    sp_vec2 pts[40];
    double t[40];
    sp_stroke st = visitor_stroke(0, pts, t);
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "a b", &st, 1280, 800, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "dropped"));
    pts[7].y = NAN;
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_INVALID);
    st = visitor_stroke(0, pts, t);
    st.count = 1;
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_INVALID);
    // Finite but beyond what a stroke file may hold: stored, it would stop every review page and training run that reads it.
    st = visitor_stroke(0, pts, t);
    pts[3].x = 2e9;
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "beyond") && strstr(err.text, "dropped"));
    st = visitor_stroke(0, pts, t);
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 2e6, 800, NULL, &err) == SP_ERR_INVALID && strstr(err.text, "canvas"));
    t[5] = INFINITY;
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "time is not a finite"));
    // No error to fill: the same answer, nothing written through NULL.
    ENSURE(sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, NULL) == SP_ERR_INVALID);
    ENSURE(sp_db_kiosk_counts(kiosk, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 3);
    // A busy database drops the sketch within the collect timeout; a read-only one drops it at once.
    sqlite3* other;
    ENSURE(sqlite3_open(p, &other) == SQLITE_OK);
    ENSURE(sqlite3_exec(other, "BEGIN IMMEDIATE; INSERT INTO log(by, action) VALUES ('other', 'hold')", NULL, NULL, NULL) ==
           SQLITE_OK);
    st = visitor_stroke(0, pts, t);
    double t0 = sp_now_ms();
    sp_result r = sp_db_collect_kiosk_sketch(kiosk, "tail", &st, 1280, 800, NULL, &err);
    double waited = sp_now_ms() - t0;
    fprintf(stderr, "  busy: %.0f ms: %s\n", waited, err.text);
    ENSURE(r == SP_ERR_BUSY && strstr(err.text, "dropped") && waited < 500);
    sqlite3_exec(other, "ROLLBACK", NULL, NULL, NULL);
    sqlite3_close(other);
    ENSURE(sp_db_collect_kiosk_sketch(reader, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_IO && strstr(err.text, "read-only"));
    ENSURE(sp_db_collect_kiosk_sketch(reader, "tail", &st, 1280, 800, NULL, NULL) == SP_ERR_IO);
    // A full disk drops it too.
    sp_db_close(kiosk);
    ENSURE(on_full_disk(p, collect_many));
    kiosk = open_ok(p, 0);
    check_ok(kiosk);
    // Review: relabel, approve, reject; an unknown id or category changes nothing.
    ENSURE(sp_db_kiosk_relabel(kiosk, b, "wings", "curator", &err) == SP_OK);
    ENSURE(sp_db_kiosk_relabel(kiosk, b, "horns", "curator", &err) == SP_ERR_INVALID && strstr(err.text, "not a part category"));
    ENSURE(sp_db_kiosk_relabel(kiosk, 999999, "tail", "curator", &err) == SP_ERR_INVALID &&
           strstr(err.text, "no kiosk sketch 999999"));
    int64_t bad[3] = {a, 999999, b};
    ENSURE(sp_db_kiosk_set_status(kiosk, bad, 3, SP_DB_APPROVED, "curator", &err) == SP_ERR_INVALID);
    int64_t some_synthetic = scalar(p, "SELECT min(id) FROM sketches WHERE source = 'synthetic'");
    ENSURE(sp_db_kiosk_set_status(kiosk, &some_synthetic, 1, SP_DB_REJECTED, "curator", &err) == SP_ERR_INVALID);
    ENSURE(sp_db_kiosk_counts(kiosk, counts, &err) == SP_OK && counts[SP_DB_PENDING] >= 3 && counts[SP_DB_APPROVED] == 0);
    int64_t ok2[2] = {a, b};
    ENSURE(sp_db_kiosk_set_status(kiosk, ok2, 2, SP_DB_APPROVED, "curator", &err) == SP_OK);
    ENSURE(sp_db_kiosk_set_status(kiosk, &c, 1, SP_DB_REJECTED, "curator", &err) == SP_OK);
    // Training uses the approved ones only, the newest per category up to the cap.
    db_training_counts tc;
    sp_dataset ds;
    ENSURE(db_load_training_set(kiosk, SP_DB_KIOSK_TRAIN_MAX, -1, &ds, &tc, &err) == SP_OK && tc.kiosk == 2);
    int synthetic = ds.count - 2;
    sp_dataset_free(&ds);
    ENSURE(db_load_training_set(kiosk, 0, -1, &ds, &tc, &err) == SP_OK && tc.kiosk == 0 && ds.count == synthetic);
    sp_dataset_free(&ds);
    char* report = NULL;
    train_ok(kiosk, -1, &report);
    ENSURE(strstr(report, "\"kiosk_sketches\": 2"));
    free(report);
    // Export keeps the review, and a rebuild from it too.
    char dir[1024], q[1024];
    snprintf(dir, sizeof dir, "%s", sp_test_tmp_path("kiosk-export"));
    snprintf(q, sizeof q, "%s", sp_test_tmp_path("kiosk-rebuilt.db"));
    sp_fixture_remove_db(q);
    ENSURE(sp_db_export(kiosk, dir, &err) == SP_OK);
    ENSURE(sp_db_create_from_export(q, dir, NULL, "test", &err) == SP_OK);
    ENSURE(scalar(q, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'approved'") == 2);
    ENSURE(scalar(q, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'rejected'") == 1);
    ENSURE(scalar(q, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'pending'") ==
           scalar(p, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'pending'"));
    // Every sketch keeps its id and its time, and the highest id ever given
    // goes with them: a review's ids named other drawings after a move (an
    // outside curator review).
    ENSURE(same_sketches(p, q) == scalar(p, "SELECT count(*) FROM sketches"));
    ENSURE(scalar(q, "SELECT " DB_SKETCH_ID_HIGH) == scalar(p, "SELECT " DB_SKETCH_ID_HIGH));
    sp_db_close(kiosk);
    sp_db_close(reader);
}

// A version 2 database (before reviews): its kiosk sketches were a curator's
// additions and stay in training (approved); new pending ones bump no generation.
static void test_kiosk_migration(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("v2.db"));
    sp_fixture_remove_db(p);
    sqlite3* h;
    ENSURE(sqlite3_open(p, &h) == SQLITE_OK);
    sqlite3_close(h);
    sp_db raw = {.path = p, .busy_ms = 1000};
    ENSURE(sqlite3_open(p, &raw.h) == SQLITE_OK);
    sp_error err = {0};
    ENSURE(db_migrate(&raw, 2, &err) == SP_OK);
    ENSURE(sqlite3_exec(
               raw.h,
               "INSERT INTO sketches(category, source, strokes, added_by) VALUES ('tail', 'kiosk',"
               " '{\"format\": \"sketchpose-strokes\", \"version\": 1, \"strokes\": [{\"points\": [[1, 2], [30, 40]]}]}', 'old')",
               NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(raw.h);
    sp_db* db = open_ok(p, 0);
    ENSURE(sp_db_schema_version(db) == SP_DB_SCHEMA_VERSION);
    int counts[SP_DB_STATUS_COUNT];
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_APPROVED] == 1 && counts[SP_DB_PENDING] == 0);
    uint64_t g = sp_db_generation(db);
    collect_ok(db, "tail", 0);
    ENSURE(sp_db_generation(db) == g);
    sp_db_close(db);
}

// `sketchpose --help` names every subcommand `db --help` lists (it lacked log and review).
static void test_db_help_lists_all(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char cmd[2048], top[8192], sub[8192];
    snprintf(cmd, sizeof cmd, "'%s' --help", bin);
    ENSURE(sp_fixture_run(cmd, top, sizeof top) == 0);
    const char* dbline = strstr(top, "\n  db ");
    ENSURE(dbline);
    char line[1024];
    snprintf(line, sizeof line, "%.*s", (int)strcspn(dbline + 1, "\n"), dbline + 1);
    snprintf(cmd, sizeof cmd, "'%s' db --help", bin);
    ENSURE(sp_fixture_run(cmd, sub, sizeof sub) == 0);
    int n = 0;
    for (const char* q = strstr(sub, "subcommands:\n"); q && (q = strstr(q, "\n  ")) != NULL; ++n) {
        char name[64], word[80];
        q += 3;
        snprintf(name, sizeof name, "%.*s", (int)strcspn(q, " \n"), q);
        snprintf(word, sizeof word, " %s", name);
        if (!strstr(line, word)) fprintf(stderr, "  '%s' not in: %s\n", name, line);
        ENSURE(strstr(line, word));
    }
    ENSURE(n >= 11);
}

// Number options out of their range (--augment past the classifier's 16,
// which it cut silently; a negative --busy-timeout, which was the default;
// sketch counts, --folds 1) and db init options of the other way to make a
// database (ignored before) are bad usage, one line naming the option and
// the range, with the database untouched. A typed 0 sketch count is none, as
// -1 (it was the default: 60 sketches).
static void test_number_options_cli(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024], cmd[4096], out[65536];
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("numbers.db"));
    sp_fixture_remove_db(p);
    snprintf(cmd, sizeof cmd, "'%s' db add-part --db '%s' '%s' --synth 0 --no-selftest", bin, p, part_file(0));
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 1 && scalar(p, "SELECT count(*) FROM sketches") == 0);
    char before[65], after[65];
    file_sha(p, before);
    const char* bad[][2] = {{"add-part x.glb --synth -2", "--synth must be -1 or 0 (none) to 10000, got -2"},
                            {"init --concepts 10001", "--concepts must be -1 or 0 (none) to 10000, got 10001"},
                            {"init --drawings 101", "--drawings must be -1 or 0 (none) to 100, got 101"},
                            {"init --folds 1", "--folds must be -1 or 0 (none), or 2..100, got 1"},
                            {"train --folds 101", "--folds must be -1 or 0 (none), or 2..100, got 101"},
                            {"train --curated-max 0", "--curated-max must be -1 (all) or 1..1000000, got 0"},
                            {"train --keep-models 0", "--keep-models must be -1 (all) or 1..1000000, got 0"},
                            {"init --from x --synth 5", "--synth does not apply with --from DIR"},
                            {"init --from x --assets y", "--assets does not apply with --from DIR"},
                            {"init --no-train", "--no-train does not apply without --from DIR"},
                            {"review --approve 1 --limit 5", "--limit chooses what is listed; it does not apply"},
                            {"review --relabel 1 tail --status all", "--status chooses what is listed; it does not apply"},
                            {"train --augment 17", "--augment must be 0..16, got 17"},
                            {"train --augment -1", "--augment must be 0..16, got -1"},
                            {"list --busy-timeout -1", "--busy-timeout must be in [0, 86400], got -1"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' db %s --db '%s' 2>&1 >/dev/null", bin, bad[i][0], p);
        int rc = sp_fixture_run(cmd, out, sizeof out);
        if (rc != 2 || !strstr(out, bad[i][1])) fprintf(stderr, "  db %s: exit %d: %s", bad[i][0], rc, out);
        ENSURE(rc == 2 && strstr(out, bad[i][1]) && strchr(out, '\n') == out + strlen(out) - 1);
    }
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
}

// The derivation options, given for a part with abstractions of its own
// (stored as it is), are refused by the library too, naming the option and
// the part: they were ignored, even a joint the part does not have.
static void test_add_part_derive_options(void)
{
    const char* p = sp_test_tmp_path("derive_options.db");
    sp_fixture_remove_db(p);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    sp_error err = {0};
    const sp_db_part_desc bad[2] = {{.name = "a", .attach_joint = "no_such_joint", .synth_sketches = -1, .selftest_seeds = -1},
                                    {.name = "a", .view = SP_DERIVE_VIEW_NEG_Z, .synth_sketches = -1, .selftest_seeds = -1}};
    for (int i = 0; i < 2; ++i) {
        ENSURE(sp_db_add_part_file(db, part_file(0), &bad[i], NULL, &err) == SP_ERR_INVALID);
        fprintf(stderr, "  %s\n", err.text);
        ENSURE(strstr(err.text, part_file(0)) == err.text && strstr(err.text, i ? "view applies" : "attach_joint applies") &&
               strstr(err.text, "already has sketchpose extras"));
    }
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 0);
    sp_db_close(db);
}

// A part whose category differs from one the database has only in case is
// refused naming both (the kiosk showed two "Front legs" tiles); the same
// category, and another one, are stored. So are part names, and sketches'
// categories.
static void test_category_case(void)
{
    const char* p = sp_test_tmp_path("category_case.db");
    sp_fixture_remove_db(p);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    add_ok(db, 0, -1); // tail_a: tail
    sp_error err = {0};
    const sp_db_part_desc quick = {.synth_sketches = -1, .selftest_seeds = -1};
    sp_db_part_desc d = quick;
    d.name = "tail_x", d.category = "Tail";
    ENSURE(sp_db_add_part_file(db, part_file(3), &d, NULL, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "category 'Tail' differs from its 'tail' only in case"));
    d.category = "tail";
    ENSURE(sp_db_add_part_file(db, part_file(3), &d, NULL, &err) == SP_OK);
    d.name = "tail_y", d.category = "tails";
    ENSURE(sp_db_add_part_file(db, part_file(3), &d, NULL, &err) == SP_OK);
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 3);
    // A part name differing only in case: two files of one name in an
    // export on a case-blind stick (an outside curator review).
    d.name = "TAIL_Y", d.category = "tails";
    ENSURE(sp_db_add_part_file(db, part_file(3), &d, NULL, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "part name 'TAIL_Y' differs from its 'tail_y' only in case"));
    // Sketches of a category differing only in case from a part's, or from
    // another of the same set, were stored apart and never trained on.
    sp_dataset ds = synth_as(db, "tail_x", 2, "TAIL");
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "category 'TAIL' differs from its 'tail' only in case"));
    free(ds.categories[0]);
    ds.categories[0] = strdup("rider");
    ENSURE(sp_dataset_add_category(&ds, "Rider") == 1);
    ds.samples[1].label = 1;
    ENSURE(sp_db_add_sketches(db, &ds, NULL, SP_DB_SOURCE_CURATED, "test", NULL, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "categories 'rider' and 'Rider' differ only in case"));
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'curated'") == 0);
    sp_dataset_free(&ds);
    sp_db_close(db);
}

// A part whose sp_part names a joint its skeleton lacks (a bone renamed in
// an editor after deriving) is refused naming the joint; the kiosk attached
// it by its root without a word (an outside curator review).
static void test_attach_joint_missing(void)
{
    const char* p = sp_test_tmp_path("attach_missing.db");
    sp_fixture_remove_db(p);
    sp_db* db = open_ok(p, SP_DB_CREATE);
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(part_file(0), &ch, &err) == SP_OK);
    ch.has_part = true, ch.part.has_attach = true;
    snprintf(ch.part.attach.joint, sizeof ch.part.attach.joint, "Hips");
    if (!ch.part.category[0]) snprintf(ch.part.category, sizeof ch.part.category, "tail");
    const char* renamed = sp_test_tmp_path("renamed.glb");
    ENSURE(sp_gltf_save(&ch, ch.pose, renamed, &err) == SP_OK);
    sp_character_free(&ch);
    const sp_db_part_desc quick = {.synth_sketches = -1, .selftest_seeds = -1};
    ENSURE(sp_db_add_part_file(db, renamed, &quick, NULL, &err) == SP_ERR_INVALID);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(strstr(err.text, "sp_part.attach names joint 'Hips', which the part does not have"));
    ENSURE(scalar(p, "SELECT count(*) FROM parts") == 0);
    sp_db_close(db);
}

// A set built by one public call and then appended to by another: the
// builders sized the samples exactly while sp_dataset_add_sample took its
// room from the count, and wrote past the end (an outside code review;
// ASan saw it).
static void test_dataset_appends_after_builders(void)
{
    sp_character ch = {0};
    sp_error err = {0};
    ENSURE(sp_gltf_load(part_file(0), &ch, &err) == SP_OK);
    sp_dataset ds = {0};
    ENSURE(sp_dataset_add_category(&ds, "tail") == 0);
    ENSURE(sp_handdraw_dataset(&ch.rig, 0, &ch.camera, &(sp_handdraw_desc){0}, 1, 3, 0, 0, &ds, &err) == SP_OK);
    ENSURE(ds.count == 3 && ds.capacity >= 3);
    for (int k = 0; k < 20; ++k) {
        sp_sample smp = {.label = 0};
        ENSURE(sp_sketch_add_stroke(&smp.sketch, (const sp_vec2[2]){{0, 0}, {10, 10 + k}}, NULL, 2) == SP_OK);
        ENSURE(sp_dataset_add_sample(&ds, &smp) == SP_OK);
        ENSURE(ds.capacity >= ds.count && ds.samples[ds.count - 1].index == 3 + k);
    }
    ENSURE(sp_handdraw_dataset(&ch.rig, 0, &ch.camera, &(sp_handdraw_desc){0}, 2, 5, 0, 23, &ds, &err) == SP_OK);
    ENSURE(ds.count == 28 && ds.capacity >= 28 && ds.samples[27].sketch.stroke_count > 0);
    // A set made by hand (no capacity kept) holds exactly its count.
    sp_dataset exact = {.count = 1, .samples = calloc(1, sizeof(sp_sample)), .category_count = 0};
    ENSURE(exact.samples && sp_dataset_reserve(&exact, 1) == SP_OK && exact.capacity >= 2);
    ENSURE(sp_dataset_reserve(&exact, -1) == SP_ERR_NO_MEMORY && sp_dataset_reserve(&exact, INT_MAX) == SP_ERR_NO_MEMORY);
    sp_dataset_free(&exact);
    sp_dataset_free(&ds);
    sp_character_free(&ch);
}

// add-part and add-sketch create the database at a --db path where no file
// is (documented), and now say so on stderr, one line naming it, so that a
// mistyped path or a wrong folder is noticed; into an existing one, not a word.
static void test_new_db_said_cli(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024], cmd[4096], out[65536];
    const char* sketch = sp_test_tmp_path("said_one.json");
    const char* text = "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [9, 9], \"strokes\": [{\"points\": "
                       "[[1, 2], [2, 3]]}]}";
    sp_error err = {0};
    ENSURE(db_write_file(sketch, text, strlen(text), &err) == SP_OK);
    const char* adds[2][2] = {{"add-part", "--synth 0 --no-selftest --name"}, {"add-sketch", "--category tail --source"}};
    for (int i = 0; i < 2; ++i) {
        snprintf(p, sizeof p, "%s", sp_test_tmp_path(i ? "said_sketch.db" : "said_part.db"));
        sp_fixture_remove_db(p);
        for (int again = 0; again < 2; ++again) {
            // The second part needs a name of its own; the sketches take either source.
            const char* last = i ? (again ? "kiosk" : "curated") : (again ? "p1" : "p0");
            snprintf(cmd, sizeof cmd, "'%s' db %s --db '%s' '%s' %s %s 2>&1 >/dev/null", bin, adds[i][0], p,
                     i ? sketch : part_file(0), adds[i][1], last);
            int rc = sp_fixture_run(cmd, out, sizeof out);
            fprintf(stderr, "  db %s (%s): exit %d: %s", adds[i][0], again ? "again" : "new", rc, out);
            char want[1400];
            snprintf(want, sizeof want,
                     "sketchpose db %s: created a new database %s (no file was there; the kiosk's default database is built by "
                     "`sketchpose db init`)\n",
                     adds[i][0], p);
            ENSURE(rc == 0 && (again ? !strstr(out, "created a new database") : strstr(out, want) == out));
        }
        ENSURE(scalar(p, i ? "SELECT count(*) FROM sketches" : "SELECT count(*) FROM parts") == 2);
    }
}

// A sketch of a category no part has is stored (a curator may add the
// sketch before the part) with one warning line naming the category and the
// database's part categories; it was stored silently, and training later
// counted it among unused drawings. A category with a part gets no warning.
static void test_add_sketch_partless_cli(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024], cmd[4096], out[65536];
    snprintf(p, sizeof p, "%s", base_db("partless.db"));
    const char* one = sp_test_tmp_path("partless.json");
    const char* text = "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [9, 9], \"strokes\": [{\"points\": "
                       "[[1, 2], [2, 3]]}]}";
    sp_error err = {0};
    ENSURE(db_write_file(one, text, strlen(text), &err) == SP_OK);
    int before = scalar(p, "SELECT count(*) FROM sketches");
    snprintf(cmd, sizeof cmd, "'%s' db add-sketch --db '%s' --category horns '%s' 2>&1 >/dev/null", bin, p, one);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    fprintf(stderr, "  %s", out);
    ENSURE(strstr(out, "warning: no part of category 'horns'") && strstr(out, "its part categories: tail, wings") &&
           strchr(out, '\n') == out + strlen(out) - 1);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches") == before + 1);
    snprintf(cmd, sizeof cmd, "'%s' db add-sketch --db '%s' --category tail '%s' 2>&1 >/dev/null", bin, p, one);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && out[0] == 0);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches") == before + 2);
}

// db init through the command line: it says how many people's strokes joined,
// and a --quickdraw folder that is not there is one line, exit 1, no database.
static void test_default_db_cli(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char root[1024], assets[1100], p[1024], cmd[8192], out[65536];
    snprintf(root, sizeof root, "%s", default_assets("defcli", assets, sizeof assets));
    snprintf(p, sizeof p, "%s", sp_test_tmp_path("defcli.db"));
    sp_fixture_remove_db(p);
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s' --assets '%s' --synth 8 --concepts 2 --folds -1 --words 32 --quickdraw '%s/nowhere' 2>&1",
             bin, p, assets, root);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "nowhere: no such folder") &&
           strchr(out, '\n') == out + strlen(out) - 1);
    struct stat st;
    ENSURE(stat(p, &st) != 0);
    // A folder that is not there: the error names the database given, not the file built beside it.
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s/nowhere/x.db' --assets '%s' 2>&1", bin, root, assets);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "nowhere/x.db: cannot create it: the folder") &&
           strstr(out, "nowhere is not there") && !strstr(out, ".building-"));
    // A concept family that is not one: one line, a usage exit, no database.
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s' --assets '%s' --concept-family 0 2>&1", bin, p, assets);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "--concept-family must be 1 to 1000000") &&
           strchr(out, '\n') == out + strlen(out) - 1);
    ENSURE(stat(p, &st) != 0);
    // Two tails and a horn join, and the JSON counts each maker's sketches: 3 parts x 8, tail and wings concepts x 2
    // (horns have none), the one design twice.
    char f[1200];
    snprintf(f, sizeof f, "%s/sketches/drawings.json", assets);
    put_text(f, "{\"drawings\": [{\"name\": \"t\", \"label\": \"tail\", \"points\": [[0, 50], [50, 30], [100, 60]]}]}");
    // What builds killed meanwhile left beside it (SIGKILL, SIGTERM, each
    // under its own pid) goes with the next build: one of an older
    // sketchpose (no lock file) whose pid is gone, one whose lock nobody
    // holds. A build whose lock is held stays, whatever its pid says (in
    // another PID namespace or on another NFS client it means nothing here),
    // and so does one with no lock whose process is alive.
    pid_t gone = fork();
    if (gone == 0) _exit(0);
    ENSURE(gone > 0 && waitpid(gone, NULL, 0) == gone);
    char stale[4][1200], live[1200], held[2][1200];
    static const char* const sides[4] = {"", "-wal", "-shm", "-lock"};
    for (int i = 0; i < 4; ++i) {
        snprintf(stale[i], sizeof stale[i], "%s.building-%ld%s", p, (long)(i < 3 ? gone : gone + 1000000), i < 3 ? sides[i] : "");
        put_text(stale[i], "left by a killed build");
    }
    char unheld_lock[1300];
    snprintf(unheld_lock, sizeof unheld_lock, "%s-lock", stale[3]);
    put_text(unheld_lock, "");
    snprintf(live, sizeof live, "%s.building-%ld", p, (long)getpid());
    put_text(live, "a build that is still running");
    for (int i = 0; i < 2; ++i)
        snprintf(held[i], sizeof held[i], "%s.building-%ld%s", p, (long)gone + 2000000, sides[3 * i]);
    put_text(held[0], "a build in another namespace");
    int held_fd = open(held[1], O_RDWR | O_CREAT, 0600);
    ENSURE(held_fd >= 0 && flock(held_fd, LOCK_EX | LOCK_NB) == 0);
    // A hidden database's leftovers too (the folder reader skipped them).
    char hidden_db[1200], hidden[1300];
    snprintf(hidden_db, sizeof hidden_db, "%s/.hidden_%ld.db", root, (long)getpid());
    snprintf(hidden, sizeof hidden, "%s.building-%ld", hidden_db, (long)gone);
    put_text(hidden, "left by a killed build of a hidden database");
    snprintf(cmd, sizeof cmd,
             "'%s' db init --db '%s' --assets '%s' --synth 8 --concepts 2 --drawings 2 --folds -1 --words 32 2>/dev/null", bin, p,
             assets);
    int rc = sp_fixture_run(cmd, out, sizeof out);
    for (int i = 0; i < 4; ++i)
        ENSURE(stat(stale[i], &st) != 0);
    ENSURE(stat(unheld_lock, &st) != 0);
    ENSURE(stat(live, &st) == 0 && stat(held[0], &st) == 0 && stat(held[1], &st) == 0);
    unlink(live), unlink(held[0]), unlink(held[1]);
    close(held_fd);
    // The build itself left nothing beside the database: no file, no lock.
    char listing[4096];
    snprintf(cmd, sizeof cmd, "ls -a \"$(dirname '%s')\" | grep -F \"$(basename '%s').building-\"", p, p);
    ENSURE(sp_fixture_run(cmd, listing, sizeof listing) == 1 && !listing[0]);
    snprintf(cmd, sizeof cmd, "'%s' db init --db '%s' --assets '%s' --synth 8 --concepts 2 --folds -1 --words 32 >/dev/null 2>&1",
             bin, hidden_db, assets);
    ENSURE(system(cmd) == 0 && stat(hidden, &st) != 0 && stat(hidden_db, &st) == 0);
    sp_fixture_remove_db(hidden_db);
    if (rc != 0) fprintf(stderr, "  db init: %d %s\n", rc, out);
    ENSURE(rc == 0 && strstr(out, "\"people_strokes\": 3") && strstr(out, "\"part_sketches\": 24") &&
           strstr(out, "\"concept_sketches\": 4") && strstr(out, "\"design_sketches\": 2"));
    // The data moved away: built without them, with a warning that names picks.json.
    sp_fixture_remove_db(p);
    snprintf(cmd, sizeof cmd, "rm -rf '%s/qd' && '%s' db init --db '%s' --assets '%s' --synth 8 --concepts 2 --folds -1 --words 32 2>&1 >/dev/null",
             root, bin, p, assets);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 &&
           strstr(out, "sketches/picks.json: the Quick, Draw! data is not where it says"));
    ENSURE(stat(p, &st) == 0);
}

// `db remove` says what the removal leaves the kiosk: a category the
// newest model still knows that no part has now (its strokes became
// another part, with nothing offered, until a retrain) and a dragon with no
// body. Another part of the category left: nothing said.
static void test_remove_notes(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024], cmd[4096], out[8192];
    snprintf(p, sizeof p, "%s", base_db("remove_notes.db"));
    sp_db* db = open_ok(p, 0);
    sp_error err = {0};
    const sp_db_part_desc quick = {.synth_sketches = -1, .selftest_seeds = -1};
    sp_db_part_desc d = quick;
    d.name = "tail_b", d.category = "tail";
    ENSURE(sp_db_add_part_file(db, part_file(0), &d, NULL, &err) == SP_OK);
    d.name = "blob", d.category = "torso";
    ENSURE(sp_db_add_part_file(db, part_file(3), &d, NULL, &err) == SP_OK);
    sp_db_close(db);
    const char* cases[][2] = {{"tail_b", ""}, // tail_a stays
                              {"wings_a", "no part of category wings is left, and the newest model still knows it"},
                              {"blob", "no body (category torso) is left"}};
    for (int i = 0; i < 3; ++i) {
        snprintf(cmd, sizeof cmd, "'%s' db remove %s --db '%s' 2>&1 >/dev/null", bin, cases[i][0], p);
        ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
        fprintf(stderr, "  remove %s: %s", cases[i][0], out[0] ? out : "(nothing said)\n");
        ENSURE(cases[i][1][0] ? strstr(out, cases[i][1]) && !strchr(strchr(out, '\n') + 1, '\n') : !out[0]);
    }
}

// The review through the command line, end to end: a stroke the visitor
// corrected is collected with the corrected label, listed, approved, trained on.
// A page of kiosk sketches approved but the few rejected: FIRST-LAST sets
// the pending ones in it, in one transaction with the ids given alone.
static void test_kiosk_review_ranges(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("ranges.db"));
    sp_db* db = open_ok(p, 0);
    int64_t id[8];
    for (int i = 0; i < 8; ++i)
        id[i] = collect_ok(db, i % 2 ? "tail" : "wings", i);
    sp_error err = {0};
    ENSURE(sp_db_kiosk_set_status(db, &id[2], 1, SP_DB_REJECTED, "curator", &err) == SP_OK);
    // The library: an id also in a range is listed once; a range with
    // nothing pending fails and changes nothing.
    int64_t* changed = NULL;
    int m = 0;
    sp_db_kiosk_range g = {id[6], id[7]};
    ENSURE(sp_db_kiosk_review(db, &id[7], 1, &g, 1, SP_DB_REJECTED, "curator", &changed, &m, &err) == SP_OK);
    ENSURE(m == 2 && changed[0] == id[6] && changed[1] == id[7]);
    free(changed);
    int counts[SP_DB_STATUS_COUNT];
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 5 && counts[SP_DB_REJECTED] == 3);
    ENSURE(sp_db_kiosk_review(db, &id[0], 1, &g, 1, SP_DB_APPROVED, "curator", NULL, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "no pending kiosk sketch in"));
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 5 && counts[SP_DB_APPROVED] == 0);
    // A good range and an unknown id: the range's changes are rolled back.
    int64_t bogus = 424242;
    g = (sp_db_kiosk_range){id[0], id[1]};
    ENSURE(sp_db_kiosk_review(db, &bogus, 1, &g, 1, SP_DB_APPROVED, "curator", NULL, NULL, &err) == SP_ERR_INVALID &&
           strstr(err.text, "no kiosk sketch 424242"));
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 5 && counts[SP_DB_APPROVED] == 0);
    sp_db_close(db);
    // The command: the range approves the pending ones, the rejected stay so.
    char cmd[4096], out[65536], want[256];
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --approve %lld-%lld", bin, p, (long long)id[0], (long long)id[7]);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    snprintf(want, sizeof want, "{\"approved\": [%lld, %lld, %lld, %lld, %lld]}", (long long)id[0], (long long)id[1],
             (long long)id[3], (long long)id[4], (long long)id[5]);
    fprintf(stderr, "  %s", out);
    ENSURE(strstr(out, want));
    db = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 0 && counts[SP_DB_APPROVED] == 5 &&
           counts[SP_DB_REJECTED] == 3);
    sp_db_close(db);
    // Nothing pending left in it (exit 1), a range backwards, a half range (exit 2): one line, nothing changed.
    char before[65], after[65];
    file_sha(p, before);
    const char* bad[][2] = {{"", "no pending kiosk sketch in"}, {"9-3", "'9-3' is not a kiosk sketch id"}, {"4-", "'4-' is not"}};
    for (int i = 0; i < 3; ++i) {
        if (i == 0)
            snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --reject %lld-%lld 2>&1 >/dev/null", bin, p, (long long)id[0],
                     (long long)id[7]);
        else
            snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --reject %s 2>&1 >/dev/null", bin, p, bad[i][0]);
        // A malformed value (backwards, half a range) is bad usage, exit 2, as a number out of its range; none pending is exit 1.
        ENSURE(sp_fixture_run(cmd, out, sizeof out) == (i == 0 ? 1 : 2) && strstr(out, bad[i][1]) &&
               strchr(out, '\n') == out + strlen(out) - 1);
    }
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // --delete-rejected: the three rejected go, the approved stay; with a
    // listing option it is bad usage and changes nothing.
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --delete-rejected --status all 2>&1 >/dev/null", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "--status chooses what is listed"));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --delete-rejected --approve %lld 2>&1 >/dev/null", bin, p,
             (long long)id[0]);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "more than one action given"));
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --delete-rejected", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "{\"deleted\": 3}"));
    db = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 0 && counts[SP_DB_APPROVED] == 5 &&
           counts[SP_DB_REJECTED] == 0);
    sp_db_close(db);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "{\"deleted\": 0}"));
}

// A kiosk nobody reviews stops at the cap of pending sketches instead of
// filling its disk (its saves and `db train` need room too): a stroke past
// it is dropped with one line saying why, and a reviewed one makes room. The
// default cap is SP_DB_KIOSK_PENDING_MAX, filled here by SQL with copies of
// one small stroke. Deleting the rejected ones leaves the rest.
static void test_kiosk_pending_cap(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("pending_cap.db"));
    sp_db* db = open_ok(p, 0);
    sp_db_set_kiosk_pending_max(db, 3);
    int64_t id[3];
    for (int i = 0; i < 3; ++i)
        id[i] = collect_ok(db, "tail", i);
    sp_vec2 pts[40];
    double t[40];
    sp_stroke st = visitor_stroke(7, pts, t);
    sp_error err = {0};
    int64_t got = -1;
    ENSURE(sp_db_collect_kiosk_sketch(db, "tail", &st, 1280, 800, &got, &err) == SP_ERR_UNSUPPORTED);
    fprintf(stderr, "  %s\n", err.text);
    ENSURE(got == 0 && strstr(err.text, ": 3 kiosk sketches await review") && strstr(err.text, "sketch dropped") &&
           !strchr(err.text, '\n'));
    int counts[SP_DB_STATUS_COUNT];
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == 3);
    // Rejected and approved ones are not waiting: each makes room for one.
    ENSURE(sp_db_kiosk_set_status(db, &id[0], 1, SP_DB_REJECTED, "curator", &err) == SP_OK);
    collect_ok(db, "tail", 8);
    ENSURE(sp_db_collect_kiosk_sketch(db, "tail", &st, 1280, 800, NULL, &err) == SP_ERR_UNSUPPORTED);
    ENSURE(sp_db_kiosk_set_status(db, &id[1], 1, SP_DB_APPROVED, "curator", &err) == SP_OK);
    collect_ok(db, "wings", 9);
    // The default cap.
    sp_db_set_kiosk_pending_max(db, 0);
    sp_stroke small = visitor_stroke(0, pts, t);
    small.count = 2;
    int64_t seed = 0;
    ENSURE(sp_db_collect_kiosk_sketch(db, "tail", &small, 1280, 800, &seed, &err) == SP_OK);
    sqlite3* h;
    ENSURE(sqlite3_open(p, &h) == SQLITE_OK);
    sqlite3_busy_timeout(h, 5000);
    char sql[512];
    snprintf(sql, sizeof sql,
             "WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n WHERE i < %d) "
             "INSERT INTO sketches(category, source, strokes, added_by, status) "
             "SELECT category, source, strokes, added_by, status FROM sketches, n WHERE sketches.id = %lld",
             SP_DB_KIOSK_PENDING_MAX - 5, (long long)seed);
    ENSURE(sqlite3_exec(h, sql, NULL, NULL, NULL) == SQLITE_OK);
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_PENDING] == SP_DB_KIOSK_PENDING_MAX - 1);
    collect_ok(db, "tail", 10);
    double t0 = sp_now_ms();
    sp_result r = sp_db_collect_kiosk_sketch(db, "tail", &st, 1280, 800, NULL, &err);
    fprintf(stderr, "  at the default cap, %.1f ms: %s\n", sp_now_ms() - t0, err.text);
    char want[64];
    snprintf(want, sizeof want, ": %d kiosk sketches await review", SP_DB_KIOSK_PENDING_MAX);
    ENSURE(r == SP_ERR_UNSUPPORTED && strstr(err.text, want));
    // The curator's review says so, on stderr (its JSON on stdout as always).
    const char* bin = sketchpose_bin();
    if (bin) {
        char cmd[4096], out[4096];
        snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --limit 1 2>&1 >/dev/null", bin, p);
        ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "kiosk sketches await review, the most a kiosk keeps") &&
               strchr(out, '\n') == out + strlen(out) - 1);
    }
    // Deleting the rejected: only they go, logged; the pending, approved and
    // the part's own sketches stay.
    int all = scalar(p, "SELECT count(*) FROM sketches");
    int deleted = -1;
    ENSURE(sp_db_kiosk_delete_rejected(db, "curator", &deleted, &err) == SP_OK && deleted == 1);
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_REJECTED] == 0 && counts[SP_DB_APPROVED] == 1 &&
           counts[SP_DB_PENDING] == SP_DB_KIOSK_PENDING_MAX);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches") == all - 1);
    ENSURE(scalar(p, "SELECT count(*) FROM log WHERE action = 'delete' AND subject = 'rejected kiosk sketches'") == 1);
    ENSURE(sp_db_kiosk_delete_rejected(db, "curator", &deleted, &err) == SP_OK && deleted == 0);
    // A database in use: nothing deleted, one line.
    ENSURE(sp_db_kiosk_set_status(db, &id[2], 1, SP_DB_REJECTED, "curator", &err) == SP_OK);
    ENSURE(sqlite3_exec(h, "BEGIN IMMEDIATE", NULL, NULL, NULL) == SQLITE_OK);
    sp_db_set_busy_timeout(db, 50);
    deleted = -1;
    ENSURE(sp_db_kiosk_delete_rejected(db, "curator", &deleted, &err) == SP_ERR_BUSY && deleted == 0 && strstr(err.text, p));
    sqlite3_exec(h, "ROLLBACK", NULL, NULL, NULL);
    sqlite3_close(h);
    ENSURE(sp_db_kiosk_counts(db, counts, &err) == SP_OK && counts[SP_DB_REJECTED] == 1);
    sp_db_close(db);
}

// A sketch id names one drawing for good: the newest kiosk sketches
// rejected and deleted, the next one stored takes a new id (SQLite gave it
// the deleted one's, and the log's "rejected [ids]" and a review's --after
// then named another visitor's stroke: an operations review).
static void test_sketch_ids_kept(void)
{
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("ids.db"));
    sp_db* db = open_ok(p, 0);
    sp_error err = {0};
    int64_t id[3];
    for (int k = 0; k < 3; ++k)
        id[k] = collect_ok(db, "tail", k);
    ENSURE(sp_db_kiosk_set_status(db, &id[1], 2, SP_DB_REJECTED, "curator", &err) == SP_OK);
    int deleted = 0;
    ENSURE(sp_db_kiosk_delete_rejected(db, "curator", &deleted, &err) == SP_OK && deleted == 2);
    int64_t next = collect_ok(db, "head", 3);
    fprintf(stderr, "  ids %lld %lld %lld, the last two deleted: the next is %lld\n", (long long)id[0], (long long)id[1],
            (long long)id[2], (long long)next);
    ENSURE(next > id[2]);
    sp_db_close(db);
}

static void test_kiosk_review_cli(void)
{
    const char* bin = sketchpose_bin();
    if (!bin) SKIP("sketchpose not built");
    char p[1024];
    snprintf(p, sizeof p, "%s", base_db("review.db"));
    sp_db* kiosk = open_ok(p, 0);
    int64_t first = collect_ok(kiosk, "tail", 0); // the classifier's guess, left as it was
    int64_t id = collect_ok(kiosk, "wings", 3);   // the visitor tapped the "Wings?" chip
    sp_db_close(kiosk);
    char cmd[4096], out[65536];
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s'", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    char want[128];
    snprintf(want, sizeof want, "{\"id\": %lld, \"category\": \"wings\", \"status\": \"pending\", \"created_at\": \"",
             (long long)id);
    ENSURE(strstr(out, "{\"sketches\": [{\"id\": ") && strstr(out, want) && strstr(out, "\"points\": [[303, 403]"));
    ENSURE(strstr(out, "\"counts\": {\"pending\": 2, \"approved\": 0, \"rejected\": 0}"));
    ENSURE(strstr(out, "{\"id\": ") < strstr(out, want)); // oldest first: the other one is listed before
    // Pages: next_after is the next page's --after, null on the last page (also when that page is full).
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --limit 1", bin, p);
    snprintf(want, sizeof want, "\"next_after\": %lld}", (long long)first);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, want));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --limit 1 --after %lld", bin, p, (long long)first);
    snprintf(want, sizeof want, "{\"id\": %lld,", (long long)id);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, want) && strstr(out, "\"next_after\": null}"));
    // The contact sheet.
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --sheet '%s' >/dev/null", bin, p, sp_test_tmp_path("review.png"));
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    struct stat fs;
    ENSURE(stat(sp_test_tmp_path("review.png"), &fs) == 0 && fs.st_size > 1000);
    // A sheet not named .png is bad usage, one line, and no file (it got a PNG).
    unlink(sp_test_tmp_path("review.jpg"));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --sheet '%s' 2>&1 >/dev/null", bin, p, sp_test_tmp_path("review.jpg"));
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "--sheet writes a PNG") &&
           strchr(out, '\n') == out + strlen(out) - 1);
    ENSURE(stat(sp_test_tmp_path("review.jpg"), &fs) != 0);
    // An unknown id: one line, exit 1, nothing changed.
    char before[65], after[65];
    file_sha(p, before);
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --approve %lld 424242 2>&1 >/dev/null", bin, p, (long long)id);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "no kiosk sketch 424242") &&
           !strchr(strchr(out, '\n') + 1, '\n'));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --reject nine 2>&1 >/dev/null", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "'nine' is not a kiosk sketch id"));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --approve 99999999999999999999 2>&1 >/dev/null", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, "'99999999999999999999' is not a kiosk sketch id"));
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // A database in use: one clear line, exit 1, nothing lost.
    sqlite3* other;
    ENSURE(sqlite3_open(p, &other) == SQLITE_OK);
    ENSURE(sqlite3_exec(other, "BEGIN IMMEDIATE; INSERT INTO log(by, action) VALUES ('other', 'hold')", NULL, NULL, NULL) ==
           SQLITE_OK);
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --busy-timeout 0.2 --approve %lld 2>&1 >/dev/null", bin, p,
             (long long)id);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "database is busy") && !strchr(strchr(out, '\n') + 1, '\n'));
    sqlite3_exec(other, "COMMIT", NULL, NULL, NULL);
    sqlite3_close(other);
    // Results that cannot be written (a full disk) are an error, not success.
    snprintf(cmd, sizeof cmd, "'%s' db list --db '%s' 2>&1 >/dev/full", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "sketchpose: stdout: write error (No space left on device)"));
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' 2>&1 >/dev/full", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "stdout: write error"));
    // Locked outright (a rollback-journal write): --busy-timeout holds from the
    // open on (the open waited the default 5 s and named it).
    ENSURE(sqlite3_open(p, &other) == SQLITE_OK);
    ENSURE(sqlite3_exec(other,
                        "PRAGMA journal_mode = DELETE; BEGIN EXCLUSIVE; INSERT INTO log(by, action) VALUES ('other', 'hold')",
                        NULL, NULL, NULL) == SQLITE_OK);
    snprintf(cmd, sizeof cmd, "'%s' db list --db '%s' --busy-timeout 0.2 2>&1 >/dev/null", bin, p);
    double t0 = sp_now_ms();
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "more than 0.2 s"));
    ENSURE(sp_now_ms() - t0 < 3000);
    // 0 means no wait (it was the default 5 s).
    snprintf(cmd, sizeof cmd, "'%s' db list --db '%s' --busy-timeout 0 2>&1 >/dev/null", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "more than 0 s"));
    sqlite3_exec(other, "COMMIT", NULL, NULL, NULL);
    sqlite3_close(other);
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'pending'") == 2);
    // Approve, reject the other, train: the new model's training set has it.
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --approve %lld", bin, p, (long long)id);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "\"approved\": ["));
    // Its JSON lost to a full disk: exit 1, and the line says the rejection is kept (it is).
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --reject %lld 2>&1 >/dev/full", bin, p, (long long)first);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "done all the same: the review is stored in") &&
           !strchr(strchr(out, '\n') + 1, '\n'));
    ENSURE(scalar(p, "SELECT count(*) FROM sketches WHERE source = 'kiosk' AND status = 'rejected'") == 1);
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --status approved", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "\"status\": \"approved\"") &&
           strstr(out, "\"category\": \"wings\""));
    // --status all lists every status, the rejected one too.
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --status all", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "\"status\": \"approved\"") &&
           strstr(out, "\"status\": \"rejected\""));
    // One action at a time, and --relabel takes one id and one category:
    // anything else is bad usage (exit 2), and nothing changes.
    file_sha(p, before);
    // Each said for what was given (one message read as if no action had
    // been given; an outside review).
    const struct {
        const char *args, *says;
    } usage[] = {{"--approve %1$lld --reject %2$lld", "more than one action given"},
                 {"--relabel %1$lld wings %2$lld", "--relabel takes one id and its new category (--relabel ID CATEGORY), got 3"},
                 {"--relabel %1$lld", "got 1 value\n"},
                 {"--approve %1$lld --sheet s.png", "an action with --sheet"}};
    for (size_t u = 0; u < sizeof usage / sizeof usage[0]; ++u) {
        char args[200];
        snprintf(args, sizeof args, usage[u].args, (long long)id, (long long)first);
        snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' %s 2>&1 >/dev/null", bin, p, args);
        ENSURE(sp_fixture_run(cmd, out, sizeof out) == 2 && strstr(out, usage[u].says) &&
               strchr(out, '\n') == out + strlen(out) - 1);
    }
    // --relabel acts on kiosk sketches only: a curated or generated one is
    // "no kiosk sketch", exit 1.
    long long other_id = (long long)scalar(p, "SELECT min(id) FROM sketches WHERE source != 'kiosk'");
    snprintf(cmd, sizeof cmd, "'%s' db review --db '%s' --relabel %lld wings 2>&1 >/dev/null", bin, p, other_id);
    char no_such[80];
    snprintf(no_such, sizeof no_such, "no kiosk sketch %lld", other_id);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, no_such));
    file_sha(p, after);
    ENSURE(!strcmp(before, after));
    // A model trained with its report lost to a full disk is kept, and the line says so.
    int models = scalar(p, "SELECT count(*) FROM models");
    snprintf(cmd, sizeof cmd, "'%s' db train --db '%s' --words 64 --folds -1 2>&1 >/dev/full", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "done all the same: the new model is stored in"));
    ENSURE(scalar(p, "SELECT count(*) FROM models") == models + 1);
    snprintf(cmd, sizeof cmd, "'%s' db train --db '%s' --words 64 --folds -1", bin, p);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0);
    fprintf(stderr, "  train: %.160s\n", out);
    ENSURE(strstr(out, "\"kiosk_sketches\": 1,"));
    sp_db* db = open_ok(p, SP_DB_READONLY);
    sp_dataset ds;
    db_training_counts n;
    sp_error err = {0};
    ENSURE(db_load_training_set(db, SP_DB_KIOSK_TRAIN_MAX, -1, &ds, &n, &err) == SP_OK && n.kiosk == 1);
    bool found = false;
    for (int i = 0; i < ds.count; ++i) {
        const sp_sketch* s = &ds.samples[i].sketch;
        found |= !strcmp(ds.categories[ds.samples[i].label], "wings") && s->stroke_count == 1 && s->strokes[0].count == 40 &&
                 s->strokes[0].points[0].x == 303 && s->strokes[0].points[0].y == 403;
    }
    ENSURE(found);
    sp_dataset_free(&ds);
    sp_db_close(db);
    // db check: a part whose bytes no longer match their checksum, or their
    // recorded size, is a problem, said, with exit 1.
    const char* tamper[] = {"UPDATE parts SET sha256 = 'x' || substr(sha256, 2) WHERE name = (SELECT min(name) FROM parts)",
                            "UPDATE parts SET bytes = bytes + 1 WHERE name = (SELECT min(name) FROM parts)"};
    const char* said[] = {"checksum mismatch", "size mismatch"};
    for (int t = 0; t < 2; ++t) {
        char copy[1100];
        snprintf(copy, sizeof copy, "%s", sp_test_tmp_path("tampered.db"));
        sp_fixture_remove_db(copy);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p, copy);
        ENSURE(system(cmd) == 0);
        ENSURE(sqlite3_open(copy, &other) == SQLITE_OK && sqlite3_exec(other, tamper[t], NULL, NULL, NULL) == SQLITE_OK);
        sqlite3_close(other);
        snprintf(cmd, sizeof cmd, "'%s' db check --db '%s' 2>/dev/null", bin, copy);
        ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "\"ok\": false") && strstr(out, said[t]));
        sp_fixture_remove_db(copy);
    }
    // Past the file size limit (ulimit -f: 5 KB, less than the -shm SQLite
    // makes to read a WAL database): one line that says so, exit 1, not
    // "disk I/O error" (nor, before SIGXFSZ was ignored, a silent death).
    {
        char copy[1100];
        snprintf(copy, sizeof copy, "%s", sp_test_tmp_path("limited.db"));
        sp_fixture_remove_db(copy);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p, copy);
        ENSURE(system(cmd) == 0);
        snprintf(cmd, sizeof cmd, "ulimit -f 10; '%s' db check --db '%s' 2>&1 >/dev/null", bin, copy);
        int rc = sp_fixture_run(cmd, out, sizeof out);
        fprintf(stderr, "  ulimit -f 10: exit %d: %s", rc, out);
        ENSURE(rc == 1 && strstr(out, "file size limit (ulimit -f)") && strchr(out, '\n') == out + strlen(out) - 1);
        sp_fixture_remove_db(copy);
    }
    // The database's current model classifies (classify --db); a bad stroke file is one line and exit 1.
    snprintf(cmd, sizeof cmd, "'%s' classify --db '%s' --strokes '%s/tests/data/visitors/tune/tail/tail-wavy-line.json'", bin, p,
             SP_SOURCE_DIR);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 0 && strstr(out, "{\"ranked\": [{\"category\": "));
    const char* badf = sp_test_tmp_path("bad-stroke.json");
    ENSURE(db_write_file(badf, "{\"format\": \"sketchpose-strokes\", \"strokes\": [", 40, &err) == SP_OK);
    snprintf(cmd, sizeof cmd, "'%s' classify --db '%s' --strokes '%s' 2>&1 >/dev/null", bin, p, badf);
    ENSURE(sp_fixture_run(cmd, out, sizeof out) == 1 && strstr(out, "bad-stroke.json") && !strchr(strchr(out, '\n') + 1, '\n'));
}

// Everything under dir (names, sizes, modes, times of change), one entry a
// line: equal listings mean a folder was left exactly as it was.
static void tree_listing(const char* dir, char* out, size_t cap)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "cd '%s' && find . -mindepth 1 -printf '%%p %%s %%m %%T@ %%C@\\n' | sort", dir);
    ENSURE(sp_fixture_run(cmd, out, cap) == 0);
}

static const char* g_export_to; // where export_to writes: past_limit takes no context

static sp_result export_to(sp_db* db, sp_error* err)
{
    return sp_db_export(db, g_export_to, err);
}

// Exports db p into dir with room for files up to `limit` bytes; true when
// it failed part-way at dir/`file`.
static bool export_cut_short(const char* p, const char* dir, off_t limit, const char* file)
{
    char want[1400];
    snprintf(want, sizeof want, "%s/%s", dir, file);
    g_export_to = dir;
    return past_limit(p, SP_DB_READONLY, limit, export_to, want);
}

// SQLite's progress calls counted; the one numbered stop_at (0: none) interrupts the statement.
typedef struct progress {
    int calls, stop_at;
} progress;

static int on_progress(void* p)
{
    progress* g = p;
    return ++g->calls == g->stop_at;
}

// An export is whole or absent: one that fails part-way leaves neither DIR
// nor its temporary folder, an empty DIR stays as it was, and a DIR that is
// not empty is refused untouched (an export never merges into another).
static void test_export_whole(void)
{
    char p[1024], parent[1024], dir[1100], full[1100], cmd[2400];
    snprintf(p, sizeof p, "%s", base_db("export_whole.db"));
    snprintf(parent, sizeof parent, "%s", sp_test_tmp_path("export_whole"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", parent);
    ENSURE(system(cmd) == 0 && mkdir(parent, 0755) == 0);
    snprintf(dir, sizeof dir, "%s/out", parent);
    snprintf(full, sizeof full, "%s/full", parent);
    // Parts are written first, by name: room for tail_a.glb, not wings_a.glb.
    int tail = scalar(p, "SELECT bytes FROM parts WHERE name = 'tail_a'");
    ENSURE(tail < scalar(p, "SELECT bytes FROM parts WHERE name = 'wings_a'"));
    static char before[1 << 16], after[1 << 16];
    tree_listing(parent, before, sizeof before);
    ENSURE(!before[0]);
    ENSURE(export_cut_short(p, dir, tail, "parts/wings_a.glb"));
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after)); // no DIR, no DIR.partial-*
    // An empty DIR is a fine place for an export, and stays as it was when the export fails.
    ENSURE(mkdir(dir, 0750) == 0);
    tree_listing(parent, before, sizeof before);
    ENSURE(export_cut_short(p, dir, tail, "parts/wings_a.glb"));
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // A complete export in a folder of its own is refused as a DIR, and left as it was.
    sp_db* db = open_ok(p, SP_DB_READONLY);
    sp_error err = {0};
    ENSURE(sp_db_export(db, full, &err) == SP_OK);
    tree_listing(parent, before, sizeof before);
    ENSURE(sp_db_export(db, full, &err) == SP_ERR_INVALID && strstr(err.text, full) == err.text && strstr(err.text, "not empty"));
    fprintf(stderr, "  over an export: %s\n", err.text);
    snprintf(cmd, sizeof cmd, "%s/", full); // the same folder, written with a '/'
    ENSURE(sp_db_export(db, cmd, &err) == SP_ERR_INVALID && strstr(err.text, "not empty"));
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // A read failing part-way through the rows (interrupted here, three
    // quarters of the way through a whole export's SQLite steps) fails it too.
    progress g = {0};
    sqlite3_progress_handler(((struct sp_db*)db)->h, 20, on_progress, &g);
    snprintf(cmd, sizeof cmd, "%s/counted", parent);
    ENSURE(sp_db_export(db, cmd, &err) == SP_OK);
    snprintf(cmd, sizeof cmd, "rm -r '%s/counted'", parent);
    ENSURE(system(cmd) == 0);
    g.stop_at = g.calls * 3 / 4, g.calls = 0;
    ENSURE(g.stop_at > 0);
    ENSURE(sp_db_export(db, dir, &err) == SP_ERR_INTERNAL && strstr(err.text, "no export was written") &&
           !strchr(err.text, '\n'));
    fprintf(stderr, "  read cut short: %s\n", err.text);
    sqlite3_progress_handler(((struct sp_db*)db)->h, 0, NULL, NULL);
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // The empty folder takes a whole export and keeps its permissions.
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    sp_db_close(db);
    struct stat st;
    ENSURE(stat(dir, &st) == 0 && (st.st_mode & 0777) == 0750);
    snprintf(cmd, sizeof cmd, "diff -r '%s' '%s'", dir, full);
    ENSURE(system(cmd) == 0);
    // A sketch whose strokes do not parse fails the export, naming the
    // database and the row: `db init --from` would refuse the export (it
    // was written whole, with exit 0).
    sqlite3* h = NULL;
    ENSURE(sqlite3_open(p, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(
               h, "UPDATE sketches SET strokes = 'not json' WHERE id = (SELECT min(id) FROM sketches WHERE strokes IS NOT NULL)",
               NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(h);
    long long bad = scalar(p, "SELECT id FROM sketches WHERE strokes = 'not json'");
    snprintf(cmd, sizeof cmd, "%s/bad", parent);
    tree_listing(parent, before, sizeof before);
    db = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_db_export(db, cmd, &err) == SP_ERR_PARSE && strstr(err.text, p) == err.text && !strchr(err.text, '\n'));
    fprintf(stderr, "  a sketch that does not parse: %s\n", err.text);
    char want[64];
    snprintf(want, sizeof want, ": sketch %lld (", bad);
    ENSURE(strstr(err.text, want) && strstr(err.text, "malformed JSON") && strstr(err.text, "no export was written"));
    sp_db_close(db);
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // So does a part whose stored bytes no longer match their checksum (it
    // was copied without a word, and `db init --from` refused the export).
    ENSURE(sqlite3_open(p, &h) == SQLITE_OK);
    ENSURE(sqlite3_exec(h, "UPDATE parts SET gltf = substr(gltf, 1, 1000) WHERE name = 'tail_a'", NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(h);
    db = open_ok(p, SP_DB_READONLY);
    ENSURE(sp_db_export(db, cmd, &err) == SP_ERR_PARSE && strstr(err.text, p) == err.text && !strchr(err.text, '\n'));
    fprintf(stderr, "  a damaged part: %s\n", err.text);
    ENSURE(strstr(err.text, ": part tail_a (tail): stored bytes do not match the checksum (`db check` lists such parts)") &&
           strstr(err.text, "no export was written"));
    sp_db_close(db);
    tree_listing(parent, after, sizeof after);
    ENSURE(!strcmp(before, after));
    // The command: that one line, exit 1.
    const char* bin = sketchpose_bin();
    if (bin) {
        char line[8192], out[65536];
        snprintf(line, sizeof line, "'%s' db export '%s' --db '%s' 2>&1 >/dev/null", bin, cmd, p);
        int rc = sp_fixture_run(line, out, sizeof out);
        ENSURE(rc == 1 && strstr(out, "sketchpose db export: ") == out && strstr(out, "part tail_a (tail): stored bytes") &&
               strchr(out, '\n') == out + strlen(out) - 1);
        tree_listing(parent, after, sizeof after);
        ENSURE(!strcmp(before, after));
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", parent);
    ENSURE(system(cmd) == 0);
}

// Models go between the classifier and the database in memory: training and
// loading work with no usable temporary folder (a kiosk whose /tmp is full or
// read-only), and a damaged stored model is named by its database and id.
static void test_model_in_memory(void)
{
    const char* p = base_db("model_memory.db");
    char* was = getenv("TMPDIR") ? strdup(getenv("TMPDIR")) : NULL;
    setenv("TMPDIR", "/nonexistent/sp-no-tmp", 1);
    sp_db* db = open_ok(p, 0);
    train_ok(db, -1, NULL);
    sp_clf* clf = NULL;
    sp_error err = {0};
    int64_t id = 0;
    ENSURE(sp_db_load_model(db, &clf, &id, &err) == SP_OK && clf && id > 0);
    sp_clf_destroy(clf);
    sp_db_close(db);
    if (was)
        setenv("TMPDIR", was, 1);
    else
        unsetenv("TMPDIR");
    free(was);
    // A stored model whose bytes still match their checksum but do not parse.
    char sql[256];
    snprintf(sql, sizeof sql, "UPDATE models SET model = X'00', sha256 = '%s' WHERE id = %lld",
             "6e340b9cffb37a989ca544e6bb780a2c78901d3fb33738768511a30617afa01d", (long long)id);
    db = open_ok(p, 0);
    ENSURE(sqlite3_exec(((struct sp_db*)db)->h, sql, NULL, NULL, NULL) == SQLITE_OK);
    ENSURE(sp_db_load_model(db, &clf, NULL, &err) == SP_ERR_PARSE && !clf);
    fprintf(stderr, "  %s\n", err.text);
    char want[1200];
    snprintf(want, sizeof want, "%s: model %lld: not a sketchpose classifier model", p, (long long)id);
    ENSURE(!strcmp(err.text, want));
    sp_db_close(db);
}

// ---- durability ----------------------------------------------------------------------
// What makes a write survive a power cut, recorded through the linker's
// --wrap (partdb.cmake): each fsync(2) by the path its descriptor names, each
// rename(2) and link(2) by absolute paths, in order.

typedef struct sync_event {
    char kind; // 'f' fsync, 'r' rename, 'l' link
    char path[1100], to[1100];
} sync_event;

static struct {
    bool on;
    int n;
    sync_event ev[4096];
} g_sync;

int __real_fsync(int fd);
int __real_rename(const char* from, const char* to);
int __real_link(const char* from, const char* to);

// `p` made absolute by its folder (which exists; p itself may not any more).
static void absolute(const char* p, char out[1100])
{
    char dir[1100], real[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", p);
    char* slash = strrchr(dir, '/');
    const char* base = slash ? slash + 1 : p;
    if (slash) *slash = 0;
    if (!realpath(slash ? (dir[0] ? dir : "/") : ".", real)) snprintf(real, sizeof real, "?");
    snprintf(out, 1100, "%.900s/%.190s", strcmp(real, "/") ? real : "", base); // test paths are far shorter
}

static sync_event* sync_record(char kind)
{
    if (!g_sync.on || g_sync.n == (int)(sizeof g_sync.ev / sizeof g_sync.ev[0])) return NULL;
    sync_event* e = &g_sync.ev[g_sync.n++];
    memset(e, 0, sizeof *e);
    e->kind = kind;
    return e;
}

int __wrap_fsync(int fd)
{
    sync_event* e = sync_record('f');
    if (e) {
        char link[64];
        snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
        ssize_t n = readlink(link, e->path, sizeof e->path - 1);
        e->path[n > 0 ? n : 0] = 0;
    }
    return __real_fsync(fd);
}

// rename(2) or link(2): recorded once it has given `to` its name.
static int record_naming(char kind, const char* from, const char* to, int (*real)(const char*, const char*))
{
    char a[1100], b[1100];
    absolute(from, a), absolute(to, b);
    int r = real(from, to);
    sync_event* e = r == 0 ? sync_record(kind) : NULL;
    if (e) memcpy(e->path, a, sizeof a), memcpy(e->to, b, sizeof b);
    return r;
}

int __wrap_rename(const char* from, const char* to)
{
    return record_naming('r', from, to, __real_rename);
}

int __wrap_link(const char* from, const char* to)
{
    return record_naming('l', from, to, __real_link);
}

static int synced_before(const char* path, int before)
{
    for (int i = 0; i < before; ++i)
        if (g_sync.ev[i].kind == 'f' && !strcmp(g_sync.ev[i].path, path)) return 1;
    return 0;
}

// The event that gave `target` its name (kind 'r' or 'l'); its folder must be synced after it.
static int named_durably(const char* target, char kind)
{
    char abs[1100], parent[1100];
    absolute(target, abs);
    snprintf(parent, sizeof parent, "%s", abs);
    *strrchr(parent, '/') = 0;
    for (int i = 0; i < g_sync.n; ++i) {
        if (g_sync.ev[i].kind != kind || strcmp(g_sync.ev[i].to, abs)) continue;
        for (int j = i + 1; j < g_sync.n; ++j)
            if (g_sync.ev[j].kind == 'f' && !strcmp(g_sync.ev[j].path, parent[0] ? parent : "/")) return i;
        fprintf(stderr, "  %s: its folder was not synced after it got its name\n", abs);
        return -1;
    }
    fprintf(stderr, "  %s: never got its name by %s\n", abs, kind == 'r' ? "rename" : "link");
    return -1;
}

static struct {
    const char *final, *tmp;
    int at, missing;
} g_tree;

static int tree_entry_synced(const char* path, const struct stat* st, int flag, struct FTW* ftw)
{
    (void)st, (void)flag, (void)ftw;
    char was[1100];
    snprintf(was, sizeof was, "%s%s", g_tree.tmp, path + strlen(g_tree.final));
    if (!synced_before(was, g_tree.at)) {
        fprintf(stderr, "  %s: not synced before the export took its name\n", path);
        ++g_tree.missing;
    }
    return 0;
}

// Files written whole are synced before their rename and their folder after
// it, so that after a power cut a name holds the old file or the whole new
// one: sp_file_write (new and over an old file), a classifier model, a whole
// export folder (every file and folder in it), and a database built beside
// its name and linked into place.
static void test_durable(void)
{
    char db_path[1024], parent[1024], cmd[2400];
    snprintf(db_path, sizeof db_path, "%s", base_db("durable.db"));
    snprintf(parent, sizeof parent, "%s", sp_test_tmp_path("durable"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", parent);
    ENSURE(system(cmd) == 0 && mkdir(parent, 0755) == 0);
    char file[1100], model[1100], dir[1100], built[1100];
    snprintf(file, sizeof file, "%s/file.txt", parent);
    snprintf(model, sizeof model, "%s/model.spclf", parent);
    snprintf(dir, sizeof dir, "%s/export", parent);
    snprintf(built, sizeof built, "%s/built.db", parent);
    sp_error err = {0};
    sp_db* db = open_ok(db_path, SP_DB_READONLY);
    sp_clf* clf = NULL;
    ENSURE(sp_db_load_model(db, &clf, NULL, &err) == SP_OK);

    g_sync.on = true, g_sync.n = 0;
    ENSURE(sp_file_write(file, "one\n", 4, &err) == SP_OK);
    int i = named_durably(file, 'r');
    ENSURE(i >= 0 && synced_before(g_sync.ev[i].path, i));
    g_sync.n = 0;
    ENSURE(sp_file_write(file, "two\n", 4, &err) == SP_OK); // over the old file
    ENSURE((i = named_durably(file, 'r')) >= 0 && synced_before(g_sync.ev[i].path, i));
    g_sync.n = 0;
    ENSURE(sp_clf_save(clf, model, &err) == SP_OK);
    ENSURE((i = named_durably(model, 'r')) >= 0 && synced_before(g_sync.ev[i].path, i));
    g_sync.n = 0;
    ENSURE(sp_db_export(db, dir, &err) == SP_OK);
    ENSURE((i = named_durably(dir, 'r')) >= 0);
    g_tree.final = dir, g_tree.tmp = g_sync.ev[i].path, g_tree.at = i, g_tree.missing = 0;
    ENSURE(synced_before(g_tree.tmp, i)); // the folder's own entries
    ENSURE(nftw(dir, tree_entry_synced, 16, FTW_PHYS) == 0 && g_tree.missing == 0);
    g_sync.n = 0;
    ENSURE(sp_db_create_from_export(built, dir, NULL, "test", &err) == SP_OK);
    ENSURE(named_durably(built, 'l') >= 0);
    g_sync.on = false;

    sp_clf_destroy(clf);
    sp_db_close(db);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", parent);
    ENSURE(system(cmd) == 0);
}

int main(int argc, char** argv)
{
    if (argc == 3 && !strcmp(argv[1], "--write-parts")) {
        // Checked here: a failed check outside sp_test_run has nowhere to return to.
        struct stat st;
        if (stat(argv[2], &st) != 0 || !S_ISDIR(st.st_mode) || access(argv[2], W_OK) != 0) {
            fprintf(stderr, "test_partdb --write-parts: %s: not a folder this user may write\n", argv[2]);
            return 1;
        }
        for (int i = 0; i < 4; ++i) {
            char f[1100];
            snprintf(f, sizeof f, "%s/%s.glb", argv[2], k_parts[i].name);
            write_part(&k_parts[i], f);
        }
        return 0;
    }
    return sp_test_run(argc, argv,
                       (sp_test[]){{"sha256", test_sha256},
                                   {"refusal_says_why", test_refusal_says_why},
                                   {"read_only_file_system", test_read_only_file_system},
                                   {"same_file_twice", test_same_file_twice},
                                   {"round_trip", test_round_trip},
                                   {"export_gltf_named", test_export_gltf_named},
                                   {"export_clears_stopped", test_export_clears_stopped},
                                   {"export_onto_mount_point", test_export_onto_mount_point},
                                   {"sketch_doubles_exact", test_sketch_doubles_exact},
                                   {"export_whole", test_export_whole},
                                   {"durable", test_durable},
                                   {"model_in_memory", test_model_in_memory},
                                   {"curator_category", test_curator_category},
                                   {"crash_add_part", test_crash_add_part},
                                   {"crash_train", test_crash_train},
                                   {"two_writers", test_two_writers},
                                   {"read_only_and_full", test_read_only_and_full},
                                   {"unreachable", test_unreachable},
                                   {"read_only_folder", test_read_only_folder},
                                   {"foreign_wal", test_foreign_wal},
                                   {"drop_sidecars_long_path", test_drop_sidecars_long_path},
                                   {"long_paths", test_long_paths},
                                   {"own_readonly_leftovers", test_own_readonly_leftovers},
                                   {"readers_leave_one_file", test_readers_leave_one_file},
                                   {"schema_versions", test_schema_versions},
                                   {"bad_input", test_bad_input},
                                   {"names_escaped", test_names_escaped},
                                   {"generation", test_generation},
                                   {"keep_models", test_keep_models},
                                   {"people_strokes", test_people_strokes},
                                   {"drawn_sketches", test_drawn_sketches},
                                   {"curated_cap", test_curated_cap},
                                   {"default_db", test_default_db},
                                   {"default_db_cli", test_default_db_cli},
                                   {"remove_notes", test_remove_notes},
                                   {"attach_joint_missing", test_attach_joint_missing},
                                   {"db_help_lists_all", test_db_help_lists_all},
                                   {"kiosk_collect", test_kiosk_collect},
                                   {"kiosk_migration", test_kiosk_migration},
                                   {"kiosk_review_cli", test_kiosk_review_cli},
                                   {"sketch_ids_kept", test_sketch_ids_kept},
                                   {"kiosk_review_ranges", test_kiosk_review_ranges},
                                   {"kiosk_pending_cap", test_kiosk_pending_cap},
                                   {"file_check", test_file_check},
                                   {"number_options_cli", test_number_options_cli},
                                   {"add_sketch_partless_cli", test_add_sketch_partless_cli},
                                   {"new_db_said_cli", test_new_db_said_cli},
                                   {"add_part_derive_options", test_add_part_derive_options},
                                   {"category_case", test_category_case},
                                   {"dataset_appends_after_builders", test_dataset_appends_after_builders},
                                   {0}});
}
