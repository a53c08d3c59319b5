/*
 * optimization_json.c: the optimisation document (schemas/optimization.schema.json) to the
 * design problem of opt/design_problem.h and the optimiser's options. Every problem of the
 * document is reported at once with its JSON pointer, as src/io/study_json.c does for studies.
 * The result document: optimization_result.c; the run: src/app/optimize.c.
 *
 * The fields, their limits and C members are stated once, in the schema ("x-prsm"); io/doc.c
 * reads the document by the table generated from it. What a table cannot say is here, as the
 * steps and hooks the schema names: the base design (the variables' defaults), a variable given
 * as pitch or lead and as roller or screw radius, the integer sets (values or min to max), the
 * ranges' order, the objectives in the problem's list, what the method needs of them, the
 * caller's evaluation cap, and the robust constraints with the study every candidate's is made
 * from, checked once on the base design (its problems re-pointed under /robust).
 */
#include "io/optimization_json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/design_json.h"
#include "io/doc.h"
#include "io/json_util.h"
#include "io/study_json.h"
#include "opt/design_problem.h"
#include "prsm_io_tables.h"

/* Robust studies: default samples per candidate. */
#define ROBUST_DEFAULT_SAMPLES 256

/* What the steps share while a document is read. */
typedef struct {
	size_t max_evaluations;  /* the caller's cap, 0: PRSM_IO_OPT_MAX_EVALUATIONS */
	const cJSON *design;     /* the base design */
	int design_ok;
	int robust_start;        /* the problems' count once the robust section's keys were checked */
	const prsm_io_study_options *study; /* the study reader's hooks (may be NULL) */
} opt_reading;

void prsm_io_optimization_release(prsm_io_optimization *od)
{
	if (od) {
		cJSON_Delete(od->study);
		od->study = NULL;
	}
}

/* The base design: every field the optimiser does not vary. */
int prsm_io_step_opt_design(prsm_io_at *at, prsm_problems *pr)
{
	opt_reading *c = at->ctx;
	prsm_design base;
	c->design = cJSON_GetObjectItemCaseSensitive(at->obj, "design");
	if (c->design)
		c->design_ok = prsm_io_design_from_json(&base, c->design, "/design", pr) == 0;
	if (!c->design_ok)
		prsm_design_init(&base);
	prsm_io_optimization *od = at->root;
	prsm_dp_spec_init(&od->spec, &base);
	/* the allowed values of the lead or pitch are members of `variables` only when given */
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(at->obj, "variables");
	od->pitch_values_given = cJSON_IsObject(v) && (cJSON_GetObjectItemCaseSensitive(v, "lead_values_mm") ||
	                                               cJSON_GetObjectItemCaseSensitive(v, "pitch_values_mm"));
	return 0;
}

static int ascending(const void *a, const void *b)
{
	const double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* ---- the variables -------------------------------------------------------------------------- */

/* Pitch or lead, roller or screw radius: one of each pair, read as the range it is. */
int prsm_io_step_opt_variables(prsm_io_at *at, prsm_problems *pr)
{
	prsm_dp_spec *s = &((prsm_io_optimization *)at->root)->spec;
	static const char *const pairs[][2] = {{"pitch_mm", "lead_mm"}, {"roller_radius_mm", "screw_radius_mm"}};
	int second[2];
	for (int k = 0; k < 2; k++) {
		second[k] = cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][1]) &&
		            !cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][0]);
		if (cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][0]) &&
		    cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][1]))
			prsm_io_problem(pr, at->pointer, pairs[k][1], "conflict", "give %s or %s, not both", pairs[k][0],
			                pairs[k][1]);
	}
	s->pitch_is_lead = second[0];
	const prsm_io_optimization *od = at->root;
	if (od->pitch_values_given) {
		/* a list of allowed leads (or pitches) instead of a range: a discrete variable */
		const int lead = cJSON_GetObjectItemCaseSensitive(at->obj, "lead_values_mm") != NULL;
		const char *key = lead ? "lead_values_mm" : "pitch_values_mm";
		if (lead && cJSON_GetObjectItemCaseSensitive(at->obj, "pitch_values_mm"))
			prsm_io_problem(pr, at->pointer, "pitch_values_mm", "conflict",
			                "give lead_values_mm or pitch_values_mm, not both");
		for (int k = 0; k < 2; k++)
			if (cJSON_GetObjectItemCaseSensitive(at->obj, pairs[0][k]))
				prsm_io_problem(pr, at->pointer, pairs[0][k], "conflict",
				                "give %s (a range) or %s (allowed values), not both", pairs[0][k], key);
		s->pitch_is_lead = lead;
		prsm_io_get(at, key, pr);
		if (s->n_pitch_values > 0 && s->n_pitch_values <= PRSM_OPT_MAX_LEVELS)
			qsort(s->pitch_values, (size_t)s->n_pitch_values, sizeof s->pitch_values[0], ascending);
	} else {
		prsm_io_get(at, pairs[0][second[0]], pr);
	}
	s->radius_is_screw = second[1];
	prsm_io_get(at, pairs[1][second[1]], pr);
	return 0;
}

