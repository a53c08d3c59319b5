/*
 * test_dyn_model.c: docs/model §8.1–8.2.4 — the kinematic structure of a stage (A, B, n.A = n.B
 * = 0, k* and the statics engine's carrier_ratio_min_slip), the masses and inertias of §8.2.2,
 * J_theta against the torque an acceleration needs, the Newton-Euler recovery against the
 * Lagrange carrier equation and the power balance on random states (one to three stages, every
 * friction law, couplings, drags, the statics losses), the loss torques against the statics
 * engine at scaled loads, the Karnopp break-away torques against their closed form, and every
 * refusal of the options and the model.
 */
#include "test_dyn_support.h"

#include "model/losses.h"
#include "model/performance.h"

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* xorshift64*: high-entropy test inputs without util/rng's streams */
static double uniform(uint64_t *s, double lo, double hi)
{
	*s ^= *s >> 12;
	*s ^= *s << 25;
	*s ^= *s >> 27;
	const uint64_t r = *s * 2685821657736338717ULL;
	return lo + (hi - lo) * ((double)(r >> 11) / 9007199254740992.0);
}

/* docs/model §8.8 V1: A, B of the lower flank, |A|^2, A.B, |B|^2, k*; the statics engine's k* */
static void test_slip_basis_case_a(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	dyn_v1_options(&o);
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	const double *A = p->A_mm[PRSM_DYN_FLANK_LOWER], *B = p->B_mm[PRSM_DYN_FLANK_LOWER];
	const double Aexp[3] = {-2.507125, 25.81091, 0.0}, Bexp[3] = {-0.6267813, -9.797272, -1.591549};
	for (int i = 0; i < 3; i++) {
		assert_close(A[i], Aexp[i], 1e-6 * fabs(Aexp[1]));
		assert_close(B[i], Bexp[i], 1e-6 * fabs(Bexp[1]));
	}
	assert_rel(dot3(A, A), 672.48887, 1e-7);
	assert_rel(dot3(A, B), -251.30511, 1e-7);
	assert_rel(dot3(B, B), 98.912421, 1e-7);
	assert_rel(p->carrier_ratio_min_slip, 0.37369408, 1e-6);
	/* the statics engine reports k* beside its contact-radius ratio (O1, docs/model §8.9) */
	assert_close(a.kinematics.carrier_ratio_min_slip, p->carrier_ratio_min_slip, 1e-15);
	assert_close(a.kinematics.carrier_ratio, 0.37564, 5e-6);
	assert_close(p->carrier_ratio_statics, a.kinematics.carrier_ratio, 0.0);
	/* cage speed -0.5 %, slip speed +0.03 % (docs/model §8.1 item 6) */
	assert_close(p->carrier_ratio_min_slip / a.kinematics.carrier_ratio - 1.0, -0.005186, 2e-5);
	double v_star[3], v_cr[3];
	for (int i = 0; i < 3; i++) {
		v_star[i] = B[i] + p->carrier_ratio_min_slip * A[i];
		v_cr[i] = B[i] + a.kinematics.carrier_ratio * A[i];
	}
	assert_close(sqrt(dot3(v_cr, v_cr) / dot3(v_star, v_star)) - 1.0, 3e-4, 1e-4);
	assert_close(p->min_slip_mm_per_rad, sqrt(dot3(v_star, v_star)), 1e-14);
	/* ring gear: i_g = 5, r_g1 = r_r; the nut contact at the pitch point (16.25, 0) */
	assert_close(p->ring_gear_ratio, 5.0, 1e-15);
	assert_close(p->gear_pitch_radius_mm, 3.25, 1e-14);
	assert_close(p->nut_contact_mm[0][0], 16.25, 1e-9);
	assert_close(p->nut_contact_mm[0][1], 0.0, 1e-9);
	prsm_dyn_model_free(m);
}

/* docs/model §8.1 item 5: n.A = n.B = 0 to 1e-12 with the statics contact, on both flanks, for
 * several geometries and both hands; k* is where |A k + B| is smallest and the same for both
 * flanks and both hands. */
