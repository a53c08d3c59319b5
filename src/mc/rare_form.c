/*
 * rare_form.c: FORM and SORM of the rare-event engine (rare.h, docs/rare-events.md).
 *
 * FORM. HL-RF (Hasofer & Lind 1974, Rackwitz & Fiessler 1978) with Zhang & Der Kiureghian's
 * merit function (1995): from u with G = g(u) and its gradient, the HL-RF point is
 * ((grad.u - G) / |grad|^2) grad, the direction d that point minus u, and the step u + lambda d
 * takes the largest lambda = backtrack^j whose merit m = |u|^2 / 2 + c |G| satisfies Armijo's
 * m(u + lambda d) - m(u) <= armijo lambda grad m . d (plus a rounding allowance of a few ulps of
 * m and of c g, so that a converged iterate is not refused for noise), with
 * c = 2 max(|u| / |grad|, |u + d|^2 / (2 |G|)) > |u| / |grad|, which makes d a descent direction
 * of m; the second bound only while |G| > 1000 tol_g |g(u_0)| (on the limit state it grows as
 * 1 / |G| and the merit would follow the noise of g). With G = 0 the merit is |u|^2 / 2 and the
 * full step is a projection, which satisfies Armijo with equality for armijo = 1/2: the default
 * armijo is 0.1. The run has converged when |G| <= tol_g |g(u_0)| and
 * |u - (alpha.u) alpha| <= tol_u.
 *
 * The gradient is a central difference in U: h_i = fd_step max(1, |u_i|) (U is already in units
 * of standard deviations, so the step is relative to the variable's scale), divided by the
 * representable (u_i + h) - (u_i - h); 2 d evaluations per gradient, all of them in one parallel
 * batch, each task building its point and writing its own slot.
 *
 * SORM. The Hessian of g in U at u* by central differences (h_i = hessian_step max(1, |u*_i|):
 * 2 d evaluations for the diagonal, 4 per pair off it, 2 d^2 in all), rotated by R, an orthonormal
 * matrix whose last row is alpha (Gram-Schmidt from alpha and the unit vectors but the one
 * alpha leans on most), A = (R H R^T)_{d-1 x d-1} / |grad g|; its eigenvalues are the principal
 * curvatures kappa_i. Breitung (1984): P = Phi(-beta) prod (1 + beta kappa_i)^-1/2;
 * Hohenbichler & Rackwitz (1988): beta replaced by psi = phi(beta) / Phi(-beta) inside the
 * product; Tvedt's three-term formula (1990), with the product over (1 + (beta + i) kappa_i)^-1/2
 * taken as the exponential of the sum of the principal logarithms.
 */
#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>

#include "mc/rare.h"
#include "mc/rare_internal.h"
#include "util/clock.h"

void prsm_rare_form_result_free(prsm_rare_form_result *r)
{
	if (!r)
		return;
	free(r->u_star);
	free(r->x_star);
	free(r->alpha);
	free(r->alpha2);
	free(r->importance);
	free(r->points);
	r->u_star = r->x_star = r->alpha = r->alpha2 = r->importance = r->points = NULL;
}

void prsm_rare_sorm_result_free(prsm_rare_sorm_result *r)
{
	if (!r)
		return;
	free(r->kappa);
	r->kappa = NULL;
}

/* ---- batches of points ---------------------------------------------------------------------- */

typedef struct {
	rare_pool *pool;
	const prsm_rare_options *o;
	size_t d;
	const double *base;               /* the point of the batch: u, or the line search's trial */
	double *h;                        /* d gradient steps (the representable half-distances) */
	int gradient;                     /* the batch: 2 d gradient points, else base alone */
	double *gv;                       /* 2 d values */
	int *code, *lscode;
	size_t evaluations;               /* of the whole FORM call */
	size_t failed_index;
	prsm_error *err;
} form_ctx;

