/*
 * test_vib_reduced.c: the reduced vibration model of case A (docs/model §8.3, V5's setting:
 * payload 400 kg, F_0 7 kN) against the statics engine and the rigid model it is built on, and
 * against independent computations:
 *  - the parameters: k_a and b_a from the statics (611.40 N/um, 10 um), k*, the teeth and contact
 *    ratio of the losses, the masses of §8.2.2, omega_ref ~ 2.0e5 rad/s, omega_e = 1 at ~6.3e3 rad/s,
 *    F-bar of a few newtons and a static mesh deflection of ~0.05 um, G_psi - n G_phi = A;
 *  - the static state is an equilibrium (friction balance at k*, the mean mesh force);
 *  - the axial branch against its closed form line by line (a response started on it, and the
 *    steady state's extremes of y and F_th from the static state);
 *  - the eigenvalues: the axial mode's closed form, the rigid carrier's friction rate against the
 *    rigid model's sigma_c, the roller mode against a free decay in the time domain;
 *  - lambda_max of the linear system (constant stiffness, no excitation) against the slowest
 *    eigenvalue;
 *  - the TE lines: a least-squares fit of a synthetic record, the lines of an error set (named
 *    orders with k*);
 *  - a gear-branch sweep (V5's setting, short) bit-identical for 1 and 2 threads;
 *  - a steady state of both branches with its spectrum's mechanism lines;
 *  - the refusals.
 */
#include "test_case_a_fixture.h"

#include "dyn/vib.h"
#include "io/design_json.h"
#include "io/global.h"

static void v5_options(prsm_dyn_options *dopt, prsm_vib_options *vo)
{
	prsm_dyn_options_init(dopt);
	dopt->inertia.payload_kg = 400.0;
	dopt->load.value = 7000.0;
	prsm_vib_options_init(vo);
}

static void v5_lines(prsm_vib_options *vo)
{
	const double ord[5] = {1.0, 1.875, 0.625, 3.75, 0.375}, amp[5] = {1.84, 0.443, 0.260, 0.181, 0.141};
	vo->te_source = PRSM_VIB_TE_LINES;
	vo->te_lines = 5;
	for (int k = 0; k < 5; k++) {
		vo->te_line[k].order_per_rev = ord[k];
		vo->te_line[k].amplitude_m = amp[k] * 1e-6;
		vo->te_line[k].phase_rad = 0.0;
	}
}

