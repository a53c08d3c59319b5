/*
 * allocation_json.c: the tolerance-allocation document (schemas/allocation.schema.json) read
 * and checked with every problem at once, the allocation run through src/opt/alloc_mc.h, and
 * the result written (schemas/allocation-result.schema.json). See allocation_json.h.
 *
 * Two kinds of document. `study`: an embedded tolerance study (its own reader, problems
 * re-pointed under /study); each allocated tolerance names one of the study's tolerances; the
 * linear model comes from central differences of the study's model; Monte Carlo verifies and
 * corrects. `analytic`: outputs with nominals, tolerances with explicit sensitivities and sd
 * ratios; the linear model is the document itself and there is no Monte Carlo.
 */
#include "io/allocation_json.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/json_util.h"
#include "io/study_json.h"
#include "opt/alloc_mc.h"
#include "util/clock.h"
#include "util/utf8.h"
#include "util/version.h"

#define PRSM_ALLOC_ENGINE "prsm-alloc 2 (KKT: Brent roots on ln of the multipliers, projected Newton on the dual; NLopt 2.7 SLSQP/COBYLA; Monte Carlo correction of the yield targets with common random numbers)"
#define DEFAULT_MAX_CORRECTIONS 8
#define DEFAULT_SCALE_RTOL 0.01

static const char *const root_keys[] = {"name", "study", "analytic", "allocate", "constraints", "stack",
                                        "solver", "monte_carlo", NULL};
static const char *const analytic_keys[] = {"outputs", NULL};
static const char *const aout_keys[] = {"name", "nominal", NULL};
static const char *const tol_keys_study[] = {"parameter", "cost", "bounds", NULL};
static const char *const tol_keys_analytic[] = {"parameter", "cost", "bounds", "sensitivities", "sd_ratio",
                                                "reference_half_width", NULL};
static const char *const cost_keys[] = {"model", "fixed", "coefficient", "power", "rate", NULL};
static const char *const cost_names[] = {"reciprocal", "reciprocal_squared", "reciprocal_power", "exponential", NULL};
static const char *const bounds_keys[] = {"lower", "upper", NULL};
static const char *const cons_keys[] = {"output", "spec", "target_yield_percent", "target_ppm",
                                        "assembly_tolerance", NULL};
static const char *const spec_keys[] = {"lower", "upper", NULL};
static const char *const stack_names[] = {"rss", "worst_case", NULL};
static const char *const solver_names[] = {"exact", "slsqp", "cobyla", NULL};
static const char *const mc_keys[] = {"verify", "samples", "seed", "max_corrections", "scale_tolerance",
                                      "threads", NULL};

static const prsm_json_range ANY = {-HUGE_VAL, HUGE_VAL, 0, 0};
static const prsm_json_range POSITIVE = {0.0, HUGE_VAL, 1, 0};
static const prsm_json_range NONNEG = {0.0, HUGE_VAL, 0, 0};
/* cost figures: bounded so that a cost at any sensible half-width stays finite */
#define COST_MAX 1e100
static const prsm_json_range COST_COEFFICIENT = {0.0, COST_MAX, 1, 0};
static const prsm_json_range COST_FIXED = {0.0, COST_MAX, 0, 0};

/* Everything a loaded document holds. Large: on the heap. */
typedef struct {
	char name[404]; /* up to 100 characters of UTF-8 */
	int is_study;
	prsm_io_study *study;                         /* study kind */
	char tol_name[PRSM_ALLOC_MAX_TOLERANCES][PRSM_STUDY_NAME_MAX];
	char out_name[PRSM_ALLOC_MAX_CONSTRAINTS][48];
	char unit[PRSM_ALLOC_MAX_TOLERANCES][16];     /* the tolerance's unit ("um", "mrad", "") */
	double ref_given[PRSM_ALLOC_MAX_TOLERANCES];  /* analytic: reference half-width or NAN */
	size_t n_aout;                                /* analytic outputs */
	char aout_name[PRSM_ALLOC_MAX_CONSTRAINTS][48];
	double aout_nominal[PRSM_ALLOC_MAX_CONSTRAINTS];
	double sens[PRSM_ALLOC_MAX_TOLERANCES][PRSM_ALLOC_MAX_CONSTRAINTS]; /* analytic, by analytic output */
	int has_spec[PRSM_ALLOC_MAX_CONSTRAINTS];
	double target_yield[PRSM_ALLOC_MAX_CONSTRAINTS]; /* fraction, NAN when the tolerance is given */
	prsm_alloc_model model;
	prsm_alloc_mc_options opt;
	int threads;                                  /* monte_carlo.threads, 0: the study's */
	uint64_t seed;
	size_t samples;
} doc_state;

static void state_free(doc_state *d)
{
	if (d) {
		free(d->study);
		free(d);
	}
}

/* The unit suffix of a parameter name ("screw.runout_um" -> "um"). */
static const char *unit_of(const char *name)
{
	static const char *const units[] = {"um_per_300mm", "um", "mrad", "deg", NULL};
	for (int i = 0; units[i]; i++) {
		size_t ln = strlen(name), lu = strlen(units[i]);
		if (ln > lu + 1 && strcmp(name + ln - lu, units[i]) == 0 && name[ln - lu - 1] == '_')
			return units[i];
	}
	return "";
}

