/*
 * test_rating.c: the ratings both ways and the contact-ellipse truncation (model/rating.h,
 * MODEL.md §6), catalogue sizes (model/nominal.h, MODEL.md §1) and the plausibility checks and
 * blame of derived radii (model/geometry.h).
 *
 * Independent computations: the flank distances from the closed forms written out here, the
 * truncation load by a Hertz solve at that load (the semi-axis must equal the margin), the
 * equal-sharing C_0a by bisection on Hertz's p_max, the truncation-limited C_0a of the spring
 * chain by re-solving the distribution at that load, Z_max by placing the rollers.
 */
#include "test_support.h"

#include "model/analysis.h"
#include "model/geometry.h"
#include "model/hertz.h"
#include "model/life.h"
#include "model/nominal.h"
#include "model/performance.h"
#include "model/rating.h"

#include <string.h>

/* A design from a catalogue size (nominal.h), analysed at load F_N (N). */
static void nominal_design(prsm_design *d, prsm_analysis *a, double d0_mm, double lead_mm, double F_N)
{
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_nominal n = {d0_mm, lead_mm, 0, 0, 0};
	prsm_nominal_geometry g;
	assert_int_equal(prsm_nominal_resolve(&g, &n, 45.0 * DEG, 0.1, &e), 0);
	standard_design(d, g.starts, g.pitch_mm, g.roller_radius_mm, 45.0, g.rollers, g.engaged_threads);
	d->axial_load_N = F_N;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(a, d, &e, &err), 0);
}

/* The peak pressure of a contact at normal load Q (N), MPa. */
static double p_max_at(const prsm_contact *c, const prsm_design *d, double Q)
{
	prsm_hertz h;
	assert_int_equal(prsm_hertz_solve(&h, c->curvature_per_mm[0], c->curvature_per_mm[1], d->screw_material.E_MPa,
	                                  d->screw_material.poisson, d->roller_material.E_MPa,
	                                  d->roller_material.poisson, Q),
	                 0);
	return h.p_max_MPa;
}

/* Flank distances against their closed forms, the profile axis (a on the screw side, b on the
 * nut side: MODEL.md §2's curvature estimates), and the truncation load by a Hertz solve. */
static void test_truncation_case_a(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 5, 2.0, 3.25, 45.0, 10, 10);
	assert_int_equal(prsm_analysis_nominal(&a, &d, &w, &err), 0);
	const prsm_contact *c[2] = {&a.screw, &a.nut};
	for (int s = 0; s < 2; s++) {
		prsm_hertz ref;
		const prsm_material *m = s == 0 ? &d.screw_material : &d.nut_material;
		assert_int_equal(prsm_hertz_solve(&ref, c[s]->curvature_per_mm[0], c[s]->curvature_per_mm[1], m->E_MPa,
		                                  m->poisson, d.roller_material.E_MPa, d.roller_material.poisson, 37.913),
		                 0);
		prsm_truncation t;
		assert_int_equal(prsm_rating_truncation(&t, &d, c[s], &ref, s, &err), 0);
		const double rho = c[s]->body_rho_mm, u = c[s]->roller_u_mm, R = d.roller_arc_radius_mm;
		const double cb = cos(45.0 * DEG);
		const double body_crest = s == 0 ? d.screw_crest_radius_mm - rho : rho - d.nut_crest_radius_mm;
		const double body_root = s == 0 ? rho - d.screw_root_radius_mm : d.nut_root_radius_mm - rho;
		assert_close(t.distance_mm[PRSM_FLANK_EDGE_BODY_CREST], body_crest / cb, 1e-12);
		assert_close(t.distance_mm[PRSM_FLANK_EDGE_BODY_ROOT], body_root / cb, 1e-12);
		/* the roller arc: arc length = R x the angle between the two radii on the sphere */
		const double th_u = asin(u / R), th_c = asin(d.roller_crest_radius_mm / R);
		const double th_r = asin(d.roller_root_radius_mm / R);
		assert_close(t.distance_mm[PRSM_FLANK_EDGE_ROLLER_CREST], R * (th_c - th_u), 1e-12);
		assert_close(t.distance_mm[PRSM_FLANK_EDGE_ROLLER_ROOT], R * (th_u - th_r), 1e-12);
		double mn = INFINITY;
		for (int k = 0; k < 4; k++)
			mn = fmin(mn, t.distance_mm[k]);
		assert_close(t.margin_mm, mn, 0.0);
		/* case A: the contact sits near the pitch radius, so the crest (0.25 P / cos beta away)
		 * is nearer than the root (0.30 P / cos beta) */
		assert_true(t.edge == PRSM_FLANK_EDGE_BODY_CREST || t.edge == PRSM_FLANK_EDGE_ROLLER_CREST);
		assert_true(t.margin_mm > 0.6 && t.margin_mm < 0.25 * 2.0 / cb + 0.1);
		assert_int_equal(t.profile_is_major, s == 0 ? 1 : 0);
		/* at q_limit a fresh Hertz solve puts the profile semi-axis exactly on the margin */
		prsm_hertz h;
		assert_int_equal(prsm_hertz_solve(&h, c[s]->curvature_per_mm[0], c[s]->curvature_per_mm[1], m->E_MPa,
		                                  m->poisson, d.roller_material.E_MPa, d.roller_material.poisson,
		                                  t.q_limit_N),
		                 0);
		assert_close(s == 0 ? h.a_mm : h.b_mm, t.margin_mm, 1e-9 * t.margin_mm);
		assert_close(h.p_max_MPa, t.p_limit_MPa, 1e-9 * t.p_limit_MPa);
		assert_close(prsm_truncation_profile_axis_mm(&t, t.q_limit_N), t.margin_mm, 1e-12);
		/* case A is not truncated at 4200 MPa: p_limit is above p_allow */
		assert_true(t.p_limit_MPa > 4200.0);
	}
	/* error paths: no load, an unknown side */
	prsm_hertz zero = {0};
	prsm_truncation t;
	assert_int_equal(prsm_rating_truncation(&t, &d, &a.screw, &zero, 0, &err), PRSM_EINVAL);
	assert_int_equal(prsm_rating_truncation(&t, &d, &a.screw, &zero, 7, &err), PRSM_EINVAL);
}

