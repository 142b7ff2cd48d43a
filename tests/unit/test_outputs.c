// A command's outputs, all or none (app/common/outputs.h): what a failure at
// any step leaves, links, long names, and the names in a writer's message.
#include <dirent.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "fixtures.h"
#include "outputs.h"
#include "sp/sketch_io.h"
#include "test.h"

static char g_dir[1024];

// A fresh folder of the test's own.
static const char* fresh_dir(const char* name)
{
    snprintf(g_dir, sizeof g_dir, "%s", sp_test_tmp_path(name));
    sp_dir_remove_tree(g_dir);
    ENSURE(mkdir(g_dir, 0755) == 0);
    return g_dir;
}

static void put(const char* path, const char* text)
{
    sp_error e = {0};
    ENSURE(sp_file_write(path, text, strlen(text), &e) == SP_OK);
}

// The file's text, or "(none)".
static bool holds(const char* path, const char* text)
{
    struct stat st;
    char* t = stat(path, &st) == 0 ? sp_fixture_file_text(path, NULL) : NULL;
    bool same = t ? !strcmp(t, text) : !strcmp(text, "(none)");
    if (!same) printf("  %s holds '%s', not '%s'\n", path, t ? t : "(none)", text);
    free(t);
    return same;
}

// Names in the folder other than those expected (temporaries, backups).
static int entries(const char* dir)
{
    DIR* d = opendir(dir);
    ENSURE(d);
    int n = 0;
    for (struct dirent* e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) ++n;
    closedir(d);
    return n;
}

// One output cannot be put in place (its name became a folder meanwhile):
// the one already put is put back, the old file or none, and nothing staged
// is left. Before, the first stayed replaced, with exit 1.
static void test_rollback(void)
{
    const char* dir = fresh_dir("outputs_rollback");
    char a[1200], b[1200], c[1200];
    snprintf(a, sizeof a, "%s/a.json", dir);
    snprintf(b, sizeof b, "%s/b.png", dir);
    snprintf(c, sizeof c, "%s/c.json", dir);
    put(a, "old a");
    ENSURE(chmod(a, 0640) == 0);
    for (int round = 0; round < 2; ++round) {
        sp_outputs o = {0};
        sp_error e = {0};
        const char *ta, *tb, *tc;
        ENSURE(sp_outputs_stage(&o, a, &ta, &e) == SP_OK && strcmp(ta, a));
        ENSURE(sp_outputs_stage(&o, c, &tc, &e) == SP_OK && strcmp(tc, c));
        ENSURE(sp_outputs_stage(&o, b, &tb, &e) == SP_OK && strcmp(tb, b));
        // Hidden and short, ending as the name given ends.
        ENSURE(strrchr(ta, '/')[1] == '.' && !strcmp(ta + strlen(ta) - 5, ".json") && !strcmp(tb + strlen(tb) - 4, ".png"));
        put(ta, "new a"), put(tb, "new b"), put(tc, "new c");
        if (round == 0) {
            ENSURE(mkdir(b, 0755) == 0);
            char inside[1300];
            snprintf(inside, sizeof inside, "%s/keep", b);
            put(inside, "x"); // not empty: rename(2) cannot replace it
            ENSURE(sp_outputs_commit(&o, &e) == SP_ERR_IO && strstr(e.text, "b.png: cannot write"));
            ENSURE(holds(a, "old a") && holds(c, "(none)"));
            struct stat st;
            ENSURE(stat(a, &st) == 0 && (st.st_mode & 0777) == 0640);
            ENSURE(entries(dir) == 2); // a.json and the folder b.png
            sp_dir_remove_tree(b);
        } else {
            ENSURE(sp_outputs_commit(&o, &e) == SP_OK);
            ENSURE(holds(a, "new a") && holds(b, "new b") && holds(c, "new c"));
            struct stat st;
            ENSURE(stat(a, &st) == 0 && (st.st_mode & 0777) == 0640); // a replaced file keeps its permissions
            ENSURE(entries(dir) == 3);
        }
        ENSURE(o.count == 0);
    }
}

