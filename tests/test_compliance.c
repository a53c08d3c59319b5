/*
 * test_compliance.c: docs/model/kinematics-efficiency-stiffness-life.md thread compliance — Yamamoto's five terms against values
 * computed independently (30-digit mpmath transcription of the formulas as printed in
 * compliance.h after Yamamoto 1980 / Zhang et al. 2016), the tooth shapes of a design against
 * a brute-force scan of the docs/model/geometry-and-meshing.md flank functions, scaling with E, width and
 * calibration, the `none` rule, the negative-term flags of 45-degree flanks, and the stretch
 * compliance P/(E A).
 */
#include "test_support.h"

#include "model/compliance.h"

#include <string.h>

#define REL(x, e) (fabs(e) * (x))

/* A high-entropy straight-flank tooth: P 2.385, b 1.0731, c 0.6127, E 203500, nu 0.287. */
static prsm_thread_tooth entropy_tooth(double beta_deg, double d_mm, int internal, double Do_mm)
{
	prsm_thread_tooth t;
	memset(&t, 0, sizeof t);
	t.pitch_mm = 2.385;
	t.flank_angle_rad = beta_deg * DEG;
	t.load_thickness_mm = 1.0731;
	t.load_height_mm = 0.6127;
	t.root_thickness_mm = 1.0731 + 2.0 * 0.6127 * tan(beta_deg * DEG);
	t.diameter_mm = d_mm;
	t.internal = internal;
	t.outer_diameter_mm = Do_mm;
	t.E_MPa = 203500.0;
	t.poisson = 0.287;
	return t;
}

/* beta 27.7 deg: every term positive. Reference values: mpmath, 30 digits. */
static void test_terms_against_independent_values(void **state)
{
	(void)state;
	prsm_thread_tooth t = entropy_tooth(27.7, 23.71, 0, 0.0);
	prsm_yamamoto y;
	prsm_error err = PRSM_ERROR_INIT;
	assert_close(t.root_thickness_mm, 1.7164493829883809, 1e-14);
	assert_int_equal(prsm_compliance_yamamoto(&y, &t, PRSM_YAMAMOTO_CLAMP, &err), 0);
	assert_close(y.bending, 2.4715067446101685e-7, REL(1e-11, 2.47e-7));
	assert_close(y.shear, 6.7897322632205606e-6, REL(1e-11, 6.79e-6));
	assert_close(y.root_tilt, 1.1856469995987435e-6, REL(1e-11, 1.19e-6));
	assert_close(y.root_shear, 5.7402359708344553e-6, REL(1e-11, 5.74e-6));
	assert_close(y.radial, 4.8003877277469414e-6, REL(1e-11, 4.80e-6));
	assert_int_equal(y.negative_terms, 0);
	assert_int_equal(y.clamped, 0);
	assert_close(y.sum_mm2_per_N, y.bending + y.shear + y.root_tilt + y.root_shear + y.radial, 1e-20);

	/* the same tooth as a nut thread (d 31.37, D_o 41.9): Lame ring in the radial term */
	t = entropy_tooth(27.7, 31.37, 1, 41.9);
	assert_int_equal(prsm_compliance_yamamoto(&y, &t, PRSM_YAMAMOTO_CLAMP, &err), 0);
	assert_close(y.radial, 3.4187767504049594e-5, REL(1e-11, 3.42e-5));
}

