/*
 * test_io_write.c: the generic table writer (io/write.h) and the result writers on it.
 *
 * A hand-made table shows every kind of field; then every cJSON allocation of each result
 * writer is made to fail in turn (the n-th, n = 1, 2, ... until the writer needs fewer): the
 * writer must give no document at all each time, and the reference otherwise. LeakSanitizer
 * stays on (make test-asan): nothing the writers made may leak on any of those paths.
 */
#include "test_support.h"

#include "io/analysis_json.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/assembly_json.h"
#include "io/global.h"
#include "app/study.h"
#include "io/study_json.h"
#include "io/write.h"
#include "mc/study.h"

/* ---- the kinds of field ---------------------------------------------------------------- */

typedef struct {
	double x, v[3];
	int n, flags, kind, on;
	size_t z;
	char name[8];
	const char *label;
	const double *pv;
	int count;
} inner;

typedef struct {
	inner in;
	const inner *p;
	const inner *none;
	double col_a[2], col_b[2];
} outer;

static void hook_twice(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_number(w, obj, key, 2.0 * *(const double *)at);
}

static const char *const kind_names[] = {"one", "two"};
static const int kind_values[] = {1, 2};

static const prsm_io_wfield tuple_fields[] = {
	{.name = NULL, .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(inner, v[2])}},
	{.name = NULL, .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(inner, n)}},
};
static const prsm_io_wtable tuple_table = {tuple_fields, 2};

static const prsm_io_wfield inner_fields[] = {
	{.name = "x_um", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(inner, x)}, .scale = 1000.0},
	{.name = "x_half", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(inner, x)}, .divide = 2.0},
	{.name = "n", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(inner, n)}},
	{.name = "z", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_SIZE, .at = {.offset = offsetof(inner, z)}},
	{.name = "bit4", .kind = PRSM_IO_W_BOOL, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(inner, flags)}, .mask = 4},
	{.name = "constant", .kind = PRSM_IO_W_BOOL, .mask = 0},
	{.name = "kind", .kind = PRSM_IO_W_ENUM, .at = {.offset = offsetof(inner, kind)}, .names = kind_names, .values = kind_values, .n_values = 2, .text = "other"},
	{.name = "flags", .kind = PRSM_IO_W_FLAGS, .at = {.offset = offsetof(inner, flags)}, .names = kind_names, .values = kind_values, .n_values = 2},
	{.name = "name", .kind = PRSM_IO_W_STRING, .type = PRSM_IO_W_CHARS, .at = {.offset = offsetof(inner, name)}},
	{.name = "label", .kind = PRSM_IO_W_STRING, .type = PRSM_IO_W_CSTR, .at = {.offset = offsetof(inner, label)}},
	{.name = "text", .kind = PRSM_IO_W_TEXT, .text = "as it is"},
	{.name = "v", .kind = PRSM_IO_W_ARRAY, .type = PRSM_IO_W_DOUBLE, .count = 3, .at = {.offset = offsetof(inner, v), .stride = sizeof(double)}},
	{.name = "pv", .kind = PRSM_IO_W_ARRAY, .type = PRSM_IO_W_DOUBLE, .count_type = PRSM_IO_W_INT, .count_at = {.offset = offsetof(inner, count)},
	 .at = {.offset = offsetof(inner, pv), .pointer = 1, .stride = sizeof(double)}, .scale = 10.0},
	{.name = "tuple", .kind = PRSM_IO_W_ARRAY, .shape = PRSM_IO_W_TUPLE, .child = &tuple_table},
	{.name = "twice", .kind = PRSM_IO_W_HOOK, .hook = hook_twice, .at = {.offset = offsetof(inner, x)}},
	{.name = "if_on", .kind = PRSM_IO_W_TEXT, .text = "on", .when = PRSM_IO_W_IF, .when_type = PRSM_IO_W_INT, .when_at = {.offset = offsetof(inner, on)}},
	{.name = "if_off", .kind = PRSM_IO_W_TEXT, .text = "off", .when = PRSM_IO_W_IF_NOT, .when_type = PRSM_IO_W_INT, .when_at = {.offset = offsetof(inner, on)}, .else_null = 1},
	{.name = "if_kind_2", .kind = PRSM_IO_W_TEXT, .text = "two", .when = PRSM_IO_W_IF_IS, .when_value = 2, .when_type = PRSM_IO_W_INT, .when_at = {.offset = offsetof(inner, kind)}},
	{.name = "if_x", .kind = PRSM_IO_W_TEXT, .text = "x is a number", .when = PRSM_IO_W_IF, .when_type = PRSM_IO_W_DOUBLE, .when_at = {.offset = offsetof(inner, x)}},
};
static const prsm_io_wtable inner_table = {inner_fields, sizeof inner_fields / sizeof inner_fields[0]};

