/*
 * alloc_mc.h: tolerance allocation on a tolerance study: the linear stack model taken from the
 * study's own model, the allocation at a target yield, and its Monte Carlo verification and
 * correction with common random numbers (issue 7, item 4).
 *
 * The linear model (prsm_alloc_model) of output o: nominal mu_o = the model at every
 * distribution's centre; per allocated tolerance i its reference half-width T_ref,i (the study's
 * distribution, prsm_dist_halfwidth), k_i = half-width / sd (3 for the {tol, cpk 1} normal,
 * sqrt 3 for a uniform; a radial magnitude counts with sqrt(E[R^2]/2), its variance along any
 * direction) and the sensitivity c_oi (output unit per tolerance unit): central differences of
 * the model over each variable's reference half-width (+-T_ref; a radial magnitude at +T_ref in
 * its worst of 8 directions), every variable of the tolerance (every roller, every start)
 * combined as the root sum of squares (RSS) or the sum of absolute values (worst case: then
 * c_oi T_ref,i is the study's own one-at-a-time stack figure). Tolerances of the study that
 * are not allocated stay as they are and use up part of the budget: their variance (RSS) or
 * their worst-case sum.
 *
 * The constraint of output o, the yield rule: RSS, sum_i (3 c_oi T_i / k_i)^2 <= T_asm,o^2 - 9
 * var_fixed,o with T_asm,o = 3 sigma_max,o, sigma_max the largest sd of a normal output centred
 * on mu_o whose yield against the spec is the target (prsm_alloc_sigma_for_out_fraction);
 * worst case, sum_i |c_oi| T_i <= T_asm,o - wc_fixed,o with T_asm,o = min(U - mu, mu - L). An
 * assembly tolerance may also be given directly (no yield target): a hard limit that the
 * correction never scales, checked on every step's linear stack (assembly_ok).
 *
 * The Monte Carlo correction: the study is run with the allocated widths (each distribution
 * scaled about its centre), same seed, same samples, so the yield is a deterministic function
 * of the widths (common random numbers) and threads do not change it. Every limit T_asm,o that
 * comes from a yield target is multiplied by one factor f (f = 1 first): if some output misses
 * its target, f shrinks by 0.8 until every target is met; if all are met, f grows by 1.25 until
 * one is missed (or every tolerance sits at its upper bound, or every target's constraint is
 * slack, so a larger f changes nothing); then a safeguarded secant on ln f between the two
 * (clamped to the inner 10..90 % of the bracket) until the bracket is within the relative width
 * asked for. Each f is re-allocated exactly. The result is the largest f that met every target:
 * the cheapest allocation the Monte Carlo accepts.
 *
 * "Met" is decided on the sample's evidence, not on its point estimate: a target is met when
 * the lower end of the yield's 95 % Wilson score interval is at or above it, i.e. when the score
 * test rejects "the true yield is below the target" at the one-sided 2.5 % level. A point
 * estimate at or just above the target says nothing (the true yield is below it about half the
 * time); this rule accepts an allocation whose true yield misses its target at most 2.5 % of
 * the time, and reports that confidence (mc_confidence: Phi of the score statistic
 * (y - p0) / sqrt(p0 (1 - p0) / n) at the target p0) with every run. The price of being sure
 * is a margin: fewer samples make the accepted allocation tighter (dearer), never wrong.
 */
#ifndef PRSM_OPT_ALLOC_MC_H
#define PRSM_OPT_ALLOC_MC_H

#include "mc/study.h"
#include "opt/alloc.h"
#include "util/cancel.h"
#include "util/progress.h"

#define PRSM_ALLOC_MAX_STEPS 32      /* the linear allocation and up to 31 corrections */

