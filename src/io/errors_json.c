/*
 * errors_json.c: the `errors` and `assembly` objects of an analyze request (see errors_json.h,
 * docs/model/errors-and-assembly.md), reporting every problem at once with its JSON pointer.
 *
 * Each part's scalar fields are one table (key, struct offset, unit scale, limit) that both the
 * reader and the writer walk, so the two cannot disagree on a name or a unit. The field list and
 * the limits here and in schemas/analyze-request.schema.json must agree.
 */
#include "io/errors_json.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "io/write.h"
#include "prsm_io_tables.h"

/* ---- field tables ------------------------------------------------------------------------ */

/* API units per engine unit: engine value = JSON value / scale. */
#define SCALE_UM 1000.0                /* µm per mm */
#define SCALE_MRAD 1000.0              /* mrad per rad */
#define SCALE_DEG (180.0 / M_PI)       /* deg per rad */
#define SCALE_LEAD (1000.0 * 300.0)    /* µm per 300 mm, per (mm per mm) */

typedef struct {
	const char *key;    /* JSON name, with its unit */
	size_t offset;      /* offset of the double in the part's struct (engine units) */
	double scale;       /* JSON units per engine unit */
	double limit;       /* |JSON value| <= limit, or [0, limit] for a magnitude */
	const char *phase;  /* magnitude: the key of its direction; NULL: signed value */
} field_spec;

#define BODY(field) offsetof(prsm_body_errors, field)
#define ROLLER(field) offsetof(prsm_roller_errors, field)
#define CARRIER(field) offsetof(prsm_carrier_errors, field)