static const prsm_io_wfield n_fields[] = {
	{.name = "n", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(inner, n)}},
};
static const prsm_io_wtable n_table = {n_fields, 1};

static const prsm_io_wfield row_fields[] = {
	{.name = "a", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(outer, col_a[0]), .stride = sizeof(double)}},
	{.name = "b", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(outer, col_b[0]), .stride = sizeof(double)},
	 .when = PRSM_IO_W_IF_ROW, .when_value = 1},
};
static const prsm_io_wtable row_table = {row_fields, 2};

static const prsm_io_wfield outer_fields[] = {
	{.name = "in", .kind = PRSM_IO_W_OBJECT, .child = &inner_table, .at = {.offset = offsetof(outer, in)}},
	{.name = "p_n", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(outer, p), .deref = 1, .offset2 = offsetof(inner, n)}},
	{.name = "none_n", .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_INT, .at = {.offset = offsetof(outer, none), .deref = 1, .offset2 = offsetof(inner, n)}},
	{.name = "none", .kind = PRSM_IO_W_OBJECT, .child = &inner_table, .at = {.offset = offsetof(outer, none), .pointer = 1}},
	{.name = "rows", .kind = PRSM_IO_W_ARRAY, .shape = PRSM_IO_W_ROWS, .count = 2, .child = &row_table},
	{.name = "structs", .kind = PRSM_IO_W_ARRAY, .shape = PRSM_IO_W_STRUCTS, .count = 1, .child = &n_table,
	 .at = {.offset = offsetof(outer, p), .pointer = 1, .stride = sizeof(inner)}},
};
static const prsm_io_wtable outer_table = {outer_fields, sizeof outer_fields / sizeof outer_fields[0]};

static void test_kinds(void **state)
{
	(void)state;
	const double pv[2] = {0.5, NAN};
	outer o = {.in = {.x = 0.25, .v = {1, 2, 3}, .n = 7, .flags = 6, .kind = 3, .on = 1, .z = 9, .name = "abc",
	                  .label = "lbl", .pv = pv, .count = 2},
	           .col_a = {1, 2}, .col_b = {3, 4}};
	inner p = {.n = 42, .v = {0, 0, 8}, .x = NAN};
	o.p = &p;
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	prsm_io_write_fields(&w, root, &o, &outer_table, 0);
	root = prsm_jw_done(&w, root);
	assert_non_null(root);
	char *text = cJSON_PrintUnformatted(root);
	assert_string_equal(text,
	    "{\"in\":{\"x_um\":250,\"x_half\":0.125,\"n\":7,\"z\":9,\"bit4\":true,\"constant\":false,\"kind\":\"other\","
	    "\"flags\":[\"two\"],\"name\":\"abc\",\"label\":\"lbl\",\"text\":\"as it is\",\"v\":[1,2,3],\"pv\":[5,null],"
	    "\"tuple\":[3,7],\"twice\":0.5,\"if_on\":\"on\",\"if_off\":null,\"if_x\":\"x is a number\"},"
	    "\"p_n\":42,\"rows\":[{\"a\":1},{\"a\":2,\"b\":4}],\"structs\":[{\"n\":42}]}");
	cJSON_free(text);
	cJSON_Delete(root);
}

/* Out of memory at once: nothing, and the writer's state says so. */
static void test_sticky(void **state)
{
	(void)state;
	prsm_jw w = PRSM_JW_INIT;
	cJSON *arr = cJSON_CreateArray();
	prsm_jw_number(&w, NULL, "lost", 1.0);
	assert_true(w.failed);
	prsm_jw_number(&w, arr, NULL, 1.0);
	assert_null(prsm_jw_done(&w, arr));
}

/* ---- every allocation of the result writers failing in turn --------------------------------- */

typedef cJSON *(*writer_fn)(const void *ctx);

/* The number of runs with a failure injected. */
static int sweep(writer_fn build, const void *ctx)
{
	cJSON *ref = build(ctx);
	assert_non_null(ref);
	char *reference = cJSON_PrintUnformatted(ref);
	cJSON_Delete(ref);
	for (long n = 1;; n++) {
		const unsigned long before = prsm_json_alloc_failures();
		prsm_json_inject_alloc_failure(n);
		cJSON *doc = build(ctx);
		prsm_json_inject_alloc_failure(0);
		if (prsm_json_alloc_failures() == before) {
			char *text = cJSON_PrintUnformatted(doc);
			assert_string_equal(text, reference);
			cJSON_free(text);
			cJSON_Delete(doc);
			cJSON_free(reference);
			return (int)n - 1;
		}
		assert_null(doc); /* never a partial document */
	}
}

