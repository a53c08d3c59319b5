/*
 * robust.h: robust constraints of the design optimisation (issue 7, item 1; DESIGN.md
 * "Optimisation": robust terms use common random numbers so f(x) is deterministic).
 *
 * A robust constraint asks that the Monte Carlo yield of one study output (backlash_um,
 * te_pp_um, load_sharing_factor, ...: every output of mc/prsm_model.h) against a spec be at
 * least a target fraction. For a candidate design the caller's builder makes the tolerance study
 * of THAT design (the same tolerance set, assembly settings, seed, sample count, sampler and
 * block size for every candidate), the study runs (src/mc: bit-identical for any thread count),
 * and the yield of each constrained output is read from its summary. Same seed and sampler for
 * every candidate: common random numbers, so the yield is a deterministic function of the design
 * (piecewise constant: it moves by 1/n when a sample crosses a spec limit).
 *
 * Two values per constraint: the checked one, g = target - yield (fraction, feasible when <= 0:
 * the yield the result reports and the optimiser's feasibility test uses), and a smooth stand-in
 * the solver sees instead (opt/optimize.h `has_surrogate`), on the probit scale
 * g_s = Phi^-1(target) - Phi^-1(Y_s), Y_s clamped to [1e-12, 1 - 1e-12]:
 *   * kernel (default): Y_s = (1/n) sum_i [Phi((U - y_i)/h) - Phi((L - y_i)/h)] over the kept
 *     samples y_i, h = sd n^(-1/3) (the indicator of each sample smoothed by a normal kernel;
 *     tends to the Monte Carlo yield as h -> 0, continuous in the design because every y_i is);
 *   * normal: Y_s = Phi((U - mean)/sd) - Phi((L - mean)/sd) of the fitted normal;
 *   * none: Y_s = the Monte Carlo yield itself.
 * A side without a limit drops its term. The stand-in only steers the solver; whether a point is
 * feasible, and what the result reports, is always the Monte Carlo yield.
 *
 * The builder may fail (the candidate cannot be analysed, or its study cannot be built); the
 * evaluation then says so and the caller counts the constraint as violated. A small cache of the
 * last evaluations (keyed by the candidate's starts, pitch, roller radius, rollers, engaged
 * threads and flank angle: every field the optimiser varies) saves re-running a candidate NLopt
 * or the final re-check asks for again. A prsm_robust is not shared between threads (its cache
 * changes on every evaluation). No JSON here: the application layer (src/app/optimize.c)
 * supplies the builder.
 */
#ifndef PRSM_OPT_ROBUST_H
#define PRSM_OPT_ROBUST_H

#include <stddef.h>
#include <stdint.h>

#include "mc/study.h"
#include "model/design.h"
#include "util/cancel.h"
#include "util/error.h"

#define PRSM_ROBUST_MAX 8          /* robust constraints of one problem */
#define PRSM_ROBUST_CACHE 8        /* candidates remembered */
#define PRSM_ROBUST_NAME_MAX 48

typedef enum {
	PRSM_ROBUST_KERNEL = 0,        /* smoothed indicator (default) */
	PRSM_ROBUST_NORMAL = 1,        /* normal approximation from the sample mean and sd */
	PRSM_ROBUST_NONE = 2           /* the Monte Carlo yield itself */
} prsm_robust_surrogate;

/* "kernel", "normal", "none", NULL: indexed by prsm_robust_surrogate. */
extern const char *const prsm_robust_surrogate_names[];

typedef struct {
	char output[PRSM_ROBUST_NAME_MAX]; /* a study output name with its unit, e.g. "backlash_um" */
	prsm_spec spec;                    /* in the output's unit */
	double yield_min;                  /* target fraction in spec, in (0, 1) */
} prsm_robust_constraint;

