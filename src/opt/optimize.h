/*
 * optimize.h: a generic mixed-integer optimiser over a problem given by callbacks (issue 7,
 * DESIGN.md "Optimisation").
 *
 * A problem has continuous variables with bounds, discrete variables with explicit value sets
 * (levels), objectives in their own units (each minimised or maximised) and inequality
 * constraints given as scaled violations g (feasible when g <= 0, e.g. (value - limit)/limit).
 * The discrete variables are enumerated in an outer loop, lexicographically (the first variable
 * slowest); a combination is skipped when the problem's prune callback says that no point of
 * the continuous box can make it feasible (a cheap bound, e.g. more rollers than fit the most
 * favourable geometry). Each remaining combination is solved as a continuous NLopt problem
 * (COBYLA by default; SLSQP, MMA or AUGLAG selectable; gradients for SLSQP and MMA by central
 * finite differences unless the problem gives exact ones) from `multistart` randomised Sobol
 * points of the box: GSL's gsl_qrng_sobol sequence (0.5, 0.5, ...; then 0.75/0.25, ...) with a
 * Cranley-Patterson rotation, u = frac(sobol + shift), the shift uniform on [0, 1)^n drawn from
 * the Philox stream (seed, combination index) of util/rng.h: each combination gets its own
 * shift, a seed gives the same starts every time, another seed other (equally well spread)
 * starts. The evaluation budget is shared out over the remaining runs as it goes (what an
 * early-converged run leaves goes to the next), and NLopt's maxeval and maxtime are always set.
 *
 * Every evaluation's constraints are checked here, never trusted from NLopt's return code: a
 * point is feasible when every g <= 0 (the raw limits, no tolerance). constraint_tol only steers
 * the solver: NLopt sees each constraint as g + constraint_tol <= 0 (its own tolerance 0), so
 * the points it converges to sit that far inside an active limit instead of a rounding error
 * outside it (where gradient methods such as SLSQP end, and where our check would reject them).
 * A pass/fail constraint should therefore report a negative value when met (e.g. -1), not 0.
 * The reported point is the
 * best evaluated feasible point, re-evaluated at the end (not after a cancel: the stored
 * evaluation is reported as it is, since a cancelled problem may not evaluate again); with no
 * feasible point, the least violating one (status PRSM_OPT_INFEASIBLE, the violations in
 * `constraints`). Stochastic algorithms are seeded with nlopt_srand in the calling thread before
 * every run, so the same problem, options and seed give a bit-identical result (unless the time
 * cap stops it). Cancellation: *cancel is polled in every evaluation, which then calls
 * nlopt_force_stop; the best feasible point so far is still returned, flagged.
 *
 * A local run is "truncated" when it stopped on its evaluation share (NLOPT_MAXEVAL_REACHED),
 * the time cap or a forced stop (budget used up, cancel) rather than on its tolerances; the stop
 * reason says "converged" only when no run was truncated.
 *
 * Multi-objective problems are scalarised by the options: one objective, a normalised weighted
 * sum (each objective as (sense f - ideal)/range), or one objective subject to epsilon limits on
 * others (the Pareto sweep of opt/pareto.h).
 *
 * Nothing here allocates memory that outlives the call; prsm_opt_run allocates its NLopt objects
 * and the Sobol generator and frees them before it returns. No JSON.
 */
#ifndef PRSM_OPT_OPTIMIZE_H
#define PRSM_OPT_OPTIMIZE_H

#include <stddef.h>

#include "util/cancel.h"
#include "util/error.h"
#include "util/progress.h"

#define PRSM_OPT_MAX_CONTINUOUS 8
#define PRSM_OPT_MAX_DISCRETE 4
#define PRSM_OPT_MAX_LEVELS 64
#define PRSM_OPT_MAX_OBJECTIVES 4
#define PRSM_OPT_MAX_CONSTRAINTS 24
#define PRSM_OPT_MAX_COMBINATIONS 100000
#define PRSM_OPT_NAME_MAX 48

