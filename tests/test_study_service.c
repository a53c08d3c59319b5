/*
 * test_study_service.c: whole studies run by a study service (mc/study.h prsm_study_service,
 * what src/par does over the ranks of an MPI job), without MPI. The service here does what every
 * other rank does: it loads the study document it is handed with the study reader, takes the
 * caller's settings into it (prsm_study_adopt) and runs that study. Case A's allocation and its
 * robust optimisation through it give the results they give without it (elapsed times aside),
 * with every Monte Carlo correction and every robust study handed to the service with the study
 * document; prsm_study_adopt refuses a study of another size.
 */
#include "test_support.h"

#include "app/allocate.h"
#include "app/optimize.h"
#include "io/global.h"
#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"

typedef struct {
	int calls;
	int sources_seen;            /* calls whose source parsed as a document with tolerances */
} counter;

/* The service: load the source as a fresh study, adopt the caller's settings, run it. */
static int reload_and_run(prsm_study_result *r, const prsm_study *s, const char *source, size_t source_len, void *ctx,
                          prsm_error *err)
{
	counter *c = ctx;
	c->calls++;
	prsm_problems *pr = malloc(sizeof *pr);
	prsm_io_study *fresh = calloc(1, sizeof *fresh);
	assert_non_null(pr);
	assert_non_null(fresh);
	prsm_problems_init(pr);
	cJSON *doc = prsm_json_parse(source, source_len, pr);
	assert_non_null(doc);
	c->sources_seen += cJSON_GetObjectItemCaseSensitive(doc, "tolerances") != NULL;
	assert_int_equal(prsm_app_study_load(fresh, doc, NULL, pr), 0);
	cJSON_Delete(doc);
	assert_int_equal(prsm_study_adopt(&fresh->study, s, err), 0);
	int rc = prsm_study_run(r, &fresh->study, err);
	free(fresh);
	free(pr);
	return rc;
}

/* The document printed without its elapsed times. */
static void drop_elapsed(cJSON *v)
{
	if (!cJSON_IsObject(v) && !cJSON_IsArray(v))
		return;
	cJSON_DeleteItemFromObjectCaseSensitive(v, "elapsed_s");
	for (cJSON *c = v->child; c; c = c->next)
		drop_elapsed(c);
}

static char *printed(cJSON *res)
{
	drop_elapsed(res);
	char *text = cJSON_PrintUnformatted(res);
	assert_non_null(text);
	return text;
}

static void test_allocation(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("allocate-case-a.json");
	cJSON *mc = cJSON_GetObjectItemCaseSensitive(doc, "monte_carlo");
	cJSON_ReplaceItemInObject(mc, "samples", cJSON_CreateNumber(2048));
	cJSON_ReplaceItemInObject(mc, "max_corrections", cJSON_CreateNumber(4));
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *plain = NULL, *served = NULL;
	assert_int_equal(prsm_app_allocate(&plain, doc, NULL, NULL, NULL, 0.0, 1, &pr, &err), 0);
	counter c = {0, 0};
	const prsm_study_service svc = {reload_and_run, &c};
	assert_int_equal(prsm_app_allocate_with(&served, doc, NULL, NULL, NULL, 0.0, 1, &svc, &pr, &err), 0);
	/* every correction went to the service with the study document */
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(plain, "monte_carlo");
	const double total = cJSON_GetObjectItemCaseSensitive(m, "samples_total")->valuedouble;
	assert_int_equal(c.calls, (int)(total / 2048.0));
	assert_true(c.calls >= 2);
	assert_int_equal(c.sources_seen, c.calls);
	char *a = printed(plain), *b = printed(served);
	assert_string_equal(a, b);
	cJSON_free(a);
	cJSON_free(b);
	cJSON_Delete(plain);
	cJSON_Delete(served);
	cJSON_Delete(doc);
}

static void test_robust_optimisation(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("optimize-case-a-robust.json");
	cJSON *rmc = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "robust"), "monte_carlo");
	cJSON_ReplaceItemInObject(rmc, "samples", cJSON_CreateNumber(128));
	cJSON_AddNumberToObject(rmc, "block_size", 32);
	cJSON *solver = cJSON_GetObjectItemCaseSensitive(doc, "solver");
	cJSON_ReplaceItemInObject(solver, "max_evaluations", cJSON_CreateNumber(120));
	cJSON_ReplaceItemInObject(solver, "multistart", cJSON_CreateNumber(1));
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *plain = NULL, *served = NULL;
	assert_int_equal(prsm_app_optimize(&plain, doc, NULL, NULL, NULL, 0.0, &pr, &err), 0);
	counter c = {0, 0};
	const prsm_study_service svc = {reload_and_run, &c};
	assert_int_equal(prsm_app_optimize_with(&served, doc, NULL, NULL, NULL, 0.0, &svc, &pr, &err), 0);
	const cJSON *rob = cJSON_GetObjectItemCaseSensitive(plain, "robust");
	const int studies = (int)cJSON_GetObjectItemCaseSensitive(rob, "studies")->valuedouble;
	assert_true(studies >= 2);
	assert_true(c.calls >= studies); /* the search's studies and the reported point's fresh re-run */
	assert_int_equal(c.sources_seen, c.calls);
	char *a = printed(plain), *b = printed(served);
	assert_string_equal(a, b);
	cJSON_free(a);
	cJSON_free(b);
	cJSON_Delete(plain);
	cJSON_Delete(served);
	cJSON_Delete(doc);
}

static void test_adopt_refuses_other_sizes(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("case-a-tolerances.json");
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_io_study *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
	assert_non_null(a);
	assert_non_null(b);
	assert_int_equal(prsm_app_study_load(a, doc, NULL, &pr), 0);
	assert_int_equal(prsm_app_study_load(b, doc, NULL, &pr), 0);
	prsm_error err = PRSM_ERROR_INIT;
	/* the same document: taken, the model and pointers kept */
	const prsm_mc_model model = b->study.model;
	a->study.mc.seed = 12345;
	assert_int_equal(prsm_study_adopt(&b->study, &a->study, &err), 0);
	assert_int_equal(b->study.mc.seed, 12345);
	assert_ptr_equal(b->study.model.ctx, model.ctx);
	/* another size: refused */
	a->study.d--;
	assert_int_equal(prsm_study_adopt(&b->study, &a->study, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "variables"));
	free(a);
	free(b);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_allocation),
		cmocka_unit_test(test_robust_optimisation),
		cmocka_unit_test(test_adopt_refuses_other_sizes),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
