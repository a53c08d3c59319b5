/*
 * doc.c: the table-driven document reader (see doc.h).
 */
#include "io/doc.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "io/json_util.h"
#include "util/error.h"
#include "util/utf8.h"

#define PUT(base, offset, v) memcpy((char *)(base) + (offset), &(v), sizeof(v))

/* A field's strings, tables and functions by their indices (doc.h). */
#define STR(i) prsm_io_gen_strings[(i)]
#define NAME(f) STR((f)->name)

static void vproblem(prsm_problems *problems, const char *pointer, const char *key, const char *code,
                     const char *fmt, va_list ap)
{
	char p[PRSM_JSON_POINTER_MAX], msg[4 * PRSM_PROBLEM_MESSAGE_MAX]; /* cut by prsm_problems_add */
	if (key)
		prsm_json_pointer_append(p, sizeof p, pointer, key);
	vsnprintf(msg, sizeof msg, fmt, ap);
	prsm_problems_add(problems, key ? p : pointer, code, "%s", msg);
}

void prsm_io_problem(prsm_problems *problems, const char *pointer, const char *key, const char *code,
                     const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vproblem(problems, pointer, key, code, fmt, ap);
	va_end(ap);
}

static int read_object(const prsm_io_at *r, void *base, const prsm_io_table *t, const cJSON *obj, const char *ptr,
                       int index, int start, prsm_io_at *at, prsm_problems *problems);

static void put_count(void *base, const prsm_io_field *f, size_t n)
{
	const int i = (int)n;
	if (f->count_size == sizeof(int))
		PUT(base, f->count_offset, i);
	else
		PUT(base, f->count_offset, n);
}

/* The items of an array (its shape checked) or of a map: objects by the child table into their
 * place (a map's: the key step's pick; else a scratch struct), numbers and strings checked; each
 * given to the step, and counted unless a step refused it. */
static void read_items(const prsm_io_at *r, void *base, const prsm_io_field *f, const cJSON *x, const char *xp,
                       prsm_problems *problems)
{
	union {
		max_align_t align;
		unsigned char bytes[PRSM_IO_SCRATCH_MAX];
	} scratch;
	size_t kept = 0;
	int i = 0;
	for (const cJSON *it = x->child; it; it = it->next, i++) {
		char ip[PRSM_JSON_POINTER_MAX];
		const char *s;
		double d;
		const int map = f->kind == PRSM_IO_MAP, start = prsm_problems_total(problems);
		if (map)
			prsm_json_pointer_append(ip, sizeof ip, xp, it->string);
		else
			prsm_json_pointer_append_index(ip, sizeof ip, xp, i);
		prsm_io_at at = {r->root, r->ctx, base, NULL, it, ip, map ? -1 : i, start, 0};
		char *slot = map ? prsm_io_gen_keys[f->key](&at, it->string, problems)
		             : f->stored ? (char *)base + f->offset + (f->compact ? kept : (size_t)i) * f->item_size
		                         : (char *)scratch.bytes;
		if (f->child) {
			if (slot == NULL || prsm_json_object_value(it, ip, problems))
				continue;
			if (!map)
				memset(slot, 0, f->item_size);
			if (read_object(r, slot, prsm_io_gen_tables[f->child], it, ip, at.index, start, &at, problems))
				continue;
		} else if (f->items == PRSM_IO_NUMBER) {
			const prsm_json_range range = {f->min, f->max, f->min_exclusive, f->max_exclusive};
			if (prsm_json_number_value(&d, it, ip, range, problems))
				continue;
			if (f->stored)
				PUT(slot, 0, d);
		} else if (prsm_json_string_value(&s, it, ip, f->max_chars ? f->max_chars : (size_t)-1, problems)) {
			continue;
		}
		if ((f->step && prsm_io_gen_steps[f->step](&at, problems)) || !f->stored)
			continue;
		if (f->compact) /* the count as it grows */
			put_count(base, f, ++kept);
	}
	if (f->count_size && !f->compact)
		put_count(base, f, (size_t)i);
}

/* A magnitude (f->direction) given negative: the problem says what to give instead. Returns 1
 * when it added it. */
