/*
 * analyze.c: `prsm analyze` and `prsm validate`: read a design document, report every problem
 * with its JSON pointer, or print the nominal analysis.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "io/analysis_json.h"
#include "io/assembly_json.h"
#include "io/design_json.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "model/analysis.h"
#include "model/assembly_report.h"
#include "util/file.h"

/* What a request asks for: a design document alone (the nominal analysis), or
 * {"design", "errors", "assembly"} (the nominal analysis and the error analysis of MODEL.md §3,
 * §4 for one concrete error set). */
typedef struct {
	prsm_design d;
	prsm_analysis a;
	int with_errors;               /* the request form with errors and/or assembly */
	prsm_errors errors;
	prsm_assembly_options options;
	prsm_assembly as;
} request;

static const char *const request_keys[] = {"design", "errors", "assembly", NULL};

typedef struct {
	const char *path;
	const char *out_path;
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
		} else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
			o->out_path = argv[++i];
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
		        strcmp(argv[0], "analyze") == 0 ? " [--out FILE]" : "");
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
	char *text = cJSON_Print(doc);
	if (text == NULL)
		return PRSM_EXIT_FAILED;
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

/* Load the request document doc (taken over and freed here); problems go to *problems.
 * Returns 0 or an exit code. */
static int load(request *rq, prsm_geometry *g, prsm_problems *warnings, prsm_problems *problems,
                cJSON *doc)
{
	int rc;
	rq->with_errors = cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "design") != NULL;
	if (!rq->with_errors) {
		rc = prsm_io_design_load(&rq->d, g, warnings, doc, "", problems);
	} else {
		prsm_json_check_keys(doc, "", request_keys, problems);
		const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
		rc = prsm_io_design_load(&rq->d, g, warnings, design, "/design", problems);
		const cJSON *errors = NULL, *opts = NULL;
		char ep[PRSM_JSON_POINTER_MAX], op[PRSM_JSON_POINTER_MAX];
		prsm_json_get_object(&errors, doc, "", "errors", PRSM_JSON_OPTIONAL, problems);
		prsm_json_get_object(&opts, doc, "", "assembly", PRSM_JSON_OPTIONAL, problems);
		prsm_json_pointer_append(ep, sizeof ep, "", "errors");
		prsm_json_pointer_append(op, sizeof op, "", "assembly");
		/* the error set's shape (Z rollers, n starts) and the lead need the design; when it is
		 * invalid the rest is still checked against an unknown one, all problems at once */
		prsm_design unknown;
		prsm_design_init(&unknown);
		unknown.rollers = unknown.starts = 0;
		const prsm_design *shape = rc == 0 ? &rq->d : &unknown;
		prsm_io_errors_from_json(&rq->errors, errors, ep, shape, problems);
		prsm_io_assembly_options_from_json(&rq->options, opts, op, shape, problems);
		if (problems->count || problems->dropped)
			rc = PRSM_EINVAL;
	}
	cJSON_Delete(doc);
	return rc ? PRSM_EXIT_INVALID : 0;
}

/* Parse, load and analyse the request: the checks shared by validate and analyze. Problems of
 * the document and of the nominal contacts (edge contact, no contact point) go to *problems;
 * warnings are those of the analysis. Returns 0 or an exit code. */
static int load_and_analyse(request *rq, prsm_problems *warnings, prsm_problems *problems,
                            cJSON *doc)
{
	prsm_geometry g;
	int rc = load(rq, &g, warnings, problems, doc);
	if (rc)
		return rc;
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_analysis_nominal(&rq->a, &rq->d, warnings, &err);
	if (arc == 0 && rq->with_errors)
		arc = prsm_assembly_init(&rq->as, &rq->d, &rq->a, &err);
	if (arc == 0)
		return 0;
	/* only the contact solver can tell that the contacts lie on their flanks */
	char ptr[PRSM_JSON_POINTER_MAX + 8];
	snprintf(ptr, sizeof ptr, "%s%s", rq->with_errors ? "/design" : "", err.pointer);
	prsm_problems_add(problems, ptr,
	                  arc == PRSM_EEDGE ? "edge_contact" : arc == PRSM_EINVAL ? "too_large" : "no_contact",
	                  "%s", err.message);
	return prsm_error_exit_code(arc);
}

