/*
 * optimize.c: the mixed-integer search of optimize.h: discrete combinations enumerated with
 * pruning, each a continuous NLopt problem from seeded, randomly rotated Sobol starting points,
 * every evaluation checked against the raw constraints here (DESIGN.md "Optimisation": never
 * trust NLopt's return code), the best feasible point kept across runs, the evaluation budget
 * shared out as it goes.
 */
#include "opt/optimize.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_qrng.h>
#include <nlopt.h>

#include "util/clock.h"
#include "util/rng.h"

const char *const prsm_opt_algorithm_names[] = {"cobyla", "slsqp", "mma", "auglag", NULL};
const char *const prsm_opt_stop_names[] = {"converged", "max_evaluations", "max_time", "cancelled",
                                           "all_pruned", NULL};

#define NCON_MAX (PRSM_OPT_MAX_CONSTRAINTS + PRSM_OPT_MAX_OBJECTIVES)

void prsm_opt_options_init(prsm_opt_options *o)
{
	memset(o, 0, sizeof *o);
	o->algorithm = PRSM_OPT_COBYLA;
	o->max_evaluations = 2000;
	o->max_time_s = 60.0;
	o->multistart = 2;
	o->seed = 1;
	o->xtol_rel = 1e-6;
	o->ftol_rel = 1e-6;
	o->constraint_tol = 1e-6;
	o->fd_step_rel = 1e-6;
	o->scalarisation = PRSM_OPT_SINGLE;
	for (int k = 0; k < PRSM_OPT_MAX_OBJECTIVES; k++) {
		o->weight[k] = 1.0;
		o->range[k] = 1.0;
	}
}

double prsm_opt_scalar(const prsm_opt_problem *p, const prsm_opt_options *o, const double *f)
{
	if (o->scalarisation != PRSM_OPT_WEIGHTED_SUM)
		return p->sense[o->objective] * f[o->objective];
	double s = 0.0;
	for (int k = 0; k < p->n_objectives; k++)
		if (o->weight[k] != 0.0)
			s += o->weight[k] * (p->sense[k] * f[k] - o->ideal[k]) / o->range[k];
	return s;
}

/* One evaluated point: the problem's values and what we derive from them. */
typedef struct {
	double x[PRSM_OPT_MAX_CONTINUOUS];
	double f[PRSM_OPT_MAX_OBJECTIVES];
	double g[NCON_MAX];          /* problem constraints, then the epsilon ones (checked) */
	double gs[NCON_MAX];         /* what the solver sees: g, or the problem's stand-ins */
	double scalar;
	double violation;            /* sum of the positive g */
	int failed;                  /* eval returned nonzero */
	int feasible;
} point;

typedef struct {
	const prsm_opt_problem *p;
	const prsm_opt_options *o;
	int n, m;                    /* continuous variables, constraints handed to NLopt */
	int n_eps;
	int eps_index[PRSM_OPT_MAX_OBJECTIVES];
	double levels[PRSM_OPT_MAX_DISCRETE];
	nlopt_opt opt;               /* the run in progress */
	/* the last point evaluated (NLopt asks for f and the constraints at the same x) */
	int have_last, last_has_grad;
	point last;
	double last_grad_s[PRSM_OPT_MAX_CONTINUOUS];
	double last_grad_g[NCON_MAX * PRSM_OPT_MAX_CONTINUOUS];
	/* across the whole search */
	size_t evaluations, budget;
	int have_best;               /* 0 none, 1 infeasible only, 2 feasible */
	point best;
	double best_levels[PRSM_OPT_MAX_DISCRETE];
	double worst_scalar;         /* largest finite scalar seen: the stand-in for a failed point */
	int cancelled, out_of_budget;
	size_t truncated;            /* local runs stopped by maxeval, maxtime or a forced stop */
	double t0;
} search;

static void report(search *s)
{
	const prsm_opt_options *o = s->o;
	if (!o->progress)
		return;
	prsm_progress pr = PRSM_PROGRESS_INIT;
	pr.done = o->progress_offset + s->evaluations;
	pr.planned = o->progress_planned ? o->progress_planned : o->max_evaluations;
	if (s->have_best == 2)
		pr.best = o->scalarisation == PRSM_OPT_WEIGHTED_SUM ? s->best.scalar
		                                                    : s->best.f[o->objective];
	o->progress(o->progress_ctx, &pr);
}

