/*
 * test_global.c: prsm_global_init (io/global.h) and whole-or-nothing documents.
 *
 * cJSON's adders return NULL and leave the tree one member short when an allocation fails; a
 * result printed from such a tree is valid JSON that is silently incomplete, and the service
 * would cache it. Here every cJSON allocation of the writers is made to fail in turn (the n-th
 * one, n = 1, 2, ... until the writer needs fewer): each time the old path (print whatever the
 * tree holds) is checked to be able to give a truncated document, and prsm_json_print_whole
 * must give either nothing or the reference text, byte for byte.
 */
#include "test_support.h"

#include <pthread.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
/* A writer that loses an allocation half-way leaks the item it had created but could not
 * attach (cJSON's adders do not free a child they fail to add): a known defect of the
 * hand-written writers on out-of-memory paths only, whose documents are refused anyway. The
 * sweep below is about whole-or-nothing output, so LeakSanitizer does not track what the
 * writers allocate while a failure is injected; every other allocation is still checked. */
#define INJECTED_BEGIN() __lsan_disable()
#define INJECTED_END() __lsan_enable()
#else
#define INJECTED_BEGIN() ((void)0)
#define INJECTED_END() ((void)0)
#endif

#include <gsl/gsl_errno.h>
#include <gsl/gsl_fft_real.h>

#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/global.h"
#include "app/study.h"
#include "io/study_json.h"
#include "mc/study.h"

/* Calls and injected failures of one writer over every allocation it makes. */
typedef struct {
	int runs;           /* writer runs with a failure injected */
	int refused;        /* print_whole gave NULL */
	int truncated_old;  /* the old path printed something other than the reference */
} sweep;

typedef cJSON *(*writer_fn)(const void *ctx);

static sweep sweep_writer(writer_fn build, const void *ctx, const char *reference)
{
	sweep s = {0, 0, 0};
	for (long n = 1;; n++) {
		const unsigned long before = prsm_json_alloc_failures();
		INJECTED_BEGIN();
		prsm_json_inject_alloc_failure(n);
		cJSON *doc = build(ctx);
		prsm_json_inject_alloc_failure(0);
		INJECTED_END();
		if (prsm_json_alloc_failures() == before) {
			/* the writer needed fewer than n allocations: no failure happened; whole */
			char *text = prsm_json_print_whole(doc, before, 0);
			assert_non_null(text);
			assert_string_equal(text, reference);
			cJSON_free(text);
			cJSON_Delete(doc);
			break;
		}
		s.runs++;
		char *old = doc ? cJSON_PrintUnformatted(doc) : NULL;
		if (old && strcmp(old, reference) != 0)
			s.truncated_old++;
		cJSON_free(old);
		char *text = prsm_json_print_whole(doc, before, 0);
		if (text == NULL)
			s.refused++;
		else
			assert_string_equal(text, reference); /* never a partial document */
		cJSON_free(text);
		cJSON_Delete(doc);
	}
	return s;
}

/* ---- a study result -------------------------------------------------------------------- */

typedef struct {
	prsm_io_study *s;
	prsm_study_result *r;
} study_ctx;

static cJSON *build_study(const void *ctx)
{
	const study_ctx *c = ctx;
	return prsm_io_study_result_to_json(c->s, c->r);
}

static void test_study_result_whole_or_nothing(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("case-a.json");
	cJSON *study = cJSON_CreateObject();
	cJSON_AddItemToObject(study, "design", doc);
	cJSON_AddItemToObject(study, "tolerances",
	                      cJSON_Parse("[{\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": 5, \"cpk\": 1.0},"
	                                  " {\"parameter\": \"screw.lead_deviation_um_per_300mm\", \"distribution\": \"uniform\","
	                                  "  \"lower\": -12, \"upper\": 12}]"));
	cJSON_AddItemToObject(study, "outputs", cJSON_Parse("[\"backlash_um\", \"load_sharing_factor\"]"));
	cJSON_AddItemToObject(study, "monte_carlo", cJSON_Parse("{\"samples\": 128, \"block_size\": 32, \"seed\": 17}"));
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr;
	prsm_problems_init(&pr);
	int rc = prsm_app_study_load(s, study, NULL, &pr);
	for (int i = 0; i < pr.count; i++)
		print_message("%s: %s\n", pr.items[i].pointer, pr.items[i].message);
	assert_int_equal(rc, 0);
	cJSON_Delete(study);
	prsm_study_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(&r, &s->study, &err), 0);
	study_ctx c = {s, &r};
	cJSON *ref = build_study(&c);
	char *reference = cJSON_PrintUnformatted(ref);
	assert_non_null(reference);
	cJSON_Delete(ref);

	sweep w = sweep_writer(build_study, &c, reference);
	print_message("study result: %d allocations failed in turn, %d refused, %d truncated by the old path\n",
	              w.runs, w.refused, w.truncated_old);
	assert_true(w.runs > 100);
	/* the study writer is on the sticky-error writer (io/write.h): no document at all, never a
	 * truncated one */
	assert_int_equal(w.truncated_old, 0);
	assert_int_equal(w.refused, w.runs);
	cJSON_free(reference);
	prsm_study_result_free(&r);
	free(s);
}

