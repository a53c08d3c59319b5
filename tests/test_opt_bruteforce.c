/*
 * test_opt_bruteforce.c: the design optimiser's answer against an independent brute-force
 * search (issue 7). studies/optimize-case-a.json (maximise the axial stiffness over starts
 * 3-6, pitch 1-3 mm, roller radius 2.5-5 mm and every roller count up to Z_max inside a 50 mm
 * nut, static safety >= 2.5, L10 >= 2000 h, standard rules) is solved by
 * prsm_app_optimize; then every point of a grid over the same box is loaded as a
 * design document, analysed from scratch (prsm_analysis_nominal, prsm_performance_compute) and
 * checked against the same constraints without the optimiser's code. No feasible grid point
 * may be stiffer than the optimiser's best, and the best must itself pass the same checks.
 */
#include "test_support.h"

#include <cJSON.h>

#include "io/design_json.h"
#include "io/global.h"
#include "app/optimize.h"
#include "io/optimization_json.h"
#include "model/analysis.h"
#include "model/compliance.h"
#include "model/performance.h"

#include <gsl/gsl_errno.h>

typedef struct {
	int feasible;
	double stiffness_N_per_um;
} grid_point;

/* Analyse the design document d (a copy) with geometry members set; the constraints of
 * optimize-case-a.json checked independently. */
static grid_point evaluate(const cJSON *design, int starts, double pitch_mm, double roller_radius_mm, int rollers)
{
	grid_point out = {0, NAN};
	cJSON *d = cJSON_Duplicate(design, 1);
	cJSON *g = cJSON_GetObjectItemCaseSensitive(d, "geometry");
	cJSON_ReplaceItemInObjectCaseSensitive(g, "starts", cJSON_CreateNumber(starts));
	cJSON_ReplaceItemInObjectCaseSensitive(g, "pitch_mm", cJSON_CreateNumber(pitch_mm));
	cJSON_ReplaceItemInObjectCaseSensitive(g, "roller_radius_mm", cJSON_CreateNumber(roller_radius_mm));
	cJSON_ReplaceItemInObjectCaseSensitive(g, "rollers", cJSON_CreateNumber(rollers));
	prsm_design des;
	prsm_geometry geom;
	prsm_problems w, p;
	prsm_problems_init(&w);
	prsm_problems_init(&p);
	int rc = prsm_io_design_load(&des, &geom, &w, d, "", &p);
	cJSON_Delete(d);
	if (rc || p.count || w.count || des.rollers > geom.z_max)
		return out; /* impossible, or off the standard rules (a constraint of the document) */
	prsm_analysis a;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_analysis_nominal(&a, &des, &w, &err))
		return out;
	prsm_performance perf;
	if (prsm_performance_compute(&perf, &des, &a, &err))
		return out;
	double od_mm = 2.0 * prsm_compliance_nut_outer_radius_mm(des.nut_outer_radius_mm, &des);
	out.feasible = od_mm <= 50.0 && perf.static_safety >= 2.5 && perf.life.hours >= 2000.0;
	out.stiffness_N_per_um = perf.stiffness_N_per_um;
	prsm_performance_free(&perf);
	return out;
}

static void test_no_grid_point_beats_the_optimum(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("optimize-case-a.json");

	cJSON *res = NULL;
	prsm_problems problems;
	prsm_problems_init(&problems);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_app_optimize(&res, doc, NULL, NULL, NULL, 0.0, &problems, &err), 0);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(res, "feasible")));
	const cJSON *best = cJSON_GetObjectItemCaseSensitive(res, "best");
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(best, "variables");
	double best_k = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(best, "objectives"), 0),
	                                                 "value")->valuedouble;
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");

	/* the optimiser's best passes the independent checks, with the stiffness it reports */
	grid_point b = evaluate(design, cJSON_GetObjectItemCaseSensitive(v, "starts")->valueint,
	                        cJSON_GetObjectItemCaseSensitive(v, "pitch_mm")->valuedouble,
	                        cJSON_GetObjectItemCaseSensitive(v, "roller_radius_mm")->valuedouble,
	                        cJSON_GetObjectItemCaseSensitive(v, "rollers")->valueint);
	assert_true(b.feasible);
	assert_close(b.stiffness_N_per_um, best_k, 1e-9 * best_k);

	/* a grid over the box: 4 starts x 13 pitches x 16 radii x Z 3..20 (Z_max cuts it) */
	int feasible = 0;
	double grid_best = 0.0;
	for (int n = 3; n <= 6; n++)
		for (int i = 0; i <= 12; i++)
			for (int j = 0; j <= 15; j++)
				for (int z = 3; z <= 20; z++) {
					double pitch_mm = 1.0 + 2.0 * i / 12.0 + 0.0137; /* off the round values */
					double radius_mm = 2.5 + 2.5 * j / 15.0 - 0.0071;
					if (pitch_mm > 3.0 || radius_mm < 2.5)
						continue;
					grid_point q = evaluate(design, n, pitch_mm, radius_mm, z);
					if (!q.feasible)
						continue;
					feasible++;
					if (q.stiffness_N_per_um > grid_best)
						grid_best = q.stiffness_N_per_um;
				}
	print_message("optimiser %.4f N/um; best of %d feasible grid points %.4f N/um\n", best_k, feasible, grid_best);
	assert_true(feasible > 50);
	assert_true(grid_best <= best_k * (1.0 + 1e-9));
	/* and the grid is not trivially far below: the optimum is within a grid step's reach */
	assert_true(grid_best >= 0.8 * best_k);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_no_grid_point_beats_the_optimum),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
