/*
 * test_vib_gear_pair.c: the dimensionless gear pair of docs/model §8.3.5 against the open
 * validation case V4a (§8.8) and against independent computations:
 *  - the linear regime's closed form (V4a amplitudes and mean after 300 + 64 periods from the
 *    static state; a time response started on the closed-form orbit, interpolated outputs);
 *  - the piecewise-constant mesh stiffness against the exact segment-by-segment solution;
 *  - eigenvalues of the linearised model against a time-domain free decay, the FRF against the
 *    receptance, half-power against modal damping;
 *  - Lyapunov exponents: -zeta for the linear system (V4a), their sum -2 zeta (the trace) also with
 *    impacts, lambda_1 = ln|mu_max| / T of the shooting's Floquet multipliers, the two-trajectory
 *    method's sign, a chaotic point;
 *  - the Poincaré count of a period-2 orbit against the shooting solution (and the unstable
 *    period-1 orbit it doubled from);
 *  - harmonic balance against the closed form and against integrated sweeps and shooting (the
 *    jump intervals bracket the exact folds, HB's folds near them);
 *  - located against unlocated dead-zone crossings;
 *  - sweeps and basin grids bit-identical for 1 and 2 threads;
 *  - the refusals of bad input.
 */
#include "test_support.h"

#include "dyn/vib.h"
#include "io/global.h"

static prsm_vib_model *gear_pair(double zeta, double fm, double eps, double kappa, double Omega)
{
	prsm_vib_gear_pair g = PRSM_VIB_GEAR_PAIR_INIT;
	g.damping_ratio = zeta;
	g.mean_force = fm;
	g.mesh_error = eps;
	g.stiffness_variation = kappa;
	g.frequency_ratio = Omega;
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_vib_gear_pair_new(&m, &g, &err)) {
		print_error("gear pair: %s\n", err.message);
		fail();
	}
	return m;
}

static void steady(prsm_vib_steady *s, const prsm_vib_model *m, const double *y0, const prsm_vib_steady_options *o)
{
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_vib_steady_state(s, m, y0, o, NULL, &err);
	if (rc) {
		print_error("steady state: %s (%s)\n", err.message, prsm_error_name(rc));
		fail();
	}
}

static void lyapunov(prsm_vib_lyapunov *l, const prsm_vib_model *m, const prsm_vib_lyapunov_options *o)
{
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_vib_lyapunov_run(l, m, NULL, o, NULL, &err);
	if (rc) {
		print_error("lyapunov: %s (%s)\n", err.message, prsm_error_name(rc));
		fail();
	}
}

static double closed_form_amplitude(double eps, double zeta, double W)
{
	return eps * W * W / sqrt((1.0 - W * W) * (1.0 - W * W) + (2.0 * zeta * W) * (2.0 * zeta * W));
}

/* V4a (open, §8.8): epsilon 0.005, zeta 0.05, f_m 0.1 -- no contact loss: the amplitudes at
 * Omega = 0.5, 1.0, 1.5 to 1e-6 relative, the mean 1 + f_m, period 1 */
static void test_v4a_amplitudes(void **state)
{
	(void)state;
	const double W[3] = {0.5, 1.0, 1.5}, expect[3] = {0.00166298, 0.05, 0.00893589};
	for (int i = 0; i < 3; i++) {
		prsm_vib_model *m = gear_pair(0.05, 0.1, 0.005, 0.0, W[i]);
		prsm_vib_steady_options o = PRSM_VIB_STEADY_OPTIONS_INIT;
		prsm_vib_steady s;
		steady(&s, m, NULL, &o);
		const prsm_vib_extreme *x = &s.extreme[0];
		assert_int_equal(x->observable, PRSM_VIB_OBS_MESH_DEFLECTION);
		const double amp = 0.5 * (x->max - x->min);
		assert_close(amp, expect[i], 1e-6 * expect[i] + 5e-9);      /* the published digits */
		assert_close(amp, closed_form_amplitude(0.005, 0.05, W[i]), 1e-6 * amp);
		assert_close(0.5 * (x->max + x->min), 1.1, 1e-8);
		assert_close(x->mean, 1.1, 1e-8);
		assert_int_equal(s.classification, PRSM_VIB_PERIODIC);
		assert_int_equal(s.period, 1);
		assert_true(s.max_return_distance < 1e-8);
		/* the forcing line of the spectrum is the amplitude (rectangular window, whole periods;
		 * the samples are interpolated, quintic Hermite) */
		assert_string_equal(s.line[0].name, "forcing");
		assert_close(s.line[0].amplitude, amp, 1e-5 * amp);
		assert_true(s.line[1].amplitude < 1e-6 * amp); /* no second harmonic in the linear regime */
		/* a period-1 response has no subharmonic lines: each is evaluated over whole cycles of
		 * itself with the mean removed, so neither the forcing line nor the mean leaks in */
		for (int l = 0; l < s.lines; l++)
			if (strncmp(s.line[l].name, "subharmonic_", 12) == 0)
				assert_true(s.line[l].amplitude < 1e-9 * amp);
		assert_false(s.spectrum_window_hann);
		/* never out of contact, a phase portrait of >= 100 samples per period */
		assert_close(s.loss_share[0], 0.0, 0.0);
		assert_int_equal(s.portrait_points, 64 * 128);
		prsm_vib_steady_free(&s);
		prsm_vib_model_free(m);
	}
}

