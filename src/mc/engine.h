/*
 * engine.h: the Monte Carlo engine (DESIGN.md, "Monte Carlo engine").
 *
 * A model maps an input vector x (one value per variable, physical units) to outputs y. The
 * engine draws x from the variables' distributions and runs the model over many samples:
 *
 *   * samples are processed in blocks of `block_size`; block b draws its uniforms from its own
 *     Philox stream keyed by (seed, b) (random, LHS) or from the points b*B... of a Sobol
 *     sequence (Joe-Kuo directions, scrambled: seeded linear matrix scramble + digital shift), so a block's numbers do not depend on which thread
 *     runs it or on the other blocks;
 *   * every sample's inputs and outputs go to fixed slots of the result, and the running
 *     statistics the stop rules look at are merged in block order, so results are
 *     bit-identical for any thread count and for a run split into block ranges;
 *   * workspaces are allocated once per worker thread; the sample loop does not allocate;
 *   * stop rules (standard error, coefficient of variation, yield interval width) are checked
 *     on the completed prefix of blocks, so where a run stops does not depend on timing either
 *     (the time cap and cancellation are the exceptions, and say so in the stop reason);
 *   * failed samples (the model returned an error) and edge-contact samples are counted and
 *     listed; policy `abort` stops at the first, `skip` leaves them out of every statistic and
 *     stops when they exceed a fraction of the samples.
 *
 * Inputs may be correlated through a Gaussian copula (pairs of variables with a rank-free
 * normal-scores correlation). The Saltelli design for Sobol indices (mc/sens.h) is a second
 * mode of the same runner: each base row draws A and B, and evaluates A, B and A with each
 * group's columns taken from B.
 *
 * No JSON, sockets or SQL here; the study layer (mc/study.h) and io/ sit above.
 */
#ifndef PRSM_MC_ENGINE_H
#define PRSM_MC_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "mc/dist.h"
#include "mc/stats.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/progress.h"

/* Limits (also what the request validation enforces). */
#define PRSM_MC_MAX_VARIABLES 1024    /* sampled scalar variables */
#define PRSM_MC_MAX_OUTPUTS 16
#define PRSM_MC_MAX_GROUPS 128        /* tolerances (Sobol groups) */
#define PRSM_MC_MAX_SAMPLES 4000000   /* sample cap of one run */
#define PRSM_MC_MAX_STORED 33554432   /* doubles a run may store (256 MiB) */
#define PRSM_MC_MAX_BLOCK 65536
#define PRSM_MC_MIN_BLOCK 16
#define PRSM_MC_MAX_THREADS 64
#define PRSM_MC_MAX_CORRELATIONS 64
#define PRSM_MC_MAX_TARGETS 8
#define PRSM_MC_LISTED_FAILURES 100   /* failed samples listed by index */

/* Flags a model sets on a sample it evaluated. */
#define PRSM_MC_FLAG_EDGE 1u          /* a contact left its flank */

/* The model the engine runs. eval is called concurrently from several threads, each with its
 * own workspace; ctx is shared and read-only. eval returns 0, or a negative PRSM_E* code for a
 * failed sample (then y is ignored). */
typedef struct {
	size_t n_outputs;
	const void *ctx;
	int (*workspace_alloc)(void **ws, const void *ctx); /* may be NULL: no workspace */
	void (*workspace_free)(void *ws);
	int (*eval)(double *y, unsigned *flags, const void *ctx, void *ws, const double *x);
} prsm_mc_model;

typedef struct {
	prsm_dist dist;
	int group;                        /* tolerance it belongs to, 0..n_groups-1 */
} prsm_mc_variable;

typedef struct {
	size_t a, b;                      /* variable indices, a != b */
	double rho;                       /* correlation of their normal scores, |rho| < 1 */
} prsm_mc_correlation;

typedef enum { PRSM_SAMPLER_RANDOM = 0, PRSM_SAMPLER_LHS = 1, PRSM_SAMPLER_SOBOL = 2 } prsm_sampler_kind;
typedef enum { PRSM_FAILURE_SKIP = 0, PRSM_FAILURE_ABORT = 1 } prsm_failure_policy;
typedef enum { PRSM_EDGE_EXCLUDE = 0, PRSM_EDGE_INCLUDE = 1 } prsm_edge_policy;

