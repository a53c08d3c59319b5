/*
 * test_job.c: job/ — the worker pool over a temporary store with a test kind ("sleepy": N
 * steps of 5 ms, progress after each, a cancel checked between steps) and with the real
 * study kind (a small Ishigami study): a job runs to done with its result; the same request
 * again, in another key order, is the cache hit (cache_hit in the result); a running job is
 * cancelled and a second cancel is a conflict; a failing run is stored with its problem;
 * closing the pool under a running job queues it again and the next open finishes it with the
 * same result; the queue cap; the service's sample cap refuses a study at its pointer; the
 * study's samples come back as CSV.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "job/jobs.h"
#include "util/sha256.h"
#include "util/version.h"

#include "test_db.h"

/* ---- the test kind ---- */

static const char *sleepy_version(void)
{
	return "sleepy 1";
}

static int sleepy_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	(void)lim;
	const cJSON *steps = cJSON_GetObjectItemCaseSensitive(doc, "steps");
	if (!cJSON_IsNumber(steps) || steps->valuedouble < 1) {
		prsm_problems_add(problems, "/steps", "required", "steps: a number >= 1");
		return PRSM_EINVAL;
	}
	*out = cJSON_Duplicate(doc, 1);
	return 0;
}

static int sleepy_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	cJSON *doc = cJSON_Parse(request);
	int steps = cJSON_GetObjectItemCaseSensitive(doc, "steps")->valueint;
	int fail = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(doc, "fail"));
	int keep = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(doc, "keep"));
	cJSON_Delete(doc);
	for (int i = 0; i < steps; i++) {
		if (*ctx->cancel) {
			if (keep) { /* like an optimisation: the best point so far */
				char best[64];
				snprintf(best, sizeof best, "{\"best_step\":%d}", i);
				out->result = strdup(best);
				out->result_len = strlen(best);
			}
			return prsm_error_set(err, PRSM_ECANCELLED, NULL, "cancelled");
		}
		struct timespec ts = {0, 5000000L};
		nanosleep(&ts, NULL);
		prsm_progress p = PRSM_PROGRESS_INIT;
		p.done = (size_t)i + 1;
		p.planned = (size_t)steps;
		p.interval_width = 1.0 / (i + 1);
		p.interval_goal = 0.125;
		ctx->progress(ctx->progress_ctx, &p);
	}
	if (fail)
		return prsm_error_set(err, PRSM_ENOCONVERGE, "/fail", "it was asked to fail");
	char buf[64];
	snprintf(buf, sizeof buf, "{\"steps\":%d,\"cache_hit\":false}", steps);
	out->result = strdup(buf);
	out->result_len = strlen(buf);
	out->samples_done = out->samples_planned = steps;
	return 0;
}

static const prsm_job_kind sleepy = {
	.name = "sleepy",
	.collection = "sleeps",
	.request_schema = "none",
	.result_schema = "none",
	.has_samples_csv = 0,
	.version = sleepy_version,
	.normalise = sleepy_normalise,
	.run = sleepy_run,
};

static const prsm_job_kind *const test_kinds[] = {&sleepy};

/* The engine build the next open_jobs gives (NULL: this binary's). */
static const char *engine_build;

static prsm_jobs *open_jobs(int workers, size_t max_queued, int use_test_kind, int *recovered)
{
	prsm_jobs_options o = PRSM_JOBS_OPTIONS_INIT;
	o.db_path = db_path;
	o.engine_build = engine_build;
	o.workers = workers;
	o.max_queued = max_queued;
	if (use_test_kind) {
		o.kinds = test_kinds;
		o.n_kinds = 1;
	}
	prsm_jobs *j = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_jobs_open(&j, &o, recovered, &err);
	if (rc)
		print_error("open: %s\n", err.message);
	assert_int_equal(rc, 0);
	return j;
}

static cJSON *parse(const char *text)
{
	cJSON *t = cJSON_Parse(text);
	assert_non_null(t);
	return t;
}

