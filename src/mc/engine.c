/*
 * engine.c: blocks, streams, samplers, worker threads and stop rules of the Monte Carlo
 * engine (DESIGN.md, "Monte Carlo engine"). See engine.h for the guarantees.
 *
 * Threading: the calling thread starts `threads` workers and then only merges (with one worker
 * it runs the blocks itself, in order: no thread to start or hand blocks to). Workers take
 * block indices from a shared counter and write their samples into the block's own slots; the
 * calling thread merges the per-block moments in block order as the completed prefix grows,
 * checks the stop rules on that prefix and lowers `stop_blocks` when the run should end.
 * Blocks at or beyond stop_blocks are discarded, so the result is always the first blocks of
 * the one deterministic sequence.
 */
#include "mc/engine.h"

#include <float.h>
#include <stddef.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "mc/sobol.h"
#include "mc/stats.h"
#include "util/clock.h"
#include "util/mem.h"
#include "util/rng.h"

/* Stream key of the Sobol scramble (matrices and digital shift): far from any block index. */
#define SOBOL_SHIFT_STREAM UINT64_C(0xfffffffffffff00d)
#define U_MIN (0x1p-53)
#define U_MAX (1.0 - 0x1p-53)

void prsm_mc_options_default(prsm_mc_options *o)
{
	memset(o, 0, sizeof *o);
	o->seed = 1;
	o->samples = 10000;
	o->min_samples = 0;
	o->block_size = 1024;
	o->threads = 1;
	o->sampler = PRSM_SAMPLER_RANDOM;
	o->failure = PRSM_FAILURE_SKIP;
	o->max_failed_fraction = 0.01;
	o->edge = PRSM_EDGE_EXCLUDE;
}

const char *prsm_sampler_name(prsm_sampler_kind k)
{
	switch (k) {
	case PRSM_SAMPLER_RANDOM: return "random";
	case PRSM_SAMPLER_LHS: return "lhs";
	case PRSM_SAMPLER_SOBOL: return "sobol";
	}
	return "?";
}

const char *prsm_stop_reason_name(prsm_stop_reason s)
{
	switch (s) {
	case PRSM_STOP_SAMPLE_CAP: return "sample_cap";
	case PRSM_STOP_TARGET: return "target";
	case PRSM_STOP_TIME_CAP: return "time_cap";
	case PRSM_STOP_CANCELLED: return "cancelled";
	case PRSM_STOP_FAILURES: return "failures";
	}
	return "?";
}

static double clamp_u(double u)
{
	return u < U_MIN ? U_MIN : (u > U_MAX ? U_MAX : u);
}

/* ---- samplers ----------------------------------------------------------------------------- */

/* The Sobol sampler's points are the indices of the run's rows (row r of the run is point r;
 * a Saltelli row is one point of 2 d dimensions, A its first d, B the rest), so a block starts
 * its own points by the sequence's direct skip-ahead. The sequence is scrambled once per seed
 * (mc/sobol.h: Joe-Kuo direction numbers, linear matrix scramble and digital shift from the
 * Philox stream (seed, SOBOL_SHIFT_STREAM)), the same in every worker. */
_Static_assert(PRSM_MC_MAX_SAMPLES <= PRSM_SOBOL_MAX_POINTS, "a run's rows must fit in the Sobol sequence");

typedef struct {
	prsm_sampler_kind kind;
	size_t dim;
	uint64_t seed;
	gsl_rng *rng;
	prsm_sobol_seq sobol;
} sampler;

static void sampler_free(sampler *s)
{
	if (s->rng)
		gsl_rng_free(s->rng);
	prsm_sobol_seq_free(&s->sobol);
	memset(s, 0, sizeof *s);
}

/* Returns 0, PRSM_EINVAL (Sobol: dim is 0 or more than PRSM_SOBOL_MAX_DIM) or PRSM_ENOMEM. */
static int sampler_init(sampler *s, prsm_sampler_kind kind, size_t dim, uint64_t seed)
{
	memset(s, 0, sizeof *s);
	s->kind = kind;
	s->dim = dim;
	s->seed = seed;
	s->rng = prsm_rng_alloc(seed, 0);
	if (!s->rng)
		return PRSM_ENOMEM;
	if (kind == PRSM_SAMPLER_SOBOL) {
		int rc = prsm_sobol_seq_init(&s->sobol, dim, 1, seed, SOBOL_SHIFT_STREAM);
		if (rc) {
			sampler_free(s);
			return rc;
		}
	}
	return 0;
}

/* Uniforms of rows [first, first + n) of the run: block stream `stream`. */
static void sampler_block(sampler *s, double *u, size_t n, uint64_t stream, size_t first,
                          size_t *perm)
{
	size_t dim = s->dim;
	switch (s->kind) {
	case PRSM_SAMPLER_RANDOM:
		prsm_rng_set_stream(s->rng, s->seed, stream);
		prsm_rng_fill_uniform_pos(s->rng, u, n * dim);
		break;
	case PRSM_SAMPLER_LHS:
		/* one stratified column per dimension: stratum perm[i] of n, uniform inside it */
		prsm_rng_set_stream(s->rng, s->seed, stream);
		for (size_t j = 0; j < dim; j++) {
			for (size_t i = 0; i < n; i++)
				perm[i] = i;
			gsl_ran_shuffle(s->rng, perm, n, sizeof *perm);
			for (size_t i = 0; i < n; i++)
				u[i * dim + j] = clamp_u(((double)perm[i] + prsm_rng_uniform_pos(s->rng)) / (double)n);
		}
		break;
	case PRSM_SAMPLER_SOBOL:
		/* points first .. first + n - 1, already in [U_MIN, U_MAX] (sobol.h) */
		prsm_sobol_seq_block(&s->sobol, u, n, first);
		break;
	}
}

