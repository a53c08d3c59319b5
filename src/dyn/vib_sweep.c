/*
 * vib_sweep.c: the analyses over many points (docs/model §8.4): bifurcation sweeps up and down
 * with continuation, basins of attraction on a grid of initial states, the frequency response
 * with its jumps, and the small pthread pool they run on.
 *
 * Determinism: a task (one direction of a continuation sweep, one independent sweep point, one
 * basin cell) depends only on its own inputs and owns its integrator and model copy; results are
 * written at the task's index, efforts summed in task order, attractors of a basin grid
 * identified afterwards in grid order. So every result is bit-identical for any thread count.
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/clock.h"

/* ---- the pool ---- */

struct vib_pool {
	pthread_mutex_t mu;
	pthread_cond_t cv;
	atomic_size_t next;
	atomic_int stop;
	size_t n;
	vib_task_fn fn;
	void *ctx;
	size_t units, done;
	int finished;
	int inline_mode;
	const prsm_cancel_flag *cancel;
	prsm_progress_fn progress;
	void *progress_ctx;
	int rc;
	size_t rc_task;
};

static void report(vib_pool *p, size_t done)
{
	if (p->progress == NULL)
		return;
	prsm_progress pr = PRSM_PROGRESS_INIT;
	pr.done = done;
	pr.planned = p->units;
	p->progress(p->progress_ctx, &pr);
}

void vib_pool_done(vib_pool *p, size_t units)
{
	if (p->inline_mode) {
		p->done += units;
		report(p, p->done);
		return;
	}
	pthread_mutex_lock(&p->mu);
	p->done += units;
	pthread_cond_signal(&p->cv);
	pthread_mutex_unlock(&p->mu);
}

int vib_pool_cancelled(const vib_pool *p)
{
	return prsm_cancel_requested(p->cancel) || atomic_load(&p->stop);
}

static void worker_loop(vib_pool *p)
{
	for (;;) {
		if (vib_pool_cancelled(p))
			break;
		const size_t t = atomic_fetch_add(&p->next, 1);
		if (t >= p->n)
			break;
		const int rc = p->fn(p->ctx, p, t);
		if (rc) {
			if (!p->inline_mode)
				pthread_mutex_lock(&p->mu);
			if (p->rc == 0 || t < p->rc_task) {
				p->rc = rc;
				p->rc_task = t;
			}
			atomic_store(&p->stop, 1);
			if (!p->inline_mode)
				pthread_mutex_unlock(&p->mu);
		}
	}
}

static void *worker_main(void *arg)
{
	vib_pool *p = arg;
	worker_loop(p);
	pthread_mutex_lock(&p->mu);
	p->finished++;
	pthread_cond_signal(&p->cv);
	pthread_mutex_unlock(&p->mu);
	return NULL;
}

int vib_pool_run(size_t n, int threads, vib_task_fn fn, void *ctx, size_t units, const prsm_cancel_flag *cancel,
                 prsm_progress_fn progress, void *progress_ctx)
{
	vib_pool p;
	memset(&p, 0, sizeof p);
	atomic_init(&p.next, 0);
	atomic_init(&p.stop, 0);
	p.n = n;
	p.fn = fn;
	p.ctx = ctx;
	p.units = units;
	p.cancel = cancel;
	p.progress = progress;
	p.progress_ctx = progress_ctx;
	if (threads < 1)
		threads = 1;
	if ((size_t)threads > n)
		threads = (int)(n > 0 ? n : 1);
	if (threads == 1) {
		p.inline_mode = 1;
		worker_loop(&p);
	} else {
		pthread_t th[64];
		int started = 0;
		if (threads > 64)
			threads = 64;
		pthread_mutex_init(&p.mu, NULL);
		prsm_cond_init_monotonic(&p.cv);
		for (int i = 0; i < threads; i++)
			if (pthread_create(&th[started], NULL, worker_main, &p) == 0)
				started++;
		if (started == 0) {
			/* no thread could start: run here */
			p.inline_mode = 1;
			worker_loop(&p);
		} else {
			size_t reported = 0;
			pthread_mutex_lock(&p.mu);
			while (p.finished < started) {
				prsm_cond_wait_for(&p.cv, &p.mu, 0.2);
				if (p.done != reported) {
					reported = p.done;
					pthread_mutex_unlock(&p.mu);
					report(&p, reported);
					pthread_mutex_lock(&p.mu);
				}
			}
			pthread_mutex_unlock(&p.mu);
			for (int i = 0; i < started; i++)
				pthread_join(th[i], NULL);
			if (p.done != reported)
				report(&p, p.done);
		}
		pthread_cond_destroy(&p.cv);
		pthread_mutex_destroy(&p.mu);
	}
	if (p.rc == 0 && prsm_cancel_requested(cancel))
		return PRSM_ECANCELLED;
	return p.rc;
}

/* ---- sweeps ---- */

void prsm_vib_sweep_options_init(prsm_vib_sweep_options *o)
{
	const prsm_vib_steady_options s = PRSM_VIB_STEADY_OPTIONS_INIT;
	memset(o, 0, sizeof *o);
	o->parameter = PRSM_VIB_PARAM_FREQUENCY_RATIO;
	o->from = 0.7;
	o->to = 1.6;
	o->step = 0.05;
	o->up = 1;
	o->down = 1;
	o->continuation = 1;
	o->steady = s;
	o->steady.integration.rel_tol = 1e-9;
	o->steady.integration.abs_tol = 1e-9;
	o->initial_state = NULL;
	o->threads = 1;
}