/* ---- an analysis with errors ------------------------------------------------------------ */

typedef struct {
	const prsm_analyze_request *rq;
	const prsm_problems *warnings;
} analyze_ctx;

static cJSON *build_analysis(const void *ctx)
{
	const analyze_ctx *c = ctx;
	return prsm_io_analyze_to_json(c->rq, c->warnings);
}

static prsm_analyze_request *load_measured(prsm_problems *warnings)
{
	cJSON *doc = prsm_test_read_study("case-a-measured.json");
	prsm_analyze_request *rq = calloc(1, sizeof *rq);
	assert_non_null(rq);
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_problems_init(warnings);
	assert_int_equal(prsm_app_analyze_load(rq, doc, warnings, &pr), 0);
	cJSON_Delete(doc);
	assert_int_equal(rq->with_errors, 1);
	assert_int_equal(prsm_app_analyze_run(rq), 0);
	return rq;
}

static void test_analysis_whole_or_nothing(void **state)
{
	(void)state;
	prsm_problems warnings;
	prsm_analyze_request *rq = load_measured(&warnings);
	analyze_ctx c = {rq, &warnings};
	cJSON *ref = build_analysis(&c);
	char *reference = cJSON_PrintUnformatted(ref);
	assert_non_null(reference);
	cJSON_Delete(ref);
	sweep w = sweep_writer(build_analysis, &c, reference);
	print_message("analysis: %d allocations failed in turn, %d refused, %d truncated by the old path\n", w.runs,
	              w.refused, w.truncated_old);
	assert_true(w.runs > 100);
	assert_true(w.truncated_old > 0);
	assert_true(w.refused > 0);
	cJSON_free(reference);
	prsm_io_analyze_free(rq);
	free(rq);
}

/* ---- prsm_global_init ------------------------------------------------------------------- */

/* Idempotent, and GSL's handler is off afterwards: an invalid FFT length is a return code, not
 * an abort. */
static void test_init_switches_gsl_handler_off(void **state)
{
	(void)state;
	prsm_global_init();
	prsm_global_init();
	double x[3] = {1.0, 2.0, 3.0};
	assert_int_equal(gsl_fft_real_radix2_transform(x, 1, 3), GSL_EINVAL);
}

/* Two threads analysing at once give the same documents as one. model/ used to switch GSL's
 * process-wide handler around its FFT, a data race ThreadSanitizer reports (make test-tsan). */
static void *analyse_thread(void *arg)
{
	char **out = arg;
	prsm_problems warnings;
	prsm_analyze_request *rq = load_measured(&warnings);
	analyze_ctx c = {rq, &warnings};
	cJSON *doc = build_analysis(&c);
	*out = cJSON_PrintUnformatted(doc);
	cJSON_Delete(doc);
	prsm_io_analyze_free(rq);
	free(rq);
	return NULL;
}

static void test_concurrent_analyses(void **state)
{
	(void)state;
	char *a = NULL, *b = NULL, *ref = NULL;
	analyse_thread(&ref);
	pthread_t t1, t2;
	assert_int_equal(pthread_create(&t1, NULL, analyse_thread, &a), 0);
	assert_int_equal(pthread_create(&t2, NULL, analyse_thread, &b), 0);
	pthread_join(t1, NULL);
	pthread_join(t2, NULL);
	assert_non_null(a);
	assert_non_null(b);
	assert_string_equal(a, ref);
	assert_string_equal(b, ref);
	cJSON_free(a);
	cJSON_free(b);
	cJSON_free(ref);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_init_switches_gsl_handler_off),
		cmocka_unit_test(test_study_result_whole_or_nothing),
		cmocka_unit_test(test_analysis_whole_or_nothing),
		cmocka_unit_test(test_concurrent_analyses),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
