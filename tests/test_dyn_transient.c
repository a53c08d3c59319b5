/*
 * test_dyn_transient.c: docs/model §8.2.4–8.2.6 integrated — a Coulomb start-up of case A
 * (V2's inputs) against a 1-D quadrature of the carrier's equation for the transient times, the
 * closed form of eta(0+), the energy balance, the stepper and halved tolerances; a torque input
 * from rest (V2b's inputs) against its torque balance and its late exponential rate; Karnopp
 * stick and break-away at the located event times; seed 000's two-stage start-up; time-varying
 * input and load against their closed-form work; progress, cancel and a run that does not
 * converge (an error and no curve).
 */
#include "test_dyn_support.h"

#include <gsl/gsl_integration.h>
#include <pthread.h>

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* V2's inputs (docs/model §8.8): Coulomb 0.05, v_eps 1e-4, 100 rad/s, 7 kN, sliding only. */
static void v2_options(prsm_dyn_options *o)
{
	prsm_dyn_options_init(o);
	o->losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o->time.end_s = 5e-4;
	o->time.output_step_s = 2e-6;
}

/* The carrier's own equation at constant screw speed, written out from the slip basis:
 * J_psi dw/dt = Z f.A(w), f = -mu N v / sqrt(|v|^2 + eps^2), N = -F / (Z (n_z - mu s_z)). */
typedef struct {
	double A[3], B[3], n[3], w, F, mu, eps, Z, J;
} carrier_eq;

static double carrier_force(double x, const carrier_eq *c)
{
	double v[3];
	for (int i = 0; i < 3; i++)
		v[i] = c->A[i] * x + c->B[i] * c->w;
	const double r = sqrt(dot3(v, v) + c->eps * c->eps);
	const double N = -c->F / (c->Z * (c->n[2] - c->mu * v[2] / r));
	return c->Z * (-c->mu * N * dot3(v, c->A) / r);
}

static double dt_dw(double x, void *p)
{
	const carrier_eq *c = p;
	return c->J / carrier_force(x, c);
}

static void carrier_eq_of(carrier_eq *c, const prsm_dyn_model *m, double w, double F, double mu)
{
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	for (int i = 0; i < 3; i++) {
		c->A[i] = p->A_mm[PRSM_DYN_FLANK_LOWER][i] * 1e-3;
		c->B[i] = p->B_mm[PRSM_DYN_FLANK_LOWER][i] * 1e-3;
		c->n[i] = p->normal[PRSM_DYN_FLANK_LOWER][i];
	}
	c->w = w;
	c->F = F;
	c->mu = mu;
	c->eps = 1e-4;
	c->Z = p->rollers;
	c->J = p->carrier_side_inertia_kg_m2;
}

