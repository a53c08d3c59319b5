/*
 * test_dist.c: the tolerance distributions of mc/dist.h — for every kind, with high-entropy
 * parameters: moments of samples drawn through the quantile against the exact mean and sd,
 * those exact moments against numerical integration of the density (GSL QUADPACK), the CDF
 * inverting the quantile, every error path of prsm_dist_check, names, stack figures and the
 * {tol, cpk} shorthand.
 */
#include "test_support.h"

#include "mc/dist.h"
#include "util/error.h"
#include "util/rng.h"

#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>

#define D1(k, a) {k, {a, 0, 0, 0}}
#define D2(k, a, b) {k, {a, b, 0, 0}}
#define D3(k, a, b, c) {k, {a, b, c, 0}}
#define D4(k, a, b, c, e) {k, {a, b, c, e}}

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
};
#define N_CASES (sizeof cases / sizeof cases[0])

static double support_lower(const prsm_dist *d)
{
	switch (d->kind) {
	case PRSM_DIST_TRUNCNORMAL:
		return d->p[2];
	case PRSM_DIST_UNIFORM:
	case PRSM_DIST_TRIANGULAR:
		return d->p[0];
	case PRSM_DIST_LOGNORMAL:
	case PRSM_DIST_RAYLEIGH:
		return 0.0;
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
		return d->p[1];
	case PRSM_DIST_TRIANGULAR:
		return d->p[2];
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
	double cuts[3] = {lo, hi, hi};
	int ncuts = 2;
	if (d->kind == PRSM_DIST_TRIANGULAR) {
		cuts[1] = d->p[1];
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
	const char *names[] = {"normal", "truncnormal", "uniform", "triangular", "lognormal", "rayleigh"};
	for (int k = 0; k < PRSM_DIST_KIND_COUNT; k++) {
		prsm_dist_kind out = PRSM_DIST_RAYLEIGH;
		assert_string_equal(prsm_dist_name((prsm_dist_kind)k), names[k]);
		assert_int_equal(prsm_dist_kind_parse(names[k], &out), 0);
		assert_int_equal((int)out, k);
	}
	prsm_dist_kind out = PRSM_DIST_UNIFORM;
	assert_int_equal(prsm_dist_kind_parse("Normal", &out), PRSM_ENOTFOUND);
	assert_int_equal(prsm_dist_kind_parse("gamma", &out), PRSM_ENOTFOUND);
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
		cmocka_unit_test(test_cdf_inverts_quantile),
		cmocka_unit_test(test_known_quantiles),
		cmocka_unit_test(test_narrow_window),
		cmocka_unit_test(test_check_rejects),
		cmocka_unit_test(test_names),
		cmocka_unit_test(test_center_halfwidth),
		cmocka_unit_test(test_from_tolerance),
		cmocka_unit_test(test_normal_quantile_matches_gsl),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
