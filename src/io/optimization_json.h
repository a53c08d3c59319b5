/*
 * optimization_json.h: the design-optimisation document (schemas/optimization.schema.json, whose
 * descriptions say what it holds and what the reader checks) to the design problem of
 * src/opt/design_problem.h, and its result (schemas/optimization-result.schema.json) to JSON.
 * Issue 7, DESIGN.md "Optimisation".
 */
#ifndef PRSM_IO_OPTIMIZATION_JSON_H
#define PRSM_IO_OPTIMIZATION_JSON_H

#include <stddef.h>

#include <cJSON.h>

#include "io/study_json.h"
#include "mc/study.h"
#include "model/analysis.h"
#include "model/performance.h"
#include "opt/design_problem.h"
#include "opt/optimize.h"
#include "opt/pareto.h"
#include "opt/robust.h"
#include "util/error.h"
#include "util/problems.h"

#define PRSM_IO_OPT_MAX_EVALUATIONS 1000000 /* solver.max_evaluations' cap (the schema's maximum) */

/* The methods of multi_objective.method. */
enum { PRSM_IO_OPT_SINGLE = 0, PRSM_IO_OPT_WEIGHTED = 1, PRSM_IO_OPT_PARETO = 2 };

/* A loaded document. The run (src/app/optimize.c) points the problem's context at spec and the
 * robust studies' builder at its own code, so the struct must not move once read. */
typedef struct {
	char name[404]; /* up to 100 characters of UTF-8 */
	prsm_dp_spec spec;
	prsm_opt_problem problem;
	prsm_opt_options options;
	int method;
	int points;                       /* Pareto levels */
	double weight[PRSM_OPT_MAX_OBJECTIVES];
	int rollers_auto_max;             /* rollers' max defaulted to the Z_max bound */
	int pitch_values_given;           /* the document gives lead_values_mm or pitch_values_mm (those
	                                     members exist only then: the readers' parity, docs/ratings.md) */
	/* robust constraints (the "robust" section) */
	int has_robust;
	prsm_robust robust;
	cJSON *study;                     /* the study document of a candidate: the base design (its
	                                     geometry replaced per candidate), the section's tolerances,
	                                     correlations, assembly and monte_carlo, the constrained
	                                     outputs and specs, no sensitivities; owned */
	char sampler[16];                 /* the robust studies' sampler, as run */
	size_t block_size;
	int threads;
} prsm_io_optimization;

/* An objective as the table-driven reader reads it (generated from the schema, src/io/doc.h);
 * a step appends it to spec.objective and weight. */
typedef struct {
	int kind;                         /* PRSM_DP_* */
	double weight;
} prsm_io_opt_objective;

/* Read and check doc into od, the robust section's study of the base design with the study
 * reader's hooks `study` (io/study_json.h; prsm_app_study_options, as the run will load it):
 * every problem to problems with its pointer, remarks (e.g.
 * base-design radii the optimiser replaces) to warnings (may be NULL); max_evaluations caps
 * solver.max_evaluations (0: PRSM_IO_OPT_MAX_EVALUATIONS). The design problem (od->problem)
 * and the robust builder are the run's (src/app/optimize.h). Release od with
 * prsm_io_optimization_release whatever is returned. Returns 0, PRSM_EINVAL or PRSM_ENOMEM. */
int prsm_io_optimization_read(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations,
                              const prsm_io_study_options *study, prsm_problems *warnings,
                              prsm_problems *problems);

/* Free what od owns (not od). */
void prsm_io_optimization_release(prsm_io_optimization *od);

/* ---- the result (optimization_result.c), from what the run computed ---- */

/* A point of the result, evaluated afresh: its design, figures and violations (each constraint
 * against its raw limit), the full analysis when `analysed`, the robust constraints' fresh run. */
typedef struct {
	prsm_design design;                     /* resolved by the standard rules */
	prsm_dp_figures fig;
	double g[PRSM_OPT_MAX_CONSTRAINTS];     /* prsm_dp_violation, no tolerance */
	int analysed;                           /* analysis and perf are valid */
	const prsm_analysis *analysis;
	const prsm_performance *perf;
	int robust_rc;                          /* prsm_dp_robust's return code */
	prsm_robust_eval robust;
	prsm_error robust_err;
} prsm_io_opt_point;

/* The run's counts as the result reports them. */
typedef struct {
	size_t evaluations, combinations, pruned, runs, runs_feasible, runs_truncated;
	int stop;                               /* prsm_opt_stop */
	int cancelled;
	double elapsed_s;                       /* s */
} prsm_io_opt_run;

/* The head of the result into doc: name, versions, method, warnings, the run's stop reason,
 * evaluations, solver and search. Returns 0 or PRSM_ENOMEM. */
int prsm_io_optimization_run_json(cJSON *doc, const prsm_io_optimization *od, const prsm_problems *warnings,
                                  const prsm_io_opt_run *run);

/* status, feasible, violated and best (p NULL when the run found nothing). Returns 0 or
 * PRSM_ENOMEM. */
int prsm_io_optimization_best_json(cJSON *doc, const prsm_io_optimization *od, int status,
                                   const prsm_io_opt_point *p);

/* The "pareto" section (its points array returned, for the caller to fill with
 * prsm_io_optimization_front_point_json); NULL when out of memory. */
cJSON *prsm_io_optimization_pareto_json(cJSON *doc, const prsm_io_optimization *od,
                                        const prsm_opt_front *front);
int prsm_io_optimization_front_point_json(cJSON *points, const prsm_io_optimization *od,
                                          double epsilon_limit, const prsm_io_opt_point *p);

/* The weighted sum's normalisation (ideal and range per objective). */
void prsm_io_optimization_normalisation_json(cJSON *doc, const prsm_io_optimization *od,
                                             const double *ideal, const double *range);

/* The robust studies' settings and cost (nothing without robust constraints). */
void prsm_io_optimization_robust_json(cJSON *doc, const prsm_io_optimization *od);

#endif
