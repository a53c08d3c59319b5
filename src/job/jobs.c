/*
 * jobs.c: submissions, the worker pool and live progress (see jobs.h).
 *
 * Locking: j->mu guards the workers' slots (which job each runs, its progress), the work
 * generation and the stopping flag, and is never held across a call into the store (whose
 * writes may wait for SQLite's busy timeout): a claim happens outside it and the claimed job
 * is registered under it afterwards. A cancel writes the store first, then raises the flag of
 * the worker that runs the job; a worker, once registered, reads its job's state back from
 * the store, so a cancel that fell between the claim and the registration is seen there and
 * one after the registration finds the flag. The flags are C11 atomics (util/cancel.h): the
 * running computation polls them without the lock. Idle workers sleep on j->cv until a
 * submission raises the work generation (no polling of the store); after a store error they
 * retry after a second. The store has its own locks.
 */
#include "job/jobs.h"
#include "io/global.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "io/analysis_json.h"
#include "io/canonical.h"
#include "io/json_util.h"
#include "util/clock.h"
#include "util/sha256.h"
#include "util/version.h"

typedef struct {
	struct prsm_jobs *jobs;
	pthread_t thread;
	int started;
	char id[PRSM_STORE_ID_MAX];          /* the job running here, "" when idle */
	prsm_cancel_flag cancel;             /* raised by a cancel or by closing */
	prsm_progress progress;              /* of the running job */
	double started_clock_s;              /* prsm_clock_seconds() at its start */
} worker;

struct prsm_jobs {
	prsm_store *store;
	prsm_jobs_options opt;
	pthread_mutex_t mu;
	pthread_cond_t cv;
	unsigned long work_generation;       /* raised by every submission that queues a job */
	int stopping;
	int n_workers;
	worker w[PRSM_JOBS_MAX_WORKERS];
};

void prsm_job_view_clear(prsm_job_view *v)
{
	prsm_store_job_clear(&v->row);
}

static void progress_cb(void *ctx, const prsm_progress *p)
{
	worker *w = ctx;
	pthread_mutex_lock(&w->jobs->mu);
	w->progress = *p;
	pthread_mutex_unlock(&w->jobs->mu);
}

/* The problem document of a failed run, as text (malloc'd; NULL when out of memory). */
static char *failure_problem(const prsm_error *err)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_problems_add(&p, err->pointer, "computation", "%s", err->message[0] ? err->message : prsm_error_name(err->code));
	int status = prsm_error_http_status(err->code);
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *doc = prsm_io_problem_document(status, status == 422 ? "Unprocessable Content" : "Computation failed", &p);
	char *text = prsm_json_print_whole(doc, mark, 0);
	cJSON_Delete(doc);
	return text;
}