static prsm_vib_model *model(const prsm_dyn_options *dopt, const prsm_vib_options *vo)
{
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_vib_model_new(&m, &fx->d, &fx->a, dopt, vo, NULL, NULL, &err);
	if (rc) {
		print_error("model: %s (%s) at %s\n", err.message, prsm_error_name(rc), err.pointer);
		fail();
	}
	return m;
}

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* §8.3.1 with the statics engine's values (V5: k_a 611.40 N/um, b_a 10 um) */
static void test_parameters(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	prsm_vib_model *m = model(&dopt, &vo);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	assert_int_equal(P->kind, PRSM_VIB_REDUCED);
	assert_int_equal(P->rollers, 10);
	assert_int_equal(P->states, 2 * 11 + 2);
	assert_int_equal(P->poincare_size, 2 * 10 + 1 + 2);
	assert_close(P->axial_stiffness_N_per_m * 1e-6, 611.40, 0.01);
	assert_close(P->axial_half_play_m * 1e6, 10.0, 1e-6);
	assert_close(P->carrier_ratio, 0.37369408, 1e-8);
	assert_int_equal(P->teeth_roller, 17);
	assert_int_equal(P->teeth_ring, 85);
	assert_close(P->contact_ratio, 1.5, 0.0);
	assert_close(P->gear_face_width_mm, 4.0, 1e-12);
	assert_close(P->mesh_single_N_per_m, 5.6e7, 1e-3);
	assert_close(P->mesh_mean_N_per_m, 8.4e7, 1e-3);
	assert_close(P->base_radius_roller_m, 3.25e-3 * cos(20.0 * DEG), 1e-15);
	/* the masses of §8.2.2 (case A: m_R 7.2936 g, J_R 3.8520e-8 kg m^2), m_a with the payload */
	const double p_r = 2e-3 / (2.0 * M_PI), mR = 7.2936e-3, JR = 3.8520e-8;
	assert_close(P->inertia_phiphi_kg_m2, JR + mR * p_r * p_r, 1e-4 * JR);
	assert_close(P->inertia_psiphi_kg_m2, JR + 5.0 * mR * p_r * p_r, 1e-4 * JR);
	assert_close(P->axial_mass_kg, 0.12582 + 10 * mR + 0.016671 + 400.0, 1e-3);
	/* omega_ref ~ 2.0e5 rad/s (32 kHz); omega_e = 1 at ~6.3e3 rad/s */
	assert_close(P->reference_frequency_rad_s, 2.0e5, 0.02 * 2.0e5);
	assert_close(P->reference_frequency_rad_s / (P->teeth_ring * P->carrier_ratio), 6.3e3, 0.02 * 6.3e3);
	assert_close(P->frequency_ratio, 330.0 * 85 * P->carrier_ratio / P->reference_frequency_rad_s, 1e-12);
	/* the ring gears are almost unloaded: F-bar a few newtons, a static deflection ~0.05 um */
	assert_true(P->mean_mesh_force_N > 1.0 && P->mean_mesh_force_N < 20.0);
	const double dstat = P->static_mesh_deflection_m - P->gear_half_backlash_m;
	assert_true(dstat > 0.02e-6 && dstat < 0.1e-6);
	assert_close(P->gear_pair.mean_force, P->mean_mesh_force_N / (2.0 * P->mesh_mean_N_per_m * 5e-6), 1e-15);
	/* mesh phases 0, 1/2, 0, ... (85 teeth, 10 rollers) */
	assert_close(P->mesh_phase[0], 0.0, 0.0);
	assert_close(P->mesh_phase[1], 0.5, 1e-12);
	assert_close(P->mesh_phase[2], 0.0, 1e-12);
	/* §8.3.3: G_psi - n G_phi = A of the rigid model; the slip v* is the rigid model's at k* */
	prsm_dyn_model *dm = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	dopt.input.signal.value = 330.0;
	dopt.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	assert_int_equal(prsm_dyn_model_new(&dm, 1, &fx->d, &fx->a, &dopt, &err), 0);
	const prsm_dyn_stage_params *sp = prsm_dyn_model_stage(dm, 0);
	for (int i = 0; i < 3; i++) {
		assert_close(P->G_psi_m[i] - 5.0 * P->G_phi_m[i], sp->A_mm[P->flank][i] * 1e-3, 1e-15);
		assert_close(P->slip_m_s[i], (sp->A_mm[P->flank][i] * P->carrier_ratio + sp->B_mm[P->flank][i]) * 1e-3 * 330.0,
		             1e-12);
	}
	/* friction balance: f . A = 0 at v* (the carrier needs no mean mesh force) */
	double A[3];
	for (int i = 0; i < 3; i++)
		A[i] = sp->A_mm[P->flank][i];
	assert_close(dot3(P->slip_m_s, A) / (sqrt(dot3(P->slip_m_s, P->slip_m_s)) * sqrt(dot3(A, A))), 0.0, 1e-12);
	prsm_dyn_model_free(dm);
	prsm_vib_model_free(m);
}

/* The static state is an equilibrium without excitation (constant stiffness, no error, no TE). */
static void test_static_equilibrium(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	vo.double_to_single_stiffness = 1.0;
	prsm_vib_model *m = model(&dopt, &vo);
	prsm_vib_response r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_time_response(&r, m, NULL, 2e-4, 2e-5, NULL, NULL, &err), 0);
	double y0[PRSM_VIB_STATE_MAX];
	prsm_vib_static_state(m, y0);
	const size_t last = r.points - 1;
	for (int i = 0; i < r.states; i++)
		assert_close(r.state[last * r.states + i], y0[i], 1e-10);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	assert_close(r.mesh_force[last * 10 + 3], P->mean_mesh_force_N, 1e-6 * P->mean_mesh_force_N);
	assert_close(r.thread_force_N[last], 7000.0, 1e-6);
	assert_close(r.axial_deflection[last], P->axial_static_m / P->axial_half_play_m, 1e-12);
	prsm_vib_response_free(&r);
	prsm_vib_model_free(m);
}

/* The axial branch's closed form (§8.3.2) line by line: Y_k = -m (nu w)^2 A e^{i phi} /
 * (k - m (nu w)^2 + i nu w c). V5's lines at 330 rad/s (the 3.75 line on the axial resonance);
 * y stays above b_a, so the branch is linear. */
