/*
 * batch.c: `prsm batch FILE.jsonl` (issue 7): many requests of any job kind, one per line, run
 * through the same job machinery and SQLite cache as `prsm serve` (src/job), in parallel, with
 * one result line per input line, in input order.
 *
 * An input line is {"kind": "study" | "optimization" | "allocation" | "simulation", "request":
 * {...}} with an
 * optional "id" (a label of the caller's, echoed). Every line is validated and submitted first,
 * so identical requests share one job and requests already done are answered from the cache;
 * then the results are written in order as they finish. Accepted jobs live in the database
 * (--db, default ./prsm.db): a batch stopped by SIGINT/SIGTERM (running jobs queued again) or
 * killed outright resumes where it stopped when run again, and what was done is not redone.
 *
 * Output line: {"line": N (1-based), "id": label or null, "kind", "state": "done" | "failed" |
 * "cancelled" | "invalid", "job_id": id or null, "cache_hit": bool, and "result" (done) or
 * "problem" (failed, invalid: the problem document with every JSON pointer, relative to the
 * line's request)}. schemas/batch-line.schema.json and batch-result.schema.json describe both.
 *
 * Exit: 0 when every line is done, 1 when some line was invalid, 2 when some job failed (or the
 * database failed), 64 usage, 130 when stopped by a signal (run again to resume).
 *
 * Under MPI with more than one rank (mpirun, srun: docs/mpi.md) rank 0 is the batch above, its
 * database and its output file, with one job worker of its own (--workers to change it), and a
 * dispatcher on its main thread: every other rank asks nothing and runs what it is sent. The
 * dispatcher claims queued jobs from the same database (its own connection, the same claim as
 * the workers': the oldest queued job) for each idle rank, sends the stored canonical request,
 * and records what comes back as a worker would (done, failed with its problem document, or
 * queued again when the batch stops), so the cache, the output and the resume are the plain
 * batch's. A rank that dies ends the job (mpirun/srun); its jobs stay `running` in the database
 * and are queued again when the batch is run again.
 */
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/global.h"
#include "io/analysis_json.h"
#include "io/json_util.h"
#include "job/jobs.h"
#include "par/par.h"
#include "util/clock.h"
#include "util/file.h"

#define BATCH_MAX_FILE_BYTES (512u * 1024u * 1024u)
#define BATCH_MAX_LINES 100000

typedef struct {
	const char *path, *out_path, *db_path;
	int workers, threads, quiet;
	int workers_given;
} batch_options;

typedef struct {
	cJSON *label;                       /* the line's "id" (a copy), or NULL */
	const prsm_job_kind *kind;          /* NULL: the line is invalid */
	char kind_name[32];
	char job_id[PRSM_STORE_ID_MAX];     /* "" when not submitted */
	int cache_hit;
	cJSON *problem;                     /* the problem document of an invalid line, or NULL */
} batch_line;

static volatile sig_atomic_t batch_stop;
/* a follower's running job (MPI): raised with batch_stop */
static prsm_cancel_flag follower_cancel;

static void on_signal(int sig)
{
	(void)sig;
	batch_stop = 1;
	prsm_cancel_set(&follower_cancel, 1);
}

static void batch_usage(FILE *f)
{
	fprintf(f, "usage: prsm batch FILE.jsonl|- [--out FILE] [--db PATH] [--workers N] [--threads N] [--quiet]\n"
	           "  one request per line: {\"kind\": \"study\"|\"optimization\"|\"allocation\"|\"simulation\","
	           " \"request\": {...},"
	           " \"id\": label}\n"
	           "  one result per line, in input order, on stdout or --out; run again to resume\n");
}