/* V4a: the Lyapunov exponents of the linear regime, lambda_1 = lambda_2 = -zeta to 2e-4 after
 * 2000 periods; their sum is -2 zeta (the trace) to rounding; the two-trajectory method agrees */
static void test_v4a_lyapunov(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.005, 0.0, 1.0);
	prsm_vib_lyapunov_options o = PRSM_VIB_LYAPUNOV_OPTIONS_INIT;
	o.exponents = 2;
	prsm_vib_lyapunov l;
	lyapunov(&l, m, &o);
	assert_int_equal(l.exponents, 2);
	assert_close(l.lambda[0], -0.05, 2e-4);
	assert_close(l.lambda[1], -0.05, 2e-4);
	assert_close(l.sum, -0.1, 1e-8);
	assert_int_equal(l.blocks, 10);
	assert_true(l.block_min <= l.lambda[0] + 1e-12 && l.block_max >= l.lambda[0] - 1e-12);
	o.method = PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES;
	o.exponents = 1;
	o.periods = 500;
	lyapunov(&l, m, &o);
	assert_close(l.lambda[0], -0.05, 5e-3);
	prsm_vib_model_free(m);
}

/* the exact solution of x'' + 2 zeta x' + k (x - 1) = f_m over a time t (contact closed) */
static void segment_exact(double *x, double *v, double k, double zeta, double fm, double t)
{
	const double xe = 1.0 + fm / k, z0 = *x - xe, v0 = *v, w = sqrt(k - zeta * zeta), e = exp(-zeta * t);
	*x = xe + e * (z0 * cos(w * t) + (v0 + zeta * z0) / w * sin(w * t));
	*v = e * (v0 * cos(w * t) - (zeta * v0 + k * z0) / w * sin(w * t));
}

/* The rectangular mesh stiffness (kappa != 0): the integration stops at every switch; three
 * periods against the exact piecewise solution (double contact on u < eps_alpha - 1). */
static void test_stiffness_switching_exact(void **state)
{
	(void)state;
	const double zeta = 0.05, fm = 0.1, kappa = 0.4, W = 1.3;
	prsm_vib_model *m = gear_pair(zeta, fm, 0.0, kappa, W);
	const double D = 0.5, T = 2.0 * M_PI / W, kd = 1.0 + kappa * (1.0 - D), ks = 1.0 - kappa * D;
	double x = 1.1, v = 0.0;
	for (int p = 0; p < 3; p++) {
		segment_exact(&x, &v, kd, zeta, fm, D * T);
		segment_exact(&x, &v, ks, zeta, fm, (1.0 - D) * T);
	}
	prsm_vib_response r;
	prsm_error err = PRSM_ERROR_INIT;
	const double y0[2] = {1.1, 0.0};
	assert_int_equal(prsm_vib_time_response(&r, m, y0, 3.0 * T, T / 7.0, NULL, NULL, &err), 0);
	assert_close(r.tau[r.points - 1], 3.0 * T, 1e-12);
	assert_close(r.state[(r.points - 1) * 2], x, 1e-9);
	assert_close(r.state[(r.points - 1) * 2 + 1], v, 1e-9);
	assert_int_equal(r.effort.switches, 6);
	/* the mesh force follows kappa(tau) h(x) */
	assert_close(r.mesh_force[1], kd * (r.state[2] - 1.0), 1e-12);
	prsm_vib_response_free(&r);
	prsm_vib_model_free(m);
}

