/*
 * dist.c: quantile, CDF, exact moments and stack figures of the tolerance distributions of
 * dist.h, on GSL's normal, lognormal, Rayleigh, exponential, gamma, Weibull and beta CDFs and
 * their inverses (gsl_cdf_*_P, _Q, _Pinv, _Qinv); the Gumbel's closed forms and the histogram's
 * exact piecewise-linear inversion are written out here.
 *
 * The truncated normal works in standard units a = (lower - mean)/sd, b = (upper - mean)/sd and
 * takes its probabilities from the tail the window lies in: the upper-tail Q when the window's
 * centre is above the mean, the lower-tail P otherwise. Both tail probabilities of the window
 * then stay >= its mass (>= 1e-12 by prsm_dist_check) and keep full relative precision, so a
 * window deep in a tail, truncnormal(0, 1, 6, 8), still samples [6, 8] with the right mean.
 * Its mean and variance use the closed form (Johnson, Kotz & Balakrishnan, Continuous
 * Univariate Distributions vol. 1, 2nd ed., ch. 13)
 *   m = (phi(a) - phi(b)) / Z,  v = 1 + (a phi(a) - b phi(b)) / Z - m^2,  Z = P(b) - P(a),
 * except for windows narrower than TRUNC_NARROW standard units, where v is the difference of
 * nearly equal terms; there 20-point Gauss-Legendre quadrature over the window (exact to
 * rounding for so smooth an integrand) takes its place.
 *
 * The quantiles of the skewed families work from the lower tail (P) for u <= 1/2 and from the
 * upper tail (Q = 1 - u, exact in doubles there) above, so both tails keep the precision u
 * itself has. Exponential and Weibull take GSL's closed-form inverses (gsl_cdf_*_Pinv, _Qinv),
 * the Gumbel its own. GSL's gamma and beta inverses are no use over the whole range (NaN, or
 * CDF errors of 1e-2, for gamma shape 1000 or 0.1, beta(2, 1000), beta(0.5, 0.1), ...), so their
 * quantiles invert GSL's CDFs (gsl_cdf_gamma_P/Q, gsl_cdf_beta_P) here: ln F(e^s) = ln u by
 * Newton's method in s = ln x, kept inside a bracket that bisection falls back to (ln F is
 * nearly linear in s in the lower tail, where x^shape rules, and in the gamma's upper tail
 * nearly linear in x, so a few steps from the Wilson-Hilferty or small-x first guess reach
 * a few ulps). A beta's upper half is the lower half of Beta(beta, alpha) mirrored.
 *
 * A histogram's quantile finds the bin whose cumulative probabilities bracket u (bisection over
 * at most 64 bins) and interpolates linearly inside it: the exact inverse of its
 * piecewise-linear CDF.
 */
#include "mc/dist.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_sf_gamma.h>

#include "util/error.h"
#include "util/simd.h"

#if PRSM_HAVE_AVX2_CLONES
#include <immintrin.h>
#endif

#define TRUNC_MIN_MASS 1e-12   /* smallest probability a truncation window may hold */
#define TRUNC_NARROW 0.5       /* windows narrower than this (standard units) use quadrature */
#define STACK_TAIL 0.00135     /* 1 - 0.99865: one-sided 3-sigma tail of the stack half-widths */

static const char *const dist_names[PRSM_DIST_KIND_COUNT] = {
	"normal", "truncnormal", "uniform", "triangular", "lognormal", "rayleigh",
	"exponential", "gamma", "weibull", "beta", "gumbel", "histogram",
};

const char *prsm_dist_name(prsm_dist_kind k)
{
	if ((int)k < 0 || (int)k >= PRSM_DIST_KIND_COUNT)
		return "unknown";
	return dist_names[k];
}

int prsm_dist_kind_parse(const char *name, prsm_dist_kind *out)
{
	assert(out != NULL);
	if (name == NULL)
		return PRSM_ENOTFOUND;
	for (int k = 0; k < PRSM_DIST_KIND_COUNT; k++) {
		if (strcmp(name, dist_names[k]) == 0) {
			*out = (prsm_dist_kind)k;
			return 0;
		}
	}
	return PRSM_ENOTFOUND;
}

/* ---- truncated normal ------------------------------------------------------------------- */

typedef struct {
	double a, b;    /* window in standard units, a < b, either may be infinite */
	int upper_tail; /* 1: fa, fb are Q(a), Q(b); 0: P(a), P(b) */
	double fa, fb;  /* tail probabilities of the window's ends */
	double mass;    /* Z = probability of the window, |fa - fb| */
} trunc_window;

static void trunc_window_init(trunc_window *w, const prsm_dist *d)
{
	const double mean = d->p[0], sd = d->p[1];
	w->a = (d->p[2] - mean) / sd;
	w->b = (d->p[3] - mean) / sd;
	w->upper_tail = w->a + w->b > 0.0;
	if (w->upper_tail) {
		w->fa = gsl_cdf_ugaussian_Q(w->a);
		w->fb = gsl_cdf_ugaussian_Q(w->b);
		w->mass = w->fa - w->fb;
	} else {
		w->fa = gsl_cdf_ugaussian_P(w->a);
		w->fb = gsl_cdf_ugaussian_P(w->b);
		w->mass = w->fb - w->fa;
	}
}

/*
 * The standard normal quantile by Wichura's algorithm AS 241 (PPND16: Applied Statistics 37,
 * 477-484, 1988; relative error about 1e-16), the published coefficients, each rational function
 * evaluated by Horner's rule, numerator and denominator, then divided. Evaluated in that order
 * it gives the same doubles as GSL's gsl_cdf_ugaussian_Pinv (test_dist checks equality on a
 * million probabilities across the three regions); written out here so that the Monte Carlo
 * kernel inlines it: the sampling of a 40-variable study spent more instructions in the loops
 * of the library's generic rational evaluator than in its arithmetic.
 */
#define HORNER8(c, x) \
	(((((((c[7] * (x) + c[6]) * (x) + c[5]) * (x) + c[4]) * (x) + c[3]) * (x) + c[2]) * (x) + c[1]) * (x) + c[0])

static const double as241_central_num[8] = {3.387132872796366608, 133.14166789178437745, 1971.5909503065514427,
                                             13731.693765509461125, 45921.953931549871457,
                                             67265.770927008700853, 33430.575583588128105,
                                             2509.0809287301226727};
static const double as241_central_den[8] = {1.0, 42.313330701600911252, 687.1870074920579083,
                                             5394.1960214247511077, 21213.794301586595867,
                                             39307.89580009271061, 28729.085735721942674,
                                             5226.495278852854561};
static const double as241_middle_num[8] = {1.42343711074968357734, 4.6303378461565452959,
                                            5.7694972214606914055, 3.64784832476320460504,
                                            1.27045825245236838258, 0.24178072517745061177,
                                            0.0227238449892691845833, 7.7454501427834140764e-4};
static const double as241_middle_den[8] = {1.0, 2.05319162663775882187, 1.6763848301838038494,
                                            0.68976733498510000455, 0.14810397642748007459,
                                            0.0151986665636164571966, 5.475938084995344946e-4,
                                            1.05075007164441684324e-9};
static const double as241_tail_num[8] = {6.6579046435011037772, 5.4637849111641143699, 1.7848265399172913358,
                                          0.29656057182850489123, 0.026532189526576123093,
                                          0.0012426609473880784386, 2.71155556874348757815e-5,
                                          2.01033439929228813265e-7};
static const double as241_tail_den[8] = {1.0, 0.59983220655588793769, 0.13692988092273580531,
                                          0.0148753612908506148525, 7.868691311456132591e-4,
                                          1.8463183175100546818e-5, 1.4215117583164458887e-7,
                                          2.04426310338993978564e-15};

/* p in (0, 1) */
static inline double normal_quantile_open(double p)
{
	const double q = p - 0.5;
	if (fabs(q) <= 0.425) {
		const double r = 0.180625 - q * q;
		return q * (HORNER8(as241_central_num, r) / HORNER8(as241_central_den, r));
	}
	const double r = sqrt(-log(p < 0.5 ? p : 1.0 - p));
	double x;
	if (r <= 5.0) {
		const double t = r - 1.6;
		x = HORNER8(as241_middle_num, t) / HORNER8(as241_middle_den, t);
	} else {
		const double t = r - 5.0;
		x = HORNER8(as241_tail_num, t) / HORNER8(as241_tail_den, t);
	}
	return p < 0.5 ? -x : x;
}

