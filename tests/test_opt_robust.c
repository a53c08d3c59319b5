/*
 * test_opt_robust.c: robust constraints of the design optimisation (issue 7, item 1): the
 * Monte Carlo yield of a study output of each candidate against a spec, with common random
 * numbers. Determinism (the same document twice, threads 1 and 2: identical results); the
 * yield the result reports is the one an equivalent study document gives for the returned
 * design (prsm_app_study_load + prsm_study_run, independently of the optimiser), and meets the
 * target; the constraint binds (the unconstrained optimum misses the target, the robust run
 * returns another design that meets it, at a lower objective); the smooth stand-ins tend to the
 * Monte Carlo yield; a run cancelled after some hundreds of evaluations reports its best design
 * so far as it is (feasible, every robust constraint satisfied by a fresh run of its study);
 * invalid robust sections reported with their pointers. Small sample counts keep it fast.
 */
#include "test_support.h"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>

#include "app/optimize.h"
#include "io/optimization_json.h"
#include "io/global.h"
#include "app/study.h"
#include "io/study_json.h"
#include "opt/robust.h"

/* Case A's envelope (the stiffest design in a 50 mm nut), the load-sharing factor's yield
 * against 1.45 at 99 % under a tight tolerance set: the stiffest design (13 rollers) misses it. */
static const char *design_text =
	"{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	" \"target_axial_clearance_um\": 20,"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}}";

static const char *robust_text =
	"{\"tolerances\": ["
	" {\"parameter\": \"screw.pitch_radius_um\", \"tol_um\": 2},"
	" {\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": 2},"
	" {\"parameter\": \"screw.runout_um\", \"tol_um\": 3},"
	" {\"parameter\": \"nut.runout_um\", \"tol_um\": 3},"
	" {\"parameter\": \"roller.pitch_radius_um\", \"tol_um\": 1},"
	" {\"parameter\": \"roller.thickness_um\", \"tol_um\": 1}],"
	" \"assembly\": {\"mode\": \"linear\", \"angles_per_revolution\": 16, \"measuring_load_N\": 50},"
	" \"monte_carlo\": {\"samples\": 128, \"seed\": 7, \"sampler\": \"lhs\"},"
	" \"constraints\": [{\"output\": \"load_sharing_factor\", \"spec\": {\"upper\": 1.45},"
	" \"yield_min_percent\": 99}]}";

/* The optimisation document; with_robust 0 leaves the robust section out. Caller deletes. */
static cJSON *make_doc(int with_robust)
{
	cJSON *doc = cJSON_Parse(
		"{\"variables\": {\"starts\": {\"values\": [4, 5, 6]}, \"pitch_mm\": {\"min\": 1.5, \"max\": 3},"
		" \"roller_radius_mm\": {\"min\": 2.5, \"max\": 5}, \"rollers\": {\"min\": 6}},"
		" \"objectives\": [{\"name\": \"stiffness_N_per_um\"}],"
		" \"constraints\": {\"nut_outer_diameter_max_mm\": 50, \"static_safety_min\": 2.5},"
		" \"solver\": {\"max_evaluations\": 700, \"multistart\": 1, \"seed\": 3}}");
	assert_non_null(doc);
	cJSON_AddItemToObject(doc, "design", cJSON_Parse(design_text));
	if (with_robust)
		cJSON_AddItemToObject(doc, "robust", cJSON_Parse(robust_text));
	return doc;
}

static cJSON *run(const cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	int rc = prsm_app_optimize(&res, doc, NULL, NULL, NULL, 0.0, &p, &err);
	if (rc)
		print_error("execute: %d %s %s %s\n", rc, err.message, p.count ? p.items[0].pointer : "",
		            p.count ? p.items[0].message : "");
	assert_int_equal(rc, 0);
	assert_non_null(res);
	return res;
}

/* Drop every elapsed_s member (wall-clock times differ between runs). */
static void strip_times(cJSON *o)
{
	if (!o)
		return;
	cJSON_DeleteItemFromObjectCaseSensitive(o, "elapsed_s");
	for (cJSON *it = o->child; it; it = it->next)
		if (cJSON_IsObject(it) || cJSON_IsArray(it))
			strip_times(it);
}

