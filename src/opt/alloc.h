/*
 * alloc.h: tolerance allocation with a linear stack model (issue 7, item 4;
 * the closed form for power-law costs is in docs/allocation.md).
 *
 * Minimise the total cost sum_i cost_i(T_i) of tolerance half-widths T_i (each in its own unit)
 * within bounds t_min_i <= T_i <= t_max_i, subject to one linear stack constraint per output:
 *   RSS         sum_i (c_oi T_i)^2 <= L_o^2
 *   worst case  sum_i |c_oi| T_i   <= L_o
 * c_oi is the output o's change per unit of tolerance i (output unit per tolerance unit), L_o
 * the assembly tolerance (output unit). Cost models (cost units): reciprocal-power A + B/T^k
 * (reciprocal k = 1, reciprocal-squared k = 2) and exponential A + B e^(-m T).
 *
 * The exact solver uses the KKT conditions: for multipliers lambda_o >= 0 every tolerance
 * minimises cost_i(T) + a_i T^2 (RSS, a_i = sum_o lambda_o c_oi^2) or cost_i(T) + a_i T (worst
 * case, a_i = sum_o lambda_o |c_oi|) in closed form (a power law, or Lambert W0 for the
 * exponential cost with RSS), clamped to its bounds (exact: each one-dimensional problem is
 * convex); each lambda_o is a one-dimensional root (Brent on log lambda) of its constraint held
 * with equality, or 0 when the constraint is slack; the allocation is computed from ln lambda
 * (log-sum-exp over the constraints), so any cost scale is searched without overflow. Several
 * constraints: one sweep of those exact roots (coordinate ascent on the concave dual), then a
 * projected Newton method on the dual (normalised multipliers mu_o = lambda_o L_o^q >= 0, the
 * dual's gradient the relative violations and its Hessian from dT/da in closed form,
 * Cholesky with a small ridge, backtracking on the dual value) until every constraint holds to
 * 1e-12 relative with complementary slackness; if Newton stalls, further coordinate sweeps, and
 * if those stall, SLSQP. NLopt (SLSQP or COBYLA on log T) solves the same problem as a check.
 * The solve polls the problem's cancel flag and honours its time cap between iterations (and
 * NLopt's maxtime and forced stop).
 *
 * The yield rule (the allocation document's targets): an output with spec [L, U] (one or both
 * sides) and mean mu, normal with sd sigma, has yield Phi((U - mu)/sigma) - Phi((L - mu)/sigma);
 * a target fixes the largest sigma (a 1-D root). A tolerance +-T is +-k sd of its distribution
 * (k = 3 for the normal shorthand), so RSS reads sum (c T / k)^2 <= sigma_max^2.
 *
 * No JSON, no I/O. Plain data; nothing here allocates but the NLopt solver's own workspace.
 */
#ifndef PRSM_OPT_ALLOC_H
#define PRSM_OPT_ALLOC_H

#include <stddef.h>

#include "mc/stats.h"
#include "util/cancel.h"
#include "util/error.h"

#define PRSM_ALLOC_MAX_TOLERANCES 64
#define PRSM_ALLOC_MAX_CONSTRAINTS 16

typedef enum {
	PRSM_ALLOC_COST_RECIPROCAL = 0,          /* A + B / T */
	PRSM_ALLOC_COST_RECIPROCAL_SQUARED = 1,  /* A + B / T^2 */
	PRSM_ALLOC_COST_RECIPROCAL_POWER = 2,    /* A + B / T^k */
	PRSM_ALLOC_COST_EXPONENTIAL = 3          /* A + B exp(-m T) */
} prsm_alloc_cost_kind;

typedef struct {
	prsm_alloc_cost_kind kind;
	double fixed;        /* A >= 0: cost units, independent of T */
	double coefficient;  /* B > 0: cost units x (tolerance unit)^k; exponential: cost units */
	double power;        /* k > 0 (reciprocal 1, reciprocal-squared 2; set by the kind) */
	double rate;         /* m > 0: per tolerance unit (exponential) */
} prsm_alloc_cost;

typedef enum { PRSM_ALLOC_RSS = 0, PRSM_ALLOC_WORST_CASE = 1 } prsm_alloc_stack;

typedef enum {
	PRSM_ALLOC_SOLVER_EXACT = 0,   /* KKT with 1-D roots on the multipliers */
	PRSM_ALLOC_SOLVER_SLSQP = 1,   /* NLopt LD_SLSQP on log T */
	PRSM_ALLOC_SOLVER_COBYLA = 2   /* NLopt LN_COBYLA on log T */
} prsm_alloc_solver;

