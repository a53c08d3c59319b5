/*
 * errors_json.c: the `errors` and `assembly` objects of an analyze request (see errors_json.h,
 * docs/model/errors-and-assembly.md), reporting every problem at once with its JSON pointer.
 *
 * Each part's scalar fields are the table generated from schemas/analyze-request.schema.json
 * ($defs/body, roller, carrier: name with its unit, member, divisor, limits, the magnitudes'
 * directions), which the reader (io/doc.c), the writer below and the tolerance names walk, so
 * they cannot disagree on a name or a unit. What the tables cannot say is here: the arrays that
 * have one element per start or roller of the design.
 */
#include "io/errors_json.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "io/write.h"
#include "prsm_io_tables.h"

#define NAME(f) prsm_io_gen_strings[(f)->name]

/* The table of part "screw", "nut", "roller" or "carrier" (a tolerance's part), NULL if none. */
static const prsm_io_table *part_table(const char *part)
{
	if (strcmp(part, "screw") == 0 || strcmp(part, "nut") == 0)
		return &prsm_io_t_error_body;
	if (strcmp(part, "roller") == 0)
		return &prsm_io_t_error_roller;
	if (strcmp(part, "carrier") == 0)
		return &prsm_io_t_error_carrier;
	return NULL;
}

/* The scalar field named key of table t, NULL if none. */
static const prsm_io_field *field_named(const prsm_io_table *t, const char *key)
{
	for (size_t i = 0; i < t->n_fields; i++)
		if (t->fields[i].kind == PRSM_IO_NUMBER && strcmp(NAME(&t->fields[i]), key) == 0)
			return &t->fields[i];
	return NULL;
}

/* 1 when f is a direction: the phase of a magnitude of its table. */
static int is_phase(const prsm_io_table *t, const prsm_io_field *f)
{
	for (size_t i = 0; i < t->n_fields; i++)
		if (t->fields[i].direction && strcmp(prsm_io_gen_strings[t->fields[i].direction], NAME(f)) == 0)
			return 1;
	return 0;
}

size_t prsm_io_error_field_names(const char *part, const char **names, size_t cap)
{
	const prsm_io_table *t = part_table(part);
	size_t k = 0;
	for (size_t i = 0; t && i < t->n_fields && k + 1 < cap; i++)
		if (t->fields[i].kind == PRSM_IO_NUMBER && !is_phase(t, &t->fields[i]))
			names[k++] = NAME(&t->fields[i]);
	if (cap)
		names[k] = NULL;
	return k;
}

const char *prsm_io_error_unit_of(const char *name)
{
	static const char *const units[] = {"um_per_300mm", "um", "mrad", "deg", NULL};
	for (int i = 0; units[i]; i++) {
		size_t ln = strlen(name), lu = strlen(units[i]);
		if (ln > lu + 1 && strcmp(name + ln - lu, units[i]) == 0 && name[ln - lu - 1] == '_')
			return units[i];
	}
	return "";
}

int prsm_io_error_field_find(prsm_io_error_field *out, const char *part, const char *key)
{
	const prsm_io_table *t = part_table(part);
	const prsm_io_field *f = t ? field_named(t, key) : NULL;
	if (f == NULL)
		return PRSM_ENOTFOUND;
	memset(out, 0, sizeof *out);
	out->offset = f->offset;
	out->scale = f->divide;
	out->limit = f->max;
	out->phase = is_phase(t, f);
	if (f->direction) {
		out->magnitude = 1;
		out->phase_offset = field_named(t, prsm_io_gen_strings[f->direction])->offset;
	}
	return 0;
}

/* ---- reading errors: the hand-written steps of the tables -------------------------------- */

/* The array obj[key] (its pointer to ap) of one element per `what` of the design: n of them
 * (its symbol's value; n 0: the design is unknown, it was invalid); items says what they are.
 * NULL when it is absent or no array (a problem then). The caller checks the elements past n
 * too, so that every problem shows at once. */
static const cJSON *per_design(char *ap, const cJSON *obj, const char *pointer, const char *key, const char *items,
                               const char *what, const char *symbol, int n, prsm_problems *problems)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(obj, key);
	if (arr == NULL)
		return NULL;
	prsm_json_pointer_append(ap, PRSM_JSON_POINTER_MAX, pointer, key);
	if (!cJSON_IsArray(arr)) {
		prsm_problems_add(problems, ap, "type", "must be an array of %s, one per %s (got %s)", items, what,
		                  prsm_json_type_name(arr));
		return NULL;
	}
	const int got = cJSON_GetArraySize(arr);
	if (n > 0 && got != n)
		prsm_problems_add(problems, ap, "array_length",
		                  "must have exactly %d elements, one per %s of the design (%s = %d); got %d", n, what,
		                  symbol, n, got);
	return arr;
}

