/// sp/clock.h: the one monotonic clock every module times itself with.
///
///     double t0 = sp_now_ms();
///     ...
///     printf("%.1f ms\n", sp_now_ms() - t0);
#ifndef SP_CLOCK_H
#define SP_CLOCK_H

#ifdef __cplusplus
extern "C" {
#endif

/// Milliseconds on CLOCK_MONOTONIC (an arbitrary origin: differences only).
double sp_now_ms(void);

#ifdef __cplusplus
}
#endif
#endif
