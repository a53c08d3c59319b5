/*
 * test_dist.c: the tolerance distributions of mc/dist.h — for every kind, with high-entropy
 * parameters: moments of samples drawn through the quantile against the exact mean and sd,
 * those exact moments against numerical integration of the density (GSL QUADPACK), the CDF
 * inverting the quantile, every error path of prsm_dist_check, names, stack figures and the
 * {tol, cpk} shorthand. The skewed families (exponential, gamma, Weibull, beta, Gumbel) also
 * against closed forms and GSL's own inverses where those work, and over their whole range of
 * shapes; the histogram against its piecewise-linear CDF, bin by bin.
 */
#include "test_support.h"

#include "mc/dist.h"
#include "util/error.h"
#include "util/rng.h"
#include "util/simd.h"

#include <float.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_sf_gamma.h>

#define D1(k, a) {k, {a, 0, 0, 0}, NULL}
#define D2(k, a, b) {k, {a, b, 0, 0}, NULL}
#define D3(k, a, b, c) {k, {a, b, c, 0}, NULL}
#define D4(k, a, b, c, e) {k, {a, b, c, e}, NULL}

/* Histograms: bins with a zero weight inside and at both ends (the support is [-0.5, 2.75]), a
 * single bin (a uniform), and uneven widths; their cdf is filled by the group's setup. */
static prsm_dist_histogram hist_gappy = {6, {-1.0, -0.5, 0.25, 0.5, 1.5, 2.75}, 5, {0.0, 3.0, 0.0, 1.5, 2.25}, {0}};
static prsm_dist_histogram hist_one = {2, {0.3, 1.7}, 1, {4.0}, {0}};
static prsm_dist_histogram hist_uneven = {5, {-2.0, -1.9, 0.0, 0.05, 3.0}, 4, {0.7, 2.0, 0.3, 1.0}, {0}};

/* The valid distributions every generic test runs over. */
static const prsm_dist cases[] = {
	D2(PRSM_DIST_NORMAL, 2.385, 0.713),
	D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -0.9, 2.2),
	D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 6.0, 8.0),           /* deep upper tail */
	D4(PRSM_DIST_TRUNCNORMAL, 2.5, 0.25, -INFINITY, 1.0),    /* deep lower tail, one-sided */
	D4(PRSM_DIST_TRUNCNORMAL, 1.23, 0.57, 0.95, INFINITY),   /* one-sided below */
	D4(PRSM_DIST_TRUNCNORMAL, -0.37, 2.11, -INFINITY, -1.9), /* one-sided above */
	D4(PRSM_DIST_TRUNCNORMAL, 3.3, 2.7, 1.05, 1.65),         /* narrow window: quadrature */
	D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 6.5, 6.9),           /* narrow and deep: quadrature */
	D2(PRSM_DIST_UNIFORM, -1.7, 3.1),
	D3(PRSM_DIST_TRIANGULAR, -0.6, 0.35, 2.9),
	D3(PRSM_DIST_TRIANGULAR, 0.2, 0.2, 1.7), /* mode at the lower end */
	D3(PRSM_DIST_TRIANGULAR, -3.1, 0.8, 0.8), /* mode at the upper end */
	D2(PRSM_DIST_LOGNORMAL, 0.3, 0.45),
	D1(PRSM_DIST_RAYLEIGH, 1.9),
	D2(PRSM_DIST_EXPONENTIAL, 0.85, 0.0),
	D2(PRSM_DIST_EXPONENTIAL, 2.3, -1.25),           /* shifted */
	D3(PRSM_DIST_GAMMA, 2.7, 0.45, 0.0),
	D3(PRSM_DIST_GAMMA, 0.6, 1.8, 0.3),             /* shape < 1: infinite density at location */
	D3(PRSM_DIST_GAMMA, 85.0, 0.02, -1.0),          /* nearly normal */
	D3(PRSM_DIST_WEIBULL, 2.2, 1.4, 0.0),
	D3(PRSM_DIST_WEIBULL, 0.8, 0.9, -0.4),          /* shape < 1 */
	D3(PRSM_DIST_WEIBULL, 11.0, 3.0, 1.0),          /* left-skewed */
	D4(PRSM_DIST_BETA, 2.0, 5.0, 0.0, 1.0),
	D4(PRSM_DIST_BETA, 0.8, 0.9, -1.0, 2.0),        /* U-shaped */
	D4(PRSM_DIST_BETA, 6.5, 1.7, -3.0, 0.5),        /* left-skewed */
	D4(PRSM_DIST_BETA, 40.0, 60.0, 10.0, 10.5),     /* peaked */
	D2(PRSM_DIST_GUMBEL, 0.0, 1.0),
	D2(PRSM_DIST_GUMBEL, -2.4, 0.35),
	{PRSM_DIST_HISTOGRAM, {-0.5, 2.75, 0, 0}, &hist_gappy},
	{PRSM_DIST_HISTOGRAM, {0.3, 1.7, 0, 0}, &hist_one},
	{PRSM_DIST_HISTOGRAM, {-2.0, 3.0, 0, 0}, &hist_uneven},
};
#define N_CASES (sizeof cases / sizeof cases[0])

/* The histograms' cumulative weights, as prsm_dist_histogram_set fills them (its support must
 * be the one the cases state). */
static int setup_histograms(void **state)
{
	(void)state;
	prsm_dist_histogram *h[] = {&hist_gappy, &hist_one, &hist_uneven};
	for (size_t i = 0; i < sizeof h / sizeof h[0]; i++) {
		prsm_dist d;
		char msg[128];
		if (prsm_dist_histogram_set(&d, h[i], msg, sizeof msg) != 0)
			return -1;
		for (size_t c = 0; c < N_CASES; c++)
			if (cases[c].hist == h[i] && (cases[c].p[0] != d.p[0] || cases[c].p[1] != d.p[1]))
				return -1;
	}
	return 0;
}

static double support_lower(const prsm_dist *d)
{
	switch (d->kind) {
	case PRSM_DIST_TRUNCNORMAL:
		return d->p[2];
	case PRSM_DIST_UNIFORM:
	case PRSM_DIST_TRIANGULAR:
	case PRSM_DIST_HISTOGRAM:
		return d->p[0];
	case PRSM_DIST_LOGNORMAL:
	case PRSM_DIST_RAYLEIGH:
		return 0.0;
	case PRSM_DIST_EXPONENTIAL:
		return d->p[1];
	case PRSM_DIST_GAMMA:
	case PRSM_DIST_WEIBULL:
	case PRSM_DIST_BETA:
		return d->p[2];
	default:
		return -INFINITY;
	}
}

static double support_upper(const prsm_dist *d)
{
	switch (d->kind) {
	case PRSM_DIST_TRUNCNORMAL:
		return d->p[3];
	case PRSM_DIST_UNIFORM:
	case PRSM_DIST_HISTOGRAM:
		return d->p[1];
	case PRSM_DIST_TRIANGULAR:
		return d->p[2];
	case PRSM_DIST_BETA:
		return d->p[3];
	default:
		return INFINITY;
	}
}

static void test_all_cases_valid(void **state)
{
	(void)state;
	for (size_t i = 0; i < N_CASES; i++) {
		char msg[128] = "untouched";
		int rc = prsm_dist_check(&cases[i], msg, sizeof msg);
		if (rc != 0)
			print_error("case %zu: %s\n", i, msg);
		assert_int_equal(rc, 0);
		assert_string_equal(msg, "");
	}
}

/* ---- moments of samples ----------------------------------------------------------------- */

enum { SAMPLES = 40000 };
static double sample[SAMPLES];

static void test_sample_moments(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(0x5eed2385ULL, 0);
	assert_non_null(r);
	for (size_t i = 0; i < N_CASES; i++) {
		const prsm_dist *d = &cases[i];
		const double lo = support_lower(d), hi = support_upper(d);
		prsm_rng_set_stream(r, 0x5eed2385ULL, i);
		double m = 0.0;
		for (size_t j = 0; j < SAMPLES; j++) {
			double x = prsm_dist_quantile(d, prsm_rng_uniform_pos(r));
			assert_true(x >= lo && x <= hi);
			sample[j] = x;
			m += x;
		}
		m /= SAMPLES;
		double m2 = 0.0, m4 = 0.0;
		for (size_t j = 0; j < SAMPLES; j++) {
			double e = sample[j] - m, e2 = e * e;
			m2 += e2;
			m4 += e2 * e2;
		}
		double var = m2 / (SAMPLES - 1);
		m4 /= SAMPLES;
		const double mean = prsm_dist_mean(d), sd = prsm_dist_sd(d);
		if (!(fabs(m - mean) <= 4.5 * sd / sqrt(SAMPLES)) ||
		    !(fabs(var - sd * sd) <= 4.5 * sqrt((m4 - pow(sd, 4)) / SAMPLES)))
			print_error("case %zu (%s)\n", i, prsm_dist_name(d->kind));
		assert_close(m, mean, 4.5 * sd / sqrt(SAMPLES));
		assert_close(var, sd * sd, 4.5 * sqrt((m4 - pow(sd, 4)) / SAMPLES));
	}
	gsl_rng_free(r);
}

