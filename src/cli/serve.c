/*
 * serve.c: `prsm serve`: the HTTP/JSON service (DESIGN.md, "Service"; api/openapi.yaml).
 *
 * Opens the database (jobs left running by a crash are queued again), starts the job workers
 * and the HTTP threads, and waits for SIGTERM or SIGINT: then it stops accepting connections,
 * lets the open ones finish (up to a few seconds), stops the workers — a job still running is
 * queued again and resumes at the next start — and exits 0. Signals are blocked in every
 * thread and taken by sigwait() here, so no handler runs inside the libraries.
 */
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <microhttpd.h>

#include "cli/commands.h"
#include "io/global.h"
#include "http/server.h"
#include "job/jobs.h"
#include "job/slurm.h"
#include "util/file.h"

#ifndef PRSM_SOURCE_DATA_DIR
#define PRSM_SOURCE_DATA_DIR "."
#endif
#ifndef PRSM_BIN_TO_DATA
#define PRSM_BIN_TO_DATA "../share/prsm"
#endif

/* dir holds the service's data (its schemas/ at least) */
static int is_data_dir(const char *dir)
{
	char path[PATH_MAX];
	struct stat st;
	if (snprintf(path, sizeof path, "%s/schemas/design.schema.json", dir) >= (int)sizeof path)
		return 0;
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* Where the data is when --data-dir does not say: $PRSM_DATA_DIR; next to the binary as
 * installed (<bindir>/PRSM_BIN_TO_DATA); else the source tree it was built from. */
static const char *default_data_dir(char *buf, size_t cap)
{
	const char *env = getenv("PRSM_DATA_DIR");
	if (env && env[0])
		return env;
	char exe[PATH_MAX];
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n > 0) {
		exe[n] = '\0';
		char *slash = strrchr(exe, '/');
		if (slash) {
			*slash = '\0';
			if (snprintf(buf, cap, "%s/%s", exe, PRSM_BIN_TO_DATA) < (int)cap && is_data_dir(buf))
				return buf;
		}
	}
	return PRSM_SOURCE_DATA_DIR;
}

#define TOKEN_MAX 511

static void serve_usage(FILE *f)
{
	fprintf(f,
	        "usage: prsm serve [options]\n"
	        "  --host ADDR          address to bind (default 127.0.0.1; numeric IPv4 or IPv6)\n"
	        "  --port N             TCP port (default 8080; 0: any free port)\n"
	        "  --db PATH            SQLite database (default ./prsm.db)\n"
	        "  --threads N          HTTP threads (default 2)\n"
	        "  --workers N          jobs run at once (default 1)\n"
	        "  --job-threads N      engine threads per job (default 1)\n"
	        "  --token-file PATH    bearer token for POST and DELETE (or env PRSM_TOKEN)\n"
	        "  --max-body-bytes N   largest request body (default 1048576)\n"
	        "  --timeout-s N        idle connection timeout (default 30)\n"
	        "  --max-connections N  open connections at most (default 512)\n"
	        "  --max-queued N       queued jobs at most, then 503 (default 64)\n"
	        "  --max-samples N      Monte Carlo samples per job (default 200000)\n"
	        "  --job-time-cap-s S   time cap per job (default 600)\n"
	        "  --sync-time-ms N     POST /v1/designs/analyze computes at most this long on the\n"
	        "                       HTTP thread, then queues the request as a job (default 2000)\n"
	        "  --sync-budget N      ... and only requests of at most N contact-gap evaluations\n"
	        "                       (default 20000000; 0: every error analysis is a job)\n"
	        "  --data-dir DIR       directory with schemas/, api/ and web/ (default: $PRSM_DATA_DIR,\n"
	        "                       else %s next to the binary when installed, else %s)\n"
	        "  --executor local|slurm  where jobs run: the workers (default), or jobs of at least\n"
	        "                       --slurm-min-samples Monte Carlo samples go to Slurm (sbatch,\n"
	        "                       squeue, sacct, scancel on PATH; docs/mpi.md)\n"
	        "  --slurm-min-samples N  (default 1000000)\n"
	        "  --slurm-spool DIR    the Slurm jobs' files, on a filesystem the nodes share\n"
	        "                       (default ./prsm-slurm)\n"
	        "  --slurm-poll-s S     seconds between squeue calls (default 10)\n"
	        "  --slurm-prsm PATH    the prsm the nodes run (default: this one)\n"
	        "  --sbatch-arg ARG     an extra sbatch argument, e.g. --sbatch-arg --partition=long\n"
	        "                       (repeatable, up to %d)\n",
	        PRSM_BIN_TO_DATA, PRSM_SOURCE_DATA_DIR, PRSM_SLURM_MAX_ARGS);
}