static int parse_options(batch_options *o, int argc, char **argv)
{
	long cores = sysconf(_SC_NPROCESSORS_ONLN);
	*o = (batch_options){NULL, NULL, "prsm.db", cores > 0 && cores < 64 ? (int)cores : 2, 1, 0, 0};
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const char *v = i + 1 < argc ? argv[i + 1] : NULL;
		long long n;
		if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
			batch_usage(stdout);
			return 1;
		} else if (strcmp(a, "--quiet") == 0) {
			o->quiet = 1;
		} else if (strcmp(a, "--out") == 0 && v) {
			o->out_path = v;
			i++;
		} else if (strcmp(a, "--db") == 0 && v) {
			o->db_path = v;
			i++;
		} else if (strcmp(a, "--workers") == 0) {
			if (prsm_cli_int_option(&n, "batch", a, v, 1, PRSM_JOBS_MAX_WORKERS))
				return -1;
			o->workers = (int)n;
			o->workers_given = 1;
			i++;
		} else if (strcmp(a, "--threads") == 0) {
			if (prsm_cli_int_option(&n, "batch", a, v, 1, 256))
				return -1;
			o->threads = (int)n;
			i++;
		} else if (a[0] == '-' && a[1]) {
			fprintf(stderr, "prsm batch: unknown option '%s'\n", a);
			return -1;
		} else if (!o->path) {
			o->path = a;
		} else {
			fprintf(stderr, "prsm batch: one input file only\n");
			return -1;
		}
	}
	if (!o->path) {
		batch_usage(stderr);
		return -1;
	}
	return 0;
}

/* An invalid line's problem document (422, or 400 for JSON that does not parse). */
static cJSON *line_problem(int status, const prsm_problems *p)
{
	return prsm_io_problem_document(status, status == 400 ? "Malformed line" : "Invalid request", p);
}

/* Validate and submit one line; on any problem l->problem says why. Returns 0, or PRSM_EIO
 * when the database failed (err). */
static int submit_line(prsm_jobs *jobs, batch_line *l, const char *text, prsm_error *err)
{
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = cJSON_Parse(text);
	int rc = 0;
	if (!doc) {
		prsm_problems_add(&p, "", "syntax", "the line is not JSON (byte %zu)",
		                  cJSON_GetErrorPtr() ? (size_t)(cJSON_GetErrorPtr() - text) : (size_t)0);
		l->problem = line_problem(400, &p);
		goto done;
	}
	if (!cJSON_IsObject(doc)) {
		prsm_problems_add(&p, "", "type", "a line is an object {\"kind\": ..., \"request\": {...}}");
		l->problem = line_problem(422, &p);
		goto done;
	}
	const cJSON *id = cJSON_GetObjectItemCaseSensitive(doc, "id");
	if (id && (cJSON_IsString(id) || cJSON_IsNumber(id)))
		l->label = cJSON_Duplicate(id, 0);
	else if (id)
		prsm_problems_add(&p, "/id", "type", "the label is a string or a number");
	const cJSON *kind = cJSON_GetObjectItemCaseSensitive(doc, "kind");
	const cJSON *req = cJSON_GetObjectItemCaseSensitive(doc, "request");
	if (!cJSON_IsString(kind)) {
		prsm_problems_add(&p, "/kind", kind ? "type" : "required", "kind is one of study, optimization, allocation, simulation");
	} else {
		snprintf(l->kind_name, sizeof l->kind_name, "%s", kind->valuestring);
		l->kind = prsm_job_kind_by_name(kind->valuestring);
		if (!l->kind)
			prsm_problems_add(&p, "/kind", "enum", "'%.40s' is not a job kind (study, optimization, allocation, simulation)",
			                  kind->valuestring);
	}
	if (!cJSON_IsObject(req))
		prsm_problems_add(&p, "/request", req ? "type" : "required", "the request is an object");
	for (const cJSON *c = doc->child; c; c = c->next)
		if (strcmp(c->string, "id") && strcmp(c->string, "kind") && strcmp(c->string, "request"))
			prsm_problems_add(&p, "", "additional", "unknown member '%.40s' (a line has kind, request, id)",
			                  c->string);
	if (p.count) {
		l->problem = line_problem(422, &p);
		l->kind = NULL;
		goto done;
	}
	prsm_job_view v;
	prsm_submit_outcome oc;
	prsm_problems rp;
	prsm_problems_init(&rp);
	rc = prsm_jobs_submit(jobs, &v, &oc, l->kind, req, &rp, err);
	if (rc == PRSM_EIO || rc == PRSM_ENOMEM) {
		goto done;
	} else if (rc) {
		/* the request's own problems, pointers relative to the request */
		rc = 0;
		l->problem = line_problem(422, &rp);
		l->kind = NULL;
		goto done;
	}
	snprintf(l->job_id, sizeof l->job_id, "%s", v.row.id);
	l->cache_hit = oc == PRSM_SUBMIT_CACHED;
	prsm_job_view_clear(&v);
done:
	cJSON_Delete(doc);
	return rc;
}

