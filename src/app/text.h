/*
 * text.h: the short text summaries of a run's results for engineers (prsm simulate and prsm
 * calibrate --format text): what the application layer computed, printed, never a document
 * (the JSON results are written by io/ from their schemas).
 */
#ifndef PRSM_APP_TEXT_H
#define PRSM_APP_TEXT_H

#include <stdio.h>

#include "dyn/dyn.h"
#include "io/dynamics_json.h"
#include "io/measured.h"
#include "util/problems.h"

/* A start-up transient. Returns 0 or PRSM_EIO. */
int prsm_app_text_transient(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r, const prsm_problems *warnings);

/* A vibration analysis. Returns 0 or PRSM_EIO. */
int prsm_app_text_vibration(FILE *f, const prsm_io_vib_request *q, const prsm_vib_model *m, const prsm_io_vib_result *r,
                            const prsm_problems *warnings);

/* A calibration, with the caveats printed with the result. Returns 0 or PRSM_EIO. */
int prsm_app_text_calibration(FILE *f, const prsm_io_calibration *c);

#endif
