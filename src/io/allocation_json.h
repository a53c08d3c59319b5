/*
 * allocation_json.h: the tolerance-allocation document (schemas/allocation.schema.json, whose
 * descriptions say what it holds and what the reader checks) to the allocation problem of
 * src/opt/alloc.h and its Monte Carlo verification and correction (src/opt/alloc_mc.h), and the
 * result (schemas/allocation-result.schema.json). Issue 7, item 4.
 */
#ifndef PRSM_IO_ALLOCATION_JSON_H
#define PRSM_IO_ALLOCATION_JSON_H

#include <stddef.h>

#include <cJSON.h>

#include "io/study_json.h"
#include "opt/alloc_mc.h"
#include "util/problems.h"

#define PRSM_IO_ALLOC_MAX_SAMPLES 4000000 /* samples of all Monte Carlo runs together, at most */

/* A loaded document. Large: on the heap. */
typedef struct {
	char name[404]; /* up to 100 characters of UTF-8 */
	int is_study;
	prsm_io_study *study;                         /* study kind */
	char tol_name[PRSM_ALLOC_MAX_TOLERANCES][PRSM_STUDY_NAME_MAX];
	char out_name[PRSM_ALLOC_MAX_CONSTRAINTS][48];
	char unit[PRSM_ALLOC_MAX_TOLERANCES][16];     /* the tolerance's unit ("um", "mrad", "") */
	double ref_given[PRSM_ALLOC_MAX_TOLERANCES];  /* analytic: reference half-width or NAN */
	size_t n_aout;                                /* analytic outputs */
	char aout_name[PRSM_ALLOC_MAX_CONSTRAINTS][48];
	double aout_nominal[PRSM_ALLOC_MAX_CONSTRAINTS];
	double sens[PRSM_ALLOC_MAX_TOLERANCES][PRSM_ALLOC_MAX_CONSTRAINTS]; /* analytic, by analytic output */
	int has_spec[PRSM_ALLOC_MAX_CONSTRAINTS];
	double target_yield[PRSM_ALLOC_MAX_CONSTRAINTS]; /* fraction, NAN when the tolerance is given */
	prsm_alloc_model model;
	prsm_alloc_mc_options opt;
	int threads;                                  /* monte_carlo.threads, 0: the study's */
	long seed;                                    /* monte_carlo.seed, else the study's */
	size_t samples;
} prsm_io_allocation;

/* The items of the document's arrays as the table-driven reader reads them (generated from the
 * schema, src/io/doc.h); the steps of allocation_json.c move them into the parallel arrays above. */
typedef struct {
	double nominal;
} prsm_io_alloc_output;                          /* analytic/outputs/N (its name: the step's) */
typedef struct {
	double lower, upper;
} prsm_io_alloc_bounds;
void prsm_io_alloc_bounds_init(prsm_io_alloc_bounds *b); /* lower 0, upper INFINITY (none) */
typedef struct {
	prsm_alloc_cost cost;
	prsm_io_alloc_bounds bounds;
	double sd_ratio, reference_half_width;
} prsm_io_alloc_tolerance;                       /* allocate/N (its parameter: the step's) */
typedef struct {
	prsm_spec spec;                              /* the constraint's own spec, when has_spec */
	int has_spec;
	double target_yield_percent, target_ppm, assembly_tolerance;
	int yield_method, has_yield_method;          /* prsm_study_yield_method, when given */
} prsm_io_alloc_constraint;                      /* constraints/N (its output: the step's) */

/* Read and check doc into *out (owned by the caller: prsm_io_allocation_free): a study is
 * loaded with the study reader's hooks `study` (io/study_json.h; the application's,
 * prsm_app_study_options, to run it), an analytic stack's linear model filled in; a study's
 * linear model and the feasibility of the allocation are the run's (src/app/allocate.h). max_samples caps the Monte
 * Carlo samples of the whole allocation (0: PRSM_IO_ALLOC_MAX_SAMPLES). Every problem goes to
 * problems with its pointer, remarks to warnings (may be NULL). Returns 0, PRSM_EINVAL or
 * PRSM_ENOMEM (*out NULL). */
int prsm_io_allocation_read(prsm_io_allocation **out, const cJSON *doc, size_t max_samples,
                            const prsm_io_study_options *study, prsm_problems *warnings,
                            prsm_problems *problems);
void prsm_io_allocation_free(prsm_io_allocation *d);

/* The result document of a run (r->best a valid step); NULL when out of memory. */
cJSON *prsm_io_allocation_result_json(const prsm_io_allocation *d, const prsm_alloc_mc_result *r,
                                      int cancelled);

#endif
