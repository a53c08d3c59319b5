/*
 * kind_analysis.c: the "analysis" job kind (/v1/analyses): the analyze request
 * (schemas/analyze-request.schema.json in, schemas/analysis.schema.json out) run on a job
 * worker. POST /v1/designs/analyze answers a request itself while it fits the service's
 * synchronous budget (http/server.c); a heavier one (a long transmission-error record, a fine
 * angle grid, many rollers and threads in exact mode) becomes one of these jobs (202), so the
 * HTTP threads stay free for health checks and cached reads. Submitted directly to
 * /v1/analyses it runs the same way. The per-job time cap stops the error analysis
 * (model/assembly_report.h, checked every few angles); cancel stops it too.
 */
#include "job/kind.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/global.h"
#include "util/clock.h"

static char analysis_version_text[512] = "prsm-analysis (versions unknown)";
static pthread_once_t analysis_version_once = PTHREAD_ONCE_INIT;

/* The versions an analysis result names (its "engine" object), read from the analysis of a
 * small design so the cache key follows the engine's own strings. */
static void analysis_version_init(void)
{
	const char *design = "{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25,"
	                     " \"flank_angle_deg\": 45, \"rollers\": 10, \"engaged_threads\": 10},"
	                     " \"target_axial_clearance_um\": 20}";
	cJSON *doc = cJSON_Parse(design), *res = NULL;
	prsm_problems p;
	prsm_problems_init(&p);
	if (doc && prsm_app_analyze(&res, doc, &p) == 0) {
		const cJSON *eng = cJSON_GetObjectItemCaseSensitive(res, "engine");
		const cJSON *v = cJSON_GetObjectItemCaseSensitive(eng, "version");
		const cJSON *b = cJSON_GetObjectItemCaseSensitive(eng, "build");
		const cJSON *m = cJSON_GetObjectItemCaseSensitive(eng, "model");
		if (cJSON_IsString(v) && cJSON_IsString(b) && cJSON_IsString(m))
			snprintf(analysis_version_text, sizeof analysis_version_text, "%s; build %s; %s", v->valuestring,
			         b->valuestring, m->valuestring);
	}
	cJSON_Delete(doc);
	cJSON_Delete(res);
}

static const char *analysis_version(void)
{
	pthread_once(&analysis_version_once, analysis_version_init);
	return analysis_version_text;
}

/* Loading runs the nominal analysis (contacts, performance): cheap, and it finds every problem
 * of the document at once, as the synchronous route does. */
static int analysis_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	(void)lim; /* the request's own caps (record length) are the document's rules */
	*out = NULL;
	prsm_analyze_request *rq = calloc(1, sizeof *rq); /* freed below */
	if (!rq)
		return PRSM_ENOMEM;
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	int rc = prsm_app_analyze_load(rq, doc, &warnings, problems);
	prsm_io_analyze_free(rq);
	free(rq);
	if (rc)
		return rc;
	*out = cJSON_Duplicate(doc, 1); /* handed to the caller */
	return *out ? 0 : PRSM_ENOMEM;
}

static int analysis_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	cJSON *doc = cJSON_Parse(request);
	prsm_analyze_request *rq = calloc(1, sizeof *rq); /* freed below */
	int rc;
	if (!doc || !rq) {
		rc = prsm_error_set(err, doc ? PRSM_ENOMEM : PRSM_EINVAL, NULL, "cannot read the stored request");
		goto done;
	}
	rc = prsm_app_analyze_load(rq, doc, &warnings, &problems);
	if (rc) {
		rc = prsm_error_set(err, rc, problems.count ? problems.items[0].pointer : NULL, "%s",
		                    problems.count ? problems.items[0].message : "the stored request is invalid");
		goto done;
	}
	rq->options.cancel = ctx->cancel;
	if (ctx->limits.max_time_s > 0)
		rq->options.deadline_s = prsm_clock_seconds() + ctx->limits.max_time_s;
	rc = prsm_app_analyze_run(rq);
	if (rc == PRSM_ECANCELLED) {
		rc = prsm_cancel_requested(ctx->cancel)
		         ? prsm_error_set(err, PRSM_ECANCELLED, NULL, "the analysis was cancelled")
		         : prsm_error_set(err, PRSM_ECANCELLED, NULL, "the analysis took longer than this service's %g s per job",
		                          ctx->limits.max_time_s);
		goto done;
	}
	if (rc) {
		rc = prsm_error_set(err, rc, NULL, "the analysis failed (%s)", prsm_error_name(rc));
		goto done;
	}
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *res = prsm_io_analyze_to_json(rq, &warnings);
	out->result = prsm_json_print_whole(res, mark, 0); /* handed to the caller */
	cJSON_Delete(res);
	if (!out->result) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
		goto done;
	}
	out->result_len = strlen(out->result);
	out->samples_done = out->samples_planned = rq->with_errors ? rq->report.record_length : 0;
done:
	if (rc)
		prsm_job_output_free(out);
	if (rq)
		prsm_io_analyze_free(rq);
	free(rq);
	cJSON_Delete(doc);
	return rc;
}

const prsm_job_kind prsm_job_kind_analysis = {
	.name = "analysis",
	.collection = "analyses",
	.request_schema = "analyze-request.schema.json",
	.result_schema = "analysis.schema.json",
	.has_samples_csv = 0,
	.progress_unit = "samples",
	.version = analysis_version,
	.normalise = analysis_normalise,
	.run = analysis_run,
};
