/*
 * optimize.c: `prsm optimize FILE|-`: a design optimisation (issue 7, DESIGN.md "Optimisation").
 * Reads the optimisation document, reports every problem with its pointer (exit 1), runs the
 * search with a progress line on stderr when stderr is a terminal (evaluations and the best
 * feasible objective so far), and prints the result as JSON on stdout or --out. A result whose
 * best design is infeasible is still printed (exit 0, "feasible": false, the violated
 * constraints named); a failed computation exits 2.
 *
 * Under MPI (docs/mpi.md) rank 0 reads, searches and writes; the robust constraints' studies run
 * over every rank (par/study.h, a study service), so the result is one process's, byte for
 * byte; the other ranks serve those studies and exit with rank 0's code. The search itself stays
 * on rank 0: its evaluation budget is shared out as it goes, so its local runs are sequential.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "app/optimize.h"
#include "par/par.h"
#include "par/study.h"

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

static int optimize(const prsm_cli_doc_options *o);

int prsm_cli_optimize(int argc, char **argv)
{
	prsm_cli_doc_options o;
	const int par = prsm_par_active();
	if (par && prsm_par_rank() != 0)
		return prsm_cli_study_serve(); /* the robust constraints' studies, until rank 0 is done */
	int rc = prsm_cli_doc_options_parse(&o, argc, argv, "optimize", 0) ? PRSM_EXIT_USAGE : optimize(&o);
	if (par)
		prsm_par_study_service_finish(rc);
	return rc;
}

/* Under MPI this is rank 0's: the robust constraints' studies run over every rank. */
static int optimize(const prsm_cli_doc_options *opt)
{
	const prsm_cli_doc_options o = *opt;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	int bar = !o.quiet && isatty(STDERR_FILENO);
	const int par = prsm_par_active();
	prsm_cli_progress_lines lines = {.command = "optimize", .unit = "evaluations", .last_s = -1e9};
	prsm_progress_fn fn = bar ? progress : par && !o.quiet ? prsm_cli_progress_lines_fn : NULL;
	void *fn_ctx = bar ? NULL : &lines;
	cJSON *res = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	int orc = prsm_app_optimize_with(&res, doc, NULL, fn, fn_ctx, 0.0, par ? prsm_par_study_service() : NULL,
	                                 &problems, &err);
	cJSON_Delete(doc);
	if (bar)
		fputc('\n', stderr);
	else if (fn)
		prsm_cli_progress_lines_flush(&lines);
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
