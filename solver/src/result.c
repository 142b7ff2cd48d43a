#include "sp/result.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

// A text cut to fit its buffer says so: "..." at its end, not inside a
// UTF-8 character (a path cut short hid the part an error was about).
static void mark_cut(char* s, size_t cap)
{
    if (cap < 4) return;
    size_t w = strlen(s);
    if (w + 4 > cap) w = cap - 4;
    while (w > 0 && ((unsigned char)s[w] & 0xC0) == 0x80)
        --w;
    memcpy(s + w, "...", 4);
}

void sp_text_escape_controls(char* s, size_t cap)
{
    const unsigned char* p = (const unsigned char*)s;
    while (*p && *p >= 0x20 && *p != 0x7f)
        ++p;
    if (!*p) return; // nothing to escape: the text as it is
    char out[SP_TEXT_LINE_MAX];
    size_t w = 0, room = cap < sizeof out ? cap : sizeof out;
    bool cut = false;
    for (p = (const unsigned char*)s; *p; ++p) {
        char one[8];
        int k = *p == '\n'                ? snprintf(one, sizeof one, "\\n")
                : *p == '\t'              ? snprintf(one, sizeof one, "\\t")
                : *p < 0x20 || *p == 0x7f ? snprintf(one, sizeof one, "\\x%02x", *p)
                                          : snprintf(one, sizeof one, "%c", *p);
        if (w + (size_t)k + 1 > room) {
            cut = true;
            break;
        }
        memcpy(out + w, one, (size_t)k);
        w += (size_t)k;
    }
    memcpy(s, out, w);
    s[w] = 0;
    if (cut) mark_cut(s, room);
}

// Text s (w bytes) into buf (cap bytes) with its middle left out, "..." in
// its place, neither end inside a UTF-8 character.
static void cut_middle(const char* s, size_t w, char* buf, size_t cap)
{
    size_t head = (cap - 4) / 3, tail = cap - 4 - head;
    while (head > 0 && ((unsigned char)s[head] & 0xC0) == 0x80)
        --head;
    size_t from = w - tail;
    while (from < w && ((unsigned char)s[from] & 0xC0) == 0x80)
        ++from;
    memcpy(buf, s, head);
    memcpy(buf + head, "...", 3);
    memcpy(buf + head + 3, s + from, w - from + 1);
}

void sp_text_vline(char* buf, size_t cap, const char* fmt, va_list ap)
{
    if (cap == 0) return;
    char whole[SP_TEXT_LINE_MAX];
    int n = vsnprintf(whole, sizeof whole, fmt, ap);
    if (n < 0) whole[0] = 0;
    if (n >= 0 && (size_t)n >= sizeof whole) mark_cut(whole, sizeof whole);
    // One line, whatever a file's names hold: a joint named with a newline
    // and an escape code split a message and cleared the terminal.
    sp_text_escape_controls(whole, sizeof whole);
    size_t w = strlen(whole);
    // Too long, the middle goes: a path's end and the reason after it name
    // the problem ("<a long path>: cannot open (...)" kept only the path).
    if (w < cap)
        memcpy(buf, whole, w + 1);
    else if (cap >= 16)
        cut_middle(whole, w, buf, cap);
    else
        memcpy(buf, whole, cap - 1), buf[cap - 1] = 0, mark_cut(buf, cap);
}

sp_result sp_fail(sp_error* err, sp_result code, const char* fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        sp_text_vline(err->text, sizeof err->text, fmt, ap);
        va_end(ap);
    }
    return code;
}

const char* sp_result_name(sp_result r)
{
    switch (r) {
    case SP_OK: return "ok";
    case SP_ERR_IO: return "i/o error";
    case SP_ERR_PARSE: return "parse error";
    case SP_ERR_INVALID: return "invalid data";
    case SP_ERR_UNSUPPORTED: return "unsupported";
    case SP_ERR_NO_MEMORY: return "out of memory";
    case SP_ERR_BUSY: return "busy";
    case SP_ERR_INTERNAL: return "internal error";
    case SP_ERR_TIMEOUT:
        return "time cap reached";
    }
    return "unknown";
}
