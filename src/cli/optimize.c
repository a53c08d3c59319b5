/*
 * optimize.c: `prsm optimize FILE|-`: a design optimisation (issue 7, DESIGN.md "Optimisation").
 * Reads the optimisation document, reports every problem with its pointer (exit 1), runs the
 * search with a progress line on stderr when stderr is a terminal (evaluations and the best
 * feasible objective so far), and prints the result as JSON on stdout or --out. A result whose
 * best design is infeasible is still printed (exit 0, "feasible": false, the violated
 * constraints named); a failed computation exits 2.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "app/optimize.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	fprintf(stderr, "\r%zu / %zu evaluations, best ", p->done, p->planned);
	if (isnan(p->best))
		fprintf(stderr, "(none feasible yet)   ");
	else
		fprintf(stderr, "%.6g          ", p->best);
	fflush(stderr);
}

int prsm_cli_optimize(int argc, char **argv)
{
	prsm_cli_doc_options o;
	if (prsm_cli_doc_options_parse(&o, argc, argv, "optimize", 0))
		return PRSM_EXIT_USAGE;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	int bar = !o.quiet && isatty(STDERR_FILENO);
	cJSON *res = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	int orc = prsm_app_optimize(&res, doc, NULL, bar ? progress : NULL, NULL, 0.0,
	                                       &problems, &err);
	cJSON_Delete(doc);
	if (bar)
		fputc('\n', stderr);
	if (orc == PRSM_EINVAL && problems.count) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		cJSON_Delete(res);
		return PRSM_EXIT_INVALID;
	}
	if (orc && !res) {
		fprintf(stderr, "%s: %s\n", o.path, err.message);
		return prsm_error_exit_code(orc);
	}
	rc = prsm_cli_print_json(res, o.out_path);
	cJSON_Delete(res);
	return rc ? rc : orc ? prsm_error_exit_code(orc) : PRSM_EXIT_OK;
}
