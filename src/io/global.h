/*
 * global.h: the library's process-wide setup, done once (libgit2's git_libgit2_init style).
 *
 * prsm_global_init() must be called before any other prsm function, from any thread, any number
 * of times (pthread_once). It
 *   - switches GSL's error handler off: model code reads GSL's return codes and reports them
 *     (docs/model/errors-and-assembly.md); the default handler would abort the process, and nothing below this file
 *     ever switches the handler again (a process-wide switch around one call races with every
 *     other thread);
 *   - installs cJSON allocation hooks that count failed allocations per thread, so a document
 *     writer can tell that a member was silently dropped (cJSON's adders return NULL and leave
 *     the tree one member short) and fail as a whole instead of caching a truncated result.
 */
#ifndef PRSM_IO_GLOBAL_H
#define PRSM_IO_GLOBAL_H

#include <cJSON.h>

void prsm_global_init(void);

/* Failed cJSON allocations on the calling thread since it started (a monotonic count: take it
 * before building a document, compare after). */
unsigned long prsm_json_alloc_failures(void);

/* The text of doc (malloc'd, the caller frees it; indented when formatted is 1) when no cJSON
 * allocation failed on this thread since the count was failures_before and printing succeeded;
 * NULL otherwise: the document is incomplete (out of memory) and must not be used. */
char *prsm_json_print_whole(const cJSON *doc, unsigned long failures_before, int formatted);

/* Testing: the n-th cJSON allocation from now on this thread fails (n >= 1), every later one
 * succeeds again; 0 switches injection off. */
void prsm_json_inject_alloc_failure(long n);

#endif
