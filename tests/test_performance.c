/*
 * test_performance.c: the operating-point analysis of issue 4 through prsm_performance_compute
 * (docs/model/kinematics-efficiency-stiffness-life.md): the §5 closed form when spin, gear and drag are off; efficiency rising
 * with lead when a drag torque is given; stiffness rising with rollers, engaged threads and
 * load and falling with thread compliance; the first thread at the load entry carrying most
 * ("same side"); uniform thread loads and the equal-share Hertz results with rigid bodies;
 * C_0a reached exactly at p_allow; life = a1 (C_a/F)^3 10^6 and its cube law; the duty cycle
 * of docs/model/kinematics-efficiency-stiffness-life.md (217.66 lbf) and the preload derating through the design; the column limits;
 * the load-deflection curve against the stiffness at the operating load.
 */
#include "test_support.h"

#include "model/analysis.h"
#include "io/global.h"
#include "model/loaddist.h"
#include "model/performance.h"

#include <string.h>

#include <gsl/gsl_errno.h>

#define LBF_N 4.4482216152605 /* N per lbf */

/* Case A at load F (N) and 100 rad/s, nominal analysis, thinning for 20 um of play. */
static void case_a_at(prsm_design *d, prsm_analysis *a, double F)
{
	case_a(d);
	d->target_axial_clearance_mm = 0.02;
	d->axial_load_N = F;
	d->screw_speed_rad_s = 100.0;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(a, d, &w, &err), 0);
}

static void compute(prsm_performance *p, prsm_design *d, prsm_analysis *a)
{
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(a, d, &w, &err), 0);
	int rc = prsm_performance_compute(p, d, a, &err);
	if (rc)
		fail_msg("performance: %s", err.message);
}

static double stiffness_of(prsm_design *d)
{
	prsm_analysis a;
	prsm_performance p;
	compute(&p, d, &a);
	const double k = p.stiffness_N_per_um;
	prsm_performance_free(&p);
	return k;
}

static void test_efficiency(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_performance p;
	case_a_at(&d, &a, 7385.0);
	/* spin, gear, drag off: the sliding efficiency, within 0.001 of the §5 closed form */
	d.losses.spin = d.losses.gear_mesh = 0;
	compute(&p, &d, &a);
	assert_close(p.losses.eta, a.efficiency.eta, 1e-12);
	assert_close(p.losses.eta, tan(M_PI / 4) / tan(M_PI / 4 + atan(0.05)), 1e-3);
	assert_close(p.losses.eta, 0.9048, 1e-3);
	prsm_performance_free(&p);
	/* every loss on: lower, and the torque split adds up */
	case_a_at(&d, &a, 7385.0);
	d.losses.drag_torque_Nm = 0.237;
	d.losses.seal_torque_Nm = 0.0913;
	compute(&p, &d, &a);
	const prsm_losses_result *l = &p.losses;
	assert_true(l->eta < a.efficiency.eta - 0.005);
	assert_close(l->input_torque_Nm, l->ideal_torque_Nm + l->sliding_torque_Nm + l->spin_torque_Nm +
	                                     l->gear_torque_Nm + l->drag_torque_Nm + l->seal_torque_Nm, 1e-12);
	assert_close(l->eta, l->ideal_torque_Nm / l->input_torque_Nm, 1e-12);
	const double eta_5 = l->eta;
	prsm_performance_free(&p);
	/* a longer lead with the same drag raises eta (pitch 2.4 mm: lead 12 mm, same radii) */
	prsm_design d5b = d;
	d5b.pitch_mm = 2.4; /* same starts, longer pitch: lead 12 mm */
	prsm_problems e;
	prsm_problems_init(&e);
	d5b.screw_crest_radius_mm = d5b.screw_root_radius_mm = NAN;
	d5b.roller_crest_radius_mm = d5b.roller_root_radius_mm = NAN;
	d5b.nut_crest_radius_mm = d5b.nut_root_radius_mm = NAN;
	d5b.roller_arc_radius_mm = NAN;
	assert_int_equal(prsm_design_resolve(&d5b, &e), 0);
	compute(&p, &d5b, &a);
	assert_true(p.losses.eta > eta_5);
	prsm_performance_free(&p);
	/* and a higher load raises it too (drag and seal are load-independent) */
	d.axial_load_N = 2.0 * 7385.0;
	compute(&p, &d, &a);
	assert_true(p.losses.eta > eta_5);
	prsm_performance_free(&p);
}

