/*
 * pareto.c: anchors and payoff table, the normalised weighted sum and the epsilon-constraint
 * sweep of pareto.h, with the dominance filter of the front.
 */
#include "opt/pareto.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/clock.h"

int prsm_opt_dominates(const prsm_opt_problem *p, int a, int b, const double *fu, const double *fv)
{
	double ua = p->sense[a] * fu[a], ub = p->sense[b] * fu[b];
	double va = p->sense[a] * fv[a], vb = p->sense[b] * fv[b];
	return ua <= va && ub <= vb && (ua < va || ub < vb);
}

/* The stop reason of several runs: the most telling one (cancelled, then the time cap, then the
 * evaluation budget or a truncated run; converged or all pruned only when every run says so). */
static int merge_stop(int a, int b)
{
	static const int rank[] = {0, 1, 2, 3, 0}; /* indexed by PRSM_OPT_STOP_* */
	return rank[b] > rank[a] ? b : a;
}

/* A sub-run with its share of the budget and the progress counted over the whole. */
static int sub_run(prsm_opt_result *r, const prsm_opt_problem *p, prsm_opt_options *so,
                   size_t *used, size_t share, double t0, const prsm_opt_options *o,
                   prsm_error *err)
{
	so->max_evaluations = share < 1 ? 1 : share;
	so->progress_offset = o->progress_offset + *used;
	so->progress_planned = o->progress_planned ? o->progress_planned : o->max_evaluations;
	so->max_time_s = o->max_time_s - (prsm_clock_seconds() - t0);
	if (!(so->max_time_s > 0.0)) {
		memset(r, 0, sizeof *r);
		r->status = PRSM_OPT_NOTHING;
		r->stop = PRSM_OPT_STOP_MAXTIME;
		return 0;
	}
	int rc = prsm_opt_run(r, p, so, err);
	*used += r->evaluations;
	return rc;
}

/* Single-objective anchors of the objectives flagged in want; fills ideal and nadir (minimised
 * sense) from the payoff table. */
static int anchors(prsm_opt_result *anchor, double *ideal, double *nadir, const prsm_opt_problem *p,
                   const prsm_opt_options *o, const int *want, size_t share, size_t *used,
                   double t0, prsm_error *err)
{
	for (int k = 0; k < p->n_objectives; k++) {
		if (!want[k])
			continue;
		prsm_opt_options so = *o;
		so.scalarisation = PRSM_OPT_SINGLE;
		so.objective = k;
		int rc = sub_run(&anchor[k], p, &so, used, share, t0, o, err);
		if (rc)
			return rc;
	}
	for (int k = 0; k < p->n_objectives; k++) {
		ideal[k] = INFINITY;
		nadir[k] = -INFINITY;
		for (int j = 0; j < p->n_objectives; j++) {
			if (!want[j] || anchor[j].status != PRSM_OPT_FEASIBLE)
				continue;
			double v = p->sense[k] * anchor[j].objectives[k];
			ideal[k] = fmin(ideal[k], v);
			nadir[k] = fmax(nadir[k], v);
		}
	}
	return 0;
}

/* range = nadir - ideal, kept positive when the objectives agree. */
static double range_of(double ideal, double nadir)
{
	double r = nadir - ideal;
	double floor_ = 1e-9 * fmax(1.0, fabs(ideal));
	return isfinite(r) && r > floor_ ? r : floor_;
}

