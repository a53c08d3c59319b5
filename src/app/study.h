/*
 * study.h: a tolerance study's computations before it runs (schemas/study.schema.json): the
 * nominal analysis of its design, the assembly built on it, and the engine's model of the
 * design with what its outputs need of the nominal nut unit or of the dynamic model, and the
 * ranges it would compute checked (distributions, a benchmark's outputs). The
 * document is read by io/study_json.h, which calls these where its reading needs them (its
 * hooks, prsm_io_study_options), so that a study's problems come in one list, in the reading's
 * order; the study then runs by mc/study.h and is written by io/study_json.h.
 */
#ifndef PRSM_APP_STUDY_H
#define PRSM_APP_STUDY_H

#include <cJSON.h>

#include "io/study_json.h"
#include "util/problems.h"

/* Set *o to the application's hooks: the design analysed and the model built. Returns 0. */
int prsm_app_study_options(prsm_io_study_options *o);

/* Read, check and prepare the study document doc (prsm_io_study_load with
 * prsm_app_study_options): what a study is run from. Every problem goes to problems with its
 * pointer; rule and analysis warnings to warnings (may be NULL). Returns 0, PRSM_EINVAL
 * (problems were added) or PRSM_EGEOMETRY / PRSM_EEDGE (the design cannot be analysed; a
 * problem names it). */
int prsm_app_study_load(prsm_io_study *out, const cJSON *doc, prsm_problems *warnings, prsm_problems *problems);

#endif
