// lint_scan.c: see lint_scan.h.
#include "lint_scan.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>

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

char* lint_read_all(const char* tool, const char* path, size_t* n)
{
    char* s = read_all(path, n);
    if (!s) {
        fprintf(stderr, "%s: cannot read %s\n", tool, path);
        exit(2);
    }
    return s;
}

bool lint_next(lint_cursor* c)
{
    while (c->i < c->n) {
        if (c->stop_at_directives && c->at_line_start && c->s[c->i] == '#') return true;
        size_t j = skip_inert(c->s, c->n, c->i, &c->line, c->at_line_start);
        if (j != c->i) {
            c->i = j;
            continue;
        }
        const char ch = c->s[c->i];
        if (ch == '\n') {
            ++c->line, c->at_line_start = true, ++c->i;
            continue;
        }
        if (!isspace((unsigned char)ch)) return true;
        ++c->i;
    }
    return false;
}

void lint_word(lint_cursor* c, char* w, size_t cap)
{
    size_t k = 0;
    for (; c->i < c->n && (isalnum((unsigned char)c->s[c->i]) || c->s[c->i] == '_'); ++c->i)
        if (k + 1 < cap) w[k++] = c->s[c->i];
    w[k] = 0;
}