/* The `start_index_mrad` array of a screw or nut (at->base): exactly `starts` numbers of the
 * design (at->ctx), rad in start_index_rad[]. */
int prsm_io_step_error_start_index(prsm_io_at *at, prsm_problems *problems)
{
	prsm_body_errors *b = at->base;
	const int starts = at->ctx ? ((const prsm_design *)at->ctx)->starts : 0;
	char ap[PRSM_JSON_POINTER_MAX], ep[PRSM_JSON_POINTER_MAX], items[64];
	snprintf(items, sizeof items, "numbers from -%g to %g", PRSM_IO_ERRORS_INDEX_MAX_MRAD,
	         PRSM_IO_ERRORS_INDEX_MAX_MRAD);
	const cJSON *arr = per_design(ap, at->obj, at->pointer, "start_index_mrad", items, "start", "n", starts, problems);
	const prsm_json_range r = {-PRSM_IO_ERRORS_INDEX_MAX_MRAD, PRSM_IO_ERRORS_INDEX_MAX_MRAD, 0, 0};
	int i = 0;
	for (const cJSON *el = arr ? arr->child : NULL; el != NULL; el = el->next, i++) {
		prsm_json_pointer_append_index(ep, sizeof ep, ap, i);
		double v;
		if (prsm_json_number_value(&v, el, ep, r, problems) == 0 && i < starts && i < PRSM_ERRORS_MAX_STARTS)
			b->start_index_rad[i] = v / 1000.0; /* mrad -> rad */
	}
	return 0;
}

/* The `rollers` array: exactly Z = base->rollers objects, roller j = element j, each by the
 * roller's table. */
void prsm_io_hook_error_rollers(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_errors *out = base;
	const int z = out->rollers;
	char ap[PRSM_JSON_POINTER_MAX], ep[PRSM_JSON_POINTER_MAX];
	const cJSON *arr = per_design(ap, obj, obj_pointer, "rollers", "objects", "roller", "Z", z, problems);
	int j = 0;
	for (const cJSON *el = arr ? arr->child : NULL; el != NULL; el = el->next, j++) {
		prsm_json_pointer_append_index(ep, sizeof ep, ap, j);
		if (prsm_json_object_value(el, ep, problems) != 0)
			continue;
		/* elements past Z are still checked, into a scratch roller */
		prsm_roller_errors scratch;
		prsm_io_read(j < z ? &out->roller[j] : &scratch, &prsm_io_t_error_roller, el, ep, problems);
	}
}

