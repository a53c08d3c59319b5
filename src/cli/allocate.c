/*
 * allocate.c: `prsm allocate FILE`: tolerance allocation (issue 7, item 4). Reads the
 * allocation document, reports every problem with its pointer (exit 1), allocates with the
 * linear stack model, verifies and corrects with Monte Carlo (a progress line on stderr when
 * stderr is a terminal), and prints the result as JSON on stdout or --out.
 *
 * Under MPI (mpirun, srun, --mpi: docs/mpi.md) rank 0 reads, allocates and writes; each
 * correction's study runs over every rank (par/study.h, a study service), so the result is one
 * process's, byte for byte; the other ranks serve those studies and exit with rank 0's code.
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
#include "par/par.h"
#include "par/study.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	fprintf(stderr, "\r%zu / %zu Monte Carlo samples", p->done, p->planned);
	if (isfinite(p->best))
		fprintf(stderr, ", best cost %.6g", p->best);
	fflush(stderr);
}

static int allocate(const prsm_cli_doc_options *o);

int prsm_cli_allocate(int argc, char **argv)
{
	prsm_cli_doc_options o;
	const int par = prsm_par_active();
	if (par && prsm_par_rank() != 0)
		return prsm_cli_study_serve(); /* the corrections' studies, until rank 0 is done */
	int rc = prsm_cli_doc_options_parse(&o, argc, argv, "allocate", PRSM_CLI_WITH_THREADS) ? PRSM_EXIT_USAGE
	                                                                                        : allocate(&o);
	if (par)
		prsm_par_study_service_finish(rc);
	return rc;
}

/* Under MPI this is rank 0's: the corrections' studies run over every rank (a study service). */
static int allocate(const prsm_cli_doc_options *opt)
{
	const prsm_cli_doc_options o = *opt;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc, *res = NULL;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	int show = !o.quiet && isatty(STDERR_FILENO);
	const int par = prsm_par_active();
	prsm_cli_progress_lines lines = {.command = "allocate", .unit = "Monte Carlo samples", .last_s = -1e9};
	prsm_progress_fn fn = show ? progress : par && !o.quiet ? prsm_cli_progress_lines_fn : NULL;
	void *fn_ctx = show ? NULL : &lines;
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_app_allocate_with(&res, doc, NULL, fn, fn_ctx, 0.0, o.threads,
	                                 par ? prsm_par_study_service() : NULL, &problems, &err);
	cJSON_Delete(doc);
	if (show)
		fputc('\n', stderr);
	else if (fn)
		prsm_cli_progress_lines_flush(&lines);
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
