/*
 * optimization_result.c: the optimisation result (schemas/optimization-result.schema.json) from
 * what the run (src/app/optimize.c) computed; see optimization_json.h.
 */
#include "io/optimization_json.h"

#include <math.h>
#include <stdio.h>

#include <nlopt.h>

#include "io/analysis_json.h"
#include "io/write.h"
#include "prsm_io_writers.h"

static const char *const constraint_units[] = {"-", "-", "rule warnings", "mm", "mm", "mm", "-",
                                               "h", "revolutions", "MPa", "-"};

static double percent(double fraction)
{
	return 100.0 * fraction;
}

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

/* Every constraint with its value, limit and whether it meets its raw limit; violated names
 * to viol (may be NULL). */
static void constraints_json(prsm_jw *w, cJSON *arr, const prsm_io_optimization *od,
                             const prsm_io_opt_point *p, cJSON *viol)
{
	const prsm_dp_spec *s = &od->spec;
	for (int i = 0; i < s->n_constraints; i++) {
		int kind = s->constraint_kind[i];
		cJSON *c = prsm_jw_object(w, arr, NULL);
		prsm_jw_string(w, c, "name", prsm_dp_constraint_names[kind]);
		prsm_jw_string(w, c, "unit", constraint_units[kind]);
		prsm_jw_number(w, c, "value", p->fig.constraint_value[kind]);
		prsm_jw_number(w, c, "limit", s->constraint_limit[i]);
		prsm_jw_string(w, c, "bound", kind == PRSM_DP_C_SCREW_DIAMETER_MIN ||
		                                      kind == PRSM_DP_C_STATIC_SAFETY ||
		                                      kind == PRSM_DP_C_LIFE_HOURS ||
		                                      kind == PRSM_DP_C_LIFE_REVOLUTIONS ||
		                                      kind == PRSM_DP_C_CRITICAL_SPEED
		                                  ? "min" : "max");
		int ok = p->g[i] <= 0.0;
		prsm_jw_bool(w, c, "satisfied", ok);
		if (!ok && viol)
			prsm_jw_string(w, viol, NULL, prsm_dp_constraint_names[kind]);
		if (kind == PRSM_DP_C_ANALYSABLE && p->fig.failure[0])
			prsm_jw_string(w, c, "message", p->fig.failure);
	}
}

static void objectives_json(prsm_jw *w, cJSON *arr, const prsm_io_optimization *od, const prsm_io_opt_point *p)
{
	for (int k = 0; k < od->spec.n_objectives; k++) {
		cJSON *o = prsm_jw_object(w, arr, NULL);
		prsm_jw_string(w, o, "name", prsm_dp_objective_names[od->spec.objective[k]]);
		prsm_jw_string(w, o, "sense", od->problem.sense[k] > 0 ? "minimise" : "maximise");
		prsm_jw_number(w, o, "value", p->fig.objective[od->spec.objective[k]]);
		if (od->method == PRSM_IO_OPT_WEIGHTED)
			prsm_jw_number(w, o, "weight", od->weight[k]);
	}
}

/* The robust constraints of the point as the result's "robust" array: the fresh run's yields;
 * `satisfied` is that run's yield against its target, no tolerance. Unsatisfied names go to
 * viol (may be NULL). */
static void robust_json(prsm_jw *w, cJSON *arr, const prsm_io_optimization *od,
                        const prsm_io_opt_point *p, cJSON *viol)
{
	const prsm_robust_eval *re = &p->robust;
	for (int k = 0; k < od->robust.n; k++) {
		const prsm_robust_constraint *c = &od->robust.c[k];
		const prsm_robust_value *v = &re->v[k];
		cJSON *e = prsm_jw_object(w, arr, NULL);
		char name[PRSM_OPT_NAME_MAX];
		snprintf(name, sizeof name, "yield_%.40s", c->output);
		prsm_jw_string(w, e, "name", name);
		prsm_jw_string(w, e, "output", c->output);
		cJSON *sp = prsm_jw_object(w, e, "spec");
		if (c->spec.has_lower)
			prsm_jw_number(w, sp, "lower", c->spec.lower);
		if (c->spec.has_upper)
			prsm_jw_number(w, sp, "upper", c->spec.upper);
		prsm_jw_number(w, e, "yield_min_percent", percent(c->yield_min));
		const int ok = p->robust_rc == 0 && re->evaluated;
		prsm_jw_bool(w, e, "evaluated", ok);
		prsm_jw_number(w, e, "yield_percent", ok ? percent(v->yield) : NAN);
		prsm_jw_number(w, e, "yield_low95_percent", ok ? percent(v->yield_low95) : NAN);
		prsm_jw_number(w, e, "yield_high95_percent", ok ? percent(v->yield_high95) : NAN);
		prsm_jw_number(w, e, "samples", ok ? (double)re->samples : 0.0);
		prsm_jw_number(w, e, "failed_samples", ok ? (double)re->failed : 0.0);
		prsm_jw_number(w, e, "edge_contact_samples", ok ? (double)re->edge : 0.0);
		prsm_jw_number(w, e, "seed", (double)od->robust.seed);
		prsm_jw_string(w, e, "sampler", od->sampler);
		prsm_jw_number(w, e, "mean", ok ? v->mean : NAN);
		prsm_jw_number(w, e, "sd", ok ? v->sd : NAN);
		prsm_jw_number(w, e, "normal_yield_percent", ok ? percent(v->normal_yield) : NAN);
		prsm_jw_number(w, e, "surrogate_yield_percent", ok ? percent(v->smooth_yield) : NAN);
		/* the fresh run's verdict (the search saw the same yield: common random numbers) */
		const int sat = ok && v->g <= 0.0;
		prsm_jw_bool(w, e, "satisfied", sat);
		if (!ok)
			prsm_jw_string(w, e, "message", p->robust_rc ? p->robust_err.message : re->failure);
		if (!sat && viol)
			prsm_jw_string(w, viol, NULL, name);
	}
}

