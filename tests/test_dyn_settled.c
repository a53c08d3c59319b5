/*
 * test_dyn_settled.c: docs/model §8.2.5 — the settled state, computed algebraically: its
 * efficiency equals the statics engine's within 1e-4 (one stage and seed 000's two-stage chain,
 * sliding only and with the statics losses; the chain within 2e-5 of the statics chain with the
 * losses off and nut-roller mu 0, V3), the carriers at k*, the spline force and thrust-bearing
 * torque of the chain; a carrier drag against an independent bisection; a torque input's
 * settled speed against the torque balance; no steady state when nothing limits the speed.
 */
#include "test_dyn_support.h"

#include "model/performance.h"
#include "model/stages.h"

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* One stage: sliding only against prsm_efficiency_sliding, with the losses against
 * prsm_performance_compute (load distribution, spin, gear, drag, seal). */
static void test_settled_one_stage(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.3, 2.87, 38.0}, {6, 1.7, 4.13, 42.5}};
	for (size_t i = 0; i < sizeof designs / sizeof designs[0]; i++) {
		prsm_design d;
		prsm_analysis a;
		standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 5, 9);
		d.mu_screw_roller = 0.0731;
		d.axial_load_N = 5432.0;
		d.screw_speed_rad_s = 87.3;
		d.losses.drag_torque_Nm = 0.0117;
		d.losses.viscous_drag_Nm_s_per_rad = 1.1e-4;
		dyn_test_analyse(&a, &d);
		for (int losses = 0; losses < 2; losses++) {
			prsm_dyn_options o;
			prsm_dyn_options_init(&o);
			o.input.signal.value = 87.3;
			o.load.value = 5432.0;
			o.losses = losses ? PRSM_DYN_LOSSES_SLIDING_ONLY : PRSM_DYN_LOSSES_STATICS;
			prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
			const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
			double eta_statics;
			if (losses) {
				eta_statics = a.efficiency.eta;
			} else {
				prsm_performance perf;
				assert_int_equal(prsm_performance_compute(&perf, &d, &a, NULL), 0);
				eta_statics = perf.losses.eta;
				prsm_performance_free(&perf);
			}
			assert_close(s->efficiency_statics, eta_statics, 1e-12);
			assert_close(s->efficiency, eta_statics, 1e-4);
			/* k* slides less than the contact-radius ratio: a little more efficient */
			assert_true(s->efficiency > eta_statics);
			assert_rel(s->carrier_ratio[0], prsm_dyn_model_stage(m, 0)->carrier_ratio_min_slip, 1e-14);
			assert_close(s->carrier_ratio_statics[0], a.kinematics.carrier_ratio, 0.0);
			/* theta-ddot = 0 and psi-ddot = 0 there; the checks hold */
			assert_close(s->point.screw_accel_rad_s2, 0.0, 0.0);
			assert_close(s->stage[0].carrier_accel_rad_s2, 0.0, 1e-6);
			assert_true(s->point.power_balance_relative < 1e-12);
			assert_true(s->point.newton_euler_residual < 1e-9);
			/* the stage carries the load */
			assert_rel(s->stage[0].stage_axial_load_N, 5432.0, 1e-12);
			prsm_dyn_model_free(m);
		}
	}
	/* case A: the difference is the k* question alone, about 2e-5 (docs/model §8.2.5) */
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const double diff = prsm_dyn_model_settled(m)->efficiency - a.efficiency.eta;
	assert_true(diff > 1.5e-5 && diff < 2.5e-5);
	prsm_dyn_model_free(m);
}

/* Stage torques of the statics chain, computed here from the statics engine. */
typedef struct {
	prsm_design *d;
	prsm_analysis *a;
	int losses;
	double speed_rad_s;
} chain_ctx;

static double stage_torque(void *ctx, int k, double load_N)
{
	chain_ctx *c = ctx;
	if (c->losses) {
		prsm_design d = c->d[k];
		d.axial_load_N = load_N;
		d.screw_speed_rad_s = c->speed_rad_s;
		return prsm_performance_input_torque(&d, &c->a[k]);
	}
	return load_N * prsm_design_lead_mm(&c->d[k]) * 1e-3 / (2 * M_PI * c->a[k].efficiency.eta);
}

/* Seed 000's two-stage chain (V3's setting, docs/model §8.8): the settled chain efficiency, the
 * spline force and thrust-bearing torque equal the statics chain's. */