static int negative_magnitude(const prsm_io_field *f, const cJSON *obj, const char *ptr, prsm_problems *problems)
{
	const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, NAME(f));
	if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || !(item->valuedouble < 0.0))
		return 0;
	char got[40], lim[40];
	prsm_json_format_number(got, sizeof got, item->valuedouble);
	prsm_json_format_number(lim, sizeof lim, f->max);
	prsm_io_problem(problems, ptr, NAME(f), "range",
	                "must be a number from 0 to %s (got %s): it is a magnitude; give its direction with %s "
	                "instead (-a is a with the phase turned by 180 deg)", lim, got, STR(f->direction));
	return 1;
}

/* One field of obj (pointer ptr) into base. Returns 1 when it was there and valid (scalars). */
static int read_field(const prsm_io_at *r, void *base, const prsm_io_field *f, const cJSON *obj, const char *ptr,
                      prsm_problems *problems)
{
	const int req = f->required && !f->missing ? PRSM_JSON_REQUIRED : PRSM_JSON_OPTIONAL;
	char p[PRSM_JSON_POINTER_MAX];
	const cJSON *sub;
	int present = 0, v;
	double d;
	if (f->missing && f->required && !cJSON_GetObjectItemCaseSensitive(obj, NAME(f)))
		prsm_io_problem(problems, ptr, NAME(f), "required", "%s", STR(f->missing));
	switch (f->kind) {
	case PRSM_IO_NUMBER: {
		const prsm_json_range range = {f->min, f->max, f->min_exclusive, f->max_exclusive};
		if (f->direction && negative_magnitude(f, obj, ptr, problems))
			break;
		present = prsm_json_get_number(&d, obj, ptr, NAME(f), req, range, problems) == PRSM_JSON_PRESENT;
		if (present) {
			d = f->divide != 0.0 ? d / f->divide : f->scale != 0.0 ? d * f->scale : d;
			PUT(base, f->offset, d);
		}
		break;
	}
	case PRSM_IO_INT:
	case PRSM_IO_SIZE:
	case PRSM_IO_LONG:
		present = prsm_json_get_int(&v, obj, ptr, NAME(f), req, (int)f->min, (int)f->max, problems) ==
		          PRSM_JSON_PRESENT;
		if (present && f->kind == PRSM_IO_INT)
			PUT(base, f->offset, v);
		else if (present && f->kind == PRSM_IO_LONG)
			PUT(base, f->offset, (long){v});
		else if (present)
			PUT(base, f->offset, (size_t){(size_t)v});
		break;
	case PRSM_IO_BOOL:
		present = prsm_json_get_bool(&v, obj, ptr, NAME(f), req, problems) == PRSM_JSON_PRESENT;
		if (present)
			PUT(base, f->offset, v);
		break;
	case PRSM_IO_ENUM:
		present = prsm_json_get_enum(&v, obj, ptr, NAME(f), req, prsm_io_gen_names[f->names], problems) ==
		          PRSM_JSON_PRESENT;
		if (present)
			PUT(base, f->offset, prsm_io_gen_values[f->values][v]);
		break;
	case PRSM_IO_STRING: {
		const char *s;
		present = prsm_json_get_string(&s, obj, ptr, NAME(f), req, f->max_chars ? f->max_chars : (size_t)-1,
		                               problems) == PRSM_JSON_PRESENT;
		if (present && f->capacity)
			prsm_utf8_copy((char *)base + f->offset, f->capacity, s);
		break;
	}
	case PRSM_IO_OBJECT: {
		void *child = (char *)base + f->offset;
		prsm_io_at at;
		if (f->init)
			prsm_io_gen_inits[f->init](child);
		if (prsm_json_get_object(&sub, obj, ptr, NAME(f), req, problems) != PRSM_JSON_PRESENT)
			return 0;
		prsm_json_pointer_append(p, sizeof p, ptr, NAME(f));
		if (f->has_set)
			PUT(base, f->set_offset, f->set_value);
		if (read_object(r, child, prsm_io_gen_tables[f->child], sub, p, -1, prsm_problems_total(problems), &at, problems) == 0 &&
		    f->hook)
			prsm_io_gen_hooks[f->hook](child, sub, p, problems);
		return 0;
	}
	case PRSM_IO_ARRAY: {
		sub = cJSON_GetObjectItemCaseSensitive(obj, NAME(f));
		const int start = prsm_problems_total(problems), n = cJSON_GetArraySize(sub);
		prsm_json_pointer_append(p, sizeof p, ptr, NAME(f));
		if (sub && cJSON_IsArray(sub) && n >= f->min_items && n <= f->max_items)
			read_items(r, base, f, sub, p, problems);
		else if (sub || (f->required && !f->missing))
			prsm_problems_add(problems, p, sub ? STR(f->code) : "required", "%s", STR(f->message));
		prsm_io_at at = {r->root, r->ctx, base, NULL, sub, p, -1, start, 0};
		if (f->after)
			prsm_io_gen_steps[f->after](&at, problems);
		return 0;
	}
	case PRSM_IO_MAP:
		if (prsm_json_get_object(&sub, obj, ptr, NAME(f), req, problems) != PRSM_JSON_PRESENT)
			return 0;
		prsm_json_pointer_append(p, sizeof p, ptr, NAME(f));
		prsm_json_check_duplicates(sub, p, problems);
		read_items(r, base, f, sub, p, problems);
		return 0;
	case PRSM_IO_HOOK:
		prsm_io_gen_hooks[f->hook](base, obj, ptr, problems);
		return 0;
	case PRSM_IO_COVERED:
	case PRSM_IO_STEP:
		return 0;
	}
	if (present && f->has_set)
		PUT(base, f->set_offset, f->set_value);
	if (f->conflict_with && cJSON_GetObjectItemCaseSensitive(obj, NAME(f)) &&
	    cJSON_GetObjectItemCaseSensitive(obj, STR(f->conflict_with)))
		prsm_io_problem(problems, ptr, NAME(f), "conflict", "%s", STR(f->conflict_message));
	return present;
}