int prsm_opt_weighted_sum(prsm_opt_result *out, double *ideal, double *range,
                          const prsm_opt_problem *p, const prsm_opt_options *o, prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	prsm_opt_result *anchor = calloc(PRSM_OPT_MAX_OBJECTIVES, sizeof *anchor);
	if (!anchor)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int want[PRSM_OPT_MAX_OBJECTIVES] = {0}, n_want = 0;
	for (int k = 0; k < p->n_objectives; k++) {
		want[k] = o->weight[k] > 0.0;
		n_want += want[k];
	}
	size_t used = 0, share = o->max_evaluations / (size_t)(n_want + 1);
	double nadir[PRSM_OPT_MAX_OBJECTIVES];
	int rc = anchors(anchor, ideal, nadir, p, o, want, share, &used, t0, err);
	if (rc) {
		/* cancelled during an anchor: its best point is the best so far */
		for (int k = 0; k < p->n_objectives; k++)
			if (want[k] && anchor[k].cancelled)
				*out = anchor[k];
		goto cleanup;
	}
	prsm_opt_options so = *o;
	so.scalarisation = PRSM_OPT_WEIGHTED_SUM;
	for (int k = 0; k < p->n_objectives; k++) {
		if (!isfinite(ideal[k])) {
			ideal[k] = 0.0; /* no feasible anchor: plain weights */
			nadir[k] = 1.0;
		}
		range[k] = range_of(ideal[k], nadir[k]);
		so.ideal[k] = ideal[k];
		so.range[k] = range[k];
	}
	rc = sub_run(out, p, &so, &used, o->max_evaluations - used, t0, o, err);
	out->evaluations = used;
	/* the counts and the stop reason over the anchors and the weighted run */
	for (int k = 0; k < p->n_objectives; k++) {
		if (!want[k])
			continue;
		out->runs += anchor[k].runs;
		out->runs_feasible += anchor[k].runs_feasible;
		out->runs_truncated += anchor[k].runs_truncated;
		if (!out->cancelled)
			out->stop = merge_stop(out->stop, anchor[k].stop);
	}
cleanup:
	out->elapsed_s = prsm_clock_seconds() - t0;
	free(anchor);
	return rc;
}

static void add_point(prsm_opt_front *f, const prsm_opt_problem *p, const prsm_opt_result *r,
                      double eps)
{
	if (r->status != PRSM_OPT_FEASIBLE || f->n_points >= PRSM_OPT_MAX_FRONT)
		return;
	prsm_opt_point *pt = &f->points[f->n_points++];
	memcpy(pt->x, r->x, sizeof pt->x);
	memcpy(pt->levels, r->levels, sizeof pt->levels);
	memcpy(pt->objectives, r->objectives, sizeof pt->objectives);
	memcpy(pt->constraints, r->constraints, (size_t)p->n_constraints * sizeof *r->constraints);
	pt->eps_limit = eps;
}

/* Drop dominated points and duplicates, sort by objective a. Two points are the same
 * trade-off when they differ by at most DUPLICATE_REL of the front's range (ideal to nadir) in
 * both objectives (two runs ending a rounding error apart); the one with the lower sum of
 * normalised objectives stays (the earlier one on a tie). */
#define DUPLICATE_REL 1e-4
static void filter(prsm_opt_front *f, const prsm_opt_problem *p)
{
	int a = f->objective_a, b = f->objective_b, kept = 0;
	double ra = range_of(f->ideal[a], f->nadir[a]), rb = range_of(f->ideal[b], f->nadir[b]);
	ra = isfinite(ra) ? ra : 1.0; /* no feasible anchor: no points either */
	rb = isfinite(rb) ? rb : 1.0;
	for (int i = 0; i < f->n_points; i++) {
		const double *fi = f->points[i].objectives;
		const double si = p->sense[a] * fi[a] / ra + p->sense[b] * fi[b] / rb;
		int drop = 0;
		for (int j = 0; j < f->n_points && !drop; j++) {
			if (j == i)
				continue;
			const double *fj = f->points[j].objectives;
			const double sj = p->sense[a] * fj[a] / ra + p->sense[b] * fj[b] / rb;
			if (prsm_opt_dominates(p, a, b, fj, fi))
				drop = 1;
			else if (fabs(fj[a] - fi[a]) <= DUPLICATE_REL * ra &&
			         fabs(fj[b] - fi[b]) <= DUPLICATE_REL * rb && (sj < si || (sj == si && j < i)))
				drop = 1; /* the same trade-off found twice */
		}
		if (drop) {
			f->dominated_removed++;
			continue;
		}
		f->points[kept++] = f->points[i];
	}
	/* points kept in the same array: dominance was judged against the full set above, and a
	 * dropped point never dominates a kept one alone (dominance is transitive) */
	f->n_points = kept;
	/* insertion sort: stable and deterministic, n <= 64 */
	for (int i = 1; i < f->n_points; i++) {
		prsm_opt_point t = f->points[i];
		int j = i - 1;
		while (j >= 0 && f->points[j].objectives[a] > t.objectives[a]) {
			f->points[j + 1] = f->points[j];
			j--;
		}
		f->points[j + 1] = t;
	}
}