/* beta 41.3 deg: the bending term is negative (the pathology of steep flanks). */
static void test_negative_bending_flagged(void **state)
{
	(void)state;
	prsm_thread_tooth t = entropy_tooth(41.3, 23.71, 0, 0.0);
	prsm_yamamoto clamp, keep;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_compliance_yamamoto(&clamp, &t, PRSM_YAMAMOTO_CLAMP, &err), 0);
	assert_int_equal(prsm_compliance_yamamoto(&keep, &t, PRSM_YAMAMOTO_KEEP, &err), 0);
	assert_close(clamp.bending, -2.8166824202205844e-7, REL(1e-11, 2.82e-7));
	assert_close(clamp.shear, 6.0016521837789495e-6, REL(1e-11, 6.0e-6));
	assert_close(clamp.root_tilt, 3.2276288992803028e-7, REL(1e-11, 3.2e-7));
	assert_close(clamp.root_shear, 5.0549915234637488e-6, REL(1e-11, 5.05e-6));
	assert_close(clamp.radial, 1.3441354848492536e-5, REL(1e-11, 1.34e-5));
	assert_int_equal(clamp.negative_terms, PRSM_YAMAMOTO_BENDING);
	assert_int_equal(keep.negative_terms, PRSM_YAMAMOTO_BENDING);
	assert_int_equal(clamp.clamped, 1);
	assert_int_equal(keep.clamped, 0);
	const double others = clamp.shear + clamp.root_tilt + clamp.root_shear + clamp.radial;
	assert_close(clamp.sum_mm2_per_N, others, 1e-20);
	assert_close(keep.sum_mm2_per_N, others + clamp.bending, 1e-20);
	assert_true(keep.sum_mm2_per_N < clamp.sum_mm2_per_N);
}

/* Lame ring factor: for a thin nut wall the radial term grows, for D_o -> infinity the ring
 * factor tends to 1 + nu (an infinite body with a hole). */
static void test_nut_radial_limits(void **state)
{
	(void)state;
	prsm_yamamoto thick, solid;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_thread_tooth t = entropy_tooth(33.3, 31.37, 1, 31.37 * 1e4);
	prsm_thread_tooth s = entropy_tooth(33.3, 31.37, 0, 0.0);
	assert_int_equal(prsm_compliance_yamamoto(&thick, &t, PRSM_YAMAMOTO_CLAMP, &err), 0);
	assert_int_equal(prsm_compliance_yamamoto(&solid, &s, PRSM_YAMAMOTO_CLAMP, &err), 0);
	/* ratio of ring factors: (1 + nu)/(1 - nu) up to the 1e-8 of (D^2+d^2)/(D^2-d^2) - 1 */
	assert_close(thick.radial / solid.radial, (1.0 + 0.287) / (1.0 - 0.287), 1e-7);
	/* the other terms do not depend on the body */
	assert_close(thick.bending, solid.bending, 1e-20);
	assert_close(thick.root_shear, solid.root_shear, 1e-20);
	prsm_yamamoto thin;
	t.outer_diameter_mm = 1.1 * 31.37;
	assert_int_equal(prsm_compliance_yamamoto(&thin, &t, PRSM_YAMAMOTO_CLAMP, &err), 0);
	assert_true(thin.radial > 5.0 * thick.radial);
}

/* Roller tooth thickness by brute force from docs/model/geometry-and-meshing.md's flank functions: the roller tooth
 * at radius u spans P - 2 Z_r(u) axially, Z_r = z_c - sqrt(R^2 - u^2), z_c = P/4 + sqrt(R^2 -
 * r_r^2). Scan u down from r_r until the groove closes (thickness P) or the root is reached. */
static void roller_tooth_brute(const prsm_design *d, double *a, double *c)
{
	const double P = d->pitch_mm, R = d->roller_arc_radius_mm, rr = d->roller_radius_mm;
	const double zc = 0.25 * P + sqrt(R * R - rr * rr);
	const double t = d->flank_shift_roller_mm;
	double u = rr, th = 0.0;
	const double h = 1e-7;
	for (; u > d->roller_root_radius_mm; u -= h) {
		th = P - 2.0 * (zc - sqrt(R * R - u * u)) - 2.0 * t;
		if (th >= P)
			break;
	}
	*a = fmin(th, P);
	*c = rr - fmax(u, d->roller_root_radius_mm);
}

