/*
 * rare.h: the rare-event engine (issue 21, docs/rare-events.md): estimators of a small failure
 * probability P_f = P(g(X) <= 0) of a limit state g over the engine's random variables X.
 *
 *   FORM    HL-RF iteration with Zhang & Der Kiureghian's merit function and an Armijo line
 *           search, in the standard normal space U; reliability index beta, P_f = Phi(-beta),
 *           the design point u* and x*, the importance factors; optional extra starting points
 *           give further design points (series systems).
 *   SORM    principal curvatures at the design point from a finite-difference Hessian in U,
 *           then Breitung's, Hohenbichler-Rackwitz's and Tvedt's formulas.
 *   IS      importance sampling around the design point(s): a standard normal shifted to each
 *           u* (a mixture when there are several), estimate, standard error, CoV, 95 % interval,
 *           stop rule on a CoV target. With no centre it is plain Monte Carlo in U.
 *   subset  subset simulation (Au & Beck 2001) with the modified Metropolis algorithm,
 *           intermediate thresholds at the p0 sample quantile, CoV by Au & Beck's formula with
 *           the chains' correlation factors gamma_j.
 *
 * The space. Variable i of X has the marginal vars[i].dist and the variables are coupled by the
 * engine's Gaussian copula (prsm_mc_correlation: the correlation of the normal scores). U holds
 * d independent standard normals; z = L u on the correlated variables (L the lower Cholesky
 * factor of their normal-score correlation matrix, as mc/engine.c applies it), z = u on the
 * others; x_i = F_i^-1(Phi(z_i)). The normal, lognormal, Rayleigh and uniform marginals take
 * the closed form of that composition (mean + sd z, exp(mu + sigma z), ...) so that the far
 * tails keep their precision; every other kind goes through prsm_dist_quantile of Phi(z) (of
 * 1 - Q(z) above the median, so its upper tail is resolved to about z = 8).
 *
 * Determinism. Every random number comes from the engine's Philox streams (util/rng.h) keyed by
 * (seed, stream_offset + a key per block or chain): plain MC block b has key 2^48 + b, IS block
 * b 3 * 2^48 + b, subset level j chain (or level-0 block) c 2 * 2^48 + j 2^32 + c. Limit-state
 * evaluations run in parallel batches on `threads` threads (FORM: the gradient's and the
 * Hessian's points; IS and MC: rounds of blocks; subset: the chains of a level), each result
 * goes to its own slot and everything is merged in a fixed order, so every figure is
 * bit-identical for any thread count. Stop rules are checked on the completed prefix of blocks
 * in block order; only the time cap and cancellation depend on timing (and say so in `stop`).
 *
 * Errors. A limit state that returns nonzero, or a non-finite value, stops the method with
 * PRSM_ENOCONVERGE; err names the evaluation (FORM, SORM), the sample (MC, IS) or the level,
 * chain and sample (subset), and the result's failed_index holds that index (the first in the
 * method's fixed order, whatever the thread count). Cancellation and the time cap return 0 with
 * what was done, converged = 0 and stop saying which.
 *
 * No JSON, sockets or SQL here (mc/ never sees documents).
 */
#ifndef PRSM_MC_RARE_H
#define PRSM_MC_RARE_H

#include <stddef.h>
#include <stdint.h>

#include "mc/engine.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/progress.h"

#define PRSM_RARE_MAX_DESIGN_POINTS 8 /* distinct design points FORM keeps (multi-start) */
#define PRSM_RARE_MAX_STARTS 16       /* extra FORM starting points */
#define PRSM_RARE_MAX_LEVELS 40       /* subset levels, including level 0 */
#define PRSM_RARE_REASON_MAX 160

/* The limit state over the physical variables x (d values, in the variables' units): *value =
 * g(x), failure when g(x) <= 0. Called concurrently from several threads, each with its own
 * workspace; ctx is shared and read-only (as prsm_mc_model's eval). Returns 0, or nonzero for a
 * failed evaluation (a negative PRSM_E* code preferably; the method then stops). */
typedef struct {
	const void *ctx;
	int (*workspace_alloc)(void **ws, const void *ctx); /* may be NULL: no workspace */
	void (*workspace_free)(void *ws);
	int (*g)(double *value, const void *ctx, void *ws, const double *x);
} prsm_rare_limit_state;

/* A problem: the limit state and the variables as the engine takes them. The arrays must live
 * as long as the call. */