static void read_cost(prsm_alloc_cost *c, const cJSON *o, const char *ptr, prsm_problems *pr)
{
	int kind = 0;
	memset(c, 0, sizeof *c);
	c->power = 1.0;
	if (prsm_json_object_value(o, ptr, pr))
		return;
	prsm_json_check_keys(o, ptr, cost_keys, pr);
	if (prsm_json_get_enum(&kind, o, ptr, "model", PRSM_JSON_REQUIRED, cost_names, pr) != PRSM_JSON_PRESENT)
		return;
	c->kind = (prsm_alloc_cost_kind)kind;
	prsm_json_get_number(&c->fixed, o, ptr, "fixed", PRSM_JSON_OPTIONAL, COST_FIXED, pr);
	prsm_json_get_number(&c->coefficient, o, ptr, "coefficient", PRSM_JSON_REQUIRED, COST_COEFFICIENT, pr);
	char kp[PRSM_JSON_POINTER_MAX];
	if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_POWER) {
		prsm_json_get_number(&c->power, o, ptr, "power", PRSM_JSON_REQUIRED, (prsm_json_range){0.0, 20.0, 1, 0}, pr);
	} else if (cJSON_GetObjectItemCaseSensitive(o, "power")) {
		prsm_json_pointer_append(kp, sizeof kp, ptr, "power");
		prsm_problems_add(pr, kp, "not_allowed", "power belongs to the reciprocal_power model");
	}
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL) {
		prsm_json_get_number(&c->rate, o, ptr, "rate", PRSM_JSON_REQUIRED, POSITIVE, pr);
	} else if (cJSON_GetObjectItemCaseSensitive(o, "rate")) {
		prsm_json_pointer_append(kp, sizeof kp, ptr, "rate");
		prsm_problems_add(pr, kp, "not_allowed", "rate belongs to the exponential model");
	}
	if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_SQUARED)
		c->power = 2.0;
}