static prsm_job_view submit(prsm_jobs *j, const prsm_job_kind *k, const char *text, prsm_submit_outcome *oc)
{
	cJSON *doc = parse(text);
	prsm_job_view v;
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_jobs_submit(j, &v, oc, k, doc, &pr, &err);
	if (rc)
		print_error("submit: %s %s\n", err.message, pr.count ? pr.items[0].message : "");
	assert_int_equal(rc, 0);
	cJSON_Delete(doc);
	return v;
}

/* Poll until the job reaches state (or 30 s pass). */
static void wait_state(prsm_jobs *j, const prsm_job_kind *k, const char *id, prsm_job_state state)
{
	for (int i = 0; i < 3000; i++) {
		prsm_job_view v;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_jobs_get(j, &v, k, id, 0, &err), 0);
		prsm_job_state s = v.row.state;
		prsm_job_view_clear(&v);
		if (s == state)
			return;
		struct timespec ts = {0, 10000000L};
		nanosleep(&ts, NULL);
	}
	fail_msg("job %s never became %s", id, prsm_job_state_name(state));
}

static char *job_text(prsm_jobs *j, const prsm_job_kind *k, const char *id, int cache_hit)
{
	prsm_job_view v;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_jobs_get(j, &v, k, id, PRSM_STORE_WITH_RESULT, &err), 0);
	v.cache_hit = cache_hit;
	char *text;
	size_t len;
	assert_int_equal(prsm_job_view_to_text(&text, &len, &v), 0);
	assert_int_equal(strlen(text), len);
	prsm_job_view_clear(&v);
	return text;
}

static void test_run_and_cache(void **state)
{
	(void)state;
	prsm_jobs *j = open_jobs(2, 16, 1, NULL);
	prsm_submit_outcome oc;
	prsm_job_view v = submit(j, &sleepy, "{\"steps\": 3, \"tag\": \"a\"}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	char id[PRSM_STORE_ID_MAX];
	snprintf(id, sizeof id, "%s", v.row.id);
	prsm_job_view_clear(&v);
	wait_state(j, &sleepy, id, PRSM_JOB_DONE);
	char *text = job_text(j, &sleepy, id, 0);
	cJSON *doc = parse(text);
	assert_string_equal(cJSON_GetObjectItem(doc, "state")->valuestring, "done");
	const cJSON *res = cJSON_GetObjectItem(doc, "result");
	assert_int_equal(cJSON_GetObjectItem(res, "steps")->valueint, 3);
	assert_true(cJSON_IsFalse(cJSON_GetObjectItem(res, "cache_hit")));
	assert_int_equal(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "progress"), "samples_done")->valueint, 3);
	cJSON_Delete(doc);
	free(text);

	/* the same request in another order and spacing: the cache */
	v = submit(j, &sleepy, "{\"tag\":\"a\",  \"steps\": 3.0}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CACHED);
	assert_string_equal(v.row.id, id);
	assert_non_null(v.row.result);
	char *cached;
	size_t len;
	assert_int_equal(prsm_job_view_to_text(&cached, &len, &v), 0);
	doc = parse(cached);
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(doc, "cache_hit")));
	assert_true(cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "result"), "cache_hit")));
	cJSON_Delete(doc);
	free(cached);
	prsm_job_view_clear(&v);

	/* an invalid request: its problem, nothing stored */
	cJSON *bad = parse("{\"steps\": 0}");
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_jobs_submit(j, &v, &oc, &sleepy, bad, &pr, &err), PRSM_EINVAL);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].pointer, "/steps");
	cJSON_Delete(bad);

	/* a failing run */
	v = submit(j, &sleepy, "{\"steps\": 1, \"fail\": true}", &oc);
	snprintf(id, sizeof id, "%s", v.row.id);
	prsm_job_view_clear(&v);
	wait_state(j, &sleepy, id, PRSM_JOB_FAILED);
	text = job_text(j, &sleepy, id, 0);
	doc = parse(text);
	const cJSON *problem = cJSON_GetObjectItem(doc, "problem");
	assert_non_null(problem);
	assert_int_equal(cJSON_GetObjectItem(problem, "status")->valueint, 500);
	assert_string_equal(cJSON_GetArrayItem(cJSON_GetObjectItem(problem, "errors"), 0)->child->valuestring, "/fail");
	assert_null(cJSON_GetObjectItem(doc, "result"));
	cJSON_Delete(doc);
	free(text);
	/* a job of another kind is not found under this one */
	assert_int_equal(prsm_jobs_get(j, &v, &prsm_job_kind_study, id, 0, &err), PRSM_ENOTFOUND);
	prsm_jobs_close(j);
}