static void test_normal_does_no_work(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.3, 2.87, 38.0}, {7, 2.5, 3.1, 55.0}, {6, 1.7, 4.13, 42.5}};
	for (size_t i = 0; i < sizeof designs / sizeof designs[0]; i++) {
		double kstar[2];
		for (int hand = 0; hand < 2; hand++) {
			prsm_design d;
			prsm_analysis a;
			standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 3, 5);
			d.hand = hand ? PRSM_HAND_LEFT : PRSM_HAND_RIGHT;
			dyn_test_analyse(&a, &d);
			prsm_dyn_options o;
			dyn_v1_options(&o);
			prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
			const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
			for (int fl = 0; fl < 2; fl++) {
				assert_close(p->normal_dot_A_mm[fl], 0.0, 1e-12);
				assert_close(p->normal_dot_B_mm[fl], 0.0, 1e-12);
				assert_close(sqrt(dot3(p->normal[fl], p->normal[fl])), 1.0, 1e-15);
				/* the nut contact rolls: A at p_n vanishes */
				const double *pn = p->nut_contact_mm[fl];
				const double a_mm = p->orbit_radius_mm, s = 1.0 - p->ring_gear_ratio;
				assert_close(a_mm + s * (pn[0] - a_mm), 0.0, 1e-9);
				const double *A = p->A_mm[fl], *B = p->B_mm[fl];
				assert_close(-dot3(A, B) / dot3(A, A), p->carrier_ratio_min_slip, 1e-14);
				/* |v(k)| is smallest at k*: its neighbours are slower... faster */
				double vs[3];
				for (int j = -1; j <= 1; j++) {
					const double k = p->carrier_ratio_min_slip + j * 1e-4;
					double v[3] = {B[0] + k * A[0], B[1] + k * A[1], B[2] + k * A[2]};
					vs[j + 1] = dot3(v, v);
				}
				assert_true(vs[1] < vs[0] && vs[1] < vs[2]);
			}
			assert_close(a.kinematics.carrier_ratio_min_slip, p->carrier_ratio_min_slip, 1e-15);
			kstar[hand] = p->carrier_ratio_min_slip;
			prsm_dyn_model_free(m);
		}
		assert_close(kstar[0], kstar[1], 1e-14);
	}
}

/* docs/model §8.2.2, case A column */
static void test_masses_case_a(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	assert_close(p->gear_face_width_mm, 4.0, 1e-15);
	assert_close(p->roller_length_mm, 28.0, 1e-14);
	assert_close(p->roller_mass_kg, 7.2936e-3, 5e-8);
	assert_close(p->roller_inertia_kg_m2, 3.8520e-8, 5e-12);
	assert_close(p->carrier_mass_kg, 16.671e-3, 5e-7);
	assert_close(p->carrier_inertia_kg_m2, 2.9935e-6, 5e-10);
	assert_close(p->nut_mass_kg, 125.82e-3, 5e-6);
	assert_close(p->screw_mass_kg, 300.08e-3, 5e-6);
	assert_close(p->screw_inertia_kg_m2, 1.4263e-5, 5e-10);
	assert_rel(p->carrier_side_inertia_kg_m2, 2.148289e-5, 1e-6);
	assert_close(p->axial_mass_kg, p->nut_mass_kg + 10 * p->roller_mass_kg + p->carrier_mass_kg, 1e-15);
	const double L = 10e-3 / (2 * M_PI);
	assert_close(p->cumulative_lead_m_per_rad, L, 1e-18);
	assert_rel(prsm_dyn_model_screw_side_inertia(m), p->screw_inertia_kg_m2 + p->axial_mass_kg * L * L, 1e-14);
	prsm_dyn_model_free(m);

	/* overrides: each one replaces its default; J_R follows an overridden m_R; the payload
	 * rides on the last nut; J_M on the screw */
	o.inertia.stage[0].roller_mass_kg = 0.01237;
	o.inertia.stage[0].carrier_inertia_kg_m2 = 3.71e-6;
	o.inertia.stage[0].gear_face_width_mm = 3.3;
	o.inertia.payload_kg = 4.13;
	o.inertia.stroke_mm = 237.0;
	o.inertia.density_kg_m3 = 7810.0;
	o.input.motor_inertia_kg_m2 = 2.3e-5;
	m = dyn_test_model(1, &d, &a, &o);
	p = prsm_dyn_model_stage(m, 0);
	const double rr = 3.25e-3, rs = 9.75e-3, a_m = 13e-3;
	assert_close(p->roller_length_mm, 26.6, 1e-13);
	assert_close(p->roller_mass_kg, 0.01237, 0.0);
	assert_rel(p->roller_inertia_kg_m2, 0.5 * 0.01237 * rr * rr, 1e-14);
	assert_close(p->carrier_inertia_kg_m2, 3.71e-6, 0.0);
	assert_rel(p->screw_mass_kg, 7810.0 * M_PI * rs * rs * (26.6e-3 + 0.237), 1e-13);
	assert_rel(p->carrier_side_inertia_kg_m2, 3.71e-6 + 10 * (0.01237 * a_m * a_m + 0.5 * 0.01237 * rr * rr * 16), 1e-13);
	assert_rel(p->axial_mass_kg, p->nut_mass_kg + 10 * 0.01237 + p->carrier_mass_kg + 4.13, 1e-14);
	assert_rel(prsm_dyn_model_screw_side_inertia(m),
	           2.3e-5 + p->screw_inertia_kg_m2 + p->axial_mass_kg * L * L, 1e-14);
	prsm_dyn_model_free(m);
}

