/*
 * design_json.c: reading a design document into prsm_design (see design_json.h), reporting
 * every problem of the document at once with its JSON pointer.
 *
 * The fields, their limits, units and C members are stated once, in schemas/design.schema.json
 * ("x-prsm"); scripts/gen-io-tables.py turns them into the table io/doc.c reads by. What a table
 * cannot say is here, as hooks and steps: the nut length converted to engaged threads, the
 * reliability's gaps, the thread-compliance rules that tie fields together, the duty cycle, the
 * column.
 */
#include "io/design_json.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "model/compliance.h"
#include "model/life.h"
#include "prsm_io_tables.h"

static const char *const duty_keys[] = {"axial_load_N", "travel_mm", NULL};

static prsm_json_range range(double min, int min_exclusive, double max, int max_exclusive)
{
	return (prsm_json_range){min, max, min_exclusive, max_exclusive};
}

/* (0, inf): lengths and radii */
static prsm_json_range positive(void)
{
	return range(0.0, 1, INFINITY, 0);
}

/* obj[key] is there at all, whatever its type (for the either/or rules). */
static int has_member(const cJSON *obj, const char *key)
{
	return cJSON_IsObject(obj) && cJSON_GetObjectItemCaseSensitive(obj, key) != NULL;
}

/* obj[key] is there and no problem was reported at its pointer (it was read). */
static int member_read(const cJSON *obj, const char *obj_pointer, const char *key, const prsm_problems *problems)
{
	return has_member(obj, key) && !prsm_io_problem_at(problems, 0, obj_pointer, key);
}

/* engaged_threads, or nut_length_mm converted to whole threads; exactly one of them. */
void prsm_io_hook_engagement(void *base, const cJSON *g, const char *gp, prsm_problems *problems)
{
	prsm_design *d = base;
	const int pitch_ok = member_read(g, gp, "pitch_mm", problems);
	const int has_threads = has_member(g, "engaged_threads");
	const int has_length = has_member(g, "nut_length_mm");
	if (!has_threads && !has_length) {
		prsm_io_problem(problems, gp, "engaged_threads", "required",
		                "is required (an integer from 1 to %d), or give nut_length_mm instead",
		                PRSM_DESIGN_ENGAGED_THREADS_MAX);
		return;
	}
	if (has_threads)
		prsm_json_get_int(&d->engaged_threads, g, gp, "engaged_threads", PRSM_JSON_REQUIRED, 1,
		                  PRSM_DESIGN_ENGAGED_THREADS_MAX, problems);
	double length_mm = NAN;
	int length_ok = has_length && prsm_json_get_number(&length_mm, g, gp, "nut_length_mm",
	                                                   PRSM_JSON_REQUIRED, positive(),
	                                                   problems) == PRSM_JSON_PRESENT;
	if (has_threads && has_length) {
		prsm_io_problem(problems, gp, "nut_length_mm", "conflict", "give engaged_threads or nut_length_mm, not both");
		return;
	}
	if (!length_ok || !pitch_ok)
		return;
	/* whole threads in the nut length; a ratio within 1e-9 of a whole number counts as whole */
	double threads = floor(length_mm / d->pitch_mm + 1e-9);
	if (threads < 1.0)
		prsm_io_problem(problems, gp, "nut_length_mm", "range",
		                "nut_length_mm %g mm is shorter than one pitch (%g mm): no thread engages", length_mm,
		                d->pitch_mm);
	else if (threads > PRSM_DESIGN_ENGAGED_THREADS_MAX)
		prsm_io_problem(problems, gp, "nut_length_mm", "range",
		                "nut_length_mm %g mm gives %g engaged threads at pitch %g mm, more than %d", length_mm,
		                threads, d->pitch_mm, PRSM_DESIGN_ENGAGED_THREADS_MAX);
	else
		d->engaged_threads = (int)threads;
}

/* "stiffness"."thread_compliance": model "none" (rigid threads) wins over any width, which then
 * has no meaning (docs/model/kinematics-efficiency-stiffness-life.md). */
int prsm_io_step_compliance_none(prsm_io_at *at, prsm_problems *problems)
{
	const cJSON *model = cJSON_GetObjectItemCaseSensitive(at->obj, "model");
	if (!cJSON_IsString(model) || strcmp(model->valuestring, "none") != 0)
		return 0;
	((prsm_design_stiffness *)at->base)->width_rule = PRSM_THREAD_COMPLIANCE_NONE;
	if (has_member(at->obj, "width"))
		prsm_io_problem(problems, at->pointer, "width", "conflict",
		                "a width has no meaning with model \"none\" (rigid threads)");
	return 0;
}

/* width "given" needs width_mm. */
int prsm_io_step_compliance_width_mm(prsm_io_at *at, prsm_problems *problems)
{
	if (((prsm_design_stiffness *)at->base)->width_rule == PRSM_THREAD_WIDTH_GIVEN && !has_member(at->obj, "width_mm"))
		prsm_io_problem(problems, at->pointer, "width_mm", "required", "is required with width \"given\" (mm)");
	return 0;
}