static void run_one(worker *w, prsm_store_job *job)
{
	prsm_jobs *j = w->jobs;
	const prsm_job_kind *k = NULL;
	for (size_t i = 0; i < j->opt.n_kinds; i++)
		if (strcmp(j->opt.kinds[i]->name, job->kind) == 0)
			k = j->opt.kinds[i];
	prsm_error err = PRSM_ERROR_INIT;
	prsm_job_output out = {0};
	int rc;
	if (!k) {
		rc = prsm_error_set(&err, PRSM_EINVAL, NULL, "this prsm has no job kind '%s'", job->kind);
	} else {
		prsm_job_run_ctx ctx = {&w->cancel, progress_cb, w, j->opt.limits};
		const prsm_job_executor *ex = j->opt.executor;
		if (ex && ex->wants(ex->ctx, k, job->request))
			rc = ex->run(ex->ctx, &out, k, job->id, job->request, &ctx, &err);
		else
			rc = k->run(&out, job->request, &ctx, &err);
	}
	pthread_mutex_lock(&j->mu);
	int cancelled = prsm_cancel_requested(&w->cancel), stopping = j->stopping;
	w->id[0] = '\0';
	pthread_mutex_unlock(&j->mu);
	prsm_error serr = PRSM_ERROR_INIT;
	if (rc == 0) {
		if (prsm_store_finish(j->store, job->id, PRSM_JOB_DONE, out.result, NULL, out.csv, out.csv_len,
		                      out.samples_done, out.samples_planned, NULL, &serr))
			fprintf(stderr, "prsm serve: job %s: %s\n", job->id, serr.message);
	} else if (cancelled || rc == PRSM_ECANCELLED) {
		/* a cancel left the store's row cancelled already: it keeps the best point so far of a
		 * kind that hands one back; a shutdown queues it again */
		if (stopping) {
			if (prsm_store_requeue(j->store, job->id, &serr))
				fprintf(stderr, "prsm serve: job %s: %s\n", job->id, serr.message);
		} else if (out.result &&
		           prsm_store_finish(j->store, job->id, PRSM_JOB_CANCELLED, out.result, NULL, NULL, 0,
		                             out.samples_done, out.samples_planned, NULL, &serr)) {
			fprintf(stderr, "prsm serve: job %s: %s\n", job->id, serr.message);
		}
	} else {
		char *problem = failure_problem(&err);
		if (prsm_store_finish(j->store, job->id, PRSM_JOB_FAILED, NULL, problem ? problem : "{}", NULL, 0, 0, 0,
		                      NULL, &serr))
			fprintf(stderr, "prsm serve: job %s: %s\n", job->id, serr.message);
		free(problem);
	}
	prsm_job_output_free(&out);
}

/* Under j->mu: take job (just claimed from the store) as w's. A worker registered after
 * prsm_jobs_close began is cancelled at once (its job is then queued again). */
static void register_claim(worker *w, const prsm_store_job *job)
{
	snprintf(w->id, sizeof w->id, "%s", job->id);
	prsm_cancel_set(&w->cancel, w->jobs->stopping ? PRSM_CANCEL_SHUTDOWN : PRSM_CANCEL_NONE);
	w->progress = (prsm_progress)PRSM_PROGRESS_INIT;
	w->started_clock_s = prsm_clock_seconds();
}

/* A cancel that reached the store between the claim and the registration (see the top). */
static void read_back_cancel(worker *w, const char *id)
{
	prsm_store_job row;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_store_get(w->jobs->store, &row, id, 0, &err) == 0) {
		if (row.state == PRSM_JOB_CANCELLED)
			prsm_cancel_set(&w->cancel, PRSM_CANCEL_JOB);
		prsm_store_job_clear(&row);
	}
}

static void *worker_main(void *arg)
{
	worker *w = arg;
	prsm_jobs *j = w->jobs;
	pthread_mutex_lock(&j->mu);
	while (!j->stopping) {
		const unsigned long generation = j->work_generation;
		pthread_mutex_unlock(&j->mu);
		prsm_store_job job;
		prsm_error err = PRSM_ERROR_INIT;
		int rc = prsm_store_claim(j->store, &job, &err);
		pthread_mutex_lock(&j->mu);
		if (rc == 0) {
			register_claim(w, &job);
			pthread_mutex_unlock(&j->mu);
			read_back_cancel(w, job.id);
			run_one(w, &job);
			prsm_store_job_clear(&job);
			pthread_mutex_lock(&j->mu);
			continue;
		}
		if (rc != PRSM_ENOTFOUND) {
			/* the store failed (busy past its timeout, disk): try again in a second */
			fprintf(stderr, "prsm serve: worker: %s\n", err.message);
			prsm_cond_wait_for(&j->cv, &j->mu, 1.0);
			continue;
		}
		/* nothing queued: sleep until a submission queues a job (or closing) */
		while (!j->stopping && j->work_generation == generation)
			pthread_cond_wait(&j->cv, &j->mu);
	}
	pthread_mutex_unlock(&j->mu);
	return NULL;
}