static cJSON *build_analysis(const void *ctx)
{
	const prsm_analyze_request *rq = ctx;
	prsm_problems none;
	prsm_problems_init(&none);
	prsm_problems_add(&none, "/geometry/rollers", "rule", "a warning");
	return prsm_io_analysis_to_json(&rq->a, &rq->d, &rq->perf, &none);
}

static cJSON *build_assembly(const void *ctx)
{
	const prsm_analyze_request *rq = ctx;
	return prsm_io_assembly_to_json(&rq->report, &rq->as, &rq->options, rq->ws);
}

static cJSON *build_multistage(const void *ctx)
{
	const prsm_analyze_request *rq = ctx;
	prsm_problems none;
	prsm_problems_init(&none);
	return prsm_io_multistage_to_json(rq->ms, rq->ms_perf, &none);
}

static prsm_analyze_request *analyse(const char *study, int curve)
{
	cJSON *doc = prsm_test_read_study(study);
	cJSON *as = cJSON_GetObjectItemCaseSensitive(doc, "assembly");
	if (as && curve)
		cJSON_AddTrueToObject(as, "curve");
	prsm_analyze_request *rq = calloc(1, sizeof *rq);
	assert_non_null(rq);
	prsm_problems pr, warnings;
	prsm_problems_init(&pr);
	prsm_problems_init(&warnings);
	assert_int_equal(prsm_app_analyze_load(rq, doc, &warnings, &pr), 0);
	cJSON_Delete(doc);
	assert_int_equal(prsm_app_analyze_run(rq), 0);
	return rq;
}

static void test_analysis_oom(void **state)
{
	(void)state;
	prsm_analyze_request *rq = analyse("case-a-measured.json", 1);
	int a = sweep(build_analysis, rq), b = sweep(build_assembly, rq);
	print_message("analysis: %d allocations failed in turn, assembly %d\n", a, b);
	assert_true(a > 100 && b > 100);
	prsm_io_analyze_free(rq);
	free(rq);
	rq = analyse("seed000-two-stage.json", 0);
	assert_true(rq->multistage);
	assert_true(sweep(build_multistage, rq) > 200);
	prsm_io_analyze_free(rq);
	free(rq);
}

typedef struct {
	prsm_io_study *s;
	prsm_study_result *r;
} study_ctx;

static cJSON *build_study(const void *ctx)
{
	const study_ctx *c = ctx;
	return prsm_io_study_result_to_json(c->s, c->r);
}

static void test_study_oom(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse("{\"name\": \"g\", \"model\": {\"benchmark\": \"linear\", \"coefficients\": [1, -2, 0.5]},"
	                         " \"tolerances\": [{\"parameter\": \"x1\", \"tol\": 1, \"cpk\": 1},"
	                         "  {\"parameter\": \"x2\", \"distribution\": \"truncnormal\", \"mean\": 0, \"sd\": 1, \"lower\": -1, \"upper\": 2},"
	                         "  {\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": -1, \"upper\": 1}],"
	                         " \"specs\": {\"y\": {\"lower\": -2}},"
	                         " \"monte_carlo\": {\"samples\": 256, \"block_size\": 64},"
	                         " \"sensitivity\": {\"src\": true, \"stack\": true, \"sobol\": {\"samples\": 64, \"bootstrap\": 10}}}");
	assert_non_null(doc);
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), 0);
	cJSON_Delete(doc);
	prsm_study_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(&r, &s->study, &err), 0);
	study_ctx c = {s, &r};
	assert_true(sweep(build_study, &c) > 100);
	prsm_study_result_free(&r);
	free(s);
}

static cJSON *build_problem_document(const void *ctx)
{
	return prsm_io_problem_document(422, "Unprocessable Content", ctx);
}

static void test_problems_oom(void **state)
{
	(void)state;
	prsm_problems p;
	prsm_problems_init(&p);
	for (int i = 0; i < PRSM_PROBLEMS_MAX + 3; i++)
		prsm_problems_add(&p, "/a", i % 2 ? "" : "code", "problem %d", i);
	assert_true(sweep(build_problem_document, &p) > 100);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_kinds),
		cmocka_unit_test(test_sticky),
		cmocka_unit_test(test_analysis_oom),
		cmocka_unit_test(test_study_oom),
		cmocka_unit_test(test_problems_oom),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