/* ---- MPI: rank 0's dispatcher and the other ranks (see the top of the file) -------------- */

enum { TAG_JOB = 1, TAG_RESULT = 2, TAG_STOP = 3 };

/* A job sent to a rank: this header, then the canonical request. */
typedef struct {
	char id[PRSM_STORE_ID_MAX];
	char kind[PRSM_STORE_KIND_MAX];
} job_head;

/* What a rank sends back: this header, then the result and the CSV (their lengths here). */
typedef struct {
	char id[PRSM_STORE_ID_MAX];
	int32_t rc, cancelled;
	prsm_error err;
	int64_t samples_done, samples_planned;
	uint64_t has_result, result_len, csv_len;
} result_head;

typedef struct {
	prsm_store *store;
	int size;
	char (*busy)[PRSM_STORE_ID_MAX];    /* per rank, the job it runs ("" idle; rank 0: unused) */
	int in_flight;
	double next_claim_s;                /* nothing was queued: claim again from then on */
} dispatcher;

/* The problem document of a failed run, as text (malloc'd; NULL when out of memory): what the
 * job workers store (job/jobs.c, failure_problem), for the jobs other ranks ran. */
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

/* A rank's answer recorded in the store, as a job worker records its own (job/jobs.c, run_one). */
static void record_result(dispatcher *D, int from, const char *buf, size_t len)
{
	result_head h;
	if (len < sizeof h)
		prsm_par_abort(PRSM_EXIT_FAILED, "rank %d sent %zu bytes for a job's result", from, len);
	memcpy(&h, buf, sizeof h);
	h.id[sizeof h.id - 1] = '\0';
	if (len != sizeof h + h.result_len + h.csv_len || strcmp(h.id, D->busy[from]))
		prsm_par_abort(PRSM_EXIT_FAILED, "rank %d sent a result that does not match job %s", from, D->busy[from]);
	/* the result and the CSV, each NUL-terminated */
	char *result = h.has_result ? malloc(h.result_len + 1) : NULL, *csv = h.csv_len ? malloc(h.csv_len + 1) : NULL;
	if ((h.has_result && !result) || (h.csv_len && !csv))
		prsm_par_abort(PRSM_EXIT_FAILED, "out of memory for the result of job %s", h.id);
	if (result) {
		memcpy(result, buf + sizeof h, h.result_len);
		result[h.result_len] = '\0';
	}
	if (csv) {
		memcpy(csv, buf + sizeof h + h.result_len, h.csv_len);
		csv[h.csv_len] = '\0';
	}
	prsm_error serr = PRSM_ERROR_INIT;
	int src = 0;
	if (h.rc == 0) {
		src = prsm_store_finish(D->store, h.id, PRSM_JOB_DONE, result, NULL, csv, h.csv_len, h.samples_done,
		                        h.samples_planned, NULL, &serr);
	} else if (h.cancelled || h.rc == PRSM_ECANCELLED) {
		if (batch_stop)
			src = prsm_store_requeue(D->store, h.id, &serr);
		else if (result)
			src = prsm_store_finish(D->store, h.id, PRSM_JOB_CANCELLED, result, NULL, NULL, 0, h.samples_done,
			                        h.samples_planned, NULL, &serr);
	} else {
		char *problem = failure_problem(&h.err);
		src = prsm_store_finish(D->store, h.id, PRSM_JOB_FAILED, NULL, problem ? problem : "{}", NULL, 0, 0, 0, NULL,
		                        &serr);
		free(problem);
	}
	if (src)
		fprintf(stderr, "prsm batch: job %s (rank %d): %s\n", h.id, from, serr.message);
	free(result);
	free(csv);
	D->busy[from][0] = '\0';
	D->in_flight--;
}

