/*
 * test_hertz.c: the Hertz ellipticity solve (docs/model/kinematics-efficiency-stiffness-life.md) by GSL's Brent solver, against the
 * bisection it replaced (kept here as an independent reference), the circular contact, the
 * small- and large-ellipticity limits, and the bearing-handbook coefficients of docs/model/kinematics-efficiency-stiffness-life.md.
 * GSL's error handler is left as it is (abort): the solver must never raise a GSL error.
 */
#include "test_support.h"

#include <gsl/gsl_sf_ellint.h>

#include "model/hertz.h"

/* F(kappa) written out independently of model/hertz.c (Harris). */
static double ref_curvature_difference(double kappa, double *K, double *E)
{
	const double e = sqrt(1.0 - 1.0 / (kappa * kappa));
	*K = gsl_sf_ellint_Kcomp(e, GSL_PREC_DOUBLE);
	*E = gsl_sf_ellint_Ecomp(e, GSL_PREC_DOUBLE);
	return ((kappa * kappa + 1.0) * (*E) - 2.0 * (*K)) / ((kappa * kappa - 1.0) * (*E));
}

/* The bisection prsm_hertz_coefficients used before GSL's Brent solver: ln kappa in
 * [0, ln 1e6] halved until the interval is 1e-15 max(1, hi), kappa at its midpoint. */
static double ref_bisection_kappa(double F)
{
	if (!(F > 1e-10))
		return 1.0;
	double K, E, lo = 0.0, hi = log(1e6);
	for (int i = 0; i < 200 && hi - lo > 1e-15 * fmax(1.0, hi); i++) {
		const double mid = 0.5 * (lo + hi);
		const double k = exp(mid);
		if (k <= 1.0 + 1e-12 || ref_curvature_difference(k, &K, &E) < F)
			lo = mid;
		else
			hi = mid;
	}
	return exp(0.5 * (lo + hi));
}

/* splitmix64: a fixed, well-mixed stream for the sample of curvature ratios */
static uint64_t splitmix64(uint64_t *s)
{
	uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
	return z ^ (z >> 31);
}

static double uniform01(uint64_t *s)
{
	return (double)(splitmix64(s) >> 11) * 0x1.0p-53;
}

/* How far the two solvers may disagree in ln kappa: both stop at an interval of about 1e-15
 * (1 + ln kappa), and F(kappa) itself is only computed to a few ulps, which moves its root by
 * about 1e-15 / F near the circle (cancellation in (kappa^2 + 1) E - 2 K) and by about
 * 1e-16 / (1 - F) near F = 1 (where dF/d ln kappa ~ 2 (1 - F)). */
static double allowed_ln_kappa_difference(double F, double kappa)
{
	return 4e-15 * (1.0 + log(kappa)) + 2e-15 / F + 2e-15 / (1.0 - F);
}

static void check_against_bisection(double F, double *max_rel, double *max_ratio)
{
	prsm_hertz h;
	assert_int_equal(prsm_hertz_coefficients(&h, F), 0);
	const double ref = ref_bisection_kappa(F);
	const double d = fabs(log(h.kappa) - log(ref));
	const double allowed = allowed_ln_kappa_difference(F, ref);
	if (!(d <= allowed)) {
		print_error("F = %.17g: kappa %.17g, bisection %.17g (|d ln kappa| %.3g > %.3g)\n", F,
		            h.kappa, ref, d, allowed);
		fail();
	}
	*max_rel = fmax(*max_rel, fabs(h.kappa - ref) / ref);
	*max_ratio = fmax(*max_ratio, d / allowed);
	/* K, E and the coefficients belong to the kappa returned */
	double K, E;
	if (h.kappa > 1.0) {
		ref_curvature_difference(h.kappa, &K, &E);
		assert_true(h.ellint_K == K && h.ellint_E == E);
	}
	assert_close(h.a_star, cbrt(2.0 * h.kappa * h.kappa * h.ellint_E / M_PI), 1e-15 * h.a_star);
	assert_close(h.b_star, cbrt(2.0 * h.ellint_E / (M_PI * h.kappa)), 1e-15 * h.b_star);
	assert_true(h.kappa >= 1.0 && h.a_star >= h.b_star);
}

