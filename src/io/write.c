/*
 * write.c: the sticky-error document writer and the generic table writer (see write.h).
 */
#include "io/write.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "util/version.h"

cJSON *prsm_jw_item(prsm_jw *w, cJSON *parent, const char *key, cJSON *item)
{
	if (item && parent && (key ? cJSON_AddItemToObject(parent, key, item) : cJSON_AddItemToArray(parent, item)))
		return item;
	cJSON_Delete(item);
	w->failed = 1;
	return NULL;
}

cJSON *prsm_jw_root(prsm_jw *w)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		w->failed = 1;
	return root;
}

cJSON *prsm_jw_done(prsm_jw *w, cJSON *root)
{
	if (w->failed) {
		cJSON_Delete(root);
		return NULL;
	}
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

void prsm_jw_pair(prsm_jw *w, cJSON *parent, const char *key, double a, double b)
{
	cJSON *arr = prsm_jw_array(w, parent, key);
	prsm_jw_number(w, arr, NULL, a);
	prsm_jw_number(w, arr, NULL, b);
}

cJSON *prsm_io_problems_to_json(const prsm_problems *p)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *arr = cJSON_CreateArray();
	for (int i = 0; arr && i < p->count; i++) {
		cJSON *it = prsm_jw_object(&w, arr, NULL);
		prsm_jw_string(&w, it, "pointer", p->items[i].pointer);
		if (p->items[i].code[0])
			prsm_jw_string(&w, it, "code", p->items[i].code);
		prsm_jw_string(&w, it, "message", p->items[i].message);
	}
	if (arr && p->dropped) {
		char msg[96];
		snprintf(msg, sizeof msg, "%d more problems not listed", p->dropped);
		cJSON *it = prsm_jw_object(&w, arr, NULL);
		prsm_jw_string(&w, it, "pointer", "");
		prsm_jw_string(&w, it, "code", "truncated");
		prsm_jw_string(&w, it, "message", msg);
	}
	return prsm_jw_done(&w, arr);
}

void prsm_io_whook_problems(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_item(w, obj, key, prsm_io_problems_to_json(at));
}

void prsm_io_whook_engine_build(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_string(w, obj, key, prsm_engine_build());
}

/* ---- the table writer ---------------------------------------------------------------------- */

static const char *member(const void *base, const prsm_io_wref *r, size_t i)
{
	const char *p = (const char *)base + r->offset;
	if (r->deref && (p = *(const char *const *)p) != NULL)
		p += r->offset2;
	if (p && r->pointer)
		p = *(const char *const *)p;
	return p ? p + i * r->stride + r->after : NULL;
}

static double number(const char *p, int type)
{
	switch (type) {
	case PRSM_IO_W_INT:
		return *(const int *)p;
	case PRSM_IO_W_SIZE:
		return (double)*(const size_t *)p;
	case PRSM_IO_W_U64:
		return (double)*(const uint64_t *)p;
	case PRSM_IO_W_ULONG:
		return (double)*(const unsigned long *)p;
	case PRSM_IO_W_LONG:
		return (double)*(const long *)p;
	default:
		return *(const double *)p;
	}
}

/* The number v of field f scaled: x scale, then / divide (each a constant or a double member). */
static double scaled(const void *base, const prsm_io_wfield *f, double v, size_t row)
{
	const char *s = f->scale_by ? member(base, &f->scale_at, row) : NULL;
	const char *d = f->divide_by ? member(base, &f->divide_at, row) : NULL;
	v *= s ? *(const double *)(const void *)s : f->scale != 0.0 ? f->scale : 1.0;
	return d ? v / *(const double *)(const void *)d : f->divide != 0.0 ? v / f->divide : v;
}