static void test_case_a_tooth_shapes(void **state)
{
	(void)state;
	prsm_design d;
	prsm_thread_tooth t;
	prsm_error err = PRSM_ERROR_INIT;
	case_a(&d);
	/* screw: b = P/2 = 1, the 45-degree groove closes 0.5 mm below the pitch line, before the
	 * root radius (0.6 mm): c = 0.5, a = P = 2 */
	assert_int_equal(prsm_compliance_tooth(&t, &d, PRSM_THREAD_SCREW, NAN, &err), 0);
	assert_close(t.load_thickness_mm, 1.0, 1e-15);
	assert_close(t.load_height_mm, 0.5, 1e-15);
	assert_close(t.root_thickness_mm, 2.0, 1e-15);
	assert_close(t.diameter_mm, 19.5, 1e-15);
	assert_int_equal(t.internal, 0);
	assert_int_equal(prsm_compliance_tooth(&t, &d, PRSM_THREAD_NUT, 21.7, &err), 0);
	assert_close(t.load_height_mm, 0.5, 1e-15);
	assert_close(t.root_thickness_mm, 2.0, 1e-15);
	assert_close(t.outer_diameter_mm, 43.4, 1e-15);
	assert_int_equal(t.internal, 1);

	/* roller, arc flank, with a high-entropy thinning and a shallower root */
	const double shifts[] = {0.0, 0.0173};
	const double roots[] = {NAN, 2.93};
	for (int i = 0; i < 2; i++) {
		case_a(&d);
		d.flank_shift_roller_mm = shifts[i];
		if (!isnan(roots[i]))
			d.roller_root_radius_mm = roots[i];
		double a, c;
		roller_tooth_brute(&d, &a, &c);
		assert_int_equal(prsm_compliance_tooth(&t, &d, PRSM_THREAD_ROLLER, NAN, &err), 0);
		assert_close(t.load_thickness_mm, 1.0 - 2.0 * shifts[i], 1e-15);
		assert_close(t.root_thickness_mm, a, 1e-6);
		assert_close(t.load_height_mm, c, 1e-6);
	}
}

/* The design-level compliances: widths by rule, sums per side, sign and flags. */
static void test_design_width_rules(void **state)
{
	(void)state;
	prsm_design d;
	prsm_design_compliance dc;
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 5, 1.85, 3.71, 43.7, 9, 11);
	prsm_compliance_options o = PRSM_COMPLIANCE_OPTIONS_INIT;
	assert_int_equal(prsm_compliance_design(&dc, &d, NULL, NULL, &err), 0);
	assert_int_equal(dc.options.width_rule, PRSM_THREAD_WIDTH_SHARE);
	assert_close(dc.nut_outer_radius_mm, 1.3 * d.nut_radius_mm, 1e-12);
	assert_close(dc.screw.width_mm, 2.0 * M_PI * d.screw_radius_mm / 9.0, 1e-12);
	assert_close(dc.nut.width_mm, 2.0 * M_PI * d.nut_radius_mm / 9.0, 1e-12);
	assert_close(dc.roller_screw_side.width_mm, M_PI * d.roller_radius_mm, 1e-12);
	assert_close(dc.screw.compliance_mm_per_N, dc.screw.terms.sum_mm2_per_N / dc.screw.width_mm, 1e-18);
	assert_close(dc.screw_side_mm_per_N,
	             dc.screw.compliance_mm_per_N + dc.roller_screw_side.compliance_mm_per_N, 1e-18);
	assert_close(dc.nut_side_mm_per_N,
	             dc.nut.compliance_mm_per_N + dc.roller_nut_side.compliance_mm_per_N, 1e-18);
	assert_true(dc.screw.compliance_mm_per_N > 0.0 && dc.nut.compliance_mm_per_N > 0.0);
	assert_true(dc.roller_screw_side.compliance_mm_per_N > 0.0);
	/* steep flanks: the bending term is negative and clamped, and says so */
	assert_true(dc.negative_terms & PRSM_YAMAMOTO_BENDING);
	assert_int_equal(dc.screw.terms.clamped, 1);

	/* fraction of the share scales the width */
	o.width_fraction = 0.37;
	prsm_design_compliance f;
	assert_int_equal(prsm_compliance_design(&f, &d, &o, NULL, &err), 0);
	assert_close(f.screw.width_mm, 0.37 * dc.screw.width_mm, 1e-12);
	assert_close(f.screw.compliance_mm_per_N, dc.screw.compliance_mm_per_N / 0.37, 1e-15);

	/* ellipse rule: w = factor x 2a per side */
	const double a_mm[2] = {0.213, 0.287};
	o = (prsm_compliance_options)PRSM_COMPLIANCE_OPTIONS_INIT;
	o.width_rule = PRSM_THREAD_WIDTH_ELLIPSE;
	o.ellipse_factor = 2.6;
	assert_int_equal(prsm_compliance_design(&f, &d, &o, a_mm, &err), 0);
	assert_close(f.screw.width_mm, 2.6 * 2.0 * 0.213, 1e-14);
	assert_close(f.roller_screw_side.width_mm, 2.6 * 2.0 * 0.213, 1e-14);
	assert_close(f.roller_nut_side.width_mm, 2.6 * 2.0 * 0.287, 1e-14);
	assert_close(f.nut.width_mm, 2.6 * 2.0 * 0.287, 1e-14);
	assert_int_equal(prsm_compliance_design(&f, &d, &o, NULL, &err), PRSM_EINVAL);

	/* a gentle flank (beta 27.3 deg): no negative term anywhere */
	standard_design(&d, 4, 2.21, 4.13, 27.3, 7, 9);
	assert_int_equal(prsm_compliance_design(&dc, &d, NULL, NULL, &err), 0);
	assert_int_equal(dc.negative_terms, 0);
	assert_int_equal(dc.screw.terms.clamped, 0);
}

