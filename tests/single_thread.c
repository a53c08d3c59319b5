/*
 * single_thread.c: linked into the unit tests that tests/CMakeLists.txt labels single_thread
 * (with -Wl,--wrap=pthread_create). The ThreadSanitizer phase of `make test` leaves those tests
 * out: a process with one thread has no data race to find, and they are half of that phase's
 * time. This keeps the label honest: a labelled test whose code starts a thread stops here with
 * a message instead of silently losing its race check (docs/tests.md, "Sanitizers").
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

int __wrap_pthread_create(pthread_t *thread, const pthread_attr_t *attr, void *(*start)(void *), void *arg);

int __wrap_pthread_create(pthread_t *thread, const pthread_attr_t *attr, void *(*start)(void *), void *arg)
{
	(void)thread;
	(void)attr;
	(void)start;
	(void)arg;
	fprintf(stderr, "this test is labelled single_thread in tests/CMakeLists.txt but started a thread: "
	                "take it off PRSM_SINGLE_THREAD_TESTS so that the ThreadSanitizer phase runs it\n");
	abort();
}