double prsm_normal_quantile(double p)
{
	if (p == 1.0)
		return INFINITY;
	if (p == 0.0)
		return -INFINITY;
	return normal_quantile_open(p);
}

/* Standard-unit quantile of the window for u in (0, 1). The tail probability is formed from
 * the nearer end so that u and 1 - u are resolved alike. */
static double trunc_std_quantile(const trunc_window *w, double u)
{
	if (w->upper_tail) {
		double q = u <= 0.5 ? w->fa - u * w->mass : w->fb + (1.0 - u) * w->mass;
		return gsl_cdf_ugaussian_Qinv(q);
	}
	double p = u <= 0.5 ? w->fa + u * w->mass : w->fb - (1.0 - u) * w->mass;
	return prsm_normal_quantile(p);
}

/* phi(x) and x phi(x), both 0 at infinite x. */
static double phi0(double x)
{
	return isinf(x) ? 0.0 : gsl_ran_ugaussian_pdf(x);
}

static double x_phi0(double x)
{
	return isinf(x) ? 0.0 : x * gsl_ran_ugaussian_pdf(x);
}

/* P_n(z) and P_n'(z) by the Legendre recurrence. */
static double legendre(int n, double z, double *derivative)
{
	double p0 = 1.0, p1 = 0.0;
	for (int j = 1; j <= n; j++) {
		double p2 = p1;
		p1 = p0;
		p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
	}
	*derivative = n * (z * p0 - p1) / (z * z - 1.0);
	return p0;
}

/* Nodes x[i] (descending, in (-1, 1)) and weights of n-point Gauss-Legendre quadrature: Newton's
 * method on P_n from the Chebyshev-like first guess, weight 2 / ((1 - x^2) P_n'(x)^2). */
