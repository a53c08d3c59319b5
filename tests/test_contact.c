/*
 * test_contact.c: docs/model/geometry-and-meshing.md — contact points, gaps, normals, curvatures, the Newton solver
 * against a brute-force minimum and finite differences, the offset rule, thinning.
 */
#include "test_support.h"

#include "model/analysis.h"
#include "model/contact.h"

#include <string.h>

static void test_case_a_screw_contact(void **state)
{
	(void)state;
	prsm_design d;
	prsm_flank_pair p;
	prsm_contact c;
	case_a(&d);
	prsm_flank_pair_nominal(&p, &d, PRSM_SIDE_SCREW);
	assert_int_equal(prsm_contact_solve(&c, &p), 0);
	assert_close(c.x_mm, 9.79727, 1e-4);
	assert_close(c.y_mm, 0.62678, 1e-4);
	assert_close(c.body_angle_rad / DEG, 3.6605, 1e-3);
	assert_close(c.roller_angle_rad / DEG, -11.0730, 1e-3);
	assert_close(c.gap_mm * 1e3, -82.36, 0.01);
	assert_close(c.normal[0], 0.70251, 1e-4);
	assert_close(c.normal[1], -0.11389, 1e-4);
	assert_close(c.normal[2], 0.70251, 1e-4);
	assert_true(c.iterations <= 6);
	assert_int_equal(c.edge, 0);
}

static void test_case_a_nut_contact_conjugate(void **state)
{
	(void)state;
	prsm_design d;
	prsm_flank_pair p;
	prsm_contact c;
	case_a(&d);
	prsm_flank_pair_nominal(&p, &d, PRSM_SIDE_NUT);
	assert_int_equal(prsm_contact_solve(&c, &p), 0);
	assert_close(c.x_mm, 16.25, 1e-10);
	assert_close(c.y_mm, 0.0, 1e-10);
	assert_close(c.gap_mm, 0.0, 1e-12);
	assert_true(c.iterations <= 6);
}

/* The Newton contact equals the minimum of G over a fine grid around it (independent of the
 * analytic derivatives). Done for several designs, both hands and both sides. */
static void test_newton_equals_grid_minimum(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.5, 2.71, 40.0}, {6, 3.0, 6.0, 52.5}};
	for (size_t i = 0; i < 3; i++) {
		for (int hand = -1; hand <= 1; hand += 2) {
			for (int side = 0; side < 2; side++) {
				prsm_design d;
				prsm_flank_pair p;
				prsm_contact c;
				standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 3, 5);
				d.hand = hand;
				prsm_flank_pair_nominal(&p, &d, side);
				assert_int_equal(prsm_contact_solve(&c, &p), 0);
				/* coarse-to-fine grid search for the minimum of G */
				double bx = c.x_mm + 0.013, by = c.y_mm - 0.021, h = 0.05;
				double best = prsm_contact_gap(&p, bx, by);
				for (int level = 0; level < 9; level++) {
					double cx = bx, cy = by;
					for (int ix = -20; ix <= 20; ix++)
						for (int iy = -20; iy <= 20; iy++) {
							double x = cx + ix * h, y = cy + iy * h;
							double g = prsm_contact_gap(&p, x, y);
							if (g < best) {
								best = g;
								bx = x;
								by = y;
							}
						}
					h /= 8.0;
				}
				assert_close(bx, c.x_mm, 1e-6);
				assert_close(by, c.y_mm, 1e-6);
				assert_close(best, c.gap_mm, 1e-12);
			}
		}
	}
}

