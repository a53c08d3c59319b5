/*
 * write.c: the sticky-error document writer (see write.h).
 */
#include "io/write.h"

#include <math.h>

cJSON *prsm_jw_item(prsm_jw *w, cJSON *parent, const char *key, cJSON *item)
{
	if (item == NULL) {
		w->failed = 1;
		return NULL;
	}
	int ok = parent != NULL && (key ? cJSON_AddItemToObject(parent, key, item)
	                                : cJSON_AddItemToArray(parent, item));
	if (!ok) {
		cJSON_Delete(item);
		w->failed = 1;
		return NULL;
	}
	return item;
}

cJSON *prsm_jw_root(prsm_jw *w)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		w->failed = 1;
	return root;
}

cJSON *prsm_jw_object(prsm_jw *w, cJSON *parent, const char *key)
{
	return prsm_jw_item(w, parent, key, cJSON_CreateObject());
}

cJSON *prsm_jw_array(prsm_jw *w, cJSON *parent, const char *key)
{
	return prsm_jw_item(w, parent, key, cJSON_CreateArray());
}

void prsm_jw_number(prsm_jw *w, cJSON *parent, const char *key, double v)
{
	prsm_jw_item(w, parent, key, isfinite(v) ? cJSON_CreateNumber(v) : cJSON_CreateNull());
}

void prsm_jw_string(prsm_jw *w, cJSON *parent, const char *key, const char *s)
{
	prsm_jw_item(w, parent, key, cJSON_CreateString(s));
}

void prsm_jw_bool(prsm_jw *w, cJSON *parent, const char *key, int b)
{
	prsm_jw_item(w, parent, key, cJSON_CreateBool(b));
}

void prsm_jw_null(prsm_jw *w, cJSON *parent, const char *key)
{
	prsm_jw_item(w, parent, key, cJSON_CreateNull());
}