/* Point q of a batch: base, or base +- h_i e_i for q = 2 i, 2 i + 1. */
static void form_task(rare_worker *w, size_t q, void *argp)
{
	form_ctx *c = argp;
	const double *u = c->base;
	if (c->gradient) {
		memcpy(w->a, c->base, c->d * sizeof *w->a);
		size_t i = q / 2;
		w->a[i] = q % 2 == 0 ? c->base[i] + c->h[i] : c->base[i] - c->h[i];
		u = w->a;
	}
	c->code[q] = rare_eval(w, u, &c->gv[q], &c->lscode[q]);
}

/* Evaluate the batch. Returns 0, a prsm_rare_stop (> 0: halted or out of budget) or a negative
 * error code (err filled, failed_index set). */
static int form_batch(form_ctx *c, size_t n, const char *what, size_t start, size_t iter)
{
	if (c->evaluations + n > c->o->max_evaluations)
		return PRSM_RARE_STOP_MAX_EVALUATIONS;
	int h = rare_pool_halted(c->pool);
	if (h)
		return h;
	size_t before = c->evaluations;
	rare_pool_run(c->pool, n, form_task, c);
	for (size_t i = 0; i < n; i++)
		if (c->code[i] != RARE_HALTED)
			c->evaluations++;
	rare_progress(c->pool, c->evaluations, NAN, 0);
	for (size_t i = 0; i < n; i++) {
		if (c->code[i] == RARE_HALTED)
			return rare_pool_halted(c->pool);
		if (c->code[i]) {
			char where[128];
			c->failed_index = before + i;
			snprintf(where, sizeof where, "FORM evaluation %zu (%s, start %zu, iteration %zu)", before + i, what,
			         start, iter);
			return rare_eval_error(c->err, c->lscode[i], where);
		}
	}
	return 0;
}

/* grad g at u. */
static int form_gradient(form_ctx *c, const double *u, double *grad, size_t start, size_t iter)
{
	size_t d = c->d;
	for (size_t i = 0; i < d; i++) {
		double h = c->o->fd_step * fmax(1.0, fabs(u[i]));
		c->h[i] = ((u[i] + h) - (u[i] - h)) / 2.0;
	}
	c->base = u;
	c->gradient = 1;
	int rc = form_batch(c, 2 * d, "gradient", start, iter);
	if (rc)
		return rc;
	for (size_t i = 0; i < d; i++)
		grad[i] = (c->gv[2 * i] - c->gv[2 * i + 1]) / ((u[i] + c->h[i]) - (u[i] - c->h[i]));
	return 0;
}

static int form_eval1(form_ctx *c, const double *u, double *g, const char *what, size_t start, size_t iter)
{
	c->base = u;
	c->gradient = 0;
	int rc = form_batch(c, 1, what, start, iter);
	if (rc == 0)
		*g = c->gv[0];
	return rc;
}

/* One HL-RF run. */
typedef struct {
	double *u, *grad;                 /* at the end */
	double G, G0, e1, e2;
	size_t iterations;
	int converged;
	prsm_rare_stop stop;
	char reason[PRSM_RARE_REASON_MAX];
} form_run;

