/*
 * test_sens.c: sensitivity analysis of mc/sens.h against reference/benchmarks.md — SRC of the
 * linear stack LS-1 (variance shares 25/54, 16/54, 9/54, 4/54, R^2 = 1), SRRC against SRC on a
 * monotone non-linear response, average ranks on a hand-checkable tied sample, Sobol' indices
 * of the Ishigami function, the G-function and LS-1 within multiples of their bootstrap
 * standard errors, reproducible bootstraps and every error path.
 */
#include "test_support.h"

#include "mc/sens.h"
#include "util/clock.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <stdlib.h>
#include <string.h>

/* LS-1: Y = X1 + X2 - X3 - X4, X_i ~ N(nominal_i, (t_i/3)^2); variance shares t_i^2 / 54e-4. */
static const double ls1_nominal[4] = {30.0, 20.0, 24.9, 25.0};
static const double ls1_tol[4] = {0.05, 0.04, 0.03, 0.02};
static const double ls1_sign[4] = {1.0, 1.0, -1.0, -1.0};
static const double ls1_share[4] = {25.0 / 54.0, 16.0 / 54.0, 9.0 / 54.0, 4.0 / 54.0};

static double ls1(const double *x)
{
	return x[0] + x[1] - x[2] - x[3];
}

static void ls1_draw(double *x, gsl_rng *r)
{
	for (int k = 0; k < 4; k++)
		x[k] = ls1_nominal[k] + gsl_ran_gaussian(r, ls1_tol[k] / 3.0);
}

/* For Y linear in independent inputs, SRC_j^2 = b_j^2 s_j^2 / s_Y^2 with sample variances; to
 * first order in their sampling errors (Var(s^2)/sigma^4 = 2/n, sample covariances
 * N(0, w_k w_l / n)) the share w_j has SE 2 w_j sqrt((1 - w_j)/n). */
static double share_se(double w, size_t n)
{
	return 2.0 * w * sqrt((1.0 - w) / (double)n);
}

static void test_src_linear_stack(void **state)
{
	(void)state;
	const size_t n = 20000, d = 4;
	double *x = malloc(n * (d + 1) * sizeof *x), *x5 = malloc(n * (d + 1) * sizeof *x5), *y = malloc(n * sizeof *y);
	assert_true(x != NULL && x5 != NULL && y != NULL);
	gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(r, 4455709);
	for (size_t i = 0; i < n; i++) {
		ls1_draw(x + i * d, r);
		y[i] = ls1(x + i * d);
	}
	gsl_rng_free(r);
	double coef[5], r2;
	int constant[5];
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, n, d, y, 0, &err), 0);
	assert_true(r2 > 0.999999);
	double worst = 0.0;
	for (size_t j = 0; j < d; j++) {
		assert_int_equal(constant[j], 0);
		assert_true(coef[j] * ls1_sign[j] > 0.0);
		const double se = share_se(ls1_share[j], n);
		assert_close(coef[j] * coef[j], ls1_share[j], 5.0 * se);
		worst = fmax(worst, fabs(coef[j] * coef[j] - ls1_share[j]) / se);
	}
	print_message("LS-1 SRC n=%zu: R^2 = 1 - %.2g, worst share off by %.2f SE\n", n, 1.0 - r2, worst);

	/* a fifth, constant column: flagged, coefficient 0, the others unchanged bit for bit */
	for (size_t i = 0; i < n; i++) {
		memcpy(x5 + i * (d + 1), x + i * d, d * sizeof *x);
		x5[i * (d + 1) + d] = 2.385;
	}
	double coef5[5], r25;
	assert_int_equal(prsm_sens_src(coef5, &r25, constant, x5, n, d + 1, y, 0, &err), 0);
	assert_int_equal(constant[d], 1);
	assert_true(coef5[d] == 0.0);
	assert_memory_equal(coef5, coef, d * sizeof *coef);
	assert_true(r25 == r2);
	/* constant may be NULL */
	assert_int_equal(prsm_sens_src(coef5, &r25, NULL, x5, n, d + 1, y, 1, &err), 0);
	assert_true(coef5[d] == 0.0 && r25 > 0.9 && r25 <= 1.0);
	free(y);
	free(x5);
	free(x);
}

/* y = exp(x1) + 0.1 x2: monotone in both inputs but far from linear in x1, so the rank
 * regression explains more than the linear one. */