/* J_theta (docs/model §8.2.2) is what an acceleration costs: with viscous friction (independent
 * of the normal force) T_in(theta-ddot) - T_in(0) = J_theta theta-ddot, one stage and two. */
static void test_screw_side_inertia(void **state)
{
	(void)state;
	prsm_design d[2];
	prsm_analysis a[2];
	dyn_seed000(d, a);
	for (int K = 1; K <= 2; K++) {
		prsm_dyn_options o;
		dyn_v1_options(&o);
		dyn_seed000_inertia(&o);
		o.inertia.payload_kg = 12.7;
		o.input.motor_inertia_kg_m2 = 3.1e-5;
		prsm_dyn_model *m = dyn_test_model(K, d, a, &o);
		prsm_dyn_state s = {0};
		s.time_s = 1e-4;
		s.screw_speed_rad_s = 47.3;
		s.carrier_speed_rad_s[0] = 13.1;
		s.carrier_speed_rad_s[1] = 9.7;
		prsm_dyn_point p0, p1;
		prsm_dyn_stage_point sp[2];
		s.screw_accel_rad_s2 = 0.0;
		assert_int_equal(prsm_dyn_evaluate(&p0, sp, m, &s, NULL), 0);
		s.screw_accel_rad_s2 = 1.73e4;
		assert_int_equal(prsm_dyn_evaluate(&p1, sp, m, &s, NULL), 0);
		/* the formula from the parts */
		double J = 3.1e-5;
		for (int k = 0; k < K; k++) {
			const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, k);
			const double Lk = p->cumulative_lead_m_per_rad;
			J += p->screw_inertia_kg_m2 + p->axial_mass_kg * Lk * Lk;
			if (k > 0) {
				const double Lp = prsm_dyn_model_stage(m, k - 1)->cumulative_lead_m_per_rad;
				J += p->screw_mass_kg * Lp * Lp;
			}
		}
		assert_rel(prsm_dyn_model_screw_side_inertia(m), J, 1e-14);
		assert_rel((p1.input_torque_Nm - p0.input_torque_Nm) / 1.73e4, J, 1e-9);
		prsm_dyn_model_free(m);
	}
}

/* Three standard stages nested (their radii need not fit inside each other for the model). */
static void three_stages(prsm_design d[3], prsm_analysis a[3], double mu)
{
	const double rr[3] = {3.25, 5.5, 7.75};
	for (int k = 0; k < 3; k++) {
		standard_design(&d[k], 5, 2.0, rr[k], 45.0, 7, 10);
		d[k].mu_screw_roller = mu;
		d[k].losses.drag_torque_Nm = 0.0131 * (k + 1);
		d[k].losses.seal_torque_Nm = 0.0217;
		d[k].losses.viscous_drag_Nm_s_per_rad = 1.3e-4;
		dyn_test_analyse(&a[k], &d[k]);
	}
}

/* On random states (speeds of either sign, accelerations, time-varying load): the Newton-Euler
 * recovery gives the Lagrange psi-ddot to 1e-9 and the power balance closes to 1e-12, for every
 * friction law, with drags, coupling friction and the statics losses, one to three stages. */
