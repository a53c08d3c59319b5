/*
 * test_kinematics.c: docs/model/kinematics-efficiency-stiffness-life.md — speed ratios, sliding, sliding efficiency against the
 * closed forms, and §6 — Hertz coefficients of the bearing handbook.
 */
#include "test_support.h"

#include "model/analysis.h"
#include "model/hertz.h"

static void analyse(prsm_analysis *a, prsm_design *d)
{
	prsm_problems w;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(a, d, &w, NULL), 0);
}

static void test_case_a_ratios(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	case_a(&d);
	analyse(&a, &d);
	const prsm_kinematics *k = &a.kinematics;
	assert_close(k->carrier_ratio_ideal, 0.375, 1e-12);
	assert_close(k->roller_spin_ratio_ideal, -1.875, 1e-12);
	assert_close(k->roller_abs_ratio_ideal, -1.5, 1e-12);
	assert_close(k->carrier_ratio, 0.37564, 5e-6);
	assert_close(k->slip_ratio_screw, 1.405, 5e-4);
	assert_close(k->slip_ratio_nut, 0.0, 1e-9);
	assert_close(fabs(k->nut_speed_mm_per_rad) * 2 * M_PI, 10.0, 1e-12);
}

/* With the contact-radius kinematics the sliding velocity lies in the tangent plane of the
 * screw flank: no velocity along the common normal (an independent consistency check). */
static void test_slip_tangent_to_flank(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.3, 2.87, 38.0}, {7, 2.5, 3.1, 55.0}};
	for (size_t i = 0; i < 3; i++) {
		prsm_design d;
		prsm_analysis a;
		standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 3, 5);
		analyse(&a, &d);
		const double *n = a.screw.normal, *s = a.kinematics.slip_screw;
		double vn = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
		assert_close(vn / fabs(a.kinematics.nut_speed_mm_per_rad), 0.0, 2e-3);
	}
}

/* docs/model/kinematics-efficiency-stiffness-life.md: eta = tan b / tan(b + rho), eta' = tan(b - rho) / tan b; at 45 deg both are
 * (1 - mu)/(1 + mu): 0.9048 at mu = 0.05, 0.8182 at 0.10; the 3-D sum agrees within 0.001. */
static void test_efficiency_closed_form(void **state)
{
	(void)state;
	const double mus[] = {0.05, 0.10, 0.0731};
	for (int i = 0; i < 3; i++) {
		prsm_design d;
		prsm_analysis a;
		case_a(&d);
		d.mu_screw_roller = mus[i];
		d.mu_nut_roller = 0.087;
		analyse(&a, &d);
		double cf = (1 - mus[i]) / (1 + mus[i]);
		assert_close(a.efficiency.eta_closed_form, cf, 1e-12);
		assert_close(a.efficiency.eta_back_closed_form, cf, 1e-12);
		assert_close(a.efficiency.eta, cf, 1e-3);
		assert_close(a.efficiency.eta_back, cf, 1e-3);
	}
	prsm_design d;
	prsm_analysis a;
	case_a(&d);
	analyse(&a, &d);
	assert_close(a.efficiency.eta_closed_form, 0.9048, 5e-5);
	d.mu_screw_roller = 0.10;
	analyse(&a, &d);
	assert_close(a.efficiency.eta_closed_form, 0.8182, 5e-5);
	/* frictionless: lossless */
	d.mu_screw_roller = 0.0;
	d.mu_nut_roller = 0.0;
	analyse(&a, &d);
	assert_close(a.efficiency.eta, 1.0, 1e-15);
	assert_close(a.efficiency.eta_back, 1.0, 1e-15);
}

/* To first order the sliding efficiency does not depend on lead or radii (docs/model/kinematics-efficiency-stiffness-life.md). */
static void test_efficiency_independent_of_lead(void **state)
{
	(void)state;
	double ref = -1.0;
	for (int n = 3; n <= 7; n++) {
		prsm_design d;
		prsm_analysis a;
		standard_design(&d, n, 1.75, 3.61, 45.0, 3, 5);
		analyse(&a, &d);
		if (ref < 0)
			ref = a.efficiency.eta;
		assert_close(a.efficiency.eta, ref, 2e-3);
	}
}

/* Torque at the operating point: T = F L / (2 pi eta). */
static void test_operating_torque(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	case_a(&d);
	d.axial_load_N = 7123.0;
	d.screw_speed_rad_s = 91.7;
	analyse(&a, &d);
	double ideal = 7123.0 * 10.0 / (2 * M_PI) * 1e-3;
	assert_close(a.efficiency.ideal_torque_Nm, ideal, 1e-12);
	assert_close(a.efficiency.input_torque_Nm, ideal / a.efficiency.eta, 1e-12);
	assert_close(a.efficiency.output_power_W, 7123.0 * 10e-3 / (2 * M_PI) * 91.7, 1e-9);
	assert_close(a.efficiency.input_power_W - a.efficiency.loss_power_W, a.efficiency.output_power_W, 1e-9);
}

