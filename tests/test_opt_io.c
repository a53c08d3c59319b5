/*
 * test_opt_io.c: the optimisation document through src/io/optimization_json.h: the check with
 * the caller's evaluation cap, every problem at its pointer at once, a run's result document,
 * a cancelled run returning its best design so far (flagged), progress in evaluations; the
 * constraint tolerance never relaxes a limit (the largest the document allows, 0.1: the
 * reported design meets every raw limit, Z <= Z_max; a limit 5 % out of reach is reported
 * violated); the search figures (runs truncated and the stop reason that follows).
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "app/optimize.h"
#include "io/optimization_json.h"
#include "io/global.h"

static const char *doc_text =
	"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	" \"target_axial_clearance_um\": 20,"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}},"
	" \"variables\": {\"starts\": {\"values\": [3, 4, 5, 6]}, \"pitch_mm\": {\"min\": 1, \"max\": 3},"
	" \"roller_radius_mm\": {\"min\": 2.5, \"max\": 5}, \"rollers\": {\"min\": 3}},"
	" \"objectives\": [{\"name\": \"stiffness_N_per_um\"}],"
	" \"constraints\": {\"nut_outer_diameter_max_mm\": 50, \"static_safety_min\": 2.5},"
	" \"solver\": {\"max_evaluations\": 1500, \"seed\": 3}}";

static int has_pointer(const prsm_problems *p, const char *ptr)
{
	for (int i = 0; i < p->count; i++)
		if (strcmp(p->items[i].pointer, ptr) == 0)
			return 1;
	return 0;
}

static void test_check(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse(doc_text);
	prsm_problems w, p;
	prsm_problems_init(&w);
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), 0);
	assert_int_equal(p.count, 0);
	/* the service's cap: 1500 evaluations are too many under a cap of 1000 */
	assert_int_equal(prsm_app_optimization_check(doc, 1000, &w, &p), PRSM_EINVAL);
	assert_true(has_pointer(&p, "/solver/max_evaluations"));
	cJSON_Delete(doc);
}

static void test_every_problem(void **state)
{
	(void)state;
	const char *bad =
		"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": -2, \"roller_radius_mm\": 3.25,"
		" \"rollers\": 10, \"engaged_threads\": 10}},"
		" \"variables\": {\"pitch_mm\": {\"min\": 3, \"max\": 1}, \"lead_mm\": {\"min\": 1, \"max\": 2},"
		" \"roller_radius_mm\": {\"min\": -1, \"max\": 5}, \"rollers\": {\"values\": [12, 11]}},"
		" \"objectives\": [{\"name\": \"efficiency\"}, {\"name\": \"efficiency\"}],"
		" \"multi_objective\": {\"method\": \"pareto\", \"points\": 1000},"
		" \"constraints\": {\"life_min_h\": -5, \"critical_speed_factor_min\": 1.2},"
		" \"solver\": {\"max_evaluations\": 1e12, \"max_time_s\": 0, \"algorithm\": \"newton\","
		" \"multistart\": 0, \"seed\": 1.5}, \"extra\": 1}";
	cJSON *doc = cJSON_Parse(bad);
	assert_non_null(doc);
	prsm_problems w, p;
	prsm_problems_init(&w);
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
	const char *want[] = {"/extra", "/design/geometry/pitch_mm", "/variables/pitch_mm/max",
	                      "/variables/lead_mm", "/variables/roller_radius_mm/min",
	                      "/variables/rollers/values/1", "/objectives/1/name",
	                      "/multi_objective/points", "/constraints/life_min_h",
	                      "/constraints/critical_speed_factor_min", "/solver/max_evaluations",
	                      "/solver/max_time_s", "/solver/algorithm", "/solver/multistart",
	                      "/solver/seed", NULL};
	for (int i = 0; want[i]; i++) {
		if (!has_pointer(&p, want[i]))
			print_error("missing a problem at %s\n", want[i]);
		assert_true(has_pointer(&p, want[i]));
	}
	cJSON_Delete(doc);
	/* not an object; no variable varied */
	doc = cJSON_Parse("[1]");
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
	cJSON_Delete(doc);
}

