// clock.c: sp_now_ms, the monotonic clock of solve reports, the pipeline,
// the kiosk and the benchmarks.
#include "sp/clock.h"

#include <time.h>

double sp_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