/* A range whose min and max were read: min < max, and it varies. */
static void range_read(const prsm_io_at *at, prsm_dp_range *r, prsm_problems *pr)
{
	if (!(r->min < r->max))
		prsm_io_problem(pr, at->pointer, "max", "empty_range", "max (%g) must exceed min (%g)", r->max, r->min);
	r->vary = 1;
}

int prsm_io_step_opt_range(prsm_io_at *at, prsm_problems *pr)
{
	if (prsm_io_was_read(at, "min") && prsm_io_was_read(at, "max"))
		range_read(at, at->base, pr);
	return 0;
}

/* The flank angle: read up to 90 deg inclusive, then refused there with its own message. */
int prsm_io_step_opt_flank(prsm_io_at *at, prsm_problems *pr)
{
	prsm_dp_range *r = at->base;
	const prsm_json_range rg = {0.0, 90.0, 1, 0};
	const int a = prsm_json_get_number(&r->min, at->obj, at->pointer, "min", PRSM_JSON_REQUIRED, rg, pr);
	const int b = prsm_json_get_number(&r->max, at->obj, at->pointer, "max", PRSM_JSON_REQUIRED, rg, pr);
	if (a == PRSM_JSON_PRESENT && b == PRSM_JSON_PRESENT)
		range_read(at, r, pr);
	if (r->vary && r->max >= 90.0)
		prsm_problems_add(pr, at->pointer, "range", "flank angle must stay below 90 deg");
	return 0;
}

/* A discrete set {values} or {min, max} at obj[key] (integers in [lo, hi]). max may be left
 * out when auto_min is not NULL: *auto_min is then set and the caller fills the set. */
static void read_set(prsm_dp_set *s, const cJSON *obj, const char *base, const char *key, int lo, int hi,
                     int *auto_min, prsm_problems *pr)
{
	static const char *const set_keys[] = {"values", "min", "max", NULL};
	const cJSON *o = NULL;
	char ptr[PRSM_JSON_POINTER_MAX], vp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&o, ptr, sizeof ptr, obj, base, key, PRSM_JSON_OPTIONAL, set_keys,
	                          pr) != PRSM_JSON_PRESENT)
		return;
	const cJSON *values = cJSON_GetObjectItemCaseSensitive(o, "values");
	prsm_json_pointer_append(vp, sizeof vp, ptr, "values");
	if (values) {
		if (cJSON_GetObjectItemCaseSensitive(o, "min") || cJSON_GetObjectItemCaseSensitive(o, "max"))
			prsm_problems_add(pr, vp, "conflict", "give values or min/max, not both");
		if (!cJSON_IsArray(values)) {
			prsm_problems_add(pr, vp, "type", "must be an array, got %s", prsm_json_type_name(values));
			return;
		}
		int n = cJSON_GetArraySize(values);
		if (n < 1 || n > PRSM_OPT_MAX_LEVELS) {
			prsm_problems_add(pr, vp, "count", "1..%d values (got %d)", PRSM_OPT_MAX_LEVELS, n);
			return;
		}
		int i = 0, bad = 0;
		const cJSON *v;
		cJSON_ArrayForEach(v, values) {
			char ip[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ip, sizeof ip, vp, i);
			int x = i > 0 ? s->values[i - 1] : lo - 1; /* a bad value: as the last good one */
			if (prsm_json_int_value(&x, v, ip, lo, hi, pr)) {
				bad = 1;
			} else if (i > 0 && x <= s->values[i - 1]) {
				prsm_problems_add(pr, ip, "order", "values must be distinct and ascending");
				bad = 1;
			}
			s->values[i++] = x;
		}
		if (!bad)
			s->count = n;
		return;
	}
	int mn = lo, mx = hi;
	int a = prsm_json_get_int(&mn, o, ptr, "min", PRSM_JSON_REQUIRED, lo, hi, pr);
	int b = prsm_json_get_int(&mx, o, ptr, "max", auto_min ? PRSM_JSON_OPTIONAL : PRSM_JSON_REQUIRED, lo, hi, pr);
	if (a != PRSM_JSON_PRESENT || b < 0)
		return;
	if (b == PRSM_JSON_ABSENT) {
		*auto_min = mn; /* rollers up to Z_max: filled once the geometry is known */
		return;
	}
	if (mx < mn || mx - mn + 1 > PRSM_OPT_MAX_LEVELS) {
		prsm_io_problem(pr, ptr, "max", "range", "max (%d) must be at least min (%d) and span at most %d values", mx,
		                mn, PRSM_OPT_MAX_LEVELS);
		return;
	}
	for (int v = mn; v <= mx; v++)
		s->values[s->count++] = v;
}