static void test_execute(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse(doc_text);
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	assert_int_equal(prsm_app_optimize(&res, doc, NULL, NULL, NULL, 0.0, &p, &err), 0);
	assert_non_null(res);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(res, "cancelled")));
	const cJSON *best = cJSON_GetObjectItem(res, "best");
	assert_non_null(cJSON_GetObjectItem(best, "design"));
	assert_non_null(cJSON_GetObjectItem(best, "analysis"));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

static double num(const cJSON *o, const char *key)
{
	const cJSON *it = cJSON_GetObjectItem(o, key);
	assert_true(cJSON_IsNumber(it));
	return it->valuedouble;
}

static cJSON *execute_ok(const cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	assert_int_equal(prsm_app_optimize(&res, doc, NULL, NULL, NULL, 0.0, &p, &err), 0);
	assert_non_null(res);
	return res;
}

/* The constraint by name in a point's constraints. */
static const cJSON *constraint(const cJSON *point, const char *name)
{
	const cJSON *arr = cJSON_GetObjectItem(point, "constraints");
	for (const cJSON *it = arr ? arr->child : NULL; it; it = it->next)
		if (strcmp(cJSON_GetObjectItem(it, "name")->valuestring, name) == 0)
			return it;
	fail_msg("no constraint %s", name);
	return NULL;
}

/* constraint_tolerance 0.1 (the document's largest) only steers the solver: the design found
 * meets every raw limit, Z <= Z_max among them, and each `satisfied` is the raw comparison. */
static void test_constraint_tolerance(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse(doc_text);
	cJSON *sv = cJSON_GetObjectItem(doc, "solver");
	cJSON_AddNumberToObject(sv, "constraint_tolerance", 0.1);
	cJSON *res = execute_ok(doc);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
	assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(res, "violated")), 0);
	assert_close(num(cJSON_GetObjectItem(res, "solver"), "constraint_tolerance"), 0.1, 0.0);
	const cJSON *best = cJSON_GetObjectItem(res, "best");
	const cJSON *fig = cJSON_GetObjectItem(best, "figures");
	assert_true(num(fig, "rollers") <= num(fig, "z_max"));
	assert_true(num(fig, "nut_outer_diameter_mm") <= 50.0);
	assert_true(num(fig, "static_safety") >= 2.5);
	for (const cJSON *it = cJSON_GetObjectItem(best, "constraints")->child; it; it = it->next) {
		assert_true(cJSON_IsTrue(cJSON_GetObjectItem(it, "satisfied")));
		const char *bound = cJSON_GetObjectItem(it, "bound")->valuestring;
		if (strcmp(cJSON_GetObjectItem(it, "name")->valuestring, "roller_fit") == 0)
			continue; /* Z asin(s)/pi <= 1 by the integer Z_max (checked above) */
		if (strcmp(bound, "max") == 0)
			assert_true(num(it, "value") <= num(it, "limit"));
		else
			assert_true(num(it, "value") >= num(it, "limit"));
	}
	cJSON_Delete(res);

	/* a static safety 5 % beyond any pitch in [1.9, 2.1] mm (at most 3.98): within the
	 * tolerance, but not met: infeasible, the constraint named and not satisfied */
	cJSON_Delete(doc);
	doc = cJSON_Parse(doc_text);
	cJSON *vars = cJSON_CreateObject();
	cJSON *pr = cJSON_AddObjectToObject(vars, "pitch_mm");
	cJSON_AddNumberToObject(pr, "min", 1.9);
	cJSON_AddNumberToObject(pr, "max", 2.1);
	cJSON_ReplaceItemInObject(doc, "variables", vars);
	cJSON_ReplaceItemInObject(cJSON_GetObjectItem(doc, "constraints"), "static_safety_min",
	                          cJSON_CreateNumber(4.2));
	cJSON_ReplaceItemInObject(doc, "solver", cJSON_Parse("{\"max_evaluations\": 300, "
	                                                     "\"constraint_tolerance\": 0.1}"));
	res = execute_ok(doc);
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(res, "feasible")));
	assert_string_equal(cJSON_GetObjectItem(res, "status")->valuestring, "infeasible");
	const cJSON *viol = cJSON_GetObjectItem(res, "violated");
	assert_int_equal(cJSON_GetArraySize(viol), 1);
	assert_string_equal(cJSON_GetArrayItem(viol, 0)->valuestring, "static_safety");
	const cJSON *ss = constraint(cJSON_GetObjectItem(res, "best"), "static_safety");
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(ss, "satisfied")));
	assert_true(num(ss, "value") < 4.2 && num(ss, "value") > 4.2 * 0.9);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* The search figures: runs truncated at their evaluation share, and the stop reason says so. */