/* Receive what the ranks sent back, and hand queued jobs to idle ranks (unless draining). */
static void dispatch_pump(dispatcher *D, int draining)
{
	prsm_error err = PRSM_ERROR_INIT;
	while (prsm_par_probe()) {
		int from, tag;
		char *buf;
		size_t len;
		if (prsm_par_recv(-1, -1, &from, &tag, &buf, &len, NULL, &err))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
		if (tag != TAG_RESULT || from <= 0 || from >= D->size || !D->busy[from][0])
			prsm_par_abort(PRSM_EXIT_FAILED, "unexpected message (tag %d) from rank %d", tag, from);
		record_result(D, from, buf, len);
		free(buf);
	}
	if (draining || batch_stop || prsm_clock_seconds() < D->next_claim_s)
		return;
	for (int r = 1; r < D->size; r++) {
		if (D->busy[r][0])
			continue;
		prsm_store_job job;
		int rc = prsm_store_claim(D->store, &job, &err);
		if (rc) {
			if (rc != PRSM_ENOTFOUND)
				fprintf(stderr, "prsm batch: %s\n", err.message);
			D->next_claim_s = prsm_clock_seconds() + 0.1;
			return;
		}
		const size_t rlen = job.request ? strlen(job.request) : 0;
		job_head h;
		memset(&h, 0, sizeof h);
		snprintf(h.id, sizeof h.id, "%s", job.id);
		snprintf(h.kind, sizeof h.kind, "%s", job.kind);
		char *msg = malloc(sizeof h + rlen);
		if (!msg)
			prsm_par_abort(PRSM_EXIT_FAILED, "out of memory for job %s", job.id);
		memcpy(msg, &h, sizeof h);
		if (rlen)
			memcpy(msg + sizeof h, job.request, rlen);
		if (prsm_par_send(r, TAG_JOB, msg, sizeof h + rlen, &err))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
		free(msg);
		snprintf(D->busy[r], sizeof D->busy[r], "%s", job.id);
		D->in_flight++;
		prsm_store_job_clear(&job);
	}
}

/* The end of the batch for the other ranks: the jobs they run finish (or, stopping, come back
 * cancelled and are queued again), then each is told to exit with code. */
static void dispatch_end(dispatcher *D, int code)
{
	prsm_error err = PRSM_ERROR_INIT;
	int32_t c = code;
	if (batch_stop)
		for (int r = 1; r < D->size; r++)
			if (prsm_par_send(r, TAG_STOP, &c, sizeof c, &err))
				prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
	const double give_up = prsm_clock_seconds() + 30.0;
	while (D->in_flight > 0) {
		dispatch_pump(D, 1);
		if (batch_stop && prsm_clock_seconds() > give_up)
			break;
		struct timespec ts = {0, 5000000L};
		nanosleep(&ts, NULL);
	}
	for (int r = 1; r < D->size; r++) {
		if (D->busy[r][0] && D->store) /* a rank that did not answer in time: its job runs again next time */
			prsm_store_requeue(D->store, D->busy[r], &err);
		if (!batch_stop && prsm_par_send(r, TAG_STOP, &c, sizeof c, &err))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
	}
}

typedef struct {
	job_head head;
	const char *request;
	prsm_job_limits limits;
	prsm_job_output out;
	prsm_error err;
	int rc;
	atomic_int done;
} follower_job;

static void *follower_run(void *arg)
{
	follower_job *j = arg;
	const prsm_job_kind *k = prsm_job_kind_by_name(j->head.kind);
	if (!k) {
		j->rc = prsm_error_set(&j->err, PRSM_EINVAL, NULL, "this prsm has no job kind '%s'", j->head.kind);
	} else {
		prsm_job_run_ctx ctx = {&follower_cancel, NULL, NULL, j->limits};
		j->rc = k->run(&j->out, j->request, &ctx, &j->err);
	}
	atomic_store(&j->done, 1);
	return NULL;
}

/* A rank other than 0: run the jobs rank 0 sends, one at a time, on a thread of their own so
 * that this one keeps listening (a stop from rank 0 cancels the running job); until told to stop.
 * Returns the exit code rank 0 gives, or 130 on a signal. */
