/*
 * study.c: `prsm study FILE`: a Monte Carlo tolerance study (DESIGN.md, "Monte Carlo engine").
 * Reads the study document, reports every problem with its pointer (exit 1), runs the engine
 * with a progress bar on stderr when stderr is a terminal, and prints the result as JSON on
 * stdout or --out; --csv writes every sample.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/analysis_json.h"
#include "io/study_json.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	int width = 40, filled = p->planned ? (int)((double)p->done / (double)p->planned * width) : width;
	fprintf(stderr, "\r[");
	for (int i = 0; i < width; i++)
		fputc(i < filled ? '#' : '.', stderr);
	fprintf(stderr, "] %zu / %zu samples", p->done, p->planned);
	if (!isnan(p->interval_width))
		fprintf(stderr, ", interval %.4g (goal %.4g)", p->interval_width, p->interval_goal);
	fflush(stderr);
}

int prsm_cli_study_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study *s = calloc(1, sizeof *s);
	if (!s)
		return PRSM_EXIT_FAILED;
	int rc = prsm_io_study_load(s, doc, warnings, problems);
	free(s);
	return rc ? prsm_error_exit_code(rc) : 0;
}

int prsm_cli_study(int argc, char **argv)
{
	prsm_cli_doc_options o;
	if (prsm_cli_doc_options_parse(&o, argc, argv, "study", PRSM_CLI_WITH_CSV | PRSM_CLI_WITH_THREADS))
		return PRSM_EXIT_USAGE;
	prsm_problems warnings, problems;
	prsm_problems_init(&warnings);
	prsm_problems_init(&problems);
	cJSON *doc;
	int rc = prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_study_result *r = calloc(1, sizeof *r);
	if (!s || !r) {
		free(s);
		free(r);
		cJSON_Delete(doc);
		return PRSM_EXIT_FAILED;
	}
	int lrc = prsm_io_study_load(s, doc, &warnings, &problems);
	cJSON_Delete(doc);
	if (lrc) {
		prsm_cli_print_problems(stderr, o.path, &problems);
		rc = prsm_error_exit_code(lrc);
		goto done;
	}
	if (o.threads)
		s->study.mc.threads = o.threads;
	if (!o.quiet && isatty(STDERR_FILENO)) {
		s->study.mc.progress = progress;
		s->study.mc.progress_ctx = NULL;
	}
	prsm_error err = PRSM_ERROR_INIT;
	int src = prsm_study_run(r, &s->study, &err);
	if (s->study.mc.progress)
		fputc('\n', stderr);
	if (src) {
		fprintf(stderr, "%s: %s\n", o.path, err.message);
		rc = prsm_error_exit_code(src);
		goto done;
	}
	cJSON *res = prsm_io_study_result_to_json(s, r);
	if (res && warnings.count)
		cJSON_AddItemToObject(res, "design_warnings", prsm_io_problems_to_json(&warnings));
	rc = res ? prsm_cli_print_json(res, o.out_path) : PRSM_EXIT_FAILED;
	cJSON_Delete(res);
	if (rc == 0 && o.csv_path) {
		FILE *f = fopen(o.csv_path, "w");
		if (!f) {
			perror(o.csv_path);
			rc = PRSM_EXIT_FAILED;
		} else {
			if (prsm_io_study_write_csv(f, s, r))
				rc = PRSM_EXIT_FAILED;
			if (fclose(f))
				rc = PRSM_EXIT_FAILED;
		}
	}
	prsm_study_result_free(r);
done:
	free(s);
	free(r);
	return rc;
}