typedef struct {
	size_t n, m;                     /* allocated tolerances, constrained outputs */
	prsm_alloc_stack stack;
	prsm_alloc_solver solver;
	prsm_alloc_cost cost[PRSM_ALLOC_MAX_TOLERANCES];
	double t_min[PRSM_ALLOC_MAX_TOLERANCES];  /* tolerance unit */
	double t_max[PRSM_ALLOC_MAX_TOLERANCES];  /* tolerance unit; INFINITY: none */
	double t_ref[PRSM_ALLOC_MAX_TOLERANCES];  /* reference half-width, tolerance unit */
	double k[PRSM_ALLOC_MAX_TOLERANCES];      /* half-width / sd, dimensionless */
	double c[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES]; /* output unit per tolerance unit */
	double nominal[PRSM_ALLOC_MAX_CONSTRAINTS];   /* mu_o, output unit */
	double fixed_var[PRSM_ALLOC_MAX_CONSTRAINTS]; /* variance of the tolerances kept, output unit^2 */
	double fixed_wc[PRSM_ALLOC_MAX_CONSTRAINTS];  /* their worst-case sum, output unit */
	prsm_spec spec[PRSM_ALLOC_MAX_CONSTRAINTS];
	int has_target[PRSM_ALLOC_MAX_CONSTRAINTS];   /* 1: out_fraction is the target; 0: assembly_tol given */
	double out_fraction[PRSM_ALLOC_MAX_CONSTRAINTS]; /* 1 - target yield */
	double assembly_tol[PRSM_ALLOC_MAX_CONSTRAINTS]; /* given T_asm,o (output unit) when !has_target */
} prsm_alloc_model;

/* One allocation: the limits at scale f, the solution, the linear prediction and (when run)
 * the Monte Carlo figures. */
typedef struct {
	double scale;                                       /* f */
	double assembly_tol[PRSM_ALLOC_MAX_CONSTRAINTS];    /* f T_asm,o (a target) or the given T_asm,o, output unit */
	double limit[PRSM_ALLOC_MAX_CONSTRAINTS];           /* the stack limit solved for: T_asm,o less the
	                                                       kept tolerances' share, output unit */
	double sigma_max[PRSM_ALLOC_MAX_CONSTRAINTS];       /* T_asm,o / 3 (RSS); NAN for worst case */
	prsm_alloc_solution sol;
	double predicted_sd[PRSM_ALLOC_MAX_CONSTRAINTS];    /* linear sd of the output, output unit */
	double predicted_yield[PRSM_ALLOC_MAX_CONSTRAINTS]; /* normal at mu_o with that sd */
	int has_mc;
	size_t samples;                                     /* samples kept */
	double mc_mean[PRSM_ALLOC_MAX_CONSTRAINTS], mc_sd[PRSM_ALLOC_MAX_CONSTRAINTS]; /* output unit */
	double mc_yield[PRSM_ALLOC_MAX_CONSTRAINTS], mc_low95[PRSM_ALLOC_MAX_CONSTRAINTS],
	       mc_high95[PRSM_ALLOC_MAX_CONSTRAINTS];      /* fraction in spec, 95 % Wilson interval */
	double mc_confidence[PRSM_ALLOC_MAX_CONSTRAINTS];   /* one-sided confidence that the true yield
	                                                       meets the target (NAN without one) */
	int mc_meets[PRSM_ALLOC_MAX_CONSTRAINTS];           /* Wilson lower end >= target (no target: 1) */
	int mc_interval[PRSM_ALLOC_MAX_CONSTRAINTS];        /* prsm_alloc_yield_interval: where the yield came from */
	int mc_method[PRSM_ALLOC_MAX_CONSTRAINTS];          /* prsm_rare_method: PRSM_RARE_MC for the count */
	int assembly_ok;                                    /* every given T_asm,o holds (linear stack) */
	int meets;                                          /* every target met (MC when run: mc_meets,
	                                                       else linear) and assembly_ok */
} prsm_alloc_step;

/* The yield a correction step judges a target on (issue 21 item 4): the Monte Carlo count with
 * its Wilson interval, or, when the study spec's yield_method is not mc, its rare-event
 * estimate (the study's rare_event section) with the sum of the sides' intervals, or a FORM /
 * SORM point estimate (judged on the point, as no interval exists). */
typedef enum {
	PRSM_ALLOC_YIELD_WILSON = 0,
	PRSM_ALLOC_YIELD_RARE = 1,
	PRSM_ALLOC_YIELD_RARE_POINT = 2
} prsm_alloc_yield_interval;

typedef enum {
	PRSM_ALLOC_STOP_LINEAR = 0,      /* no Monte Carlo asked for */
	PRSM_ALLOC_STOP_CONVERGED = 1,   /* the bracket on f closed, or every tolerance at its upper bound */
	PRSM_ALLOC_STOP_MAX_CORRECTIONS = 2,
	PRSM_ALLOC_STOP_INFEASIBLE = 3,  /* f shrank until the lower bounds could not meet the limits */
	PRSM_ALLOC_STOP_TIME_CAP = 4,
	PRSM_ALLOC_STOP_CANCELLED = 5
} prsm_alloc_stop;

