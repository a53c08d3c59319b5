/*
 * run_job.c: `prsm run-job KIND REQUEST --out RESULT [...]`: one stored job request run by its
 * kind (job/kind.h), as a service worker runs it. The service's Slurm executor (job/slurm.h)
 * writes a job script that runs this on a compute node, then reads the files back into its
 * cache, so a job gives the same result on the cluster as in the service.
 *
 *   --out FILE       the result document (written only when the run succeeds)
 *   --csv FILE       the samples CSV, when the kind writes one
 *   --error FILE     the kind's error as {"code", "pointer", "message"} (when it fails)
 *   --counts FILE    "samples_done samples_planned"
 *   --threads N, --time-cap-s S, --max-samples N: the service's per-job limits
 *
 * Exit codes: 0 done, 1 an invalid request, 2 the run failed, 64 usage.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "cli/commands.h"
#include "job/kind.h"
#include "util/file.h"

static int write_file(const char *path, const char *text, size_t len)
{
	FILE *f = fopen(path, "w");
	if (!f) {
		perror(path);
		return -1;
	}
	int bad = fwrite(text, 1, len, f) != len;
	if (fclose(f) || bad) {
		fprintf(stderr, "prsm run-job: %s: cannot write\n", path);
		return -1;
	}
	return 0;
}

static int usage(void)
{
	fprintf(stderr, "usage: prsm run-job KIND REQUEST --out FILE [--csv FILE] [--error FILE] [--counts FILE]\n"
	                "                    [--threads N] [--time-cap-s S] [--max-samples N]\n");
	return PRSM_EXIT_USAGE;
}

int prsm_cli_run_job(int argc, char **argv)
{
	if (argc < 3)
		return usage();
	const prsm_job_kind *k = prsm_job_kind_by_name(argv[1]);
	if (!k) {
		fprintf(stderr, "prsm run-job: no job kind '%s'\n", argv[1]);
		return PRSM_EXIT_USAGE;
	}
	const char *request_path = argv[2], *out_path = NULL, *csv_path = NULL, *error_path = NULL,
	           *counts_path = NULL;
	prsm_job_limits lim = {0, 0.0, 1};
	for (int i = 3; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		long long n;
		if (!v)
			return usage();
		i++;
		if (strcmp(a, "--out") == 0) {
			out_path = v;
		} else if (strcmp(a, "--csv") == 0) {
			csv_path = v;
		} else if (strcmp(a, "--error") == 0) {
			error_path = v;
		} else if (strcmp(a, "--counts") == 0) {
			counts_path = v;
		} else if (strcmp(a, "--threads") == 0) {
			if (prsm_cli_int_option(&n, "run-job", a, v, 1, 64))
				return PRSM_EXIT_USAGE;
			lim.threads = (int)n;
		} else if (strcmp(a, "--max-samples") == 0) {
			if (prsm_cli_int_option(&n, "run-job", a, v, 0, 4000000))
				return PRSM_EXIT_USAGE;
			lim.max_samples = (size_t)n;
		} else if (strcmp(a, "--time-cap-s") == 0) {
			char *end = NULL;
			double s = strtod(v, &end);
			if (end == v || *end || !(s >= 0.0) || !isfinite(s)) {
				fprintf(stderr, "prsm run-job: --time-cap-s: a number of seconds >= 0, not '%s'\n", v);
				return PRSM_EXIT_USAGE;
			}
			lim.max_time_s = s;
		} else {
			fprintf(stderr, "prsm run-job: unknown option '%s'\n", a);
			return usage();
		}
	}
	if (!out_path)
		return usage();
	char *request = NULL;
	size_t len = 0;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_file_read(&request, &len, request_path, 64u * 1024u * 1024u, &err);
	prsm_job_output out = {0};
	if (rc == 0) {
		prsm_job_run_ctx ctx = {NULL, NULL, NULL, lim};
		rc = k->run(&out, request, &ctx, &err);
	}
	free(request);
	int exit_code = 0;
	if (rc) {
		if (error_path) {
			cJSON *e = cJSON_CreateObject();
			cJSON_AddNumberToObject(e, "code", rc);
			cJSON_AddStringToObject(e, "pointer", err.pointer);
			cJSON_AddStringToObject(e, "message", err.message[0] ? err.message : prsm_error_name(rc));
			char *text = cJSON_PrintUnformatted(e);
			if (!text || write_file(error_path, text, strlen(text)))
				exit_code = PRSM_EXIT_FAILED;
			cJSON_free(text);
			cJSON_Delete(e);
		}
		fprintf(stderr, "prsm run-job: %s: %s\n", request_path, err.message[0] ? err.message : prsm_error_name(rc));
		prsm_job_output_free(&out);
		return prsm_error_exit_code(rc);
	}
	if (write_file(out_path, out.result, out.result_len) || (csv_path && out.csv && write_file(csv_path, out.csv, out.csv_len)))
		exit_code = PRSM_EXIT_FAILED;
	if (counts_path) {
		char line[64];
		int n = snprintf(line, sizeof line, "%lld %lld\n", out.samples_done, out.samples_planned);
		if (write_file(counts_path, line, (size_t)n))
			exit_code = PRSM_EXIT_FAILED;
	}
	prsm_job_output_free(&out);
	return exit_code;
}