/* Makers' convention by independent computations, for the four sizes of issue 18: C_0a at
 * equal sharing (bisection on p_max), C_a with the load factor 1, C_0a/C_a above 1 for all
 * four (catalogues list C_0a above C_a), the 48 x 5 (P = 1 mm) truncated at C_0a. */
static void test_makers_four_sizes(void **state)
{
	(void)state;
	const double sizes[4][2] = {{21.0, 5.0}, {30.0, 10.0}, {48.0, 5.0}, {60.0, 20.0}};
	for (int k = 0; k < 4; k++) {
		prsm_design d;
		prsm_analysis a;
		nominal_design(&d, &a, sizes[k][0], sizes[k][1], 7319.0);
		prsm_performance p;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), 0);
		/* equal sharing: the normal load at which p_max = 4200 MPa, by bisection in log Q */
		double C0[2];
		const prsm_contact *c[2] = {&a.screw, &a.nut};
		for (int s = 0; s < 2; s++) {
			double lo = 1.0, hi = 1e7;
			for (int i = 0; i < 200; i++) {
				const double mid = sqrt(lo * hi);
				if (p_max_at(c[s], &d, mid) > 4200.0)
					hi = mid;
				else
					lo = mid;
			}
			C0[s] = 0.5 * (lo + hi) * fabs(c[s]->normal[2]) * d.rollers * d.engaged_threads;
		}
		assert_close(p.makers.C0a_screw_N, C0[0], 1e-9 * C0[0]);
		assert_close(p.makers.C0a_nut_N, C0[1], 1e-9 * C0[1]);
		assert_close(p.makers.C0a_N, fmin(C0[0], C0[1]), 1e-9 * C0[0]);
		/* C_a with equal sharing = the distribution's C_a / its factor (life.h: linear in it) */
		assert_close(p.makers.C_a_N, p.dynamic.C_a_N / p.distribution_factor, 1e-9 * p.makers.C_a_N);
		prsm_dynamic_capacity eq;
		assert_int_equal(prsm_life_dynamic_capacity(&eq, &d, NULL, 1.0, &err), 0);
		assert_close(p.makers.C_a_N, eq.row_N * pow(d.engaged_threads, 0.7), 1e-9 * p.makers.C_a_N);
		assert_close(p.makers.C0a_over_C_a, p.makers.C0a_N / p.makers.C_a_N, 1e-12);
		print_message("%g x %g: n %d P %g r_r %g Z %d n_t %d; makers C_0a %.4g C_a %.4g ratio %.3f; "
		              "distribution C_0a %.4g (%s) ratio %.3f\n",
		              sizes[k][0], sizes[k][1], d.starts, d.pitch_mm, d.roller_radius_mm, d.rollers,
		              d.engaged_threads, p.makers.C0a_N, p.makers.C_a_N, p.makers.C0a_over_C_a, p.C0a_N,
		              p.C0a_truncation_limited ? "truncation" : "pressure", p.C0a_over_C_a);
		assert_true(p.makers.C0a_over_C_a > 1.0);
		/* the distribution's rating is below the makers' (its most loaded contact is above the mean) */
		assert_true(p.C0a_pressure_N < p.makers.C0a_N);
		assert_true(p.C0a_N <= p.C0a_pressure_N);
		/* only the 48 x 5 (P = 1 mm, r_r = 8 mm: R = 11.3 mm) runs off its flank */
		const int fine = k == 2;
		assert_int_equal(p.makers.truncated, fine);
		assert_int_equal(p.C0a_truncation_limited, fine);
		assert_int_equal(p.truncation_screw.truncated_at_C0a || p.truncation_nut.truncated_at_C0a, fine);
		prsm_performance_free(&p);
	}
}