#define GL_POINTS 20
static void gauss_legendre(double x[GL_POINTS], double wt[GL_POINTS])
{
	const int n = GL_POINTS;
	for (int i = 0; i < (n + 1) / 2; i++) {
		double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp;
		for (int iter = 0; iter < 50; iter++) {
			double step = legendre(n, z, &dp) / dp;
			z -= step;
			if (fabs(step) < 1e-15) /* nodes are O(1): full precision */
				break;
		}
		(void)legendre(n, z, &dp);
		x[i] = z;
		x[n - 1 - i] = -z;
		wt[i] = wt[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
	}
}

/* Mean and variance of the truncated standard normal on the window (standard units). */
static void trunc_std_moments(const trunc_window *w, double *mean, double *var)
{
	if (!(w->b - w->a < TRUNC_NARROW)) {
		double m = (phi0(w->a) - phi0(w->b)) / w->mass;
		*mean = m;
		*var = 1.0 + (x_phi0(w->a) - x_phi0(w->b)) / w->mass - m * m;
		return;
	}
	/* Narrow window: density proportional to exp(-s t - t^2/2) for t = x - s in [-h, h],
	 * s the window's centre; moments about s, then the variance about the mean. */
	double x[GL_POINTS], wt[GL_POINTS], f[GL_POINTS];
	const double s = 0.5 * (w->a + w->b), h = 0.5 * (w->b - w->a);
	double m0 = 0.0, m1 = 0.0, m2 = 0.0;
	gauss_legendre(x, wt);
	for (int i = 0; i < GL_POINTS; i++) {
		double t = h * x[i];
		f[i] = wt[i] * exp(-s * t - 0.5 * t * t);
		m0 += f[i];
		m1 += f[i] * t;
	}
	m1 /= m0;
	for (int i = 0; i < GL_POINTS; i++) {
		double t = h * x[i] - m1;
		m2 += f[i] * t * t;
	}
	*mean = s + m1;
	*var = m2 / m0;
}

/* ---- gamma and beta quantiles ------------------------------------------------------------ */

/* A tail equation H(s) = 0 in s = ln x, H increasing: the value at s and its slope dH/ds. */
typedef double (*tail_eq)(double s, const double *par, double *slope);

/* par: {shape k, ln u}: ln P(x) - ln u of the unit-scale gamma, slope x f(x) / P(x). */
static double gamma_lower_eq(double s, const double *par, double *slope)
{
	const double x = exp(s), P = gsl_cdf_gamma_P(x, par[0], 1.0);
	*slope = x * gsl_ran_gamma_pdf(x, par[0], 1.0) / P;
	return log(P) - par[1];
}

/* par: {shape k, ln q}: ln q - ln Q(x), slope x f(x) / Q(x). */
static double gamma_upper_eq(double s, const double *par, double *slope)
{
	const double x = exp(s), Q = gsl_cdf_gamma_Q(x, par[0], 1.0);
	*slope = x * gsl_ran_gamma_pdf(x, par[0], 1.0) / Q;
	return par[1] - log(Q);
}

/* par: {a, b, ln u}: ln I_x(a, b) - ln u on (0, 1), slope x f(x) / I_x(a, b). */
static double beta_lower_eq(double s, const double *par, double *slope)
{
	const double x = exp(s);
	if (x >= 1.0) {
		*slope = NAN;
		return -par[2];
	}
	const double P = gsl_cdf_beta_P(x, par[0], par[1]);
	*slope = x * gsl_ran_beta_pdf(x, par[0], par[1]) / P;
	return log(P) - par[2];
}

/* The root of H in (-inf, s_max] from the first guess s: Newton's steps while they stay inside
 * the bracket found so far and shrink, bisection otherwise; the bracket found by steps doubling
 * outward. Stops at a step of a few ulps of s, or after a Newton step below 1e-8 |s|: near the
 * root the error is then of the order of the square of that step. s stays within
 * [S_MIN, s_max]; a root below S_MIN (x below every positive double) is -inf. */
#define S_MIN (-750.0)
static double solve_tail(tail_eq H, const double *par, double s, double s_max)
{
	double lo = -INFINITY, hi = INFINITY, step = 1.0, last = INFINITY;
	if (s > s_max)
		s = s_max;
	for (int it = 0; it < 400; it++) {
		double slope, h = H(s, par, &slope);
		if (h == 0.0)
			return s;
		if (h < 0.0 || isnan(h))
			lo = s;
		else
			hi = s;
		if (s <= S_MIN && h > 0.0) /* the root is below every positive double */
			return -INFINITY;
		const double newton = s - h / slope, scale = fmax(1.0, fabs(s));
		double next;
		if (isfinite(newton) && slope > 0.0 && newton > lo && newton < hi && fabs(newton - s) < 0.5 * last) {
			next = newton;
			if (fabs(newton - s) <= 1e-8 * fabs(s))
				return newton;
		} else if (isfinite(lo) && isfinite(hi)) {
			next = 0.5 * (lo + hi);
		} else if (isfinite(lo)) { /* the root is above s */
			next = fmin(s + step, s_max);
			step *= 2.0;
		} else {
			next = fmax(s - step, S_MIN);
			step *= 2.0;
		}
		if (isfinite(lo) && isfinite(hi) && hi - lo <= 4.0 * DBL_EPSILON * scale)
			return next;
		if (fabs(next - s) <= 2.0 * DBL_EPSILON * scale)
			return next;
		last = isfinite(lo) && isfinite(hi) ? fabs(next - s) : INFINITY;
		s = next;
	}
	return s;
}

/* The u-quantile of the unit-scale gamma of shape k, u in (0, 1). */
static double gamma_std_quantile(double k, double u)
{
	/* first guess: Wilson-Hilferty, or the small-x form P = x^k / Gamma(k + 1) where it fails */
	const double c = 1.0 / (9.0 * k), w = 1.0 - c + prsm_normal_quantile(u) * sqrt(c);
	double x0 = w > 0.0 ? k * w * w * w : 0.0;
	if (!(x0 > 0.0) || (u <= 0.5 && k < 1.0))
		x0 = exp((log(u) + gsl_sf_lngamma(k + 1.0)) / k);
	if (!(x0 > 0.0) || !isfinite(x0))
		x0 = k;
	double s;
	if (u <= 0.5) {
		const double par[2] = {k, log(u)};
		s = solve_tail(gamma_lower_eq, par, log(x0), 709.0);
	} else {
		const double par[2] = {k, log1p(-u)};
		s = solve_tail(gamma_upper_eq, par, log(x0), 709.0);
	}
	return exp(s);
}

/* x with I_x(a, b) = u, u in (0, 1), by the equation of the lower tail. */
static double beta_lower_quantile(double a, double b, double u)
{
	/* first guess: the approximation of Cran, Martin & Thomas (AS 109, Applied Statistics 26,
	 * 111-114, 1977), after Majumder & Bhattacharjee, from the normal deviate y of 1 - u */
	const double lnbeta = gsl_sf_lnbeta(a, b), y = -prsm_normal_quantile(u);
	double x0;
	if (a > 1.0 && b > 1.0) {
		const double r = (y * y - 3.0) / 6.0, sa = 1.0 / (2.0 * a - 1.0), tb = 1.0 / (2.0 * b - 1.0);
		const double h = 2.0 / (sa + tb);
		const double w = y * sqrt(h + r) / h - (tb - sa) * (r + 5.0 / 6.0 - 2.0 / (3.0 * h));
		x0 = a / (a + b * exp(2.0 * w));
	} else {
		const double r = 2.0 * b, t9 = 1.0 / (9.0 * b), c = 1.0 - t9 + y * sqrt(t9), t = r * c * c * c;
		if (t <= 0.0) {
			x0 = -expm1((log1p(-u) + log(b) + lnbeta) / b);
		} else {
			const double t2 = (4.0 * a + r - 2.0) / t;
			x0 = t2 <= 1.0 ? exp((log(u * a) + lnbeta) / a) : 1.0 - 2.0 / (t2 + 1.0);
		}
	}
	if (!(x0 > 0.0 && x0 < 1.0))
		x0 = a / (a + b);
	const double par[3] = {a, b, log(u)};
	return exp(solve_tail(beta_lower_eq, par, log(x0), 0.0));
}

/* The u-quantile of Beta(a, b) on [0, 1] as x and 1 - x, each to its own relative precision:
 * from the lower tail for u <= 1/2, else as 1 - the (1 - u)-quantile of Beta(b, a); solved
 * again from the other side when the answer lies within 1e-4 of the far end (a beta so skewed
 * that its median is that close to an end), where 1 minus it would lose its digits. */
#define BETA_FAR 1e-4
static double beta_std_quantile(double a, double b, double u, double *one_minus)
{
	if (u <= 0.5) {
		const double x = beta_lower_quantile(a, b, u);
		if (1.0 - x >= BETA_FAR) {
			*one_minus = 1.0 - x;
			return x;
		}
		const double y = beta_lower_quantile(b, a, 1.0 - u);
		*one_minus = y;
		return 1.0 - y;
	}
	const double y = beta_lower_quantile(b, a, 1.0 - u);
	if (1.0 - y >= BETA_FAR) {
		*one_minus = y;
		return 1.0 - y;
	}
	const double x = beta_lower_quantile(a, b, u);
	*one_minus = 1.0 - x;
	return x;
}

/* ---- checks ----------------------------------------------------------------------------- */

static int check_fail(char *msg, size_t msg_size, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

static int check_fail(char *msg, size_t msg_size, const char *fmt, ...)
{
	if (msg != NULL && msg_size > 0) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(msg, msg_size, fmt, ap);
		va_end(ap);
	}
	return PRSM_EINVAL;
}

/* Names of the parameters p[0..3] of each kind, NULL past the last one (a histogram's bins are
 * arrays, not parameters). */
static const char *const param_names[PRSM_DIST_KIND_COUNT][4] = {
	{"mean", "sd", NULL, NULL},        {"mean", "sd", "lower", "upper"},
	{"lower", "upper", NULL, NULL},     {"lower", "mode", "upper", NULL},
	{"mu", "sigma", NULL, NULL},        {"sigma", NULL, NULL, NULL},
	{"scale", "location", NULL, NULL},  {"shape", "scale", "location", NULL},
	{"shape", "scale", "location", NULL}, {"alpha", "beta", "lower", "upper"},
	{"location", "scale", NULL, NULL},  {NULL, NULL, NULL, NULL},
};

const char *prsm_dist_param_name(prsm_dist_kind k, int q)
{
	if ((int)k < 0 || (int)k >= PRSM_DIST_KIND_COUNT || q < 0 || q >= 4)
		return NULL;
	return param_names[k][q];
}

int prsm_dist_param_default(prsm_dist_kind k, int q, double *value)
{
	assert(value != NULL);
	const char *name = prsm_dist_param_name(k, q);
	if (name == NULL)
		return 0;
	if (strcmp(name, "location") == 0 || (strcmp(name, "mean") == 0)) {
		*value = 0.0;
		return 1;
	}
	if (k == PRSM_DIST_TRUNCNORMAL && q >= 2) {
		*value = q == 2 ? -INFINITY : INFINITY;
		return 1;
	}
	return 0;
}

/* ---- histogram -------------------------------------------------------------------------- */

/* The bins' counts, edges and weights (not the cdf). Returns 0 or PRSM_EINVAL with msg. */
static int hist_check_bins(const prsm_dist_histogram *h, char *msg, size_t msg_size)
{
	const size_t ne = h->n_edges, nw = h->n_weights;
	if (ne < 2 || ne > PRSM_DIST_HISTOGRAM_MAX_BINS + 1)
		return check_fail(msg, msg_size, "histogram needs 1 to %d bins, so 2 to %d edges (got %zu edges)",
		                  PRSM_DIST_HISTOGRAM_MAX_BINS, PRSM_DIST_HISTOGRAM_MAX_BINS + 1, ne);
	if (nw != ne - 1)
		return check_fail(msg, msg_size, "histogram has %zu edges, so %zu bins: it needs one weight per bin "
		                  "(got %zu weights)", ne, ne - 1, nw);
	for (size_t i = 0; i < ne; i++) {
		if (!isfinite(h->edges[i]))
			return check_fail(msg, msg_size, "histogram edges[%zu] must be finite (got %g)", i, h->edges[i]);
		if (i > 0 && !(h->edges[i] > h->edges[i - 1]))
			return check_fail(msg, msg_size, "histogram edges must increase: edges[%zu] = %g is not above "
			                  "edges[%zu] = %g", i, h->edges[i], i - 1, h->edges[i - 1]);
	}
	double total = 0.0;
	for (size_t i = 0; i < nw; i++) {
		if (!(isfinite(h->weights[i]) && h->weights[i] >= 0.0))
			return check_fail(msg, msg_size, "histogram weights[%zu] must be finite and >= 0 (got %g)", i,
			                  h->weights[i]);
		total += h->weights[i];
	}
	if (!(total > 0.0) || !isfinite(total))
		return check_fail(msg, msg_size, "histogram weights must have a finite, positive sum (got %g)", total);
	return 0;
}

/* cdf[i] = (w[0] + ... + w[i-1]) / total: the same partial sums as the total, so cdf[bins] is
 * exactly 1. The support's ends: the outer edges of the first and last bins of positive weight. */
static void hist_cdf(const prsm_dist_histogram *h, double *cdf, double *lo, double *hi)
{
	const size_t bins = h->n_weights;
	double total = 0.0;
	for (size_t i = 0; i < bins; i++)
		total += h->weights[i];
	double run = 0.0;
	cdf[0] = 0.0;
	for (size_t i = 0; i < bins; i++) {
		run += h->weights[i];
		cdf[i + 1] = run / total;
	}
	size_t first = 0, last = bins - 1;
	while (h->weights[first] == 0.0)
		first++;
	while (h->weights[last] == 0.0)
		last--;
	*lo = h->edges[first];
	*hi = h->edges[last + 1];
}

int prsm_dist_histogram_set(prsm_dist *d, prsm_dist_histogram *h, char *msg, size_t msg_size)
{
	assert(d != NULL && h != NULL);
	if (msg != NULL && msg_size > 0)
		msg[0] = '\0';
	if (hist_check_bins(h, msg, msg_size))
		return PRSM_EINVAL;
	double lo, hi;
	hist_cdf(h, h->cdf, &lo, &hi);
	memset(d, 0, sizeof *d);
	d->kind = PRSM_DIST_HISTOGRAM;
	d->p[0] = lo;
	d->p[1] = hi;
	d->hist = h;
	return 0;
}

/* The bin j (0 .. bins-1) with cdf[j] <= u < cdf[j + 1], for u in [0, 1): it has positive mass. */
static size_t hist_bin_of_u(const prsm_dist_histogram *h, double u)
{
	size_t lo = 0, hi = h->n_weights - 1; /* the answer lies in [lo, hi] */
	while (lo < hi) {
		const size_t mid = lo + (hi - lo) / 2;
		if (h->cdf[mid + 1] > u)
			hi = mid;
		else
			lo = mid + 1;
	}
	return lo;
}

/* The bin j with edges[j] <= x < edges[j + 1], for x inside (edges[0], edges[bins]). */
static size_t hist_bin_of_x(const prsm_dist_histogram *h, double x)
{
	size_t lo = 0, hi = h->n_weights - 1;
	while (lo < hi) {
		const size_t mid = lo + (hi - lo + 1) / 2;
		if (h->edges[mid] <= x)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

static double hist_quantile(const prsm_dist *d, double u)
{
	const prsm_dist_histogram *h = d->hist;
	if (u <= 0.0)
		return d->p[0];
	if (u >= 1.0)
		return d->p[1];
	const size_t j = hist_bin_of_u(h, u);
	const double a = h->edges[j], b = h->edges[j + 1], fa = h->cdf[j], fb = h->cdf[j + 1];
	/* from the nearer end of the bin, so that u near either end is resolved alike */
	const double x = u - fa <= fb - u ? a + (u - fa) / (fb - fa) * (b - a) : b - (fb - u) / (fb - fa) * (b - a);
	return x < a ? a : (x > b ? b : x);
}

static double hist_cdf_at(const prsm_dist *d, double x)
{
	const prsm_dist_histogram *h = d->hist;
	if (x <= d->p[0])
		return 0.0;
	if (x >= d->p[1])
		return 1.0;
	const size_t j = hist_bin_of_x(h, x);
	const double a = h->edges[j], b = h->edges[j + 1];
	const double f = h->cdf[j] + (x - a) / (b - a) * (h->cdf[j + 1] - h->cdf[j]);
	return f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
}

/* Mean and variance: each bin's midpoint and width^2 / 12 about the overall mean. */
static void hist_moments(const prsm_dist *d, double *mean, double *var)
{
	const prsm_dist_histogram *h = d->hist;
	const size_t bins = h->n_weights;
	double total = 0.0, m = 0.0, v = 0.0;
	for (size_t i = 0; i < bins; i++)
		total += h->weights[i];
	for (size_t i = 0; i < bins; i++)
		m += h->weights[i] / total * (0.5 * h->edges[i] + 0.5 * h->edges[i + 1]);
	for (size_t i = 0; i < bins; i++) {
		const double c = 0.5 * h->edges[i] + 0.5 * h->edges[i + 1] - m, w = h->edges[i + 1] - h->edges[i];
		v += h->weights[i] / total * (c * c + w * w / 12.0);
	}
	*mean = m;
	*var = v;
}

int prsm_dist_check(const prsm_dist *d, char *msg, size_t msg_size)
{
	assert(d != NULL);
	if (msg != NULL && msg_size > 0)
		msg[0] = '\0';
	if ((int)d->kind < 0 || (int)d->kind >= PRSM_DIST_KIND_COUNT)
		return check_fail(msg, msg_size, "unknown distribution kind %d", (int)d->kind);
	const char *name = dist_names[d->kind];
	const char *const *pn = param_names[d->kind];
	const double *p = d->p;

	/* every parameter finite, except the truncation bounds, which may be infinite outward */
	for (int i = 0; i < 4 && pn[i] != NULL; i++) {
		int may_be_infinite = d->kind == PRSM_DIST_TRUNCNORMAL && i >= 2;
		if (isnan(p[i]) || (!may_be_infinite && isinf(p[i])))
			return check_fail(msg, msg_size, "%s %s must be finite (got %g)", name, pn[i], p[i]);
	}

	switch (d->kind) {
	case PRSM_DIST_NORMAL:
	case PRSM_DIST_LOGNORMAL:
	case PRSM_DIST_TRUNCNORMAL:
		if (!(p[1] > 0.0))
			return check_fail(msg, msg_size, "%s %s must be > 0 (got %g)", name, pn[1], p[1]);
		break;
	case PRSM_DIST_RAYLEIGH:
		if (!(p[0] > 0.0))
			return check_fail(msg, msg_size, "%s sigma must be > 0 (got %g)", name, p[0]);
		break;
	case PRSM_DIST_UNIFORM:
		if (!(p[0] < p[1]))
			return check_fail(msg, msg_size, "%s lower must be < upper (got %g >= %g)", name,
			                  p[0], p[1]);
		break;
	case PRSM_DIST_TRIANGULAR:
		if (!(p[0] < p[2]))
			return check_fail(msg, msg_size, "%s lower must be < upper (got %g >= %g)", name,
			                  p[0], p[2]);
		if (!(p[0] <= p[1] && p[1] <= p[2]))
			return check_fail(msg, msg_size, "%s mode must lie in [lower, upper] = [%g, %g] (got %g)",
			                  name, p[0], p[2], p[1]);
		break;
	case PRSM_DIST_EXPONENTIAL:
		if (!(p[0] > 0.0))
			return check_fail(msg, msg_size, "%s scale must be > 0 (got %g)", name, p[0]);
		break;
	case PRSM_DIST_GAMMA:
	case PRSM_DIST_WEIBULL:
	case PRSM_DIST_BETA: {
		/* the shapes: gamma's and weibull's p[0], beta's p[0] and p[1] */
		const int shapes = d->kind == PRSM_DIST_BETA ? 2 : 1;
		for (int i = 0; i < shapes; i++)
			if (!(p[i] >= PRSM_DIST_SHAPE_MIN && p[i] <= PRSM_DIST_SHAPE_MAX))
				return check_fail(msg, msg_size, "%s %s must lie in [%g, %g] (got %g)", name, pn[i],
				                  PRSM_DIST_SHAPE_MIN, PRSM_DIST_SHAPE_MAX, p[i]);
		if (d->kind != PRSM_DIST_BETA && !(p[1] > 0.0))
			return check_fail(msg, msg_size, "%s scale must be > 0 (got %g)", name, p[1]);
		if (d->kind == PRSM_DIST_BETA && !(p[2] < p[3]))
			return check_fail(msg, msg_size, "%s lower must be < upper (got %g >= %g)", name, p[2], p[3]);
		break;
	}
	case PRSM_DIST_GUMBEL:
		if (!(p[1] > 0.0))
			return check_fail(msg, msg_size, "%s scale must be > 0 (got %g)", name, p[1]);
		break;
	case PRSM_DIST_HISTOGRAM: {
		const prsm_dist_histogram *h = d->hist;
		if (h == NULL)
			return check_fail(msg, msg_size, "histogram has no bins (see prsm_dist_histogram_set)");
		if (hist_check_bins(h, msg, msg_size))
			return PRSM_EINVAL;
		double cdf[PRSM_DIST_HISTOGRAM_MAX_BINS + 1], lo, hi;
		hist_cdf(h, cdf, &lo, &hi);
		if (memcmp(cdf, h->cdf, h->n_edges * sizeof cdf[0]) != 0 || p[0] != lo || p[1] != hi)
			return check_fail(msg, msg_size, "histogram cumulative weights or support out of date (see "
			                  "prsm_dist_histogram_set)");
		break;
	}
	}

	if (d->kind == PRSM_DIST_TRUNCNORMAL) {
		if (!(p[2] < p[3]))
			return check_fail(msg, msg_size, "%s lower must be < upper (got %g >= %g)", name,
			                  p[2], p[3]);
		if (isinf(p[2]) && isinf(p[3]))
			return check_fail(msg, msg_size,
			                  "%s lower and upper are both infinite: use a normal distribution", name);
		trunc_window w;
		trunc_window_init(&w, d);
		if (!(w.mass >= TRUNC_MIN_MASS))
			return check_fail(msg, msg_size,
			                  "%s window [lower, upper] = [%g, %g] holds %.3g of the probability of "
			                  "normal(%g, %g), less than %g",
			                  name, p[2], p[3], w.mass, p[0], p[1], TRUNC_MIN_MASS);
	}

	/* parameters that are finite one by one may still overflow the figures derived from them
	 * (a uniform over [-1e308, 1e308], a lognormal with mu = 800) */
	double mean = prsm_dist_mean(d), sd = prsm_dist_sd(d);
	double center = prsm_dist_center(d), halfwidth = prsm_dist_halfwidth(d);
	if (!isfinite(mean) || !isfinite(sd) || !isfinite(center) || !isfinite(halfwidth) || !(sd > 0.0))
		return check_fail(msg, msg_size,
		                  "%s parameters out of range: mean %g, sd %g, centre %g, half-width %g", name,
		                  mean, sd, center, halfwidth);
	return 0;
}

/* ---- quantile and CDF ------------------------------------------------------------------- */

static double clamp(double x, double lo, double hi)
{
	return x < lo ? lo : (x > hi ? hi : x);
}

/* ---- the batch quantile (docs/speed.md, "Engine overhead") ---------------------------------
 *
 * A column of the engine's block is cut into chunks of QN_CHUNK values. Each chunk is copied to
 * contiguous storage (the column is strided in the block), then its quantiles are computed as if
 * every value lay in the region that almost all of them lie in (the normal's central region,
 * the uniform's open interval) by a loop without branches, which the compiler vectorises, and
 * last the values are stored, the few outside that region computed again by the scalar path.
 * The vector loop performs, lane by lane, the scalar expressions' operations in their order, so
 * every double is the one prsm_dist_quantile gives (test_dist checks both builds of the loop).
 * The chunk's count is a constant multiple of the vector width so that -O2's very cheap
 * vectoriser takes the loop whole; a short chunk is padded with 1/2. The AVX2 build does a
 * column's whole chunks in one pass without the copies (whole_chunks_avx2, below). */
#define QN_CHUNK 64

/* The normal's value for u in the central region |u - 1/2| <= 0.425 (AS 241's first rational
 * function, as normal_quantile_open evaluates it), for all QN_CHUNK values whatever their region. */
static inline void normal_central_chunk(const double *restrict ut, double *restrict xt, double mean, double sd)
{
	for (size_t k = 0; k < QN_CHUNK; k++) {
		const double q = ut[k] - 0.5;
		const double r = 0.180625 - q * q;
		xt[k] = mean + sd * (q * (HORNER8(as241_central_num, r) / HORNER8(as241_central_den, r)));
	}
}

/* The uniform's value for u in (0, 1), as prsm_dist_quantile's clamp(lo + u (hi - lo), lo, hi). */
static inline void uniform_open_chunk(const double *restrict ut, double *restrict xt, double lo, double hi)
{
	for (size_t k = 0; k < QN_CHUNK; k++) {
		const double x = lo + ut[k] * (hi - lo);
		xt[k] = x < lo ? lo : (x > hi ? hi : x);
	}
}

typedef void (*quantile_chunk_fn)(const double *restrict ut, double *restrict xt, double a, double b);

#if PRSM_HAVE_AVX2_CLONES
/* Bit k set when ut[k] lies outside the chunk kernel's region: for the normal (normal = 1) not
 * |u - 1/2| <= 0.425, for the uniform not 0 < u < 1; NaN lies outside both (ordered compares).
 * The scalar tests of the two regions, vector by vector, their signs gathered by movemask: the
 * store then copies the chunk whole and visits only these values, instead of testing each. */
static uint64_t outside_mask(const double *ut, int normal)
{
	const __m128d half = _mm_set1_pd(0.5), lim = _mm_set1_pd(0.425), zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
	const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)); /* fabs: clear the sign */
	uint64_t mask = 0;
	for (unsigned k = 0; k < QN_CHUNK; k += 2) {
		const __m128d v = _mm_loadu_pd(ut + k);
		const __m128d in = normal ? _mm_cmple_pd(_mm_and_pd(_mm_sub_pd(v, half), abs_mask), lim)
		                          : _mm_and_pd(_mm_cmpgt_pd(v, zero), _mm_cmplt_pd(v, one));
		mask |= (uint64_t)(~_mm_movemask_pd(in) & 3) << k;
	}
	return mask;
}

/* ---- the AVX2 whole chunk, strided (docs/speed.md, "Engine overhead") ----
 *
 * With AVX2, a whole chunk of a column is done in one pass: four values of the column loaded
 * into a vector (two halves, two loads each), kept in ut for the scalar fix-ups, the region's
 * function evaluated, the region's test on the same vector into the returned mask, and the four
 * results stored straight into the strided column. The operations are those of the loops above
 * (normal_central_chunk, uniform_open_chunk and outside_mask), written with intrinsics, so the
 * doubles are the same; the strided copies in and out of the chunk and the mask's second pass
 * are gone. Each group of four is read before it is written, so u and x may be the same array. */
PRSM_TARGET_AVX2 static inline __m256d horner8_avx2(const double c[8], __m256d x)
{
	__m256d s = _mm256_set1_pd(c[7]);
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[6]));
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[5]));
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[4]));
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[3]));
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[2]));
	s = _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[1]));
	return _mm256_add_pd(_mm256_mul_pd(s, x), _mm256_set1_pd(c[0]));
}

