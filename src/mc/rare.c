/*
 * rare.c: the rare-event engine's common parts (rare.h): options, the map U -> X, the pool of
 * worker threads, the "auto" rule, the one-call orchestrator and the spec limit state. FORM and
 * SORM are in rare_form.c, importance sampling and subset simulation in rare_sample.c.
 *
 * The pool: a batch of n tasks runs on min(threads, n) threads, the calling thread being one of
 * them; the others are started for the batch and joined at its end (a join orders everything
 * they wrote before what the caller reads next). Tasks are taken from an atomic counter and
 * write only their own slots, so which thread ran a task never shows in a result. Each worker
 * owns the limit state's workspace, its scratch vectors and one Philox generator that a task
 * sets to its own stream.
 */
#include "mc/rare.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "mc/rare_internal.h"
#include "util/clock.h"
#include "util/rng.h"

int prsm_rare_options_init(prsm_rare_options *o)
{
	const prsm_rare_options d = PRSM_RARE_OPTIONS_INIT;
	*o = d;
	return 0;
}

static int pos_finite(double v)
{
	return v > 0.0 && isfinite(v);
}

int prsm_rare_options_check(const prsm_rare_options *o, size_t d, prsm_error *err)
{
	if (d == 0 || d > PRSM_MC_MAX_VARIABLES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "variables must be 1..%d, got %zu", PRSM_MC_MAX_VARIABLES, d);
	if (o->threads < 1 || o->threads > PRSM_MC_MAX_THREADS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "threads must be 1..%d", PRSM_MC_MAX_THREADS);
	if (!(o->time_cap_s >= 0.0) || !isfinite(o->time_cap_s))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "time cap must be finite and >= 0");
	if (o->max_evaluations < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "max evaluations must be >= 1");
	if (!(o->target_cov > 0.0 && o->target_cov < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "target CoV must be in (0, 1)");
	if (!(o->is_max_cov_error > 0.0) || !isfinite(o->is_max_cov_error))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the IS CoV error limit must be finite and > 0");
	if (o->form_max_iterations < 1 || o->form_max_iterations > 100000)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "FORM iterations must be 1..100000");
	if (!pos_finite(o->form_tol_g) || !pos_finite(o->form_tol_u))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "FORM tolerances must be > 0");
	if (!(o->fd_step > 0.0 && o->fd_step <= 0.1) || !(o->hessian_step > 0.0 && o->hessian_step <= 0.5))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "finite-difference steps must be in (0, 0.1] (gradient) and (0, 0.5] (Hessian)");
	if (o->line_search_max < 1 || o->line_search_max > 100)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "line search trials must be 1..100");
	if (!(o->armijo > 0.0 && o->armijo < 1.0) || !(o->backtrack > 0.0 && o->backtrack < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "Armijo and backtracking factors must be in (0, 1)");
	if (o->n_starts > PRSM_RARE_MAX_STARTS || (o->n_starts > 0 && o->starts == NULL))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "at most %d starting points, given as n_starts x d values",
		                      PRSM_RARE_MAX_STARTS);
	for (size_t i = 0; i < o->n_starts * d; i++)
		if (!isfinite(o->starts[i]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "starting point %zu is not finite", i / d);
	if (o->block_size < 16 || o->block_size > PRSM_MC_MAX_BLOCK || o->round_blocks < 1 || o->round_blocks > 1024)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "block size must be 16..%d and round blocks 1..1024",
		                      PRSM_MC_MAX_BLOCK);
	if (o->max_samples < 2 || o->min_samples > o->max_samples || o->pilot_samples < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "samples: need 2 <= max samples, min samples <= max samples, pilot >= 1");
	if (!(o->subset_p0 >= 0.01 && o->subset_p0 <= 0.5))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "subset p0 must be in [0.01, 0.5]");
	double nc = floor(o->subset_p0 * (double)o->subset_samples + 0.5);
	if (o->subset_samples < 20 || o->subset_samples > 10000000 || nc < 2 || nc >= (double)o->subset_samples)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "subset samples per level must be 20..10000000 with at least 2 chains (p0 N)");
	if (o->subset_max_levels < 2 || o->subset_max_levels > PRSM_RARE_MAX_LEVELS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "subset levels must be 2..%d", PRSM_RARE_MAX_LEVELS);
	if (o->subset_proposal != PRSM_RARE_PROPOSAL_NORMAL && o->subset_proposal != PRSM_RARE_PROPOSAL_UNIFORM)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "unknown subset proposal");
	if (!(o->subset_width > 0.0 && o->subset_width <= 10.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "subset proposal width must be in (0, 10]");
	return 0;
}