static void test_stiffness_trends(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	case_a_at(&d, &a, 6123.0);
	const double k0 = stiffness_of(&d);
	assert_true(k0 > 100.0 && k0 < 5000.0); /* N/um: the order of catalogue roller screws */
	prsm_design x = d;
	x.rollers = 7;
	assert_true(stiffness_of(&x) < k0);
	x = d;
	x.engaged_threads = 14;
	assert_true(stiffness_of(&x) > k0);
	x = d;
	x.engaged_threads = 6;
	assert_true(stiffness_of(&x) < k0);
	x = d;
	x.axial_load_N = 2.0 * 6123.0;
	assert_true(stiffness_of(&x) > k0);
	x = d;
	x.stiffness.calibration = 2.5;
	assert_true(stiffness_of(&x) < k0);
	x = d;
	x.stiffness.width_rule = PRSM_THREAD_COMPLIANCE_NONE;
	assert_true(stiffness_of(&x) > k0);
}

static void test_distribution(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_performance p;
	case_a_at(&d, &a, 8761.0);
	compute(&p, &d, &a);
	/* same side: thread 1 at the load entry carries the most, and loads fall away from it */
	for (int i = 1; i < p.threads; i++)
		assert_true(p.thread_load_screw_N[i] < p.thread_load_screw_N[i - 1]);
	assert_int_equal(p.dist.side[PRSM_SIDE_SCREW].max_index, 0);
	double sum = 0.0;
	for (int i = 0; i < p.threads; i++)
		sum += p.thread_load_screw_N[i];
	assert_close(sum, 8761.0 / d.rollers, 1e-9 * sum);
	const double same = p.dist.side[PRSM_SIDE_SCREW].max_over_mean;
	prsm_performance_free(&p);
	d.stiffness.load_entry = PRSM_ENTRY_OPPOSITE_SIDE;
	compute(&p, &d, &a);
	assert_true(p.dist.side[PRSM_SIDE_SCREW].max_over_mean < same);
	prsm_performance_free(&p);

	/* rigid bodies: uniform loads and the equal-share Hertz of the nominal analysis */
	prsm_loaddist_params lp;
	prsm_design_compliance tc;
	prsm_segment_compliance seg;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_compliance_design(&tc, &d, NULL, NULL, &err), 0);
	assert_int_equal(prsm_compliance_segments(&seg, &d, NAN, &err), 0);
	seg.screw_mm_per_N = seg.roller_mm_per_N = seg.nut_mm_per_N = 0.0;
	assert_int_equal(prsm_loaddist_params_from_design(&lp, &d, &a.screw, &a.nut, &tc, &seg,
	                                                  PRSM_LOAD_ENTRY_SAME, &err), 0);
	prsm_loaddist_workspace *ws = prsm_loaddist_alloc(d.engaged_threads);
	prsm_loaddist_result r;
	assert_int_equal(prsm_loaddist_solve(&r, ws, &lp, 8761.0, &err), 0);
	for (int i = 0; i < d.engaged_threads; i++)
		assert_close(r.axial_screw_N[i], 8761.0 / (d.rollers * d.engaged_threads), 1e-9);
	assert_close(r.side[PRSM_SIDE_SCREW].p_max_MPa, a.hertz_screw.p_max_MPa, 1e-6 * a.hertz_screw.p_max_MPa);
	assert_close(r.side[PRSM_SIDE_NUT].p_max_MPa, a.hertz_nut.p_max_MPa, 1e-6 * a.hertz_nut.p_max_MPa);
	assert_close(r.side[PRSM_SIDE_SCREW].a_mm, a.hertz_screw.a_mm, 1e-9);
	prsm_loaddist_free(ws);
}

