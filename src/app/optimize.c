/*
 * optimize.c: running an optimisation document (see optimize.h): read, search, evaluate the
 * reported points afresh, write.
 */
#include "app/optimize.h"
#include "app/study.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/optimization_json.h"
#include "io/study_json.h"
#include "io/design_json.h"

/* ---- the design problem ---- */

/* The design problem of a read document: the rollers' range when its max was left out, the
 * problem itself, the combination count, and at least one combination that the cheap bounds
 * leave alive. Problems at their pointers. */
static int prepare(prsm_io_optimization *od, prsm_problems *pr)
{
	const int before = prsm_problems_total(pr);
	prsm_dp_spec *s = &od->spec;
	/* the rollers' max left out: up to the largest Z_max any start count reaches */
	if (od->rollers_auto_max >= 1) {
		int zb = 0;
		if (s->starts.count)
			for (int i = 0; i < s->starts.count; i++) {
				int z = prsm_dp_z_max_bound(s, s->starts.values[i]);
				zb = z > zb ? z : zb;
			}
		else
			zb = prsm_dp_z_max_bound(s, s->base.starts);
		if (zb > PRSM_DESIGN_ROLLERS_MAX)
			zb = PRSM_DESIGN_ROLLERS_MAX;
		for (int z = od->rollers_auto_max; z <= zb && s->rollers.count < PRSM_OPT_MAX_LEVELS; z++)
			s->rollers.values[s->rollers.count++] = z;
		if (s->rollers.count == 0) {
			prsm_problems_add(pr, "/variables/rollers/min", "z_max",
			                  "no roller count from %d up fits the geometry (Z_max at most %d)",
			                  od->rollers_auto_max, zb);
			return PRSM_EINVAL;
		}
	}
	if (!s->starts.count && s->base.starts < 3)
		prsm_problems_add(pr, "/design/geometry/starts", "starts_min",
		                  "the optimiser's standard rule r_s = (n-2) r_r needs at least 3 starts");
	if (s->radius_is_screw && !s->starts.count && s->radius.vary && s->base.starts < 3)
		return PRSM_EINVAL;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_problems_total(pr) > before)
		return PRSM_EINVAL;
	if (prsm_dp_problem(&od->problem, s, &err)) {
		prsm_problems_add(pr, err.pointer[0] ? err.pointer : "/variables", "invalid", "%s", err.message);
		return PRSM_EINVAL;
	}
	double combos = 1.0;
	for (int d = 0; d < od->problem.n_discrete; d++)
		combos *= od->problem.n_levels[d];
	if (combos > PRSM_OPT_MAX_COMBINATIONS) {
		prsm_problems_add(pr, "/variables", "too_many", "%.0f combinations of starts, rollers and "
		                  "engaged threads exceed %d", combos, PRSM_OPT_MAX_COMBINATIONS);
		return PRSM_EINVAL;
	}
	/* at least one combination must survive the cheap bounds */
	size_t alive = 0, n = (size_t)combos;
	for (size_t c = 0; c < n && !alive; c++) {
		double lv[PRSM_OPT_MAX_DISCRETE];
		size_t r = c;
		for (int d = od->problem.n_discrete - 1; d >= 0; d--) {
			lv[d] = od->problem.levels[d][r % (size_t)od->problem.n_levels[d]];
			r /= (size_t)od->problem.n_levels[d];
		}
		alive += !od->problem.prune(od->problem.ctx, lv, od->problem.lower, od->problem.upper);
	}
	if (!alive) {
		prsm_problems_add(pr, "/variables", "infeasible", "no combination of the variables can fit "
		                  "its rollers and the diameter limits, even at the most favourable corner "
		                  "of the ranges");
		return PRSM_EINVAL;
	}
	for (int k = 0; k < s->n_objectives; k++)
		od->options.weight[k] = od->weight[k];
	return 0;
}