static const char *const method_names[] = {"auto", "mc", "form", "sorm", "is", "subset"};

const char *prsm_rare_method_name(prsm_rare_method m)
{
	if ((int)m < 0 || (int)m > PRSM_RARE_SUBSET)
		return "?";
	return method_names[m];
}

int prsm_rare_method_parse(const char *name, prsm_rare_method *out)
{
	for (int m = 0; m <= PRSM_RARE_SUBSET; m++)
		if (strcmp(name, method_names[m]) == 0) {
			*out = (prsm_rare_method)m;
			return 0;
		}
	return PRSM_ENOTFOUND;
}

const char *prsm_rare_stop_name(prsm_rare_stop s)
{
	switch (s) {
	case PRSM_RARE_STOP_CONVERGED: return "converged";
	case PRSM_RARE_STOP_MAX_ITERATIONS: return "max_iterations";
	case PRSM_RARE_STOP_MAX_SAMPLES: return "max_samples";
	case PRSM_RARE_STOP_MAX_EVALUATIONS: return "max_evaluations";
	case PRSM_RARE_STOP_LINE_SEARCH: return "line_search";
	case PRSM_RARE_STOP_ZERO_GRADIENT: return "zero_gradient";
	case PRSM_RARE_STOP_MAX_LEVELS: return "max_levels";
	case PRSM_RARE_STOP_STAGNATION: return "stagnation";
	case PRSM_RARE_STOP_CURVATURE: return "curvature";
	case PRSM_RARE_STOP_FORM: return "form_not_converged";
	case PRSM_RARE_STOP_TIME_CAP: return "time_cap";
	case PRSM_RARE_STOP_CANCELLED: return "cancelled";
	}
	return "?";
}

/* ---- numeric helpers ------------------------------------------------------------------------ */

double rare_phi_minus(double b)
{
	return gsl_cdf_ugaussian_Q(b);
}

double rare_beta_of(double p)
{
	if (!(p >= 0.0 && p <= 1.0))
		return NAN;
	return gsl_cdf_ugaussian_Qinv(p);
}

double rare_dot(const double *a, const double *b, size_t n)
{
	double s = 0.0;
	for (size_t i = 0; i < n; i++)
		s += a[i] * b[i];
	return s;
}

double rare_norm(const double *a, size_t n)
{
	return sqrt(rare_dot(a, a, n));
}

/* ---- the map U -> X ------------------------------------------------------------------------- */

/* Beyond this |z| every normal tail probability is 0 or 1 in doubles. */
#define Z_MAX 37.5

/* x = F^-1(Phi(z)) of one marginal (rare.h, "The space"). */
static double marginal(const prsm_dist *dist, double z)
{
	const double *p = dist->p;
	if (z > Z_MAX)
		z = Z_MAX;
	else if (z < -Z_MAX)
		z = -Z_MAX;
	switch (dist->kind) {
	case PRSM_DIST_NORMAL:
		return p[0] + p[1] * z;
	case PRSM_DIST_LOGNORMAL:
		return exp(p[0] + p[1] * z);
	case PRSM_DIST_RAYLEIGH: {
		/* F^-1(v) = sigma sqrt(-2 ln(1 - v)), 1 - v = Q(z) */
		double t = z > 0.0 ? -2.0 * log(gsl_cdf_ugaussian_Q(z)) : -2.0 * log1p(-gsl_cdf_ugaussian_P(z));
		return p[0] * sqrt(t);
	}
	case PRSM_DIST_UNIFORM: {
		double w = p[1] - p[0];
		double x = z <= 0.0 ? p[0] + w * gsl_cdf_ugaussian_P(z) : p[1] - w * gsl_cdf_ugaussian_Q(z);
		return x < p[0] ? p[0] : (x > p[1] ? p[1] : x);
	}
	default:
		return prsm_dist_quantile(dist, z <= 0.0 ? gsl_cdf_ugaussian_P(z) : 1.0 - gsl_cdf_ugaussian_Q(z));
	}
}

