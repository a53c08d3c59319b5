/*
 * global.c: prsm_global_init and the counting cJSON allocation hooks (see global.h).
 */
#include "io/global.h"

#include <pthread.h>
#include <stdlib.h>

#include <gsl/gsl_errno.h>

static _Thread_local unsigned long alloc_failures;
static _Thread_local long inject_countdown; /* > 0: that many allocations until one fails */

static void *counting_malloc(size_t n)
{
	if (inject_countdown > 0 && --inject_countdown == 0) {
		alloc_failures++;
		return NULL;
	}
	void *p = malloc(n);
	if (p == NULL)
		alloc_failures++;
	return p;
}

static void init_once(void)
{
	gsl_set_error_handler_off();
	cJSON_Hooks hooks = {counting_malloc, free};
	cJSON_InitHooks(&hooks);
}

void prsm_global_init(void)
{
	static pthread_once_t once = PTHREAD_ONCE_INIT;
	pthread_once(&once, init_once);
}

unsigned long prsm_json_alloc_failures(void)
{
	return alloc_failures;
}

void prsm_json_inject_alloc_failure(long n)
{
	inject_countdown = n > 0 ? n : 0;
}

char *prsm_json_print_whole(const cJSON *doc, unsigned long failures_before, int formatted)
{
	if (doc == NULL || alloc_failures != failures_before)
		return NULL;
	char *text = formatted ? cJSON_Print(doc) : cJSON_PrintUnformatted(doc);
	if (text != NULL && alloc_failures != failures_before) {
		/* printing hit a failure it recovered from: refuse rather than trust it */
		cJSON_free(text);
		return NULL;
	}
	return text;
}
