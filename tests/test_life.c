/*
 * test_life.c: docs/model/kinematics-efficiency-stiffness-life.md capacity and life — the duty-cycle check (217.7 lbf), L10 and its
 * units, reliability factors, static capacity against a brute-force Hertz solve, the
 * Lundberg–Palmgren dynamic capacity (values from an independent 30-digit mpmath transcription
 * of the formulas in life.h, homogeneity, the combination rule, a catalogue-size band), the
 * preload derating against the exact two-half Hertz solution, and the column limits against
 * beam theory and the catalogue constants.
 */
#include "test_support.h"

#include "model/hertz.h"
#include "model/life.h"

#include <string.h>

#define LBF_N 4.4482216152605 /* N per lbf */

/* docs/model/kinematics-efficiency-stiffness-life.md: 500, 100, 250, 50 lbf over 0.5, 2.9, 1.0, 3.5 in give F_m = 217.7 lbf. Units
 * cancel in the weights; the loads are given in N and converted back. */
static void test_cubic_mean_model_check(void **state)
{
	(void)state;
	const double lbf[] = {500.0, 100.0, 250.0, 50.0};
	const double in[] = {0.5, 2.9, 1.0, 3.5};
	double F[4], mm[4], Fm;
	prsm_error err = PRSM_ERROR_INIT;
	for (int i = 0; i < 4; i++) {
		F[i] = lbf[i] * LBF_N;
		mm[i] = in[i] * 25.4;
	}
	assert_int_equal(prsm_life_cubic_mean_load(&Fm, F, mm, 4, &err), 0);
	assert_close(Fm / LBF_N, 217.7, 0.05);
	assert_close(Fm / LBF_N, 217.659125976855, 1e-9); /* mpmath, 30 digits */
	/* the sign of a load does not matter (either direction fatigues the flanks it loads) */
	F[2] = -F[2];
	double Fm2;
	assert_int_equal(prsm_life_cubic_mean_load(&Fm2, F, mm, 4, &err), 0);
	assert_close(Fm2, Fm, 1e-12 * Fm);

	/* speed x time weights give the same mean when travel = n q lead (t arbitrary units):
	 * steps at 137, 911, 420.5, 1203 rpm with time fractions travel / speed */
	const double rpm[] = {137.0, 911.0, 420.5, 1203.0};
	double q[4];
	for (int i = 0; i < 4; i++)
		q[i] = in[i] / rpm[i];
	assert_int_equal(prsm_life_cubic_mean_load_speed_time(&Fm2, F, rpm, q, 4, &err), 0);
	assert_close(Fm2, Fm, 1e-12 * Fm);

	/* a constant load is its own mean */
	const double c3[] = {1234.5, 1234.5, 1234.5};
	const double w3[] = {0.3, 7.1, 2.2};
	assert_int_equal(prsm_life_cubic_mean_load(&Fm2, c3, w3, 3, &err), 0);
	assert_close(Fm2, 1234.5, 1e-9);

	/* errors */
	const double bad[] = {1.0, -2.0};
	assert_int_equal(prsm_life_cubic_mean_load(&Fm2, F, bad, 2, &err), PRSM_EINVAL);
	assert_int_equal(prsm_life_cubic_mean_load(&Fm2, F, mm, 0, &err), PRSM_EINVAL);
	const double zero[] = {0.0, 0.0};
	assert_int_equal(prsm_life_cubic_mean_load(&Fm2, F, zero, 2, &err), PRSM_EINVAL);
	assert_int_equal(prsm_life_cubic_mean_load_speed_time(&Fm2, F, rpm, zero, 2, &err), PRSM_EINVAL);
}