/* 2000 curvature ratios k2/k1 log-uniform in [1, 1e4], and their extremes. */
static void test_brent_matches_bisection(void **state)
{
	(void)state;
	uint64_t seed = 0x5EED0023A7ull;
	double max_rel = 0.0, max_ratio = 0.0;
	for (int i = 0; i < 2000; i++) {
		const double ratio = exp(log(1e4) * uniform01(&seed));
		const double F = (ratio - 1.0) / (ratio + 1.0);
		check_against_bisection(F, &max_rel, &max_ratio);
	}
	print_message("2000 log-uniform ratios in [1, 1e4]: max |kappa - kappa_bisection| / kappa = %.3g, "
	              "max share of the allowed difference %.3g\n", max_rel, max_ratio);
	assert_true(max_rel < 1e-11);
	/* near the circle, where F(kappa) loses digits to cancellation, and the largest ratios */
	const double extra[] = {1.0 + 1e-9, 1.0 + 1e-8, 1.0 + 1e-7, 1.0 + 1e-6, 1.0 + 1e-5, 1.0 + 1e-4,
	                        1.001, 1e5, 1e6, 1e8, 1e10};
	max_rel = max_ratio = 0.0;
	for (size_t i = 0; i < sizeof extra / sizeof extra[0]; i++)
		check_against_bisection((extra[i] - 1.0) / (extra[i] + 1.0), &max_rel, &max_ratio);
	print_message("ratios 1 + 1e-9 .. 1e10: max relative difference %.3g, share of allowed %.3g\n",
	              max_rel, max_ratio);
	/* F at the double just below 1: kappa at its cap, as the bisection had it */
	double a = 0.0, b = 0.0;
	check_against_bisection(nextafter(1.0, 0.0), &a, &b);
	prsm_hertz h;
	assert_int_equal(prsm_hertz_coefficients(&h, nextafter(1.0, 0.0)), 0);
	assert_close(h.kappa, PRSM_HERTZ_KAPPA_MAX, 1e-9 * PRSM_HERTZ_KAPPA_MAX);
}

/* The solved kappa satisfies the equation it solves, to the rounding of F(kappa). */
static void test_residual(void **state)
{
	(void)state;
	uint64_t seed = 0xC0FFEEull;
	for (int i = 0; i < 500; i++) {
		const double ratio = exp(log(1e4) * uniform01(&seed));
		const double F = (ratio - 1.0) / (ratio + 1.0);
		if (!(F > 1e-6))
			continue;
		prsm_hertz h;
		double K, E;
		assert_int_equal(prsm_hertz_coefficients(&h, F), 0);
		const double Fk = ref_curvature_difference(h.kappa, &K, &E);
		/* |F(kappa) - F| within a few ulps of the terms, relative to (kappa^2 - 1) E */
		assert_close(Fk, F, 1e-15 + 2e-15 / (h.kappa * h.kappa - 1.0));
	}
}

/* Circular contact: F = 0 (and up to PRSM_HERTZ_CIRCLE_F) is kappa = 1 exactly, K = E = pi/2,
 * a* = b* = delta* = 1; just above it the solution joins continuously. */
static void test_circle(void **state)
{
	(void)state;
	const double Fs[] = {0.0, 1e-300, 1e-12, PRSM_HERTZ_CIRCLE_F};
	for (size_t i = 0; i < sizeof Fs / sizeof Fs[0]; i++) {
		prsm_hertz h;
		assert_int_equal(prsm_hertz_coefficients(&h, Fs[i]), 0);
		assert_true(h.kappa == 1.0);
		assert_true(h.ellint_K == M_PI / 2.0 && h.ellint_E == M_PI / 2.0);
		assert_close(h.a_star, 1.0, 1e-15);
		assert_close(h.b_star, 1.0, 1e-15);
		assert_close(h.delta_star, 1.0, 1e-15);
	}
	prsm_hertz h;
	assert_int_equal(prsm_hertz_coefficients(&h, 2.0 * PRSM_HERTZ_CIRCLE_F), 0);
	assert_close(h.kappa, 1.0, 1e-7);
	/* equal principal curvatures through prsm_hertz_solve: Hertz's spheres */
	const double R = 8.5, E0 = 206000.0, nu = 0.3, Q = 321.0;
	assert_int_equal(prsm_hertz_solve(&h, 2.0 / R, 2.0 / R, E0, nu, E0, nu, Q), 0);
	assert_true(h.kappa == 1.0);
	const double Reff = R / 2.0, Estar = E0 / (2.0 * (1.0 - nu * nu));
	const double a = cbrt(3.0 * Q * Reff / (4.0 * Estar));
	assert_close(h.a_mm, a, 1e-12 * a);
	assert_close(h.b_mm, a, 1e-12 * a);
}

/* The limits: near the circle F = (3/4)(kappa - 1) + O((kappa - 1)^2), so kappa - 1 ~ 4F/3;
 * for a long ellipse 1 - F ~ 2 (ln(4 kappa) - 1) / kappa^2 (K ~ ln 4 kappa, E ~ 1 + ...). */