int prsm_opt_pareto(prsm_opt_front *out, const prsm_opt_problem *p, const prsm_opt_options *o,
                    int objective_a, int objective_b, int points, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->objective_a = objective_a;
	out->objective_b = objective_b;
	if (objective_a < 0 || objective_b < 0 || objective_a >= p->n_objectives ||
	    objective_b >= p->n_objectives || objective_a == objective_b || points < 2 ||
	    points > PRSM_OPT_MAX_FRONT)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Pareto sweep: two different objectives and 2..%d points",
		                      PRSM_OPT_MAX_FRONT);
	double t0 = prsm_clock_seconds();
	prsm_opt_result *anchor = calloc(PRSM_OPT_MAX_OBJECTIVES, sizeof *anchor);
	prsm_opt_result *r = calloc(1, sizeof *r);
	int rc = 0;
	if (!anchor || !r) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	int want[PRSM_OPT_MAX_OBJECTIVES] = {0};
	want[objective_a] = want[objective_b] = 1;
	size_t used = 0, share = o->max_evaluations / (size_t)points;
	rc = anchors(anchor, out->ideal, out->nadir, p, o, want, share, &used, t0, err);
	out->anchor[0] = anchor[objective_a];
	out->anchor[1] = anchor[objective_b];
	add_point(out, p, &anchor[objective_a], NAN);
	add_point(out, p, &anchor[objective_b], NAN);
	out->stop = merge_stop(anchor[objective_a].stop, anchor[objective_b].stop);
	for (int k = 0; k < 2; k++) {
		const prsm_opt_result *an = &out->anchor[k];
		out->local_runs += an->runs;
		out->local_runs_feasible += an->runs_feasible;
		out->runs_truncated += an->runs_truncated;
	}
	if (rc)
		goto done;
	if (anchor[objective_a].status != PRSM_OPT_FEASIBLE ||
	    anchor[objective_b].status != PRSM_OPT_FEASIBLE)
		goto done; /* no trade-off to sweep: the front is what the anchors found */
	const int b = objective_b;
	/* objective b's levels, strictly between its values at the two anchors (minimised sense) */
	double best_b = p->sense[b] * anchor[b].objectives[b];
	double worst_b = p->sense[b] * anchor[objective_a].objectives[b];
	prsm_opt_options so = *o;
	so.scalarisation = PRSM_OPT_EPSILON;
	so.objective = objective_a;
	memset(so.eps_active, 0, sizeof so.eps_active);
	so.eps_active[b] = 1;
	so.range[b] = range_of(best_b, worst_b);
	for (int j = 1; j < points - 1; j++) {
		double level = worst_b + (best_b - worst_b) * j / (points - 1);
		so.eps_limit[b] = p->sense[b] * level;
		size_t left = o->max_evaluations > used ? o->max_evaluations - used : 1;
		int runs_left = points - 1 - j;
		rc = sub_run(r, p, &so, &used, left / (size_t)runs_left, t0, o, err);
		out->runs++;
		out->runs_feasible += r->status == PRSM_OPT_FEASIBLE;
		add_point(out, p, r, so.eps_limit[b]);
		out->stop = merge_stop(out->stop, r->stop);
		out->local_runs += r->runs;
		out->local_runs_feasible += r->runs_feasible;
		out->runs_truncated += r->runs_truncated;
		if (rc)
			break;
	}
done:
	filter(out, p);
	out->evaluations = used;
	out->cancelled = rc == PRSM_ECANCELLED;
	if (out->cancelled)
		out->stop = PRSM_OPT_STOP_CANCELLED;
cleanup:
	out->elapsed_s = prsm_clock_seconds() - t0;
	free(anchor);
	free(r);
	return rc;
}

int prsm_opt_front_lead(const prsm_opt_front *front, const prsm_opt_problem *p)
{
	int lead = -1;
	double best = INFINITY;
	for (int i = 0; i < front->n_points; i++) {
		double dmax = 0.0;
		for (int k = 0; k < 2; k++) {
			const double rg = front->nadir[k] - front->ideal[k];
			const double v = p->sense[k] * front->points[i].objectives[k] - front->ideal[k];
			dmax = fmax(dmax, rg > 0.0 ? v / rg : 0.0);
		}
		if (dmax < best) {
			best = dmax;
			lead = i;
		}
	}
	return lead;
}