/* Returns 0 (the run ended: see r->stop) or a negative error code. */
static int form_one(form_ctx *c, const double *u0, size_t start, form_run *r, double *dir, double *ut)
{
	const prsm_rare_options *o = c->o;
	size_t d = c->d;
	memcpy(r->u, u0, d * sizeof *r->u);
	r->iterations = 0;
	r->converged = 0;
	r->stop = PRSM_RARE_STOP_MAX_ITERATIONS;
	r->G = r->G0 = r->e1 = r->e2 = NAN;
	int rc = form_eval1(c, r->u, &r->G, "start", start, 0);
	if (rc == 0) {
		r->G0 = r->G;
		rc = form_gradient(c, r->u, r->grad, start, 0);
	}
	if (rc < 0)
		return rc;
	if (rc > 0) {
		r->stop = (prsm_rare_stop)rc;
		snprintf(r->reason, sizeof r->reason, "stopped at the start: %s", prsm_rare_stop_name(r->stop));
		return 0;
	}
	double scale = fabs(r->G0) > 0.0 ? fabs(r->G0) : 1.0;
	for (;;) {
		double gn = rare_norm(r->grad, d);
		r->e1 = fabs(r->G) / scale;
		if (!(gn > 0.0) || !isfinite(gn)) {
			r->stop = PRSM_RARE_STOP_ZERO_GRADIENT;
			snprintf(r->reason, sizeof r->reason, "the gradient vanished at iteration %zu (|g|/|g0| = %.3g)",
			         r->iterations, r->e1);
			return 0;
		}
		double au = -rare_dot(r->grad, r->u, d) / gn, e2 = 0.0;
		for (size_t i = 0; i < d; i++) {
			double v = r->u[i] - au * (-r->grad[i] / gn);
			e2 += v * v;
		}
		r->e2 = sqrt(e2);
		if (r->e1 <= o->form_tol_g && r->e2 <= o->form_tol_u) {
			r->converged = 1;
			r->stop = PRSM_RARE_STOP_CONVERGED;
			snprintf(r->reason, sizeof r->reason, "converged in %zu iterations (|g|/|g0| = %.3g, |u - (alpha.u) alpha| = %.3g)",
			         r->iterations, r->e1, r->e2);
			return 0;
		}
		if (r->iterations >= (size_t)o->form_max_iterations) {
			r->stop = PRSM_RARE_STOP_MAX_ITERATIONS;
			snprintf(r->reason, sizeof r->reason, "%d iterations without convergence (|g|/|g0| = %.3g, |u - (alpha.u) alpha| = %.3g)",
			         o->form_max_iterations, r->e1, r->e2);
			return 0;
		}
		/* HL-RF direction and the merit function */
		double gu = rare_dot(r->grad, r->u, d);
		double f = (gu - r->G) / (gn * gn);
		for (size_t i = 0; i < d; i++)
			dir[i] = f * r->grad[i] - r->u[i];
		double un = rare_norm(r->u, d);
		double cm = un / gn;
		if (fabs(r->G) > 1e3 * o->form_tol_g * scale) {
			/* off the limit state: large enough that the full HL-RF step passes (Zhang & Der
			 * Kiureghian's second bound); on it this bound would blow up as 1 / |G| and leave
			 * the merit function to the noise of g */
			double s = 0.0;
			for (size_t i = 0; i < d; i++)
				s += (r->u[i] + dir[i]) * (r->u[i] + dir[i]);
			cm = fmax(cm, 0.5 * s / fabs(r->G));
		}
		cm *= 2.0;
		if (!(cm > 0.0))
			cm = 1.0 / gn;
		double m0 = 0.5 * un * un + cm * fabs(r->G);
		double slope = rare_dot(r->u, dir, d) - cm * fabs(r->G);
		double lambda = 1.0, Gt = NAN;
		int accepted = 0;
		for (int t = 0; t < o->line_search_max; t++) {
			for (size_t i = 0; i < d; i++)
				ut[i] = r->u[i] + lambda * dir[i];
			rc = form_eval1(c, ut, &Gt, "line search", start, r->iterations);
			if (rc < 0)
				return rc;
			if (rc > 0) {
				r->stop = (prsm_rare_stop)rc;
				snprintf(r->reason, sizeof r->reason, "stopped at iteration %zu: %s", r->iterations,
				         prsm_rare_stop_name(r->stop));
				return 0;
			}
			double utn = rare_norm(ut, d);
			double mt = 0.5 * utn * utn + cm * fabs(Gt);
			/* Armijo, with an allowance for rounding in m and in g */
			double noise = 8.0 * DBL_EPSILON * (m0 + mt) + 16.0 * DBL_EPSILON * cm * (scale + fabs(r->G));
			if (mt - m0 <= o->armijo * lambda * slope + noise) {
				accepted = 1;
				break;
			}
			lambda *= o->backtrack;
		}
		if (!accepted) {
			r->stop = PRSM_RARE_STOP_LINE_SEARCH;
			snprintf(r->reason, sizeof r->reason, "no step decreased the merit function at iteration %zu "
			         "(|g|/|g0| = %.3g, |u - (alpha.u) alpha| = %.3g)", r->iterations, r->e1, r->e2);
			return 0;
		}
		memcpy(r->u, ut, d * sizeof *r->u);
		r->G = Gt;
		r->iterations++;
		rc = form_gradient(c, r->u, r->grad, start, r->iterations);
		if (rc < 0)
			return rc;
		if (rc > 0) {
			r->stop = (prsm_rare_stop)rc;
			snprintf(r->reason, sizeof r->reason, "stopped at iteration %zu: %s", r->iterations,
			         prsm_rare_stop_name(r->stop));
			return 0;
		}
	}
}