static void test_checks_on_random_states(void **state)
{
	(void)state;
	prsm_design d[3];
	prsm_analysis a[3];
	three_stages(d, a, 0.0613);
	uint64_t seed = 0x9e3779b97f4a7c15ULL;
	const int models[] = {PRSM_DYN_FRICTION_COULOMB, PRSM_DYN_FRICTION_VISCOUS, PRSM_DYN_FRICTION_STRIBECK};
	int count = 0;
	for (int K = 1; K <= 3; K++)
		for (int fm = 0; fm < 3; fm++)
			for (int losses = 0; losses < 2; losses++) {
				prsm_dyn_options o;
				prsm_dyn_options_init(&o);
				o.friction.model = models[fm];
				o.friction.viscous_N_s_per_m = 23.7;
				o.friction.static_mu = 0.0917;
				o.friction.carrier_drag_Nm_s_per_rad = 2.9e-5;
				o.losses = losses ? PRSM_DYN_LOSSES_STATICS : PRSM_DYN_LOSSES_SLIDING_ONLY;
				o.couplings.spline_friction = 0.137;
				o.couplings.thrust_bearing_friction = 0.0551;
				o.input.viscous_drag_Nm_s_per_rad = 0.0173;
				o.input.motor_inertia_kg_m2 = 1.9e-5;
				o.inertia.payload_kg = 3.7;
				o.load.shape = PRSM_DYN_SHAPE_SINE;
				o.load.value = 5123.0;
				o.load.sine_amplitude = 1377.0;
				o.load.sine_frequency_Hz = 173.0;
				prsm_dyn_model *m = dyn_test_model(K, d, a, &o);
				for (int trial = 0; trial < 12; trial++) {
					prsm_dyn_state s = {0};
					s.time_s = uniform(&seed, 0.0, 0.01);
					s.screw_angle_rad = uniform(&seed, -3.0, 3.0);
					s.screw_speed_rad_s = uniform(&seed, -150.0, 150.0);
					s.screw_accel_rad_s2 = uniform(&seed, -3e4, 3e4);
					for (int k = 0; k < K; k++)
						s.carrier_speed_rad_s[k] = s.screw_speed_rad_s * uniform(&seed, -0.2, 0.6);
					prsm_dyn_point p;
					prsm_dyn_stage_point sp[3];
					prsm_error err = PRSM_ERROR_INIT;
					assert_int_equal(prsm_dyn_evaluate(&p, sp, m, &s, &err), 0);
					assert_true(p.power_balance_relative < 1e-12);
					assert_true(p.newton_euler_residual < 1e-9);
					/* the output power is F_N Lambda_K theta-dot, independently */
					const double F = 5123.0 + 1377.0 * sin(2 * M_PI * 173.0 * s.time_s);
					const double LK = prsm_dyn_model_stage(m, K - 1)->cumulative_lead_m_per_rad;
					assert_rel(p.power_output_W, F * LK * s.screw_speed_rad_s, 1e-13);
					for (int k = 0; k < K; k++) {
						assert_true(sp[k].contact_normal_force_N >= 0.0);
						assert_true(sp[k].nut_contact_force_N >= 0.0);
						assert_close(sp[k].newton_euler_carrier_accel_rad_s2, sp[k].carrier_accel_rad_s2,
						             1e-9 * (fabs(sp[k].carrier_accel_rad_s2) + 1e3));
					}
					count++;
				}
				prsm_dyn_model_free(m);
			}
	assert_int_equal(count, 3 * 3 * 2 * 12);
}

/* losses "statics" (docs/model §8.2.3): the loss torque charged to a screw at a stage load F is
 * the statics engine's spin + gear + drag + seal torque with the load distribution of the
 * reference load scaled to F (model/losses.h called here at the scaled loads). */