static int read_token(char *out, size_t size, const char *path)
{
	char *text = NULL;
	size_t len = 0;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_file_read(&text, &len, path, TOKEN_MAX, &err)) {
		fprintf(stderr, "prsm serve: --token-file %s: %s\n", path, err.message);
		return -1;
	}
	while (len && (text[len - 1] == '\n' || text[len - 1] == '\r' || text[len - 1] == ' '))
		text[--len] = '\0';
	snprintf(out, size, "%s", text);
	free(text);
	if (!out[0]) {
		fprintf(stderr, "prsm serve: --token-file %s is empty\n", path);
		return -1;
	}
	return 0;
}

int prsm_cli_serve(int argc, char **argv)
{
	prsm_global_init();
	prsm_http_options ho = PRSM_HTTP_OPTIONS_INIT;
	prsm_jobs_options jo = PRSM_JOBS_OPTIONS_INIT;
	char data_buf[PATH_MAX];
	ho.data_dir = default_data_dir(data_buf, sizeof data_buf);
	const char *token_file = NULL;
	char token[TOKEN_MAX + 1] = "";
	int slurm_on = 0;
	const char *slurm_spool = "prsm-slurm", *slurm_prsm = NULL;
	long long slurm_min = 1000000;
	double slurm_poll_s = 10.0;
	const char *slurm_option = NULL; /* the last --slurm-* or --sbatch-arg option given */
	static prsm_slurm slurm; /* the workers use it until prsm_jobs_close */
	memset(&slurm, 0, sizeof slurm);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const char *v = i + 1 < argc ? argv[i + 1] : NULL;
		long long n;
		if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
			serve_usage(stdout);
			return 0;
		}
		if (!v || a[0] != '-') {
			fprintf(stderr, "prsm serve: unknown or incomplete option '%s'\n", a);
			serve_usage(stderr);
			return PRSM_EXIT_USAGE;
		}
		i++;
		if (strncmp(a, "--slurm-", 8) == 0 || strcmp(a, "--sbatch-arg") == 0)
			slurm_option = a; /* refused below without --executor slurm */
		if (strcmp(a, "--host") == 0) {
			ho.host = v;
		} else if (strcmp(a, "--port") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 0, 65535))
				return PRSM_EXIT_USAGE;
			ho.port = (int)n;
		} else if (strcmp(a, "--db") == 0) {
			jo.db_path = v;
		} else if (strcmp(a, "--threads") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 64))
				return PRSM_EXIT_USAGE;
			ho.threads = (int)n;
		} else if (strcmp(a, "--workers") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, PRSM_JOBS_MAX_WORKERS))
				return PRSM_EXIT_USAGE;
			jo.workers = (int)n;
		} else if (strcmp(a, "--job-threads") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 64))
				return PRSM_EXIT_USAGE;
			jo.limits.threads = (int)n;
		} else if (strcmp(a, "--token-file") == 0) {
			token_file = v;
		} else if (strcmp(a, "--max-body-bytes") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1024, 256LL * 1024 * 1024))
				return PRSM_EXIT_USAGE;
			ho.max_body_bytes = (size_t)n;
		} else if (strcmp(a, "--timeout-s") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 3600))
				return PRSM_EXIT_USAGE;
			ho.timeout_s = (unsigned)n;
		} else if (strcmp(a, "--max-connections") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 100000))
				return PRSM_EXIT_USAGE;
			ho.max_connections = (unsigned)n;
		} else if (strcmp(a, "--max-queued") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 1000000))
				return PRSM_EXIT_USAGE;
			jo.max_queued = (size_t)n;
		} else if (strcmp(a, "--max-samples") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 2, 4000000))
				return PRSM_EXIT_USAGE;
			jo.limits.max_samples = (size_t)n;
		} else if (strcmp(a, "--job-time-cap-s") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 86400 * 7))
				return PRSM_EXIT_USAGE;
			jo.limits.max_time_s = (double)n;
		} else if (strcmp(a, "--sync-time-ms") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 1, 600000))
				return PRSM_EXIT_USAGE;
			ho.sync_time_s = (double)n * 1e-3;
		} else if (strcmp(a, "--sync-budget") == 0) {
			if (prsm_cli_int_option(&n, "serve", a, v, 0, 1000000000000LL))
				return PRSM_EXIT_USAGE;
			ho.sync_evaluations = (double)n;
		} else if (strcmp(a, "--data-dir") == 0) {
			ho.data_dir = v;
		} else if (strcmp(a, "--executor") == 0) {
			if (strcmp(v, "local") != 0 && strcmp(v, "slurm") != 0) {
				fprintf(stderr, "prsm serve: --executor: local or slurm, not '%s'\n", v);
				return PRSM_EXIT_USAGE;
			}
			slurm_on = strcmp(v, "slurm") == 0;
		} else if (strcmp(a, "--slurm-min-samples") == 0) {
			if (prsm_cli_int_option(&slurm_min, "serve", a, v, 0, 1000000000000LL))
				return PRSM_EXIT_USAGE;
		} else if (strcmp(a, "--slurm-spool") == 0) {
			slurm_spool = v;
		} else if (strcmp(a, "--slurm-prsm") == 0) {
			slurm_prsm = v;
		} else if (strcmp(a, "--slurm-poll-s") == 0) {
			char *end = NULL;
			slurm_poll_s = strtod(v, &end);
			if (end == v || *end || !(slurm_poll_s >= 0.01 && slurm_poll_s <= 3600.0)) {
				fprintf(stderr, "prsm serve: --slurm-poll-s: seconds in [0.01, 3600], not '%s'\n", v);
				return PRSM_EXIT_USAGE;
			}
		} else if (strcmp(a, "--sbatch-arg") == 0) {
			if (slurm.n_sbatch_args == PRSM_SLURM_MAX_ARGS) {
				fprintf(stderr, "prsm serve: at most %d --sbatch-arg\n", PRSM_SLURM_MAX_ARGS);
				return PRSM_EXIT_USAGE;
			}
			slurm.sbatch_args[slurm.n_sbatch_args++] = argv[i];
		} else {
			fprintf(stderr, "prsm serve: unknown option '%s'\n", a);
			serve_usage(stderr);
			return PRSM_EXIT_USAGE;
		}
	}
	if (token_file) {
		if (read_token(token, sizeof token, token_file))
			return PRSM_EXIT_USAGE;
	} else if (getenv("PRSM_TOKEN") && getenv("PRSM_TOKEN")[0]) {
		snprintf(token, sizeof token, "%s", getenv("PRSM_TOKEN"));
	}
	ho.token = token[0] ? token : NULL;
	if (!slurm_on && slurm_option) {
		fprintf(stderr, "prsm serve: %s needs --executor slurm\n", slurm_option);
		return PRSM_EXIT_USAGE;
	}
	if (slurm_on) {
		prsm_error serr = PRSM_ERROR_INIT;
		if (prsm_slurm_init(&slurm, slurm_spool, slurm_prsm, (size_t)slurm_min, slurm_poll_s, &serr)) {
			fprintf(stderr, "prsm serve: --executor slurm: %s\n", serr.message);
			return PRSM_EXIT_USAGE;
		}
		jo.executor = &slurm.executor;
	}
	jo.store_connections = ho.threads + jo.workers + 2;
	if (jo.store_connections > PRSM_STORE_MAX_CONNS)
		jo.store_connections = PRSM_STORE_MAX_CONNS;

	/* every thread started from here on inherits the blocked signals; sigwait takes them */
	sigset_t set;
	sigemptyset(&set);
	sigaddset(&set, SIGINT);
	sigaddset(&set, SIGTERM);
	pthread_sigmask(SIG_BLOCK, &set, NULL);
	signal(SIGPIPE, SIG_IGN);

	prsm_error err = PRSM_ERROR_INIT;
	prsm_jobs *jobs = NULL;
	int recovered = 0;
	if (prsm_jobs_open(&jobs, &jo, &recovered, &err)) {
		fprintf(stderr, "prsm serve: %s\n", err.message);
		return PRSM_EXIT_FAILED;
	}
	prsm_http *http = NULL;
	if (prsm_http_start(&http, &ho, jobs, &err)) {
		fprintf(stderr, "prsm serve: %s\n", err.message);
		prsm_jobs_close(jobs);
		return PRSM_EXIT_FAILED;
	}
	fprintf(stderr, "prsm serve: listening on http://%s%s%s:%d/ (database %s, data %s, %d worker%s%s%s)\n",
	        strchr(ho.host, ':') ? "[" : "", ho.host, strchr(ho.host, ':') ? "]" : "", prsm_http_port(http),
	        jo.db_path, ho.data_dir, jo.workers, jo.workers == 1 ? "" : "s",
	        ho.token ? ", token required for POST and DELETE" : "", recovered ? ", resuming interrupted jobs" : "");
	if (slurm_on)
		fprintf(stderr, "prsm serve: jobs of %lld samples or more go to Slurm (spool %s, prsm %s)%s\n", slurm_min,
		        slurm.spool, slurm.prsm,
		        (size_t)slurm_min > jo.limits.max_samples ? "; no study reaches that under --max-samples" : "");
	int sig = 0;
	sigwait(&set, &sig);
	fprintf(stderr, "prsm serve: %s: stopping\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
	prsm_http_quiesce(http);
	/* a moment for requests in flight to be answered */
	struct timespec ts = {0, 200000000L};
	nanosleep(&ts, NULL);
	prsm_http_stop(http);
	prsm_jobs_close(jobs);
	fprintf(stderr, "prsm serve: stopped\n");
	return 0;
}