static double beta_of_run(const form_run *r, size_t d)
{
	double gn = rare_norm(r->grad, d);
	if (!(gn > 0.0) || !isfinite(gn))
		return rare_norm(r->u, d) * (r->G0 < 0.0 ? -1.0 : 1.0);
	return -rare_dot(r->grad, r->u, d) / gn;
}

int prsm_rare_form(prsm_rare_form_result *out, const prsm_rare_problem *p, const prsm_rare_options *o,
                   prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	memset(out, 0, sizeof *out);
	out->failed_index = SIZE_MAX;
	out->beta = out->pf = out->g0 = out->g_star = out->grad_norm = out->e1 = out->e2 = NAN;
	int rc = prsm_rare_options_check(o, p->d, err);
	if (rc)
		return rc;
	size_t d = p->d;
	out->d = d;
	out->u_star = calloc(d, sizeof *out->u_star);
	out->x_star = calloc(d, sizeof *out->x_star);
	out->alpha = calloc(d, sizeof *out->alpha);
	out->alpha2 = calloc(d, sizeof *out->alpha2);
	out->importance = calloc(d, sizeof *out->importance);
	out->points = calloc(PRSM_RARE_MAX_DESIGN_POINTS * d, sizeof *out->points);
	if (!out->u_star || !out->x_star || !out->alpha || !out->alpha2 || !out->importance || !out->points)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");

	rare_space s;
	rare_pool pool;
	rc = rare_setup(&s, &pool, p, o, err);
	if (rc)
		return rc;
	form_ctx c;
	memset(&c, 0, sizeof c);
	c.pool = &pool;
	c.o = o;
	c.d = d;
	c.err = err;
	c.failed_index = SIZE_MAX;
	c.h = malloc(d * sizeof *c.h);
	c.gv = malloc(2 * d * sizeof *c.gv);
	c.code = malloc(2 * d * sizeof *c.code);
	c.lscode = malloc(2 * d * sizeof *c.lscode);
	form_run run, best;
	memset(&run, 0, sizeof run);
	memset(&best, 0, sizeof best);
	run.u = malloc(d * sizeof *run.u);
	run.grad = malloc(d * sizeof *run.grad);
	best.u = malloc(d * sizeof *best.u);
	best.grad = malloc(d * sizeof *best.grad);
	double *dir = malloc(d * sizeof *dir), *ut = malloc(d * sizeof *ut), *z = malloc(d * sizeof *z);
	double *u0 = calloc(d, sizeof *u0);
	if (!c.h || !c.gv || !c.code || !c.lscode || !run.u || !run.grad || !best.u || !best.grad || !dir || !ut ||
	    !z || !u0) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for FORM in %zu variables", d);
		goto done;
	}

	int have_best = 0;
	double best_beta = INFINITY;
	for (size_t st = 0; st <= o->n_starts; st++) {
		const double *start = st == 0 ? u0 : o->starts + (st - 1) * d;
		rc = form_one(&c, start, st, &run, dir, ut);
		if (rc < 0) {
			out->failed_index = c.failed_index;
			goto done;
		}
		rc = 0;
		if (st == 0)
			out->g0 = run.G0;
		double b = beta_of_run(&run, d);
		if (run.converged) {
			/* a new design point unless it is one already found */
			int seen = 0;
			for (size_t q = 0; q < out->n_points && !seen; q++) {
				double dist2 = 0.0;
				for (size_t i = 0; i < d; i++) {
					double v = out->points[q * d + i] - run.u[i];
					dist2 += v * v;
				}
				seen = sqrt(dist2) <= 1e-3 * fmax(1.0, rare_norm(run.u, d));
			}
			if (!seen && out->n_points < PRSM_RARE_MAX_DESIGN_POINTS) {
				/* keep them sorted by beta (stable: earlier starts first among equals) */
				size_t q = out->n_points;
				while (q > 0 && out->point_beta[q - 1] > b) {
					out->point_beta[q] = out->point_beta[q - 1];
					memcpy(out->points + q * d, out->points + (q - 1) * d, d * sizeof *out->points);
					q--;
				}
				out->point_beta[q] = b;
				memcpy(out->points + q * d, run.u, d * sizeof *out->points);
				out->n_points++;
			}
		}
		/* the reported run: the converged one of least beta, else the first */
		int take = !have_best || (run.converged && (!best.converged || b < best_beta));
		if (take) {
			memcpy(best.u, run.u, d * sizeof *best.u);
			memcpy(best.grad, run.grad, d * sizeof *best.grad);
			best.G = run.G;
			best.G0 = run.G0;
			best.e1 = run.e1;
			best.e2 = run.e2;
			best.iterations = run.iterations;
			best.converged = run.converged;
			best.stop = run.stop;
			memcpy(best.reason, run.reason, sizeof best.reason);
			best_beta = b;
			have_best = 1;
		}
		if (run.stop == PRSM_RARE_STOP_CANCELLED || run.stop == PRSM_RARE_STOP_TIME_CAP ||
		    run.stop == PRSM_RARE_STOP_MAX_EVALUATIONS)
			break;
	}

	/* the result */
	memcpy(out->u_star, best.u, d * sizeof *out->u_star);
	double gn = rare_norm(best.grad, d);
	out->grad_norm = gn;
	for (size_t i = 0; i < d; i++)
		out->alpha[i] = gn > 0.0 ? -best.grad[i] / gn : 0.0;
	for (size_t i = 0; i < d; i++)
		out->alpha2[i] = out->alpha[i] * out->alpha[i];
	rare_space_importance(&s, out->alpha, out->importance);
	rare_space_to_x(&s, out->u_star, z, out->x_star);
	out->beta = best_beta;
	out->pf = rare_phi_minus(best_beta);
	out->g_star = best.G;
	out->e1 = best.e1;
	out->e2 = best.e2;
	out->iterations = best.iterations;
	out->converged = best.converged;
	out->stop = best.stop;
	snprintf(out->reason, sizeof out->reason, "%s", best.reason);
	rare_progress(&pool, c.evaluations, NAN, 1);