/* A time response started on the closed-form steady orbit of the linear regime stays on it:
 * every interpolated output to 1e-7 of x (1e-5 of the amplitude: integration and the quintic
 * Hermite outputs between steps of up to half the natural period). */
static void test_time_response_closed_form(void **state)
{
	(void)state;
	const double zeta = 0.05, eps = 0.005, W = 0.8;
	prsm_vib_model *m = gear_pair(zeta, 0.1, eps, 0.0, W);
	/* x = 1.1 + Re(X e^{i W tau}), X = eps W^2 / (1 - W^2 + 2 i zeta W) */
	const double re = 1.0 - W * W, im = 2.0 * zeta * W, den = re * re + im * im;
	const double Xr = eps * W * W * re / den, Xi = -eps * W * W * im / den;
	const double y0[2] = {1.1 + Xr, -W * Xi};
	prsm_vib_response r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_time_response(&r, m, y0, 40.0, 0.0137, NULL, NULL, &err), 0);
	double worst = 0.0;
	for (size_t k = 0; k < r.points; k++) {
		const double t = r.tau[k];
		const double x = 1.1 + Xr * cos(W * t) - Xi * sin(W * t), v = -W * (Xr * sin(W * t) + Xi * cos(W * t));
		worst = fmax(worst, fabs(r.state[2 * k] - x));
		worst = fmax(worst, fabs(r.state[2 * k + 1] - v));
		assert_int_equal(r.contact_lost[k], 0);
	}
	assert_true(worst < 1e-7);
	assert_close(r.tau[r.points - 1], 40.0, 0.0);
	prsm_vib_response_free(&r);
	prsm_vib_model_free(m);
}

/* Eigenvalues of the linearised gear pair against a free decay in the time domain: the damped
 * period from successive upward crossings of the mean, the decay rate from the deviation one
 * period apart; the FRF is the receptance, half-power damping within O(zeta^2) of the modal one. */
static void test_eigenvalues_vs_free_decay(void **state)
{
	(void)state;
	const double zeta = 0.0537;
	prsm_vib_model *m = gear_pair(zeta, 0.1, 0.0, 0.0, 1.0);
	prsm_vib_linear l;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_linearise(&l, m, &err), 0);
	assert_int_equal(l.eigenvalues, 2);
	assert_int_equal(l.kind[0], PRSM_VIB_EIG_OSCILLATORY);
	assert_close(l.eig_re[0], -zeta, 1e-12);
	assert_close(fabs(l.eig_im[0]), sqrt(1.0 - zeta * zeta), 1e-12);
	assert_close(l.damping_ratio[0], zeta, 1e-12);
	/* free decay from x = 1.1 + 0.06 (the contact stays closed) */
	const double y0[2] = {1.16, 0.0};
	prsm_vib_response r;
	assert_int_equal(prsm_vib_time_response(&r, m, y0, 30.0, 1e-3, NULL, NULL, &err), 0);
	double up[8];
	int n_up = 0;
	for (size_t k = 1; k < r.points && n_up < 8; k++) {
		const double a = r.state[2 * (k - 1)] - 1.1, b = r.state[2 * k] - 1.1;
		if (a < 0.0 && b >= 0.0)
			up[n_up++] = r.tau[k - 1] + (r.tau[k] - r.tau[k - 1]) * (-a) / (b - a);
	}
	assert_true(n_up >= 3);
	const double Td = up[2] - up[1];
	assert_close(2.0 * M_PI / Td, fabs(l.eig_im[0]), 1e-7);
	/* the deviation one damped period apart: exactly e^{Re(lambda) T_d} */
	const size_t k0 = 2000, k1 = k0 + (size_t)floor(Td / 1e-3);
	const double frac = (Td - (double)(k1 - k0) * 1e-3) / 1e-3;
	const double d0 = r.state[2 * k0] - 1.1;
	const double d1 = (1.0 - frac) * r.state[2 * k1] + frac * r.state[2 * (k1 + 1)] - 1.1;
	assert_close(log(d1 / d0) / Td, l.eig_re[0], 2e-5);
	prsm_vib_response_free(&r);
	/* FRF: the receptance 1 / (1 - W^2 + 2 i zeta W) of a unit force */
	const double w[3] = {0.3, 0.97, 2.1};
	double hr[3], hi[3];
	assert_int_equal(prsm_vib_frf(hr, hi, m, &l, PRSM_VIB_IN_NUT_FORCE, 0, PRSM_VIB_OUT_MESH_DEFLECTION, 0, w, 3, &err), 0);
	for (int i = 0; i < 3; i++) {
		const double re = 1.0 - w[i] * w[i], im = 2.0 * zeta * w[i], den = re * re + im * im;
		assert_close(hr[i], re / den, 1e-12 / den);
		assert_close(hi[i], -im / den, 1e-12 / den);
	}
	prsm_vib_half_power hp;
	assert_int_equal(prsm_vib_half_power_run(&hp, m, &l, PRSM_VIB_IN_NUT_FORCE, 0, PRSM_VIB_OUT_MESH_DEFLECTION, 0,
	                                         0.5, 1.5, &err),
	                 0);
	assert_true(hp.defined);
	assert_close(hp.modal_damping_ratio, zeta, 1e-12);
	assert_close(hp.damping_ratio, zeta, 2.0 * zeta * zeta * zeta + 1e-5); /* O(zeta^2) relative */
	assert_close(hp.peak_omega, sqrt(1.0 - 2.0 * zeta * zeta), 1e-5);
	/* a band without the peak inside: undefined, with a reason */
	assert_int_equal(prsm_vib_half_power_run(&hp, m, &l, PRSM_VIB_IN_NUT_FORCE, 0, PRSM_VIB_OUT_MESH_DEFLECTION, 0,
	                                         1.2, 1.5, &err),
	                 0);
	assert_false(hp.defined);
	assert_true(strlen(hp.reason) > 0);
	prsm_vib_linear_free(&l);
	prsm_vib_model_free(m);
}