void prsm_vib_sweep_free(prsm_vib_sweep *s)
{
	free(s->point);
	free(s->poincare);
	free(s->end_state);
	memset(s, 0, sizeof *s);
}

typedef struct {
	const prsm_vib_model *m;
	const prsm_vib_sweep_options *o;
	prsm_vib_sweep *out;
	size_t grid;
	size_t n_up;                 /* points of the up direction (0 or grid) */
	prsm_vib_effort *effort;     /* per task */
	char (*msg)[PRSM_ERROR_MESSAGE_MAX]; /* per point: the failure's message */
} sweep_ctx;

/* ---- tasks spread over parts (vib.h, prsm_vib_split) ---- */

typedef struct {
	vib_task_fn fn;
	void *ctx;
	size_t part, parts;
} split_tasks;

static int split_task(void *ctx, vib_pool *pool, size_t i)
{
	const split_tasks *s = ctx;
	return s->fn(s->ctx, pool, s->part + i * s->parts);
}

/* A split the run can take: NULL or 1 part (none), else 0 .. parts-1 with an exchange. */
static int split_ok(const prsm_vib_split *sp)
{
	return !sp || (sp->parts >= 1 && sp->part >= 0 && sp->part < sp->parts && sp->exchange);
}

/* Tasks of n that part `part` of `parts` computes: part, part + parts, ... */
static size_t split_count(size_t n, int part, int parts)
{
	return n > (size_t)part ? (n - (size_t)part + (size_t)parts - 1) / (size_t)parts : 0;
}

/* Part 0's progress: its own units scaled to the whole. */
typedef struct {
	prsm_progress_fn fn;
	void *ctx;
	size_t mine, total;
} split_progress;

static void split_progress_fn(void *ctx, const prsm_progress *p)
{
	const split_progress *s = ctx;
	prsm_progress q = *p;
	q.planned = s->total;
	q.done = s->mine ? (size_t)((double)p->done * (double)s->total / (double)s->mine) : s->total;
	if (q.done > q.planned)
		q.done = q.planned;
	s->fn(s->ctx, &q);
}

/* The pool over this part's tasks (every task without a split); units: the whole run's progress
 * units, units_per_task each task's. */
static int split_pool_run(size_t n, int threads, vib_task_fn fn, void *ctx, size_t units, size_t units_per_task,
                          const prsm_vib_split *sp, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                          void *progress_ctx)
{
	if (!sp)
		return vib_pool_run(n, threads, fn, ctx, units, cancel, progress, progress_ctx);
	split_tasks st = {fn, ctx, (size_t)sp->part, (size_t)sp->parts};
	const size_t mine = split_count(n, sp->part, sp->parts);
	split_progress pr = {progress, progress_ctx, mine * units_per_task, units};
	return vib_pool_run(mine, threads, split_task, &st, mine * units_per_task, cancel,
	                    progress && sp->part == 0 ? split_progress_fn : NULL, &pr);
}

static void put(char **p, const void *src, size_t n)
{
	memcpy(*p, src, n);
	*p += n;
}

static void get(const char **p, void *dst, size_t n)
{
	memcpy(dst, *p, n);
	*p += n;
}

/* This part's buffer to the exchange: buf (len bytes, its head filled here with code, message and
 * tasks; NULL: a head alone, for a failure). On part 0, *shares gets every part's buffer, each
 * checked: the first failure (this part's own first, then in part order) is returned with err
 * set. Returns 0, a failure, or the exchange's error. Frees buf. */
static int split_exchange(const prsm_vib_split *sp, char *buf, size_t len, int code, const char *message, size_t tasks,
                          prsm_vib_share **shares, prsm_error *err)
{
	prsm_vib_share_head h;
	memset(&h, 0, sizeof h);
	h.code = code;
	h.tasks = code ? 0 : tasks;
	snprintf(h.message, sizeof h.message, "%s", message ? message : "");
	if (!buf || code) {
		free(buf);
		buf = NULL;
		len = sizeof h;
	}
	const void *mine = buf ? (const void *)buf : (const void *)&h;
	if (buf)
		memcpy(buf, &h, sizeof h);
	*shares = NULL;
	prsm_vib_share *all = sp->part == 0 ? calloc((size_t)sp->parts, sizeof *all) : NULL;
	int rc = 0;
	if (sp->part == 0 && !all)
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	/* every part exchanges once, whatever happened (the others wait for it) */
	int xrc = sp->exchange(sp->ctx, mine, len, all, err);
	free(buf);
	if (rc || xrc) {
		if (all)
			for (int q = 0; q < sp->parts; q++)
				free(all[q].data);
		free(all);
		return rc ? rc : xrc;
	}
	if (sp->part != 0)
		return 0;
	for (int q = 0; q < sp->parts && !rc; q++) {
		prsm_vib_share_head qh;
		if (all[q].len < sizeof qh) {
			rc = prsm_error_set(err, PRSM_EIO, NULL, "rank %d of %d sent %zu bytes, less than a head", q, sp->parts,
			                    all[q].len);
			break;
		}
		memcpy(&qh, all[q].data, sizeof qh);
		qh.message[sizeof qh.message - 1] = '\0';
		if (qh.code)
			rc = prsm_error_set(err, qh.code, NULL, "rank %d of %d failed: %s", q, sp->parts,
			                    qh.message[0] ? qh.message : prsm_error_name(qh.code));
	}
	if (rc) {
		for (int q = 0; q < sp->parts; q++)
			free(all[q].data);
		free(all);
		return rc;
	}
	*shares = all;
	return 0;
}