/* Compliance is proportional to 1/E (every term is W/E times a shape factor at fixed nu), to
 * 1/width and to the calibration factor; `none` gives 0 with the rule echoed. */
static void test_scaling_and_none(void **state)
{
	(void)state;
	prsm_design d, d2;
	prsm_design_compliance c1, c2;
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 6, 2.57, 3.93, 39.1, 8, 13);
	d.screw_material.E_MPa = 211300.0;
	d.roller_material.E_MPa = 197700.0;
	d.nut_material.E_MPa = 203900.0;
	d2 = d;
	d2.screw_material.E_MPa *= 1.731;
	d2.roller_material.E_MPa *= 1.731;
	d2.nut_material.E_MPa *= 1.731;
	prsm_compliance_options o = PRSM_COMPLIANCE_OPTIONS_INIT;
	o.nut_outer_radius_mm = 37.3;
	assert_int_equal(prsm_compliance_design(&c1, &d, &o, NULL, &err), 0);
	assert_int_equal(prsm_compliance_design(&c2, &d2, &o, NULL, &err), 0);
	assert_close(c2.screw.compliance_mm_per_N * 1.731, c1.screw.compliance_mm_per_N, 1e-12 * c1.screw.compliance_mm_per_N);
	assert_close(c2.nut.compliance_mm_per_N * 1.731, c1.nut.compliance_mm_per_N, 1e-12 * c1.nut.compliance_mm_per_N);
	assert_close(c2.roller_nut_side.compliance_mm_per_N * 1.731, c1.roller_nut_side.compliance_mm_per_N,
	             1e-12 * c1.roller_nut_side.compliance_mm_per_N);
	assert_close(c1.nut_outer_radius_mm, 37.3, 0.0);

	/* given width: 1/w */
	o.width_rule = PRSM_THREAD_WIDTH_GIVEN;
	o.width_mm = 0.83;
	assert_int_equal(prsm_compliance_design(&c1, &d, &o, NULL, &err), 0);
	o.width_mm = 0.83 * 3.17;
	assert_int_equal(prsm_compliance_design(&c2, &d, &o, NULL, &err), 0);
	assert_close(c1.screw.compliance_mm_per_N / c2.screw.compliance_mm_per_N, 3.17, 1e-12);
	assert_close(c1.nut_side_mm_per_N / c2.nut_side_mm_per_N, 3.17, 1e-12);
	assert_close(c2.screw.width_mm, 0.83 * 3.17, 0.0);

	/* calibration factor */
	o.calibration = 1.37;
	prsm_design_compliance c3;
	assert_int_equal(prsm_compliance_design(&c3, &d, &o, NULL, &err), 0);
	assert_close(c3.screw_side_mm_per_N / c2.screw_side_mm_per_N, 1.37, 1e-12);
	assert_close(c3.screw.calibration, 1.37, 0.0);

	/* none */
	o.width_rule = PRSM_THREAD_COMPLIANCE_NONE;
	assert_int_equal(prsm_compliance_design(&c3, &d, &o, NULL, &err), 0);
	assert_int_equal(c3.options.width_rule, PRSM_THREAD_COMPLIANCE_NONE);
	assert_int_equal(c3.screw.width_rule, PRSM_THREAD_COMPLIANCE_NONE);
	assert_true(c3.screw.compliance_mm_per_N == 0.0 && c3.nut.compliance_mm_per_N == 0.0);
	assert_true(c3.screw_side_mm_per_N == 0.0 && c3.nut_side_mm_per_N == 0.0);
	assert_true(c3.screw.width_mm == 0.0);
}