/* Read and prepare; od released by the caller. */
static int load(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations,
                prsm_problems *warnings, prsm_problems *pr)
{
	prsm_io_study_options study;
	prsm_app_study_options(&study);
	int rc = prsm_io_optimization_read(od, doc, max_evaluations, &study, warnings, pr);
	return rc ? rc : prepare(od, pr);
}

int prsm_app_optimization_check(const cJSON *doc, size_t max_evaluations, prsm_problems *warnings,
                                prsm_problems *problems)
{
	prsm_io_optimization *od = calloc(1, sizeof *od);
	if (!od)
		return PRSM_ENOMEM;
	int rc = load(od, doc, max_evaluations, warnings, problems);
	prsm_io_optimization_release(od);
	free(od);
	return rc;
}

/* ---- the robust constraints' studies: a candidate's study document through the study reader */

/* Set obj[key] to the number v (replacing it or adding it). */
static void set_number(cJSON *obj, const char *key, double v)
{
	cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
	if (it && cJSON_IsNumber(it))
		cJSON_SetNumberValue(it, v);
	else {
		cJSON_DeleteItemFromObjectCaseSensitive(obj, key);
		cJSON_AddNumberToObject(obj, key, v);
	}
}

/* The flank angle in degrees that the design reader turns back into exactly beta_rad. */
static double flank_deg_exact(double beta_rad)
{
	double deg = beta_rad * (180.0 / M_PI);
	for (int k = 0; k < 8 && deg * (M_PI / 180.0) != beta_rad; k++)
		deg = nextafter(deg, deg * (M_PI / 180.0) < beta_rad ? INFINITY : -INFINITY);
	return deg;
}

/* Put candidate d's varied fields into the study document's design geometry: what
 * prsm_dp_design_at changes in the base design, with the derived radii left to the rules. */
static void candidate_geometry(cJSON *study, const prsm_design *d)
{
	cJSON *g = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(study, "design"),
	                                            "geometry");
	if (!g)
		return;
	static const char *const derived[] = {"screw_radius_mm", "nut_radius_mm", "roller_arc_radius_mm",
	                                      "screw_crest_radius_mm", "screw_root_radius_mm",
	                                      "roller_crest_radius_mm", "roller_root_radius_mm",
	                                      "nut_crest_radius_mm", "nut_root_radius_mm",
	                                      "nut_length_mm", NULL};
	for (int k = 0; derived[k]; k++)
		cJSON_DeleteItemFromObjectCaseSensitive(g, derived[k]);
	set_number(g, "starts", d->starts);
	set_number(g, "pitch_mm", d->pitch_mm);
	if (isfinite(d->roller_radius_mm))
		set_number(g, "roller_radius_mm", d->roller_radius_mm);
	set_number(g, "rollers", d->rollers);
	set_number(g, "engaged_threads", d->engaged_threads);
	set_number(g, "flank_angle_deg", flank_deg_exact(d->flank_angle_rad));
}

/* A candidate's study and, when its studies run elsewhere (a study service), the document. */
typedef struct {
	prsm_io_study s;
	char *source;
} candidate_study;

/* prsm_robust_build_fn: the tolerance study of candidate d through the study reader (so the
 * study is exactly the one an equivalent study document gives); with a study service, that
 * document's text is the source another process loads. */
static int build_study(void *ctx, prsm_study **study, void **handle, const char **source, size_t *source_len,
                       const prsm_design *d, prsm_error *err)
{
	prsm_io_optimization *od = ctx;
	candidate_geometry(od->study, d);
	candidate_study *cs = calloc(1, sizeof *cs);
	prsm_io_study *s = cs ? &cs->s : NULL;
	prsm_problems *pr = malloc(sizeof *pr);
	int rc = 0;
	if (!cs || !pr || (od->robust.service && !(cs->source = cJSON_PrintUnformatted(od->study)))) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto fail;
	}
	prsm_problems_init(pr);
	rc = prsm_app_study_load(s, od->study, NULL, pr);
	if (rc) {
		if (pr->count && pr->items[0].pointer[0])
			prsm_error_set(err, rc, NULL, "%s: %s", pr->items[0].pointer, pr->items[0].message);
		else if (pr->count) /* the whole study: no pointer to put before the message */
			prsm_error_set(err, rc, NULL, "%s", pr->items[0].message);
		else
			prsm_error_set(err, rc, NULL, "the study could not be built");
		goto fail;
	}
	free(pr);
	*study = &s->study;
	*handle = cs;
	*source = cs->source;
	*source_len = cs->source ? strlen(cs->source) : 0;
	return 0;
