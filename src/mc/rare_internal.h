/*
 * rare_internal.h: what the rare-event files share (mc/rare.c, rare_form.c, rare_sample.c):
 * the map U -> X, the pool of worker threads that evaluates the limit state in parallel
 * batches, and small numeric helpers. Not part of the engine's interface.
 */
#ifndef PRSM_MC_RARE_INTERNAL_H
#define PRSM_MC_RARE_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include <gsl/gsl_rng.h>

#include "mc/rare.h"

/* Stream key families (rare.h, "Determinism"). */
#define RARE_KEY_MC (UINT64_C(1) << 48)
#define RARE_KEY_SUBSET (UINT64_C(2) << 48)
#define RARE_KEY_IS (UINT64_C(3) << 48)

/* An evaluation that did not run because the run is stopping (cancel, time cap). Positive, so
 * never a limit state's PRSM_E* code. */
#define RARE_HALTED 1

#define RARE_Z95 1.959963984540054

/* The map U -> X: the copula on the k correlated variables (a copy of mc/engine.c's copula:
 * lower Cholesky factor L of their normal-score correlation matrix, variable idx[i] is row i),
 * then each marginal. */
typedef struct {
	const prsm_rare_problem *p;
	size_t d;
	size_t k;
	size_t *idx;                      /* k */
	double *L;                        /* k x k, row-major, lower */
} rare_space;

int rare_space_init(rare_space *s, const prsm_rare_problem *p, prsm_error *err);
void rare_space_free(rare_space *s);
/* x (d) from u (d); z is d of scratch. */
void rare_space_to_x(const rare_space *s, const double *u, double *z, double *x);
/* gamma = L^-T alpha normalised, squared (the importance by variable); out may not alias alpha. */
void rare_space_importance(const rare_space *s, const double *alpha, double *out);

typedef struct rare_pool rare_pool;

typedef struct {
	rare_pool *pool;
	void *ws;                         /* the limit state's workspace */
	double *x, *z;                    /* d each: the point in X, scratch of the map */
	double *a, *b;                    /* d each: scratch of the tasks */
	gsl_rng *rng;                     /* set to a task's stream by the task */
	pthread_t thread;
} rare_worker;

/* A task of a batch: index i of n. Writes only its own slots. */
typedef void (*rare_task_fn)(rare_worker *w, size_t i, void *arg);

struct rare_pool {
	const rare_space *space;
	const prsm_rare_options *o;
	int n_workers;
	rare_worker *w;
	double t0;
	atomic_int halt;                  /* 0 running, else the prsm_rare_stop that ends the run */
	/* the current batch */
	rare_task_fn task;
	void *arg;
	size_t n_tasks;
	atomic_size_t next;
	double last_progress;
};

int rare_pool_init(rare_pool *pool, const rare_space *s, const prsm_rare_options *o, prsm_error *err);
void rare_pool_free(rare_pool *pool);
/* rare_space_init then rare_pool_init, the space freed again when the pool fails: 0 with both to
 * free (rare_pool_free, rare_space_free), or the error. */
int rare_setup(rare_space *s, rare_pool *pool, const prsm_rare_problem *p, const prsm_rare_options *o,
               prsm_error *err);
/* Run tasks 0..n-1 on the pool's threads (the calling thread is worker 0). */
void rare_pool_run(rare_pool *pool, size_t n, rare_task_fn task, void *arg);
/* 0 while running, else the prsm_rare_stop (TIME_CAP, CANCELLED) that halts the run; polls the
 * flag and the clock. */
int rare_pool_halted(rare_pool *pool);
/* g at u (d values in U) by worker w: 0, RARE_HALTED (nothing evaluated), the limit state's
 * nonzero code, or PRSM_ENOCONVERGE for a non-finite value (*code gets the limit state's own
 * return: 0 for a non-finite value). */
int rare_eval(rare_worker *w, const double *u, double *g, int *code);
void rare_progress(rare_pool *pool, size_t done, double cov, int final);

/* The error of a failed evaluation: PRSM_ENOCONVERGE with "the limit state failed (CODE) at
 * <where>" or "returned a non-finite value at <where>". */
int rare_eval_error(prsm_error *err, int lscode, const char *where);

/* Phi(-b) and -Phi^-1(p) with full tail precision. */
double rare_phi_minus(double b);
double rare_beta_of(double p);
double rare_dot(const double *a, const double *b, size_t n);
double rare_norm(const double *a, size_t n);

/* Internal entry points shared by rare.c's orchestrator. */
typedef struct {
	/* running sums of the kept prefix */
	double s1, s2;                    /* sum of I w and of (I w)^2 */
	double s3, s4;                    /* of (I w)^3 and (I w)^4: the CoV's own reliability */
	size_t samples, failures, evaluations;
	size_t next_block;                /* the next block of the sequence */
	int done;
} rare_is_state;

/* Continue an IS (n_centres > 0) or plain MC run from st (zeroed at the start) with whole
 * blocks until: the kept samples reach cap_samples (done, stop MAX_SAMPLES, when check_target;
 * else the leg just returns: the auto pilot), the CoV stop rule (only when check_target), the
 * evaluation budget (st->evaluations <= budget; stop MAX_EVALUATIONS), a halt, or a failed
 * evaluation (error). Fills out's figures from the state. weights: as prsm_rare_is. */
int rare_is_advance(rare_is_state *st, prsm_rare_is_result *out, rare_pool *pool, const double *centres,
                    const double *weights, size_t n_centres, size_t cap_samples, int check_target,
                    size_t budget, prsm_error *err);

#endif