int rare_space_init(rare_space *s, const prsm_rare_problem *p, prsm_error *err)
{
	memset(s, 0, sizeof *s);
	s->p = p;
	s->d = p->d;
	if (p->d == 0 || p->d > PRSM_MC_MAX_VARIABLES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "variables must be 1..%d, got %zu", PRSM_MC_MAX_VARIABLES, p->d);
	if (p->vars == NULL || p->limit.g == NULL)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the problem needs variables and a limit state");
	for (size_t i = 0; i < p->d; i++) {
		char msg[160];
		if (prsm_dist_check(&p->vars[i].dist, msg, sizeof msg))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "variable %zu: %s", i, msg);
	}
	if (p->n_corr == 0)
		return 0;
	if (p->corr == NULL)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%zu correlations given without their array", p->n_corr);
	/* the engine's own check (pairs, |rho| < 1, positive definite), then the factor here */
	int rc = prsm_mc_correlation_check(p->corr, p->n_corr, p->d, err);
	if (rc)
		return rc;
	size_t kmax = 2 * p->n_corr;
	s->idx = malloc(kmax * sizeof *s->idx);
	s->L = calloc(kmax * kmax, sizeof *s->L);
	if (!s->idx || !s->L) {
		rare_space_free(s);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	/* variables in order of first mention, as mc/engine.c's copula_init */
	for (size_t i = 0; i < p->n_corr; i++) {
		size_t ab[2] = {p->corr[i].a, p->corr[i].b};
		for (int t = 0; t < 2; t++) {
			size_t q = 0;
			while (q < s->k && s->idx[q] != ab[t])
				q++;
			if (q == s->k)
				s->idx[s->k++] = ab[t];
		}
	}
	size_t k = s->k;
	double *a = s->L;
	for (size_t i = 0; i < k; i++)
		a[i * k + i] = 1.0;
	for (size_t i = 0; i < p->n_corr; i++) {
		size_t qa = 0, qb = 0;
		while (s->idx[qa] != p->corr[i].a)
			qa++;
		while (s->idx[qb] != p->corr[i].b)
			qb++;
		a[qa * k + qb] = a[qb * k + qa] = p->corr[i].rho;
	}
	/* Cholesky in place (lower), Cholesky-Banachiewicz */
	for (size_t i = 0; i < k; i++) {
		for (size_t j = 0; j <= i; j++) {
			double sum = a[i * k + j];
			for (size_t q = 0; q < j; q++)
				sum -= a[i * k + q] * a[j * k + q];
			if (i == j) {
				if (!(sum > 0.0)) {
					rare_space_free(s);
					return prsm_error_set(err, PRSM_EINVAL, NULL, "the correlation matrix is not positive definite");
				}
				a[i * k + i] = sqrt(sum);
			} else {
				a[i * k + j] = sum / a[j * k + j];
			}
		}
		for (size_t j = i + 1; j < k; j++)
			a[i * k + j] = 0.0;
	}
	return 0;
}

void rare_space_free(rare_space *s)
{
	free(s->idx);
	free(s->L);
	s->idx = NULL;
	s->L = NULL;
	s->k = 0;
}

void rare_space_to_x(const rare_space *s, const double *u, double *z, double *x)
{
	size_t d = s->d, k = s->k;
	memcpy(z, u, d * sizeof *z);
	for (size_t i = 0; i < k; i++) {
		double sum = 0.0;
		for (size_t j = 0; j <= i; j++)
			sum += s->L[i * k + j] * u[s->idx[j]];
		z[s->idx[i]] = sum;
	}
	for (size_t i = 0; i < d; i++)
		x[i] = marginal(&s->p->vars[i].dist, z[i]);
}