// A link stays a link and its target gets the file, written as the name
// given says (a link x.glb to model.gltf is a .glb); a dangling link's
// target is created on success only.
static void test_links(void)
{
    const char* dir = fresh_dir("outputs_links");
    char model[1200], link[1200], gone[1200], dang[1200];
    snprintf(model, sizeof model, "%s/model.gltf", dir);
    snprintf(link, sizeof link, "%s/x.glb", dir);
    snprintf(gone, sizeof gone, "%s/sub/new.json", dir);
    snprintf(dang, sizeof dang, "%s/d.json", dir);
    put(model, "old");
    ENSURE(symlink("model.gltf", link) == 0);
    char sub[1200];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    ENSURE(mkdir(sub, 0755) == 0);
    ENSURE(symlink("sub/new.json", dang) == 0);
    for (int round = 0; round < 2; ++round) {
        sp_outputs o = {0};
        sp_error e = {0};
        const char *tl, *td;
        ENSURE(sp_outputs_stage(&o, link, &tl, &e) == SP_OK && !strcmp(tl + strlen(tl) - 4, ".glb"));
        ENSURE(sp_outputs_stage(&o, dang, &td, &e) == SP_OK && strstr(td, "/sub/."));
        put(tl, "new"), put(td, "made");
        if (round == 0) {
            sp_outputs_undo(&o, &e);
            ENSURE(holds(model, "old") && holds(gone, "(none)") && entries(sub) == 0);
        } else {
            ENSURE(sp_outputs_commit(&o, &e) == SP_OK);
            ENSURE(holds(model, "new") && holds(gone, "made"));
        }
        struct stat st;
        ENSURE(lstat(link, &st) == 0 && S_ISLNK(st.st_mode) && lstat(dang, &st) == 0 && S_ISLNK(st.st_mode));
    }
    // Streams are written as they go.
    sp_outputs o = {0};
    sp_error e = {0};
    const char* t;
    ENSURE(sp_outputs_stage(&o, "-", &t, &e) == SP_OK && !strcmp(t, "-"));
    ENSURE(sp_outputs_stage(&o, "/dev/null", &t, &e) == SP_OK && !strcmp(t, "/dev/null") && o.count == 0);
}

// A name near the file system's 255-byte limit still has a temporary beside
// it (".part<pid>-<k>" or ".tmp<pid>-<k>" added to it was too long, found
// after the work).
static void test_long_name(void)
{
    const char* dir = fresh_dir("outputs_long");
    char name[300], path[1400];
    memset(name, 'n', 250);
    snprintf(name + 250, sizeof name - 250, ".json");
    snprintf(path, sizeof path, "%s/%s", dir, name);
    sp_outputs o = {0};
    sp_error e = {0};
    const char* t;
    ENSURE(sp_outputs_stage(&o, path, &t, &e) == SP_OK);
    put(t, "long");
    ENSURE(sp_outputs_commit(&o, &e) == SP_OK && holds(path, "long"));
    // The same for one file written alone (its ".tmp<pid>-<k>" was too long).
    ENSURE(sp_file_write(path, "alone", 5, &e) == SP_OK && holds(path, "alone"));
    ENSURE(entries(dir) == 1);
}

// A writer's message names the staged file: undo says the name the user
// gave instead, wherever it appears, however long it is (a long name for a
// short staged one used to be written past the message's end).
static void test_message(void)
{
    const char* dir = fresh_dir("outputs_message");
    char path[1200];
    int n = snprintf(path, sizeof path, "%s/", dir);
    while (n < 600)
        n += snprintf(path + n, sizeof path - (size_t)n, "./");
    snprintf(path + n, sizeof path - (size_t)n, "l.json"); // a link to a short name
    char link[1200];
    snprintf(link, sizeof link, "%s/l.json", dir);
    ENSURE(symlink("x.json", link) == 0);
    sp_outputs o = {0};
    sp_error e = {0};
    const char* t;
    ENSURE(sp_outputs_stage(&o, path, &t, &e) == SP_OK);
    snprintf(e.text, sizeof e.text, "%s: cannot write (No space left on device); %s again", t, t);
    sp_outputs_undo(&o, &e);
    ENSURE(!strncmp(e.text, path, strlen(path) < sizeof e.text - 1 ? strlen(path) : sizeof e.text - 1));
    ENSURE(!strstr(e.text, "/.sp-") && strlen(e.text) < sizeof e.text);
    // A short name said where a staged one was.
    snprintf(path, sizeof path, "%s/s.json", dir);
    ENSURE(sp_outputs_stage(&o, path, &t, &e) == SP_OK);
    snprintf(e.text, sizeof e.text, "%s: disk full", t);
    sp_outputs_undo(&o, &e);
    char want[1300];
    snprintf(want, sizeof want, "%s: disk full", path);
    ENSURE(!strcmp(e.text, want));
    ENSURE(entries(dir) == 1); // the link
}

