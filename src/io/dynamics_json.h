/*
 * dynamics_json.h: the `dynamics` object of a request (schemas/dynamics.schema.json) into the
 * options of the rigid-body transient (dyn/dyn.h), and a simulation's result document
 * (schemas/dynamics-result.schema.json) and time series (CSV). docs/dynamics.md.
 *
 * The reader is the table generated from the annotated schema (io/doc.h) filling
 * prsm_dyn_options directly; what a table cannot say is in the hooks of dynamics_json.c (the
 * analysis name, the input's kind-specific names, the per-stage masses, the step cap) and in
 * prsm_io_dynamics_from_json (the chain's form of the masses, the default output step, then
 * the model's own cross-field rules, prsm_dyn_options_check). Every problem is at its JSON
 * pointer under /dynamics.
 *
 * The writer uses the sticky-error writer of io/write.h: a result is whole or not at all.
 */
#ifndef PRSM_IO_DYNAMICS_JSON_H
#define PRSM_IO_DYNAMICS_JSON_H

#include <stdio.h>

#include <cJSON.h>

#include "dyn/dyn.h"
#include "io/write.h"
#include "util/problems.h"

/* The model a simulation result names ("engine"."model"). */
#define PRSM_DYN_MODEL_VERSION "prsm dynamics 2026-12 (docs/dynamics.md: rigid-body transient of single- and multi-stage screws)"

/* Default output grid: end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS (501 output times; for the default
 * 0.005 s a step of 1e-5 s, where a case-A start-up still runs at its full speed: every output
 * time cuts the integrator's step and evaluates every force, docs/dynamics.md). */
#define PRSM_IO_DYN_DEFAULT_OUTPUTS 500

/* The residual limits the result's checks judge against: the power balance relative to the
 * input power, the Newton-Euler recovery of the carrier acceleration (relative), -. */
#define PRSM_IO_DYN_POWER_BALANCE_LIMIT 1e-6
#define PRSM_IO_DYN_NEWTON_EULER_LIMIT 1e-9

/*
 * Read the dynamics object obj (at /dynamics; NULL: absent, every default) of a request for a
 * chain of `stages` stages (1 for a single design) into *o, which is set to the defaults
 * first: the fields by the schema's table, output_step_s = end_s / 500 when not given, the
 * single-stage or chain form of the masses, then prsm_dyn_options_check (each of its problems
 * unless the field already has one). couplings are not part of the object: the caller copies a
 * chain's from its multi-stage document. Returns 0 or PRSM_EINVAL (problems added).
 */
int prsm_io_dynamics_from_json(prsm_dyn_options *o, const cJSON *obj, int stages, prsm_problems *problems);

/* The dynamics result (the `dynamics` member of the document) of a finished simulation r of
 * model m, as obj[key]. warnings (may be NULL) gets a problem per failed check. */
void prsm_io_dynamics_write(prsm_jw *w, cJSON *obj, const char *key, const prsm_dyn_model *m,
                            const prsm_dyn_result *r, prsm_problems *warnings);

/* The whole result document {engine, name, warnings, dynamics} (schemas/dynamics-result.schema.json);
 * name may be NULL or "". The caller owns it; NULL when out of memory. The checks' warnings are
 * appended to a copy of warnings (may be NULL). */
cJSON *prsm_io_dynamics_result_to_json(const char *name, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                       const prsm_problems *warnings);

/* The time series as CSV: a header line, then one line per output time (numbers in %.17g,
 * empty where a value is not defined, e.g. the efficiency at rest). Returns 0 or PRSM_EIO. */
int prsm_io_dynamics_write_csv(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r);

/* A short text summary for engineers (prsm simulate --format text). Returns 0 or PRSM_EIO. */
int prsm_io_dynamics_write_text(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                const prsm_problems *warnings);

#endif