static void axial_closed_form(const prsm_vib_params *P, double t, double *y, double *ydot)
{
	const double m = P->axial_mass_kg, k = P->axial_stiffness_N_per_m, c = P->axial_damping_N_s_per_m;
	*y = P->axial_static_m;
	*ydot = 0.0;
	for (int l = 0; l < P->te_lines; l++) {
		const double w = P->te_line[l].order_per_rev * P->screw_speed_rad_s, A = P->te_line[l].amplitude_m;
		const double phi = P->te_line[l].phase_rad;
		/* Y = -m w^2 A e^{i phi} / (k - m w^2 + i w c) */
		const double dr = k - m * w * w, di = w * c, den = dr * dr + di * di;
		const double nr = -m * w * w * A * cos(phi), ni = -m * w * w * A * sin(phi);
		const double Yr = (nr * dr + ni * di) / den, Yi = (ni * dr - nr * di) / den;
		*y += Yr * cos(w * t) - Yi * sin(w * t);
		*ydot += -w * (Yr * sin(w * t) + Yi * cos(w * t));
	}
}

static void test_axial_closed_form(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	v5_lines(&vo);
	vo.branches = PRSM_VIB_BRANCHES_AXIAL;
	prsm_vib_model *m = model(&dopt, &vo);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	assert_close(P->te_period_rev, 8.0, 0.0);
	/* a response started on the closed form stays on it */
	double y0[PRSM_VIB_STATE_MAX];
	prsm_vib_static_state(m, y0);
	double y, yd;
	axial_closed_form(P, 0.0, &y, &yd);
	y0[2 * 11] = y / P->axial_half_play_m;
	y0[2 * 11 + 1] = yd / (P->axial_half_play_m * P->axial_frequency_rad_s);
	prsm_vib_response r;
	prsm_error err = PRSM_ERROR_INIT;
	const double Tte = 8.0 * 2.0 * M_PI / 330.0;
	assert_int_equal(prsm_vib_time_response(&r, m, y0, Tte, Tte / 997.0, NULL, NULL, &err), 0);
	double worst = 0.0, worstF = 0.0;
	for (size_t k = 0; k < r.points; k++) {
		axial_closed_form(P, r.time_s[k], &y, &yd);
		worst = fmax(worst, fabs(r.axial_deflection[k] - y / P->axial_half_play_m));
		const double F = P->axial_stiffness_N_per_m * (y - P->axial_half_play_m) + P->axial_damping_N_s_per_m * yd;
		worstF = fmax(worstF, fabs(r.thread_force_N[k] - F));
		assert_int_equal(r.contact_lost[k * r.contacts], 0);
	}
	assert_true(worst < 2e-7);   /* of b_a: 1e-6 of the response (outputs interpolated) */
	assert_true(worstF < 1e-3);  /* N, of 7 kN +- ~1.3 kN */
	prsm_vib_response_free(&r);
	/* the steady state from the static state: the TE clock, period 1, the extremes of y and F_th
	 * those of the closed form over the period, never out of contact */
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.observable = PRSM_VIB_OBS_AXIAL_DEFLECTION;
	so.transient_periods = 6;
	so.recorded_periods = 2;
	prsm_vib_steady s;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &so, NULL, &err), 0);
	assert_int_equal(s.clock, PRSM_VIB_CLOCK_TE);
	assert_close(s.period_s, Tte, 1e-12);
	assert_int_equal(s.classification, PRSM_VIB_PERIODIC);
	assert_int_equal(s.period, 1);
	double ymin = INFINITY, ymax = -INFINITY, Fmin = INFINITY, Fmax = -INFINITY;
	for (int i = 0; i < 200000; i++) {
		axial_closed_form(P, Tte * i / 200000.0, &y, &yd);
		ymin = fmin(ymin, y);
		ymax = fmax(ymax, y);
		const double F = P->axial_stiffness_N_per_m * (y - P->axial_half_play_m) + P->axial_damping_N_s_per_m * yd;
		Fmin = fmin(Fmin, F);
		Fmax = fmax(Fmax, F);
	}
	int seen = 0;
	for (int i = 0; i < s.extremes; i++) {
		const prsm_vib_extreme *x = &s.extreme[i];
		if (x->observable == PRSM_VIB_OBS_AXIAL_DEFLECTION) {
			assert_close(x->min * P->axial_half_play_m, ymin, 1e-6 * (ymax - ymin));
			assert_close(x->max * P->axial_half_play_m, ymax, 1e-6 * (ymax - ymin));
			seen++;
		} else if (x->observable == PRSM_VIB_OBS_THREAD_FORCE) {
			assert_close(x->min, Fmin, 1e-6 * (Fmax - Fmin));
			assert_close(x->max, Fmax, 1e-6 * (Fmax - Fmin));
			seen++;
		}
	}
	assert_int_equal(seen, 2);
	assert_close(s.loss_share[0], 0.0, 0.0);
	/* the named TE line 3.75 on the axial resonance carries most of the response */
	double a375 = NAN, a1 = NAN;
	for (int i = 0; i < s.lines; i++) {
		if (fabs(s.line[i].order_per_rev - 3.75) < 1e-12 && strncmp(s.line[i].name, "te_line", 7) == 0)
			a375 = s.line[i].amplitude;
		if (fabs(s.line[i].order_per_rev - 1.0) < 1e-12 && strncmp(s.line[i].name, "te_line", 7) == 0)
			a1 = s.line[i].amplitude;
	}
	assert_true(a375 > a1);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);
}