PRSM_TARGET_AVX2 static inline __m256d load4_strided(const double *a, size_t s)
{
	const __m128d lo = _mm_loadh_pd(_mm_load_sd(a), a + s);
	const __m128d hi = _mm_loadh_pd(_mm_load_sd(a + 2 * s), a + 3 * s);
	return _mm256_insertf128_pd(_mm256_castpd128_pd256(lo), hi, 1);
}

PRSM_TARGET_AVX2 static inline void store4_strided(double *a, size_t s, __m256d v)
{
	const __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
	_mm_storel_pd(a, lo);
	_mm_storeh_pd(a + s, lo);
	_mm_storel_pd(a + 2 * s, hi);
	_mm_storeh_pd(a + 3 * s, hi);
}

/* The normal's chunk: x = mean + sd (q (num(r) / den(r))), q = u - 1/2, r = 0.180625 - q q;
 * bit k of the result set when |q| <= 0.425 fails (outside the central region, or NaN). */
PRSM_TARGET_AVX2 static uint64_t normal_chunk_strided_avx2(const double *uk, size_t us, double *restrict ut,
                                                           double *xk, size_t xs, double mean, double sd)
{
	const __m256d half = _mm256_set1_pd(0.5), c = _mm256_set1_pd(0.180625), lim = _mm256_set1_pd(0.425);
	const __m256d vmean = _mm256_set1_pd(mean), vsd = _mm256_set1_pd(sd);
	const __m256d abs_mask = _mm256_castsi256_pd(_mm256_set1_epi64x(INT64_MAX));
	uint64_t mask = 0;
	for (unsigned k = 0; k < QN_CHUNK; k += 4) {
		const __m256d v = load4_strided(uk + k * us, us);
		_mm256_storeu_pd(ut + k, v);
		const __m256d q = _mm256_sub_pd(v, half);
		const __m256d r = _mm256_sub_pd(c, _mm256_mul_pd(q, q));
		const __m256d ratio = _mm256_div_pd(horner8_avx2(as241_central_num, r), horner8_avx2(as241_central_den, r));
		store4_strided(xk + k * xs, xs, _mm256_add_pd(vmean, _mm256_mul_pd(vsd, _mm256_mul_pd(q, ratio))));
		const __m256d in = _mm256_cmp_pd(_mm256_and_pd(q, abs_mask), lim, _CMP_LE_OQ);
		mask |= (uint64_t)(~_mm256_movemask_pd(in) & 15) << k;
	}
	return mask;
}