/* screw and nut, start_index_mrad apart (an array of n) */
static const field_spec body_fields[] = {
	{"pitch_radius_um", BODY(pitch_radius_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"thickness_um", BODY(thickness_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"flank_angle_mrad", BODY(flank_angle_rad), SCALE_MRAD, PRSM_IO_ERRORS_FLANK_ANGLE_MAX_MRAD, NULL},
	{"runout_um", BODY(runout_mm), SCALE_UM, PRSM_IO_ERRORS_MAGNITUDE_MAX_UM, "runout_phase_deg"},
	{"runout_phase_deg", BODY(runout_phase_rad), SCALE_DEG, PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
	{"lead_deviation_um_per_300mm", BODY(lead_deviation), SCALE_LEAD,
	 PRSM_IO_ERRORS_LEAD_MAX_UM_PER_300MM, NULL},
	{"lead_periodic_um", BODY(lead_periodic_mm), SCALE_UM, PRSM_IO_ERRORS_MAGNITUDE_MAX_UM,
	 "lead_periodic_phase_deg"},
	{"lead_periodic_phase_deg", BODY(lead_periodic_phase_rad), SCALE_DEG,
	 PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
	{"tilt_mrad", BODY(tilt_rad), SCALE_MRAD, PRSM_IO_ERRORS_TILT_MAX_MRAD, "tilt_phase_deg"},
	{"tilt_phase_deg", BODY(tilt_phase_rad), SCALE_DEG, PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
};

static const field_spec roller_fields[] = {
	{"pitch_radius_um", ROLLER(pitch_radius_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"thickness_um", ROLLER(thickness_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"arc_radius_um", ROLLER(arc_radius_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"runout_um", ROLLER(runout_mm), SCALE_UM, PRSM_IO_ERRORS_MAGNITUDE_MAX_UM, "runout_phase_deg"},
	{"runout_phase_deg", ROLLER(runout_phase_rad), SCALE_DEG, PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
	{"lead_deviation_um_per_300mm", ROLLER(lead_deviation), SCALE_LEAD,
	 PRSM_IO_ERRORS_LEAD_MAX_UM_PER_300MM, NULL},
	{"lead_periodic_um", ROLLER(lead_periodic_mm), SCALE_UM, PRSM_IO_ERRORS_MAGNITUDE_MAX_UM,
	 "lead_periodic_phase_deg"},
	{"lead_periodic_phase_deg", ROLLER(lead_periodic_phase_rad), SCALE_DEG,
	 PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
	{"pin_radial_um", ROLLER(pin_radial_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"pin_tangential_um", ROLLER(pin_tangential_mm), SCALE_UM, PRSM_IO_ERRORS_LENGTH_MAX_UM, NULL},
	{"gear_phase_mrad", ROLLER(gear_phase_rad), SCALE_MRAD, PRSM_IO_ERRORS_INDEX_MAX_MRAD, NULL},
	{"tilt_radial_mrad", ROLLER(tilt_radial_rad), SCALE_MRAD, PRSM_IO_ERRORS_TILT_MAX_MRAD, NULL},
	{"tilt_tangential_mrad", ROLLER(tilt_tangential_rad), SCALE_MRAD, PRSM_IO_ERRORS_TILT_MAX_MRAD,
	 NULL},
};

static const field_spec carrier_fields[] = {
	{"runout_um", CARRIER(runout_mm), SCALE_UM, PRSM_IO_ERRORS_MAGNITUDE_MAX_UM, "runout_phase_deg"},
	{"runout_phase_deg", CARRIER(runout_phase_rad), SCALE_DEG, PRSM_IO_ERRORS_PHASE_MAX_DEG, NULL},
};

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static const char *const errors_keys[] = {"screw", "nut", "carrier", "rollers", NULL};
static const char *const body_keys[] = {
	"pitch_radius_um", "thickness_um", "flank_angle_mrad", "runout_um", "runout_phase_deg",
	"lead_deviation_um_per_300mm", "lead_periodic_um", "lead_periodic_phase_deg",
	"start_index_mrad", "tilt_mrad", "tilt_phase_deg", NULL};
static const char *const roller_keys[] = {
	"pitch_radius_um", "thickness_um", "arc_radius_um", "runout_um", "runout_phase_deg",
	"lead_deviation_um_per_300mm", "lead_periodic_um", "lead_periodic_phase_deg",
	"pin_radial_um", "pin_tangential_um", "gear_phase_mrad", "tilt_radial_mrad",
	"tilt_tangential_mrad", NULL};
static const char *const carrier_keys[] = {"runout_um", "runout_phase_deg", NULL};

size_t prsm_io_error_field_names(const char *part, const char **names, size_t cap)
{
	const field_spec *t = NULL;
	size_t n = 0, k = 0;
	if (strcmp(part, "screw") == 0 || strcmp(part, "nut") == 0) {
		t = body_fields;
		n = COUNT(body_fields);
	} else if (strcmp(part, "roller") == 0) {
		t = roller_fields;
		n = COUNT(roller_fields);
	} else if (strcmp(part, "carrier") == 0) {
		t = carrier_fields;
		n = COUNT(carrier_fields);
	}
	for (size_t i = 0; i < n && k + 1 < cap; i++)
		if (t[i].scale != SCALE_DEG)
			names[k++] = t[i].key;
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
	const field_spec *t;
	size_t n;
	if (strcmp(part, "screw") == 0 || strcmp(part, "nut") == 0) {
		t = body_fields;
		n = COUNT(body_fields);
	} else if (strcmp(part, "roller") == 0) {
		t = roller_fields;
		n = COUNT(roller_fields);
	} else if (strcmp(part, "carrier") == 0) {
		t = carrier_fields;
		n = COUNT(carrier_fields);
	} else {
		return PRSM_ENOTFOUND;
	}
	for (size_t i = 0; i < n; i++) {
		if (strcmp(t[i].key, key) != 0)
			continue;
		memset(out, 0, sizeof *out);
		out->offset = t[i].offset;
		out->scale = t[i].scale;
		out->limit = t[i].limit;
		out->phase = t[i].scale == SCALE_DEG;
		if (t[i].phase) {
			out->magnitude = 1;
			for (size_t j = 0; j < n; j++)
				if (strcmp(t[j].key, t[i].phase) == 0)
					out->phase_offset = t[j].offset;
		}
		return 0;
	}
	return PRSM_ENOTFOUND;
}

static double *field_at(void *part, const field_spec *f)
{
	return (double *)((char *)part + f->offset);
}

static double field_value(const void *part, const field_spec *f)
{
	return *(const double *)((const char *)part + f->offset);
}

static prsm_json_range range(double min, int min_exclusive, double max, int max_exclusive)
{
	return (prsm_json_range){min, max, min_exclusive, max_exclusive};
}

/* ---- reading errors ---------------------------------------------------------------------- */

/* item (at pointer) as the field f in JSON units, checked; 0 or PRSM_EINVAL. */
static int read_value(double *json_value, const cJSON *item, const char *pointer,
                      const field_spec *f, prsm_problems *problems)
{
	if (f->phase != NULL) {
		/* a magnitude: say why a negative one is refused and what to give instead */
		if (cJSON_IsNumber(item) && isfinite(item->valuedouble) && item->valuedouble < 0.0) {
			char got[40], lim[40];
			prsm_json_format_number(got, sizeof got, item->valuedouble);
			prsm_json_format_number(lim, sizeof lim, f->limit);
			prsm_problems_add(problems, pointer, "range",
			                  "must be a number from 0 to %s (got %s): it is a magnitude; give "
			                  "its direction with %s instead (-a is a with the phase turned by 180 deg)",
			                  lim, got, f->phase);
			return PRSM_EINVAL;
		}
		return prsm_json_number_value(json_value, item, pointer, range(0.0, 0, f->limit, 0),
		                              problems);
	}
	return prsm_json_number_value(json_value, item, pointer, range(-f->limit, 0, f->limit, 0),
	                              problems);
}

/* Every field of the table present in obj into part (engine units). */
static void read_fields(void *part, const field_spec *fields, size_t count, const cJSON *obj,
                        const char *obj_pointer, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	for (size_t i = 0; i < count; i++) {
		const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, fields[i].key);
		if (item == NULL)
			continue;
		prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, fields[i].key);
		double v;
		if (read_value(&v, item, ptr, &fields[i], problems) == 0)
			*field_at(part, &fields[i]) = v / fields[i].scale;
	}
}

/* The `start_index_mrad` array of a screw or nut: exactly `starts` numbers (rad in out[]). */
static void read_start_index(double *out, const cJSON *body, const char *body_pointer, int starts,
                             prsm_problems *problems)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(body, "start_index_mrad");
	if (arr == NULL)
		return;
	char ap[PRSM_JSON_POINTER_MAX], ep[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ap, sizeof ap, body_pointer, "start_index_mrad");
	if (!cJSON_IsArray(arr)) {
		prsm_problems_add(problems, ap, "type",
		                  "must be an array of numbers from -%g to %g, one per start (got %s)",
		                  PRSM_IO_ERRORS_INDEX_MAX_MRAD, PRSM_IO_ERRORS_INDEX_MAX_MRAD,
		                  prsm_json_type_name(arr));
		return;
	}
	const int n = cJSON_GetArraySize(arr);
	if (starts > 0 && n != starts) /* starts 0: the design is unknown (it was invalid) */
		prsm_problems_add(problems, ap, "array_length",
		                  "must have exactly %d elements, one per start of the design (n = %d); "
		                  "got %d", starts, starts, n);
	const prsm_json_range r = range(-PRSM_IO_ERRORS_INDEX_MAX_MRAD, 0, PRSM_IO_ERRORS_INDEX_MAX_MRAD, 0);
	int i = 0;
	for (const cJSON *el = arr->child; el != NULL; el = el->next, i++) {
		prsm_json_pointer_append_index(ep, sizeof ep, ap, i);
		double v;
		/* elements past n are still checked, so that every problem shows at once */
		if (prsm_json_number_value(&v, el, ep, r, problems) == 0 && i < starts &&
		    i < PRSM_ERRORS_MAX_STARTS)
			out[i] = v / SCALE_MRAD;
	}
}

static void read_body(prsm_body_errors *b, const cJSON *errs, const char *pointer, const char *key,
                      int starts, prsm_problems *problems)
{
	char bp[PRSM_JSON_POINTER_MAX];
	const cJSON *o;
	if (prsm_json_get_section(&o, bp, sizeof bp, errs, pointer, key, PRSM_JSON_OPTIONAL,
	                          body_keys, problems) != PRSM_JSON_PRESENT)
		return;
	read_fields(b, body_fields, COUNT(body_fields), o, bp, problems);
	read_start_index(b->start_index_rad, o, bp, starts, problems);
}

/* The `rollers` array: exactly Z objects, roller j = element j. */
static void read_rollers(prsm_errors *out, const cJSON *errs, const char *pointer,
                         prsm_problems *problems)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(errs, "rollers");
	if (arr == NULL)
		return;
	const int z = out->rollers;
	char ap[PRSM_JSON_POINTER_MAX], ep[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ap, sizeof ap, pointer, "rollers");
	if (!cJSON_IsArray(arr)) {
		prsm_problems_add(problems, ap, "type",
		                  "must be an array of objects, one per roller (got %s)",
		                  prsm_json_type_name(arr));
		return;
	}
	const int n = cJSON_GetArraySize(arr);
	if (z > 0 && n != z) /* z 0: the design is unknown (it was invalid) */
		prsm_problems_add(problems, ap, "array_length",
		                  "must have exactly %d elements, one per roller of the design (Z = %d); "
		                  "got %d", z, z, n);
	int j = 0;
	for (const cJSON *el = arr->child; el != NULL; el = el->next, j++) {
		prsm_json_pointer_append_index(ep, sizeof ep, ap, j);
		if (prsm_json_object_value(el, ep, problems) != 0)
			continue;
		prsm_json_check_keys(el, ep, roller_keys, problems);
		/* elements past Z are still checked, into a scratch roller */
		prsm_roller_errors scratch;
		prsm_roller_errors *r = j < z ? &out->roller[j] : &scratch;
		read_fields(r, roller_fields, COUNT(roller_fields), el, ep, problems);
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
	prsm_json_check_keys(obj, base, errors_keys, problems);
	read_body(&out->screw, obj, base, "screw", d->starts, problems);
	read_body(&out->nut, obj, base, "nut", d->starts, problems);
	char cp[PRSM_JSON_POINTER_MAX];
	const cJSON *c;
	if (prsm_json_get_section(&c, cp, sizeof cp, obj, base, "carrier", PRSM_JSON_OPTIONAL,
	                          carrier_keys, problems) == PRSM_JSON_PRESENT)
		read_fields(&out->carrier, carrier_fields, COUNT(carrier_fields), c, cp, problems);
	read_rollers(out, obj, base, problems);
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
 * when that reads back as v (v = x / scale in read_fields), so that 63.7 µm is written 63.7 and
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

/* Every non-zero field of part into obj. */
static void write_fields(prsm_jw *w, cJSON *obj, const void *part, const field_spec *fields, size_t count)
{
	for (size_t i = 0; i < count; i++) {
		const double v = field_value(part, &fields[i]);
		if (v != 0.0)
			prsm_jw_number(w, obj, fields[i].key, to_api(v, fields[i].scale));
	}
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
	int any = !all_zero(b->start_index_rad, starts);
	for (size_t i = 0; i < COUNT(body_fields) && !any; i++)
		any = field_value(b, &body_fields[i]) != 0.0;
	if (!any)
		return;
	cJSON *o = prsm_jw_object(w, obj, key);
	write_fields(w, o, b, body_fields, COUNT(body_fields));
	if (all_zero(b->start_index_rad, starts))
		return;
	cJSON *arr = prsm_jw_array(w, o, "start_index_mrad");
	for (int i = 0; i < starts; i++)
		prsm_jw_number(w, arr, NULL, to_api(b->start_index_rad[i], SCALE_MRAD));
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
		write_fields(&w, prsm_jw_object(&w, obj, "carrier"), &e->carrier, carrier_fields, COUNT(carrier_fields));
	int any_roller = 0;
	for (int j = 0; j < e->rollers && !any_roller; j++)
		any_roller = !all_zero((const double *)&e->roller[j],
		                       (int)(sizeof e->roller[j] / sizeof(double)));
	if (any_roller) {
		cJSON *arr = prsm_jw_array(&w, obj, "rollers");
		for (int j = 0; j < e->rollers; j++)
			write_fields(&w, prsm_jw_object(&w, arr, NULL), &e->roller[j], roller_fields, COUNT(roller_fields));
	}
	return prsm_jw_done(&w, obj);
}
