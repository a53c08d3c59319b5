/*
 * pareto.h: multi-objective optimisation on top of opt/optimize.h (issue 7): a normalised
 * weighted sum, and an epsilon-constraint sweep that returns a Pareto front of two objectives
 * (for the PRSM: efficiency against stiffness), each point with its variables and every
 * objective and constraint.
 *
 * Normalisation: each objective's single-objective optimum is found first (the anchors); the
 * payoff table gives, in the minimised sense (sense x f), the ideal (the best value of each
 * objective) and the nadir (its worst value at the other anchors); range = nadir - ideal (a tiny
 * positive value when the objectives do not conflict). The weighted sum minimises
 * sum w_k (sense_k f_k - ideal_k) / range_k. The sweep minimises objective a subject to
 * objective b being no worse than points - 2 levels evenly spaced strictly between its values at
 * the two anchors; the anchors and every feasible sweep result are pooled, dominated points and
 * duplicates (two points within 1e-4 of the ideal-to-nadir range in both objectives: the one
 * with the lower normalised sum stays) are removed and the rest sorted by objective a (in its
 * own unit, ascending).
 *
 * The evaluation budget o->max_evaluations is shared equally by the anchors and the sweep's
 * (or the weighted sum's) runs; progress counts over all of them. A cancel stops the sweep; the
 * front found so far is returned, flagged.
 */
#ifndef PRSM_OPT_PARETO_H
#define PRSM_OPT_PARETO_H

#include "opt/optimize.h"

#define PRSM_OPT_MAX_FRONT 64

typedef struct {
	double x[PRSM_OPT_MAX_CONTINUOUS];
	double levels[PRSM_OPT_MAX_DISCRETE];
	double objectives[PRSM_OPT_MAX_OBJECTIVES];   /* own units */
	double constraints[PRSM_OPT_MAX_CONSTRAINTS]; /* scaled violations */
	double eps_limit;            /* the level of objective b it was found at (own unit); NaN: an anchor */
} prsm_opt_point;

typedef struct {
	int n_points;                /* non-dominated, sorted by objective a */
	prsm_opt_point points[PRSM_OPT_MAX_FRONT];
	int objective_a, objective_b;
	prsm_opt_result anchor[2];   /* the single-objective optima of a and b */
	double ideal[PRSM_OPT_MAX_OBJECTIVES], nadir[PRSM_OPT_MAX_OBJECTIVES]; /* minimised sense */
	int runs, runs_feasible;     /* epsilon runs (the anchors not counted) */
	int dominated_removed;       /* feasible results dropped as dominated or duplicate */
	size_t evaluations;
	size_t local_runs;           /* NLopt runs of the anchors and every epsilon run */
	size_t local_runs_feasible;  /* of which the end point was feasible */
	size_t runs_truncated;       /* of which stopped by maxeval, maxtime or a forced stop */
	int stop;                    /* PRSM_OPT_STOP_* over every run: cancelled, else max_time when
	                                any run hit the time cap, else max_evaluations when any was
	                                truncated or used its budget, else converged (or all_pruned) */
	int cancelled;
	double elapsed_s;
} prsm_opt_front;

/* The anchors of the objectives with weight > 0 (or all when o->scalarisation is not
 * WEIGHTED_SUM), then the weighted sum with the normalisation they give. out is the weighted
 * run's result, with evaluations, runs, runs_feasible, runs_truncated and stop over the anchors
 * and the weighted run together; ideal and range (PRSM_OPT_MAX_OBJECTIVES each, minimised sense) receive the
 * normalisation used. Returns 0, PRSM_ECANCELLED (out holds the best so far), PRSM_EINVAL,
 * PRSM_ENOMEM. */
int prsm_opt_weighted_sum(prsm_opt_result *out, double *ideal, double *range,
                          const prsm_opt_problem *p, const prsm_opt_options *o, prsm_error *err);

/* The epsilon-constraint sweep of objective a against objective b with `points` levels in all
 * (2..PRSM_OPT_MAX_FRONT, the two anchors included). Returns 0, PRSM_ECANCELLED (out holds the
 * front so far), PRSM_EINVAL, PRSM_ENOMEM. */
int prsm_opt_pareto(prsm_opt_front *out, const prsm_opt_problem *p, const prsm_opt_options *o,
                    int objective_a, int objective_b, int points, prsm_error *err);

/* The point of a front a result leads with: the one closest to the ideal point in the
 * normalised Chebyshev distance max_k (sense_k f_k - ideal_k) / (nadir_k - ideal_k) over the two
 * objectives (a zero range counts 0); the first such point on ties. -1 when the front is empty. */
int prsm_opt_front_lead(const prsm_opt_front *front, const prsm_opt_problem *p);

/* 1 when point u dominates v on objectives a and b of p (no worse in both, better in one). */
int prsm_opt_dominates(const prsm_opt_problem *p, int a, int b, const double *fu, const double *fv);

#endif
