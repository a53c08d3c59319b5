/*
 * commands.h: the subcommands of the prsm command line. Each takes the arguments after the
 * program name (argv[0] is the command) and returns the process exit code.
 */
#ifndef PRSM_CLI_COMMANDS_H
#define PRSM_CLI_COMMANDS_H

#include <stdio.h>

#include <cJSON.h>

#include "model/design.h"
#include "util/problems.h"
#include "util/progress.h"

enum { PRSM_EXIT_OK = 0, PRSM_EXIT_INVALID = 1, PRSM_EXIT_FAILED = 2, PRSM_EXIT_USAGE = 64 };

/* Largest request file the CLI reads, bytes. */
#define PRSM_CLI_MAX_REQUEST_BYTES (16u * 1024u * 1024u)

int prsm_cli_analyze(int argc, char **argv);
int prsm_cli_validate(int argc, char **argv);
int prsm_cli_bench(int argc, char **argv);
int prsm_cli_version(int argc, char **argv);
int prsm_cli_study(int argc, char **argv);
int prsm_cli_serve(int argc, char **argv);
int prsm_cli_optimize(int argc, char **argv);
int prsm_cli_allocate(int argc, char **argv);
int prsm_cli_batch(int argc, char **argv);
int prsm_cli_simulate(int argc, char **argv);
int prsm_cli_calibrate(int argc, char **argv);
int prsm_cli_run_job(int argc, char **argv);

/* One `prsm bench` entry, value rounded to `decimals` (null when not finite). */
void prsm_cli_bench_add(cJSON *list, const char *name, double value, const char *unit, int threads,
                        int decimals);
/* The Monte Carlo entries of `prsm bench`, each sized to about budget_s seconds. */
void prsm_cli_bench_study(cJSON *list, double budget_s);
/* The rigid-body dynamics entries of `prsm bench` (src/cli/bench_dyn.c), each about budget_s. */
void prsm_cli_bench_dyn(cJSON *list, double budget_s);
/* The design-optimisation entry of `prsm bench` (src/cli/bench_opt.c). */
void prsm_cli_bench_opt(cJSON *list);
/* Case A of docs/model/geometry-and-meshing.md as the benches take it (Z = 10, 10 engaged threads, 20 um target
 * clearance, 7000 N at 100 rad/s), not yet resolved by the standard rules. */
void prsm_cli_bench_case_a(prsm_design *d);

/* A whole-number option value in lo..hi into *out; otherwise says so ("prsm COMMAND: OPT takes
 * an integer lo..hi") and returns -1. value may be NULL (missing). */
int prsm_cli_int_option(long long *out, const char *command, const char *opt, const char *value, long long lo,
                        long long hi);

/* The options of a command that runs one document: FILE|- (required), --out FILE, --quiet, and
 * with PRSM_CLI_WITH_CSV --csv FILE, with PRSM_CLI_WITH_THREADS --threads N (1..PRSM_MC_MAX_THREADS). */
typedef struct {
	const char *path, *out_path, *csv_path;
	int threads;     /* 0: the document's */
	int quiet;
} prsm_cli_doc_options;

enum { PRSM_CLI_WITH_CSV = 1, PRSM_CLI_WITH_THREADS = 2 };

/* Parse argv (argv[0] is the command); problems and the usage line go to stderr. 0 or -1. */
int prsm_cli_doc_options_parse(prsm_cli_doc_options *o, int argc, char **argv, const char *command, int with);

/* Read and parse a request file ("-": stdin) into *doc (the caller frees it); problems of the
 * file or its JSON go to problems. Returns 0 or an exit code. */
int prsm_cli_read_document(cJSON **doc, const char *path, prsm_problems *problems);
/* The document under MPI: rank 0 reads the bytes (the launcher gives standard input to rank 0
 * only) and broadcasts them, every rank parses them (problems are rank 0's to print). Returns 0
 * or the exit code, the same on every rank. */
int prsm_cli_read_document_par(cJSON **doc, const char *path, prsm_problems *problems);
/* Print every problem as "path: pointer: message", one per line. */
void prsm_cli_print_problems(FILE *f, const char *path, const prsm_problems *p);
/* Print doc as JSON to out_path (NULL: stdout). Returns 0 or PRSM_EXIT_FAILED. */
int prsm_cli_print_json(const cJSON *doc, const char *out_path);

/* Validate a study document (a parsed tree the caller keeps); returns 0 or an exit code. */
int prsm_cli_study_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems);

/* Under MPI, a rank other than 0 of a command whose studies rank 0 hands out (allocate, optimize:
 * par/study.h, a study service): loads each study's document with the study reader and runs its
 * part, until rank 0 finishes; returns rank 0's exit code. */
int prsm_cli_study_serve(void);

/* Progress of a command under MPI when stderr is not a terminal (a launcher's pipe, a Slurm log):
 * "prsm COMMAND: DONE / PLANNED UNIT on N ranks[, interval W (goal G)]" every 10 s and when a run
 * reaches its cap; a phase without a count (planned 0) first prints the count the throttle held
 * back (a run that stopped early on its target), then "prsm COMMAND: PHASE on N ranks". ctx: a
 * prsm_cli_progress_lines with command, unit and last_s -1e9 (the rest zero). */
typedef struct {
	const char *command, *unit;
	double last_s;
	prsm_progress held; /* the last report the throttle held back, when has_held */
	int has_held;
} prsm_cli_progress_lines;
void prsm_cli_progress_lines_fn(void *ctx, const prsm_progress *p);
/* Print the report the throttle held back, if any (at the end of a command). */
void prsm_cli_progress_lines_flush(prsm_cli_progress_lines *pl);

#endif
