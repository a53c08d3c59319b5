/*
 * kind_simulation.c: the "simulation" job kind (/v1/simulations): a start-up transient or a
 * vibration analysis (linear, vibration, sweep, frequency_response, basins of the reduced model
 * or of a gear pair; docs/vibration.md) (schemas/simulation.schema.json in,
 * schemas/dynamics-result.schema.json out, the series as CSV at /v1/simulations/{id}/samples.csv:
 * the transient's time series, or the CSV of `prsm simulate --csv` for the analysis), run exactly
 * as `prsm simulate` runs it (app/simulate.h) with the service's per-job time cap, threads and
 * cancel. Progress counts simulated nanoseconds (transient), sweep points (sweep,
 * frequency_response), basin cells (basins) or analyses, 1 (linear, vibration); the job's
 * progress.unit says which (progress_unit_of reads the analysis from the stored request). Normalising builds the model (masses, statics references, the settled state, the
 * vibration model), so every problem a run could find before integrating is a 422 at submission;
 * the service also caps what bounds the stored result: the transient's output grid
 * (PRSM_JOB_SIMULATION_POINTS_MAX points), the recorded values of a sweep
 * (PRSM_JOB_SWEEP_VALUES_MAX) and the samples of a steady state's window
 * (PRSM_JOB_STEADY_SAMPLES_MAX). Nothing in the request is irrelevant to the result (the engine
 * threads are the service's, and the results do not depend on them): the cache key is the whole
 * request.
 */
#include "job/kind.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/simulate.h"
#include "io/dynamics_json.h"
#include "io/global.h"
#include "util/version.h"

/* Output times a service job may ask for (about 0.7 kB of JSON each for one stage). */
#define PRSM_JOB_SIMULATION_POINTS_MAX 100001
/* Sweep points x recorded periods of a sweep or frequency-response job (about 20 bytes each). */
#define PRSM_JOB_SWEEP_VALUES_MAX 1000000
/* Recorded periods x samples per period of a steady state (the phase portrait, two numbers each). */
#define PRSM_JOB_STEADY_SAMPLES_MAX 500000

static char simulation_version_text[512];
static pthread_once_t simulation_version_once = PTHREAD_ONCE_INIT;

/* The versions a simulation result names (its "engine" object), from the same constants. */
static void simulation_version_init(void)
{
	snprintf(simulation_version_text, sizeof simulation_version_text, "prsm %s; build %s; %s; %s", PRSM_VERSION,
	         prsm_engine_build(), PRSM_DYN_MODEL_VERSION, PRSM_VIB_MODEL_VERSION);
}

static const char *simulation_version(void)
{
	pthread_once(&simulation_version_once, simulation_version_init);
	return simulation_version_text;
}

static int simulation_normalise(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems)
{
	(void)lim;
	*out = NULL;
	prsm_app_simulation *s;
	int rc = prsm_app_simulation_load(&s, doc, NULL, problems);
	if (rc)
		return rc;
	const size_t points = prsm_app_simulation_points(s);
	const prsm_app_vibration *vib = prsm_app_simulation_vibration(s);
	if (vib != NULL) {
		const prsm_io_vib_request *q = prsm_app_vibration_request(vib);
		const int analysis = prsm_app_simulation_analysis(s);
		const size_t work = prsm_app_vibration_work(vib);
		double values = 0.0;
		if (analysis == PRSM_IO_DYN_SWEEP || analysis == PRSM_IO_DYN_FREQUENCY_RESPONSE)
			values = (double)work * q->sweep.recorded_periods;
		const double samples = analysis == PRSM_IO_DYN_VIBRATION
		                           ? (double)q->steady_state.recorded_periods * q->steady_state.samples_per_period
		                           : 0.0;
		const int recorded = q->sweep.recorded_periods;
		prsm_app_simulation_free(s); /* q with it */
		if (values > PRSM_JOB_SWEEP_VALUES_MAX) {
			prsm_problems_add(problems, "/dynamics/sweep/step", "service_cap",
			                  "%.0f sweep points x %d recorded periods: this service keeps at most %d recorded values "
			                  "per sweep (the command line more): raise the step or record fewer periods",
			                  (double)work, recorded, PRSM_JOB_SWEEP_VALUES_MAX);
			return PRSM_EINVAL;
		}
		if (samples > PRSM_JOB_STEADY_SAMPLES_MAX) {
			prsm_problems_add(problems, "/dynamics/steady_state/samples_per_period", "service_cap",
			                  "%.0f samples of the recorded window: this service keeps at most %d (the command line "
			                  "more): fewer samples per period or recorded periods",
			                  samples, PRSM_JOB_STEADY_SAMPLES_MAX);
			return PRSM_EINVAL;
		}
		*out = cJSON_Duplicate(doc, 1); /* handed to the caller */
		return *out ? 0 : PRSM_ENOMEM;
	}
	prsm_app_simulation_free(s);
	if (points > PRSM_JOB_SIMULATION_POINTS_MAX) {
		prsm_problems_add(problems, "/dynamics/time/output_step_s", "service_cap",
		                  "%zu output times: this service keeps at most %d per simulation (the command line "
		                  "up to %d): raise the output step",
		                  points, PRSM_JOB_SIMULATION_POINTS_MAX, PRSM_DYN_OUTPUT_POINTS_MAX);
		return PRSM_EINVAL;
	}
	*out = cJSON_Duplicate(doc, 1); /* handed to the caller */
	return *out ? 0 : PRSM_ENOMEM;
}

