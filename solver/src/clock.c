// clock.c: sp_now_ms, the monotonic clock of solve reports, the pipeline,
// the kiosk and the benchmarks; sp_rss_kb, the kiosk's and its benchmark's memory gauge.
#include "sp/clock.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

double sp_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

long sp_rss_kb(void)
{
    FILE* f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (!f) return 0;
    if (fscanf(f, "%ld %ld", &pages, &res) != 2) res = 0;
    fclose(f);
    return res * (sysconf(_SC_PAGESIZE) / 1024);
}
