/*
 * study.c: `prsm study FILE`: a Monte Carlo tolerance study (DESIGN.md, "Monte Carlo engine").
 * Reads the study document, reports every problem with its pointer (exit 1), runs the engine
 * with a progress bar on stderr when stderr is a terminal, and prints the result as JSON on
 * stdout or --out; --csv writes every sample.
 *
 * Under MPI (mpirun, srun, --mpi: src/par, docs/mpi.md) every rank runs this: rank 0 reads the
 * document (the launcher gives standard input to rank 0 only) and broadcasts its bytes, every
 * rank loads it, the study runs over the ranks (par/study.h), and rank 0 alone reports, prints
 * the progress and writes; the others exit with rank 0's code.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/commands.h"
#include "io/analysis_json.h"
#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"
#include "par/par.h"
#include "par/study.h"
#include "util/clock.h"
#include "util/file.h"
#include "util/mem.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	if (p->planned == 0) {
		/* a phase without a count (the summaries): named on a line of its own, which the next
		 * phase's bar overwrites */
		if (p->phase)
			fprintf(stderr, "\n%s", p->phase);
		fflush(stderr);
		return;
	}
	int width = 40, filled = (int)((double)p->done / (double)p->planned * width);
	fprintf(stderr, "\r[");
	for (int i = 0; i < width; i++)
		fputc(i < filled ? '#' : '.', stderr);
	fprintf(stderr, "] %zu / %zu samples", p->done, p->planned);
	if (!isnan(p->interval_width))
		fprintf(stderr, ", interval %.4g (goal %.4g)", p->interval_width, p->interval_goal);
	fflush(stderr);
}

int prsm_cli_read_document_par(cJSON **doc, const char *path, prsm_problems *problems)
{
	*doc = NULL;
	char *text = NULL;
	size_t len = 0;
	int32_t status = 0;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_par_rank() == 0 && prsm_file_read(&text, &len, path, PRSM_CLI_MAX_REQUEST_BYTES, &err)) {
		prsm_problems_add(problems, "", err.code == PRSM_EIO ? "unreadable" : "too_large", "%s", err.message);
		status = err.code == PRSM_EIO ? PRSM_EXIT_USAGE : PRSM_EXIT_INVALID;
	}
	if (prsm_par_bcast(&status, sizeof status, &err) || (status == 0 && prsm_par_bcast_blob(&text, &len, &err)))
		prsm_par_abort(PRSM_EXIT_FAILED, "%s", err.message);
	if (status)
		return status;
	*doc = prsm_json_parse(text, len, problems);
	free(text);
	return *doc ? 0 : PRSM_EXIT_INVALID;
}