/* epsilon 0.2, Omega 1.80 from (1 + f_m, 0): a period-2 orbit, its 128 Poincaré points two
 * distinct values; shooting finds the same two points with stable multipliers, and the
 * period-1 orbit next to it has a multiplier below -1 (it doubled) */
static void test_period_two(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.2, 0.0, 1.8);
	prsm_vib_steady_options o = PRSM_VIB_STEADY_OPTIONS_INIT;
	o.transient_periods = 500;
	o.recorded_periods = 128;
	prsm_vib_steady s;
	const double y0[2] = {1.1, 0.0};
	steady(&s, m, y0, &o);
	assert_int_equal(s.classification, PRSM_VIB_PERIODIC);
	assert_int_equal(s.period, 2);
	double distinct[4][2];
	int nd = 0;
	for (int i = 0; i < s.recorded; i++) {
		const double *p = s.poincare + 2 * i;
		int k = 0;
		while (k < nd && !(fabs(p[0] - distinct[k][0]) < 1e-6 && fabs(p[1] - distinct[k][1]) < 1e-6))
			k++;
		if (k == nd && nd < 4) {
			distinct[nd][0] = p[0];
			distinct[nd][1] = p[1];
			nd++;
		}
	}
	assert_int_equal(nd, 2);
	assert_true(fabs(distinct[0][0] - distinct[1][0]) > 1e-3);
	/* the Poincaré values of the observable alternate */
	assert_close(s.poincare_observable[0], s.poincare_observable[2], 1e-7);
	assert_true(fabs(s.poincare_observable[0] - s.poincare_observable[1]) > 1e-3);
	/* shooting from the last point */
	prsm_vib_orbit orb;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_periodic_orbit(&orb, m, s.final_state, 2, NULL, NULL, &err), 0);
	assert_true(orb.converged);
	assert_close(orb.state[0], s.final_state[0], 1e-8);
	assert_close(orb.state[1], s.final_state[1], 1e-8);
	assert_true(hypot(orb.multiplier_re[0], orb.multiplier_im[0]) < 1.0);
	/* the multipliers' product is det = exp(-2 zeta m T) (the trace) */
	const double T = 2.0 * M_PI / 1.8;
	const double prod_abs = hypot(orb.multiplier_re[0], orb.multiplier_im[0]) * hypot(orb.multiplier_re[1], orb.multiplier_im[1]);
	assert_close(prod_abs, exp(-2.0 * 0.05 * 2.0 * T), 1e-7);
	assert_close(0.5 * (orb.max - orb.min), 0.5 * (s.extreme[0].max - s.extreme[0].min), 1e-8);
	/* the period-1 orbit between the two points: unstable through a multiplier < -1 */
	double mid[2] = {0.5 * (distinct[0][0] + distinct[1][0]), 0.5 * (distinct[0][1] + distinct[1][1])};
	prsm_vib_orbit one;
	assert_int_equal(prsm_vib_periodic_orbit(&one, m, mid, 1, NULL, NULL, &err), 0);
	assert_true(one.converged);
	int below = 0;
	for (int i = 0; i < one.multipliers; i++)
		below |= fabs(one.multiplier_im[i]) < 1e-12 && one.multiplier_re[i] < -1.0;
	assert_true(below);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);
}

