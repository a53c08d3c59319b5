/*
 * test_rating_opt.c: the optimiser restricted to a list of allowed leads or pitches (issue 18,
 * schemas/optimization.schema.json variables.lead_values_mm / pitch_values_mm,
 * src/opt/design_problem.c). With only discrete variables (starts and the allowed leads, radius
 * and rollers fixed) the optimiser must return exactly the best of the combinations, found here
 * by analysing each one from scratch (design documents through prsm_io_design_load, the model's
 * analyses, the constraints checked independently); every reported lead is one of the list,
 * never a value between (issue 18 saw 12.66 mm); the readers refuse a list together with a range.
 */
#include "test_support.h"

#include <cJSON.h>

#include "app/optimize.h"
#include "io/design_json.h"
#include "io/global.h"
#include "io/json_util.h"
#include "model/analysis.h"
#include "model/performance.h"

static const char *const base_design =
	"{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 8, "
	"\"engaged_threads\": 11}, \"target_axial_clearance_um\": 17, "
	"\"operating_point\": {\"axial_load_N\": 6137, \"screw_speed_rpm\": 733}}";

/* Stiffness (N/um) of the base design with starts n and lead L, or NaN when it fails the
 * checks of the document below (analysable, standard rules, static safety >= 2.2). */
static double evaluate(int n, double lead_mm)
{
	prsm_problems p, w;
	prsm_problems_init(&p);
	prsm_problems_init(&w);
	cJSON *d = prsm_json_parse(base_design, strlen(base_design), &p);
	cJSON *g = cJSON_GetObjectItemCaseSensitive(d, "geometry");
	cJSON_ReplaceItemInObjectCaseSensitive(g, "starts", cJSON_CreateNumber(n));
	cJSON_ReplaceItemInObjectCaseSensitive(g, "pitch_mm", cJSON_CreateNumber(lead_mm / n));
	prsm_design des;
	prsm_geometry geom;
	int rc = prsm_io_design_load(&des, &geom, &w, d, "", &p);
	cJSON_Delete(d);
	if (rc || p.count || des.rollers > geom.z_max)
		return NAN;
	for (int i = 0; i < w.count; i++) /* a rule warning breaks standard_rules */
		if (strcmp(w.items[i].code, "implausible") != 0)
			return NAN;
	prsm_analysis a;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_analysis_nominal(&a, &des, &w, &err))
		return NAN;
	prsm_performance perf;
	if (prsm_performance_compute(&perf, &des, &a, &err))
		return NAN;
	const double k = perf.static_safety >= 2.2 ? perf.stiffness_N_per_um : NAN;
	prsm_performance_free(&perf);
	return k;
}

static cJSON *optimise(const char *variables, prsm_problems *problems, int *rc)
{
	char text[2048];
	snprintf(text, sizeof text,
	         "{\"design\": %s, \"variables\": %s, \"objectives\": [{\"name\": \"stiffness_N_per_um\"}], "
	         "\"constraints\": {\"static_safety_min\": 2.2, \"standard_rules\": true}, "
	         "\"solver\": {\"algorithm\": \"cobyla\", \"max_evaluations\": 400, \"seed\": 3}}",
	         base_design, variables);
	prsm_problems_init(problems);
	cJSON *doc = prsm_json_parse(text, strlen(text), problems);
	assert_non_null(doc);
	cJSON *res = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	*rc = prsm_app_optimize(&res, doc, NULL, NULL, NULL, 0.0, problems, &err);
	cJSON_Delete(doc);
	return res;
}

static void test_allowed_leads(void **state)
{
	(void)state;
	const double leads[] = {5.0, 8.0, 10.0, 12.7, 20.0};
	int rc;
	prsm_problems problems;
	/* given unsorted: the reader sorts them */
	cJSON *res = optimise("{\"starts\": {\"values\": [4, 5, 6]}, \"lead_values_mm\": [12.7, 5, 20, 8, 10]}",
	                      &problems, &rc);
	if (rc)
		for (int i = 0; i < problems.count; i++)
			print_error("%s: %s\n", problems.items[i].pointer, problems.items[i].message);
	assert_int_equal(rc, 0);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(res, "feasible")));
	const cJSON *best = cJSON_GetObjectItemCaseSensitive(res, "best");
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(best, "variables");
	const double lead = cJSON_GetObjectItemCaseSensitive(v, "lead_mm")->valuedouble;
	const int starts = cJSON_GetObjectItemCaseSensitive(v, "starts")->valueint;
	const double k = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(best, "objectives"), 0),
	                                                  "value")->valuedouble;
	int in_list = 0;
	for (int i = 0; i < 5; i++)
		in_list |= fabs(lead - leads[i]) <= 1e-12 * leads[i];
	assert_true(in_list);
	/* brute force over the 15 combinations */
	double best_k = -INFINITY, best_lead = NAN;
	int best_n = 0, feasible = 0;
	for (int n = 4; n <= 6; n++)
		for (int i = 0; i < 5; i++) {
			const double q = evaluate(n, leads[i]);
			if (isnan(q))
				continue;
			feasible++;
			if (q > best_k) {
				best_k = q;
				best_lead = leads[i];
				best_n = n;
			}
		}
	print_message("optimiser: %d starts, lead %g mm, %.6g N/um; brute force over %d feasible of 15: %d starts, "
	              "lead %g mm, %.6g N/um\n", starts, lead, k, feasible, best_n, best_lead, best_k);
	assert_true(feasible >= 3);
	assert_int_equal(starts, best_n);
	assert_close(lead, best_lead, 0.0);
	assert_close(k, best_k, 1e-9 * best_k);
	cJSON_Delete(res);

	/* pitches instead: P itself from the list, whatever the starts */
	res = optimise("{\"starts\": {\"values\": [4, 5]}, \"pitch_values_mm\": [1.5, 2.5, 2]}", &problems, &rc);
	assert_int_equal(rc, 0);
	v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(res, "best"), "variables");
	const double P = cJSON_GetObjectItemCaseSensitive(v, "pitch_mm")->valuedouble;
	assert_true(P == 1.5 || P == 2.0 || P == 2.5);
	cJSON_Delete(res);

	/* a list and a range of the same variable, or both lists: refused at the field */
	const char *bad[][2] = {
		{"{\"lead_values_mm\": [5, 10], \"lead_mm\": {\"min\": 4, \"max\": 20}}", "/variables/lead_mm"},
		{"{\"lead_values_mm\": [5, 10], \"pitch_mm\": {\"min\": 1, \"max\": 3}}", "/variables/pitch_mm"},
		{"{\"lead_values_mm\": [5, 10], \"pitch_values_mm\": [1, 2]}", "/variables/pitch_values_mm"},
		{"{\"lead_values_mm\": [5, -10]}", "/variables/lead_values_mm/1"},
	};
	for (int i = 0; i < 4; i++) {
		res = optimise(bad[i][0], &problems, &rc);
		assert_int_not_equal(rc, 0);
		int found = 0;
		for (int j = 0; j < problems.count; j++)
			found |= strcmp(problems.items[j].pointer, bad[i][1]) == 0;
		if (!found)
			print_error("%s: no problem at %s (first %s: %s)\n", bad[i][0], bad[i][1],
			            problems.count ? problems.items[0].pointer : "-", problems.count ? problems.items[0].message : "-");
		assert_true(found);
		cJSON_Delete(res);
	}
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_allowed_leads),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