int prsm_mc_block_uniforms(double *u, size_t n, size_t dim, prsm_sampler_kind kind, uint64_t seed,
                           uint64_t stream, size_t first_index, size_t *scratch)
{
	sampler s;
	int rc = sampler_init(&s, kind, dim, seed);
	if (rc)
		return rc;
	sampler_block(&s, u, n, stream, first_index, scratch);
	sampler_free(&s);
	return 0;
}

/* ---- copula ------------------------------------------------------------------------------- */

typedef struct {
	size_t k;                         /* variables involved */
	size_t idx[2 * PRSM_MC_MAX_CORRELATIONS];
	double L[2 * PRSM_MC_MAX_CORRELATIONS][2 * PRSM_MC_MAX_CORRELATIONS]; /* lower Cholesky factor */
} copula;

static int copula_init(copula *c, const prsm_mc_correlation *corr, size_t n_corr, size_t d,
                       prsm_error *err)
{
	/* only the k x k corner of L and the first k indices are ever read; clearing the whole
	 * 128 KiB struct cost 32 page faults per run */
	c->k = 0;
	if (n_corr > PRSM_MC_MAX_CORRELATIONS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "at most %d correlations", PRSM_MC_MAX_CORRELATIONS);
	for (size_t i = 0; i < n_corr; i++) {
		if (corr[i].a >= d || corr[i].b >= d || corr[i].a == corr[i].b)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "correlation %zu names a bad variable pair", i);
		if (!(fabs(corr[i].rho) < 1.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "correlation %zu: |rho| must be < 1", i);
		size_t ab[2] = {corr[i].a, corr[i].b};
		for (int t = 0; t < 2; t++) {
			size_t q = 0;
			while (q < c->k && c->idx[q] != ab[t])
				q++;
			if (q == c->k)
				c->idx[c->k++] = ab[t];
		}
	}
	if (c->k == 0)
		return 0;
	gsl_matrix *m = gsl_matrix_alloc(c->k, c->k);
	if (!m)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	gsl_matrix_set_identity(m);
	for (size_t i = 0; i < n_corr; i++) {
		size_t qa = 0, qb = 0;
		while (c->idx[qa] != corr[i].a)
			qa++;
		while (c->idx[qb] != corr[i].b)
			qb++;
		gsl_matrix_set(m, qa, qb, corr[i].rho);
		gsl_matrix_set(m, qb, qa, corr[i].rho);
	}
	/* needs GSL's error handler off (prsm's main and the service set it once at start) */
	int rc = gsl_linalg_cholesky_decomp1(m);
	if (rc) {
		gsl_matrix_free(m);
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "the correlation matrix is not positive definite");
	}
	for (size_t i = 0; i < c->k; i++)
		for (size_t j = 0; j <= i; j++)
			c->L[i][j] = gsl_matrix_get(m, i, j);
	gsl_matrix_free(m);
	return 0;
}

int prsm_mc_correlation_check(const prsm_mc_correlation *corr, size_t n_corr, size_t d,
                              prsm_error *err)
{
	copula *c = malloc(sizeof *c);
	if (!c)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int rc = copula_init(c, corr, n_corr, d, err);
	free(c);
	return rc;
}

/* Correlate the normal scores of the involved variables of one row of d uniforms. */
static void copula_apply(const copula *c, double *u)
{
	double z[2 * PRSM_MC_MAX_CORRELATIONS];
	if (c->k == 0)
		return;
	for (size_t i = 0; i < c->k; i++)
		z[i] = prsm_normal_quantile(u[c->idx[i]]);
	for (size_t i = c->k; i-- > 0;) {
		double s = 0.0;
		for (size_t j = 0; j <= i; j++)
			s += c->L[i][j] * z[j];
		/* upper tail through Q keeps precision near 1 */
		u[c->idx[i]] = clamp_u(s > 0 ? 1.0 - gsl_cdf_ugaussian_Q(s) : gsl_cdf_ugaussian_P(s));
	}
}

/* ---- the run ------------------------------------------------------------------------------ */

typedef struct {
	const prsm_mc_model *model;
	const prsm_mc_variable *vars;
	size_t d, m, dim, n_groups;
	int saltelli;
	const prsm_mc_options *o;
	size_t block_size, first_block, n_blocks; /* blocks of this run */
	size_t first_row, n_rows;                 /* global index of row 0, rows of this run */
	prsm_mc_result *res;
	/* per block, filled by the worker that ran it */
	unsigned char *block_done;
	prsm_moments *block_mom;                  /* n_blocks x n_targets */
	size_t *block_in;                         /* n_blocks x n_targets: in-spec counts */
	size_t *group_vars;                       /* Saltelli: the variables of group g are */
	size_t *group_start;                      /* group_vars[group_start[g] .. group_start[g + 1]) */
	pthread_mutex_t mu;
	pthread_cond_t cv;
	size_t next_block;                        /* next block a worker takes (run-relative) */
	size_t stop_blocks;                       /* blocks at or beyond are not run/kept */
	copula cop;                               /* last: its 128 KiB factor is not cleared (run_ctx_alloc) */
} run_ctx;

/* A cleared run_ctx but for its copula's factor, of which copula_init writes and copula_apply
 * reads only the k x k corner: clearing it all (calloc) cost 128 KiB of memset per run. */
