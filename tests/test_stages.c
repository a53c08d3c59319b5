/*
 * test_stages.c: docs/model/kinematics-efficiency-stiffness-life.md, the multi-stage chain — output speed omega sum L / 2pi; with the
 * couplings frictionless the chain efficiency is the travel-weighted harmonic rule
 * sum L / sum (L_k / eta_k); the exact power balance with friction; the closed-form torques
 * against an independent fixed-point solution of the force balances; locking and bad input.
 */
#include "test_support.h"

#include "model/stages.h"

#include <string.h>

/* A synthetic stage: T(F) = F L / (2 pi eta) + c F^(4/3) + T0 (sliding, spin-like, drag). */
typedef struct {
	double lead_mm[PRSM_STAGES_MAX];
	double eta[PRSM_STAGES_MAX];
	double spin[PRSM_STAGES_MAX];   /* N m per N^(4/3) */
	double drag_Nm[PRSM_STAGES_MAX];
	int calls;
} stages_ctx;

static double stage_torque(void *ctx, int k, double F)
{
	stages_ctx *c = ctx;
	c->calls++;
	return F * c->lead_mm[k] * 1e-3 / (2.0 * M_PI * c->eta[k]) + c->spin[k] * pow(F, 4.0 / 3.0) +
	       c->drag_Nm[k];
}

static void seed000(prsm_chain_input *in, stages_ctx *c)
{
	memset(in, 0, sizeof *in);
	memset(c, 0, sizeof *c);
	in->stages = 2;
	in->lead_mm[0] = c->lead_mm[0] = 10.0;
	in->lead_mm[1] = c->lead_mm[1] = 10.0;
	c->eta[0] = 0.9047619;
	c->eta[1] = 0.8712345;
	in->spline_radius_mm[1] = 9.75;
	in->thrust_radius_mm[1] = 16.375;
	in->axial_load_N = 7000.0;
	in->screw_speed_rad_s = 100.0;
}

static void test_frictionless_couplings(void **state)
{
	(void)state;
	prsm_chain_input in;
	stages_ctx c;
	seed000(&in, &c);
	in.lead_mm[1] = c.lead_mm[1] = 7.385;
	prsm_chain ch;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), 0);
	/* output speed omega sum L / 2 pi */
	assert_close(ch.output_speed_mm_s, 100.0 * 17.385 / (2.0 * M_PI), 1e-12);
	assert_close(ch.stage[0].nut_speed_mm_s, 100.0 * 10.0 / (2.0 * M_PI), 1e-12);
	/* every stage carries F; eta = sum L / sum (L_k / eta_k) */
	assert_close(ch.stage[0].load_N, 7000.0, 0.0);
	assert_close(ch.stage[1].load_N, 7000.0, 0.0);
	const double harmonic = 17.385 / (10.0 / c.eta[0] + 7.385 / c.eta[1]);
	assert_close(ch.efficiency, harmonic, 1e-12);
	assert_close(ch.harmonic_efficiency, harmonic, 1e-12);
	/* and not the product of the stage efficiencies */
	assert_true(fabs(ch.efficiency - c.eta[0] * c.eta[1]) > 0.05);
	/* one stage is that stage */
	in.stages = 1;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), 0);
	assert_close(ch.efficiency, c.eta[0], 1e-12);
}

/* The force balances solved by plain fixed-point iteration on the spline forces, forwards
 * through the stages: an independent route to the same torques. */
static void fixed_point(double M[], double s[], const prsm_chain_input *in, stages_ctx *c)
{
	const int K = in->stages;
	const double F = in->axial_load_N;
	for (int k = 0; k < K; k++)
		s[k] = 0.0;
	for (int it = 0; it < 200; it++) {
		double Mk = 0.0;
		for (int k = K - 1; k >= 0; k--) {
			const double Fk = F + (k + 1 < K ? s[k + 1] : 0.0);
			const double Nk = k ? in->thrust_bearing_friction * (F + s[k]) * in->thrust_radius_mm[k] * 1e-3 : 0.0;
			Mk += stage_torque(c, k, Fk) + Nk;
			M[k] = Mk;
		}
		for (int k = 1; k < K; k++)
			s[k] = in->spline_friction * M[k] / (in->spline_radius_mm[k] * 1e-3);
	}
}