static void shares_free(prsm_vib_share *all, int parts)
{
	if (!all)
		return;
	for (int q = 0; q < parts; q++)
		free(all[q].data);
	free(all);
}

static double grid_value(const prsm_vib_sweep_options *o, size_t i)
{
	return o->from + (double)i * o->step;
}

/* one point on integrator it (model parameter set, state set at tau 0) into slot k */
static int sweep_point(sweep_ctx *x, vib_int *it, size_t k, double value, int direction, const double *start,
                       double *next_start)
{
	const prsm_vib_sweep_options *o = x->o;
	prsm_vib_sweep *out = x->out;
	prsm_vib_sweep_point *pt = &out->point[k];
	const int n = it->n;
	memset(pt, 0, sizeof *pt);
	pt->parameter = value;
	pt->direction = direction;
	pt->lyapunov = NAN;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = vib_model_set(&it->mod, o->parameter, value, &err);
	if (rc == 0) {
		vib_int_model_changed(it);
		double y0[PRSM_VIB_STATE_MAX];
		if (start != NULL)
			memcpy(y0, start, (size_t)n * sizeof *y0);
		else
			prsm_vib_static_state(&it->mod, y0);
		vib_int_set(it, 0.0, y0);
		it->max_steps = it->effort.steps + o->steady.integration.max_steps; /* per point */
		prsm_vib_steady s;
		rc = vib_steady_core(&s, it, &o->steady, 1, &err);
		if (rc == 0) {
			pt->classification = s.classification;
			pt->period = s.period;
			pt->min = s.extreme[0].min;
			pt->max = s.extreme[0].max;
			pt->mean = s.extreme[0].mean;
			pt->rms = s.extreme[0].rms;
			pt->amplitude = 0.5 * (pt->max - pt->min);
			pt->lyapunov = s.lyapunov;
			pt->max_return_distance = s.max_return_distance;
			memcpy(out->poincare + k * (size_t)out->recorded, s.poincare_observable,
			       (size_t)out->recorded * sizeof(double));
			memcpy(out->end_state + k * (size_t)n, s.final_state, (size_t)n * sizeof(double));
			if (next_start != NULL)
				memcpy(next_start, s.final_state, (size_t)n * sizeof(double));
			prsm_vib_steady_free(&s);
			return 0;
		}
	}
	if (rc == PRSM_ECANCELLED || rc == PRSM_ENOMEM)
		return rc;
	/* a point that fails is reported, not drawn; the next starts from the static state */
	pt->status = rc;
	pt->classification = PRSM_VIB_FAILED;
	pt->min = pt->max = pt->mean = pt->rms = pt->amplitude = NAN;
	pt->max_return_distance = NAN;
	for (int i = 0; i < out->recorded; i++)
		out->poincare[k * (size_t)out->recorded + i] = NAN;
	for (int i = 0; i < n; i++)
		out->end_state[k * (size_t)n + i] = NAN;
	snprintf(x->msg[k], sizeof x->msg[k], "parameter %g: %.200s", value, err.message);
	return 1; /* failed: restart from the static state */
}

static int sweep_task(void *ctx, vib_pool *pool, size_t task)
{
	sweep_ctx *x = ctx;
	const prsm_vib_sweep_options *o = x->o;
	vib_int it;
	if (vib_int_init(&it, x->m, 0, 1, &o->steady.integration, pool->cancel))
		return PRSM_ENOMEM;
	if (!isnan(o->steady.integration.initial_step))
		it.h = o->steady.integration.initial_step;
	int rc = 0;
	const int n = it.n;
	double state[PRSM_VIB_STATE_MAX];
	if (o->continuation) {
		/* task 0: the up direction (if asked), the other: down; each point from the last end state */
		const int up = (task == 0 && x->n_up > 0);
		const int has = o->initial_state != NULL;
		if (has)
			memcpy(state, o->initial_state, (size_t)n * sizeof *state);
		int from_static = !has;
		for (size_t i = 0; i < x->grid; i++) {
			const size_t g = up ? i : x->grid - 1 - i;
			const size_t k = up ? i : x->n_up + i;
			const int r = sweep_point(x, &it, k, grid_value(o, g), up ? 1 : -1, from_static ? NULL : state, state);
			if (r < 0) {
				rc = r;
				break;
			}
			from_static = r == 1;
			vib_pool_done(pool, 1);
			if (vib_pool_cancelled(pool))
				break;
		}
	} else {
		/* an independent point: from the initial state or the static state */
		const int r = sweep_point(x, &it, task, grid_value(o, task), 1, o->initial_state, NULL);
		if (r < 0)
			rc = r;
		vib_pool_done(pool, 1);
	}
	x->effort[task] = it.effort;
	vib_int_free(&it);
	return rc;
}

/* The points (slots k0 .. k0 + nk - 1) task t writes. */
static void sweep_slots(const sweep_ctx *x, size_t t, size_t *k0, size_t *nk)
{
	if (x->o->continuation) {
		*k0 = (t == 0 && x->n_up > 0) ? 0 : x->n_up;
		*nk = x->grid;
	} else {
		*k0 = t;
		*nk = 1;
	}
}

static size_t sweep_task_bytes(const sweep_ctx *x, size_t nk)
{
	const prsm_vib_sweep *out = x->out;
	return sizeof(prsm_vib_effort) +
	       nk * (sizeof(prsm_vib_sweep_point) + ((size_t)out->recorded + (size_t)out->states) * sizeof(double) +
	             sizeof *x->msg);
}

/* A split sweep's exchange: this part's tasks packed (part 0 sends its head alone: its results
 * are in place), the others' unpacked into their slots on part 0. own: this part's pool code. */
