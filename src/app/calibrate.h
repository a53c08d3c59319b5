/*
 * calibrate.h: running a calibration request (schemas/measured-request.schema.json;
 * docs/measured-data.md): the application layer between cli/calibrate.c and the readers and
 * writers of io/measured.h, io/analyze_request.h, and the model layer dyn/measured.h and
 * dyn/calib.h (MODEL-DYNAMICS.md §8.5).
 *
 *   prsm_app_calibration *c;
 *   prsm_app_calibration_load(&c, doc, csv_path, &problems);  the document and the CSV, every problem
 *   prsm_app_calibration_run(c, &err);                          comparison, identification, calibration
 *   cJSON *res = prsm_app_calibration_result(c);                 the result document
 *   prsm_app_calibration_free(c);
 */
#ifndef PRSM_APP_CALIBRATE_H
#define PRSM_APP_CALIBRATE_H

#include <stdio.h>

#include <cJSON.h>

#include "io/measured.h"
#include "util/error.h"
#include "util/problems.h"

typedef struct prsm_app_calibration prsm_app_calibration;

/* Read and check the request doc (not taken over) and, when csv_path is not NULL, the measured
 * TE curve from that CSV file (it replaces a curve in the document, with a warning). Every
 * problem goes to problems (JSON pointers; CSV problems at the file's path with line and
 * column). Returns 0 with *out allocated (prsm_app_calibration_free), or PRSM_EINVAL,
 * PRSM_EIO (the CSV cannot be read), PRSM_EGEOMETRY, PRSM_EEDGE, PRSM_ENOCONVERGE, PRSM_ENOMEM
 * with *out NULL. */
int prsm_app_calibration_load(prsm_app_calibration **out, const cJSON *doc, const char *csv_path,
                              prsm_problems *problems);

/* Compute what the measurements allow: §8.5 items 1-4. Returns 0, PRSM_EINVAL (err: a
 * calibration option the data cannot take), PRSM_ENOCONVERGE, PRSM_ENOMEM. */
int prsm_app_calibration_run(prsm_app_calibration *c, prsm_error *err);

/* The result document (the caller owns it; NULL when out of memory or not run). */
cJSON *prsm_app_calibration_result(const prsm_app_calibration *c);
/* The text summary. Returns 0, PRSM_EIO, or PRSM_EINVAL when not run. */
int prsm_app_calibration_text(FILE *f, const prsm_app_calibration *c);
/* What was computed (for tests). */
const prsm_io_calibration *prsm_app_calibration_data(const prsm_app_calibration *c);

void prsm_app_calibration_free(prsm_app_calibration *c);

#endif
