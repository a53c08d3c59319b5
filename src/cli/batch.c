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
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/global.h"
#include "io/analysis_json.h"
#include "job/jobs.h"
#include "util/file.h"

#define BATCH_MAX_FILE_BYTES (512u * 1024u * 1024u)
#define BATCH_MAX_LINES 100000

typedef struct {
	const char *path, *out_path, *db_path;
	int workers, threads, quiet;
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

static void on_signal(int sig)
{
	(void)sig;
	batch_stop = 1;
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
	*o = (batch_options){NULL, NULL, "prsm.db", cores > 0 && cores < 64 ? (int)cores : 2, 1, 0};
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

/* Wait until the line's job has finished (or a stop); *view gets it with its result.
 * Returns 0, PRSM_ECANCELLED on a stop, or the store's code. */
static int wait_line(prsm_jobs *jobs, const batch_line *l, prsm_job_view *view, prsm_error *err)
{
	for (;;) {
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
	prsm_error err = PRSM_ERROR_INIT;
	char *text = NULL;
	size_t len = 0;
	if (prsm_file_read(&text, &len, o.path, BATCH_MAX_FILE_BYTES, &err)) {
		fprintf(stderr, "prsm batch: %s: %s\n", o.path, err.message);
		return PRSM_EXIT_INVALID;
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
			int rc = wait_line(jobs, l, &v, &err);
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