static int sweep_exchange(sweep_ctx *x, size_t tasks, int own, prsm_error *err)
{
	const prsm_vib_split *sp = x->o->split;
	prsm_vib_sweep *out = x->out;
	const size_t R = (size_t)out->recorded, n = (size_t)out->states;
	const size_t mine = split_count(tasks, sp->part, sp->parts);
	size_t len = sizeof(prsm_vib_share_head);
	if (sp->part != 0)
		for (size_t i = 0; i < mine; i++) {
			size_t k0, nk;
			sweep_slots(x, (size_t)sp->part + i * (size_t)sp->parts, &k0, &nk);
			len += sweep_task_bytes(x, nk);
		}
	char *buf = own ? NULL : malloc(len);
	int code = own ? own : buf ? 0 : PRSM_ENOMEM;
	if (buf && sp->part != 0) {
		char *p = buf + sizeof(prsm_vib_share_head);
		for (size_t i = 0; i < mine; i++) {
			const size_t t = (size_t)sp->part + i * (size_t)sp->parts;
			size_t k0, nk;
			sweep_slots(x, t, &k0, &nk);
			put(&p, &x->effort[t], sizeof x->effort[t]);
			put(&p, out->point + k0, nk * sizeof *out->point);
			put(&p, out->poincare + k0 * R, nk * R * sizeof(double));
			put(&p, out->end_state + k0 * n, nk * n * sizeof(double));
			put(&p, x->msg + k0, nk * sizeof *x->msg);
		}
	}
	prsm_vib_share *all;
	int rc = split_exchange(sp, buf, len, code, code == PRSM_ECANCELLED ? "cancelled" : code ? "out of memory" : NULL,
	                        sp->part == 0 ? 0 : mine, &all, err);
	if (rc || sp->part != 0)
		return rc;
	for (int q = 1; q < sp->parts && !rc; q++) {
		const size_t qn = split_count(tasks, q, sp->parts);
		size_t want = sizeof(prsm_vib_share_head);
		for (size_t i = 0; i < qn; i++) {
			size_t k0, nk;
			sweep_slots(x, (size_t)q + i * (size_t)sp->parts, &k0, &nk);
			want += sweep_task_bytes(x, nk);
		}
		prsm_vib_share_head h;
		memcpy(&h, all[q].data, sizeof h);
		if (all[q].len != want || h.tasks != qn) {
			rc = prsm_error_set(err, PRSM_EIO, NULL, "rank %d of %d sent %zu bytes for %llu sweep tasks, expected %zu for %zu",
			                    q, sp->parts, all[q].len, (unsigned long long)h.tasks, want, qn);
			break;
		}
		const char *p = all[q].data + sizeof h;
		for (size_t i = 0; i < qn; i++) {
			const size_t t = (size_t)q + i * (size_t)sp->parts;
			size_t k0, nk;
			sweep_slots(x, t, &k0, &nk);
			get(&p, &x->effort[t], sizeof x->effort[t]);
			get(&p, out->point + k0, nk * sizeof *out->point);
			get(&p, out->poincare + k0 * R, nk * R * sizeof(double));
			get(&p, out->end_state + k0 * n, nk * n * sizeof(double));
			get(&p, x->msg + k0, nk * sizeof *x->msg);
		}
	}
	shares_free(all, sp->parts);
	return rc;
}

static int sweep_check(const prsm_vib_model *m, const prsm_vib_sweep_options *o, size_t *grid, prsm_error *err)
{
	if (!(o->step > 0.0 && isfinite(o->step) && isfinite(o->from) && isfinite(o->to) && o->to >= o->from))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/step",
		                      "a sweep needs finite from <= to and a step > 0 (got %g, %g, %g)", o->from, o->to,
		                      o->step);
	const double q = floor((o->to - o->from) / o->step + 1e-9);
	if (!(q + 1.0 <= PRSM_VIB_SWEEP_POINTS_MAX))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/step",
		                      "the sweep has %.0f points, more than %d: raise the step", q + 1.0,
		                      PRSM_VIB_SWEEP_POINTS_MAX);
	*grid = (size_t)q + 1;
	if (!o->up && !o->down)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/directions", "a sweep runs up, down or both");
	if (o->threads < 1 || o->threads > 256)
		return prsm_error_set(err, PRSM_EINVAL, "/threads", "1 to 256 threads (got %d)", o->threads);
	if (!split_ok(o->split))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a split needs parts >= 1, a part in 0 .. parts-1 and an exchange");
	const double periods = (double)*grid * (o->up + o->down) *
	                       ((double)o->steady.transient_periods + o->steady.recorded_periods +
	                        (o->steady.lyapunov ? o->steady.lyapunov_periods : 0));
	if (periods > 5e8)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep",
		                      "the sweep integrates %.3g forcing periods in all, more than 5e8: fewer points or periods",
		                      periods);
	/* every grid value must be a valid parameter value */
	prsm_vib_model *probe = prsm_vib_model_copy(m);
	if (probe == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int rc = 0;
	for (size_t i = 0; i < *grid && rc == 0; i += (*grid > 1 ? *grid - 1 : 1))
		rc = vib_model_set(probe, o->parameter, grid_value(o, i), err);
	prsm_vib_model_free(probe);
	return rc;
}