/* Lyapunov exponents with impacts (epsilon 0.2, Omega 0.7, a period-1 orbit that loses contact
 * every period): their sum is still -2 zeta (the trace: the located kinks keep the variational
 * part exact), lambda_1 = ln|mu_max| / T from the shooting; a chaotic point (Omega 1.30) has a
 * positive exponent by both methods and is classified chaotic. */
static void test_lyapunov_with_impacts(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.2, 0.0, 0.7);
	prsm_vib_lyapunov_options o = PRSM_VIB_LYAPUNOV_OPTIONS_INIT;
	o.exponents = 2;
	o.periods = 1000;
	prsm_vib_lyapunov l;
	lyapunov(&l, m, &o);
	assert_close(l.sum, -0.1, 1e-7);
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	prsm_vib_steady s;
	steady(&s, m, NULL, &so);
	assert_int_equal(s.period, 1);
	assert_true(s.loss_share[0] > 0.3); /* impacts every period */
	prsm_vib_orbit orb;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_periodic_orbit(&orb, m, s.final_state, 1, NULL, NULL, &err), 0);
	assert_true(orb.converged);
	assert_close(l.lambda[0], orb.lambda_max, 2e-4);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);

	m = gear_pair(0.05, 0.1, 0.2, 0.0, 1.3);
	o.exponents = 1;
	o.periods = 600;
	lyapunov(&l, m, &o);
	assert_true(l.lambda[0] > 0.02);
	o.method = PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES;
	lyapunov(&l, m, &o);
	assert_true(l.lambda[0] > 0.01);
	so.lyapunov = 1;
	so.lyapunov_periods = 300;
	so.recorded_periods = 64;
	steady(&s, m, NULL, &so);
	assert_int_equal(s.classification, PRSM_VIB_CHAOTIC);
	assert_true(s.lyapunov > 1e-3);
	assert_true(s.spectrum_window_hann);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);
}

/* Located and unlocated dead-zone crossings agree; the located integration converges with the
 * tolerance much faster (every step smooth). */
static void test_kink_location(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.2, 0.0, 0.7);
	prsm_vib_steady_options o = PRSM_VIB_STEADY_OPTIONS_INIT;
	o.transient_periods = 200;
	o.recorded_periods = 8;
	prsm_vib_steady a, b, c;
	o.integration.rel_tol = o.integration.abs_tol = 1e-9;
	steady(&a, m, NULL, &o);
	o.integration.rel_tol = o.integration.abs_tol = 1e-12;
	steady(&b, m, NULL, &o);
	o.integration.locate_kinks = PRSM_VIB_LOCATE_NEVER;
	steady(&c, m, NULL, &o);
	assert_close(a.extreme[0].max, b.extreme[0].max, 1e-10);
	assert_close(a.extreme[0].min, b.extreme[0].min, 1e-10);
	assert_close(a.poincare[0], b.poincare[0], 1e-10);
	assert_close(c.extreme[0].max, b.extreme[0].max, 1e-8);
	assert_close(c.extreme[0].min, b.extreme[0].min, 1e-8);
	assert_true(a.effort.events > 0);
	assert_int_equal(c.effort.events, 0);
	prsm_vib_steady_free(&a);
	prsm_vib_steady_free(&b);
	prsm_vib_steady_free(&c);
	prsm_vib_model_free(m);
}

/* Harmonic balance: the closed form in the linear regime; at epsilon 0.02 two folds, the exact
 * folds by shooting inside the jump intervals of the integrated sweeps up and down, HB's folds
 * near them (HB is approximate with impacts), HB = integration where the contact never opens */