static void test_coulomb_startup(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	v2_options(&o);
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	carrier_eq c;
	carrier_eq_of(&c, m, 100.0, 7000.0, 0.05);
	const double kstar = prsm_dyn_model_stage(m, 0)->carrier_ratio_min_slip;
	/* t(w) = int_0^w J dw / (Z f.A): the second method of V2 */
	gsl_integration_workspace *ws = gsl_integration_workspace_alloc(200);
	assert_non_null(ws);
	const double shares[3] = {0.5, 0.9, 0.99};
	for (int j = 0; j < 3; j++) {
		gsl_function f = {dt_dw, &c};
		double t, abserr;
		assert_int_equal(gsl_integration_qags(&f, 0.0, shares[j] * kstar * 100.0, 0.0, 1e-12, 200, ws, &t, &abserr), 0);
		assert_rel(r.carrier_time_to_share_s[0][j], t, 1e-6);
	}
	gsl_integration_workspace_free(ws);
	/* eta(0+): carrier at rest, v = B theta-dot: T = Lambda F + Z mu N |B|^2 w / r */
	const double L = 10e-3 / (2 * M_PI), w = 100.0;
	const double BB = dot3(c.B, c.B), r0 = sqrt(BB * w * w + c.eps * c.eps);
	const double N0 = -7000.0 / (10 * (c.n[2] - 0.05 * c.B[2] * w / r0));
	const double T0 = L * 7000.0 + 10 * 0.05 * N0 * BB * w / r0;
	assert_rel(r.point[0].input_torque_Nm, T0, 1e-12);
	assert_close(r.point[0].efficiency, L * 7000.0 / T0, 1e-12);
	assert_true(r.point[0].efficiency > 0.68 && r.point[0].efficiency < 0.70); /* ~0.7 (docs/model §8.2.6) */
	/* settled by the end: the algebraic state */
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	const size_t last = r.points - 1;
	assert_rel(r.stage[last].carrier_ratio, s->carrier_ratio[0], 1e-9);
	assert_close(r.point[last].efficiency, s->efficiency, 1e-9);
	assert_rel(r.stage[last].contact_normal_force_N, s->stage[0].contact_normal_force_N, 1e-9);
	assert_rel(r.stage[last].nut_contact_force_N, s->stage[0].nut_contact_force_N, 1e-9);
	assert_rel(r.stage[last].cage_force_N, s->stage[0].cage_force_N, 1e-6);
	assert_close(s->efficiency, a.efficiency.eta, 1e-4);
	/* the checks at every output time */
	assert_true(r.max_power_balance_relative < 1e-12);
	assert_true(r.max_newton_euler_residual < 1e-9);
	for (size_t i = 0; i < r.points; i++) {
		assert_true(r.stage[i].contact_normal_force_N > 0.0);
		assert_int_equal(r.stage[i].flank, PRSM_DYN_FLANK_LOWER); /* drive: the lower flank */
		assert_close(r.stage[i].gear_tooth_force_N,
		             fabs(r.stage[i].gear_tangential_force_N) / (2 * cos(20 * DEG)), 1e-12);
	}
	/* the carrier rate sigma_c ~ 7e4 /s at 7 kN, 100 rad/s (docs/model §8.2.6) */
	assert_true(s->carrier_rate_per_s[0] > 6e4 && s->carrier_rate_per_s[0] < 8e4);

	/* msbdf and halved tolerances: the same to the stated digits */
	for (int variant = 0; variant < 2; variant++) {
		prsm_dyn_options o2;
		v2_options(&o2);
		if (variant == 0) {
			o2.time.stepper = PRSM_DYN_STEPPER_MSBDF;
		} else {
			o2.time.rel_tol = o2.time.abs_tol = 5e-11;
		}
		prsm_dyn_model *m2 = dyn_test_model(1, &d, &a, &o2);
		prsm_dyn_result r2;
		dyn_test_simulate(&r2, m2);
		for (int j = 0; j < 3; j++)
			assert_rel(r2.carrier_time_to_share_s[0][j], r.carrier_time_to_share_s[0][j], 1e-6);
		for (size_t i = 0; i < r.points; i++)
			assert_close(r2.point[i].efficiency, r.point[i].efficiency, 1e-7);
		prsm_dyn_result_free(&r2);
		prsm_dyn_model_free(m2);
	}
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

/* Energy: input work - output work = the sliding work (Simpson over the output times) + the
 * carrier's kinetic energy at the end (the screw turns at a constant speed). */
static void test_energy_balance(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.0571);
	prsm_dyn_options o;
	v2_options(&o);
	o.input.signal.value = 83.9;
	o.load.value = 6411.0;
	o.time.end_s = 2e-4;
	o.time.output_step_s = 1e-7;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	assert_int_equal(r.points % 2, 1);
	double W = 0.0;
	const double h = 1e-7;
	for (size_t i = 0; i + 2 < r.points; i += 2)
		W += h / 3.0 * (r.point[i].power_sliding_W + 4 * r.point[i + 1].power_sliding_W + r.point[i + 2].power_sliding_W);
	const size_t e = r.points - 1;
	const double J = prsm_dyn_model_stage(m, 0)->carrier_side_inertia_kg_m2, psid = r.stage[e].carrier_speed_rad_s;
	const double lhs = r.point[e].energy_input_J - r.point[e].energy_output_J;
	assert_rel(lhs, W + 0.5 * J * psid * psid, 1e-7);
	assert_rel(r.point[e].energy_output_J, 6411.0 * 10e-3 / (2 * M_PI) * 83.9 * 2e-4, 1e-10);
	assert_true(r.point[e].energy_efficiency < r.point[e].efficiency);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

/* A torque input from rest (V2b's inputs): msbdf through the stiff start, rk8pd after; the final
 * approach is exponential at c_v / J_eff with J_eff = dT_in / d theta-ddot at the settled
 * state; the same with msbdf all the way. */
static void test_torque_input(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.input.kind = PRSM_DYN_INPUT_TORQUE;
	o.input.signal.value = 15.0;
	o.input.viscous_drag_Nm_s_per_rad = 0.02;
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o.time.end_s = 0.008;
	o.time.output_step_s = 1e-4;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	const double wf = s->screw_speed_rad_s;
	assert_true(r.stepper_switch_time_s > 0.0 && r.stepper_switch_time_s < 1e-4);
	assert_true(r.jacobian_evaluations > 0);
	assert_close(r.point[0].screw_speed_rad_s, 0.0, 0.0);
	assert_true(isnan(r.point[0].efficiency));
	for (size_t i = 1; i < r.points; i++) {
		assert_true(r.point[i].screw_speed_rad_s > r.point[i - 1].screw_speed_rad_s);
		assert_true(r.point[i].power_balance_relative < 1e-12);
		assert_true(r.point[i].newton_euler_residual < 1e-9);
		assert_close(r.point[i].motor_torque_Nm, 15.0, 0.0);
		assert_rel(r.point[i].input_torque_Nm, 15.0, 1e-11);
	}
	assert_true(r.speed_time_to_share_s[0] < r.speed_time_to_share_s[1]);
	assert_true(r.speed_time_to_share_s[1] < r.speed_time_to_share_s[2]);
	assert_true(r.speed_time_to_share_s[2] < 0.008);
	/* J_eff from two evaluations at the settled state */
	prsm_dyn_state st = {0};
	st.screw_speed_rad_s = wf;
	st.carrier_speed_rad_s[0] = s->carrier_ratio[0] * wf;
	prsm_dyn_point p0, p1;
	prsm_dyn_stage_point sp;
	st.screw_accel_rad_s2 = 0.0;
	assert_int_equal(prsm_dyn_evaluate(&p0, &sp, m, &st, NULL), 0);
	st.screw_accel_rad_s2 = 1e3;
	assert_int_equal(prsm_dyn_evaluate(&p1, &sp, m, &st, NULL), 0);
	const double Jeff = (p1.input_torque_Nm - p0.input_torque_Nm) / 1e3;
	const size_t i1 = 60, i2 = 80; /* 6 ms and 8 ms */
	const double rate = log((wf - r.point[i1].screw_speed_rad_s) / (wf - r.point[i2].screw_speed_rad_s)) /
	                    (r.point[i2].time_s - r.point[i1].time_s);
	/* the carriers follow at k*: their inertia J_psi k*^2 adds to the screw's */
	const double kstar = s->carrier_ratio[0], Jpsi = prsm_dyn_model_stage(m, 0)->carrier_side_inertia_kg_m2;
	assert_rel(rate, 0.02 / (Jeff + Jpsi * kstar * kstar), 1e-2);
	/* exactly: the slow eigenvalue of the linearised (theta-dot, psi-dot) system */
	double jac[2][2];
	for (int j = 0; j < 2; j++) {
		double acc[2][2];
		for (int side = 0; side < 2; side++) {
			prsm_dyn_state q = {0};
			const double dx = (side ? -1.0 : 1.0) * 1e-4 * wf;
			q.screw_speed_rad_s = wf + (j == 0 ? dx : 0.0);
			q.carrier_speed_rad_s[0] = kstar * wf + (j == 1 ? dx : 0.0);
			q.screw_accel_rad_s2 = NAN; /* solved from the motor torque */
			assert_int_equal(prsm_dyn_evaluate(&p0, &sp, m, &q, NULL), 0);
			acc[side][0] = p0.screw_accel_rad_s2;
			acc[side][1] = sp.carrier_accel_rad_s2;
		}
		for (int i = 0; i < 2; i++)
			jac[i][j] = (acc[0][i] - acc[1][i]) / (2e-4 * wf);
	}
	const double tr = jac[0][0] + jac[1][1], det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
	const double slow = 0.5 * tr + sqrt(0.25 * tr * tr - det); /* the one nearer 0 (both < 0) */
	assert_rel(rate, -slow, 1e-4);
	/* msbdf all the way */
	o.time.stiff_switch_rad_s = INFINITY;
	prsm_dyn_model *m2 = dyn_test_model(1, &d, &a, &o);
	prsm_dyn_result r2;
	dyn_test_simulate(&r2, m2);
	assert_true(isnan(r2.stepper_switch_time_s));
	for (int j = 0; j < 3; j++)
		assert_rel(r2.speed_time_to_share_s[j], r.speed_time_to_share_s[j], 1e-6);
	assert_rel(r2.point[10].screw_speed_rad_s, r.point[10].screw_speed_rad_s, 1e-6);
	assert_rel(r2.stage[10].carrier_ratio, r.stage[10].carrier_ratio, 1e-6);
	prsm_dyn_result_free(&r2);
	prsm_dyn_model_free(m2);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

/* Karnopp (docs/model §8.2.6): inside the break-away band the screw stays; a sine torque breaks
 * it away where T_m(t) = T_f; a ramp from 0 lets the load back-drive it, the rising torque
 * catches it (it sticks), then breaks it away at T_m = T_f. */
static void test_karnopp(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.input.kind = PRSM_DYN_INPUT_TORQUE;
	o.input.signal.value = 11.0;
	o.input.viscous_drag_Nm_s_per_rad = 0.02;
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o.friction.stick_model = PRSM_DYN_STICK_KARNOPP;
	o.friction.static_mu = 0.08;
	o.time.end_s = 0.002;
	o.time.output_step_s = 1e-4;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	double Tf, Tb;
	assert_int_equal(prsm_dyn_breakaway_torques(&Tf, &Tb, m, 0.0, NULL), 0);
	assert_true(Tb < 11.0 && 11.0 < Tf);
	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	for (size_t i = 0; i < r.points; i++) {
		assert_int_equal(r.point[i].stuck, 1);
		assert_close(r.point[i].screw_speed_rad_s, 0.0, 0.0);
		assert_close(r.point[i].screw_angle_rad, 0.0, 0.0);
		assert_close(r.stage[i].carrier_speed_rad_s, 0.0, 0.0);
		assert_close(r.point[i].input_torque_Nm, 11.0, 0.0);
	}
	assert_int_equal(r.mode_changes, 0);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);

	/* sine: 11 + 9 sin(2 pi 50 t) reaches T_f at asin((T_f - 11) / 9) / (2 pi 50) */
	o.input.signal.shape = PRSM_DYN_SHAPE_SINE;
	o.input.signal.sine_amplitude = 9.0;
	o.input.signal.sine_frequency_Hz = 50.0;
	o.time.end_s = 0.0045;
	m = dyn_test_model(1, &d, &a, &o);
	dyn_test_simulate(&r, m);
	const double t_break = asin((Tf - 11.0) / 9.0) / (2 * M_PI * 50.0);
	assert_true(r.mode_changes >= 1);
	assert_int_equal(r.mode_change_to_stick[0], 0);
	assert_close(r.mode_change_time_s[0], t_break, 1e-9);
	for (size_t i = 0; i < r.points; i++) {
		if (r.point[i].time_s < t_break) {
			assert_int_equal(r.point[i].stuck, 1);
			assert_close(r.point[i].screw_angle_rad, 0.0, 0.0);
		} else {
			assert_int_equal(r.point[i].stuck, 0);
			assert_true(r.point[i].screw_speed_rad_s > 0.0);
		}
		assert_true(r.point[i].power_balance_relative < 1e-12);
	}
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);

	/* ramp 0 -> 30 N m over 10 ms: back-driven first (T_m < T_b), caught, broken away */
	o.input.signal.shape = PRSM_DYN_SHAPE_RAMP;
	o.input.signal.value = 30.0;
	o.input.signal.ramp_time_s = 0.01;
	o.time.end_s = 0.008;
	m = dyn_test_model(1, &d, &a, &o);
	dyn_test_simulate(&r, m);
	assert_int_equal(r.mode_changes, 2);
	assert_int_equal(r.mode_change_to_stick[0], 1);
	assert_int_equal(r.mode_change_to_stick[1], 0);
	assert_true(r.mode_change_time_s[0] > Tb / 30.0 * 0.01); /* caught once inside the band */
	assert_close(r.mode_change_time_s[1], Tf / 30.0 * 0.01, 1e-9);
	assert_true(r.point[10].screw_speed_rad_s < 0.0); /* 1 ms: back-driven */
	assert_true(r.max_power_balance_relative < 1e-12);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

/* Seed 000's two stages start up: both carriers settle (stage 1 first, it is lighter), the
 * efficiency rises in two steps, the checks hold at every output time. */
static void test_two_stage_startup(void **state)
{
	(void)state;
	prsm_design d[2];
	prsm_analysis a[2];
	dyn_seed000(d, a);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	dyn_seed000_inertia(&o);
	o.couplings.spline_friction = 0.15;
	o.couplings.thrust_bearing_friction = 0.055;
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o.time.end_s = 0.002;
	o.time.output_step_s = 1e-5;
	prsm_dyn_model *m = dyn_test_model(2, d, a, &o);
	prsm_dyn_result r;
	dyn_test_simulate(&r, m);
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	assert_true(r.carrier_time_to_share_s[0][2] < r.carrier_time_to_share_s[1][2]);
	const size_t e = r.points - 1;
	for (int k = 0; k < 2; k++)
		assert_rel(r.stage[e * 2 + k].carrier_ratio, s->carrier_ratio[k], 1e-7);
	assert_close(r.point[e].efficiency, s->efficiency, 1e-7);
	/* eta at carrier 1's t99: between eta(0+) and the settled value */
	const size_t i99 = (size_t)ceil(r.carrier_time_to_share_s[0][2] / 1e-5);
	assert_true(r.point[0].efficiency < r.point[i99].efficiency);
	assert_true(r.point[i99].efficiency < s->efficiency - 0.01);
	assert_true(r.max_power_balance_relative < 1e-12);
	assert_true(r.max_newton_euler_residual < 1e-9);
	for (size_t i = 0; i < r.points; i++) {
		assert_true(r.stage[2 * i + 1].spline_force_N > 0.0);
		assert_true(r.stage[2 * i + 1].thrust_torque_Nm > 0.0);
		assert_rel(r.stage[2 * i + 1].stage_axial_load_N, 7000.0, 1e-12);
	}
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

/* A speed ramp (with its kink inside the run) and a sine load: the output work in closed form. */
static void test_time_varying(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.0537);
	const double L = 10e-3 / (2 * M_PI);
	for (int variant = 0; variant < 2; variant++) {
		prsm_dyn_options o;
		prsm_dyn_options_init(&o);
		o.time.end_s = 3e-3;
		o.time.output_step_s = 3e-5;
		if (variant == 0) {
			o.input.signal.shape = PRSM_DYN_SHAPE_RAMP;
			o.input.signal.value = 71.3;
			o.input.signal.ramp_time_s = 1.33e-3;
			o.load.value = 5311.0;
		} else {
			o.input.signal.value = 91.7;
			o.load.shape = PRSM_DYN_SHAPE_SINE;
			o.load.value = 5311.0;
			o.load.sine_amplitude = 1723.0;
			o.load.sine_frequency_Hz = 417.0;
		}
		prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
		prsm_dyn_result r;
		dyn_test_simulate(&r, m);
		for (size_t i = 0; i < r.points; i++) {
			const double t = r.point[i].time_s;
			double W;
			if (variant == 0) {
				const double tr = 1.33e-3, th = t < tr ? 0.5 * 71.3 * t * t / tr : 71.3 * (t - 0.5 * tr);
				W = 5311.0 * L * th;
				assert_close(r.point[i].screw_angle_rad, th, 1e-14);
			} else {
				const double w = 2 * M_PI * 417.0;
				W = L * 91.7 * (5311.0 * t + 1723.0 * (1.0 - cos(w * t)) / w);
			}
			assert_close(r.point[i].energy_output_J, W, 1e-9 * W + 1e-15);
			assert_true(r.point[i].power_balance_relative < 1e-12);
			assert_true(r.point[i].newton_euler_residual < 1e-9);
		}
		prsm_dyn_result_free(&r);
		prsm_dyn_model_free(m);
	}
}

typedef struct {
	int calls;
	size_t last_done, planned;
	int monotone;
	prsm_cancel_flag *cancel_after_first;
} progress_log;

static void on_progress(void *ctx, const prsm_progress *p)
{
	progress_log *l = ctx;
	if (l->calls > 0 && p->done < l->last_done)
		l->monotone = 0;
	l->calls++;
	l->last_done = p->done;
	l->planned = p->planned;
	if (l->cancel_after_first != NULL)
		prsm_cancel_set(l->cancel_after_first, 1);
}

/* Progress in simulated nanoseconds; cancel; a run that cannot converge returns no curve. */
static void test_progress_cancel_failure(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	v2_options(&o);
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	prsm_dyn_result r;
	prsm_error err = PRSM_ERROR_INIT;
	progress_log log = {0, 0, 0, 1, NULL};
	assert_int_equal(prsm_dyn_simulate(&r, m, NULL, on_progress, &log, &err), 0);
	assert_true(log.calls >= 2 && log.calls <= 201);
	assert_true(log.monotone);
	assert_int_equal(log.planned, 500000);
	assert_int_equal(log.last_done, log.planned);
	prsm_dyn_result_free(&r);
	/* cancelled from the progress callback: PRSM_ECANCELLED and nothing else */
	prsm_cancel_flag flag;
	prsm_cancel_set(&flag, 0);
	progress_log stop = {0, 0, 0, 1, &flag};
	assert_int_equal(prsm_dyn_simulate(&r, m, &flag, on_progress, &stop, &err), PRSM_ECANCELLED);
	assert_int_equal(err.code, PRSM_ECANCELLED);
	assert_int_equal(r.points, 0);
	assert_null(r.point);
	assert_null(r.stage);
	prsm_dyn_model_free(m);
	/* too few steps allowed: it does not converge, and says so */
	o.time.max_steps = 3;
	m = dyn_test_model(1, &d, &a, &o);
	prsm_error_clear(&err);
	assert_int_equal(prsm_dyn_simulate(&r, m, NULL, NULL, NULL, &err), PRSM_ENOCONVERGE);
	assert_non_null(strstr(err.message, "did not converge"));
	assert_int_equal(r.points, 0);
	assert_null(r.point);
	prsm_dyn_result_free(&r);
	prsm_dyn_model_free(m);
}

typedef struct {
	const prsm_dyn_model *m;
	prsm_dyn_result r;
	int rc;
} thread_run;

static void *simulate_thread(void *arg)
{
	thread_run *t = arg;
	t->rc = prsm_dyn_simulate(&t->r, t->m, NULL, NULL, NULL, NULL);
	return NULL;
}

/* One model, read-only, serves simulations on several threads at once (ThreadSanitizer checks
 * this in the tsan build); they agree bit for bit. */
static void test_shared_model_threads(void **state)
{
	(void)state;
	prsm_design d[2];
	prsm_analysis a[2];
	dyn_seed000(d, a);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	dyn_seed000_inertia(&o);
	o.couplings.spline_friction = 0.15;
	o.couplings.thrust_bearing_friction = 0.055;
	o.time.end_s = 5e-4;
	o.time.output_step_s = 1e-5;
	prsm_dyn_model *m = dyn_test_model(2, d, a, &o);
	thread_run runs[3];
	pthread_t th[3];
	for (int i = 0; i < 3; i++) {
		runs[i].m = m;
		runs[i].rc = -99;
		assert_int_equal(pthread_create(&th[i], NULL, simulate_thread, &runs[i]), 0);
	}
	for (int i = 0; i < 3; i++)
		assert_int_equal(pthread_join(th[i], NULL), 0);
	for (int i = 0; i < 3; i++) {
		assert_int_equal(runs[i].rc, 0);
		assert_int_equal(runs[i].r.points, runs[0].r.points);
		assert_memory_equal(runs[i].r.stage, runs[0].r.stage, runs[0].r.points * 2 * sizeof *runs[0].r.stage);
	}
	for (int i = 0; i < 3; i++)
		prsm_dyn_result_free(&runs[i].r);
	prsm_dyn_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_coulomb_startup),
		cmocka_unit_test(test_energy_balance),
		cmocka_unit_test(test_torque_input),
		cmocka_unit_test(test_karnopp),
		cmocka_unit_test(test_two_stage_startup),
		cmocka_unit_test(test_time_varying),
		cmocka_unit_test(test_progress_cancel_failure),
		cmocka_unit_test(test_shared_model_threads),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