/* 1 when field f is written (at row i). */
static int wanted(const void *base, const prsm_io_wfield *f, size_t i)
{
	if (f->when == PRSM_IO_W_ALWAYS)
		return 1;
	if (f->when == PRSM_IO_W_IF_ROW)
		return i >= (size_t)f->when_value;
	const char *p = member(base, &f->when_at, i);
	if (p == NULL)
		return 0;
	double v = f->when_type == PRSM_IO_W_CHARS ? p[0] != '\0' : number(p, f->when_type);
	switch (f->when) {
	case PRSM_IO_W_IF:
		return f->when_type == PRSM_IO_W_DOUBLE ? !isnan(v) : v != 0.0;
	case PRSM_IO_W_IF_NOT:
		return v == 0.0;
	case PRSM_IO_W_IF_IS:
		return v == f->when_value;
	default:
		return v != f->when_value;
	}
}

/* A field's pointers, from the generated tables' indices when the pointer is not set. */
static const char *f_name(const prsm_io_wfield *f)
{
	return f->name ? f->name : prsm_io_wgen_strings[f->name_i];
}

static const char *f_text(const prsm_io_wfield *f)
{
	return f->text ? f->text : prsm_io_wgen_strings[f->text_i];
}

static const char *const *f_names(const prsm_io_wfield *f)
{
	return f->names ? f->names : prsm_io_wgen_names[f->names_i];
}

static const int *f_values(const prsm_io_wfield *f)
{
	return f->values ? f->values : prsm_io_wgen_values[f->values_i];
}

static const prsm_io_wtable *f_child(const prsm_io_wfield *f)
{
	return f->child ? f->child : prsm_io_wgen_tables[f->child_i];
}

static prsm_io_whook f_hook(const prsm_io_wfield *f)
{
	return f->hook ? f->hook : prsm_io_wgen_hooks[f->hook_i];
}

static const char *string(const char *p, int type)
{
	return type == PRSM_IO_W_CSTR ? *(const char *const *)p : p;
}

/* An enum's name for the int at p (else its text, or null). */
static void enum_name(prsm_jw *w, cJSON *o, const prsm_io_wfield *f, const char *key, const char *p)
{
	const char *name = f_text(f);
	const char *const *names = f_names(f);
	const int *values = f_values(f);
	for (int i = 0; i < f->n_values; i++)
		if (values[i] == *(const int *)p)
			name = names[i];
	if (name)
		prsm_jw_string(w, o, key, name);
	else
		prsm_jw_null(w, o, key);
}

/* A count: the fixed one, or (type) the member's at row (0 when a pointer on the way is NULL). */
static size_t count_of(const void *base, int fixed, int type, const prsm_io_wref *at, size_t row)
{
	if (!type)
		return (size_t)fixed;
	const char *c = member(base, at, row);
	return c ? (size_t)number(c, type) : 0;
}

/* Numbers evenly spaced from the double at `at` to the double at step_at, as the C expression
 * lo + (hi - lo) * i / (n - 1) computes them (bit-identical to the model's grids). */
static void grid(prsm_jw *w, cJSON *arr, const void *base, const prsm_io_wfield *f, size_t n, size_t row)
{
	const char *lo = member(base, &f->at, row), *hi = member(base, &f->step_at, row);
	if (lo == NULL || hi == NULL)
		return;
	const double a = *(const double *)(const void *)lo, b = *(const double *)(const void *)hi;
	for (size_t i = 0; arr && i < n; i++)
		prsm_jw_number(w, arr, NULL, scaled(base, f, n > 1 ? a + (b - a) * (double)i / (double)(n - 1) : a, row));
}