/* The keys of obj, then its fields and steps in order; at is filled for the steps (and the
 * item's). Returns nonzero when a step stopped it. */
static int read_object(const prsm_io_at *r, void *base, const prsm_io_table *t, const cJSON *obj, const char *ptr,
                       int index, int start, prsm_io_at *at, prsm_problems *problems)
{
	*at = (prsm_io_at){r->root, r->ctx, base, t, obj, ptr, index, start, 0};
	int holds = 1;
	if (t->keys_else) {
		int v;
		memcpy(&v, (const char *)r->root + t->when_offset, sizeof v);
		holds = (v != 0) != t->when_not;
	}
	prsm_json_check_keys(obj, ptr, holds ? t->keys : t->keys_else, problems);
	for (size_t i = 0; i < t->n_fields; i++) {
		const prsm_io_field *f = &t->fields[i];
		if (f->kind == PRSM_IO_STEP && prsm_io_gen_steps[f->step](at, problems))
			return 1;
		if (f->kind != PRSM_IO_STEP && !f->deferred && (holds || !f->when) &&
		    read_field(r, base, f, obj, ptr, problems) && i < 64)
			at->read |= 1ULL << i;
	}
	/* the members that belong with one value of a sibling (an input's kind), once it is read */
	for (int pass = 0; pass < 2; pass++)
		for (size_t i = 0; i < t->n_fields; i++) {
			const prsm_io_field *f = &t->fields[i];
			if (!f->only_key || prsm_io_problem_at(problems, 0, ptr, STR(f->only_key)))
				continue;
			int v;
			memcpy(&v, (const char *)base + f->only_offset, sizeof v);
			const int present = cJSON_GetObjectItemCaseSensitive(obj, NAME(f)) != NULL;
			if (pass == 0 && f->only_required && v == f->only_value && !present)
				prsm_io_problem(problems, ptr, NAME(f), "required", "%s", STR(f->only_required));
			else if (pass == 1 && v != f->only_value && present)
				prsm_io_problem(problems, ptr, NAME(f), STR(f->only_code), "%s", STR(f->only_message));
		}
	return 0;
}

int prsm_io_read_ctx(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer, void *ctx,
                     prsm_problems *problems)
{
	const int before = prsm_problems_total(problems);
	const prsm_io_at r = {base, ctx, base, t, obj, obj_pointer ? obj_pointer : "", -1, before, 0};
	prsm_io_at at;
	read_object(&r, base, t, obj, r.pointer, -1, before, &at, problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

int prsm_io_read(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer,
                 prsm_problems *problems)
{
	return prsm_io_read_ctx(base, t, obj, obj_pointer, NULL, problems);
}

int prsm_io_problem_at(const prsm_problems *problems, int from, const char *obj_pointer, const char *key)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	if (key)
		prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, key);
	for (int i = from; i < problems->count; i++)
		if (strcmp(problems->items[i].pointer, key ? ptr : obj_pointer) == 0)
			return 1;
	return 0;
}