/* Analytic gradient and Hessian against central differences at scattered points. */
static void test_derivatives_finite_difference(void **state)
{
	(void)state;
	prsm_design d;
	standard_design(&d, 4, 1.73, 2.917, 41.3, 4, 6);
	d.hand = PRSM_HAND_LEFT;
	for (int side = 0; side < 2; side++) {
		prsm_flank_pair p;
		prsm_flank_pair_nominal(&p, &d, side);
		p.body_x_mm = 0.0173;
		p.roller_y_mm = -0.0291;
		double x0, y0;
		prsm_contact_start(&p, &x0, &y0);
		for (int k = 0; k < 7; k++) {
			double x = x0 + 0.031 * sin(1.3 * k), y = y0 + 0.047 * cos(2.1 * k), g[2], hs[3];
			prsm_contact_gap_derivatives(&p, x, y, g, hs);
			const double e = 1e-5;
			double gx = (prsm_contact_gap(&p, x + e, y) - prsm_contact_gap(&p, x - e, y)) / (2 * e);
			double gy = (prsm_contact_gap(&p, x, y + e) - prsm_contact_gap(&p, x, y - e)) / (2 * e);
			assert_close(g[0], gx, 1e-8);
			assert_close(g[1], gy, 1e-8);
			double gp[2], gm[2];
			prsm_contact_gap_derivatives(&p, x + e, y, gp, NULL);
			prsm_contact_gap_derivatives(&p, x - e, y, gm, NULL);
			assert_close(hs[0], (gp[0] - gm[0]) / (2 * e), 1e-6);
			assert_close(hs[1], (gp[1] - gm[1]) / (2 * e), 1e-6);
			prsm_contact_gap_derivatives(&p, x, y + e, gp, NULL);
			prsm_contact_gap_derivatives(&p, x, y - e, gm, NULL);
			assert_close(hs[2], (gp[1] - gm[1]) / (2 * e), 1e-6);
		}
	}
}

/* Relative principal curvatures: extremes over directions of the relative normal curvature
 * H(d,d) / (|grad Z| factor * I(d,d)), computed here by sweeping directions. The simple
 * estimate of docs/model/geometry-and-meshing.md agrees on the sum within a few per cent. */
static void test_curvatures(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_problems w;
	case_a(&d);
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(&a, &d, &w, NULL), 0);
	for (int side = 0; side < 2; side++) {
		const prsm_contact *c = side ? &a.nut : &a.screw;
		const double *est = side ? a.curvature_estimate_nut : a.curvature_estimate_screw;
		prsm_flank_pair p;
		prsm_flank_pair_nominal(&p, &d, side);
		double g[2], h[3];
		prsm_contact_gap_derivatives(&p, c->x_mm, c->y_mm, g, h);
		/* body flank slope from the normal: n = (-Zx, -Zy, 1)/norm in the radial frame */
		double th = atan2(c->y_mm, c->x_mm), nr = c->normal[0], nt = c->normal[1], nz = c->normal[2];
		double zx = -(nr * cos(th) - nt * sin(th)) / nz, zy = -(nr * sin(th) + nt * cos(th)) / nz;
		double kmin = INFINITY, kmax = -INFINITY;
		for (int i = 0; i < 20000; i++) {
			double t = M_PI * i / 20000.0, dx = cos(t), dy = sin(t);
			double hdd = h[0] * dx * dx + 2 * h[1] * dx * dy + h[2] * dy * dy;
			double idd = dx * dx + dy * dy + (zx * dx + zy * dy) * (zx * dx + zy * dy);
			double k = hdd / idd * nz;
			kmin = fmin(kmin, k);
			kmax = fmax(kmax, k);
		}
		assert_close(c->curvature_per_mm[0], kmin, 1e-7);
		assert_close(c->curvature_per_mm[1], kmax, 1e-7);
		double sum = c->curvature_per_mm[0] + c->curvature_per_mm[1];
		assert_close(sum, est[0] + est[1], 0.03 * (est[0] + est[1]));
	}
}

/* docs/model/geometry-and-meshing.md: y_c ~ P cot(beta) / pi within 4 % over n = 3..8 and beta = 30..60 deg. The rule is
 * the quadratic approximation of G, so its error grows like (P / r_r)^2: at case A's
 * P / r_r = 0.62 it is 8 % for n = 3, beta = 30 deg (a coarse pitch on a 3-start screw); the test
 * uses P / r_r = 0.29 and checks that scaling on the worst corner as well. */