static void test_harmonic_balance_vs_integration(void **state)
{
	(void)state;
	prsm_vib_gear_pair g = PRSM_VIB_GEAR_PAIR_INIT;
	prsm_vib_hb hb;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_harmonic_balance(&hb, &g, 0.5, 1.5, 2000, &err), 0);
	assert_true(hb.points > 100);
	assert_int_equal(hb.folds, 0);
	for (size_t k = 0; k < hb.points; k++) {
		assert_close(hb.point[k].amplitude, closed_form_amplitude(0.005, 0.05, hb.point[k].omega),
		             1e-9 * hb.point[k].amplitude);
		assert_close(hb.point[k].mean, 1.1, 1e-12);
		assert_true(hb.point[k].stable);
	}
	prsm_vib_hb_free(&hb);
	/* describing functions: fully closed contact N_0 = x_m - 1, N_1 = 1 */
	double N0, N1;
	prsm_vib_dead_zone_describing(1.3, 0.2, &N0, &N1);
	assert_close(N0, 0.3, 1e-14);
	assert_close(N1, 1.0, 1e-14);

	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.02, 0.0, 0.85);
	prsm_vib_sweep_options so;
	prsm_vib_sweep_options_init(&so);
	so.from = 0.85;
	so.to = 0.95;
	so.step = 0.01;
	so.steady.transient_periods = 300;
	so.steady.recorded_periods = 16;
	so.threads = 2;
	prsm_vib_frequency_response fr;
	assert_int_equal(prsm_vib_frequency_response_run(&fr, m, &so, NAN, NULL, NULL, NULL, &err), 0);
	assert_int_equal(fr.hb.folds, 2);
	assert_int_equal(fr.jumps, 2);
	int seen_up = 0, seen_down = 0;
	for (int k = 0; k < fr.jumps; k++) {
		const prsm_vib_jump *j = &fr.jump[k];
		const prsm_vib_exact_fold *f = &fr.exact_fold[k];
		assert_true(f->found);
		assert_true(f->omega >= fmin(j->from, j->to) && f->omega <= fmax(j->from, j->to));
		assert_true(f->last_multiplier > 0.99);
		/* the HB fold of the same kind */
		const int kind = j->direction > 0 ? 1 : -1;
		for (int h = 0; h < fr.hb.folds; h++)
			if (fr.hb.fold[h].kind == kind)
				assert_close(fr.hb.fold[h].omega, f->omega, 0.02);
		seen_up |= j->direction > 0;
		seen_down |= j->direction < 0;
	}
	assert_true(seen_up && seen_down);
	/* the up sweep leaves the small branch at the upper fold: the small orbit (contact closed)
	 * equals HB's low branch */
	const prsm_vib_sweep_point *p = &fr.sweep.point[0]; /* Omega 0.85, up */
	assert_close(p->parameter, 0.85, 1e-12);
	assert_close(p->amplitude, closed_form_amplitude(0.02, 0.05, 0.85), 1e-6 * p->amplitude);
	prsm_vib_frequency_response_free(&fr);
	prsm_vib_model_free(m);
}

static int same_bytes(const void *a, const void *b, size_t n)
{
	return memcmp(a, b, n) == 0;
}

/* Sweeps (continuation in both directions, and independent points) and basin grids give
 * bit-identical results for 1 and 2 threads; progress reaches the planned count. */
typedef struct {
	size_t last, planned;
	int calls;
} progress_log;

static void on_progress(void *ctx, const prsm_progress *p)
{
	progress_log *l = ctx;
	l->last = p->done;
	l->planned = p->planned;
	l->calls++;
}