typedef enum {
	PRSM_TARGET_SE = 0,               /* standard error of the mean <= value (output unit) */
	PRSM_TARGET_CV = 1,               /* standard error of the mean / |mean| <= value */
	PRSM_TARGET_YIELD_WIDTH = 2       /* width of the 95 % Wilson interval of the yield <= value */
} prsm_target_kind;

typedef struct {
	prsm_target_kind kind;
	size_t output;
	double value;
	int has_lower, has_upper;         /* the output's spec (YIELD_WIDTH) */
	double lower, upper;
} prsm_mc_target;

typedef enum {
	PRSM_STOP_SAMPLE_CAP = 0,         /* ran every sample asked for */
	PRSM_STOP_TARGET = 1,             /* every target met */
	PRSM_STOP_TIME_CAP = 2,           /* the time cap ended it (not reproducible) */
	PRSM_STOP_CANCELLED = 3,
	PRSM_STOP_FAILURES = 4            /* failed samples beyond policy */
} prsm_stop_reason;

typedef struct {
	uint64_t seed;
	size_t samples;                   /* cap (plain) or base rows (Saltelli) */
	size_t min_samples;               /* no target stop before this many samples */
	size_t block_size;
	int threads;
	prsm_sampler_kind sampler;
	double time_cap_s;                /* 0: none */
	prsm_failure_policy failure;
	double max_failed_fraction;       /* skip: stop (reason FAILURES) beyond it */
	prsm_edge_policy edge;
	int n_targets;
	prsm_mc_target targets[PRSM_MC_MAX_TARGETS];
	/* split runs: blocks first_block .. first_block + block_count - 1 of the full run
	 * (block_count 0: to the cap); targets are not checked in a split run */
	size_t first_block, block_count;
	uint64_t stream_offset;           /* added to block indices as stream keys (distinct runs of one seed) */
	prsm_cancel_flag *cancel;             /* may be NULL; nonzero cancels */
	prsm_progress_fn progress;        /* may be NULL; called from the calling thread about every
	                                     0.2 s and once at the end: samples done of the cap, and with
	                                     targets the stop rule's current figure (util/progress.h) */
	void *progress_ctx;
} prsm_mc_options;

void prsm_mc_options_default(prsm_mc_options *o);

/* Sample status. */
enum { PRSM_SAMPLE_OK = 0, PRSM_SAMPLE_FAILED = 1, PRSM_SAMPLE_EDGE = 2, PRSM_SAMPLE_UNRUN = 3 };

typedef struct {
	size_t n;                         /* samples (rows) in the result */
	size_t d, m;                      /* variables, outputs */
	size_t first_sample;              /* global index of row 0 (split runs) */
	double *x;                        /* n x d inputs, row-major (plain mode) */
	double *y;                        /* n x m outputs; NAN for failed samples */
	unsigned char *status;            /* n PRSM_SAMPLE_* */
	int *fail_code;                   /* n model return codes (0 when ok) */
	size_t n_ok, n_failed, n_edge;    /* n_ok counts edge samples when they are included */
	prsm_stop_reason stop;
	int converged;                    /* every target met */
	prsm_sampler_kind sampler;        /* what ran */
	char warning[256];                /* a note on the run; "" when none */
	double elapsed_s;
	/* Saltelli mode */
	size_t n_groups;
	double *ys;                       /* m x (n_groups + 2) x n: [o][k][j], k = 0 A, 1 B, 2 + g AB_g */
} prsm_mc_result;

/* Plain run. Allocates the result's arrays (free with prsm_mc_result_free). Returns 0;
 * PRSM_EINVAL (bad options: err names it), PRSM_ENOMEM, or the model's code when the
 * failure policy aborted (err names the sample). A cancelled or timed-out run returns 0 with
 * the samples done. */
int prsm_mc_run(prsm_mc_result *out, const prsm_mc_model *model, const prsm_mc_variable *vars,
                size_t d, const prsm_mc_correlation *corr, size_t n_corr, const prsm_mc_options *o,
                prsm_error *err);

/* Saltelli run over n_groups groups (vars[i].group): o->samples base rows, each evaluating
 * A, B and the n_groups mixed rows. Sobol sampling needs 2 d <= PRSM_SOBOL_MAX_DIM (21201) dimensions. Failed rows are
 * marked in status and left out. Allocates out->ys and out->status. */