const char *prsm_alloc_stop_name(prsm_alloc_stop s);

typedef struct {
	size_t group[PRSM_ALLOC_MAX_TOLERANCES];    /* the study tolerance (group) of each allocated one */
	size_t output[PRSM_ALLOC_MAX_CONSTRAINTS];  /* the study output of each constraint */
	int verify;                                 /* run the Monte Carlo correction */
	int max_corrections;                        /* Monte Carlo runs after the first */
	double scale_rtol;                          /* bracket width on f that ends the correction */
	prsm_cancel_flag *cancel;                       /* may be NULL */
	prsm_progress_fn progress;                  /* may be NULL: samples done / planned, best cost */
	void *progress_ctx;
	double max_time_s;                          /* 0: none */
	/* who runs the correction studies (mc/study.h: e.g. over the ranks of an MPI job) and the
	 * study document the study was loaded from; NULL: this process */
	const prsm_study_service *service;
	const char *study_source;
	size_t study_source_len;
} prsm_alloc_mc_options;

typedef struct {
	prsm_alloc_step steps[PRSM_ALLOC_MAX_STEPS];
	int n_steps;
	int best;                 /* index of the reported step (-1 when none) */
	int converged;            /* the reported step meets every target and the correction ended normally */
	prsm_alloc_stop stop;
	size_t samples_total;     /* Monte Carlo samples of every run */
	double elapsed_s;
} prsm_alloc_mc_result;

/* The constraint limits at scale f and the allocation problem: f multiplies the T_asm,o that
 * come from yield targets; an assembly tolerance given directly is a hard limit and stays as
 * given. Returns 0 or PRSM_EINVAL (the nominal is outside a spec: pointer
 * "/constraints/o/spec"; the tolerances kept use up the budget: "/constraints/o"). */
int prsm_alloc_model_problem(prsm_alloc_problem *p, prsm_alloc_step *step, const prsm_alloc_model *md,
                             double scale, prsm_error *err);

/* Allocate at scale f and fill the linear prediction of step. cancel (may be NULL) and
 * max_time_s (0: none) go to the solve. Returns as prsm_alloc_solve. */
int prsm_alloc_model_allocate(prsm_alloc_step *step, const prsm_alloc_model *md, double scale,
                              prsm_cancel_flag *cancel, double max_time_s, prsm_error *err);

/* Fill md's t_ref, k, c, nominal, fixed_var and fixed_wc from the study s (md->n, md->m and
 * md->stack set, the groups and outputs in o). Evaluates the model 2 per variable (8 per radial
 * magnitude) + 1 times. Returns 0, PRSM_EINVAL (a tolerance of a kind that cannot be scaled, a
 * zero half-width), PRSM_ENOMEM, or the model's code when it fails at the centre or a half-width. */
int prsm_alloc_mc_linearise(prsm_alloc_model *md, const prsm_study *s, const prsm_alloc_mc_options *o,
                            prsm_error *err);

/* Scale distribution d about its centre by r > 0 (half-width times r). PRSM_EINVAL for a
 * lognormal, whose half-width does not scale with one parameter. */
int prsm_alloc_dist_scale(prsm_dist *out, const prsm_dist *d, double r);

/* Allocate, verify and correct (see the top). s is changed while it runs (the distributions,
 * the output specs, no stop targets, no sensitivities) and its distributions are restored
 * before returning. out is large: allocate it on the heap. o->cancel and o->max_time_s reach
 * every allocation's solve as well as the Monte Carlo runs. Returns 0 with out->best >= 0 (also
 * when the target was not met: out->converged 0; when the time cap ran out before the first
 * Monte Carlo run finished, the linear allocation unverified, stop time_cap), PRSM_ECANCELLED
 * (out holds the steps so far, out->best -1 when there is none), PRSM_EINVAL (the linear
 * allocation at f = 1 is impossible), PRSM_ENOCONVERGE (the time cap ran out before the linear
 * allocation was solved, or it did not settle), or the engine's code. */
int prsm_alloc_mc_run(prsm_alloc_mc_result *out, prsm_study *s, const prsm_alloc_model *md,
                      const prsm_alloc_mc_options *o, prsm_error *err);

#endif
