/*
 * test_vib_mc.c: one sample of the dynamic Monte Carlo (src/dyn/vib_mc.c; MODEL-DYNAMICS.md §8.6 on
 * the model of §8.3) on case A with V5's setting (payload 400 kg, F_0 7 kN, 330 rad/s):
 *  - a screened sample's closed form (every contact on its loaded flank) against the integrator
 *    started anywhere else (the static state): peak dynamic TE, peak thread force, RMS nut
 *    acceleration, peak mesh force; and the closed form's state at t = 0 is a periodic orbit of
 *    the integrator (one window later it returns to itself);
 *  - the axial closed form against §8.3.2's line formula evaluated independently here;
 *  - a sample forced into contact loss (a large mesh error, or a tiny axial load with a TE line on
 *    the axial resonance) is not screened, is integrated, and the integrated steady state shows
 *    the contact loss;
 *  - the refusals of prsm_vib_mc_apply.
 */
#include "test_case_a_fixture.h"

#include <complex.h>

#include "dyn/vib_mc.h"
#include "io/design_json.h"
#include "io/global.h"

/* case A, V5's operating point, the V5 lines (orders at k_c); k_d / k_s = ratio (0: the default) */
static prsm_vib_model *model_ratio(double load_N, double ratio)
{
	prsm_dyn_options dopt;
	prsm_dyn_options_init(&dopt);
	dopt.inertia.payload_kg = 400.0;
	dopt.load.value = load_N;
	prsm_vib_options vo;
	prsm_vib_options_init(&vo);
	vo.screw_speed_rad_s = 330.0;
	if (ratio > 0.0)
		vo.double_to_single_stiffness = ratio;
	const double ord[5] = {1.0, 1.875, 0.625, 3.75, 0.375}, amp[5] = {1.84, 0.443, 0.260, 0.181, 0.141};
	vo.te_source = PRSM_VIB_TE_LINES;
	vo.te_lines = 5;
	for (int k = 0; k < 5; k++) {
		vo.te_line[k].order_per_rev = ord[k];
		vo.te_line[k].amplitude_m = amp[k] * 1e-6;
		vo.te_line[k].phase_rad = 0.3 * k;
	}
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_vib_model_new(&m, &fx->d, &fx->a, &dopt, &vo, NULL, NULL, &err);
	if (rc) {
		print_error("model: %s (%s) at %s\n", err.message, prsm_error_name(rc), err.pointer);
		fail();
	}
	return m;
}

static prsm_vib_model *model(double load_N)
{
	return model_ratio(load_N, 0.0);
}

static void apply(prsm_vib_model *m, double mesh_error_um, double zeta)
{
	prsm_vib_mc_sample s;
	prsm_vib_mc_sample_init(&s);
	s.mesh_error_m = mesh_error_um * 1e-6;
	s.axial_damping_ratio = zeta;
	s.mesh_damping_ratio = zeta;
	s.window_rev = 8.0;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_vib_mc_apply(m, &s, &err);
	if (rc)
		print_error("apply: %s\n", err.message);
	assert_int_equal(rc, 0);
}

static void show(const char *what, const prsm_vib_mc_out *o)
{
	print_message("%s: screened %d integrated %d loss %d regime %d windows %d: peak TE %.6g um, F_th %.8g N, rms %.6g "
	              "m/s2, mesh %.6g N; margins axial %.4g mesh %.4g, F_th min %.6g N\n",
	              what, o->screened, o->integrated, o->contact_loss, o->regime, o->windows, o->peak_dynamic_te_m * 1e6,
	              o->peak_thread_force_N, o->axial_vibration_rms_m_s2, o->mesh_force_peak_N, o->axial_margin,
	              o->mesh_margin, o->thread_force_min_N);
}