/* Eigenvalues: the axial mode's closed form; the rigid carrier's decay is the rigid model's
 * friction rate sigma_c (§8.2.6); the roller mode against a free decay (antisymmetric spins,
 * constant stiffness, gear branch only) measured in the time domain. */
static void test_eigenvalues(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	vo.frequency_ratio = 1.0;
	vo.double_to_single_stiffness = 1.0;
	prsm_vib_model *m = model(&dopt, &vo);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	prsm_vib_linear l;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_linearise(&l, m, &err), 0);
	assert_int_equal(l.dofs, 12);
	assert_int_equal(l.kind[0], PRSM_VIB_EIG_RIGID);
	assert_int_equal(l.kind[1], PRSM_VIB_EIG_REAL);
	/* the rigid model's sigma_c at the same speed and load */
	prsm_dyn_model *dm = NULL;
	dopt.input.signal.value = P->screw_speed_rad_s;
	dopt.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	assert_int_equal(prsm_dyn_model_new(&dm, 1, &fx->d, &fx->a, &dopt, &err), 0);
	/* (the friction damping couples the rigid direction weakly to the roller modes: O((sigma_c /
	 * omega_ref)^2) apart) */
	assert_close(-l.eig_re[1], prsm_dyn_model_settled(dm)->carrier_rate_per_s[0], 1e-4 * fabs(l.eig_re[1]));
	prsm_dyn_model_free(dm);
	/* the axial mode: -zeta w_a +- i w_a sqrt(1 - zeta^2), shape y only */
	const double wa = P->axial_frequency_rad_s, za = P->axial_damping_ratio;
	assert_int_equal(l.kind[2], PRSM_VIB_EIG_OSCILLATORY);
	assert_close(l.eig_re[2], -za * wa, 1e-9 * wa);
	assert_close(fabs(l.eig_im[2]), wa * sqrt(1.0 - za * za), 1e-9 * wa);
	/* the roller modes (Z - 1 of them, at one frequency) */
	int rk = -1, count = 0;
	for (int k = 0; k < l.eigenvalues; k++)
		if (l.kind[k] == PRSM_VIB_EIG_OSCILLATORY && l.eig_im[k] > 0.0 && fabs(l.eig_im[k] - 0.99 * P->reference_frequency_rad_s) < 0.05 * P->reference_frequency_rad_s) {
			if (rk < 0)
				rk = k;
			if (fabs(l.eig_im[k] - l.eig_im[rk]) < 1e-6 * l.eig_im[rk])
				count++;
		}
	assert_true(rk >= 0);
	assert_int_equal(count, 9);
	prsm_vib_model_free(m);
	/* free decay of the antisymmetric roller mode, gear branch only */
	vo.branches = PRSM_VIB_BRANCHES_GEAR;
	m = model(&dopt, &vo);
	double y0[PRSM_VIB_STATE_MAX];
	prsm_vib_static_state(m, y0);
	const double x_s = y0[1];
	y0[1] += 1e-3;
	y0[2] -= 1e-3;
	const double wr = l.eig_im[rk];
	const double Td = 2.0 * M_PI / wr;
	prsm_vib_response r;
	assert_int_equal(prsm_vib_time_response(&r, m, y0, 4.0 * Td, Td / 2000.0, NULL, NULL, &err), 0);
	double up[6];
	int n_up = 0;
	for (size_t k = 1; k < r.points && n_up < 6; k++) {
		const double a = r.mesh_deflection[(k - 1) * 10] - x_s, b = r.mesh_deflection[k * 10] - x_s;
		if (a < 0.0 && b >= 0.0)
			up[n_up++] = r.time_s[k - 1] + (r.time_s[k] - r.time_s[k - 1]) * (-a) / (b - a);
	}
	assert_true(n_up >= 3);
	const double Tm = up[2] - up[1];
	assert_close(Tm, Td, 1e-4 * Td);
	/* the deviation one damped period apart */
	const size_t k0 = 1000, k1 = k0 + 2000;
	const double ratio = (r.mesh_deflection[k1 * 10] - x_s) / (r.mesh_deflection[k0 * 10] - x_s);
	assert_close(log(ratio) / Td, l.eig_re[rk], 1e-3 * fabs(l.eig_re[rk]));
	/* the carrier did not move (the mode is antisymmetric) */
	assert_close(r.state[(r.points - 1) * r.states + 0], 0.0, 1e-9);
	prsm_vib_response_free(&r);
	/* half-power of the roller mode from a unit mesh error on roller 0 to d_0 */
	prsm_vib_half_power hp;
	prsm_vib_linear lg;
	assert_int_equal(prsm_vib_linearise(&lg, m, &err), 0);
	assert_int_equal(prsm_vib_half_power_run(&hp, m, &lg, PRSM_VIB_IN_MESH_ERROR, 0, PRSM_VIB_OUT_MESH_DEFLECTION, 0,
	                                         0.7 * wr, 1.3 * wr, &err),
	                 0);
	if (!hp.defined)
		print_error("half power: %s\n", hp.reason);
	assert_true(hp.defined);
	assert_close(hp.damping_ratio, hp.modal_damping_ratio, 0.02 * hp.modal_damping_ratio);
	assert_close(hp.modal_omega, wr, 1e-9 * wr);
	prsm_vib_linear_free(&lg);
	prsm_vib_linear_free(&l);
	prsm_vib_model_free(m);
}

