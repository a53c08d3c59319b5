/*
 * study_mc_legacy.c: the hand-written readers of a study's "monte_carlo" and "sensitivity"
 * sections before the
 * table-driven one (issue 24's side-by-side proof, tests/test_io_doc.c). Delete it with that
 * test once every document is ported.
 */
#include "legacy/design_reader_legacy.h"

#include <math.h>
#include <string.h>

#include "io/json_util.h"

static const char *const mc_keys[] = {"samples", "seed", "sampler", "block_size", "threads",
                                      "min_samples", "time_cap_s", "targets", "failure",
                                      "edge_contact", NULL};
static const char *const sampler_names[] = {"random", "lhs", "sobol", NULL};
static const char *const failure_keys[] = {"policy", "max_failed_fraction", NULL};
static const char *const policy_names[] = {"skip", "abort", NULL};
static const char *const edge_names[] = {"exclude", "include", NULL};
static const char *const sens_keys[] = {"src", "stack", "sobol", NULL};
static const char *const sobol_keys[] = {"samples", "bootstrap", "sampler", NULL};
static const char *const target_keys[] = {"output", "standard_error", "cv", "yield_interval_width", NULL};
static const prsm_json_range POSITIVE = {0.0, HUGE_VAL, 1, 0};

static int output_index(const prsm_io_study *s, const char *name)
{
	for (size_t o = 0; o < s->study.m; o++)
		if (strcmp(s->study.outputs[o].name, name) == 0)
			return (int)o;
	return -1;
}

void prsm_legacy_study_mc_from_json(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	prsm_mc_options *o = &s->study.mc;
	prsm_mc_options_default(o);
	const cJSON *mc = NULL;
	char p[PRSM_JSON_POINTER_MAX] = "/monte_carlo";
	if (prsm_json_get_section(&mc, p, sizeof p, doc, "", "monte_carlo", PRSM_JSON_OPTIONAL, mc_keys, pr) !=
	    PRSM_JSON_PRESENT)
		return;
	int v;
	if (prsm_json_get_int(&v, mc, p, "samples", PRSM_JSON_OPTIONAL, 2, PRSM_MC_MAX_SAMPLES, pr) == PRSM_JSON_PRESENT)
		o->samples = (size_t)v;
	double seed;
	if (prsm_json_get_number(&seed, mc, p, "seed", PRSM_JSON_OPTIONAL,
	                         (prsm_json_range){0.0, 9007199254740992.0, 0, 0}, pr) == PRSM_JSON_PRESENT) {
		if (seed != floor(seed))
			prsm_problems_add(pr, "/monte_carlo/seed", "integer", "seed must be an integer");
		else
			o->seed = (uint64_t)seed;
	}
	if (prsm_json_get_enum(&v, mc, p, "sampler", PRSM_JSON_OPTIONAL, sampler_names, pr) == PRSM_JSON_PRESENT)
		o->sampler = (prsm_sampler_kind)v;
	if (prsm_json_get_int(&v, mc, p, "block_size", PRSM_JSON_OPTIONAL, PRSM_MC_MIN_BLOCK, PRSM_MC_MAX_BLOCK, pr) ==
	    PRSM_JSON_PRESENT)
		o->block_size = (size_t)v;
	if (prsm_json_get_int(&v, mc, p, "threads", PRSM_JSON_OPTIONAL, 1, PRSM_MC_MAX_THREADS, pr) == PRSM_JSON_PRESENT)
		o->threads = v;
	if (prsm_json_get_int(&v, mc, p, "min_samples", PRSM_JSON_OPTIONAL, 0, PRSM_MC_MAX_SAMPLES, pr) ==
	    PRSM_JSON_PRESENT)
		o->min_samples = (size_t)v;
	prsm_json_get_number(&o->time_cap_s, mc, p, "time_cap_s", PRSM_JSON_OPTIONAL,
	                     (prsm_json_range){0.0, 86400.0 * 7, 1, 0}, pr);
	if (prsm_json_get_enum(&v, mc, p, "edge_contact", PRSM_JSON_OPTIONAL, edge_names, pr) == PRSM_JSON_PRESENT)
		o->edge = (prsm_edge_policy)v;
	const cJSON *fail = NULL;
	char fp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&fail, fp, sizeof fp, mc, p, "failure", PRSM_JSON_OPTIONAL, failure_keys, pr) ==
	    PRSM_JSON_PRESENT) {
		if (prsm_json_get_enum(&v, fail, fp, "policy", PRSM_JSON_OPTIONAL, policy_names, pr) == PRSM_JSON_PRESENT)
			o->failure = (prsm_failure_policy)v;
		prsm_json_get_number(&o->max_failed_fraction, fail, fp, "max_failed_fraction", PRSM_JSON_OPTIONAL,
		                     (prsm_json_range){0.0, 1.0, 0, 0}, pr);
	}
	const cJSON *targets = cJSON_GetObjectItemCaseSensitive(mc, "targets");
	if (targets) {
		int n = cJSON_GetArraySize(targets);
		if (!cJSON_IsArray(targets) || n > PRSM_MC_MAX_TARGETS) {
			prsm_problems_add(pr, "/monte_carlo/targets", "bad_array", "targets: an array of at most %d objects",
			                  PRSM_MC_MAX_TARGETS);
			return;
		}
		int i = 0;
		for (const cJSON *it = targets->child; it; it = it->next, i++) {
			char tp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(tp, sizeof tp, "/monte_carlo/targets", i);
			if (prsm_json_object_value(it, tp, pr))
				continue;
			prsm_json_check_keys(it, tp, target_keys, pr);
			const char *name = NULL;
			prsm_mc_target *tg = &o->targets[o->n_targets];
			memset(tg, 0, sizeof *tg);
			if (prsm_json_get_string(&name, it, tp, "output", PRSM_JSON_REQUIRED, 47, pr) != PRSM_JSON_PRESENT)
				continue;
			int oi = output_index(s, name);
			if (oi < 0) {
				char op[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append(op, sizeof op, tp, "output");
				prsm_problems_add(pr, op, "unknown_output", "'%s' is not one of the study's outputs", name);
				continue;
			}
			tg->output = (size_t)oi;
			int kinds = 0;
			static const char *const tk[] = {"standard_error", "cv", "yield_interval_width"};
			for (int k = 0; k < 3; k++)
				if (prsm_json_get_number(&tg->value, it, tp, tk[k], PRSM_JSON_OPTIONAL, POSITIVE, pr) ==
				    PRSM_JSON_PRESENT) {
					tg->kind = (prsm_target_kind)k;
					kinds++;
				}
			if (kinds != 1) {
				prsm_problems_add(pr, tp, "required", "a target has exactly one of standard_error, cv, yield_interval_width");
				continue;
			}
			if (tg->kind == PRSM_TARGET_YIELD_WIDTH) {
				const prsm_study_output *so = &s->study.outputs[oi];
				if (!so->has_spec) {
					prsm_problems_add(pr, tp, "no_spec", "a yield target needs a spec for %s in specs", name);
					continue;
				}
				tg->has_lower = so->spec.has_lower;
				tg->has_upper = so->spec.has_upper;
				tg->lower = so->spec.lower;
				tg->upper = so->spec.upper;
			}
			o->n_targets++;
		}
	}
}