/* ---- exact moments against numerical integration ---------------------------------------- */

typedef struct {
	const prsm_dist *d;
	int power;     /* integrate (x - centre)^power * density */
	double centre;
} moment_params;

/* The density, written independently of dist.c (truncnormal unnormalised: the integral of
 * power 0 normalises it). */
static double density(const prsm_dist *d, double x)
{
	const double *p = d->p;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		return gsl_ran_gaussian_pdf(x - p[0], p[1]);
	case PRSM_DIST_TRUNCNORMAL:
		return (x < p[2] || x > p[3]) ? 0.0 : gsl_ran_gaussian_pdf(x - p[0], p[1]);
	case PRSM_DIST_UNIFORM:
		return gsl_ran_flat_pdf(x, p[0], p[1]);
	case PRSM_DIST_TRIANGULAR:
		if (x < p[0] || x > p[2])
			return 0.0;
		if (x < p[1])
			return 2.0 * (x - p[0]) / ((p[2] - p[0]) * (p[1] - p[0]));
		if (x > p[1])
			return 2.0 * (p[2] - x) / ((p[2] - p[0]) * (p[2] - p[1]));
		return 2.0 / (p[2] - p[0]);
	case PRSM_DIST_LOGNORMAL:
		return gsl_ran_lognormal_pdf(x, p[0], p[1]);
	case PRSM_DIST_RAYLEIGH:
		return gsl_ran_rayleigh_pdf(x, p[0]);
	case PRSM_DIST_EXPONENTIAL:
		return x < p[1] ? 0.0 : gsl_ran_exponential_pdf(x - p[1], p[0]);
	case PRSM_DIST_GAMMA:
		return x <= p[2] ? 0.0 : gsl_ran_gamma_pdf(x - p[2], p[0], p[1]);
	case PRSM_DIST_WEIBULL: /* GSL's Weibull: scale first */
		return x <= p[2] ? 0.0 : gsl_ran_weibull_pdf(x - p[2], p[1], p[0]);
	case PRSM_DIST_BETA:
		return x <= p[2] || x >= p[3] ? 0.0 : gsl_ran_beta_pdf((x - p[2]) / (p[3] - p[2]), p[0], p[1]) / (p[3] - p[2]);
	case PRSM_DIST_GUMBEL: {
		const double z = (x - p[0]) / p[1];
		return exp(-z - exp(-z)) / p[1];
	}
	case PRSM_DIST_HISTOGRAM: {
		const prsm_dist_histogram *h = d->hist;
		double total = 0.0;
		for (size_t i = 0; i < h->n_weights; i++)
			total += h->weights[i];
		for (size_t i = 0; i < h->n_weights; i++)
			if (x >= h->edges[i] && x < h->edges[i + 1])
				return h->weights[i] / total / (h->edges[i + 1] - h->edges[i]);
		return 0.0;
	}
	}
	return NAN;
}

static double moment_integrand(double x, void *params)
{
	const moment_params *mp = params;
	return pow(x - mp->centre, mp->power) * density(mp->d, x);
}

/* Integral of (x - centre)^power f(x) over [lo, hi] (either may be infinite), split at the
 * triangular mode where the density has a kink. */
static double integrate(const prsm_dist *d, int power, double centre)
{
	moment_params mp = {d, power, centre};
	gsl_function f = {&moment_integrand, &mp};
	gsl_integration_workspace *ws = gsl_integration_workspace_alloc(1000);
	assert_non_null(ws);
	double lo = support_lower(d), hi = support_upper(d);
	double cuts[PRSM_DIST_HISTOGRAM_MAX_BINS + 1] = {lo, hi, hi};
	int ncuts = 2;
	if (d->kind == PRSM_DIST_TRIANGULAR) {
		cuts[1] = d->p[1];
		ncuts = 3;
	} else if (d->kind == PRSM_DIST_HISTOGRAM) { /* each bin on its own */
		ncuts = (int)d->hist->n_edges;
		memcpy(cuts, d->hist->edges, d->hist->n_edges * sizeof cuts[0]);
	} else if (d->kind == PRSM_DIST_GUMBEL) { /* the two tails apart: the upper one is far longer */
		cuts[0] = -INFINITY;
		cuts[1] = d->p[0];
		cuts[2] = INFINITY;
		ncuts = 3;
	}
	double total = 0.0;
	for (int k = 0; k + 1 < ncuts; k++) {
		double a = cuts[k], b = cuts[k + 1], result = 0.0, abserr = 0.0;
		int rc;
		if (!(b > a))
			continue;
		if (isinf(a) && isinf(b))
			rc = gsl_integration_qagi(&f, 0.0, 1e-13, 1000, ws, &result, &abserr);
		else if (isinf(b))
			rc = gsl_integration_qagiu(&f, a, 0.0, 1e-13, 1000, ws, &result, &abserr);
		else if (isinf(a))
			rc = gsl_integration_qagil(&f, b, 0.0, 1e-13, 1000, ws, &result, &abserr);
		else
			rc = gsl_integration_qags(&f, a, b, 0.0, 1e-13, 1000, ws, &result, &abserr);
		assert_int_equal(rc, 0);
		total += result;
	}
	gsl_integration_workspace_free(ws);
	return total;
}

static void test_exact_moments_against_integration(void **state)
{
	(void)state;
	for (size_t i = 0; i < N_CASES; i++) {
		const prsm_dist *d = &cases[i];
		const double z = integrate(d, 0, 0.0);
		const double mean = integrate(d, 1, 0.0) / z;
		const double sd = sqrt(integrate(d, 2, mean) / z);
		if (d->kind != PRSM_DIST_TRUNCNORMAL)
			assert_close(z, 1.0, 1e-11);
		if (!(fabs(prsm_dist_mean(d) - mean) <= 1e-10 * (fabs(mean) + sd)) ||
		    !(fabs(prsm_dist_sd(d) - sd) <= 1e-9 * sd))
			print_error("case %zu (%s): mean %.17g against %.17g, sd %.17g against %.17g\n", i,
			            prsm_dist_name(d->kind), prsm_dist_mean(d), mean, prsm_dist_sd(d), sd);
		assert_close(prsm_dist_mean(d), mean, 1e-10 * (fabs(mean) + sd));
		assert_close(prsm_dist_sd(d), sd, 1e-9 * sd);
	}
}

/* The closed forms of the textbook cases, and the truncated normal's limits. */
static void test_exact_moments_closed_forms(void **state)
{
	(void)state;
	const prsm_dist u = D2(PRSM_DIST_UNIFORM, -1.7, 3.1), r = D1(PRSM_DIST_RAYLEIGH, 1.9);
	const prsm_dist ln = D2(PRSM_DIST_LOGNORMAL, 0.3, 0.45);
	assert_close(prsm_dist_mean(&u), 0.7, 1e-15);
	assert_close(prsm_dist_sd(&u), 4.8 / sqrt(12.0), 1e-15);
	assert_close(prsm_dist_mean(&r), 1.9 * sqrt(M_PI / 2.0), 1e-14);
	assert_close(prsm_dist_sd(&r), 1.9 * sqrt((4.0 - M_PI) / 2.0), 1e-14);
	assert_close(prsm_dist_mean(&ln), exp(0.3 + 0.45 * 0.45 / 2.0), 1e-14);
	assert_close(prsm_dist_sd(&ln), sqrt((exp(0.45 * 0.45) - 1.0) * exp(0.6 + 0.45 * 0.45)), 1e-14);

	/* a wide window is the parent normal; a half-normal has mean sd sqrt(2/pi) */
	const prsm_dist wide = D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -40.0, 40.0);
	assert_close(prsm_dist_mean(&wide), 0.41, 1e-14);
	assert_close(prsm_dist_sd(&wide), 1.37, 1e-14);
	const prsm_dist half = D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, 0.41, INFINITY);
	assert_close(prsm_dist_mean(&half), 0.41 + 1.37 * sqrt(2.0 / M_PI), 1e-14);
	assert_close(prsm_dist_sd(&half), 1.37 * sqrt(1.0 - 2.0 / M_PI), 1e-14);

	/* a window far narrower than sd is uniform (closed form would lose every digit) */
	const prsm_dist narrow = D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1e4, 1.0, 1.001);
	assert_int_equal(prsm_dist_check(&narrow, NULL, 0), 0);
	assert_close(prsm_dist_mean(&narrow), 1.0005, 1e-12);
	assert_close(prsm_dist_sd(&narrow), 0.001 / sqrt(12.0), 1e-12);

	/* both sides of the switch to quadrature at 0.5 sd agree with integration */
	for (double w = 0.49; w < 0.52; w += 0.02) {
		const prsm_dist t = D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 5.3, 5.3 + w);
		const double z = integrate(&t, 0, 0.0), mean = integrate(&t, 1, 0.0) / z;
		const double sd = sqrt(integrate(&t, 2, mean) / z);
		assert_close(prsm_dist_mean(&t), mean, 1e-12 * mean);
		assert_close(prsm_dist_sd(&t), sd, 1e-9 * sd);
	}
}