/* The error analysis of the request's error set (MODEL.md §3, §4); ws buffers allocated here. */
typedef struct {
	prsm_assembly_report report;
	prsm_assembly_workspace *ws;
} error_analysis;

static int run_error_analysis(error_analysis *ea, const request *rq)
{
	int n, m;
	prsm_assembly_record_length(&n, &m, &rq->as, &rq->options);
	ea->ws = calloc(1, sizeof *ea->ws);
	if (ea->ws == NULL)
		return PRSM_EXIT_FAILED;
	ea->ws->te_mm = calloc((size_t)n, sizeof(double));
	ea->ws->spectrum_mm = calloc((size_t)m, sizeof(double));
	if (ea->ws->te_mm == NULL || ea->ws->spectrum_mm == NULL)
		return PRSM_EXIT_FAILED;
	prsm_assembly_analyse(&ea->report, &rq->as, &rq->errors, &rq->options, ea->ws);
	return 0;
}

static void free_error_analysis(error_analysis *ea)
{
	if (ea->ws) {
		free(ea->ws->te_mm);
		free(ea->ws->spectrum_mm);
		free(ea->ws);
	}
}

int prsm_cli_validate(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 1))
		return PRSM_EXIT_USAGE;
	request *rq = calloc(1, sizeof *rq);
	if (rq == NULL)
		return PRSM_EXIT_FAILED;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc == 0 && cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "tolerances")) {
		rc = prsm_cli_study_check(doc, &warnings, &problems);
		cJSON_Delete(doc);
	} else if (rc == 0) {
		rc = load_and_analyse(rq, &warnings, &problems, doc);
	}
	free(rq);
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
		cJSON *res = cJSON_CreateObject();
		cJSON_AddBoolToObject(res, "valid", rc == 0);
		cJSON_AddItemToObject(res, "errors", prsm_io_problems_to_json(&problems));
		cJSON_AddItemToObject(res, "warnings", prsm_io_problems_to_json(&warnings));
		prsm_cli_print_json(res, NULL);
		cJSON_Delete(res);
	}
	return rc;
}

static int write_analysis(const options *o, const request *rq, const error_analysis *ea,
                          const prsm_problems *warnings)
{
	if (o->text) {
		FILE *f = o->out_path ? fopen(o->out_path, "w") : stdout;
		if (f == NULL) {
			perror(o->out_path);
			return PRSM_EXIT_FAILED;
		}
		prsm_io_analysis_print_text(f, &rq->a, &rq->d, warnings);
		if (rq->with_errors)
			prsm_io_assembly_print_text(f, &ea->report, &rq->as);
		int bad = ferror(f);
		if (f != stdout)
			bad |= fclose(f);
		return bad ? PRSM_EXIT_FAILED : 0;
	}
	cJSON *res = prsm_io_analysis_to_json(&rq->a, &rq->d, warnings);
	if (res == NULL)
		return PRSM_EXIT_FAILED;
	if (rq->with_errors) {
		cJSON_AddItemToObject(res, "errors", prsm_io_errors_to_json(&rq->errors, rq->d.starts));
		cJSON_AddItemToObject(res, "assembly", prsm_io_assembly_to_json(&ea->report, &rq->as, &rq->options, ea->ws));
	}
	int rc = prsm_cli_print_json(res, o->out_path);
	cJSON_Delete(res);
	return rc;
}

int prsm_cli_analyze(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 0))
		return PRSM_EXIT_USAGE;
	request *rq = calloc(1, sizeof *rq);
	if (rq == NULL)
		return PRSM_EXIT_FAILED;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	error_analysis ea = {0};
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc == 0)
		rc = load_and_analyse(rq, &warnings, &problems, doc);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
	} else {
		if (rq->with_errors)
			rc = run_error_analysis(&ea, rq);
		if (rc == 0)
			rc = write_analysis(&o, rq, &ea, &warnings);
	}
	free_error_analysis(&ea);
	free(rq);
	return rc;
}

int prsm_cli_version(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	printf("{\"engine\": \"prsm\", \"version\": \"%s\", \"model\": \"MODEL.md 2026-11\"}\n", PRSM_VERSION);
	return 0;
}