static run_ctx *run_ctx_alloc(void)
{
	run_ctx *c = malloc(sizeof *c);
	if (c)
		memset(c, 0, offsetof(run_ctx, cop) + offsetof(copula, L));
	return c;
}

typedef struct {
	run_ctx *rc;
	void *ws;
	sampler smp;
	double *u;                                /* block_size x dim */
	size_t *perm;                             /* block_size */
	double *xrow;                             /* d (Saltelli mixed row) */
	double *y;                                /* m */
	pthread_t thread;
	int started;
} worker;

static size_t block_rows(const run_ctx *rc, size_t b)
{
	size_t start = b * rc->block_size;
	size_t end = start + rc->block_size;
	if (end > rc->n_rows)
		end = rc->n_rows;
	return end - start;
}

/* The inputs of nb rows of uniforms u (row stride dim, the row's variables from column c0 on)
 * into x (row stride x_stride; x may be u + c0 with x_stride dim): each row's copula, then the
 * quantiles a variable's column at a time (prsm_dist_quantile_n: the same doubles as one
 * prsm_dist_quantile per value). */
static void to_inputs_block(const run_ctx *rc, double *x, size_t x_stride, double *u, size_t c0, size_t nb)
{
	if (rc->cop.k > 0)
		for (size_t r = 0; r < nb; r++)
			copula_apply(&rc->cop, u + r * rc->dim + c0);
	for (size_t i = 0; i < rc->d; i++)
		prsm_dist_quantile_n(&rc->vars[i].dist, u + c0 + i, rc->dim, x + i, x_stride, nb);
}

/* Evaluate one sample: returns PRSM_SAMPLE_* and the model's code. */
static inline int eval_one(const prsm_mc_model *mdl, void *ws, const double *x, double *y, int *code)
{
	const size_t m = mdl->n_outputs;
	unsigned flags = 0;
	int rc = mdl->eval(y, &flags, mdl->ctx, ws, x);
	*code = rc;
	if (rc)
		return PRSM_SAMPLE_FAILED;
	for (size_t o = 0; o < m; o++)
		if (!isfinite(y[o])) {
			*code = PRSM_ENOCONVERGE;
			return PRSM_SAMPLE_FAILED;
		}
	return (flags & PRSM_MC_FLAG_EDGE) ? PRSM_SAMPLE_EDGE : PRSM_SAMPLE_OK;
}

static void run_block(worker *w, size_t b)
{
	run_ctx *rc = w->rc;
	prsm_mc_result *res = rc->res;
	const prsm_mc_options *o = rc->o;
	const prsm_mc_model *mdl = rc->model;
	size_t nb = block_rows(rc, b);
	size_t row0 = b * rc->block_size;            /* run-relative */
	size_t gb = rc->first_block + b;             /* global block index */
	size_t m = rc->m, d = rc->d;
	sampler_block(&w->smp, w->u, nb, o->stream_offset + gb, rc->first_row + row0, w->perm);
	for (int t = 0; t < o->n_targets; t++) {
		prsm_moments_init(&rc->block_mom[b * (size_t)o->n_targets + (size_t)t]);
		rc->block_in[b * (size_t)o->n_targets + (size_t)t] = 0;
	}
	if (!rc->saltelli) {
		/* the block's inputs straight into the result: its rows are one range, faulted in at once */
		double *xb = res->x + row0 * d;
		prsm_mem_populate(xb, nb * d * sizeof *xb);
		to_inputs_block(rc, xb, d, w->u, 0, nb);
		for (size_t i = 0; i < nb; i++) {
			size_t r = row0 + i;
			int code = 0;
			double *x = xb + i * d;
			double *y = res->y + r * m;
			int st = eval_one(mdl, w->ws, x, y, &code);
			if (st == PRSM_SAMPLE_FAILED)
				for (size_t k = 0; k < m; k++)
					y[k] = NAN;
			if (prsm_mc_sample_kept(o, st))
				for (int t = 0; t < o->n_targets; t++) {
					const prsm_mc_target *tg = &o->targets[t];
					double v = y[tg->output];
					size_t q = b * (size_t)o->n_targets + (size_t)t;
					prsm_moments_add(&rc->block_mom[q], v);
					if ((!tg->has_lower || v >= tg->lower) && (!tg->has_upper || v <= tg->upper))
						rc->block_in[q]++;
				}
			res->status[r] = (unsigned char)st;
			res->fail_code[r] = code;
		}
		return;
	}
	/* Saltelli: A = u[0..d), B = u[d..2d) of each row, their inputs in place; rows A, B, then A
	 * with group g's columns from B (the mixed row starts as A; group g's variables are set from
	 * B for its evaluation and back from A after it) */
	const size_t dim = rc->dim, G = rc->n_groups, K = G + 2, n = rc->n_rows;
	to_inputs_block(rc, w->u, dim, w->u, 0, nb);
	to_inputs_block(rc, w->u + d, dim, w->u, d, nb);
	for (size_t i = 0; i < nb; i++) {
		size_t r = row0 + i;
		const double *xa = w->u + i * dim, *xb = xa + d;
		int code = 0, st = PRSM_SAMPLE_OK;
		memcpy(w->xrow, xa, d * sizeof *xa);
		for (size_t k = 0; k < K && st != PRSM_SAMPLE_FAILED; k++) {
			const double *x = k == 0 ? xa : (k == 1 ? xb : w->xrow);
			const size_t *gv = NULL, *ge = NULL;
			if (k >= 2) {
				gv = rc->group_vars + rc->group_start[k - 2];
				ge = rc->group_vars + rc->group_start[k - 1];
				for (const size_t *v = gv; v < ge; v++)
					w->xrow[*v] = xb[*v];
			}
			int s1 = eval_one(mdl, w->ws, x, w->y, &code);
			if (s1 == PRSM_SAMPLE_FAILED || s1 == PRSM_SAMPLE_EDGE)
				st = s1;
			for (size_t oo = 0; oo < m; oo++)
				res->ys[(oo * K + k) * n + r] = s1 == PRSM_SAMPLE_FAILED ? NAN : w->y[oo];
			for (const size_t *v = gv; v < ge; v++)
				w->xrow[*v] = xa[*v];
		}
		res->status[r] = (unsigned char)st;
		res->fail_code[r] = code;
	}
}

