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
#include "io/allocation_json.h"
#include "io/analysis_json.h"
#include "mc/engine.h"

typedef struct {
	const char *path, *out_path;
	int threads;     /* 0: the document's */
	int quiet;
} allocate_options;

static int parse(allocate_options *o, int argc, char **argv)
{
	memset(o, 0, sizeof *o);
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
			o->out_path = argv[++i];
		} else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
			char *end;
			long v = strtol(argv[++i], &end, 10);
			if (*end || v < 1 || v > PRSM_MC_MAX_THREADS) {
				fprintf(stderr, "prsm allocate: --threads takes 1..%d\n", PRSM_MC_MAX_THREADS);
				return -1;
			}
			o->threads = (int)v;
		} else if (strcmp(argv[i], "--quiet") == 0) {
			o->quiet = 1;
		} else if (argv[i][0] == '-' && argv[i][1] != '\0') {
			fprintf(stderr, "prsm allocate: unknown option '%s'\n", argv[i]);
			return -1;
		} else if (!o->path) {
			o->path = argv[i];
		} else {
			fprintf(stderr, "prsm allocate: more than one file given\n");
			return -1;
		}
	}
	if (!o->path) {
		fprintf(stderr, "usage: prsm allocate FILE|- [--out FILE] [--threads N] [--quiet]\n");
		return -1;
	}
	return 0;
}

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
	allocate_options o;
	if (parse(&o, argc, argv))
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
	int arc = prsm_io_allocation_execute(&res, doc, NULL, show ? progress : NULL, NULL, 0.0, o.threads,
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