static void test_loss_torque_is_the_statics_engines(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.0587);
	d.losses.drag_torque_Nm = 0.0143;
	d.losses.seal_torque_Nm = 0.0291;
	d.losses.viscous_drag_Nm_s_per_rad = 2.3e-4;
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.load.value = 6131.0;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const double Fref = prsm_dyn_model_stage(m, 0)->loss_reference_load_N;
	assert_close(Fref, 6131.0, 1e-9); /* one stage: the load itself */
	double *ref = calloc(20, sizeof(double)), *scaled = calloc(20, sizeof(double));
	assert_non_null(ref);
	assert_non_null(scaled);
	prsm_design dr = d;
	dr.axial_load_N = Fref;
	assert_int_equal(prsm_performance_normal_loads(ref, ref + 10, &dr, &a, NULL), 0);
	const double accels[] = {-2.7e5, 0.0, 1.9e5, 5.3e5};
	for (size_t i = 0; i < sizeof accels / sizeof accels[0]; i++) {
		prsm_dyn_state s = {0};
		s.screw_speed_rad_s = 83.7;
		s.screw_accel_rad_s2 = accels[i];
		s.carrier_speed_rad_s[0] = 29.3;
		prsm_dyn_point p;
		prsm_dyn_stage_point sp;
		assert_int_equal(prsm_dyn_evaluate(&p, &sp, m, &s, NULL), 0);
		const double F = sp.stage_axial_load_N;
		for (int j = 0; j < 20; j++)
			scaled[j] = ref[j] * F / Fref;
		prsm_design dl = d;
		dl.axial_load_N = F;
		dl.screw_speed_rad_s = 83.7;
		prsm_losses_options lo;
		prsm_losses_options_from_design(&lo, &dl);
		prsm_losses_result r;
		assert_int_equal(prsm_losses_compute(&r, &dl, &a.kinematics, &a.screw, &a.nut, scaled, scaled + 10, &lo, NULL), 0);
		const double T = r.spin_torque_Nm + r.gear_torque_Nm + r.drag_torque_Nm + r.seal_torque_Nm;
		const double sigma = 83.7 / sqrt(83.7 * 83.7 + 1e-6);
		assert_rel(sp.loss_torque_Nm, sigma * T, 1e-12);
		if (accels[i] != 0.0)
			assert_true(fabs(F - 6131.0) > 30.0);
	}
	free(ref);
	free(scaled);
	prsm_dyn_model_free(m);
}

/* docs/model §8.2.6: T_f, T_b with the carrier at rest, slip along +-B, mu_s:
 * T = Lambda F + mu_s |B| N (+- 1) with N = -h F / (n_z -+ mu_s B_z/|B|) per unit Z, lower flank. */
static void test_breakaway_torques(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.0523);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.input.kind = PRSM_DYN_INPUT_TORQUE;
	o.input.signal.value = 11.3;
	o.time.stepper = PRSM_DYN_STEPPER_MSBDF;
	o.friction.stick_model = PRSM_DYN_STICK_KARNOPP;
	o.friction.static_mu = 0.0811;
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o.load.value = 6871.0;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &o);
	const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, 0);
	double Tf, Tb;
	assert_int_equal(prsm_dyn_breakaway_torques(&Tf, &Tb, m, 0.0, NULL), 0);
	const double *B = p->B_mm[PRSM_DYN_FLANK_LOWER], *n = p->normal[PRSM_DYN_FLANK_LOWER];
	const double Bn = sqrt(dot3(B, B)) * 1e-3, Bz = B[2] * 1e-3 / Bn, F = 6871.0, mus = 0.0811;
	const double L = p->cumulative_lead_m_per_rad;
	const double Nf = -F / (n[2] - mus * Bz), Nb = -F / (n[2] + mus * Bz);
	assert_rel(Tf, L * F + mus * Bn * Nf, 1e-12);
	assert_rel(Tb, L * F - mus * Bn * Nb, 1e-12);
	assert_true(Tf > L * F && Tb < L * F);
	prsm_dyn_model_free(m);
}