static void test_truncated_runs(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse(doc_text);
	cJSON *res = execute_ok(doc);
	const cJSON *search = cJSON_GetObjectItem(res, "search");
	double runs = num(search, "runs"), truncated = num(search, "runs_truncated");
	assert_true(truncated >= 0 && truncated <= runs);
	const char *stop = cJSON_GetObjectItem(res, "stop_reason")->valuestring;
	if (truncated > 0)
		assert_string_equal(stop, "max_evaluations");
	else
		assert_true(strcmp(stop, "converged") == 0 || strcmp(stop, "max_evaluations") == 0);
	cJSON_Delete(res);
	/* a roomy budget and loose tolerances: every run converges, and only then "converged" */
	cJSON_ReplaceItemInObject(doc, "solver", cJSON_Parse("{\"max_evaluations\": 20000, "
	                                                     "\"xtol_rel\": 0.01, \"ftol_rel\": 0.01}"));
	res = execute_ok(doc);
	search = cJSON_GetObjectItem(res, "search");
	print_message("roomy budget: %g evaluations, %g runs, %g truncated, %s\n", num(res, "evaluations"),
	              num(search, "runs"), num(search, "runs_truncated"),
	              cJSON_GetObjectItem(res, "stop_reason")->valuestring);
	assert_int_equal((int)num(search, "runs_truncated"), 0);
	assert_string_equal(cJSON_GetObjectItem(res, "stop_reason")->valuestring, "converged");
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

typedef struct {
	prsm_cancel_flag *flag;
	size_t last_done, planned;
	double best;
} watch;

static void on_progress(void *ctx, const prsm_progress *pr)
{
	watch *w = ctx;
	assert_true(pr->done >= w->last_done);
	w->last_done = pr->done;
	w->planned = pr->planned;
	w->best = pr->best;
	if (pr->done >= 800)
		*w->flag = 1;
}

static void test_cancel(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse(doc_text);
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	prsm_cancel_flag flag = 0;
	watch w = {&flag, 0, 0, NAN};
	assert_int_equal(prsm_app_optimize(&res, doc, &flag, on_progress, &w, 0.0, &p, &err),
	                 PRSM_ECANCELLED);
	assert_non_null(res);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "cancelled")));
	assert_string_equal(cJSON_GetObjectItem(res, "stop_reason")->valuestring, "cancelled");
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
	assert_int_equal(w.planned, 1500);
	assert_true(w.best > 100.0); /* N/um, the best feasible stiffness so far */
	const cJSON *best = cJSON_GetObjectItem(res, "best");
	const cJSON *fig = cJSON_GetObjectItem(best, "figures");
	assert_close(cJSON_GetObjectItem(fig, "stiffness_N_per_um")->valuedouble, w.best, 1e-9 * w.best);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_check),
		cmocka_unit_test(test_every_problem),
		cmocka_unit_test(test_execute),
		cmocka_unit_test(test_cancel),
		cmocka_unit_test(test_constraint_tolerance),
		cmocka_unit_test(test_truncated_runs),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
