/*
 * jobs.h: the job service under the HTTP layer (DESIGN.md, "Service"): submissions become
 * stored jobs keyed by the SHA-256 of their canonical request and the engine version; a pool
 * of worker threads (separate from the HTTP threads) claims them from the store in order and
 * runs them by their kind (kind.h); identical requests share one job while it is queued or
 * running, and a done job is the cached answer. Progress lives in memory while a job runs;
 * everything else is in the store, so accepted work survives a crash: at open, jobs left
 * running are queued again and run from the start (a study is deterministic for its seed).
 * Closing stops the workers: a running job is cancelled and queued again for the next start.
 */
#ifndef PRSM_JOB_JOBS_H
#define PRSM_JOB_JOBS_H

#include <stddef.h>

#include <cJSON.h>

#include "job/kind.h"
#include "store/store.h"
#include "util/error.h"
#include "util/problems.h"

#define PRSM_JOBS_MAX_WORKERS 64
#define PRSM_JOBS_MAX_REQUEST_BYTES (8u * 1024u * 1024u) /* canonical request */

/* Where a job runs when not in the worker thread itself (e.g. a Slurm cluster: job/slurm.h).
 * wants: 1 when the job of kind k with this stored (canonical) request goes there. run: as the
 * kind's run (kind.h), on the worker's thread, which waits for it: *out filled with the result
 * (and CSV and counts) of the kind's run, or an error in err (code, pointer and message as the
 * kind's run gave them); ctx->cancel polled (PRSM_ECANCELLED). id: the job's id. */
typedef struct prsm_job_executor {
	const char *name;
	int (*wants)(void *ctx, const prsm_job_kind *k, const char *request);
	int (*run)(void *ctx, prsm_job_output *out, const prsm_job_kind *k, const char *id, const char *request,
	           const prsm_job_run_ctx *run_ctx, prsm_error *err);
	void *ctx;
} prsm_job_executor;

typedef struct {
	const char *db_path;       /* SQLite file */
	int workers;               /* worker threads (jobs run at once) */
	int store_connections;     /* connections in the store's pool (HTTP threads + workers + 1) */
	size_t max_queued;         /* submissions past this many queued jobs are refused */
	prsm_job_limits limits;    /* per job */
	const prsm_job_kind *const *kinds; /* the kinds run here; NULL: prsm_job_kinds (tests
	                                      give their own) */
	size_t n_kinds;
	const char *engine_build;  /* part of every cache key; NULL: this binary's
	                              prsm_engine_build() (tests give another to act as an
	                              older or newer engine) */
	const prsm_job_executor *executor; /* NULL: every job runs in its worker thread */
} prsm_jobs_options;

#define PRSM_JOBS_OPTIONS_INIT {"prsm.db", 1, 4, 64, {200000, 600.0, 1}, NULL, 0, NULL, NULL}

typedef struct prsm_jobs prsm_jobs;

/* A job as the API shows it: its stored row (text members owned: prsm_job_view_clear) and,
 * while it runs here, its live progress. */
typedef struct {
	prsm_store_job row;
	const prsm_job_kind *kind;
	int live;                        /* progress figures below are from the running worker */
	long long samples_done, samples_planned;
	double eta_s;                    /* NAN when unknown */
	double interval_width;           /* the running stop rule's figure (prsm_progress), NAN: none */
	double interval_goal;            /* its goal, NAN: none */
	double best;                     /* best objective so far (optimisation), NAN: none */
	const char *phase;               /* the running phase (prsm_progress.phase), NULL: none */
	const char *unit;                /* what samples_done counts: the running work's own unit, else
	                                    the kind's for this request (progress_unit_of), else the kind's */
	int cache_hit;                   /* the submission was answered from the cache */
} prsm_job_view;

void prsm_job_view_clear(prsm_job_view *v);

/* The cache key (PRSM_SHA256_HEX bytes into key) of the canonical request text canon (len
 * bytes) of kind k for the engine build engine_build: the SHA-256 of the kind's name, the
 * kind's version, the engine build and the text. A cache written by another build of the
 * engine (another model, engine, reader or schema source) never matches. */
void prsm_jobs_cache_key(char *key, const prsm_job_kind *k, const char *engine_build, const char *canon,
                         size_t len);

/* Open the store (recovering jobs left running) and start the workers. *out owned by the
 * caller (prsm_jobs_close). Returns 0 or the store's code. *recovered (may be NULL) gets the
 * number of jobs queued again. */
int prsm_jobs_open(prsm_jobs **out, const prsm_jobs_options *o, int *recovered, prsm_error *err);

/* Stop accepting work, stop the workers (a running job is cancelled and queued again), close
 * the store and free j. */
void prsm_jobs_close(prsm_jobs *j);

/* Validate and submit doc (not taken over) as a job of kind k. Returns 0 with *out and
 * *outcome (created, shared, cached: then out->row has the result; full: nothing stored);
 * PRSM_EINVAL (or the kind's code) with every problem in problems; PRSM_EIO. */
int prsm_jobs_submit(prsm_jobs *j, prsm_job_view *out, prsm_submit_outcome *outcome,
                     const prsm_job_kind *k, const cJSON *doc, prsm_problems *problems, prsm_error *err);

/* The job id of kind k (flags: PRSM_STORE_WITH_RESULT for the result or problem).
 * PRSM_ENOTFOUND when there is none of that kind. */
int prsm_jobs_get(prsm_jobs *j, prsm_job_view *out, const prsm_job_kind *k, const char *id, int flags,
                  prsm_error *err);

/* Cancel a queued or running job of kind k. PRSM_ENOTFOUND, or PRSM_ECANCELLED when it had
 * already finished or was cancelled (out then has it as it is). */
int prsm_jobs_cancel(prsm_jobs *j, prsm_job_view *out, const prsm_job_kind *k, const char *id,
                     prsm_error *err);

/* The samples CSV of a done job of kind k (*csv owned by the caller). */
int prsm_jobs_csv(prsm_jobs *j, char **csv, size_t *len, const prsm_job_kind *k, const char *id,
                  prsm_error *err);

/* A page of jobs of kind k, newest first, older than the cursor seq (0: the newest).
 * items has room for max; *n written; *next_seq the cursor of the next page (0: none). */
int prsm_jobs_list(prsm_jobs *j, prsm_job_view *items, size_t max, size_t *n, long long *next_seq,
                   const prsm_job_kind *k, long long before_seq, prsm_error *err);

/* Workers and how many run a job now (for /health). */
void prsm_jobs_counts(prsm_jobs *j, int *workers, int *running);

/* The per-job limits submissions are held to (for POST /v1/validate). */
prsm_job_limits prsm_jobs_limits(const prsm_jobs *j);

/* The job document (schemas/job.schema.json) of a view, without "result" (the caller splices
 * the stored result text in, see prsm_job_view_to_text). Caller owns the tree. */
cJSON *prsm_job_view_to_json(const prsm_job_view *v);

/* The whole job document as text with the stored result (if any) spliced in, with
 * "cache_hit" of the result set when the view was a cache hit. *out is malloc'd (the
 * caller's). Returns 0 or PRSM_ENOMEM. */
int prsm_job_view_to_text(char **out, size_t *len, const prsm_job_view *v);

#endif
