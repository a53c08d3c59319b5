/*
 * simulate.h: running a simulation request (schemas/simulation.schema.json): the application
 * layer between the callers (cli/simulate.c, job/kind_simulation.c) and the reader and writer of
 * io/ (io/analyze_request.h reads the design or the chain with its statics and the `dynamics`
 * object, io/dynamics_json.h writes the result) and the rigid-body transient of dyn/.
 * Issue 15; docs/dynamics.md. The vibration analyses of the same document (an analysis other
 * than transient: linear, vibration, sweep, frequency_response, basins; docs/vibration.md) run
 * through app/vibrate.h behind the same handle: on the reduced elastic model of a single-stage
 * design, or on the 1-DOF gear pair of a request without a design,
 * {"dynamics": {"analysis": ..., "gear_pair": {...}}}.
 *
 * A run is read -> model -> simulate -> write:
 *
 *   prsm_app_simulation *s;
 *   prsm_app_simulation_load(&s, doc, &warnings, &problems);   the document, every problem
 *   prsm_app_simulation_run(s, cancel, progress, ctx, 0, &err); the integration
 *   cJSON *res = prsm_app_simulation_result(s);                  the result document
 *   prsm_app_simulation_free(s);
 *
 * A simulation that does not converge is an error that says so (PRSM_ENOCONVERGE with err),
 * never a curve.
 */
#ifndef PRSM_APP_SIMULATE_H
#define PRSM_APP_SIMULATE_H

#include <stddef.h>
#include <stdio.h>

#include <cJSON.h>

#include "app/vibrate.h"
#include "dyn/dyn.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

typedef struct prsm_app_simulation prsm_app_simulation;

/*
 * Read and check the simulation request doc (not taken over): the form ({design, dynamics} or a
 * multi-stage design with dynamics; no error set), the design or each stage with its nominal
 * analysis, the dynamics object, then the model (kinematic structure, masses, statics
 * references and the settled state). Every problem goes to problems with its pointer, the
 * designs' rule warnings to warnings (may be NULL). Returns 0 with *out allocated
 * (prsm_app_simulation_free), or PRSM_EINVAL, PRSM_EGEOMETRY, PRSM_EEDGE, PRSM_ENOCONVERGE (the
 * statics references did not converge), PRSM_ENOMEM with *out NULL.
 */
int prsm_app_simulation_load(prsm_app_simulation **out, const cJSON *doc, prsm_problems *warnings,
                             prsm_problems *problems);

/* Output times the loaded request asks for (end_s / output_step_s, the end included; 0 for the
 * vibration analyses). */
size_t prsm_app_simulation_points(const prsm_app_simulation *s);

/* The loaded request's analysis (io/dynamics_json.h, PRSM_IO_DYN_*). */
int prsm_app_simulation_analysis(const prsm_app_simulation *s);

/* The progress a run plans and its unit (*unit may be NULL): simulated nanoseconds
 * ("simulated_ns", the transient), sweep points ("sweep_points"), basin cells ("basin_cells"),
 * or 1 ("analyses"). */
size_t prsm_app_simulation_work(const prsm_app_simulation *s, const char **unit);

/* The engine threads of the vibration analyses' sweeps and grids (1 to 256; the default 1). The
 * result does not depend on them. */
void prsm_app_simulation_set_threads(prsm_app_simulation *s, int threads);
/* A sweep's or basin grid's tasks over processes (app/vibrate.h prsm_app_vibration_set_split):
 * 1 when this simulation's analysis takes the split, else 0 (it runs whole). */
int prsm_app_simulation_set_split(prsm_app_simulation *s, const prsm_vib_split *split);

/* The vibration analysis of the loaded request (NULL for the transient). */
const prsm_app_vibration *prsm_app_simulation_vibration(const prsm_app_simulation *s);

/*
 * Integrate the loaded request. cancel (may be NULL) stops it; progress (may be NULL) is called
 * with done / planned in simulated nanoseconds (vibration analyses: prsm_app_simulation_work's
 * unit); max_time_s > 0 caps the wall-clock time (then cancel and the cap are looked at with
 * each progress report, every 1/200 of the simulated time or output time, whichever is later;
 * for the vibration analyses by a watchdog thread every 20 ms). Returns 0; PRSM_ECANCELLED (err says whether the
 * flag or the time cap stopped it); PRSM_ENOCONVERGE (err says when and why); PRSM_ENOMEM.
 */
int prsm_app_simulation_run(prsm_app_simulation *s, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                            void *progress_ctx, double max_time_s, prsm_error *err);

/* The result document of a run (schemas/dynamics-result.schema.json); the caller owns it. NULL
 * when out of memory or not run. */
cJSON *prsm_app_simulation_result(const prsm_app_simulation *s);

/* The run's time series as CSV, and its text summary. Return 0, PRSM_EIO, or PRSM_EINVAL when not run. */
int prsm_app_simulation_csv(FILE *f, const prsm_app_simulation *s);
int prsm_app_simulation_text(FILE *f, const prsm_app_simulation *s);

/* The model and the run's result (NULL before a successful run), for tests and summaries. */
const prsm_dyn_model *prsm_app_simulation_model(const prsm_app_simulation *s);
const prsm_dyn_result *prsm_app_simulation_dyn_result(const prsm_app_simulation *s);

/* Release a simulation (NULL is fine). */
void prsm_app_simulation_free(prsm_app_simulation *s);

/* Load and free: the document's check (prsm validate, the fuzz target). Returns as _load. */
int prsm_app_simulation_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems);

/* Load, run and write in one call; the caller owns *result (NULL unless 0 is returned).
 * Returns 0, PRSM_EINVAL (problems filled), or the codes of _load and _run with err. */
int prsm_app_simulate(cJSON **result, const cJSON *doc, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                      void *progress_ctx, double max_time_s, prsm_problems *problems, prsm_error *err);

#endif