/* The skewed families' textbook moments, written independently of dist.c. */
static void test_skewed_closed_forms(void **state)
{
	(void)state;
	const prsm_dist e = D2(PRSM_DIST_EXPONENTIAL, 2.3, -1.25);
	assert_close(prsm_dist_mean(&e), 1.05, 1e-15);
	assert_close(prsm_dist_sd(&e), 2.3, 0.0);
	const prsm_dist g = D3(PRSM_DIST_GAMMA, 2.7, 0.45, 0.3);
	assert_close(prsm_dist_mean(&g), 0.3 + 2.7 * 0.45, 1e-15);
	assert_close(prsm_dist_sd(&g), sqrt(2.7) * 0.45, 1e-15);
	/* Weibull k = 2 (Rayleigh-like): mean lambda sqrt(pi) / 2, variance lambda^2 (1 - pi / 4); k = 1:
	 * the exponential; k = 1000: sd lambda pi / (k sqrt 6) to first order */
	const prsm_dist w2 = D3(PRSM_DIST_WEIBULL, 2.0, 1.4, 0.5);
	assert_close(prsm_dist_mean(&w2), 0.5 + 1.4 * sqrt(M_PI) / 2.0, 1e-14);
	assert_close(prsm_dist_sd(&w2), 1.4 * sqrt(1.0 - M_PI / 4.0), 1e-14);
	const prsm_dist w1 = D3(PRSM_DIST_WEIBULL, 1.0, 0.85, 0.0), ex = D2(PRSM_DIST_EXPONENTIAL, 0.85, 0.0);
	assert_close(prsm_dist_mean(&w1), prsm_dist_mean(&ex), 1e-15);
	assert_close(prsm_dist_sd(&w1), prsm_dist_sd(&ex), 1e-14);
	const prsm_dist wk = D3(PRSM_DIST_WEIBULL, 1000.0, 2.0, 0.0);
	assert_close(prsm_dist_sd(&wk), 2.0 * M_PI / (1000.0 * sqrt(6.0)), 2e-3 * 2.0 * M_PI / (1000.0 * sqrt(6.0)));
	const double gk = gsl_sf_gamma(1.001), g2k = gsl_sf_gamma(1.002); /* the textbook form, 1e-6 digits lost */
	assert_close(prsm_dist_sd(&wk), 2.0 * sqrt(g2k - gk * gk), 1e-9 * prsm_dist_sd(&wk));
	/* Beta(2, 5) on [0, 1]: mean 2/7, variance 10 / (49 8); on [-3, 0.5]: scaled and shifted */
	const prsm_dist b = D4(PRSM_DIST_BETA, 2.0, 5.0, 0.0, 1.0), bs = D4(PRSM_DIST_BETA, 2.0, 5.0, -3.0, 0.5);
	assert_close(prsm_dist_mean(&b), 2.0 / 7.0, 1e-15);
	assert_close(prsm_dist_sd(&b), sqrt(10.0 / 392.0), 1e-15);
	assert_close(prsm_dist_mean(&bs), -3.0 + 3.5 * 2.0 / 7.0, 1e-15);
	assert_close(prsm_dist_sd(&bs), 3.5 * sqrt(10.0 / 392.0), 1e-15);
	/* Beta(1, 1) is the uniform */
	const prsm_dist b11 = D4(PRSM_DIST_BETA, 1.0, 1.0, -1.7, 3.1), u = D2(PRSM_DIST_UNIFORM, -1.7, 3.1);
	assert_close(prsm_dist_mean(&b11), prsm_dist_mean(&u), 1e-15);
	assert_close(prsm_dist_sd(&b11), prsm_dist_sd(&u), 1e-15);
	/* Gumbel: mean location + Euler's gamma scale, sd pi scale / sqrt 6 */
	const prsm_dist gu = D2(PRSM_DIST_GUMBEL, -2.4, 0.35);
	assert_close(prsm_dist_mean(&gu), -2.4 + 0.5772156649015329 * 0.35, 1e-15);
	assert_close(prsm_dist_sd(&gu), 0.35 * M_PI / sqrt(6.0), 1e-15);
	/* a one-bin histogram is the uniform; two bins of equal width and weight too */
	assert_close(prsm_dist_mean(&cases[N_CASES - 2]), 1.0, 1e-15);
	assert_close(prsm_dist_sd(&cases[N_CASES - 2]), 1.4 / sqrt(12.0), 1e-15);
	prsm_dist_histogram h2 = {3, {-1.7, 0.7, 3.1}, 2, {2.5, 2.5}, {0}};
	prsm_dist d2;
	assert_int_equal(prsm_dist_histogram_set(&d2, &h2, NULL, 0), 0);
	assert_close(prsm_dist_mean(&d2), prsm_dist_mean(&u), 1e-15);
	assert_close(prsm_dist_sd(&d2), prsm_dist_sd(&u), 1e-15);
	/* the gappy histogram by hand: bins [-0.5, 0.25) 3/6.75, [0.5, 1.5) 1.5/6.75, [1.5, 2.75) 2.25/6.75 */
	const double pw[3] = {3.0 / 6.75, 1.5 / 6.75, 2.25 / 6.75}, lo[3] = {-0.5, 0.5, 1.5}, hi[3] = {0.25, 1.5, 2.75};
	double m = 0.0, m2 = 0.0;
	for (int i = 0; i < 3; i++) {
		m += pw[i] * (lo[i] + hi[i]) / 2.0;
		m2 += pw[i] * (lo[i] * lo[i] + lo[i] * hi[i] + hi[i] * hi[i]) / 3.0;
	}
	assert_close(prsm_dist_mean(&cases[N_CASES - 3]), m, 1e-15);
	assert_close(prsm_dist_sd(&cases[N_CASES - 3]), sqrt(m2 - m * m), 1e-14);
}

/* ---- quantile and CDF ------------------------------------------------------------------- */

static void test_cdf_inverts_quantile(void **state)
{
	(void)state;
	const double grid[] = {1e-9, 3.7e-7, 1e-4, 0.0137, 0.1, 0.25, 0.385, 0.5, 0.61803,
	                       0.75, 0.9, 0.987, 1.0 - 1e-4, 1.0 - 3.7e-7, 1.0 - 1e-9};
	for (size_t i = 0; i < N_CASES; i++) {
		const prsm_dist *d = &cases[i];
		double previous = -INFINITY;
		for (size_t j = 0; j < sizeof grid / sizeof grid[0]; j++) {
			double x = prsm_dist_quantile(d, grid[j]);
			assert_true(x >= support_lower(d) && x <= support_upper(d));
			assert_true(x >= previous);
			previous = x;
			assert_close(prsm_dist_cdf(d, x), grid[j], 1e-10);
		}
		/* ends of the support, NaN */
		assert_true(prsm_dist_quantile(d, 0.0) == support_lower(d));
		assert_true(prsm_dist_quantile(d, 1.0) == support_upper(d));
		assert_true(isnan(prsm_dist_quantile(d, NAN)));
		assert_true(prsm_dist_cdf(d, -INFINITY) == 0.0);
		assert_true(prsm_dist_cdf(d, INFINITY) == 1.0);
		if (isfinite(support_lower(d)))
			assert_true(prsm_dist_cdf(d, support_lower(d) - 0.125) == 0.0);
		if (isfinite(support_upper(d)))
			assert_true(prsm_dist_cdf(d, support_upper(d) + 0.125) == 1.0);
	}
}

/* Known quantiles: independent values of GSL and the definitions. */
static void test_known_quantiles(void **state)
{
	(void)state;
	const prsm_dist n = D2(PRSM_DIST_NORMAL, 2.385, 0.713);
	assert_close(prsm_dist_quantile(&n, 0.975), 2.385 + 0.713 * 1.9599639845400536, 1e-13);
	const prsm_dist u = D2(PRSM_DIST_UNIFORM, -1.7, 3.1);
	assert_close(prsm_dist_quantile(&u, 0.25), -0.5, 1e-15);
	const prsm_dist t = D3(PRSM_DIST_TRIANGULAR, -0.6, 0.35, 2.9);
	assert_close(prsm_dist_quantile(&t, 0.95 / 3.5), 0.35, 1e-14);
	const prsm_dist r = D1(PRSM_DIST_RAYLEIGH, 1.9);
	assert_close(prsm_dist_quantile(&r, 0.5), 1.9 * sqrt(2.0 * log(2.0)), 1e-14);
	const prsm_dist ln = D2(PRSM_DIST_LOGNORMAL, 0.3, 0.45);
	assert_close(prsm_dist_quantile(&ln, 0.5), exp(0.3), 1e-14);
	/* truncnormal median of a window symmetric about the mean is the mean */
	const prsm_dist s = D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, 0.41 - 2.2, 0.41 + 2.2);
	assert_close(prsm_dist_quantile(&s, 0.5), 0.41, 1e-14);
	/* deep tail: the window [6, 8] is resolved, its lower quartile near 6 + 0.0466 */
	const prsm_dist deep = D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 6.0, 8.0);
	double q = prsm_dist_quantile(&deep, 0.25);
	assert_close(gsl_cdf_ugaussian_Q(6.0) - gsl_cdf_ugaussian_Q(q),
	             0.25 * (gsl_cdf_ugaussian_Q(6.0) - gsl_cdf_ugaussian_Q(8.0)), 1e-22);
	assert_true(q > 6.04 && q < 6.05);
	/* one-sided window, u -> 1: the tail probability (1 - u) Q(a) keeps its relative precision */
	const prsm_dist one = D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 0.5, INFINITY);
	for (double tail = 1e-6; tail > 1e-14; tail *= 1e-2) {
		double u1 = 1.0 - tail;
		double expected = gsl_cdf_ugaussian_Qinv((1.0 - u1) * gsl_cdf_ugaussian_Q(0.5));
		assert_close(prsm_dist_quantile(&one, u1), expected, 1e-13 * expected);
	}
}

