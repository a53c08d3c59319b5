/*
 * optimization_result.c: the optimisation result (schemas/optimization-result.schema.json) from
 * what the run (src/app/optimize.c) computed; see optimization_json.h.
 */
#include "io/optimization_json.h"

#include <stdio.h>

#include <nlopt.h>

#include "io/analysis_json.h"
#include "io/write.h"
#include "prsm_io_writers.h"

static const char *const constraint_units[] = {"-", "-", "rule warnings", "mm", "mm", "mm", "-",
                                               "h", "revolutions", "MPa", "-"};

void prsm_io_whook_lead(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_number(w, obj, key, prsm_design_lead_mm(at));
}

void prsm_io_whook_nlopt_version(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	char nl[32];
	int maj, min, bug;
	nlopt_version(&maj, &min, &bug);
	snprintf(nl, sizeof nl, "%d.%d.%d", maj, min, bug);
	prsm_jw_string(w, obj, key, nl);
}

void prsm_io_whook_opt_analysis(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_opt_point *p = at;
	prsm_problems none;
	prsm_problems_init(&none);
	prsm_io_analysis_write(w, prsm_jw_object(w, obj, key), p->analysis, &p->design, p->perf, &none);
}

/* The point by its table (its epsilon limit first when has_epsilon): the constraints judged
 * against their raw limits, the robust constraints by their fresh run (the search saw the same
 * yields: common random numbers); the names of those violated appended to violated (may be
 * NULL). Returns 0 or PRSM_ENOMEM. */
static int point_json(cJSON *o, const prsm_io_optimization *od, const prsm_io_opt_point *p, int has_epsilon,
                      double epsilon_limit, cJSON *violated)
{
	prsm_jw w = PRSM_JW_INIT;
	prsm_io_opt_point_view v = {.od = od, .p = p, .has_epsilon = has_epsilon, .epsilon_limit = epsilon_limit};
	for (int k = 0; k < od->spec.n_objectives; k++)
		v.objective[k] = p->fig.objective[od->spec.objective[k]];
	for (int i = 0; i < od->spec.n_constraints; i++) {
		const int kind = od->spec.constraint_kind[i];
		v.value[i] = p->fig.constraint_value[kind];
		v.unit[i] = constraint_units[kind];
		v.at_least[i] = kind == PRSM_DP_C_SCREW_DIAMETER_MIN || kind == PRSM_DP_C_STATIC_SAFETY ||
		                kind == PRSM_DP_C_LIFE_HOURS || kind == PRSM_DP_C_LIFE_REVOLUTIONS ||
		                kind == PRSM_DP_C_CRITICAL_SPEED;
		v.satisfied[i] = p->g[i] <= 0.0;
		v.message[i] = kind == PRSM_DP_C_ANALYSABLE && p->fig.failure[0] ? p->fig.failure : NULL;
		if (!v.satisfied[i] && violated)
			prsm_jw_string(&w, violated, NULL, prsm_dp_constraint_names[kind]);
	}
	const prsm_robust_eval *re = &p->robust;
	v.robust = od->has_robust && p->robust_rc != PRSM_ENOMEM;
	v.ok = p->robust_rc == 0 && re->evaluated;
	if (v.ok) {
		v.samples = re->samples;
		v.failed = re->failed;
		v.edge = re->edge;
	} else {
		v.robust_message = p->robust_rc ? p->robust_err.message : re->failure;
	}
	for (int k = 0; v.robust && k < od->robust.n; k++) {
		snprintf(v.robust_name[k], sizeof v.robust_name[k], "yield_%.40s", od->robust.c[k].output);
		v.robust_satisfied[k] = v.ok && re->v[k].g <= 0.0;
		if (!v.robust_satisfied[k] && violated)
			prsm_jw_string(&w, violated, NULL, v.robust_name[k]);
	}
	prsm_io_write_fields(&w, o, &v, &prsm_io_w_opt_point, 0);
	return w.failed ? PRSM_ENOMEM : 0;
}

int prsm_io_optimization_run_json(cJSON *doc, const prsm_io_optimization *od, const prsm_problems *warnings,
                                  const prsm_io_opt_run *run)
{
	prsm_jw w = PRSM_JW_INIT;
	const prsm_io_optimization_result_view v = {od, warnings, run};
	prsm_io_write_fields(&w, doc, &v, &prsm_io_w_optimization_result, 0);
	return w.failed ? PRSM_ENOMEM : 0;
}

int prsm_io_optimization_best_json(cJSON *doc, const prsm_io_optimization *od, int status,
                                   const prsm_io_opt_point *p)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *violated = cJSON_CreateArray();
	cJSON *best = cJSON_CreateObject();
	int rc = 0;
	if (!violated || !best)
		rc = PRSM_ENOMEM;
	else if (status != PRSM_OPT_NOTHING)
		rc = point_json(best, od, p, 0, 0.0, violated);
	/* feasible only when the optimiser found it so and the fresh check violates nothing */
	if (status == PRSM_OPT_FEASIBLE && cJSON_GetArraySize(violated) > 0)
		status = PRSM_OPT_INFEASIBLE;
	prsm_jw_string(&w, doc, "status", status == PRSM_OPT_FEASIBLE     ? "feasible"
	                                  : status == PRSM_OPT_INFEASIBLE ? "infeasible"
	                                                                  : "none");
	prsm_jw_bool(&w, doc, "feasible", status == PRSM_OPT_FEASIBLE);
	prsm_jw_item(&w, doc, "violated", violated);
	if (status != PRSM_OPT_NOTHING) {
		prsm_jw_item(&w, doc, "best", best);
	} else {
		cJSON_Delete(best);
		prsm_jw_null(&w, doc, "best");
	}
	return rc ? rc : w.failed ? PRSM_ENOMEM : 0;
}

cJSON *prsm_io_optimization_pareto_json(cJSON *doc, const prsm_io_optimization *od,
                                        const prsm_opt_front *front)
{
	prsm_jw w = PRSM_JW_INIT;
	const prsm_io_opt_pareto_view v = {od, front};
	cJSON *pts = prsm_jw_array(&w, prsm_io_write(&w, doc, "pareto", &v, &prsm_io_w_opt_pareto), "points");
	return w.failed ? NULL : pts;
}

int prsm_io_optimization_front_point_json(cJSON *points, const prsm_io_optimization *od,
                                          double epsilon_limit, const prsm_io_opt_point *p)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *pt = prsm_jw_object(&w, points, NULL);
	int rc = pt ? point_json(pt, od, p, 1, epsilon_limit, NULL) : 0;
	return rc ? rc : w.failed ? PRSM_ENOMEM : 0;
}

void prsm_io_optimization_normalisation_json(cJSON *doc, const prsm_io_optimization *od,
                                             const double *ideal, const double *range)
{
	prsm_jw w = PRSM_JW_INIT;
	prsm_io_opt_normalisation_view v = {.od = od, .range = range};
	for (int k = 0; k < od->spec.n_objectives; k++)
		v.ideal[k] = od->problem.sense[k] * ideal[k];
	prsm_io_write(&w, doc, "normalisation", &v, &prsm_io_w_opt_normalisation);
}

void prsm_io_optimization_robust_json(cJSON *doc, const prsm_io_optimization *od)
{
	if (!od->has_robust)
		return;
	prsm_jw w = PRSM_JW_INIT;
	prsm_io_write(&w, doc, "robust", od, &prsm_io_w_robust_settings);
}