int prsm_jobs_open(prsm_jobs **out, const prsm_jobs_options *o, int *recovered, prsm_error *err)
{
	*out = NULL;
	if (o->workers < 1 || o->workers > PRSM_JOBS_MAX_WORKERS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "workers: %d (1..%d)", o->workers, PRSM_JOBS_MAX_WORKERS);
	prsm_jobs *j = calloc(1, sizeof *j); /* handed to the caller */
	if (!j)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	j->opt = *o;
	if (!j->opt.engine_build)
		j->opt.engine_build = prsm_engine_build();
	if (!j->opt.kinds) {
		j->opt.kinds = prsm_job_kinds;
		j->opt.n_kinds = prsm_job_kind_count;
	}
	int rc = prsm_store_open(&j->store, o->db_path, o->store_connections, err);
	if (rc) {
		free(j);
		return rc;
	}
	int n = 0;
	rc = prsm_store_recover(j->store, &n, err);
	if (rc) {
		prsm_store_close(j->store);
		free(j);
		return rc;
	}
	if (recovered)
		*recovered = n;
	/* compute the kinds' versions now, not in the first request */
	for (size_t i = 0; i < j->opt.n_kinds; i++)
		j->opt.kinds[i]->version();
	pthread_mutex_init(&j->mu, NULL);
	prsm_cond_init_monotonic(&j->cv);
	j->n_workers = o->workers;
	for (int i = 0; i < j->n_workers; i++) {
		j->w[i].jobs = j;
		j->w[i].started = pthread_create(&j->w[i].thread, NULL, worker_main, &j->w[i]) == 0;
		if (!j->w[i].started) {
			prsm_jobs_close(j);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "cannot start worker %d", i);
		}
	}
	*out = j;
	return 0;
}

void prsm_jobs_close(prsm_jobs *j)
{
	if (!j)
		return;
	pthread_mutex_lock(&j->mu);
	j->stopping = 1;
	for (int i = 0; i < j->n_workers; i++)
		if (j->w[i].id[0])
			prsm_cancel_set(&j->w[i].cancel, PRSM_CANCEL_SHUTDOWN);
	pthread_cond_broadcast(&j->cv);
	pthread_mutex_unlock(&j->mu);
	for (int i = 0; i < j->n_workers; i++)
		if (j->w[i].started)
			pthread_join(j->w[i].thread, NULL);
	pthread_cond_destroy(&j->cv);
	pthread_mutex_destroy(&j->mu);
	prsm_store_close(j->store);
	free(j);
}

/* Live progress of a job running here, under j->mu. */
static void add_live(prsm_jobs *j, prsm_job_view *v)
{
	v->eta_s = NAN;
	v->interval_width = NAN;
	v->interval_goal = NAN;
	v->best = NAN;
	v->phase = NULL;
	v->unit = v->row.request && v->kind && v->kind->progress_unit_of ? v->kind->progress_unit_of(v->row.request) : NULL;
	v->samples_done = v->row.samples_done;
	v->samples_planned = v->row.samples_planned;
	if (v->row.state != PRSM_JOB_RUNNING)
		return;
	pthread_mutex_lock(&j->mu);
	for (int i = 0; i < j->n_workers; i++) {
		worker *w = &j->w[i];
		if (w->id[0] && strcmp(w->id, v->row.id) == 0) {
			v->live = 1;
			const prsm_progress *p = &w->progress;
			v->samples_done = (long long)p->done;
			v->samples_planned = (long long)p->planned;
			v->interval_width = p->interval_width;
			v->interval_goal = p->interval_goal;
			v->best = p->best;
			v->phase = p->phase;
			if (p->unit)
				v->unit = p->unit;
			double elapsed = prsm_clock_seconds() - w->started_clock_s;
			if (p->done > 0 && p->planned >= p->done)
				v->eta_s = elapsed * (double)(p->planned - p->done) / (double)p->done;
			break;
		}
	}
	pthread_mutex_unlock(&j->mu);
}

