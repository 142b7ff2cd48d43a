#define _XOPEN_SOURCE 700 // nftw
#include "test.h"

#include <dirent.h>
#include <ftw.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "sp/clock.h"

int sp_test_failures = 0;
jmp_buf sp_test_jmp;
const char* sp_test_skip_reason = NULL;

static char* ring_next(void)
{
    static char ring[8][1024];
    static int at = 0;
    return ring[at++ & 7];
}

const char* sp_test_data_dir(void)
{
    struct stat st;
    if (stat(SP_SHARED_DATA, &st) == 0 && S_ISDIR(st.st_mode)) return SP_SHARED_DATA;
    return NULL;
}

const char* sp_test_src_path(const char* rel)
{
    char* b = ring_next();
    snprintf(b, 1024, "%s/%s", SP_SOURCE_DIR, rel);
    return b;
}

const char* sp_test_keep_path(const char* name)
{
    char* b = ring_next();
    mkdir(SP_BINARY_DIR "/tmp", 0755);
    snprintf(b, 1024, "%s/tmp/%s", SP_BINARY_DIR, name);
    return b;
}

const char* sp_test_tmp_path(const char* name)
{
    char* b = ring_next();
    mkdir(SP_BINARY_DIR "/tmp", 0755);
    snprintf(b, 1024, "%s/tmp/%d_%s", SP_BINARY_DIR, (int)getpid(), name);
    return b;
}

// True when every folder from / down to dir lets other users pass (o+x).
static bool others_may_enter(const char* dir)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", dir);
    for (;;) {
        struct stat st;
        if (stat(buf[0] ? buf : "/", &st) != 0 || !(st.st_mode & S_IXOTH)) return false;
        char* slash = strrchr(buf, '/');
        if (!slash) return true;
        *slash = 0;
        if (!buf[0]) return stat("/", &st) == 0 && (st.st_mode & S_IXOTH);
    }
}

const char* sp_test_reachable_dir(const char* prefix)
{
    static char dir[1024]; // until the next call
    const char* tmpdir = getenv("TMPDIR");
    const char* candidates[] = {SP_BINARY_DIR "/tmp", tmpdir && tmpdir[0] ? tmpdir : P_tmpdir, P_tmpdir};
    for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; ++i) {
        mkdir(candidates[i], 0755);
        if (!others_may_enter(candidates[i])) continue;
        if (snprintf(dir, sizeof dir, "%s/%s_XXXXXX", candidates[i], prefix) >= 1000) continue;
        if (mkdtemp(dir) && chmod(dir, 0755) == 0) return dir;
    }
    return NULL;
}

static time_t g_started; // when sp_test_run began: older <pid>_ files are another run's

static int remove_entry(const char* path, const struct stat* st, int flag, struct FTW* ftw)
{
    (void)st, (void)flag, (void)ftw;
    remove(path);
    return 0;
}

// A passing run takes its scratch files (sp_test_tmp_path's <pid>_ names)
// with it: left behind, every run of the suite added some 100 MB to the
// build folder. A failing run keeps them.
static void remove_own_scratch(void)
{
    char prefix[32];
    snprintf(prefix, sizeof prefix, "%d_", (int)getpid());
    DIR* d = opendir(SP_BINARY_DIR "/tmp");
    if (!d) return;
    for (struct dirent* e; (e = readdir(d));) {
        if (strncmp(e->d_name, prefix, strlen(prefix)) != 0) continue;
        char path[1200];
        snprintf(path, sizeof path, "%s/tmp/%s", SP_BINARY_DIR, e->d_name);
        // A failed run long ago under the same pid kept its files to look at.
        struct stat st;
        if (lstat(path, &st) != 0 || st.st_mtime < g_started) continue;
        nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    }
    closedir(d);
}

// 0 ok, 1 failed, 2 skipped. The setjmp lives here, apart from the loop's
// locals, so that longjmp cannot clobber them.
static int run_one(const sp_test* t)
{
    int before = sp_test_failures;
    sp_test_skip_reason = NULL;
    if (setjmp(sp_test_jmp) == 0) t->fn();
    else if (sp_test_skip_reason) return 2;
    return sp_test_failures > before ? 1 : 0;
}

// The tests hand paths to the shell in single quotes ('%s'), which a path
// with a single quote of its own would end early: such a clone is refused
// with a reason, not run half right. NULL when the paths are fine.
static const char* unquotable_path(void)
{
    static char why[1200];
    const char* paths[] = {SP_SOURCE_DIR, SP_BINARY_DIR, SP_SHARED_DATA};
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; ++i)
        if (strchr(paths[i], '\'')) {
            snprintf(why, sizeof why,
                     "%s has a single quote, which the tests' shell commands cannot quote: clone to a path without one",
                     paths[i]);
            return why;
        }
    return NULL;
}

int sp_test_run(int argc, char** argv, const sp_test* tests)
{
    g_started = time(NULL) - 1; // mtimes have whole seconds on some file systems
    int ran = 0, failed = 0, skipped = 0;
    const char* refused = unquotable_path();
    for (const sp_test* t = tests; t->name; ++t) {
        if (argc > 1 && !strstr(t->name, argv[1])) continue;
        double t0 = sp_now_ms();
        sp_test_skip_reason = refused;
        int rc = refused ? 2 : run_one(t);
        double took = 1e-3 * (sp_now_ms() - t0); // the suite's slow parts, for keeping CI in budget
        ++ran;
        if (rc == 2) {
            ++skipped;
            printf("SKIP %s: %s\n", t->name, sp_test_skip_reason);
        } else if (rc == 1) {
            ++failed;
            printf("FAIL %s (%.1f s)\n", t->name, took);
        } else {
            printf("ok   %s (%.1f s)\n", t->name, took);
        }
        fflush(stdout);
    }
    printf("%d passed, %d failed, %d skipped\n", ran - failed - skipped, failed, skipped);
    if (failed)
        printf("scratch files kept for a look: %s/tmp/%d_*\n", SP_BINARY_DIR, (int)getpid());
    else
        remove_own_scratch();
    return failed ? 1 : 0;
}