/*
 * Build the tolerance study of candidate design d (unresolved: the rules fill its radii). On
 * success *study points to a study whose outputs include every constrained output by name,
 * *handle to whatever owns it (released by the release callback, never NULL on success) and
 * *source (*source_len bytes, owned by the handle) to the study document it was loaded from, or
 * NULL when there is none (the study then runs in this process whatever the service).
 * Returns 0, or a PRSM_E* code with err saying why (the candidate then counts as violating).
 */
typedef int (*prsm_robust_build_fn)(void *ctx, prsm_study **study, void **handle, const char **source,
                                    size_t *source_len, const prsm_design *d, prsm_error *err);
typedef void (*prsm_robust_release_fn)(void *ctx, void *handle);

/* The figures of one constraint at one candidate. */
typedef struct {
	double yield;                  /* Monte Carlo fraction in spec over the kept samples */
	double yield_low95, yield_high95; /* its 95 % Wilson interval */
	double mean, sd;               /* of the output over the kept samples, output unit */
	double normal_yield;           /* the fitted normal's fraction in spec */
	double smooth_yield;           /* Y_s of the surrogate in use */
	double g;                      /* target - yield (checked), fraction */
	double g_solver;               /* Phi^-1(target) - Phi^-1(Y_s) (what the solver sees) */
} prsm_robust_value;

/* One candidate's evaluation. */
typedef struct {
	int evaluated;                 /* the study ran and every figure below is set */
	char failure[PRSM_ERROR_MESSAGE_MAX]; /* why not, when not */
	size_t samples;                /* samples kept (the yields' denominator) */
	size_t failed, edge;           /* failed and edge-contact samples of the run */
	double elapsed_s;              /* building and running the study, s */
	prsm_robust_value v[PRSM_ROBUST_MAX];
} prsm_robust_eval;

typedef struct {
	double key[6];                 /* starts, pitch (mm), r_r (mm), Z, n_t, beta (rad) */
	prsm_robust_eval e;
} prsm_robust_cache_entry;

typedef struct {
	int n;                                    /* constraints, 1..PRSM_ROBUST_MAX */
	prsm_robust_constraint c[PRSM_ROBUST_MAX];
	prsm_robust_surrogate surrogate;
	prsm_robust_build_fn build;
	prsm_robust_release_fn release;
	void *build_ctx;
	prsm_cancel_flag *cancel;                     /* may be NULL: handed to every study run */
	const prsm_study_service *service;        /* who runs the studies (mc/study.h; NULL: here) */
	/* settings echoed by the result (the builder's study uses them) */
	uint64_t seed;
	size_t samples;
	/* counters and cache, changed by every evaluation */
	size_t studies;                           /* studies run (cache misses) */
	size_t samples_total;                     /* samples of every study run */
	double elapsed_s;                         /* time in the studies, s */
	int cache_used, cache_next;
	prsm_robust_cache_entry cache[PRSM_ROBUST_CACHE];
} prsm_robust;

/* No constraints, kernel surrogate, empty cache; the caller sets c, n, build, release, ctx. */
void prsm_robust_init(prsm_robust *r);

/* Empty the cache: the next evaluation of any candidate runs its study again. */
void prsm_robust_forget(prsm_robust *r);

/* Evaluate every constraint at candidate d (through the cache). Fills out; out->evaluated 0
 * with out->failure when the builder or the study failed (not an error of the call). Returns 0,
 * PRSM_ECANCELLED (*cancel was set during the study; out->evaluated 0) or PRSM_ENOMEM. */
int prsm_robust_evaluate(prsm_robust_eval *out, prsm_robust *r, const prsm_design *d,
                         prsm_error *err);

/* The figures of one constraint from a finished study result (exposed for tests): output index
 * o of study s, constraint c, surrogate kind. Returns 0 or PRSM_EINVAL (fewer than 2 samples
 * kept). */
int prsm_robust_value_of(prsm_robust_value *out, const prsm_study *s, const prsm_study_result *res,
                         size_t o, const prsm_robust_constraint *c, prsm_robust_surrogate kind,
                         prsm_error *err);

#endif