/* Compare a new point with the best so far: feasible beats infeasible, then the lower scalar
 * (feasible) or the lower violation (infeasible); ties keep the earlier point. */
static void consider(search *s, const point *pt)
{
	int better;
	if (pt->feasible)
		better = s->have_best < 2 || pt->scalar < s->best.scalar;
	else
		better = s->have_best == 0 || (s->have_best == 1 && pt->violation < s->best.violation);
	if (!better)
		return;
	s->best = *pt;
	memcpy(s->best_levels, s->levels, sizeof s->levels);
	s->have_best = pt->feasible ? 2 : 1;
}

/* Call the problem at x; fill pt (and the gradients when gs is not NULL: exact ones only). */
static void eval_raw(search *s, point *pt, const double *x, double *gf, double *gc)
{
	const prsm_opt_problem *p = s->p;
	const prsm_opt_options *o = s->o;
	double gbuf[2 * PRSM_OPT_MAX_CONSTRAINTS];
	const int nc = p->n_constraints;
	memset(pt, 0, sizeof *pt); /* unused entries stay 0: results compare and copy cleanly */
	memcpy(pt->x, x, (size_t)s->n * sizeof *x);
	for (int k = 0; k < p->n_objectives; k++)
		pt->f[k] = NAN;
	for (int i = 0; i < 2 * nc; i++)
		gbuf[i] = NAN;
	pt->failed = p->eval(p->ctx, x, s->levels, pt->f, gbuf, gf, gc) != 0;
	s->evaluations++;
	for (int i = 0; i < nc; i++) {
		/* cannot tell: count it as violated */
		pt->g[i] = isfinite(gbuf[i]) ? gbuf[i] : 1.0;
		pt->gs[i] = !p->has_surrogate ? pt->g[i] : isfinite(gbuf[nc + i]) ? gbuf[nc + i] : 1.0;
	}
	for (int e = 0; e < s->n_eps; e++) {
		int k = s->eps_index[e];
		double gk = p->sense[k] * (pt->f[k] - o->eps_limit[k]) / o->range[k];
		pt->g[nc + e] = pt->gs[nc + e] = isfinite(gk) ? gk : 1.0;
	}
	pt->scalar = prsm_opt_scalar(p, o, pt->f);
	if (!isfinite(pt->scalar)) {
		pt->failed = 1;
		pt->scalar = s->worst_scalar;
	} else if (!pt->failed && pt->scalar > s->worst_scalar) {
		s->worst_scalar = pt->scalar;
	}
	pt->violation = 0.0;
	int ok = !pt->failed;
	for (int i = 0; i < s->m; i++) {
		if (pt->g[i] > 0.0)
			pt->violation += pt->g[i];
		if (!(pt->g[i] <= 0.0)) /* the raw limit: constraint_tol only steers NLopt */
			ok = 0;
	}
	if (pt->failed)
		pt->violation += 1.0;
	pt->feasible = ok;
	consider(s, pt);
	if (s->evaluations % 16 == 0)
		report(s);
}