fail:
	free(pr);
	if (cs)
		cJSON_free(cs->source);
	free(cs);
	return rc;
}

static void release_study(void *ctx, void *handle)
{
	(void)ctx;
	candidate_study *cs = handle;
	cJSON_free(cs->source);
	free(cs);
}
/* The design at (x, levels) analysed afresh and in full into p (p->analysis and p->perf owned
 * by the caller's a and perf, freed with prsm_performance_free), the robust constraints re-run
 * from scratch (the cache emptied first: the reported yields are a fresh Monte Carlo run of the
 * study, with common random numbers the one the search saw; run only when the point's fresh
 * deterministic violations hold). */
static void evaluate(prsm_io_opt_point *p, prsm_analysis *a, prsm_performance *perf,
                     const prsm_io_optimization *od, const double *x, const double *levels)
{
	memset(p, 0, sizeof *p);
	prsm_dp_design_at(&p->design, &od->spec, x, levels);
	const prsm_design unresolved = p->design;
	p->analysed = prsm_dp_analyse(&p->fig, &p->design, &od->spec, 1, a, perf) == 0;
	p->analysis = a;
	p->perf = perf;
	for (int i = 0; i < od->spec.n_constraints; i++)
		p->g[i] = prsm_dp_violation(&od->spec, i, &p->fig, p->design.rollers);
	if (od->has_robust) {
		prsm_error_clear(&p->robust_err);
		prsm_robust_forget(od->spec.robust);
		p->robust_rc = prsm_dp_robust(&p->robust, &od->spec, &unresolved, p->g, &p->robust_err);
	}
}

/* Evaluate the point and write it: as the best point (status) into doc, or with points as a
 * point of the Pareto front (its epsilon limit eps). */
static int write_point(cJSON *doc, cJSON *points, const prsm_io_optimization *od, int status,
                       const double *x, const double *levels, double eps)
{
	prsm_io_opt_point *p = calloc(1, sizeof *p);
	prsm_analysis *a = calloc(1, sizeof *a);
	prsm_performance perf;
	memset(&perf, 0, sizeof perf);
	int rc = 0;
	if (!p || !a) {
		rc = PRSM_ENOMEM;
	} else if (!points && status == PRSM_OPT_NOTHING) {
		rc = prsm_io_optimization_best_json(doc, od, status, NULL);
	} else {
		evaluate(p, a, &perf, od, x, levels);
		rc = points ? prsm_io_optimization_front_point_json(points, od, eps, p)
		            : prsm_io_optimization_best_json(doc, od, status, p);
		if (rc == 0 && od->has_robust && p->robust_rc == PRSM_ECANCELLED)
			rc = PRSM_ECANCELLED;
		if (od->has_robust && p->robust_rc == PRSM_ENOMEM)
			rc = PRSM_ENOMEM;
		prsm_performance_free(&perf);
	}
	free(a);
	free(p);
	return rc;
}

int prsm_app_optimize(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                      prsm_problems *problems, prsm_error *err)
{
	return prsm_app_optimize_with(result, doc, cancel, progress, progress_ctx, max_time_s, NULL, problems, err);
}

