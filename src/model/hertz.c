/*
 * hertz.c: Hertz point contact, Harris's formulation (docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "model/hertz.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_sf_ellint.h>
#include <math.h>

#include "util/error.h"

/* F(rho) as a function of kappa >= 1, with K and E returned. */
static double curvature_difference_of(double kappa, double *K, double *E)
{
	double e = sqrt(1.0 - 1.0 / (kappa * kappa));
	*K = gsl_sf_ellint_Kcomp(e, GSL_PREC_DOUBLE);
	*E = gsl_sf_ellint_Ecomp(e, GSL_PREC_DOUBLE);
	return ((kappa * kappa + 1.0) * (*E) - 2.0 * (*K)) / ((kappa * kappa - 1.0) * (*E));
}

/* The target F and the two bracket ends checked before GSL's solver evaluates them again. */
typedef struct {
	double target;
	double t[2], r[2];
	int n;
} residual_params;

/* F(rho) of kappa = exp(t) minus the target. At kappa <= 1 + 1e-12 the formula is 0/0 (or
 * rounding noise): there it is the circle's F = 0, so the residual is -target, finite and
 * negative (GSL's solver refuses a non-finite value through its error handler). */
static double residual(double t, void *params)
{
	residual_params *p = params;
	for (int i = 0; i < p->n; i++)
		if (p->t[i] == t)
			return p->r[i];
	const double kappa = exp(t);
	double K, E;
	if (!(kappa > 1.0 + 1e-12))
		return -p->target;
	return curvature_difference_of(kappa, &K, &E) - p->target;
}

/* residual(t), remembered for the solver's first two evaluations (the bracket ends). */
static double residual_kept(double t, residual_params *p)
{
	const double r = residual(t, p);
	if (p->n < 2) {
		p->t[p->n] = t;
		p->r[p->n++] = r;
	}
	return r;
}

int prsm_hertz_coefficients(prsm_hertz *out, double F)
{
	if (!(F >= 0.0 && F < 1.0))
		return PRSM_EINVAL;
	double kappa = 1.0, K = M_PI / 2.0, E = M_PI / 2.0;
	if (F > PRSM_HERTZ_CIRCLE_F) {
		/* F increases with kappa from 0 (circle) to 1: a root of residual(t), t = ln kappa in
		 * (0, ln PRSM_HERTZ_KAPPA_MAX], by Brent's method from a bracket around Hamrock and
		 * Brewe's kappa ~ (k2/k1)^(2/pi), i.e. t ~ (4/pi) atanh F; the true root lies within
		 * [0.85, 1.05] times that for every F below F(PRSM_HERTZ_KAPPA_MAX). Each end is
		 * checked and, when it does not hold, moved to the end of the whole range (t = 0 where
		 * the residual is -F < 0, t = ln kappa_max), so that GSL is only given a bracket. */
		residual_params rp = {F, {0.0, 0.0}, {0.0, 0.0}, 0};
		const double t_max = log(PRSM_HERTZ_KAPPA_MAX);
		const double t_guess = (4.0 / M_PI) * atanh(F);
		double lo = 0.8 * t_guess, hi = 1.1 * t_guess;
		if (!(hi < t_max))
			hi = t_max;
		if (!(lo < hi))
			lo = 0.0;
		if (!(residual_kept(lo, &rp) < 0.0))
			lo = 0.0;
		double r_hi = residual_kept(hi, &rp);
		if (!(r_hi > 0.0) && hi < t_max) {
			hi = t_max;
			r_hi = residual_kept(hi, &rp);
		}
		double t;
		if (r_hi > 0.0) {
			gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
			if (!s)
				return PRSM_ENOMEM;
			gsl_function fn = {residual, &rp};
			int status = gsl_root_fsolver_set(s, &fn, lo, hi), converged = 0;
			for (int i = 0; status == GSL_SUCCESS && !converged && i < PRSM_HERTZ_MAX_ITER; i++) {
				status = gsl_root_fsolver_iterate(s);
				if (status == GSL_SUCCESS)
					converged = gsl_root_test_interval(gsl_root_fsolver_x_lower(s),
					                                   gsl_root_fsolver_x_upper(s), PRSM_HERTZ_TOL,
					                                   PRSM_HERTZ_TOL) == GSL_SUCCESS;
			}
			t = gsl_root_fsolver_root(s);
			gsl_root_fsolver_free(s);
			if (status != GSL_SUCCESS || !converged)
				return PRSM_ENOCONVERGE;
		} else {
			t = t_max; /* F >= F(kappa_max): kappa_max, as the bisection before it gave */
		}
		kappa = exp(t);
		curvature_difference_of(kappa, &K, &E);
	}
	out->curvature_difference = F;
	out->kappa = kappa;
	out->ellint_K = K;
	out->ellint_E = E;
	out->a_star = cbrt(2.0 * kappa * kappa * E / M_PI);
	out->b_star = cbrt(2.0 * E / (M_PI * kappa));
	out->delta_star = (2.0 * K / M_PI) * cbrt(M_PI / (2.0 * kappa * kappa * E));
	return 0;
}

int prsm_hertz_solve(prsm_hertz *out, double k1, double k2, double E1, double nu1, double E2,
                     double nu2, double Q)
{
	if (k1 > k2) {
		double t = k1;
		k1 = k2;
		k2 = t;
	}
	double sum = k1 + k2;
	if (!(k1 > 0.0) || !(E1 > 0.0) || !(E2 > 0.0) || !(Q >= 0.0) || !isfinite(sum))
		return PRSM_EINVAL;
	int rc = prsm_hertz_coefficients(out, (k2 - k1) / sum);
	if (rc)
		return rc;
	const double S = (1.0 - nu1 * nu1) / E1 + (1.0 - nu2 * nu2) / E2; /* 1/MPa */
	const double base = cbrt(1.5 * Q * S / sum);                       /* mm */
	out->sum_rho_per_mm = sum;
	out->load_N = Q;
	out->a_mm = out->a_star * base;
	out->b_mm = out->b_star * base;
	out->delta_mm = out->delta_star * base * base * sum / 2.0;
	out->p_max_MPa = Q > 0.0 ? 1.5 * Q / (M_PI * out->a_mm * out->b_mm) : 0.0;
	return 0;
}