/* "life"."reliability_percent": 90, or 95 to 99 (the table of reliability factors, docs/model/kinematics-efficiency-stiffness-life.md) */
void prsm_io_hook_reliability(void *base, const cJSON *l, const char *lp, prsm_problems *problems)
{
	prsm_design_life *o = base;
	int pct;
	if (prsm_json_get_int(&pct, l, lp, "reliability_percent", PRSM_JSON_OPTIONAL, 90, 99, problems) !=
	    PRSM_JSON_PRESENT)
		return;
	if (pct > 90 && pct < 95)
		prsm_io_problem(problems, lp, "reliability_percent", "enum", "must be 90, 95, 96, 97, 98 or 99 (got %d)", pct);
	else
		o->reliability_percent = pct;
}

/* "life"."duty_cycle": steps of load and travel (docs/model/kinematics-efficiency-stiffness-life.md) */
void prsm_io_hook_duty_cycle(void *base, const cJSON *l, const char *lp, prsm_problems *problems)
{
	prsm_design_life *o = base;
	char dp[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	const cJSON *duty = cJSON_GetObjectItemCaseSensitive(l, "duty_cycle");
	if (duty == NULL)
		return;
	prsm_json_pointer_append(dp, sizeof dp, lp, "duty_cycle");
	const int n = cJSON_GetArraySize(duty);
	if (!cJSON_IsArray(duty) || n < 1 || n > PRSM_DUTY_CYCLE_MAX) {
		prsm_problems_add(problems, dp, cJSON_IsArray(duty) ? "size" : "type",
		                  "must be an array of 1 to %d steps {axial_load_N, travel_mm}",
		                  PRSM_DUTY_CYCLE_MAX);
		return;
	}
	double travel_sum = 0.0;
	int i = 0;
	for (const cJSON *step = duty->child; step; step = step->next, i++) {
		prsm_json_pointer_append_index(ip, sizeof ip, dp, i);
		if (prsm_json_object_value(step, ip, problems) != 0)
			continue;
		prsm_json_check_keys(step, ip, duty_keys, problems);
		prsm_json_get_number(&o->duty_load_N[i], step, ip, "axial_load_N", PRSM_JSON_REQUIRED,
		                     range(-PRSM_DESIGN_LOAD_MAX_N, 0, PRSM_DESIGN_LOAD_MAX_N, 0), problems);
		if (prsm_json_get_number(&o->duty_travel_mm[i], step, ip, "travel_mm", PRSM_JSON_REQUIRED,
		                         range(0.0, 0, 1e9, 0), problems) == PRSM_JSON_PRESENT)
			travel_sum += o->duty_travel_mm[i];
	}
	o->duty_steps = n;
	if (!(travel_sum > 0.0))
		prsm_problems_add(problems, dp, "range", "the steps' travel_mm must not all be 0");
}

/* "column": both members read, or no column check */
void prsm_io_hook_column(void *base, const cJSON *c, const char *cp, prsm_problems *problems)
{
	prsm_design *d = base;
	d->life.column = member_read(c, cp, "free_length_mm", problems) && member_read(c, cp, "fixity", problems);
}

void prsm_io_operating_point_from_json(prsm_design *d, const cJSON *doc, const char *base,
                                       prsm_problems *problems)
{
	prsm_io_read_member(d, &prsm_io_t_design, "operating_point", doc, base, problems);
}

int prsm_io_design_from_json(prsm_design *out, const cJSON *doc, const char *base_pointer,
                             prsm_problems *problems)
{
	assert(out != NULL && problems != NULL);
	const char *base = base_pointer ? base_pointer : "";
	const int before = prsm_problems_total(problems);
	prsm_design_init(out);
	if (prsm_json_object_value(doc, base, problems) != 0)
		return PRSM_EINVAL;
	prsm_io_read(out, &prsm_io_t_design, doc, base, problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

int prsm_io_design_load(prsm_design *out, prsm_geometry *geom, prsm_problems *warnings,
                        const cJSON *doc, const char *base_pointer, prsm_problems *problems)
{
	assert(out != NULL && problems != NULL);
	int rc = prsm_io_design_from_json(out, doc, base_pointer, problems);
	if (rc != 0)
		return rc;
	/* the model's checks know only the design's own pointers: collect, then prefix */
	prsm_geometry local_geom;
	prsm_problems *scratch = malloc(2 * sizeof *scratch); /* ~50 kB: kept off worker stacks */
	if (scratch == NULL) {
		prsm_problems_add(problems, base_pointer ? base_pointer : "", "out_of_memory",
		                  "out of memory while checking the design");
		return PRSM_ENOMEM;
	}
	prsm_problems *errors = &scratch[0], *rule_warnings = &scratch[1];
	prsm_problems_init(errors);
	prsm_problems_init(rule_warnings);
	rc = prsm_design_resolve(out, errors);
	prsm_json_problems_append_prefixed(problems, errors, base_pointer);
	if (rc != 0)
		goto cleanup;
	prsm_problems_init(errors);
	rc = prsm_geometry_check(geom ? geom : &local_geom, rule_warnings, errors, out);
	prsm_geometry_plausibility(rule_warnings, out);
	prsm_json_problems_append_prefixed(problems, errors, base_pointer);
	if (warnings != NULL)
		prsm_json_problems_append_prefixed(warnings, rule_warnings, base_pointer);
cleanup:
	free(scratch);
	return rc;
}