/* Evaluate at x through the one-point cache, with gradients when want_grad. */
static void evaluate(search *s, const double *x, int want_grad)
{
	const prsm_opt_problem *p = s->p;
	const int n = s->n, m = s->m;
	if (s->have_last && memcmp(s->last.x, x, (size_t)n * sizeof *x) == 0 &&
	    (!want_grad || s->last_has_grad))
		return;
	if (want_grad && p->has_gradient) {
		double gf[PRSM_OPT_MAX_OBJECTIVES * PRSM_OPT_MAX_CONTINUOUS];
		double gc[PRSM_OPT_MAX_CONSTRAINTS * PRSM_OPT_MAX_CONTINUOUS];
		eval_raw(s, &s->last, x, gf, gc);
		const prsm_opt_options *o = s->o;
		for (int j = 0; j < n; j++) {
			double d = 0.0;
			if (o->scalarisation == PRSM_OPT_WEIGHTED_SUM) {
				for (int k = 0; k < p->n_objectives; k++)
					d += o->weight[k] * p->sense[k] * gf[k * n + j] / o->range[k];
			} else {
				d = p->sense[o->objective] * gf[o->objective * n + j];
			}
			s->last_grad_s[j] = d;
			for (int i = 0; i < p->n_constraints; i++)
				s->last_grad_g[i * n + j] = gc[i * n + j];
			for (int e = 0; e < s->n_eps; e++) {
				int k = s->eps_index[e];
				s->last_grad_g[(p->n_constraints + e) * n + j] =
				    p->sense[k] * gf[k * n + j] / o->range[k];
			}
		}
		s->have_last = s->last_has_grad = 1;
		return;
	}
	eval_raw(s, &s->last, x, NULL, NULL);
	s->have_last = 1;
	s->last_has_grad = 0;
	if (!want_grad)
		return;
	/* central differences inside the bounds (one-sided at a bound) */
	point centre = s->last, lo, hi;
	double xs[PRSM_OPT_MAX_CONTINUOUS];
	memcpy(xs, x, (size_t)n * sizeof *x);
	for (int j = 0; j < n; j++) {
		double h = s->o->fd_step_rel * (p->upper[j] - p->lower[j]);
		double a = fmax(p->lower[j], x[j] - h), b = fmin(p->upper[j], x[j] + h);
		xs[j] = a;
		eval_raw(s, &lo, xs, NULL, NULL);
		xs[j] = b;
		eval_raw(s, &hi, xs, NULL, NULL);
		xs[j] = x[j];
		double w = b - a;
		s->last_grad_s[j] = w > 0.0 ? (hi.scalar - lo.scalar) / w : 0.0;
		for (int i = 0; i < m; i++)
			s->last_grad_g[i * n + j] = w > 0.0 ? (hi.gs[i] - lo.gs[i]) / w : 0.0;
	}
	s->last = centre;
	s->last_has_grad = 1;
}

static int stop_now(search *s)
{
	if (prsm_cancel_requested(s->o->cancel)) {
		s->cancelled = 1;
		return 1;
	}
	if (s->evaluations >= s->budget) {
		s->out_of_budget = 1;
		return 1;
	}
	return 0;
}

static double objective_cb(unsigned n, const double *x, double *grad, void *data)
{
	search *s = data;
	if (stop_now(s)) {
		nlopt_force_stop(s->opt);
		if (grad)
			memset(grad, 0, n * sizeof *grad);
		return s->have_last ? s->last.scalar : 0.0;
	}
	evaluate(s, x, grad != NULL);
	if (grad)
		memcpy(grad, s->last_grad_s, n * sizeof *grad);
	return s->last.scalar;
}

static void constraints_cb(unsigned m, double *result, unsigned n, const double *x, double *grad,
                           void *data)
{
	search *s = data;
	if (stop_now(s) && !(s->have_last && memcmp(s->last.x, x, n * sizeof *x) == 0)) {
		nlopt_force_stop(s->opt);
		for (unsigned i = 0; i < m; i++)
			result[i] = 1.0;
		if (grad)
			memset(grad, 0, (size_t)m * n * sizeof *grad);
		return;
	}
	evaluate(s, x, grad != NULL);
	/* the solver's view, aimed constraint_tol inside every limit (optimize.h); we check g <= 0 */
	for (unsigned i = 0; i < m; i++)
		result[i] = s->last.gs[i] + s->o->constraint_tol;
	if (grad)
		memcpy(grad, s->last_grad_g, (size_t)m * n * sizeof *grad);
}

static nlopt_algorithm algorithm_of(int a)
{
	switch (a) {
	case PRSM_OPT_SLSQP: return NLOPT_LD_SLSQP;
	case PRSM_OPT_MMA: return NLOPT_LD_MMA;
	case PRSM_OPT_AUGLAG: return NLOPT_LN_AUGLAG;
	default: return NLOPT_LN_COBYLA;
	}
}

/* One local NLopt run from x0 with at most maxeval evaluations and maxtime seconds. Returns
 * the NLopt result (NLOPT_OUT_OF_MEMORY means we could not set it up). */