/* The skewed families' quantiles: closed forms, and GSL's own inverses where they work. */
static void test_skewed_known_quantiles(void **state)
{
	(void)state;
	const prsm_dist e = D2(PRSM_DIST_EXPONENTIAL, 2.3, -1.25);
	assert_close(prsm_dist_quantile(&e, 0.5), -1.25 + 2.3 * M_LN2, 1e-14);
	const double u12 = 1.0 - 1e-12, tail12 = 1.0 - u12; /* 1 - u12 exactly */
	assert_close(prsm_dist_quantile(&e, u12), -1.25 - 2.3 * log(tail12), 1e-13);
	const prsm_dist w = D3(PRSM_DIST_WEIBULL, 2.2, 1.4, 0.5);
	assert_close(prsm_dist_quantile(&w, 0.5), 0.5 + 1.4 * pow(M_LN2, 1.0 / 2.2), 1e-14);
	const prsm_dist gu = D2(PRSM_DIST_GUMBEL, -2.4, 0.35);
	assert_close(prsm_dist_quantile(&gu, 0.5), -2.4 - 0.35 * log(M_LN2), 1e-14);
	assert_close(prsm_dist_quantile(&gu, exp(-1.0)), -2.4, 1e-14); /* F(location) = 1/e */
	/* far upper tail: x = location - scale ln(-ln u), -ln u = -ln(1 - t) = t + t^2 / 2 resolved */
	assert_close(prsm_dist_quantile(&gu, u12), -2.4 - 0.35 * log(tail12 + 0.5 * tail12 * tail12), 1e-13);
	/* gamma of shape 1 is the exponential; of shape 2, F = 1 - e^-x (1 + x) */
	const prsm_dist g1 = D3(PRSM_DIST_GAMMA, 1.0, 2.3, -1.25), g2 = D3(PRSM_DIST_GAMMA, 2.0, 1.0, 0.0);
	for (double u = 1e-8; u < 1.0; u = u < 0.5 ? u * 7.0 : 1.0 - (1.0 - u) / 7.0) {
		assert_close(prsm_dist_quantile(&g1, u), prsm_dist_quantile(&e, u), 1e-13 * fmax(1.0, fabs(prsm_dist_quantile(&e, u))));
		const double x = prsm_dist_quantile(&g2, u);
		assert_close(-expm1(-x) - x * exp(-x), u, 1e-14);
	}
	/* Beta(2, 1): F = x^2; Beta(1, 3): F = 1 - (1 - x)^3; Beta(0.5, 0.5): F = 2 asin(sqrt x) / pi */
	const prsm_dist b21 = D4(PRSM_DIST_BETA, 2.0, 1.0, 0.0, 1.0), b13 = D4(PRSM_DIST_BETA, 1.0, 3.0, 0.0, 1.0);
	const prsm_dist arc = D4(PRSM_DIST_BETA, 0.5, 0.5, 0.0, 1.0);
	for (double u = 1e-9; u < 1.0; u = u < 0.5 ? u * 5.0 : 1.0 - (1.0 - u) / 5.0) {
		assert_close(prsm_dist_quantile(&b21, u), sqrt(u), 1e-14);
		assert_close(prsm_dist_quantile(&b13, u), -expm1(log1p(-u) / 3.0), 1e-14);
		const double s = sin(0.5 * M_PI * u);
		assert_close(prsm_dist_quantile(&arc, u), s * s, 1e-14);
	}
	/* GSL's inverses agree where they are reliable */
	const prsm_dist g = D3(PRSM_DIST_GAMMA, 2.7, 0.45, 0.0), b = D4(PRSM_DIST_BETA, 2.0, 5.0, 0.0, 1.0);
	for (double u = 0.01; u < 1.0; u += 0.049) {
		assert_close(prsm_dist_quantile(&g, u), gsl_cdf_gamma_Pinv(u, 2.7, 0.45), 1e-12);
		assert_close(prsm_dist_quantile(&b, u), gsl_cdf_beta_Pinv(u, 2.0, 5.0), 1e-12);
		assert_close(prsm_dist_quantile(&w, u), 0.5 + gsl_cdf_weibull_Pinv(u, 1.4, 2.2), 1e-13);
		assert_close(prsm_dist_quantile(&e, u), -1.25 + gsl_cdf_exponential_Pinv(u, 2.3), 1e-13);
		assert_close(prsm_dist_quantile(&gu, u), -2.4 + 0.35 * gsl_cdf_gumbel1_Pinv(u, 1.0, 1.0), 1e-13);
	}
}

/* Where GSL's gamma and beta inverses fail (NaN, or CDF errors of 1e-2: shape 1000 or 0.1,
 * beta(2, 1000), beta(0.5, 0.1), ...), the quantiles still invert the CDF, over the whole range of
 * shapes: every pair of shapes in [0.05, 1000] on a grid from 1e-9 to 1 - 1e-9 and at random u,
 * monotone, within the support, the CDF back to 1e-10 wherever the quantile is resolved in
 * doubles (a beta with shape 0.05 holds most of its mass within an ulp of its end, where
 * x = end is the only answer: those points are skipped). */
static void test_skewed_shape_range(void **state)
{
	(void)state;
	const double shapes[] = {0.05, 0.11, 0.3, 0.73, 1.0, 1.9, 4.4, 17.0, 160.0, 1000.0};
	const size_t ns = sizeof shapes / sizeof shapes[0];
	const double grid[] = {1e-9, 3.7e-7, 1e-4, 0.0137, 0.1, 0.25, 0.385, 0.5, 0.61803,
	                       0.75, 0.9, 0.987, 1.0 - 1e-4, 1.0 - 3.7e-7, 1.0 - 1e-9};
	gsl_rng *r = prsm_rng_alloc(20261201, 3);
	assert_non_null(r);
	int checked = 0, skipped = 0;
	for (size_t i = 0; i < ns; i++)
		for (size_t j = 0; j < ns; j++) {
			prsm_dist d[3] = {D4(PRSM_DIST_BETA, shapes[i], shapes[j], 0.0, 1.0),
			                  D3(PRSM_DIST_GAMMA, shapes[i], 1.3, 0.0), D3(PRSM_DIST_WEIBULL, shapes[i], 1.3, 0.0)};
			for (int k = 0; k < (j == 0 ? 3 : 1); k++) {
				assert_int_equal(prsm_dist_check(&d[k], NULL, 0), 0);
				double previous = -INFINITY;
				for (size_t g = 0; g < sizeof grid / sizeof grid[0] + 200; g++) {
					const double u = g < sizeof grid / sizeof grid[0] ? grid[g] : gsl_rng_uniform_pos(r);
					const double x = prsm_dist_quantile(&d[k], u);
					assert_true(x >= support_lower(&d[k]) && x <= support_upper(&d[k]));
					if (g < sizeof grid / sizeof grid[0]) {
						assert_true(x >= previous);
						previous = x;
					}
					/* resolved: the neighbouring doubles have other CDF values */
					const double below = prsm_dist_cdf(&d[k], nextafter(x, -INFINITY));
					const double above = prsm_dist_cdf(&d[k], nextafter(x, INFINITY));
					if (above - below > 1e-10) {
						skipped++;
						continue;
					}
					checked++;
					if (!(fabs(prsm_dist_cdf(&d[k], x) - u) <= 1e-10))
						print_error("%s(%g, %g): u %.17g, x %.17g, F(x) %.17g\n", prsm_dist_name(d[k].kind),
						            d[k].p[0], d[k].p[1], u, x, prsm_dist_cdf(&d[k], x));
					assert_close(prsm_dist_cdf(&d[k], x), u, 1e-10);
				}
			}
		}
	gsl_rng_free(r);
	print_message("skewed shapes: %d quantiles inverted, %d at an unresolved end skipped\n", checked, skipped);
	assert_true(checked > 20000 && skipped * 10 < checked);
}

/* The histogram: the quantile is the exact inverse of the piecewise-linear CDF, bin by bin; the
 * bins without weight are never drawn; u at a bin's cumulative weight gives its edge. */
