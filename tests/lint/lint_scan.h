// lint_scan.h: what the lints (tests/lint/*.c) share: reading a file and
// walking its code, past comments, literals and whitespace.
#ifndef SP_LINT_SCAN_H
#define SP_LINT_SCAN_H

#include <stdbool.h>
#include <stddef.h>

// The whole file, NUL-terminated, its length in *n. An unreadable file ends
// the program: "<tool>: cannot read <path>" and exit status 2.
char* lint_read_all(const char* tool, const char* path, size_t* n);

// A walk over one file's code: s[i] is the current character, on line `line`.
typedef struct lint_cursor {
    const char* s;
    size_t n, i;
    int line;
    bool at_line_start;      // only whitespace before s[i] on its line
    bool stop_at_directives; // stop at a '#' that starts a line (else preprocessor lines are skipped)
} lint_cursor;

// Moves to the next significant character at or after s[i]: past comments,
// string and character literals, whitespace (counting lines) and, unless
// stop_at_directives, preprocessor lines. False at the end of the file.
// The caller consumes the character (and clears at_line_start).
bool lint_next(lint_cursor* c);
// Reads the identifier at s[i] into w (cut to cap - 1 bytes) and moves past it.
void lint_word(lint_cursor* c, char* w, size_t cap);

#endif
