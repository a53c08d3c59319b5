/*
 * errors_json.h: the analyze request's `errors` object (one concrete error set: a measured part
 * or one Monte Carlo sample, docs/model/errors-and-assembly.md) to prsm_errors and back, and its `assembly` options
 * object to prsm_assembly_options (schemas/analyze-request.schema.json).
 *
 * Units convert by the tables generated from the schema's x-prsm ($defs/body, roller, carrier:
 * "divide") and nowhere else: the API names the unit in the field, the engine works in mm, rad
 * and mm per mm (model/errors.h):
 *   *_um                       -> mm            (/ 1000)
 *   *_mrad                     -> rad           (/ 1000)
 *   *_deg                      -> rad           (/ (180 / pi))
 *   *_um_per_300mm             -> mm per mm     (/ 300000)
 * Every problem is added with its JSON pointer, all of them at once (io/json_util.h).
 *
 * The limits below are the schema's; schemas/analyze-request.schema.json states the same
 * numbers (tests/schema_test.py). The two rules a schema cannot express are checked by hand
 * (a step and a hook of the tables): `rollers` has exactly Z = d->rollers elements and each
 * `start_index_mrad` exactly n = d->starts.
 */
#ifndef PRSM_IO_ERRORS_JSON_H
#define PRSM_IO_ERRORS_JSON_H

#include <cJSON.h>

#include "model/assembly.h"
#include "model/design.h"
#include "model/errors.h"
#include "util/problems.h"

/* |x| limit of an index error, mrad: start_index_mrad[] (read by a step) and gear_phase_mrad; the
 * other errors' limits are the schema's own, in the generated tables (analyze-request.schema.json
 * "$defs"), and the generated tables assert that this one is the schema's too. */
#define PRSM_IO_ERRORS_INDEX_MAX_MRAD 100.0

/* assembly options */
#define PRSM_IO_ASSEMBLY_LOAD_MAX_N 1e6         /* measuring_load_N in (0, max] */
#define PRSM_IO_ASSEMBLY_ANGLES_MIN 8           /* angles_per_revolution */
#define PRSM_IO_ASSEMBLY_ANGLES_MAX 4096
#define PRSM_IO_ASSEMBLY_STROKE_MAX_MM 10000.0  /* stroke_mm in [0, max] */
#define PRSM_IO_ASSEMBLY_SPECTRUM_REVOLUTIONS_MAX 1000 /* spectrum_revolutions in [1, max] */
/* angles_per_revolution * max(spectrum_revolutions, stroke_mm / lead_mm) may not exceed this */
#define PRSM_IO_ASSEMBLY_SAMPLES_MAX 1000000

/*
 * Read the `errors` object (a concrete error set: a measured part or one sample) into out.
 * d is the resolved design (for the roller count Z = d->rollers and the start count
 * n = d->starts). out is prsm_errors_zero(out, d->rollers) first, so absent fields are 0; obj
 * NULL (no `errors` in the request) leaves it so and returns 0. pointer is the errors object's
 * own pointer (e.g. "/errors"); every problem is added below it. Returns 0, or PRSM_EINVAL when
 * a problem was added (out then holds the fields that were valid). A design with 0 rollers or
 * 0 starts stands for an unknown design (its document was invalid): the array lengths are then
 * not checked, everything else is, so that every problem of a request shows at once.
 */
int prsm_io_errors_from_json(prsm_errors *out, const cJSON *obj, const char *pointer,
                             const prsm_design *d, prsm_problems *problems);

/*
 * Read the `assembly` options object into out: prsm_assembly_options_default() first, so absent
 * fields keep their defaults; obj NULL leaves the defaults and returns 0. d (resolved) gives the
 * lead n P for the sample-count rule, which is reported at pointer itself. Returns 0 or
 * PRSM_EINVAL (a problem was added).
 */
int prsm_io_assembly_options_from_json(prsm_assembly_options *out, const cJSON *obj,
                                       const char *pointer, const prsm_design *d,
                                       prsm_problems *problems);

/*
 * The error set as an `errors` object in the API's units, only its non-zero fields: a zero set
 * is {}, a part without errors is left out, `rollers` is left out when every roller is zero
 * (otherwise it has e->rollers elements, {} for a zero roller) and `start_index_mrad` when every
 * start is zero (otherwise it has `starts` elements). Reading the object back with a design of
 * e->rollers rollers and `starts` starts gives the same set, bit for bit, for every set that was
 * read from JSON, and any other set within the limits above to a relative 2^-52 (not every
 * double in mm is a double in µm divided by 1000). Values are written as short as reads back
 * (63.7, not 63.70000000000001). The tree holds the doubles exactly; printing it is the
 * caller's (cJSON_Print() keeps only 15 digits when they are within DBL_EPSILON, so text can
 * lose the last bit). Returns NULL when out of memory; the caller owns the tree (cJSON_Delete()).
 */
cJSON *prsm_io_errors_to_json(const prsm_errors *e, int starts);

/* One scalar error field as the API names it (for tolerance paths such as "screw.runout_um"). */
typedef struct {
	size_t offset;        /* offset of the double in prsm_body_errors, prsm_roller_errors or
	                         prsm_carrier_errors (engine units) */
	double scale;         /* API units per engine unit */
	double limit;         /* the field's limit in API units */
	int magnitude;        /* 1: a radial magnitude with a phase */
	size_t phase_offset;  /* its phase's offset (magnitude only), rad in the engine */
	int phase;            /* 1: this field is itself a phase */
} prsm_io_error_field;

/* Look up key in part "screw", "nut", "carrier" or "roller" (start_index_mrad, an array, is
 * not a scalar field). Returns 0 or PRSM_ENOTFOUND. */
int prsm_io_error_field_find(prsm_io_error_field *out, const char *part, const char *key);

/* The unit suffix of an error field or parameter name ("screw.runout_um" -> "um",
 * "lead_deviation_um_per_300mm" -> "um_per_300mm"), "" when it has none. */
const char *prsm_io_error_unit_of(const char *name);

/* The scalar fields of part that a tolerance may name (phases left out), NULL-terminated into
 * names (cap entries, the last one the NULL). Returns the count (0 for an unknown part). */
size_t prsm_io_error_field_names(const char *part, const char **names, size_t cap);

#endif