/* lambda_max of the linear system (constant stiffness, no error, no TE: the static state is a
 * fixed point) is the slowest decay among the eigenvalues of the reduced system (the carrier's
 * friction rate here, the rigid carrier angle excluded) */
static void test_lyapunov_linear(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	vo.frequency_ratio = 1.0;
	vo.double_to_single_stiffness = 1.0;
	vo.branches = PRSM_VIB_BRANCHES_GEAR;
	prsm_vib_model *m = model(&dopt, &vo);
	prsm_vib_linear l;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_linearise(&l, m, &err), 0);
	double slowest = -INFINITY;
	for (int k = 0; k < l.eigenvalues; k++)
		if (l.kind[k] != PRSM_VIB_EIG_RIGID)
			slowest = fmax(slowest, l.eig_re[k]);
	prsm_vib_lyapunov_options o = PRSM_VIB_LYAPUNOV_OPTIONS_INIT;
	o.transient_periods = 100;
	o.periods = 400;
	prsm_vib_lyapunov ly;
	assert_int_equal(prsm_vib_lyapunov_run(&ly, m, NULL, &o, NULL, &err), 0);
	assert_close(ly.lambda_per_s[0], slowest, 0.01 * fabs(slowest));
	prsm_vib_linear_free(&l);
	prsm_vib_model_free(m);
}

/* §8.3.4: the least-squares line fit recovers amplitudes and phases next to a lead slope */
static void test_te_lines_fit(void **state)
{
	(void)state;
	const int M = 64, n = 10 * M + 1;
	const double ord[3] = {0.6263, 1.0, 3.737}, A[3] = {2.5e-3, 1.1e-3, 0.3e-3}, ph[3] = {0.7, -2.1, 3.0};
	double *x = malloc((size_t)n * sizeof *x);
	for (int i = 0; i < n; i++) {
		x[i] = 0.004 - 2e-5 * i;
		for (int k = 0; k < 3; k++)
			x[i] += A[k] * cos(2.0 * M_PI * ord[k] * i / M + ph[k]);
	}
	prsm_vib_te_line l[3];
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_te_lines_fit(l, x, n, M, ord, 3, &err), 0);
	for (int k = 0; k < 3; k++) {
		assert_close(l[k].order_per_rev, ord[k], 0.0);
		assert_close(l[k].amplitude_m, A[k] * 1e-3, 1e-12 * 1e-3);
		assert_close(l[k].phase_rad, ph[k], 1e-9);
	}
	assert_int_equal(prsm_vib_te_lines_fit(l, x, 6, M, ord, 3, &err), PRSM_EINVAL);
	free(x);
}