static void test_histogram(void **state)
{
	(void)state;
	const prsm_dist *gappy = &cases[N_CASES - 3];
	const prsm_dist_histogram *h = gappy->hist;
	assert_close(h->cdf[0], 0.0, 0.0);
	assert_true(h->cdf[5] == 1.0);
	assert_close(h->cdf[2], 3.0 / 6.75, 1e-16);
	assert_true(h->cdf[1] == 0.0 && h->cdf[3] == h->cdf[2]);
	/* support without the empty end bin */
	assert_true(prsm_dist_quantile(gappy, 0.0) == -0.5 && prsm_dist_quantile(gappy, 1.0) == 2.75);
	/* u = cdf[2]: the upper edge of the first bin with weight; the empty bin [0.25, 0.5) never drawn */
	const double c2 = h->cdf[2];
	assert_true(prsm_dist_quantile(gappy, c2) == 0.5);
	assert_true(prsm_dist_quantile(gappy, nextafter(c2, 0.0)) <= 0.25);
	for (double u = 1e-6; u < 1.0; u += 1e-3) {
		const double x = prsm_dist_quantile(gappy, u);
		assert_false(x > 0.25 && x < 0.5);
		/* inside a bin: linear between its edges */
		size_t j = 0;
		while (!(h->cdf[j] <= u && u < h->cdf[j + 1]))
			j++;
		const double expect = h->edges[j] + (u - h->cdf[j]) / (h->cdf[j + 1] - h->cdf[j]) * (h->edges[j + 1] - h->edges[j]);
		assert_close(x, expect, 1e-14);
	}
	/* CDF flat over the empty bin, linear in the others */
	assert_close(prsm_dist_cdf(gappy, 0.3), c2, 0.0);
	assert_close(prsm_dist_cdf(gappy, 0.45), c2, 0.0);
	assert_close(prsm_dist_cdf(gappy, 1.0), c2 + 0.5 * 1.5 / 6.75, 1e-15);
	assert_true(prsm_dist_cdf(gappy, -0.75) == 0.0 && prsm_dist_cdf(gappy, 2.75) == 1.0);
	/* one bin: the uniform, exactly */
	const prsm_dist *one = &cases[N_CASES - 2];
	const prsm_dist u = D2(PRSM_DIST_UNIFORM, 0.3, 1.7);
	for (double v = 0.0625; v < 1.0; v += 0.125)
		assert_close(prsm_dist_quantile(one, v), prsm_dist_quantile(&u, v), 1e-15);
	/* the check refuses a histogram whose cumulative weights are stale, or none */
	prsm_dist_histogram stale = *h;
	prsm_dist d = *gappy;
	d.hist = &stale;
	assert_int_equal(prsm_dist_check(&d, NULL, 0), 0);
	stale.weights[4] = 9.0;
	char msg[PRSM_ERROR_MESSAGE_MAX];
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
	assert_non_null(strstr(msg, "out of date"));
	d.hist = NULL;
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
	assert_non_null(strstr(msg, "no bins"));
}

/* prsm_dist_histogram_set: its refusals, each naming what is wrong, d untouched. */
static void test_histogram_set_rejects(void **state)
{
	(void)state;
	const struct {
		prsm_dist_histogram h;
		const char *names;
	} bad[] = {
		{{1, {0.0}, 0, {0.0}, {0}}, "1 to 64 bins"},
		{{66, {0.0}, 65, {0.0}, {0}}, "1 to 64 bins"},
		{{3, {0.0, 1.0, 2.0}, 3, {1.0, 1.0, 1.0}, {0}}, "one weight per bin"},
		{{3, {0.0, 1.0, 2.0}, 1, {1.0}, {0}}, "one weight per bin"},
		{{3, {0.0, 1.0, 1.0}, 2, {1.0, 1.0}, {0}}, "edges must increase: edges[2]"},
		{{3, {0.0, -1.0, 2.0}, 2, {1.0, 1.0}, {0}}, "edges must increase: edges[1]"},
		{{3, {0.0, NAN, 2.0}, 2, {1.0, 1.0}, {0}}, "edges[1] must be finite"},
		{{3, {-INFINITY, 1.0, 2.0}, 2, {1.0, 1.0}, {0}}, "edges[0] must be finite"},
		{{3, {0.0, 1.0, 2.0}, 2, {1.0, -0.5}, {0}}, "weights[1] must be finite and >= 0"},
		{{3, {0.0, 1.0, 2.0}, 2, {NAN, 1.0}, {0}}, "weights[0]"},
		{{3, {0.0, 1.0, 2.0}, 2, {INFINITY, 1.0}, {0}}, "weights[0]"},
		{{3, {0.0, 1.0, 2.0}, 2, {0.0, 0.0}, {0}}, "positive sum"},
		{{3, {0.0, 1.0, 2.0}, 2, {1e308, 1e308}, {0}}, "positive sum"},
		{{3, {-1.5e308, 0.0, 1.5e308}, 2, {1.0, 1.0}, {0}}, NULL}, /* accepted here, refused by the check */
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		prsm_dist d = D1(PRSM_DIST_NORMAL, 7.0), before = d;
		prsm_dist_histogram h = bad[i].h;
		char msg[PRSM_ERROR_MESSAGE_MAX] = "x";
		const int rc = prsm_dist_histogram_set(&d, &h, msg, sizeof msg);
		if (bad[i].names == NULL) {
			assert_int_equal(rc, 0);
			assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
			assert_non_null(strstr(msg, "out of range"));
			continue;
		}
		if (rc != PRSM_EINVAL || strstr(msg, bad[i].names) == NULL)
			print_error("bad histogram %zu: rc %d, \"%s\", expected \"%s\"\n", i, rc, msg, bad[i].names);
		assert_int_equal(rc, PRSM_EINVAL);
		assert_non_null(strstr(msg, bad[i].names));
		assert_memory_equal(&d, &before, sizeof d);
		/* the check says the same of a distribution pointing at these bins */
		prsm_dist hd = {PRSM_DIST_HISTOGRAM, {0.0, 1.0, 0.0, 0.0}, &h};
		char msg2[PRSM_ERROR_MESSAGE_MAX];
		assert_int_equal(prsm_dist_check(&hd, msg2, sizeof msg2), PRSM_EINVAL);
		assert_string_equal(msg2, msg);
	}
}

/* Which parameters a document may leave out, and the value they then take. */
static void test_param_defaults(void **state)
{
	(void)state;
	double v = 42.0;
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_NORMAL, 0, &v), 1);
	assert_true(v == 0.0);
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_NORMAL, 1, &v), 0);
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_TRUNCNORMAL, 2, &v), 1);
	assert_true(v == -INFINITY);
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_TRUNCNORMAL, 3, &v), 1);
	assert_true(v == INFINITY);
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_UNIFORM, 0, &v), 0);
	assert_int_equal(prsm_dist_param_default(PRSM_DIST_BETA, 2, &v), 0); /* a beta's ends are required */
	const struct {
		prsm_dist_kind k;
		int q;
	} located[] = {{PRSM_DIST_EXPONENTIAL, 1}, {PRSM_DIST_GAMMA, 2}, {PRSM_DIST_WEIBULL, 2}, {PRSM_DIST_GUMBEL, 0}};
	for (size_t i = 0; i < sizeof located / sizeof located[0]; i++) {
		v = 42.0;
		assert_string_equal(prsm_dist_param_name(located[i].k, located[i].q), "location");
		assert_int_equal(prsm_dist_param_default(located[i].k, located[i].q, &v), 1);
		assert_true(v == 0.0);
	}
	for (int q = 0; q < 4; q++) {
		assert_null(prsm_dist_param_name(PRSM_DIST_HISTOGRAM, q));
		assert_int_equal(prsm_dist_param_default(PRSM_DIST_HISTOGRAM, q, &v), 0);
	}
	assert_int_equal(prsm_dist_param_default((prsm_dist_kind)99, 0, &v), 0);
}

/* A window narrower than the resolution of P near the mean: the quantile stays inside and the
 * CDF inverts it to the precision the window's mass allows (about eps / mass). */
static void test_narrow_window(void **state)
{
	(void)state;
	const prsm_dist d = D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1e4, 1.0, 1.001);
	for (double u = 0.0625; u < 1.0; u += 0.125) {
		double x = prsm_dist_quantile(&d, u);
		assert_true(x >= 1.0 && x <= 1.001);
		assert_close(x, 1.0 + 0.001 * u, 1e-9);
		assert_close(prsm_dist_cdf(&d, x), u, 1e-6);
	}
}

/* ---- check ------------------------------------------------------------------------------ */