static void test_capacity_and_life(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_performance p, q;
	case_a_at(&d, &a, 7013.0);
	compute(&p, &d, &a);
	/* C_0a: the most loaded contact of the weaker side is at p_allow exactly */
	prsm_loaddist_params lp;
	prsm_design_compliance tc;
	prsm_segment_compliance seg;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_compliance_design(&tc, &d, NULL, NULL, &err), 0);
	assert_int_equal(prsm_compliance_segments(&seg, &d, NAN, &err), 0);
	assert_int_equal(prsm_loaddist_params_from_design(&lp, &d, &a.screw, &a.nut, &tc, &seg,
	                                                  PRSM_LOAD_ENTRY_SAME, &err), 0);
	prsm_loaddist_workspace *ws = prsm_loaddist_alloc(d.engaged_threads);
	prsm_loaddist_result r;
	assert_int_equal(prsm_loaddist_solve(&r, ws, &lp, p.C0a_N, &err), 0);
	const double pm = fmax(r.side[0].p_max_MPa, r.side[1].p_max_MPa);
	assert_close(pm, 4200.0, 1e-6 * 4200.0);
	prsm_loaddist_free(ws);
	/* below the equal-sharing figure: the distribution costs capacity */
	assert_true(p.C0a_N < fmin(p.static_screw.C0a_N, p.static_nut.C0a_N));
	assert_close(p.static_safety, p.C0a_N / 7013.0, 1e-12);
	/* C_a about the L-P figure of case A (38.3 kN with equal rows), derated by the distribution */
	assert_true(p.distribution_factor < 1.0 && p.distribution_factor > 0.95);
	assert_close(p.dynamic.C_a_N / p.distribution_factor, 38.3e3, 0.1e3);
	/* L10 = (C_a / F)^3 10^6, hours at 100 rad/s, km with the 10 mm lead */
	const double L = pow(p.dynamic.C_a_N / 7013.0, 3.0) * 1e6;
	assert_close(p.life.revolutions, L, 1e-9 * L);
	assert_close(p.life.hours, L / (100.0 * 60.0 / (2.0 * M_PI)) / 60.0, 1e-9 * p.life.hours);
	assert_close(p.life.distance_km, L * 10.0 * 1e-6, 1e-9 * p.life.distance_km);
	/* the cube law between two loads, the capacity's own change accounted for */
	d.axial_load_N = 2.0 * 7013.0;
	compute(&q, &d, &a);
	const double ratio = pow(q.dynamic.C_a_N / p.dynamic.C_a_N, 3.0) / 8.0;
	assert_close(q.life.revolutions / p.life.revolutions, ratio, 1e-9);
	prsm_performance_free(&q);
	/* reliability 95 %: a1 = 0.62 */
	d.axial_load_N = 7013.0;
	d.life.reliability_percent = 95;
	compute(&q, &d, &a);
	assert_close(q.life.revolutions / p.life.revolutions, 0.62, 1e-12);
	prsm_performance_free(&q);
	/* the duty cycle of docs/model/kinematics-efficiency-stiffness-life.md: 500, 100, 250, 50 lbf over 0.5, 2.9, 1.0, 3.5 in */
	d.life.reliability_percent = 90;
	d.life.duty_steps = 4;
	const double lbf[] = {500.0, 100.0, 250.0, 50.0}, in[] = {0.5, 2.9, 1.0, 3.5};
	for (int i = 0; i < 4; i++) {
		d.life.duty_load_N[i] = lbf[i] * LBF_N;
		d.life.duty_travel_mm[i] = in[i] * 25.4;
	}
	compute(&q, &d, &a);
	assert_close(q.mean_load_N / LBF_N, 217.659125976855, 1e-9);
	assert_close(q.life.revolutions, pow(q.dynamic.C_a_N / q.mean_load_N, 3.0) * 1e6, 1e-9 * q.life.revolutions);
	prsm_performance_free(&q);
	/* a preload raises the equivalent load; beyond 2^1.5 F_pr it no longer matters */
	d.life.duty_steps = 0;
	d.life.preload_N = 1234.5;
	compute(&q, &d, &a);
	assert_close(q.equivalent_load_N, 7013.0, 1e-9); /* 7013 > 2^1.5 x 1234.5 */
	prsm_performance_free(&q);
	d.life.preload_N = 4321.0;
	compute(&q, &d, &a);
	assert_true(q.equivalent_load_N > 7013.0);
	assert_true(q.life.revolutions < p.life.revolutions);
	prsm_performance_free(&q);
	/* column limits when given */
	d.life.preload_N = 0.0;
	d.life.column = 1;
	d.life.free_length_mm = 812.5;
	d.life.fixity = PRSM_FIXITY_FIXED_SUPPORTED;
	compute(&q, &d, &a);
	assert_true(q.has_column);
	const double dr = 2.0 * d.screw_root_radius_mm, I = M_PI * pow(dr, 4) / 64.0;
	assert_close(q.column.buckling_load_N, 2.0457 * M_PI * M_PI * 206000.0 * I / (812.5 * 812.5),
	             1e-3 * q.column.buckling_load_N);
	prsm_performance_free(&q);
	prsm_performance_free(&p);
}

