/// sp/clock.h: the one monotonic clock every module times itself with, and
/// the one gauge of the process's memory (so the kiosk's live statistics and
/// its soak benchmark report the same quantity).
///
///     double t0 = sp_now_ms();
///     ...
///     printf("%.1f ms, %ld KiB resident\n", sp_now_ms() - t0, sp_rss_kb());
#ifndef SP_CLOCK_H
#define SP_CLOCK_H

#ifdef __cplusplus
extern "C" {
#endif

/// Milliseconds on CLOCK_MONOTONIC (an arbitrary origin: differences only).
double sp_now_ms(void);

/// Resident memory of this process in KiB, from /proc/self/statm (0 where it cannot be read).
long sp_rss_kb(void);

#ifdef __cplusplus
}
#endif
#endif