static void test_check_rejects(void **state)
{
	(void)state;
	const struct {
		prsm_dist d;
		const char *names; /* expected in the message */
	} bad[] = {
		{D2(PRSM_DIST_NORMAL, NAN, 0.713), "normal mean"},
		{D2(PRSM_DIST_NORMAL, INFINITY, 0.713), "normal mean"},
		{D2(PRSM_DIST_NORMAL, 2.385, INFINITY), "normal sd"},
		{D2(PRSM_DIST_NORMAL, 2.385, NAN), "normal sd"},
		{D2(PRSM_DIST_NORMAL, 2.385, 0.0), "normal sd"},
		{D2(PRSM_DIST_NORMAL, 2.385, -0.713), "normal sd"},
		{D4(PRSM_DIST_TRUNCNORMAL, NAN, 1.37, -0.9, 2.2), "truncnormal mean"},
		{D4(PRSM_DIST_TRUNCNORMAL, -INFINITY, 1.37, -0.9, 2.2), "truncnormal mean"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 0.0, -0.9, 2.2), "truncnormal sd"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, -1.37, -0.9, 2.2), "truncnormal sd"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, INFINITY, -0.9, 2.2), "truncnormal sd"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, NAN, 2.2), "truncnormal lower"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -0.9, NAN), "truncnormal upper"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, 2.2, -0.9), "lower must be < upper"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, 2.2, 2.2), "lower must be < upper"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, INFINITY, INFINITY), "lower must be < upper"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -INFINITY, -INFINITY), "lower must be < upper"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -INFINITY, INFINITY), "both infinite"},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 7.3, 9.0), "window"},          /* Q(7.3) = 1.4e-13 */
		{D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, -INFINITY, -7.3), "window"},   /* lower tail */
		{D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 0.5, 0.5 + 1e-15), "window"}, /* too narrow */
		{D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 40.0, INFINITY), "window"},   /* Q underflows */
		{D2(PRSM_DIST_UNIFORM, 3.1, 3.1), "uniform lower must be < upper"},
		{D2(PRSM_DIST_UNIFORM, 3.1, -1.7), "uniform lower must be < upper"},
		{D2(PRSM_DIST_UNIFORM, NAN, 3.1), "uniform lower"},
		{D2(PRSM_DIST_UNIFORM, -1.7, INFINITY), "uniform upper"},
		{D2(PRSM_DIST_UNIFORM, -1.5e308, 1.5e308), "out of range"}, /* range overflows */
		{D3(PRSM_DIST_TRIANGULAR, -0.6, -0.61, 2.9), "triangular mode"},
		{D3(PRSM_DIST_TRIANGULAR, -0.6, 2.91, 2.9), "triangular mode"},
		{D3(PRSM_DIST_TRIANGULAR, -0.6, NAN, 2.9), "triangular mode"},
		{D3(PRSM_DIST_TRIANGULAR, 0.35, 0.35, 0.35), "triangular lower must be < upper"},
		{D3(PRSM_DIST_TRIANGULAR, 2.9, 0.35, -0.6), "triangular lower must be < upper"},
		{D3(PRSM_DIST_TRIANGULAR, -INFINITY, 0.35, 2.9), "triangular lower"},
		{D3(PRSM_DIST_TRIANGULAR, -0.6, 0.35, INFINITY), "triangular upper"},
		{D2(PRSM_DIST_LOGNORMAL, 0.3, 0.0), "lognormal sigma"},
		{D2(PRSM_DIST_LOGNORMAL, 0.3, -0.45), "lognormal sigma"},
		{D2(PRSM_DIST_LOGNORMAL, 0.3, INFINITY), "lognormal sigma"},
		{D2(PRSM_DIST_LOGNORMAL, NAN, 0.45), "lognormal mu"},
		{D2(PRSM_DIST_LOGNORMAL, 800.0, 0.45), "out of range"}, /* exp(800) overflows */
		{D2(PRSM_DIST_LOGNORMAL, 0.3, 30.0), "out of range"},   /* exp(sigma^2) overflows */
		{D1(PRSM_DIST_RAYLEIGH, 0.0), "rayleigh sigma"},
		{D1(PRSM_DIST_RAYLEIGH, -1.9), "rayleigh sigma"},
		{D1(PRSM_DIST_RAYLEIGH, NAN), "rayleigh sigma"},
		{D1(PRSM_DIST_RAYLEIGH, INFINITY), "rayleigh sigma"},
		{D2(PRSM_DIST_EXPONENTIAL, 0.0, 0.0), "exponential scale must be > 0"},
		{D2(PRSM_DIST_EXPONENTIAL, -1.0, 0.0), "exponential scale"},
		{D2(PRSM_DIST_EXPONENTIAL, INFINITY, 0.0), "exponential scale"},
		{D2(PRSM_DIST_EXPONENTIAL, 1.0, NAN), "exponential location"},
		{D2(PRSM_DIST_EXPONENTIAL, 1e308, 1e308), "out of range"},
		{D3(PRSM_DIST_GAMMA, 0.0, 1.0, 0.0), "gamma shape must lie in [0.05, 1000]"},
		{D3(PRSM_DIST_GAMMA, 0.049, 1.0, 0.0), "gamma shape must lie in"},
		{D3(PRSM_DIST_GAMMA, 1000.5, 1.0, 0.0), "gamma shape must lie in"},
		{D3(PRSM_DIST_GAMMA, NAN, 1.0, 0.0), "gamma shape"},
		{D3(PRSM_DIST_GAMMA, 2.0, 0.0, 0.0), "gamma scale must be > 0"},
		{D3(PRSM_DIST_GAMMA, 2.0, -1.0, 0.0), "gamma scale"},
		{D3(PRSM_DIST_GAMMA, 2.0, 1.0, INFINITY), "gamma location"},
		{D3(PRSM_DIST_GAMMA, 2.0, 1e308, 0.0), "out of range"},
		{D3(PRSM_DIST_WEIBULL, 0.01, 1.0, 0.0), "weibull shape must lie in"},
		{D3(PRSM_DIST_WEIBULL, 2000.0, 1.0, 0.0), "weibull shape must lie in"},
		{D3(PRSM_DIST_WEIBULL, 2.0, 0.0, 0.0), "weibull scale must be > 0"},
		{D3(PRSM_DIST_WEIBULL, 2.0, NAN, 0.0), "weibull scale"},
		{D3(PRSM_DIST_WEIBULL, 2.0, 1.0, -INFINITY), "weibull location"},
		{D3(PRSM_DIST_WEIBULL, 0.05, 1e300, 0.0), "out of range"}, /* Gamma(21) 1e300 overflows */
		{D4(PRSM_DIST_BETA, 0.0, 1.0, 0.0, 1.0), "beta alpha must lie in"},
		{D4(PRSM_DIST_BETA, 1.0, 1e4, 0.0, 1.0), "beta beta must lie in"},
		{D4(PRSM_DIST_BETA, 1.0, NAN, 0.0, 1.0), "beta beta"},
		{D4(PRSM_DIST_BETA, 2.0, 5.0, 1.0, 1.0), "beta lower must be < upper"},
		{D4(PRSM_DIST_BETA, 2.0, 5.0, 1.0, -1.0), "beta lower must be < upper"},
		{D4(PRSM_DIST_BETA, 2.0, 5.0, -INFINITY, 1.0), "beta lower"},
		{D4(PRSM_DIST_BETA, 2.0, 5.0, 0.0, INFINITY), "beta upper"},
		{D4(PRSM_DIST_BETA, 2.0, 5.0, -1.5e308, 1.5e308), "out of range"},
		{D2(PRSM_DIST_GUMBEL, 0.0, 0.0), "gumbel scale must be > 0"},
		{D2(PRSM_DIST_GUMBEL, 0.0, -0.35), "gumbel scale"},
		{D2(PRSM_DIST_GUMBEL, NAN, 0.35), "gumbel location"},
		{D2(PRSM_DIST_GUMBEL, 0.0, 1e308), "out of range"},
		{D2(PRSM_DIST_HISTOGRAM, 0.0, 1.0), "histogram has no bins"},
		{D1((prsm_dist_kind)17, 1.9), "unknown distribution kind"},
		{D1((prsm_dist_kind)-1, 1.9), "unknown distribution kind"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		char msg[PRSM_ERROR_MESSAGE_MAX] = "";
		int rc = prsm_dist_check(&bad[i].d, msg, sizeof msg);
		if (rc != PRSM_EINVAL || strstr(msg, bad[i].names) == NULL)
			print_error("bad case %zu: rc %d, message \"%s\", expected \"%s\"\n", i, rc, msg,
			            bad[i].names);
		assert_int_equal(rc, PRSM_EINVAL);
		assert_non_null(strstr(msg, bad[i].names));
		assert_null(strchr(msg, '\n'));
		/* without a buffer, and with a short one (truncated, terminated) */
		assert_int_equal(prsm_dist_check(&bad[i].d, NULL, 0), PRSM_EINVAL);
		char shortmsg[8];
		memset(shortmsg, 'x', sizeof shortmsg);
		assert_int_equal(prsm_dist_check(&bad[i].d, shortmsg, sizeof shortmsg), PRSM_EINVAL);
		assert_int_equal((int)strlen(shortmsg), 7);
	}
}

/* ---- names, stack figures, shorthand ---------------------------------------------------- */

