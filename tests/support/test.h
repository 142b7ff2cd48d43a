/// test.h: the tiny test harness every test executable uses.
///
///     static void test_fk(void) { ENSURE(x == 1); ENSURE_NEAR(a, b, 1e-9); }
///     int main(int argc, char** argv) { return sp_test_run(argc, argv, (sp_test[]){
///         {"fk", test_fk}, {0}}); }
///
/// `./test_x name` runs only the tests whose name contains `name`. A failed
/// check prints file:line and the values and marks the test failed; the
/// executable exits non-zero if any test failed. SKIP() ends a test as
/// skipped with a reason (e.g. ../shared/data absent).
#ifndef SP_TEST_H
#define SP_TEST_H

#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct sp_test {
    const char* name;
    void (*fn)(void);
} sp_test;

extern int sp_test_failures;
extern jmp_buf sp_test_jmp;
extern const char* sp_test_skip_reason;

#define ENSURE(c)                                                                   \
    do {                                                                            \
        if (!(c)) {                                                                 \
            fprintf(stderr, "  %s:%d: ENSURE(%s) failed\n", __FILE__, __LINE__, #c);\
            ++sp_test_failures;                                                     \
            longjmp(sp_test_jmp, 1);                                                \
        }                                                                           \
    } while (0)

#define ENSURE_NEAR(a, b, tol)                                                                      \
    do {                                                                                            \
        double sp_a_ = (double)(a), sp_b_ = (double)(b);                                            \
        if (!(fabs(sp_a_ - sp_b_) <= (tol))) {                                                      \
            fprintf(stderr, "  %s:%d: ENSURE_NEAR(%s, %s, %s) failed: %.12g vs %.12g (diff %.3g)\n", \
                    __FILE__, __LINE__, #a, #b, #tol, sp_a_, sp_b_, fabs(sp_a_ - sp_b_));         \
            ++sp_test_failures;                                                                     \
            longjmp(sp_test_jmp, 1);                                                                \
        }                                                                                           \
    } while (0)

#define SKIP(reason)                      \
    do {                                  \
        sp_test_skip_reason = (reason);   \
        longjmp(sp_test_jmp, 2);          \
    } while (0)

/// Path of ../shared/data (compiled in), or NULL when it is absent.
const char* sp_test_data_dir(void);
/// Path inside the project source tree / the build tree (static buffer, rotates over 8).
const char* sp_test_src_path(const char* rel);
/// <build>/tmp/<pid>_<name>: scratch, removed when the run passes.
const char* sp_test_tmp_path(const char* name);
/// <build>/tmp/<name>: a file kept for a person to look at (a picture),
/// overwritten by the next run.
const char* sp_test_keep_path(const char* name);
/// A fresh folder <prefix>_XXXXXX (mode 0755) that any user can reach, for
/// cases run as another user (root ignores permissions, so a test drops
/// them in a child): the build folder may lie under one only its owner may
/// enter (a clone in a fresh `mktemp -d`). NULL when there is none; the
/// path stays until the next call.
const char* sp_test_reachable_dir(const char* prefix);
/// Runs the NULL-terminated table; argv[1] filters by substring.
int sp_test_run(int argc, char** argv, const sp_test* tests);

#endif