static void test_threads_bit_identical(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.05, 0.1, 0.2, 0.0, 1.0);
	prsm_vib_sweep_options so;
	prsm_vib_sweep_options_init(&so);
	so.from = 0.6;
	so.to = 1.4;
	so.step = 0.1;
	so.steady.transient_periods = 100;
	so.steady.recorded_periods = 32;
	prsm_error err = PRSM_ERROR_INIT;
	for (int cont = 1; cont >= 0; cont--) {
		so.continuation = cont;
		prsm_vib_sweep s1, s2;
		progress_log pl = {0, 0, 0};
		so.threads = 1;
		assert_int_equal(prsm_vib_sweep_run(&s1, m, &so, NULL, on_progress, &pl, &err), 0);
		assert_int_equal(pl.last, pl.planned);
		so.threads = 2;
		pl.calls = 0;
		assert_int_equal(prsm_vib_sweep_run(&s2, m, &so, NULL, on_progress, &pl, &err), 0);
		assert_true(pl.calls > 0);
		assert_int_equal(pl.last, pl.planned);
		assert_int_equal(s1.points, 18);
		assert_int_equal(s2.points, 18);
		assert_true(same_bytes(s1.point, s2.point, s1.points * sizeof *s1.point));
		assert_true(same_bytes(s1.poincare, s2.poincare, s1.points * s1.recorded * sizeof(double)));
		assert_true(same_bytes(s1.end_state, s2.end_state, s1.points * s1.states * sizeof(double)));
		assert_int_equal(s1.effort.steps, s2.effort.steps);
		/* the directions and their order */
		assert_int_equal(s1.point[0].direction, 1);
		assert_close(s1.point[0].parameter, 0.6, 1e-15);
		assert_int_equal(s1.point[9].direction, -1);
		assert_close(s1.point[9].parameter, 1.4, 1e-15);
		prsm_vib_sweep_free(&s1);
		prsm_vib_sweep_free(&s2);
	}
	prsm_vib_model_free(m);

	/* basins at epsilon 0.02, Omega 0.90: the small and the large orbit coexist */
	m = gear_pair(0.05, 0.1, 0.02, 0.0, 0.9);
	prsm_vib_basin_options bo;
	prsm_vib_basin_options_init(&bo);
	bo.nx = 7;
	bo.nv = 6;
	bo.x_min = 0.8;
	bo.x_max = 1.4;
	bo.v_min = -0.3;
	bo.v_max = 0.3;
	bo.periods = 60;
	bo.identify_periods = 8;
	prsm_vib_basins b1, b2;
	bo.threads = 1;
	assert_int_equal(prsm_vib_basins_run(&b1, m, &bo, NULL, NULL, NULL, &err), 0);
	bo.threads = 2;
	assert_int_equal(prsm_vib_basins_run(&b2, m, &bo, NULL, NULL, NULL, &err), 0);
	assert_int_equal(b1.attractors, b2.attractors);
	assert_true(same_bytes(b1.label, b2.label, 42 * sizeof(int)));
	assert_true(b1.attractors >= 2);
	double total = b1.other_fraction + b1.failed_fraction;
	for (int a = 0; a < b1.attractors; a++) {
		total += b1.attractor[a].fraction;
		assert_true(b1.attractor[a].fraction > 0.0);
		assert_int_equal(b1.attractor[a].period, 1);
		assert_true(same_bytes(b1.attractor[a].poincare, b2.attractor[a].poincare, 2 * sizeof(double)));
	}
	assert_close(total, 1.0, 1e-12);
	/* a known attractor given first keeps index 0 */
	const double known[2] = {b1.attractor[1].poincare[0], b1.attractor[1].poincare[1]};
	const int kp = 1;
	bo.known = 1;
	bo.known_state = known;
	bo.known_period = &kp;
	prsm_vib_basins b3;
	assert_int_equal(prsm_vib_basins_run(&b3, m, &bo, NULL, NULL, NULL, &err), 0);
	assert_true(b3.attractor[0].given);
	assert_int_equal(b3.attractor[0].cells, b1.attractor[1].cells);
	prsm_vib_basins_free(&b1);
	prsm_vib_basins_free(&b2);
	prsm_vib_basins_free(&b3);
	prsm_vib_model_free(m);
}

/* The period test on synthetic sections (a period must repeat at least once in the record). */
static void test_period_of(void **state)
{
	(void)state;
	double P[40];
	for (int i = 0; i < 20; i++) {
		P[2 * i] = (i % 3 == 0) ? 1.0 : (i % 3 == 1 ? 2.0 : 3.0);
		P[2 * i + 1] = 0.5;
	}
	double d;
	assert_int_equal(prsm_vib_period_of(P, 20, 2, 1e-6, 32, &d), 3);
	assert_close(d, 0.0, 0.0);
	P[2 * 7] += 1e-5;
	assert_int_equal(prsm_vib_period_of(P, 20, 2, 1e-6, 32, &d), 0);
	assert_close(d, 2.0, 1e-4);
	assert_int_equal(prsm_vib_period_of(P, 20, 2, 1e-4, 32, &d), 3);
}