/* The uniform's chunk: x = lo + u (hi - lo), then x < lo ? lo : (x > hi ? hi : x); bit k set
 * when 0 < u < 1 fails. */
PRSM_TARGET_AVX2 static uint64_t uniform_chunk_strided_avx2(const double *uk, size_t us, double *restrict ut,
                                                            double *xk, size_t xs, double lo, double hi)
{
	const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
	const __m256d vlo = _mm256_set1_pd(lo), vhi = _mm256_set1_pd(hi), w = _mm256_set1_pd(hi - lo);
	uint64_t mask = 0;
	for (unsigned k = 0; k < QN_CHUNK; k += 4) {
		const __m256d v = load4_strided(uk + k * us, us);
		_mm256_storeu_pd(ut + k, v);
		const __m256d x = _mm256_add_pd(vlo, _mm256_mul_pd(v, w));
		const __m256d upper = _mm256_blendv_pd(x, vhi, _mm256_cmp_pd(x, vhi, _CMP_GT_OQ));
		store4_strided(xk + k * xs, xs, _mm256_blendv_pd(upper, vlo, _mm256_cmp_pd(x, vlo, _CMP_LT_OQ)));
		const __m256d in = _mm256_and_pd(_mm256_cmp_pd(v, zero, _CMP_GT_OQ), _mm256_cmp_pd(v, one, _CMP_LT_OQ));
		mask |= (uint64_t)(~_mm256_movemask_pd(in) & 15) << k;
	}
	return mask;
}
#endif

