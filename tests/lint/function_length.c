// function_length: fails when a C function is longer than a limit.
//
//     function_length MAX FILE...
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

typedef struct scan {
    const char* path;
    int max;
    int over; // functions over the limit
} scan;

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
            if (len > sc->max) {
                printf("%s:%d: %s is %d lines, limit %d\n", sc->path, body_line, body_name, len, sc->max);
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
        fprintf(stderr, "usage: function_length MAX FILE...\n");
        return 2;
    }
    scan sc = {.max = atoi(argv[1])};
    for (int a = 2; a < argc; ++a) {
        sc.path = argv[a];
        check_file(&sc);
    }
    return sc.over ? 1 : 0;
}
