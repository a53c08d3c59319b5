/*
 * dist.c: quantile, CDF, exact moments and stack figures of the tolerance distributions of
 * dist.h, on GSL's normal, lognormal and Rayleigh CDFs and their inverses.
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
 */
#include "mc/dist.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_randist.h>

#include "util/error.h"

#define TRUNC_MIN_MASS 1e-12   /* smallest probability a truncation window may hold */
#define TRUNC_NARROW 0.5       /* windows narrower than this (standard units) use quadrature */
#define STACK_TAIL 0.00135     /* 1 - 0.99865: one-sided 3-sigma tail of the stack half-widths */

static const char *const dist_names[PRSM_DIST_KIND_COUNT] = {
	"normal", "truncnormal", "uniform", "triangular", "lognormal", "rayleigh",
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

double prsm_normal_quantile(double p)
{
	if (p == 1.0)
		return INFINITY;
	if (p == 0.0)
		return -INFINITY;
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

/* Names of the parameters p[0..3] of each kind, NULL past the last one. */
static const char *const param_names[PRSM_DIST_KIND_COUNT][4] = {
	{"mean", "sd", NULL, NULL},        {"mean", "sd", "lower", "upper"},
	{"lower", "upper", NULL, NULL},     {"lower", "mode", "upper", NULL},
	{"mu", "sigma", NULL, NULL},        {"sigma", NULL, NULL, NULL},
};

const char *prsm_dist_param_name(prsm_dist_kind k, int q)
{
	if ((int)k < 0 || (int)k >= PRSM_DIST_KIND_COUNT || q < 0 || q >= 4)
		return NULL;
	return param_names[k][q];
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
		return gsl_cdf_rayleigh_Pinv(u, p[0]);
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
}
