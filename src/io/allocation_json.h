/*
 * allocation_json.h: the tolerance-allocation document (schemas/allocation.schema.json) to the
 * allocation problem of src/opt/alloc.h, its Monte Carlo verification and correction
 * (src/opt/alloc_mc.h), and the result (schemas/allocation-result.schema.json). Issue 7, item 4.
 *
 * A document is either a tolerance study (schemas/study.schema.json, under `study`) whose
 * tolerances get a cost model and bounds, or a pure analytic stack (`analytic`: explicit
 * sensitivities and nominals, no design, no Monte Carlo), plus the constraints (an output with
 * its spec and a target yield or ppm, or an assembly tolerance given directly), the stack model
 * (`rss` or `worst_case`) and the solver. Every problem of the document is reported at once with
 * its JSON pointer. The result carries, per tolerance, the allocated half-width (in the
 * parameter's unit) and its cost; the total cost; per constraint the assembly tolerance, the
 * predicted (linear) yield and the Monte Carlo yield with its 95 % Wilson interval; the
 * correction steps; the stop reason, the time and the versions.
 */
#ifndef PRSM_IO_ALLOCATION_JSON_H
#define PRSM_IO_ALLOCATION_JSON_H

#include <stddef.h>

#include <cJSON.h>

#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

/* Limits of the document (schemas/allocation.schema.json states the same numbers). */
#define PRSM_IO_ALLOC_MAX_TOLERANCES 64      /* tolerances allocated */
#define PRSM_IO_ALLOC_MAX_CONSTRAINTS 16     /* constrained outputs */
#define PRSM_IO_ALLOC_MAX_CORRECTIONS 30     /* monte_carlo.max_corrections */
#define PRSM_IO_ALLOC_MAX_SAMPLES 4000000    /* samples of all Monte Carlo runs together */

/* Validate doc with these limits: max_samples caps the Monte Carlo samples of the whole
 * allocation, monte_carlo.samples x (1 + max_corrections) (0: PRSM_IO_ALLOC_MAX_SAMPLES).
 * Loads the embedded study (design analysis included). Every problem goes to problems with its
 * pointer; the design's rule warnings to warnings (may be NULL). Returns 0 or PRSM_EINVAL
 * (PRSM_EGEOMETRY / PRSM_EEDGE when the study's design cannot be analysed, PRSM_ENOMEM). */
int prsm_io_allocation_check(const cJSON *doc, size_t max_samples, prsm_problems *warnings,
                             prsm_problems *problems);

/* Load, run and write the result in one call. The caller owns *result (cJSON_Delete).
 * cancel (may be NULL) is polled between and inside the Monte Carlo runs and the solves; progress (may be
 * NULL) is called from this thread with done / planned = Monte Carlo samples (evaluations of
 * the linear solver for an analytic document) and best = the total cost of the best allocation
 * that met every target so far. max_time_s 0: no cap (it also caps each allocation's solve;
 * when it ends before the first Monte Carlo run the result is the linear allocation,
 * unverified, stop_reason time_cap); threads 0: the study's own (results do not depend on it).
 * Returns 0 (the result may say "converged": false when the correction could not
 * meet the target), PRSM_EINVAL (problems filled, *result NULL; also a spec that no allocation
 * within the bounds can meet), PRSM_ENOCONVERGE (the time cap ended before the linear
 * allocation was solved), PRSM_ECANCELLED (*result set to the best-so-far document when
 * there is one, flagged "cancelled": true), PRSM_ENOMEM, or another PRSM_E* code with err. */
int prsm_io_allocation_execute(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                               prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                               int threads, prsm_problems *problems, prsm_error *err);

#endif