void prsm_io_hook_opt_starts(void *base, const cJSON *v, const char *p, prsm_problems *pr)
{
	read_set(&((prsm_io_optimization *)base)->spec.starts, v, p, "starts", 3, PRSM_DESIGN_STARTS_MAX, NULL, pr);
}

void prsm_io_hook_opt_rollers(void *base, const cJSON *v, const char *p, prsm_problems *pr)
{
	prsm_io_optimization *od = base;
	od->rollers_auto_max = -1;
	read_set(&od->spec.rollers, v, p, "rollers", 1, PRSM_DESIGN_ROLLERS_MAX, &od->rollers_auto_max, pr);
}

void prsm_io_hook_opt_threads(void *base, const cJSON *v, const char *p, prsm_problems *pr)
{
	read_set(&((prsm_io_optimization *)base)->spec.threads, v, p, "engaged_threads", 1,
	         PRSM_DESIGN_ENGAGED_THREADS_MAX, NULL, pr);
}

int prsm_io_step_opt_nothing_varies(prsm_io_at *at, prsm_problems *pr)
{
	const prsm_io_optimization *od = at->root;
	const prsm_dp_spec *s = &od->spec;
	if (!s->pitch.vary && !s->radius.vary && !s->flank_deg.vary && !s->starts.count && !s->rollers.count &&
	    od->rollers_auto_max < 0 && !s->threads.count && !s->n_pitch_values)
		prsm_problems_add(pr, at->pointer, "nothing_varies", "give at least one variable a range or values");
	return 0;
}

/* ---- objectives, method, constraints, solver ------------------------------------------------- */

/* An objective, once, appended to the problem's list with its weight (default 1). */
int prsm_io_step_opt_objective(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_optimization *od = at->root;
	const prsm_io_opt_objective *o = at->base;
	if (!prsm_io_was_read(at, "name"))
		return 0;
	for (int k = 0; k < od->spec.n_objectives; k++)
		if (od->spec.objective[k] == o->kind) {
			prsm_io_problem(pr, at->pointer, "name", "duplicate", "objective %s given twice",
			                prsm_dp_objective_names[o->kind]);
			break;
		}
	od->spec.objective[od->spec.n_objectives] = o->kind;
	od->weight[od->spec.n_objectives] = prsm_io_was_read(at, "weight") ? o->weight : 1.0;
	od->spec.n_objectives++;
	return 0;
}

/* What the method needs of the objectives. */
void prsm_io_hook_opt_method(void *base, const cJSON *m, const char *p, prsm_problems *pr)
{
	(void)m;
	const prsm_io_optimization *od = base;
	const int n = od->spec.n_objectives;
	if (od->method == PRSM_IO_OPT_PARETO && n != 2)
		prsm_io_problem(pr, p, "method", "objectives", "a Pareto sweep needs exactly 2 objectives (got %d)", n);
	if (od->method == PRSM_IO_OPT_WEIGHTED) {
		double sum = 0.0;
		for (int k = 0; k < n; k++)
			sum += od->weight[k];
		if (!(sum > 0.0))
			prsm_problems_add(pr, "/objectives", "weights", "at least one weight must be positive");
	}
	if (od->method == PRSM_IO_OPT_SINGLE && n > 1)
		prsm_io_problem(pr, p, "method", "objectives", "single needs exactly one objective (got %d)", n);
}