/* Every bad option at its pointer. */
static void test_options_refused(void **state)
{
	(void)state;
	prsm_dyn_options o, defaults = PRSM_DYN_OPTIONS_INIT;
	assert_int_equal(prsm_dyn_options_init(&o), 0);
	assert_memory_equal(&o.input, &defaults.input, sizeof o.input);
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_dyn_options_check(&o, 2, &p), 0);
	assert_int_equal(p.count, 0);
	assert_close(o.load.value, 7000.0, 0.0);
	assert_close(o.input.signal.value, 100.0, 0.0);
	assert_close(o.time.end_s, 0.005, 0.0);
	assert_close(o.time.rel_tol, 1e-10, 0.0);
	assert_close(o.friction.smoothing_velocity_m_s, 1e-4, 0.0);
	assert_true(isnan(o.inertia.stage[7].screw_inertia_kg_m2));

	/* one mutation per case, and the pointer its problem must carry */
	const char *pointers[] = {
		"/dynamics/input/kind", "/dynamics/input/value_rad_s", "/dynamics/input/ramp_time_s",
		"/dynamics/input/sine_frequency_Hz", "/dynamics/input/motor_inertia_kg_mm2",
		"/dynamics/input/viscous_drag_Nm_s_per_rad", "/dynamics/load/axial_load_N",
		"/dynamics/load/shape", "/dynamics/friction/model", "/dynamics/friction/viscous_N_s_per_m",
		"/dynamics/friction/mu", "/dynamics/friction/smoothing_velocity_m_s",
		"/dynamics/friction/static_mu", "/dynamics/friction/stribeck_velocity_m_s",
		"/dynamics/friction/stick_model", "/dynamics/friction/stick_model",
		"/dynamics/friction/carrier_drag_Nm_s_per_rad", "/dynamics/friction/coupling_smoothing_rad_s",
		"/dynamics/losses", "/dynamics/inertia/density_kg_m3", "/dynamics/inertia/stroke_mm",
		"/dynamics/inertia/payload_kg", "/dynamics/inertia/stages/1/roller_inertia_kg_mm2",
		"/dynamics/inertia/stages/0/gear_face_width_mm", "/couplings/spline_friction",
		"/couplings/thrust_bearing_radius_mm/0", "/dynamics/time/end_s", "/dynamics/time/output_step_s",
		"/dynamics/time/output_step_s", "/dynamics/time/stepper", "/dynamics/time/stepper",
		"/dynamics/time/rel_tol", "/dynamics/time/abs_tol", "/dynamics/time/max_steps",
		"/dynamics/input/value_Nm", "/dynamics/friction/stick_model"};
	const int n = (int)(sizeof pointers / sizeof pointers[0]);
	for (int i = 0; i < n; i++) {
		prsm_dyn_options_init(&o);
		switch (i) {
		case 0: o.input.kind = 7; break;
		case 1: o.input.signal.value = NAN; break;
		case 2: o.input.signal.shape = PRSM_DYN_SHAPE_RAMP; o.input.signal.ramp_time_s = 0.0; break;
		case 3: o.input.signal.shape = PRSM_DYN_SHAPE_SINE; o.input.signal.sine_frequency_Hz = -3.0; break;
		case 4: o.input.motor_inertia_kg_m2 = -1e-6; break;
		case 5: o.input.viscous_drag_Nm_s_per_rad = -0.01; break;
		case 6: o.load.value = INFINITY; break;
		case 7: o.load.shape = 9; break;
		case 8: o.friction.model = 5; break;
		case 9: o.friction.model = PRSM_DYN_FRICTION_VISCOUS; o.friction.viscous_N_s_per_m = -2.0; break;
		case 10: o.friction.mu = -0.05; break;
		case 11: o.friction.smoothing_velocity_m_s = 0.0; break;
		case 12: o.friction.static_mu = -0.1; break;
		case 13: o.friction.stribeck_velocity_m_s = 0.0; break;
		case 14: o.friction.stick_model = 3; break;
		case 15: o.friction.stick_model = PRSM_DYN_STICK_KARNOPP; break; /* speed input */
		case 16: o.friction.carrier_drag_Nm_s_per_rad = -1e-5; break;
		case 17: o.friction.coupling_smoothing_rad_s = 0.0; break;
		case 18: o.losses = 4; break;
		case 19: o.inertia.density_kg_m3 = 0.0; break;
		case 20: o.inertia.stroke_mm = -1.0; break;
		case 21: o.inertia.payload_kg = -0.5; break;
		case 22: o.inertia.stage[1].roller_inertia_kg_m2 = -2e-8; break; /* negative inertia */
		case 23: o.inertia.stage[0].gear_face_width_mm = 0.0; break;
		case 24: o.couplings.spline_friction = 1.0; break;
		case 25: o.couplings.thrust_radius_mm[1] = -16.0; break;
		case 26: o.time.end_s = 0.0; break; /* zero end time */
		case 27: o.time.output_step_s = 5e-10; break; /* finer than 1e-9 s */
		case 28: o.time.end_s = 2.0; o.time.output_step_s = 1e-6; break; /* more than 10^6 points */
		case 29: o.time.stepper = 11; break;
		case 30: /* stiff without an implicit stepper */
			o.input.kind = PRSM_DYN_INPUT_TORQUE;
			o.time.stepper = PRSM_DYN_STEPPER_RK8PD;
			break;
		case 31: o.time.rel_tol = 0.0; break;
		case 32: o.time.abs_tol = 0.5; break;
		case 33: o.time.max_steps = 0; break;
		case 34: o.input.kind = PRSM_DYN_INPUT_TORQUE; o.input.signal.value = NAN; break;
		case 35: o.input.kind = PRSM_DYN_INPUT_TORQUE; o.friction.model = PRSM_DYN_FRICTION_VISCOUS;
			o.friction.stick_model = PRSM_DYN_STICK_KARNOPP; break;
		}
		prsm_problems_init(&p);
		assert_int_equal(prsm_dyn_options_check(&o, 2, &p), PRSM_EINVAL);
		int hit = 0;
		for (int j = 0; j < p.count; j++)
			hit |= strcmp(p.items[j].pointer, pointers[i]) == 0;
		if (!hit) {
			print_error("case %d: no problem at %s (first: %s %s)\n", i, pointers[i],
			            p.count ? p.items[0].pointer : "-", p.count ? p.items[0].message : "");
			fail();
		}
	}
	/* the 10^6 points are allowed, one more is not */
	prsm_dyn_options_init(&o);
	o.time.end_s = 0.999999;
	o.time.output_step_s = 1e-6;
	prsm_problems_init(&p);
	assert_int_equal(prsm_dyn_options_check(&o, 1, &p), 0);
	/* the model refuses bad options with the first problem's pointer */
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options_init(&o);
	o.time.output_step_s = 1e-12;
	prsm_dyn_model *m = (prsm_dyn_model *)&o; /* must be reset to NULL */
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dyn_model_new(&m, 1, &d, &a, &o, &err), PRSM_EINVAL);
	assert_null(m);
	assert_string_equal(err.pointer, "/dynamics/time/output_step_s");
}

