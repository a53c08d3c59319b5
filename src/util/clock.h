/*
 * clock.h: monotonic wall-clock time for timings and time caps, and timed waits on condition
 * variables against the same clock (a wait on CLOCK_REALTIME jumps when the system clock is
 * set, so a 0.1 s wait could last hours or nothing).
 */
#ifndef PRSM_UTIL_CLOCK_H
#define PRSM_UTIL_CLOCK_H

#include <pthread.h>

/* Seconds since an arbitrary fixed point, monotonic. */
double prsm_clock_seconds(void);

/* Initialise cv so that its timed waits measure CLOCK_MONOTONIC. Returns pthread's code. */
int prsm_cond_init_monotonic(pthread_cond_t *cv);

/* Wait on cv (initialised by prsm_cond_init_monotonic; mu held) for a signal or at most
 * seconds (> 0) of monotonic time. Returns pthread_cond_timedwait's code (ETIMEDOUT). */
int prsm_cond_wait_for(pthread_cond_t *cv, pthread_mutex_t *mu, double seconds);

#endif