static void array(prsm_jw *w, cJSON *arr, const void *base, const prsm_io_wfield *f, size_t row)
{
	const size_t n = count_of(base, f->count, f->count_type, &f->count_at, row);
	if (f->shape == PRSM_IO_W_TUPLE) {
		prsm_io_write_fields(w, arr, base, f_child(f), row);
		return;
	}
	if (f->shape == PRSM_IO_W_GRID) { /* step_at is the grid's end, no count */
		grid(w, arr, base, f, n, row);
		return;
	}
	const size_t step = count_of(base, f->step, f->step_type, &f->step_at, row);
	for (size_t i = 0; arr && i < n; i++) {
		if (f->shape == PRSM_IO_W_MATRIX) { /* item i: elements i x step to i x step + step - 1 */
			cJSON *r = prsm_jw_array(w, arr, NULL);
			for (size_t j = 0; r && j < step; j++) {
				const char *p = member(base, &f->at, i * step + j);
				if (p == NULL)
					break;
				prsm_jw_number(w, r, NULL, scaled(base, f, number(p, f->type), row));
			}
			continue;
		}
		const size_t k = f->shape == PRSM_IO_W_SLICE ? row * n + i : step ? row + i * step : i;
		const char *p = f->shape == PRSM_IO_W_ROWS ? base : member(base, &f->at, k);
		if (p == NULL)
			break;
		if (f_child(f))
			prsm_io_write_fields(w, prsm_jw_object(w, arr, NULL), p, f_child(f), f->shape == PRSM_IO_W_ROWS ? i : 0);
		else if (f_names(f))
			enum_name(w, arr, f, NULL, p);
		else if (f->is_set)
			prsm_jw_bool(w, arr, NULL, *(const int *)p == f->is_value);
		else if (f->mask)
			prsm_jw_bool(w, arr, NULL, (*(const int *)p & f->mask) != 0);
		else if (f->type >= PRSM_IO_W_CHARS)
			prsm_jw_string(w, arr, NULL, string(p, f->type));
		else
			prsm_jw_number(w, arr, NULL, scaled(base, f, number(p, f->type), row));
	}
}

static void field(prsm_jw *w, cJSON *o, const void *base, const prsm_io_wfield *f, size_t row)
{
	const char *p = f->kind == PRSM_IO_W_TEXT || f->kind == PRSM_IO_W_ARRAY || f->kind == PRSM_IO_W_INDEX
	                ? base : member(base, &f->at, row);
	if (p == NULL)
		return;
	switch (f->kind) {
	case PRSM_IO_W_NUMBER:
		prsm_jw_number(w, o, f_name(f), scaled(base, f, number(p, f->type), row));
		break;
	case PRSM_IO_W_BOOL:
		prsm_jw_bool(w, o, f_name(f), f->type ? (f->mask ? (*(const int *)p & f->mask) != 0 : *(const int *)p != 0)
		                                    : f->mask);
		break;
	case PRSM_IO_W_ENUM:
		enum_name(w, o, f, f_name(f), p);
		break;
	case PRSM_IO_W_FLAGS: {
		cJSON *arr = prsm_jw_array(w, o, f_name(f));
		const char *const *names = f_names(f);
		const int *values = f_values(f);
		for (int i = 0; i < f->n_values; i++)
			if (*(const int *)p & values[i])
				prsm_jw_string(w, arr, NULL, names[i]);
		break;
	}
	case PRSM_IO_W_STRING:
		if (string(p, f->type))
			prsm_jw_string(w, o, f_name(f), string(p, f->type));
		break;
	case PRSM_IO_W_TEXT:
		prsm_jw_string(w, o, f_name(f), f_text(f));
		break;
	case PRSM_IO_W_OBJECT: /* a section of the same struct keeps the row */
		prsm_io_write_fields(w, prsm_jw_object(w, o, f_name(f)), p, f_child(f), f->at.stride ? 0 : row);
		break;
	case PRSM_IO_W_ARRAY:
		array(w, prsm_jw_array(w, o, f_name(f)), p, f, row);
		break;
	case PRSM_IO_W_HOOK:
		f_hook(f)(w, o, f_name(f), p);
		break;
	case PRSM_IO_W_INDEX:
		prsm_jw_number(w, o, f_name(f), (double)(row + (size_t)f->count));
		break;
	}
}

void prsm_io_write_fields(prsm_jw *w, cJSON *obj, const void *base, const prsm_io_wtable *t, size_t row)
{
	for (size_t i = 0; obj && i < t->n_fields; i++) {
		const prsm_io_wfield *f = &t->fields[i];
		if (wanted(base, f, row))
			field(w, obj, base, f, row);
		else if (f->else_null)
			prsm_jw_null(w, obj, f_name(f));
	}
}

cJSON *prsm_io_write(prsm_jw *w, cJSON *parent, const char *key, const void *base, const prsm_io_wtable *t)
{
	cJSON *o = prsm_jw_object(w, parent, key);
	prsm_io_write_fields(w, o, base, t, 0);
	return o;
}