static int follow(const batch_options *o)
{
	prsm_error err = PRSM_ERROR_INIT;
	const prsm_job_limits limits = {0, 0.0, o->threads};
	int stop_code = -1;
	while (stop_code < 0) {
		int from, tag;
		char *buf;
		size_t len;
		int rc = prsm_par_recv(0, -1, &from, &tag, &buf, &len, &batch_stop, &err);
		if (rc == PRSM_ECANCELLED)
			return 130;
		if (rc)
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
		if (tag == TAG_STOP) {
			int32_t c = 0;
			memcpy(&c, buf, len < sizeof c ? len : sizeof c);
			free(buf);
			return c;
		}
		if (tag != TAG_JOB || len < sizeof(job_head))
			prsm_par_abort(PRSM_EXIT_FAILED, "unexpected message (tag %d, %zu bytes) from rank 0", tag, len);
		follower_job *j = calloc(1, sizeof *j);
		if (!j)
			prsm_par_abort(PRSM_EXIT_FAILED, "out of memory");
		memcpy(&j->head, buf, sizeof j->head);
		j->head.id[sizeof j->head.id - 1] = '\0';
		j->head.kind[sizeof j->head.kind - 1] = '\0';
		j->request = buf + sizeof j->head; /* NUL-terminated by prsm_par_recv */
		j->limits = limits;
		atomic_init(&j->done, 0);
		pthread_t th;
		if (prsm_par_fault()) {
			j->rc = prsm_error_set(&j->err, PRSM_EIO, NULL, "rank %d failed: injected failure (PRSM_PAR_FAULT)",
			                       prsm_par_rank());
			atomic_store(&j->done, 1);
		} else if (pthread_create(&th, NULL, follower_run, j)) {
			prsm_par_abort(PRSM_EXIT_FAILED, "cannot start a thread for job %s", j->head.id);
		} else {
			long ns = 50000;
			while (!atomic_load(&j->done)) {
				if (stop_code < 0 && prsm_par_probe()) {
					/* only a stop comes while a job runs */
					char *sbuf;
					size_t slen;
					if (prsm_par_recv(0, TAG_STOP, &from, &tag, &sbuf, &slen, NULL, &err))
						prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
					int32_t c = 0;
					memcpy(&c, sbuf, slen < sizeof c ? slen : sizeof c);
					free(sbuf);
					stop_code = c;
					prsm_cancel_set(&follower_cancel, 1);
				}
				struct timespec ts = {0, ns};
				nanosleep(&ts, NULL);
				if (ns < 5000000)
					ns *= 2;
			}
			pthread_join(th, NULL);
		}
		/* the answer */
		result_head h;
		memset(&h, 0, sizeof h);
		memcpy(h.id, j->head.id, sizeof h.id);
		h.rc = j->rc;
		h.cancelled = prsm_cancel_requested(&follower_cancel);
		h.err = j->err;
		h.samples_done = j->out.samples_done;
		h.samples_planned = j->out.samples_planned;
		h.has_result = j->out.result != NULL;
		h.result_len = j->out.result ? (j->out.result_len ? j->out.result_len : strlen(j->out.result)) : 0;
		h.csv_len = j->out.csv ? j->out.csv_len : 0;
		char *msg = malloc(sizeof h + h.result_len + h.csv_len);
		if (!msg)
			prsm_par_abort(PRSM_EXIT_FAILED, "out of memory for the result of job %s", h.id);
		memcpy(msg, &h, sizeof h);
		if (h.result_len)
			memcpy(msg + sizeof h, j->out.result, h.result_len);
		if (h.csv_len)
			memcpy(msg + sizeof h + h.result_len, j->out.csv, h.csv_len);
		if (prsm_par_send(0, TAG_RESULT, msg, sizeof h + h.result_len + h.csv_len, &err))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
		free(msg);
		prsm_job_output_free(&j->out);
		free(j);
		free(buf);
		if (batch_stop && stop_code < 0)
			return 130;
	}
	return stop_code;
}


/* Wait until the line's job has finished (or a stop); *view gets it with its result.
 * Returns 0, PRSM_ECANCELLED on a stop, or the store's code. */
static int wait_line(prsm_jobs *jobs, const batch_line *l, prsm_job_view *view, dispatcher *D, prsm_error *err)
{
	for (;;) {
		if (D)
			dispatch_pump(D, 0);
		int rc = prsm_jobs_get(jobs, view, l->kind, l->job_id, PRSM_STORE_WITH_RESULT, err);
		if (rc)
			return rc;
		prsm_job_state s = view->row.state;
		if (s == PRSM_JOB_DONE || s == PRSM_JOB_FAILED || s == PRSM_JOB_CANCELLED)
			return 0;
		prsm_job_view_clear(view);
		if (batch_stop)
			return PRSM_ECANCELLED;
		struct timespec ts = {0, 20000000L};
		nanosleep(&ts, NULL);
	}
}

