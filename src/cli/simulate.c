/*
 * simulate.c: `prsm simulate FILE|-`: the start-up transient of a design or a chain (issue 15,
 * docs/dynamics.md), or a vibration analysis of the reduced model of a design or of a 1-DOF gear
 * pair (issue 16, docs/vibration.md: linear, vibration, sweep, frequency_response, basins).
 * Reads the simulation request (schemas/simulation.schema.json), reports every problem with its
 * pointer (exit 1), runs it with a progress line on stderr when stderr is a terminal (simulated
 * time, sweep points or basin cells), and prints the result as JSON
 * (schemas/dynamics-result.schema.json) or, with --format text, a summary, on stdout or --out;
 * --csv FILE writes the time series (transient; vibration: the recorded window), the
 * bifurcation points (sweep, frequency_response), the basin grid or the FRF (linear); --threads N
 * runs sweep points and basin cells on N threads (the result does not depend on N). A run that
 * does not converge prints why and exits 2.
 *
 * Under MPI (docs/mpi.md) every rank reads the request (rank 0's bytes) and a sweep's directions
 * (continuation) or points, or a basin grid's cells, are spread over the ranks (par/vib.h); rank 0
 * finishes, reports and writes the result one process writes, byte for byte. Any other analysis
 * runs whole on rank 0, the other ranks exit at once.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/simulate.h"
#include "cli/commands.h"
#include "par/par.h"
#include "par/vib.h"

static void progress(void *ctx, const prsm_progress *p)
{
	(void)ctx;
	fprintf(stderr, "\rsimulated %.6g of %.6g s   ", (double)p->done * 1e-9, (double)p->planned * 1e-9);
	fflush(stderr);
}

/* The vibration analyses: sweep points, basin cells, or one analysis. */
static void progress_count(void *ctx, const prsm_progress *p)
{
	const char *const *unit = ctx;
	fprintf(stderr, "\r%zu of %zu %s   ", p->done, p->planned, *unit);
	fflush(stderr);
}

typedef struct {
	const char *path, *out_path, *csv_path;
	int text, quiet, threads;
} options;

static int parse(options *o, int argc, char **argv)
{
	memset(o, 0, sizeof *o);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const int has_value = i + 1 < argc;
		if (strcmp(a, "--format") == 0 && has_value) {
			const char *f = argv[++i];
			if (strcmp(f, "json") != 0 && strcmp(f, "text") != 0) {
				fprintf(stderr, "prsm simulate: --format must be json or text (got '%s')\n", f);
				return -1;
			}
			o->text = strcmp(f, "text") == 0;
		} else if (strcmp(a, "--out") == 0 && has_value) {
			o->out_path = argv[++i];
		} else if (strcmp(a, "--csv") == 0 && has_value) {
			o->csv_path = argv[++i];
		} else if (strcmp(a, "--quiet") == 0) {
			o->quiet = 1;
		} else if (strcmp(a, "--threads") == 0 && has_value) {
			char *end;
			const long t = strtol(argv[++i], &end, 10);
			if (*end != '\0' || t < 1 || t > 256) {
				fprintf(stderr, "prsm simulate: --threads must be 1 to 256 (got '%s')\n", argv[i]);
				return -1;
			}
			o->threads = (int)t;
		} else if (a[0] == '-' && a[1] != '\0') {
			fprintf(stderr, "prsm simulate: unknown option '%s'\n", a);
			return -1;
		} else if (!o->path) {
			o->path = a;
		} else {
			fprintf(stderr, "prsm simulate: more than one file given\n");
			return -1;
		}
	}
	if (!o->path) {
		fprintf(stderr, "usage: prsm simulate FILE|- [--format json|text] [--out FILE] [--csv FILE] [--threads N] [--quiet]\n");
		return -1;
	}
	return 0;
}

/* The CSV of the run to path. */
static int write_csv(const char *path, const prsm_app_simulation *s)
{
	FILE *f = fopen(path, "w");
	if (!f) {
		perror(path);
		return PRSM_EXIT_FAILED;
	}
	int rc = prsm_app_simulation_csv(f, s) ? PRSM_EXIT_FAILED : 0;
	if (fclose(f))
		rc = PRSM_EXIT_FAILED;
	return rc;
}

