/*
 * kind_design_opt.c: the "optimization" (/v1/optimizations) and "allocation" (/v1/allocations)
 * job kinds (issue 7; DESIGN.md "Optimisation", "Service"). Both run a document of src/io in
 * one call (prsm_app_optimize, prsm_app_allocate) with the job's cancel
 * flag, progress (objective evaluations, or Monte Carlo samples of an allocation, and the best
 * objective so far) and the service's limits: the per-job evaluation or sample cap (the
 * service's max_samples) checked when the job is submitted, the time cap, and for allocations
 * the engine threads. A cancelled run hands back its best point so far, which the job keeps.
 * Thread counts cannot change a result, so they are dropped from the cache key.
 */
#include "job/kind.h"
#include "io/global.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/allocate.h"
#include "io/allocation_json.h"
#include "io/optimization_json.h"
#include "app/optimize.h"

/* Versions of the results: the model and engine versions of the study kind (both documents
 * run the same model and, for robust terms and allocations, the same engine) and the
 * document's own revision; part of the cache key. */
static char optimization_version_text[600];
static char allocation_version_text[600];
static pthread_once_t versions_once = PTHREAD_ONCE_INIT;

static void versions_init(void)
{
	const char *base = prsm_job_kind_study.version();
	snprintf(optimization_version_text, sizeof optimization_version_text, "%s; optimization 1", base);
	snprintf(allocation_version_text, sizeof allocation_version_text, "%s; allocation 1", base);
}

static const char *optimization_version(void)
{
	pthread_once(&versions_once, versions_init);
	return optimization_version_text;
}

static const char *allocation_version(void)
{
	pthread_once(&versions_once, versions_init);
	return allocation_version_text;
}

/* A copy of doc without the members at paths (each a NULL-terminated list of member names)
 * that cannot change the result. The caller owns it; NULL when out of memory. */
static cJSON *without(const cJSON *doc, const char *const *const *paths)
{
	cJSON *norm = cJSON_Duplicate(doc, 1);
	if (!norm)
		return NULL;
	for (size_t p = 0; paths[p]; p++) {
		cJSON *o = norm;
		size_t i = 0;
		while (o && paths[p][i + 1]) {
			o = cJSON_GetObjectItemCaseSensitive(o, paths[p][i]);
			i++;
		}
		if (cJSON_IsObject(o))
			cJSON_DeleteItemFromObjectCaseSensitive(o, paths[p][i]);
	}
	return norm;
}

/* an optimisation runs on one thread; its robust constraints' studies may use more */
static const char *const opt_robust_threads[] = {"robust", "monte_carlo", "threads", NULL};
static const char *const *const opt_volatile[] = {opt_robust_threads, NULL};

static const char *const alloc_threads[] = {"monte_carlo", "threads", NULL};
static const char *const alloc_study_threads[] = {"study", "monte_carlo", "threads", NULL};
static const char *const *const alloc_volatile[] = {alloc_threads, alloc_study_threads, NULL};

static int optimization_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	*out = NULL;
	int rc = prsm_app_optimization_check(doc, lim->max_samples, NULL, problems);
	/* robust constraints run a study per candidate: its samples are capped like a study's */
	const cJSON *mc = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "robust"), "monte_carlo");
	const cJSON *samples = cJSON_GetObjectItemCaseSensitive(mc, "samples");
	if (lim->max_samples && cJSON_IsNumber(samples) && samples->valuedouble > (double)lim->max_samples) {
		prsm_problems_add(problems, "/robust/monte_carlo/samples", "service_cap",
		                  "%.0f samples per candidate: this service runs at most %zu per study", samples->valuedouble,
		                  lim->max_samples);
		rc = PRSM_EINVAL;
	}
	if (rc)
		return rc;
	*out = without(doc, opt_volatile);
	return *out ? 0 : PRSM_ENOMEM;
}

static int allocation_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	*out = NULL;
	int rc = prsm_app_allocation_check(doc, lim->max_samples, NULL, problems);
	if (rc)
		return rc;
	*out = without(doc, alloc_volatile);
	return *out ? 0 : PRSM_ENOMEM;
}

/* Relays progress to the job and keeps the last counts for the stored row. */
typedef struct {
	const prsm_job_run_ctx *ctx;
	prsm_progress last;
} relay;

static void relay_progress(void *c, const prsm_progress *p)
{
	relay *r = c;
	r->last = *p;
	if (r->ctx->progress)
		r->ctx->progress(r->ctx->progress_ctx, p);
}

/* The shared body: parse the stored request, run it with one of the two executors, hand back
 * the result text (also the best-so-far result of a cancelled run). */
static int run_document(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, int allocation,
                        prsm_error *err)
{
	memset(out, 0, sizeof *out);
	cJSON *doc = cJSON_Parse(request);
	if (!doc)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "cannot read the stored request");
	prsm_problems problems;
	prsm_problems_init(&problems);
	relay r = {ctx, PRSM_PROGRESS_INIT};
	cJSON *res = NULL;
	const unsigned long mark = prsm_json_alloc_failures();
	int rc = allocation ? prsm_app_allocate(&res, doc, ctx->cancel, relay_progress, &r,
	                                                 ctx->limits.max_time_s, ctx->limits.threads, &problems, err)
	                    : prsm_app_optimize(&res, doc, ctx->cancel, relay_progress, &r,
	                                                   ctx->limits.max_time_s, &problems, err);
	if (rc == PRSM_EINVAL && problems.count)
		prsm_error_set(err, rc, problems.items[0].pointer, "%s", problems.items[0].message);
	if (rc == 0 || rc == PRSM_ECANCELLED) {
		if (prsm_cancel_requested(ctx->cancel) && rc == 0)
			rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the job was cancelled");
		if (res) {
			/* whole or nothing: a member cJSON dropped for want of memory fails the run */
			out->result = prsm_json_print_whole(res, mark, 0); /* handed to the caller */
			if (!out->result && rc == 0)
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
			out->result_len = out->result ? strlen(out->result) : 0;
		}
		out->samples_done = (long long)r.last.done;
		out->samples_planned = (long long)r.last.planned;
	}
	if (rc && rc != PRSM_ECANCELLED)
		prsm_job_output_free(out);
	cJSON_Delete(res);
	cJSON_Delete(doc);
	return rc;
}

static int optimization_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	return run_document(out, request, ctx, 0, err);
}

static int allocation_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	return run_document(out, request, ctx, 1, err);
}

const prsm_job_kind prsm_job_kind_optimization = {
	.name = "optimization",
	.collection = "optimizations",
	.request_schema = "optimization.schema.json",
	.result_schema = "optimization-result.schema.json",
	.has_samples_csv = 0,
	.progress_unit = "evaluations",
	.version = optimization_version,
	.normalise = optimization_normalise,
	.run = optimization_run,
};

const prsm_job_kind prsm_job_kind_allocation = {
	.name = "allocation",
	.collection = "allocations",
	.request_schema = "allocation.schema.json",
	.result_schema = "allocation-result.schema.json",
	.has_samples_csv = 0,
	.progress_unit = "samples",
	.version = allocation_version,
	.normalise = allocation_normalise,
	.run = allocation_run,
};