int prsm_app_optimize_with(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                           const prsm_study_service *service, prsm_problems *problems, prsm_error *err)
{
	*result = NULL;
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	prsm_io_optimization *od = calloc(1, sizeof *od);
	prsm_opt_result *r = calloc(1, sizeof *r);
	prsm_opt_front *front = NULL;
	int rc = 0;
	if (!od || !r) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	rc = load(od, doc, 0, &warnings, problems);
	if (rc) {
		prsm_error_set(err, rc, NULL, "the optimisation document is invalid");
		goto cleanup;
	}
	/* the problem's ctx points into od->spec: od does not move from here on */
	od->problem.ctx = &od->spec;
	if (od->has_robust) {
		od->robust.build = build_study;
		od->robust.release = release_study;
		od->robust.build_ctx = od;
		od->robust.service = service;
	}
	prsm_opt_options *o = &od->options;
	o->cancel = cancel;
	od->robust.cancel = cancel;
	o->progress = progress;
	o->progress_ctx = progress_ctx;
	if (max_time_s > 0.0 && max_time_s < o->max_time_s)
		o->max_time_s = max_time_s;
	cJSON *out = cJSON_CreateObject();
	if (!out) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	*result = out;
	int run_rc;
	if (od->method == PRSM_IO_OPT_PARETO) {
		front = calloc(1, sizeof *front);
		if (!front) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		run_rc = prsm_opt_pareto(front, &od->problem, o, 0, 1, od->points, err);
		if (run_rc && run_rc != PRSM_ECANCELLED) {
			rc = run_rc;
			goto cleanup;
		}
		/* the point closest to the ideal (Chebyshev distance, normalised) leads the result */
		const int lead = prsm_opt_front_lead(front, &od->problem);
		od->robust.cancel = NULL; /* the result's re-checks run to the end */
		const prsm_io_opt_run run = {front->evaluations, front->anchor[0].combinations,
		                             front->anchor[0].pruned, front->local_runs,
		                             front->local_runs_feasible, front->runs_truncated, front->stop,
		                             front->cancelled, front->elapsed_s};
		rc = prsm_io_optimization_run_json(out, od, &warnings, &run);
		if (rc == 0 && lead >= 0)
			rc = write_point(out, NULL, od, PRSM_OPT_FEASIBLE, front->points[lead].x,
			                 front->points[lead].levels, 0.0);
		else if (rc == 0)
			rc = write_point(out, NULL, od, PRSM_OPT_NOTHING, NULL, NULL, 0.0);
		cJSON *pts = prsm_io_optimization_pareto_json(out, od, front);
		if (!pts && rc == 0)
			rc = PRSM_ENOMEM;
		for (int i = 0; i < front->n_points && rc == 0; i++)
			rc = write_point(out, pts, od, 0, front->points[i].x, front->points[i].levels,
			                 front->points[i].eps_limit);
		if (rc == 0)
			rc = run_rc;
	} else {
		double ideal[PRSM_OPT_MAX_OBJECTIVES], range[PRSM_OPT_MAX_OBJECTIVES];
		if (od->method == PRSM_IO_OPT_WEIGHTED)
			run_rc = prsm_opt_weighted_sum(r, ideal, range, &od->problem, o, err);
		else
			run_rc = prsm_opt_run(r, &od->problem, o, err);
		if (run_rc && run_rc != PRSM_ECANCELLED) {
			rc = run_rc;
			goto cleanup;
		}
		od->robust.cancel = NULL; /* the result's re-checks run to the end */
		const prsm_io_opt_run run = {r->evaluations, r->combinations, r->pruned, r->runs,
		                             r->runs_feasible, r->runs_truncated, r->stop,
		                             r->cancelled || run_rc == PRSM_ECANCELLED, r->elapsed_s};
		rc = prsm_io_optimization_run_json(out, od, &warnings, &run);
		if (rc == 0)
			rc = write_point(out, NULL, od, r->status, r->x, r->levels, 0.0);
		if (od->method == PRSM_IO_OPT_WEIGHTED)
			prsm_io_optimization_normalisation_json(out, od, ideal, range);
		if (rc == 0)
			rc = run_rc;
	}
	prsm_io_optimization_robust_json(out, od);
cleanup:
	if (rc && rc != PRSM_ECANCELLED && *result) {
		cJSON_Delete(*result);
		*result = NULL;
	}
	free(front);
	free(r);
	if (od)
		prsm_io_optimization_release(od);
	free(od);
	return rc;
}