static void *worker_main(void *arg)
{
	worker *w = arg;
	run_ctx *rc = w->rc;
	for (;;) {
		pthread_mutex_lock(&rc->mu);
		size_t b = rc->next_block;
		if (b >= rc->stop_blocks) {
			pthread_mutex_unlock(&rc->mu);
			break;
		}
		rc->next_block++;
		pthread_mutex_unlock(&rc->mu);
		run_block(w, b);
		pthread_mutex_lock(&rc->mu);
		rc->block_done[b] = 1;
		pthread_cond_broadcast(&rc->cv);
		pthread_mutex_unlock(&rc->mu);
	}
	return NULL;
}

static void worker_free(worker *w)
{
	if (w->ws && w->rc->model->workspace_free)
		w->rc->model->workspace_free(w->ws);
	sampler_free(&w->smp);
	free(w->u);
	free(w->perm);
	free(w->xrow);
	free(w->y);
}

static int worker_init(worker *w, run_ctx *rc, prsm_sampler_kind kind)
{
	memset(w, 0, sizeof *w);
	w->rc = rc;
	const prsm_mc_model *mdl = rc->model;
	if (mdl->workspace_alloc && mdl->workspace_alloc(&w->ws, mdl->ctx))
		return PRSM_ENOMEM;
	int r = sampler_init(&w->smp, kind, rc->dim, rc->o->seed);
	if (r)
		return r;
	w->u = malloc(rc->block_size * rc->dim * sizeof *w->u);
	w->perm = malloc(rc->block_size * sizeof *w->perm);
	w->xrow = malloc(rc->d * sizeof *w->xrow);
	w->y = malloc((rc->m ? rc->m : 1) * sizeof *w->y);
	if (!w->u || !w->perm || !w->xrow || !w->y)
		return PRSM_ENOMEM;
	return 0;
}

void prsm_mc_result_free(prsm_mc_result *r)
{
	if (!r)
		return;
	free(r->x);
	free(r->y);
	free(r->ys);
	free(r->status);
	free(r->fail_code);
	memset(r, 0, sizeof *r);
}

static int check_options(const prsm_mc_options *o, size_t d, size_t m, prsm_error *err)
{
	if (d == 0 || d > PRSM_MC_MAX_VARIABLES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "variables must be 1..%d, got %zu",
		                      PRSM_MC_MAX_VARIABLES, d);
	if (m == 0 || m > PRSM_MC_MAX_OUTPUTS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "outputs must be 1..%d", PRSM_MC_MAX_OUTPUTS);
	if (o->samples < 2 || o->samples > PRSM_MC_MAX_SAMPLES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "samples must be 2..%d, got %zu",
		                      PRSM_MC_MAX_SAMPLES, o->samples);
	if (o->block_size < PRSM_MC_MIN_BLOCK || o->block_size > PRSM_MC_MAX_BLOCK)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "block size must be %d..%d",
		                      PRSM_MC_MIN_BLOCK, PRSM_MC_MAX_BLOCK);
	if (o->threads < 1 || o->threads > PRSM_MC_MAX_THREADS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "threads must be 1..%d", PRSM_MC_MAX_THREADS);
	if (!(o->max_failed_fraction >= 0.0 && o->max_failed_fraction <= 1.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "max failed fraction must be in [0, 1]");
	if (!(o->time_cap_s >= 0.0) || !isfinite(o->time_cap_s))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "time cap must be finite and >= 0");
	if (o->n_targets < 0 || o->n_targets > PRSM_MC_MAX_TARGETS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "at most %d targets", PRSM_MC_MAX_TARGETS);
	for (int t = 0; t < o->n_targets; t++)
		if (o->targets[t].output >= m || !(o->targets[t].value > 0.0) || !isfinite(o->targets[t].value))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "target %d is invalid", t);
	return 0;
}

/* The figure a target's stop rule compares with its value: the standard error of the mean
 * (output unit), that over |mean|, or the width of the yield's 95 % Wilson interval; NAN
 * before two samples (or a zero mean for CV). */
static double target_figure(const prsm_mc_target *tg, const prsm_moments *mom, size_t in)
{
	if (mom->n < 2)
		return NAN;
	double se = prsm_moments_sd(mom) / sqrt((double)mom->n);
	switch (tg->kind) {
	case PRSM_TARGET_SE:
		return se;
	case PRSM_TARGET_CV:
		return mom->mean != 0.0 ? se / fabs(mom->mean) : NAN;
	case PRSM_TARGET_YIELD_WIDTH: {
		double lo, hi;
		prsm_stats_wilson(in, mom->n, 1.959963984540054, &lo, &hi);
		return hi - lo;
	}
	}
	return NAN;
}