/* Several objectives need a method. */
int prsm_io_step_opt_multi(prsm_io_at *at, prsm_problems *pr)
{
	const int n = ((prsm_io_optimization *)at->root)->spec.n_objectives;
	if (!cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(at->obj, "multi_objective")) && n > 1)
		prsm_problems_add(pr, "/multi_objective", "required",
		                  "%d objectives need a multi_objective method (weighted_sum or pareto)", n);
	return 0;
}

void prsm_io_hook_opt_constraints(void *base, const cJSON *c, const char *p, prsm_problems *pr)
{
	(void)c;
	const prsm_dp_spec *s = base;
	if (!isnan(s->screw_diameter_min_mm) && !isnan(s->screw_diameter_max_mm) &&
	    !(s->screw_diameter_min_mm < s->screw_diameter_max_mm))
		prsm_io_problem(pr, p, "screw_diameter_max_mm", "empty_range",
		                "screw_diameter_max_mm (%g) must exceed screw_diameter_min_mm (%g)", s->screw_diameter_max_mm,
		                s->screw_diameter_min_mm);
	if (!isnan(s->critical_speed_factor_min) && !s->base.life.column)
		prsm_io_problem(pr, p, "critical_speed_factor_min", "needs_column",
		                "a critical-speed constraint needs the design's column (free_length_mm and fixity)");
}

/* solver.max_evaluations: at most the caller's cap. */
int prsm_io_step_opt_max_evaluations(prsm_io_at *at, prsm_problems *pr)
{
	const opt_reading *c = at->ctx;
	prsm_opt_options *o = at->base;
	size_t cap = c->max_evaluations ? c->max_evaluations : PRSM_IO_OPT_MAX_EVALUATIONS;
	if (cap > PRSM_IO_OPT_MAX_EVALUATIONS)
		cap = PRSM_IO_OPT_MAX_EVALUATIONS;
	int me = (int)o->max_evaluations;
	if (prsm_json_get_int(&me, at->obj, at->pointer, "max_evaluations", PRSM_JSON_OPTIONAL, 1, (int)cap, pr) ==
	    PRSM_JSON_PRESENT)
		o->max_evaluations = (size_t)me;
	return 0;
}

/* solver.seed: an integer up to 2^53 - 1. */
void prsm_io_hook_opt_seed(void *base, const cJSON *s, const char *p, prsm_problems *pr)
{
	double seed = 1.0;
	if (prsm_json_get_number(&seed, s, p, "seed", PRSM_JSON_OPTIONAL, (prsm_json_range){0.0, 9007199254740991.0, 0, 0},
	                         pr) == PRSM_JSON_PRESENT) {
		if (seed != floor(seed))
			prsm_io_problem(pr, p, "seed", "integer", "must be an integer (got %g)", seed);
		((prsm_opt_options *)base)->seed = (unsigned long)seed;
	}
}

/* ---- robust constraints ---- */

int prsm_io_step_opt_robust(prsm_io_at *at, prsm_problems *pr)
{
	prsm_robust_init(at->base);
	((opt_reading *)at->ctx)->robust_start = prsm_problems_total(pr);
	return 0;
}