done:
	out->evaluations = c.evaluations;
	free(c.h);
	free(c.gv);
	free(c.code);
	free(c.lscode);
	free(run.u);
	free(run.grad);
	free(best.u);
	free(best.grad);
	free(dir);
	free(ut);
	free(z);
	free(u0);
	rare_pool_free(&pool);
	rare_space_free(&s);
	out->elapsed_s = prsm_clock_seconds() - t0;
	return rc;
}

/* ---- SORM ----------------------------------------------------------------------------------- */

typedef struct {
	const double *u;                  /* u* */
	const double *h;                  /* steps */
	size_t d, n_pairs;
	const size_t *pi, *pj;            /* pairs i < j */
	double *g;
	int *code, *lscode;
} hess_arg;

/* Point q of the Hessian stencil: q < 2d the diagonal (u +- h_i e_i), then 4 per pair
 * (+ +, + -, - +, - -). */
static void hess_point(const hess_arg *a, size_t q, double *u)
{
	size_t d = a->d;
	memcpy(u, a->u, d * sizeof *u);
	if (q < 2 * d) {
		size_t i = q / 2;
		u[i] = q % 2 == 0 ? a->u[i] + a->h[i] : a->u[i] - a->h[i];
		return;
	}
	size_t r = q - 2 * d, pr = r / 4, sg = r % 4;
	size_t i = a->pi[pr], j = a->pj[pr];
	u[i] = sg < 2 ? a->u[i] + a->h[i] : a->u[i] - a->h[i];
	u[j] = sg % 2 == 0 ? a->u[j] + a->h[j] : a->u[j] - a->h[j];
}