/* (a) the closed form of a screened sample against the integrator */
static void test_screened_equals_integrated(void **state)
{
	(void)state;
	prsm_vib_model *m = model(7000.0);
	apply(m, 0.02, 0.05);
	prsm_vib_mc_options o;
	prsm_vib_mc_options_init(&o);
	prsm_vib_mc_out cf, in;
	prsm_error err = PRSM_ERROR_INIT;
	double y0[PRSM_VIB_STATE_MAX];
	assert_int_equal(prsm_vib_mc_screen(&cf, y0, m, &o, &err), 0);
	show("closed form", &cf);
	assert_int_equal(cf.screened, 1);
	assert_int_equal(cf.contact_loss, 0);
	/* from the static state: the transient decays to the same orbit */
	in = cf;
	o.integration.rel_tol = o.integration.abs_tol = 1e-10;
	assert_int_equal(prsm_vib_mc_integrate(&in, m, NULL, &o, NULL, &err), 0);
	show("integrated", &in);
	assert_int_equal(in.regime, 1);
	assert_int_equal(in.contact_loss, 0);
	assert_close(in.peak_dynamic_te_m, cf.peak_dynamic_te_m, 2e-3 * cf.peak_dynamic_te_m);
	assert_close(in.peak_thread_force_N, cf.peak_thread_force_N, 2e-4 * cf.peak_thread_force_N);
	assert_close(in.axial_vibration_rms_m_s2, cf.axial_vibration_rms_m_s2, 2e-3 * cf.axial_vibration_rms_m_s2);
	assert_close(in.mesh_force_peak_N, cf.mesh_force_peak_N, 1e-3 * cf.mesh_force_peak_N);
	/* from the closed form's state at t = 0: periodic at once (one window returns to itself) */
	prsm_vib_mc_out on = cf;
	assert_int_equal(prsm_vib_mc_integrate(&on, m, y0, &o, NULL, &err), 0);
	show("integrated from the closed form", &on);
	assert_int_equal(on.regime, 1);
	assert_int_equal(on.windows, 3); /* two returns checked, one recorded */
	assert_true(on.max_return_distance < 1e-5);
	assert_close(on.peak_dynamic_te_m, cf.peak_dynamic_te_m, 1e-4 * cf.peak_dynamic_te_m);
	assert_close(on.peak_thread_force_N, cf.peak_thread_force_N, 1e-5 * cf.peak_thread_force_N);
	assert_close(on.axial_vibration_rms_m_s2, cf.axial_vibration_rms_m_s2, 1e-4 * cf.axial_vibration_rms_m_s2);
	assert_close(on.mesh_force_peak_N, cf.mesh_force_peak_N, 1e-3 * cf.mesh_force_peak_N);
	prsm_vib_model_free(m);
}

/* (b) contact loss: a mesh error far beyond the static mesh deflection (the gear rattles), and a
 * light axial load whose thread lifts off under the TE lines */
static void test_contact_loss_integrated(void **state)
{
	(void)state;
	prsm_vib_mc_options o;
	prsm_vib_mc_options_init(&o);
	prsm_error err = PRSM_ERROR_INIT;
	prsm_vib_mc_out r;
	prsm_vib_model *m = model(7000.0);
	apply(m, 30.0, 0.05);
	assert_int_equal(prsm_vib_mc_eval(&r, m, &o, NULL, &err), 0);
	show("mesh error 30 um", &r);
	assert_true(r.mesh_margin < 0.0);
	assert_true(r.axial_margin > 0.0);
	assert_int_equal(r.screened, 0);
	assert_int_equal(r.integrated, 1);
	assert_int_equal(r.contact_loss, 1);
	assert_true(r.windows >= 3);
	assert_true(r.effort.steps > 0);
	prsm_vib_model_free(m);

	m = model(150.0);
	apply(m, 0.0, 0.05);
	assert_int_equal(prsm_vib_mc_eval(&r, m, &o, NULL, &err), 0);
	show("F_0 150 N", &r);
	assert_true(r.axial_margin < 0.0);
	assert_int_equal(r.screened, 0);
	assert_int_equal(r.integrated, 1);
	assert_int_equal(r.contact_loss, 1);
	prsm_vib_model_free(m);
}