static void test_limits(void **state)
{
	(void)state;
	const double small[] = {1e-5, 1e-4, 1e-3};
	for (size_t i = 0; i < sizeof small / sizeof small[0]; i++) {
		prsm_hertz h;
		assert_int_equal(prsm_hertz_coefficients(&h, small[i]), 0);
		assert_close(h.kappa - 1.0, 4.0 * small[i] / 3.0, 2.0 * small[i] * small[i]);
	}
	const double kappas[] = {300.0, 3000.0, 30000.0};
	for (size_t i = 0; i < sizeof kappas / sizeof kappas[0]; i++) {
		const double k = kappas[i];
		const double F = 1.0 - 2.0 * (log(4.0 * k) - 1.0) / (k * k);
		prsm_hertz h;
		assert_int_equal(prsm_hertz_coefficients(&h, F), 0);
		/* the next order, ~ln(kappa) / kappa^2, and F's own rounding (about 1e-16 / (1 - F)) */
		assert_close(h.kappa, k, k * (log(k) / (k * k) + 2e-16 / (1.0 - F)));
	}
	/* Hamrock and Brewe's kappa ~ (k2/k1)^(2/pi), within 4 % up to k2/k1 = 100 */
	for (double ratio = 1.5; ratio <= 100.0; ratio *= 1.7) {
		prsm_hertz h;
		assert_int_equal(prsm_hertz_coefficients(&h, (ratio - 1.0) / (ratio + 1.0)), 0);
		const double approx = pow(ratio, 2.0 / M_PI);
		assert_close(h.kappa, approx, 0.04 * approx);
	}
	/* kappa grows with F */
	double prev = 1.0;
	for (double F = 1e-3; F < 0.9999; F += 1e-3) {
		prsm_hertz h;
		assert_int_equal(prsm_hertz_coefficients(&h, F), 0);
		assert_true(h.kappa > prev);
		prev = h.kappa;
	}
}

/* docs/model/kinematics-efficiency-stiffness-life.md: a = C_a E0 (Q/sum rho)^(1/3), b = C_b ..., delta = C_delta E0^2 (sum rho Q^2)^(1/3),
 * E0 = (1.137e5 (1/E01 + 1/E02))^(1/3): F 0 -> C_a = C_b = 0.02363; 0.5 -> 0.03511, 0.01694,
 * 0.0002617; 0.9 -> 0.07305, 0.01089, 0.0001898 (to the handbook's 4 digits, 0.1 %). */
static void test_model_md_coefficients(void **state)
{
	(void)state;
	const double table[][4] = {{0.0, 0.02363, 0.02363, NAN},
	                           {0.5, 0.03511, 0.01694, 0.0002617},
	                           {0.9, 0.07305, 0.01089, 0.0001898}};
	const double E1 = 206000.0, nu1 = 0.3, E2 = 206000.0, nu2 = 0.3, Q = 700.0, sum = 0.41;
	const double E0 = cbrt(1.137e5 * ((1 - nu1 * nu1) / E1 + (1 - nu2 * nu2) / E2));
	for (int i = 0; i < 3; i++) {
		const double F = table[i][0];
		prsm_hertz h;
		assert_int_equal(prsm_hertz_solve(&h, sum * (1 - F) / 2, sum * (1 + F) / 2, E1, nu1, E2, nu2, Q), 0);
		const double s = E0 * cbrt(Q / sum);
		assert_close(h.a_mm / s, table[i][1], 1e-3 * table[i][1]);
		assert_close(h.b_mm / s, table[i][2], 1e-3 * table[i][2]);
		if (!isnan(table[i][3]))
			assert_close(h.delta_mm / (E0 * E0 * cbrt(sum * Q * Q)), table[i][3], 1e-3 * table[i][3]);
	}
}

static void test_invalid(void **state)
{
	(void)state;
	prsm_hertz h;
	assert_int_equal(prsm_hertz_coefficients(&h, -1e-300), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_coefficients(&h, 1.0), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_coefficients(&h, NAN), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_coefficients(&h, INFINITY), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_solve(&h, 0.0, 0.2, 2e5, 0.3, 2e5, 0.3, 1.0), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_solve(&h, 0.1, 0.2, 0.0, 0.3, 2e5, 0.3, 1.0), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_solve(&h, 0.1, INFINITY, 2e5, 0.3, 2e5, 0.3, 1.0), PRSM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_brent_matches_bisection),
		cmocka_unit_test(test_residual),
		cmocka_unit_test(test_circle),
		cmocka_unit_test(test_limits),
		cmocka_unit_test(test_model_md_coefficients),
		cmocka_unit_test(test_invalid),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