// The folder checked before the work is the one the file is written in:
// through a link, its target's (a link into a missing folder passed the
// check and failed after the work).
static void test_folder_check(void)
{
    const char* dir = fresh_dir("outputs_folder");
    char into_none[1200], into_dir[1200];
    snprintf(into_none, sizeof into_none, "%s/a.png", dir);
    snprintf(into_dir, sizeof into_dir, "%s/b.png", dir);
    ENSURE(symlink("none/a.png", into_none) == 0 && symlink("sub/b.png", into_dir) == 0);
    char sub[1200];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    ENSURE(mkdir(sub, 0755) == 0);
    ENSURE(!sp_cli_check_out_folder("test", "--render", into_none));
    ENSURE(sp_cli_check_out_folder("test", "--render", into_dir));
    // And written there, the link kept.
    sp_error e = {0};
    ENSURE(sp_file_write(into_dir, "png", 3, &e) == SP_OK);
    char b[1300];
    snprintf(b, sizeof b, "%s/b.png", sub);
    struct stat st;
    ENSURE(holds(b, "png") && lstat(into_dir, &st) == 0 && S_ISLNK(st.st_mode));
}

static void harness_passes(void) {}

static void harness_fails(void)
{
    ENSURE(0);
}

// Runs a one-test table in a child that first makes a scratch file and a
// scratch folder; true when the child's scratch is still there after it.
static bool scratch_kept(void (*fn)(void))
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        FILE* f = fopen(sp_test_tmp_path("probe.txt"), "w");
        if (!f || fputs("x", f) < 0 || fclose(f) != 0) _exit(3);
        // An older file under the same pid: a failed run's, long ago, kept.
        f = fopen(sp_test_tmp_path("probe_old.txt"), "w");
        if (!f || fclose(f) != 0) _exit(3);
        struct timespec old[2] = {{time(NULL) - 86400, 0}, {time(NULL) - 86400, 0}};
        if (utimensat(AT_FDCWD, sp_test_tmp_path("probe_old.txt"), old, 0) != 0) _exit(3);
        char sub[1100];
        snprintf(sub, sizeof sub, "%s/inner", sp_test_tmp_path("probe_dir"));
        if (mkdir(sp_test_tmp_path("probe_dir"), 0755) != 0 || mkdir(sub, 0755) != 0) _exit(3);
        int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 1), dup2(devnull, 2);
        char* argv[] = {"probe", NULL};
        _exit(sp_test_run(1, argv, (sp_test[]){{"probe", fn}, {0}}));
    }
    int status = 0;
    ENSURE(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status));
    ENSURE(WEXITSTATUS(status) == (fn == harness_passes ? 0 : 1));
    char file[1100], dir[1100];
    snprintf(file, sizeof file, "%s/tmp/%d_probe.txt", SP_BINARY_DIR, (int)pid);
    snprintf(dir, sizeof dir, "%s/tmp/%d_probe_dir/inner", SP_BINARY_DIR, (int)pid);
    struct stat st;
    bool has_file = stat(file, &st) == 0, has_dir = stat(dir, &st) == 0;
    char old[1100];
    snprintf(old, sizeof old, "%s/tmp/%d_probe_old.txt", SP_BINARY_DIR, (int)pid);
    ENSURE(stat(old, &st) == 0); // never another run's
    remove(old), remove(file), rmdir(dir);
    *strrchr(dir, '/') = '\0';
    rmdir(dir);
    ENSURE(has_file == has_dir);
    return has_file;
}

// A passing test run removes its scratch files; a failing one keeps them to
// look at (the build folder grew by some 100 MB a run before).
// The command lines commands print to be pasted (demo's "again from these
// strokes"): every word reads back as itself in sh (the demo printed a
// folder with a space bare, and the pasted line failed).
static void test_shell_words(void)
{
    const char* words[] = {"build/app/sketchpose", "my db.db", "it's", "", "a;b", "$HOME", "x=1,y:2+3-4_5.json"};
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    ENSURE(f);
    fputs("printf '[%s]' ", f);
    for (size_t i = 0; i < sizeof words / sizeof words[0]; ++i) {
        sp_cli_print_shell_word(f, words[i]);
        fputc(' ', f);
    }
    fclose(f);
    FILE* p = popen(text, "r");
    char got[512] = "";
    size_t n = fread(got, 1, sizeof got - 1, p);
    got[n] = 0;
    ENSURE(pclose(p) == 0);
    ENSURE(!strcmp(got, "[build/app/sketchpose][my db.db][it's][][a;b][$HOME][x=1,y:2+3-4_5.json]"));
    ENSURE(strstr(text, " build/app/sketchpose ") && strstr(text, " x=1,y:2+3-4_5.json ")); // plain words stay plain
    free(text);
}

static void test_harness_scratch(void)
{
    ENSURE(!scratch_kept(harness_passes));
    ENSURE(scratch_kept(harness_fails));
}

int main(int argc, char** argv)
{
    return sp_test_run(argc, argv,
                       (sp_test[]){{"rollback", test_rollback},
                                   {"links", test_links},
                                   {"long_name", test_long_name},
                                   {"message", test_message},
                                   {"folder_check", test_folder_check},
                                   {"harness_scratch", test_harness_scratch},
                                   {"shell_words", test_shell_words},
                                   {0}});
}
