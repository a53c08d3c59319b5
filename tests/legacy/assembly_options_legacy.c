/*
 * assembly_options_legacy.c: the hand-written reader of the analyze request's "assembly" options
 * before the table-driven one (issue 24's side-by-side proof, tests/test_io_doc.c). Delete it
 * with that test once every document is ported.
 */
#include "legacy/design_reader_legacy.h"

#include <assert.h>
#include <math.h>

#include "io/errors_json.h"
#include "io/json_util.h"

static const char *const assembly_keys[] = {
	"mode", "measuring_load_N", "angles_per_revolution", "stroke_mm", "spectrum_revolutions", "curve", NULL};
static const char *const mode_names[] = {"linear", "exact", NULL}; /* index = PRSM_MODE_* */

static prsm_json_range range(double min, int min_exclusive, double max, int max_exclusive)
{
	return (prsm_json_range){min, max, min_exclusive, max_exclusive};
}

int prsm_legacy_assembly_options_from_json(prsm_assembly_options *out, const cJSON *obj,
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
	prsm_json_check_keys(obj, base, assembly_keys, problems);

	int mode;
	if (prsm_json_get_enum(&mode, obj, base, "mode", PRSM_JSON_OPTIONAL, mode_names, problems) ==
	    PRSM_JSON_PRESENT)
		out->mode = mode == 0 ? PRSM_MODE_LINEAR : PRSM_MODE_EXACT;
	prsm_json_get_number(&out->measuring_load_N, obj, base, "measuring_load_N", PRSM_JSON_OPTIONAL,
	                     range(0.0, 1, PRSM_IO_ASSEMBLY_LOAD_MAX_N, 0), problems);
	/* the sample-count rule needs these three valid (or absent: their defaults) */
	const int angles_ok =
		prsm_json_get_int(&out->angles_per_revolution, obj, base, "angles_per_revolution",
		                  PRSM_JSON_OPTIONAL, PRSM_IO_ASSEMBLY_ANGLES_MIN,
		                  PRSM_IO_ASSEMBLY_ANGLES_MAX, problems) >= 0;
	const int stroke_ok =
		prsm_json_get_number(&out->stroke_mm, obj, base, "stroke_mm", PRSM_JSON_OPTIONAL,
		                     range(0.0, 0, PRSM_IO_ASSEMBLY_STROKE_MAX_MM, 0), problems) >= 0;
	const int spectrum_ok =
		prsm_json_get_int(&out->spectrum_revolutions, obj, base, "spectrum_revolutions",
		                  PRSM_JSON_OPTIONAL, 1, PRSM_IO_ASSEMBLY_SPECTRUM_REVOLUTIONS_MAX,
		                  problems) >= 0;
	prsm_json_get_bool(&out->curve, obj, base, "curve", PRSM_JSON_OPTIONAL, problems);

	/* transmission error is sampled angles_per_revolution times per screw revolution over the
	 * longer of the spectrum record and the stroke (stroke / lead revolutions) */
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