static nlopt_result local_run(search *s, double *x0, int maxeval, double maxtime)
{
	const prsm_opt_problem *p = s->p;
	const prsm_opt_options *o = s->o;
	nlopt_result r = NLOPT_OUT_OF_MEMORY;
	nlopt_opt local = NULL;
	nlopt_opt opt = nlopt_create(algorithm_of(o->algorithm), (unsigned)s->n);
	if (!opt)
		return r;
	double tol[NCON_MAX];
	for (int i = 0; i < s->m; i++)
		tol[i] = 0.0; /* NLopt's own: none (the margin is in the values; we check g <= 0) */
	nlopt_set_lower_bounds(opt, p->lower);
	nlopt_set_upper_bounds(opt, p->upper);
	nlopt_set_min_objective(opt, objective_cb, s);
	if (s->m > 0 && nlopt_add_inequality_mconstraint(opt, (unsigned)s->m, constraints_cb, s, tol) < 0)
		goto cleanup;
	nlopt_set_xtol_rel(opt, o->xtol_rel);
	nlopt_set_ftol_rel(opt, o->ftol_rel);
	nlopt_set_maxeval(opt, maxeval);
	nlopt_set_maxtime(opt, maxtime);
	if (o->algorithm == PRSM_OPT_AUGLAG) {
		local = nlopt_create(NLOPT_LN_BOBYQA, (unsigned)s->n);
		if (!local)
			goto cleanup;
		nlopt_set_xtol_rel(local, o->xtol_rel);
		nlopt_set_ftol_rel(local, o->ftol_rel);
		nlopt_set_maxeval(local, maxeval);
		nlopt_set_local_optimizer(opt, local);
	}
	/* an initial step of a tenth of the box: COBYLA's simplex spans the box's scale */
	double dx[PRSM_OPT_MAX_CONTINUOUS];
	for (int j = 0; j < s->n; j++)
		dx[j] = 0.1 * (p->upper[j] - p->lower[j]);
	nlopt_set_initial_step(opt, dx);
	nlopt_srand(o->seed); /* DESIGN.md: seeded in the thread that runs it */
	s->opt = opt;
	s->have_last = 0;
	double f;
	r = nlopt_optimize(opt, x0, &f);
	s->opt = NULL;
cleanup:
	nlopt_destroy(local);
	nlopt_destroy(opt);
	return r;
}

static int check(const prsm_opt_problem *p, const prsm_opt_options *o, prsm_error *err)
{
	if (!p->eval || p->n_continuous < 0 || p->n_continuous > PRSM_OPT_MAX_CONTINUOUS ||
	    p->n_discrete < 0 || p->n_discrete > PRSM_OPT_MAX_DISCRETE || p->n_objectives < 1 ||
	    p->n_objectives > PRSM_OPT_MAX_OBJECTIVES || p->n_constraints < 0 ||
	    p->n_constraints > PRSM_OPT_MAX_CONSTRAINTS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "optimisation problem: sizes out of range");
	for (int j = 0; j < p->n_continuous; j++)
		if (!(isfinite(p->lower[j]) && isfinite(p->upper[j]) && p->lower[j] < p->upper[j]))
			return prsm_error_set(err, PRSM_EINVAL, NULL,
			                      "variable %s: bounds [%g, %g] must be finite with lower < upper",
			                      p->continuous_name[j], p->lower[j], p->upper[j]);
	double combos = 1.0;
	for (int d = 0; d < p->n_discrete; d++) {
		if (p->n_levels[d] < 1 || p->n_levels[d] > PRSM_OPT_MAX_LEVELS)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "variable %s: 1..%d values",
			                      p->discrete_name[d], PRSM_OPT_MAX_LEVELS);
		combos *= p->n_levels[d];
	}
	if (combos > PRSM_OPT_MAX_COMBINATIONS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%.0f combinations of the discrete variables "
		                      "exceed %d", combos, PRSM_OPT_MAX_COMBINATIONS);
	for (int k = 0; k < p->n_objectives; k++)
		if (p->sense[k] != PRSM_OPT_MINIMISE && p->sense[k] != PRSM_OPT_MAXIMISE)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "objective %s: no sense", p->objective_name[k]);
	if (o->algorithm < PRSM_OPT_COBYLA || o->algorithm > PRSM_OPT_AUGLAG || o->max_evaluations < 1 ||
	    !(o->max_time_s > 0.0) || o->multistart < 1 || !(o->xtol_rel >= 0.0) ||
	    !(o->ftol_rel >= 0.0) || !(o->constraint_tol >= 0.0) || !(o->fd_step_rel > 0.0) ||
	    o->objective < 0 || o->objective >= p->n_objectives ||
	    o->scalarisation < PRSM_OPT_SINGLE || o->scalarisation > PRSM_OPT_EPSILON)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "optimisation options out of range");
	for (int k = 0; k < p->n_objectives; k++)
		if (!(o->range[k] > 0.0) || !isfinite(o->range[k]) || !(o->weight[k] >= 0.0) ||
		    !isfinite(o->ideal[k]))
			return prsm_error_set(err, PRSM_EINVAL, NULL,
			                      "objective %s: range must be > 0, weight >= 0, ideal finite",
			                      p->objective_name[k]);
	return 0;
}