static void test_l10_and_units(void **state)
{
	(void)state;
	prsm_life_rating r, r2;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_life_l10(&r, 48731.0, 9137.0, 873.0, 7.5, 90, &err), 0);
	const double ratio = 48731.0 / 9137.0;
	assert_close(r.revolutions, ratio * ratio * ratio * 1e6, 1e-6);
	assert_close(r.hours, r.revolutions / (60.0 * 873.0), 1e-9);
	assert_close(r.distance_km, r.revolutions * 7.5 / 1e6, 1e-9);
	/* life ~ (C/F)^3 exactly: scale C by 1.37 and F by 0.71 */
	assert_int_equal(prsm_life_l10(&r2, 48731.0 * 1.37, 9137.0 * 0.71, 873.0, 7.5, 90, &err), 0);
	const double s = 1.37 / 0.71;
	assert_close(r2.revolutions / r.revolutions, s * s * s, 1e-12);
	/* reliability factors (docs/model/kinematics-efficiency-stiffness-life.md) */
	const int pct[] = {90, 95, 96, 97, 98, 99};
	const double a1[] = {1.0, 0.62, 0.53, 0.44, 0.33, 0.21};
	for (int i = 0; i < 6; i++) {
		assert_int_equal(prsm_life_l10(&r2, 48731.0, 9137.0, 873.0, 7.5, pct[i], &err), 0);
		assert_close(r2.reliability_factor, a1[i], 0.0);
		assert_close(r2.revolutions, a1[i] * r.revolutions, 1e-9 * r.revolutions);
	}
	/* speed 0: hours 0, distance still given */
	assert_int_equal(prsm_life_l10(&r2, 48731.0, 9137.0, 0.0, 7.5, 90, &err), 0);
	assert_true(r2.hours == 0.0 && r2.distance_km > 0.0);
	double f;
	assert_int_equal(prsm_life_reliability_factor(&f, 93, &err), PRSM_EINVAL);
	assert_int_equal(prsm_life_l10(&r2, 48731.0, 0.0, 873.0, 7.5, 90, &err), PRSM_EINVAL);
	assert_int_equal(prsm_life_l10(&r2, 48731.0, 9137.0, 873.0, -1.0, 90, &err), PRSM_EINVAL);
}

/* C_0a: brute force — the Hertz solve at Q_allow gives p_max = p_allow. */
static void test_static_capacity_brute_force(void **state)
{
	(void)state;
	const double k1 = 0.2176, k2 = 0.3391, E1 = 206000.0, n1 = 0.3, E2 = 201300.0, n2 = 0.29;
	prsm_hertz h, h2;
	prsm_static_capacity s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_hertz_solve(&h, k1, k2, E1, n1, E2, n2, 731.3), 0);
	assert_int_equal(prsm_life_static_capacity(&s, &h, 0.70251, 110, 1.83, PRSM_STATIC_P_ALLOW_MPA, &err), 0);
	assert_int_equal(prsm_hertz_solve(&h2, k1, k2, E1, n1, E2, n2, s.q_allow_N), 0);
	assert_close(h2.p_max_MPa / PRSM_STATIC_P_ALLOW_MPA, 1.0, 1e-6);
	assert_close(s.C0a_N, s.q_allow_N * 0.70251 * 110.0 / 1.83, 1e-9 * s.C0a_N);
	/* a different reference load gives the same capacity */
	prsm_static_capacity s2;
	assert_int_equal(prsm_hertz_solve(&h2, k1, k2, E1, n1, E2, n2, 12.77), 0);
	assert_int_equal(prsm_life_static_capacity(&s2, &h2, 0.70251, 110, 1.83, PRSM_STATIC_P_ALLOW_MPA, &err), 0);
	assert_close(s2.C0a_N, s.C0a_N, 1e-9 * s.C0a_N);
	/* capacity ~ p_allow^3 and ~ 1/K */
	assert_int_equal(prsm_life_static_capacity(&s2, &h, 0.70251, 110, 1.0, 2700.0, &err), 0);
	const double r = 2700.0 / 4200.0;
	assert_close(s2.C0a_N / s.C0a_N, 1.83 * r * r * r, 1e-9);
	/* errors */
	assert_int_equal(prsm_life_static_capacity(&s2, &h, 0.7, 110, 0.9, 4200.0, &err), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_solve(&h2, k1, k2, E1, n1, E2, n2, 0.0), 0);
	assert_int_equal(prsm_life_static_capacity(&s2, &h2, 0.7, 110, 1.2, 4200.0, &err), PRSM_EINVAL);
}

/* Dynamic capacity against an independent transcription (mpmath, 30 digits) for case A and a
 * high-entropy design. */