/* robust/constraints/N: a study output, once, and its spec. */
int prsm_io_step_opt_robust_constraint(prsm_io_at *at, prsm_problems *pr)
{
	static const char *const spec_keys[] = {"lower", "upper", NULL};
	const prsm_io_optimization *od = at->root;
	prsm_robust_constraint *c = at->base;
	const char *name = NULL;
	if (prsm_json_get_string(&name, at->obj, at->pointer, "output", PRSM_JSON_REQUIRED, PRSM_ROBUST_NAME_MAX - 1,
	                         pr) == PRSM_JSON_PRESENT) {
		prsm_output_kind kind;
		if (prsm_output_parse(name, &kind))
			prsm_io_problem(pr, at->pointer, "output", "unknown_output", "unknown output '%s': " PRSM_OUTPUT_NAMES_TEXT,
			                name);
		else
			for (int k = 0; k < od->robust.n; k++)
				if (strcmp(od->robust.c[k].output, name) == 0)
					prsm_io_problem(pr, at->pointer, "output", "duplicate", "%s has a robust constraint already "
					                "(at /robust/constraints/%d)", name, k);
		snprintf(c->output, sizeof c->output, "%s", name);
	}
	const cJSON *spec = NULL;
	char sp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&spec, sp, sizeof sp, at->obj, at->pointer, "spec", PRSM_JSON_REQUIRED, spec_keys, pr) ==
	    PRSM_JSON_PRESENT) {
		const prsm_json_range any = {-1e300, 1e300, 0, 0};
		int lo = prsm_json_get_number(&c->spec.lower, spec, sp, "lower", PRSM_JSON_OPTIONAL, any, pr);
		int hi = prsm_json_get_number(&c->spec.upper, spec, sp, "upper", PRSM_JSON_OPTIONAL, any, pr);
		c->spec.has_lower = lo == PRSM_JSON_PRESENT;
		c->spec.has_upper = hi == PRSM_JSON_PRESENT;
		if (lo == PRSM_JSON_ABSENT && hi == PRSM_JSON_ABSENT)
			prsm_problems_add(pr, sp, "required", "a spec needs lower, upper or both");
		if (c->spec.has_lower && c->spec.has_upper && !(c->spec.lower < c->spec.upper))
			prsm_io_problem(pr, sp, "upper", "range", "upper must be greater than lower");
	}
	return 0;
}

/* A robust constraint is kept when it has no problem. */
int prsm_io_step_opt_robust_kept(prsm_io_at *at, prsm_problems *pr)
{
	return prsm_problems_total(pr) > at->start;
}

/* Re-point a problem of the candidate study document into the optimisation document. */
static void add_study_problem(prsm_problems *pr, const prsm_io_optimization *od, const prsm_problem *p)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	const char *q = p->pointer;
	if (strncmp(q, "/design", 7) == 0 && (q[7] == '\0' || q[7] == '/')) {
		prsm_problems_add(pr, "/robust", "base_design", "the tolerance set is checked on the base "
		                  "design, which its study refuses at %.80s: %.120s", q, p->message);
		return;
	}
	if (strncmp(q, "/outputs/", 9) == 0 || strncmp(q, "/specs/", 7) == 0) {
		int o = -1;
		if (q[1] == 'o') {
			o = (int)strtol(q + 9, NULL, 10);
		} else {
			const cJSON *outs = cJSON_GetObjectItemCaseSensitive(od->study, "outputs");
			int i = 0;
			const cJSON *it;
			cJSON_ArrayForEach(it, outs) {
				if (cJSON_IsString(it) && strncmp(q + 7, it->valuestring, strlen(it->valuestring)) == 0)
					o = i;
				i++;
			}
		}
		int k = o >= 0 && o < od->robust.n ? o : 0; /* output k is robust constraint k's */
		char base[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(base, sizeof base, "/robust/constraints", k);
		prsm_json_pointer_append(ptr, sizeof ptr, base, q[1] == 'o' ? "output" : "spec");
		prsm_problems_add(pr, ptr, p->code, "%s", p->message);
		return;
	}
	snprintf(ptr, sizeof ptr, "/robust%.*s", (int)(sizeof ptr - 8), q);
	prsm_problems_add(pr, ptr, p->code, "%s", p->message);
}

/* The study document every candidate's study is made from, checked once on the base design
 * (every problem re-pointed under /robust): the robust section without a problem of its own. */