typedef struct {
	prsm_rare_limit_state limit;
	const prsm_mc_variable *vars;     /* d variables (only .dist is read) */
	size_t d;                         /* 1..PRSM_MC_MAX_VARIABLES */
	const prsm_mc_correlation *corr;  /* n_corr pairs (may be NULL when n_corr is 0) */
	size_t n_corr;
} prsm_rare_problem;

typedef enum {
	PRSM_RARE_AUTO = 0,               /* prsm_rare_run: a pilot MC block, then prsm_rare_auto_select */
	PRSM_RARE_MC = 1,                 /* plain Monte Carlo (in U, with the CoV stop rule) */
	PRSM_RARE_FORM = 2,
	PRSM_RARE_SORM = 3,
	PRSM_RARE_IS = 4,                 /* FORM, then IS around its design point(s) */
	PRSM_RARE_SUBSET = 5
} prsm_rare_method;

typedef enum {
	PRSM_RARE_PROPOSAL_NORMAL = 0,    /* component-wise N(0, width^2) steps */
	PRSM_RARE_PROPOSAL_UNIFORM = 1    /* component-wise uniform steps on [-width, width] */
} prsm_rare_proposal;

typedef enum {
	PRSM_RARE_STOP_CONVERGED = 0,     /* FORM: both criteria met; SORM: every formula applied;
	                                     MC/IS: the CoV target met; subset: the last level reached g <= 0 */
	PRSM_RARE_STOP_MAX_ITERATIONS = 1,/* FORM: the iteration cap */
	PRSM_RARE_STOP_MAX_SAMPLES = 2,   /* MC/IS: the sample cap before the CoV target (the estimate stands) */
	PRSM_RARE_STOP_MAX_EVALUATIONS = 3, /* the evaluation budget (max_evaluations) */
	PRSM_RARE_STOP_LINE_SEARCH = 4,   /* FORM: no step decreased the merit function */
	PRSM_RARE_STOP_ZERO_GRADIENT = 5, /* FORM: the gradient vanished away from the limit state */
	PRSM_RARE_STOP_MAX_LEVELS = 6,    /* subset: max levels before g <= 0 */
	PRSM_RARE_STOP_STAGNATION = 7,    /* subset: the threshold stopped decreasing (a plateau of g) */
	PRSM_RARE_STOP_CURVATURE = 8,     /* SORM: some formula refused (1 + beta kappa_i <= 0, beta <= 0) */
	PRSM_RARE_STOP_FORM = 9,          /* SORM: the FORM under it did not converge */
	PRSM_RARE_STOP_TIME_CAP = 10,     /* the time cap ended it (not reproducible) */
	PRSM_RARE_STOP_CANCELLED = 11
} prsm_rare_stop;

/* Options of every method (libgit2 style: PRSM_RARE_OPTIONS_INIT or prsm_rare_options_init). */
typedef struct {
	uint64_t seed;                    /* 1 */
	uint64_t stream_offset;           /* 0: added to every stream key (distinct runs of one seed) */
	int threads;                      /* 1..PRSM_MC_MAX_THREADS; results do not depend on it */
	double time_cap_s;                /* 0: none */
	prsm_cancel_flag *cancel;         /* may be NULL */
	prsm_progress_fn progress;        /* may be NULL; calling thread, about every 0.2 s and at the
	                                     end: evaluations done of max_evaluations, the current CoV
	                                     and target_cov */
	void *progress_ctx;
	size_t max_evaluations;           /* budget of limit-state evaluations of one call (100000) */
	double target_cov;                /* MC/IS stop rule: CoV <= this (0.05); auto's MC projection */
	double is_max_cov_error;          /* IS stop rule also: the CoV's own relative error <= this (0.1) */
	int is_fallback_subset;           /* prsm_rare_run's IS: keep half the budget and run subset
	                                     simulation with it when IS does not settle (0; auto: always) */
	/* FORM */
	int form_max_iterations;          /* 100 */
	double form_tol_g;                /* 1e-8: |g(u)| <= tol_g |g(u_0)| (absolute when g(u_0) = 0) */
	double form_tol_u;                /* 1e-6: |u - (alpha . u) alpha| <= tol_u */
	double fd_step;                   /* 1e-4: central-difference step h_i = fd_step max(1, |u_i|) */
	int line_search_max;              /* 30 halvings at most */
	double armijo;                    /* 0.1: sufficient-decrease factor a */
	double backtrack;                 /* 0.5: step factor per rejected trial */
	size_t n_starts;                  /* extra starting points (0..PRSM_RARE_MAX_STARTS) */
	const double *starts;             /* n_starts x d points in U; the origin is always the first */
	/* SORM */
	double hessian_step;              /* 1e-3: h_i = hessian_step max(1, |u*_i|) */
	/* MC and IS */
	size_t block_size;                /* 256 samples per block */
	size_t round_blocks;              /* 8: at most this many blocks per parallel round (a round runs
	                                     what the stop rule is projected to need) */
	size_t min_samples;               /* 1000: no CoV stop before */
	size_t min_failures;              /* 10: no CoV stop before this many samples in the failure domain */
	size_t max_samples;               /* 100000 */
	size_t pilot_samples;             /* 1024: the first MC samples auto decides on */
	/* subset */
	size_t subset_samples;            /* N per level (1000) */
	double subset_p0;                 /* 0.1: conditional probability of each intermediate level */
	int subset_max_levels;            /* 20 (2..PRSM_RARE_MAX_LEVELS) */
	prsm_rare_proposal subset_proposal; /* normal */
	double subset_width;              /* 1.0: proposal sd (normal) or half-width (uniform), in U */
} prsm_rare_options;

