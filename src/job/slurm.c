/*
 * slurm.c: the Slurm executor of the service (see slurm.h).
 */
#include "job/slurm.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "util/file.h"

extern char **environ;

#define OUTPUT_MAX 65536          /* bytes of a command's output kept */
#define RESULT_MAX (1024u * 1024u * 1024u) /* largest result or CSV read back */
#define SETTLE_POLLS 20           /* polls to wait for exit_code once the job left the queue */

/* ---- the size of a request ---------------------------------------------------------------- */

static double number_at(const cJSON *o, const char *a, const char *b, const char *c)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, a);
	if (b)
		v = cJSON_GetObjectItemCaseSensitive(v, b);
	if (c)
		v = cJSON_GetObjectItemCaseSensitive(v, c);
	return cJSON_IsNumber(v) && isfinite(v->valuedouble) && v->valuedouble > 0.0 ? v->valuedouble : 0.0;
}

double prsm_slurm_job_samples(const char *kind, const char *request)
{
	cJSON *doc = cJSON_Parse(request);
	double n = 0.0;
	if (!doc)
		return 0.0;
	if (strcmp(kind, "study") == 0) {
		n = number_at(doc, "monte_carlo", "samples", NULL);
	} else if (strcmp(kind, "allocation") == 0) {
		double s = number_at(doc, "monte_carlo", "samples", NULL);
		if (s == 0.0)
			s = number_at(doc, "study", "monte_carlo", "samples");
		n = s * (1.0 + number_at(doc, "monte_carlo", "max_corrections", NULL));
	} else if (strcmp(kind, "optimization") == 0) {
		n = number_at(doc, "robust", "monte_carlo", "samples") * number_at(doc, "solver", "max_evaluations", NULL);
	}
	cJSON_Delete(doc);
	return n;
}

/* ---- running a command -------------------------------------------------------------------- */

/* Run argv[0] (found on PATH) with argv, its stdout and stderr into *out (malloc'd, NUL-terminated,
 * the first OUTPUT_MAX bytes), without a shell; the service's blocked and ignored signals are
 * reset for it. *status: its exit status, -1 when a signal ended it. Returns 0, or PRSM_EIO when
 * it could not be started (err says why). */