/* Designs and chains the rigid model cannot take, each refused with its pointer; a friction that
 * wedges the flanks fails to converge instead of returning numbers. */
static void test_models_refused(void **state)
{
	(void)state;
	prsm_design d[3];
	prsm_analysis a[3];
	prsm_dyn_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	dyn_seed000(d, a);
	assert_int_equal(prsm_dyn_model_new(&m, 0, d, a, &o, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/stages");
	assert_int_equal(prsm_dyn_model_new(&m, PRSM_DYN_STAGES_MAX + 1, d, a, &o, &err), PRSM_EINVAL);
	/* mixed hands */
	d[1].hand = PRSM_HAND_LEFT;
	dyn_test_analyse(&a[1], &d[1]);
	assert_int_equal(prsm_dyn_model_new(&m, 2, d, a, &o, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/stages/1/geometry/hand");
	assert_null(m);
	dyn_seed000(d, a);
	/* couplings that lock: mu_SS mu_NS r_NS / r_SS >= 1 */
	o.couplings.spline_friction = 0.9;
	o.couplings.thrust_bearing_friction = 0.95;
	assert_int_equal(prsm_dyn_model_new(&m, 2, d, a, &o, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/couplings");
	prsm_dyn_options_init(&o);
	/* roller migration: r_n != n r_r (the statics engine warns; the rigid model refuses) */
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_design_init(&d[0]);
	d[0].starts = 5;
	d[0].pitch_mm = 2.0;
	d[0].roller_radius_mm = 3.25;
	d[0].flank_angle_rad = 45.0 * DEG;
	d[0].rollers = 8;
	d[0].engaged_threads = 10;
	d[0].screw_radius_mm = 9.75;
	d[0].nut_radius_mm = 16.31;
	assert_int_equal(prsm_design_resolve(&d[0], &e), 0);
	dyn_test_analyse(&a[0], &d[0]);
	assert_int_equal(prsm_dyn_model_new(&m, 1, d, a, &o, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/geometry/nut_radius_mm");
	assert_non_null(strstr(err.message, "drift"));
	/* friction that wedges the flanks: no curve, a reason */
	dyn_case_a(&d[0], &a[0], 1.23);
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	assert_int_equal(prsm_dyn_model_new(&m, 1, d, a, &o, &err), PRSM_ENOCONVERGE);
	assert_non_null(strstr(err.message, "wedges"));
	assert_null(m);
	prsm_dyn_model_free(NULL);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_slip_basis_case_a),
		cmocka_unit_test(test_normal_does_no_work),
		cmocka_unit_test(test_masses_case_a),
		cmocka_unit_test(test_screw_side_inertia),
		cmocka_unit_test(test_checks_on_random_states),
		cmocka_unit_test(test_loss_torque_is_the_statics_engines),
		cmocka_unit_test(test_breakaway_torques),
		cmocka_unit_test(test_options_refused),
		cmocka_unit_test(test_models_refused),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