/* A truncation-limited C_0a of the spring chain: re-solve the distribution at C_0a (the
 * operating load) and the most loaded contact's profile semi-axis is exactly the margin on the
 * limiting side; a little above it the operating-load check reports the truncation. */
static void test_truncation_limits_distribution_C0a(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	nominal_design(&d, &a, 48.0, 5.0, 1000.0);
	prsm_performance p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), 0);
	assert_true(p.C0a_truncation_limited);
	const int side = p.C0a_screw_N <= p.C0a_nut_N ? 0 : 1;
	const double C0a = p.C0a_N, margin = (side == 0 ? p.truncation_screw : p.truncation_nut).t.margin_mm;
	assert_false(p.truncation_screw.truncated_operating || p.truncation_nut.truncated_operating);
	prsm_performance_free(&p);

	d.axial_load_N = C0a;
	assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), 0);
	const prsm_truncation_check *tc = side == 0 ? &p.truncation_screw : &p.truncation_nut;
	assert_close(tc->operating_axis_mm, margin, 1e-8 * margin);
	assert_close(p.static_safety, 1.0, 1e-8);
	prsm_performance_free(&p);

	d.axial_load_N = 1.013 * C0a;
	assert_int_equal(prsm_performance_compute(&p, &d, &a, &err), 0);
	tc = side == 0 ? &p.truncation_screw : &p.truncation_nut;
	assert_true(tc->truncated_operating);
	assert_true(tc->operating_axis_mm > margin);
	prsm_performance_free(&p);
}

/* MODEL.md §1: Ø30 lead 20 with 5 starts -> roller Ø10, pitch 4, nut Ø50; Z_max by placing the
 * rollers; n_t = round(d_0 / P); the rules' refusals at their pointers. */
static void test_nominal_rules(void **state)
{
	(void)state;
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_nominal n = {30.0, 20.0, 0, 0, 0};
	prsm_nominal_geometry g;
	assert_int_equal(prsm_nominal_resolve(&g, &n, 45.0 * DEG, 0.1, &e), 0);
	assert_int_equal(g.starts, 5);
	assert_close(g.pitch_mm, 4.0, 1e-15);
	assert_close(2.0 * g.roller_radius_mm, 10.0, 1e-14);
	assert_close(2.0 * g.nut_radius_mm, 50.0, 1e-13);
	assert_close(g.screw_radius_mm, 15.0, 0.0);
	assert_int_equal(g.engaged_threads, 8); /* 30 / 4 = 7.5 -> 8 */
	/* Z_max: Z rollers of crest radius r_c at orbit a fit when 2 (r_c + c/2) <= 2 a sin(pi / Z) */
	const double rr = g.roller_radius_mm, crest = fmin(rr + 0.25 * g.pitch_mm, rr + 0.9 * (rr / sin(45.0 * DEG) - rr));
	const double orbit = g.screw_radius_mm + rr;
	int z = 1;
	while (crest + 0.05 <= orbit * sin(M_PI / (z + 1)))
		z++;
	assert_int_equal(g.rollers, z);

	/* high-entropy: 37.3 x 13.7 with 4 starts, 7 rollers and 11 threads given */
	prsm_nominal m = {37.3, 13.7, 4, 7, 11};
	assert_int_equal(prsm_nominal_resolve(&g, &m, 40.0 * DEG, 0.1, &e), 0);
	assert_close(g.pitch_mm, 13.7 / 4.0, 1e-15);
	assert_close(g.roller_radius_mm, 37.3 / 4.0, 1e-14);
	assert_close(g.nut_radius_mm, 4.0 * 37.3 / 4.0, 1e-13);
	assert_int_equal(g.rollers, 7);
	assert_int_equal(g.engaged_threads, 11);

	prsm_nominal bad = {-2.0, 0.0, 2, 0, 0};
	assert_int_equal(prsm_nominal_resolve(&g, &bad, 45.0 * DEG, 0.1, &e), PRSM_EINVAL);
	assert_int_equal(e.count, 3);
	assert_string_equal(e.items[0].pointer, "/nominal/diameter_mm");
	assert_string_equal(e.items[1].pointer, "/nominal/lead_mm");
	assert_string_equal(e.items[2].pointer, "/nominal/starts");
}