static int target_met(const prsm_mc_target *tg, const prsm_moments *mom, size_t in)
{
	double f = target_figure(tg, mom, in);
	return !isnan(f) && f <= tg->value;
}

/* Progress of a run: prefix samples of the cap and, with targets, the figure of the target
 * furthest from its goal (the largest figure / goal; a target without a figure yet counts as
 * furthest). */
static void report_progress(const prsm_mc_options *o, size_t done, size_t cap, const prsm_moments *mom,
                            const size_t *in, size_t nt)
{
	prsm_progress p = PRSM_PROGRESS_INIT;
	p.done = done;
	p.planned = cap;
	double worst = -1.0;
	for (size_t t = 0; t < nt; t++) {
		double f = target_figure(&o->targets[t], &mom[t], in[t]);
		double ratio = isnan(f) ? INFINITY : f / o->targets[t].value;
		if (ratio > worst) {
			worst = ratio;
			p.interval_width = f;
			p.interval_goal = o->targets[t].value;
		}
	}
	o->progress(o->progress_ctx, &p);
}

void prsm_mc_prefix_init(prsm_mc_prefix *p)
{
	memset(p, 0, sizeof *p);
	for (size_t t = 0; t < PRSM_MC_MAX_TARGETS; t++)
		prsm_moments_init(&p->mom[t]);
}

/* Merge one block into the prefix: its targets' moments and in-spec counts (bmom, bin), its
 * failed and edge samples (status, fail_code: nb rows, the first at global row first_row); then
 * the failure policy and, when check_targets, the targets on the prefix. Returns 0 to go on, or
 * 1 with *stop and *code (the abort policy's error, with err) when the run stops here. The one
 * statement of the stop rules: the run's merge loop and prsm_mc_prefix_add both call it. */
static int prefix_merge(prsm_mc_prefix *p, const prsm_mc_options *o, const prsm_moments *bmom, const size_t *bin,
                        const unsigned char *status, const int *fail_code, size_t nb, size_t first_row,
                        int check_targets, prsm_stop_reason *stop, int *code, prsm_error *err)
{
	const size_t nt = (size_t)o->n_targets;
	*code = 0;
	for (size_t t = 0; t < nt; t++) {
		prsm_moments_merge(&p->mom[t], &bmom[t]);
		p->in[t] += bin[t];
	}
	size_t first_bad = SIZE_MAX;
	for (size_t i = 0; i < nb; i++) {
		int st = status[i];
		if (st == PRSM_SAMPLE_FAILED) {
			p->failed++;
			if (first_bad == SIZE_MAX)
				first_bad = i;
		} else if (st == PRSM_SAMPLE_EDGE) {
			p->edge++;
			if (o->edge == PRSM_EDGE_EXCLUDE && first_bad == SIZE_MAX)
				first_bad = i;
		}
	}
	p->blocks++;
	p->rows += nb;
	if (o->failure == PRSM_FAILURE_ABORT && first_bad != SIZE_MAX) {
		int st = status[first_bad];
		int fc = fail_code[first_bad];
		/* a computation failure (exit 2) whatever the model's own code was */
		if (st == PRSM_SAMPLE_EDGE)
			*code = prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
			                       "sample %zu has an edge contact (failure policy: abort)", first_row + first_bad);
		else
			*code = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "sample %zu failed (%s%s) (failure policy: abort)",
			                       first_row + first_bad, prsm_error_name(fc ? fc : PRSM_ENOCONVERGE),
			                       fc == PRSM_EINVAL ? ": the model refused the sampled values, e.g. a "
			                                           "negative friction coefficient"
			                       : fc == PRSM_ENOCONVERGE || !fc ? ": a solve did not converge" : "");
		*stop = PRSM_STOP_FAILURES;
		return 1;
	}
	size_t bad = p->failed + (o->edge == PRSM_EDGE_EXCLUDE ? p->edge : 0);
	if (o->failure == PRSM_FAILURE_SKIP && (double)bad > o->max_failed_fraction * (double)p->rows) {
		*stop = PRSM_STOP_FAILURES;
		return 1;
	}
	if (check_targets && p->rows >= o->min_samples) {
		int all = 1;
		for (size_t t = 0; t < nt; t++)
			all = all && target_met(&o->targets[t], &p->mom[t], p->in[t]);
		if (all) {
			*stop = PRSM_STOP_TARGET;
			return 1;
		}
	}
	return 0;
}

int prsm_mc_prefix_add(prsm_mc_prefix *p, const prsm_mc_options *o, size_t m, size_t total_blocks,
                       const double *y, const unsigned char *status, const int *fail_code, size_t nb,
                       prsm_stop_reason *stop, int *code, prsm_error *err)
{
	/* the block's moments as run_block accumulates them: kept samples in row order */
	const size_t nt = (size_t)o->n_targets;
	prsm_moments bmom[PRSM_MC_MAX_TARGETS];
	size_t bin[PRSM_MC_MAX_TARGETS] = {0};
	for (size_t t = 0; t < nt; t++)
		prsm_moments_init(&bmom[t]);
	for (size_t i = 0; i < nb; i++) {
		if (!prsm_mc_sample_kept(o, status[i]))
			continue;
		for (size_t t = 0; t < nt; t++) {
			const prsm_mc_target *tg = &o->targets[t];
			double v = y[i * m + tg->output];
			prsm_moments_add(&bmom[t], v);
			if ((!tg->has_lower || v >= tg->lower) && (!tg->has_upper || v <= tg->upper))
				bin[t]++;
		}
	}
	return prefix_merge(p, o, bmom, bin, status, fail_code, nb, p->rows, nt && p->blocks + 1 < total_blocks, stop,
	                    code, err);
}