int prsm_opt_run(prsm_opt_result *out, const prsm_opt_problem *p, const prsm_opt_options *o,
                 prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->status = PRSM_OPT_NOTHING;
	int rc = check(p, o, err);
	if (rc)
		return rc;
	search *s = calloc(1, sizeof *s);
	gsl_qrng *q = NULL;
	gsl_rng *shift_rng = NULL;
	unsigned char *active = NULL;
	if (!s)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	s->p = p;
	s->o = o;
	s->n = p->n_continuous;
	s->budget = o->max_evaluations;
	s->worst_scalar = 1.0;
	s->t0 = prsm_clock_seconds();
	if (o->scalarisation == PRSM_OPT_EPSILON)
		for (int k = 0; k < p->n_objectives; k++)
			if (o->eps_active[k] && k != o->objective)
				s->eps_index[s->n_eps++] = k;
	s->m = p->n_constraints + s->n_eps;

	/* the combinations, and which of them can be feasible */
	size_t combos = 1;
	for (int d = 0; d < p->n_discrete; d++)
		combos *= (size_t)p->n_levels[d];
	active = calloc(combos, 1);
	if (!active) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	size_t n_active = 0;
	double lv[PRSM_OPT_MAX_DISCRETE];
	for (size_t c = 0; c < combos; c++) {
		size_t r = c;
		for (int d = p->n_discrete - 1; d >= 0; d--) {
			lv[d] = p->levels[d][r % (size_t)p->n_levels[d]];
			r /= (size_t)p->n_levels[d];
		}
		active[c] = !(p->prune && p->prune(p->ctx, lv, p->lower, p->upper));
		n_active += active[c];
	}
	out->combinations = combos;
	out->pruned = combos - n_active;

	if (s->n > 0) {
		q = gsl_qrng_alloc(gsl_qrng_sobol, (unsigned)s->n);
		shift_rng = prsm_rng_alloc((uint64_t)o->seed, 0);
		if (!q || !shift_rng) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory (Sobol generator)");
			goto cleanup;
		}
	}
	size_t runs_left = n_active * (size_t)(s->n > 0 ? o->multistart : 1);
	int timed_out = 0;
	for (size_t c = 0; c < combos && !s->cancelled && !timed_out; c++) {
		if (!active[c])
			continue;
		size_t r = c;
		for (int d = p->n_discrete - 1; d >= 0; d--) {
			s->levels[d] = p->levels[d][r % (size_t)p->n_levels[d]];
			r /= (size_t)p->n_levels[d];
		}
		if (s->n == 0) {
			/* nothing continuous: one evaluation decides the combination */
			if (stop_now(s))
				break;
			point only;
			double none[1] = {0.0};
			eval_raw(s, &only, none, NULL, NULL);
			out->runs++;
			out->runs_feasible += (size_t)only.feasible;
			runs_left--;
			continue;
		}
		/* the Sobol points with this combination's Cranley-Patterson shift (optimize.h): the
		 * Philox stream (seed, c) whatever was pruned or run before */
		double shift[PRSM_OPT_MAX_CONTINUOUS];
		gsl_qrng_init(q);
		prsm_rng_set_stream(shift_rng, (uint64_t)o->seed, (uint64_t)c);
		for (int j = 0; j < s->n; j++)
			shift[j] = gsl_rng_uniform(shift_rng);
		for (int k = 0; k < o->multistart && !s->cancelled && !timed_out; k++) {
			double u[PRSM_OPT_MAX_CONTINUOUS], x[PRSM_OPT_MAX_CONTINUOUS];
			gsl_qrng_get(q, u);
			for (int j = 0; j < s->n; j++) {
				double v = u[j] + shift[j];
				v -= floor(v);
				x[j] = fmin(p->upper[j], p->lower[j] + v * (p->upper[j] - p->lower[j]));
			}
			if (stop_now(s))
				goto done;
			double elapsed = prsm_clock_seconds() - s->t0;
			if (elapsed >= o->max_time_s) {
				timed_out = 1;
				break;
			}
			size_t share = (s->budget - s->evaluations) / runs_left;
			int maxeval = (int)(share < 1 ? 1 : share > (size_t)INT_MAX ? INT_MAX : share);
			nlopt_result nr = local_run(s, x, maxeval, o->max_time_s - elapsed);
			runs_left--;
			if (nr == NLOPT_OUT_OF_MEMORY) {
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory (NLopt)");
				goto cleanup;
			}
			if (nr == NLOPT_MAXTIME_REACHED)
				timed_out = 1;
			if (nr == NLOPT_MAXEVAL_REACHED || nr == NLOPT_MAXTIME_REACHED ||
			    nr == NLOPT_FORCED_STOP)
				s->truncated++;
			out->runs++;
			if (prsm_cancel_requested(o->cancel)) {
				/* a cancelled problem may not evaluate again (a robust study would stop at
				 * once): the run's end point is not re-checked */
				s->cancelled = 1;
				break;
			}
			/* re-check the returned point ourselves, whatever NLopt says */
			point again;
			eval_raw(s, &again, x, NULL, NULL);
			out->runs_feasible += (size_t)again.feasible;
		}
	}
