/*
 * calibrate.c: `prsm calibrate FILE|- [--measured CSV]` (issue 17, docs/measured-data.md): a
 * design with measured data (schemas/measured-request.schema.json) compared with the model,
 * its TE lines identified by spectrum, the line model or the physical model calibrated
 * (estimates, standard errors, correlation, the identifiability caveats), friction from a
 * measured efficiency and carrier drag from a measured cage ratio (MODEL §8.5). The TE curve is
 * the document's measured.te or a CSV file (--measured; every problem of the file at its line
 * and column). Prints the result as JSON (schemas/measured-result.schema.json) or, with
 * --format text, a summary with the caveats; on stdout or --out. Exit codes as every command:
 * 1 an invalid request or CSV file, 2 a computation that failed, 64 usage.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/calibrate.h"
#include "cli/commands.h"

typedef struct {
	const char *path, *out_path, *csv_path;
	int text;
} options;

static int parse(options *o, int argc, char **argv)
{
	memset(o, 0, sizeof *o);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const int has_value = i + 1 < argc;
		if (strcmp(a, "--format") == 0 && has_value) {
			const char *f = argv[++i];
			if (strcmp(f, "json") != 0 && strcmp(f, "text") != 0) {
				fprintf(stderr, "prsm calibrate: --format must be json or text (got '%s')\n", f);
				return -1;
			}
			o->text = strcmp(f, "text") == 0;
		} else if (strcmp(a, "--out") == 0 && has_value) {
			o->out_path = argv[++i];
		} else if (strcmp(a, "--measured") == 0 && has_value) {
			o->csv_path = argv[++i];
		} else if (a[0] == '-' && a[1] != '\0') {
			fprintf(stderr, "prsm calibrate: unknown option '%s'\n", a);
			return -1;
		} else if (!o->path) {
			o->path = a;
		} else {
			fprintf(stderr, "prsm calibrate: more than one file given\n");
			return -1;
		}
	}
	if (!o->path) {
		fprintf(stderr, "usage: prsm calibrate FILE|- [--measured CSV] [--format json|text] [--out FILE]\n");
		return -1;
	}
	return 0;
}

int prsm_cli_calibrate(int argc, char **argv)
{
	options o;
	if (parse(&o, argc, argv))
		return PRSM_EXIT_USAGE;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	prsm_app_calibration *c;
	const int lrc = prsm_app_calibration_load(&c, doc, o.csv_path, &problems);
	cJSON_Delete(doc);
	if (lrc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return lrc == PRSM_EIO ? PRSM_EXIT_INVALID : prsm_error_exit_code(lrc);
	}
	prsm_error err = PRSM_ERROR_INIT;
	const int crc = prsm_app_calibration_run(c, &err);
	if (crc) {
		if (err.pointer[0])
			fprintf(stderr, "%s: %s: %s\n", o.path, err.pointer, err.message);
		else
			fprintf(stderr, "%s: %s\n", o.path, err.message);
		prsm_app_calibration_free(c);
		return prsm_error_exit_code(crc);
	}
	if (o.text) {
		FILE *f = o.out_path ? fopen(o.out_path, "w") : stdout;
		if (!f) {
			perror(o.out_path);
			rc = PRSM_EXIT_FAILED;
		} else {
			rc = prsm_app_calibration_text(f, c) ? PRSM_EXIT_FAILED : 0;
			if (f != stdout && fclose(f))
				rc = PRSM_EXIT_FAILED;
		}
	} else {
		cJSON *res = prsm_app_calibration_result(c);
		rc = res ? prsm_cli_print_json(res, o.out_path) : PRSM_EXIT_FAILED;
		cJSON_Delete(res);
	}
	prsm_app_calibration_free(c);
	return rc;
}