static void test_offset_rule(void **state)
{
	(void)state;
	for (int n = 3; n <= 8; n++) {
		for (double beta = 30.0; beta <= 60.0 + 1e-9; beta += 5.0) {
			prsm_design d;
			prsm_flank_pair p;
			prsm_contact c;
			standard_design(&d, n, 1.2, 4.13, beta, 3, 5);
			prsm_flank_pair_nominal(&p, &d, PRSM_SIDE_SCREW);
			int rc = prsm_contact_solve(&c, &p);
			assert_true(rc == 0 || rc == PRSM_EEDGE);
			double rule = d.pitch_mm / (M_PI * tan(beta * DEG));
			assert_close(c.y_mm, rule, 0.04 * rule);
		}
	}
	/* error ratio between P / r_r = 0.29 and 0.145 on the worst corner: ~4 (quadratic) */
	double err[2];
	for (int i = 0; i < 2; i++) {
		prsm_design d;
		prsm_flank_pair p;
		prsm_contact c;
		standard_design(&d, 3, i ? 0.6 : 1.2, 4.13, 30.0, 3, 5);
		prsm_flank_pair_nominal(&p, &d, PRSM_SIDE_SCREW);
		prsm_contact_solve(&c, &p);
		err[i] = c.y_mm / (d.pitch_mm / (M_PI * tan(30.0 * DEG))) - 1.0;
	}
	assert_close(err[0] / err[1], 4.0, 0.4);
}

/* Flank shifts add to the gap one to one and a target clearance is met exactly. */
static void test_thinning_for_target_clearance(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_problems w;
	case_a(&d);
	d.target_axial_clearance_mm = 0.0237;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(&a, &d, &w, NULL), 0);
	assert_close(a.backlash_mm, 0.0237, 1e-12);
	assert_close(a.screw.gap_mm, a.nut.gap_mm, 1e-12);
	assert_close(d.flank_shift_screw_mm, 0.0237 / 4 + 0.08236, 1e-5);
	assert_close(d.flank_shift_roller_mm, 0.0, 0.0);
	assert_int_equal(w.count, 0);

	/* given shifts: gap = G0 + t_s + t_r on the screw side */
	prsm_design e;
	case_a(&e);
	e.thinning_rule = PRSM_THINNING_GIVEN;
	e.flank_shift_screw_mm = 0.0512;
	e.flank_shift_roller_mm = 0.0173;
	e.flank_shift_nut_mm = 0.0041;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(&a, &e, &w, NULL), 0);
	assert_close(a.screw.gap_mm - a.gap0_screw_mm, 0.0512 + 0.0173, 1e-12);
	assert_close(a.nut.gap_mm - a.gap0_nut_mm, 0.0041 + 0.0173, 1e-12);
	/* the screw side still interferes: a warning says so */
	assert_true(w.count >= 1);
}

/* An edge contact is reported, never silently used. */
static void test_edge_contact(void **state)
{
	(void)state;
	prsm_design d;
	prsm_flank_pair p;
	prsm_contact c;
	case_a(&d);
	d.screw_crest_radius_mm = 9.80; /* contact radius is 9.817 */
	prsm_flank_pair_nominal(&p, &d, PRSM_SIDE_SCREW);
	assert_int_equal(prsm_contact_solve(&c, &p), PRSM_EEDGE);
	assert_true(c.edge & PRSM_EDGE_BODY_CREST);
	prsm_analysis a;
	prsm_problems w;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(&a, &d, &w, &err), PRSM_EEDGE);
	assert_non_null(strstr(err.message, "edge contact"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_case_a_screw_contact),
		cmocka_unit_test(test_case_a_nut_contact_conjugate),
		cmocka_unit_test(test_newton_equals_grid_minimum),
		cmocka_unit_test(test_derivatives_finite_difference),
		cmocka_unit_test(test_curvatures),
		cmocka_unit_test(test_offset_rule),
		cmocka_unit_test(test_thinning_for_target_clearance),
		cmocka_unit_test(test_edge_contact),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
