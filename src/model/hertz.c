/*
 * hertz.c: Hertz point contact, Harris's formulation (MODEL.md §6).
 */
#include "model/hertz.h"

#include <gsl/gsl_errno.h>
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

int prsm_hertz_coefficients(prsm_hertz *out, double F)
{
	if (!(F >= 0.0 && F < 1.0))
		return PRSM_EINVAL;
	double kappa = 1.0, K = M_PI / 2.0, E = M_PI / 2.0;
	if (F > 1e-10) {
		/* F is increasing in kappa: bisect on log kappa, then polish (monotone, robust) */
		double lo = 0.0, hi = log(1e6);
		for (int i = 0; i < 200 && hi - lo > 1e-15 * fmax(1.0, hi); i++) {
			double mid = 0.5 * (lo + hi);
			double k = exp(mid);
			if (k <= 1.0 + 1e-12 || curvature_difference_of(k, &K, &E) < F)
				lo = mid;
			else
				hi = mid;
		}
		kappa = exp(0.5 * (lo + hi));
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