static int run_command(char **out, int *status, char *const argv[], prsm_error *err)
{
	*out = NULL;
	*status = -1;
	int fd[2];
	if (pipe(fd))
		return prsm_error_set(err, PRSM_EIO, NULL, "%s: cannot make a pipe: %s", argv[0], strerror(errno));
	posix_spawn_file_actions_t fa;
	posix_spawnattr_t at;
	posix_spawn_file_actions_init(&fa);
	posix_spawnattr_init(&at);
	posix_spawn_file_actions_addclose(&fa, fd[0]);
	posix_spawn_file_actions_adddup2(&fa, fd[1], STDOUT_FILENO);
	posix_spawn_file_actions_adddup2(&fa, fd[1], STDERR_FILENO);
	posix_spawn_file_actions_addclose(&fa, fd[1]);
	sigset_t none, dflt;
	sigemptyset(&none);
	sigemptyset(&dflt);
	sigaddset(&dflt, SIGPIPE);
	sigaddset(&dflt, SIGINT);
	sigaddset(&dflt, SIGTERM);
	posix_spawnattr_setsigmask(&at, &none);
	posix_spawnattr_setsigdefault(&at, &dflt);
	posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
	pid_t pid;
	int e = posix_spawnp(&pid, argv[0], &fa, &at, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	posix_spawnattr_destroy(&at);
	close(fd[1]);
	if (e) {
		close(fd[0]);
		return prsm_error_set(err, PRSM_EIO, NULL, "cannot run %s: %s", argv[0], strerror(e));
	}
	char *buf = malloc(OUTPUT_MAX + 1);
	size_t len = 0;
	for (;;) {
		char chunk[4096];
		ssize_t n = read(fd[0], chunk, sizeof chunk);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			break;
		size_t keep = buf && len < OUTPUT_MAX ? (size_t)n < OUTPUT_MAX - len ? (size_t)n : OUTPUT_MAX - len : 0;
		if (keep)
			memcpy(buf + len, chunk, keep);
		len += keep;
	}
	close(fd[0]);
	int ws = 0;
	while (waitpid(pid, &ws, 0) < 0 && errno == EINTR)
		;
	*status = WIFEXITED(ws) ? WEXITSTATUS(ws) : -1;
	if (!buf)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	buf[len] = '\0';
	*out = buf;
	return 0;
}

/* The first line of a command's output, trimmed, for messages. */
static void first_line(char *dst, size_t cap, const char *text)
{
	size_t n = text ? strcspn(text, "\r\n") : 0;
	snprintf(dst, cap, "%.*s", (int)(n < 200 ? n : 200), text ? text : "");
}

/* ---- files -------------------------------------------------------------------------------- */

static int write_text(const char *path, const char *text, size_t len, prsm_error *err)
{
	FILE *f = fopen(path, "w");
	if (!f)
		return prsm_error_set(err, PRSM_EIO, NULL, "%s: %s", path, strerror(errno));
	int bad = fwrite(text, 1, len, f) != len;
	if (fclose(f) || bad)
		return prsm_error_set(err, PRSM_EIO, NULL, "%s: cannot write", path);
	return 0;
}

static int path_in(char *dst, size_t cap, const char *dir, const char *name)
{
	return snprintf(dst, cap, "%s/%s", dir, name) >= (int)cap ? -1 : 0;
}

/* ---- the executor ------------------------------------------------------------------------- */

static int slurm_wants(void *ctx, const prsm_job_kind *k, const char *request)
{
	const prsm_slurm *s = ctx;
	return prsm_slurm_job_samples(k->name, request) >= (double)s->min_samples;
}

/* Sleep poll_s in short naps; 1 when a cancel came meanwhile. */
static int nap(const prsm_slurm *s, const prsm_job_run_ctx *rc)
{
	const long step_ns = 50000000L;
	for (double slept = 0.0; slept < s->poll_s; slept += 0.05) {
		if (prsm_cancel_requested(rc->cancel))
			return 1;
		struct timespec ts = {0, step_ns};
		nanosleep(&ts, NULL);
	}
	return prsm_cancel_requested(rc->cancel);
}

/* The job's state in squeue (PENDING, RUNNING, ...) into state; 0 when squeue lists it, 1 when
 * not (the job has left the queue, or squeue does not know it any more). */
static int squeue_state(char *state, size_t cap, char *jobid)
{
	char *out = NULL;
	int status;
	prsm_error err = PRSM_ERROR_INIT;
	char *argv[] = {"squeue", "-h", "-j", jobid, "-o", "%T", NULL};
	if (run_command(&out, &status, argv, &err))
		return 1;
	first_line(state, cap, out);
	free(out);
	return status == 0 && state[0] ? 0 : 1;
}

/* The final state sacct reports (COMPLETED, FAILED, CANCELLED, TIMEOUT, ...), "" when it cannot
 * say (no accounting). */
static void sacct_state(char *state, size_t cap, char *jobid)
{
	char *out = NULL;
	int status;
	prsm_error err = PRSM_ERROR_INIT;
	char *argv[] = {"sacct", "-n", "-P", "-X", "-j", jobid, "-o", "State", NULL};
	state[0] = '\0';
	if (run_command(&out, &status, argv, &err))
		return;
	if (status == 0) {
		char line[256];
		first_line(line, sizeof line, out);
		size_t n = strcspn(line, " \t+");
		snprintf(state, cap, "%.*s", (int)n, line);
	}
	free(out);
}

static void scancel(char *jobid)
{
	char *out = NULL;
	int status;
	prsm_error err = PRSM_ERROR_INIT;
	char *argv[] = {"scancel", jobid, NULL};
	if (run_command(&out, &status, argv, &err) == 0)
		free(out);
}

/* The kind's error as run-job wrote it: {"code": -N, "pointer": "...", "message": "..."}. */
static int read_error(const char *path, prsm_error *err)
{
	char *text = NULL;
	size_t len = 0;
	prsm_error ferr = PRSM_ERROR_INIT;
	if (prsm_file_read(&text, &len, path, 65536, &ferr))
		return 0;
	cJSON *doc = cJSON_ParseWithLength(text, len);
	free(text);
	const cJSON *c = cJSON_GetObjectItemCaseSensitive(doc, "code");
	const cJSON *p = cJSON_GetObjectItemCaseSensitive(doc, "pointer");
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(doc, "message");
	int rc = 0;
	if (cJSON_IsNumber(c) && c->valuedouble <= -1.0 && c->valuedouble >= -8.0 && cJSON_IsString(m))
		rc = prsm_error_set(err, (int)c->valuedouble, cJSON_IsString(p) && p->valuestring[0] ? p->valuestring : NULL,
		                    "%s", m->valuestring);
	cJSON_Delete(doc);
	return rc;
}

/* The outputs of a job that exited 0: result, CSV (when written), counts. */
static int read_outputs(prsm_job_output *out, const char *dir, const char *jobid, prsm_error *err)
{
	char path[PRSM_SLURM_PATH_MAX + 32];
	prsm_error ferr = PRSM_ERROR_INIT;
	if (path_in(path, sizeof path, dir, "result.json") ||
	    prsm_file_read(&out->result, &out->result_len, path, RESULT_MAX, &ferr))
		return prsm_error_set(err, PRSM_EIO, NULL, "the Slurm job %s ended without its result: %s", jobid,
		                      ferr.message);
	struct stat st;
	if (path_in(path, sizeof path, dir, "samples.csv") == 0 && stat(path, &st) == 0 &&
	    prsm_file_read(&out->csv, &out->csv_len, path, RESULT_MAX, &ferr))
		return prsm_error_set(err, PRSM_EIO, NULL, "the Slurm job %s: its samples CSV: %s", jobid, ferr.message);
	char *counts = NULL;
	size_t len = 0;
	if (path_in(path, sizeof path, dir, "counts.txt") == 0 && prsm_file_read(&counts, &len, path, 256, &ferr) == 0) {
		long long d = 0, p = 0;
		if (sscanf(counts, "%lld %lld", &d, &p) == 2 && d >= 0 && p >= 0) {
			out->samples_done = d;
			out->samples_planned = p;
		}
		free(counts);
	}
	return 0;
}

/* The exit_code file: 0 and *code when it is there. */
static int read_exit_code(const char *dir, int *code)
{
	char path[PRSM_SLURM_PATH_MAX + 32];
	char *text = NULL;
	size_t len = 0;
	prsm_error ferr = PRSM_ERROR_INIT;
	if (path_in(path, sizeof path, dir, "exit_code") || prsm_file_read(&text, &len, path, 64, &ferr))
		return -1;
	char *end = NULL;
	long v = strtol(text, &end, 10);
	int ok = end != text && v >= 0 && v <= 255;
	free(text);
	if (!ok)
		return -1;
	*code = (int)v;
	return 0;
}

/* The id of the Slurm job an earlier run of this prsm job submitted from dir, into jobid, and 1,
 * when it can be picked up: dir holds the same request and script (so the same work, with the
 * same limits, by the same prsm) and the job is still queued or running, or has written its exit
 * code. 0 otherwise: the job is then submitted anew. */
static int previous_job(char *jobid, size_t cap, const char *dir, const char *request, const char *script)
{
	char path[PRSM_SLURM_PATH_MAX + 96];
	const char *want[] = {"request.json", request, "job.sh", script};
	for (int i = 0; i < 4; i += 2) {
		char *text = NULL;
		size_t len = 0;
		prsm_error ferr = PRSM_ERROR_INIT;
		if (path_in(path, sizeof path, dir, want[i]) || prsm_file_read(&text, &len, path, RESULT_MAX, &ferr))
			return 0;
		const int same = len == strlen(want[i + 1]) && memcmp(text, want[i + 1], len) == 0;
		free(text);
		if (!same)
			return 0;
	}
	char *text = NULL;
	size_t len = 0;
	prsm_error ferr = PRSM_ERROR_INIT;
	if (path_in(path, sizeof path, dir, "jobid") || prsm_file_read(&text, &len, path, 64, &ferr))
		return 0;
	size_t digits = strspn(text, "0123456789");
	const int ok = digits > 0 && digits < cap && digits == len;
	if (ok)
		snprintf(jobid, cap, "%.*s", (int)digits, text);
	free(text);
	if (!ok)
		return 0;
	int code;
	char state[64];
	if (read_exit_code(dir, &code) == 0 || squeue_state(state, sizeof state, jobid) == 0)
		return 1;
	jobid[0] = '\0';
	return 0;
}

static int slurm_run(void *ctx, prsm_job_output *out, const prsm_job_kind *k, const char *id, const char *request,
                     const prsm_job_run_ctx *run_ctx, prsm_error *err)
{
	const prsm_slurm *s = ctx;
	char dir[PRSM_SLURM_PATH_MAX + 64], path[PRSM_SLURM_PATH_MAX + 96];
	if (snprintf(dir, sizeof dir, "%s/%s", s->spool, id) >= (int)sizeof dir)
		return prsm_error_set(err, PRSM_EIO, NULL, "the Slurm spool path is too long");
	if (mkdir(dir, 0755) && errno != EEXIST)
		return prsm_error_set(err, PRSM_EIO, NULL, "%s: %s", dir, strerror(errno));
	char script[4 * PRSM_SLURM_PATH_MAX + 512];
	int n = snprintf(script, sizeof script,
	                 "#!/bin/sh\n"
	                 "# prsm job %s (kind %s), submitted by prsm serve --executor slurm\n"
	                 "cd '%s' || exit 1\n"
	                 "'%s' run-job %s request.json --out result.json --csv samples.csv --error error.json "
	                 "--counts counts.txt --threads %d --time-cap-s %.17g --max-samples %zu\n"
	                 "echo $? > exit_code\n",
	                 id, k->name, dir, s->prsm, k->name, run_ctx->limits.threads, run_ctx->limits.max_time_s,
	                 run_ctx->limits.max_samples);
	if (n >= (int)sizeof script)
		return prsm_error_set(err, PRSM_EIO, NULL, "cannot write the Slurm job's script in %s", dir);

	/* the Slurm job of an earlier run of this job, left running when the service stopped or died:
	 * picked up again instead of submitting the work twice */
	char jobid[32] = "";
	int rc;
	if (!previous_job(jobid, sizeof jobid, dir, request, script)) {
		/* a job run again (the service restarted, or it was cancelled and submitted anew) starts clean */
		static const char *const stale[] = {"result.json", "samples.csv", "error.json", "counts.txt", "exit_code",
		                                    "slurm.out", "jobid", NULL};
		for (int i = 0; stale[i]; i++)
			if (path_in(path, sizeof path, dir, stale[i]) == 0)
				unlink(path);
		if (path_in(path, sizeof path, dir, "request.json") || write_text(path, request, strlen(request), err))
			return prsm_error_set(err, PRSM_EIO, NULL, "cannot write the Slurm job's request in %s", dir);
		if (path_in(path, sizeof path, dir, "job.sh") || write_text(path, script, (size_t)n, err))
			return prsm_error_set(err, PRSM_EIO, NULL, "cannot write the Slurm job's script in %s", dir);

		/* sbatch */
		char name[64], chdir_arg[PRSM_SLURM_PATH_MAX + 96], output_arg[PRSM_SLURM_PATH_MAX + 96];
		snprintf(name, sizeof name, "--job-name=prsm-%.12s", id);
		snprintf(chdir_arg, sizeof chdir_arg, "--chdir=%s", dir);
		snprintf(output_arg, sizeof output_arg, "--output=%s/slurm.out", dir);
		char *argv[8 + PRSM_SLURM_MAX_ARGS];
		int a = 0;
		argv[a++] = "sbatch";
		argv[a++] = "--parsable";
		argv[a++] = name;
		argv[a++] = chdir_arg;
		argv[a++] = output_arg;
		for (int i = 0; i < s->n_sbatch_args; i++)
			argv[a++] = s->sbatch_args[i];
		argv[a++] = path;
		argv[a] = NULL;
		char *sout = NULL;
		int status;
		if ((rc = run_command(&sout, &status, argv, err)) != 0)
			return rc;
		size_t digits = strspn(sout, "0123456789");
		if (status != 0 || digits == 0 || digits >= sizeof jobid) {
			char line[256];
			first_line(line, sizeof line, sout);
			free(sout);
			return prsm_error_set(err, PRSM_EIO, NULL, "sbatch refused the job (exit %d): %s", status, line);
		}
		snprintf(jobid, sizeof jobid, "%.*s", (int)digits, sout);
		free(sout);
		/* written whole, then renamed: a service killed meanwhile leaves no half-written id */
		char final_path[PRSM_SLURM_PATH_MAX + 96];
		if (path_in(path, sizeof path, dir, "jobid.tmp") == 0 &&
		    path_in(final_path, sizeof final_path, dir, "jobid") == 0 &&
		    write_text(path, jobid, strlen(jobid), err) == 0)
			rename(path, final_path);
	}

	/* poll until it leaves the queue, then its exit code */
	char state[64] = "PENDING", final[64] = "";
	int settle = 0, code = -1;
	for (;;) {
		if (nap(s, run_ctx)) {
			if (prsm_cancel_reason(run_ctx->cancel) == PRSM_CANCEL_SHUTDOWN)
				return prsm_error_set(err, PRSM_ECANCELLED, NULL,
				                      "the service is stopping: Slurm job %s is left to run and picked up at the restart",
				                      jobid);
			scancel(jobid);
			/* never picked up again: a new run of this job submits anew */
			if (path_in(path, sizeof path, dir, "jobid") == 0)
				unlink(path);
			return prsm_error_set(err, PRSM_ECANCELLED, NULL, "cancelled: Slurm job %s cancelled (scancel)", jobid);
		}
		if (squeue_state(state, sizeof state, jobid) == 0)
			continue;
		if (read_exit_code(dir, &code) == 0)
			break;
		if (!final[0])
			sacct_state(final, sizeof final, jobid);
		const int ended_badly = final[0] && strcmp(final, "COMPLETED") != 0 && strcmp(final, "RUNNING") != 0 &&
		                        strcmp(final, "PENDING") != 0 && strcmp(final, "COMPLETING") != 0;
		/* the exit_code file may reach a shared filesystem after the job has left the queue */
		if (ended_badly || ++settle > SETTLE_POLLS)
			return prsm_error_set(err, PRSM_EIO, NULL, "the Slurm job %s ended%s%s without a result; its log: %s/slurm.out",
			                      jobid, final[0] ? " " : "", final, dir);
	}
	if (code == 0)
		return read_outputs(out, dir, jobid, err);
	if (path_in(path, sizeof path, dir, "error.json") == 0 && read_error(path, err))
		return err->code;
	return prsm_error_set(err, PRSM_EIO, NULL, "the Slurm job %s: prsm run-job exited %d; its log: %s/slurm.out", jobid,
	                      code, dir);
}

int prsm_slurm_init(prsm_slurm *s, const char *spool, const char *prsm, size_t min_samples, double poll_s,
                    prsm_error *err)
{
	if (!(poll_s > 0.0) || !isfinite(poll_s))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the Slurm poll interval must be > 0 s");
	if (strchr(spool, '\'') || strchr(spool, '\n') || (prsm && (strchr(prsm, '\'') || strchr(prsm, '\n'))))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the Slurm spool and prsm paths must not hold a quote or a newline");
	if (mkdir(spool, 0755) && errno != EEXIST)
		return prsm_error_set(err, PRSM_EIO, NULL, "Slurm spool %s: %s", spool, strerror(errno));
	char buf[PATH_MAX];
	if (!realpath(spool, buf))
		return prsm_error_set(err, PRSM_EIO, NULL, "Slurm spool %s: %s", spool, strerror(errno));
	if (snprintf(s->spool, sizeof s->spool, "%s", buf) >= (int)sizeof s->spool)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "Slurm spool %s: the path is too long", spool);
	if (prsm) {
		if (!realpath(prsm, buf))
			return prsm_error_set(err, PRSM_EIO, NULL, "the prsm for Slurm jobs, %s: %s", prsm, strerror(errno));
	} else {
		ssize_t len = readlink("/proc/self/exe", buf, sizeof buf - 1);
		if (len <= 0)
			return prsm_error_set(err, PRSM_EIO, NULL, "cannot tell where this prsm is: give --slurm-prsm");
		buf[len] = '\0';
	}
	if (snprintf(s->prsm, sizeof s->prsm, "%s", buf) >= (int)sizeof s->prsm)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the prsm path is too long");
	/* the job script quotes both paths in single quotes */
	if (strchr(s->spool, '\'') || strchr(s->prsm, '\'') || strchr(s->spool, '\n') || strchr(s->prsm, '\n'))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the Slurm spool and prsm paths must not hold a quote or a newline");
	s->min_samples = min_samples;
	s->poll_s = poll_s;
	s->executor.name = "slurm";
	s->executor.wants = slurm_wants;
	s->executor.run = slurm_run;
	s->executor.ctx = s;
	return 0;
}