static void read_bounds(double *lo, double *hi, const cJSON *tol, const char *ptr, prsm_problems *pr)
{
	const cJSON *b = NULL;
	char bp[PRSM_JSON_POINTER_MAX];
	*lo = 0.0;
	*hi = INFINITY;
	if (prsm_json_get_section(&b, bp, sizeof bp, tol, ptr, "bounds", PRSM_JSON_OPTIONAL, bounds_keys, pr) !=
	    PRSM_JSON_PRESENT)
		return;
	prsm_json_get_number(lo, b, bp, "lower", PRSM_JSON_OPTIONAL, NONNEG, pr);
	prsm_json_get_number(hi, b, bp, "upper", PRSM_JSON_OPTIONAL, POSITIVE, pr);
	if (!(*hi > *lo)) {
		char up[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(up, sizeof up, bp, "upper");
		prsm_problems_add(pr, up, "impossible", "the upper bound %g must exceed the lower bound %g", *hi, *lo);
	}
}

static int find_name(char names[][48], size_t n, const char *name)
{
	for (size_t i = 0; i < n; i++)
		if (strcmp(names[i], name) == 0)
			return (int)i;
	return -1;
}

static void read_analytic(doc_state *d, const cJSON *a, prsm_problems *pr)
{
	if (prsm_json_object_value(a, "/analytic", pr))
		return;
	prsm_json_check_keys(a, "/analytic", analytic_keys, pr);
	const cJSON *outs = cJSON_GetObjectItemCaseSensitive(a, "outputs");
	int n = cJSON_GetArraySize(outs);
	if (!cJSON_IsArray(outs) || n < 1 || n > PRSM_ALLOC_MAX_CONSTRAINTS) {
		prsm_problems_add(pr, "/analytic/outputs", outs ? "bad_array" : "required",
		                  "outputs: an array of 1 to %d outputs", PRSM_ALLOC_MAX_CONSTRAINTS);
		return;
	}
	int i = 0;
	for (const cJSON *it = outs->child; it; it = it->next, i++) {
		char p[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(p, sizeof p, "/analytic/outputs", i);
		if (prsm_json_object_value(it, p, pr))
			continue;
		prsm_json_check_keys(it, p, aout_keys, pr);
		const char *name = NULL;
		if (prsm_json_get_string(&name, it, p, "name", PRSM_JSON_REQUIRED, 40, pr) == PRSM_JSON_PRESENT) {
			if (find_name(d->aout_name, (size_t)i, name) >= 0) {
				char np[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append(np, sizeof np, p, "name");
				prsm_problems_add(pr, np, "duplicate", "output %s is named twice", name);
			}
			snprintf(d->aout_name[i], sizeof d->aout_name[i], "%s", name);
		}
		prsm_json_get_number(&d->aout_nominal[i], it, p, "nominal", PRSM_JSON_REQUIRED, ANY, pr);
	}
	d->n_aout = (size_t)n;
}

static void read_tolerances(doc_state *d, const cJSON *doc, int kind_ok, prsm_problems *pr)
{
	const cJSON *tols = cJSON_GetObjectItemCaseSensitive(doc, "allocate");
	int n = cJSON_GetArraySize(tols);
	if (!cJSON_IsArray(tols) || n < 1 || n > PRSM_IO_ALLOC_MAX_TOLERANCES) {
		prsm_problems_add(pr, "/allocate", tols ? "bad_array" : "required",
		                  "allocate: an array of 1 to %d tolerances to allocate", PRSM_IO_ALLOC_MAX_TOLERANCES);
		return;
	}
	prsm_alloc_model *md = &d->model;
	int i = 0;
	for (const cJSON *it = tols->child; it; it = it->next, i++) {
		char p[PRSM_JSON_POINTER_MAX], pp[PRSM_JSON_POINTER_MAX], cp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(p, sizeof p, "/allocate", i);
		d->ref_given[i] = NAN;
		if (prsm_json_object_value(it, p, pr))
			continue;
		prsm_json_check_keys(it, p, d->is_study ? tol_keys_study : tol_keys_analytic, pr);
		prsm_json_pointer_append(pp, sizeof pp, p, "parameter");
		const char *name = NULL;
		if (prsm_json_get_string(&name, it, p, "parameter", PRSM_JSON_REQUIRED, PRSM_STUDY_NAME_MAX - 1, pr) ==
		    PRSM_JSON_PRESENT) {
			snprintf(d->tol_name[i], sizeof d->tol_name[i], "%s", name);
			for (int k = 0; k < i; k++)
				if (strcmp(d->tol_name[k], name) == 0)
					prsm_problems_add(pr, pp, "duplicate", "%s is allocated twice (at /allocate/%d)", name, k);
			snprintf(d->unit[i], sizeof d->unit[i], "%s", d->is_study ? unit_of(name) : "");
			if (d->is_study && kind_ok) {
				const prsm_io_study *s = d->study;
				int g = -1;
				for (size_t k = 0; k < s->n_tolerances; k++)
					if (strcmp(s->tolerances[k].parameter, name) == 0)
						g = (int)k;
				if (g < 0) {
					prsm_problems_add(pr, pp, "unknown_tolerance", "%s is not a tolerance of the study", name);
				} else {
					d->opt.group[i] = (size_t)g;
					if (s->tolerances[g].dist.kind == PRSM_DIST_LOGNORMAL)
						prsm_problems_add(pr, pp, "not_scalable", "%s has a lognormal distribution, whose "
						                  "half-width does not scale with one parameter: give it a normal, "
						                  "truncnormal, uniform, triangular or rayleigh distribution", name);
				}
			}
		}
		prsm_json_pointer_append(cp, sizeof cp, p, "cost");
		const cJSON *cost = cJSON_GetObjectItemCaseSensitive(it, "cost");
		if (!cost)
			prsm_problems_add(pr, cp, "required", "cost is required: {\"model\": ..., \"coefficient\": ...}");
		else
			read_cost(&md->cost[i], cost, cp, pr);
		read_bounds(&md->t_min[i], &md->t_max[i], it, p, pr);
		if (!d->is_study) {
			md->k[i] = 3.0;
			prsm_json_get_number(&md->k[i], it, p, "sd_ratio", PRSM_JSON_OPTIONAL,
			                     (prsm_json_range){0.0, 100.0, 1, 0}, pr);
			prsm_json_get_number(&d->ref_given[i], it, p, "reference_half_width", PRSM_JSON_OPTIONAL, POSITIVE, pr);
			const cJSON *sens = NULL;
			char sp[PRSM_JSON_POINTER_MAX];
			if (prsm_json_get_section(&sens, sp, sizeof sp, it, p, "sensitivities", PRSM_JSON_REQUIRED, NULL, pr) ==
			    PRSM_JSON_PRESENT) {
				int any = 0;
				for (const cJSON *s = sens->child; s; s = s->next) {
					char ep[PRSM_JSON_POINTER_MAX];
					prsm_json_pointer_append(ep, sizeof ep, sp, s->string);
					int o = find_name(d->aout_name, d->n_aout, s->string);
					double v;
					if (prsm_json_number_value(&v, s, ep, ANY, pr))
						continue;
					if (o < 0)
						prsm_problems_add(pr, ep, "unknown_output", "%s is not an output of /analytic/outputs",
						                  s->string);
					else
						d->sens[i][o] = v;
					any = 1;
				}
				if (!any)
					prsm_problems_add(pr, sp, "required", "give the tolerance's sensitivity to at least one output");
			}
		}
	}
	md->n = (size_t)n;
}

static void read_constraints(doc_state *d, const cJSON *doc, int kind_ok, prsm_problems *pr)
{
	const cJSON *cons = cJSON_GetObjectItemCaseSensitive(doc, "constraints");
	int n = cJSON_GetArraySize(cons);
	prsm_alloc_model *md = &d->model;
	if (!cJSON_IsArray(cons) || n < 1 || n > PRSM_IO_ALLOC_MAX_CONSTRAINTS) {
		prsm_problems_add(pr, "/constraints", cons ? "bad_array" : "required",
		                  "constraints: an array of 1 to %d outputs with a target", PRSM_IO_ALLOC_MAX_CONSTRAINTS);
		return;
	}
	int i = 0;
	for (const cJSON *it = cons->child; it; it = it->next, i++) {
		char p[PRSM_JSON_POINTER_MAX], op[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(p, sizeof p, "/constraints", i);
		d->target_yield[i] = NAN;
		if (prsm_json_object_value(it, p, pr))
			continue;
		prsm_json_check_keys(it, p, cons_keys, pr);
		prsm_json_pointer_append(op, sizeof op, p, "output");
		const char *name = NULL;
		int have_default_spec = 0;
		prsm_spec spec = {0, 0, 0.0, 0.0};
		if (prsm_json_get_string(&name, it, p, "output", PRSM_JSON_REQUIRED, 40, pr) == PRSM_JSON_PRESENT) {
			snprintf(d->out_name[i], sizeof d->out_name[i], "%s", name);
			if (find_name(d->out_name, (size_t)i, name) >= 0)
				prsm_problems_add(pr, op, "duplicate", "%s is constrained twice", name);
			if (d->is_study && kind_ok) {
				const prsm_study *st = &d->study->study;
				int o = -1;
				for (size_t k = 0; k < st->m; k++)
					if (strcmp(st->outputs[k].name, name) == 0)
						o = (int)k;
				if (o < 0) {
					prsm_problems_add(pr, op, "unknown_output", "%s is not among the study's outputs", name);
				} else {
					d->opt.output[i] = (size_t)o;
					have_default_spec = st->outputs[o].has_spec;
					spec = st->outputs[o].spec;
				}
			} else if (!d->is_study && find_name(d->aout_name, d->n_aout, name) < 0) {
				prsm_problems_add(pr, op, "unknown_output", "%s is not an output of /analytic/outputs", name);
			}
		}
		const cJSON *sp = NULL;
		char spp[PRSM_JSON_POINTER_MAX];
		if (prsm_json_get_section(&sp, spp, sizeof spp, it, p, "spec", PRSM_JSON_OPTIONAL, spec_keys, pr) ==
		    PRSM_JSON_PRESENT) {
			spec = (prsm_spec){0, 0, 0.0, 0.0};
			spec.has_lower = prsm_json_get_number(&spec.lower, sp, spp, "lower", PRSM_JSON_OPTIONAL, ANY, pr) ==
			                 PRSM_JSON_PRESENT;
			spec.has_upper = prsm_json_get_number(&spec.upper, sp, spp, "upper", PRSM_JSON_OPTIONAL, ANY, pr) ==
			                 PRSM_JSON_PRESENT;
			if (!spec.has_lower && !spec.has_upper)
				prsm_problems_add(pr, spp, "required", "a spec has a lower limit, an upper limit or both");
			if (spec.has_lower && spec.has_upper && !(spec.lower < spec.upper)) {
				char up[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append(up, sizeof up, spp, "upper");
				prsm_problems_add(pr, up, "impossible", "the upper limit must exceed the lower limit");
			}
			have_default_spec = 1;
		}
		md->spec[i] = spec;
		d->has_spec[i] = have_default_spec;
		int given = 0;
		double v;
		if (prsm_json_get_number(&v, it, p, "target_yield_percent", PRSM_JSON_OPTIONAL,
		                         (prsm_json_range){50.0, 100.0, 1, 1}, pr) == PRSM_JSON_PRESENT) {
			given++;
			md->has_target[i] = 1;
			md->out_fraction[i] = (100.0 - v) / 100.0;
			d->target_yield[i] = v / 100.0;
		}
		if (prsm_json_get_number(&v, it, p, "target_ppm", PRSM_JSON_OPTIONAL,
		                         (prsm_json_range){0.0, 500000.0, 1, 1}, pr) == PRSM_JSON_PRESENT) {
			given++;
			md->has_target[i] = 1;
			md->out_fraction[i] = v * 1e-6;
			d->target_yield[i] = 1.0 - v * 1e-6;
		}
		if (prsm_json_get_number(&v, it, p, "assembly_tolerance", PRSM_JSON_OPTIONAL, POSITIVE, pr) ==
		    PRSM_JSON_PRESENT) {
			given++;
			md->has_target[i] = 0;
			md->assembly_tol[i] = v;
		}
		if (given != 1)
			prsm_problems_add(pr, p, given ? "conflict" : "required",
			                  "give exactly one of target_yield_percent, target_ppm, assembly_tolerance");
		if (md->has_target[i] && given == 1 && !have_default_spec && (!d->is_study || kind_ok))
			prsm_problems_add(pr, p, "required", "a target yield needs a spec: give one here or in the study");
	}
	md->m = (size_t)n;
}

static void read_mc(doc_state *d, const cJSON *doc, size_t max_samples, prsm_problems *pr)
{
	const cJSON *mc = NULL;
	char mp[PRSM_JSON_POINTER_MAX];
	int got = prsm_json_get_section(&mc, mp, sizeof mp, doc, "", "monte_carlo", PRSM_JSON_OPTIONAL, mc_keys, pr);
	d->opt.verify = d->is_study;
	d->opt.max_corrections = DEFAULT_MAX_CORRECTIONS;
	d->opt.scale_rtol = DEFAULT_SCALE_RTOL;
	if (d->study) {
		d->samples = d->study->study.mc.samples;
		d->seed = d->study->study.mc.seed;
	}
	if (got == PRSM_JSON_PRESENT) {
		if (!d->is_study) {
			prsm_problems_add(pr, "/monte_carlo", "not_allowed",
			                  "an analytic allocation has no Monte Carlo: its linear model is the document");
			return;
		}
		prsm_json_get_bool(&d->opt.verify, mc, mp, "verify", PRSM_JSON_OPTIONAL, pr);
		int samples = 0, seed = 0, threads = 0;
		if (prsm_json_get_int(&samples, mc, mp, "samples", PRSM_JSON_OPTIONAL, 64, PRSM_MC_MAX_SAMPLES, pr) ==
		    PRSM_JSON_PRESENT)
			d->samples = (size_t)samples;
		if (prsm_json_get_int(&seed, mc, mp, "seed", PRSM_JSON_OPTIONAL, 0, 2147483647, pr) == PRSM_JSON_PRESENT)
			d->seed = (uint64_t)seed;
		prsm_json_get_int(&d->opt.max_corrections, mc, mp, "max_corrections", PRSM_JSON_OPTIONAL, 0,
		                  PRSM_IO_ALLOC_MAX_CORRECTIONS, pr);
		prsm_json_get_number(&d->opt.scale_rtol, mc, mp, "scale_tolerance", PRSM_JSON_OPTIONAL,
		                     (prsm_json_range){1e-4, 0.5, 0, 0}, pr);
		if (prsm_json_get_int(&threads, mc, mp, "threads", PRSM_JSON_OPTIONAL, 1, PRSM_MC_MAX_THREADS, pr) ==
		    PRSM_JSON_PRESENT)
			d->threads = threads;
	}
	if (d->is_study && d->opt.verify && d->samples > 0) {
		double total = (double)d->samples * (double)(d->opt.max_corrections + 1);
		size_t cap = max_samples ? max_samples : PRSM_IO_ALLOC_MAX_SAMPLES;
		if (total > (double)cap)
			prsm_problems_add(pr, got == PRSM_JSON_PRESENT ? "/monte_carlo/samples" : "/study/monte_carlo/samples",
			                  "too_large", "%zu samples x (1 + %d corrections) = %.0f Monte Carlo samples: at most "
			                  "%zu", d->samples, d->opt.max_corrections, total, cap);
	}
}

/* Read and check everything; for a study also load it and linearise; for both, the linear
 * allocation at f = 1 must be possible. *out owned by the caller (state_free). */
static int load(doc_state **out, const cJSON *doc, size_t max_samples, prsm_problems *warnings,
                prsm_problems *pr)
{
	*out = NULL;
	doc_state *d = calloc(1, sizeof *d);
	if (!d)
		return PRSM_ENOMEM;
	const int start = prsm_problems_total(pr);
	int rc = 0, kind_ok = 0;
	if (prsm_json_object_value(doc, "", pr)) {
		rc = PRSM_EINVAL;
		goto done;
	}
	prsm_json_check_keys(doc, "", root_keys, pr);
	const char *name = NULL;
	if (prsm_json_get_string(&name, doc, "", "name", PRSM_JSON_OPTIONAL, 100, pr) == PRSM_JSON_PRESENT)
		prsm_utf8_copy(d->name, sizeof d->name, name);
	const cJSON *study = cJSON_GetObjectItemCaseSensitive(doc, "study");
	const cJSON *analytic = cJSON_GetObjectItemCaseSensitive(doc, "analytic");
	int lrc = 0;
	if (study && analytic) {
		prsm_problems_add(pr, "/analytic", "conflict", "an allocation has a study or an analytic stack, not both");
	} else if (study) {
		d->is_study = 1;
		d->study = calloc(1, sizeof *d->study);
		prsm_problems *sp = calloc(1, sizeof *sp);
		if (!d->study || !sp) {
			free(sp);
			rc = PRSM_ENOMEM;
			goto done;
		}
		prsm_problems_init(sp);
		lrc = prsm_io_study_load(d->study, study, warnings, sp);
		prsm_json_problems_append_prefixed(pr, sp, "/study");
		free(sp);
		kind_ok = lrc == 0;
	} else if (analytic) {
		read_analytic(d, analytic, pr);
		kind_ok = prsm_problems_total(pr) == start;
	} else {
		prsm_problems_add(pr, "/study", "required", "an allocation needs a study (or an analytic stack)");
	}
	read_tolerances(d, doc, kind_ok, pr);
	read_constraints(d, doc, kind_ok, pr);
	int v = 0;
	if (prsm_json_get_enum(&v, doc, "", "stack", PRSM_JSON_OPTIONAL, stack_names, pr) == PRSM_JSON_PRESENT)
		d->model.stack = (prsm_alloc_stack)v;
	v = 0;
	if (prsm_json_get_enum(&v, doc, "", "solver", PRSM_JSON_OPTIONAL, solver_names, pr) == PRSM_JSON_PRESENT)
		d->model.solver = (prsm_alloc_solver)v;
	read_mc(d, doc, max_samples, pr);
	if (prsm_problems_total(pr) != start) {
		rc = lrc && lrc != PRSM_EINVAL ? lrc : PRSM_EINVAL;
		goto done;
	}

	/* the linear model */
	prsm_alloc_model *md = &d->model;
	prsm_error err = PRSM_ERROR_INIT;
	if (d->is_study) {
		prsm_study *st = &d->study->study;
		st->mc.samples = d->samples;
		st->mc.seed = d->seed;
		if (d->threads)
			st->mc.threads = d->threads;
		rc = prsm_alloc_mc_linearise(md, st, &d->opt, &err);
		if (rc) {
			prsm_problems_add(pr, "/study", "model", "%s", err.message);
			rc = rc == PRSM_ENOMEM ? rc : PRSM_EINVAL;
			goto done;
		}
	} else {
		for (size_t o = 0; o < md->m; o++) {
			int ao = find_name(d->aout_name, d->n_aout, d->out_name[o]);
			md->nominal[o] = d->aout_nominal[ao];
			for (size_t i = 0; i < md->n; i++)
				md->c[o][i] = d->sens[i][ao];
		}
		for (size_t i = 0; i < md->n; i++)
			md->t_ref[i] = d->ref_given[i];
	}
	prsm_alloc_step *st0 = malloc(sizeof *st0);
	if (!st0) {
		rc = PRSM_ENOMEM;
		goto done;
	}
	rc = prsm_alloc_model_allocate(st0, md, 1.0, NULL, 0.0, &err);
	free(st0);
	if (rc) {
		prsm_problems_add(pr, err.pointer[0] ? err.pointer : "/constraints", "infeasible", "%s", err.message);
		rc = rc == PRSM_ENOMEM ? rc : PRSM_EINVAL;
	}
done:
	if (rc)
		state_free(d);
	else
		*out = d;
	return rc;
}

int prsm_io_allocation_check(const cJSON *doc, size_t max_samples, prsm_problems *warnings,
                             prsm_problems *problems)
{
	doc_state *d;
	int rc = load(&d, doc, max_samples, warnings, problems);
	state_free(d);
	return rc;
}

/* ---- result ------------------------------------------------------------------------------ */

static cJSON *pair(double a, double b)
{
	cJSON *arr = cJSON_CreateArray();
	cJSON *x = isfinite(a) ? cJSON_CreateNumber(a) : cJSON_CreateNull();
	cJSON *y = isfinite(b) ? cJSON_CreateNumber(b) : cJSON_CreateNull();
	cJSON_AddItemToArray(arr, x);
	cJSON_AddItemToArray(arr, y);
	return arr;
}

static cJSON *cost_json(const prsm_alloc_cost *c)
{
	cJSON *j = cJSON_CreateObject();
	cJSON_AddStringToObject(j, "model", prsm_alloc_cost_name(c->kind));
	cJSON_AddNumberToObject(j, "fixed", c->fixed);
	cJSON_AddNumberToObject(j, "coefficient", c->coefficient);
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		cJSON_AddNumberToObject(j, "rate", c->rate);
	else if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_POWER)
		cJSON_AddNumberToObject(j, "power", c->power);
	return j;
}

static cJSON *spec_json(const prsm_spec *s)
{
	cJSON *j = cJSON_CreateObject();
	if (s->has_lower)
		prsm_json_add_number(j, "lower", s->lower);
	if (s->has_upper)
		prsm_json_add_number(j, "upper", s->upper);
	return j;
}

static cJSON *half_widths_json(const doc_state *d, const prsm_alloc_step *st)
{
	cJSON *a = cJSON_CreateArray();
	for (size_t i = 0; i < d->model.n; i++)
		cJSON_AddItemToArray(a, cJSON_CreateNumber(st->sol.t[i]));
	return a;
}

static cJSON *mc_yield_json(const doc_state *d, const prsm_alloc_step *st, size_t o)
{
	if (!st->has_mc || !d->has_spec[o])
		return cJSON_CreateNull();
	cJSON *j = cJSON_CreateObject();
	prsm_json_add_number(j, "fraction", st->mc_yield[o]);
	cJSON_AddItemToObject(j, "interval95", pair(st->mc_low95[o], st->mc_high95[o]));
	cJSON_AddStringToObject(j, "interval_method", "Wilson score, 95 %");
	cJSON_AddNumberToObject(j, "samples", (double)st->samples);
	prsm_json_add_number(j, "mean", st->mc_mean[o]);
	prsm_json_add_number(j, "sd", st->mc_sd[o]);
	return j;
}

static cJSON *result_json(const doc_state *d, const prsm_alloc_mc_result *r, int cancelled)
{
	const prsm_alloc_model *md = &d->model;
	assert(r->best >= 0 && r->best < r->n_steps);
	const prsm_alloc_step *best = &r->steps[r->best];
	cJSON *doc = cJSON_CreateObject();
	if (!doc)
		return NULL;
	if (d->name[0])
		cJSON_AddStringToObject(doc, "name", d->name);
	cJSON_AddStringToObject(doc, "kind", d->is_study ? "study" : "analytic");
	cJSON *ver = cJSON_AddObjectToObject(doc, "versions");
	cJSON_AddStringToObject(ver, "prsm", PRSM_VERSION);
	cJSON_AddStringToObject(ver, "engine", PRSM_ALLOC_ENGINE);
	cJSON_AddStringToObject(ver, "build", prsm_engine_build());
	cJSON_AddStringToObject(doc, "stack", prsm_alloc_stack_name(md->stack));
	cJSON_AddStringToObject(doc, "solver", prsm_alloc_solver_name(best->sol.solver));
	cJSON_AddStringToObject(doc, "convention",
	                        "a tolerance +-T is +-k sd of its distribution (k = 3 for a normal and the "
	                        "{tol, cpk 1} shorthand, sqrt 3 for a uniform; sd_ratio in an analytic document); "
	                        "RSS: sum (3 c T / k)^2 <= T_asm^2, T_asm = 3 sigma_max, sigma_max the largest sd "
	                        "of a normal output centred on the nominal whose yield is the target; worst case: "
	                        "sum |c| T <= T_asm = min(U - nominal, nominal - L)");
	cJSON_AddStringToObject(doc, "sensitivity_source",
	                        d->is_study ? "central differences of the study's model over each variable's reference "
	                                      "half-width (a radial magnitude at its worst of 8 directions), the "
	                                      "tolerance's variables combined in quadrature (RSS) or summed (worst case)"
	                                    : "given in the document");
	cJSON *tols = cJSON_AddArrayToObject(doc, "tolerances");
	for (size_t i = 0; i < md->n; i++) {
		cJSON *t = cJSON_CreateObject();
		cJSON_AddStringToObject(t, "parameter", d->tol_name[i]);
		cJSON_AddStringToObject(t, "unit", d->unit[i]);
		prsm_json_add_number(t, "half_width", best->sol.t[i]);
		prsm_json_add_number(t, "reference_half_width", md->t_ref[i]);
		prsm_json_add_number(t, "sd_ratio", md->k[i]);
		prsm_json_add_number(t, "cost", best->sol.cost[i]);
		cJSON_AddItemToObject(t, "cost_model", cost_json(&md->cost[i]));
		cJSON *b = cJSON_AddObjectToObject(t, "bounds");
		prsm_json_add_number(b, "lower", md->t_min[i]);
		prsm_json_add_number(b, "upper", md->t_max[i]);
		if (best->sol.at_bound[i])
			cJSON_AddStringToObject(t, "at_bound", best->sol.at_bound[i] < 0 ? "lower" : "upper");
		else
			cJSON_AddNullToObject(t, "at_bound");
		cJSON *sens = cJSON_AddObjectToObject(t, "sensitivities");
		for (size_t o = 0; o < md->m; o++)
			prsm_json_add_number(sens, d->out_name[o], md->c[o][i]);
		cJSON_AddItemToArray(tols, t);
	}
	prsm_json_add_number(doc, "total_cost", best->sol.total_cost);
	cJSON *cons = cJSON_AddArrayToObject(doc, "constraints");
	for (size_t o = 0; o < md->m; o++) {
		cJSON *c = cJSON_CreateObject();
		cJSON_AddStringToObject(c, "output", d->out_name[o]);
		if (d->has_spec[o])
			cJSON_AddItemToObject(c, "spec", spec_json(&md->spec[o]));
		else
			cJSON_AddNullToObject(c, "spec");
		prsm_json_add_number(c, "nominal", md->nominal[o]);
		prsm_json_add_number(c, "target_yield", d->target_yield[o]);
		prsm_json_add_number(c, "assembly_tolerance", best->assembly_tol[o]);
		prsm_json_add_number(c, "assembly_tolerance_linear", r->steps[0].assembly_tol[o]);
		prsm_json_add_number(c, "sigma_max", best->sigma_max[o]);
		prsm_json_add_number(c, "multiplier", best->sol.multiplier[o]);
		prsm_json_add_number(c, "stack", best->sol.stack[o]);
		prsm_json_add_number(c, "kept_tolerances_sd", sqrt(md->fixed_var[o]));
		prsm_json_add_number(c, "kept_tolerances_worst_case", md->fixed_wc[o]);
		prsm_json_add_number(c, "predicted_sd", best->predicted_sd[o]);
		prsm_json_add_number(c, "predicted_yield", d->has_spec[o] ? best->predicted_yield[o] : NAN);
		cJSON_AddItemToObject(c, "monte_carlo", mc_yield_json(d, best, o));
		if (md->has_target[o])
			cJSON_AddBoolToObject(c, "meets_target", best->has_mc ? best->mc_yield[o] >= d->target_yield[o]
			                                                      : best->predicted_yield[o] >= d->target_yield[o] - 1e-12);
		else /* a given assembly tolerance: the linear stack within it */
			cJSON_AddBoolToObject(c, "meets_target", best->sol.stack[o] <= best->limit[o] * (1.0 + 1e-9));
		cJSON_AddItemToArray(cons, c);
	}
	cJSON *lin = cJSON_AddObjectToObject(doc, "linear");
	prsm_json_add_number(lin, "total_cost", r->steps[0].sol.total_cost);
	cJSON_AddItemToObject(lin, "half_widths", half_widths_json(d, &r->steps[0]));
	cJSON *py = cJSON_AddArrayToObject(lin, "predicted_yields");
	for (size_t o = 0; o < md->m; o++)
		cJSON_AddItemToArray(py, d->has_spec[o] ? cJSON_CreateNumber(r->steps[0].predicted_yield[o]) : cJSON_CreateNull());
	cJSON *cor = cJSON_AddObjectToObject(doc, "correction");
	prsm_json_add_number(cor, "scale", best->scale);
	cJSON_AddStringToObject(cor, "stop_reason", prsm_alloc_stop_name(r->stop));
	cJSON_AddBoolToObject(cor, "converged", r->converged);
	cJSON_AddNumberToObject(cor, "max_corrections", d->is_study && d->opt.verify ? d->opt.max_corrections : 0);
	cJSON_AddNumberToObject(cor, "scale_tolerance", d->opt.scale_rtol);
	cJSON *steps = cJSON_AddArrayToObject(cor, "steps");
	for (int k = 0; k < r->n_steps; k++) {
		const prsm_alloc_step *st = &r->steps[k];
		cJSON *s = cJSON_CreateObject();
		prsm_json_add_number(s, "scale", st->scale);
		prsm_json_add_number(s, "total_cost", st->sol.total_cost);
		cJSON_AddItemToObject(s, "half_widths", half_widths_json(d, st));
		cJSON *ys = cJSON_AddArrayToObject(s, "yields");
		for (size_t o = 0; o < md->m; o++)
			cJSON_AddItemToArray(ys, mc_yield_json(d, st, o));
		cJSON_AddBoolToObject(s, "meets_target", st->meets);
		cJSON_AddBoolToObject(s, "reported", k == r->best);
		cJSON_AddItemToArray(steps, s);
	}
	if (d->is_study) {
		cJSON *mc = cJSON_AddObjectToObject(doc, "monte_carlo");
		cJSON_AddBoolToObject(mc, "verify", d->opt.verify);
		cJSON_AddNumberToObject(mc, "samples", (double)d->samples);
		cJSON_AddNumberToObject(mc, "seed", (double)d->seed);
		cJSON_AddStringToObject(mc, "sampler", prsm_sampler_name(d->study->study.mc.sampler));
		cJSON_AddNumberToObject(mc, "samples_total", (double)r->samples_total);
		cJSON_AddNumberToObject(mc, "threads", d->study->study.mc.threads);
		cJSON_AddStringToObject(mc, "common_random_numbers",
		                        "every run uses the same seed and sample count, so the yield is a "
		                        "deterministic function of the widths");
	} else {
		cJSON_AddNullToObject(doc, "monte_carlo");
	}
	size_t evals = 0;
	for (int k = 0; k < r->n_steps; k++)
		evals += r->steps[k].sol.evaluations;
	cJSON_AddNumberToObject(doc, "evaluations", (double)evals);
	cJSON_AddBoolToObject(doc, "cancelled", cancelled);
	prsm_json_add_number(doc, "elapsed_s", r->elapsed_s);
	return doc;
}

int prsm_io_allocation_execute(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                               prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                               int threads, prsm_problems *problems, prsm_error *err)
{
	*result = NULL;
	doc_state *d;
	int rc = load(&d, doc, 0, NULL, problems);
	if (rc)
		return prsm_error_set(err, rc, problems->count ? problems->items[0].pointer : NULL, "%s",
		                      rc == PRSM_EINVAL ? "the allocation document is invalid" : "could not load the allocation");
	prsm_alloc_mc_result *r = calloc(1, sizeof *r);
	if (!r) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	d->opt.cancel = cancel;
	d->opt.progress = progress;
	d->opt.progress_ctx = progress_ctx;
	d->opt.max_time_s = max_time_s;
	if (d->is_study) {
		if (threads > 0)
			d->study->study.mc.threads = threads;
		rc = prsm_alloc_mc_run(r, &d->study->study, &d->model, &d->opt, err);
		if (rc && !(rc == PRSM_ECANCELLED && r->best >= 0))
			goto cleanup;
		if (r->best < 0) { /* prsm_alloc_mc_run promises a step; never read steps[-1] */
			rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "no allocation step finished");
			goto cleanup;
		}
	} else {
		double t0 = prsm_clock_seconds();
		if (prsm_cancel_requested(cancel)) {
			rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
			goto cleanup;
		}
		rc = prsm_alloc_model_allocate(&r->steps[0], &d->model, 1.0, cancel, max_time_s, err);
		if (rc)
			goto cleanup;
		r->n_steps = 1;
		r->best = 0;
		r->stop = PRSM_ALLOC_STOP_LINEAR;
		r->converged = r->steps[0].meets;
		r->elapsed_s = prsm_clock_seconds() - t0;
		if (progress) {
			prsm_progress p = PRSM_PROGRESS_INIT;
			p.done = p.planned = r->steps[0].sol.evaluations;
			p.best = r->steps[0].sol.total_cost;
			progress(progress_ctx, &p);
		}
	}
	*result = result_json(d, r, rc == PRSM_ECANCELLED);
	if (!*result)
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
cleanup:
	free(r);
	state_free(d);
	return rc;
}
