/*
 * allocation_result.c: the allocation result (schemas/allocation-result.schema.json) of a run
 * (src/app/allocate.c); see allocation_json.h.
 */
#include "io/allocation_json.h"

#include <assert.h>
#include <math.h>

#include "io/write.h"
#include "util/version.h"

#define PRSM_ALLOC_ENGINE "prsm-alloc 2 (KKT: Brent roots on ln of the multipliers, projected Newton on the dual; NLopt 2.7 SLSQP/COBYLA; Monte Carlo correction of the yield targets with common random numbers)"

static void pair(prsm_jw *w, cJSON *parent, const char *key, double a, double b)
{
	cJSON *arr = prsm_jw_array(w, parent, key);
	prsm_jw_number(w, arr, NULL, a);
	prsm_jw_number(w, arr, NULL, b);
}

static void cost_json(prsm_jw *w, cJSON *j, const prsm_alloc_cost *c)
{
	prsm_jw_string(w, j, "model", prsm_alloc_cost_name(c->kind));
	prsm_jw_number(w, j, "fixed", c->fixed);
	prsm_jw_number(w, j, "coefficient", c->coefficient);
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		prsm_jw_number(w, j, "rate", c->rate);
	else if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_POWER)
		prsm_jw_number(w, j, "power", c->power);
}

static void spec_json(prsm_jw *w, cJSON *j, const prsm_spec *s)
{
	if (s->has_lower)
		prsm_jw_number(w, j, "lower", s->lower);
	if (s->has_upper)
		prsm_jw_number(w, j, "upper", s->upper);
}

static void half_widths_json(prsm_jw *w, cJSON *a, const prsm_io_allocation *d, const prsm_alloc_step *st)
{
	for (size_t i = 0; i < d->model.n; i++)
		prsm_jw_number(w, a, NULL, st->sol.t[i]);
}

static void mc_yield_json(prsm_jw *w, cJSON *parent, const char *key, const prsm_io_allocation *d,
                          const prsm_alloc_step *st, size_t o)
{
	if (!st->has_mc || !d->has_spec[o]) {
		prsm_jw_null(w, parent, key);
		return;
	}
	cJSON *j = prsm_jw_object(w, parent, key);
	prsm_jw_number(w, j, "fraction", st->mc_yield[o]);
	pair(w, j, "interval95", st->mc_low95[o], st->mc_high95[o]);
	prsm_jw_string(w, j, "interval_method", "Wilson score, 95 %");
	prsm_jw_number(w, j, "samples", (double)st->samples);
	prsm_jw_number(w, j, "mean", st->mc_mean[o]);
	prsm_jw_number(w, j, "sd", st->mc_sd[o]);
	prsm_jw_number(w, j, "confidence_meets_target", st->mc_confidence[o]);
}

