/*
 * vibrate.h: the vibration analyses of a simulation request (docs/vibration.md): the reduced
 * elastic model of a design, or the 1-DOF gear pair of a request without a design, built from
 * the request's dynamics object (io/dynamics_json.h, prsm_io_vib_request), run (dyn/vib.h:
 * linear, vibration, sweep, frequency_response, basins) and written. app/simulate.c calls it for
 * every analysis other than the transient; the callers (cli/simulate.c, job/kind_simulation.c)
 * see one prsm_app_simulation handle.
 *
 * Results do not depend on the number of threads (dyn/vib.h: every sweep point and basin cell is
 * a task of its own). A point of a sweep that fails is reported in the result, not an error;
 * an analysis that fails as a whole (a steady state that does not converge) is PRSM_ENOCONVERGE
 * with err, and no result.
 */
#ifndef PRSM_APP_VIBRATE_H
#define PRSM_APP_VIBRATE_H

#include <stddef.h>
#include <stdio.h>

#include <cJSON.h>

#include "dyn/dyn.h"
#include "dyn/vib.h"
#include "io/dynamics_json.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/design.h"
#include "model/errors.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

typedef struct prsm_app_vibration prsm_app_vibration;

/*
 * Build the model of request q: the gear pair (q->gear_pair_model; design, analysis, dyn, errors
 * and assembly unused, may be NULL) or the reduced model of design d with its nominal analysis a,
 * the transient options dyn of the request (load, friction, masses) and, for TE lines from the
 * statics, the error set and its assembly options. Then the rules that need the model (rollers,
 * the TE period, the Lyapunov exponents, the linear band's defaults), each at its pointer. The
 * request is copied. Returns 0 with *out allocated, PRSM_EINVAL (problems added), PRSM_ENOCONVERGE
 * (the statics), PRSM_ENOMEM.
 */
int prsm_app_vibration_new(prsm_app_vibration **out, const prsm_io_vib_request *q, const prsm_design *d,
                           const prsm_analysis *a, const prsm_dyn_options *dyn, const prsm_errors *errors,
                           const prsm_assembly_options *assembly, prsm_problems *problems);

/* Progress units the run plans (sweep points, basin cells; 1 for the other analyses) and their
 * name ("sweep_points", "basin_cells", "analyses"). */
size_t prsm_app_vibration_work(const prsm_app_vibration *v);
const char *prsm_app_vibration_work_unit(const prsm_app_vibration *v);

/* Run the analysis on `threads` threads (>= 1). cancel (may be NULL) stops it, progress (may be
 * NULL) gets done / planned in the units above from the calling thread. Returns 0,
 * PRSM_ECANCELLED, PRSM_ENOCONVERGE, PRSM_EINVAL, PRSM_ENOMEM with err. */
int prsm_app_vibration_run(prsm_app_vibration *v, int threads, const prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, prsm_error *err);

/* Spread the run's tasks over processes (dyn/vib.h prsm_vib_split: a sweep's directions or
 * points, a basin grid's cells; every process runs the same request with its part, part 0 gets
 * the result, the others an empty one). Only the sweep and basins analyses can: returns 1 for
 * them (split taken), else 0 (split ignored: the analysis runs whole wherever it is run). */
int prsm_app_vibration_set_split(prsm_app_vibration *v, const prsm_vib_split *split);

/* The result document (schemas/dynamics-result.schema.json), NULL when not run or out of memory. */
cJSON *prsm_app_vibration_result(const prsm_app_vibration *v, const char *name, const prsm_problems *warnings);
/* The analysis' series as CSV and its text summary (io/dynamics_json.h). PRSM_EINVAL when not run. */
int prsm_app_vibration_csv(FILE *f, const prsm_app_vibration *v);
int prsm_app_vibration_text(FILE *f, const prsm_app_vibration *v, const prsm_problems *warnings);

/* The request as the run takes it (defaults resolved), the model, and the run's output (NULL
 * before a successful run). */
const prsm_io_vib_request *prsm_app_vibration_request(const prsm_app_vibration *v);
const prsm_vib_model *prsm_app_vibration_model(const prsm_app_vibration *v);
const prsm_io_vib_result *prsm_app_vibration_output(const prsm_app_vibration *v);

void prsm_app_vibration_free(prsm_app_vibration *v);

#endif