void rare_space_importance(const rare_space *s, const double *alpha, double *out)
{
	size_t d = s->d, k = s->k;
	memcpy(out, alpha, d * sizeof *out);
	double w[2 * PRSM_MC_MAX_CORRELATIONS];
	/* L^T w = alpha on the correlated variables (back substitution) */
	for (size_t i = k; i-- > 0;) {
		double sum = alpha[s->idx[i]];
		for (size_t j = i + 1; j < k; j++)
			sum -= s->L[j * k + i] * w[j];
		w[i] = sum / s->L[i * k + i];
	}
	for (size_t i = 0; i < k; i++)
		out[s->idx[i]] = w[i];
	double ss = 0.0;
	for (size_t i = 0; i < d; i++)
		ss += out[i] * out[i];
	for (size_t i = 0; i < d; i++)
		out[i] = ss > 0.0 ? out[i] * out[i] / ss : 0.0;
}

int prsm_rare_u_to_x(const prsm_rare_problem *p, const double *u, double *x, prsm_error *err)
{
	rare_space s;
	int rc = rare_space_init(&s, p, err);
	if (rc)
		return rc;
	double *z = malloc(p->d * sizeof *z);
	if (!z) {
		rare_space_free(&s);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	rare_space_to_x(&s, u, z, x);
	free(z);
	rare_space_free(&s);
	return 0;
}

/* ---- the pool ------------------------------------------------------------------------------- */

static void worker_free(rare_worker *w, const prsm_rare_limit_state *ls)
{
	if (w->ws && ls->workspace_free)
		ls->workspace_free(w->ws);
	if (w->rng)
		gsl_rng_free(w->rng);
	free(w->x);
	free(w->z);
	free(w->a);
	free(w->b);
	memset(w, 0, sizeof *w);
}

int rare_pool_init(rare_pool *pool, const rare_space *s, const prsm_rare_options *o, prsm_error *err)
{
	memset(pool, 0, sizeof *pool);
	pool->space = s;
	pool->o = o;
	pool->t0 = prsm_clock_seconds();
	pool->last_progress = pool->t0;
	atomic_init(&pool->halt, 0);
	atomic_init(&pool->next, 0);
	pool->w = calloc((size_t)o->threads, sizeof *pool->w);
	if (!pool->w)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	const prsm_rare_limit_state *ls = &s->p->limit;
	size_t d = s->d;
	for (int t = 0; t < o->threads; t++) {
		rare_worker *w = &pool->w[t];
		pool->n_workers = t + 1;
		w->pool = pool;
		if (ls->workspace_alloc && ls->workspace_alloc(&w->ws, ls->ctx)) {
			w->ws = NULL;
			rare_pool_free(pool);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "cannot allocate the limit state's workspace");
		}
		w->rng = prsm_rng_alloc(o->seed, 0);
		w->x = malloc(d * sizeof *w->x);
		w->z = malloc(d * sizeof *w->z);
		w->a = malloc(d * sizeof *w->a);
		w->b = malloc(d * sizeof *w->b);
		if (!w->rng || !w->x || !w->z || !w->a || !w->b) {
			rare_pool_free(pool);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		}
	}
	return 0;
}

int rare_setup(rare_space *s, rare_pool *pool, const prsm_rare_problem *p, const prsm_rare_options *o,
               prsm_error *err)
{
	int rc = rare_space_init(s, p, err);
	if (rc)
		return rc;
	rc = rare_pool_init(pool, s, o, err);
	if (rc)
		rare_space_free(s);
	return rc;
}

void rare_pool_free(rare_pool *pool)
{
	if (pool->w)
		for (int t = 0; t < pool->n_workers; t++)
			worker_free(&pool->w[t], &pool->space->p->limit);
	free(pool->w);
	pool->w = NULL;
	pool->n_workers = 0;
}

int rare_pool_halted(rare_pool *pool)
{
	int h = atomic_load_explicit(&pool->halt, memory_order_relaxed);
	if (h)
		return h;
	const prsm_rare_options *o = pool->o;
	int why = 0;
	if (prsm_cancel_requested(o->cancel))
		why = PRSM_RARE_STOP_CANCELLED;
	else if (o->time_cap_s > 0.0 && prsm_clock_seconds() - pool->t0 > o->time_cap_s)
		why = PRSM_RARE_STOP_TIME_CAP;
	if (why) {
		int expected = 0;
		atomic_compare_exchange_strong(&pool->halt, &expected, why);
		return atomic_load(&pool->halt);
	}
	return 0;
}

