/*
 * dist.h: one-dimensional distributions of the tolerances of a study (DESIGN.md "Documents":
 * normal, truncnormal, uniform, triangular, lognormal, rayleigh, and the {tol, cpk} shorthand).
 *
 * Every distribution is sampled by its inverse CDF from a uniform u in (0, 1), so the random,
 * LHS and Sobol samplers all drive it the same way. A prsm_dist is plain data (a kind and up to
 * four parameters in the unit of the toleranced quantity); prsm_dist_check validates it once and
 * the other functions assume a checked distribution (programming errors are asserted).
 *
 * Parameters p[]:
 *   normal       {mean, sd}
 *   truncnormal  {mean, sd, lower, upper}: normal(mean, sd) restricted to [lower, upper]; lower may
 *                be -INFINITY or upper +INFINITY, not both; the window must hold >= 1e-12 of
 *                the probability of the parent normal
 *   uniform      {lower, upper}
 *   triangular   {lower, mode, upper}
 *   lognormal    {mu, sigma} of the underlying normal: value = exp(N(mu, sigma))
 *   rayleigh     {sigma}: magnitude of a radial error whose x and y components are N(0, sigma)
 *                (the uniform phase is drawn elsewhere)
 * Unused entries of p are ignored.
 */
#ifndef PRSM_MC_DIST_H
#define PRSM_MC_DIST_H

#include <stddef.h>

typedef enum {
	PRSM_DIST_NORMAL,
	PRSM_DIST_TRUNCNORMAL,
	PRSM_DIST_UNIFORM,
	PRSM_DIST_TRIANGULAR,
	PRSM_DIST_LOGNORMAL,
	PRSM_DIST_RAYLEIGH
} prsm_dist_kind;

#define PRSM_DIST_KIND_COUNT 6

typedef struct {
	prsm_dist_kind kind;
	double p[4]; /* parameters, see above; in the unit of the quantity (lognormal: of its log) */
} prsm_dist;

/* The document name of a kind ("normal", "truncnormal", "uniform", "triangular", "lognormal",
 * "rayleigh"); "unknown" for a value outside the enum. Never NULL. */
const char *prsm_dist_name(prsm_dist_kind k);

/* The document name of parameter p[q] of kind k ("mean", "sd", "lower", "upper", "mode", "mu",
 * "sigma"), or NULL past the kind's last parameter (or for an invalid k or q). */
const char *prsm_dist_param_name(prsm_dist_kind k, int q);

/* The kind named name (exact, case-sensitive). Returns 0, or PRSM_ENOTFOUND (out untouched). */
int prsm_dist_kind_parse(const char *name, prsm_dist_kind *out);

/* Validate d. Returns 0, or PRSM_EINVAL with a one-line message naming the offending parameter
 * written to msg (if msg is not NULL and msg_size > 0; truncated to msg_size): an unknown kind,
 * non-finite values, sd or sigma <= 0, lower >= upper, mode outside [lower, upper], a truncation
 * window holding < 1e-12 of the probability, a lognormal whose mean or sd overflows. */
int prsm_dist_check(const prsm_dist *d, char *msg, size_t msg_size);

/* The standard normal quantile for p in [0, 1] (-inf at 0, +inf at 1): Wichura's AS 241, the same
 * doubles as GSL's gsl_cdf_ugaussian_Pinv, inlined for the sampling kernel. */
double prsm_normal_quantile(double p);

/* The u-quantile (inverse CDF) for u in (0, 1); always within the support (truncnormal: within
 * [lower, upper]). u <= 0 and u >= 1 give the ends of the support (possibly infinite). */
double prsm_dist_quantile(const prsm_dist *d, double u);

/* P(X <= x), in [0, 1]. */
double prsm_dist_cdf(const prsm_dist *d, double x);

/* Exact mean and standard deviation of the distribution (truncnormal: of the truncated
 * distribution, by the closed form, or by Gauss-Legendre quadrature for windows narrower than
 * 0.5 sd where the closed form cancels). */
double prsm_dist_mean(const prsm_dist *d);
double prsm_dist_sd(const prsm_dist *d);

/* Centre and tolerance half-width used by the worst-case and RSS stack figures:
 *   normal       mean, 3 sd
 *   truncnormal  c = the parent's mean clamped into [lower, upper] (the nearer end when the mean
 *                lies outside the window), min(3 sd, max(c - lower, upper - c)), sd the parent's
 *   uniform      midpoint, half range
 *   triangular   mode, max(mode - lower, upper - mode)
 *   lognormal    median exp(mu), q(0.99865) - median
 *   rayleigh     0, q(0.99865) = sigma sqrt(-2 ln 0.00135) */
double prsm_dist_center(const prsm_dist *d);
double prsm_dist_halfwidth(const prsm_dist *d);

/* The engineering shorthand {"tol": t, "cpk": c} around the nominal x0: normal with mean x0 and
 * sd = t / (3 c). Does not validate: a non-positive tol or cpk gives a distribution that
 * prsm_dist_check refuses. */
void prsm_dist_from_tolerance(prsm_dist *out, double nominal, double tol, double cpk);

#endif