/* prefix_merge of the run's block b (its moments, in-spec counts, statuses and failure codes in
 * c and out); the targets are checked on the prefix unless the run is split or b is its last
 * block. Both merge loops of the run (one worker, several) call it. */
static int merge_block(prsm_mc_prefix *pf, const run_ctx *c, const prsm_mc_options *o, size_t b, int split,
                       prsm_mc_result *out, int *code, prsm_error *err)
{
	const size_t nt = (size_t)o->n_targets, r0 = b * c->block_size;
	return prefix_merge(pf, o, &c->block_mom[b * nt], &c->block_in[b * nt], out->status + r0, out->fail_code + r0,
	                    block_rows(c, b), c->first_row + r0, nt && !split && b + 1 < c->stop_blocks, &out->stop,
	                    code, err);
}

void prsm_mc_prefix_progress(const prsm_mc_prefix *p, const prsm_mc_options *o, size_t cap)
{
	if (o->progress)
		report_progress(o, p->rows, cap, p->mom, p->in, (size_t)o->n_targets);
}

void prsm_mc_prefix_finish(prsm_mc_result *out, const prsm_mc_prefix *p, const prsm_mc_options *o,
                           prsm_stop_reason stop)
{
	out->n = p->rows;
	out->n_failed = p->failed;
	out->n_edge = p->edge;
	out->n_ok = p->rows - p->failed - (o->edge == PRSM_EDGE_EXCLUDE ? p->edge : 0);
	out->stop = stop;
	out->converged = stop == PRSM_STOP_TARGET;
}

/* Check a run's settings and lay out its blocks in c (c->cop too): everything run() refuses
 * before it samples, in its order. *stored gets the values the run stores, *split whether it is
 * a split run. */
static int plan(run_ctx *c, double *stored, int *split, const prsm_mc_model *model, const prsm_mc_variable *vars,
                size_t d, size_t n_groups, int saltelli, const prsm_mc_correlation *corr, size_t n_corr,
                const prsm_mc_options *o, prsm_error *err)
{
	size_t m = model->n_outputs;
	int rc = check_options(o, d, m, err);
	if (rc)
		return rc;
	for (size_t i = 0; i < d; i++) {
		char msg[160];
		if (prsm_dist_check(&vars[i].dist, msg, sizeof msg))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "variable %zu: %s", i, msg);
		if (saltelli && (vars[i].group < 0 || (size_t)vars[i].group >= n_groups))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "variable %zu has no group", i);
	}
	if (saltelli && (n_groups == 0 || n_groups > PRSM_MC_MAX_GROUPS))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "groups must be 1..%d", PRSM_MC_MAX_GROUPS);
	c->model = model;
	c->vars = vars;
	c->d = d;
	c->m = m;
	c->saltelli = saltelli;
	c->n_groups = n_groups;
	c->dim = saltelli ? 2 * d : d;
	c->o = o;
	c->block_size = o->block_size;
	rc = copula_init(&c->cop, corr, n_corr, d, err);
	if (rc)
		return rc;

	/* blocks of this run */
	size_t total_blocks = (o->samples + o->block_size - 1) / o->block_size;
	if (o->first_block >= total_blocks)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "first block %zu is past the last block %zu",
		                      o->first_block, total_blocks - 1);
	c->first_block = o->first_block;
	c->n_blocks = total_blocks - o->first_block;
	if (o->block_count && o->block_count < c->n_blocks)
		c->n_blocks = o->block_count;
	c->first_row = c->first_block * o->block_size;
	c->n_rows = c->n_blocks * o->block_size;
	if (c->first_row + c->n_rows > o->samples)
		c->n_rows = o->samples - c->first_row;
	*split = o->first_block != 0 || c->n_blocks != total_blocks;

	/* sampler: Sobol runs in any dimension the table has, else the run is refused */
	if (o->sampler == PRSM_SAMPLER_SOBOL && c->dim > PRSM_SOBOL_MAX_DIM)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Sobol sampling has at most %d dimensions, this run needs %zu (%s%zu variables): "
		                      "use the %s sampler", PRSM_SOBOL_MAX_DIM, c->dim, saltelli ? "2 x " : "", d,
		                      saltelli ? "random" : "random or lhs");

	/* storage */
	*stored = saltelli ? (double)m * (double)(n_groups + 2) * (double)c->n_rows : (double)(d + m) * (double)c->n_rows;
	if (*stored > PRSM_MC_MAX_STORED)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "the run would store %.0f values, more than the limit %d: "
		                      "fewer samples, tolerances or outputs", *stored, PRSM_MC_MAX_STORED);
	return 0;
}

int prsm_mc_run_check(const prsm_mc_model *model, const prsm_mc_variable *vars, size_t d,
                      const prsm_mc_correlation *corr, size_t n_corr, const prsm_mc_options *o,
                      prsm_error *err)
{
	run_ctx *c = run_ctx_alloc();
	if (!c)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	double stored;
	int split;
	int rc = plan(c, &stored, &split, model, vars, d, 0, 0, corr, n_corr, o, err);
	free(c);
	return rc;
}