typedef struct {
	size_t n;                    /* tolerances, 1..PRSM_ALLOC_MAX_TOLERANCES */
	size_t m;                    /* constraints, 1..PRSM_ALLOC_MAX_CONSTRAINTS */
	prsm_alloc_stack stack;
	prsm_alloc_cost cost[PRSM_ALLOC_MAX_TOLERANCES];
	double t_min[PRSM_ALLOC_MAX_TOLERANCES]; /* tolerance unit, >= 0 */
	double t_max[PRSM_ALLOC_MAX_TOLERANCES]; /* tolerance unit, > t_min; INFINITY: none */
	double c[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES]; /* output unit per tolerance unit */
	double limit[PRSM_ALLOC_MAX_CONSTRAINTS]; /* L_o > 0, output unit */
	prsm_cancel_flag *cancel;        /* may be NULL: polled between iterations (PRSM_ECANCELLED) */
	double max_time_s;           /* 0: none; the solve's own time cap (PRSM_ENOCONVERGE, time_cap set) */
} prsm_alloc_problem;

typedef struct {
	double t[PRSM_ALLOC_MAX_TOLERANCES];      /* allocated half-widths, tolerance unit */
	double cost[PRSM_ALLOC_MAX_TOLERANCES];   /* cost units */
	int at_bound[PRSM_ALLOC_MAX_TOLERANCES];  /* -1 at t_min, +1 at t_max, 0 inside */
	double total_cost;                        /* cost units */
	double multiplier[PRSM_ALLOC_MAX_CONSTRAINTS]; /* lambda_o (exact solver; NAN for NLopt) */
	double stack[PRSM_ALLOC_MAX_CONSTRAINTS]; /* the constraint's left side: RSS sqrt(sum (cT)^2),
	                                             worst case sum |c| T; output unit */
	size_t evaluations;                       /* closed-form allocations or NLopt evaluations */
	int sweeps;                               /* coordinate-ascent sweeps (exact solver) */
	prsm_alloc_solver solver;                 /* what produced it */
	int time_cap;                             /* 1: the solve stopped at p->max_time_s */
} prsm_alloc_solution;

/* Cost of one tolerance at half-width t (cost units; +inf at t = 0 for the reciprocal models). */
double prsm_alloc_cost_eval(const prsm_alloc_cost *c, double t);

/* Check p: sizes, finite positive coefficients, bounds, every tolerance either constrained or
 * bounded above, and feasibility (every constraint strictly met with every tolerance at t_min).
 * Returns 0 or PRSM_EINVAL with err saying which; its pointer names the tolerance or the
 * constraint as the allocation document lays them out ("/allocate/i", "/constraints/o"). */
int prsm_alloc_check(const prsm_alloc_problem *p, prsm_error *err);

/* Solve p (see the top of the file). Returns 0, PRSM_EINVAL (prsm_alloc_check, or a constraint
 * the lower bounds cannot meet: pointer "/constraints/o"), PRSM_ECANCELLED (p->cancel), or
 * PRSM_ENOCONVERGE (the time cap ran out: out->time_cap 1; NLopt failed; or the dual methods
 * did not settle: err says how far). */
int prsm_alloc_solve(prsm_alloc_solution *out, const prsm_alloc_problem *p, prsm_alloc_solver solver,
                     prsm_error *err);

/* The constraint's left side for half-widths t (RSS: sqrt(sum (c T)^2); worst case sum |c| T). */
double prsm_alloc_stack_value(const prsm_alloc_problem *p, size_t o, const double *t);

/* Fraction out of spec of a normal(mean, sigma) output: Phi((L - mean)/sigma) +
 * Q((U - mean)/sigma) over the sides the spec has, computed from the tails (no cancellation);
 * sigma 0: 0 or 1. */
double prsm_alloc_normal_out_fraction(const prsm_spec *spec, double mean, double sigma);

/* The largest sigma (output unit) with prsm_alloc_normal_out_fraction(spec, mean, sigma) =
 * out_fraction (= 1 - target yield, in (0, 0.5)): closed form for a one-sided spec, a Brent root
 * on log sigma within [d/z(q/2), d/z(q)] (d the nearer limit's distance) for two sides. Returns 0,
 * or PRSM_EINVAL when the mean is not strictly inside the spec or the fraction is out of range. */
int prsm_alloc_sigma_for_out_fraction(double *sigma, const prsm_spec *spec, double mean,
                                      double out_fraction, prsm_error *err);

/* Worst case: T_asm = min(U - mean, mean - L) over the sides the spec has (output unit).
 * PRSM_EINVAL when the mean is not strictly inside. */
int prsm_alloc_worst_case_limit(double *limit, const prsm_spec *spec, double mean, prsm_error *err);

const char *prsm_alloc_cost_name(prsm_alloc_cost_kind k);
const char *prsm_alloc_stack_name(prsm_alloc_stack s);
const char *prsm_alloc_solver_name(prsm_alloc_solver s);

#endif