int prsm_io_step_opt_robust_study(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_optimization *od = at->root;
	const opt_reading *c = at->ctx;
	if (!od->has_robust || prsm_problems_total(pr) > c->robust_start || !c->design_ok)
		return 0;
	const cJSON *r = cJSON_GetObjectItemCaseSensitive(at->obj, "robust");
	const cJSON *mc = cJSON_GetObjectItemCaseSensitive(r, "monte_carlo");
	/* the study document of the base design: every candidate's is this one with its geometry */
	cJSON *st = cJSON_CreateObject();
	od->study = st;
	if (!st)
		return 0;
	cJSON_AddItemToObject(st, "design", cJSON_Duplicate(c->design, 1));
	static const char *const copied[] = {"tolerances", "correlations", "assembly", NULL};
	for (int k = 0; copied[k]; k++) {
		const cJSON *it = cJSON_GetObjectItemCaseSensitive(r, copied[k]);
		if (it)
			cJSON_AddItemToObject(st, copied[k], cJSON_Duplicate(it, 1));
	}
	cJSON *outs = cJSON_AddArrayToObject(st, "outputs");
	cJSON *specs = cJSON_AddObjectToObject(st, "specs");
	for (int k = 0; k < od->robust.n; k++) {
		const prsm_robust_constraint *rc = &od->robust.c[k];
		cJSON_AddItemToArray(outs, cJSON_CreateString(rc->output));
		cJSON *so = cJSON_AddObjectToObject(specs, rc->output);
		if (rc->spec.has_lower)
			cJSON_AddNumberToObject(so, "lower", rc->spec.lower);
		if (rc->spec.has_upper)
			cJSON_AddNumberToObject(so, "upper", rc->spec.upper);
	}
	cJSON *smc = mc ? cJSON_Duplicate(mc, 1) : cJSON_CreateObject();
	cJSON_AddItemToObject(st, "monte_carlo", smc);
	if (!cJSON_GetObjectItemCaseSensitive(smc, "samples"))
		cJSON_AddNumberToObject(smc, "samples", ROBUST_DEFAULT_SAMPLES);
	cJSON *sens = cJSON_AddObjectToObject(st, "sensitivity");
	cJSON_AddFalseToObject(sens, "src");
	cJSON_AddFalseToObject(sens, "stack");

	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_problems *sp = malloc(sizeof *sp);
	if (s && sp) {
		prsm_problems_init(sp);
		if (prsm_io_study_load(s, st, c->study, NULL, sp)) {
			for (int i = 0; i < sp->count; i++)
				add_study_problem(pr, od, &sp->items[i]);
			if (sp->count == 0)
				prsm_problems_add(pr, "/robust", "invalid", "the robust study cannot be built");
		} else {
			od->robust.seed = s->study.mc.seed;
			od->robust.samples = s->study.mc.samples;
			snprintf(od->sampler, sizeof od->sampler, "%s", prsm_sampler_name(s->study.mc.sampler));
			od->block_size = s->study.mc.block_size;
			od->threads = s->study.mc.threads;
		}
	} else {
		prsm_problems_add(pr, "/robust", "memory", "out of memory");
	}
	free(sp);
	free(s);
	return 0;
}

/* Replaced radii of the base design as warnings (the optimiser's rules recompute them). */
static void base_warnings(const cJSON *doc, prsm_problems *warnings)
{
	static const char *const derived[] = {"screw_radius_mm", "nut_radius_mm", "roller_arc_radius_mm",
	                                      "screw_crest_radius_mm", "screw_root_radius_mm",
	                                      "roller_crest_radius_mm", "roller_root_radius_mm",
	                                      "nut_crest_radius_mm", "nut_root_radius_mm", NULL};
	const cJSON *g = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "design"), "geometry");
	for (int k = 0; g && derived[k]; k++)
		if (cJSON_GetObjectItemCaseSensitive(g, derived[k]))
			prsm_io_problem(warnings, "/design/geometry", derived[k], "replaced", "the optimiser derives %s from the "
			                "standard rules and the default thread proportions; the given value is not used",
			                derived[k]);
}

int prsm_io_optimization_read(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations,
                              const prsm_io_study_options *study, prsm_problems *warnings, prsm_problems *pr)
{
	memset(od, 0, sizeof *od);
	const int before = prsm_problems_total(pr);
	if (prsm_json_object_value(doc, "", pr))
		return PRSM_EINVAL;
	/* the defaults of the sections the document may leave out */
	od->points = 7;
	prsm_opt_options_init(&od->options);
	od->options.xtol_rel = 1e-4;
	od->options.ftol_rel = 1e-6;
	opt_reading c = {max_evaluations, NULL, 0, 0, study};
	prsm_io_read_ctx(od, &prsm_io_t_optimization, doc, "", &c, pr);
	if (prsm_problems_total(pr) > before)
		return PRSM_EINVAL;
	if (od->has_robust) {
		od->spec.robust = &od->robust;
		od->spec.robust_gate_tol = 0.0; /* studies only for candidates meeting every other limit */
	}
	base_warnings(doc, warnings);
	return 0;
}
