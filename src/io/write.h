/*
 * write.h: building a result document with a sticky error. Every call takes the writer and
 * the parent it adds to; once an allocation has failed (or a parent is NULL because an earlier
 * one failed) the calls do nothing but keep w->failed set, and an item that cannot be attached
 * is freed, so a writer checks once, at the end, and never leaks on out-of-memory.
 *
 * Numbers that are not finite are written as null (JSON has no NaN or infinity).
 */
#ifndef PRSM_IO_WRITE_H
#define PRSM_IO_WRITE_H

#include <cJSON.h>

typedef struct {
	int failed; /* an allocation failed: the document is incomplete */
} prsm_jw;

#define PRSM_JW_INIT {0}

/* A new document root (an object the caller owns); NULL when out of memory. */
cJSON *prsm_jw_root(prsm_jw *w);

/* A new object or array under parent[key] (key NULL: appended to the array parent). NULL when
 * it could not be made or parent is NULL. */
cJSON *prsm_jw_object(prsm_jw *w, cJSON *parent, const char *key);
cJSON *prsm_jw_array(prsm_jw *w, cJSON *parent, const char *key);

/* parent[key] = value (key NULL: appended to the array parent). */
void prsm_jw_number(prsm_jw *w, cJSON *parent, const char *key, double v); /* null unless finite */
void prsm_jw_string(prsm_jw *w, cJSON *parent, const char *key, const char *s);
void prsm_jw_bool(prsm_jw *w, cJSON *parent, const char *key, int b);
void prsm_jw_null(prsm_jw *w, cJSON *parent, const char *key);

/* Attach item (made elsewhere; NULL counts as a failure) at parent[key]; freed when it cannot
 * be attached. Returns item when attached, else NULL. */
cJSON *prsm_jw_item(prsm_jw *w, cJSON *parent, const char *key, cJSON *item);

#endif
