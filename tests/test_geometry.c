/*
 * test_geometry.c: docs/model/geometry-and-meshing.md — standard rules, lead, helix angles, Z_max, rule checks.
 */
#include "test_support.h"

#include <string.h>

static void test_case_a_helix_angles(void **state)
{
	(void)state;
	prsm_design d;
	prsm_geometry g;
	prsm_problems w, e;
	case_a(&d);
	prsm_problems_init(&w);
	prsm_problems_init(&e);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), 0);
	assert_close(d.screw_radius_mm, 9.75, 1e-12);
	assert_close(d.nut_radius_mm, 16.25, 1e-12);
	assert_close(g.lead_mm, 10.0, 1e-12);
	assert_close(g.helix_screw_rad / DEG, 9.2710, 5e-5);
	assert_close(g.helix_roller_rad / DEG, 5.5938, 5e-5);
	assert_close(g.helix_nut_rad / DEG, 5.5938, 5e-5);
	assert_true(g.standard_rules);
	assert_int_equal(w.count, 0);
	assert_close(g.migration_mm_per_rad, 0.0, 1e-12);
}

static void test_seed000_stage2_helix(void **state)
{
	(void)state;
	prsm_design d;
	prsm_geometry g;
	prsm_problems w, e;
	standard_design(&d, 5, 2.0, 5.5, 45.0, 7, 10);
	prsm_problems_init(&w);
	prsm_problems_init(&e);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), 0);
	assert_close(d.screw_radius_mm, 16.5, 1e-12);
	assert_close(g.helix_screw_rad / DEG, 5.51, 5e-3);
}

/* A public example: screw diameter 30, lead 20, 5 starts -> roller 10, pitch 4, nut 50. */
static void test_public_example(void **state)
{
	(void)state;
	const double rs = 15.0, lead = 20.0;
	const int n = 5;
	double rr = rs / (n - 2), P = lead / n;
	prsm_design d;
	standard_design(&d, n, P, rr, 45.0, 8, 10);
	assert_close(2.0 * d.roller_radius_mm, 10.0, 1e-12);
	assert_close(d.pitch_mm, 4.0, 1e-12);
	assert_close(2.0 * d.nut_radius_mm, 50.0, 1e-12);
	assert_close(2.0 * d.screw_radius_mm, 30.0, 1e-12);
}

/* Z_max against an independent check: Z rollers fit when the chord between neighbouring
 * roller centres is at least 2 r_ro + c. */
static void test_z_max_brute_force(void **state)
{
	(void)state;
	const double cases[][3] = {{3.65, 0.1, 13.0}, {2.117, 0.05, 7.391}, {5.93, 0.3, 22.87},
	                           {1.003, 0.0, 9.871}, {4.4, 0.25, 6.0}};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		double ro = cases[i][0], c = cases[i][1], a = cases[i][2];
		int zmax = prsm_geometry_z_max(ro, c, a), brute = 0;
		for (int z = 1; z < 1000; z++) {
			double chord = z == 1 ? INFINITY : 2.0 * a * sin(M_PI / z);
			if (chord >= 2.0 * ro + c)
				brute = z;
		}
		assert_int_equal(zmax, brute);
	}
}

static int has_pointer(const prsm_problems *p, const char *ptr)
{
	for (int i = 0; i < p->count; i++)
		if (strcmp(p->items[i].pointer, ptr) == 0)
			return 1;
	return 0;
}

static void test_impossible_designs(void **state)
{
	(void)state;
	prsm_design d;
	prsm_geometry g;
	prsm_problems w, e;
	/* too many rollers */
	standard_design(&d, 5, 2.0, 3.25, 45.0, 11, 10);
	prsm_problems_init(&w);
	prsm_problems_init(&e);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), PRSM_EGEOMETRY);
	assert_int_equal(g.z_max, 10);
	assert_true(has_pointer(&e, "/geometry/rollers"));
	assert_non_null(strstr(e.items[0].message, "Z_max = 10"));
	/* n < 3 with the standard rule */
	prsm_design_init(&d);
	d.starts = 2;
	d.pitch_mm = 1.5;
	d.roller_radius_mm = 2.2;
	d.rollers = 4;
	d.engaged_threads = 5;
	prsm_problems_init(&e);
	assert_int_equal(prsm_design_resolve(&d, &e), PRSM_EINVAL);
	assert_true(has_pointer(&e, "/geometry/starts"));
	/* roller crest beyond the arc radius R = r_r / sin(beta) */
	standard_design(&d, 5, 2.0, 3.25, 45.0, 8, 10);
	d.roller_crest_radius_mm = 4.7; /* R = 4.596 */
	prsm_problems_init(&w);
	prsm_problems_init(&e);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), PRSM_EGEOMETRY);
	assert_true(has_pointer(&e, "/geometry/roller_crest_radius_mm"));
}

static void test_non_standard_warns(void **state)
{
	(void)state;
	prsm_design d;
	prsm_geometry g;
	prsm_problems w, e;
	standard_design(&d, 5, 2.0, 3.25, 45.0, 8, 10);
	d.nut_radius_mm = 16.37; /* r_n != n r_r and != r_s + 2 r_r */
	d.nut_crest_radius_mm = 16.37 - 0.5;
	d.nut_root_radius_mm = 16.37 + 0.6;
	prsm_problems_init(&w);
	prsm_problems_init(&e);
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), 0);
	assert_true(has_pointer(&w, "/geometry/nut_radius_mm"));
	assert_false(g.standard_rules);
	/* v_mig per carrier radian = (P / 2 pi)(n - r_n / r_r) */
	assert_close(g.migration_mm_per_rad, 2.0 / (2 * M_PI) * (5 - 16.37 / 3.25), 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_case_a_helix_angles), cmocka_unit_test(test_seed000_stage2_helix),
		cmocka_unit_test(test_public_example),      cmocka_unit_test(test_z_max_brute_force),
		cmocka_unit_test(test_impossible_designs),  cmocka_unit_test(test_non_standard_warns),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
