/*
 * progress.h: how a long computation (a Monte Carlo run, an optimisation, an allocation) tells
 * its caller how far it is. One struct for every kind of work, so the job machinery (src/job)
 * stores and serves it the same way whatever runs.
 */
#ifndef PRSM_UTIL_PROGRESS_H
#define PRSM_UTIL_PROGRESS_H

#include <math.h>
#include <stddef.h>

typedef struct {
	size_t done;            /* samples (Monte Carlo) or objective evaluations (optimisation) done */
	size_t planned;         /* the cap of the current run, same unit */
	double interval_width;  /* Monte Carlo with targets: the stop rule's current figure of the
	                           target furthest from its goal (standard error in the output's unit,
	                           coefficient of variation, or width of the yield's 95 % Wilson
	                           interval); NAN when the run has no target */
	double interval_goal;   /* that target's goal, same unit; NAN when none */
	double best;            /* optimisation: best feasible objective so far (the kind's unit);
	                           NAN when none yet or not an optimisation */
	const char *phase;      /* a static string naming the phase that runs when the work has
	                           several (a study: "monte_carlo", "rare_events", "sobol"); NULL:
	                           the work's only phase */
	const char *unit;       /* a static string: what done and planned count when it is not the
	                           job kind's unit ("evaluations", "sweep_points", "basin_cells",
	                           "analyses"); NULL: the kind's */
} prsm_progress;

#define PRSM_PROGRESS_INIT {0, 0, NAN, NAN, NAN, NULL, NULL}

/* Called from the thread that runs the work; must be quick and must not call back into it. */
typedef void (*prsm_progress_fn)(void *ctx, const prsm_progress *p);

#endif