int prsm_io_errors_from_json(prsm_errors *out, const cJSON *obj, const char *pointer,
                             const prsm_design *d, prsm_problems *problems)
{
	assert(out != NULL && d != NULL && problems != NULL);
	const char *base = pointer ? pointer : "";
	prsm_errors_zero(out, d->rollers);
	if (obj == NULL)
		return 0;
	const int before = prsm_problems_total(problems);
	if (prsm_json_object_value(obj, base, problems) != 0)
		return PRSM_EINVAL;
	/* the fields: schemas/analyze-request.schema.json, $defs/errors (x-prsm) */
	prsm_io_read_ctx(out, &prsm_io_t_errors, obj, base, (void *)(uintptr_t)d, problems); /* read only */
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

/* ---- reading assembly options ------------------------------------------------------------ */

int prsm_io_assembly_options_from_json(prsm_assembly_options *out, const cJSON *obj,
                                       const char *pointer, const prsm_design *d,
                                       prsm_problems *problems)
{
	assert(out != NULL && d != NULL && problems != NULL);
	const char *base = pointer ? pointer : "";
	prsm_assembly_options_default(out);
	if (obj == NULL)
		return 0;
	const int before = prsm_problems_total(problems);
	if (prsm_json_object_value(obj, base, problems) != 0)
		return PRSM_EINVAL;
	/* the fields: schemas/analyze-request.schema.json, $defs/assembly (x-prsm) */
	prsm_io_read(out, &prsm_io_t_assembly_options, obj, base, problems);

	/* transmission error is sampled angles_per_revolution times per screw revolution over the
	 * longer of the spectrum record and the stroke (stroke / lead revolutions); the rule needs
	 * the three valid (or absent: their defaults) */
	const int angles_ok = !prsm_io_problem_at(problems, before, base, "angles_per_revolution");
	const int stroke_ok = !prsm_io_problem_at(problems, before, base, "stroke_mm");
	const int spectrum_ok = !prsm_io_problem_at(problems, before, base, "spectrum_revolutions");
	const double lead_mm = d->starts * d->pitch_mm;
	if (angles_ok && stroke_ok && spectrum_ok && lead_mm > 0.0) {
		const double stroke_revs = out->stroke_mm / lead_mm;
		const double revs = fmax((double)out->spectrum_revolutions, stroke_revs);
		const double samples = out->angles_per_revolution * revs;
		if (samples > PRSM_IO_ASSEMBLY_SAMPLES_MAX)
			prsm_problems_add(problems, base, "too_many_samples",
			                  "angles_per_revolution %d x %.6g revolutions (the larger of "
			                  "spectrum_revolutions %d and stroke_mm %g / lead %g mm) = %.0f "
			                  "transmission-error samples, more than %d",
			                  out->angles_per_revolution, revs, out->spectrum_revolutions,
			                  out->stroke_mm, lead_mm, ceil(samples), PRSM_IO_ASSEMBLY_SAMPLES_MAX);
	}
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

/* ---- writing errors ---------------------------------------------------------------------- */

/*
 * The JSON value (API units) of the engine value v: v * scale rounded to 15 significant digits
 * when that reads back as v (v = x / scale as the table reads it), so that 63.7 µm is written 63.7 and
 * not 63.70000000000001; otherwise v * scale itself. For a v that was read from JSON,
 * v = j / scale, v * scale reads back as v (checked over millions of random j for each scale, and
 * by the tests); for any other v the read gives v to a relative 2^-52.
 */
static double to_api(double v, double scale)
{
	const double x = v * scale;
	char text[40];
	snprintf(text, sizeof text, "%.15g", x);
	const double rounded = strtod(text, NULL);
	return rounded / scale == v ? rounded : x;
}

/* Field i of part (table t), engine units; 0 when it is not a scalar field. */
static double value_of(const void *part, const prsm_io_table *t, size_t i)
{
	double v = 0.0;
	if (t->fields[i].kind == PRSM_IO_NUMBER)
		memcpy(&v, (const char *)part + t->fields[i].offset, sizeof v);
	return v;
}

/* Every non-zero field of part (table t) into obj; w NULL: only counted. Returns their count. */
static int write_fields(prsm_jw *w, cJSON *obj, const void *part, const prsm_io_table *t)
{
	int n = 0;
	for (size_t i = 0; i < t->n_fields; i++) {
		const double v = value_of(part, t, i);
		if (v == 0.0)
			continue;
		n++;
		if (w)
			prsm_jw_number(w, obj, NAME(&t->fields[i]), to_api(v, t->fields[i].divide));
	}
	return n;
}

static int all_zero(const double *v, int n)
{
	for (int i = 0; i < n; i++)
		if (v[i] != 0.0)
			return 0;
	return 1;
}

/* The screw or nut as obj[key], left out when it has no errors (start_index_rad[] counts up to
 * `starts`). */
static void write_body(prsm_jw *w, cJSON *obj, const char *key, const prsm_body_errors *b, int starts)
{
	if (all_zero(b->start_index_rad, starts) && write_fields(NULL, NULL, b, &prsm_io_t_error_body) == 0)
		return;
	cJSON *o = prsm_jw_object(w, obj, key);
	write_fields(w, o, b, &prsm_io_t_error_body);
	if (all_zero(b->start_index_rad, starts))
		return;
	cJSON *arr = prsm_jw_array(w, o, "start_index_mrad");
	for (int i = 0; i < starts; i++)
		prsm_jw_number(w, arr, NULL, to_api(b->start_index_rad[i], 1000.0)); /* rad -> mrad */
}

cJSON *prsm_io_errors_to_json(const prsm_errors *e, int starts)
{
	assert(e != NULL);
	if (starts < 0)
		starts = 0;
	if (starts > PRSM_ERRORS_MAX_STARTS)
		starts = PRSM_ERRORS_MAX_STARTS;
	prsm_jw w = PRSM_JW_INIT;
	cJSON *obj = prsm_jw_root(&w);
	write_body(&w, obj, "screw", &e->screw, starts);
	write_body(&w, obj, "nut", &e->nut, starts);
	if (!all_zero((const double *)&e->carrier, (int)(sizeof e->carrier / sizeof(double))))
		write_fields(&w, prsm_jw_object(&w, obj, "carrier"), &e->carrier, &prsm_io_t_error_carrier);
	int any_roller = 0;
	for (int j = 0; j < e->rollers && !any_roller; j++)
		any_roller = !all_zero((const double *)&e->roller[j],
		                       (int)(sizeof e->roller[j] / sizeof(double)));
	if (any_roller) {
		cJSON *arr = prsm_jw_array(&w, obj, "rollers");
		for (int j = 0; j < e->rollers; j++)
			write_fields(&w, prsm_jw_object(&w, arr, NULL), &e->roller[j], &prsm_io_t_error_roller);
	}
	return prsm_jw_done(&w, obj);
}
