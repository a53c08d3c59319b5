/*
 * test_opt_io.c: the optimisation document through src/io/optimization_json.h: the check with
 * the caller's evaluation cap, every problem at its pointer at once, a run's result document,
 * a cancelled run returning its best design so far (flagged), progress in evaluations.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "io/optimization_json.h"

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
	assert_int_equal(prsm_io_optimization_check(doc, 0, &w, &p), 0);
	assert_int_equal(p.count, 0);
	/* the service's cap: 1500 evaluations are too many under a cap of 1000 */
	assert_int_equal(prsm_io_optimization_check(doc, 1000, &w, &p), PRSM_EINVAL);
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
	assert_int_equal(prsm_io_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
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
	assert_int_equal(prsm_io_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
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
	assert_int_equal(prsm_io_optimization_execute(&res, doc, NULL, NULL, NULL, 0.0, &p, &err), 0);
	assert_non_null(res);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(res, "cancelled")));
	const cJSON *best = cJSON_GetObjectItem(res, "best");
	assert_non_null(cJSON_GetObjectItem(best, "design"));
	assert_non_null(cJSON_GetObjectItem(best, "analysis"));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

typedef struct {
	volatile int *flag;
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
	volatile int flag = 0;
	watch w = {&flag, 0, 0, NAN};
	assert_int_equal(prsm_io_optimization_execute(&res, doc, &flag, on_progress, &w, 0.0, &p, &err),
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
	gsl_set_error_handler_off();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_check),
		cmocka_unit_test(test_every_problem),
		cmocka_unit_test(test_execute),
		cmocka_unit_test(test_cancel),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
