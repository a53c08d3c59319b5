/*
 * dist.h: one-dimensional distributions of the tolerances of a study (DESIGN.md "Documents":
 * normal, truncnormal, uniform, triangular, lognormal, rayleigh, exponential, gamma, weibull,
 * beta, gumbel, histogram, and the {tol, cpk} shorthand).
 *
 * Every distribution is sampled by its inverse CDF from a uniform u in (0, 1), so the random,
 * LHS and Sobol samplers all drive it the same way. A prsm_dist is plain data (a kind and up to
 * four parameters in the unit of the toleranced quantity; a histogram points to its bins, which
 * must outlive it); prsm_dist_check validates it once and the other functions assume a checked
 * distribution (programming errors are asserted).
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
 *   exponential  {scale, location}: location + Exp(mean scale), on [location, inf)
 *   gamma        {shape, scale, location}: location + Gamma(shape k, scale theta), density
 *                proportional to t^(k-1) exp(-t / theta), t = x - location >= 0
 *   weibull      {shape, scale, location}: location + Weibull(shape k, scale lambda),
 *                F = 1 - exp(-(t / lambda)^k), t = x - location >= 0
 *   beta         {alpha, beta, lower, upper}: lower + (upper - lower) Beta(alpha, beta)
 *   gumbel       {location, scale}: the largest-value (type I extreme value) distribution,
 *                F = exp(-exp(-(x - location) / scale)), mode location, right-skewed
 *   histogram    no parameters: piecewise uniform over the bins of d->hist (bin i on
 *                [edges[i], edges[i + 1]) with probability weights[i] / sum of weights);
 *                p[0], p[1] are the ends of its support (the outer edges of the first and last
 *                bins of positive weight), set by prsm_dist_histogram_set
 * Unused entries of p are ignored. Shapes are limited to what the quantiles resolve (see
 * prsm_dist_check); location defaults to 0 in the documents (prsm_dist_param_default).
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
	PRSM_DIST_RAYLEIGH,
	PRSM_DIST_EXPONENTIAL,
	PRSM_DIST_GAMMA,
	PRSM_DIST_WEIBULL,
	PRSM_DIST_BETA,
	PRSM_DIST_GUMBEL,
	PRSM_DIST_HISTOGRAM
} prsm_dist_kind;

#define PRSM_DIST_KIND_COUNT 12

/* Limits of the shapes (gamma and weibull shape, beta alpha and beta): within them the
 * quantiles invert GSL's CDFs to 1e-10 wherever the quantile is resolved in doubles (beyond
 * 1000, GSL's gamma CDF is itself noisy at 1e-10; a gamma or beta that peaked is a normal). */
#define PRSM_DIST_SHAPE_MIN 0.05
#define PRSM_DIST_SHAPE_MAX 1000.0

/* The bins of a histogram: edges[0] < edges[1] < ... < edges[bins], weights[i] >= 0 for the bin
 * [edges[i], edges[i + 1]), their sum > 0; cdf is filled by prsm_dist_histogram_set. */
#define PRSM_DIST_HISTOGRAM_MAX_BINS 64
typedef struct {
	size_t n_edges;                                   /* bins + 1 */
	double edges[PRSM_DIST_HISTOGRAM_MAX_BINS + 1];
	size_t n_weights;                                 /* bins */
	double weights[PRSM_DIST_HISTOGRAM_MAX_BINS];
	double cdf[PRSM_DIST_HISTOGRAM_MAX_BINS + 1];     /* cdf[i] = P(X < edges[i]); 0 .. 1 */
} prsm_dist_histogram;

typedef struct {
	prsm_dist_kind kind;
	double p[4]; /* parameters, see above; in the unit of the quantity (lognormal: of its log) */
	const prsm_dist_histogram *hist; /* histogram: its bins (outlive the distribution); else NULL */
} prsm_dist;

/* The document name of a kind ("normal", "truncnormal", "uniform", "triangular", "lognormal",
 * "rayleigh", "exponential", "gamma", "weibull", "beta", "gumbel", "histogram"); "unknown" for a
 * value outside the enum. Never NULL. */
const char *prsm_dist_name(prsm_dist_kind k);

/* The document name of parameter p[q] of kind k ("mean", "sd", "lower", "upper", "mode", "mu",
 * "sigma", "scale", "location", "shape", "alpha", "beta"), or NULL past the kind's last
 * parameter (or for an invalid k or q; a histogram has none: its bins are arrays). */
const char *prsm_dist_param_name(prsm_dist_kind k, int q);

