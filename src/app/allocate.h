/*
 * allocate.h: checking and running a tolerance-allocation document
 * (schemas/allocation.schema.json): read by io/allocation_json.h, linearised (a study's model
 * by central differences), allocated and corrected by opt/alloc_mc.h, written by
 * io/allocation_result.c. Issue 7, item 4; docs/optimisation.md.
 */
#ifndef PRSM_APP_ALLOCATE_H
#define PRSM_APP_ALLOCATE_H

#include <stddef.h>

#include <cJSON.h>

#include "mc/study.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

/* Validate doc with these limits: max_samples caps the Monte Carlo samples of the whole
 * allocation, monte_carlo.samples x (1 + max_corrections) (0: PRSM_IO_ALLOC_MAX_SAMPLES).
 * Loads the embedded study (design analysis included), builds the linear model and checks that
 * the linear allocation can meet every constraint. Every problem goes to problems with its
 * pointer; the design's rule warnings to warnings (may be NULL). Returns 0 or PRSM_EINVAL
 * (PRSM_EGEOMETRY / PRSM_EEDGE when the study's design cannot be analysed, PRSM_ENOMEM). */
int prsm_app_allocation_check(const cJSON *doc, size_t max_samples, prsm_problems *warnings,
                              prsm_problems *problems);

/* Load, run and write the result in one call. The caller owns *result (cJSON_Delete).
 * cancel (may be NULL) is polled between and inside the Monte Carlo runs and the solves;
 * progress (may be NULL) is called from this thread with done / planned = Monte Carlo samples
 * (evaluations of the linear solver for an analytic document) and best = the total cost of the
 * best allocation that met every target so far. max_time_s 0: no cap (it also caps each
 * allocation's solve; when it ends before the first Monte Carlo run the result is the linear
 * allocation, unverified, stop_reason time_cap); threads 0: the study's own (results do not
 * depend on it). Returns 0 (the result may say "converged": false when the correction could
 * not meet the target), PRSM_EINVAL (problems filled, *result NULL; also a spec that no
 * allocation within the bounds can meet), PRSM_ENOCONVERGE (the time cap ended before the
 * linear allocation was solved), PRSM_ECANCELLED (*result set to the best-so-far document when
 * there is one, flagged "cancelled": true), PRSM_ENOMEM, or another PRSM_E* code with err. */
int prsm_app_allocate(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, double max_time_s, int threads,
                      prsm_problems *problems, prsm_error *err);

/* prsm_app_allocate with the Monte Carlo corrections' studies run by service (mc/study.h: e.g.
 * over the ranks of an MPI job, src/par; NULL: this process), which is handed the embedded study
 * document with each. The result is the same with any service that returns prsm_study_run's. */
int prsm_app_allocate_with(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, double max_time_s, int threads,
                           const prsm_study_service *service, prsm_problems *problems, prsm_error *err);

#endif
