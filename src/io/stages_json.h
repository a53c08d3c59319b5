/*
 * stages_json.h: the multi-stage design document (docs/model/kinematics-efficiency-stiffness-life.md;
 * schemas/multistage-design.schema.json) and its analysis result.
 *
 * {"name", "description", "stages": [design, ...], "couplings": {...}, "operating_point"}:
 * each stage is a single-stage design document without an operating point (the load F acts
 * on the last nut, the speed is the common screw speed); the couplings give the spline
 * friction mu_SS and the thrust-bearing friction mu_NS of seed 000 and, per coupling
 * (stage k >= 2), the spline and thrust-bearing radii. Defaults, echoed in the result: mu 0,
 * spline radius = the screw pitch radius of stage k-1 (the spline drives screw k from screw
 * k-1), thrust-bearing radius = the mean of the nut pitch radius of stage k-1 and the screw
 * pitch radius of stage k (the bearing sits between them).
 */
#ifndef PRSM_IO_STAGES_JSON_H
#define PRSM_IO_STAGES_JSON_H

#include <stdio.h>

#include <cJSON.h>

#include "model/analysis.h"
#include "model/performance.h"
#include "model/stages.h"
#include "util/problems.h"

typedef struct {
	int stages;
	prsm_design design[PRSM_STAGES_MAX];     /* resolved stage designs, at the stage loads */
	prsm_analysis analysis[PRSM_STAGES_MAX]; /* each at its load F_k from the chain */
	int spline_radius_default[PRSM_STAGES_MAX], thrust_radius_default[PRSM_STAGES_MAX];
	prsm_chain_input chain_input;
	prsm_chain chain;
} prsm_io_multistage;

/* doc has the multi-stage form (a "stages" member). */
int prsm_io_is_multistage(const cJSON *doc);

/* Read and check the multi-stage document: every problem with its pointer; rule warnings of
 * the stages to warnings. Returns 0, PRSM_EINVAL or PRSM_EGEOMETRY. The stages' analyses and
 * the chain (analysis[], chain, each design at its stage load) are prsm_app_multistage_load's
 * (app/analyze.h). */
int prsm_io_multistage_read(prsm_io_multistage *out, const cJSON *doc, prsm_problems *warnings,
                            prsm_problems *problems);

/* The result document, with each stage's operating-point analysis perf[k]; the caller owns
 * it. NULL when out of memory. */
cJSON *prsm_io_multistage_to_json(const prsm_io_multistage *m, const prsm_performance *perf,
                                  const prsm_problems *warnings);

#endif
