/*
 * analyze.c: `prsm analyze` and `prsm validate`: read a design document, report every problem
 * with its JSON pointer, or print the nominal analysis. `prsm analyze` never simulates: a
 * request's `dynamics` object is checked and the result says (a warning) that the transient is
 * `prsm simulate`'s (docs/dynamics.md).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "cli/summary.h"
#include "io/global.h"
#include "app/allocate.h"
#include "app/validate.h"
#include "app/simulate.h"
#include "io/allocation_json.h"
#include "io/analysis_json.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/json_util.h"
#include "app/optimize.h"
#include "io/optimization_json.h"
#include "util/file.h"
#include "util/version.h"

typedef struct {
	const char *path;
	const char *out_path;
	const char *measured_path; /* validate --measured CSV: a calibration's curve */
	int text;   /* --format text */
} options;

static int parse_options(options *o, int argc, char **argv, int text_default)
{
	memset(o, 0, sizeof *o);
	o->text = text_default;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--format") == 0 && i + 1 < argc) {
			const char *f = argv[++i];
			if (strcmp(f, "text") == 0)
				o->text = 1;
			else if (strcmp(f, "json") == 0)
				o->text = 0;
			else {
				fprintf(stderr, "prsm: --format must be json or text (got '%s')\n", f);
				return -1;
			}
		} else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc && strcmp(argv[0], "analyze") == 0) {
			o->out_path = argv[++i];
		} else if (strcmp(argv[i], "--measured") == 0 && i + 1 < argc && strcmp(argv[0], "validate") == 0) {
			o->measured_path = argv[++i];
		} else if (argv[i][0] == '-' && argv[i][1] != '\0') {
			fprintf(stderr, "prsm %s: unknown option '%s'\n", argv[0], argv[i]);
			return -1;
		} else if (o->path == NULL) {
			o->path = argv[i];
		} else {
			fprintf(stderr, "prsm %s: more than one file given\n", argv[0]);
			return -1;
		}
	}
	if (o->path == NULL) {
		fprintf(stderr, "usage: prsm %s FILE|- [--format json|text]%s\n", argv[0],
		        strcmp(argv[0], "analyze") == 0 ? " [--out FILE]" : " [--measured CSV]");
		return -1;
	}
	return 0;
}

void prsm_cli_print_problems(FILE *f, const char *path, const prsm_problems *p)
{
	for (int i = 0; i < p->count; i++)
		fprintf(f, "%s: %s: %s\n", path, p->items[i].pointer[0] ? p->items[i].pointer : "/",
		        p->items[i].message);
	if (p->dropped)
		fprintf(f, "%s: and %d more problems\n", path, p->dropped);
}

int prsm_cli_print_json(const cJSON *doc, const char *out_path)
{
	/* a command builds one document on the main thread: any cJSON allocation that failed since
	 * the process started may have dropped a member of it, so it is not printed (global.h) */
	char *text = prsm_json_print_whole(doc, 0, 1);
	if (text == NULL) {
		fprintf(stderr, "prsm: out of memory writing the result\n");
		return PRSM_EXIT_FAILED;
	}
	FILE *f = out_path ? fopen(out_path, "w") : stdout;
	if (f == NULL) {
		perror(out_path);
		free(text);
		return PRSM_EXIT_FAILED;
	}
	fprintf(f, "%s\n", text);
	int bad = ferror(f);
	if (f != stdout)
		bad |= fclose(f);
	free(text);
	return bad ? PRSM_EXIT_FAILED : PRSM_EXIT_OK;
}

int prsm_cli_read_document(cJSON **doc, const char *path, prsm_problems *problems)
{
	char *text = NULL;
	size_t len = 0;
	prsm_error err = PRSM_ERROR_INIT;
	*doc = NULL;
	if (prsm_file_read(&text, &len, path, PRSM_CLI_MAX_REQUEST_BYTES, &err)) {
		prsm_problems_add(problems, "", err.code == PRSM_EIO ? "unreadable" : "too_large", "%s", err.message);
		return err.code == PRSM_EIO ? PRSM_EXIT_USAGE : PRSM_EXIT_INVALID;
	}
	*doc = prsm_json_parse(text, len, problems);
	free(text);
	return *doc ? 0 : PRSM_EXIT_INVALID;
}

int prsm_cli_validate(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 1))
		return PRSM_EXIT_USAGE;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	/* read as the command that runs it reads it (app/validate.h: the kind by its members) */
	prsm_doc_kind kind = PRSM_DOC_DESIGN;
	int vrc = 0;
	if (rc == 0) {
		vrc = prsm_app_validate(doc, o.measured_path, &kind, &warnings, &problems);
		rc = prsm_error_exit_code(vrc);
	}
	cJSON_Delete(doc);
	if (rc == PRSM_EXIT_USAGE) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	if (o.text) {
		prsm_cli_print_problems(stdout, o.path, &problems);
		if (rc == 0) {
			for (int i = 0; i < warnings.count; i++)
				printf("%s: warning: %s: %s\n", o.path, warnings.items[i].pointer, warnings.items[i].message);
			printf("%s: valid\n", o.path);
		}
	} else {
		cJSON *res = prsm_app_validation_to_json(rc == 0 ? 0 : vrc ? vrc : PRSM_EINVAL, kind, &warnings, &problems);
		if (res == NULL)
			return PRSM_EXIT_FAILED;
		prsm_cli_print_json(res, NULL);
		cJSON_Delete(res);
	}
	return rc;
}

static int write_analysis(const options *o, const prsm_analyze_request *rq,
                          const prsm_problems *warnings)
{
	if (o->text) {
		FILE *f = o->out_path ? fopen(o->out_path, "w") : stdout;
		if (f == NULL) {
			perror(o->out_path);
			return PRSM_EXIT_FAILED;
		}
		prsm_cli_print_analyze(f, rq, warnings);
		int bad = ferror(f);
		if (f != stdout)
			bad |= fclose(f);
		return bad ? PRSM_EXIT_FAILED : 0;
	}
	cJSON *res = prsm_io_analyze_to_json(rq, warnings);
	if (res == NULL)
		return PRSM_EXIT_FAILED;
	int rc = prsm_cli_print_json(res, o->out_path);
	cJSON_Delete(res);
	return rc;
}

int prsm_cli_analyze(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 0))
		return PRSM_EXIT_USAGE;
	prsm_analyze_request *rq = calloc(1, sizeof *rq);
	if (rq == NULL)
		return PRSM_EXIT_FAILED;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc == 0)
		rc = prsm_error_exit_code(prsm_app_analyze_load(rq, doc, &warnings, &problems));
	cJSON_Delete(doc);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
	} else {
		rc = prsm_error_exit_code(prsm_app_analyze_run(rq));
		if (rc == 0)
			rc = write_analysis(&o, rq, &warnings);
	}
	prsm_io_analyze_free(rq);
	free(rq);
	return rc;
}

int prsm_cli_version(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	printf("{\"engine\": \"prsm\", \"version\": \"%s\", \"build\": \"%s\", \"git_revision\": \"%s\", "
	       "\"model\": \"prsm model 2026-11\"}\n",
	       PRSM_VERSION, prsm_engine_build(), prsm_git_revision());
	return 0;
}