int prsm_vib_sweep_run(prsm_vib_sweep *out, const prsm_vib_model *m, const prsm_vib_sweep_options *o,
                       const prsm_cancel_flag *cancel, prsm_progress_fn progress, void *progress_ctx,
                       prsm_error *err)
{
	memset(out, 0, sizeof *out);
	size_t grid = 0;
	int rc = sweep_check(m, o, &grid, err);
	if (rc)
		return rc;
	/* the per-point options are checked by the first point; check them here for a clear error */
	{
		prsm_vib_steady_options so = o->steady;
		if (so.recorded_periods < 2 || so.transient_periods < 0)
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/recorded_periods",
			                      "transient >= 0 and recorded >= 2 periods");
	}
	const int n = m->c.n;
	const size_t n_up = o->up ? grid : 0;
	const size_t points = o->continuation ? grid * ((size_t)o->up + (size_t)o->down) : grid;
	out->parameter = o->parameter;
	out->grid = grid;
	out->recorded = o->steady.recorded_periods;
	out->states = n;
	const size_t total = o->continuation ? points : grid * ((size_t)o->up + (size_t)o->down);
	out->points = total;
	out->point = calloc(total, sizeof *out->point);
	out->poincare = malloc(total * (size_t)out->recorded * sizeof(double));
	out->end_state = malloc(total * (size_t)n * sizeof(double));
	const size_t tasks = o->continuation ? (size_t)o->up + (size_t)o->down : grid;
	sweep_ctx x;
	memset(&x, 0, sizeof x);
	x.m = m;
	x.o = o;
	x.out = out;
	x.grid = grid;
	x.n_up = o->continuation ? n_up : grid;
	x.effort = calloc(tasks, sizeof *x.effort);
	x.msg = calloc(total, sizeof *x.msg);
	const prsm_vib_split *sp = o->split && o->split->parts > 1 ? o->split : NULL;
	if (!out->point || !out->poincare || !out->end_state || !x.effort || !x.msg) {
		free(x.effort);
		free(x.msg);
		prsm_vib_sweep_free(out);
		if (sp) {
			/* the other parts wait for this one's exchange */
			prsm_vib_share *all;
			prsm_error xerr = PRSM_ERROR_INIT;
			if (split_exchange(sp, NULL, 0, PRSM_ENOMEM, "out of memory", 0, &all, &xerr) == 0)
				shares_free(all, sp->parts);
		}
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu sweep points", total);
	}
	rc = split_pool_run(tasks, o->threads, sweep_task, &x, points, o->continuation ? grid : 1, sp, cancel, progress,
	                    progress_ctx);
	int err_set = 0;
	if (sp) {
		const int own = rc;
		rc = sweep_exchange(&x, tasks, own, err);
		err_set = rc != 0 && rc != own;
		if (sp->part != 0) {
			/* this part's tasks went to part 0, which finishes the sweep */
			free(x.effort);
			free(x.msg);
			prsm_vib_sweep_free(out);
			if (rc && !err_set)
				prsm_error_set(err, rc, NULL, "%s", rc == PRSM_ECANCELLED ? "cancelled" : "out of memory in a sweep point");
			return rc;
		}
	}
	if (rc == 0 && !o->continuation && o->down) {
		/* independent points, computed ascending in slots 0 .. grid-1: the down direction is the
		 * same points in descending order (after the up ones, or in their place) */
		const size_t R = (size_t)out->recorded;
		for (size_t i = 0; i < grid; i++) {
			const size_t src = grid - 1 - i, dst = (o->up ? grid : 0) + i;
			if (o->up) {
				out->point[dst] = out->point[src];
				memcpy(out->poincare + dst * R, out->poincare + src * R, R * sizeof(double));
				memcpy(out->end_state + dst * (size_t)n, out->end_state + src * (size_t)n, (size_t)n * sizeof(double));
			} else if (i < src) {
				prsm_vib_sweep_point t = out->point[i];
				out->point[i] = out->point[src];
				out->point[src] = t;
				for (size_t q = 0; q < R; q++) {
					const double v = out->poincare[i * R + q];
					out->poincare[i * R + q] = out->poincare[src * R + q];
					out->poincare[src * R + q] = v;
				}
				for (int q = 0; q < n; q++) {
					const double v = out->end_state[i * (size_t)n + q];
					out->end_state[i * (size_t)n + q] = out->end_state[src * (size_t)n + q];
					out->end_state[src * (size_t)n + q] = v;
				}
			}
		}
		for (size_t i = 0; i < grid; i++)
			out->point[(o->up ? grid : 0) + i].direction = -1;
	}
	for (size_t t = 0; t < tasks; t++) {
		out->effort.steps += x.effort[t].steps;
		out->effort.rejected += x.effort[t].rejected;
		out->effort.rhs_evaluations += x.effort[t].rhs_evaluations;
		out->effort.events += x.effort[t].events;
		out->effort.switches += x.effort[t].switches;
	}
	for (size_t k = 0; k < total && out->first_error[0] == '\0'; k++)
		if (x.msg[k][0])
			snprintf(out->first_error, sizeof out->first_error, "%s", x.msg[k]);
	free(x.effort);
	free(x.msg);
	if (rc) {
		prsm_vib_sweep_free(out);
		if (err_set)
			return rc;
		return prsm_error_set(err, rc, NULL, "%s", rc == PRSM_ECANCELLED ? "cancelled" : "out of memory in a sweep point");
	}
	return 0;
}

/* ---- basins of attraction ---- */

void prsm_vib_basin_options_init(prsm_vib_basin_options *o)
{
	const prsm_vib_integration integ = PRSM_VIB_INTEGRATION_INIT;
	memset(o, 0, sizeof *o);
	o->x_state = 0;
	o->v_state = 1;
	o->x_min = -2.0;
	o->x_max = 4.0;
	o->v_min = -3.0;
	o->v_max = 3.0;
	o->nx = 41;
	o->nv = 41;
	o->periods = 100;
	o->identify_periods = 64;
	o->distance = 1e-3;
	o->period_tol = NAN;
	o->clock = PRSM_VIB_CLOCK_AUTO;
	o->integration = integ;
	o->integration.rel_tol = 1e-9;
	o->integration.abs_tol = 1e-9;
	o->threads = 1;
}