/* prsm_par_study_load_fn: the study of a document rank 0 sends, through the study reader. */
static int serve_load(void *ctx, prsm_study **study, void **handle, const char *text, size_t len, prsm_error *err)
{
	(void)ctx;
	prsm_problems *pr = malloc(sizeof *pr);
	prsm_io_study *s = calloc(1, sizeof *s);
	if (!pr || !s) {
		free(pr);
		free(s);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	prsm_problems_init(pr);
	cJSON *doc = prsm_json_parse(text, len, pr);
	int rc = doc ? prsm_app_study_load(s, doc, NULL, pr) : PRSM_EINVAL;
	cJSON_Delete(doc);
	if (rc) {
		prsm_error_set(err, rc, NULL, "%s%s%s", pr->count ? pr->items[0].pointer : "",
		               pr->count && pr->items[0].pointer[0] ? ": " : "",
		               pr->count ? pr->items[0].message : "the study could not be loaded");
		free(pr);
		free(s);
		return rc;
	}
	free(pr);
	*study = &s->study;
	*handle = s;
	return 0;
}

static void serve_release(void *ctx, void *handle)
{
	(void)ctx;
	free(handle);
}

int prsm_cli_study_serve(void)
{
	return prsm_par_study_serve(serve_load, serve_release, NULL);
}

static void progress_line(const prsm_cli_progress_lines *pl, const prsm_progress *p)
{
	fprintf(stderr, "prsm %s: %zu / %zu %s on %d ranks", pl->command, p->done, p->planned, p->unit ? p->unit : pl->unit,
	        prsm_par_size());
	if (!isnan(p->interval_width))
		fprintf(stderr, ", interval %.4g (goal %.4g)", p->interval_width, p->interval_goal);
	fputc('\n', stderr);
	fflush(stderr);
}

void prsm_cli_progress_lines_flush(prsm_cli_progress_lines *pl)
{
	if (pl->has_held)
		progress_line(pl, &pl->held);
	pl->has_held = 0;
}

void prsm_cli_progress_lines_fn(void *ctx, const prsm_progress *p)
{
	prsm_cli_progress_lines *pl = ctx;
	if (p->planned == 0) {
		/* a phase without a count (a study's summaries): the count it ended on, then its name */
		prsm_cli_progress_lines_flush(pl);
		if (p->phase) {
			fprintf(stderr, "prsm %s: %s on %d ranks\n", pl->command, p->phase, prsm_par_size());
			fflush(stderr);
		}
		return;
	}
	double now = prsm_clock_seconds();
	if (p->done < p->planned && now - pl->last_s < 10.0) {
		pl->held = *p;
		pl->has_held = 1;
		return;
	}
	pl->last_s = now;
	pl->has_held = 0;
	progress_line(pl, p);
}

int prsm_cli_study_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study *s = calloc(1, sizeof *s);
	if (!s)
		return PRSM_EXIT_FAILED;
	int rc = prsm_app_study_load(s, doc, warnings, problems);
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
	const int par = prsm_par_active(), leader = prsm_par_rank() == 0;
	cJSON *doc;
	int rc = par ? prsm_cli_read_document_par(&doc, o.path, &problems) : prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		if (leader)
			prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	/* the reader clears the whole study (some 700 KB) first: its pages faulted in at once */
	prsm_io_study *s = prsm_mem_calloc_populated(sizeof *s);
	prsm_study_result *r = calloc(1, sizeof *r);
	if (!s || !r) {
		free(s);
		free(r);
		cJSON_Delete(doc);
		return PRSM_EXIT_FAILED;
	}
	int lrc = prsm_app_study_load(s, doc, &warnings, &problems);
	cJSON_Delete(doc);
	if (par) {
		/* every rank loaded the same bytes: the same outcome, or something is badly wrong */
		int32_t lead_rc = lrc;
		prsm_error berr = PRSM_ERROR_INIT;
		if (prsm_par_bcast(&lead_rc, sizeof lead_rc, &berr))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", berr.message);
		if (lead_rc != lrc)
			prsm_par_abort(PRSM_EXIT_FAILED, "loaded the study with code %d where rank 0 had %d", lrc, (int)lead_rc);
	}
	if (lrc) {
		if (leader)
			prsm_cli_print_problems(stderr, o.path, &problems);
		rc = prsm_error_exit_code(lrc);
		goto done;
	}
	if (o.threads)
		s->study.mc.threads = o.threads;
	prsm_cli_progress_lines lines = {.command = "study", .unit = "samples", .last_s = -1e9};
	if (leader && !o.quiet && isatty(STDERR_FILENO)) {
		s->study.mc.progress = progress;
		s->study.mc.progress_ctx = NULL;
	} else if (leader && par && !o.quiet) {
		s->study.mc.progress = prsm_cli_progress_lines_fn;
		s->study.mc.progress_ctx = &lines;
	}
	prsm_error err = PRSM_ERROR_INIT;
	int src = par ? prsm_par_study_run(r, &s->study, &err) : prsm_study_run(r, &s->study, &err);
	if (!leader) {
		/* a follower: rank 0 reports and writes */
		rc = prsm_error_exit_code(src);
		goto done;
	}
	if (s->study.mc.progress == progress)
		fputc('\n', stderr);
	else if (s->study.mc.progress)
		prsm_cli_progress_lines_flush(&lines);
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
