/*
 * kind_calibration.c: the "calibration" job kind (/v1/calibrations): a measured transmission-error
 * curve (and optionally the cage ratio and the efficiency) confronted with the model, its lines
 * identified and calibrated (docs/measured-data.md; schemas/measured-request.schema.json in,
 * schemas/measured-result.schema.json out), run exactly as `prsm calibrate` runs it
 * (app/calibrate.h). The curve comes inside the request as arrays (measured.te): the service takes
 * no CSV file. Normalising reads and checks the whole request (the design with its statics, the
 * error set, the measured section and the calibration options), so every problem a run could
 * find before fitting is a 422 at submission, each at its JSON pointer. Progress counts analyses
 * (1): the application layer's calibration has no intermediate progress and no cancel point, so a
 * cancel takes effect when the fit returns. Nothing in the request is irrelevant to the result
 * (the measured name is echoed): the cache key is the whole request.
 */
#include "job/kind.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/calibrate.h"
#include "io/analysis_json.h"
#include "io/dynamics_json.h"
#include "io/global.h"
#include "io/measured.h"
#include "util/version.h"

static char calibration_version_text[512];
static pthread_once_t calibration_version_once = PTHREAD_ONCE_INIT;

/* The versions a calibration result names (its "engine" object), from the same constants: the
 * calibration, the statics model it compares with and the rigid model of the cage ratio. */
static void calibration_version_init(void)
{
	snprintf(calibration_version_text, sizeof calibration_version_text, "prsm %s; build %s; %s; %s; %s",
	         PRSM_VERSION, prsm_engine_build(), PRSM_CALIB_MODEL_VERSION, PRSM_MODEL_VERSION, PRSM_DYN_MODEL_VERSION);
}

static const char *calibration_version(void)
{
	pthread_once(&calibration_version_once, calibration_version_init);
	return calibration_version_text;
}

static int calibration_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	(void)lim;
	*out = NULL;
	prsm_app_calibration *c = NULL;
	int rc = prsm_app_calibration_load(&c, doc, NULL, problems);
	if (rc)
		return rc;
	prsm_app_calibration_free(c);
	*out = cJSON_Duplicate(doc, 1); /* handed to the caller */
	return *out ? 0 : PRSM_ENOMEM;
}

/* One analysis: planned 1, done 0 or 1. */
static void report(const prsm_job_run_ctx *ctx, size_t done)
{
	if (!ctx->progress)
		return;
	prsm_progress p = PRSM_PROGRESS_INIT;
	p.done = done;
	p.planned = 1;
	ctx->progress(ctx->progress_ctx, &p);
}

static int calibration_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	prsm_problems problems;
	prsm_problems_init(&problems);
	prsm_app_calibration *c = NULL;
	int rc;
	cJSON *doc = cJSON_Parse(request);
	if (!doc) {
		rc = prsm_error_set(err, PRSM_EINVAL, NULL, "cannot read the stored request");
		goto done;
	}
	report(ctx, 0);
	rc = prsm_app_calibration_load(&c, doc, NULL, &problems);
	if (rc) {
		rc = prsm_error_set(err, rc, problems.count ? problems.items[0].pointer : NULL, "%s",
		                    problems.count ? problems.items[0].message : "the stored request is invalid");
		goto done;
	}
	if (prsm_cancel_requested(ctx->cancel)) {
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the calibration was cancelled");
		goto done;
	}
	rc = prsm_app_calibration_run(c, err);
	if (rc)
		goto done;
	if (prsm_cancel_requested(ctx->cancel)) {
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the calibration was cancelled");
		goto done;
	}
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *res = prsm_app_calibration_result(c);
	out->result = res ? prsm_json_print_whole(res, mark, 0) : NULL; /* handed to the caller */
	cJSON_Delete(res);
	if (!out->result) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
		goto done;
	}
	out->result_len = strlen(out->result);
	out->samples_done = out->samples_planned = 1;
	report(ctx, 1);
done:
	if (rc)
		prsm_job_output_free(out);
	prsm_app_calibration_free(c);
	cJSON_Delete(doc);
	return rc;
}

const prsm_job_kind prsm_job_kind_calibration = {
	.name = "calibration",
	.collection = "calibrations",
	.request_schema = "measured-request.schema.json",
	.result_schema = "measured-result.schema.json",
	.has_samples_csv = 0,
	.progress_unit = "analyses",
	.progress_unit_of = NULL,
	.version = calibration_version,
	.normalise = calibration_normalise,
	.run = calibration_run,
};