int prsm_mc_run_saltelli(prsm_mc_result *out, const prsm_mc_model *model,
                         const prsm_mc_variable *vars, size_t d, size_t n_groups,
                         const prsm_mc_correlation *corr, size_t n_corr,
                         const prsm_mc_options *o, prsm_error *err);

/* Concatenate split runs a then b (b's first block follows a's last) into out, as the full
 * run would have stored them. Allocates out. */
int prsm_mc_result_concat(prsm_mc_result *out, const prsm_mc_result *a, const prsm_mc_result *b,
                          prsm_error *err);

void prsm_mc_result_free(prsm_mc_result *r);

/* What prsm_mc_run checks before it samples (options, distributions, correlations, the Sobol
 * dimension, the storage the run needs), with the same codes and messages: 0, PRSM_EINVAL or
 * PRSM_ENOMEM. For a caller that assembles one run from split runs computed elsewhere. */
int prsm_mc_run_check(const prsm_mc_model *model, const prsm_mc_variable *vars, size_t d,
                      const prsm_mc_correlation *corr, size_t n_corr, const prsm_mc_options *o,
                      prsm_error *err);

/* The completed prefix of a plain run assembled block by block by a caller (a run split over
 * processes: src/par): the stop rules prsm_mc_run checks on its own prefix, by the same code,
 * so where the assembled run stops is where one prsm_mc_run of the same options stops. */
typedef struct {
	prsm_moments mom[PRSM_MC_MAX_TARGETS];
	size_t in[PRSM_MC_MAX_TARGETS];
	size_t blocks, rows, failed, edge;  /* blocks and rows merged; failed and edge samples among them */
} prsm_mc_prefix;

void prsm_mc_prefix_init(prsm_mc_prefix *p);

/* Merge the next block of the full run (global block p->blocks of total_blocks; its nb rows
 * start at global row p->rows): its outputs y (nb x m), status and fail_code. Returns 0 to go on,
 * or 1 when the run stops after this block: *stop says why (PRSM_STOP_FAILURES or
 * PRSM_STOP_TARGET), *code is 0 or the error the failure policy `abort` returns, err naming the
 * sample as prsm_mc_run does. */
int prsm_mc_prefix_add(prsm_mc_prefix *p, const prsm_mc_options *o, size_t m, size_t total_blocks,
                       const double *y, const unsigned char *status, const int *fail_code, size_t nb,
                       prsm_stop_reason *stop, int *code, prsm_error *err);

/* o->progress (when set) with the prefix's samples of cap and the stop rule's figure. */
void prsm_mc_prefix_progress(const prsm_mc_prefix *p, const prsm_mc_options *o, size_t cap);

/* The counts of a run that kept the prefix and stopped for `stop`: out->n, n_ok, n_failed,
 * n_edge, stop and converged, as prsm_mc_run sets them. */
void prsm_mc_prefix_finish(prsm_mc_result *out, const prsm_mc_prefix *p, const prsm_mc_options *o,
                           prsm_stop_reason stop);

/* 1 when a sample of this status enters the statistics under o's edge policy (inline: the
 * study's loops over every Saltelli evaluation ask it). */
static inline int prsm_mc_sample_kept(const prsm_mc_options *o, int status)
{
	return status == PRSM_SAMPLE_OK || (status == PRSM_SAMPLE_EDGE && o->edge == PRSM_EDGE_INCLUDE);
}

/* Check correlations as the runs will: valid pairs, |rho| < 1, a positive definite matrix.
 * Returns 0 or PRSM_EINVAL with err saying which. */
int prsm_mc_correlation_check(const prsm_mc_correlation *corr, size_t n_corr, size_t d,
                              prsm_error *err);

const char *prsm_sampler_name(prsm_sampler_kind k);
const char *prsm_stop_reason_name(prsm_stop_reason s);

/* Uniforms of one block, n rows x dim, row-major, in (0,1): what the engine feeds the
 * quantiles before any copula. Exposed for tests (LHS stratification, Sobol points). The
 * Sobol variant restarts its generator at the block's first point. Allocates nothing but
 * may use `scratch` of n * dim doubles (LHS) . Returns 0 or PRSM_EINVAL. */
int prsm_mc_block_uniforms(double *u, size_t n, size_t dim, prsm_sampler_kind s, uint64_t seed,
                           uint64_t stream, size_t first_index, size_t *scratch);

#endif