static void test_names(void **state)
{
	(void)state;
	const char *names[] = {"normal",      "truncnormal", "uniform", "triangular", "lognormal", "rayleigh",
	                       "exponential", "gamma",       "weibull", "beta",       "gumbel",    "histogram"};
	assert_int_equal(PRSM_DIST_KIND_COUNT, 12);
	for (int k = 0; k < PRSM_DIST_KIND_COUNT; k++) {
		prsm_dist_kind out = PRSM_DIST_RAYLEIGH;
		assert_string_equal(prsm_dist_name((prsm_dist_kind)k), names[k]);
		assert_int_equal(prsm_dist_kind_parse(names[k], &out), 0);
		assert_int_equal((int)out, k);
	}
	prsm_dist_kind out = PRSM_DIST_UNIFORM;
	assert_int_equal(prsm_dist_kind_parse("Normal", &out), PRSM_ENOTFOUND);
	assert_int_equal(prsm_dist_kind_parse("cauchy", &out), PRSM_ENOTFOUND);
	assert_int_equal(prsm_dist_kind_parse("Gumbel", &out), PRSM_ENOTFOUND);
	assert_int_equal(prsm_dist_kind_parse("", &out), PRSM_ENOTFOUND);
	assert_int_equal(prsm_dist_kind_parse(NULL, &out), PRSM_ENOTFOUND);
	assert_int_equal((int)out, PRSM_DIST_UNIFORM);
	assert_string_equal(prsm_dist_name((prsm_dist_kind)42), "unknown");
}

static void test_center_halfwidth(void **state)
{
	(void)state;
	const struct {
		prsm_dist d;
		double center, halfwidth;
	} expect[] = {
		{D2(PRSM_DIST_NORMAL, 2.385, 0.713), 2.385, 2.139},
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 1.37, -0.9, 2.2), 0.41, 1.79},        /* window */
		{D4(PRSM_DIST_TRUNCNORMAL, 0.41, 0.37, -0.9, 2.2), 0.41, 1.11},        /* 3 sd */
		{D4(PRSM_DIST_TRUNCNORMAL, 1.23, 0.57, 0.95, INFINITY), 1.23, 1.71},   /* one-sided */
		{D4(PRSM_DIST_TRUNCNORMAL, -0.37, 2.11, -INFINITY, -1.9), -1.9, 6.33}, /* mean outside: its end */
		{D4(PRSM_DIST_TRUNCNORMAL, 0.0, 1.0, 6.0, 8.0), 6.0, 2.0},
		{D2(PRSM_DIST_UNIFORM, -1.7, 3.1), 0.7, 2.4},
		{D3(PRSM_DIST_TRIANGULAR, -0.6, 0.35, 2.9), 0.35, 2.55},
		{D3(PRSM_DIST_TRIANGULAR, -3.1, 0.8, 0.8), 0.8, 3.9},
		{D2(PRSM_DIST_LOGNORMAL, 0.3, 0.45), 1.3498588075760032,
		 1.3498588075760032 * (exp(0.45 * 2.999976992703401) - 1.0)},
		{D1(PRSM_DIST_RAYLEIGH, 1.9), 0.0, 1.9 * 3.6352855971798967},
	};
	for (size_t i = 0; i < sizeof expect / sizeof expect[0]; i++) {
		const prsm_dist *d = &expect[i].d;
		assert_close(prsm_dist_center(d), expect[i].center, 1e-14);
		assert_close(prsm_dist_halfwidth(d), expect[i].halfwidth, 1e-12);
	}
	/* lognormal and rayleigh: centre + half-width is the 0.99865 quantile */
	for (size_t i = 9; i < 11; i++) {
		const prsm_dist *d = &expect[i].d;
		assert_close(prsm_dist_cdf(d, prsm_dist_center(d) + prsm_dist_halfwidth(d)), 0.99865, 1e-12);
		assert_close(prsm_dist_center(d) + prsm_dist_halfwidth(d), prsm_dist_quantile(d, 0.99865),
		             1e-12);
	}
	/* the skewed families: the median, and the farther of the 0.135 and 99.865 % quantiles */
	const prsm_dist e = D2(PRSM_DIST_EXPONENTIAL, 2.3, -1.25);
	assert_close(prsm_dist_center(&e), -1.25 + 2.3 * M_LN2, 1e-14);
	assert_close(prsm_dist_halfwidth(&e), 2.3 * (-log(0.00135) - M_LN2), 1e-13);
	const prsm_dist gu = D2(PRSM_DIST_GUMBEL, -2.4, 0.35);
	assert_close(prsm_dist_center(&gu), -2.4 - 0.35 * log(M_LN2), 1e-14);
	assert_close(prsm_dist_halfwidth(&gu), 0.35 * (-log(-log(0.99865)) + log(M_LN2)), 1e-13);
	const prsm_dist wl = D3(PRSM_DIST_WEIBULL, 11.0, 3.0, 1.0); /* left-skewed: the lower side is farther */
	const double m = prsm_dist_quantile(&wl, 0.5);
	assert_close(prsm_dist_halfwidth(&wl), m - prsm_dist_quantile(&wl, 0.00135), 1e-14);
	assert_true(m - prsm_dist_quantile(&wl, 0.00135) > prsm_dist_quantile(&wl, 0.99865) - m);
	/* bounded: the median and the farther end of the support */
	const prsm_dist b = D4(PRSM_DIST_BETA, 2.0, 5.0, -3.0, 0.5);
	assert_close(prsm_dist_center(&b), prsm_dist_quantile(&b, 0.5), 0.0);
	assert_close(prsm_dist_halfwidth(&b), 0.5 - prsm_dist_quantile(&b, 0.5), 1e-15);
	const prsm_dist *one = &cases[N_CASES - 2];
	assert_close(prsm_dist_center(one), 1.0, 1e-15);
	assert_close(prsm_dist_halfwidth(one), 0.7, 1e-15);
}

/* The inlined AS 241 normal quantile gives GSL's doubles exactly, in the central region, the
 * middle and the far tails (p down to 1e-300), and the ends; and it inverts the CDF. */
static void test_normal_quantile_matches_gsl(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(20261125, 7);
	assert_non_null(r);
	for (long i = 0; i < 1000000; i++) {
		double p;
		switch (i % 4) {
		case 0: p = gsl_rng_uniform_pos(r); break;                          /* mostly central */
		case 1: p = 0.075 * gsl_rng_uniform_pos(r); break;                  /* the middle region */
		case 2: p = 1.0 - 0.075 * gsl_rng_uniform_pos(r); break;            /* its mirror */
		default: p = pow(10.0, -300.0 * gsl_rng_uniform_pos(r)); break;     /* tails to 1e-300 */
		}
		const double a = prsm_normal_quantile(p), b = gsl_cdf_ugaussian_Pinv(p);
		if (memcmp(&a, &b, sizeof a) != 0)
			fail_msg("p = %.17g: %.17g against GSL's %.17g", p, a, b);
	}
	gsl_rng_free(r);
	const double edges[] = {0.0, 1.0, 0.075, 0.925, 0.5, 0.5 - 0.425, 0.5 + 0.425, exp(-25.0), 1e-320};
	for (size_t k = 0; k < sizeof edges / sizeof edges[0]; k++) {
		const double a = prsm_normal_quantile(edges[k]), b = gsl_cdf_ugaussian_Pinv(edges[k]);
		assert_memory_equal(&a, &b, sizeof a);
	}
	/* an independent check: Phi(quantile(p)) = p */
	for (double p = 1e-12; p < 1.0; p = p < 0.5 ? p * 3.7 : 1.0 - (1.0 - p) / 3.7)
		assert_true(fabs(gsl_cdf_ugaussian_P(prsm_normal_quantile(p)) - p) <= 1e-14 * fmin(p, 1.0 - p) + 1e-16);
}

/* The batch quantile is prsm_dist_quantile value for value, bit for bit, for every kind: with
 * strides, in place, at the ends (0, 1, NaN) and in the normal's three regions. */
static void test_quantile_n_matches(void **state)
{
	(void)state;
	enum { N = 4099 };
	static double u[2 * N], x[3 * N], w[2 * N];
	gsl_rng *r = prsm_rng_alloc(20261126, 3);
	assert_non_null(r);
	for (size_t k = 0; k < N; k++) {
		double v;
		switch (k % 5) {
		case 0: v = gsl_rng_uniform_pos(r); break;
		case 1: v = 0.075 * gsl_rng_uniform_pos(r); break;
		case 2: v = 1.0 - 0.075 * gsl_rng_uniform_pos(r); break;
		case 3: v = pow(10.0, -300.0 * gsl_rng_uniform_pos(r)); break;
		default: v = 0.5 + 0.425 * (2.0 * gsl_rng_uniform_pos(r) - 1.0); break;
		}
		u[2 * k] = v;
		u[2 * k + 1] = -1.0; /* the other column of a two-column block: never read */
	}
	const double ends[] = {0.0, 1.0, NAN, -0.5, 1.5, 0.5, 0.075, 0.925, 0.5 - 0.425, 0.5 + 0.425, 1e-320};
	for (size_t k = 0; k < sizeof ends / sizeof ends[0]; k++)
		u[2 * k] = ends[k];
	gsl_rng_free(r);
	for (size_t c = 0; c < N_CASES; c++) {
		const prsm_dist *d = &cases[c];
		prsm_dist_quantile_n(d, u, 2, x, 3, N);
		for (size_t k = 0; k < N; k++) {
			const double a = x[3 * k], b = prsm_dist_quantile(d, u[2 * k]);
			if (memcmp(&a, &b, sizeof a) != 0)
				fail_msg("case %zu, u = %.17g: %.17g against %.17g", c, u[2 * k], a, b);
		}
		memcpy(w, u, sizeof w);
		prsm_dist_quantile_n(d, w, 2, w, 2, N); /* in place, as the engine's Saltelli rows */
		for (size_t k = 0; k < N; k++) {
			assert_memory_equal(&w[2 * k], &x[3 * k], sizeof w[0]);
			assert_true(w[2 * k + 1] == -1.0);
		}
	}
}