static void test_friction_balance(void **state)
{
	(void)state;
	prsm_chain_input in;
	stages_ctx c;
	seed000(&in, &c);
	in.stages = 3;
	in.lead_mm[2] = c.lead_mm[2] = 12.7;
	c.eta[2] = 0.8833;
	in.spline_radius_mm[2] = 14.2;
	in.thrust_radius_mm[2] = 21.9;
	for (int k = 0; k < 3; k++) {
		c.spin[k] = 2.3e-5 * (k + 1);
		c.drag_Nm[k] = 0.137 * (k + 1);
	}
	in.spline_friction = 0.15;
	in.thrust_bearing_friction = 0.055;
	prsm_chain ch;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), 0);

	double M[3], s[3];
	fixed_point(M, s, &in, &c);
	for (int k = 0; k < 3; k++)
		assert_close(ch.stage[k].spline_torque_Nm, M[k], 1e-10 * M[k]);
	assert_close(ch.stage[1].spline_force_N, s[1], 1e-9 * s[1]);
	assert_close(ch.stage[2].spline_force_N, s[2], 1e-9 * s[2]);
	/* loads grow towards the input: F_k = F + s_{k+1} */
	assert_close(ch.stage[2].load_N, 7000.0, 0.0);
	assert_close(ch.stage[1].load_N, 7000.0 + s[2], 1e-9);
	assert_true(ch.stage[0].load_N > ch.stage[1].load_N);

	/* exact power balance: input = output + stage, spline and thrust-bearing losses */
	double losses = 0.0;
	for (int k = 0; k < 3; k++)
		losses += ch.stage[k].stage_loss_W + ch.stage[k].spline_loss_W + ch.stage[k].thrust_loss_W;
	assert_close(ch.input_power_W, ch.output_power_W + losses, 1e-12 * ch.input_power_W);
	assert_close(ch.efficiency, ch.output_power_W / ch.input_power_W, 1e-12);

	/* thrust-bearing friction lowers the efficiency, strongly (seed 000) */
	prsm_chain lo, hi;
	in.stages = 2;
	in.thrust_bearing_friction = 0.005;
	assert_int_equal(prsm_stages_chain(&lo, &in, stage_torque, &c, &err), 0);
	in.thrust_bearing_friction = 0.105;
	assert_int_equal(prsm_stages_chain(&hi, &in, stage_torque, &c, &err), 0);
	assert_true(lo.efficiency - hi.efficiency > 0.1);
	/* finite difference of the input torque in mu_NS: dT/dmu = r_NS B / (1 - lock) exactly when
	 * the stage torques do not depend on mu_NS (stage 2 carries F) */
	const double h = 1e-6;
	prsm_chain a, b;
	in.thrust_bearing_friction = 0.055 + h;
	assert_int_equal(prsm_stages_chain(&a, &in, stage_torque, &c, &err), 0);
	in.thrust_bearing_friction = 0.055 - h;
	assert_int_equal(prsm_stages_chain(&b, &in, stage_torque, &c, &err), 0);
	assert_true((a.input_torque_Nm - b.input_torque_Nm) / (2 * h) > 7000.0 * 0.016375);
}

static void test_errors(void **state)
{
	(void)state;
	prsm_chain_input in;
	stages_ctx c;
	prsm_chain ch;
	prsm_error err = PRSM_ERROR_INIT;
	seed000(&in, &c);
	in.spline_friction = 0.9;
	in.thrust_bearing_friction = 0.9;
	in.thrust_radius_mm[1] = 20.0;
	in.spline_radius_mm[1] = 5.0;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "lock"));
	seed000(&in, &c);
	in.stages = 0;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
	seed000(&in, &c);
	in.axial_load_N = NAN;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
	seed000(&in, &c);
	in.spline_radius_mm[1] = 0.0;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
	seed000(&in, &c);
	in.lead_mm[1] = -1.0;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
	seed000(&in, &c);
	c.eta[1] = NAN;
	assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &c, &err), PRSM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_frictionless_couplings),
		cmocka_unit_test(test_friction_balance),
		cmocka_unit_test(test_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