static const cJSON *robust_entry(const cJSON *res)
{
	const cJSON *arr = cJSON_GetObjectItem(cJSON_GetObjectItem(res, "best"), "robust");
	assert_true(cJSON_IsArray(arr));
	assert_int_equal(cJSON_GetArraySize(arr), 1);
	return cJSON_GetArrayItem(arr, 0);
}

static double num(const cJSON *o, const char *key)
{
	const cJSON *it = cJSON_GetObjectItem(o, key);
	assert_true(cJSON_IsNumber(it));
	return it->valuedouble;
}

/* The Monte Carlo yield (fraction) of the load-sharing factor of design document `design`
 * under the robust section's tolerances, by an ordinary study document, and its kept samples. */
static double study_yield(const cJSON *design, size_t *kept)
{
	cJSON *robust = cJSON_Parse(robust_text);
	cJSON *st = cJSON_CreateObject();
	cJSON_AddItemToObject(st, "design", cJSON_Duplicate(design, 1));
	cJSON_AddItemToObject(st, "tolerances", cJSON_DetachItemFromObject(robust, "tolerances"));
	cJSON_AddItemToObject(st, "assembly", cJSON_DetachItemFromObject(robust, "assembly"));
	cJSON_AddItemToObject(st, "monte_carlo", cJSON_DetachItemFromObject(robust, "monte_carlo"));
	cJSON_AddItemToObject(st, "outputs", cJSON_Parse("[\"load_sharing_factor\"]"));
	cJSON_AddItemToObject(st, "specs", cJSON_Parse("{\"load_sharing_factor\": {\"upper\": 1.45}}"));
	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_study_result *r = calloc(1, sizeof *r);
	assert_non_null(s);
	assert_non_null(r);
	prsm_problems p;
	prsm_problems_init(&p);
	int rc = prsm_app_study_load(s, st, NULL, &p);
	if (rc)
		print_error("study: %s %s\n", p.count ? p.items[0].pointer : "", p.count ? p.items[0].message : "");
	assert_int_equal(rc, 0);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(r, &s->study, &err), 0);
	double y = r->out[0].summary.yield;
	*kept = r->out[0].summary.n;
	prsm_study_result_free(r);
	free(r);
	free(s);
	cJSON_Delete(st);
	cJSON_Delete(robust);
	return y;
}

/* The same document twice, and with 2 threads per study: the same result. */
static void test_deterministic(void **state)
{
	(void)state;
	cJSON *doc = make_doc(1);
	cJSON *a = run(doc), *b = run(doc);
	cJSON_AddNumberToObject(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "robust"), "monte_carlo"),
	                        "threads", 2);
	cJSON *c = run(doc);
	/* the echoed thread count aside, identical */
	cJSON_ReplaceItemInObject(cJSON_GetObjectItem(c, "robust"), "threads", cJSON_CreateNumber(1));
	strip_times(a);
	strip_times(b);
	strip_times(c);
	char *ta = cJSON_PrintUnformatted(a), *tb = cJSON_PrintUnformatted(b), *tc = cJSON_PrintUnformatted(c);
	assert_string_equal(ta, tb);
	assert_string_equal(ta, tc);
	free(ta);
	free(tb);
	free(tc);
	cJSON_Delete(a);
	cJSON_Delete(b);
	cJSON_Delete(c);
	cJSON_Delete(doc);
}

/* The constraint binds: the stiffest design misses the yield target (checked by a study of its
 * own), the robust run returns another, less stiff design whose yield, by an independent study
 * document of the returned design, is the reported one and meets the target. */