#if PRSM_HAVE_AVX2_CLONES
/* The normal's tails of a chunk, four at a time: lg[i] = log(min(v, 1 - v)) of the values v in
 * (0, 1) outside the central region (the library call, scalar, as normal_quantile_open makes it),
 * lower[i] -0 when v < 1/2 (its sign bit turns x into -x), +0 otherwise; each result mean + sd x goes to xk[idx[i] xs]. Per lane the
 * operations of normal_quantile_open and prsm_dist_quantile: r = sqrt(-lg), both rational functions of
 * the middle and the far tail, the one r picks (r <= 5), its sign, then mean + sd x; so the same
 * doubles. lg, lower: m rounded up to a multiple of four, the padding lanes not stored. */
PRSM_TARGET_AVX2 static void normal_tails_avx2(const double *lg, const double *lower, const unsigned char *idx,
                                               unsigned m, double *xk, size_t xs, double mean, double sd)
{
	const __m256d vmean = _mm256_set1_pd(mean), vsd = _mm256_set1_pd(sd), five = _mm256_set1_pd(5.0);
	const __m256d sign = _mm256_set1_pd(-0.0), mid0 = _mm256_set1_pd(1.6);
	for (unsigned i = 0; i < m; i += 4) {
		const __m256d r = _mm256_sqrt_pd(_mm256_xor_pd(_mm256_loadu_pd(lg + i), sign));
		const __m256d t = _mm256_sub_pd(r, mid0), t5 = _mm256_sub_pd(r, five);
		const __m256d xm = _mm256_div_pd(horner8_avx2(as241_middle_num, t), horner8_avx2(as241_middle_den, t));
		const __m256d xt = _mm256_div_pd(horner8_avx2(as241_tail_num, t5), horner8_avx2(as241_tail_den, t5));
		__m256d x = _mm256_blendv_pd(xt, xm, _mm256_cmp_pd(r, five, _CMP_LE_OQ));
		x = _mm256_xor_pd(x, _mm256_and_pd(_mm256_loadu_pd(lower + i), sign));
		double out[4];
		_mm256_storeu_pd(out, _mm256_add_pd(vmean, _mm256_mul_pd(vsd, x)));
		for (unsigned l = 0; l < 4 && i + l < m; l++)
			xk[idx[i + l] * xs] = out[l];
	}
}

/* The normal's or the uniform's column (d) by whole chunks with the AVX2 kernels, the values
 * outside the kernel's region again by prsm_dist_quantile (the normal's tails four at a time, by
 * normal_tails_avx2); returns how many values were done (a multiple of QN_CHUNK). */
static size_t whole_chunks_avx2(const prsm_dist *d, const double *u, size_t u_stride, double *x, size_t x_stride,
                                size_t n)
{
	const double *p = d->p;
	const int normal = d->kind == PRSM_DIST_NORMAL;
	double ut[QN_CHUNK];
	size_t k0 = 0;
	for (; n - k0 >= QN_CHUNK; k0 += QN_CHUNK) {
		const double *uk = u + k0 * u_stride;
		double *xk = x + k0 * x_stride;
		uint64_t outside = normal ? normal_chunk_strided_avx2(uk, u_stride, ut, xk, x_stride, p[0], p[1])
		                          : uniform_chunk_strided_avx2(uk, u_stride, ut, xk, x_stride, p[0], p[1]);
		if (!normal) {
			while (outside) {
				const size_t k = (size_t)__builtin_ctzll(outside);
				outside &= outside - 1;
				xk[k * x_stride] = prsm_dist_quantile(d, ut[k]);
			}
			continue;
		}
		_Static_assert(QN_CHUNK <= 256, "a chunk's indices fit an unsigned char");
		double lg[QN_CHUNK + 3], lower[QN_CHUNK + 3];
		unsigned char idx[QN_CHUNK];
		unsigned m = 0;
		while (outside) {
			const unsigned k = (unsigned)__builtin_ctzll(outside);
			outside &= outside - 1;
			const double v = ut[k];
			if (!(v > 0.0 && v < 1.0)) {
				xk[k * x_stride] = prsm_dist_quantile(d, v); /* NaN, 0 or 1 */
				continue;
			}
			lg[m] = log(v < 0.5 ? v : 1.0 - v);
			lower[m] = v < 0.5 ? -0.0 : 0.0; /* the sign bit: x = -x below one half */
			idx[m++] = (unsigned char)k;
		}
		for (unsigned i = m; i % 4 != 0; i++)
			lg[i] = lower[i] = 0.0;
		normal_tails_avx2(lg, lower, idx, m, xk, x_stride, p[0], p[1]);
	}
	return k0;
}
#endif

/* The Rayleigh quantile for u in (0, 1): GSL's gsl_cdf_rayleigh_Pinv (cdf/rayleighinv.c,
 * sigma * M_SQRT2 * sqrt(-log1p(-P))) written out, the same operations in the same order, so
 * the same doubles (test_dist checks them against GSL's), without the library call. */
static inline double rayleigh_open(double sigma, double u)
{
	return sigma * M_SQRT2 * sqrt(-log1p(-u));
}

/* The batch form of prsm_dist_quantile (dist.h): the kind's case once per column, the same
 * expressions per value, so the same doubles; the normal and the uniform by chunks (above). */
