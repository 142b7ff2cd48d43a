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

enum { NAME_MAX_LEN = 128 };

typedef struct scan {
    const char* path;
    int max;
    int over; // functions over the limit
} scan;

static char* read_all(const char* path, size_t* n)
{
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, len = 0;
    char* buf = malloc(cap + 1);
    size_t got;
    while (buf && (got = fread(buf + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) {
            char* more = realloc(buf, 2 * cap + 1);
            if (!more) free(buf);
            buf = more, cap *= 2;
        }
    }
    fclose(f);
    if (buf) buf[len] = 0;
    *n = len;
    return buf;
}

// Skips a comment, literal or preprocessor line starting at s[i] (counting
// newlines into *line); returns the index after it, or i when there is none.
static size_t skip_inert(const char* s, size_t n, size_t i, int* line, bool at_line_start)
{
    if (s[i] == '/' && i + 1 < n && s[i + 1] == '/') {
        while (i < n && s[i] != '\n')
            ++i;
        return i;
    }
    if (s[i] == '/' && i + 1 < n && s[i + 1] == '*') {
        for (i += 2; i + 1 < n && !(s[i] == '*' && s[i + 1] == '/'); ++i)
            *line += s[i] == '\n';
        return i + 2 < n ? i + 2 : n;
    }
    if (s[i] == '"' || s[i] == '\'') {
        const char q = s[i];
        for (++i; i < n && s[i] != q; ++i) {
            if (s[i] == '\\' && i + 1 < n) ++i;
            *line += s[i] == '\n';
        }
        return i + 1;
    }
    if (s[i] == '#' && at_line_start) { // a directive, with its continuation lines
        for (; i < n && s[i] != '\n'; ++i)
            if (s[i] == '\\' && i + 1 < n && s[i + 1] == '\n') ++i, ++*line;
        return i;
    }
    return i;
}

static void check_file(scan* sc)
{
    size_t n;
    char* s = read_all(sc->path, &n);
    if (!s) {
        fprintf(stderr, "function_length: cannot read %s\n", sc->path);
        exit(2);
    }
    int line = 1, depth = 0, parens = 0, body_line = 0;
    char last = 0; // the last significant character at file scope
    char ident[NAME_MAX_LEN] = "", name[NAME_MAX_LEN] = "", body_name[NAME_MAX_LEN] = "";
    bool at_line_start = true;
    for (size_t i = 0; i < n;) {
        size_t j = skip_inert(s, n, i, &line, at_line_start);
        if (j != i) {
            i = j;
            continue;
        }
        const char c = s[i];
        if (c == '\n') {
            ++line, at_line_start = true, ++i;
            continue;
        }
        if (isspace((unsigned char)c)) {
            ++i;
            continue;
        }
        at_line_start = false;
        if (isalpha((unsigned char)c) || c == '_') {
            size_t k = 0;
            while (i < n && (isalnum((unsigned char)s[i]) || s[i] == '_')) {
                if (k + 1 < sizeof ident) ident[k++] = s[i];
                ++i;
            }
            ident[k] = 0;
            if (depth == 0) last = 'a';
            continue;
        }
        if (depth == 0) {
            if (c == '(' && parens++ == 0) snprintf(name, sizeof name, "%s", ident); // the name before a parameter list
            if (c == ')') --parens;
            if (c == '{') {
                if (last == ')')
                    body_line = line, snprintf(body_name, sizeof body_name, "%s", name);
                else
                    body_line = 0; // an initialiser or a type
            }
            last = c;
        }
        if (c == '{') ++depth;
        if (c == '}' && --depth == 0 && body_line > 0) {
            const int len = line - body_line + 1;
            if (len > sc->max) {
                printf("%s:%d: %s is %d lines, limit %d\n", sc->path, body_line, body_name, len, sc->max);
                ++sc->over;
            }
            body_line = 0;
        }
        ++i;
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