int rare_eval(rare_worker *w, const double *u, double *g, int *code)
{
	rare_pool *pool = w->pool;
	*code = 0;
	if (rare_pool_halted(pool))
		return RARE_HALTED;
	const prsm_rare_limit_state *ls = &pool->space->p->limit;
	rare_space_to_x(pool->space, u, w->z, w->x);
	double v = NAN;
	int rc = ls->g(&v, ls->ctx, w->ws, w->x);
	if (rc) {
		*code = rc;
		*g = NAN;
		return PRSM_ENOCONVERGE;
	}
	*g = v;
	return isfinite(v) ? 0 : PRSM_ENOCONVERGE;
}

static void *pool_thread(void *arg)
{
	rare_worker *w = arg;
	rare_pool *pool = w->pool;
	for (;;) {
		size_t i = atomic_fetch_add(&pool->next, 1);
		if (i >= pool->n_tasks)
			break;
		pool->task(w, i, pool->arg);
	}
	return NULL;
}

void rare_pool_run(rare_pool *pool, size_t n, rare_task_fn task, void *arg)
{
	if (n == 0)
		return;
	pool->task = task;
	pool->arg = arg;
	pool->n_tasks = n;
	atomic_store(&pool->next, 0);
	int want = pool->n_workers;
	if ((size_t)want > n)
		want = (int)n;
	int started[PRSM_MC_MAX_THREADS] = {0};
	for (int t = 1; t < want; t++)
		started[t] = pthread_create(&pool->w[t].thread, NULL, pool_thread, &pool->w[t]) == 0;
	pool_thread(&pool->w[0]);
	for (int t = 1; t < want; t++)
		if (started[t])
			pthread_join(pool->w[t].thread, NULL);
}

void rare_progress(rare_pool *pool, size_t done, double cov, int final)
{
	const prsm_rare_options *o = pool->o;
	if (!o->progress)
		return;
	double now = prsm_clock_seconds();
	if (!final && now - pool->last_progress < 0.2)
		return;
	pool->last_progress = now;
	prsm_progress pr = PRSM_PROGRESS_INIT;
	pr.done = done;
	pr.planned = o->max_evaluations;
	pr.interval_width = cov;
	pr.interval_goal = o->target_cov;
	o->progress(o->progress_ctx, &pr);
}

int rare_eval_error(prsm_error *err, int lscode, const char *where)
{
	if (lscode)
		return prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the limit state failed (%s) at %s",
		                      prsm_error_name(lscode), where);
	return prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the limit state returned a non-finite value at %s", where);
}

/* ---- auto ----------------------------------------------------------------------------------- */

static void say(char *why, size_t why_size, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

static void say(char *why, size_t why_size, const char *fmt, ...)
{
	if (!why || why_size == 0)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, why_size, fmt, ap);
	va_end(ap);
}

prsm_rare_method prsm_rare_auto_select(size_t failures, size_t n, size_t d, const prsm_rare_options *o,
                                       char *why, size_t why_size)
{
	double budget = (double)o->max_evaluations;
	double cov = o->target_cov;
	double p = n > 0 ? (double)failures / (double)n : 0.0;
	if (failures > 0 && n > 0) {
		double need = (1.0 - p) / (p * cov * cov);
		double cap = fmin((double)o->max_samples, budget);
		if (need <= cap) {
			say(why, why_size, "%zu failures in %zu samples: plain MC reaches CoV %g in about %.0f samples", failures,
			    n, cov, ceil(need));
			return PRSM_RARE_MC;
		}
	}
	double form_cost = 10.0 * (2.0 * (double)d + 1.0) + 50.0;
	if (d <= PRSM_RARE_AUTO_IS_MAX_D && form_cost + (double)o->min_samples <= budget) {
		say(why, why_size, "%zu failures in %zu samples, %zu variables: FORM (about %.0f evaluations) then IS",
		    failures, n, d, form_cost);
		return PRSM_RARE_IS;
	}
	double p_hi = failures > 0 ? p : (n > 0 ? fmin(1.0, 3.0 / (double)n) : 1.0);
	double levels = 1.0;
	if (p_hi < 1.0)
		levels = 1.0 + ceil(log(p_hi) / log(o->subset_p0));
	double nn = (double)o->subset_samples;
	double subset_cost = nn * (1.0 + (1.0 - o->subset_p0) * (levels - 1.0));
	if (subset_cost <= budget) {
		say(why, why_size, "%zu failures in %zu samples, %zu variables: subset simulation (about %.0f evaluations)",
		    failures, n, d, subset_cost);
		return PRSM_RARE_SUBSET;
	}
	if (form_cost <= budget) {
		say(why, why_size, "budget %zu too small for IS or subset simulation: FORM (no error estimate)",
		    o->max_evaluations);
		return PRSM_RARE_FORM;
	}
	say(why, why_size, "budget %zu too small for FORM: plain MC", o->max_evaluations);
	return PRSM_RARE_MC;
}