static int write_text(const char *path, const prsm_app_simulation *s)
{
	FILE *f = path ? fopen(path, "w") : stdout;
	if (!f) {
		perror(path);
		return PRSM_EXIT_FAILED;
	}
	int rc = prsm_app_simulation_text(f, s) ? PRSM_EXIT_FAILED : 0;
	if (f != stdout && fclose(f))
		rc = PRSM_EXIT_FAILED;
	return rc;
}

int prsm_cli_simulate(int argc, char **argv)
{
	options o;
	if (parse(&o, argc, argv))
		return PRSM_EXIT_USAGE;
	prsm_problems problems;
	prsm_problems_init(&problems);
	const int par = prsm_par_active(), leader = prsm_par_rank() == 0;
	cJSON *doc;
	int rc = par ? prsm_cli_read_document_par(&doc, o.path, &problems) : prsm_cli_read_document(&doc, o.path, &problems);
	if (rc) {
		if (leader)
			prsm_cli_print_problems(stderr, o.path, &problems);
		return rc;
	}
	prsm_app_simulation *s = NULL;
	int lrc = prsm_app_simulation_load(&s, doc, NULL, &problems);
	cJSON_Delete(doc);
	if (par) {
		/* every rank loaded the same bytes: the same outcome, or something is badly wrong */
		int32_t lead_rc = lrc;
		prsm_error berr = PRSM_ERROR_INIT;
		if (prsm_par_bcast(&lead_rc, sizeof lead_rc, &berr))
			prsm_par_abort(PRSM_EXIT_FAILED, "%s", berr.message);
		if (lead_rc != lrc)
			prsm_par_abort(PRSM_EXIT_FAILED, "loaded the simulation with code %d where rank 0 had %d", lrc, (int)lead_rc);
	}
	if (lrc) {
		if (leader)
			prsm_cli_print_problems(stderr, o.path, &problems);
		return prsm_error_exit_code(lrc);
	}
	prsm_vib_split split;
	if (par) {
		/* a sweep's directions or points, a basin grid's cells over the ranks; any other
		 * analysis runs whole on rank 0 */
		prsm_par_vib_split(&split);
		if (!prsm_app_simulation_set_split(s, &split) && !leader) {
			prsm_app_simulation_free(s);
			return 0;
		}
	}
	const int bar = leader && !o.quiet && isatty(STDERR_FILENO);
	prsm_error err = PRSM_ERROR_INIT;
	if (o.threads)
		prsm_app_simulation_set_threads(s, o.threads);
	const char *unit = "simulated_ns";
	prsm_app_simulation_work(s, &unit);
	const int transient = strcmp(unit, "simulated_ns") == 0;
	prsm_cli_progress_lines lines = {.command = "simulate", .unit = unit, .last_s = -1e9};
	prsm_progress_fn fn = bar ? (transient ? progress : progress_count)
	                          : par && leader && !o.quiet && !transient ? prsm_cli_progress_lines_fn : NULL;
	void *fn_ctx = bar ? (transient ? NULL : (void *)&unit) : &lines;
	int src = prsm_app_simulation_run(s, NULL, fn, fn_ctx, 0.0, &err);
	if (bar)
		fputc('\n', stderr);
	else if (fn)
		prsm_cli_progress_lines_flush(&lines);
	if (!leader) {
		/* a follower: its part went to rank 0, which reports and writes */
		prsm_app_simulation_free(s);
		return prsm_error_exit_code(src);
	}
	if (src) {
		if (err.pointer[0])
			fprintf(stderr, "%s: %s: %s\n", o.path, err.pointer, err.message);
		else
			fprintf(stderr, "%s: %s\n", o.path, err.message);
		prsm_app_simulation_free(s);
		return prsm_error_exit_code(src);
	}
	if (o.text) {
		rc = write_text(o.out_path, s);
	} else {
		cJSON *res = prsm_app_simulation_result(s);
		rc = res ? prsm_cli_print_json(res, o.out_path) : PRSM_EXIT_FAILED;
		cJSON_Delete(res);
	}
	if (rc == 0 && o.csv_path)
		rc = write_csv(o.csv_path, s);
	prsm_app_simulation_free(s);
	return rc;
}