/* The lines of an error set (§8.3.4): the named orders with k*, every amplitude > 0; a model with
 * TE from the statics takes them (no common period with k*: the TE clock is refused) */
static void test_te_lines_from_errors(void **state)
{
	(void)state;
	prsm_errors e;
	prsm_errors_zero(&e, fx->d.rollers);
	e.screw.runout_mm = 0.005;
	e.screw.lead_periodic_mm = 0.002;
	e.roller[3].pin_tangential_mm = 0.004;
	e.nut.runout_mm = 0.003;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	vo.te_source = PRSM_VIB_TE_STATICS;
	vo.branches = PRSM_VIB_BRANCHES_AXIAL;
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, &e, NULL, &err), 0);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	assert_true(P->te_lines >= 5 && P->te_lines <= 32);
	const double k = P->carrier_ratio;
	assert_close(P->te_line[0].order_per_rev, 1.0 - k, 1e-15);
	assert_close(P->te_line[1].order_per_rev, k, 1e-15);
	for (int i = 0; i < P->te_lines; i++)
		assert_true(P->te_line[i].amplitude_m > 0.0 && P->te_line[i].amplitude_m < 1e-4);
	assert_true(isnan(P->te_period_rev));
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.observable = PRSM_VIB_OBS_AXIAL_DEFLECTION;
	so.clock = PRSM_VIB_CLOCK_TE;
	prsm_vib_steady s;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &so, NULL, &err), PRSM_EINVAL);
	assert_int_equal(prsm_vib_clock_of(m, PRSM_VIB_CLOCK_AUTO, PRSM_VIB_OBS_AXIAL_DEFLECTION), PRSM_VIB_CLOCK_MESH);
	prsm_vib_model_free(m);
	/* no error set: refused */
	assert_int_equal(prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/te_lines");
}

/* V5's gear-branch sweep in short (3 points each way, 40 + 16 mesh periods): period 1 at
 * omega_e = 0.8; bit-identical results for 1 and 2 threads */
static void test_gear_sweep_threads(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	vo.branches = PRSM_VIB_BRANCHES_GEAR;
	vo.mesh_error_um = 0.1;
	prsm_vib_model *m = model(&dopt, &vo);
	prsm_vib_sweep_options so;
	prsm_vib_sweep_options_init(&so);
	so.from = 0.75;
	so.to = 0.85;
	so.step = 0.05;
	so.steady.transient_periods = 40;
	so.steady.recorded_periods = 16;
	prsm_vib_sweep s1, s2;
	prsm_error err = PRSM_ERROR_INIT;
	so.threads = 1;
	assert_int_equal(prsm_vib_sweep_run(&s1, m, &so, NULL, NULL, NULL, &err), 0);
	so.threads = 2;
	assert_int_equal(prsm_vib_sweep_run(&s2, m, &so, NULL, NULL, NULL, &err), 0);
	assert_int_equal(s1.points, 6);
	assert_memory_equal(s1.point, s2.point, s1.points * sizeof *s1.point);
	assert_memory_equal(s1.poincare, s2.poincare, s1.points * s1.recorded * sizeof(double));
	assert_memory_equal(s1.end_state, s2.end_state, s1.points * s1.states * sizeof(double));
	assert_close(s1.point[1].parameter, 0.8, 1e-15);
	assert_int_equal(s1.point[1].status, 0);
	assert_true(s1.point[1].min < s1.point[1].max);
	/* the observable x_0 = d_0 / b_g stays near the static deflection (about 1.01) */
	assert_true(s1.point[1].mean > 0.95 && s1.point[1].mean < 1.1);
	prsm_vib_sweep_free(&s1);
	prsm_vib_sweep_free(&s2);
	prsm_vib_model_free(m);
}

/* Both branches at 330 rad/s with V5's TE lines and e_g 0.1 um: a short steady state at the mesh
 * clock; the spectrum names the mechanism lines in Hz, every extreme and share is reported */