static void test_binds_and_holds(void **state)
{
	(void)state;
	cJSON *plain_doc = make_doc(0), *doc = make_doc(1);
	cJSON *plain = run(plain_doc), *res = run(doc);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(plain, "feasible")));
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
	assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(res, "violated")), 0);
	const cJSON *pb = cJSON_GetObjectItem(plain, "best"), *rb = cJSON_GetObjectItem(res, "best");
	size_t n_plain = 0, n = 0;
	double y_plain = study_yield(cJSON_GetObjectItem(pb, "design"), &n_plain);
	assert_true(y_plain < 0.99); /* the unconstrained optimum misses the target */
	assert_int_equal(n_plain, 128);

	const cJSON *e = robust_entry(res);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(e, "evaluated")));
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(e, "satisfied")));
	assert_string_equal(cJSON_GetObjectItem(e, "name")->valuestring, "yield_load_sharing_factor");
	double y = study_yield(cJSON_GetObjectItem(rb, "design"), &n);
	assert_int_equal(n, 128);
	assert_int_equal((int)num(e, "samples"), 128);
	assert_int_equal((int)num(e, "seed"), 7);
	assert_true(y >= 0.99);
	assert_close(num(e, "yield_percent"), 100.0 * y, 1e-12);
	assert_true(num(e, "yield_low95_percent") < num(e, "yield_percent"));
	assert_true(num(e, "yield_high95_percent") >= num(e, "yield_percent"));
	assert_close(num(e, "yield_min_percent"), 99.0, 1e-12);

	/* another design, stiffer designs refused */
	double k_plain = num(cJSON_GetObjectItem(pb, "figures"), "stiffness_N_per_um");
	double k_rob = num(cJSON_GetObjectItem(rb, "figures"), "stiffness_N_per_um");
	assert_true(k_rob < k_plain);
	assert_true(num(cJSON_GetObjectItem(rb, "variables"), "rollers") <
	            num(cJSON_GetObjectItem(pb, "variables"), "rollers"));
	/* studies ran for some candidates only (the gate and the cache) */
	const cJSON *sum = cJSON_GetObjectItem(res, "robust");
	assert_true(num(sum, "studies") > 0 && num(sum, "studies") < num(res, "evaluations"));
	assert_int_equal((int)num(sum, "samples_per_study"), 128);
	cJSON_Delete(plain);
	cJSON_Delete(res);
	cJSON_Delete(plain_doc);
	cJSON_Delete(doc);
}

/* A target no design meets: reported infeasible with the robust constraint named. */
static void test_unreachable(void **state)
{
	(void)state;
	cJSON *doc = make_doc(1);
	cJSON *c = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "robust"), "constraints"), 0);
	cJSON_ReplaceItemInObject(cJSON_GetObjectItem(c, "spec"), "upper", cJSON_CreateNumber(1.01));
	cJSON_ReplaceItemInObject(cJSON_GetObjectItem(doc, "solver"), "max_evaluations", cJSON_CreateNumber(200));
	cJSON *res = run(doc);
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(res, "feasible")));
	const cJSON *viol = cJSON_GetObjectItem(res, "violated");
	int named = 0;
	for (const cJSON *it = viol->child; it; it = it->next)
		named |= strcmp(it->valuestring, "yield_load_sharing_factor") == 0;
	assert_true(named);
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(robust_entry(res), "satisfied")));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* Set the cancel flag once progress reaches `at` evaluations. */
typedef struct {
	prsm_cancel_flag *flag;
	size_t at;
} cancel_at;

static void cancel_progress(void *ctx, const prsm_progress *pr)
{
	cancel_at *c = ctx;
	if (pr->done >= c->at)
		*c->flag = 1;
}

/* A cancel after some hundreds of evaluations: the best design found so far is reported as the
 * search evaluated it (not re-evaluated under the cancel, which would stop its study at once
 * and call it infeasible), feasible, each robust constraint evaluated afresh and satisfied, the
 * yield the one an independent study gives and at least the target. */