/* Local algorithms (NLopt). */
enum { PRSM_OPT_COBYLA = 0, PRSM_OPT_SLSQP = 1, PRSM_OPT_MMA = 2, PRSM_OPT_AUGLAG = 3 };
/* "cobyla", "slsqp", "mma", "auglag", NULL: indexed by PRSM_OPT_*. */
extern const char *const prsm_opt_algorithm_names[];

enum { PRSM_OPT_MINIMISE = 1, PRSM_OPT_MAXIMISE = -1 };

/* Scalarisation of the objectives. */
enum {
	PRSM_OPT_SINGLE = 0,       /* options.objective alone */
	PRSM_OPT_WEIGHTED_SUM = 1, /* sum of weight_k (sense_k f_k - ideal_k) / range_k */
	PRSM_OPT_EPSILON = 2       /* options.objective, with options.eps_* limits on others */
};

/* Outcome. */
enum { PRSM_OPT_FEASIBLE = 0, PRSM_OPT_INFEASIBLE = 1, PRSM_OPT_NOTHING = 2 };
/* Why the search stopped. */
enum {
	PRSM_OPT_STOP_CONVERGED = 0,   /* every run met its tolerances (none truncated) */
	PRSM_OPT_STOP_MAXEVAL = 1,     /* the budget was used up, or a run stopped at its share */
	PRSM_OPT_STOP_MAXTIME = 2,     /* the time cap */
	PRSM_OPT_STOP_CANCELLED = 3,   /* *cancel was set */
	PRSM_OPT_STOP_ALL_PRUNED = 4   /* no combination could be feasible */
};
/* "converged", "max_evaluations", "max_time", "cancelled", "all_pruned", NULL. */
extern const char *const prsm_opt_stop_names[];

/*
 * Evaluate the problem at the continuous point x (n_continuous values) and the discrete levels
 * (n_discrete values): objectives (n_objectives, each in its own unit) and constraints
 * (n_constraints scaled violations, feasible when <= 0; a pass/fail one negative when met).
 * When grad_objectives is not NULL (the problem has exact gradients and the algorithm needs
 * them) also write the gradients, row-major
 * (n_objectives x n_continuous and n_constraints x n_continuous). Entries that cannot be computed
 * may be NaN. When the problem has_surrogate, constraints holds 2 n_constraints values: the
 * checked violations first, then the smooth stand-ins the solver sees instead (e.g. a smoothed
 * Monte Carlo yield for a piecewise-constant one: opt/robust.h); feasibility, the best point and
 * the result always use the checked ones. Returns 0, or nonzero when the point cannot be
 * evaluated at all (it then counts as infeasible, whatever the values say). Must be deterministic.
 */
typedef int (*prsm_opt_eval_fn)(void *ctx, const double *x, const double *levels,
                                double *objectives, double *constraints,
                                double *grad_objectives, double *grad_constraints);

/* 1 when no x in [lower, upper] can make the combination `levels` feasible; 0 otherwise. */
typedef int (*prsm_opt_prune_fn)(void *ctx, const double *levels, const double *lower,
                                 const double *upper);

typedef struct {
	int n_continuous;
	char continuous_name[PRSM_OPT_MAX_CONTINUOUS][PRSM_OPT_NAME_MAX];
	double lower[PRSM_OPT_MAX_CONTINUOUS], upper[PRSM_OPT_MAX_CONTINUOUS]; /* finite, lower < upper */
	int n_discrete;
	char discrete_name[PRSM_OPT_MAX_DISCRETE][PRSM_OPT_NAME_MAX];
	int n_levels[PRSM_OPT_MAX_DISCRETE];
	double levels[PRSM_OPT_MAX_DISCRETE][PRSM_OPT_MAX_LEVELS];
	int n_objectives;
	char objective_name[PRSM_OPT_MAX_OBJECTIVES][PRSM_OPT_NAME_MAX];
	int sense[PRSM_OPT_MAX_OBJECTIVES];  /* PRSM_OPT_MINIMISE or PRSM_OPT_MAXIMISE */
	int n_constraints;
	char constraint_name[PRSM_OPT_MAX_CONSTRAINTS][PRSM_OPT_NAME_MAX];
	int has_gradient;                    /* eval writes exact gradients (of the solver's values) when asked */
	int has_surrogate;                   /* eval also writes the solver's stand-in of each constraint */
	prsm_opt_eval_fn eval;
	prsm_opt_prune_fn prune;             /* may be NULL: nothing is pruned */
	void *ctx;
} prsm_opt_problem;