void prsm_dist_quantile_n(const prsm_dist *d, const double *u, size_t u_stride, double *x, size_t x_stride,
                          size_t n)
{
	assert(d != NULL);
	const double *p = d->p;
	if (d->kind == PRSM_DIST_NORMAL || d->kind == PRSM_DIST_UNIFORM) {
		const int normal = d->kind == PRSM_DIST_NORMAL;
		/* with AVX2 the whole chunks take one pass each (whole_chunks_avx2); a column's last
		 * short chunk, and every chunk without AVX2, the baseline loops below */
		const quantile_chunk_fn chunk = normal ? normal_central_chunk : uniform_open_chunk;
		double ut[QN_CHUNK], xt[QN_CHUNK];
		size_t k0 = 0;
#if PRSM_HAVE_AVX2_CLONES
		if (prsm_simd_avx2())
			k0 = whole_chunks_avx2(d, u, u_stride, x, x_stride, n);
#endif
		for (; k0 < n; k0 += QN_CHUNK) {
			const size_t m = n - k0 < QN_CHUNK ? n - k0 : QN_CHUNK;
			const double *uk = u + k0 * u_stride;
			double *xk = x + k0 * x_stride;
			size_t k = 0;
			for (; k + 4 <= m; k += 4) { /* unrolled: the strided copy is mostly loop overhead */
				ut[k] = uk[k * u_stride];
				ut[k + 1] = uk[(k + 1) * u_stride];
				ut[k + 2] = uk[(k + 2) * u_stride];
				ut[k + 3] = uk[(k + 3) * u_stride];
			}
			for (; k < m; k++)
				ut[k] = uk[k * u_stride];
			for (; k < QN_CHUNK; k++)
				ut[k] = 0.5;
			chunk(ut, xt, p[0], p[1]);
#if PRSM_HAVE_AVX2_CLONES
			/* the whole chunk stored, then the values outside the region again by the scalar path */
			uint64_t outside = outside_mask(ut, normal); /* the padding (1/2) is inside */
			for (k = 0; k + 4 <= m; k += 4) {
				xk[k * x_stride] = xt[k];
				xk[(k + 1) * x_stride] = xt[k + 1];
				xk[(k + 2) * x_stride] = xt[k + 2];
				xk[(k + 3) * x_stride] = xt[k + 3];
			}
			for (; k < m; k++)
				xk[k * x_stride] = xt[k];
			while (outside) {
				k = (size_t)__builtin_ctzll(outside);
				outside &= outside - 1;
				xk[k * x_stride] = prsm_dist_quantile(d, ut[k]);
			}
#else
			/* the region's test is true only for u in it: NaN, 0, 1 and beyond take the scalar path */
			for (k = 0; k < m; k++) {
				const double v = ut[k];
				if (normal)
					xk[k * x_stride] = fabs(v - 0.5) <= 0.425 ? xt[k] : prsm_dist_quantile(d, v);
				else
					xk[k * x_stride] = v > 0.0 && v < 1.0 ? xt[k] : prsm_dist_quantile(d, v);
			}
#endif
		}
		return;
	}
	if (d->kind == PRSM_DIST_RAYLEIGH) {
		for (size_t k = 0; k < n; k++) {
			const double v = u[k * u_stride];
			x[k * x_stride] = isnan(v) ? NAN : v <= 0.0 ? 0.0 : v >= 1.0 ? INFINITY : rayleigh_open(p[0], v);
		}
		return;
	}
	for (size_t k = 0; k < n; k++)
		x[k * x_stride] = prsm_dist_quantile(d, u[k * u_stride]);
}

double prsm_dist_quantile(const prsm_dist *d, double u)
{
	assert(d != NULL);
	const double *p = d->p;
	if (isnan(u))
		return NAN;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		if (u <= 0.0)
			return -INFINITY;
		if (u >= 1.0)
			return INFINITY;
		return p[0] + p[1] * prsm_normal_quantile(u);
	case PRSM_DIST_TRUNCNORMAL: {
		if (u <= 0.0)
			return p[2];
		if (u >= 1.0)
			return p[3];
		trunc_window w;
		trunc_window_init(&w, d);
		return clamp(p[0] + p[1] * trunc_std_quantile(&w, u), p[2], p[3]);
	}
	case PRSM_DIST_UNIFORM:
		if (u <= 0.0)
			return p[0];
		if (u >= 1.0)
			return p[1];
		return clamp(p[0] + u * (p[1] - p[0]), p[0], p[1]);
	case PRSM_DIST_TRIANGULAR: {
		const double lo = p[0], mode = p[1], hi = p[2];
		if (u <= 0.0)
			return lo;
		if (u >= 1.0)
			return hi;
		double x;
		if (u <= (mode - lo) / (hi - lo))
			x = lo + sqrt(u * (hi - lo) * (mode - lo));
		else
			x = hi - sqrt((1.0 - u) * (hi - lo) * (hi - mode));
		return clamp(x, lo, hi);
	}
	case PRSM_DIST_LOGNORMAL:
		if (u <= 0.0)
			return 0.0;
		if (u >= 1.0)
			return INFINITY;
		return exp(p[0] + p[1] * prsm_normal_quantile(u));
	case PRSM_DIST_RAYLEIGH:
		if (u <= 0.0)
			return 0.0;
		if (u >= 1.0)
			return INFINITY;
		return rayleigh_open(p[0], u);
	case PRSM_DIST_EXPONENTIAL:
	case PRSM_DIST_GAMMA:
	case PRSM_DIST_WEIBULL: {
		const double location = d->kind == PRSM_DIST_EXPONENTIAL ? p[1] : p[2];
		if (u <= 0.0)
			return location;
		if (u >= 1.0)
			return INFINITY;
		double t;
		if (d->kind == PRSM_DIST_EXPONENTIAL)
			t = u <= 0.5 ? gsl_cdf_exponential_Pinv(u, p[0]) : gsl_cdf_exponential_Qinv(1.0 - u, p[0]);
		else if (d->kind == PRSM_DIST_GAMMA)
			t = p[1] * gamma_std_quantile(p[0], u);
		else /* GSL's Weibull takes the scale first */
			t = u <= 0.5 ? gsl_cdf_weibull_Pinv(u, p[1], p[0]) : gsl_cdf_weibull_Qinv(1.0 - u, p[1], p[0]);
		return location + (t > 0.0 ? t : 0.0);
	}
	case PRSM_DIST_BETA: {
		const double lo = p[2], hi = p[3], w = hi - lo;
		if (u <= 0.0)
			return lo;
		if (u >= 1.0)
			return hi;
		/* the upper half of the support from the upper end: 1 - X is Beta(beta, alpha) */
		double y;
		const double x = beta_std_quantile(p[0], p[1], u, &y);
		return clamp(x <= 0.5 ? lo + w * x : hi - w * y, lo, hi);
	}
	case PRSM_DIST_GUMBEL:
		if (u <= 0.0)
			return -INFINITY;
		if (u >= 1.0)
			return INFINITY;
		/* x = location - scale ln(-ln u); -ln u = -log1p(u - 1) above 1/2, where u - 1 is exact */
		return p[0] - p[1] * log(u <= 0.5 ? -log(u) : -log1p(u - 1.0));
	case PRSM_DIST_HISTOGRAM:
		return hist_quantile(d, u);
	}
	assert(!"unknown distribution kind");
	return NAN;
}

double prsm_dist_cdf(const prsm_dist *d, double x)
{
	assert(d != NULL);
	const double *p = d->p;
	if (isnan(x))
		return NAN;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return gsl_cdf_gaussian_P(x - p[0], p[1]);
	case PRSM_DIST_TRUNCNORMAL: {
		if (x <= p[2])
			return 0.0;
		if (x >= p[3])
			return 1.0;
		trunc_window w;
		trunc_window_init(&w, d);
		double z = (x - p[0]) / p[1];
		double f = w.upper_tail ? (w.fa - gsl_cdf_ugaussian_Q(z)) / w.mass
		                        : (gsl_cdf_ugaussian_P(z) - w.fa) / w.mass;
		return clamp(f, 0.0, 1.0);
	}
	case PRSM_DIST_UNIFORM:
		return clamp((x - p[0]) / (p[1] - p[0]), 0.0, 1.0);
	case PRSM_DIST_TRIANGULAR: {
		const double lo = p[0], mode = p[1], hi = p[2];
		if (x <= lo)
			return 0.0;
		if (x >= hi)
			return 1.0;
		if (x <= mode)
			return clamp((x - lo) * (x - lo) / ((hi - lo) * (mode - lo)), 0.0, 1.0);
		return clamp(1.0 - (hi - x) * (hi - x) / ((hi - lo) * (hi - mode)), 0.0, 1.0);
	}
	case PRSM_DIST_LOGNORMAL:
		return x <= 0.0 ? 0.0 : gsl_cdf_lognormal_P(x, p[0], p[1]);
	case PRSM_DIST_RAYLEIGH:
		return x <= 0.0 ? 0.0 : gsl_cdf_rayleigh_P(x, p[0]);
	case PRSM_DIST_EXPONENTIAL:
		return x <= p[1] ? 0.0 : gsl_cdf_exponential_P(x - p[1], p[0]);
	case PRSM_DIST_GAMMA:
		return x <= p[2] ? 0.0 : (isinf(x) ? 1.0 : gsl_cdf_gamma_P(x - p[2], p[0], p[1]));
	case PRSM_DIST_WEIBULL:
		return x <= p[2] ? 0.0 : gsl_cdf_weibull_P(x - p[2], p[1], p[0]);
	case PRSM_DIST_BETA:
		if (x <= p[2])
			return 0.0;
		if (x >= p[3])
			return 1.0;
		/* the upper half from the upper end, as the quantile takes it */
		if (x - p[2] <= p[3] - x)
			return clamp(gsl_cdf_beta_P((x - p[2]) / (p[3] - p[2]), p[0], p[1]), 0.0, 1.0);
		return clamp(1.0 - gsl_cdf_beta_P((p[3] - x) / (p[3] - p[2]), p[1], p[0]), 0.0, 1.0);
	case PRSM_DIST_GUMBEL:
		return exp(-exp(-(x - p[0]) / p[1]));
	case PRSM_DIST_HISTOGRAM:
		return hist_cdf_at(d, x);
	}
	assert(!"unknown distribution kind");
	return NAN;
}