/* ---- the spec limit state ------------------------------------------------------------------- */

typedef struct {
	const prsm_mc_model *model;       /* whose workspace model_ws is */
	void *model_ws;
	double y[PRSM_MC_MAX_OUTPUTS];
} spec_ws;

static int spec_ws_alloc(void **ws, const void *ctx)
{
	const prsm_rare_spec *s = ctx;
	spec_ws *w = calloc(1, sizeof *w);
	if (!w)
		return PRSM_ENOMEM;
	w->model = s->model;
	if (s->model->workspace_alloc && s->model->workspace_alloc(&w->model_ws, s->model->ctx)) {
		free(w);
		return PRSM_ENOMEM;
	}
	*ws = w;
	return 0;
}

static void spec_ws_free(void *wsp)
{
	spec_ws *w = wsp;
	if (w && w->model_ws && w->model->workspace_free)
		w->model->workspace_free(w->model_ws);
	free(w);
}

static int spec_g(double *value, const void *ctx, void *wsp, const double *x)
{
	const prsm_rare_spec *s = ctx;
	spec_ws *w = wsp;
	unsigned flags = 0;
	if (s->model->n_outputs > PRSM_MC_MAX_OUTPUTS || s->output >= s->model->n_outputs)
		return PRSM_EINVAL;
	int rc = s->model->eval(w->y, &flags, s->model->ctx, w->model_ws, x);
	if (rc)
		return rc;
	double y = w->y[s->output];
	double scale = s->scale > 0.0 ? s->scale : 1.0;
	double gu = (s->upper - y) / scale, gl = (y - s->lower) / scale;
	*value = s->side == PRSM_RARE_SIDE_UPPER ? gu : (s->side == PRSM_RARE_SIDE_LOWER ? gl : fmin(gu, gl));
	return 0;
}

void prsm_rare_spec_limit_state(prsm_rare_limit_state *ls, const prsm_rare_spec *spec)
{
	ls->ctx = spec;
	ls->workspace_alloc = spec_ws_alloc;
	ls->workspace_free = spec_ws_free;
	ls->g = spec_g;
}

/* ---- one call ------------------------------------------------------------------------------- */

void prsm_rare_result_free(prsm_rare_result *r)
{
	if (!r)
		return;
	prsm_rare_form_result_free(&r->form);
	prsm_rare_sorm_result_free(&r->sorm);
	memset(r, 0, sizeof *r);
}

static void take_is(prsm_rare_result *out, const prsm_rare_is_result *is)
{
	out->pf = is->pf;
	out->cov = is->cov;
	out->lower = is->lower;
	out->upper = is->upper;
	out->converged = is->converged;
	out->stop = is->stop;
}

/* Append a sentence to the run's note (after auto's reason, if any). */
static void note_add(prsm_rare_result *out, const char *text)
{
	size_t n = strlen(out->note);
	snprintf(out->note + n, sizeof out->note - n, "%s%s", n ? "; " : "", text);
}