done:
	if (s->have_best) {
		/* the reported point, evaluated once more so every figure belongs to it; after a
		 * cancel the stored evaluation is reported as it is (optimize.h) */
		point fin = s->best;
		if (!s->cancelled) {
			memcpy(s->levels, s->best_levels, sizeof s->levels);
			point again;
			double xb[PRSM_OPT_MAX_CONTINUOUS];
			memcpy(xb, s->best.x, sizeof xb);
			int had = s->have_best;
			eval_raw(s, &again, xb, NULL, NULL);
			s->best = fin;
			s->have_best = had;
			if (prsm_cancel_requested(o->cancel))
				s->cancelled = 1; /* cancelled during the re-check: keep the stored one */
			else
				fin = again;
		}
		out->status = fin.feasible ? PRSM_OPT_FEASIBLE : PRSM_OPT_INFEASIBLE;
		memcpy(out->x, fin.x, (size_t)s->n * sizeof *fin.x);
		memcpy(out->levels, s->best_levels, (size_t)p->n_discrete * sizeof *s->best_levels);
		memcpy(out->objectives, fin.f, (size_t)p->n_objectives * sizeof *fin.f);
		memcpy(out->constraints, fin.g, (size_t)p->n_constraints * sizeof *fin.g);
		out->scalar = fin.scalar;
	}
	out->evaluations = s->evaluations;
	out->cancelled = s->cancelled;
	out->runs_truncated = s->truncated;
	if (s->cancelled)
		out->stop = PRSM_OPT_STOP_CANCELLED;
	else if (n_active == 0)
		out->stop = PRSM_OPT_STOP_ALL_PRUNED;
	else if (timed_out)
		out->stop = PRSM_OPT_STOP_MAXTIME;
	else if (s->out_of_budget || s->evaluations >= s->budget || s->truncated > 0)
		out->stop = PRSM_OPT_STOP_MAXEVAL;
	else
		out->stop = PRSM_OPT_STOP_CONVERGED;
	report(s);
	rc = s->cancelled ? PRSM_ECANCELLED : 0;
	if (rc)
		prsm_error_set(err, rc, NULL, "optimisation cancelled after %zu evaluations",
		               s->evaluations);
cleanup:
	out->elapsed_s = prsm_clock_seconds() - s->t0;
	free(active);
	if (q)
		gsl_qrng_free(q);
	if (shift_rng)
		gsl_rng_free(shift_rng);
	free(s);
	return rc;
}