/* The output line of l (finished job in view, or invalid); the caller owns it. */
static cJSON *result_line(size_t n, const batch_line *l, const prsm_job_view *view)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "line", (double)n);
	cJSON_AddItemToObject(o, "id", l->label ? cJSON_Duplicate(l->label, 0) : cJSON_CreateNull());
	if (l->kind_name[0])
		cJSON_AddStringToObject(o, "kind", l->kind_name);
	else
		cJSON_AddNullToObject(o, "kind");
	if (!view) {
		cJSON_AddStringToObject(o, "state", "invalid");
		cJSON_AddNullToObject(o, "job_id");
		cJSON_AddFalseToObject(o, "cache_hit");
		cJSON_AddItemToObject(o, "problem", cJSON_Duplicate(l->problem, 1));
		return o;
	}
	cJSON_AddStringToObject(o, "state", prsm_job_state_name(view->row.state));
	cJSON_AddStringToObject(o, "job_id", view->row.id);
	cJSON_AddBoolToObject(o, "cache_hit", l->cache_hit);
	if (view->row.result) {
		cJSON *res = cJSON_Parse(view->row.result);
		if (res && l->cache_hit && cJSON_GetObjectItemCaseSensitive(res, "cache_hit"))
			cJSON_ReplaceItemInObjectCaseSensitive(res, "cache_hit", cJSON_CreateTrue());
		cJSON_AddItemToObject(o, "result", res ? res : cJSON_CreateNull());
	}
	if (view->row.state == PRSM_JOB_FAILED && view->row.problem) {
		cJSON *pr = cJSON_Parse(view->row.problem);
		cJSON_AddItemToObject(o, "problem", pr ? pr : cJSON_CreateNull());
	}
	return o;
}