void prsm_vib_basins_free(prsm_vib_basins *b)
{
	for (int a = 0; a < b->attractors && b->attractor != NULL; a++)
		free(b->attractor[a].poincare);
	free(b->attractor);
	free(b->label);
	memset(b, 0, sizeof *b);
}

typedef struct {
	const prsm_vib_model *m;
	const prsm_vib_basin_options *o;
	double T;
	int size;
	double *record;              /* cells x identify x size */
	int *status;                 /* per cell: 0 ok, else the error */
	prsm_vib_effort *effort;     /* per cell */
} basin_ctx;

static void cell_state(const basin_ctx *x, size_t cell, double *y)
{
	const prsm_vib_basin_options *o = x->o;
	prsm_vib_static_state(x->m, y);
	const int i = (int)(cell / (size_t)o->nv), j = (int)(cell % (size_t)o->nv);
	y[o->x_state] = o->nx > 1 ? o->x_min + (o->x_max - o->x_min) * i / (o->nx - 1) : o->x_min;
	y[o->v_state] = o->nv > 1 ? o->v_min + (o->v_max - o->v_min) * j / (o->nv - 1) : o->v_min;
}

static int basin_task(void *ctx, vib_pool *pool, size_t cell)
{
	basin_ctx *x = ctx;
	const prsm_vib_basin_options *o = x->o;
	vib_int it;
	if (vib_int_init(&it, x->m, 0, 1, &o->integration, pool->cancel))
		return PRSM_ENOMEM;
	double y[PRSM_VIB_STATE_MAX];
	cell_state(x, cell, y);
	vib_int_set(&it, 0.0, y);
	int rc = vib_periods(&it, 0.0, x->T, o->periods, NULL);
	if (rc == 0)
		rc = vib_periods(&it, it.tau, x->T, o->identify_periods,
		                 x->record + cell * (size_t)o->identify_periods * x->size);
	x->effort[cell] = it.effort;
	vib_int_free(&it);
	vib_pool_done(pool, 1);
	if (rc == PRSM_ECANCELLED || rc == PRSM_ENOMEM)
		return rc;
	x->status[cell] = rc;
	return 0;
}

/* A split basin grid's exchange: this part's cells packed (status, effort, record; part 0 sends
 * its head alone), the others' unpacked on part 0. own: this part's code so far. */
static int basin_exchange(basin_ctx *x, size_t cells, int own, prsm_error *err)
{
	const prsm_vib_split *sp = x->o->split;
	const size_t rec = (size_t)x->o->identify_periods * (size_t)x->size;
	const size_t per_cell = sizeof(int) + sizeof(prsm_vib_effort) + rec * sizeof(double);
	const size_t mine = split_count(cells, sp->part, sp->parts);
	const size_t len = sizeof(prsm_vib_share_head) + (sp->part == 0 ? 0 : mine * per_cell);
	char *buf = own ? NULL : malloc(len);
	int code = own ? own : buf ? 0 : PRSM_ENOMEM;
	if (buf && sp->part != 0) {
		char *p = buf + sizeof(prsm_vib_share_head);
		for (size_t i = 0; i < mine; i++) {
			const size_t c = (size_t)sp->part + i * (size_t)sp->parts;
			put(&p, &x->status[c], sizeof(int));
			put(&p, &x->effort[c], sizeof(prsm_vib_effort));
			put(&p, x->record + c * rec, rec * sizeof(double));
		}
	}
	prsm_vib_share *all;
	int rc = split_exchange(sp, buf, len, code, code == PRSM_ECANCELLED ? "cancelled" : code ? "out of memory" : NULL,
	                        sp->part == 0 ? 0 : mine, &all, err);
	if (rc || sp->part != 0)
		return rc;
	for (int q = 1; q < sp->parts && !rc; q++) {
		const size_t qn = split_count(cells, q, sp->parts);
		prsm_vib_share_head h;
		memcpy(&h, all[q].data, sizeof h);
		if (all[q].len != sizeof h + qn * per_cell || h.tasks != qn) {
			rc = prsm_error_set(err, PRSM_EIO, NULL, "rank %d of %d sent %zu bytes for %llu cells, expected %zu",
			                    q, sp->parts, all[q].len, (unsigned long long)h.tasks, qn);
			break;
		}
		const char *p = all[q].data + sizeof h;
		for (size_t i = 0; i < qn; i++) {
			const size_t c = (size_t)q + i * (size_t)sp->parts;
			get(&p, &x->status[c], sizeof(int));
			get(&p, &x->effort[c], sizeof(prsm_vib_effort));
			get(&p, x->record + c * rec, rec * sizeof(double));
		}
	}
	shares_free(all, sp->parts);
	return rc;
}

static double cycle_distance(const double *p, const prsm_vib_attractor *a, int size)
{
	double best = INFINITY;
	for (int k = 0; k < a->period; k++) {
		double d = 0.0;
		for (int q = 0; q < size; q++)
			d = fmax(d, fabs(p[q] - a->poincare[(size_t)k * size + q]));
		best = fmin(best, d);
	}
	return best;
}

