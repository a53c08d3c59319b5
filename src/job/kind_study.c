/*
 * kind_study.c: the "study" job kind (/v1/studies): a Monte Carlo tolerance study
 * (schemas/study.schema.json in, schemas/study-result.schema.json out, every sample as CSV),
 * run exactly as `prsm study` runs it (src/cli/study.c) but with the service's limits: the
 * per-job sample cap (samples, and Sobol evaluations N (groups + 2)), the per-job time cap
 * (the smaller of the document's and the service's) and the service's engine threads. The
 * engine's results do not depend on the thread count, so monte_carlo.threads is dropped from
 * the cache key.
 */
#include "job/kind.h"
#include "io/global.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/analysis_json.h"
#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"

/* Largest samples CSV kept with a job, bytes; a larger one is not stored (its GET says so). */
#define STUDY_CSV_MAX_BYTES (256u * 1024u * 1024u)

static char study_version_text[512] = "prsm-study (versions unknown)";
static pthread_once_t study_version_once = PTHREAD_ONCE_INIT;

/* The versions a study result names, read from the result of a tiny benchmark study, so the
 * cache key follows the engine's own version strings and never a copy of them. */
static void study_version_init(void)
{
	const char *doc_text = "{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]},"
	                       " \"tolerances\": [{\"parameter\": \"x1\", \"distribution\": \"normal\", \"sd\": 1}],"
	                       " \"monte_carlo\": {\"samples\": 16, \"block_size\": 16, \"threads\": 1},"
	                       " \"sensitivity\": {\"src\": false, \"stack\": false}}";
	cJSON *doc = cJSON_Parse(doc_text);
	prsm_io_study *s = calloc(1, sizeof *s); /* freed below */
	prsm_study_result *r = calloc(1, sizeof *r);
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	if (doc && s && r && prsm_app_study_load(s, doc, NULL, &pr) == 0 && prsm_study_run(r, &s->study, &err) == 0) {
		cJSON *res = prsm_io_study_result_to_json(s, r);
		const cJSON *v = cJSON_GetObjectItemCaseSensitive(res, "versions");
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(v, "prsm");
		const cJSON *e = cJSON_GetObjectItemCaseSensitive(v, "engine");
		const cJSON *b = cJSON_GetObjectItemCaseSensitive(v, "build");
		const cJSON *m = cJSON_GetObjectItemCaseSensitive(v, "model");
		if (cJSON_IsString(p) && cJSON_IsString(e) && cJSON_IsString(b) && cJSON_IsString(m))
			snprintf(study_version_text, sizeof study_version_text, "prsm %s; %s; build %s; %s", p->valuestring,
			         e->valuestring, b->valuestring, m->valuestring);
		cJSON_Delete(res);
		prsm_study_result_free(r);
	}
	cJSON_Delete(doc);
	free(s);
	free(r);
}

static const char *study_version(void)
{
	pthread_once(&study_version_once, study_version_init);
	return study_version_text;
}

/* The service's caps on a loaded study; problems at the fields that set them. */
static void check_limits(const prsm_io_study *s, const cJSON *doc, const prsm_job_limits *lim,
                         prsm_problems *problems)
{
	const prsm_study *st = &s->study;
	const cJSON *mc = cJSON_GetObjectItemCaseSensitive(doc, "monte_carlo");
	if (lim->max_samples && st->mc.samples > lim->max_samples)
		prsm_problems_add(problems, cJSON_GetObjectItemCaseSensitive(mc, "samples") ? "/monte_carlo/samples" : "",
		                  "service_cap", "%zu samples: this service runs at most %zu per job", st->mc.samples,
		                  lim->max_samples);
	if (st->sens.sobol && lim->max_samples) {
		size_t evals = st->sens.sobol_samples * (st->n_groups + 2);
		if (evals > lim->max_samples)
			prsm_problems_add(problems, "/sensitivity/sobol/samples", "service_cap",
			                  "%zu Sobol samples make %zu evaluations (N (tolerances + 2)): this service runs "
			                  "at most %zu per job",
			                  st->sens.sobol_samples, evals, lim->max_samples);
	}
}

