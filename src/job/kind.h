/*
 * kind.h: the kinds of job the service runs, as one table (DESIGN.md, "Service": one request =
 * one job). A kind is everything the generic machinery (queue, workers, store, cache, HTTP
 * routes /v1/<collection>) needs to know about one document type:
 *
 *   name, collection   "study", "studies": stored with each job, and the URL of its collection
 *   schemas            the request and result schemas (schemas/), named in job documents
 *   version            what produced the results (engine and model versions): part of the
 *                      cache key, so a new engine never serves an old result
 *   normalise          load and validate a request with the service's limits, every problem
 *                      with its JSON pointer; give the tree the cache key is computed from
 *   run                run a stored request with cancellation and progress, and write the
 *                      result document (and optionally a samples CSV)
 *
 * Adding /v1/optimizations is one more entry in prsm_job_kinds (kinds.c) and a file like
 * kind_study.c; the routes, paging, cancel, cache, persistence and resume come with it.
 */
#ifndef PRSM_JOB_KIND_H
#define PRSM_JOB_KIND_H

#include <stddef.h>
#include <stdio.h>

#include <cJSON.h>

#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

/* The service's limits on one job (prsm serve options). */
typedef struct {
	size_t max_samples;   /* Monte Carlo samples of one run; also Sobol evaluations */
	double max_time_s;    /* time cap of one job, s (0: none) */
	int threads;          /* engine threads per job */
} prsm_job_limits;

/* Progress (util/progress.h): samples or evaluations done and planned so far, the stop rule's
 * interval width, the best objective; called from the running worker's thread. */
typedef prsm_progress_fn prsm_job_progress_fn;

typedef struct {
	prsm_cancel_flag *cancel;              /* nonzero: stop as soon as possible (PRSM_ECANCELLED) */
	prsm_job_progress_fn progress;     /* may be NULL */
	void *progress_ctx;
	prsm_job_limits limits;
} prsm_job_run_ctx;

/* What a run hands back; the buffers are malloc'd and the caller takes them
 * (prsm_job_output_free). */
typedef struct {
	char *result;                      /* the result document, JSON text */
	size_t result_len;
	char *csv;                         /* samples as CSV, or NULL */
	size_t csv_len;
	long long samples_done, samples_planned;
} prsm_job_output;

void prsm_job_output_free(prsm_job_output *o);

/* What write(f, ctx) prints, as a malloc'd buffer (*text, the caller's, *len bytes): an in-memory
 * CSV for prsm_job_output.csv. Returns 0, write's error, PRSM_EIO or PRSM_ENOMEM (*text NULL). */
int prsm_job_text(char **text, size_t *len, int (*write)(FILE *f, const void *ctx), const void *ctx);

typedef struct prsm_job_kind {
	const char *name;            /* job kind, e.g. "study" */
	const char *collection;      /* URL collection under /v1, e.g. "studies" */
	const char *request_schema;  /* e.g. "study.schema.json" */
	const char *result_schema;   /* e.g. "study-result.schema.json" */
	int has_samples_csv;         /* GET /v1/<collection>/{id}/samples.csv exists */
	const char *progress_unit;   /* what progress counts: "samples", "evaluations" or
	                                "simulated_ns" (nanoseconds of simulated time) */
	/* What progress counts for one stored request, when it depends on the request (a static
	 * string, or NULL: progress_unit); may be NULL. */
	const char *(*progress_unit_of)(const char *request);
	/* Engine and model versions of the results (a static string, computed once). */
	const char *(*version)(void);
	/* Validate doc (not taken over) against the document's rules and lim; on success *out is
	 * the normalised request (owned by the caller: cJSON_Delete) whose canonical JSON keys the
	 * cache: fields that cannot change the result (e.g. thread counts) are dropped. Returns 0,
	 * or a PRSM_E* code with every problem in problems. */
	int (*normalise)(cJSON **out, const cJSON *doc, const prsm_job_limits *lim, prsm_problems *problems);
	/* Run a stored (normalised, canonical) request. Returns 0 with *out filled,
	 * PRSM_ECANCELLED when ctx->cancel stopped it, or another code with err saying why. */
	int (*run)(prsm_job_output *out, const char *request, const prsm_job_run_ctx *ctx, prsm_error *err);
} prsm_job_kind;

/* The table, and its length. */
extern const prsm_job_kind *const prsm_job_kinds[];
extern const size_t prsm_job_kind_count;

/* The kind of a collection ("studies") or of a name ("study"); NULL when none. */
const prsm_job_kind *prsm_job_kind_by_collection(const char *collection);
const prsm_job_kind *prsm_job_kind_by_name(const char *name);

/* The kinds, one per file. */
extern const prsm_job_kind prsm_job_kind_study;
extern const prsm_job_kind prsm_job_kind_optimization;
extern const prsm_job_kind prsm_job_kind_allocation;
extern const prsm_job_kind prsm_job_kind_analysis;
extern const prsm_job_kind prsm_job_kind_simulation;
extern const prsm_job_kind prsm_job_kind_calibration;

#endif