int prsm_cli_batch(int argc, char **argv)
{
	batch_options o;
	int prc = parse_options(&o, argc, argv);
	if (prc)
		return prc > 0 ? PRSM_EXIT_OK : PRSM_EXIT_USAGE;
	/* MPI with other ranks: they run what rank 0 sends; rank 0 keeps one job worker of its own */
	const int par = prsm_par_active() && prsm_par_size() > 1;
	dispatcher D = {NULL, prsm_par_size(), NULL, 0, 0.0};
	if (par) {
		if (prsm_par_rank() != 0) {
			signal(SIGINT, on_signal);
			signal(SIGTERM, on_signal);
			return follow(&o);
		}
		D.busy = calloc((size_t)D.size, sizeof *D.busy);
		if (!D.busy)
			prsm_par_abort(PRSM_EXIT_FAILED, "out of memory");
		if (!o.workers_given)
			o.workers = 1;
	}
	prsm_error err = PRSM_ERROR_INIT;
	char *text = NULL;
	size_t len = 0;
	if (prsm_file_read(&text, &len, o.path, BATCH_MAX_FILE_BYTES, &err)) {
		/* a file that cannot be read is a usage error (64, README "Exit codes"), as for the other
		 * commands; one too large is an invalid request (1) */
		const int code = err.code == PRSM_EIO ? PRSM_EXIT_USAGE : PRSM_EXIT_INVALID;
		fprintf(stderr, "prsm batch: %s: %s\n", o.path, err.message);
		if (par) {
			dispatch_end(&D, code);
			free(D.busy);
		}
		return code;
	}
	/* the lines, in place: every '\n' becomes a terminator */
	size_t n_lines = 0;
	char **starts = malloc(sizeof *starts * BATCH_MAX_LINES); /* freed below */
	batch_line *lines = NULL;
	FILE *out = NULL;
	prsm_jobs *jobs = NULL;
	int exit_code = PRSM_EXIT_OK;
	if (!starts) {
		exit_code = PRSM_EXIT_FAILED;
		goto cleanup;
	}
	for (char *p = text; p < text + len;) {
		char *nl = memchr(p, '\n', (size_t)(text + len - p));
		char *end = nl ? nl : text + len;
		*end = '\0';
		char *q = p;
		while (*q == ' ' || *q == '\t' || *q == '\r')
			q++;
		if (*q) {
			if (n_lines == BATCH_MAX_LINES) {
				fprintf(stderr, "prsm batch: %s: more than %d requests; split the file\n", o.path, BATCH_MAX_LINES);
				exit_code = PRSM_EXIT_INVALID;
				goto cleanup;
			}
			starts[n_lines++] = p;
		}
		p = end + 1;
	}
	lines = calloc(n_lines ? n_lines : 1, sizeof *lines);
	out = o.out_path ? fopen(o.out_path, "w") : stdout;
	if (!lines || !out) {
		fprintf(stderr, "prsm batch: %s\n", !out ? "cannot write the output file" : "out of memory");
		exit_code = PRSM_EXIT_FAILED;
		goto cleanup;
	}

	prsm_jobs_options jo = PRSM_JOBS_OPTIONS_INIT;
	jo.db_path = o.db_path;
	jo.workers = o.workers;
	jo.store_connections = o.workers + 2;
	if (jo.store_connections > PRSM_STORE_MAX_CONNS)
		jo.store_connections = PRSM_STORE_MAX_CONNS;
	jo.max_queued = (size_t)BATCH_MAX_LINES * 4; /* a batch never refuses its own lines */
	jo.limits.max_samples = 0;   /* the documents' own caps */
	jo.limits.max_time_s = 0.0;  /* and their own time caps */
	jo.limits.threads = o.threads;
	int recovered = 0;
	if (prsm_jobs_open(&jobs, &jo, &recovered, &err)) {
		fprintf(stderr, "prsm batch: %s\n", err.message);
		exit_code = PRSM_EXIT_FAILED;
		goto cleanup;
	}
	if (par && prsm_store_open(&D.store, o.db_path, 1, &err)) {
		fprintf(stderr, "prsm batch: %s\n", err.message);
		exit_code = PRSM_EXIT_FAILED;
		goto cleanup;
	}
	signal(SIGINT, on_signal);
	signal(SIGTERM, on_signal);
	if (!o.quiet && recovered)
		fprintf(stderr, "prsm batch: resuming %d interrupted job%s\n", recovered, recovered == 1 ? "" : "s");

	for (size_t i = 0; i < n_lines && !batch_stop; i++)
		if (submit_line(jobs, &lines[i], starts[i], &err)) {
			fprintf(stderr, "prsm batch: line %zu: %s\n", i + 1, err.message);
			exit_code = PRSM_EXIT_FAILED;
			goto cleanup;
		}
	size_t done = 0, cached = 0;
	for (size_t i = 0; i < n_lines && !batch_stop; i++) {
		batch_line *l = &lines[i];
		cJSON *row = NULL;
		const unsigned long mark = prsm_json_alloc_failures();
		if (!l->kind) {
			row = result_line(i + 1, l, NULL);
			if (exit_code == PRSM_EXIT_OK)
				exit_code = PRSM_EXIT_INVALID;
		} else {
			prsm_job_view v;
			int rc = wait_line(jobs, l, &v, par ? &D : NULL, &err);
			if (rc == PRSM_ECANCELLED)
				break;
			if (rc) {
				fprintf(stderr, "prsm batch: line %zu: %s\n", i + 1, err.message);
				exit_code = PRSM_EXIT_FAILED;
				goto cleanup;
			}
			row = result_line(i + 1, l, &v);
			if (v.row.state != PRSM_JOB_DONE)
				exit_code = PRSM_EXIT_FAILED;
			prsm_job_view_clear(&v);
		}
		char *s = prsm_json_print_whole(row, mark, 0);
		cJSON_Delete(row);
		if (!s || fprintf(out, "%s\n", s) < 0 || fflush(out)) {
			free(s);
			fprintf(stderr, "prsm batch: cannot write the result of line %zu\n", i + 1);
			exit_code = PRSM_EXIT_FAILED;
			goto cleanup;
		}
		free(s);
		done++;
		cached += l->cache_hit;
		if (!o.quiet && isatty(STDERR_FILENO))
			fprintf(stderr, "\rprsm batch: %zu / %zu lines", done, n_lines);
	}
	if (batch_stop) {
		fprintf(stderr, "\nprsm batch: stopped after %zu of %zu lines; run the same command again to resume\n", done,
		        n_lines);
		exit_code = 130;
	} else if (!o.quiet) {
		fprintf(stderr, "%sprsm batch: %zu lines, %zu from the cache\n", isatty(STDERR_FILENO) ? "\n" : "", n_lines,
		        cached);
	}

cleanup:
	if (par) {
		dispatch_end(&D, exit_code);
		prsm_store_close(D.store);
		free(D.busy);
	}
	prsm_jobs_close(jobs);
	if (out && out != stdout)
		fclose(out);
	if (lines)
		for (size_t i = 0; i < n_lines; i++) {
			cJSON_Delete(lines[i].label);
			cJSON_Delete(lines[i].problem);
		}
	free(lines);
	free(starts);
	free(text);
	return exit_code;
}