static void test_cancel(void **state)
{
	(void)state;
	cJSON *doc = make_doc(1);
	static const size_t at[] = {300, 450, 600};
	for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
		prsm_cancel_flag flag = 0;
		cancel_at c = {&flag, at[i]};
		prsm_problems p;
		prsm_problems_init(&p);
		prsm_error err = PRSM_ERROR_INIT;
		cJSON *res = NULL;
		int rc = prsm_app_optimize(&res, doc, &flag, cancel_progress, &c, 0.0, &p, &err);
		assert_int_equal(rc, PRSM_ECANCELLED);
		assert_non_null(res);
		assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "cancelled")));
		assert_string_equal(cJSON_GetObjectItem(res, "stop_reason")->valuestring, "cancelled");
		assert_true(num(res, "evaluations") < 700);
		assert_true(cJSON_IsTrue(cJSON_GetObjectItem(res, "feasible")));
		assert_string_equal(cJSON_GetObjectItem(res, "status")->valuestring, "feasible");
		assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(res, "violated")), 0);
		const cJSON *e = robust_entry(res);
		assert_true(cJSON_IsTrue(cJSON_GetObjectItem(e, "evaluated")));
		assert_true(cJSON_IsTrue(cJSON_GetObjectItem(e, "satisfied")));
		size_t n = 0;
		double y = study_yield(cJSON_GetObjectItem(cJSON_GetObjectItem(res, "best"), "design"), &n);
		assert_true(y >= 0.99);
		assert_close(num(e, "yield_percent"), 100.0 * y, 1e-12);
		const cJSON *cons = cJSON_GetObjectItem(cJSON_GetObjectItem(res, "best"), "constraints");
		for (const cJSON *it = cons->child; it; it = it->next)
			assert_true(cJSON_IsTrue(cJSON_GetObjectItem(it, "satisfied")));
		print_message("cancel at %zu: %g evaluations, %g N/um, yield %.2f %%\n", at[i],
		              num(res, "evaluations"),
		              num(cJSON_GetObjectItem(cJSON_GetObjectItem(res, "best"), "figures"),
		                  "stiffness_N_per_um"),
		              num(e, "yield_percent"));
		cJSON_Delete(res);
	}
	cJSON_Delete(doc);
}

static int has_pointer(const prsm_problems *p, const char *ptr)
{
	for (int i = 0; i < p->count; i++)
		if (strcmp(p->items[i].pointer, ptr) == 0)
			return 1;
	return 0;
}

/* Every problem of the robust section at its pointer in the optimisation document. */
static void test_invalid(void **state)
{
	(void)state;
	cJSON *doc = make_doc(0);
	cJSON_AddItemToObject(doc, "robust", cJSON_Parse(
		"{\"tolerances\": [{\"parameter\": \"screw.colour_um\", \"tol_um\": 2},"
		" {\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": -2},"
		" {\"parameter\": \"screw.runout_um\", \"distribution\": \"uniform\", \"lower\": 3, \"upper\": 1}],"
		" \"assembly\": {\"mode\": \"sideways\"},"
		" \"monte_carlo\": {\"samples\": 5, \"sampler\": \"dice\", \"targets\": []},"
		" \"constraints\": [{\"output\": \"beauty\", \"spec\": {\"upper\": 1}, \"yield_min_percent\": 99},"
		" {\"output\": \"backlash_um\", \"spec\": {\"lower\": 30, \"upper\": 5}, \"yield_min_percent\": 100}],"
		" \"surrogate\": \"magic\", \"extra\": 1}"));
	prsm_problems w, p;
	prsm_problems_init(&w);
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
	const char *want[] = {"/robust/extra", "/robust/surrogate", "/robust/monte_carlo/samples",
	                      "/robust/monte_carlo/targets", "/robust/constraints/0/output",
	                      "/robust/constraints/1/spec/upper",
	                      "/robust/constraints/1/yield_min_percent", NULL};
	for (int i = 0; want[i]; i++) {
		if (!has_pointer(&p, want[i]))
			print_error("missing a problem at %s\n", want[i]);
		assert_true(has_pointer(&p, want[i]));
	}
	/* the tolerance set's own problems, once the section's shape is right */
	cJSON_ReplaceItemInObject(doc, "robust", cJSON_Parse(
		"{\"tolerances\": [{\"parameter\": \"screw.colour_um\", \"tol_um\": 2},"
		" {\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": -2},"
		" {\"parameter\": \"screw.runout_um\", \"distribution\": \"uniform\", \"lower\": 3, \"upper\": 1}],"
		" \"correlations\": [{\"between\": [\"nut.pitch_radius_um\", \"roller.nothing_um\"], \"rho\": 0.5}],"
		" \"assembly\": {\"mode\": \"sideways\"},"
		" \"monte_carlo\": {\"sampler\": \"dice\"},"
		" \"constraints\": [{\"output\": \"backlash_um\", \"spec\": {\"lower\": 5}, \"yield_min_percent\": 99}]}"));
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
	const char *want2[] = {"/robust/tolerances/0/parameter", "/robust/tolerances/1/tol_um",
	                       "/robust/tolerances/2", "/robust/assembly/mode",
	                       "/robust/monte_carlo/sampler", "/robust/correlations/0/between/1", NULL};
	for (int i = 0; want2[i]; i++) {
		if (!has_pointer(&p, want2[i]))
			print_error("missing a problem at %s\n", want2[i]);
		assert_true(has_pointer(&p, want2[i]));
	}
	/* no tolerances; load sharing without an operating load */
	cJSON_ReplaceItemInObject(doc, "robust", cJSON_Parse(
		"{\"constraints\": [{\"output\": \"backlash_um\", \"spec\": {\"lower\": 5}, \"yield_min_percent\": 99}]}"));
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_optimization_check(doc, 0, &w, &p), PRSM_EINVAL);
	assert_true(has_pointer(&p, "/robust/tolerances"));
	cJSON_Delete(doc);
}