static void test_settled_two_stage(void **state)
{
	(void)state;
	prsm_design d[2];
	prsm_analysis a[2];
	dyn_seed000(d, a);
	const double rows[][2] = {{0.0, 0.0}, {0.10, 0.005}, {0.15, 0.055}, {0.20, 0.105}, {0.137, 0.0731}};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
		for (int losses = 0; losses < 2; losses++) {
			prsm_dyn_options o;
			prsm_dyn_options_init(&o);
			dyn_seed000_inertia(&o);
			o.couplings.spline_friction = rows[i][0];
			o.couplings.thrust_bearing_friction = rows[i][1];
			o.losses = losses ? PRSM_DYN_LOSSES_STATICS : PRSM_DYN_LOSSES_SLIDING_ONLY;
			prsm_dyn_model *m = dyn_test_model(2, d, a, &o);
			const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
			prsm_chain_input in;
			memset(&in, 0, sizeof in);
			in.stages = 2;
			in.lead_mm[0] = in.lead_mm[1] = 10.0;
			in.spline_friction = rows[i][0];
			in.thrust_bearing_friction = rows[i][1];
			in.spline_radius_mm[1] = 9.75;                  /* r_s of stage 1 */
			in.thrust_radius_mm[1] = 0.5 * (16.25 + 16.5);  /* (r_n,1 + r_s,2) / 2 */
			in.axial_load_N = 7000.0;
			in.screw_speed_rad_s = 100.0;
			chain_ctx ctx = {d, a, losses, 100.0};
			prsm_chain ch;
			assert_int_equal(prsm_stages_chain(&ch, &in, stage_torque, &ctx, NULL), 0);
			assert_close(s->efficiency_statics, ch.efficiency, 1e-12);
			assert_close(s->efficiency, ch.efficiency, losses ? 1e-4 : 2e-5);
			assert_rel(s->stage[1].spline_force_N, ch.stage[1].spline_force_N, 1e-3);
			assert_rel(s->stage[1].thrust_torque_Nm, ch.stage[1].thrust_torque_Nm, 1e-3);
			assert_rel(s->stage[1].thrust_load_N, ch.stage[1].thrust_load_N, 1e-4);
			assert_rel(s->stage[0].stage_axial_load_N, ch.stage[0].load_N, 1e-4);
			assert_rel(s->stage[1].stage_axial_load_N, 7000.0, 1e-12);
			/* both carriers at their k*; stage 2 settles slightly higher (seed 000, V3) */
			for (int k = 0; k < 2; k++)
				assert_rel(s->carrier_ratio[k], a[k].kinematics.carrier_ratio_min_slip, 1e-14);
			assert_true(s->carrier_ratio[1] > s->carrier_ratio[0]);
			assert_true(s->point.power_balance_relative < 1e-12);
			assert_true(s->point.newton_euler_residual < 1e-9);
			if (rows[i][0] == 0.0) {
				/* frictionless couplings: the travel-weighted harmonic mean of the stages' */
				const double T2 = s->stage[1].spline_torque_Nm, T1 = s->stage[0].spline_torque_Nm - T2;
				const double eta1 = 7000.0 * 10e-3 / (2 * M_PI * T1), eta2 = 7000.0 * 10e-3 / (2 * M_PI * T2);
				assert_close(s->efficiency, 20.0 / (10.0 / eta1 + 10.0 / eta2), 1e-12);
			}
			prsm_dyn_model_free(m);
		}
}

/* Z f.A - c_C psi-dot = 0 with a carrier drag (docs/model §8.2.5), by bisection here on the
 * friction law written out from the slip basis: Coulomb, one stage, theta-ddot = 0. */
