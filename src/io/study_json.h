/*
 * study_json.h: the study document (schemas/study.schema.json) to a prsm_study, and its result
 * to JSON and CSV (DESIGN.md, "Documents": study, result).
 *
 * A study is a design (or a named analytic benchmark, or a model of the study's own
 * expressions, mc/expr_model.h) + `tolerances` + `outputs` + `specs` +
 * `monte_carlo` + `sensitivity`, with optional `errors` (a fixed error set every sample starts
 * from), `assembly` (mode, measuring load, angles per revolution) and `correlations`. Every
 * problem is reported at once with its JSON pointer. Units convert here: a tolerance is given in
 * the unit its parameter names (screw.runout_um in µm), the engine binds it in mm or rad.
 */
#ifndef PRSM_IO_STUDY_JSON_H
#define PRSM_IO_STUDY_JSON_H

#include <stdio.h>

#include <cJSON.h>

#include "mc/bench_models.h"
#include "mc/expr_model.h"
#include "mc/prsm_model.h"
#include "mc/study.h"
#include "model/assembly.h"
#include "util/problems.h"

/* Limits of the document (the schema states the same numbers). */
#define PRSM_IO_STUDY_MAX_TOLERANCES 64
#define PRSM_IO_STUDY_MAX_LOSS_THREADS 500 /* = PRSM_DESIGN_ENGAGED_THREADS_MAX */

/* One tolerance as the document gave it (echoed in the result). */
typedef struct {
	char parameter[PRSM_STUDY_NAME_MAX];
	prsm_dist dist;                  /* in the parameter's API unit */
	prsm_dist_histogram hist;        /* a histogram's bins (dist.hist points here) */
	int shorthand;                   /* given as {"tol_*": t, "cpk": c} */
	double tol, cpk;                 /* the shorthand's values */
	int per_roller, per_start, shared, radial;
} prsm_io_tolerance;

/* A loaded study: everything the engine's model points into lives here, so the struct must
 * not move after prsm_io_study_load(). Large (about 1 MB): allocate it on the heap. The
 * analysis, the assembly, prsm's model terms and dynamics' prepared model are filled by the
 * reader's hooks (prsm_io_study_options), the rest by the reader. */
typedef struct {
	char name[404]; /* up to 100 characters of UTF-8 */
	int is_benchmark;               /* an analytic model, not a design: a benchmark or expressions */
	prsm_bench_model bench;         /* kind PRSM_BENCH_EXPRESSION (inputs: expr's) for expressions */
	prsm_expr_model expr;           /* the expression model, when bench.kind says so */
	int expr_single;                /* given as "expression" (one output, y), not "expressions" */
	prsm_design design;
	prsm_analysis analysis;
	prsm_assembly assembly;
	prsm_assembly_options assembly_options;
	prsm_mc_prsm prsm;
	prsm_mc_binding bindings[PRSM_MC_MAX_VARIABLES];
	size_t n_tolerances;
	prsm_io_tolerance tolerances[PRSM_IO_STUDY_MAX_TOLERANCES];
	prsm_study study;
	/* efficiency_with_losses: the nominal load distribution's normal loads of one roller's
	 * contacts, screw side then nut side, N (prsm.loss_*_loads_N point here) */
	int loss_threads;
	double loss_loads_N[2][PRSM_IO_STUDY_MAX_LOSS_THREADS];
	/* dynamic outputs (docs/vibration.md, "Monte Carlo over dynamic outputs"): the dynamics and
	 * dynamic_monte_carlo sections (prsm.dyn points here when has_dynamics) */
	int has_dynamics;
	prsm_mc_dyn dynamics;
	double dyn_stop_half_width;     /* dynamic_monte_carlo/stop_half_width; NaN: none */
} prsm_io_study;

/* What the study reader leaves to its caller (app/study.h, prsm_app_study_options): io reads
 * documents and runs no analysis, yet the reading needs two results of one, in place, so that
 * its problems come in the order and number they always did.
 *
 * analyse_design is called by the design step once the design, its error set and the assembly
 * options are read and the design is valid: it runs the nominal analysis into s->analysis and
 * builds s->assembly, adding a problem (at the design's pointer) when the design cannot work,
 * and returns 0 or that code. The steps after it take the design as usable only when it
 * returned 0 (the parameters a tolerance may name, the outputs needing a load, the dynamics
 * section), and the reader returns its code.
 *
 * prepare_model is called by the model step of a design study with no problem so far, once
 * s->prsm holds the bindings, outputs and assembly options: it builds s->study.model (and what
 * the outputs need of the nominal nut unit or of the dynamic model), adding a problem at the
 * output or section that needed what could not be computed.
 *
 * check_study is called by prsm_io_study_load once the document reads without a problem: it
 * refuses, at the field at fault, what the engine could not compute (app/study.c: the
 * distributions' and a benchmark's outputs' ranges), adding problems and warnings.
 *
 * NULL hooks (PRSM_IO_STUDY_OPTIONS_INIT): the design is taken as usable when it reads, and a
 * design study's model is left unbuilt (the study cannot run), nothing checked: a pure reading. */
typedef struct {
	int (*analyse_design)(prsm_io_study *s, prsm_problems *warnings, prsm_problems *problems, void *ctx);
	void (*prepare_model)(prsm_io_study *s, prsm_problems *problems, void *ctx);
	void (*check_study)(prsm_io_study *s, prsm_problems *warnings, prsm_problems *problems, void *ctx);
	void *ctx; /* the hooks' */
} prsm_io_study_options;

#define PRSM_IO_STUDY_OPTIONS_INIT {NULL, NULL, NULL, NULL}

/* Set *o to PRSM_IO_STUDY_OPTIONS_INIT. Returns 0. */
int prsm_io_study_options_init(prsm_io_study_options *o);

/* Read and check the study document doc, with the hooks (NULL: PRSM_IO_STUDY_OPTIONS_INIT), and
 * build the variables, then check what the reading alone cannot (hooks->check_study). Every
 * problem goes to problems with its pointer; rule warnings of the design to warnings (may be
 * NULL). Returns 0, PRSM_EINVAL (problems were added) or, from
 * hooks->analyse_design, PRSM_EGEOMETRY / PRSM_EEDGE (the design cannot be analysed; a problem
 * names it). prsm_app_study_load (app/study.h) is this with the application's hooks: what
 * every caller that runs the study calls. */
int prsm_io_study_load(prsm_io_study *out, const cJSON *doc, const prsm_io_study_options *hooks,
                       prsm_problems *warnings, prsm_problems *problems);

/* The result document (schemas/study-result.schema.json). The caller owns the tree. */
cJSON *prsm_io_study_result_to_json(const prsm_io_study *s, const prsm_study_result *r);

/* Every sample as CSV: sample index, status, the variables in their API units, the outputs
 * (empty for failed samples). Returns 0 or PRSM_EIO. */
int prsm_io_study_write_csv(FILE *f, const prsm_io_study *s, const prsm_study_result *r);

#endif