static void test_steady_both_branches(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	v5_lines(&vo);
	vo.mesh_error_um = 0.1;
	prsm_vib_model *m = model(&dopt, &vo);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.transient_periods = 6;
	so.recorded_periods = 4;
	so.samples_per_period = 64;
	prsm_vib_steady s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &so, NULL, &err), 0);
	assert_int_equal(s.clock, PRSM_VIB_CLOCK_MESH);
	assert_close(s.period_s, 2.0 * M_PI / P->mesh_frequency_rad_s, 1e-15);
	assert_int_equal(s.extremes, 2 * 10 + 2);
	assert_int_equal(s.contacts, 11);
	for (int k = 0; k < s.contacts; k++)
		assert_true(s.loss_share[k] >= 0.0 && s.loss_share[k] <= 1.0);
	int found = 0;
	for (int i = 0; i < s.lines; i++)
		if (strcmp(s.line[i].name, "mesh") == 0) {
			assert_close(s.line[i].frequency, 85 * P->carrier_ratio * 330.0 / (2.0 * M_PI), 1e-9);
			found = 1;
		}
	assert_true(found);
	assert_true(s.spectrum_bins > 10);
	for (int i = 0; i < s.extremes; i++)
		assert_true(s.extreme[i].min <= s.extreme[i].max);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);
}

/* Bad input is refused at its field. */
static void test_refusals(void **state)
{
	(void)state;
	prsm_dyn_options dopt;
	prsm_vib_options vo;
	v5_options(&dopt, &vo);
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	vo.gear_backlash_um = 0.0;
	assert_int_equal(prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/gear_backlash_um");
	v5_options(&dopt, &vo);
	vo.mesh_damping_ratio = 0.0;
	assert_int_equal(prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/mesh_damping_ratio");
	v5_options(&dopt, &vo);
	vo.te_source = PRSM_VIB_TE_LINES;
	vo.te_lines = 1;
	vo.te_line[0].order_per_rev = -1.0;
	assert_int_equal(prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/te_lines/0/order_per_rev");
	assert_null(m);
	/* the gear branch alone has no axial observable, no thread-force FRF */
	v5_options(&dopt, &vo);
	vo.branches = PRSM_VIB_BRANCHES_GEAR;
	m = model(&dopt, &vo);
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.observable = PRSM_VIB_OBS_AXIAL_DEFLECTION;
	prsm_vib_steady s;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &so, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/sweep/observable");
	prsm_vib_linear l;
	assert_int_equal(prsm_vib_linearise(&l, m, &err), 0);
	double re, im, w = 1e5;
	assert_int_equal(prsm_vib_frf(&re, &im, m, &l, PRSM_VIB_IN_NUT_FORCE, 0, PRSM_VIB_OUT_THREAD_FORCE, 0, &w, 1, &err),
	                 PRSM_EINVAL);
	assert_int_equal(prsm_vib_frf(&re, &im, m, &l, PRSM_VIB_IN_MESH_ERROR, 10, PRSM_VIB_OUT_MESH_DEFLECTION, 0, &w, 1, &err),
	                 PRSM_EINVAL);
	/* sweep parameters the reduced model has not */
	assert_int_equal(prsm_vib_model_set(m, PRSM_VIB_PARAM_MEAN_FORCE, 0.1, &err), PRSM_EINVAL);
	assert_int_equal(prsm_vib_model_set(m, PRSM_VIB_PARAM_SCREW_SPEED, -3.0, &err), PRSM_EINVAL);
	assert_int_equal(prsm_vib_model_set(m, PRSM_VIB_PARAM_SCREW_SPEED, 500.0, &err), 0);
	assert_close(prsm_vib_model_params(m)->screw_speed_rad_s, 500.0, 0.0);
	prsm_vib_linear_free(&l);
	prsm_vib_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_parameters),
		cmocka_unit_test(test_static_equilibrium),
		cmocka_unit_test(test_axial_closed_form),
		cmocka_unit_test(test_eigenvalues),
		cmocka_unit_test(test_lyapunov_linear),
		cmocka_unit_test(test_te_lines_fit),
		cmocka_unit_test(test_te_lines_from_errors),
		cmocka_unit_test(test_gear_sweep_threads),
		cmocka_unit_test(test_steady_both_branches),
		cmocka_unit_test(test_refusals),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