/* Probabilities for the batch kernels' tests: every region of the normal and the uniform, the
 * doubles either side of the central region's ends (|u - 1/2| = 0.425), the ends of (0, 1) and
 * beyond, NaN, infinities, subnormals and signed zeros, the engine's U_MIN and U_MAX. */
static double kernel_probability(gsl_rng *r, size_t k)
{
	static const double special[] = {0.0, -0.0, 1.0, NAN, INFINITY, -INFINITY, -0.5, 1.5, 0x1p-53, 1.0 - 0x1p-53,
	                                  0x1p-1074, DBL_MIN, 0.5, 0.075, 0.925, 0.5 - 0.425, 0.5 + 0.425, 1e-300,
	                                  0x1p-1022, 1.0 - 0x1p-52};
	const size_t ns = sizeof special / sizeof special[0];
	switch (k % 9) {
	case 0: return special[(k / 9) % ns];
	case 1: return nextafter(0.5 - 0.425, (k / 9) % 2 ? 0.0 : 1.0);
	case 2: return nextafter(0.5 + 0.425, (k / 9) % 2 ? 0.0 : 1.0);
	case 3: return 0.075 * gsl_rng_uniform_pos(r);
	case 4: return 1.0 - 0.075 * gsl_rng_uniform_pos(r);
	case 5: return pow(10.0, -300.0 * gsl_rng_uniform_pos(r));
	case 6: return 1.0 - pow(2.0, -53.0 * gsl_rng_uniform_pos(r));
	default: return gsl_rng_uniform_pos(r);
	}
}

/* The chunked kernels of the batch quantile (the normal's and the uniform's vector loops and
 * their scalar fix-ups, the Rayleigh written out), in the baseline and the AVX2 builds, give
 * prsm_dist_quantile's bits: many probabilities in every region, columns of every length
 * around the chunk's 64, strided and in place. */
static void test_quantile_n_kernels(void **state)
{
	(void)state;
	enum { N = 100003 };
	static double u[3 * N], x[2 * N], w[3 * N];
	static const prsm_dist kinds[] = {
		D2(PRSM_DIST_NORMAL, 2.385, 0.713), D2(PRSM_DIST_NORMAL, -0.0, 1.0), D2(PRSM_DIST_NORMAL, 1e6, 1e-9),
		D2(PRSM_DIST_NORMAL, -3.5, 250.0), D2(PRSM_DIST_UNIFORM, -1.7, 3.1), D2(PRSM_DIST_UNIFORM, -0.0, 1e-3),
		D2(PRSM_DIST_UNIFORM, -5.0, 5.0), D2(PRSM_DIST_UNIFORM, 1e9, 1e9 + 1.0), D1(PRSM_DIST_RAYLEIGH, 2.5),
		D1(PRSM_DIST_RAYLEIGH, 3e-4),
	};
	gsl_rng *r = prsm_rng_alloc(20261126, 19);
	assert_non_null(r);
	for (size_t k = 0; k < N; k++)
		u[3 * k] = kernel_probability(r, k);
	gsl_rng_free(r);
	static const size_t lengths[] = {0, 1, 3, 4, 5, 63, 64, 65, 127, 128, 129, 1000, N};
	for (int allow = 0; allow < 2; allow++) {
		prsm_simd_allow_avx2(allow);
		for (size_t c = 0; c < sizeof kinds / sizeof kinds[0]; c++) {
			const prsm_dist *d = &kinds[c];
			for (size_t l = 0; l < sizeof lengths / sizeof lengths[0]; l++) {
				const size_t n = lengths[l], off = (l * 7) % 5; /* the column starts anywhere */
				const size_t m = n + off > N ? N - off : n;
				for (size_t k = 0; k < 2 * N; k++)
					x[k] = -7.0;
				prsm_dist_quantile_n(d, u + 3 * off, 3, x, 2, m);
				for (size_t k = 0; k < m; k++) {
					const double a = x[2 * k], b = prsm_dist_quantile(d, u[3 * (off + k)]);
					if (memcmp(&a, &b, sizeof a) != 0)
						fail_msg("build %d, %s(%g, %g), u = %a: %a against %a", allow, prsm_dist_name(d->kind),
						         d->p[0], d->p[1], u[3 * (off + k)], a, b);
					assert_true(x[2 * k + 1] == -7.0);
				}
				assert_true(x[2 * m] == -7.0); /* nothing past the column */
				/* in place, as the engine's Saltelli rows (the AVX2 build reads each group of
				 * four values before it writes them) */
				memcpy(w, u, sizeof w);
				prsm_dist_quantile_n(d, w + 3 * off, 3, w + 3 * off, 3, m);
				for (size_t k = 0; k < m; k++)
					assert_memory_equal(&w[3 * (off + k)], &x[2 * k], sizeof x[0]);
				if (off + m < N) /* nothing past the column */
					assert_memory_equal(&w[3 * (off + m)], &u[3 * (off + m)], sizeof u[0]);
			}
		}
	}
	prsm_simd_allow_avx2(1);
}

/* The Rayleigh quantile, written out, is GSL's gsl_cdf_rayleigh_Pinv bit for bit over the whole
 * of (0, 1) and both tails, for scales from 1e-6 to 1e6. */
static void test_rayleigh_matches_gsl(void **state)
{
	(void)state;
	static const double sigmas[] = {1e-6, 3e-4, 0.7, 1.0, 1.9, 2.5, 3.0, 17.3, 1e6};
	gsl_rng *r = prsm_rng_alloc(20261126, 23);
	assert_non_null(r);
	for (size_t s = 0; s < sizeof sigmas / sizeof sigmas[0]; s++) {
		const prsm_dist d = D1(PRSM_DIST_RAYLEIGH, sigmas[s]);
		for (long i = 0; i < 200000; i++) {
			double p = kernel_probability(r, (size_t)i);
			if (!(p > 0.0 && p < 1.0))
				continue;
			const double a = prsm_dist_quantile(&d, p), b = gsl_cdf_rayleigh_Pinv(p, sigmas[s]);
			double c;
			prsm_dist_quantile_n(&d, &p, 1, &c, 1, 1);
			if (memcmp(&a, &b, sizeof a) != 0 || memcmp(&c, &b, sizeof c) != 0)
				fail_msg("sigma %g, p = %a: %a and %a against GSL's %a", sigmas[s], p, a, c, b);
		}
	}
	gsl_rng_free(r);
}

static void test_from_tolerance(void **state)
{
	(void)state;
	prsm_dist d;
	memset(&d, 0xff, sizeof d);
	prsm_dist_from_tolerance(&d, 12.5, 0.03, 1.33);
	assert_int_equal((int)d.kind, PRSM_DIST_NORMAL);
	assert_close(d.p[0], 12.5, 0.0);
	assert_close(d.p[1], 0.03 / (3.0 * 1.33), 1e-17);
	assert_close(prsm_dist_sd(&d), 0.03 / 3.99, 1e-17);
	assert_close(prsm_dist_halfwidth(&d), 0.03 / 1.33, 1e-16);
	assert_int_equal(prsm_dist_check(&d, NULL, 0), 0);

	char msg[PRSM_ERROR_MESSAGE_MAX];
	prsm_dist_from_tolerance(&d, 12.5, 0.0, 1.33);
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
	assert_non_null(strstr(msg, "sd"));
	prsm_dist_from_tolerance(&d, 12.5, 0.03, 0.0);
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
	prsm_dist_from_tolerance(&d, 12.5, 0.03, -1.33);
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
	prsm_dist_from_tolerance(&d, 12.5, -0.03, 1.33);
	assert_int_equal(prsm_dist_check(&d, msg, sizeof msg), PRSM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_all_cases_valid),
		cmocka_unit_test(test_sample_moments),
		cmocka_unit_test(test_exact_moments_against_integration),
		cmocka_unit_test(test_exact_moments_closed_forms),
		cmocka_unit_test(test_skewed_closed_forms),
		cmocka_unit_test(test_cdf_inverts_quantile),
		cmocka_unit_test(test_known_quantiles),
		cmocka_unit_test(test_skewed_known_quantiles),
		cmocka_unit_test(test_skewed_shape_range),
		cmocka_unit_test(test_histogram),
		cmocka_unit_test(test_histogram_set_rejects),
		cmocka_unit_test(test_param_defaults),
		cmocka_unit_test(test_narrow_window),
		cmocka_unit_test(test_check_rejects),
		cmocka_unit_test(test_names),
		cmocka_unit_test(test_center_halfwidth),
		cmocka_unit_test(test_from_tolerance),
		cmocka_unit_test(test_normal_quantile_matches_gsl),
		cmocka_unit_test(test_quantile_n_matches),
		cmocka_unit_test(test_quantile_n_kernels),
		cmocka_unit_test(test_rayleigh_matches_gsl),
	};
	return cmocka_run_group_tests(tests, setup_histograms, NULL);
}