/* ---- moments and stack figures ---------------------------------------------------------- */

double prsm_dist_mean(const prsm_dist *d)
{
	assert(d != NULL);
	const double *p = d->p;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return p[0];
	case PRSM_DIST_TRUNCNORMAL: {
		trunc_window w;
		double m, v;
		trunc_window_init(&w, d);
		trunc_std_moments(&w, &m, &v);
		return clamp(p[0] + p[1] * m, p[2], p[3]);
	}
	case PRSM_DIST_UNIFORM:
		return 0.5 * (p[0] + p[1]);
	case PRSM_DIST_TRIANGULAR:
		return (p[0] + p[1] + p[2]) / 3.0;
	case PRSM_DIST_LOGNORMAL:
		return exp(p[0] + 0.5 * p[1] * p[1]);
	case PRSM_DIST_RAYLEIGH:
		return p[0] * sqrt(0.5 * M_PI);
	case PRSM_DIST_EXPONENTIAL:
		return p[1] + p[0];
	case PRSM_DIST_GAMMA:
		return p[2] + p[0] * p[1];
	case PRSM_DIST_WEIBULL:
		return p[2] + p[1] * exp(gsl_sf_lngamma(1.0 + 1.0 / p[0]));
	case PRSM_DIST_BETA:
		return p[2] + (p[3] - p[2]) * (p[0] / (p[0] + p[1]));
	case PRSM_DIST_GUMBEL:
		return p[0] + M_EULER * p[1];
	case PRSM_DIST_HISTOGRAM: {
		double m, v;
		hist_moments(d, &m, &v);
		return m;
	}
	}
	assert(!"unknown distribution kind");
	return NAN;
}

double prsm_dist_sd(const prsm_dist *d)
{
	assert(d != NULL);
	const double *p = d->p;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return p[1];
	case PRSM_DIST_TRUNCNORMAL: {
		trunc_window w;
		double m, v;
		trunc_window_init(&w, d);
		trunc_std_moments(&w, &m, &v);
		return p[1] * sqrt(fmax(v, 0.0));
	}
	case PRSM_DIST_UNIFORM:
		return (p[1] - p[0]) / sqrt(12.0);
	case PRSM_DIST_TRIANGULAR: {
		/* (a^2 + b^2 + c^2 - ab - ac - bc) / 18, about the lower end to avoid cancellation */
		const double mode = p[1] - p[0], hi = p[2] - p[0];
		return sqrt((mode * mode + hi * hi - mode * hi) / 18.0);
	}
	case PRSM_DIST_LOGNORMAL: {
		const double s2 = p[1] * p[1];
		return exp(p[0] + 0.5 * s2) * sqrt(expm1(s2));
	}
	case PRSM_DIST_RAYLEIGH:
		return p[0] * sqrt(2.0 - 0.5 * M_PI);
	case PRSM_DIST_EXPONENTIAL:
		return p[0];
	case PRSM_DIST_GAMMA:
		return sqrt(p[0]) * p[1];
	case PRSM_DIST_WEIBULL: {
		/* lambda^2 (G(1 + 2/k) - G(1 + 1/k)^2) = lambda^2 G(1 + 1/k)^2 expm1(lnG(1 + 2/k) - 2 lnG(1 + 1/k)):
		 * no difference of nearly equal terms for large k */
		const double g1 = gsl_sf_lngamma(1.0 + 1.0 / p[0]), g2 = gsl_sf_lngamma(1.0 + 2.0 / p[0]);
		return p[1] * exp(g1) * sqrt(expm1(g2 - 2.0 * g1));
	}
	case PRSM_DIST_BETA: {
		const double a = p[0], b = p[1], s = a + b;
		return (p[3] - p[2]) * sqrt(a * b / (s + 1.0)) / s;
	}
	case PRSM_DIST_GUMBEL:
		return p[1] * M_PI / sqrt(6.0);
	case PRSM_DIST_HISTOGRAM: {
		double m, v;
		hist_moments(d, &m, &v);
		return sqrt(v);
	}
	}
	assert(!"unknown distribution kind");
	return NAN;
}

double prsm_dist_center(const prsm_dist *d)
{
	assert(d != NULL);
	const double *p = d->p;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return p[0];
	case PRSM_DIST_TRUNCNORMAL:
		/* the parent's mean, or the nearer end of the window when the mean lies outside it */
		return fmin(fmax(p[0], p[2]), p[3]);
	case PRSM_DIST_UNIFORM:
		return 0.5 * (p[0] + p[1]);
	case PRSM_DIST_TRIANGULAR:
		return p[1];
	case PRSM_DIST_LOGNORMAL:
		return exp(p[0]);
	case PRSM_DIST_RAYLEIGH:
		return 0.0;
	case PRSM_DIST_EXPONENTIAL:
	case PRSM_DIST_GAMMA:
	case PRSM_DIST_WEIBULL:
	case PRSM_DIST_BETA:
	case PRSM_DIST_GUMBEL:
	case PRSM_DIST_HISTOGRAM:
		return prsm_dist_quantile(d, 0.5);
	}
	assert(!"unknown distribution kind");
	return NAN;
}

double prsm_dist_halfwidth(const prsm_dist *d)
{
	assert(d != NULL);
	const double *p = d->p;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return 3.0 * p[1];
	case PRSM_DIST_TRUNCNORMAL:
	{
		const double c = prsm_dist_center(d);
		return fmin(3.0 * p[1], fmax(c - p[2], p[3] - c));
	}
	case PRSM_DIST_UNIFORM:
		return 0.5 * (p[1] - p[0]);
	case PRSM_DIST_TRIANGULAR:
		return fmax(p[1] - p[0], p[2] - p[1]);
	case PRSM_DIST_LOGNORMAL:
		/* q(0.99865) - median = exp(mu) (exp(sigma z) - 1) */
		return exp(p[0]) * expm1(p[1] * gsl_cdf_ugaussian_Qinv(STACK_TAIL));
	case PRSM_DIST_RAYLEIGH:
		return p[0] * sqrt(-2.0 * log(STACK_TAIL));
	case PRSM_DIST_EXPONENTIAL:
	case PRSM_DIST_GAMMA:
	case PRSM_DIST_WEIBULL:
	case PRSM_DIST_GUMBEL: {
		/* the farther of the 0.135 and 99.865 % quantiles from the median */
		const double m = prsm_dist_quantile(d, 0.5);
		return fmax(prsm_dist_quantile(d, 1.0 - STACK_TAIL) - m, m - prsm_dist_quantile(d, STACK_TAIL));
	}
	case PRSM_DIST_BETA: {
		const double m = prsm_dist_quantile(d, 0.5);
		return fmax(m - p[2], p[3] - m);
	}
	case PRSM_DIST_HISTOGRAM: {
		const double m = prsm_dist_quantile(d, 0.5);
		return fmax(m - p[0], p[1] - m);
	}
	}
	assert(!"unknown distribution kind");
	return NAN;
}

void prsm_dist_from_tolerance(prsm_dist *out, double nominal, double tol, double cpk)
{
	assert(out != NULL);
	out->kind = PRSM_DIST_NORMAL;
	out->p[0] = nominal;
	out->p[1] = tol / (3.0 * cpk);
	out->p[2] = out->p[3] = 0.0;
	out->hist = NULL;
}
