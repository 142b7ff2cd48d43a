#include "sp/result.h"

#include <stdio.h>

sp_result sp_fail(sp_error* err, sp_result code, const char* fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->text, sizeof err->text, fmt, ap);
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