int prsm_vib_basins_run(prsm_vib_basins *out, const prsm_vib_model *m, const prsm_vib_basin_options *o,
                        const prsm_cancel_flag *cancel, prsm_progress_fn progress, void *progress_ctx,
                        prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const vib_core *c = &m->c;
	if (o->nx < 1 || o->nv < 1 || (double)o->nx * o->nv > PRSM_VIB_BASIN_CELLS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/grid", "the grid has 1 to %d cells (got %d x %d)",
		                      PRSM_VIB_BASIN_CELLS_MAX, o->nx, o->nv);
	if (o->x_state < 0 || o->x_state >= c->n || o->v_state < 0 || o->v_state >= c->n || o->x_state == o->v_state)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/states", "two different state components");
	if (!(isfinite(o->x_min) && isfinite(o->x_max) && isfinite(o->v_min) && isfinite(o->v_max)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/box", "the box must be finite");
	if (o->periods < 0 || o->identify_periods < 2 || o->identify_periods > 4 * PRSM_VIB_PERIOD_MAX ||
	    (double)o->nx * o->nv * (o->periods + o->identify_periods) > 2e8)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/periods",
		                      "periods >= 0, 2 to %d identification periods, at most 2e8 periods in all",
		                      4 * PRSM_VIB_PERIOD_MAX);
	if (!(o->distance > 0.0) || o->threads < 1 || o->threads > 256 || o->known < 0 ||
	    (o->known > 0 && (o->known_state == NULL || o->known_period == NULL)) || !split_ok(o->split))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins", "bad distance, threads or known attractors");
	const int clock = prsm_vib_clock_of(m, o->clock, PRSM_VIB_OBS_MESH_DEFLECTION);
	const double T = prsm_vib_period(m, clock);
	if (!(T > 0.0 && isfinite(T)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/clock", "the clock has no period");
	const int size = vib_reduced_size(c);
	const size_t cells = (size_t)o->nx * o->nv;
	const double tol = isnan(o->period_tol) ? vib_default_period_tol(m) : o->period_tol;
	const prsm_vib_split *sp = o->split && o->split->parts > 1 ? o->split : NULL;
	int exchanged = 0, err_set = 0;
	basin_ctx x;
	memset(&x, 0, sizeof x);
	x.m = m;
	x.o = o;
	x.T = T;
	x.size = size;
	x.record = malloc(cells * (size_t)o->identify_periods * size * sizeof(double));
	x.status = calloc(cells, sizeof(int));
	x.effort = calloc(cells, sizeof *x.effort);
	out->label = malloc(cells * sizeof(int));
	const int max_attr = o->known + 64;
	out->attractor = calloc((size_t)max_attr, sizeof *out->attractor);
	int rc = 0;
	if (!x.record || !x.status || !x.effort || !out->label || !out->attractor) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu cells", cells);
		goto cleanup;
	}
	out->nx = o->nx;
	out->nv = o->nv;
	out->x_min = o->x_min;
	out->x_max = o->x_max;
	out->v_min = o->v_min;
	out->v_max = o->v_max;
	out->poincare_size = size;
	/* the known attractors' cycles */
	for (int a = 0; a < o->known; a++) {
		const int per = o->known_period[a];
		if (per < 1 || per > PRSM_VIB_PERIOD_MAX) {
			rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/basins/attractors", "a known period is 1 to %d",
			                    PRSM_VIB_PERIOD_MAX);
			goto cleanup;
		}
		prsm_vib_attractor *at = &out->attractor[out->attractors++];
		at->period = per;
		at->given = 1;
		at->poincare = malloc((size_t)per * size * sizeof(double));
		vib_int it;
		if (at->poincare == NULL || vib_int_init(&it, m, 0, 1, &o->integration, cancel)) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		vib_int_set(&it, 0.0, o->known_state + (size_t)a * c->n);
		rc = vib_periods(&it, 0.0, T, per, at->poincare);
		vib_int_free(&it);
		if (rc) {
			rc = prsm_error_set(err, rc, NULL, "a known attractor could not be integrated");
			goto cleanup;
		}
	}
	rc = split_pool_run(cells, o->threads, basin_task, &x, cells, 1, sp, cancel, progress, progress_ctx);
	if (sp) {
		const int own = rc;
		exchanged = 1;
		rc = basin_exchange(&x, cells, own, err);
		err_set = rc != 0 && rc != own;
		if (sp->part != 0 && rc == 0) {
			/* this part's cells went to part 0, which labels the grid */
			prsm_vib_basins_free(out);
			goto cleanup;
		}
	}
	if (rc) {
		if (!err_set)
			prsm_error_set(err, rc, NULL, "%s", rc == PRSM_ECANCELLED ? "cancelled" : "out of memory in a cell");
		goto cleanup;
	}
	/* labels in grid order (deterministic) */
	for (size_t cell = 0; cell < cells; cell++) {
		if (x.status[cell]) {
			out->label[cell] = -2;
			out->failed++;
			continue;
		}
		const double *rec = x.record + cell * (size_t)o->identify_periods * size;
		const double *last = rec + (size_t)(o->identify_periods - 1) * size;
		int label = -1;
		for (int a = 0; a < out->attractors && label < 0; a++)
			if (cycle_distance(last, &out->attractor[a], size) < o->distance)
				label = a;
		if (label < 0) {
			const int per = prsm_vib_period_of(rec, o->identify_periods, size, tol, PRSM_VIB_PERIOD_MAX, NULL);
			if (per > 0 && out->attractors < max_attr) {
				prsm_vib_attractor *at = &out->attractor[out->attractors];
				at->period = per;
				at->given = 0;
				at->poincare = malloc((size_t)per * size * sizeof(double));
				if (at->poincare == NULL) {
					rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
					goto cleanup;
				}
				memcpy(at->poincare, rec + (size_t)(o->identify_periods - per) * size, (size_t)per * size * sizeof(double));
				label = out->attractors++;
			}
		}
		out->label[cell] = label;
		if (label >= 0)
			out->attractor[label].cells++;
		else
			out->other++;
	}
	for (int a = 0; a < out->attractors; a++)
		out->attractor[a].fraction = (double)out->attractor[a].cells / cells;
	out->other_fraction = (double)out->other / cells;
	out->failed_fraction = (double)out->failed / cells;
	for (size_t cell = 0; cell < cells; cell++) {
		out->effort.steps += x.effort[cell].steps;
		out->effort.rejected += x.effort[cell].rejected;
		out->effort.rhs_evaluations += x.effort[cell].rhs_evaluations;
		out->effort.events += x.effort[cell].events;
		out->effort.switches += x.effort[cell].switches;
	}
cleanup:
	if (sp && !exchanged) {
		/* failed before the exchange: the other parts wait for this one's */
		prsm_vib_share *all;
		prsm_error xerr = PRSM_ERROR_INIT;
		if (split_exchange(sp, NULL, 0, rc ? rc : PRSM_EIO, err->message, 0, &all, &xerr) == 0)
			shares_free(all, sp->parts);
	}
	free(x.record);
	free(x.status);
	free(x.effort);
	if (rc)
		prsm_vib_basins_free(out);
	return rc;
}

/* ---- frequency response with jumps ---- */

void prsm_vib_frequency_response_free(prsm_vib_frequency_response *f)
{
	prsm_vib_hb_free(&f->hb);
	prsm_vib_sweep_free(&f->sweep);
	memset(f, 0, sizeof *f);
}

int prsm_vib_frequency_response_run(prsm_vib_frequency_response *out, const prsm_vib_model *m,
                                    const prsm_vib_sweep_options *o_in, double agree_tol,
                                    const prsm_cancel_flag *cancel, prsm_progress_fn progress, void *progress_ctx,
                                    prsm_error *err)
{
	memset(out, 0, sizeof *out);
	prsm_vib_sweep_options o = *o_in;
	o.up = 1;
	o.down = 1;
	o.continuation = 1;
	o.parameter = PRSM_VIB_PARAM_FREQUENCY_RATIO;
	if (isnan(agree_tol))
		agree_tol = 1e-3;
	int rc = 0;
	if (m->par.kind == PRSM_VIB_GEAR_PAIR && m->par.gear_pair.stiffness_variation == 0.0) {
		prsm_vib_gear_pair g = m->par.gear_pair;
		if ((rc = prsm_vib_harmonic_balance(&out->hb, &g, o.from, o.to, 4000, err)))
			return rc;
	}
	if ((rc = prsm_vib_sweep_run(&out->sweep, m, &o, cancel, progress, progress_ctx, err))) {
		prsm_vib_frequency_response_free(out);
		return rc;
	}
	/* the runs of grid points where the two directions disagree (coexisting attractors) */
	const size_t G = out->sweep.grid;
	const prsm_vib_sweep_point *up = out->sweep.point, *dn = out->sweep.point + G;
	int prev = 0;
	size_t start = 0;
	for (size_t i = 0; i <= G; i++) {
		int dis = 0;
		if (i < G) {
			const prsm_vib_sweep_point *a = &up[i], *b = &dn[G - 1 - i];
			dis = a->classification != b->classification || a->period != b->period ||
			      !(fabs(a->amplitude - b->amplitude) <= agree_tol * fmax(fabs(a->amplitude), fabs(b->amplitude)));
			if (a->classification == PRSM_VIB_FAILED || b->classification == PRSM_VIB_FAILED)
				dis = 0;
		}
		if (dis && !prev)
			start = i;
		if (!dis && prev && out->jumps + 2 <= 32) {
			/* run [start, i-1]: the sweep up leaves it upwards, the sweep down downwards */
			if (i < G) {
				prsm_vib_jump *j = &out->jump[out->jumps++];
				j->from = up[i - 1].parameter;
				j->to = up[i].parameter;
				j->direction = 1;
			}
			if (start > 0) {
				prsm_vib_jump *j = &out->jump[out->jumps++];
				j->from = up[start].parameter;
				j->to = up[start - 1].parameter;
				j->direction = -1;
			}
		}
		prev = dis;
	}
	/* the exact folds: shooting from the last point on the branch a sweep leaves (periodic only) */
	for (int k = 0; k < out->jumps; k++) {
		const prsm_vib_jump *j = &out->jump[k];
		prsm_vib_exact_fold *f = &out->exact_fold[k];
		memset(f, 0, sizeof *f);
		f->omega = NAN;
		const size_t gi = (size_t)floor((j->from - o.from) / o.step + 0.5);
		if (gi >= G)
			continue;
		const size_t idx = j->direction > 0 ? gi : G + (G - 1 - gi);
		const prsm_vib_sweep_point *p = &out->sweep.point[idx];
		if (p->classification != PRSM_VIB_PERIODIC)
			continue;
		prsm_error ferr = PRSM_ERROR_INIT;
		const int frc = prsm_vib_fold_track(f, m, out->sweep.end_state + idx * (size_t)out->sweep.states, p->period,
		                                    j->from, j->to, &o.steady.integration, cancel, &ferr);
		if (frc == PRSM_ECANCELLED) {
			prsm_vib_frequency_response_free(out);
			return prsm_error_set(err, frc, NULL, "cancelled");
		}
	}
	return 0;
}