static void test_srrc_monotone_nonlinear(void **state)
{
	(void)state;
	const size_t n = 5000, d = 2;
	double *x = malloc(n * d * sizeof *x), *y = malloc(n * sizeof *y);
	assert_true(x != NULL && y != NULL);
	gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(r, 2718);
	for (size_t i = 0; i < n; i++) {
		x[i * d] = gsl_ran_gaussian(r, 1.0);
		x[i * d + 1] = gsl_ran_gaussian(r, 1.0);
		y[i] = exp(x[i * d]) + 0.1 * x[i * d + 1];
	}
	gsl_rng_free(r);
	double src[2], srrc[2], r2_src, r2_srrc;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_sens_src(src, &r2_src, NULL, x, n, d, y, 0, &err), 0);
	assert_int_equal(prsm_sens_src(srrc, &r2_srrc, NULL, x, n, d, y, 1, &err), 0);
	print_message("exp(x1) + 0.1 x2: R^2 SRC %.4f, SRRC %.4f; SRC (%.3f, %.3f), SRRC (%.3f, %.3f)\n", r2_src,
	              r2_srrc, src[0], src[1], srrc[0], srrc[1]);
	assert_true(r2_srrc > r2_src);
	assert_true(src[0] > src[1] && src[1] > 0.0 && srrc[0] > srrc[1] && srrc[1] > 0.0);
	free(y);
	free(x);
}

/* Average ranks of a tied sample by hand. x = (2.385, 1.5, 2.385, 0.75, 4.0) has ranks
 * (3.5, 2, 3.5, 1, 5); y = (0.3, 0.1, 0.5, 0.2, 0.4) has ranks (3, 1, 5, 2, 4). Deviations from
 * the mean rank 3: (0.5, -1, 0.5, -2, 2) and (0, -2, 2, -1, 1): sum of products 7, of squares
 * 9.5 and 10. With one input the standardized slope is Pearson's r = 7/sqrt(95), R^2 = 49/95. */
static void test_srrc_ties_by_hand(void **state)
{
	(void)state;
	const double x[5] = {2.385, 1.5, 2.385, 0.75, 4.0}, y[5] = {0.3, 0.1, 0.5, 0.2, 0.4};
	double coef, r2;
	int constant;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_sens_src(&coef, &r2, &constant, x, 5, 1, y, 1, &err), 0);
	assert_close(coef, 7.0 / sqrt(95.0), 1e-14);
	assert_close(r2, 49.0 / 95.0, 1e-14);
	assert_int_equal(constant, 0);
	/* y a decreasing function of x, ties and all: SRRC exactly -1 with R^2 = 1 */
	double ydec[5];
	for (int i = 0; i < 5; i++)
		ydec[i] = -x[i] * x[i] * x[i];
	assert_int_equal(prsm_sens_src(&coef, &r2, &constant, x, 5, 1, ydec, 1, &err), 0);
	assert_close(coef, -1.0, 1e-14);
	assert_close(r2, 1.0, 1e-14);
}

static void test_src_errors(void **state)
{
	(void)state;
	double x[12] = {1.25, 2.385, 0.5, 3.0, 1.75, 0.125, 2.0, 4.5, 3.25, 0.875, 1.0, 2.625};
	double y[6] = {0.1, 0.7, 0.2, 0.9, 0.4, 0.35};
	double coef[2], r2;
	int constant[2];
	prsm_error err = PRSM_ERROR_INIT;
	/* n = 3 rows of d = 2 inputs: too few */
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 3, 2, y, 0, &err), PRSM_EINVAL);
	assert_int_equal(err.code, PRSM_EINVAL);
	assert_non_null(strstr(err.message, "at least 4"));
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 0, y, 0, &err), PRSM_EINVAL);
	x[7] = NAN;
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 2, y, 0, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "input 1 of sample 3"));
	x[7] = 4.5;
	y[5] = INFINITY;
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 2, y, 1, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "output sample 5"));
	/* a constant output: nothing to share out, NAN (not an error) */
	for (int i = 0; i < 6; i++)
		y[i] = 2.385;
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 2, y, 0, &err), 0);
	assert_true(isnan(coef[0]) && isnan(coef[1]) && isnan(r2));
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 2, y, 1, &err), 0);
	assert_true(isnan(coef[0]) && isnan(r2));
	/* every input constant: coefficients 0, R^2 = 0 */
	for (int i = 0; i < 12; i++)
		x[i] = 0.5;
	y[0] = 0.3;
	assert_int_equal(prsm_sens_src(coef, &r2, constant, x, 6, 2, y, 0, &err), 0);
	assert_true(coef[0] == 0.0 && coef[1] == 0.0 && r2 == 0.0 && constant[0] && constant[1]);
}