/* the axial closed form against §8.3.2's formula for one line: F_th = F_0 + |F_1| cos(...),
 * |X - X_static| peaks at |Y_1 - A_1|, the RMS acceleration is |F_1| / (sqrt 2 m_a) */
static void test_axial_single_line(void **state)
{
	(void)state;
	prsm_vib_model *m = model(7000.0);
	prsm_vib_mc_sample s;
	prsm_vib_mc_sample_init(&s);
	s.te_source = 1;
	s.te_lines = 1;
	s.te_line[0].order_per_rev = 3.75;
	s.te_line[0].amplitude_m = 0.181e-6;
	s.te_line[0].phase_rad = 0.7;
	s.mesh_error_m = 0.0;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), 0);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	const double w = 3.75 * P->screw_speed_rad_s, k = P->axial_stiffness_N_per_m, ma = P->axial_mass_kg,
	             c = P->axial_damping_N_s_per_m;
	const double complex A = 0.181e-6 * cexp(I * 0.7);
	const double complex Y = -ma * w * w * A / (k - ma * w * w + I * w * c), F = (k + I * w * c) * Y;
	prsm_vib_mc_options o;
	prsm_vib_mc_options_init(&o);
	prsm_vib_mc_out r;
	assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), 0);
	print_message("one line: |F| %.6g N, |Y - A| %.6g um; closed form %.8g N, %.6g um, %.6g m/s2\n", cabs(F),
	              cabs(Y - A) * 1e6, r.peak_thread_force_N, r.peak_dynamic_te_m * 1e6, r.axial_vibration_rms_m_s2);
	assert_int_equal(r.screened, 1);
	assert_close(r.peak_thread_force_N, 7000.0 + cabs(F), 1e-6 * cabs(F));
	assert_close(r.thread_force_min_N, 7000.0 - cabs(F), 1e-3 * cabs(F));
	assert_close(r.peak_dynamic_te_m, cabs(Y - A), 1e-6 * cabs(Y - A));
	assert_close(r.axial_vibration_rms_m_s2, cabs(F) / (sqrt(2.0) * ma), 1e-12 * cabs(F) / ma);
	/* the window is the line's period rounded: 3.75 = 30 / 8, W = 4 revolutions would do; the
	 * model keeps W = 8 and the order */
	assert_close(P->te_line[0].order_per_rev, 3.75, 0.0);
	prsm_vib_model_free(m);
}