static void test_cancel_and_queue_cap(void **state)
{
	(void)state;
	prsm_jobs *j = open_jobs(1, 1, 1, NULL);
	prsm_submit_outcome oc;
	prsm_job_view a = submit(j, &sleepy, "{\"steps\": 4000}", &oc);
	wait_state(j, &sleepy, a.row.id, PRSM_JOB_RUNNING);
	prsm_job_view b = submit(j, &sleepy, "{\"steps\": 4001}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	prsm_job_view c = submit(j, &sleepy, "{\"steps\": 4002}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_FULL);
	/* identical in flight: shared, even with the queue full */
	prsm_job_view a2 = submit(j, &sleepy, "{\"steps\": 4000}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_SHARED);
	assert_string_equal(a2.row.id, a.row.id);

	/* live progress of the running job */
	prsm_job_view v;
	prsm_error err = PRSM_ERROR_INIT;
	for (int i = 0; i < 200; i++) {
		assert_int_equal(prsm_jobs_get(j, &v, &sleepy, a.row.id, 0, &err), 0);
		if (v.samples_done > 0)
			break;
		prsm_job_view_clear(&v);
		struct timespec ts = {0, 10000000L};
		nanosleep(&ts, NULL);
	}
	assert_true(v.live);
	assert_int_equal(v.samples_planned, 4000);
	assert_true(v.samples_done > 0);
	/* the stop rule's figure as the run reported it last (sleepy: 1 / steps done) */
	assert_true(v.interval_width > 0.0 && v.interval_width <= 1.0);
	assert_float_equal(v.interval_goal, 0.125, 0.0);
	assert_true(isnan(v.best));
	cJSON *live = prsm_job_view_to_json(&v);
	const cJSON *lp = cJSON_GetObjectItemCaseSensitive(live, "progress");
	assert_true(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(lp, "interval_width")));
	assert_float_equal(cJSON_GetObjectItemCaseSensitive(lp, "interval_goal")->valuedouble, 0.125, 0.0);
	assert_true(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(lp, "best_objective")));
	assert_string_equal(cJSON_GetObjectItemCaseSensitive(lp, "unit")->valuestring, "samples");
	cJSON_Delete(live);
	prsm_job_view_clear(&v);

	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, a.row.id, &err), 0);
	assert_int_equal(v.row.state, PRSM_JOB_CANCELLED);
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, a.row.id, &err), PRSM_ECANCELLED);
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, "0123", &err), PRSM_ENOTFOUND);
	/* the worker moves on to b; cancel it while queued or running */
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, b.row.id, &err), 0);
	int workers = 0, running = 1;
	for (int i = 0; i < 200 && running; i++) {
		prsm_jobs_counts(j, &workers, &running);
		struct timespec ts = {0, 10000000L};
		nanosleep(&ts, NULL);
	}
	assert_int_equal(workers, 1);
	assert_int_equal(running, 0);
	assert_int_equal(prsm_jobs_get(j, &v, &sleepy, a.row.id, 0, &err), 0);
	assert_int_equal(v.row.state, PRSM_JOB_CANCELLED);
	prsm_job_view_clear(&v);
	/* a cancelled request submitted again is a new job */
	prsm_job_view a3 = submit(j, &sleepy, "{\"steps\": 4000}", &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	assert_string_not_equal(a3.row.id, a.row.id);
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, a3.row.id, &err), 0);
	(void)c;

	/* the list pages through them, newest first */
	prsm_job_view items[2];
	size_t n;
	long long next;
	assert_int_equal(prsm_jobs_list(j, items, 2, &n, &next, &sleepy, 0, &err), 0);
	assert_int_equal(n, 2);
	assert_string_equal(items[0].row.id, a3.row.id);
	assert_true(next > 0);
	assert_int_equal(prsm_jobs_list(j, items, 2, &n, &next, &sleepy, next, &err), 0);
	assert_int_equal(n, 1);
	assert_string_equal(items[0].row.id, a.row.id);
	assert_int_equal(next, 0);
	prsm_jobs_close(j);
}