static int study_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	*out = NULL;
	prsm_io_study *s = calloc(1, sizeof *s); /* about 1 MB; freed below */
	if (!s)
		return PRSM_ENOMEM;
	int rc = prsm_app_study_load(s, doc, NULL, problems);
	if (!rc) {
		check_limits(s, doc, lim, problems);
		if (prsm_problems_total(problems))
			rc = PRSM_EINVAL;
	}
	free(s);
	if (rc)
		return rc;
	cJSON *norm = cJSON_Duplicate(doc, 1); /* handed to the caller */
	if (!norm)
		return PRSM_ENOMEM;
	cJSON *mc = cJSON_GetObjectItemCaseSensitive(norm, "monte_carlo");
	if (cJSON_IsObject(mc))
		cJSON_DeleteItemFromObjectCaseSensitive(mc, "threads");
	*out = norm;
	return 0;
}

typedef struct {
	const prsm_io_study *s;
	const prsm_study_result *r;
} study_csv;

static int write_samples(FILE *f, const void *ctx)
{
	const study_csv *c = ctx;
	return prsm_io_study_write_csv(f, c->s, c->r);
}

/* Every sample as CSV into a malloc'd buffer (*csv, the caller's), or NULL when it would be
 * larger than STUDY_CSV_MAX_BYTES. Returns 0 or PRSM_EIO / PRSM_ENOMEM. */
static int samples_csv(char **csv, size_t *len, const prsm_io_study *s, const prsm_study_result *r)
{
	*csv = NULL;
	*len = 0;
	/* a row is at most about 25 bytes per column */
	size_t cols = r->run.d + r->run.m + 2;
	if (r->run.n > STUDY_CSV_MAX_BYTES / (25 * cols))
		return 0;
	const study_csv c = {s, r};
	return prsm_job_text(csv, len, write_samples, &c);
}

static int study_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	int rc = 0;
	cJSON *doc = cJSON_Parse(request);
	prsm_io_study *s = calloc(1, sizeof *s);          /* freed below */
	prsm_study_result *r = calloc(1, sizeof *r);      /* freed below */
	if (!doc || !s || !r) {
		rc = prsm_error_set(err, doc ? PRSM_ENOMEM : PRSM_EINVAL, NULL, "cannot read the stored request");
		goto done;
	}
	rc = prsm_app_study_load(s, doc, &warnings, &problems);
	if (rc) {
		rc = prsm_error_set(err, rc, problems.count ? problems.items[0].pointer : NULL, "%s",
		                    problems.count ? problems.items[0].message : "the stored request is invalid");
		goto done;
	}
	prsm_mc_options *mc = &s->study.mc;
	if (ctx->limits.threads > 0)
		mc->threads = ctx->limits.threads;
	if (ctx->limits.max_time_s > 0 && (mc->time_cap_s <= 0 || mc->time_cap_s > ctx->limits.max_time_s))
		mc->time_cap_s = ctx->limits.max_time_s;
	mc->cancel = ctx->cancel;
	mc->progress = ctx->progress;
	mc->progress_ctx = ctx->progress_ctx;
	rc = prsm_study_run(r, &s->study, err);
	if (rc)
		goto done;
	if (prsm_cancel_requested(ctx->cancel)) {
		prsm_study_result_free(r);
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the study was cancelled");
		goto done;
	}
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *res = prsm_io_study_result_to_json(s, r);
	if (res && warnings.count)
		cJSON_AddItemToObject(res, "design_warnings", prsm_io_problems_to_json(&warnings));
	/* whole or nothing: a member cJSON dropped for want of memory fails the run (global.h) */
	out->result = prsm_json_print_whole(res, mark, 0); /* handed to the caller */
	cJSON_Delete(res);
	if (!out->result) {
		prsm_study_result_free(r);
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
		goto done;
	}
	out->result_len = strlen(out->result);
	out->samples_done = (long long)r->run.n;
	out->samples_planned = (long long)mc->samples;
	rc = samples_csv(&out->csv, &out->csv_len, s, r);
	if (rc)
		rc = prsm_error_set(err, rc, NULL, "cannot write the samples CSV");
	prsm_study_result_free(r);
done:
	if (rc)
		prsm_job_output_free(out);
	cJSON_Delete(doc);
	free(s);
	free(r);
	return rc;
}

const prsm_job_kind prsm_job_kind_study = {
	.name = "study",
	.collection = "studies",
	.request_schema = "study.schema.json",
	.result_schema = "study-result.schema.json",
	.has_samples_csv = 1,
	.progress_unit = "samples",
	.version = study_version,
	.normalise = study_normalise,
	.run = study_run,
};
