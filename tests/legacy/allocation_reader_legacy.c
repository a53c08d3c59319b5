/*
 * allocation_reader_legacy.c: the hand-written allocation reader before issue 24's port
 * (src/io/allocation_json.c as it was), for the side-by-side proof in tests/test_io_doc.c. Delete
 * it with that test once every document is ported. Only the entry point is renamed:
 * prsm_legacy_allocation_read; the struct is freed by today's prsm_io_allocation_free.
 */
#include "legacy/opt_alloc_reader_legacy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"
#include "mc/stats.h"
#include "opt/alloc_mc.h"
#include "util/utf8.h"

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
                                        "assembly_tolerance", "yield_method", NULL};
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
/* an analytic stack's figures: bounded so that the stack and its squares stay finite */
#define FIGURE_MAX 1e100
static const prsm_json_range FIGURE = {-FIGURE_MAX, FIGURE_MAX, 0, 0};



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

static void read_analytic(prsm_io_allocation *d, const cJSON *a, prsm_problems *pr)
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
		prsm_json_get_number(&d->aout_nominal[i], it, p, "nominal", PRSM_JSON_REQUIRED, FIGURE, pr);
	}
	d->n_aout = (size_t)n;
}

static void read_tolerances(prsm_io_allocation *d, const cJSON *doc, int kind_ok, prsm_problems *pr)
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
					any = 1; /* given (a bad value has its own problem) */
					if (prsm_json_number_value(&v, s, ep, FIGURE, pr))
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

static void read_constraints(prsm_io_allocation *d, const cJSON *doc, int kind_ok, prsm_problems *pr)
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

static void read_mc(prsm_io_allocation *d, const cJSON *doc, size_t max_samples, prsm_problems *pr)
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
		/* a target counts as met when the yield's Wilson lower end reaches it; with no sample
		 * out of spec that end is n / (n + z^2), so fewer samples can never show the target */
		for (size_t o = 0; o < d->model.m; o++) {
			const double p0 = d->target_yield[o];
			if (!(p0 > 0.0 && p0 < 1.0))
				continue;
			const double z2 = PRSM_STATS_Z95 * PRSM_STATS_Z95;
			const double n_min = ceil(z2 * p0 / (1.0 - p0));
			if ((double)d->samples < n_min) {
				char cp[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append_index(cp, sizeof cp, "/constraints", (int)o);
				prsm_problems_add(pr, got == PRSM_JSON_PRESENT ? "/monte_carlo/samples" : "/study/monte_carlo/samples",
				                  "too_few", "%zu samples cannot show the target yield of %s (%.10g %%): even "
				                  "with no sample out of spec the lower end of the 95 %% Wilson interval stays "
				                  "below it unless there are at least %.0f samples (several times that to "
				                  "leave room for the ones that fail)", d->samples, cp, 100.0 * p0, n_min);
				break;
			}
		}
	}
}

int prsm_legacy_allocation_read(prsm_io_allocation **out, const cJSON *doc, size_t max_samples,
                                prsm_problems *warnings, prsm_problems *pr)
{
	*out = NULL;
	prsm_io_allocation *d = calloc(1, sizeof *d);
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
		lrc = prsm_app_study_load(d->study, study, warnings, sp);
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
	if (!d->is_study) { /* the analytic linear model is the document's */
		prsm_alloc_model *md = &d->model;
		for (size_t o = 0; o < md->m; o++) {
			int ao = find_name(d->aout_name, d->n_aout, d->out_name[o]);
			md->nominal[o] = d->aout_nominal[ao];
			for (size_t i = 0; i < md->n; i++)
				md->c[o][i] = d->sens[i][ao];
		}
		for (size_t i = 0; i < md->n; i++)
			md->t_ref[i] = d->ref_given[i];
	}
done:
	if (rc)
		prsm_io_allocation_free(d);
	else
		*out = d;
	return rc;
}