void prsm_jobs_cache_key(char *key, const prsm_job_kind *k, const char *engine_build, const char *canon,
                         size_t len)
{
	prsm_sha256 h;
	uint8_t d[PRSM_SHA256_BYTES];
	const char *version = k->version();
	prsm_sha256_init(&h);
	prsm_sha256_update(&h, k->name, strlen(k->name) + 1);
	prsm_sha256_update(&h, version, strlen(version) + 1);
	prsm_sha256_update(&h, engine_build, strlen(engine_build) + 1);
	prsm_sha256_update(&h, canon, len);
	prsm_sha256_final(&h, d);
	prsm_sha256_to_hex(key, d);
}

int prsm_jobs_submit(prsm_jobs *j, prsm_job_view *out, prsm_submit_outcome *outcome,
                     const prsm_job_kind *k, const cJSON *doc, prsm_problems *problems, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->kind = k;
	out->eta_s = out->interval_width = out->interval_goal = out->best = NAN;
	cJSON *norm = NULL;
	int rc = k->normalise(&norm, doc, &j->opt.limits, problems);
	if (rc)
		return prsm_error_set(err, rc, NULL, "the request is invalid");
	char *canon = NULL;
	size_t len = 0;
	rc = prsm_canonical_json(&canon, &len, norm, PRSM_JOBS_MAX_REQUEST_BYTES, err);
	cJSON_Delete(norm);
	if (rc) {
		prsm_problems_add(problems, err->pointer, "canonical", "%s", err->message);
		return rc;
	}
	char key[PRSM_SHA256_HEX];
	prsm_jobs_cache_key(key, k, j->opt.engine_build, canon, len);
	rc = prsm_store_submit(j->store, &out->row, outcome, k->name, key, canon, j->opt.max_queued, err);
	free(canon);
	if (rc)
		return rc;
	if (*outcome == PRSM_SUBMIT_CREATED) {
		pthread_mutex_lock(&j->mu);
		j->work_generation++;
		pthread_cond_signal(&j->cv);
		pthread_mutex_unlock(&j->mu);
	} else if (*outcome == PRSM_SUBMIT_CACHED) {
		char id[PRSM_STORE_ID_MAX];
		snprintf(id, sizeof id, "%s", out->row.id);
		rc = prsm_store_get(j->store, &out->row, id, PRSM_STORE_WITH_RESULT, err);
		if (rc)
			return rc;
		out->cache_hit = 1;
	}
	if (*outcome != PRSM_SUBMIT_FULL)
		add_live(j, out);
	return 0;
}

int prsm_jobs_get(prsm_jobs *j, prsm_job_view *out, const prsm_job_kind *k, const char *id, int flags,
                  prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->kind = k;
	if (k->progress_unit_of) /* the unit of a finished job follows from its request */
		flags |= PRSM_STORE_WITH_REQUEST;
	int rc = prsm_store_get(j->store, &out->row, id, flags, err);
	if (rc)
		return rc;
	if (strcmp(out->row.kind, k->name) != 0) {
		prsm_job_view_clear(out);
		return prsm_error_set(err, PRSM_ENOTFOUND, NULL, "no %s %.40s", k->name, id);
	}
	add_live(j, out);
	return 0;
}

int prsm_jobs_cancel(prsm_jobs *j, prsm_job_view *out, const prsm_job_kind *k, const char *id,
                     prsm_error *err)
{
	int rc = prsm_jobs_get(j, out, k, id, 0, err);
	if (rc)
		return rc;
	prsm_job_view_clear(out);
	memset(out, 0, sizeof *out);
	out->kind = k;
	out->eta_s = out->interval_width = out->interval_goal = out->best = NAN;
	/* the store first, then the flag: see the top of the file */
	rc = prsm_store_cancel(j->store, &out->row, id, err);
	if (rc == 0) {
		pthread_mutex_lock(&j->mu);
		for (int i = 0; i < j->n_workers; i++)
			if (j->w[i].id[0] && strcmp(j->w[i].id, id) == 0)
				prsm_cancel_set(&j->w[i].cancel, PRSM_CANCEL_JOB);
		pthread_mutex_unlock(&j->mu);
	}
	out->samples_done = out->row.samples_done;
	out->samples_planned = out->row.samples_planned;
	return rc;
}