void prsm_legacy_study_sensitivity_from_json(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	prsm_sens_options *o = &s->study.sens;
	prsm_sens_options_default(o);
	const cJSON *sec = NULL;
	char p[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&sec, p, sizeof p, doc, "", "sensitivity", PRSM_JSON_OPTIONAL, sens_keys, pr) !=
	    PRSM_JSON_PRESENT)
		return;
	prsm_json_get_bool(&o->src, sec, p, "src", PRSM_JSON_OPTIONAL, pr);
	prsm_json_get_bool(&o->stack, sec, p, "stack", PRSM_JSON_OPTIONAL, pr);
	const cJSON *sob = cJSON_GetObjectItemCaseSensitive(sec, "sobol");
	if (!sob)
		return;
	if (cJSON_IsBool(sob)) {
		o->sobol = cJSON_IsTrue(sob);
		return;
	}
	char sp[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(sp, sizeof sp, p, "sobol");
	if (!cJSON_IsObject(sob)) {
		prsm_problems_add(pr, sp, "type", "sobol: true, false or an object {samples, bootstrap, sampler}");
		return;
	}
	prsm_json_check_keys(sob, sp, sobol_keys, pr);
	o->sobol = 1;
	int v;
	if (prsm_json_get_int(&v, sob, sp, "samples", PRSM_JSON_OPTIONAL, 16, PRSM_IO_STUDY_SOBOL_MAX_SAMPLES, pr) ==
	    PRSM_JSON_PRESENT)
		o->sobol_samples = (size_t)v;
	if (prsm_json_get_int(&v, sob, sp, "bootstrap", PRSM_JSON_OPTIONAL, 0, PRSM_IO_STUDY_MAX_BOOTSTRAP, pr) ==
	    PRSM_JSON_PRESENT) {
		if (v == 1) {
			char bp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(bp, sizeof bp, sp, "bootstrap");
			prsm_problems_add(pr, bp, "range", "bootstrap: 0 (none) or at least 2 resamples");
		}
		o->bootstrap = (size_t)v;
	}
	if (prsm_json_get_enum(&v, sob, sp, "sampler", PRSM_JSON_OPTIONAL, sampler_names, pr) == PRSM_JSON_PRESENT) {
		if (v == PRSM_SAMPLER_LHS) {
			char bp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(bp, sizeof bp, sp, "sampler");
			prsm_problems_add(pr, bp, "enum", "the Saltelli design takes random or sobol");
		}
		o->sobol_sampler = (prsm_sampler_kind)v;
	}
}