static void hess_task(rare_worker *w, size_t q, void *argp)
{
	hess_arg *a = argp;
	hess_point(a, q, w->a);
	a->code[q] = rare_eval(w, w->a, &a->g[q], &a->lscode[q]);
}

static int cmp_desc(const void *pa, const void *pb)
{
	double a = *(const double *)pa, b = *(const double *)pb;
	return a > b ? -1 : (a < b ? 1 : 0);
}

int prsm_rare_sorm(prsm_rare_sorm_result *out, const prsm_rare_problem *p,
                   const prsm_rare_form_result *form, const prsm_rare_options *o, prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	memset(out, 0, sizeof *out);
	out->failed_index = SIZE_MAX;
	out->pf_breitung = out->pf_hr = out->pf_tvedt = NAN;
	out->beta_breitung = out->beta_hr = out->beta_tvedt = NAN;
	int rc = prsm_rare_options_check(o, p->d, err);
	if (rc)
		return rc;
	if (form->d != p->d || form->u_star == NULL)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the FORM result is not of this problem");
	size_t d = p->d;
	if (!form->converged) {
		out->stop = PRSM_RARE_STOP_FORM;
		snprintf(out->reason, sizeof out->reason, "FORM did not converge (%s)", prsm_rare_stop_name(form->stop));
		out->elapsed_s = prsm_clock_seconds() - t0;
		return 0;
	}
	size_t n1 = d - 1;
	out->n_curvatures = n1;
	out->kappa = calloc(n1 ? n1 : 1, sizeof *out->kappa);
	if (!out->kappa)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	double beta = form->beta;

	if (n1 > 0) {
		size_t n_pairs = d * (d - 1) / 2, n_pts = 2 * d + 4 * n_pairs;
		if (n_pts > o->max_evaluations) {
			out->stop = PRSM_RARE_STOP_MAX_EVALUATIONS;
			snprintf(out->reason, sizeof out->reason,
			         "the Hessian needs %zu evaluations, more than the budget %zu", n_pts, o->max_evaluations);
			out->elapsed_s = prsm_clock_seconds() - t0;
			return 0;
		}
		rare_space s;
		rare_pool pool;
		rc = rare_setup(&s, &pool, p, o, err);
		if (rc)
			return rc;
		double *h = malloc(d * sizeof *h);
		size_t *pi = malloc((n_pairs ? n_pairs : 1) * sizeof *pi), *pj = malloc((n_pairs ? n_pairs : 1) * sizeof *pj);
		double *g = malloc(n_pts * sizeof *g);
		int *code = malloc(n_pts * sizeof *code), *lscode = malloc(n_pts * sizeof *lscode);
		double *H = calloc(d * d, sizeof *H), *R = calloc(d * d, sizeof *R), *T = calloc(d * d, sizeof *T);
		gsl_matrix *A = gsl_matrix_alloc(n1, n1);
		gsl_vector *ev = gsl_vector_alloc(n1);
		gsl_eigen_symm_workspace *ew = gsl_eigen_symm_alloc(n1);
		if (!h || !pi || !pj || !g || !code || !lscode || !H || !R || !T || !A || !ev || !ew) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the Hessian of %zu variables", d);
			goto sorm_free;
		}
		const double *u = form->u_star;
		for (size_t i = 0; i < d; i++) {
			double hh = o->hessian_step * fmax(1.0, fabs(u[i]));
			/* the representable half-distance of u +- h */
			h[i] = ((u[i] + hh) - (u[i] - hh)) / 2.0;
		}
		size_t q = 0;
		for (size_t i = 0; i < d; i++)
			for (size_t j = i + 1; j < d; j++) {
				pi[q] = i;
				pj[q] = j;
				q++;
			}
		hess_arg ha = {u, h, d, n_pairs, pi, pj, g, code, lscode};
		int halted = rare_pool_halted(&pool);
		if (!halted) {
			rare_pool_run(&pool, n_pts, hess_task, &ha);
			for (size_t k = 0; k < n_pts; k++)
				if (code[k] != RARE_HALTED)
					out->evaluations++;
			for (size_t k = 0; k < n_pts && !halted; k++) {
				if (code[k] == RARE_HALTED) {
					halted = rare_pool_halted(&pool);
				} else if (code[k]) {
					char where[96];
					out->failed_index = k;
					snprintf(where, sizeof where, "SORM Hessian evaluation %zu", k);
					rc = rare_eval_error(err, lscode[k], where);
					goto sorm_free;
				}
			}
		}
		if (halted) {
			out->stop = (prsm_rare_stop)halted;
			snprintf(out->reason, sizeof out->reason, "stopped: %s", prsm_rare_stop_name(out->stop));
			goto sorm_free;
		}
		/* H */
		double g0 = form->g_star;
		for (size_t i = 0; i < d; i++) {
			double hp = (u[i] + h[i]) - u[i], hm = u[i] - (u[i] - h[i]);
			H[i * d + i] = 2.0 * ((g[2 * i] - g0) / hp - (g0 - g[2 * i + 1]) / hm) / (hp + hm);
		}
		for (size_t k = 0; k < n_pairs; k++) {
			size_t i = pi[k], j = pj[k];
			const double *gg = g + 2 * d + 4 * k;
			double v = (gg[0] - gg[1] - gg[2] + gg[3]) / (4.0 * h[i] * h[j]);
			H[i * d + j] = H[j * d + i] = v;
		}
		/* R: last row alpha, the others from the unit vectors (but the one alpha leans on most),
		 * orthonormalised by modified Gram-Schmidt (twice) */
		const double *al = form->alpha;
		size_t piv = 0;
		for (size_t i = 1; i < d; i++)
			if (fabs(al[i]) > fabs(al[piv]))
				piv = i;
		double an = rare_norm(al, d);
		for (size_t i = 0; i < d; i++)
			R[(d - 1) * d + i] = al[i] / an;
		size_t row = 0;
		for (size_t e = 0; e < d; e++) {
			if (e == piv)
				continue;
			double *r = R + row * d;
			memset(r, 0, d * sizeof *r);
			r[e] = 1.0;
			for (int pass = 0; pass < 2; pass++) {
				const double *a0 = R + (d - 1) * d;
				double pr = rare_dot(r, a0, d);
				for (size_t i = 0; i < d; i++)
					r[i] -= pr * a0[i];
				for (size_t k = 0; k < row; k++) {
					const double *rk = R + k * d;
					double pk = rare_dot(r, rk, d);
					for (size_t i = 0; i < d; i++)
						r[i] -= pk * rk[i];
				}
			}
			double rn = rare_norm(r, d);
			for (size_t i = 0; i < d; i++)
				r[i] /= rn;
			row++;
		}
		/* A = (R H R^T)[0..n1) / |grad| */
		for (size_t i = 0; i < n1; i++)
			for (size_t j = 0; j < d; j++)
				T[i * d + j] = rare_dot(R + i * d, H + j * d, d); /* (R H)_ij, H symmetric */
		for (size_t i = 0; i < n1; i++)
			for (size_t j = 0; j <= i; j++) {
				double v = rare_dot(T + i * d, R + j * d, d) / form->grad_norm;
				gsl_matrix_set(A, i, j, v);
				gsl_matrix_set(A, j, i, v);
			}
		gsl_eigen_symm(A, ev, ew);
		for (size_t i = 0; i < n1; i++)
			out->kappa[i] = gsl_vector_get(ev, i);
		qsort(out->kappa, n1, sizeof *out->kappa, cmp_desc);
	sorm_free:
		free(h);
		free(pi);
		free(pj);
		free(g);
		free(code);
		free(lscode);
		free(H);
		free(R);
		free(T);
		if (A)
			gsl_matrix_free(A);
		if (ev)
			gsl_vector_free(ev);
		if (ew)
			gsl_eigen_symm_free(ew);
		rare_pool_free(&pool);
		rare_space_free(&s);
		if (rc || out->stop == PRSM_RARE_STOP_CANCELLED || out->stop == PRSM_RARE_STOP_TIME_CAP) {
			out->elapsed_s = prsm_clock_seconds() - t0;
			return rc;
		}
	}

	/* the formulas */
	double q = rare_phi_minus(beta), ph = gsl_ran_ugaussian_pdf(beta);
	double psi = ph / q;
	int ok_b = beta > 0.0, ok_h = beta > 0.0, ok_t = beta > 0.0;
	double lb = 0.0, lh = 0.0, l1 = 0.0;
	double complex lc = 0.0;
	for (size_t i = 0; i < n1; i++) {
		double k = out->kappa[i];
		if (!(1.0 + beta * k > 0.0))
			ok_b = ok_t = 0;
		if (!(1.0 + psi * k > 0.0))
			ok_h = 0;
		if (!(1.0 + (beta + 1.0) * k > 0.0))
			ok_t = 0;
		if (ok_b)
			lb += -0.5 * log1p(beta * k);
		if (ok_h)
			lh += -0.5 * log1p(psi * k);
		if (ok_t) {
			l1 += -0.5 * log1p((beta + 1.0) * k);
			lc += -0.5 * clog(1.0 + (beta + I) * k);
		}
	}
	if (ok_b) {
		out->ok_breitung = 1;
		out->pf_breitung = q * exp(lb);
		out->beta_breitung = rare_beta_of(out->pf_breitung);
	}
	if (ok_h) {
		out->ok_hr = 1;
		out->pf_hr = q * exp(lh);
		out->beta_hr = rare_beta_of(out->pf_hr);
	}
	if (ok_t) {
		double p1 = exp(lb), p2 = exp(l1), p3 = creal(cexp(lc));
		double t = beta * q - ph;
		double pt = q * p1 + t * (p1 - p2) + (beta + 1.0) * t * (p1 - p3);
		if (pt > 0.0 && pt < 1.0) {
			out->ok_tvedt = 1;
			out->pf_tvedt = pt;
			out->beta_tvedt = rare_beta_of(pt);
		}
	}
	out->converged = out->ok_breitung && out->ok_hr && out->ok_tvedt;
	out->stop = out->converged ? PRSM_RARE_STOP_CONVERGED : PRSM_RARE_STOP_CURVATURE;
	if (out->converged)
		snprintf(out->reason, sizeof out->reason, "%zu curvatures from %zu evaluations", n1, out->evaluations);
	else if (!(beta > 0.0))
		snprintf(out->reason, sizeof out->reason, "beta = %.6g <= 0: the SORM formulas do not apply", beta);
	else
		snprintf(out->reason, sizeof out->reason, "refused: %s%s%s(some 1 + beta kappa_i <= 0)",
		         out->ok_breitung ? "" : "Breitung ", out->ok_hr ? "" : "Hohenbichler-Rackwitz ",
		         out->ok_tvedt ? "" : "Tvedt ");
	out->elapsed_s = prsm_clock_seconds() - t0;
	return 0;
}