cJSON *prsm_io_allocation_result_json(const prsm_io_allocation *d, const prsm_alloc_mc_result *r,
                                      int cancelled)
{
	const prsm_alloc_model *md = &d->model;
	assert(r->best >= 0 && r->best < r->n_steps);
	const prsm_alloc_step *best = &r->steps[r->best];
	prsm_jw jw = PRSM_JW_INIT, *w = &jw;
	cJSON *doc = prsm_jw_root(w);
	if (d->name[0])
		prsm_jw_string(w, doc, "name", d->name);
	prsm_jw_string(w, doc, "kind", d->is_study ? "study" : "analytic");
	cJSON *ver = prsm_jw_object(w, doc, "versions");
	prsm_jw_string(w, ver, "prsm", PRSM_VERSION);
	prsm_jw_string(w, ver, "engine", PRSM_ALLOC_ENGINE);
	prsm_jw_string(w, ver, "build", prsm_engine_build());
	prsm_jw_string(w, doc, "stack", prsm_alloc_stack_name(md->stack));
	prsm_jw_string(w, doc, "solver", prsm_alloc_solver_name(best->sol.solver));
	prsm_jw_string(w, doc, "convention",
	                        "a tolerance +-T is +-k sd of its distribution (k = 3 for a normal and the "
	                        "{tol, cpk 1} shorthand, sqrt 3 for a uniform; sd_ratio in an analytic document); "
	                        "RSS: sum (3 c T / k)^2 <= T_asm^2, T_asm = 3 sigma_max, sigma_max the largest sd "
	                        "of a normal output centred on the nominal whose yield is the target; worst case: "
	                        "sum |c| T <= T_asm = min(U - nominal, nominal - L)");
	prsm_jw_string(w, doc, "sensitivity_source",
	                        d->is_study ? "central differences of the study's model over each variable's reference "
	                                      "half-width (a radial magnitude at its worst of 8 directions), the "
	                                      "tolerance's variables combined in quadrature (RSS) or summed (worst case)"
	                                    : "given in the document");
	cJSON *tols = prsm_jw_array(w, doc, "tolerances");
	for (size_t i = 0; i < md->n; i++) {
		cJSON *t = prsm_jw_object(w, tols, NULL);
		prsm_jw_string(w, t, "parameter", d->tol_name[i]);
		prsm_jw_string(w, t, "unit", d->unit[i]);
		prsm_jw_number(w, t, "half_width", best->sol.t[i]);
		prsm_jw_number(w, t, "reference_half_width", md->t_ref[i]);
		prsm_jw_number(w, t, "sd_ratio", md->k[i]);
		prsm_jw_number(w, t, "cost", best->sol.cost[i]);
		cost_json(w, prsm_jw_object(w, t, "cost_model"), &md->cost[i]);
		cJSON *b = prsm_jw_object(w, t, "bounds");
		prsm_jw_number(w, b, "lower", md->t_min[i]);
		prsm_jw_number(w, b, "upper", md->t_max[i]);
		if (best->sol.at_bound[i])
			prsm_jw_string(w, t, "at_bound", best->sol.at_bound[i] < 0 ? "lower" : "upper");
		else
			prsm_jw_null(w, t, "at_bound");
		cJSON *sens = prsm_jw_object(w, t, "sensitivities");
		for (size_t o = 0; o < md->m; o++)
			prsm_jw_number(w, sens, d->out_name[o], md->c[o][i]);
	}
	prsm_jw_number(w, doc, "total_cost", best->sol.total_cost);
	cJSON *cons = prsm_jw_array(w, doc, "constraints");
	for (size_t o = 0; o < md->m; o++) {
		cJSON *c = prsm_jw_object(w, cons, NULL);
		prsm_jw_string(w, c, "output", d->out_name[o]);
		if (d->has_spec[o])
			spec_json(w, prsm_jw_object(w, c, "spec"), &md->spec[o]);
		else
			prsm_jw_null(w, c, "spec");
		prsm_jw_number(w, c, "nominal", md->nominal[o]);
		prsm_jw_number(w, c, "target_yield", d->target_yield[o]);
		prsm_jw_number(w, c, "assembly_tolerance", best->assembly_tol[o]);
		prsm_jw_number(w, c, "assembly_tolerance_linear", r->steps[0].assembly_tol[o]);
		prsm_jw_number(w, c, "sigma_max", best->sigma_max[o]);
		prsm_jw_number(w, c, "multiplier", best->sol.multiplier[o]);
		prsm_jw_number(w, c, "stack", best->sol.stack[o]);
		prsm_jw_number(w, c, "kept_tolerances_sd", sqrt(md->fixed_var[o]));
		prsm_jw_number(w, c, "kept_tolerances_worst_case", md->fixed_wc[o]);
		prsm_jw_number(w, c, "predicted_sd", best->predicted_sd[o]);
		prsm_jw_number(w, c, "predicted_yield", d->has_spec[o] ? best->predicted_yield[o] : NAN);
		mc_yield_json(w, c, "monte_carlo", d, best, o);
		if (md->has_target[o])
			prsm_jw_bool(w, c, "meets_target", best->has_mc ? best->mc_meets[o]
			                                              : best->predicted_yield[o] >= d->target_yield[o] - 1e-12);
		else /* a given assembly tolerance: the linear stack within it */
			prsm_jw_bool(w, c, "meets_target", best->sol.stack[o] <= best->limit[o] * (1.0 + 1e-9));
	}
	cJSON *lin = prsm_jw_object(w, doc, "linear");
	prsm_jw_number(w, lin, "total_cost", r->steps[0].sol.total_cost);
	half_widths_json(w, prsm_jw_array(w, lin, "half_widths"), d, &r->steps[0]);
	cJSON *py = prsm_jw_array(w, lin, "predicted_yields");
	for (size_t o = 0; o < md->m; o++)
		prsm_jw_number(w, py, NULL, d->has_spec[o] ? r->steps[0].predicted_yield[o] : NAN);
	cJSON *cor = prsm_jw_object(w, doc, "correction");
	prsm_jw_number(w, cor, "scale", best->scale);
	prsm_jw_string(w, cor, "stop_reason", prsm_alloc_stop_name(r->stop));
	prsm_jw_bool(w, cor, "converged", r->converged);
	prsm_jw_number(w, cor, "max_corrections", d->is_study && d->opt.verify ? d->opt.max_corrections : 0);
	prsm_jw_number(w, cor, "scale_tolerance", d->opt.scale_rtol);
	cJSON *steps = prsm_jw_array(w, cor, "steps");
	for (int k = 0; k < r->n_steps; k++) {
		const prsm_alloc_step *st = &r->steps[k];
		cJSON *s = prsm_jw_object(w, steps, NULL);
		prsm_jw_number(w, s, "scale", st->scale);
		prsm_jw_number(w, s, "total_cost", st->sol.total_cost);
		half_widths_json(w, prsm_jw_array(w, s, "half_widths"), d, st);
		cJSON *ys = prsm_jw_array(w, s, "yields");
		for (size_t o = 0; o < md->m; o++)
			mc_yield_json(w, ys, NULL, d, st, o);
		prsm_jw_bool(w, s, "meets_target", st->meets);
		prsm_jw_bool(w, s, "reported", k == r->best);
	}
	if (d->is_study) {
		cJSON *mc = prsm_jw_object(w, doc, "monte_carlo");
		prsm_jw_bool(w, mc, "verify", d->opt.verify);
		prsm_jw_number(w, mc, "samples", (double)d->samples);
		prsm_jw_number(w, mc, "seed", (double)d->seed);
		prsm_jw_string(w, mc, "sampler", prsm_sampler_name(d->study->study.mc.sampler));
		prsm_jw_number(w, mc, "samples_total", (double)r->samples_total);
		prsm_jw_number(w, mc, "threads", d->study->study.mc.threads);
		prsm_jw_string(w, mc, "common_random_numbers",
		                        "every run uses the same seed and sample count, so the yield is a "
		                        "deterministic function of the widths");
	} else {
		prsm_jw_null(w, doc, "monte_carlo");
	}
	size_t evals = 0;
	for (int k = 0; k < r->n_steps; k++)
		evals += r->steps[k].sol.evaluations;
	prsm_jw_number(w, doc, "evaluations", (double)evals);
	prsm_jw_bool(w, doc, "cancelled", cancelled);
	prsm_jw_number(w, doc, "elapsed_s", r->elapsed_s);
	if (w->failed) {
		cJSON_Delete(doc);
		return NULL;
	}
	return doc;
}