/* Keep the merged prefix pf of the run in out. */
static void finish_prefix(prsm_mc_result *out, const run_ctx *c, const prsm_mc_prefix *pf, const prsm_mc_options *o,
                          int saltelli, size_t n_groups, size_t m)
{
	const size_t prefix_rows = pf->rows;
	prsm_mc_prefix_finish(out, pf, o, out->stop);
	if (saltelli && prefix_rows < c->n_rows) {
		/* compact [o][k][j] to the kept rows */
		size_t K = n_groups + 2;
		for (size_t q = 1; q < m * K; q++)
			memmove(out->ys + q * prefix_rows, out->ys + q * c->n_rows, prefix_rows * sizeof *out->ys);
	}
}

/* Shared body of the two runs. */
static int run(prsm_mc_result *out, const prsm_mc_model *model, const prsm_mc_variable *vars,
               size_t d, size_t n_groups, int saltelli, const prsm_mc_correlation *corr,
               size_t n_corr, const prsm_mc_options *o, prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	size_t m = model->n_outputs;
	memset(out, 0, sizeof *out);
	run_ctx *c = run_ctx_alloc();
	worker *ws = NULL;
	int nthreads = 0;
	if (!c)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	double stored = 0.0;
	int split = 0;
	int rc = plan(c, &stored, &split, model, vars, d, n_groups, saltelli, corr, n_corr, o, err);
	if (rc)
		goto cleanup;
	out->sampler = o->sampler;
	if (saltelli && out->sampler == PRSM_SAMPLER_LHS)
		out->sampler = PRSM_SAMPLER_RANDOM; /* A and B from one LHS row would not be independent */

	out->n = c->n_rows;
	out->d = d;
	out->m = m;
	out->n_groups = saltelli ? n_groups : 0;
	out->first_sample = c->first_row;
	out->status = malloc(c->n_rows);
	out->fail_code = calloc(c->n_rows, sizeof *out->fail_code);
	if (saltelli) {
		out->ys = malloc((size_t)stored * sizeof *out->ys);
	} else {
		out->x = malloc(c->n_rows * d * sizeof *out->x);
		out->y = malloc(c->n_rows * m * sizeof *out->y);
	}
	size_t nt = (size_t)o->n_targets;
	c->block_done = calloc(c->n_blocks, 1);
	c->block_mom = calloc(c->n_blocks * (nt ? nt : 1), sizeof *c->block_mom);
	c->block_in = calloc(c->n_blocks * (nt ? nt : 1), sizeof *c->block_in);
	if (!out->status || !out->fail_code || (saltelli ? !out->ys : (!out->x || !out->y)) ||
	    !c->block_done || !c->block_mom || !c->block_in) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu samples", c->n_rows);
		goto cleanup;
	}
	memset(out->status, PRSM_SAMPLE_UNRUN, c->n_rows);
	if (saltelli) {
		/* every row is written (a Saltelli run has no target to stop it early): fault its pages
		 * in at once */
		prsm_mem_populate(out->ys, (size_t)stored * sizeof *out->ys);
		c->group_vars = malloc(d * sizeof *c->group_vars);
		c->group_start = malloc((n_groups + 1) * sizeof *c->group_start);
		if (!c->group_vars || !c->group_start) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		size_t q = 0;
		for (size_t g = 0; g < n_groups; g++) {
			c->group_start[g] = q;
			for (size_t v = 0; v < d; v++)
				if ((size_t)vars[v].group == g)
					c->group_vars[q++] = v;
		}
		c->group_start[n_groups] = q;
	}
	c->res = out;
	c->stop_blocks = c->n_blocks;
	pthread_mutex_init(&c->mu, NULL);
	prsm_cond_init_monotonic(&c->cv);

	/* workers */
	int want = o->threads;
	if ((size_t)want > c->n_blocks)
		want = (int)c->n_blocks;
	ws = calloc((size_t)want, sizeof *ws);
	if (!ws) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto destroy;
	}
	for (int t = 0; t < want; t++) {
		int r = worker_init(&ws[t], c, out->sampler);
		nthreads = t + 1;
		if (r) {
			rc = prsm_error_set(err, r, NULL, "cannot set up a worker (%s)", prsm_error_name(r));
			goto destroy;
		}
	}
	if (want == 1) {
		/* one worker: the calling thread runs the blocks itself, in order, merging each as it
		 * ends (the same blocks and merge as with threads, so the same result). Cancel and the
		 * time cap are looked at as each block ends: either drops that block and stops, as the
		 * threads' merge loop drops the block it was waiting for */
		prsm_mc_prefix pf;
		prsm_mc_prefix_init(&pf);
		out->stop = PRSM_STOP_SAMPLE_CAP;
		double last_progress = -1.0;
		for (size_t b = 0; b < c->stop_blocks; b++) {
			run_block(&ws[0], b);
			const double now = prsm_clock_seconds();
			if (prsm_cancel_requested(o->cancel)) {
				out->stop = PRSM_STOP_CANCELLED;
				break;
			}
			if (o->time_cap_s > 0.0 && now - t0 > o->time_cap_s) {
				out->stop = PRSM_STOP_TIME_CAP;
				break;
			}
			int code = 0;
			if (merge_block(&pf, c, o, b, split, out, &code, err)) {
				rc = code;
				break;
			}
			if (o->progress && b + 1 < c->stop_blocks && now - last_progress >= 0.2) {
				last_progress = now;
				report_progress(o, pf.rows, c->n_rows, pf.mom, pf.in, split ? 0 : nt);
			}
		}
		if (o->progress)
			report_progress(o, pf.rows, c->n_rows, pf.mom, pf.in, split ? 0 : nt);
		finish_prefix(out, c, &pf, o, saltelli, n_groups, m);
		goto destroy;
	}
	pthread_mutex_lock(&c->mu);
	for (int t = 0; t < want; t++)
		if (pthread_create(&ws[t].thread, NULL, worker_main, &ws[t]) == 0)
			ws[t].started = 1;
	int started = 0;
	for (int t = 0; t < want; t++)
		started += ws[t].started;
	if (!started) {
		c->stop_blocks = 0;
		pthread_mutex_unlock(&c->mu);
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "cannot start a worker thread");
		goto destroy;
	}

	/* merge the completed prefix in block order; check the stop rules on it */
	prsm_mc_prefix pf;
	prsm_mc_prefix_init(&pf);
	out->stop = PRSM_STOP_SAMPLE_CAP;
	double last_progress = -1.0;
	while (pf.blocks < c->stop_blocks) {
		const size_t prefix = pf.blocks;
		if (c->block_done[prefix]) {
			int code = 0;
			if (merge_block(&pf, c, o, prefix, split, out, &code, err)) {
				rc = code;
				c->stop_blocks = pf.blocks;
				break;
			}
			continue;
		}
		/* wait for the next block, waking now and then for the caps and the progress */
		prsm_cond_wait_for(&c->cv, &c->mu, 0.1);
		double now = prsm_clock_seconds();
		if (prsm_cancel_requested(o->cancel)) {
			c->stop_blocks = pf.blocks;
			out->stop = PRSM_STOP_CANCELLED;
			break;
		}
		if (o->time_cap_s > 0.0 && now - t0 > o->time_cap_s) {
			c->stop_blocks = pf.blocks;
			out->stop = PRSM_STOP_TIME_CAP;
			break;
		}
		if (o->progress && now - last_progress >= 0.2) {
			last_progress = now;
			pthread_mutex_unlock(&c->mu);
			report_progress(o, pf.rows, c->n_rows, pf.mom, pf.in, split ? 0 : nt);
			pthread_mutex_lock(&c->mu);
		}
	}
	pthread_mutex_unlock(&c->mu);
	for (int t = 0; t < want; t++)
		if (ws[t].started)
			pthread_join(ws[t].thread, NULL);
	if (o->progress)
		report_progress(o, pf.rows, c->n_rows, pf.mom, pf.in, split ? 0 : nt);

	finish_prefix(out, c, &pf, o, saltelli, n_groups, m);

