/*
 * test_rating_io.c: issue 18 through the analyze request (src/io/analyze_request.c): a
 * catalogue size analysed with no geometry field, echoed with its alternatives; its problems at
 * the nominal member the user wrote; both rating conventions and the truncation warning in the
 * result; the wrong-kind message for a study or an optimisation; problem documents whose
 * detail never starts with ": " (src/io/analysis_json.c).
 */
#include "test_support.h"

#include "io/analysis_json.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/json_util.h"

#include <string.h>

static cJSON *parse(const char *text)
{
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = prsm_json_parse(text, strlen(text), &p);
	assert_non_null(doc);
	return doc;
}

static const cJSON *at(const cJSON *o, const char *a, const char *b, const char *c)
{
	const cJSON *x = cJSON_GetObjectItemCaseSensitive(o, a);
	if (b)
		x = cJSON_GetObjectItemCaseSensitive(x, b);
	if (c)
		x = cJSON_GetObjectItemCaseSensitive(x, c);
	assert_non_null(x);
	return x;
}

static double num(const cJSON *o, const char *a, const char *b, const char *c)
{
	const cJSON *x = at(o, a, b, c);
	assert_true(cJSON_IsNumber(x));
	return x->valuedouble;
}

/* {"nominal": {"diameter_mm": 30, "lead_mm": 10}} analyses alone: the resolution (MODEL.md §1:
 * 5 starts, P 2, r_r 5, r_n 25), the same design as the explicit geometry (bit for bit), the
 * alternatives 3 to 6 starts with the spread of their ratings. */
static void test_catalogue_size(void **state)
{
	(void)state;
	cJSON *doc = parse("{\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 10}}");
	cJSON *out = NULL;
	prsm_problems problems;
	prsm_problems_init(&problems);
	assert_int_equal(prsm_app_analyze(&out, doc, &problems), 0);
	assert_int_equal(problems.count, 0);
	assert_close(num(out, "nominal", "pitch_mm", NULL), 2.0, 0.0);
	assert_close(num(out, "nominal", "roller_radius_mm", NULL), 5.0, 0.0);
	assert_close(num(out, "nominal", "nut_radius_mm", NULL), 25.0, 0.0);
	assert_close(num(out, "design", "geometry", "screw_radius_mm"), 15.0, 1e-12);
	const int Z = (int)num(out, "design", "geometry", "rollers");
	const int nt = (int)num(out, "design", "geometry", "engaged_threads");
	assert_int_equal(nt, 15);
	const cJSON *alts = at(out, "nominal", "alternatives", NULL);
	assert_int_equal(cJSON_GetArraySize(alts), 4);
	double lo = INFINITY, hi = 0.0;
	for (int i = 0; i < 4; i++) {
		const cJSON *a = cJSON_GetArrayItem(alts, i);
		assert_int_equal((int)num(a, "starts", NULL, NULL), 3 + i);
		assert_true(cJSON_IsTrue(at(a, "valid", NULL, NULL)));
		assert_close(num(a, "pitch_mm", NULL, NULL), 10.0 / (3 + i), 1e-15);
		const double Ca = num(a, "makers_C_a_N", NULL, NULL);
		lo = fmin(lo, Ca);
		hi = fmax(hi, Ca);
	}
	/* the spread a "30 x 10" leaves open: 3 starts rate about 2.5 x the 6-start C_a */
	assert_true(hi / lo > 2.0);
	/* the 5-start alternative is the analysis itself */
	const cJSON *five = cJSON_GetArrayItem(alts, 2);
	assert_close(num(five, "makers_C_a_N", NULL, NULL),
	             num(at(out, "capacity", "ratings", "makers_convention"), "C_a_N", NULL, NULL), 0.0);

	/* the same design written out gives the same ratings, bit for bit */
	char text[512];
	snprintf(text, sizeof text,
	         "{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 5, \"rollers\": %d, "
	         "\"engaged_threads\": %d}}", Z, nt);
	cJSON *doc2 = parse(text), *out2 = NULL;
	assert_int_equal(prsm_app_analyze(&out2, doc2, &problems), 0);
	const char *keys[] = {"C0a_N", "C_a_N", "C0a_over_C_a"};
	for (int k = 0; k < 3; k++) {
		assert_true(num(at(out, "capacity", "ratings", "makers_convention"), keys[k], NULL, NULL) ==
		            num(at(out2, "capacity", "ratings", "makers_convention"), keys[k], NULL, NULL));
		assert_true(num(at(out, "capacity", "ratings", "load_distribution"), keys[k], NULL, NULL) ==
		            num(at(out2, "capacity", "ratings", "load_distribution"), keys[k], NULL, NULL));
	}
	assert_null(cJSON_GetObjectItemCaseSensitive(out2, "nominal"));
	cJSON_Delete(out2);
	cJSON_Delete(doc2);
	cJSON_Delete(out);
	cJSON_Delete(doc);
}

/* Problems of a catalogue size at what the user wrote: a lead of 200 mm on 30 mm is a 40 mm
 * pitch, whose default roots fail: /nominal/lead_mm, not /geometry/pitch_mm (never written);
 * a geometry member the size sets is a conflict at that member; a missing lead is required. */