#define PRSM_RARE_OPTIONS_INIT                                                                    \
	{1, 0, 1, 0.0, NULL, NULL, NULL, 100000, 0.05, 0.1, 0,                                       \
	 100, 1e-8, 1e-6, 1e-4, 30, 0.1, 0.5, 0, NULL,                                                \
	 1e-3,                                                                                        \
	 256, 8, 1000, 10, 100000, 1024,                                                              \
	 1000, 0.1, 20, PRSM_RARE_PROPOSAL_NORMAL, 1.0}

/* Set *o to PRSM_RARE_OPTIONS_INIT. Returns 0. */
int prsm_rare_options_init(prsm_rare_options *o);

/* Check options for a problem of d variables. Returns 0 or PRSM_EINVAL (err names the option). */
int prsm_rare_options_check(const prsm_rare_options *o, size_t d, prsm_error *err);

/* ---- results -------------------------------------------------------------------------------- */

typedef struct {
	size_t d;
	double beta;                      /* alpha . u*: |u*| signed, negative when u_0 is in the failure domain */
	double pf;                        /* Phi(-beta) */
	double g0, g_star;                /* g at the first start (the origin) and at u* */
	double grad_norm;                 /* |grad_u g(u*)| */
	double e1, e2;                    /* last criteria: |g|/|g(u_0)|, |u - (alpha.u) alpha| */
	double *u_star;                   /* d: the design point in U */
	double *x_star;                   /* d: the design point in the variables' units */
	double *alpha;                    /* d: -grad_u g / |grad_u g| at u* (unit, towards failure) */
	double *alpha2;                   /* d: alpha_i^2, the importance factors in U (sum 1) */
	double *importance;               /* d: importance by variable, gamma_i^2 (Der Kiureghian): the
	                                     normalised squares of L^-T alpha; alpha2 without correlations */
	size_t iterations;                /* HL-RF steps of the run that gave u* */
	size_t evaluations;               /* every limit-state evaluation, every start */
	size_t n_points;                  /* distinct converged design points, by increasing beta
	                                     (the first is u*); 0 when no start converged */
	double point_beta[PRSM_RARE_MAX_DESIGN_POINTS];
	double *points;                   /* PRSM_RARE_MAX_DESIGN_POINTS x d, rows 0..n_points-1 in U */
	size_t failed_index;              /* the evaluation that failed (error return), else SIZE_MAX */
	int converged;                    /* the run that gave u* met both criteria */
	prsm_rare_stop stop;              /* of that run */
	char reason[PRSM_RARE_REASON_MAX];/* one line: how the run ended */
	double elapsed_s;
} prsm_rare_form_result;

typedef struct {
	size_t n_curvatures;              /* d - 1 */
	double *kappa;                    /* principal curvatures, decreasing (positive: the failure
	                                     domain curves away from the origin, P_f below FORM's) */
	double pf_breitung, pf_hr, pf_tvedt; /* NAN when the formula refused */
	double beta_breitung, beta_hr, beta_tvedt; /* -Phi^-1(pf) of each, NAN likewise */
	int ok_breitung, ok_hr, ok_tvedt;
	int converged;                    /* every formula applied */
	prsm_rare_stop stop;
	size_t evaluations;               /* the Hessian's (2 d^2 for d variables) */
	size_t failed_index;
	char reason[PRSM_RARE_REASON_MAX];
	double elapsed_s;
} prsm_rare_sorm_result;