static int series_csv(FILE *f, const void *s)
{
	return prsm_app_simulation_csv(f, s);
}

static int simulation_run(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	prsm_problems problems;
	prsm_problems_init(&problems);
	prsm_app_simulation *s = NULL;
	int rc;
	cJSON *doc = cJSON_Parse(request);
	if (!doc) {
		rc = prsm_error_set(err, PRSM_EINVAL, NULL, "cannot read the stored request");
		goto done;
	}
	rc = prsm_app_simulation_load(&s, doc, NULL, &problems);
	if (rc) {
		rc = prsm_error_set(err, rc, problems.count ? problems.items[0].pointer : NULL, "%s",
		                    problems.count ? problems.items[0].message : "the stored request is invalid");
		goto done;
	}
	prsm_app_simulation_set_threads(s, ctx->limits.threads);
	rc = prsm_app_simulation_run(s, ctx->cancel, ctx->progress, ctx->progress_ctx, ctx->limits.max_time_s, err);
	if (rc)
		goto done; /* not converged, cancelled or out of time: err says which, and no curve */
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *res = prsm_app_simulation_result(s);
	out->result = prsm_json_print_whole(res, mark, 0); /* handed to the caller */
	cJSON_Delete(res);
	if (!out->result) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
		goto done;
	}
	out->result_len = strlen(out->result);
	out->samples_done = out->samples_planned = (long long)prsm_app_simulation_work(s, NULL);
	if ((rc = prsm_job_text(&out->csv, &out->csv_len, series_csv, s)))
		rc = prsm_error_set(err, rc, NULL, "cannot write the time series CSV");
done:
	if (rc)
		prsm_job_output_free(out);
	prsm_app_simulation_free(s);
	cJSON_Delete(doc);
	return rc;
}

/* What progress counts for a stored request: by its dynamics.analysis. */
static const char *simulation_unit_of(const char *request)
{
	cJSON *doc = cJSON_Parse(request);
	const cJSON *a = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "dynamics"), "analysis");
	const char *unit = "simulated_ns";
	if (cJSON_IsString(a)) {
		if (strcmp(a->valuestring, "sweep") == 0 || strcmp(a->valuestring, "frequency_response") == 0)
			unit = "sweep_points";
		else if (strcmp(a->valuestring, "basins") == 0)
			unit = "basin_cells";
		else if (strcmp(a->valuestring, "linear") == 0 || strcmp(a->valuestring, "vibration") == 0)
			unit = "analyses";
	}
	cJSON_Delete(doc);
	return unit;
}

const prsm_job_kind prsm_job_kind_simulation = {
	.name = "simulation",
	.collection = "simulations",
	.request_schema = "simulation.schema.json",
	.result_schema = "dynamics-result.schema.json",
	.has_samples_csv = 1,
	.progress_unit = "simulated_ns",
	.progress_unit_of = simulation_unit_of,
	.version = simulation_version,
	.normalise = simulation_normalise,
	.run = simulation_run,
};
