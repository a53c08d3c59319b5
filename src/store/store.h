/*
 * store.h: the service's SQLite database (DESIGN.md, "Service"): jobs, their requests, results
 * and samples; the cache is the set of finished jobs, looked up by cache key.
 *
 * One file (default ./prsm.db) in WAL mode, so readers never wait for the writer; every write
 * is one BEGIN IMMEDIATE transaction; the schema is migrated at open by PRAGMA user_version
 * (a newer database than this binary knows is refused). A small pool of connections, each
 * with its own lock and prepared statements, serves the HTTP threads and the workers; the
 * calls are safe from any thread.
 *
 * Job states: queued -> running -> done | failed; queued or running -> cancelled; running ->
 * queued again when the service stops or crashed (prsm_store_recover at open). A job's
 * request is stored as its canonical JSON, so a resumed job runs exactly what was accepted.
 * No JSON parsing here: documents are opaque text.
 */
#ifndef PRSM_STORE_STORE_H
#define PRSM_STORE_STORE_H

#include <stddef.h>

#include "util/error.h"

#define PRSM_STORE_ID_MAX 33     /* 32 hex digits and the NUL */
#define PRSM_STORE_KIND_MAX 24
#define PRSM_STORE_KEY_MAX 65    /* SHA-256 hex and the NUL */
#define PRSM_STORE_MAX_CONNS 64
#define PRSM_STORE_SCHEMA_VERSION 1 /* PRAGMA user_version this binary migrates to */

typedef enum {
	PRSM_JOB_QUEUED = 0,
	PRSM_JOB_RUNNING = 1,
	PRSM_JOB_DONE = 2,
	PRSM_JOB_FAILED = 3,
	PRSM_JOB_CANCELLED = 4
} prsm_job_state;

/* "queued", "running", "done", "failed", "cancelled"; never NULL. */
const char *prsm_job_state_name(prsm_job_state s);

/* One job's row. The text members are owned by the struct when loaded (free with
 * prsm_store_job_clear); they are NULL unless asked for. */
typedef struct {
	long long seq;                     /* insertion order, the list cursor */
	char id[PRSM_STORE_ID_MAX];
	char kind[PRSM_STORE_KIND_MAX];
	char key[PRSM_STORE_KEY_MAX];
	prsm_job_state state;
	double created_s, started_s, finished_s; /* Unix time, s; 0 when not (yet) */
	int attempts;                      /* times a worker started it */
	long long samples_done, samples_planned; /* at the last run's end */
	char *request;                     /* canonical request (PRSM_STORE_WITH_REQUEST) */
	char *result;                      /* result document, done jobs (PRSM_STORE_WITH_RESULT) */
	char *problem;                     /* problem document, failed jobs (PRSM_STORE_WITH_RESULT) */
	size_t result_len;
} prsm_store_job;

enum { PRSM_STORE_WITH_REQUEST = 1, PRSM_STORE_WITH_RESULT = 2 };

void prsm_store_job_clear(prsm_store_job *j);

typedef struct prsm_store prsm_store;

/* Open (creating) the database at path with n_conns connections (1..PRSM_STORE_MAX_CONNS),
 * WAL mode, migrated. *out is owned by the caller (prsm_store_close). Returns 0 or PRSM_EIO
 * (err says why: unopenable, not a prsm database, newer schema). */
int prsm_store_open(prsm_store **out, const char *path, int n_conns, prsm_error *err);
void prsm_store_close(prsm_store *s);

/* The schema version of an open store (PRAGMA user_version). */
int prsm_store_schema_version(prsm_store *s);

typedef enum {
	PRSM_SUBMIT_CREATED = 0, /* a new queued job */
	PRSM_SUBMIT_SHARED = 1,  /* an identical job is queued or running: that one */
	PRSM_SUBMIT_CACHED = 2,  /* an identical job is done: that one */
	PRSM_SUBMIT_FULL = 3     /* max_queued jobs are waiting: nothing inserted */
} prsm_submit_outcome;

/* In one transaction: the newest job of this kind and key that is queued, running or done,
 * or else a new queued job with a fresh random id (unless max_queued are queued already).
 * *out gets the job's row (no text members). Returns 0 or PRSM_EIO. */
int prsm_store_submit(prsm_store *s, prsm_store_job *out, prsm_submit_outcome *outcome,
                      const char *kind, const char *key, const char *request, size_t max_queued,
                      prsm_error *err);

/* The job with this id, with the text members asked for by flags. PRSM_ENOTFOUND when there
 * is none. */
int prsm_store_get(prsm_store *s, prsm_store_job *out, const char *id, int flags, prsm_error *err);

/* The samples CSV of a done job into *csv (owned by the caller: free()); PRSM_ENOTFOUND when
 * the job or its CSV does not exist. */
int prsm_store_get_csv(prsm_store *s, char **csv, size_t *len, const char *id, prsm_error *err);

/* Claim the oldest queued job: it becomes running, attempts + 1, started now; *out gets it
 * with its request. PRSM_ENOTFOUND when nothing is queued. */
int prsm_store_claim(prsm_store *s, prsm_store_job *out, prsm_error *err);

/* Record the end of a running job: state done (result, optional csv) or failed (problem).
 * A job that is no longer running (cancelled meanwhile) is left as it is, except that state
 * cancelled with a result attaches the best-so-far result of a cancelled job once; *applied
 * (may be NULL) says whether the row changed. */
int prsm_store_finish(prsm_store *s, const char *id, prsm_job_state state, const char *result,
                      const char *problem, const char *csv, size_t csv_len,
                      long long samples_done, long long samples_planned, int *applied,
                      prsm_error *err);

/* A running job back to queued (the service is stopping before it finished). */
int prsm_store_requeue(prsm_store *s, const char *id, prsm_error *err);

/* Cancel a queued or running job; *out gets its row after the change. PRSM_ENOTFOUND when
 * there is no such job, PRSM_ECANCELLED when it is already done, failed or cancelled (then
 * *out has its row as it is). */
int prsm_store_cancel(prsm_store *s, prsm_store_job *out, const char *id, prsm_error *err);

/* At start: every running job (the service stopped or crashed under it) back to queued;
 * *n gets how many. */
int prsm_store_recover(prsm_store *s, int *n, prsm_error *err);

/* Jobs of a kind, newest first, with seq < before_seq (0: from the newest), at most max rows
 * into items (no text members); *n the rows written, *more 1 when older ones remain. */
int prsm_store_list(prsm_store *s, prsm_store_job *items, size_t max, size_t *n, int *more,
                    const char *kind, long long before_seq, prsm_error *err);

/* Number of jobs in a state (all kinds). */
int prsm_store_count(prsm_store *s, long long *n, prsm_job_state state, prsm_error *err);

#endif