/* MC (n_centres 0) and IS. */
typedef struct {
	double pf;                        /* the estimate */
	double se, cov;                   /* its standard error and se / pf (NAN while pf is 0) */
	double cov_rel_error;             /* the relative standard error of cov itself, from the fourth
	                                     moment of the weighted indicator (NAN while pf is 0): large
	                                     when a few heavy weights carry the estimate */
	double lower, upper;              /* 95 % interval pf -+ 1.96 se, lower clamped at 0 */
	size_t samples;                   /* kept (the stop rule's prefix of blocks) */
	size_t failures;                  /* kept samples with g <= 0 */
	size_t evaluations;               /* all, including a round's blocks after the stopping one */
	size_t n_centres;
	size_t failed_index;              /* the sample that failed, else SIZE_MAX */
	int converged;                    /* the CoV target met */
	prsm_rare_stop stop;
	double elapsed_s;
} prsm_rare_is_result;

typedef struct {
	double pf, cov;                   /* estimate (NAN unless the last level reached g <= 0), Au & Beck's CoV */
	double lower, upper;              /* pf (1 -+ 1.96 cov), lower clamped at 0 */
	double bound;                     /* product of the conditional probabilities of the levels
	                                     run: P(g <= last threshold), an upper bound of P_f */
	int levels;                       /* levels run, level 0 (plain MC) included */
	size_t samples_per_level, chains; /* N, N_c = round(p0 N) */
	double threshold[PRSM_RARE_MAX_LEVELS];  /* b_j of level j's samples (0 for the last) */
	double p_cond[PRSM_RARE_MAX_LEVELS];     /* P(g <= b_j | g <= b_j-1) from level j's samples */
	double gamma[PRSM_RARE_MAX_LEVELS];      /* chain correlation factor (0 at level 0) */
	double delta[PRSM_RARE_MAX_LEVELS];      /* CoV of p_cond[j] */
	double acceptance[PRSM_RARE_MAX_LEVELS]; /* accepted / proposed moves (level >= 1) */
	size_t failures;                  /* last level's samples with g <= 0 */
	size_t evaluations;
	size_t failed_index;              /* level * N + sample of the level that failed, else SIZE_MAX */
	int converged;
	prsm_rare_stop stop;
	double elapsed_s;
} prsm_rare_subset_result;

/* ---- methods -------------------------------------------------------------------------------- */

/* FORM from the origin and from o->starts. Allocates out's arrays (free with
 * prsm_rare_form_result_free, also after an error). Returns 0 (converged or not: see
 * out->converged and out->stop), PRSM_EINVAL, PRSM_ENOMEM, or PRSM_ENOCONVERGE when the limit
 * state failed (out->failed_index). */
int prsm_rare_form(prsm_rare_form_result *out, const prsm_rare_problem *p, const prsm_rare_options *o,
                   prsm_error *err);
void prsm_rare_form_result_free(prsm_rare_form_result *r);

/* SORM at form's design point (form from prsm_rare_form on the same problem). Returns 0 with
 * stop FORM and no figures when form did not converge. Allocates out->kappa (free with
 * prsm_rare_sorm_result_free). */
int prsm_rare_sorm(prsm_rare_sorm_result *out, const prsm_rare_problem *p,
                   const prsm_rare_form_result *form, const prsm_rare_options *o, prsm_error *err);
void prsm_rare_sorm_result_free(prsm_rare_sorm_result *r);

/* Importance sampling around n_centres points of U (n_centres x d, row-major), the mixture
 * weights proportional to weights (NULL: to Phi(-|c_k|)); n_centres 0 is plain Monte Carlo. */
int prsm_rare_is(prsm_rare_is_result *out, const prsm_rare_problem *p, const double *centres,
                 const double *weights, size_t n_centres, const prsm_rare_options *o, prsm_error *err);

int prsm_rare_subset(prsm_rare_subset_result *out, const prsm_rare_problem *p,
                     const prsm_rare_options *o, prsm_error *err);

/* ---- one call for the rest of the engine ---------------------------------------------------- */