/* Subset simulation with the budget left (auto's fallback): its figures become the result's. */
static int run_subset_rest(prsm_rare_result *out, const prsm_rare_problem *p, const prsm_rare_options *oo,
                           size_t rest, prsm_error *err)
{
	if (rest < oo->subset_samples) {
		note_add(out, "no budget left for subset simulation");
		return 0;
	}
	prsm_rare_options so = *oo;
	so.max_evaluations = rest;
	out->has_subset = 1;
	out->method = PRSM_RARE_SUBSET;
	int rc = prsm_rare_subset(&out->subset, p, &so, err);
	out->evaluations += out->subset.evaluations;
	out->pf = out->subset.pf;
	out->cov = out->subset.cov;
	out->lower = out->subset.lower;
	out->upper = out->subset.upper;
	out->converged = out->subset.converged;
	out->stop = out->subset.stop;
	return rc;
}

int prsm_rare_run(prsm_rare_result *out, prsm_rare_method method, const prsm_rare_problem *p,
                  const prsm_rare_options *o, prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	memset(out, 0, sizeof *out);
	out->requested = method;
	out->method = method;
	out->pf = out->cov = out->lower = out->upper = out->beta = NAN;
	int rc = prsm_rare_options_check(o, p->d, err);
	if (rc)
		return rc;
	if ((int)method < 0 || (int)method > PRSM_RARE_SUBSET)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "unknown rare-event method %d", (int)method);
	prsm_rare_options oo = *o;

	if (method == PRSM_RARE_AUTO || method == PRSM_RARE_MC) {
		/* the pilot (auto) and plain MC share one sequence of blocks */
		rare_space s;
		rare_pool pool;
		rc = rare_setup(&s, &pool, p, o, err);
		if (rc)
			return rc;
		rare_is_state st;
		memset(&st, 0, sizeof st);
		out->has_is = 1;
		if (method == PRSM_RARE_AUTO) {
			rc = rare_is_advance(&st, &out->is, &pool, NULL, NULL, 0, o->pilot_samples, 0, o->max_evaluations, err);
			if (!rc && !st.done) {
				method = prsm_rare_auto_select(st.failures, st.samples, p->d, o, out->note, sizeof out->note);
				out->method = method;
			} else if (!rc) {
				/* the pilot itself was stopped (budget, cancel, time cap): its MC figures stand */
				method = out->method = PRSM_RARE_MC;
				snprintf(out->note, sizeof out->note, "the pilot stopped (%s): its plain MC figures",
				         prsm_rare_stop_name(out->is.stop));
			}
		}
		if (!rc && method == PRSM_RARE_MC && !st.done)
			rc = rare_is_advance(&st, &out->is, &pool, NULL, NULL, 0, o->max_samples, 1, o->max_evaluations, err);
		out->evaluations = st.evaluations;
		if (out->method == PRSM_RARE_MC || rc || st.done)
			take_is(out, &out->is);
		rare_pool_free(&pool);
		rare_space_free(&s);
		if (rc || out->method == PRSM_RARE_MC || st.done)
			goto finish;
		/* a halted pilot (st.done) ends the run above; else the chosen method gets the rest */
		oo.max_evaluations = o->max_evaluations > st.evaluations ? o->max_evaluations - st.evaluations : 1;
		out->has_is = 0;
		memset(&out->is, 0, sizeof out->is);
	}

	if (method == PRSM_RARE_SUBSET) {
		out->has_subset = 1;
		rc = prsm_rare_subset(&out->subset, p, &oo, err);
		out->evaluations += out->subset.evaluations;
		out->pf = out->subset.pf;
		out->cov = out->subset.cov;
		out->lower = out->subset.lower;
		out->upper = out->subset.upper;
		out->converged = out->subset.converged;
		out->stop = out->subset.stop;
		goto finish;
	}

	/* FORM, SORM, IS */
	/* IS with the subset fallback (auto's): FORM gets a quarter of the budget (at least its
	 * projected cost), and a FORM that does not converge in it (a kinked or noisy limit state, a
	 * far design point) hands the rest to subset simulation, as IS around its last iterate
	 * would carry an interval that cannot be trusted */
	const int fallback = method == PRSM_RARE_IS && (out->requested == PRSM_RARE_AUTO || o->is_fallback_subset);
	prsm_rare_options fo = oo;
	if (fallback) {
		size_t quarter = oo.max_evaluations / 4, need = 10 * (2 * p->d + 1) + 50;
		fo.max_evaluations = quarter > need ? quarter : need;
		if (fo.max_evaluations > oo.max_evaluations)
			fo.max_evaluations = oo.max_evaluations;
	}
	out->has_form = 1;
	rc = prsm_rare_form(&out->form, p, &fo, err);
	out->evaluations += out->form.evaluations;
	if (rc)
		goto finish;
	out->pf = out->form.pf;
	out->converged = out->form.converged;
	out->stop = out->form.stop;
	if (out->form.stop == PRSM_RARE_STOP_CANCELLED || out->form.stop == PRSM_RARE_STOP_TIME_CAP)
		goto finish;
	size_t left = oo.max_evaluations > out->form.evaluations ? oo.max_evaluations - out->form.evaluations : 0;
	if (fallback && out->form.n_points == 0) {
		char why[PRSM_RARE_REASON_MAX];
		snprintf(why, sizeof why, "FORM did not converge in %zu evaluations (%s): subset simulation",
		         out->form.evaluations, prsm_rare_stop_name(out->form.stop));
		note_add(out, why);
		rc = run_subset_rest(out, p, &oo, left, err);
		goto finish;
	}
	if (method == PRSM_RARE_SORM) {
		out->has_sorm = 1;
		prsm_rare_options so = oo;
		so.max_evaluations = left ? left : 1;
		rc = prsm_rare_sorm(&out->sorm, p, &out->form, &so, err);
		out->evaluations += out->sorm.evaluations;
		if (rc)
			goto finish;
		const prsm_rare_sorm_result *sr = &out->sorm;
		out->stop = sr->stop;
		out->converged = out->form.converged && sr->ok_breitung;
		if (sr->ok_tvedt)
			out->pf = sr->pf_tvedt;
		else if (sr->ok_hr)
			out->pf = sr->pf_hr;
		else if (sr->ok_breitung)
			out->pf = sr->pf_breitung;
		else
			note_add(out, sr->stop == PRSM_RARE_STOP_FORM ? "FORM did not converge: no SORM, FORM's estimate"
			                                             : "every SORM formula refused: FORM's estimate");
		goto finish;
	}
	if (method == PRSM_RARE_IS) {
		const double *centres = out->form.points;
		size_t nc = out->form.n_points;
		if (nc == 0) {
			/* FORM did not converge: sample around its last iterate (IS stays unbiased) */
			centres = out->form.u_star;
			nc = 1;
			note_add(out, out->form.stop == PRSM_RARE_STOP_MAX_ITERATIONS
			                  ? "FORM did not converge (max_iterations): IS around its last iterate"
			                  : "FORM did not converge: IS around its last iterate");
		}
		if (left == 0) {
			out->stop = PRSM_RARE_STOP_MAX_EVALUATIONS;
			out->converged = 0;
			goto finish;
		}
		out->has_is = 1;
		prsm_rare_options io = oo;
		/* auto keeps half of what is left for subset simulation, in case the weights turn out
		 * heavy-tailed (the failure probability lies far from the design points) */
		io.max_evaluations = fallback && left >= 4 * o->block_size ? left / 2 : left;
		rc = prsm_rare_is(&out->is, p, centres, NULL, nc, &io, err);
		out->evaluations += out->is.evaluations;
		take_is(out, &out->is);
		if (rc || !fallback || out->is.converged ||
		    out->is.stop == PRSM_RARE_STOP_CANCELLED || out->is.stop == PRSM_RARE_STOP_TIME_CAP)
			goto finish;
		size_t used = out->form.evaluations + out->is.evaluations;
		size_t rest = oo.max_evaluations > used ? oo.max_evaluations - used : 0;
		if (rest < o->subset_samples)
			goto finish;
		char why[PRSM_RARE_REASON_MAX];
		snprintf(why, sizeof why, "IS did not settle (CoV %.3g, its own relative error %.2g): subset simulation",
		         out->is.cov, out->is.cov_rel_error);
		note_add(out, why);
		rc = run_subset_rest(out, p, &oo, rest, err);
	}

finish:
	out->beta = rare_beta_of(out->pf);
	out->elapsed_s = prsm_clock_seconds() - t0;
	return rc;
}