/* 1 when parameter q of kind k may be left out of a document, with the value it then takes in
 * *value (normal and truncnormal mean 0; truncnormal lower -inf and upper +inf, one at least;
 * the location of exponential, gamma, weibull and gumbel 0); else 0 (*value untouched). */
int prsm_dist_param_default(prsm_dist_kind k, int q, double *value);

/* Make d the histogram of h, whose edges, weights and counts are filled: checks them (1 to
 * PRSM_DIST_HISTOGRAM_MAX_BINS bins, one weight per bin, finite increasing edges, finite
 * non-negative weights of positive sum), fills h->cdf and d (kind, hist = h, p[0], p[1] the ends
 * of the support). Returns 0, or PRSM_EINVAL with the message prsm_dist_check would give (d
 * untouched). h must outlive d and every copy of it. */
int prsm_dist_histogram_set(prsm_dist *d, prsm_dist_histogram *h, char *msg, size_t msg_size);

/* The kind named name (exact, case-sensitive). Returns 0, or PRSM_ENOTFOUND (out untouched). */
int prsm_dist_kind_parse(const char *name, prsm_dist_kind *out);

/* Validate d. Returns 0, or PRSM_EINVAL with a one-line message naming the offending parameter
 * written to msg (if msg is not NULL and msg_size > 0; truncated to msg_size): an unknown kind,
 * non-finite values, sd, sigma or scale <= 0, a shape outside [PRSM_DIST_SHAPE_MIN,
 * PRSM_DIST_SHAPE_MAX], lower >= upper, mode outside [lower, upper], a truncation window
 * holding < 1e-12 of the probability, a histogram's bins (as prsm_dist_histogram_set checks
 * them, and its cdf and support as that function sets them), a distribution whose mean, sd or
 * stack figures overflow. */
int prsm_dist_check(const prsm_dist *d, char *msg, size_t msg_size);

/* The standard normal quantile for p in [0, 1] (-inf at 0, +inf at 1): Wichura's AS 241, the same
 * doubles as GSL's gsl_cdf_ugaussian_Pinv, inlined for the sampling kernel. */
double prsm_normal_quantile(double p);

/* The u-quantile (inverse CDF) for u in (0, 1); always within the support (truncnormal: within
 * [lower, upper]). u <= 0 and u >= 1 give the ends of the support (possibly infinite). */
double prsm_dist_quantile(const prsm_dist *d, double u);

/* x[k x_stride] = prsm_dist_quantile(d, u[k u_stride]) for k < n, the same doubles: the
 * engine's block of samples, one variable's column at a time (u and x may be the same array). */
void prsm_dist_quantile_n(const prsm_dist *d, const double *u, size_t u_stride, double *x, size_t x_stride,
                          size_t n);

/* P(X <= x), in [0, 1]. */
double prsm_dist_cdf(const prsm_dist *d, double x);

/* Exact mean and standard deviation of the distribution (truncnormal: of the truncated
 * distribution, by the closed form, or by Gauss-Legendre quadrature for windows narrower than
 * 0.5 sd where the closed form cancels; weibull: from ln Gamma, the variance through expm1;
 * histogram: each bin's mean and variance, about the overall mean). */
double prsm_dist_mean(const prsm_dist *d);
double prsm_dist_sd(const prsm_dist *d);

/* Centre and tolerance half-width used by the worst-case and RSS stack figures:
 *   normal       mean, 3 sd
 *   truncnormal  c = the parent's mean clamped into [lower, upper] (the nearer end when the mean
 *                lies outside the window), min(3 sd, max(c - lower, upper - c)), sd the parent's
 *   uniform      midpoint, half range
 *   triangular   mode, max(mode - lower, upper - mode)
 *   lognormal    median exp(mu), q(0.99865) - median
 *   rayleigh     0, q(0.99865) = sigma sqrt(-2 ln 0.00135)
 *   exponential, gamma, weibull, gumbel
 *                median m, max(q(0.99865) - m, m - q(0.00135))
 *   beta, histogram
 *                median m, max(m - lower, upper - m) (the ends of the support) */
double prsm_dist_center(const prsm_dist *d);
double prsm_dist_halfwidth(const prsm_dist *d);

/* The engineering shorthand {"tol": t, "cpk": c} around the nominal x0: normal with mean x0 and
 * sd = t / (3 c). Does not validate: a non-positive tol or cpk gives a distribution that
 * prsm_dist_check refuses. */
void prsm_dist_from_tolerance(prsm_dist *out, double nominal, double tol, double cpk);

#endif
