/*
 * allocate.c: `prsm allocate FILE`: tolerance allocation (issue 7, item 4). Reads the
 * allocation document, reports every problem with its pointer (exit 1), allocates with the
 * linear stack model, verifies and corrects with Monte Carlo (a progress line on stderr when
 * stderr is a terminal), and prints the result as JSON on stdout or --out.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "app/allocate.h"
#include "io/allocation_json.h"
#include "io/analysis_json.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	fprintf(stderr, "\r%zu / %zu Monte Carlo samples", p->done, p->planned);
	if (isfinite(p->best))
		fprintf(stderr, ", best cost %.6g", p->best);
	fflush(stderr);
}

int prsm_cli_allocate(int argc, char **argv)
{
	prsm_cli_doc_options o;
	if (prsm_cli_doc_options_parse(&o, argc, argv, "allocate", PRSM_CLI_WITH_THREADS))
		return PRSM_EXIT_USAGE;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc, *res = NULL;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	int show = !o.quiet && isatty(STDERR_FILENO);
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_app_allocate(&res, doc, NULL, show ? progress : NULL, NULL, 0.0, o.threads,
	                                     &problems, &err);
	cJSON_Delete(doc);
	if (show)
		fputc('\n', stderr);
	if (arc == PRSM_EINVAL && problems.count) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		rc = PRSM_EXIT_INVALID;
	} else if (arc) {
		fprintf(stderr, "%s: %s\n", o.path, err.message);
		rc = prsm_error_exit_code(arc);
	} else {
		rc = prsm_cli_print_json(res, o.out_path);
	}
	cJSON_Delete(res);
	return rc;
}