static void test_dynamic_capacity_values(void **state)
{
	(void)state;
	prsm_design d;
	prsm_dynamic_capacity c;
	prsm_error err = PRSM_ERROR_INIT;
	case_a(&d);
	assert_int_equal(prsm_life_dynamic_capacity(&c, &d, NULL, 1.0, &err), 0);
	assert_close(c.gamma, 0.25, 1e-14);
	assert_close(c.carrier_ratio, 0.375, 1e-14);
	assert_close(c.q_screw_N, 1124.7992873033583, 1e-9);
	assert_close(c.q_nut_N, 2712.6538425615924, 1e-9);
	assert_close(c.q_roller_screw_side_N, 2336.1693619259114, 1e-9);
	assert_close(c.q_roller_nut_side_N, 5538.9661472638182, 1e-9);
	assert_close(c.q_combined_N, 1079.86469746118, 1e-9);
	assert_close(c.C_a_N, 38269.637260736295, 1e-7);
	assert_true(strstr(c.method.name, "Lundberg-Palmgren") != NULL);
	assert_close(c.method.constant, 98.1, 0.0);

	standard_design(&d, 6, 1.37, 2.93, 41.7, 9, 13);
	assert_int_equal(prsm_life_dynamic_capacity(&c, &d, NULL, 1.0, &err), 0);
	assert_close(c.gamma, 0.2, 1e-14);
	assert_close(c.q_screw_N, 1139.6536608532233, 1e-9);
	assert_close(c.q_nut_N, 2292.1172329138917, 1e-9);
	assert_close(c.q_roller_screw_side_N, 2263.5237725178054, 1e-9);
	assert_close(c.q_roller_nut_side_N, 4491.374695197603, 1e-9);
	assert_close(c.C_a_N, 43564.264440439042, 1e-7);
	/* the load-distribution factor multiplies */
	prsm_dynamic_capacity c2;
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d, NULL, 0.683, &err), 0);
	assert_close(c2.C_a_N, 0.683 * c.C_a_N, 1e-9 * c.C_a_N);
	/* material factor (ISO 281's b_m = 1.3) multiplies every surface */
	prsm_lp_method m = PRSM_LP_METHOD_INIT;
	m.material_factor = 1.3;
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d, &m, 1.0, &err), 0);
	assert_close(c2.C_a_N, 1.3 * c.C_a_N, 1e-9 * c.C_a_N);
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d, NULL, 1.2, &err), PRSM_EINVAL);
	d.engaged_threads = 0;
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d, NULL, 1.0, &err), PRSM_EINVAL);
}

/* Homogeneity: scaling every length by s keeps gamma, alpha, the cycle ratios and the track
 * length ratios, so every rating scales as s^1.8 (D^1.8); n_t threads scale C_a as n_t^0.7. */
static void test_dynamic_capacity_homogeneity(void **state)
{
	(void)state;
	prsm_design d, d2;
	prsm_dynamic_capacity c, c2;
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 5, 1.61, 3.07, 43.1, 8, 11);
	standard_design(&d2, 5, 1.61 * 2.37, 3.07 * 2.37, 43.1, 8, 11);
	assert_int_equal(prsm_life_dynamic_capacity(&c, &d, NULL, 1.0, &err), 0);
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d2, NULL, 1.0, &err), 0);
	const double s18 = pow(2.37, 1.8);
	assert_close(c2.q_screw_N / c.q_screw_N, s18, 1e-12 * s18);
	assert_close(c2.q_roller_nut_side_N / c.q_roller_nut_side_N, s18, 1e-12 * s18);
	assert_close(c2.C_a_N / c.C_a_N, s18, 1e-12 * s18);
	d2 = d;
	d2.engaged_threads = 29;
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d2, NULL, 1.0, &err), 0);
	assert_close(c2.C_a_N / c.C_a_N, pow(29.0 / 11.0, 0.7), 1e-12);
	/* ring ratings ~ Z^(-1/3) at fixed geometry */
	d2 = d;
	d2.rollers = 5;
	assert_int_equal(prsm_life_dynamic_capacity(&c2, &d2, NULL, 1.0, &err), 0);
	assert_close(c2.q_nut_N / c.q_nut_N, cbrt(8.0 / 5.0), 1e-12);
	/* the raceway formula itself: conformity factor (2f/(2f-1))^0.41 for a grooved raceway */
	prsm_lp_raceway r = {7.9375, 0.6109, 46.3, INFINITY, 12, 0};
	const prsm_lp_method m = PRSM_LP_METHOD_INIT;
	double q_flat, q_groove;
	assert_int_equal(prsm_life_raceway_rating(&q_flat, &r, &m, &err), 0);
	r.conformity = 0.52;
	assert_int_equal(prsm_life_raceway_rating(&q_groove, &r, &m, &err), 0);
	assert_close(q_groove / q_flat, pow(1.04 / 0.04, 0.41), 1e-12);
	r.conformity = 0.4;
	assert_int_equal(prsm_life_raceway_rating(&q_groove, &r, &m, &err), PRSM_EINVAL);
}

