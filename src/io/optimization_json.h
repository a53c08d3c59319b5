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

#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

/* Limits of the document (schemas/optimization.schema.json states the same numbers). */
#define PRSM_IO_OPT_MAX_EVALUATIONS 1000000  /* solver.max_evaluations, the document's cap */
#define PRSM_IO_OPT_MAX_TIME_S 86400.0       /* solver.max_time_s */
#define PRSM_IO_OPT_MAX_MULTISTART 64        /* solver.multistart */
#define PRSM_IO_OPT_MAX_PARETO_POINTS 50     /* multi_objective.points */

/* Validate doc with these limits: max_evaluations caps solver.max_evaluations (0: the
 * document's own cap, PRSM_IO_OPT_MAX_EVALUATIONS). Loads the base design and checks that at
 * least one combination of the integer variables can be feasible. Every problem goes to
 * problems with its pointer; non-fatal remarks (e.g. base-design radii the optimiser replaces)
 * to warnings (may be NULL). Returns 0 or PRSM_EINVAL (PRSM_ENOMEM when out of memory). */
int prsm_io_optimization_check(const cJSON *doc, size_t max_evaluations, prsm_problems *warnings,
                               prsm_problems *problems);

/* Load, run and write the result in one call. The caller owns *result (cJSON_Delete).
 * cancel (may be NULL) is polled in every evaluation; progress (may be NULL) is called from
 * this thread with done = evaluations, planned = the evaluation budget, best = the best
 * feasible objective so far in its unit. max_time_s 0: no cap beyond the document's.
 * Returns 0 (the result may still say "feasible": false, with the violated constraints named),
 * PRSM_EINVAL (problems filled, *result NULL), PRSM_ECANCELLED (*result still set to the best
 * result so far, flagged "cancelled": true), PRSM_ENOMEM, or another PRSM_E* code with err. */
int prsm_io_optimization_execute(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                                 prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                                 prsm_problems *problems, prsm_error *err);

#endif