/* ---- Sobol' indices -------------------------------------------------------------------- */

typedef double (*model_fn)(const double *x);
typedef void (*draw_fn)(double *x, gsl_rng *r);

/* Saltelli design with plain random A and B: yA, yB (n) and yAB (d x n). */
static void saltelli(double *yA, double *yB, double *yAB, size_t n, size_t d, model_fn f, draw_fn draw,
                     gsl_rng *r)
{
	double a[16], b[16], ab[16];
	assert_true(d <= 16);
	for (size_t j = 0; j < n; j++) {
		draw(a, r);
		draw(b, r);
		yA[j] = f(a);
		yB[j] = f(b);
		for (size_t i = 0; i < d; i++) {
			memcpy(ab, a, d * sizeof *a);
			ab[i] = b[i];
			yAB[i * n + j] = f(ab);
		}
	}
}

/* Estimate the indices of f and compare them with the exact ones: every index within
 * 4.5 bootstrap SE, and the 95 % bootstrap intervals containing the exact value for at least
 * three quarters of the 2d indices. */
static void check_sobol(const char *name, model_fn f, draw_fn draw, size_t d, const double *first,
                        const double *total, size_t n, size_t nboot, unsigned long seed)
{
	double *yA = malloc(n * sizeof *yA), *yB = malloc(n * sizeof *yB), *yAB = malloc(n * d * sizeof *yAB);
	prsm_sobol_index *idx = malloc(d * sizeof *idx);
	assert_true(yA != NULL && yB != NULL && yAB != NULL && idx != NULL);
	gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(r, seed);
	saltelli(yA, yB, yAB, n, d, f, draw, r);
	double V;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_sens_sobol(idx, &V, yA, yB, yAB, n, d, nboot, r, &err), 0);
	gsl_rng_free(r);
	double worst = 0.0;
	size_t covered = 0;
	for (size_t i = 0; i < d; i++) {
		assert_true(idx[i].first_se > 0.0 && idx[i].total_se > 0.0);
		assert_true(idx[i].first_low <= idx[i].first_high && idx[i].total_low <= idx[i].total_high);
		assert_close(idx[i].first, first[i], 4.5 * idx[i].first_se);
		assert_close(idx[i].total, total[i], 4.5 * idx[i].total_se);
		worst = fmax(worst, fabs(idx[i].first - first[i]) / idx[i].first_se);
		worst = fmax(worst, fabs(idx[i].total - total[i]) / idx[i].total_se);
		covered += idx[i].first_low <= first[i] && first[i] <= idx[i].first_high;
		covered += idx[i].total_low <= total[i] && total[i] <= idx[i].total_high;
	}
	print_message("%s n=%zu nboot=%zu: worst index %.2f bootstrap SE off, %zu of %zu intervals cover\n", name, n,
	              nboot, worst, covered, 2 * d);
	for (size_t i = 0; i < d; i++)
		print_message("  x%zu: S %.5f +- %.5f (exact %.5f)  ST %.5f +- %.5f (exact %.5f)\n", i + 1, idx[i].first,
		              idx[i].first_se, first[i], idx[i].total, idx[i].total_se, total[i]);
	assert_true(4 * covered >= 3 * 2 * d);
	free(idx);
	free(yAB);
	free(yB);
	free(yA);
}

static double ishigami(const double *x)
{
	const double s2 = sin(x[1]), x3 = x[2] * x[2];
	return sin(x[0]) + 7.0 * s2 * s2 + 0.1 * x3 * x3 * sin(x[0]);
}

static void ishigami_draw(double *x, gsl_rng *r)
{
	for (int k = 0; k < 3; k++)
		x[k] = gsl_ran_flat(r, -M_PI, M_PI);
}

static void test_sobol_ishigami(void **state)
{
	(void)state;
	const double first[3] = {0.31390519114781146, 0.4424111447900409, 0.0};
	const double total[3] = {0.5575888552099592, 0.4424111447900409, 0.2436836640621477};
	check_sobol("Ishigami", ishigami, ishigami_draw, 3, first, total, 8192, 200, 1990);
}

static const double g_a[8] = {0.0, 1.0, 4.5, 9.0, 99.0, 99.0, 99.0, 99.0};