static void test_catalogue_problems(void **state)
{
	(void)state;
	const struct {
		const char *doc, *pointer;
	} cases[] = {
		{"{\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 200}}", "/nominal/lead_mm"},
		{"{\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 10}, \"geometry\": {\"rollers\": 9}}", "/geometry/rollers"},
		{"{\"nominal\": {\"diameter_mm\": 30}}", "/nominal/lead_mm"},
		{"{\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 10, \"starts\": 2}}", "/nominal/starts"},
		{"{\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 10, \"pitch_mm\": 2}}", "/nominal/pitch_mm"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cJSON *doc = parse(cases[i].doc), *out = NULL;
		prsm_problems problems;
		prsm_problems_init(&problems);
		assert_int_not_equal(prsm_app_analyze(&out, doc, &problems), 0);
		assert_null(out);
		assert_true(problems.count >= 1);
		int found = 0;
		for (int k = 0; k < problems.count; k++) {
			found |= strcmp(problems.items[k].pointer, cases[i].pointer) == 0;
			assert_null(strstr(problems.items[k].pointer, "/geometry/pitch_mm"));
		}
		if (!found)
			print_error("%s: no problem at %s (first: %s %s)\n", cases[i].doc, cases[i].pointer,
			            problems.items[0].pointer, problems.items[0].message);
		assert_true(found);
		cJSON_Delete(doc);
	}
}

/* A study, an optimisation, an allocation given to analyze: one problem that names the command. */
static void test_wrong_kind(void **state)
{
	(void)state;
	const char *docs[][2] = {
		{"{\"design\": {}, \"tolerances\": [], \"outputs\": []}", "prsm study"},
		{"{\"design\": {}, \"variables\": {}, \"objectives\": []}", "prsm optimize"},
		{"{\"allocate\": [], \"study\": {}}", "prsm allocate"},
	};
	for (int i = 0; i < 3; i++) {
		cJSON *doc = parse(docs[i][0]), *out = NULL;
		prsm_problems problems;
		prsm_problems_init(&problems);
		assert_int_equal(prsm_app_analyze(&out, doc, &problems), PRSM_EINVAL);
		assert_int_equal(problems.count, 1);
		assert_string_equal(problems.items[0].code, "wrong_kind");
		assert_non_null(strstr(problems.items[0].message, docs[i][1]));
		/* its problem document: the detail is the message, without a leading ": " */
		cJSON *pd = prsm_io_problem_document(400, "invalid request", &problems);
		const cJSON *detail = cJSON_GetObjectItemCaseSensitive(pd, "detail");
		assert_true(cJSON_IsString(detail));
		assert_true(strncmp(detail->valuestring, ": ", 2) != 0);
		assert_string_equal(detail->valuestring, problems.items[0].message);
		cJSON_Delete(pd);
		cJSON_Delete(doc);
	}
	/* a problem with a pointer keeps "pointer: message" */
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_problems_add(&p, "/geometry/pitch_mm", "range", "must be > 0");
	cJSON *pd = prsm_io_problem_document(400, "invalid request", &p);
	assert_string_equal(cJSON_GetObjectItemCaseSensitive(pd, "detail")->valuestring, "/geometry/pitch_mm: must be > 0");
	cJSON_Delete(pd);
}

/* The 48 x 5 of issue 18 in the result: makers' C_0a/C_a above 1, prsm's C_0a limited by the
 * truncation, the warning in the list, the truncation section consistent with it. */
static void test_result_48x5(void **state)
{
	(void)state;
	cJSON *doc = parse("{\"nominal\": {\"diameter_mm\": 48, \"lead_mm\": 5}, "
	                   "\"operating_point\": {\"axial_load_N\": 31700}}");
	cJSON *out = NULL;
	prsm_problems problems;
	prsm_problems_init(&problems);
	assert_int_equal(prsm_app_analyze(&out, doc, &problems), 0);
	const cJSON *m = at(out, "capacity", "ratings", "makers_convention");
	assert_true(num(m, "C0a_over_C_a", NULL, NULL) > 1.0);
	assert_true(cJSON_IsTrue(at(m, "truncated_at_C0a", NULL, NULL)));
	assert_string_equal(at(out, "capacity", "static", "limited_by")->valuestring, "ellipse_truncation");
	const double C0a = num(out, "capacity", "static", "C0a_N");
	assert_true(C0a < num(out, "capacity", "static", "pressure_limited_N"));
	assert_close(num(at(out, "capacity", "ratings", "load_distribution"), "C0a_N", NULL, NULL), C0a, 0.0);
	int warned = 0;
	for (const cJSON *w = at(out, "warnings", NULL, NULL)->child; w; w = w->next)
		warned |= strcmp(cJSON_GetObjectItemCaseSensitive(w, "code")->valuestring, "ellipse_truncation") == 0 &&
		          strcmp(cJSON_GetObjectItemCaseSensitive(w, "pointer")->valuestring, "/nominal/lead_mm") == 0;
	assert_true(warned);
	cJSON_Delete(out);
	cJSON_Delete(doc);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_catalogue_size),
		cmocka_unit_test(test_catalogue_problems),
		cmocka_unit_test(test_wrong_kind),
		cmocka_unit_test(test_result_48x5),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