static void test_curve(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_performance p, q;
	case_a_at(&d, &a, 5000.0);
	d.stiffness.curve_points = 8;
	d.stiffness.curve_max_load_N = 40000.0;
	compute(&p, &d, &a);
	assert_int_equal(p.curve_points, 8);
	/* the point at 5 kN is the operating point's stiffness and approach */
	assert_close(p.curve_load_N[0], 5000.0, 1e-9);
	assert_close(p.curve_stiffness_N_per_um[0], p.stiffness_N_per_um, 1e-9 * p.stiffness_N_per_um);
	assert_close(p.curve_approach_um[0], p.dist.approach_mm * 1e3, 1e-9);
	/* monotone, stiffening; the slope between points brackets the tangents */
	for (int i = 1; i < 8; i++) {
		assert_true(p.curve_approach_um[i] > p.curve_approach_um[i - 1]);
		assert_true(p.curve_stiffness_N_per_um[i] > p.curve_stiffness_N_per_um[i - 1]);
		const double secant = (p.curve_load_N[i] - p.curve_load_N[i - 1]) /
		                      (p.curve_approach_um[i] - p.curve_approach_um[i - 1]);
		assert_true(secant > p.curve_stiffness_N_per_um[i - 1] && secant < p.curve_stiffness_N_per_um[i]);
	}
	/* no load: no stiffness, infinite life, the curve up to C_0a */
	d.axial_load_N = 0.0;
	d.stiffness.curve_max_load_N = NAN;
	compute(&q, &d, &a);
	assert_true(q.stiffness_N_per_um == 0.0);
	assert_true(isinf(q.life.revolutions));
	assert_close(q.curve_load_N[7], q.C0a_N, 1e-9 * q.C0a_N);
	prsm_performance_free(&q);
	prsm_performance_free(&p);
}

static void test_errors(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_performance p;
	prsm_error err = PRSM_ERROR_INIT;
	case_a_at(&d, &a, 0.0);
	d.stiffness.width_rule = PRSM_THREAD_WIDTH_ELLIPSE; /* needs a load to size the ellipse */
	assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.pointer, "/stiffness"));
	prsm_performance_free(&p);
	case_a_at(&d, &a, 1000.0);
	d.flank_shift_screw_mm = 0.6; /* the screw tooth thinned away */
	assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/thinning/screw_um");
	prsm_performance_free(&p);
	/* the input torque for the chain: NaN when the analysis cannot be done */
	assert_true(isnan(prsm_performance_input_torque(&d, &a)));
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_efficiency),
		cmocka_unit_test(test_stiffness_trends),
		cmocka_unit_test(test_distribution),
		cmocka_unit_test(test_capacity_and_life),
		cmocka_unit_test(test_curve),
		cmocka_unit_test(test_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