static void test_settled_carrier_drag(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.0613);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o.friction.carrier_drag_Nm_s_per_rad = 3.7e-3;
	o.input.signal.value = 93.1;
	o.load.value = 6217.0;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	double A[3], B[3];
	const double *n = p->normal[PRSM_DYN_FLANK_LOWER];
	for (int i = 0; i < 3; i++) {
		A[i] = p->A_mm[PRSM_DYN_FLANK_LOWER][i] * 1e-3;
		B[i] = p->B_mm[PRSM_DYN_FLANK_LOWER][i] * 1e-3;
	}
	const double w = 93.1, F = 6217.0, mu = 0.0613, eps = 1e-4, Z = 10, cC = 3.7e-3;
	double lo = 0.0, hi = p->carrier_ratio_min_slip * w;
	for (int it = 0; it < 200; it++) {
		const double x = 0.5 * (lo + hi);
		double v[3];
		for (int i = 0; i < 3; i++)
			v[i] = A[i] * x + B[i] * w;
		const double r = sqrt(dot3(v, v) + eps * eps);
		const double N = -F / (Z * (n[2] - mu * v[2] / r));
		const double g = Z * (-mu * N * dot3(v, A) / r) - cC * x;
		if (g > 0.0)
			lo = x;
		else
			hi = x;
	}
	assert_rel(s->carrier_ratio[0] * w, 0.5 * (lo + hi), 1e-12);
	assert_true(s->carrier_ratio[0] < p->carrier_ratio_min_slip - 1e-4);
	assert_close(s->stage[0].carrier_accel_rad_s2, 0.0, 1e-6);
	/* the drag's power is in the balance */
	assert_true(s->point.power_balance_relative < 1e-12);
	prsm_dyn_model_free(m);

	/* Stribeck without drag: still k* (every isotropic law) */
	prsm_dyn_options_init(&o);
	o.friction.model = PRSM_DYN_FRICTION_STRIBECK;
	o.friction.static_mu = 0.1;
	o.friction.stribeck_velocity_m_s = 0.31;
	m = dyn_test_model(1, &d, &a, &o);
	assert_rel(prsm_dyn_model_settled(m)->carrier_ratio[0], prsm_dyn_model_stage(m, 0)->carrier_ratio_min_slip, 1e-14);
	prsm_dyn_model_free(m);
}

/* Torque input: the settled speed balances the motor torque against the running torque and
 * the viscous drag; without a drag nothing limits the speed (no steady state). */
static void test_settled_torque_input(void **state)
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
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const prsm_dyn_settled *s = prsm_dyn_model_settled(m);
	assert_int_equal(s->defined, 1);
	assert_int_equal(s->at_rest, 0);
	const double w = s->screw_speed_rad_s;
	assert_true(w > 100.0 && w < 200.0);
	/* at that speed, carriers at k*, no acceleration: T_in = T_m */
	prsm_dyn_state st = {0};
	st.screw_speed_rad_s = w;
	st.screw_accel_rad_s2 = 0.0;
	st.carrier_speed_rad_s[0] = prsm_dyn_model_stage(m, 0)->carrier_ratio_min_slip * w;
	prsm_dyn_point p;
	prsm_dyn_stage_point sp;
	assert_int_equal(prsm_dyn_evaluate(&p, &sp, m, &st, NULL), 0);
	assert_rel(p.input_torque_Nm, 15.0, 1e-12);
	/* and the running torque there is the speed input's at the same speed */
	prsm_dyn_options os;
	prsm_dyn_options_init(&os);
	os.input.signal.value = w;
	os.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	prsm_dyn_model *ms = dyn_test_model(1, &d, &a, &os);
	assert_rel(prsm_dyn_model_settled(ms)->input_torque_Nm + 0.02 * w, 15.0, 1e-12);
	prsm_dyn_model_free(ms);
	prsm_dyn_model_free(m);

	/* no drag: the screw runs away */
	o.input.viscous_drag_Nm_s_per_rad = 0.0;
	m = dyn_test_model(1, &d, &a, &o);
	assert_int_equal(prsm_dyn_model_settled(m)->defined, 0);
	assert_true(isnan(prsm_dyn_model_settled(m)->efficiency));
	prsm_dyn_model_free(m);

	/* Karnopp inside the break-away band, from rest: it stays */
	o.input.viscous_drag_Nm_s_per_rad = 0.02;
	o.friction.stick_model = PRSM_DYN_STICK_KARNOPP;
	o.friction.static_mu = 0.08;
	m = dyn_test_model(1, &d, &a, &o);
	assert_int_equal(prsm_dyn_model_settled(m)->at_rest, 1);
	assert_close(prsm_dyn_model_settled(m)->screw_speed_rad_s, 0.0, 0.0);
	prsm_dyn_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_settled_one_stage),
		cmocka_unit_test(test_settled_two_stage),
		cmocka_unit_test(test_settled_carrier_drag),
		cmocka_unit_test(test_settled_torque_input),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