typedef struct {
	int algorithm;               /* PRSM_OPT_COBYLA ... */
	size_t max_evaluations;      /* budget over every combination and start, >= 1 */
	double max_time_s;           /* wall-clock cap of the whole search, s, > 0 */
	int multistart;              /* local runs per combination, from Sobol points, >= 1 */
	unsigned long seed;          /* the starts' rotation (Philox key) and nlopt_srand */
	double xtol_rel;             /* NLopt's relative x tolerance, - */
	double ftol_rel;             /* NLopt's relative f tolerance, - */
	double constraint_tol;       /* the solver's margin: NLopt sees g + this <= 0 (steers the
	                                solver only; feasibility is always g <= 0), >= 0, - */
	double fd_step_rel;          /* central-difference step as a fraction of the bounds' width */
	prsm_cancel_flag *cancel;        /* may be NULL; nonzero stops the search */
	prsm_progress_fn progress;   /* may be NULL */
	void *progress_ctx;
	size_t progress_offset;      /* added to done (a sweep's earlier runs), evaluations */
	size_t progress_planned;     /* reported as planned; 0: max_evaluations */
	/* scalarisation */
	int scalarisation;           /* PRSM_OPT_SINGLE ... */
	int objective;               /* the objective of SINGLE and EPSILON */
	double weight[PRSM_OPT_MAX_OBJECTIVES];  /* WEIGHTED_SUM, >= 0 */
	double ideal[PRSM_OPT_MAX_OBJECTIVES];   /* in the minimised sense (sense f), own unit */
	double range[PRSM_OPT_MAX_OBJECTIVES];   /* > 0, own unit */
	int eps_active[PRSM_OPT_MAX_OBJECTIVES]; /* EPSILON: f_k must be no worse than eps_limit_k */
	double eps_limit[PRSM_OPT_MAX_OBJECTIVES]; /* own unit */
} prsm_opt_options;

/* COBYLA, 2000 evaluations, 60 s, 2 starts, seed 1, tolerances 1e-6, steps 1e-6, single. */
void prsm_opt_options_init(prsm_opt_options *o);

typedef struct {
	int status;                  /* PRSM_OPT_FEASIBLE, _INFEASIBLE or _NOTHING (never evaluated) */
	int stop;                    /* PRSM_OPT_STOP_* */
	int cancelled;               /* 1 when *cancel stopped it */
	double x[PRSM_OPT_MAX_CONTINUOUS];           /* n_continuous used, the rest 0 */
	double levels[PRSM_OPT_MAX_DISCRETE];        /* n_discrete used, the rest 0 */
	double objectives[PRSM_OPT_MAX_OBJECTIVES];   /* own units; n_objectives used, the rest 0 */
	double constraints[PRSM_OPT_MAX_CONSTRAINTS]; /* scaled violations g; n_constraints used */
	double scalar;               /* the scalarised objective that was minimised */
	size_t evaluations;          /* calls of eval (finite-difference ones included) */
	size_t combinations;         /* discrete combinations in all */
	size_t pruned;               /* of which skipped by the prune callback */
	size_t runs;                 /* NLopt runs */
	size_t runs_feasible;        /* runs whose returned point we found feasible */
	size_t runs_truncated;       /* runs stopped by maxeval, maxtime or a forced stop */
	double elapsed_s;            /* wall clock, s */
} prsm_opt_result;

/* The scalarised objective of objectives f under options o (what the search minimises). */
double prsm_opt_scalar(const prsm_opt_problem *p, const prsm_opt_options *o, const double *f);

/* Run the search. Returns 0 (out->status says whether a feasible point was found),
 * PRSM_ECANCELLED (out holds the best point so far, out->cancelled = 1), PRSM_EINVAL (bad
 * problem or options; err says which), PRSM_ENOMEM. */
int prsm_opt_run(prsm_opt_result *out, const prsm_opt_problem *p, const prsm_opt_options *o,
                 prsm_error *err);

#endif