static double g_function(const double *x)
{
	double g = 1.0;
	for (int k = 0; k < 8; k++)
		g *= (fabs(4.0 * x[k] - 2.0) + g_a[k]) / (1.0 + g_a[k]);
	return g;
}

static void g_draw(double *x, gsl_rng *r)
{
	for (int k = 0; k < 8; k++)
		x[k] = gsl_rng_uniform(r);
}

static void test_sobol_g_function(void **state)
{
	(void)state;
	/* exact: V_i = 1/(3 (1 + a_i)^2), V = prod(1 + V_i) - 1, S_i = V_i/V,
	 * ST_i = V_i prod_{j != i}(1 + V_j)/V */
	double Vi[8], prod = 1.0, first[8], total[8];
	for (int k = 0; k < 8; k++) {
		Vi[k] = 1.0 / (3.0 * (1.0 + g_a[k]) * (1.0 + g_a[k]));
		prod *= 1.0 + Vi[k];
	}
	const double V = prod - 1.0;
	assert_close(V, 0.4654244319022067, 1e-15);
	for (int k = 0; k < 8; k++) {
		first[k] = Vi[k] / V;
		total[k] = Vi[k] * (prod / (1.0 + Vi[k])) / V;
	}
	/* the rounded table of benchmarks.md */
	const double table_first[5] = {0.716192, 0.179048, 0.023676, 0.007162, 0.000072};
	const double table_total[5] = {0.787144, 0.242198, 0.034317, 0.010460, 0.000105};
	for (int k = 0; k < 5; k++) {
		assert_close(first[k], table_first[k], 5e-7);
		assert_close(total[k], table_total[k], 5e-7);
	}
	check_sobol("G-function", g_function, g_draw, 8, first, total, 8192, 200, 1996);
}

static void test_sobol_linear_stack(void **state)
{
	(void)state;
	/* additive model: S_i = ST_i = the variance shares */
	check_sobol("LS-1", ls1, ls1_draw, 4, ls1_share, ls1_share, 4096, 200, 54);
}

/* Same design and generator seed: bit-identical indices; nboot = 0 skips the bootstrap. */
static void test_sobol_reproducible(void **state)
{
	(void)state;
	const size_t n = 1000, d = 3;
	double *yA = malloc(n * sizeof *yA), *yB = malloc(n * sizeof *yB), *yAB = malloc(n * d * sizeof *yAB);
	assert_true(yA != NULL && yB != NULL && yAB != NULL);
	gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
	gsl_rng_set(r, 11);
	saltelli(yA, yB, yAB, n, d, ishigami, ishigami_draw, r);
	prsm_sobol_index one[3], two[3], none[3];
	double V1, V2, V0;
	prsm_error err = PRSM_ERROR_INIT;
	memset(one, 0, sizeof one);
	memset(two, 0xff, sizeof two);
	gsl_rng_set(r, 12345);
	assert_int_equal(prsm_sens_sobol(one, &V1, yA, yB, yAB, n, d, 50, r, &err), 0);
	gsl_rng_set(r, 12345);
	assert_int_equal(prsm_sens_sobol(two, &V2, yA, yB, yAB, n, d, 50, r, &err), 0);
	assert_memory_equal(one, two, sizeof one);
	assert_true(V1 == V2);
	assert_int_equal(prsm_sens_sobol(none, &V0, yA, yB, yAB, n, d, 0, NULL, &err), 0);
	assert_true(V0 == V1);
	/* the bootstrap stops at a raised cancel flag or a deadline already past: the indices as
	 * without a bootstrap, no errors or intervals, 0 resamples done; an unreached deadline and a
	 * lowered flag change nothing (bit for bit) */
	prsm_sobol_index stopped[3], free_run[3];
	size_t done = 99;
	prsm_cancel_flag flag = 0;
	prsm_cancel_set(&flag, 1);
	assert_int_equal(prsm_sens_sobol_until(stopped, NULL, yA, yB, yAB, n, d, 50, r, &flag, 0.0, &done, &err), 0);
	assert_int_equal(done, 0);
	for (size_t i = 0; i < d; i++) {
		assert_true(stopped[i].first == one[i].first && stopped[i].total == one[i].total);
		assert_true(isnan(stopped[i].first_se) && isnan(stopped[i].total_low));
	}
	done = 99;
	assert_int_equal(prsm_sens_sobol_until(stopped, NULL, yA, yB, yAB, n, d, 50, r, NULL, prsm_clock_seconds() - 1.0,
	                                       &done, &err), 0);
	assert_int_equal(done, 0);
	assert_true(isnan(stopped[0].first_se));
	prsm_cancel_set(&flag, 0);
	gsl_rng_set(r, 12345);
	assert_int_equal(prsm_sens_sobol_until(free_run, NULL, yA, yB, yAB, n, d, 50, r, &flag,
	                                       prsm_clock_seconds() + 3600.0, &done, &err), 0);
	assert_int_equal(done, 50);
	assert_memory_equal(free_run, one, sizeof one);
	for (size_t i = 0; i < d; i++) {
		assert_true(none[i].first == one[i].first && none[i].total == one[i].total);
		assert_true(isnan(none[i].first_se) && isnan(none[i].total_high));
	}
	/* V is the variance (divisor 2n - 1) of the 2n values of A and B */
	double mean = 0.0, ss = 0.0;
	for (size_t j = 0; j < n; j++)
		mean += (yA[j] + yB[j]) / (2.0 * (double)n);
	for (size_t j = 0; j < n; j++)
		ss += (yA[j] - mean) * (yA[j] - mean) + (yB[j] - mean) * (yB[j] - mean);
	assert_close(V1, ss / (2.0 * (double)n - 1.0), 1e-12 * V1);
	/* variance_out may be NULL */
	assert_int_equal(prsm_sens_sobol(none, NULL, yA, yB, yAB, n, d, 0, NULL, &err), 0);
	/* centring: adding 1e4 to every output leaves the indices unchanged to rounding */
	for (size_t j = 0; j < n; j++) {
		yA[j] += 1e4;
		yB[j] += 1e4;
		for (size_t i = 0; i < d; i++)
			yAB[i * n + j] += 1e4;
	}
	assert_int_equal(prsm_sens_sobol(two, NULL, yA, yB, yAB, n, d, 0, NULL, &err), 0);
	for (size_t i = 0; i < d; i++) {
		assert_close(two[i].first, none[i].first, 1e-8);
		assert_close(two[i].total, none[i].total, 1e-8);
	}
	gsl_rng_free(r);
	free(yAB);
	free(yB);
	free(yA);
}

