/*
 * analysis_json.h: the nominal analysis as the JSON result document, and as a one-page text
 * summary for engineers (`prsm analyze --format text`). Units are in every field name.
 */
#ifndef PRSM_IO_ANALYSIS_JSON_H
#define PRSM_IO_ANALYSIS_JSON_H

#include <cJSON.h>
#include <stdio.h>

#include "model/analysis.h"
#include "model/performance.h"
#include "util/problems.h"

/* Build the result object; the caller owns it (cJSON_Delete). NULL when out of memory. perf
 * (may be NULL: sliding efficiency only) adds the operating-point analysis of docs/model/kinematics-efficiency-stiffness-life.md-§6. */
/* The model the results follow (what the "engine"."model" field of a result names). */
#define PRSM_MODEL_VERSION "prsm model 2026-11 (docs/model: geometry and meshing; errors and assembly; kinematics, efficiency, stiffness and life)"

cJSON *prsm_io_analysis_to_json(const prsm_analysis *a, const prsm_design *d,
                                const prsm_performance *perf, const prsm_problems *warnings);

/* Problems as a JSON array of {pointer, code, message}; caller owns it. */
cJSON *prsm_io_problems_to_json(const prsm_problems *p);

/* RFC 7807 problem document for a list of problems; caller owns it. */
cJSON *prsm_io_problem_document(int status, const char *title, const prsm_problems *p);

#endif
