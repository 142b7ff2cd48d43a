// function_length: fails when a C function is longer than a limit.
//
//     function_length MAX [--allow LIST] FILE...
//
// LIST names functions allowed past MAX, one a line, "FILE FUNCTION LINES"
// (FILE a path suffix; '#' starts a comment): each may be at most its own
// LINES, so that it can shrink and not grow. An entry that no function
// matches, or whose function is now within MAX, fails too (the list
// shrinks with the code).
//
// A function's length is the number of lines from its body's opening brace
// to its closing brace, both included. A body is a brace block at file
// scope that follows a closing parenthesis (so struct, enum and array
// initialisers at file scope are not functions); comments, string and
// character literals and preprocessor lines are skipped. Prints one line per
// function over the limit (file:line: name is N lines, limit MAX) and exits
// 1 if there was one, 2 on bad usage or an unreadable file, else 0.
//
// Why a program of our own: the check runs in CI on a fresh Debian 12 with
// only the project's packages (clang-tidy's readability-function-size is
// not among them), and the project's C style (clang-format, Linux braces)
// keeps the scan this simple.
#include <ctype.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lint_scan.h"

enum { NAME_MAX_LEN = 128 };

enum { ALLOW_MAX = 64 };

typedef struct allowed {
    char file[256], name[NAME_MAX_LEN];
    int lines;
    bool seen;
} allowed;

typedef struct scan {
    const char* path;
    int max;
    int over; // functions over the limit
    allowed allow[ALLOW_MAX];
    int allow_n;
} scan;

static bool path_ends_with(const char* path, const char* suffix)
{
    size_t p = strlen(path), s = strlen(suffix);
    return s <= p && !strcmp(path + p - s, suffix) && (s == p || path[p - s - 1] == '/');
}

// The function's own limit: its entry's, else MAX.
static int limit_of(scan* sc, const char* name, int len)
{
    for (int i = 0; i < sc->allow_n; ++i) {
        allowed* a = &sc->allow[i];
        if (strcmp(a->name, name) != 0 || !path_ends_with(sc->path, a->file)) continue;
        a->seen = true;
        if (len <= sc->max) {
            printf("%s: %s is %d lines, within %d: take it off the list\n", sc->path, name, len, sc->max);
            ++sc->over;
        }
        return a->lines;
    }
    return sc->max;
}

static bool read_allow(scan* sc, const char* list)
{
    FILE* f = fopen(list, "r");
    if (!f) {
        fprintf(stderr, "function_length: %s: cannot read\n", list);
        return false;
    }
    char line[512];
    bool ok = true;
    while (ok && fgets(line, sizeof line, f)) {
        char* hash = strchr(line, '#');
        if (hash) *hash = 0;
        allowed a = {0};
        int got = sscanf(line, "%255s %127s %d", a.file, a.name, &a.lines);
        if (got <= 0) continue;
        ok = got == 3 && a.lines > 0 && sc->allow_n < ALLOW_MAX;
        if (ok)
            sc->allow[sc->allow_n++] = a;
        else
            fprintf(stderr, "function_length: %s: bad entry: %s", list, line);
    }
    fclose(f);
    return ok;
}

static void check_file(scan* sc)
{
    size_t n;
    char* s = lint_read_all("function_length", sc->path, &n);
    int depth = 0, parens = 0, body_line = 0;
    char last = 0; // the last significant character at file scope
    char ident[NAME_MAX_LEN] = "", name[NAME_MAX_LEN] = "", body_name[NAME_MAX_LEN] = "";
    for (lint_cursor cur = {.s = s, .n = n, .line = 1, .at_line_start = true}; lint_next(&cur);) {
        cur.at_line_start = false;
        const char c = s[cur.i];
        if (isalpha((unsigned char)c) || c == '_') {
            lint_word(&cur, ident, sizeof ident);
            if (depth == 0) last = 'a';
            continue;
        }
        if (depth == 0) {
            if (c == '(' && parens++ == 0) snprintf(name, sizeof name, "%s", ident); // the name before a parameter list
            if (c == ')') --parens;
            if (c == '{') {
                if (last == ')')
                    body_line = cur.line, snprintf(body_name, sizeof body_name, "%s", name);
                else
                    body_line = 0; // an initialiser or a type
            }
            last = c;
        }
        if (c == '{') ++depth;
        if (c == '}' && --depth == 0 && body_line > 0) {
            const int len = cur.line - body_line + 1;
            const int limit = limit_of(sc, body_name, len);
            if (len > limit) {
                printf("%s:%d: %s is %d lines, limit %d\n", sc->path, body_line, body_name, len, limit);
                ++sc->over;
            }
            body_line = 0;
        }
        ++cur.i;
    }
    free(s);
}

int main(int argc, char** argv)
{
    if (argc < 3 || atoi(argv[1]) <= 0) {
        fprintf(stderr, "usage: function_length MAX [--allow LIST] FILE...\n");
        return 2;
    }
    static scan sc; // 25 KB of list entries: not on the stack
    sc.max = atoi(argv[1]);
    int first = 2;
    if (!strcmp(argv[2], "--allow")) {
        if (argc < 5 || !read_allow(&sc, argv[3])) return 2;
        first = 4;
    }
    for (int a = first; a < argc; ++a) {
        sc.path = argv[a];
        check_file(&sc);
    }
    for (int i = 0; i < sc.allow_n; ++i)
        if (!sc.allow[i].seen) {
            printf("%s: no function %s: take it off the list\n", sc.allow[i].file, sc.allow[i].name);
            ++sc.over;
        }
    return sc.over ? 1 : 0;
}