/* A unit slip warns at the field, naming the slip; a real screw does not warn. */
static void test_plausibility(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems w;
	standard_design(&d, 5, 2.0, 3250.0, 45.0, 10, 10);
	prsm_problems_init(&w);
	prsm_geometry_plausibility(&w, &d);
	assert_int_equal(w.count, 1);
	assert_string_equal(w.items[0].pointer, "/geometry/roller_radius_mm");
	assert_string_equal(w.items[0].code, "implausible");
	assert_non_null(strstr(w.items[0].message, "3250 mm: a value in µm"));
	/* a pitch in inches (0.0787 in = 2 mm), a load of 7.3e9 N, 50000 rpm */
	standard_design(&d, 5, 0.0787, 3.25, 45.0, 10, 10);
	d.axial_load_N = 7.3e9;
	d.screw_speed_rad_s = 50000.0 * M_PI / 30.0;
	prsm_problems_init(&w);
	prsm_geometry_plausibility(&w, &d);
	assert_int_equal(w.count, 3);
	assert_string_equal(w.items[0].pointer, "/geometry/pitch_mm");
	assert_non_null(strstr(w.items[0].message, "inches"));
	assert_string_equal(w.items[1].pointer, "/operating_point/axial_load_N");
	assert_string_equal(w.items[2].pointer, "/operating_point/screw_speed_rpm");
	/* case A and the four catalogue sizes are plausible */
	const double sizes[5][3] = {{5, 2.0, 3.25}, {5, 1.0, 3.5}, {5, 2.0, 5.0}, {5, 1.0, 8.0}, {5, 4.0, 10.0}};
	for (int k = 0; k < 5; k++) {
		standard_design(&d, (int)sizes[k][0], sizes[k][1], sizes[k][2], 45.0, 10, 10);
		d.axial_load_N = 7000.0;
		prsm_problems_init(&w);
		prsm_geometry_plausibility(&w, &d);
		assert_int_equal(w.count, 0);
	}
}

/* A derived default that fails blames the field the user wrote (issue 18: pitch_mm 20 blamed
 * roller_root_radius_mm); an explicit radius is still blamed itself. */
static void test_derived_blame(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems e, w;
	prsm_problems_init(&e);
	prsm_problems_init(&w);
	prsm_design_init(&d);
	d.starts = 5;
	d.pitch_mm = 20.0;
	d.roller_radius_mm = 3.25;
	d.rollers = 6;
	d.engaged_threads = 10;
	assert_int_equal(prsm_design_resolve(&d, &e), 0);
	prsm_geometry g;
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), PRSM_EGEOMETRY);
	int pitch = 0;
	for (int i = 0; i < e.count; i++) {
		assert_string_not_equal(e.items[i].pointer, "/geometry/roller_root_radius_mm");
		assert_string_not_equal(e.items[i].pointer, "/geometry/screw_root_radius_mm");
		pitch += strcmp(e.items[i].pointer, "/geometry/pitch_mm") == 0;
	}
	assert_true(pitch >= 1);
	/* the same root radius given explicitly is the user's own field */
	prsm_design_init(&d);
	d.starts = 5;
	d.pitch_mm = 2.0;
	d.roller_radius_mm = 3.25;
	d.roller_root_radius_mm = -0.5;
	d.rollers = 6;
	d.engaged_threads = 10;
	prsm_problems_init(&e);
	assert_int_equal(prsm_design_resolve(&d, &e), 0);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), PRSM_EGEOMETRY);
	assert_string_equal(e.items[0].pointer, "/geometry/roller_root_radius_mm");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_truncation_case_a),
		cmocka_unit_test(test_makers_four_sizes),
		cmocka_unit_test(test_truncation_limits_distribution_C0a),
		cmocka_unit_test(test_nominal_rules),
		cmocka_unit_test(test_plausibility),
		cmocka_unit_test(test_derived_blame),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