int prsm_io_get(const prsm_io_at *at, const char *key, prsm_problems *problems)
{
	const int before = prsm_problems_total(problems);
	int present = 0;
	for (size_t i = 0; i < at->table->n_fields; i++)
		if (at->table->fields[i].name && strcmp(NAME(&at->table->fields[i]), key) == 0)
			present |= read_field(at, at->base, &at->table->fields[i], at->obj, at->pointer, problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : present;
}

int prsm_io_read_member(void *base, const prsm_io_table *t, const char *key, const cJSON *obj,
                        const char *obj_pointer, prsm_problems *problems)
{
	const prsm_io_at at = {base, NULL, base, t, obj, obj_pointer ? obj_pointer : "", -1, 0, 0};
	return prsm_io_get(&at, key, problems) < 0 ? PRSM_EINVAL : 0;
}

int prsm_io_was_read(const prsm_io_at *at, const char *key)
{
	for (size_t i = 0; i < at->table->n_fields && i < 64; i++)
		if (at->table->fields[i].name && strcmp(NAME(&at->table->fields[i]), key) == 0 && (at->read >> i & 1))
			return 1;
	return 0;
}

/* ---- the rules of a table, checked once the object is read (doc.h) ---------------------------- */

static int listed(unsigned short names, const char *s)
{
	for (const char *const *n = prsm_io_gen_names[names]; n && *n; n++)
		if (strcmp(*n, s) == 0)
			return 1;
	return 0;
}

void prsm_io_problem_once(prsm_problems *problems, int from, const char *pointer, const char *key, const char *code,
                          const char *fmt, ...)
{
	if (prsm_io_problem_at(problems, from, pointer, key))
		return;
	va_list ap;
	va_start(ap, fmt);
	vproblem(problems, pointer, key, code, fmt, ap);
	va_end(ap);
}

/* A rule's problem at pointer/member[/key] ("{value}" in its message: the sibling's value). */
static void rule_problem(prsm_problems *problems, int from, const char *pointer, const prsm_io_rule *r,
                         const char *key, const char *value)
{
	char p[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(p, sizeof p, pointer, STR(r->member));
	const char *m = STR(r->message), *at = strstr(m, "{value}");
	prsm_io_problem_once(problems, from, p, key, STR(r->code), "%.*s%s%s", at ? (int)(at - m) : (int)strlen(m), m,
	                     at ? value : "", at ? at + strlen("{value}") : "");
}

void prsm_io_check_rules(const prsm_io_rules *rules, const cJSON *obj, const char *obj_pointer, int from,
                         prsm_problems *problems)
{
	if (!cJSON_IsObject(obj))
		return;
	for (size_t i = 0; i < rules->n; i++) {
		const prsm_io_rule *r = &rules->rules[i];
		const cJSON *w = cJSON_GetObjectItemCaseSensitive(obj, STR(r->with));
		const char *value = w == NULL ? STR(r->with_default) : cJSON_IsString(w) ? w->valuestring : NULL;
		const cJSON *m = cJSON_GetObjectItemCaseSensitive(obj, STR(r->member));
		if (value == NULL || !listed(r->with_names, value) || listed(r->allowed, value) || m == NULL ||
		    (r->present && !cJSON_GetObjectItemCaseSensitive(obj, STR(r->present))) ||
		    (r->absent && cJSON_GetObjectItemCaseSensitive(obj, STR(r->absent))))
			continue;
		if (r->keep) { /* its members but those */
			for (const cJSON *it = cJSON_IsObject(m) ? m->child : NULL; it; it = it->next)
				if (it->string != NULL && !listed(r->keep, it->string))
					rule_problem(problems, from, obj_pointer, r, it->string, value);
		} else if (r->sub) { /* its member's value */
			const cJSON *s = cJSON_IsObject(m) ? cJSON_GetObjectItemCaseSensitive(m, STR(r->sub)) : NULL;
			if (cJSON_IsString(s) && !listed(r->sub_values, s->valuestring))
				rule_problem(problems, from, obj_pointer, r, STR(r->sub), value);
		} else {
			rule_problem(problems, from, obj_pointer, r, NULL, value);
		}
	}
}