int prsm_jobs_csv(prsm_jobs *j, char **csv, size_t *len, const prsm_job_kind *k, const char *id,
                  prsm_error *err)
{
	*csv = NULL;
	*len = 0;
	prsm_job_view v;
	int rc = prsm_jobs_get(j, &v, k, id, 0, err);
	if (rc)
		return rc;
	if (v.row.state != PRSM_JOB_DONE)
		rc = prsm_error_set(err, PRSM_ENOTFOUND, NULL, "job %s is %s: samples exist once it is done", id,
		                    prsm_job_state_name(v.row.state));
	else
		rc = prsm_store_get_csv(j->store, csv, len, id, err);
	prsm_job_view_clear(&v);
	return rc;
}

int prsm_jobs_list(prsm_jobs *j, prsm_job_view *items, size_t max, size_t *n, long long *next_seq,
                   const prsm_job_kind *k, long long before_seq, prsm_error *err)
{
	*n = 0;
	*next_seq = 0;
	prsm_store_job *rows = calloc(max ? max : 1, sizeof *rows); /* freed below */
	if (!rows)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int more = 0;
	int rc = prsm_store_list(j->store, rows, max, n, &more, k->name, before_seq, err);
	for (size_t i = 0; !rc && i < *n; i++) {
		memset(&items[i], 0, sizeof items[i]);
		items[i].row = rows[i];
		items[i].kind = k;
		add_live(j, &items[i]);
	}
	if (!rc && more && *n)
		*next_seq = rows[*n - 1].seq;
	free(rows);
	return rc;
}

void prsm_jobs_counts(prsm_jobs *j, int *workers, int *running)
{
	pthread_mutex_lock(&j->mu);
	*workers = j->n_workers;
	*running = 0;
	for (int i = 0; i < j->n_workers; i++)
		*running += j->w[i].id[0] != '\0';
	pthread_mutex_unlock(&j->mu);
}

prsm_job_limits prsm_jobs_limits(const prsm_jobs *j)
{
	return j->opt.limits; /* set at open, never changed */
}

static void add_time(cJSON *o, const char *name, double unix_s)
{
	if (unix_s <= 0) {
		cJSON_AddNullToObject(o, name);
		return;
	}
	time_t t = (time_t)unix_s;
	struct tm tm;
	gmtime_r(&t, &tm);
	char buf[40], out[48];
	strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
	int ms = (int)((unix_s - (double)t) * 1000.0);
	if (ms < 0)
		ms = 0;
	if (ms > 999)
		ms = 999;
	snprintf(out, sizeof out, "%s.%03dZ", buf, ms);
	cJSON_AddStringToObject(o, name, out);
}