/* The point's variables, objectives, constraints, robust constraints, figures, design and
 * analysis into o; the names of violated constraints appended to violated (may be NULL).
 * Returns 0 or PRSM_ENOMEM. */
static int point_json(cJSON *o, const prsm_io_optimization *od, const prsm_io_opt_point *p, cJSON *violated)
{
	prsm_jw w = PRSM_JW_INIT;
	prsm_io_write(&w, o, "variables", &p->design, &prsm_io_w_variables);
	objectives_json(&w, prsm_jw_array(&w, o, "objectives"), od, p);
	constraints_json(&w, prsm_jw_array(&w, o, "constraints"), od, p, violated);
	if (od->has_robust && p->robust_rc != PRSM_ENOMEM)
		robust_json(&w, prsm_jw_array(&w, o, "robust"), od, p, violated);
	prsm_io_write(&w, o, "figures", p, &prsm_io_w_figures);
	if (p->analysed) {
		prsm_problems none;
		prsm_problems_init(&none);
		prsm_io_write(&w, o, "design", &p->design, &prsm_io_w_resolved_design);
		prsm_io_analysis_write(&w, prsm_jw_object(&w, o, "analysis"), p->analysis, &p->design, p->perf, &none);
	} else {
		prsm_jw_null(&w, o, "design");
	}
	return w.failed ? PRSM_ENOMEM : 0;
}

cJSON *prsm_io_optimization_result_head(const prsm_io_optimization *od, const prsm_problems *warnings)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *doc = prsm_jw_root(&w);
	if (od->name[0])
		prsm_jw_string(&w, doc, "name", od->name);
	prsm_io_write(&w, doc, "versions", od, &prsm_io_w_opt_versions);
	prsm_jw_string(&w, doc, "method", prsm_io_opt_method_names[od->method]);
	prsm_jw_item(&w, doc, "warnings", prsm_io_problems_to_json(warnings));
	return prsm_jw_done(&w, doc);
}

void prsm_io_optimization_run_json(cJSON *doc, const prsm_io_optimization *od, const prsm_io_opt_run *run)
{
	prsm_jw w = PRSM_JW_INIT;
	prsm_jw_bool(&w, doc, "cancelled", run->cancelled);
	prsm_jw_string(&w, doc, "stop_reason", prsm_opt_stop_names[run->stop]);
	prsm_jw_number(&w, doc, "evaluations", (double)run->evaluations);
	prsm_io_write(&w, doc, "solver", &od->options, &prsm_io_w_solver);
	prsm_io_write(&w, doc, "search", run, &prsm_io_w_search);
	prsm_jw_number(&w, doc, "elapsed_s", run->elapsed_s);
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
		rc = point_json(best, od, p, violated);
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
	cJSON *pf = prsm_jw_object(&w, doc, "pareto");
	prsm_jw_string(&w, pf, "objective_a", prsm_dp_objective_names[od->spec.objective[0]]);
	prsm_jw_string(&w, pf, "objective_b", prsm_dp_objective_names[od->spec.objective[1]]);
	prsm_jw_number(&w, pf, "levels", od->points);
	prsm_jw_number(&w, pf, "epsilon_runs", front->runs);
	prsm_jw_number(&w, pf, "epsilon_runs_feasible", front->runs_feasible);
	prsm_jw_number(&w, pf, "dominated_removed", front->dominated_removed);
	cJSON *pts = prsm_jw_array(&w, pf, "points");
	return w.failed ? NULL : pts;
}

int prsm_io_optimization_front_point_json(cJSON *points, const prsm_io_optimization *od,
                                          double epsilon_limit, const prsm_io_opt_point *p)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *pt = prsm_jw_object(&w, points, NULL);
	prsm_jw_number(&w, pt, "epsilon_limit", epsilon_limit);
	int rc = pt ? point_json(pt, od, p, NULL) : 0;
	return rc ? rc : w.failed ? PRSM_ENOMEM : 0;
}

void prsm_io_optimization_normalisation_json(cJSON *doc, const prsm_io_optimization *od,
                                             const double *ideal, const double *range)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *nm = prsm_jw_object(&w, doc, "normalisation");
	prsm_jw_string(&w, nm, "rule", "each objective as (sense f - ideal) / range, ideal and range "
	               "from the single-objective optima (payoff table), sense +1 to minimise, -1 to "
	               "maximise");
	cJSON *arr = prsm_jw_array(&w, nm, "objectives");
	for (int k = 0; k < od->spec.n_objectives; k++) {
		cJSON *e = prsm_jw_object(&w, arr, NULL);
		prsm_jw_string(&w, e, "name", prsm_dp_objective_names[od->spec.objective[k]]);
		prsm_jw_number(&w, e, "ideal", od->problem.sense[k] * ideal[k]);
		prsm_jw_number(&w, e, "range", range[k]);
	}
}

void prsm_io_optimization_robust_json(cJSON *doc, const prsm_io_optimization *od)
{
	if (!od->has_robust)
		return;
	prsm_jw w = PRSM_JW_INIT;
	prsm_io_write(&w, doc, "robust", od, &prsm_io_w_robust_settings);
}