/* A kind that hands back its best point when cancelled (an optimisation) keeps it: the job
 * stays cancelled and shows that result; a cancelled job without one has none. */
static void test_cancel_keeps_best(void **state)
{
	(void)state;
	prsm_jobs *j = open_jobs(1, 8, 1, NULL);
	prsm_submit_outcome oc;
	prsm_job_view a = submit(j, &sleepy, "{\"steps\": 4000, \"keep\": true}", &oc);
	wait_state(j, &sleepy, a.row.id, PRSM_JOB_RUNNING);
	prsm_job_view v;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, a.row.id, &err), 0);
	prsm_job_view_clear(&v);
	int have = 0;
	for (int i = 0; i < 500 && !have; i++) {
		assert_int_equal(prsm_jobs_get(j, &v, &sleepy, a.row.id, PRSM_STORE_WITH_RESULT, &err), 0);
		assert_int_equal(v.row.state, PRSM_JOB_CANCELLED);
		have = v.row.result != NULL;
		prsm_job_view_clear(&v);
		struct timespec ts = {0, 10000000L};
		nanosleep(&ts, NULL);
	}
	assert_true(have);
	char *text = job_text(j, &sleepy, a.row.id, 0);
	cJSON *doc = parse(text);
	assert_string_equal(cJSON_GetObjectItem(doc, "state")->valuestring, "cancelled");
	assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "result"), "best_step")->valueint >= 0);
	cJSON_Delete(doc);
	free(text);
	/* a second cancel is refused and the result stays */
	assert_int_equal(prsm_jobs_cancel(j, &v, &sleepy, a.row.id, &err), PRSM_ECANCELLED);
	prsm_job_view_clear(&v);
	prsm_job_view_clear(&a);
	prsm_jobs_close(j);
}

static void test_shutdown_resume(void **state)
{
	(void)state;
	prsm_jobs *j = open_jobs(1, 8, 1, NULL);
	prsm_submit_outcome oc;
	prsm_job_view a = submit(j, &sleepy, "{\"steps\": 60}", &oc);
	wait_state(j, &sleepy, a.row.id, PRSM_JOB_RUNNING);
	prsm_jobs_close(j); /* stops under the running job: queued again */
	int recovered = -1;
	j = open_jobs(1, 8, 1, &recovered);
	assert_int_equal(recovered, 0); /* a graceful stop left it queued, not running */
	wait_state(j, &sleepy, a.row.id, PRSM_JOB_DONE);
	char *text = job_text(j, &sleepy, a.row.id, 0);
	cJSON *doc = parse(text);
	assert_int_equal(cJSON_GetObjectItem(doc, "attempts")->valueint, 2);
	assert_int_equal(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "result"), "steps")->valueint, 60);
	cJSON_Delete(doc);
	free(text);
	prsm_jobs_close(j);
}

/* A database written by another build of the engine is never served: the same request under
 * another engine build runs again (a stale cache would serve old physics); under the same
 * build it is the cache hit. The key is the documented hash and names the binary's build. */