cJSON *prsm_job_view_to_json(const prsm_job_view *v)
{
	const prsm_store_job *r = &v->row;
	cJSON *o = cJSON_CreateObject();
	if (!o)
		return NULL;
	cJSON_AddStringToObject(o, "id", r->id);
	cJSON_AddStringToObject(o, "kind", r->kind);
	cJSON_AddStringToObject(o, "state", prsm_job_state_name(r->state));
	add_time(o, "created_at", r->created_s);
	add_time(o, "started_at", r->started_s);
	add_time(o, "finished_at", r->finished_s);
	cJSON_AddNumberToObject(o, "attempts", r->attempts);
	cJSON *p = cJSON_AddObjectToObject(o, "progress");
	cJSON_AddNumberToObject(p, "samples_done", (double)v->samples_done);
	cJSON_AddNumberToObject(p, "samples_planned", (double)v->samples_planned);
	if (r->state == PRSM_JOB_DONE) /* finished: all of it, even when a run stopped before its cap */
		cJSON_AddNumberToObject(p, "fraction", 1.0);
	else if (v->samples_planned > 0) /* an optimiser's last checks may run a few evaluations past its budget */
		cJSON_AddNumberToObject(p, "fraction", fmin(1.0, (double)v->samples_done / (double)v->samples_planned));
	else
		cJSON_AddNullToObject(p, "fraction");
	cJSON_AddStringToObject(p, "unit", v->unit ? v->unit : v->kind->progress_unit ? v->kind->progress_unit : "samples");
	if (v->phase)
		cJSON_AddStringToObject(p, "phase", v->phase);
	else
		cJSON_AddNullToObject(p, "phase");
	prsm_json_add_number(p, "interval_width", v->interval_width);
	prsm_json_add_number(p, "interval_goal", v->interval_goal);
	prsm_json_add_number(p, "best_objective", v->best);
	prsm_json_add_number(p, "eta_s", v->eta_s);
	cJSON_AddBoolToObject(o, "cache_hit", v->cache_hit);
	cJSON *l = cJSON_AddObjectToObject(o, "links");
	char url[160];
	snprintf(url, sizeof url, "/v1/%s/%s", v->kind->collection, r->id);
	cJSON_AddStringToObject(l, "self", url);
	if (v->kind->has_samples_csv) {
		snprintf(url, sizeof url, "/v1/%s/%s/samples.csv", v->kind->collection, r->id);
		cJSON_AddStringToObject(l, "samples_csv", url);
	}
	char schema[96];
	snprintf(schema, sizeof schema, "/v1/schemas/%s", v->kind->result_schema);
	cJSON_AddStringToObject(l, "result_schema", schema);
	return o;
}

int prsm_job_view_to_text(char **out, size_t *len, const prsm_job_view *v)
{
	*out = NULL;
	*len = 0;
	const unsigned long mark = prsm_json_alloc_failures();
	cJSON *o = prsm_job_view_to_json(v);
	if (!o)
		return PRSM_ENOMEM;
	if (v->row.state == PRSM_JOB_FAILED && v->row.problem) {
		cJSON *p = cJSON_Parse(v->row.problem);
		if (p)
			cJSON_AddItemToObject(o, "problem", p);
	}
	char *env = prsm_json_print_whole(o, mark, 0); /* freed below */
	cJSON_Delete(o);
	if (!env)
		return PRSM_ENOMEM;
	size_t elen = strlen(env);
	const char *result = v->row.state == PRSM_JOB_DONE || v->row.state == PRSM_JOB_CANCELLED ? v->row.result : NULL;
	char *marked = NULL; /* the result with cache_hit set, freed below */
	if (result && v->cache_hit) {
		cJSON *res = cJSON_Parse(result);
		if (res && cJSON_GetObjectItemCaseSensitive(res, "cache_hit"))
			cJSON_ReplaceItemInObjectCaseSensitive(res, "cache_hit", cJSON_CreateTrue());
		marked = prsm_json_print_whole(res, mark, 0);
		cJSON_Delete(res);
		if (marked)
			result = marked;
	}
	if (!result) {
		*out = env;
		*len = elen;
		return 0;
	}
	static const char mid[] = ",\"result\":";
	size_t rlen = strlen(result);
	size_t total = elen - 1 + sizeof mid - 1 + rlen + 1;
	char *buf = malloc(total + 1); /* handed to the caller */
	if (!buf) {
		free(env);
		free(marked);
		return PRSM_ENOMEM;
	}
	memcpy(buf, env, elen - 1);
	memcpy(buf + elen - 1, mid, sizeof mid - 1);
	memcpy(buf + elen - 1 + sizeof mid - 1, result, rlen);
	buf[total - 1] = '}';
	buf[total] = '\0';
	free(env);
	free(marked);
	*out = buf;
	*len = total;
	return 0;
}
