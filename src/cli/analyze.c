/*
 * analyze.c: `prsm analyze` and `prsm validate`: read a design document, report every problem
 * with its JSON pointer, or print the nominal analysis.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "io/analysis_json.h"
#include "io/design_json.h"
#include "io/json_util.h"
#include "model/analysis.h"
#include "util/file.h"

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

static void print_problems(FILE *f, const char *path, const prsm_problems *p)
{
	for (int i = 0; i < p->count; i++)
		fprintf(f, "%s: %s: %s\n", path, p->items[i].pointer[0] ? p->items[i].pointer : "/",
		        p->items[i].message);
	if (p->dropped)
		fprintf(f, "%s: and %d more problems\n", path, p->dropped);
}

static int print_json(cJSON *doc, const char *out_path)
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

/* Read, parse and load the design; problems go to *problems. Returns 0 or an exit code. */
static int load(prsm_design *d, prsm_geometry *g, prsm_problems *warnings, prsm_problems *problems,
                const char *path)
{
	char *text = NULL;
	size_t len = 0;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_file_read(&text, &len, path, PRSM_CLI_MAX_REQUEST_BYTES, &err)) {
		prsm_problems_add(problems, "", err.code == PRSM_EIO ? "unreadable" : "too_large", "%s", err.message);
		return err.code == PRSM_EIO ? PRSM_EXIT_USAGE : PRSM_EXIT_INVALID;
	}
	cJSON *doc = prsm_json_parse(text, len, problems);
	free(text);
	if (doc == NULL)
		return PRSM_EXIT_INVALID;
	int rc = prsm_io_design_load(d, g, warnings, doc, "", problems);
	cJSON_Delete(doc);
	return rc ? PRSM_EXIT_INVALID : 0;
}

/* Parse, load and analyse the design: the checks shared by validate and analyze. Problems of
 * the document and of the nominal contacts (edge contact, no contact point) go to *problems;
 * warnings are those of the analysis. Returns 0 or an exit code. */
static int load_and_analyse(prsm_design *d, prsm_analysis *a, prsm_problems *warnings,
                            prsm_problems *problems, const char *path)
{
	prsm_geometry g;
	int rc = load(d, &g, warnings, problems, path);
	if (rc)
		return rc;
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_analysis_nominal(a, d, warnings, &err);
	if (arc == 0)
		return 0;
	/* only the contact solver can tell that the contacts lie on their flanks */
	prsm_problems_add(problems, err.pointer, arc == PRSM_EEDGE ? "edge_contact" : "no_contact",
	                  "%s", err.message);
	return prsm_error_exit_code(arc);
}

int prsm_cli_validate(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 1))
		return PRSM_EXIT_USAGE;
	prsm_design d;
	prsm_analysis a;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	int rc = load_and_analyse(&d, &a, &warnings, &problems, o.path);
	if (rc == PRSM_EXIT_USAGE) {
		print_problems(stderr, o.path, &problems);
		return rc;
	}
	if (o.text) {
		print_problems(stdout, o.path, &problems);
		if (rc == 0) {
			for (int i = 0; i < warnings.count; i++)
				printf("%s: warning: %s: %s\n", o.path, warnings.items[i].pointer, warnings.items[i].message);
			printf("%s: valid\n", o.path);
		}
	} else {
		cJSON *doc = cJSON_CreateObject();
		cJSON_AddBoolToObject(doc, "valid", rc == 0);
		cJSON_AddItemToObject(doc, "errors", prsm_io_problems_to_json(&problems));
		cJSON_AddItemToObject(doc, "warnings", prsm_io_problems_to_json(&warnings));
		print_json(doc, NULL);
		cJSON_Delete(doc);
	}
	return rc;
}

int prsm_cli_analyze(int argc, char **argv)
{
	options o;
	if (parse_options(&o, argc, argv, 0))
		return PRSM_EXIT_USAGE;
	prsm_design d;
	prsm_analysis a;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	int rc = load_and_analyse(&d, &a, &warnings, &problems, o.path);
	if (rc) {
		print_problems(stderr, o.path, &problems);
		return rc;
	}
	if (o.text) {
		FILE *f = o.out_path ? fopen(o.out_path, "w") : stdout;
		if (f == NULL) {
			perror(o.out_path);
			return PRSM_EXIT_FAILED;
		}
		prsm_io_analysis_print_text(f, &a, &d, &warnings);
		if (f != stdout)
			fclose(f);
		return 0;
	}
	cJSON *res = prsm_io_analysis_to_json(&a, &d, &warnings);
	if (res == NULL)
		return PRSM_EXIT_FAILED;
	rc = print_json(res, o.out_path);
	cJSON_Delete(res);
	return rc;
}

int prsm_cli_version(int argc, char **argv)
{
	(void)argc;
	(void)argv;
	printf("{\"engine\": \"prsm\", \"version\": \"%s\", \"model\": \"MODEL.md 2026-11\"}\n", PRSM_VERSION);
	return 0;
}