/* Sign checks over a spread of flank angles and proportions: compliance positive under the
 * clamp policy, every term except bending and root tilt positive always, and the terms fall as
 * the width fraction grows. */
static void test_signs_over_designs(void **state)
{
	(void)state;
	const double betas[] = {22.9, 30.7, 37.3, 45.0, 50.3};
	for (size_t i = 0; i < sizeof betas / sizeof betas[0]; i++) {
		prsm_design d;
		prsm_design_compliance c;
		prsm_error err = PRSM_ERROR_INIT;
		standard_design(&d, 5, 1.7 + 0.11 * (double)i, 3.1 + 0.37 * (double)i, betas[i], 8, 10);
		assert_int_equal(prsm_compliance_design(&c, &d, NULL, NULL, &err), 0);
		const prsm_thread_compliance *parts[] = {&c.screw, &c.roller_screw_side, &c.nut};
		for (int k = 0; k < 3; k++) {
			const prsm_yamamoto *y = &parts[k]->terms;
			assert_true(parts[k]->compliance_mm_per_N > 0.0);
			assert_true(y->shear >= 0.0 && y->root_shear > 0.0 && y->radial > 0.0);
			assert_int_equal(y->negative_terms & ~(PRSM_YAMAMOTO_BENDING | PRSM_YAMAMOTO_ROOT_TILT), 0);
			assert_int_equal((y->bending < 0.0) != 0, (y->negative_terms & PRSM_YAMAMOTO_BENDING) != 0);
		}
	}
}

static void test_stretch(void **state)
{
	(void)state;
	prsm_design d;
	prsm_segment_compliance s;
	prsm_error err = PRSM_ERROR_INIT;
	case_a(&d);
	d.nut_material.E_MPa = 198300.0;
	assert_int_equal(prsm_compliance_segments(&s, &d, 23.9, &err), 0);
	/* screw root 9.75 - 0.6 = 9.15, roller root 3.25 - 0.6 = 2.65, nut root 16.25 + 0.6 */
	assert_close(s.screw_area_mm2, M_PI * 9.15 * 9.15, 1e-10);
	assert_close(s.screw_mm_per_N, 2.0 / (206000.0 * M_PI * 9.15 * 9.15), 1e-20);
	assert_close(s.roller_mm_per_N, 2.0 / (206000.0 * M_PI * 2.65 * 2.65), 1e-20);
	assert_close(s.nut_mm_per_N, 2.0 / (198300.0 * M_PI * (23.9 * 23.9 - 16.85 * 16.85)), 1e-20);
	assert_close(prsm_compliance_stretch(3.7, 2.0e5, 11.0), 3.7 / 2.2e6, 1e-20);
	/* default nut outer radius 1.3 r_n */
	assert_int_equal(prsm_compliance_segments(&s, &d, NAN, &err), 0);
	assert_close(s.nut_area_mm2, M_PI * (1.69 * 16.25 * 16.25 - 16.85 * 16.85), 1e-9);
	/* nut outer radius inside its root */
	assert_int_equal(prsm_compliance_segments(&s, &d, 16.0, &err), PRSM_EINVAL);
}

