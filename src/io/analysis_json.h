/*
 * analysis_json.h: the nominal analysis as the JSON result document (schemas/analysis.schema.json,
 * written by the tables generated from it). Units are in every field name.
 */
#ifndef PRSM_IO_ANALYSIS_JSON_H
#define PRSM_IO_ANALYSIS_JSON_H

#include <cJSON.h>
#include <stdio.h>

#include "io/stages_json.h"
#include "io/write.h"
#include "model/analysis.h"
#include "model/assembly_report.h"
#include "model/performance.h"
#include "util/problems.h"

/* The model the results follow (what the "engine"."model" field of a result names). */
#define PRSM_MODEL_VERSION "prsm model 2026-11 (docs/model: geometry and meshing; errors and assembly; kinematics, efficiency, stiffness and life)"

/* Build the result object with the operating-point analysis perf of
 * docs/model/kinematics-efficiency-stiffness-life.md; the caller owns it (cJSON_Delete). NULL
 * when out of memory. */
cJSON *prsm_io_analysis_to_json(const prsm_analysis *a, const prsm_design *d,
                                const prsm_performance *perf, const prsm_problems *warnings);

/* The same result's members written into obj. */
void prsm_io_analysis_write(prsm_jw *w, cJSON *obj, const prsm_analysis *a, const prsm_design *d,
                            const prsm_performance *perf, const prsm_problems *warnings);

/* RFC 7807 problem document for a list of problems; caller owns it. */
cJSON *prsm_io_problem_document(int status, const char *title, const prsm_problems *p);

/* What the generated tables of the analysis result read (the x-prsm "field"s of
 * schemas/analysis.schema.json): the parts of a result, and the values derived from them (the
 * views of the contact, the analysis, the chain and the error analysis are the schema's "view"s,
 * declared in prsm_io_writers.h). */
typedef struct {
	const prsm_loaddist_side_result *s;
	const double *loads;     /* per thread */
	int threads, most_loaded; /* n_t; the most loaded thread, from 1 */
} prsm_io_side_view;

/* The error analysis (its "assembly" member, io/assembly_json.h): the gaps of one pair. */
typedef struct {
	double min_mm, max_mm;  /* the gaps of one pair and direction */
	const double *gap_mm;   /* every gap, roller by roller (when curve) */
	int rollers, threads, curve;
} prsm_io_gap_view;

#endif
