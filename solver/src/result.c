#include "sp/result.h"

#include <stdio.h>
#include <string.h>

void sp_text_escape_controls(char* s, size_t cap)
{
    char out[1024];
    size_t w = 0, room = cap < sizeof out ? cap : sizeof out;
    for (const unsigned char* p = (const unsigned char*)s; *p && w + 5 < room; ++p)
        w += (size_t)(*p == '\n'                ? snprintf(out + w, room - w, "\\n")
                      : *p == '\t'              ? snprintf(out + w, room - w, "\\t")
                      : *p < 0x20 || *p == 0x7f ? snprintf(out + w, room - w, "\\x%02x", *p)
                                                : snprintf(out + w, room - w, "%c", *p));
    memcpy(s, out, w);
    s[w] = 0;
}

sp_result sp_fail(sp_error* err, sp_result code, const char* fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->text, sizeof err->text, fmt, ap);
        va_end(ap);
        // One line, whatever a file's names hold: a joint named with a newline
        // and an escape code split a message and cleared the terminal.
        sp_text_escape_controls(err->text, sizeof err->text);
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