static void test_engine_build_in_key(void **state)
{
	(void)state;
	const char *text = "{\"steps\": 2, \"tag\": \"build\"}";
	engine_build = "00000000000000a1";
	prsm_jobs *j = open_jobs(1, 8, 1, NULL);
	prsm_submit_outcome oc;
	prsm_job_view v = submit(j, &sleepy, text, &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	char old_id[PRSM_STORE_ID_MAX], old_key[PRSM_STORE_KEY_MAX];
	snprintf(old_id, sizeof old_id, "%s", v.row.id);
	snprintf(old_key, sizeof old_key, "%s", v.row.key);
	prsm_job_view_clear(&v);
	wait_state(j, &sleepy, old_id, PRSM_JOB_DONE);
	prsm_jobs_close(j);

	j = open_jobs(1, 8, 1, NULL); /* the same build again: the cache */
	v = submit(j, &sleepy, text, &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CACHED);
	assert_string_equal(v.row.id, old_id);
	prsm_job_view_clear(&v);
	prsm_jobs_close(j);

	engine_build = "00000000000000b2"; /* a new engine: runs again, under another key */
	j = open_jobs(1, 8, 1, NULL);
	v = submit(j, &sleepy, text, &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	assert_string_not_equal(v.row.id, old_id);
	assert_string_not_equal(v.row.key, old_key);
	char canon[] = "{\"steps\":2,\"tag\":\"build\"}";
	char key[PRSM_SHA256_HEX];
	prsm_jobs_cache_key(key, &sleepy, "00000000000000b2", canon, strlen(canon));
	assert_string_equal(v.row.key, key);
	prsm_jobs_cache_key(key, &sleepy, "00000000000000a1", canon, strlen(canon));
	assert_string_equal(old_key, key);
	wait_state(j, &sleepy, v.row.id, PRSM_JOB_DONE);
	prsm_job_view_clear(&v);
	prsm_jobs_close(j);

	engine_build = NULL; /* the binary's own build is a 16-digit hash and keys differently */
	assert_int_equal(strlen(prsm_engine_build()), 16);
	assert_int_equal(strspn(prsm_engine_build(), "0123456789abcdef"), 16);
	prsm_jobs_cache_key(key, &sleepy, prsm_engine_build(), canon, strlen(canon));
	assert_string_not_equal(key, old_key);
}

/* The optimisation kind applies the service's sample cap to a robust constraint's study, and
 * its evaluation cap to the solver, each at its field. */
static void test_optimization_kind_caps(void **state)
{
	(void)state;
	const prsm_job_kind *k = prsm_job_kind_by_collection("optimizations");
	assert_ptr_equal(k, &prsm_job_kind_optimization);
	assert_ptr_equal(prsm_job_kind_by_collection("allocations"), &prsm_job_kind_allocation);
	cJSON *doc = prsm_test_read_study("optimize-case-a-robust.json");
	prsm_job_limits lim = {100, 60.0, 1}; /* 100 samples or evaluations */
	prsm_problems pr;
	prsm_problems_init(&pr);
	cJSON *norm = NULL;
	assert_int_equal(k->normalise(&norm, doc, &lim, &pr), PRSM_EINVAL);
	assert_null(norm);
	int cap_samples = 0, cap_evaluations = 0;
	for (int i = 0; i < pr.count; i++) {
		cap_samples |= strcmp(pr.items[i].pointer, "/robust/monte_carlo/samples") == 0;
		cap_evaluations |= strcmp(pr.items[i].pointer, "/solver/max_evaluations") == 0;
	}
	assert_true(cap_samples);
	assert_true(cap_evaluations);
	/* within the caps it is the canonical document itself */
	lim.max_samples = 200000;
	prsm_problems_init(&pr);
	assert_int_equal(k->normalise(&norm, doc, &lim, &pr), 0);
	/* the robust studies' thread count cannot change the result: not in the cache key */
	cJSON *robust_mc = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "robust"), "monte_carlo");
	assert_non_null(robust_mc);
	cJSON_DeleteItemFromObjectCaseSensitive(robust_mc, "threads");
	assert_true(cJSON_Compare(norm, doc, 1));
	cJSON_Delete(norm);
	cJSON_AddNumberToObject(robust_mc, "threads", 2);
	assert_int_equal(k->normalise(&norm, doc, &lim, &pr), 0);
	assert_null(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(norm, "robust"), "monte_carlo"), "threads"));
	cJSON_Delete(norm);
	cJSON_Delete(doc);
}