/* Bad input is refused with the pointer of the field. */
static void test_refusals(void **state)
{
	(void)state;
	prsm_vib_gear_pair g = PRSM_VIB_GEAR_PAIR_INIT;
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	g.damping_ratio = 0.0;
	assert_int_equal(prsm_vib_gear_pair_new(&m, &g, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/mesh_damping_ratio");
	assert_null(m);
	g.damping_ratio = 0.05;
	g.stiffness_variation = 3.0;
	assert_int_equal(prsm_vib_gear_pair_new(&m, &g, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/vibration/stiffness_variation");
	g.stiffness_variation = 0.0;
	g.frequency_ratio = -1.0;
	assert_int_equal(prsm_vib_gear_pair_new(&m, &g, &err), PRSM_EINVAL);
	m = gear_pair(0.05, 0.1, 0.005, 0.0, 1.0);
	/* an unbounded transient */
	prsm_vib_steady_options o = PRSM_VIB_STEADY_OPTIONS_INIT;
	o.transient_periods = 2000000000;
	prsm_vib_steady s;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &o, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/sweep/transient_periods");
	o = (prsm_vib_steady_options)PRSM_VIB_STEADY_OPTIONS_INIT;
	o.observable = PRSM_VIB_OBS_THREAD_FORCE;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &o, NULL, &err), PRSM_EINVAL);
	/* a sweep of 10^7 points */
	prsm_vib_sweep_options so;
	prsm_vib_sweep_options_init(&so);
	so.from = 0.5;
	so.to = 1.5;
	so.step = 1e-7;
	prsm_vib_sweep sw;
	assert_int_equal(prsm_vib_sweep_run(&sw, m, &so, NULL, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/sweep/step");
	so.step = 0.1;
	so.to = 0.2;
	assert_int_equal(prsm_vib_sweep_run(&sw, m, &so, NULL, NULL, NULL, &err), PRSM_EINVAL);
	so.to = 1.5;
	so.from = -0.5; /* a frequency ratio <= 0 */
	assert_int_equal(prsm_vib_sweep_run(&sw, m, &so, NULL, NULL, NULL, &err), PRSM_EINVAL);
	so.from = 0.5;
	so.parameter = 42;
	assert_int_equal(prsm_vib_sweep_run(&sw, m, &so, NULL, NULL, NULL, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/sweep/parameter");
	/* harmonic balance needs the constant stiffness */
	g.stiffness_variation = 0.2;
	prsm_vib_hb hb;
	assert_int_equal(prsm_vib_harmonic_balance(&hb, &g, 0.5, 1.5, 1000, &err), PRSM_EINVAL);
	/* the Lyapunov options */
	prsm_vib_lyapunov_options lo = PRSM_VIB_LYAPUNOV_OPTIONS_INIT;
	prsm_vib_lyapunov l;
	lo.exponents = 3;
	assert_int_equal(prsm_vib_lyapunov_run(&l, m, NULL, &lo, NULL, &err), PRSM_EINVAL);
	/* a time response of too many points */
	prsm_vib_response r;
	assert_int_equal(prsm_vib_time_response(&r, m, NULL, 1e6, 1e-3, NULL, NULL, &err), PRSM_EINVAL);
	/* cancellation */
	prsm_cancel_flag cancel;
	atomic_init(&cancel, 1);
	o = (prsm_vib_steady_options)PRSM_VIB_STEADY_OPTIONS_INIT;
	o.transient_periods = 5000;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &o, &cancel, &err), PRSM_ECANCELLED);
	so.threads = 2;
	so.parameter = PRSM_VIB_PARAM_FREQUENCY_RATIO;
	assert_int_equal(prsm_vib_sweep_run(&sw, m, &so, &cancel, NULL, NULL, &err), PRSM_ECANCELLED);
	prsm_vib_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_v4a_amplitudes),
		cmocka_unit_test(test_v4a_lyapunov),
		cmocka_unit_test(test_stiffness_switching_exact),
		cmocka_unit_test(test_time_response_closed_form),
		cmocka_unit_test(test_eigenvalues_vs_free_decay),
		cmocka_unit_test(test_period_two),
		cmocka_unit_test(test_lyapunov_with_impacts),
		cmocka_unit_test(test_kink_location),
		cmocka_unit_test(test_harmonic_balance_vs_integration),
		cmocka_unit_test(test_threads_bit_identical),
		cmocka_unit_test(test_period_of),
		cmocka_unit_test(test_refusals),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