/* xorshift64*: a fixed stream of uniform numbers in [0, 1) */
static double uni(unsigned long long *x)
{
	*x ^= *x >> 12;
	*x ^= *x << 25;
	*x ^= *x >> 27;
	return (double)((*x * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

#define SAME(a, b, what, i)                                                                         \
	do {                                                                                      \
		if (memcmp(&(a), &(b), sizeof(a)) != 0) {                                         \
			print_error("sample %d: %s %.17g (fast) against %.17g (reference)\n", i, what,  \
			            (double)(a), (double)(b));                                    \
			fail();                                                                   \
		}                                                                                 \
	} while (0)

/* The screen's fast loops against its reference loops (o.reference) over random high-entropy
 * samples: every input the sample sets drawn (stiffness, play, five TE lines of random order,
 * amplitude and phase, gear backlash, mesh error up to past the contact-loss threshold, damping
 * ratios), and every output and the state at t = 0 compared bit for bit. The fast loops do the
 * same floating-point operations in the same order (real arithmetic for the complex products,
 * comparisons for fmin / fmax, a heap for the sort, SSE2 lanes that each do a scalar loop's
 * operations; their bound only evaluates more points; phasors of an argument with the same bits
 * taken from a table), so the tolerance is zero (docs/vibration.md, "Speed of the screen"). */
static void test_fast_equals_reference(void **state)
{
	(void)state;
	prsm_vib_model *m = model(7000.0);
	const prsm_vib_params *P = prsm_vib_model_params(m);
	const double k0 = P->axial_stiffness_N_per_m, b0 = P->axial_half_play_m;
	unsigned long long x = 0x9e3779b97f4a7c15ULL;
	int screened = 0, lost = 0;
	const int n = 48;
	for (int i = 0; i < n; i++) {
		prsm_vib_mc_sample s;
		prsm_vib_mc_sample_init(&s);
		s.axial_stiffness_N_per_m = k0 * (0.5 + 1.5 * uni(&x));
		s.axial_half_play_m = b0 * (0.3 + 2.0 * uni(&x));
		s.gear_half_backlash_m = (1.0 + 9.0 * uni(&x)) * 1e-6;
		s.mesh_error_m = 14e-6 * uni(&x);
		s.axial_damping_ratio = 0.02 + 0.06 * uni(&x);
		s.mesh_damping_ratio = 0.02 + 0.06 * uni(&x);
		s.te_source = 1;
		s.te_lines = 5;
		for (int k = 0; k < 5; k++) {
			s.te_line[k].order_per_rev = 0.25 + 6.5 * uni(&x);
			s.te_line[k].amplitude_m = 2.5e-6 * uni(&x);
			s.te_line[k].phase_rad = 2.0 * M_PI * uni(&x);
		}
		s.window_rev = 8.0;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_vib_mc_apply(m, &s, &err), 0);
		prsm_vib_mc_options o;
		prsm_vib_mc_options_init(&o);
		o.lyapunov_windows = 1;
		prsm_vib_mc_out fast, ref;
		double y_fast[PRSM_VIB_STATE_MAX], y_ref[PRSM_VIB_STATE_MAX];
		memset(y_ref, 0, sizeof y_ref);
		o.reference = 1;
		assert_int_equal(prsm_vib_mc_screen(&ref, y_ref, m, &o, &err), 0);
		o.reference = 0;
		/* twice: first with the phasors the previous sample left in the screen's per-thread table
		 * (its TE lines' orders differ, so those arguments differ: computed and kept; the mesh's
		 * are the same: taken from the table), then with this sample's own (all taken) */
		for (int pass = 0; pass < 2; pass++) {
			memset(y_fast, 0, sizeof y_fast);
			assert_int_equal(prsm_vib_mc_screen(&fast, y_fast, m, &o, &err), 0);
			SAME(fast.peak_dynamic_te_m, ref.peak_dynamic_te_m, "peak TE", i);
			SAME(fast.peak_thread_force_N, ref.peak_thread_force_N, "peak thread force", i);
			SAME(fast.axial_vibration_rms_m_s2, ref.axial_vibration_rms_m_s2, "RMS acceleration", i);
			SAME(fast.mesh_force_peak_N, ref.mesh_force_peak_N, "peak mesh force", i);
			SAME(fast.axial_margin, ref.axial_margin, "axial margin", i);
			SAME(fast.mesh_margin, ref.mesh_margin, "mesh margin", i);
			SAME(fast.thread_force_min_N, ref.thread_force_min_N, "min thread force", i);
			SAME(fast.lyapunov_max_per_s, ref.lyapunov_max_per_s, "largest Lyapunov exponent", i);
			SAME(fast.lyapunov_gear_per_s, ref.lyapunov_gear_per_s, "gear branch's exponent", i);
			assert_int_equal(fast.screened, ref.screened);
			assert_int_equal(fast.regime, ref.regime);
			assert_memory_equal(y_fast, y_ref, sizeof y_fast);
		}
		screened += fast.screened;
		lost += !fast.screened;
	}
	print_message("%d samples: %d screened, %d lose contact, fast = reference bit for bit\n", n, screened, lost);
	/* both kinds of sample were drawn */
	assert_true(screened > 0 && lost > 0);
	prsm_vib_model_free(m);
}

/* §8.6 lyapunov_max of a screened sample against an independent computation: with k_d = k_s the
 * mesh stiffness is constant, the linear system time-invariant and its Floquet exponents the real
 * parts of its eigenvalues, which prsm_vib_linearise gets otherwise (second-order form in the
 * generalised coordinates, every roller on its own, GSL's nonsymmetric eigensolver); the largest
 * real part of the eigenvalues that are not the rigid carrier angle must match the screen's
 * exponent (squaring the grouped monodromy, and the 2 x 2 monodromy of each group's antisymmetric
 * motion). Both take the friction Jacobian by central differences with relative steps near 1e-7,
 * whose rounding (eps / 1e-7, some 2e-9 of each entry) bounds the agreement: 1e-6 of the
 * exponent. Then with k_d = 2 k_s, where no eigenvalue problem gives it: the exponent is
 * negative (the linear sample is stable) and the same for 1 and 2 groups' worth of work,
 * i.e. reproducible, and an unscreened sample has none. */
static void test_lyapunov(void **state)
{
	(void)state;
	/* zeta_a = zeta_g, where the axial mode has the largest exponent, and a heavily damped axial
	 * branch (zeta_a 0.9), where the gear branch's Floquet exponents decide */
	const double zetas[6] = {0.02, 0.05, 0.08, 0.02, 0.05, 0.08};
	for (int q = 0; q < 6; q++) {
		prsm_vib_model *m = model_ratio(7000.0, 1.0);
		apply(m, 0.0, zetas[q]);
		if (q >= 3) {
			prsm_vib_mc_sample s;
			prsm_vib_mc_sample_init(&s);
			s.axial_damping_ratio = 0.9;
			prsm_error e2 = PRSM_ERROR_INIT;
			assert_int_equal(prsm_vib_mc_apply(m, &s, &e2), 0);
		}
		prsm_vib_mc_options o;
		prsm_vib_mc_options_init(&o);
		o.lyapunov_windows = 1;
		prsm_vib_mc_out r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), 0);
		assert_int_equal(r.screened, 1);
		prsm_vib_linear l;
		assert_int_equal(prsm_vib_linearise(&l, m, &err), 0);
		/* the axial pair: the two eigenvalues nearest -zeta_a omega_a -+ i omega_a sqrt(1 - zeta_a^2) */
		const prsm_vib_params *P = prsm_vib_model_params(m);
		const double za = P->axial_damping_ratio, wa = P->axial_frequency_rad_s;
		const double complex la = -za * wa + I * wa * sqrt(1.0 - za * za);
		int a1 = -1, a2 = -1;
		for (int k = 0; k < l.eigenvalues; k++) {
			const double complex ev = l.eig_re[k] + I * fabs(l.eig_im[k]);
			if (a1 < 0 || cabs(ev - la) < cabs(l.eig_re[a1] + I * fabs(l.eig_im[a1]) - la)) {
				a2 = a1;
				a1 = k;
			} else if (a2 < 0 || cabs(ev - la) < cabs(l.eig_re[a2] + I * fabs(l.eig_im[a2]) - la)) {
				a2 = k;
			}
		}
		assert_close(l.eig_re[a1], -za * wa, 1e-6 * za * wa);
		assert_close(l.eig_re[a2], -za * wa, 1e-6 * za * wa);
		double best = -INFINITY, gear = -INFINITY;
		for (int k = 0; k < l.eigenvalues; k++)
			if (l.kind[k] != PRSM_VIB_EIG_RIGID) {
				best = fmax(best, l.eig_re[k]);
				if (k != a1 && k != a2)
					gear = fmax(gear, l.eig_re[k]);
			}
		print_message("zeta_a %.2f zeta_g %.2f: lyapunov_max %.10g 1/s, eigenvalues' largest real part %.10g 1/s; "
		              "gear branch %.10g against %.10g 1/s\n", za, zetas[q], r.lyapunov_max_per_s, best,
		              r.lyapunov_gear_per_s, gear);
		assert_true(isfinite(r.lyapunov_max_per_s));
		assert_close(r.lyapunov_max_per_s, best, 1e-6 * fabs(best));
		assert_close(r.lyapunov_gear_per_s, gear, 1e-6 * fabs(gear));
		prsm_vib_linear_free(&l);
		prsm_vib_model_free(m);
	}
	prsm_vib_model *m = model(7000.0);
	apply(m, 0.02, 0.05);
	prsm_vib_mc_options o;
	prsm_vib_mc_options_init(&o);
	prsm_vib_mc_out r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), 0);
	assert_true(isnan(r.lyapunov_max_per_s)); /* not asked */
	o.lyapunov_windows = 1;
	assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), 0);
	print_message("k_d = 2 k_s: lyapunov_max %.10g 1/s\n", r.lyapunov_max_per_s);
	assert_int_equal(r.screened, 1);
	assert_true(r.lyapunov_max_per_s < 0.0);
	/* the same sample integrated (from the closed form's state) with Benettin's estimate over N
	 * windows: its error is the log of the generic start vector's share of the dominant mode and of
	 * that mode's conditioning over N windows, a few units / (N T_w): 3 / (N T_w) */
	{
		prsm_vib_mc_options oi = o;
		oi.force_integration = 1;
		oi.lyapunov_windows = 6;
		prsm_vib_mc_out ri;
		assert_int_equal(prsm_vib_mc_eval(&ri, m, &oi, NULL, &err), 0);
		const double tol = 3.0 / (oi.lyapunov_windows * ri.window_s);
		print_message("integrated, Benettin over %d windows of %.4g s: %.8g 1/s (closed form %.8g, tolerance %.3g)\n",
		              oi.lyapunov_windows, ri.window_s, ri.lyapunov_max_per_s, r.lyapunov_max_per_s, tol);
		assert_int_equal(ri.integrated, 1);
		assert_close(ri.lyapunov_max_per_s, r.lyapunov_max_per_s, tol);
	}
	apply(m, 30.0, 0.05);
	assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), 0);
	assert_int_equal(r.screened, 0);
	assert_true(isnan(r.lyapunov_max_per_s));
	prsm_vib_model_free(m);
}