destroy:
	for (int t = 0; t < nthreads; t++)
		worker_free(&ws[t]);
	free(ws);
	pthread_cond_destroy(&c->cv);
	pthread_mutex_destroy(&c->mu);
cleanup:
	if (c) {
		free(c->block_done);
		free(c->block_mom);
		free(c->block_in);
		free(c->group_vars);
		free(c->group_start);
	}
	free(c);
	out->elapsed_s = prsm_clock_seconds() - t0;
	if (rc)
		prsm_mc_result_free(out);
	return rc;
}

int prsm_mc_run(prsm_mc_result *out, const prsm_mc_model *model, const prsm_mc_variable *vars,
                size_t d, const prsm_mc_correlation *corr, size_t n_corr, const prsm_mc_options *o,
                prsm_error *err)
{
	return run(out, model, vars, d, 0, 0, corr, n_corr, o, err);
}

int prsm_mc_run_saltelli(prsm_mc_result *out, const prsm_mc_model *model,
                         const prsm_mc_variable *vars, size_t d, size_t n_groups,
                         const prsm_mc_correlation *corr, size_t n_corr,
                         const prsm_mc_options *o, prsm_error *err)
{
	return run(out, model, vars, d, n_groups, 1, corr, n_corr, o, err);
}

int prsm_mc_result_concat(prsm_mc_result *out, const prsm_mc_result *a, const prsm_mc_result *b,
                          prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (a->d != b->d || a->m != b->m || a->ys || b->ys || a->first_sample + a->n != b->first_sample)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "runs do not follow each other (first %zu + %zu rows, then %zu)",
		                      a->first_sample, a->n, b->first_sample);
	size_t n = a->n + b->n, d = a->d, m = a->m;
	*out = *a;
	out->x = malloc(n * d * sizeof *out->x);
	out->y = malloc(n * m * sizeof *out->y);
	out->status = malloc(n ? n : 1);
	out->fail_code = malloc((n ? n : 1) * sizeof *out->fail_code);
	out->ys = NULL;
	if (!out->x || !out->y || !out->status || !out->fail_code) {
		prsm_mc_result_free(out);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	memcpy(out->x, a->x, a->n * d * sizeof *out->x);
	memcpy(out->x + a->n * d, b->x, b->n * d * sizeof *out->x);
	memcpy(out->y, a->y, a->n * m * sizeof *out->y);
	memcpy(out->y + a->n * m, b->y, b->n * m * sizeof *out->y);
	memcpy(out->status, a->status, a->n);
	memcpy(out->status + a->n, b->status, b->n);
	memcpy(out->fail_code, a->fail_code, a->n * sizeof *out->fail_code);
	memcpy(out->fail_code + a->n, b->fail_code, b->n * sizeof *out->fail_code);
	out->n = n;
	out->n_ok = a->n_ok + b->n_ok;
	out->n_failed = a->n_failed + b->n_failed;
	out->n_edge = a->n_edge + b->n_edge;
	out->stop = b->stop;
	out->elapsed_s = a->elapsed_s + b->elapsed_s;
	return 0;
}
