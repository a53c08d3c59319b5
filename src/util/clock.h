/*
 * clock.h: monotonic wall-clock time for timings and time caps.
 */
#ifndef PRSM_UTIL_CLOCK_H
#define PRSM_UTIL_CLOCK_H

/* Seconds since an arbitrary fixed point, monotonic. */
double prsm_clock_seconds(void);

#endif
