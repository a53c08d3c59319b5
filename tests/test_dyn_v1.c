/*
 * test_dyn_v1.c: validation case V1 of docs/model §8.8 (open numbers) — case A, viscous slip
 * friction 25 N s/m per roller, a step to 1 rad/s, 100 N, sliding only — to its stated
 * tolerances (k*, tau 1e-6 relative, efficiencies 1e-6, times 1e-5 relative); the closed form
 * psi-dot(t) = k* theta-dot (1 - exp(-t/tau)) and T_in(t) at every output time; the input work
 * against its closed-form integral; both checks at every output time; the same answers from
 * rk8pd, msbdf and rk4imp and with the tolerances halved.
 */
#include "test_dyn_support.h"

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

typedef struct {
	double kstar, tau, AA, AB, BB, J;
} v1_closed_form;

static void closed_form(v1_closed_form *c, const prsm_dyn_model *m)
{
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	const double *A = p->A_mm[PRSM_DYN_FLANK_LOWER], *B = p->B_mm[PRSM_DYN_FLANK_LOWER];
	c->AA = dot3(A, A) * 1e-6; /* m^2 */
	c->AB = dot3(A, B) * 1e-6;
	c->BB = dot3(B, B) * 1e-6;
	c->kstar = -c->AB / c->AA;
	c->J = p->carrier_side_inertia_kg_m2;
	c->tau = c->J / (10 * 25.0 * c->AA);
}

static void test_v1_numbers(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	dyn_v1_options(&o);
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	v1_closed_form c;
	closed_form(&c, m);
	assert_rel(c.kstar, 0.37369408, 1e-6);
	assert_rel(prsm_dyn_model_stage(m, 0)->carrier_ratio_min_slip, 0.37369408, 1e-6);
	assert_rel(c.J, 2.148289e-5, 1e-6);
	assert_rel(c.tau, 1.277814e-4, 1e-6);
	/* settled, algebraically */
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	assert_int_equal(s->defined, 1);
	assert_close(s->efficiency, 0.9922054, 1e-6);
	assert_rel(s->input_torque_Nm, 0.1604052, 1e-6);
	assert_rel(s->carrier_ratio[0], 0.37369408, 1e-6);
	assert_rel(s->carrier_rate_per_s[0], 1.0 / c.tau, 1e-6);
	assert_true(isnan(s->efficiency_statics)); /* no statics counterpart of viscous friction */

	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	assert_int_equal(r.points, 101);
	/* 0+ */
	assert_rel(r.point[0].input_torque_Nm, 0.1838830, 1e-6);
	assert_close(r.point[0].efficiency, 0.8655226, 1e-6);
	/* transient times */
	assert_rel(r.carrier_time_to_share_s[0][0], 8.857132e-5, 1e-5);
	assert_rel(r.carrier_time_to_share_s[0][2], 5.884551e-4, 1e-5);
	assert_rel(r.carrier_time_to_share_s[0][1], c.tau * log(10.0), 1e-7);
	/* the closed form at every output time; both checks */
	const double FL = 100.0 * 10e-3 / (2 * M_PI);
	for (size_t i = 0; i < r.points; i++) {
		const double t = r.point[i].time_s, ratio = c.kstar * (1.0 - exp(-t / c.tau));
		assert_close(r.point[i].time_s, i * 1e-5, 1e-18);
		assert_close(r.stage[i].carrier_ratio, ratio, 1e-8);
		const double T = FL + 10 * 25.0 * (c.BB + c.AB * ratio);
		assert_rel(r.point[i].input_torque_Nm, T, 1e-8);
		assert_true(r.point[i].power_balance_relative < 1e-12);
		assert_true(r.point[i].newton_euler_residual < 1e-9);
		/* nut travel L/2pi theta, forward */
		assert_close(r.stage[i].nut_position_mm, 10.0 / (2 * M_PI) * t, 1e-15);
		/* the input work: int T_in dt in closed form (theta-dot = 1) */
		const double E = (FL + 10 * 25.0 * c.BB) * t + 10 * 25.0 * c.AB * c.kstar * (t - c.tau * (1.0 - exp(-t / c.tau)));
		assert_close(r.point[i].energy_input_J, E, 1e-9 * E + 1e-18);
		assert_close(r.point[i].energy_output_J, FL * t, 1e-10 * FL * t + 1e-18);
	}
	assert_true(r.max_power_balance_relative < 1e-12);
	assert_true(r.max_newton_euler_residual < 1e-9);
	prsm_dyn_result_free(&r);

	/* at t = tau exactly (the end is always an output time) */
	o.time.end_s = c.tau;
	o.time.output_step_s = 1e-5;
	prsm_dyn_model *mt = dyn_test_model(1, &d, &a, &o);
	dyn_test_simulate(&r, mt);
	assert_close(r.point[r.points - 1].time_s, c.tau, 0.0);
	assert_rel(r.stage[r.points - 1].carrier_ratio, 0.2362197, 5e-7);
	assert_close(r.point[r.points - 1].efficiency, 0.9415099, 1e-6);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(mt);
	prsm_dyn_model_free(m);
}

/* The answers do not depend on the stepper or on halving the tolerances beyond the stated
 * digits (docs/model §8.2.6). */
static void test_v1_independent_of_stepper(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	const int steppers[] = {PRSM_DYN_STEPPER_RK8PD, PRSM_DYN_STEPPER_MSBDF, PRSM_DYN_STEPPER_RK4IMP,
	                        PRSM_DYN_STEPPER_RK8PD};
	prsm_dyn_result r[4];
	for (int i = 0; i < 4; i++) {
		prsm_dyn_options o;
		dyn_v1_options(&o);
		o.time.stepper = steppers[i];
		if (i == 3) {
			o.time.rel_tol *= 0.5;
			o.time.abs_tol *= 0.5;
		}
		prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
		dyn_test_simulate(&r[i], m);
		prsm_dyn_model_free(m);
	}
	assert_true(r[1].jacobian_evaluations > 0);
	for (int i = 1; i < 4; i++) {
		assert_int_equal(r[i].points, r[0].points);
		for (int j = 0; j < 3; j++)
			assert_rel(r[i].carrier_time_to_share_s[0][j], r[0].carrier_time_to_share_s[0][j], 1e-6);
		for (size_t k = 0; k < r[0].points; k++) {
			assert_close(r[i].stage[k].carrier_ratio, r[0].stage[k].carrier_ratio, 1e-8);
			assert_close(r[i].point[k].efficiency, r[0].point[k].efficiency, 1e-8);
		}
	}
	for (int i = 0; i < 4; i++)
		prsm_dyn_result_free(&r[i]);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_v1_numbers),
		cmocka_unit_test(test_v1_independent_of_stepper),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