/* prsm_vib_mc_apply refuses values out of range */
static void test_apply_refusals(void **state)
{
	(void)state;
	prsm_vib_model *m = model(7000.0);
	prsm_error err = PRSM_ERROR_INIT;
	prsm_vib_mc_sample s;
	prsm_vib_mc_sample_init(&s);
	s.mesh_error_m = -1e-6;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), PRSM_EINVAL);
	prsm_vib_mc_sample_init(&s);
	s.axial_half_play_m = 0.0;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), PRSM_EINVAL);
	prsm_vib_mc_sample_init(&s);
	s.mesh_damping_ratio = 1.0;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), PRSM_EINVAL);
	prsm_vib_mc_sample_init(&s);
	s.axial_damping_ratio = -0.01;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), PRSM_EINVAL);
	prsm_vib_mc_sample_init(&s);
	s.window_rev = 0.0;
	assert_int_equal(prsm_vib_mc_apply(m, &s, &err), PRSM_EINVAL);
	/* the screen needs the window set by apply */
	prsm_vib_mc_options o;
	prsm_vib_mc_options_init(&o);
	prsm_vib_mc_out r;
	assert_int_equal(prsm_vib_mc_screen(&r, NULL, m, &o, &err), PRSM_EINVAL);
	prsm_vib_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_screened_equals_integrated),
		cmocka_unit_test(test_contact_loss_integrated),
		cmocka_unit_test(test_axial_single_line),
		cmocka_unit_test(test_apply_refusals),
		cmocka_unit_test(test_fast_equals_reference),
		cmocka_unit_test(test_lyapunov),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