/* docs/model/kinematics-efficiency-stiffness-life.md: a = C_a E0 (Q / sum rho)^(1/3), b likewise, delta = C_delta E0^2 (sum rho Q^2)^(1/3),
 * E0 = (1.137e5 (1/E01 + 1/E02))^(1/3); coefficients to 0.1 %. */
static void test_hertz_handbook_coefficients(void **state)
{
	(void)state;
	const double table[][4] = {{0.0, 0.02363, 0.02363, NAN},
	                           {0.5, 0.03511, 0.01694, 0.0002617},
	                           {0.9, 0.07305, 0.01089, 0.0001898}};
	const double E1 = 211700.0, nu1 = 0.29, E2 = 198300.0, nu2 = 0.31, Q = 1234.5;
	const double E01 = E1 / (1 - nu1 * nu1), E02 = E2 / (1 - nu2 * nu2);
	const double E0 = cbrt(1.137e5 * (1 / E01 + 1 / E02));
	for (int i = 0; i < 3; i++) {
		double F = table[i][0], sum = 0.2873;
		double k1 = sum * (1 - F) / 2, k2 = sum * (1 + F) / 2;
		prsm_hertz h;
		assert_int_equal(prsm_hertz_solve(&h, k1, k2, E1, nu1, E2, nu2, Q), 0);
		assert_close(h.curvature_difference, F, 1e-12);
		double s = E0 * cbrt(Q / sum);
		assert_close(h.a_mm / s, table[i][1], 1e-3 * table[i][1]);
		assert_close(h.b_mm / s, table[i][2], 1e-3 * table[i][2]);
		if (!isnan(table[i][3]))
			assert_close(h.delta_mm / (E0 * E0 * cbrt(sum * Q * Q)), table[i][3], 1e-3 * table[i][3]);
		/* the pressure integrates to the load: (2/3) p_max pi a b = Q */
		assert_close(2.0 / 3.0 * h.p_max_MPa * M_PI * h.a_mm * h.b_mm, Q, 1e-9 * Q);
	}
}

/* Circular contact: Hertz's closed form for two spheres (independent of the elliptic solve). */
static void test_hertz_spheres(void **state)
{
	(void)state;
	const double R1 = 7.3, R2 = 11.9, E = 206000.0, nu = 0.3, Q = 517.0;
	prsm_hertz h;
	double k = 1 / R1 + 1 / R2;
	assert_int_equal(prsm_hertz_solve(&h, k, k, E, nu, E, nu, Q), 0); /* both principal curvatures 1/R1 + 1/R2 */
	double Reff = 1 / k, Estar = 1 / (2 * (1 - nu * nu) / E);
	double a = cbrt(3 * Q * Reff / (4 * Estar));
	assert_close(h.a_mm, a, 1e-9 * a);
	assert_close(h.b_mm, a, 1e-9 * a);
	assert_close(h.delta_mm, a * a / Reff, 1e-9 * a * a / Reff);
	assert_close(h.kappa, 1.0, 1e-12);
	/* invalid input refused */
	assert_int_equal(prsm_hertz_solve(&h, -0.1, 0.2, E, nu, E, nu, Q), PRSM_EINVAL);
	assert_int_equal(prsm_hertz_solve(&h, 0.1, 0.2, E, nu, E, nu, -1.0), PRSM_EINVAL);
}

/* Case A at the operating load: the analysis shares F equally over Z n_t contacts. */
static void test_case_a_hertz_at_load(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	case_a(&d);
	d.axial_load_N = 7000.0;
	analyse(&a, &d);
	assert_int_equal(a.contacts_sharing, 100);
	assert_close(a.hertz_screw.load_N, 70.0 / a.screw.normal[2], 1e-9);
	assert_true(a.hertz_screw.p_max_MPa > 500.0 && a.hertz_screw.p_max_MPa < 5000.0);
	assert_true(a.hertz_screw.a_mm > a.hertz_screw.b_mm);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_case_a_ratios),
		cmocka_unit_test(test_slip_tangent_to_flank),
		cmocka_unit_test(test_efficiency_closed_form),
		cmocka_unit_test(test_efficiency_independent_of_lead),
		cmocka_unit_test(test_operating_torque),
		cmocka_unit_test(test_hertz_handbook_coefficients),
		cmocka_unit_test(test_hertz_spheres),
		cmocka_unit_test(test_case_a_hertz_at_load),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
