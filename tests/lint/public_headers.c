// public_headers: fails when a public header names a third-party library.
//
//     public_headers FILE...
//
// A public header (<library>/include/sp/*.h) is all a user compiles against
// (docs/DESIGN.md, "API conventions"): it includes only C standard headers
// and our own "sp/..." ones, and its code names no type, function or macro
// of the libraries behind it (cJSON, GLFW, GL and EGL, OpenCV, tinygltf,
// SQLite, FLANN, LAPACKE and CBLAS, stb) and no C++ scope (`cv::Mat`).
// Comments and string literals are skipped: a comment may say which library
// does the work inside (that is documentation, not a dependency). Prints one
// line per finding (file:line: what) and exits 1 if there was one, 2 on bad
// usage or an unreadable file, else 0.
#include <ctype.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lint_scan.h"

enum { WORD_MAX = 128 };

static const char* const k_std_headers[] = {
    "assert.h",  "complex.h", "ctype.h",  "errno.h",  "fenv.h",   "float.h",       "inttypes.h", "iso646.h",
    "limits.h",  "locale.h",  "math.h",   "setjmp.h", "signal.h", "stdalign.h",    "stdarg.h",   "stdatomic.h",
    "stdbool.h", "stddef.h",  "stdint.h", "stdio.h",  "stdlib.h", "stdnoreturn.h", "string.h",   "tgmath.h",
    "threads.h", "time.h",    "uchar.h",  "wchar.h",  "wctype.h",
};

// Identifier prefixes of the third-party libraries. A prefix ending in '*'
// must be followed by an upper-case letter or '_' (glGetString, GLuint,
// GL_RGBA, EGLDisplay), so that words such as "glyph" or "egg" pass.
static const char* const k_foreign[] = {
    "cJSON", "GLFW",  "glfw",     "gl*",     "GL*",     "egl*",  "EGL*",  "sqlite3", "SQLITE_",
    "flann", "FLANN", "tinygltf", "LAPACKE", "lapack_", "cblas", "CBLAS", "stbi",    "stbtt",
};

static const char* foreign_prefix(const char* w)
{
    for (size_t k = 0; k < sizeof k_foreign / sizeof *k_foreign; ++k) {
        const char* p = k_foreign[k];
        size_t n = strlen(p);
        bool upper_next = p[n - 1] == '*';
        if (upper_next) --n;
        if (strncmp(w, p, n) != 0) continue;
        if (!upper_next || isupper((unsigned char)w[n]) || w[n] == '_') return w;
    }
    return NULL;
}

static bool std_header(const char* h)
{
    for (size_t k = 0; k < sizeof k_std_headers / sizeof *k_std_headers; ++k)
        if (!strcmp(h, k_std_headers[k])) return true;
    return false;
}

// An #include at s[i] (after the '#'): reports a header that is neither a
// C standard one nor one of ours. Returns the index of the line's end.
static size_t check_include(const char* path, const char* s, size_t n, size_t i, int line, int* found)
{
    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        ++i;
    if (strncmp(s + i, "include", 7) != 0) return i; // another directive: its words are checked as code
    i += 7;
    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        ++i;
    char name[WORD_MAX] = "";
    if (i < n && (s[i] == '<' || s[i] == '"')) {
        const char close = s[i] == '<' ? '>' : '"';
        size_t k = 0;
        for (++i; i < n && s[i] != close && s[i] != '\n'; ++i)
            if (k + 1 < sizeof name) name[k++] = s[i];
        name[k] = 0;
        bool ok = close == '>' ? std_header(name) : !memcmp(name, "sp/", 3); // name is zero-filled past its end
        if (!ok) {
            printf("%s:%d: includes %c%s%c (a public header includes only C standard headers and \"sp/...\")\n", path, line,
                   close == '>' ? '<' : '"', name, close);
            ++*found;
        }
    }
    while (i < n && s[i] != '\n')
        ++i;
    return i;
}

static int check_file(const char* path)
{
    size_t n;
    char* s = lint_read_all("public_headers", path, &n);
    int found = 0;
    lint_cursor cur = {.s = s, .n = n, .line = 1, .at_line_start = true, .stop_at_directives = true};
    while (lint_next(&cur)) {
        const bool directive = cur.at_line_start && s[cur.i] == '#';
        cur.at_line_start = false;
        const char c = s[cur.i];
        if (directive) {
            cur.i = check_include(path, s, n, cur.i + 1, cur.line, &found);
        } else if (c == ':' && cur.i + 1 < n && s[cur.i + 1] == ':') {
            printf("%s:%d: names a C++ scope (::); public headers are C\n", path, cur.line);
            ++found, cur.i += 2;
        } else if (isalpha((unsigned char)c) || c == '_') {
            char w[WORD_MAX];
            lint_word(&cur, w, sizeof w);
            if (foreign_prefix(w)) {
                printf("%s:%d: names %s (a third-party library's; public headers use sp_ types only)\n", path, cur.line, w);
                ++found;
            }
        } else {
            ++cur.i;
        }
    }
    free(s);
    return found;
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: public_headers FILE...\n");
        return 2;
    }
    int found = 0;
    for (int a = 1; a < argc; ++a)
        found += check_file(argv[a]);
    return found ? 1 : 0;
}
