/*
 * doc.c: the table-driven document reader (see doc.h).
 */
#include "io/doc.h"

#include <string.h>

#include "io/json_util.h"
#include "util/error.h"

static void set_int(void *base, size_t offset, int v)
{
	memcpy((char *)base + offset, &v, sizeof v);
}

static void set_double(void *base, size_t offset, double v)
{
	memcpy((char *)base + offset, &v, sizeof v);
}

static void read_field(void *base, const prsm_io_field *f, const cJSON *obj, const char *ptr,
                       prsm_problems *problems)
{
	const int req = f->required ? PRSM_JSON_REQUIRED : PRSM_JSON_OPTIONAL;
	int present = 0;
	switch (f->kind) {
	case PRSM_IO_NUMBER: {
		double v;
		const prsm_json_range r = {f->min, f->max, f->min_exclusive, f->max_exclusive};
		present = prsm_json_get_number(&v, obj, ptr, f->name, req, r, problems) == PRSM_JSON_PRESENT;
		if (present)
			set_double(base, f->offset, f->divide != 0.0 ? v / f->divide : f->scale != 0.0 ? v * f->scale : v);
		break;
	}
	case PRSM_IO_INT: {
		int v;
		present = prsm_json_get_int(&v, obj, ptr, f->name, req, (int)f->min, (int)f->max, problems) ==
		          PRSM_JSON_PRESENT;
		if (present)
			set_int(base, f->offset, v);
		break;
	}
	case PRSM_IO_SIZE: {
		int v;
		present = prsm_json_get_int(&v, obj, ptr, f->name, req, (int)f->min, (int)f->max, problems) ==
		          PRSM_JSON_PRESENT;
		if (present) {
			const size_t z = (size_t)v;
			memcpy((char *)base + f->offset, &z, sizeof z);
		}
		break;
	}
	case PRSM_IO_BOOL: {
		int v;
		present = prsm_json_get_bool(&v, obj, ptr, f->name, req, problems) == PRSM_JSON_PRESENT;
		if (present)
			set_int(base, f->offset, v);
		break;
	}
	case PRSM_IO_ENUM: {
		int i;
		present = prsm_json_get_enum(&i, obj, ptr, f->name, req, f->names, problems) == PRSM_JSON_PRESENT;
		if (present)
			set_int(base, f->offset, f->values[i]);
		break;
	}
	case PRSM_IO_STRING: {
		const char *s;
		present = prsm_json_get_string(&s, obj, ptr, f->name, req, f->max_chars ? f->max_chars : (size_t)-1,
		                               problems) == PRSM_JSON_PRESENT;
		break;
	}
	case PRSM_IO_OBJECT: {
		char sp[PRSM_JSON_POINTER_MAX];
		const cJSON *sec;
		if (prsm_json_get_section(&sec, sp, sizeof sp, obj, ptr, f->name, req, f->child->keys, problems) !=
		    PRSM_JSON_PRESENT)
			return;
		void *child = (char *)base + f->offset;
		if (f->has_set)
			set_int(base, f->set_offset, f->set_value);
		for (size_t i = 0; i < f->child->n_fields; i++)
			read_field(child, &f->child->fields[i], sec, sp, problems);
		if (f->hook)
			f->hook(child, sec, sp, problems);
		return;
	}
	case PRSM_IO_HOOK:
		f->hook(base, obj, ptr, problems);
		return;
	case PRSM_IO_COVERED:
		return;
	}
	if (present && f->has_set)
		set_int(base, f->set_offset, f->set_value);
	if (f->conflict_with && cJSON_GetObjectItemCaseSensitive(obj, f->name) &&
	    cJSON_GetObjectItemCaseSensitive(obj, f->conflict_with)) {
		char p[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(p, sizeof p, ptr, f->name);
		prsm_problems_add(problems, p, "conflict", "%s", f->conflict_message);
	}
}

int prsm_io_read(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer,
                 prsm_problems *problems)
{
	const int before = prsm_problems_total(problems);
	const char *ptr = obj_pointer ? obj_pointer : "";
	prsm_json_check_keys(obj, ptr, t->keys, problems);
	for (size_t i = 0; i < t->n_fields; i++)
		read_field(base, &t->fields[i], obj, ptr, problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

int prsm_io_problem_at(const prsm_problems *problems, int from, const char *obj_pointer, const char *key)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, key);
	for (int i = from; i < problems->count; i++)
		if (strcmp(problems->items[i].pointer, ptr) == 0)
			return 1;
	return 0;
}

int prsm_io_read_member(void *base, const prsm_io_table *t, const char *key, const cJSON *obj,
                        const char *obj_pointer, prsm_problems *problems)
{
	const int before = prsm_problems_total(problems);
	for (size_t i = 0; i < t->n_fields; i++)
		if (strcmp(t->fields[i].name, key) == 0)
			read_field(base, &t->fields[i], obj, obj_pointer ? obj_pointer : "", problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}