typedef struct {
	prsm_rare_method method;          /* what ran (AUTO resolved) */
	prsm_rare_method requested;
	double pf;                        /* the method's estimate (SORM: Tvedt's, else HR's, else
	                                     Breitung's, else FORM's) */
	double cov, lower, upper;         /* NAN for FORM and SORM */
	double beta;                      /* generalised reliability index -Phi^-1(pf) */
	size_t evaluations;               /* all of them (pilot, FORM, SORM, sampling) */
	int converged;
	prsm_rare_stop stop;              /* of the method that gave pf */
	char note[PRSM_RARE_REASON_MAX];  /* auto's reason, or a fallback */
	int has_form, has_sorm, has_is, has_subset; /* which parts below were filled */
	prsm_rare_form_result form;
	prsm_rare_sorm_result sorm;
	prsm_rare_is_result is;           /* also MC's (n_centres 0) */
	prsm_rare_subset_result subset;
	double elapsed_s;
} prsm_rare_result;

/* Run one method (AUTO: a pilot of o->pilot_samples plain MC samples, then
 * prsm_rare_auto_select on its counts; when MC is chosen the pilot is the start of the MC run).
 * IS runs FORM first and samples around every design point FORM found (its last iterate when
 * FORM did not converge). Free out with prsm_rare_result_free (also after an error). */
int prsm_rare_run(prsm_rare_result *out, prsm_rare_method method, const prsm_rare_problem *p,
                  const prsm_rare_options *o, prsm_error *err);
void prsm_rare_result_free(prsm_rare_result *r);

/* The "auto" rule, on the counts of a first block of plain MC (failures of n samples) for d
 * variables under o's budget (max_evaluations), CoV target and subset settings:
 *   1. failures > 0 and plain MC reaches target_cov within the budget, the projected samples
 *      (1 - p) / (p cov^2) with p = failures / n being <= min(max_samples, max_evaluations): MC;
 *   2. else, FORM's projected cost 10 (2 d + 1) + 50 plus min_samples IS samples within the
 *      budget and d <= PRSM_RARE_AUTO_IS_MAX_D: IS (FORM, then IS at the design point);
 *   3. else subset simulation when its projected cost N (1 + (1 - p0)(L - 1)) fits, L = 1 +
 *      ceil(log(p_hi) / log(p0)) levels, p_hi = failures / n or 3 / n (no failure: the 95 %
 *      rule of three);
 *   4. else FORM when its projected cost fits (an estimate without an error bar);
 *   5. else MC (what the budget allows).
 * why (may be NULL) gets one line saying which branch chose. Pure: no evaluation. */
#define PRSM_RARE_AUTO_IS_MAX_D 100
prsm_rare_method prsm_rare_auto_select(size_t failures, size_t n, size_t d, const prsm_rare_options *o,
                                       char *why, size_t why_size);

const char *prsm_rare_method_name(prsm_rare_method m); /* "auto", "mc", "form", "sorm", "is", "subset" */
int prsm_rare_method_parse(const char *name, prsm_rare_method *out); /* 0 or PRSM_ENOTFOUND */
const char *prsm_rare_stop_name(prsm_rare_stop s);

/* ---- helpers -------------------------------------------------------------------------------- */

/* The map U -> X of the problem's variables (see the top of this file), for callers that report
 * a point of U in physical units. Returns 0, PRSM_EINVAL (a bad variable or correlation) or
 * PRSM_ENOMEM. */
int prsm_rare_u_to_x(const prsm_rare_problem *p, const double *u, double *x, prsm_error *err);

/* A limit state from one output of an engine model against its spec:
 *   UPPER  g = (upper - y) / scale     LOWER  g = (y - lower) / scale
 *   BOTH   g = min of the two (a series system: run FORM per side, or subset simulation).
 * The model's workspace is the limit state's (with room for the outputs); a failed model
 * evaluation is a failed limit-state evaluation; flags are ignored. spec must outlive ls. */
typedef enum { PRSM_RARE_SIDE_UPPER = 0, PRSM_RARE_SIDE_LOWER = 1, PRSM_RARE_SIDE_BOTH = 2 } prsm_rare_side;

typedef struct {
	const prsm_mc_model *model;
	size_t output;
	prsm_rare_side side;
	double lower, upper;
	double scale;                     /* > 0; e.g. the spec width, so that g is of order 1 */
} prsm_rare_spec;

void prsm_rare_spec_limit_state(prsm_rare_limit_state *ls, const prsm_rare_spec *spec);

#endif