/* The L–P combination rule against a hand-computed case, and its limits. */
static void test_combination_rule(void **state)
{
	(void)state;
	const double q[] = {2913.7, 5127.1, 8311.9, 4402.3};
	assert_close(prsm_life_combine_ratings(q, 4, 10.0 / 3.0), 2614.4686664838621, 1e-9);
	/* n equal ratings: q n^(-3/10) */
	const double e[] = {1733.0, 1733.0, 1733.0, 1733.0, 1733.0};
	assert_close(prsm_life_combine_ratings(e, 5, 10.0 / 3.0), 1733.0 * pow(5.0, -0.3), 1e-9);
	/* one rating alone is itself; a zero rating makes the chain 0 */
	assert_close(prsm_life_combine_ratings(q, 1, 10.0 / 3.0), 2913.7, 1e-10);
	const double z[] = {2913.7, 0.0};
	assert_true(prsm_life_combine_ratings(z, 2, 10.0 / 3.0) == 0.0);
	/* distribution factor: 1 for equal loads; hand case: loads 3, 1 (mean 2):
	 * [((1.5)^(10/3) + (0.5)^(10/3)) / 2]^(-3/10) */
	const double eq[] = {17.0, 17.0, 17.0};
	assert_close(prsm_life_distribution_factor(eq, 3, 10.0 / 3.0), 1.0, 1e-14);
	const double l2[] = {3.0, 1.0};
	const double x = 10.0 / 3.0;
	assert_close(prsm_life_distribution_factor(l2, 2, x),
	             pow(0.5 * (pow(1.5, x) + pow(0.5, x)), -0.3), 1e-14);
	assert_true(prsm_life_distribution_factor(l2, 2, x) < 1.0);
	assert_true(isnan(prsm_life_distribution_factor(l2, 0, x)));
}

/* Order of magnitude against roller-screw catalogues: a 30 mm-class screw, lead 5 (n 5,
 * P 1, r_r 5, Z 10, n_t 24). Catalogue dynamic ratings of this size are some tens to about a
 * hundred kN (SKF roller screws, publication 14489 EN, table B.1; its figures could not be
 * retrieved here, so only a loose band is asserted: 30 kN .. 400 kN). The method's ring
 * constant is a ball-bearing fit extrapolated to straight flanks (life.h), and the load
 * distribution factor is 1 here, so the estimate is expected on the high side. */
static void test_dynamic_capacity_catalogue_band(void **state)
{
	(void)state;
	prsm_design d;
	prsm_dynamic_capacity c;
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 5, 1.0, 5.0, 45.0, 10, 24);
	assert_close(2.0 * d.screw_radius_mm, 30.0, 1e-12);
	assert_int_equal(prsm_life_dynamic_capacity(&c, &d, NULL, 1.0, &err), 0);
	assert_true(c.C_a_N > 30e3 && c.C_a_N < 400e3);
}

/* Preload: exact at no load and at lift-off, within 3 % of the exact two-half Hertz solution
 * (delta ~ Q^(2/3), solved by bisection) in between, |F| beyond lift-off. */
static void test_preload(void **state)
{
	(void)state;
	const double Fpr = 3217.0;
	prsm_error err = PRSM_ERROR_INIT;
	double q;
	assert_int_equal(prsm_life_preload_load(&q, 0.0, Fpr, &err), 0);
	assert_close(q, Fpr, 1e-9);
	const double lift = pow(2.0, 1.5) * Fpr;
	assert_int_equal(prsm_life_preload_load(&q, lift, Fpr, &err), 0);
	assert_close(q, lift, 1e-9);
	assert_int_equal(prsm_life_preload_load(&q, -1.7 * lift, Fpr, &err), 0);
	assert_close(q, 1.7 * lift, 1e-9);
	const double d0 = pow(Fpr, 2.0 / 3.0);
	for (int i = 1; i < 40; i++) {
		const double F = lift * i / 40.0;
		double lo = 0.0, hi = d0;
		for (int k = 0; k < 200; k++) {
			const double x = 0.5 * (lo + hi);
			if (pow(d0 + x, 1.5) - pow(d0 - x, 1.5) < F)
				lo = x;
			else
				hi = x;
		}
		const double exact = pow(d0 + 0.5 * (lo + hi), 1.5);
		assert_int_equal(prsm_life_preload_load(&q, F, Fpr, &err), 0);
		assert_true(fabs(q / exact - 1.0) < 0.03);
		assert_true(q >= F); /* the working half carries at least the external load */
	}
	assert_int_equal(prsm_life_preload_load(&q, 100.0, -1.0, &err), PRSM_EINVAL);
}

/* Column limits: beam theory against a hand computation, the catalogue factors (steel,
 * E 206000, 7850 kg/m^3, with the catalogues' 0.8) within 2 %, and the fixity ratios. */
