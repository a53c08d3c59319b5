/*
 * optimization_json.h: the design-optimisation document (schemas/optimization.schema.json) to
 * the PRSM design problem of src/opt/design_problem.h, and its result to JSON
 * (schemas/optimization-result.schema.json). Issue 7, DESIGN.md "Optimisation".
 *
 * A document is a base design (every field the optimiser does not vary is taken from it), the
 * variables (starts, pitch or lead, roller or screw radius, roller count, engaged threads,
 * flank angle: each fixed, a range or a set of values), one or more objectives (efficiency,
 * stiffness, mass, reflected inertia), constraints (nut outer diameter, screw diameter range,
 * static safety, L10 life, p_max, critical speed, roller fit and standard rules always) and the
 * solver settings (algorithm, multi-start, evaluation and time caps, seed), with an optional
 * multi-objective section (weighted sum or an epsilon-constraint Pareto sweep). Every problem
 * of the document is reported at once with its JSON pointer. The result carries the best design
 * as a design document `prsm analyze` accepts, its analysis, every constraint with its value,
 * limit and whether it holds (judged on a fresh analysis against the raw limit: the document's
 * constraint_tolerance only steers the solver), the objectives, the evaluation count, the runs
 * and those truncated, the stop reason, the time, the versions, and for a sweep the Pareto front
 * with each point's design, figures and full analysis.
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

/* Limits of the document (schemas/optimization.schema.json states the same numbers). */
#define PRSM_IO_OPT_MAX_EVALUATIONS 1000000  /* solver.max_evaluations, the document's cap */
#define PRSM_IO_OPT_MAX_TIME_S 86400.0       /* solver.max_time_s */
#define PRSM_IO_OPT_MAX_MULTISTART 64        /* solver.multistart */
#define PRSM_IO_OPT_MAX_PARETO_POINTS 50     /* multi_objective.points */

/* The methods of multi_objective.method, and their names (NULL-terminated). */
enum { PRSM_IO_OPT_SINGLE = 0, PRSM_IO_OPT_WEIGHTED = 1, PRSM_IO_OPT_PARETO = 2 };
extern const char *const prsm_io_opt_method_names[];

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
	int robust_output_of[PRSM_MC_MAX_OUTPUTS]; /* constraint index of each study output */
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

/* The head of the result: name, versions, method, warnings. NULL when out of memory. */
cJSON *prsm_io_optimization_result_head(const prsm_io_optimization *od, const prsm_problems *warnings);

/* cancelled, stop_reason, evaluations, solver and search into doc. */
void prsm_io_optimization_run_json(cJSON *doc, const prsm_io_optimization *od, const prsm_io_opt_run *run);

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