static void test_sobol_errors(void **state)
{
	(void)state;
	double yA[4] = {1.25, 2.385, 0.5, 3.0}, yB[4] = {0.75, 1.5, 2.125, 0.25};
	double yAB[8] = {1.0, 2.0, 0.625, 2.875, 0.5, 1.75, 2.25, 0.375};
	prsm_sobol_index idx[2];
	prsm_error err = PRSM_ERROR_INIT;
	gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 1, 2, 0, NULL, &err), PRSM_EINVAL);
	assert_int_equal(err.code, PRSM_EINVAL);
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 0, 0, NULL, &err), PRSM_EINVAL);
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 2, 1, r, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "at least 2 resamples"));
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 2, 10, NULL, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "generator"));
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 2, SIZE_MAX / 2, r, &err), PRSM_EINVAL);
	yAB[6] = NAN;
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 2, 10, r, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "row 2 of the A_B sample of input 1"));
	yAB[6] = 2.25;
	yB[3] = -INFINITY;
	assert_int_equal(prsm_sens_sobol(idx, NULL, yA, yB, yAB, 4, 2, 10, r, &err), PRSM_EINVAL);
	/* a constant output: every index NAN, not an error */
	for (int j = 0; j < 4; j++)
		yA[j] = yB[j] = yAB[j] = yAB[4 + j] = 2.385;
	double V;
	assert_int_equal(prsm_sens_sobol(idx, &V, yA, yB, yAB, 4, 2, 10, r, &err), 0);
	assert_true(V == 0.0 && isnan(idx[0].first) && isnan(idx[1].total) && isnan(idx[0].first_se) &&
	            isnan(idx[1].total_low));
	gsl_rng_free(r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_src_linear_stack),
		cmocka_unit_test(test_srrc_monotone_nonlinear),
		cmocka_unit_test(test_srrc_ties_by_hand),
		cmocka_unit_test(test_src_errors),
		cmocka_unit_test(test_sobol_ishigami),
		cmocka_unit_test(test_sobol_g_function),
		cmocka_unit_test(test_sobol_linear_stack),
		cmocka_unit_test(test_sobol_reproducible),
		cmocka_unit_test(test_sobol_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