static void test_column(void **state)
{
	(void)state;
	const double dr = 23.71, L = 1387.0, E = 206000.0, rho = 7850.0;
	prsm_column c[4];
	prsm_error err = PRSM_ERROR_INIT;
	for (int f = 0; f < 4; f++)
		assert_int_equal(prsm_life_column(&c[f], dr, L, f, E, rho, &err), 0);
	/* hand: supported-supported, n = (60/2pi)(pi/L)^2 (d/4) sqrt(E/rho) with sqrt in mm/s */
	const double v = sqrt(E * 1e6 / rho) * 1e3; /* sqrt(E/rho): m/s -> mm/s */
	const double n_ss = 60.0 / (2.0 * M_PI) * (M_PI / L) * (M_PI / L) * (dr / 4.0) * v;
	assert_close(c[PRSM_FIXITY_SUPPORTED_SUPPORTED].critical_speed_rpm, n_ss, 1e-9 * n_ss);
	const double I = M_PI * pow(dr, 4) / 64.0;
	assert_close(c[PRSM_FIXITY_SUPPORTED_SUPPORTED].buckling_load_N, M_PI * M_PI * E * I / (L * L), 1e-6);
	/* catalogue n = f d_r/L^2 1e7 = 0.8 x beam theory for steel, within 2 % */
	for (int f = 0; f < 4; f++) {
		assert_close(c[f].catalogue_speed_rpm, c[f].catalogue_speed_factor * dr / (L * L) * 1e7, 1e-9);
		assert_close(c[f].catalogue_speed_rpm / (0.8 * c[f].critical_speed_rpm), 1.0, 0.02);
	}
	/* ratios between fixities: speed ~ lambda^2, buckling ~ m */
	const double *ss = &c[PRSM_FIXITY_SUPPORTED_SUPPORTED].critical_speed_rpm;
	assert_close(c[PRSM_FIXITY_FIXED_FIXED].critical_speed_rpm / *ss, pow(4.7300407449 / M_PI, 2), 1e-9);
	assert_close(c[PRSM_FIXITY_FIXED_FREE].critical_speed_rpm / *ss, pow(1.8751040687 / M_PI, 2), 1e-9);
	const double bss = c[PRSM_FIXITY_SUPPORTED_SUPPORTED].buckling_load_N;
	assert_close(c[PRSM_FIXITY_FIXED_FREE].buckling_load_N / bss, 0.25, 1e-12);
	assert_close(c[PRSM_FIXITY_FIXED_SUPPORTED].buckling_load_N / bss, pow(4.4934094579 / M_PI, 2), 1e-4);
	assert_close(c[PRSM_FIXITY_FIXED_FIXED].buckling_load_N / bss, 4.0, 1e-12);
	/* the eigenvalues solve their frequency equations: cos l cosh l = -1 (fixed-free),
	 * tan l = tanh l (fixed-supported), cos l cosh l = 1 (fixed-fixed) */
	double l = c[PRSM_FIXITY_FIXED_FREE].speed_eigenvalue;
	assert_close(cos(l) * cosh(l), -1.0, 1e-9);
	l = c[PRSM_FIXITY_FIXED_SUPPORTED].speed_eigenvalue;
	assert_close(tan(l), tanh(l), 1e-9);
	l = c[PRSM_FIXITY_FIXED_FIXED].speed_eigenvalue;
	assert_close(cos(l) * cosh(l), 1.0, 1e-8);
	/* L^-2 scaling and errors */
	prsm_column c2;
	assert_int_equal(prsm_life_column(&c2, dr, 2.0 * L, PRSM_FIXITY_FIXED_FIXED, E, rho, &err), 0);
	assert_close(c2.critical_speed_rpm * 4.0, c[3].critical_speed_rpm, 1e-9 * c2.critical_speed_rpm);
	assert_int_equal(prsm_life_column(&c2, dr, L, 4, E, rho, &err), PRSM_EINVAL);
	assert_int_equal(prsm_life_column(&c2, -dr, L, 0, E, rho, &err), PRSM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cubic_mean_model_check),
		cmocka_unit_test(test_l10_and_units),
		cmocka_unit_test(test_static_capacity_brute_force),
		cmocka_unit_test(test_dynamic_capacity_values),
		cmocka_unit_test(test_dynamic_capacity_homogeneity),
		cmocka_unit_test(test_combination_rule),
		cmocka_unit_test(test_dynamic_capacity_catalogue_band),
		cmocka_unit_test(test_preload),
		cmocka_unit_test(test_column),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