static void test_study_kind(void **state)
{
	(void)state;
	prsm_jobs *j = open_jobs(1, 8, 0, NULL);
	const prsm_job_kind *k = prsm_job_kind_by_collection("studies");
	assert_ptr_equal(k, &prsm_job_kind_study);
	assert_ptr_equal(prsm_job_kind_by_name("study"), k);
	assert_null(prsm_job_kind_by_collection("nothing"));
	assert_non_null(strstr(k->version(), "prsm-mc "));
	const char *study = "{\"model\": {\"benchmark\": \"ishigami\"},"
	                    " \"tolerances\": [{\"parameter\": \"x1\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159},"
	                    " {\"parameter\": \"x2\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159},"
	                    " {\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159}],"
	                    " \"monte_carlo\": {\"samples\": 2048, \"block_size\": 512, \"seed\": 7, \"threads\": 2}}";
	prsm_submit_outcome oc;
	prsm_job_view v = submit(j, k, study, &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	char id[PRSM_STORE_ID_MAX];
	snprintf(id, sizeof id, "%s", v.row.id);
	prsm_job_view_clear(&v);
	wait_state(j, k, id, PRSM_JOB_DONE);
	char *text = job_text(j, k, id, 0);
	cJSON *doc = parse(text);
	const cJSON *res = cJSON_GetObjectItem(doc, "result");
	assert_string_equal(cJSON_GetObjectItem(res, "model")->valuestring, "ishigami");
	assert_int_equal(cJSON_GetObjectItem(cJSON_GetObjectItem(res, "samples"), "run")->valueint, 2048);
	cJSON_Delete(doc);
	free(text);
	char *csv;
	size_t len;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_jobs_csv(j, &csv, &len, k, id, &err), 0);
	size_t lines = 0;
	for (size_t i = 0; i < len; i++)
		lines += csv[i] == '\n';
	assert_int_equal(lines, 2049);
	free(csv);
	/* the thread count is not part of the key */
	const char *one_thread = "{\"model\": {\"benchmark\": \"ishigami\"},"
	                         " \"tolerances\": [{\"parameter\": \"x1\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159},"
	                         " {\"parameter\": \"x2\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159},"
	                         " {\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": -3.14159, \"upper\": 3.14159}],"
	                         " \"monte_carlo\": {\"samples\": 2048, \"block_size\": 512, \"seed\": 7, \"threads\": 1}}";
	v = submit(j, k, one_thread, &oc);
	assert_int_equal(oc, PRSM_SUBMIT_CACHED);
	prsm_job_view_clear(&v);
	/* the service's sample cap, at the field's pointer */
	cJSON *big = parse("{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]},"
	                   " \"tolerances\": [{\"parameter\": \"x1\", \"distribution\": \"normal\", \"sd\": 1}],"
	                   " \"monte_carlo\": {\"samples\": 3000000}}");
	prsm_problems pr;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_jobs_submit(j, &v, &oc, k, big, &pr, &err), PRSM_EINVAL);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].pointer, "/monte_carlo/samples");
	assert_string_equal(pr.items[0].code, "service_cap");
	cJSON_Delete(big);
	/* a document problem from the study reader */
	cJSON *bad = parse("{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]}, \"tolerances\": []}");
	prsm_problems_init(&pr);
	assert_int_not_equal(prsm_jobs_submit(j, &v, &oc, k, bad, &pr, &err), 0);
	assert_true(pr.count >= 1);
	cJSON_Delete(bad);
	prsm_jobs_close(j);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_run_and_cache, setup, teardown),
		cmocka_unit_test_setup_teardown(test_cancel_and_queue_cap, setup, teardown),
		cmocka_unit_test_setup_teardown(test_cancel_keeps_best, setup, teardown),
		cmocka_unit_test_setup_teardown(test_shutdown_resume, setup, teardown),
		cmocka_unit_test_setup_teardown(test_engine_build_in_key, setup, teardown),
		cmocka_unit_test(test_optimization_kind_caps),
		cmocka_unit_test_setup_teardown(test_study_kind, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
