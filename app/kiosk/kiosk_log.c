// kiosk_log.c: the running kiosk's log lines (sp_kiosk_log).
#include <stdarg.h>
#include <stdio.h>
#include <time.h>

#include "sp/kiosk.h"

void sp_kiosk_log(const char* fmt, ...)
{
    char msg[SP_TEXT_LINE_MAX];
    va_list ap;
    va_start(ap, fmt);
    sp_text_vline(msg, sizeof msg, fmt, ap); // one line, whatever a path in it holds
    va_end(ap);
    // UTC: a kiosk's log outlives daylight saving changes and is read next to other machines'.
    char when[32] = "";
    time_t now = time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ ", &tm);
    // One call: stdio locks the stream, so the collector's thread never splits a line.
    fprintf(stderr, "%sdragon-kiosk: %s\n", when, msg);
}