/* The stand-ins: none is the Monte Carlo yield; kernel and normal close to it; probit margins. */
static void test_surrogates(void **state)
{
	(void)state;
	cJSON *st = cJSON_Parse(
		"{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1, 1], \"constant\": 0},"
		" \"tolerances\": [{\"parameter\": \"x1\", \"distribution\": \"normal\", \"sd\": 1},"
		" {\"parameter\": \"x2\", \"distribution\": \"normal\", \"sd\": 1}],"
		" \"monte_carlo\": {\"samples\": 4096, \"seed\": 11, \"sampler\": \"lhs\"},"
		" \"sensitivity\": {\"src\": false, \"stack\": false}}");
	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_study_result *r = calloc(1, sizeof *r);
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_study_load(s, st, NULL, &p), 0);
	/* y = x1 + x2 ~ N(0, 2): the spec [-2.385, 2.385] holds 92.2 % */
	prsm_robust_constraint c = {"y", {1, 1, -2.385, 2.385}, 0.9};
	s->study.outputs[0].has_spec = 1;
	s->study.outputs[0].spec = c.spec;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(r, &s->study, &err), 0);
	prsm_robust_value v[3];
	for (int k = 0; k < 3; k++)
		assert_int_equal(prsm_robust_value_of(&v[k], &s->study, r, 0, &c, (prsm_robust_surrogate)k, &err), 0);
	const double exact = 2.0 * gsl_cdf_ugaussian_P(2.385 / sqrt(2.0)) - 1.0;
	assert_close(v[PRSM_ROBUST_NONE].smooth_yield, v[PRSM_ROBUST_NONE].yield, 0.0);
	assert_close(v[PRSM_ROBUST_KERNEL].smooth_yield, v[0].yield, 0.01);
	assert_close(v[PRSM_ROBUST_NORMAL].smooth_yield, exact, 0.01);
	assert_close(v[0].yield, exact, 0.01);
	assert_close(v[0].g, 0.9 - v[0].yield, 1e-15);
	assert_close(v[PRSM_ROBUST_NORMAL].g_solver,
	             gsl_cdf_ugaussian_Pinv(0.9) - gsl_cdf_ugaussian_Pinv(v[PRSM_ROBUST_NORMAL].normal_yield), 1e-12);
	assert_true(v[0].g < 0.0 && v[0].g_solver < 0.0); /* 92 % meets 90 % */
	prsm_study_result_free(r);
	free(r);
	free(s);
	cJSON_Delete(st);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_surrogates),
		cmocka_unit_test(test_invalid),
		cmocka_unit_test(test_deterministic),
		cmocka_unit_test(test_binds_and_holds),
		cmocka_unit_test(test_unreachable),
		cmocka_unit_test(test_cancel),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
