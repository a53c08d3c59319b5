/*
 * optimize.h: running a design-optimisation document (schemas/optimization.schema.json): the
 * application layer between the callers (cli/, job/) and the reader and writer of io/ and the
 * optimiser of opt/. Issue 7; docs/optimisation.md.
 *
 * The document is read (io/optimization_json.h), the search run (one objective, the normalised
 * weighted sum or the epsilon-constraint Pareto sweep of opt/pareto.h), every reported point
 * analysed afresh (each constraint judged against its raw limit: the document's
 * constraint_tolerance only steers the solver; robust constraints re-run with the search's
 * common random numbers) and the result written (io/optimization_result.c).
 */
#ifndef PRSM_APP_OPTIMIZE_H
#define PRSM_APP_OPTIMIZE_H

#include <stddef.h>

#include <cJSON.h>

#include "mc/study.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

/* Validate doc with these limits: max_evaluations caps solver.max_evaluations (0: the
 * document's own cap, PRSM_IO_OPT_MAX_EVALUATIONS). Loads the base design and checks that at
 * least one combination of the integer variables can be feasible. Every problem goes to
 * problems with its pointer; non-fatal remarks (e.g. base-design radii the optimiser replaces)
 * to warnings (may be NULL). Returns 0 or PRSM_EINVAL (PRSM_ENOMEM when out of memory). */
int prsm_app_optimization_check(const cJSON *doc, size_t max_evaluations, prsm_problems *warnings,
                                prsm_problems *problems);

/* Load, run and write the result in one call. The caller owns *result (cJSON_Delete).
 * cancel (may be NULL) is polled in every evaluation; progress (may be NULL) is called from
 * this thread with done = evaluations, planned = the evaluation budget, best = the best
 * feasible objective so far in its unit. max_time_s 0: no cap beyond the document's.
 * Returns 0 (the result may still say "feasible": false, with the violated constraints named),
 * PRSM_EINVAL (problems filled, *result NULL), PRSM_ECANCELLED (*result still set to the best
 * result so far, flagged "cancelled": true), PRSM_ENOMEM, or another PRSM_E* code with err. */
int prsm_app_optimize(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                      prsm_problems *problems, prsm_error *err);

/* prsm_app_optimize with the robust constraints' studies run by service (mc/study.h: e.g. over
 * the ranks of an MPI job, src/par; NULL: this process). The search itself runs here: its
 * evaluation budget is shared out as it goes, so its runs are sequential. The result is the
 * same with any service that returns prsm_study_run's result. */
int prsm_app_optimize_with(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                           const prsm_study_service *service, prsm_problems *problems, prsm_error *err);

#endif