/* Every error path. */
static void test_errors(void **state)
{
	(void)state;
	prsm_design d;
	prsm_design_compliance c;
	prsm_thread_tooth t;
	prsm_yamamoto y;
	prsm_error err = PRSM_ERROR_INIT;
	case_a(&d);
	d.flank_shift_screw_mm = 0.6; /* thinning leaves no tooth: b = 1 - 1.2 < 0 */
	assert_int_equal(prsm_compliance_design(&c, &d, NULL, NULL, &err), PRSM_EINVAL);
	assert_true(strstr(err.message, "screw") != NULL);
	case_a(&d);
	assert_int_equal(prsm_compliance_tooth(&t, &d, 7, NAN, &err), PRSM_EINVAL);
	prsm_compliance_options o = PRSM_COMPLIANCE_OPTIONS_INIT;
	o.width_rule = 9;
	assert_int_equal(prsm_compliance_design(&c, &d, &o, NULL, &err), PRSM_EINVAL);
	o = (prsm_compliance_options)PRSM_COMPLIANCE_OPTIONS_INIT;
	o.width_rule = PRSM_THREAD_WIDTH_GIVEN;
	o.width_mm = -0.5;
	assert_int_equal(prsm_compliance_design(&c, &d, &o, NULL, &err), PRSM_EINVAL);
	o.width_mm = 1.0;
	o.calibration = NAN;
	assert_int_equal(prsm_compliance_design(&c, &d, &o, NULL, &err), PRSM_EINVAL);
	o = (prsm_compliance_options)PRSM_COMPLIANCE_OPTIONS_INIT;
	o.nut_outer_radius_mm = 15.0; /* inside the nut's pitch circle */
	assert_int_equal(prsm_compliance_design(&c, &d, &o, NULL, &err), PRSM_EINVAL);
	t = entropy_tooth(33.0, 20.0, 0, 0.0);
	t.root_thickness_mm = 0.9; /* a < b */
	assert_int_equal(prsm_compliance_yamamoto(&y, &t, PRSM_YAMAMOTO_CLAMP, &err), PRSM_EINVAL);
	t = entropy_tooth(33.0, 20.0, 0, 0.0);
	t.E_MPa = 0.0;
	assert_int_equal(prsm_compliance_yamamoto(&y, &t, PRSM_YAMAMOTO_CLAMP, &err), PRSM_EINVAL);
	t = entropy_tooth(33.0, 20.0, 0, 0.0);
	t.flank_angle_rad = M_PI / 2.0;
	assert_int_equal(prsm_compliance_yamamoto(&y, &t, PRSM_YAMAMOTO_CLAMP, &err), PRSM_EINVAL);
	d.rollers = 0;
	assert_int_equal(prsm_compliance_design(&c, &d, NULL, NULL, &err), PRSM_EINVAL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_terms_against_independent_values),
		cmocka_unit_test(test_negative_bending_flagged),
		cmocka_unit_test(test_nut_radial_limits),
		cmocka_unit_test(test_case_a_tooth_shapes),
		cmocka_unit_test(test_design_width_rules),
		cmocka_unit_test(test_scaling_and_none),
		cmocka_unit_test(test_signs_over_designs),
		cmocka_unit_test(test_stretch),
		cmocka_unit_test(test_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
